#!/usr/bin/env python3
"""run_firmware.py - make run-firmware: run the firmware that was last built under QEMU (mps2-an385).

    tools/run_firmware.py [--elf build/arm/firmware.elf] [--uart FILE|stdio] [--port tcp:[HOST:]N|pty]
                          [--args "--frames 10 ..."] [--qemu qemu-system-arm]

It runs the ELF as it is (never rebuilds it) and first says, on stderr, which scene that ELF holds
(fw_scene_name and the CRC-32 of fw_scene, read from the ELF itself). Where UART0 goes:

    --uart FILE    the stream into FILE (default build/arm/uart.bin)
    --uart stdio   the stream on stdout, and nothing else: every message (this script's, QEMU's,
                   the firmware's semihosting console) goes to stderr, so that
                   `make run-firmware UART=stdio | build/display -` gets the stream alone
    --port tcp:N   a TCP server on 127.0.0.1:N (tcp:HOST:N to listen elsewhere) that waits for its
                   reader (server=on,wait=on): the firmware starts only once the reader has
                   connected, so it never misses the start
    --port pty     a pseudo-terminal. QEMU starts paused (-S) with a QMP socket beside the ELF
                   (qmp.sock); the pty's path is printed, and the firmware starts once a reader
                   has the pty open (QEMU drops what is written to a pty nobody holds). Another
                   QMP client may continue it instead: {"execute": "cont"}.

Exit status: QEMU's, which is the firmware's (hal/mps2/main.c); 2 when there is no firmware to run.
"""
import argparse
import json
import os
import re
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import armelf  # noqa: E402


def say(msg):
    print(f"mps2: {msg}", file=sys.stderr, flush=True)


def qemu_cmd(qemu, elf, serial, args, extra=()):
    # -nographic would share stdio between the UART and the monitor (a 0x01 byte in a frame starts
    # a monitor escape): the monitor is off. The semihosting console goes to stderr.
    return [qemu, "-M", "mps2-an385", "-nographic", "-monitor", "none",
            "-semihosting-config", "enable=on,target=native", "-kernel", str(elf), "-serial", serial,
            *extra] + (["-append", args] if args else [])


def tcp_serial(spec):
    """tcp:N or tcp:HOST:N -> (QEMU's -serial, the reader's URL)."""
    parts = spec.split(":")
    host, port = ("127.0.0.1", parts[1]) if len(parts) == 2 else (parts[1], parts[2])
    if not port.isdigit() or not 0 < int(port) < 65536:
        raise ValueError(f"PORT={spec}: expected tcp:N or tcp:HOST:N, N a TCP port number")
    return f"tcp:{host}:{port},server=on,wait=on", f"socket://{host}:{port}"


def pts_held_by_other(pts, own_pid):
    """Whether a process other than own_pid has the pty's slave side open."""
    for pid in os.listdir("/proc"):
        if not pid.isdigit() or int(pid) == own_pid:
            continue
        try:
            fds = os.listdir(f"/proc/{pid}/fd")
        except OSError:
            continue
        for fd in fds:
            try:
                if os.readlink(f"/proc/{pid}/fd/{fd}") == pts:
                    return True
            except OSError:
                pass
    return False


def forward(fd):
    """Copy fd to stderr as it comes, until its end."""
    while True:
        chunk = os.read(fd, 4096)
        if not chunk:
            return
        sys.stderr.buffer.write(chunk)
        sys.stderr.flush()


def qmp_cont(path, timeout=10.0):
    deadline = time.time() + timeout
    while not os.path.exists(path) and time.time() < deadline:
        time.sleep(0.05)
    with socket.socket(socket.AF_UNIX) as s:
        s.connect(path)
        f = s.makefile("rw")
        f.readline()  # greeting
        for cmd in ("qmp_capabilities", "cont"):
            f.write(json.dumps({"execute": cmd}) + "\n")
            f.flush()
            f.readline()


def run_pty(cmd, qmp_path):
    """QEMU paused on a pty; continued once a reader holds the pty. Returns QEMU's status."""
    if os.path.exists(qmp_path):
        os.unlink(qmp_path)
    proc = subprocess.Popen(cmd + ["-S", "-qmp", f"unix:{qmp_path},server=on,wait=off"],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
    # QEMU names the pty on stdout, without ending the line; all it says is passed on to stderr
    pts = None
    buf = b""
    while pts is None:
        chunk = os.read(proc.stdout.fileno(), 4096)
        if not chunk:
            return proc.wait()
        sys.stderr.buffer.write(chunk)
        sys.stderr.flush()
        buf += chunk
        m = re.search(rb"(/dev/pts/\d+)", buf)
        if m:
            pts = m.group(1).decode()
    sys.stderr.buffer.write(b"" if buf.endswith(b"\n") else b"\n")
    # the rest of QEMU's messages and the firmware's, as they come
    pump = threading.Thread(target=forward, args=(proc.stdout.fileno(),), daemon=True)
    pump.start()
    say(f"UART0 on {pts}; QEMU is paused until a reader opens it (e.g. build/display {pts}, "
        f"tools/capture.py --port {pts} ...), or continue it over QMP at {qmp_path}")
    try:
        while proc.poll() is None and not pts_held_by_other(pts, proc.pid):
            time.sleep(0.1)
        if proc.poll() is None:
            # a reader flushes what is pending as it opens (pyserial does): let it finish first
            time.sleep(0.3)
            say(f"a reader has {pts} open: the firmware starts")
            qmp_cont(qmp_path)
        status = proc.wait()
    except KeyboardInterrupt:
        proc.kill()
        status = proc.wait()
    pump.join(timeout=2)
    try:
        os.unlink(qmp_path)
    except OSError:
        pass
    return status


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="See the module docstring (tools/run_firmware.py).")
    ap.add_argument("--elf", default="build/arm/firmware.elf", help="the firmware (default build/arm/firmware.elf)")
    ap.add_argument("--uart", default="", help="FILE or stdio (default: uart.bin beside the ELF)")
    ap.add_argument("--port", default="", help="tcp:N, tcp:HOST:N or pty (instead of --uart)")
    ap.add_argument("--args", default="", help="the firmware's command line (hal/mps2/args.h)")
    ap.add_argument("--qemu", default="qemu-system-arm")
    a = ap.parse_args(argv)
    elf = Path(a.elf)
    if not elf.is_file():
        say(f"no firmware at {elf}: build it first (make firmware [SCENE=...])")
        return 2
    try:
        name, crc = armelf.built_in_scene(elf)
        say(f"running {elf}, built {time.strftime('%Y-%m-%d %H:%M:%S', time.localtime(elf.stat().st_mtime))}: "
            f"scene {name} (compiled blob CRC-32 {crc:08x}); to run another scene: make firmware SCENE=...")
    except (LookupError, ValueError, OSError, subprocess.CalledProcessError) as e:
        say(f"{elf}: cannot read its scene ({e})")
    if a.port == "pty":
        # QEMU drops what its pty's reader has not read yet when it exits: unless told
        # otherwise, the firmware lingers a second after its last frame (needs the tick)
        args = a.args if "--linger" in a.args or "--no-tick" in a.args else (a.args + " --linger 1000").strip()
        return run_pty(qemu_cmd(a.qemu, elf, "pty", args), str(elf.parent / "qmp.sock"))
    if a.port.startswith("tcp:"):
        try:
            serial, url = tcp_serial(a.port)
        except ValueError as e:
            say(str(e))
            return 2
        say(f"UART0 on {url}: QEMU waits for one reader to connect before the firmware starts "
            f"(e.g. build/display {url}); firmware messages below")
    elif a.port:
        say(f"PORT={a.port}: expected tcp:N, tcp:HOST:N or pty")
        return 2
    elif a.uart == "stdio":
        serial = "stdio"
        say("UART0 -> stdout (the stream alone); firmware messages on stderr")
    else:
        out = a.uart or str(elf.parent / "uart.bin")
        serial = f"file:{out}"
        say(f"UART0 -> {out}; firmware messages below")
    cmd = qemu_cmd(a.qemu, elf, serial, a.args)
    # stdout carries the UART alone (stdio) or nothing: QEMU's own text goes to stderr
    stdout = None if serial == "stdio" else sys.stderr.fileno()
    try:
        return subprocess.call(cmd, stdout=stdout)
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
