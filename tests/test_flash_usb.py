"""build/flash through real libusb against a USB DFU device emulated with umockdev.

tests/usbdfu_mock.py sets up a umockdev test bed (sysfs, descriptors, /dev/bus/usb
node) and answers libusb's usbfs ioctls with the project's own DFU state machine
(firmware/dfu/dfu_device.c as build/libdfudev.so); build/flash runs unmodified as its
child. Each test reads the mock's JSON summary (what the device saw and holds) and checks
the device's flash region with the state machine's own dfu_app_check.

What umockdev carries here: enumeration (udev and sysfs, the `descriptors` attribute),
open, GET_CAPABILITIES, DISCONNECT_CLAIM/CLAIM/RELEASE, control URBs (SUBMITURB,
REAPURBNDELAY, DISCARDURB on a timeout, stalls as -EPIPE), RESET, and hotplug (add and
remove uevents) for the re-enumeration. What it cannot: umockdev's node is a socket, so
libusb's poll() on it is always ready and libusb polls REAPURBNDELAY in a loop instead of
sleeping (thousands of reaps during a timeout); permission denied cannot come from
umockdev itself when running as root, so the mock drops CAP_DAC_OVERRIDE from the child
and makes the node mode 000 (the open() then really fails with EACCES).

The image downloaded by default is made here from some bytes; FLASH_USB_IMAGE names
another .dfu (for example build/arm/display-board.dfu).
"""
import ctypes
import json
import os
import shutil
import subprocess
import zlib
from pathlib import Path

import pytest

from conftest import BUILD, ROOT

MOCK = ROOT / "tests" / "usbdfu_mock.py"
SYS_PY = "/usr/bin/python3"
FLASH = BUILD / "flash"
LIB = BUILD / "libdfudev.so"
SLOT_SIZE, PAGE = 4_128_768, 4096


def have_gi():
    if not Path(SYS_PY).exists():
        return False
    probe = "import gi; gi.require_version('UMockdev', '1.0'); from gi.repository import UMockdev"
    return subprocess.run([SYS_PY, "-c", probe], capture_output=True).returncode == 0


pytestmark = [
    pytest.mark.skipif(shutil.which("umockdev-wrapper") is None,
                       reason="umockdev-wrapper is missing (Debian package umockdev; tools/deps.sh)"),
    pytest.mark.skipif(not have_gi(), reason="/usr/bin/python3 cannot import gi's UMockdev "
                       "(Debian packages python3-gi, gir1.2-umockdev-1.0; tools/deps.sh)"),
]


@pytest.fixture(scope="module", autouse=True)
def built():
    for p in (FLASH, LIB):
        if not p.exists():
            pytest.fail(f"{p} is missing: run make first")


def run_mock(scenario, flash_args, *mock_args, out=None, timeout=120):
    cmd = ["umockdev-wrapper", SYS_PY, str(MOCK), scenario, *map(str, mock_args)]
    if out:
        cmd += ["--out", str(out)]
    cmd += ["--", str(FLASH), *map(str, flash_args)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout.strip().splitlines()[-1])
    assert summary["unhandled_ioctls"] == [], summary["unhandled_ioctls"]
    return summary


def make_dfu(tmp_path, data, vid="1209", pid="0001", name="fw"):
    src = tmp_path / f"{name}.bin"
    src.write_bytes(data)
    dst = tmp_path / f"{name}.dfu"
    subprocess.run([str(FLASH), "--add-suffix", src, "--vid", vid, "--pid", pid, "-o", dst],
                   check=True, capture_output=True)
    return dst


def payload_of(dfu):
    blob = dfu.read_bytes()
    return blob[:len(blob) - blob[-5]]          # bLength: the suffix's own length


@pytest.fixture
def image(tmp_path):
    given = os.environ.get("FLASH_USB_IMAGE")
    if given:
        return Path(given)
    return make_dfu(tmp_path, os.urandom(50_000) + b"bspvga")


# ---- the state machine's verdict on a dumped region, through ctypes ----------------------

def app_check(region, page=PAGE):
    """dfu_app_check() of firmware/dfu on a region: (valid, length, crc)."""
    lib = ctypes.CDLL(str(LIB))
    mem = ctypes.create_string_buffer(bytes(region), len(region))
    read_fn = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint32, ctypes.c_void_p,
                               ctypes.c_uint32)
    other_fn = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint32)
    prog_fn = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint32, ctypes.c_void_p,
                               ctypes.c_uint32)

    def read(_ctx, off, dst, n):
        if off + n > len(region):
            return -1
        ctypes.memmove(dst, ctypes.addressof(mem) + off, n)
        return 0

    class Flash(ctypes.Structure):
        _fields_ = [("ctx", ctypes.c_void_p), ("size", ctypes.c_uint32),
                    ("page_size", ctypes.c_uint32), ("erase", other_fn), ("program", prog_fn),
                    ("read", read_fn)]

    class Info(ctypes.Structure):
        _fields_ = [("length", ctypes.c_uint32), ("crc", ctypes.c_uint32)]

    cbs = (other_fn(lambda c, o: -1), prog_fn(lambda c, o, s, n: -1), read_fn(read))
    fl = Flash(None, len(region), page, *cbs)
    info = Info()
    lib.dfu_app_check.argtypes = [ctypes.POINTER(Flash), ctypes.POINTER(Info)]
    valid = lib.dfu_app_check(ctypes.byref(fl), ctypes.byref(info))
    return bool(valid), info.length, info.crc


# ---- tests ---------------------------------------------------------------------------------

def test_list_sees_the_emulated_device():
    s = run_mock("ok", ["--list"], "--serials", "BOARD-7")
    assert s["exit"] == 0, s["stderr"]
    assert "1209:0001" in s["stdout"] and "DFU mode" in s["stdout"]
    assert "serial BOARD-7" in s["stdout"]          # read with GET_DESCRIPTOR through a URB


def test_download_manifest_reenumerate(tmp_path, image):
    region = tmp_path / "region.bin"
    s = run_mock("ok", [image, "--device", "1209:0001", "-v"], out=region)
    assert s["exit"] == 0, s["stderr"]
    assert "the device verified the image and marked it valid" in s["stdout"]
    assert "re-enumerated and runs the new firmware (appIDLE)" in s["stdout"]
    dev = s["devices"][0]
    # dfuERROR (no firmware yet) -> CLRSTATUS -> blocks -> manifestation -> reset -> app
    assert dev["states_seen"][0] == "dfuERROR" and dev["states_seen"][-1] == "appIDLE"
    for st in ("dfuIDLE", "dfuDNBUSY", "dfuDNLOAD-IDLE", "dfuMANIFEST", "dfuIDLE"):
        assert st in dev["states_seen"]
    assert dev["resets"] == 1 and dev["enumerations"] == 2   # it left and came back
    assert s["ioctls"]["RESET"] == 1
    payload = payload_of(image)
    blocks = (len(payload) + 4095) // 4096
    assert dev["requests"]["DNLOAD"] == blocks + 1           # + the zero-length one
    mem = region.read_bytes()
    assert len(mem) == SLOT_SIZE
    assert mem[:len(payload)] == payload
    assert mem[len(payload):SLOT_SIZE - PAGE] == b"\xff" * (SLOT_SIZE - PAGE - len(payload))
    valid, length, crc = app_check(mem)
    assert valid and length == len(payload) and crc == zlib.crc32(payload)
    assert dev["app_valid"] and dev["app_crc"] == zlib.crc32(payload)


def test_device_vanishes_mid_transfer(tmp_path, image):
    region = tmp_path / "region.bin"
    s = run_mock("vanish", [image, "--device", "1209:0001", "--reenum-timeout", 1000],
                 "--block", 2, out=region)
    assert s["exit"] == 4, s["stderr"]
    assert "the device vanished" in s["stderr"] and "during DNLOAD of block 3" in s["stderr"]
    assert "No firmware was marked valid" in s["stderr"]
    dev = s["devices"][0]
    assert dev["blocks_written"] == 2
    assert app_check(region.read_bytes())[0] is False


def test_stall_on_dnload(tmp_path):
    # a 64 KiB device (60 KiB for the application): the state machine stalls the first
    # block past its end (errADDRESS); DFU 1.1 has no way to tell the host beforehand
    dfu = make_dfu(tmp_path, os.urandom(100_000))
    s = run_mock("stall", [dfu, "--device", "1209:0001"], "--region-size", 65536)
    assert s["exit"] == 4, s["stderr"]
    assert "errADDRESS" in s["stderr"] and "refused block 16 of 25" in s["stderr"]
    assert "sent CLRSTATUS" in s["stderr"]
    dev = s["devices"][0]
    assert dev["stalls"] == 1 and "dfuERROR" in dev["states_seen"][1:]
    assert dev["app_valid"] is False


def test_errwrite(tmp_path, image):
    region = tmp_path / "region.bin"
    s = run_mock("errwrite", [image, "--device", "1209:0001"], "--block", 3, out=region)
    assert s["exit"] == 4, s["stderr"]
    assert "errWRITE" in s["stderr"] and "while writing block 4" in s["stderr"]
    assert s["devices"][0]["state"] == "dfuIDLE"            # CLRSTATUS brought it back
    assert app_check(region.read_bytes())[0] is False


def test_timeout(image):
    s = run_mock("timeout", [image, "--device", "1209:0001", "--timeout", 300], "--block", 3)
    assert s["exit"] == 4, s["stderr"]
    assert "did not answer within 300 ms during DNLOAD of block 4" in s["stderr"]
    assert "a longer --timeout may help" in s["stderr"]
    assert s["ioctls"].get("DISCARDURB", 0) >= 1           # libusb cancelled the URB
    assert s["devices"][0]["app_valid"] is False


def test_permission_denied(image):
    s = run_mock("denied", [image, "--device", "1209:0001"])
    assert s["exit"] == 3, s["stderr"]
    assert "permission denied opening 1209:0001" in s["stderr"] and "udev rule" in s["stderr"]
    assert s["devices"][0]["requests"]["DNLOAD"] == 0


def test_several_devices_serial_chooses(tmp_path, image):
    s = run_mock("ok", [image, "--device", "1209:0001", "--serial", "B2"], "--serials", "A1,B2")
    assert s["exit"] == 0, s["stderr"]
    a, b = s["devices"]
    assert a["requests"]["DNLOAD"] == 0 and not a["app_valid"]
    assert b["app_valid"] and b["app_crc"] == zlib.crc32(payload_of(image))


def test_several_devices_without_serial(image):
    s = run_mock("ok", [image, "--device", "1209:0001"], "--serials", "A1,B2")
    assert s["exit"] == 3, s["stderr"]
    assert "2 devices match 1209:0001; choose one with --serial" in s["stderr"]
    assert "A1" in s["stderr"] and "B2" in s["stderr"]
    assert all(d["requests"]["DNLOAD"] == 0 for d in s["devices"])


def test_image_for_another_device(tmp_path):
    dfu = make_dfu(tmp_path, os.urandom(20_000), vid="1234", pid="5678")
    s = run_mock("ok", [dfu, "--device", "1209:0001"])
    assert s["exit"] == 2, s["stderr"]
    assert "the image is for 1234:5678" in s["stderr"] and "nothing was sent" in s["stderr"]
    assert s["ioctls"].get("SUBMITURB", 0) == 0


def test_absent_device(tmp_path):
    dfu = make_dfu(tmp_path, os.urandom(20_000), vid="1209", pid="00ff")
    s = run_mock("ok", [dfu, "--device", "1209:00ff"])
    assert s["exit"] == 3, s["stderr"]
    assert "no device found for 1209:00ff" in s["stderr"]
    assert "1209:0001" in s["stderr"]              # the attached DFU device is named


def manifestation_tail(tolerant):
    """The states a DFU 1.1 device goes through from the last block on (section 7): a
    manifestation-tolerant one comes back to dfuIDLE, another waits for the reset; either
    way the reset boots the new firmware."""
    after = "dfuIDLE" if tolerant else "dfuMANIFEST-WAIT-RESET"
    return ["dfuDNLOAD-IDLE", "dfuMANIFEST-SYNC", "dfuMANIFEST", after, "appIDLE"]


@pytest.mark.parametrize("tolerant", [True, False])
def test_manifestation_writes_the_mark_last(tmp_path, tolerant):
    """Manifestation end to end: the states the device goes through, the bwPollTimeout it asks
    for and the host waits out, and the order of the flash writes: the old mark erased before
    any application page, every image byte programmed once in order, then the 16-byte mark in
    the last page as the very last write."""
    payload = os.urandom(3 * PAGE + 1234)
    dfu = make_dfu(tmp_path, payload)
    region = tmp_path / "region.bin"
    extra = [] if tolerant else ["--not-tolerant"]
    s = run_mock("ok", [dfu, "--device", "1209:0001", "-v"], *extra, out=region)
    assert s["exit"] == 0, s["stderr"]
    dev = s["devices"][0]
    assert dev["manifest_tolerant"] is tolerant
    assert ("device is manifestation-tolerant" in s["stderr"]) is tolerant
    assert "the device verified the image and marked it valid" in s["stdout"]
    assert "runs the new firmware (appIDLE)" in s["stdout"]
    assert dev["states_seen"][-5:] == manifestation_tail(tolerant), dev["states_seen"]
    assert dev["resets"] == 1 and dev["stalls"] == 0

    # GETSTATUS in dfuMANIFEST asks for the manifestation time; the host asks again only after it
    gs = dev["getstatus"]
    at = [i for i, (_, state, _) in enumerate(gs) if state == "dfuMANIFEST"]
    assert len(at) == 1, gs
    t, _, poll = gs[at[0]]
    assert poll == dev["manifest_ms"]
    t_next, state_next, poll_next = gs[at[0] + 1]
    assert state_next == manifestation_tail(tolerant)[3] and poll_next == 0
    assert t_next - t >= poll

    # the writes: mark erased first, the image in order, the mark last
    mark = SLOT_SIZE - PAGE
    log = dev["flash_log"]
    assert log[0] == ["erase", mark], log[:3]
    assert log[-1] == ["program", mark, 16], log[-3:]
    assert [e for e in log if e[0] == "program" and e[1] >= mark] == [["program", mark, 16]]
    pages = (len(payload) + PAGE - 1) // PAGE
    assert [e[1] for e in log if e[0] == "erase"] == [mark] + [k * PAGE for k in range(pages)]
    end = 0
    for e in log[1:-1]:
        if e[0] == "program":
            assert e[1] == end, (e, end)
            end += e[2]
    assert end == len(payload)
    mem = region.read_bytes()
    assert mem[:len(payload)] == payload
    valid, length, crc = app_check(mem)
    assert valid and length == len(payload) and crc == zlib.crc32(payload)
