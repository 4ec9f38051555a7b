"""The real thing: the firmware under QEMU streams its fly-through over its UART, on a pty and on a
TCP socket; tools/capture.py (pyserial) captures it; every captured frame is bit-identical (same
CRC-32, same pixels) to build/render's frame for the same scene and camera. Then the same through a
relay that damages the stream: no damaged frame is ever accepted, and the link recovers."""
import json
import subprocess
import sys
import zlib

import pytest
import serial

from conftest import ROOT, program, read_png_indexed, render, run
from linkrig import ARM, FaultyRelay, Firmware, capture_run, firmware_link, outages

sys.path.insert(0, str(ROOT / "tools"))
import capture  # noqa: E402

FRAMES = 30


@pytest.fixture(scope="module")
def firmware():
    subprocess.run(["make", "-s", "--no-print-directory", "firmware"], cwd=ROOT, check=True, capture_output=True)
    elf = ARM / "firmware.elf"
    assert elf.exists()
    return elf


def captured(kind, tmp_path, frames=FRAMES, relay_rate=None, args=None):
    fw = Firmware(kind, args or f"--frames {frames} --linger 1000", tmp=tmp_path)
    relay = None
    try:
        port_url = fw.port
        if relay_rate is not None:
            relay = FaultyRelay(int(fw.port.rsplit(":", 1)[1]), relay_rate, seed=7)
            port_url = relay.port
        port = serial.serial_for_url(port_url, baudrate=115200, timeout=0.2)
        fw.start()
        try:
            summary = capture.capture(port, frames, tmp_path / "cap", timeout=20, log=sys.stderr)
        finally:
            port.close()
        status = fw.wait(timeout=120)
    finally:
        fw.kill()
    records = [json.loads(line) for line in (tmp_path / "cap" / "frames.jsonl").read_text().splitlines()]
    return status, summary, records, "".join(fw.log), relay


def host_frame(rec, tmp_path):
    """build/render's frame for the captured camera and the scene the capture names (render_args
    alone, run from the repository's root)."""
    raw = tmp_path / f"host_{rec['frame']}.bin"
    j = json.loads(run([program("render", sanitized=False), *rec["render_args"], "--raw", raw], cwd=ROOT).stdout)
    return j, raw.read_bytes()


@pytest.mark.parametrize("kind", ["pty", "tcp"])
def test_capture_is_bit_identical_to_the_host(firmware, tmp_path, kind):
    status, summary, records, log, _ = captured(kind, tmp_path)
    assert status == 0, log
    assert summary["frames_captured"] == FRAMES and summary["msgs_bad"] == 0, summary
    assert [r["frame"] for r in records] == list(range(FRAMES))
    # the capture names the scene built into the firmware, and its compiled blob's CRC-32
    crc = "%08x" % zlib.crc32((ARM / "scene.bsc").read_bytes())
    assert {(r["scene"], r["scene_crc32"]) for r in records} == {("tests/scenes/default.scene", crc)}
    assert (summary["scene"], summary["scene_crc32"]) == ("tests/scenes/default.scene", crc)
    assert records[0]["render_args"][0] == "tests/scenes/default.scene"
    for rec in records:
        j, pixels = host_frame(rec, tmp_path)
        assert j["crc32"] == rec["crc32"], rec
        assert "%08x" % zlib.crc32(pixels) == rec["crc32"]
    # the PNG holds exactly the frame's pixels
    _, _, png_pixels, _ = read_png_indexed(tmp_path / "cap" / f"frame_{records[-1]['frame']:05d}.png")
    assert png_pixels == pixels


def test_capture_help():
    proc = subprocess.run([sys.executable, str(ROOT / "tools/capture.py"), "--help"], capture_output=True, text=True)
    assert proc.returncode == 0 and "--port" in proc.stdout and "--frames" in proc.stdout


def test_capture_bad_port(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "tools/capture.py"), "--port", str(tmp_path / "nope"),
                           "--frames", "1", "--out", str(tmp_path / "o")], capture_output=True, text=True)
    assert proc.returncode != 0 and "nope" in proc.stderr


DAMAGE_FRAMES = 120
# Frames an outage may lose at 1e-4 per byte: one damage event costs about the ack window and the
# keyframe request's round trip (about 5 frames); a second event inside the outage about as much.
RESYNC_FRAMES = 24


@pytest.fixture(scope="module")
def clean_truth(firmware, tmp_path_factory):
    """Each frame's CRC-32 from an undamaged run of the stream the damaged runs send."""
    frames = DAMAGE_FRAMES
    status, _, clean, log, _ = captured("tcp", tmp_path_factory.mktemp("clean"), frames=frames,
                                        args=f"--frames {frames} --linger 1000 --acks on")
    assert status == 0 and len(clean) == frames, log
    return {r["frame"]: r["crc32"] for r in clean}


@pytest.mark.parametrize("rate", [1e-4, 1e-3, 1e-2])
def test_damaged_link_never_shows_a_damaged_frame(clean_truth, tmp_path, rate):
    """Bit flips, dropped bytes and truncated messages at `rate` per byte between the firmware and the
    receiver: every frame the receiver accepts is exactly the frame the firmware rendered under that
    number (the clean run's CRC-32), bad messages are counted, and frames keep coming after damage:
    at 1e-4, every outage (from the relay's first damaged byte to the next frame accepted) ends
    within RESYNC_FRAMES frames."""
    frames = DAMAGE_FRAMES
    status, summary, got, log, relay = captured("tcp", tmp_path / "faulty", frames=frames, relay_rate=rate,
                                                args=f"--frames {frames} --linger 1000 --acks on")
    relay.join()
    assert relay.events > 0, "the relay damaged nothing: raise the rate or the frame count"
    for r in got:
        assert clean_truth[r["frame"]] == r["crc32"], f"damaged frame {r['frame']} accepted"
    assert summary["msgs_bad"] > 0 or summary["frames_dropped"] > 0
    if rate > 1e-3:
        # At 1e-2 per byte a keyframe of a few hundred bytes rarely arrives intact: few or no frames
        # may be shown then, but none damaged (checked above).
        return
    link = firmware_link(log)
    assert link, log
    # The relay passes the back direction intact, so the firmware hears every ack but those still
    # in flight when it stops (at most its window of 4): fewer means its UART receive stalled.
    assert link["acks_heard"] >= summary["acks_sent"] - 4, \
        (f"the firmware heard {link['acks_heard']} of the receiver's {summary['acks_sent']} acks and "
         f"{link['keyreqs_heard']} of its {summary['keyreqs_sent']} keyframe requests")
    assert len(got) > 0 and got[-1]["frame"] >= frames // 2, "the link did not recover"
    if rate <= 1e-4:
        outs = outages([d for d, _ in relay.damage], [(r["stream_end"], r["frame"]) for r in got],
                       link["frames_sent"])
        assert outs
        for o in outs:
            assert o["frames_lost"] <= RESYNC_FRAMES, f"no intact frame for {o['frames_lost']} frames: {o}"


def test_display_board_over_tcp(firmware, tmp_path):
    """build/display (the C decoder) on the firmware's TCP serial port writes every frame as a PNG,
    each identical to build/render's frame for its camera, and reports its counters."""
    fw = Firmware("tcp", "--frames 12 --linger 500 --acks on", tmp=tmp_path)
    try:
        proc = subprocess.run([program("display"), fw.port, "--png", tmp_path / "png", "--frames", "12",
                               "--json", "--idle-timeout", "20"], capture_output=True, text=True, timeout=120)
        status = fw.wait(timeout=60)
    finally:
        fw.kill()
    assert proc.returncode == 0, proc.stderr
    counters = json.loads(proc.stdout)
    assert counters["frames_shown"] == 12 and counters["msgs_bad"] == 0 and counters["bytes_per_frame"] > 0
    assert status == 0
    pngs = sorted((tmp_path / "png").glob("frame_*.png"))
    assert len(pngs) == 12
    _, _, pixels, _ = read_png_indexed(pngs[0])
    assert len(pixels) == 64000 and len(set(pixels)) > 3


def test_display_help_and_bad_port(tmp_path):
    proc = subprocess.run([program("display"), "--help"], capture_output=True, text=True)
    assert proc.returncode == 0 and "socket://" in proc.stdout
    proc = subprocess.run([program("display"), str(tmp_path / "none"), "--png", str(tmp_path)],
                          capture_output=True, text=True)
    assert proc.returncode != 0 and "none" in proc.stderr


def test_capture_skips_frames_before_the_palette(tmp_path):
    """A stream that starts after its palette (hello, frames 0-2, palette, frames 3-5): the frames
    before the palette are not captured as black PNGs; those after it are, in the real palette."""
    walk = tmp_path / "walk"
    walk.mkdir()
    run([program("fltool", sanitized=False), "walk", "freedoom2.wad:MAP01", "--frames", 6, "--flat", "--out", walk])
    run([program("fltool", sanitized=False), "encode", walk / "frames.raw", "--info", walk / "frames.jsonl",
         "--palette", walk / "palette.bin", "--out", walk / "s.bin"])
    segs = (walk / "s.bin").read_bytes().split(b"\0")[:-1]
    late = [segs[0]] + segs[2:5] + [segs[1]] + segs[5:]

    class Port:
        chunks = [b"".join(s + b"\0" for s in late)]

        def read(self, n):
            if not self.chunks:
                raise serial.SerialException("closed")
            return self.chunks.pop(0)

        def write(self, data):
            return len(data)

    summary = capture.capture(Port(), 6, tmp_path / "cap", log=sys.stderr)
    assert summary["frames_no_palette"] == 3 and summary["frames_captured"] == 3
    pngs = sorted((tmp_path / "cap").glob("frame_*.png"))
    assert [p.name for p in pngs] == [f"frame_{n:05d}.png" for n in range(3, 6)]
    palette = (walk / "palette.bin").read_bytes()
    assert all(read_png_indexed(p)[3] == palette for p in pngs)
    records = [json.loads(line) for line in (tmp_path / "cap" / "frames.jsonl").read_text().splitlines()]
    assert [r["frame"] for r in records] == [3, 4, 5]


def test_capture_render_reproduces_a_frame(firmware, tmp_path):
    """tools/capture.py --render FRAME redraws a captured frame with build/render from the scene the
    capture names and says it matches; a frame whose captured pixels differ, or whose scene's blob
    CRC-32 differs from the captured one, is reported."""
    status, summary, records, log, _ = captured("tcp", tmp_path, frames=5)
    assert status == 0 and summary["frames_captured"] == 5, log
    cap = tmp_path / "cap"
    tool = [sys.executable, str(ROOT / "tools/capture.py")]
    ok = subprocess.run(tool + ["--render", "4", "--out", str(cap)], capture_output=True, text=True, cwd=tmp_path)
    assert ok.returncode == 0 and "frame 4: match" in ok.stderr, ok.stderr
    assert "warning" not in ok.stderr
    # another scene CRC recorded: a warning; another pixel CRC recorded: a mismatch
    lines = (cap / "frames.jsonl").read_text().splitlines()
    rec = json.loads(lines[4])
    rec["scene_crc32"] = "12345678"
    rec["crc32"] = "%08x" % (int(rec["crc32"], 16) ^ 1)
    lines[4] = json.dumps(rec)
    (cap / "frames.jsonl").write_text("\n".join(lines) + "\n")
    bad = subprocess.run(tool + ["--render", "4", "--out", str(cap)], capture_output=True, text=True, cwd=tmp_path)
    assert bad.returncode == 1 and "MISMATCH" in bad.stderr, bad.stderr
    assert "warning" in bad.stderr and "12345678" in bad.stderr
    missing = subprocess.run(tool + ["--render", "99", "--out", str(cap)], capture_output=True, text=True)
    assert missing.returncode == 1 and "frame 99 is not in" in missing.stderr


@pytest.fixture(scope="module")
def firmware_battle():
    """The Cortex-M3 firmware with the space-battle scene built in: ships moving along their paths."""
    out = ROOT / "build" / "firmware-test" / "arm-battle"
    proc = subprocess.run(["make", "-s", "--no-print-directory", "-j2", "firmware",
                           "SCENE=tests/scenes/battle.scene", f"ARM_OUT={out}"], cwd=ROOT, capture_output=True,
                          text=True, timeout=1800)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return out / "firmware.elf"


def test_captured_frame_with_moving_things_redraws(firmware_battle, tmp_path):
    """A frame the firmware sent while its objects were moving is redrawn bit for bit by
    tools/capture.py --render: the frame link carries the engine's time, and build/render --time puts
    every object where the firmware had it."""
    records = capture_run(firmware_battle, 12, tmp_path)
    moved = []
    for rec in records:
        at0 = list(rec["render_args"])
        at0[at0.index("--time") + 1] = "0"
        if render(*at0, sanitized=False)["crc32"] != rec["crc32"]:
            moved.append(rec)  # drawn at time 0, with the ships where they started, it would differ
    assert moved, "no captured frame shows the objects moved"
    for rec in moved[-2:]:
        ok = subprocess.run([sys.executable, str(ROOT / "tools/capture.py"), "--render", str(rec["frame"]), "--out",
                             str(tmp_path / "cap")], capture_output=True, text=True, cwd=ROOT)
        assert ok.returncode == 0 and f"frame {rec['frame']}: match" in ok.stderr, ok.stderr
