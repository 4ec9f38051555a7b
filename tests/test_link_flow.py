"""Flow control without stalls (host/link_send.c): build/emu --link never waits for its receiver.

A frame drawn while the link is behind (the receiver's window of unacknowledged frames full, or
the message before it still going out) is not sent but counted as skipped; the next frame sent
goes as a delta against the last one that was, and the last frame drawn is sent at the end.
Headless and linked, the fly-through keeps to its game clock (a frame every 83 ms), so a run
takes about the time of its frames whatever the receiver does.

The receivers here: build/display, which keeps up; and tools/framelink.py's Decoder behind a TCP
socket or a pty, one that takes 250 ms per frame before it acks, one that acks its first frame and
then never again, and one that reads the pty slowly and never acks. Every frame a receiver shows must be
the frame emu drew with that number (emu --out writes each one), and the counters must add up."""
import json
import os
import select
import socket
import subprocess
import sys
import threading
import time

import pytest

from conftest import ROOT, program, read_png_indexed
from test_hostlink import DEFAULT, MAP01, Relay, counters, listener, pty_pair

sys.path.insert(0, str(ROOT / "tools"))
import framelink  # noqa: E402

FLY_STEP_S = 0.083  # host/emu.c: FLY_STEP_MS, a headless frame's game time


class Receiver:
    """A display board in Python on a socket (listen=True: emu connects to url) or on a pty's master
    fd: decodes everything it reads, acks each frame ack_delay seconds after decoding it, only the
    first `acks` frames when given, none when acks == 0. read_every: seconds between reads of at
    most read_bytes (a receiver slower than the bytes). Collects the frame events."""

    def __init__(self, ack_delay=0.0, acks=None, fd=None, read_every=0.0, read_bytes=1 << 20):
        self.ack_delay, self.acks_left = ack_delay, acks
        self.read_every, self.read_bytes = read_every, read_bytes
        self.fd, self.conn = fd, None
        if fd is None:
            self.srv, self.url = listener()
        self.frames, self.error = [], None
        self.decoder = framelink.Decoder(back=self._back, send_acks=acks != 0)
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _back(self, msg):
        if msg[2] == framelink.MSG_ACK:  # COBS's first byte, the version, the type
            if self.acks_left is not None:
                if self.acks_left <= 0:
                    return
                self.acks_left -= 1
            time.sleep(self.ack_delay)
        try:
            if self.conn is not None:
                self.conn.sendall(msg)
            else:
                os.write(self.fd, msg)
        except OSError:
            pass  # emu has gone

    def _read(self):
        if self.conn is not None:
            return self.conn.recv(self.read_bytes)
        ready, _, _ = select.select([self.fd], [], [], 30)
        return os.read(self.fd, self.read_bytes) if ready else b""

    def _run(self):
        try:
            if self.fd is None:
                self.srv.settimeout(60)
                self.conn, _ = self.srv.accept()
            while True:
                try:
                    data = self._read()
                except OSError:  # a pty whose other end closed, a reset socket
                    return
                if not data:
                    return
                for ev in self.decoder.feed(data):
                    if ev["event"] == "frame":
                        self.frames.append(ev)
                if self.read_every:
                    time.sleep(self.read_every)
        except Exception as e:  # noqa: BLE001 (reported by join)
            self.error = e
        finally:
            if self.conn is not None:
                self.conn.close()
            if self.fd is None:
                self.srv.close()

    def join(self, timeout=60):
        self.thread.join(timeout)
        assert not self.thread.is_alive(), "the receiver did not finish"
        assert self.error is None, self.error


def run_emu(scene, frames, port, out):
    start = time.time()
    proc = subprocess.run([program("emu", sanitized=False), scene, "--headless", "--frames", str(frames),
                           "--out", str(out), "--link", port], capture_output=True, text=True, timeout=120)
    return proc, time.time() - start


def check_shown(rx, out, frames, c):
    """Every frame shown is emu's frame of that number; the counters of both ends add up."""
    d = rx.decoder.counters
    assert d["msgs_bad"] == 0 and d["frames_dropped"] == 0, d
    assert d["frames_shown"] == len(rx.frames) == c["link_frames"], (d, c)
    assert c["link_frames"] + c["link_skipped"] == frames, c
    assert c["link_keyframes"] + c["link_deltas"] == c["link_frames"], c
    nos = [f["frame"] for f in rx.frames]
    assert nos == sorted(set(nos)) and nos[0] == 0, nos
    assert nos[-1] == frames - 1, nos  # the last frame drawn is sent at the end even if skipped
    # first to last, every number shown or missed (= skipped: nothing was damaged)
    assert d["frames_missed"] == c["link_skipped"] == frames - len(nos), (d, c)
    for f in rx.frames:
        _, _, pixels, palette = read_png_indexed(out / f"frame_{f['frame']:03d}.png")
        assert f["pixels"] == pixels, f"frame {f['frame']} differs from emu's"
        assert rx.decoder.palette == palette
    return nos


@pytest.mark.parametrize("scene", [DEFAULT, MAP01], ids=["default", "map01"])
def test_a_receiver_that_keeps_up_is_sent_every_frame(tmp_path, scene):
    """build/display, through a relay, keeps up with the game: nothing is skipped."""
    frames = 24
    relay = Relay()
    png = tmp_path / "shown"
    board = subprocess.Popen([program("display"), relay.dst_url, "--png", str(png), "--json", "--idle-timeout", "20"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    proc, took = run_emu(scene, frames, relay.src_url, tmp_path / "emu")
    out, err = board.communicate(timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert board.returncode == 0, err
    c = counters(proc.stdout)
    assert c["link_skipped"] == 0 and c["link_frames"] == frames, c
    assert c["link_deltas"] == frames - 1, c  # a turn on the spot: one keyframe, then deltas
    assert f"link {relay.src_url}: {frames} frames (1 keyframes, {frames - 1} deltas, 0 raw), 0 skipped," in proc.stdout
    shown = json.loads(out)
    assert (shown["frames_shown"], shown["frames_dropped"], shown["frames_missed"], shown["msgs_bad"]) == \
        (frames, 0, 0, 0), shown
    for n in range(frames):
        assert read_png_indexed(png / f"frame_{n:05d}.png") == read_png_indexed(tmp_path / "emu" / f"frame_{n:03d}.png")
    # the fly-through at its game clock's pace
    assert (frames - 1) * FLY_STEP_S - 0.05 < took < frames * FLY_STEP_S + 10, took


def test_a_slow_receiver_gets_fewer_frames_and_the_game_does_not_wait(tmp_path):
    """4 frames a second against the game's 12: were emu to wait for it, 36 frames would take
    9 s; it takes their game time (3 s), plus at most an ack timeout or two at the end."""
    frames = 36
    rx = Receiver(ack_delay=0.25)
    proc, took = run_emu(DEFAULT, frames, rx.url, tmp_path / "emu")
    rx.join()
    assert proc.returncode == 0, proc.stderr
    c = counters(proc.stdout)
    assert c["link_skipped"] > frames // 3 and c["link_frames"] >= 4, c
    nos = check_shown(rx, tmp_path / "emu", frames, c)
    assert took < frames * FLY_STEP_S + 2.5, took
    # after a gap, the next frame still goes as a delta, against the last frame sent
    after_gap = [f for a, f in zip(nos, rx.frames[1:]) if f["frame"] != a + 1]
    assert after_gap and all(f["keyframe"] == 0 for f in after_gap), nos
    assert f"frames (1 keyframes, {c['link_deltas']} deltas, 0 raw), {c['link_skipped']} skipped," in proc.stdout


def test_a_receiver_that_stops_acking_costs_frames_not_time(tmp_path):
    """Its first ack turns flow control on; then the window fills, frames are skipped until the ack
    timeout (500 ms) gives the oldest frame in flight up, and one more frame goes each time."""
    frames = 36
    rx = Receiver(acks=1)
    proc, took = run_emu(DEFAULT, frames, rx.url, tmp_path / "emu")
    rx.join()
    assert proc.returncode == 0, proc.stderr
    c = counters(proc.stdout)
    assert c["link_acks"] == 1 and c["link_timeouts"] >= 1 and c["link_skipped"] > 0, c
    check_shown(rx, tmp_path / "emu", frames, c)
    assert took < frames * FLY_STEP_S + 2.5, took


def test_a_pty_read_slowly_never_gets_a_half_frame(tmp_path):
    """Textured frames (tens of KB each) into a pty read 4 KB at a time, 10 times a second, by a
    receiver that never acks: the port, not the window, is what is behind. A frame message goes
    out whole over as many frames as the port needs, the frames drawn meanwhile are skipped, and
    every message arrives intact."""
    frames = 24
    master, slave, path = pty_pair()
    try:
        rx = Receiver(acks=0, fd=master, read_every=0.1, read_bytes=4096)
        proc, took = run_emu(MAP01, frames, path, tmp_path / "emu")
        os.close(slave)
        rx.join(timeout=120)
    finally:
        os.close(master)
    assert proc.returncode == 0, proc.stderr
    c = counters(proc.stdout)
    assert c["link_acks"] == 0 and c["link_skipped"] > 0, c
    check_shown(rx, tmp_path / "emu", frames, c)
    assert rx.decoder.counters["bytes"] == c["link_bytes"]
    # the game's 2 s, then the last frame written out at the port's pace
    assert took < frames * FLY_STEP_S + 30, took
