#!/usr/bin/env python3
"""pcvga.py - run the PC kernel (hal/pcvga) under qemu-system-i386 and take its screen.

    python tools/pcvga.py shot KERNEL [--args "--at 700.5,120 --present copy32"]
                              [--scene SCENE.bsc] [-o shot.png] [--json out.json]
    python tools/pcvga.py bench KERNEL --scene SCENE.bsc [--frames N] [-o table.md]

boots KERNEL headless (-display none) with COM1 on a pipe and QMP on a unix socket,
runs it with --wait added to its options, takes the screen with QMP's screendump once
the kernel says it is waiting, sends it a byte, and reads its exit status. The
screendump is the VGA as QEMU displays it: mode 13h doubled to 640x400, each DAC
value (6 bits) widened to 8 by QEMU's expansion v << 2 | (v & 1) * 3. It is turned
back into 320x200 DAC values and, with --scene, compared with what build/render
draws from the camera of the last frame and in the same modes: the DAC values of every pixel, and the
palette indices wherever the scene's palette tells them apart at 6 bits. -o writes
the screendump as a PNG. Prints one JSON object.

bench runs the kernel's camera path in each present mode and prints the median write
counters per frame, beside build/render's linear page for the same frames (make bench-pcvga).

Library use (tests/test_pcvga.py): Kernel, dac_frame, indices, render_reference.
"""
import argparse
import json
import os
import re
import select
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from fxtext import fx_text
from refrender import write_png_rgb

ROOT = Path(__file__).resolve().parent.parent
QEMU = "qemu-system-i386"
W, H = 320, 200


def exit_status(qemu_status):
    """The kernel's exit status from QEMU's (isa-debug-exit: 2 * status + 1)."""
    return (qemu_status - 1) // 2 if qemu_status > 0 and qemu_status % 2 == 1 else None


class Kernel:
    """The kernel running headless under QEMU: COM1 on a pipe, QMP on a unix socket."""

    def __init__(self, kernel, args="", mem_mb=64, timeout=60):
        self.timeout = timeout
        self.dir = tempfile.mkdtemp(prefix="pcvga-")
        self.qmp_path = os.path.join(self.dir, "qmp.sock")
        cmd = [shutil.which(QEMU) or QEMU, "-m", str(mem_mb), "-kernel", str(kernel),
               "-device", "isa-debug-exit,iobase=0xf4,iosize=0x04", "-vga", "std", "-display", "none",
               "-monitor", "none", "-serial", "stdio", "-no-reboot",
               "-qmp", f"unix:{self.qmp_path},server=on,wait=off"]
        if args:
            cmd += ["-append", args]
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.out = b""
        self.qmp = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        if self.qmp:
            self.qmp.close()
        shutil.rmtree(self.dir, ignore_errors=True)

    def read_until(self, text):
        """COM1's output up to and including text; raises if the kernel exits or times out first."""
        deadline = time.monotonic() + self.timeout
        fd = self.proc.stdout.fileno()
        while text.encode() not in self.out:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError(f"pcvga: no '{text}' on COM1 in {self.timeout} s:\n{self.log()}")
            ready, _, _ = select.select([fd], [], [], min(left, 0.5))
            if ready:
                chunk = os.read(fd, 65536)
                if not chunk:
                    raise RuntimeError(f"pcvga: QEMU ended before '{text}' (status {self.proc.wait()}):\n"
                                       f"{self.log()}{self.proc.stderr.read().decode(errors='replace')}")
                self.out += chunk
        return self.log()

    def log(self):
        return self.out.decode(errors="replace").replace("\r\n", "\n")

    def command(self, execute, **arguments):
        if self.qmp is None:
            sock = socket.socket(socket.AF_UNIX)
            sock.settimeout(self.timeout)
            sock.connect(self.qmp_path)
            self.qmp = sock.makefile("rw")
            json.loads(self.qmp.readline())  # the greeting
            self.command("qmp_capabilities")
        msg = {"execute": execute}
        if arguments:
            msg["arguments"] = arguments
        self.qmp.write(json.dumps(msg) + "\n")
        self.qmp.flush()
        while True:
            reply = json.loads(self.qmp.readline())
            if "return" in reply:
                return reply["return"]
            if "error" in reply:
                raise RuntimeError(f"QMP {execute}: {reply['error']}")
            # an asynchronous event: keep reading

    def screendump(self, path):
        self.command("screendump", filename=str(path))
        return read_ppm(path)

    def finish(self):
        """Send COM1 the byte --wait waits for; returns (the kernel's exit status, COM1's whole log)."""
        self.proc.stdin.write(b"\n")
        self.proc.stdin.flush()
        try:
            status = self.proc.wait(timeout=self.timeout)
        except subprocess.TimeoutExpired:
            raise TimeoutError(f"pcvga: the kernel did not exit after the byte on COM1:\n{self.log()}")
        self.out += self.proc.stdout.read()
        return exit_status(status), self.log()


def run(kernel, args="", timeout=60):
    """Run the kernel to its end; returns (QEMU's exit status, COM1's log)."""
    with Kernel(kernel, args, timeout=timeout) as k:
        try:
            out, _ = k.proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            raise TimeoutError(f"pcvga: QEMU still running after {timeout} s")
        return k.proc.returncode, out.decode(errors="replace").replace("\r\n", "\n")


def read_ppm(path):
    """A binary PPM (P6, maxval 255) as an (h, w, 3) uint8 array."""
    data = Path(path).read_bytes()
    m = re.match(rb"P6\s+(\d+)\s+(\d+)\s+(\d+)\s", data)
    if not m or int(m.group(3)) != 255:
        raise ValueError(f"{path}: not an 8-bit binary PPM")
    w, h = int(m.group(1)), int(m.group(2))
    pixels = np.frombuffer(data[m.end():m.end() + w * h * 3], dtype=np.uint8)
    if pixels.size != w * h * 3:
        raise ValueError(f"{path}: {pixels.size} bytes of pixels for {w}x{h}")
    return pixels.reshape(h, w, 3)


def dac_frame(shot):
    """The screendump back to what the DAC holds for each of the 320x200 pixels (6 bits per gun).

    QEMU shows mode 13h at 320x200 or doubled (640x400): a doubled shot must be made of
    uniform 2x2 blocks. Each 8-bit value must be QEMU's widening of a 6-bit one."""
    h, w, _ = shot.shape
    if (w, h) not in ((W, H), (2 * W, 2 * H)):
        raise ValueError(f"screendump is {w}x{h}: not 320x200 or 640x400 (is the VGA in mode 13h?)")
    if w == 2 * W:
        frame = shot[0::2, 0::2]
        for dy in (0, 1):
            for dx in (0, 1):
                if not np.array_equal(shot[dy::2, dx::2], frame):
                    raise ValueError("screendump: a doubled pixel is not uniform")
    else:
        frame = shot
    dac = frame >> 2
    widened = (dac << 2) | ((dac & 1) * 3)
    if not np.array_equal(widened, frame):
        raise ValueError("screendump: values that are not QEMU's 6-to-8-bit DAC expansion")
    return dac


def indices(dac, palette):
    """Palette indices for a frame of DAC values: (index frame, mask of pixels whose colour
    several indices share at 6 bits, mask of pixels whose colour is no index's)."""
    pal6 = np.frombuffer(bytes(palette), dtype=np.uint8).reshape(-1, 3) >> 2
    key = (pal6[:, 0].astype(np.int32) << 12) | (pal6[:, 1].astype(np.int32) << 6) | pal6[:, 2]
    first, count = {}, {}
    for i, k in enumerate(key.tolist()):
        first.setdefault(k, i)
        count[k] = count.get(k, 0) + 1
    fkey = (dac[..., 0].astype(np.int32) << 12) | (dac[..., 1].astype(np.int32) << 6) | dac[..., 2]
    lut_index = np.zeros(1 << 18, dtype=np.int32) - 1
    lut_count = np.zeros(1 << 18, dtype=np.int32)
    for k, i in first.items():
        lut_index[k] = i
        lut_count[k] = count[k]
    return lut_index[fkey], lut_count[fkey] > 1, lut_index[fkey] < 0


def png_palette(path):
    data = Path(path).read_bytes()
    i = data.index(b"PLTE")
    (n,) = struct.unpack(">I", data[i - 4:i])
    return data[i + 4:i + 4 + n]


def render_reference(scene, frame, args, render=ROOT / "build" / "render"):
    """build/render's frame from the camera of one of the kernel's frame lines, in the render
    and present modes among its options: (64,000 palette indices, the 768-byte palette, its
    JSON). Objects and doors are drawn as at time 0: a camera path's frames match for scenes
    whose objects and doors have not moved by then."""
    words = args.split()
    extra = ["--at", ",".join(fx_text(frame[k]) for k in ("x", "y", "z")), "--angle", fx_text(frame["angle"]),
             "--look", str(frame["look"])]
    for opt in ("--mode", "--present"):
        if opt in words:
            extra += [opt, words[words.index(opt) + 1]]
    with tempfile.TemporaryDirectory() as tmp:
        raw, png = Path(tmp) / "frame.raw", Path(tmp) / "frame.png"
        proc = subprocess.run([str(render), str(scene), *extra, "--raw", str(raw), "-o", str(png)],
                              capture_output=True, text=True, check=True)
        return raw.read_bytes(), png_palette(png), json.loads(proc.stdout)


COUNTERS = ("writes", "bytes", "writes8", "writes16", "writes32", "vram_writes", "sysmem_writes", "pixels",
            "copy_writes", "bus_cycles")
FRAME_LINE = re.compile(r"^frame (\d+) (.*)$", re.M)


def frame_lines(log):
    """COM1's per-frame lines as dicts: frame, crc (hex text), camera and counters (ints)."""
    frames = []
    for m in FRAME_LINE.finditer(log):
        words = m.group(2).split()
        d = {"frame": int(m.group(1))}
        for key, value in zip(words[0::2], words[1::2]):
            d[key] = value if key == "crc" else int(value)
        frames.append(d)
    return frames


def shot(kernel, args, scene=None, png=None, timeout=60):
    """Boot, take the screen, compare (with scene); returns the summary dict."""
    with Kernel(kernel, (args + " --wait").strip(), timeout=timeout) as k, \
            tempfile.TemporaryDirectory() as tmp:
        k.read_until("waiting for a byte")
        screen = k.screendump(Path(tmp) / "screen.ppm")
        status, log = k.finish()
    dac = dac_frame(screen)
    frames = frame_lines(log)
    out = {"kernel_status": status, "screendump": f"{screen.shape[1]}x{screen.shape[0]}",
           "frames": len(frames), "last_frame": frames[-1] if frames else None}
    if png:
        write_png_rgb(png, screen)
        out["png"] = str(png)
    if scene:
        if not frames:
            raise RuntimeError(f"pcvga: the kernel reported no frame:\n{log}")
        ref, palette, ref_json = render_reference(scene, frames[-1], args)
        want = np.frombuffer(ref, dtype=np.uint8).reshape(H, W)
        pal6 = np.frombuffer(palette, dtype=np.uint8).reshape(-1, 3) >> 2
        idx, ambiguous, unknown = indices(dac, palette)
        out.update({
            "render_crc32": ref_json["crc32"],
            "render_counters": {k: ref_json[k] for k in COUNTERS},
            "dac_pixels_differing": int(np.any(pal6[want] != dac, axis=2).sum()),
            "index_pixels_differing": int(((idx != want) & ~ambiguous).sum()),
            "pixels_ambiguous_at_6_bits": int(ambiguous.sum()),
            "pixels_of_no_palette_colour": int(unknown.sum()),
        })
    return out


def bench(kernel, scene, frames=None):
    """Per-frame write counters of the kernel's camera path in each present mode (medians),
    beside build/render's linear page for the same frames in flip mode. Markdown text."""
    rows, cams = [], None
    for present in ("copy8", "copy16", "copy32", "flip"):
        args = f"--present {present}" + (f" --frames {frames}" if frames else "")
        status, log = run(kernel, args, timeout=600)
        if exit_status(status) != 0:
            raise RuntimeError(f"pcvga: the kernel failed ({args}):\n{log}")
        lines = frame_lines(log)
        cams = cams or lines
        rows.append((f"{present} (VGA{' unchained' if present == 'flip' else ' mode 13h'})", lines))
    linear = [render_reference(scene, f, "--present flip")[2] for f in cams]
    rows.append(("flip, linear page (build/render, host)", linear))

    def med(items, key):
        return int(np.median([it[key] for it in items]))

    keys = ("writes", "bytes", "writes8", "writes16", "writes32", "vram_writes", "sysmem_writes", "copy_writes",
            "bus_cycles")
    out = [f"Per frame, median of {len(cams)} frames of the kernel's camera path (bus cycles: hal.h's model, "
           "VRAM 8 and system memory 1 a transaction):", "",
           "| present | " + " | ".join(k.replace("_", " ") for k in keys) + " |",
           "|---|" + "---:|" * len(keys)]
    for name, items in rows:
        out.append(f"| {name} | " + " | ".join(f"{med(items, k):,}" for k in keys) + " |")
    return "\n".join(out) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(prog="pcvga.py", description=__doc__.split("\n\n")[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("shot", help="boot, take the screen with QMP's screendump, compare with build/render")
    s.add_argument("kernel", help="build/pcvga/kernel.elf (make pcvga)")
    s.add_argument("--args", default="", help="the kernel's options (hal/bare/args.h); --wait is added")
    s.add_argument("--scene", help="the compiled scene built into the kernel (build/pcvga/scene.bsc): compare")
    s.add_argument("-o", dest="png", help="write the screendump as a PNG")
    s.add_argument("--json", help="also write the summary here")
    s.add_argument("--timeout", type=float, default=60)
    b = sub.add_parser("bench", help="write counters per present mode over the camera path (markdown)")
    b.add_argument("kernel", help="build/pcvga/kernel.elf (make pcvga)")
    b.add_argument("--scene", required=True, help="its compiled scene (build/pcvga/scene.bsc)")
    b.add_argument("--frames", type=int, help="only the path's first N frames")
    b.add_argument("-o", dest="out", help="also write the table here")
    a = ap.parse_args(argv)
    if a.cmd == "bench":
        for f in (a.kernel, a.scene):
            if not Path(f).is_file():
                ap.error(f"{f}: no such file (make pcvga)")
        text = bench(a.kernel, a.scene, a.frames)
        print(text, end="")
        if a.out:
            Path(a.out).write_text(text)
        return 0
    if not Path(a.kernel).is_file():
        ap.error(f"{a.kernel}: no such kernel (make pcvga)")
    if a.scene and not Path(a.scene).is_file():
        ap.error(f"{a.scene}: no such scene")
    try:
        summary = shot(a.kernel, a.args, a.scene, a.png, a.timeout)
    except (RuntimeError, TimeoutError, ValueError) as e:
        print(f"pcvga.py: {e}", file=sys.stderr)
        return 1
    text = json.dumps(summary)
    print(text)
    if a.json:
        Path(a.json).write_text(text + "\n")
    bad = summary.get("dac_pixels_differing", 0) or summary.get("index_pixels_differing", 0) \
        or summary["kernel_status"] != 0
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
