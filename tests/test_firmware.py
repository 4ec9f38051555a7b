"""The Cortex-M3 firmware (hal/mps2) under QEMU's mps2-an385: it runs its camera path and
exits 0 through semihosting, streams frames the host renders bit for bit alike, refuses a
damaged built-in scene or too small a work area with a message on the UART and a non-zero
exit status, reports faults, and the instruction-counting plugin gives per-frame counts.
The largest Freedoom map builds within the board's 200,000 bytes of RAM, with its scene left
in flash, and renders what build/render renders; a build that does not fit is refused at
build time with the RAM it needs.

Builds go through make (mk/mps2.mk); variants go to their own ARM_OUT folders under build/.
"""
import json
import os
import re
import select
import shutil
import struct
import subprocess
import sys
import zlib

import pytest

from conftest import BUILD, ROOT
from linkrig import Firmware

sys.path.insert(0, str(ROOT / "tools"))
from armelf import symbol, symbols  # noqa: E402
from fxtext import fx_text  # noqa: E402

QEMU = shutil.which("qemu-system-arm")
TIMEOUT = 60
pytestmark = pytest.mark.skipif(QEMU is None, reason="qemu-system-arm missing: run make deps")

EXIT_SCENE, EXIT_FAULT, EXIT_WORK = 2, 3, 4


def make(*args, ok=True):
    proc = subprocess.run(["make", "-s", "-j2", "--no-print-directory", *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    if ok:
        assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc


def build(arm_out=None, *extra):
    out = BUILD / "arm" if arm_out is None else arm_out
    make("firmware", f"ARM_OUT={out}", *extra)
    return out / "firmware.elf"


def qemu(elf, uart, args="", plugin=None, timeout=TIMEOUT):
    """Run the firmware; UART0 to the file uart. Returns (exit status, semihosting text, UART bytes)."""
    cmd = [QEMU, "-M", "mps2-an385", "-nographic", "-monitor", "none",
           "-semihosting-config", "enable=on,target=native", "-kernel", str(elf),
           "-serial", f"file:{uart}"]
    if args:
        cmd += ["-append", args]
    if plugin:
        cmd += ["-plugin", plugin]
    proc = subprocess.run(cmd, capture_output=True, timeout=timeout)
    return proc.returncode, proc.stderr.decode(errors="replace"), uart.read_bytes()


def raw_frames(data):
    """Frames of hal/mps2/stream.c's raw encoding: [(info dict, pixels)], the palette."""
    i = data.index(b"RAWP")
    palette = data[i + 4:i + 4 + 768]
    frames, pos = [], i + 4 + 768
    while (j := data.find(b"RAWF", pos)) >= 0:
        f, x, y, z, a, look, mode, present, crc, t = struct.unpack("<IiiiiiBBxxII", data[j + 4:j + 40])
        pixels = data[j + 40:j + 40 + 64000]
        assert len(pixels) == 64000
        frames.append((dict(frame=f, x=x, y=y, z=z, angle=a, look=look, mode=mode, present=present, crc32=crc,
                            time_ms=t), pixels))
        pos = j + 40 + 64000
    end = data.find(b"RAWE", pos)
    assert end >= 0, "no end record"
    assert struct.unpack("<I", data[end + 4:end + 8])[0] == len(frames)
    return frames, palette


@pytest.fixture(scope="module")
def firmware():
    """What `make firmware` builds (build/arm/firmware.elf)."""
    return build()


@pytest.fixture(scope="module")
def raw_firmware():
    """The default scene and path with the raw stream encoding, which these tests read directly."""
    return build(BUILD / "firmware-test" / "arm-raw", "STREAM=raw")


def test_make_firmware_runs_and_exits_0(firmware, tmp_path):
    """`make firmware`'s image runs its whole camera path, streaming, and exits 0 in time."""
    status, log, uart = qemu(firmware, tmp_path / "uart.bin")
    assert status == 0, log
    assert "firmware: done, 204 frames" in log
    assert len(uart) > 204 * 100
    if "stream framelink" not in log:
        return
    # The frame link: the C decoder shows every frame, each checked against its CRC-32.
    fltool = BUILD / "fltool"
    if not fltool.exists():
        pytest.skip("build/fltool (the frame link's host tool) is not built")
    shown = tmp_path / "shown.bin"
    proc = subprocess.run([str(fltool), "decode", str(tmp_path / "uart.bin"), "--frames-out", str(shown)],
                          capture_output=True, text=True, check=True)
    events = [json.loads(line) for line in proc.stdout.splitlines()]
    counters = events[-1]["counters"]
    assert counters["frames_shown"] == 204 and counters["msgs_bad"] == 0, counters
    frames = [e for e in events if e.get("event") == "frame"]
    assert [e["frame"] for e in frames] == list(range(204))
    data = shown.read_bytes()
    for i, e in enumerate(frames):
        assert f"{zlib.crc32(data[i * 64000:(i + 1) * 64000]):08x}" == e["info"]["crc32"]


def test_frames_stream_and_match_the_host_renderer(raw_firmware, tmp_path):
    """Each frame goes over the UART with its information, and every target renders the same
    frame from the same camera: build/render, given the camera the firmware reports, gives
    the same CRC-32."""
    status, log, uart = qemu(raw_firmware, tmp_path / "uart.bin", "--frames 100")
    assert status == 0, log
    assert "firmware: done, 100 frames" in log
    frames, palette = raw_frames(uart)
    assert [info["frame"] for info, _ in frames] == list(range(100))
    assert len(set(palette)) > 16
    for info, pixels in frames:
        assert zlib.crc32(pixels) == info["crc32"]
        assert (info["mode"], info["present"]) == (3, 0)  # columns (render.h: RENDER_COLUMNS), flip
    assert frames[0][0]["crc32"] == frames[1][0]["crc32"]  # the path starts standing still
    assert len({info["crc32"] for info, _ in frames}) > 90  # then moves
    # the messages also go to the UART, as text outside the frames
    assert uart.startswith(b"firmware: mps2-an385 Cortex-M3")
    for info, _ in frames[::11]:
        cam = [fx_text(info["x"]), fx_text(info["y"]), fx_text(info["z"])]
        proc = subprocess.run([str(BUILD / "render"), str(BUILD / "default.bsc"), "--at", ",".join(cam),
                               "--angle", fx_text(info["angle"]), "--look", str(info["look"]),
                               "--time", str(info["time_ms"])],
                              capture_output=True, text=True, check=True)
        assert int(json.loads(proc.stdout)["crc32"], 16) == info["crc32"], info


def test_fixed_view_and_present_modes(raw_firmware, tmp_path):
    """Run-time options: a fixed view renders the same frame as build/render there, in every present mode."""
    ref = json.loads(subprocess.run([str(BUILD / "render"), str(BUILD / "default.bsc"), "--at", "700.5,120",
                                     "--angle", "33.25", "--look", "-20"],
                                    capture_output=True, text=True, check=True).stdout)
    for present in ("flip", "copy8", "copy32"):
        status, log, uart = qemu(raw_firmware, tmp_path / f"{present}.bin",
                                 f"--at 700.5,120 --angle 33.25 --look -20 --frames 2 --present {present}")
        assert status == 0, log
        frames, _ = raw_frames(uart)
        assert [info["crc32"] for info, _ in frames] == [int(ref["crc32"], 16)] * 2
        assert [info["present"] for info, _ in frames] == [["flip", "copy8", "copy16", "copy32"].index(present)] * 2


def test_damaged_scene_is_refused(tmp_path):
    """A firmware built around a damaged blob exits non-zero with a clear message on the UART."""
    work = BUILD / "firmware-test"
    work.mkdir(parents=True, exist_ok=True)
    blob = bytearray((BUILD / "default.bsc").read_bytes())
    blob[len(blob) // 2] ^= 0x5A
    (work / "damaged.bsc").write_bytes(bytes(blob))
    elf = build(work / "arm-damaged", f"SCENE={work / 'damaged.bsc'}", "STREAM=raw")
    status, log, uart = qemu(elf, tmp_path / "uart.bin")
    assert status == EXIT_SCENE, log
    text = uart.decode(errors="replace")
    assert "is invalid: bad CRC-32; refusing to run" in text, text
    assert "RAWF" not in text


def test_too_little_work_memory_is_refused(tmp_path):
    elf = build(BUILD / "firmware-test" / "arm-small", "WORK_BYTES=4096", "STREAM=raw")
    status, log, uart = qemu(elf, tmp_path / "uart.bin")
    assert status == EXIT_WORK, log
    text = uart.decode(errors="replace")
    assert "bytes of work memory; this build has 4096" in text, text


def test_fault_is_reported(firmware, tmp_path):
    status, log, uart = qemu(firmware, tmp_path / "uart.bin", "--fault")
    assert status == EXIT_FAULT, log
    text = uart.decode(errors="replace")
    assert "FAULT: UsageFault: pc=0x" in text and "cfsr=0x00010000" in text, text  # UNDEFINSTR


def test_bad_option_is_refused(firmware, tmp_path):
    status, log, uart = qemu(firmware, tmp_path / "uart.bin", "--frames many")
    assert status == 5 and "--frames 'many'" in uart.decode(errors="replace")


def test_instruction_counts_per_frame(firmware, tmp_path):
    """The plugin counts guest instructions between the firmware's frame markers."""
    make("insn-plugin")
    begin, end = symbol(firmware, "fw_mark_frame_begin"), symbol(firmware, "fw_mark_frame_end")
    out = tmp_path / "insns.txt"
    plugin = f"{BUILD / 'insn_count.so'},begin={begin:#x},end={end:#x},out={out}"
    # the path's first 12 frames (2 standing, 7 turning, 3 walking), without the tick
    status, log, _ = qemu(firmware, tmp_path / "uart.bin", "--frames 12 --no-tick --no-stream", plugin)
    assert status == 0, log
    rows = [list(map(int, line.split())) for line in out.read_text().splitlines() if not line.startswith("#")]
    assert [r[0] for r in rows] == list(range(12))
    render = [r[1] for r in rows]
    assert all(100_000 < n < 20_000_000 for n in render), render
    assert render[0] == render[1]  # the same frame twice: the same count
    assert all(r[2] >= r[1] for r in rows)
    # a fixed view: every frame identical, to the instruction
    out.unlink()
    status, log, _ = qemu(firmware, tmp_path / "uart.bin", "--at 300,150 --angle 10 --frames 4 --no-tick", plugin)
    assert status == 0, log
    rows = [list(map(int, line.split())) for line in out.read_text().splitlines() if not line.startswith("#")]
    assert len(rows) == 4 and len({r[1] for r in rows}) == 1, rows
    # streaming costs instructions outside the render markers
    assert all(r[2] > r[1] + 64000 for r in rows[:-1]), rows


def test_pty_started_paused_loses_nothing(raw_firmware, tmp_path):
    """On a pty QEMU drops what the guest writes while no reader has it open: started paused
    (-S) and continued over QMP once the reader is there (tests/linkrig.py), every byte arrives."""
    fw = Firmware("pty", "--frames 3 --linger 1000", elf=raw_firmware, tmp=tmp_path)
    try:
        fd = os.open(fw.port, os.O_RDWR | os.O_NOCTTY)
        import tty
        tty.setraw(fd)
        fw.start()
        data = b""
        while True:
            ready, _, _ = select.select([fd], [], [], 3)
            if not ready:
                break
            try:
                chunk = os.read(fd, 65536)
            except OSError:  # QEMU closed the pty
                break
            if not chunk:
                break
            data += chunk
        assert fw.wait(timeout=TIMEOUT) == 0
    finally:
        fw.kill()
    assert data.startswith(b"firmware: mps2-an385")
    frames, _ = raw_frames(data)
    assert len(frames) == 3 and all(zlib.crc32(p) == info["crc32"] for info, p in frames)


BOARD_RAM = 200_000  # the goal: all of the firmware's RAM on a small microcontroller
ROM_END = 0x400000   # hal/mps2/mps2.ld: flash is the first 4 MB
REFUSAL = re.compile(r"^firmware: (\S+) needs ([0-9,]+) bytes of RAM \(stack ([0-9,]+), VRAM pages and palette "
                     r"([0-9,]+), data and bss ([0-9,]+), work area ([0-9,]+)\); the board has ([0-9,]+) \(RAM_BYTES\)$")


def number(text):
    return int(text.replace(",", ""))


def ram_parts(elf):
    """The image's RAM from its symbols (hal/mps2/mps2.ld): the total and its parts."""
    a = {k: v[0] for k, v in symbols(elf).items()}
    return dict(need=a["__ram_need"], stack=a["__stack_top"] - a["__stack_limit"],
                display=a["__display_end"] - a["mps2_vram0"], data_bss=a["__work_start"] - a["__display_end"],
                work=a["__work_end"] - a["__work_start"], origin=a["__stack_limit"])


def test_build_that_does_not_fit_is_refused():
    """RAM_BYTES lowered below what the default scene's firmware needs: make fails with one line
    giving the RAM it needs and its parts, and no image. That figure is exact: with RAM_BYTES set
    to it the build links (and runs), 8 bytes fewer and it is refused again."""
    out = BUILD / "firmware-test" / "arm-tight"
    shutil.rmtree(out, ignore_errors=True)
    proc = make("firmware", f"ARM_OUT={out}", "STREAM=raw", "RAM_BYTES=140000", ok=False)
    assert proc.returncode != 0
    lines = [ln for ln in (proc.stdout + proc.stderr).splitlines() if ln.startswith("firmware:")]
    assert len(lines) == 1, proc.stdout + proc.stderr
    m = REFUSAL.match(lines[0])
    assert m, lines[0]
    assert m.group(1) == "tests/scenes/default.scene" and m.group(7) == "140,000"
    need, parts = number(m.group(2)), [number(g) for g in m.group(3, 4, 5, 6)]
    assert need == sum(parts) and need > 140_000, lines[0]
    assert number(m.group(4)) == 2 * 64000 + 768 + 4
    assert not (out / "firmware.elf").exists()
    assert "region" not in proc.stdout + proc.stderr  # the linker's own words are not shown

    elf = build(out, "STREAM=raw", f"RAM_BYTES={need}")
    ram = ram_parts(elf)
    assert ram["need"] == need and [ram["stack"], ram["display"], ram["data_bss"], ram["work"]] == parts
    status, log, _ = qemu(elf, out / "uart.bin", "--frames 2")
    assert status == 0, log
    proc = make("firmware", f"ARM_OUT={out}", "STREAM=raw", f"RAM_BYTES={need - 8}", ok=False)
    assert proc.returncode != 0 and f"needs {need:,} bytes of RAM" in proc.stdout + proc.stderr
    assert not elf.exists()  # the image that fitted before is gone


def test_map12_fits_in_200000_bytes_and_matches_the_host_renderer(tmp_path):
    """freedoom2.wad:MAP12, the largest Freedoom map: `make firmware` links it with all of its RAM
    (stack, both pages, palette, data, bss, work area) within 200,000 bytes, the scene stays in
    flash (read in place: .data holds no copy of it), and a short run under QEMU along the camera
    path, in flip and in copy32 mode, streams frames bit-identical to build/render's from the same
    cameras, with a stack high-water mark well inside the stack."""
    out = BUILD / "firmware-test" / "arm-map12"
    proc = make("firmware", "SCENE=freedoom2.wad:MAP12", f"ARM_OUT={out}", "STREAM=raw", f"RAM_BYTES={BOARD_RAM}",
                ok=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    elf = out / "firmware.elf"
    ram = ram_parts(elf)
    assert ram["need"] <= BOARD_RAM and ram["origin"] == 0x20000000, ram
    blob = (out / "scene.bsc").read_bytes()
    addr, size = symbols(elf)["fw_scene"]
    assert size == len(blob) and addr + size <= ROM_END
    assert ram["data_bss"] < 32_768  # no room for a copy of the 1.3 MB scene
    for present, frames in (("flip", 8), ("copy32", 3)):
        status, log, uart = qemu(elf, tmp_path / f"{present}.bin", f"--frames {frames} --present {present}",
                                 timeout=300)
        assert status == 0, log
        mode = re.search(r"; mode (\w+), present", log).group(1)
        used, stack = map(int, re.search(r"stack used (\d+) of (\d+) bytes", log).groups())
        assert stack == ram["stack"] and used <= stack * 3 // 4, log
        shown, _ = raw_frames(uart)
        assert len(shown) == frames
        for info, pixels in shown:
            assert zlib.crc32(pixels) == info["crc32"]
            cam = [fx_text(info["x"]), fx_text(info["y"]), fx_text(info["z"])]
            ref = subprocess.run([str(BUILD / "render"), str(out / "scene.bsc"), "--at", ",".join(cam),
                                  "--angle", fx_text(info["angle"]), "--look", str(info["look"]), "--mode", mode,
                                  "--present", present, "--time", str(info["time_ms"])], capture_output=True,
                                 text=True, check=True)
            assert int(json.loads(ref.stdout)["crc32"], 16) == info["crc32"], (present, info)
