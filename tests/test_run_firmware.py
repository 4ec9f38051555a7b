"""make run-firmware: it runs the firmware last built without rebuilding it and names its scene;
with UART=stdio its stdout carries the frame stream alone (piped into build/display: no bad
message, every byte the firmware sent); with PORT=tcp:N a reader that connects after QEMU started
misses nothing; with PORT=pty QEMU waits for the reader to open the pty."""
import json
import os
import re
import select
import subprocess
import time
import zlib

import pytest

from conftest import ROOT, program
from linkrig import ARM, free_port

sys_env = dict(os.environ)
for v in ("SCENE", "MAKEFLAGS", "MFLAGS", "MAKELEVEL"):
    sys_env.pop(v, None)


@pytest.fixture(scope="module")
def firmware():
    subprocess.run(["make", "-s", "--no-print-directory", "firmware"], cwd=ROOT, check=True, capture_output=True,
                   env=sys_env)
    return ARM / "firmware.elf"


def sent_bytes(log):
    m = re.search(r"link: (\d+) frames .*?, (\d+) bytes;", log)
    assert m, log
    return int(m.group(1)), int(m.group(2))


def test_stdio_into_display_carries_the_stream_alone(firmware, tmp_path):
    """`make run-firmware UART=stdio | build/display -`: every message goes to stderr."""
    cmd = (f"make run-firmware UART=stdio RUN_ARGS='--frames 8' 2>{tmp_path}/make.err | "
           f"{program('display', sanitized=False)} - --json --png {tmp_path}")
    proc = subprocess.run(["bash", "-o", "pipefail", "-c", cmd], cwd=ROOT, capture_output=True, text=True,
                          timeout=300, env=sys_env)
    log = (tmp_path / "make.err").read_text()
    assert proc.returncode == 0, proc.stderr + log
    counts = json.loads(proc.stdout)
    frames, sent = sent_bytes(log)
    assert frames == 8
    assert counts["msgs_bad"] == 0 and counts["frames_shown"] == 8, counts
    assert counts["bytes"] == sent, (counts, log)
    crc = "%08x" % zlib.crc32((ARM / "scene.bsc").read_bytes())
    assert (counts["scene"], counts["scene_crc32"]) == ("tests/scenes/default.scene", crc)
    assert f"scene tests/scenes/default.scene (compiled blob CRC-32 {crc})" in log


def test_scene_not_repeated_does_not_rebuild(firmware, tmp_path):
    """make run-firmware runs the ELF in ARM_OUT as it is, whatever its age and whatever else the
    folder lacks (here: nothing but the ELF, older than every source), and says which scene it
    holds, read from the ELF; a SCENE= given on the command line rebuilds first."""
    out = tmp_path / "arm"
    out.mkdir()
    elf = out / "firmware.elf"
    elf.write_bytes(firmware.read_bytes())
    os.utime(elf, (1_000_000_000, 1_000_000_000))
    proc = subprocess.run(["make", "run-firmware", f"ARM_OUT={out}", "RUN_ARGS=--frames 2 --no-stream"],
                          cwd=ROOT, capture_output=True, text=True, timeout=300, env=sys_env)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == ""
    crc = "%08x" % zlib.crc32((ARM / "scene.bsc").read_bytes())
    assert f"scene tests/scenes/default.scene (compiled blob CRC-32 {crc})" in proc.stderr
    assert sorted(p.name for p in out.iterdir()) == ["firmware.elf", "uart.bin"]  # nothing built
    assert elf.stat().st_mtime == 1_000_000_000
    # SCENE= again: a build first (make -n: what would run), its output kept off stdout
    dry = subprocess.run(["make", "-n", "run-firmware", f"ARM_OUT={out}", "SCENE=tests/scenes/default.scene"],
                         cwd=ROOT, capture_output=True, text=True, timeout=60, env=sys_env)
    assert "firmware >&2" in dry.stdout, dry.stdout


def test_no_firmware_built(tmp_path):
    proc = subprocess.run(["make", "run-firmware", f"ARM_OUT={tmp_path}/none"], cwd=ROOT, capture_output=True,
                          text=True, timeout=60, env=sys_env)
    assert proc.returncode != 0 and "no firmware at" in proc.stderr and "make firmware" in proc.stderr


def read_all(sock_or_fd, deadline):
    data = b""
    while time.time() < deadline:
        ready, _, _ = select.select([sock_or_fd], [], [], 0.5)
        if ready:
            try:
                chunk = sock_or_fd.recv(65536) if hasattr(sock_or_fd, "recv") else os.read(sock_or_fd, 65536)
            except OSError:  # a pty whose other side closed
                break
            if not chunk:
                break
            data += chunk
    return data


def test_tcp_reader_connecting_late_misses_nothing(firmware, tmp_path):
    import socket
    port = free_port()
    err = open(tmp_path / "err", "w")
    proc = subprocess.Popen(["make", "run-firmware", f"PORT=tcp:{port}", "RUN_ARGS=--frames 6"], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=err, env=sys_env)
    try:
        time.sleep(2.0)  # QEMU starts and listens; the firmware must not run before a reader connects
        deadline = time.time() + 30
        while True:  # make may take a moment longer to start QEMU on a busy machine
            try:
                s = socket.create_connection(("127.0.0.1", port), timeout=10)
                break
            except ConnectionRefusedError:
                if time.time() > deadline:
                    raise
                time.sleep(0.5)
        with s:
            data = read_all(s, time.time() + 60)
        assert proc.wait(timeout=60) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
    log = (tmp_path / "err").read_text()
    assert proc.stdout.read() == b""
    frames, sent = sent_bytes(log)
    assert len(data) == sent, log
    stream = tmp_path / "stream.bin"
    stream.write_bytes(data)
    dec = subprocess.run([program("fltool", sanitized=False), "decode", stream], capture_output=True, text=True)
    events = [json.loads(l) for l in dec.stdout.splitlines()]
    assert events[0]["event"] == "hello" and events[0]["scene"] == "tests/scenes/default.scene"
    assert events[-1]["counters"]["frames_shown"] == 6 and events[-1]["counters"]["msgs_bad"] == 0, events[-1]


def test_pty_waits_for_its_reader(firmware, tmp_path):
    proc = subprocess.Popen(["make", "run-firmware", "PORT=pty", "RUN_ARGS=--frames 4"], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=sys_env)
    try:
        buf, pts = b"", None
        deadline = time.time() + 30
        while pts is None and time.time() < deadline:
            ready, _, _ = select.select([proc.stderr], [], [], 0.5)
            if ready:
                buf += os.read(proc.stderr.fileno(), 4096)
                m = re.search(rb"UART0 on (/dev/pts/\d+)", buf)
                pts = m and m.group(1).decode()
        assert pts, buf
        time.sleep(1.5)  # paused: the firmware waits for the reader
        assert b"firmware: mps2-an385" not in buf + (os.read(proc.stderr.fileno(), 4096) if select.select(
            [proc.stderr], [], [], 0)[0] else b"")
        fd = os.open(pts, os.O_RDWR | os.O_NOCTTY)
        try:
            data = read_all(fd, time.time() + 60)
        finally:
            os.close(fd)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0
    assert out == b""
    _, sent = sent_bytes(err.decode())
    assert len(data) == sent
