"""build/display (the display board, host/display.c) on captured streams it cannot trust whole:
a stream that starts after its palette, a palette that comes late, and input that is no frame
link at all. Streams come from build/fltool (a short flat walk of freedoom2.wad:MAP01) and are cut
at message delimiters."""
import json
import random
import shutil
import subprocess
import time

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


# --png DIR: checked before anything is received, and a frame that cannot be written ends the run
# with a failure (before: "cannot write" for every frame, then exit 0 and every frame counted shown).

def test_png_at_a_regular_file_is_refused_up_front(stream, tmp_path):
    segs, _ = stream
    (tmp_path / "s.bin").write_bytes(joined(segs))
    target = tmp_path / "taken"
    target.write_bytes(b"not a folder")
    proc = subprocess.run([program("display"), str(tmp_path / "s.bin"), "--png", str(target), "--json"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr == f"display: --png {target}: exists and is not a directory\n"
    assert target.read_bytes() == b"not a folder"


def test_png_under_a_regular_file_is_refused_up_front(stream, tmp_path):
    segs, _ = stream
    (tmp_path / "s.bin").write_bytes(joined(segs))
    (tmp_path / "taken").write_bytes(b"")
    target = tmp_path / "taken" / "png"
    proc = subprocess.run([program("display"), str(tmp_path / "s.bin"), "--png", str(target), "--json"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr == f"display: --png {target}: cannot create: Not a directory\n"


@pytest.mark.parametrize("exists", [False, True], ids=["made", "existing"])
def test_png_folder_made_or_existing_gets_every_frame(stream, tmp_path, exists):
    segs, _ = stream
    (tmp_path / "s.bin").write_bytes(joined(segs))
    if exists:
        (tmp_path / "png").mkdir()
    proc, c, pngs = display(tmp_path / "s.bin", tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert c["frames_shown"] == FRAMES and [p.name for p in pngs] == [f"frame_{n:05d}.png" for n in range(FRAMES)]


def test_a_png_that_cannot_be_written_mid_run_stops_with_a_failure(stream, tmp_path):
    """The folder goes away after the first frame is written: the second frame is the first one
    lost, and the run stops there, says so once, counts one frame shown and exits 1."""
    segs, _ = stream
    png = tmp_path / "png"
    proc = subprocess.Popen([program("display"), "-", "--png", str(png), "--json", "--idle-timeout", "20"],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdin.write(joined(segs[:3]))  # hello, palette, frame 0
    proc.stdin.flush()
    first = png / "frame_00000.png"
    deadline = time.monotonic() + 30
    while not (first.exists() and first.stat().st_size > 0) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert first.exists(), "frame 0 was not written"
    time.sleep(0.2)  # png_write_indexed has closed it
    shutil.rmtree(png)
    out, err = proc.communicate(joined(segs[3:]), timeout=60)  # a pipe it closed early is no error here
    err = err.decode()
    assert proc.returncode == 1, err
    assert err.count("cannot write") == 1, err
    assert f"display: {png}/frame_00001.png: cannot write: No such file or directory; stopping" in err
    assert json.loads(out)["frames_shown"] == 1
