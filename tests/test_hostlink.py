"""The host's frame-link present (host/link_send.c): build/emu --link and build/render --link send
what they draw to a display board over a pty or a TCP socket, as the firmware does over its UART.

build/emu's fly-through goes through a TCP relay into build/display, whose last PNG must be
build/render's frame for the camera emu reports; build/render's single frame is decoded by
tools/framelink.py (the Python twin) from a pty; a receiver that vanishes or stops reading ends
the sender with a message naming the port, and a PORT that does not open is a bad option."""
import json
import os
import re
import select
import shutil
import socket
import subprocess
import sys
import threading
import time
import zlib

import pytest

from conftest import ROOT, program, read_png_indexed, run

sys.path.insert(0, str(ROOT / "tools"))
import framelink  # noqa: E402

MAP01 = "freedoom2.wad:MAP01"
DEFAULT = str(ROOT / "tests" / "scenes" / "default.scene")


def listener():
    s = socket.socket()
    s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    s.bind(("127.0.0.1", 0))
    s.listen(1)
    return s, f"socket://127.0.0.1:{s.getsockname()[1]}"


def free_port_url():
    """A socket:// URL where nothing listens."""
    s, url = listener()
    s.close()
    return url


class Relay:
    """Two listening ports, one for the sender and one for the receiver (both programs are TCP
    clients); forwards both ways until either end closes. sent counts the sender's bytes."""

    def __init__(self):
        self.src, self.src_url = listener()
        self.dst, self.dst_url = listener()
        self.sent = 0
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        a, _ = self.src.accept()
        b, _ = self.dst.accept()
        peer = {a: b, b: a}
        try:
            while True:
                ready, _, _ = select.select([a, b], [], [], 60)
                if not ready:
                    return
                for s in ready:
                    data = s.recv(65536)
                    if not data:
                        return
                    if s is a:
                        self.sent += len(data)
                    peer[s].sendall(data)
        except OSError:
            return
        finally:
            a.close()
            b.close()


def view_args(stdout):
    m = re.search(r"frame (\d+) as build/render draws it: (.*)", stdout)
    assert m, stdout
    return int(m.group(1)), m.group(2).split()


def counters(stdout):
    line = next(l for l in stdout.splitlines() if l.startswith("frame ") and "link_bytes=" in l)
    return {k: int(v) for k, v in re.findall(r"(\w+)=(\d+)", line)}


@pytest.mark.parametrize("scene,flat", [(MAP01, False), (DEFAULT, False)], ids=["map01", "default"])
def test_emu_headless_into_display_shows_the_frame_render_draws(tmp_path, scene, flat):
    frames = 10
    relay = Relay()
    png = tmp_path / "png"
    board = subprocess.Popen([program("display"), relay.dst_url, "--png", str(png), "--frames", str(frames),
                              "--json", "--idle-timeout", "20"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    emu = run([program("emu", sanitized=False), scene, "--headless", "--frames", frames, "--link", relay.src_url],
              timeout=120)
    out, err = board.communicate(timeout=60)
    assert board.returncode == 0, err
    shown = json.loads(out)
    assert shown["frames_shown"] == frames and shown["msgs_bad"] == 0 and shown["frames_dropped"] == 0

    c = counters(emu.stdout)
    assert c["link_frames"] == frames and c["link_keyframes"] + c["link_deltas"] == frames
    assert c["link_deltas"] >= frames - 2  # a turn: each frame a delta of the one before
    assert c["link_bytes"] == shown["bytes"] == relay.sent
    assert c["link_acks"] >= 1
    assert f"link {relay.src_url}: {frames} frames" in emu.stdout
    assert "wrote" not in emu.stdout  # no PNG files without --out

    last, cam = view_args(emu.stdout)
    assert last == frames - 1
    ref = tmp_path / "ref.png"
    run([program("render"), scene, *cam, "-o", ref])
    _, _, pixels, palette = read_png_indexed(png / f"frame_{last:05d}.png")
    _, _, ref_pixels, ref_palette = read_png_indexed(ref)
    assert pixels == ref_pixels and palette == ref_palette
    assert len(sorted(png.glob("frame_*.png"))) == frames


def pty_pair():
    master, slave = os.openpty()
    return master, slave, os.ttyname(slave)


def read_until_quiet(fd, decoder, events, quiet=0.5, limit=60):
    """Feed what arrives on fd to decoder until nothing comes for `quiet` seconds."""
    deadline = time.time() + limit
    while time.time() < deadline:
        ready, _, _ = select.select([fd], [], [], quiet)
        if not ready:
            return
        try:
            data = os.read(fd, 65536)
        except OSError:
            return
        if not data:
            return
        events += decoder.feed(data)


@pytest.mark.parametrize("flat", [False, True], ids=["textured", "flat"])
def test_render_link_sends_one_keyframe_that_decodes_to_its_frame(tmp_path, flat):
    master, slave, path = pty_pair()
    try:
        decoder = framelink.Decoder(back=lambda b: os.write(master, b))
        events = []
        extra = ["--flat"] if flat else []
        proc = subprocess.Popen([program("render"), MAP01, *extra, "--raw", str(tmp_path / "f.raw"),
                                 "-o", str(tmp_path / "f.png"), "--link", path],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        reader = threading.Thread(target=read_until_quiet, args=(master, decoder, events, 3))
        reader.start()
        out, err = proc.communicate(timeout=120)
        reader.join(timeout=30)
    finally:
        os.close(master)
        os.close(slave)
    assert proc.returncode == 0, err
    kinds = [e["event"] for e in events]
    assert kinds == ["hello", "palette", "frame"], kinds
    frame = events[2]
    assert frame["keyframe"] == 1 and frame["frame"] == 0
    assert frame["pixels"] == (tmp_path / "f.raw").read_bytes()
    assert events[1]["palette"] == read_png_indexed(tmp_path / "f.png")[3]
    j = json.loads(out)
    link = j["link"]
    assert link["port"] == path and not link["error"]
    assert (link["frames"], link["keyframes"], link["deltas"], link["raw"], link["skipped"]) == (1, 1, 0, 0, 0)
    assert link["bytes"] == decoder.counters["bytes"]
    assert link["acks"] == 1
    info = frame["info"]
    assert info["crc32"] == j["crc32"] and info["mode"] == ["spans", "painter", "direct", "columns"].index(j["mode"])  # render.h
    assert j["textured"] == (0 if flat else 1)
    # the hello names the scene as given and the CRC-32 of the blob it compiles to
    blob = tmp_path / "scene.bsc"
    run([program("bspc", sanitized=False), MAP01, "-o", blob])
    assert events[0]["scene"] == MAP01
    assert events[0]["scene_crc32"] == f"{zlib.crc32(blob.read_bytes()):08x}"


def test_render_link_over_tcp_without_acks_still_finishes(tmp_path):
    """A receiver that never answers: the frame goes out, render waits at most the ack timeout."""
    srv, url = listener()
    got = bytearray()

    def take():
        c, _ = srv.accept()
        while True:
            data = c.recv(65536)
            if not data:
                break
            got.extend(data)
        c.close()

    t = threading.Thread(target=take)
    t.start()
    start = time.time()
    proc = run([program("render"), DEFAULT, "--link", url, "--raw", tmp_path / "f.raw"], timeout=60)
    t.join(timeout=30)
    srv.close()
    assert time.time() - start < 20
    events = framelink.Decoder().feed(bytes(got))
    assert [e["event"] for e in events] == ["hello", "palette", "frame"]
    assert events[2]["pixels"] == (tmp_path / "f.raw").read_bytes()
    link = json.loads(proc.stdout)["link"]
    assert link["bytes"] == len(got) and link["acks"] == 0


def emu_until_receiver_goes(port, stop_receiver, frames=100000):
    proc = subprocess.Popen([program("emu", sanitized=False), MAP01, "--headless", "--frames", str(frames),
                             "--link", port], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    stop_receiver()
    out, err = proc.communicate(timeout=60)
    return proc.returncode, out, err


def test_emu_stops_with_a_message_when_the_socket_receiver_goes_away():
    srv, url = listener()

    def receive_then_close():
        srv.settimeout(60)
        c, _ = srv.accept()
        n = 0
        while n < 100000:  # the first frames
            data = c.recv(65536)
            if not data:
                break
            n += len(data)
        c.close()
        srv.close()

    rc, out, err = emu_until_receiver_goes(url, receive_then_close)
    assert rc == 1, (rc, err)
    assert f"emu: --link {url}: the receiver" in err, err
    c = counters(out) if "link_bytes=" in out else None
    assert f"link {url}:" in out and (c is None or c["link_frames"] < 100000)


def test_emu_stops_with_a_message_when_the_pty_receiver_goes_away():
    master, slave, path = pty_pair()

    def receive_then_close():
        n = 0
        deadline = time.time() + 60
        while n < 100000 and time.time() < deadline:
            ready, _, _ = select.select([master], [], [], 1)
            if ready:
                n += len(os.read(master, 65536))
        os.close(slave)  # emu has it open now: closing the master leaves it no reader
        os.close(master)

    rc, out, err = emu_until_receiver_goes(path, receive_then_close)
    assert rc == 1, (rc, err)
    assert f"emu: --link {path}: the receiver" in err, err


def test_emu_gives_up_a_receiver_that_stops_reading():
    """A pty nobody reads fills up; emu stops after LINK_STALL_MS (10 s) instead of hanging."""
    master, slave, path = pty_pair()
    try:
        start = time.time()
        rc, out, err = emu_until_receiver_goes(path, lambda: None)
        took = time.time() - start
    finally:
        os.close(master)
        os.close(slave)
    assert rc == 1, (rc, err)
    assert f"emu: --link {path}: the receiver took no bytes for 10 s" in err, err
    assert 9 < took < 50


@pytest.mark.parametrize("name", ["render", "emu"])
@pytest.mark.parametrize("port,why", [
    ("/dev/no-such-tty", "cannot open: No such file or directory"),
    ("socket://127.0.0.1", "expected socket://HOST:PORT"),
    ("socket://no-such-host.invalid:5555", "socket://no-such-host.invalid:5555: "),
    ("FREE", "cannot connect: Connection refused"),
    ("-", "frames cannot be sent on it"),
    ("README.md", "frames cannot be sent on it"),
], ids=["no-tty", "malformed", "no-host", "no-listener", "stdin", "file"])
def test_a_port_that_does_not_open_is_a_bad_option(name, port, why):
    if port == "FREE":
        port = free_port_url()
    args = [DEFAULT] + (["--headless", "--frames", "2"] if name == "emu" else [])
    proc = run([program(name, sanitized=name == "render"), *args, "--link", port], check=False, timeout=60,
               cwd=ROOT)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith(f"{name}: --link ") and why in proc.stderr, proc.stderr
    assert port.split("://")[-1].split(":")[0] in proc.stderr
    assert proc.stdout == ""


def test_help_names_link():
    for name in ("render", "emu"):
        proc = run([program(name, sanitized=False), "--help"])
        assert "--link PORT" in proc.stdout and "socket://HOST:PORT" in proc.stdout


def test_emu_window_under_xvfb_sends_its_frames(tmp_path):
    """The window run sends the frames it shows, as the headless one does, at the window's pace:
    a frame drawn while the link is behind is skipped (none, usually), the last one is sent."""
    assert shutil.which("xvfb-run"), "xvfb-run missing: run make deps"
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER")}
    env["XDG_RUNTIME_DIR"] = "/tmp"
    frames = 5
    relay = Relay()
    board = subprocess.Popen([program("display"), relay.dst_url, "--png", str(tmp_path / "png"), "--json",
                              "--idle-timeout", "20"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    emu = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", program("emu", sanitized=False), DEFAULT,
                          "--frames", str(frames), "--link", relay.src_url], capture_output=True, text=True, env=env,
                         timeout=120)
    out, err = board.communicate(timeout=60)
    assert emu.returncode == 0, emu.stdout + emu.stderr
    assert "no display available" not in emu.stdout
    assert board.returncode == 0, err
    m = re.search(rf"link {re.escape(relay.src_url)}: (\d+) frames .*, (\d+) skipped,", emu.stdout)
    assert m and int(m.group(1)) + int(m.group(2)) == frames, emu.stdout
    shown = json.loads(out)
    assert shown["frames_shown"] == int(m.group(1)) and shown["frames_dropped"] == 0
    assert (tmp_path / "png" / f"frame_{frames - 1:05d}.png").exists()  # the last frame drawn
