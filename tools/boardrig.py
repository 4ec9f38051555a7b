"""The display board (hal/board) under QEMU, fed by a sender over TCP, inspected over QMP.

Used by tests/test_display_board.py and tools/bench_board.py. The board's UART0 is a TCP server
(server=on,wait=on: QEMU does not run until the sender connects, so nothing is missed); the
rendering firmware (a second QEMU) connects to it as a client with its own UART0, so the frames
go one way and the board's acks and keyframe requests the other. The board logs each frame it
shows on semihosting (hal/board/main.c); QMP (a unix socket) stops it and reads its memory.
"""
import json
import os
import re
import select
import shutil
import socket
import struct
import subprocess
import threading
import time
from pathlib import Path

from armelf import symbol

ROOT = Path(__file__).resolve().parent.parent
ARM = ROOT / "build" / "arm"
QEMU = shutil.which("qemu-system-arm") or "qemu-system-arm"
BASE = [QEMU, "-M", "mps2-an385", "-nographic", "-monitor", "none",
        "-semihosting-config", "enable=on,target=native"]

FRAME_RE = re.compile(r"board: frame (\d+) crc32 0x([0-9a-f]{8}) shown page (\d) camera (-?\d+) (-?\d+) (-?\d+) "
                      r"(-?\d+) look (-?\d+) mode (\d+) present (\d+) key (\d) seg (\d+) time (\d+)")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def frames_of(text):
    """The board's frame lines as dicts (camera raw 16.16)."""
    out = []
    for m in FRAME_RE.finditer(text):
        f, crc, page, x, y, z, a, look, mode, present, key, seg, t = m.groups()
        out.append(dict(frame=int(f), crc32=int(crc, 16), page=int(page), x=int(x), y=int(y), z=int(z),
                        angle=int(a), look=int(look), mode=int(mode), present=int(present), key=int(key),
                        seg=int(seg), time_ms=int(t)))
    return out


class Board:
    """A running display board. image: an ELF or the raw flash image (-kernel loads a non-ELF at 0
    on M-profile). listen: UART0 a TCP server (self.tcp_port) waiting for the sender; else null."""

    def __init__(self, image, args="", listen=True, tmp="/tmp", plugin=None):
        self.qmp_path = str(Path(tmp) / f"board-qmp-{os.getpid()}-{id(self)}.sock")
        self.tcp_port = free_port() if listen else None
        serial = f"tcp:127.0.0.1:{self.tcp_port},server=on,wait=on" if listen else "null"
        cmd = BASE + ["-kernel", str(image), "-qmp", f"unix:{self.qmp_path},server=on,wait=off",
                      "-serial", serial]
        if plugin:
            cmd += ["-plugin", plugin]
        if args:
            cmd += ["-append", args]
        self.cmd = cmd
        self.text = ""
        self._lock = threading.Lock()
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self._qmp = None
        if listen:
            self.wait_for(r"waiting for connection", 15)

    def _read(self):
        while True:
            b = os.read(self.proc.stdout.fileno(), 4096)
            if not b:
                return
            with self._lock:
                self.text += b.decode(errors="replace")

    def wait_for(self, pattern, timeout):
        """The first match of pattern in the board's output, waiting up to timeout seconds."""
        deadline = time.time() + timeout
        while time.time() < deadline:
            with self._lock:
                m = re.search(pattern, self.text)
            if m:
                return m
            if self.proc.poll() is not None:
                self._reader.join(2)
                with self._lock:
                    m = re.search(pattern, self.text)
                if m:
                    return m
                raise RuntimeError(f"the board exited ({self.proc.returncode}) before '{pattern}':\n{self.text}")
            time.sleep(0.05)
        raise RuntimeError(f"no '{pattern}' from the board in {timeout} s:\n{self.text}")

    def qmp(self, execute, **arguments):
        if self._qmp is None:
            s = socket.socket(socket.AF_UNIX)
            s.connect(self.qmp_path)
            self._qmp = s.makefile("rw")
            self._qmp.readline()  # greeting
            self.qmp("qmp_capabilities")
        cmd = {"execute": execute}
        if arguments:
            cmd["arguments"] = arguments
        self._qmp.write(json.dumps(cmd) + "\n")
        self._qmp.flush()
        while True:  # events may come first
            r = json.loads(self._qmp.readline())
            if "return" in r:
                return r["return"]
            if "error" in r:
                raise RuntimeError(f"QMP {execute}: {r['error']}")

    def pmem(self, addr, size, path):
        """size bytes of the board's physical memory from addr (QMP pmemsave)."""
        self.qmp("pmemsave", val=addr, size=size, filename=str(path))
        return Path(path).read_bytes()

    def shown_page(self, elf, tmp):
        """Stop the board and read what it shows: (display-start register, the 64,000 bytes of the
        page it selects), at the addresses elf's symbols give."""
        self.qmp("stop")
        start = struct.unpack("<I", self.pmem(symbol(elf, "mps2_display_start"), 4, Path(tmp) / "ds.bin"))[0]
        assert start in (0, 1), start
        page = self.pmem(symbol(elf, "mps2_vram1" if start else "mps2_vram0"), 64000, Path(tmp) / "page.bin")
        return start, page

    def wait(self, timeout=60):
        try:
            self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            self.proc.wait()
        self._reader.join(2)
        return self.proc.returncode

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()


class Sender:
    """The rendering firmware (hal/mps2) with its UART0 a TCP client of the board's.

    The kernel's socket buffers take megabytes of frames ahead of a slow board, and QEMU drops
    what the board has not read yet when the sender's end of the connection closes. So the sender
    lingers after its last frame, and finish() pauses it over QMP (its socket stays open) once it
    has sent everything; kill() it when the board has shown what it wanted."""

    def __init__(self, elf, tcp_port, args, tmp="/tmp"):
        self.qmp_path = str(Path(tmp) / f"sender-qmp-{os.getpid()}-{id(self)}.sock")
        cmd = BASE + ["-kernel", str(elf), "-serial", f"tcp:127.0.0.1:{tcp_port}",
                      "-qmp", f"unix:{self.qmp_path},server=on,wait=off", "-append", f"{args} --linger 60000"]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        self.text = ""

    def finish(self, frames, timeout=120):
        """Wait for the sender's link summary (all frames sent), pause it; returns its output."""
        want = f"firmware: link: {frames} frames"
        buf = b""
        deadline = time.time() + timeout
        while time.time() < deadline and self.proc.poll() is None and want.encode() not in buf:
            r, _, _ = select.select([self.proc.stdout], [], [], 0.2)
            if r:
                buf += os.read(self.proc.stdout.fileno(), 4096)
        self.text = buf.decode(errors="replace")
        if want not in self.text:
            self.kill()
            raise RuntimeError(f"the sender did not send {frames} frames:\n{self.text}")
        with socket.socket(socket.AF_UNIX) as s:
            s.connect(self.qmp_path)
            f = s.makefile("rw")
            f.readline()
            for cmd in ("qmp_capabilities", "stop"):
                f.write(json.dumps({"execute": cmd}) + "\n")
                f.flush()
                f.readline()
        return self.text

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
