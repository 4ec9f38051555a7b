"""build/flash: the USB DFU flasher's command line.

--help, the DFU suffix written by --add-suffix (checked here independently, with
zlib), a download into the simulated device (--loopback) of the real Cortex-M
firmware when it has been built, images refused before anything is sent, an
interrupted download, and the libusb path with no device attached.
"""
import re
import shutil
import struct
import subprocess
import zlib

import pytest

from conftest import BUILD, ROOT, program, run

VIDPID = "1209:0001"


def flash(*args, check=False):
    return run([program("flash"), *args], check=check, timeout=120)


def firmware_bin(tmp_path):
    """The Cortex-M firmware's binary if it was built, else some real file."""
    elf = BUILD / "arm" / "firmware.elf"
    objcopy = shutil.which("arm-none-eabi-objcopy")
    out = tmp_path / "firmware.bin"
    if elf.exists() and objcopy:
        subprocess.run([objcopy, "-O", "binary", str(elf), str(out)], check=True)
    else:
        out.write_bytes((BUILD / "render").read_bytes()[:300_000])
    return out


def add_suffix(tmp_path, data, vid="1209", pid="0001", name="fw"):
    src = tmp_path / f"{name}.bin"
    src.write_bytes(data)
    dst = tmp_path / f"{name}.dfu"
    proc = flash("--add-suffix", src, "--vid", vid, "--pid", pid, "-o", dst, check=True)
    return dst, proc


def parse_suffix(blob):
    """The DFU 1.1 suffix, read independently of the C code."""
    bcd_device, pid, vid, bcd_dfu = struct.unpack("<HHHH", blob[-16:-8])
    sig, length, crc = blob[-8:-5], blob[-5], struct.unpack("<I", blob[-4:])[0]
    return dict(bcd_device=bcd_device, pid=pid, vid=vid, bcd_dfu=bcd_dfu, sig=sig, length=length, crc=crc)


def test_help():
    proc = flash("--help", check=True)
    text = proc.stdout
    for needle in ("--device VID:PID", "--serial", "--transfer-size", "--verbose", "--loopback",
                   "--add-suffix", "--vid", "--pid", "docs/flashing.md", "udev", "Exit status",
                   "without hardware", "bwPollTimeout"):
        assert needle.lower() in text.lower(), needle
    assert proc.stderr == ""
    assert max(len(line) for line in text.splitlines()) <= 100


def test_add_suffix_round_trip(tmp_path):
    data = bytes(range(256)) * 37 + b"tail"
    dst, proc = add_suffix(tmp_path, data, vid="0x1209", pid="beef")
    blob = dst.read_bytes()
    assert blob[:-16] == data and len(blob) == len(data) + 16
    s = parse_suffix(blob)
    assert (s["vid"], s["pid"], s["bcd_device"], s["bcd_dfu"]) == (0x1209, 0xBEEF, 0xFFFF, 0x0100)
    assert s["sig"] == b"UFD" and s["length"] == 16
    # DFU 1.1 appendix B: CRC-32 preset to all ones, no final inversion = ~zlib.crc32
    assert s["crc"] == zlib.crc32(blob[:-4]) ^ 0xFFFFFFFF
    assert "1209" in proc.stdout and "beef" in proc.stdout

    check = flash("--check", dst, check=True)
    assert f"{zlib.crc32(data):08x}" in check.stdout
    # matches its device, refuses another
    assert flash("--check", dst, "--device", "1209:beef").returncode == 0
    other = flash("--check", dst, "--device", "1209:0001")
    assert other.returncode == 2 and "another product id" in other.stderr
    # a second suffix is refused
    again = flash("--add-suffix", dst, "--vid", "1209", "--pid", "beef", "-o", tmp_path / "x.dfu")
    assert again.returncode == 2 and "already ends with a valid DFU suffix" in again.stderr
    # incomplete arguments
    assert flash("--add-suffix", tmp_path / "fw.bin", "-o", tmp_path / "y.dfu").returncode == 1
    assert flash("--add-suffix", tmp_path / "fw.bin", "--vid", "12345", "--pid", "1",
                 "-o", tmp_path / "y.dfu").returncode == 1


def test_loopback_download_of_the_firmware(tmp_path):
    binary = firmware_bin(tmp_path)
    data = binary.read_bytes()
    dfu, _ = add_suffix(tmp_path, data)
    proc = flash(dfu, "--loopback", "-v")
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert "the device verified the image and marked it valid" in out
    assert "runs the new firmware (appIDLE)" in out
    m = re.search(r"application valid: (\d+) bytes, CRC-32 0x([0-9a-f]{8})", out)
    assert m, out
    assert int(m.group(1)) == len(data)
    assert int(m.group(2), 16) == zlib.crc32(data)
    blocks = (len(data) + 4095) // 4096
    assert f"DNLOAD {blocks + 1}," in out          # the blocks and the empty one
    assert "0 stalls" in out
    # verbose: the steps and the progress on stderr
    assert "CLRSTATUS" in proc.stderr and "100%" in proc.stderr

    # smaller transfer size
    proc = flash(dfu, "--loopback", "--transfer-size", "64")
    assert proc.returncode == 0, proc.stderr
    assert f"DNLOAD {(len(data) + 63) // 64 + 1}," in proc.stdout
    # larger than the device takes: refused, nothing sent
    proc = flash(dfu, "--loopback", "--transfer-size", "8192")
    assert proc.returncode == 1 and "wTransferSize 4096" in proc.stderr


@pytest.mark.parametrize("damage", ["bitflip", "crc", "truncated", "signature", "empty", "tiny"])
def test_damaged_image_rejected(tmp_path, damage):
    data = bytes((i * 7 + 3) & 0xFF for i in range(10_000))
    dfu, _ = add_suffix(tmp_path, data)
    blob = bytearray(dfu.read_bytes())
    expect = {"bitflip": "CRC mismatch", "crc": "CRC mismatch", "truncated": "truncated",
              "signature": "no DFU suffix", "empty": "too short", "tiny": "too short"}[damage]
    if damage == "bitflip":
        blob[1234] ^= 0x10
    elif damage == "crc":
        blob[-1] ^= 0x80
    elif damage == "truncated":
        blob = blob[:7000]
    elif damage == "signature":
        blob[-7] = ord("X")
    elif damage == "empty":
        blob = b""
    else:
        blob = blob[-10:]
    bad = tmp_path / f"bad-{damage}.dfu"
    bad.write_bytes(bytes(blob))
    for mode in (["--loopback"], ["--device", VIDPID]):
        proc = flash(bad, *mode)
        assert proc.returncode == 2, proc.stderr
        assert str(bad) in proc.stderr and expect in proc.stderr, proc.stderr
        assert "nothing was sent" in proc.stderr
        assert "loopback:" not in proc.stdout      # the simulated device was never touched


def test_wrong_device_rejected(tmp_path):
    dfu, _ = add_suffix(tmp_path, b"\x01" * 1000, vid="1209", pid="0002")
    proc = flash(dfu, "--loopback", "--device", VIDPID)
    assert proc.returncode == 2
    assert "made for another product id" in proc.stderr and "1209:0002" in proc.stderr


def test_interrupted_download_leaves_bootloader(tmp_path):
    dfu, _ = add_suffix(tmp_path, bytes(range(256)) * 200)
    proc = flash(dfu, "--loopback", "--loopback-unplug-after", "25")
    assert proc.returncode == 4
    assert "vanished" in proc.stderr and "stays in its bootloader" in proc.stderr
    assert "no valid application: the device stays in its bootloader" in proc.stdout
    assert "dfuERROR (errFIRMWARE)" in proc.stdout


def test_libusb_no_device(tmp_path):
    """Through libusb with the device absent (here: no USB at all): a clear message."""
    dfu, _ = add_suffix(tmp_path, b"\xAA" * 4096, vid="1209", pid="0001")
    proc = flash(dfu, "--device", VIDPID)
    assert proc.returncode == 3, proc.stderr
    assert f"no device found for {VIDPID}" in proc.stderr
    assert "ERROR: AddressSanitizer" not in proc.stderr and "runtime error" not in proc.stderr
    listing = flash("--list")
    assert listing.returncode in (0, 3)
    assert "DFU devices" in listing.stdout


@pytest.mark.parametrize("args", [[], ["--device"], ["x.dfu", "--device", "12:xyz"],
                                  ["x.dfu", "--loopback", "--transfer-size", "0"],
                                  ["x.dfu"], ["a.dfu", "b.dfu", "--loopback"], ["--bogus"]])
def test_usage_errors(args):
    proc = flash(*args)
    assert proc.returncode == 1, (args, proc.stderr)
    assert proc.stderr.startswith("flash: ")


def test_missing_file(tmp_path):
    proc = flash(tmp_path / "nope.dfu", "--loopback")
    assert proc.returncode == 2
    assert "nope.dfu: cannot open" in proc.stderr


@pytest.mark.parametrize("size", [1, 4096, 10_000])
def test_unplug_verdict_follows_the_device(tmp_path, size):
    """Unplugged after every possible request: the exit status and the message follow
    what the device holds when plugged in again, never a guess about it."""
    data = bytes((i * 13 + 5) & 0xFF for i in range(size))
    dfu, _ = add_suffix(tmp_path, data)
    total = int(re.search(r"loopback: (\d+) requests", flash(dfu, "--loopback").stdout).group(1))
    seen_valid = 0
    for n in range(1, total + 1):
        proc = flash(dfu, "--loopback", "--loopback-unplug-after", str(n))
        m = re.search(r"application valid: (\d+) bytes, CRC-32 0x([0-9a-f]{8})", proc.stdout)
        holds = bool(m) and int(m.group(1)) == size and int(m.group(2), 16) == zlib.crc32(data)
        assert holds or "no valid application" in proc.stdout, (n, proc.stdout)
        if holds:
            seen_valid += 1
            assert proc.returncode == 0, (n, proc.stdout, proc.stderr)
            assert "No firmware was marked valid" not in proc.stderr, (n, proc.stderr)
        else:
            assert proc.returncode == 4, (n, proc.stdout, proc.stderr)
            assert "dfuERROR (errFIRMWARE)" in proc.stdout
    assert seen_valid >= 2   # unplugged during manifestation, and during the final reset


@pytest.mark.parametrize("blength", [15, 17, 255])
def test_suffix_length_must_be_16(tmp_path, blength):
    """A bLength other than 16, with the CRC made right, is refused: it would take
    firmware bytes for suffix."""
    dfu, _ = add_suffix(tmp_path, bytes(range(256)) * 4)
    blob = bytearray(dfu.read_bytes())
    blob[-5] = blength
    blob[-4:] = struct.pack("<I", zlib.crc32(bytes(blob[:-4])) ^ 0xFFFFFFFF)
    bad = tmp_path / "blength.dfu"
    bad.write_bytes(bytes(blob))
    for args in (["--check", bad], [bad, "--loopback"]):
        proc = flash(*args)
        assert proc.returncode == 2, (args, proc.stdout, proc.stderr)
        assert f"bLength {blength}" in proc.stderr and "not 16" in proc.stderr, proc.stderr
        assert "loopback:" not in proc.stdout


def test_loopback_is_the_projects_device(tmp_path):
    """The simulated device is 1209:0001 whatever the image says: a suffix for another
    VID:PID is refused without --device too, and --device naming another finds nothing."""
    dfu, _ = add_suffix(tmp_path, b"\x02" * 1000, vid="1234", pid="5678")
    proc = flash(dfu, "--loopback")
    assert proc.returncode == 2, (proc.stdout, proc.stderr)
    assert "another vendor id" in proc.stderr and "1234:5678" in proc.stderr
    assert "nothing was sent" in proc.stderr and "loopback:" not in proc.stdout
    anyid, _ = add_suffix(tmp_path, b"\x03" * 1000, vid="ffff", pid="ffff", name="any")
    proc = flash(anyid, "--loopback")
    assert proc.returncode == 0, proc.stderr
    assert "simulated DFU device 1209:0001" in proc.stdout
    proc = flash(anyid, "--loopback", "--device", "1234:5678")
    assert proc.returncode == 3 and "no device found for 1234:5678" in proc.stderr


def board_slot():
    """The display board's application slot and page (hal/board/board_layout.h)."""
    text = (ROOT / "hal" / "board" / "board_layout.h").read_text()
    num = lambda name: int(re.search(rf"#define {name} (0x[0-9A-Fa-f]+|\d+)u", text).group(1), 0)
    return num("BOARD_SLOT_BYTES"), num("BOARD_PAGE_BYTES")


def test_oversized_image_refused_before_anything_is_sent(tmp_path):
    """An image past the device's application area (the board's slot less its mark page:
    4,124,672 bytes on the loopback, as on the board) is refused before the first request,
    so an old valid mark is never erased."""
    slot, page = board_slot()
    cap = slot - page
    dfu, _ = add_suffix(tmp_path, b"\x5A" * (cap + 1))
    proc = flash(dfu, "--loopback")
    assert proc.returncode == 2, (proc.stdout, proc.stderr)
    assert f"{cap + 1} bytes of firmware do not fit" in proc.stderr and f"{cap} bytes" in proc.stderr
    assert "loopback: 0 requests" in proc.stdout
    fits, _ = add_suffix(tmp_path, b"\x5A" * cap, name="fits")
    assert flash(fits, "--loopback").returncode == 0


def test_loopback_and_board_image_agree_on_the_largest_image(tmp_path):
    """The largest image the loopback takes is the largest the board's slot holds: board_image (which
    assembles the board's flash through the same DFU device) takes it and refuses one byte more,
    as the loopback does."""
    slot, page = board_slot()
    cap = slot - page
    boot = tmp_path / "boot.bin"
    boot.write_bytes(b"\x01" * 256)
    for size, ok in ((cap, True), (cap + 1, False)):
        app = tmp_path / f"app{size}.bin"
        app.write_bytes(bytes((i * 7 + 1) & 0xFF for i in range(size)))
        img = run([program("board_image", sanitized=False), boot, app, tmp_path / f"img{size}.bin"], check=False,
                  timeout=120)
        assert (img.returncode == 0) == ok, (size, img.stderr)
        dfu, _ = add_suffix(tmp_path, app.read_bytes(), name=f"app{size}")
        lb = flash(dfu, "--loopback")
        assert (lb.returncode == 0) == ok, (size, lb.stdout, lb.stderr)
