"""build/display (the display board, host/display.c) on captured streams it cannot trust whole:
a stream that starts after its palette, a palette that comes late, and input that is no frame
link at all. Streams come from build/fltool (a short flat walk of freedoom2.wad:MAP01) and are cut
at message delimiters."""
import json
import random
import subprocess

import pytest

from conftest import ROOT, program, read_png_indexed, run

FRAMES = 6


@pytest.fixture(scope="module")
def stream(tmp_path_factory):
    """(messages, palette): the stream's COBS segments (hello, palette, frames) and palette.bin."""
    out = tmp_path_factory.mktemp("walk")
    run([program("fltool", sanitized=False), "walk", "freedoom2.wad:MAP01", "--frames", FRAMES, "--flat",
         "--out", out])
    run([program("fltool", sanitized=False), "encode", out / "frames.raw", "--info", out / "frames.jsonl",
         "--palette", out / "palette.bin", "--out", out / "stream.bin"])
    segs = (out / "stream.bin").read_bytes().split(b"\0")
    assert segs[-1] == b"" and len(segs) == FRAMES + 3  # hello, palette, frames, then the last delimiter
    return segs[:-1], (out / "palette.bin").read_bytes()


def joined(segs):
    return b"".join(s + b"\0" for s in segs)


def display(path, tmp_path):
    png = tmp_path / "png"
    proc = subprocess.run([program("display"), str(path), "--png", str(png), "--json", "--idle-timeout", "5"],
                          capture_output=True, text=True, timeout=60)
    counters = json.loads(proc.stdout) if proc.stdout.strip() else None
    return proc, counters, sorted(png.glob("frame_*.png"))


def test_clean_stream_shows_every_frame_in_its_palette(stream, tmp_path):
    segs, palette = stream
    (tmp_path / "s.bin").write_bytes(joined(segs))
    proc, c, pngs = display(tmp_path / "s.bin", tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert c["frames_shown"] == FRAMES and c["frames_no_palette"] == 0 and c["msgs_bad"] == 0
    assert len(pngs) == FRAMES
    assert read_png_indexed(pngs[0])[3] == palette
    assert "palette" not in proc.stderr


def test_stream_without_palette_shows_nothing_and_fails(stream, tmp_path):
    """A capture cut after its palette: the frames pass their checks, but the board has no colours
    for them, so it shows none (no all-black PNGs), says so once, and exits 1."""
    segs, _ = stream
    (tmp_path / "nopal.bin").write_bytes(joined(segs[:1] + segs[2:]))
    proc, c, pngs = display(tmp_path / "nopal.bin", tmp_path)
    assert proc.returncode == 1
    assert pngs == []
    assert c["frames_shown"] == 0 and c["frames_no_palette"] == FRAMES and c["palreqs_sent"] >= 1
    assert proc.stderr.count("arrived before any palette") == 1
    assert "nopal.bin" in proc.stderr and "no palette" in proc.stderr


def test_stream_cut_inside_the_palette(stream, tmp_path):
    segs, _ = stream
    data = joined(segs)
    cut = len(segs[0]) + 1 + len(segs[1]) // 2
    (tmp_path / "cut.bin").write_bytes(data[cut:])
    proc, c, pngs = display(tmp_path / "cut.bin", tmp_path)
    assert proc.returncode == 1 and pngs == []
    assert c["msgs_bad"] == 1 and c["frames_no_palette"] == FRAMES


def test_late_palette_shows_the_frames_after_it(stream, tmp_path):
    """Frames before the palette are held back; from the palette on they are shown in it."""
    segs, palette = stream
    late = [segs[0]] + segs[2:5] + [segs[1]] + segs[5:]
    (tmp_path / "late.bin").write_bytes(joined(late))
    proc, c, pngs = display(tmp_path / "late.bin", tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert c["frames_no_palette"] == 3 and c["frames_shown"] == FRAMES - 3
    assert [p.name for p in pngs] == [f"frame_{n:05d}.png" for n in range(3, FRAMES)]
    assert all(read_png_indexed(p)[3] == palette for p in pngs)
    assert proc.stderr.count("arrived before any palette") == 1


def test_input_that_is_no_frame_link_fails_with_its_name(tmp_path):
    readme = ROOT / "README.md"
    proc, c, pngs = display(readme, tmp_path)
    assert proc.returncode == 1 and pngs == []
    size = readme.stat().st_size
    assert f"README.md: no frame-link message in {size:,} bytes" in proc.stderr
    assert c["bytes"] == size and c["msgs_ok"] == 0


def test_garbage_with_delimiters_fails_and_counts_bad_messages(tmp_path):
    rng = random.Random(18)
    data = bytes(rng.randrange(256) for _ in range(20000))
    (tmp_path / "noise.bin").write_bytes(data)
    proc, c, pngs = display(tmp_path / "noise.bin", tmp_path)
    assert proc.returncode == 1 and pngs == []
    assert c["msgs_bad"] > 0 and c["msgs_ok"] == 0
    assert f"noise.bin: no frame-link message in 20,000 bytes ({c['msgs_bad']} bad messages)" in proc.stderr


def test_empty_stdin_fails(tmp_path):
    proc = subprocess.run([program("display"), "-", "--png", str(tmp_path / "png")], input=b"",
                          capture_output=True, timeout=60)
    assert proc.returncode == 1 and b"stdin: no frame-link message in 0 bytes" in proc.stderr
