"""The firmware under QEMU with its UART on a pty or a TCP socket, and a fault-injecting relay.

Used by the capture tests and by tools/bench_faults.py. QEMU's pty drops what the guest writes
while no reader has the pty open, so QEMU starts paused (-S) and is continued over QMP once the
reader is attached; on TCP QEMU waits for the client (server=on,wait=on) before it runs at all.
"""
import json
import os
import random
import re
import select
import shutil
import socket
import subprocess
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ARM = ROOT / "build" / "arm"
QEMU = shutil.which("qemu-system-arm") or "qemu-system-arm"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def qemu_cmd(elf, serial, args="", extra=()):
    return [QEMU, "-M", "mps2-an385", "-nographic", "-monitor", "none",
            "-semihosting-config", "enable=on,target=native", "-kernel", str(elf),
            "-serial", serial, *extra] + (["-append", args] if args else [])


class Firmware:
    """A running firmware. kind 'pty' (self.port is the pty path) or 'tcp' (self.port is a
    socket:// URL). Call start() once the reader is attached (pty: continues QEMU over QMP)."""

    def __init__(self, kind, args="", elf=None, tmp=None):
        self.kind = kind
        elf = elf or ARM / "firmware.elf"
        self.log = []
        if kind == "pty":
            self.qmp_path = str(Path(tmp or "/tmp") / f"qmp-{os.getpid()}-{id(self)}.sock")
            cmd = qemu_cmd(elf, "pty", args, ["-S", "-qmp", f"unix:{self.qmp_path},server=on,wait=off"])
        else:
            p = free_port()
            cmd = qemu_cmd(elf, f"tcp:127.0.0.1:{p},server=on,wait=on", args)
            self.port = f"socket://127.0.0.1:{p}"
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        if kind == "pty":
            self.port = self._find_pty()
        else:
            self._wait_listening(p)

    def _find_pty(self):
        deadline = time.time() + 15
        buf = b""
        while time.time() < deadline:
            ready, _, _ = select.select([self.proc.stdout, self.proc.stderr], [], [], 0.5)
            for f in ready:
                buf += os.read(f.fileno(), 4096)
            m = re.search(rb"(/dev/pts/\d+)", buf)
            if m:
                self.log.append(buf.decode(errors="replace"))
                return m.group(1).decode()
        self.kill()
        raise RuntimeError(f"QEMU named no pty: {buf!r}")

    def _wait_listening(self, port):
        """QEMU says "waiting for connection" on stderr once its server socket is up (a probe
        connection would itself become the one client QEMU accepts)."""
        deadline = time.time() + 15
        buf = b""
        while time.time() < deadline and self.proc.poll() is None:
            ready, _, _ = select.select([self.proc.stderr], [], [], 0.5)
            if ready:
                buf += os.read(self.proc.stderr.fileno(), 4096)
                if b"waiting for connection" in buf:
                    self.log.append(buf.decode(errors="replace"))
                    return
        self.kill()
        raise RuntimeError(f"QEMU did not listen on its TCP serial port: {buf!r}")

    def start(self):
        if self.kind != "pty":
            return
        deadline = time.time() + 10
        while not os.path.exists(self.qmp_path) and time.time() < deadline:
            time.sleep(0.05)
        with socket.socket(socket.AF_UNIX) as s:
            s.connect(self.qmp_path)
            f = s.makefile("rw")
            f.readline()  # greeting
            for cmd in ("qmp_capabilities", "cont"):
                f.write(json.dumps({"execute": cmd}) + "\n")
                f.flush()
                f.readline()

    def wait(self, timeout=120):
        try:
            out, err = self.proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            out, err = self.proc.communicate()
        self.log.append((out + err).decode(errors="replace"))
        return self.proc.returncode

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()


class FaultyRelay:
    """Relays bytes from `upstream` (a TCP address the firmware serves) to whoever connects to
    self.port, damaging the firmware->receiver direction at a rate per byte: bit flips, dropped
    bytes and truncated messages, in equal shares. A truncation loses the bytes from the chosen
    one up to the next message delimiter (kept); chosen on a delimiter, it keeps it and loses the
    whole next message. The receiver->firmware direction (acks, keyframe requests) passes intact.

    self.damage lists every damage event as (offset, kind), kind "flip", "drop" or "truncate", offset
    in the stream the receiver gets: how many bytes it had got before the damage (so the index of a
    flipped byte, or of the byte that follows the dropped byte or truncated run). self.sent counts the
    bytes relayed to the receiver, self.back those relayed from it to the firmware. They grow while
    the relay runs; read them after join()."""

    def __init__(self, upstream_port, rate, seed=1):
        self.rate, self.rng = rate, random.Random(seed)
        self.flips = self.drops = self.truncations = 0
        self.damage = []
        self.sent = 0
        self.back = 0
        self._skipping = False
        self.listener = socket.socket()
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(1)
        self.port = f"socket://127.0.0.1:{self.listener.getsockname()[1]}"
        self.upstream_port = upstream_port
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    @property
    def events(self):
        return self.flips + self.drops + self.truncations

    def join(self, timeout=10):
        self.thread.join(timeout)

    def _damage(self, data):
        out = bytearray()
        for b in data:
            if self._skipping:
                if b == 0:
                    self._skipping = False
                    out.append(b)
                continue
            if self.rng.random() < self.rate:
                kind = self.rng.randrange(3)
                if kind == 0:
                    self.damage.append((self.sent + len(out), "flip"))
                    out.append(b ^ (1 << self.rng.randrange(8)))
                    self.flips += 1
                elif kind == 1:
                    self.damage.append((self.sent + len(out), "drop"))
                    self.drops += 1
                else:
                    self.truncations += 1
                    self._skipping = True
                    if b == 0:
                        out.append(b)
                    self.damage.append((self.sent + len(out), "truncate"))
                continue
            out.append(b)
        self.sent += len(out)
        return bytes(out)

    def _run(self):
        down, _ = self.listener.accept()
        up = socket.create_connection(("127.0.0.1", self.upstream_port))
        socks = [up, down]
        try:
            while True:
                ready, _, _ = select.select(socks, [], [], 1.0)
                for s in ready:
                    data = s.recv(65536)
                    if not data:
                        return
                    if s is up:
                        down.sendall(self._damage(data))
                    else:
                        up.sendall(data)
                        self.back += len(data)
        except OSError:
            return
        finally:
            up.close()
            down.close()


LINK_BYTES_PER_S = 11520  # 115,200 baud, 8N1: 10 bits a byte


def firmware_link(log):
    """What the firmware says it sent and heard, from its log (hal/mps2/stream_fl.c's closing
    "link:" line): frames_sent, acks_heard, keyreqs_heard, ack_timeouts; None if it said nothing."""
    m = re.search(r"link: (\d+) frames .*?; (\d+) acks, (\d+) keyframe requests, (\d+) timeouts", log)
    if not m:
        return None
    return dict(zip(["frames_sent", "acks_heard", "keyreqs_heard", "ack_timeouts"], map(int, m.groups())))


def outages(damage, accepted, frames_sent):
    """The receiver's outages, measured from where the relay damaged the stream and where the
    receiver accepted frames (both as byte offsets in the stream the receiver got).

    damage: offsets of the damage events (FaultyRelay.damage's first fields). accepted: (offset
    just past the accepted frame's message, frame number) for each accepted frame, in stream order
    (tools/capture.py's frames.jsonl: stream_end, frame). An outage starts at the first damage
    event after the last accepted frame and ends at the next accepted frame; every damage event in
    between belongs to it. Returns one dict per outage: start and end (offsets; end None if no frame
    was accepted after it: open at the end of the run), bytes (end - start: what the receiver
    consumed from the first damaged byte until it showed an intact frame again; None if open),
    ms (those bytes' time on a 115,200 8N1 link), events (damage events in it), frames_lost (frame
    numbers between the last frame accepted before it and the next one accepted; for an open
    outage, up to the last frame sent)."""
    damage = sorted(damage)
    acc = sorted(accepted)
    out = []
    i = j = 0
    prev_no = -1
    while i < len(damage):
        d = damage[i]
        while j < len(acc) and acc[j][0] <= d:
            prev_no = acc[j][1]
            j += 1
        end = acc[j][0] if j < len(acc) else None
        k = i
        while k < len(damage) and (end is None or damage[k] < end):
            k += 1
        if end is None:
            lost = frames_sent - 1 - prev_no
            out.append({"start": d, "end": None, "bytes": None, "ms": None, "events": k - i, "frames_lost": lost})
        else:
            lost = acc[j][1] - prev_no - 1
            n = end - d
            out.append({"start": d, "end": end, "bytes": n, "ms": n * 1000 / LINK_BYTES_PER_S, "events": k - i,
                        "frames_lost": lost})
        i = k
    return out


def capture_run(elf, frames, tmp_path):
    """Runs the firmware elf for frames frames over TCP and captures them with tools/capture.py
    (pyserial) into tmp_path/cap: the frames' records (frames.jsonl), each with its render_args."""
    import json
    import sys
    import serial
    sys.path.insert(0, str(ROOT / "tools"))
    import capture
    fw = Firmware("tcp", f"--frames {frames} --linger 1000", elf=elf, tmp=tmp_path)
    try:
        port = serial.serial_for_url(fw.port, baudrate=115200, timeout=0.2)
        fw.start()
        try:
            summary = capture.capture(port, frames, tmp_path / "cap", timeout=60, log=sys.stderr)
        finally:
            port.close()
        assert fw.wait(timeout=300) == 0, "".join(fw.log)
    finally:
        fw.kill()
    assert summary["frames_captured"] == frames, summary
    return [json.loads(line) for line in (tmp_path / "cap" / "frames.jsonl").read_text().splitlines()]
