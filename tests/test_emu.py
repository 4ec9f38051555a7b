"""build/emu (make run): a window where a display exists, a headless fly-through where none does."""
import os
import re
import shutil
import subprocess
import sys
import time

import pytest

from conftest import BUILD, ROOT, read_png_indexed


def env_without_display():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER")}
    env["XDG_RUNTIME_DIR"] = "/tmp"
    return env


def test_headless_fallback_writes_png_frames(tmp_path):
    out = tmp_path / "fly"
    proc = subprocess.run([str(BUILD / "emu"), "--out", str(out)], capture_output=True, text=True,
                          env=env_without_display(), timeout=120)
    assert proc.returncode == 0, proc.stderr
    # one line on stderr says so (not stdout, not twice, nothing from libwayland)
    assert "no display available" not in proc.stdout
    assert proc.stderr.count("\n") == 1 and proc.stderr.count("no display") == 1, proc.stderr
    assert "rendering a fly-through headless instead" in proc.stderr
    assert str(out) in proc.stdout
    frames = sorted(out.glob("frame_*.png"))
    assert len(frames) == 36
    # the turn shows different views: not all frames alike, none empty
    seen = set()
    for f in frames:
        w, h, pixels, _ = read_png_indexed(f)
        assert (w, h) == (320, 200)
        assert len(set(pixels)) >= 2  # at least a wall and the background
        seen.add(pixels)
    assert len(seen) > 20


def test_window_under_xvfb(tmp_path):
    assert shutil.which("xvfb-run"), "xvfb-run missing: run make deps"
    env = env_without_display()
    start = time.time()
    proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", str(BUILD / "emu"), "--frames", "30"],
                          capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "no display available" not in proc.stdout
    assert time.time() - start < 100


def test_help():
    proc = subprocess.run([str(BUILD / "emu"), "--help"], capture_output=True, text=True)
    assert proc.returncode == 0 and "Esc" in proc.stdout


def test_no_display_without_xdg_runtime_dir_is_one_line(tmp_path):
    env = env_without_display()
    del env["XDG_RUNTIME_DIR"]
    proc = subprocess.run([str(BUILD / "emu"), "--frames", "2", "--out", str(tmp_path)], capture_output=True,
                          text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.count("\n") == 1 and "XDG_RUNTIME_DIR" not in proc.stderr, proc.stderr
    assert len(list(tmp_path.glob("frame_*.png"))) == 2


@pytest.mark.parametrize("args,message", [
    (["--scale", "0"], "--scale '0': expected a whole number 1..8"),
    (["--scale", "-3"], "--scale '-3'"),
    (["--scale", "9"], "--scale '9'"),
    (["--scale", "2x"], "--scale '2x'"),
    (["--frames", "abc"], "--frames 'abc': expected a whole number of frames"),
    (["--frames", "0"], "--frames '0'"),
    (["--frames", "-1"], "--frames '-1'"),
    (["--frames"], "--frames needs a value"),
    (["--bogus"], "unknown option '--bogus'"),
])
def test_bad_arguments_refused(args, message):
    proc = subprocess.run([str(BUILD / "emu"), "--headless", *args], capture_output=True, text=True,
                          env=env_without_display(), timeout=30)
    assert proc.returncode == 2 and message in proc.stderr, proc.stderr
    assert proc.stderr.count("\n") == 1 and proc.stdout == ""


def test_headless_frames_counted(tmp_path):
    proc = subprocess.run([str(BUILD / "emu"), "--headless", "--frames", "3", "--out", str(tmp_path)],
                          capture_output=True, text=True, env=env_without_display(), timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert len(list(tmp_path.glob("frame_*.png"))) == 3


# Keys pressed through the X server's XTEST extension (libXtst, with libX11, both by ctypes):
# V prints the camera as build/render options, S saves the frame shown, Esc quits.
PRESS_KEYS = r"""
import ctypes, subprocess, sys, time
x11, xt = ctypes.CDLL("libX11.so.6"), ctypes.CDLL("libXtst.so.6")
x11.XOpenDisplay.restype = ctypes.c_void_p
x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
x11.XKeysymToKeycode.argtypes = [ctypes.c_void_p, ctypes.c_ulong]
x11.XFlush.argtypes = [ctypes.c_void_p]
xt.XTestFakeKeyEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_ulong]
xt.XTestFakeMotionEvent.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_ulong]
emu = subprocess.Popen(sys.argv[1:], stdout=subprocess.PIPE, text=True)
d = x11.XOpenDisplay(None)
time.sleep(3)  # the window up and focused (no window manager: focus follows the pointer)
xt.XTestFakeMotionEvent(d, 0, 640, 512, 0)
for keysym in (0x76, 0x73, 0xff1b):  # v, s, Escape
    code = x11.XKeysymToKeycode(d, keysym)
    xt.XTestFakeKeyEvent(d, code, 1, 0)
    x11.XFlush(d)
    time.sleep(0.3)
    xt.XTestFakeKeyEvent(d, code, 0, 0)
    x11.XFlush(d)
    time.sleep(0.5)
out, _ = emu.communicate(timeout=60)
sys.stdout.write(out)
sys.exit(emu.returncode)
"""


def test_keys_print_the_camera_and_save_a_screenshot(tmp_path):
    assert shutil.which("xvfb-run"), "xvfb-run missing: run make deps"
    script = tmp_path / "press.py"
    script.write_text(PRESS_KEYS)
    shots = tmp_path / "shots"
    shots.mkdir()
    proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", sys.executable, str(script),
                           str(BUILD / "emu"), "--out", str(shots)],
                          capture_output=True, text=True, env=env_without_display(), timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    views = [line for line in proc.stdout.splitlines() if "as build/render draws it" in line]
    assert len(views) == 1, proc.stdout
    opts = views[0].split("draws it: ")[1].split(" --time")[0]
    assert re.fullmatch(r"--at -?[0-9.]+,-?[0-9.]+,-?[0-9.]+ --angle -?[0-9.]+ --look -?[0-9]+", opts), opts
    shot = shots / "emu-shot-000.png"
    assert shot.exists() and f"wrote {shot}" in proc.stdout, proc.stdout
    # build/render draws the same view from those options
    w, h, pixels, _ = read_png_indexed(shot)
    out = tmp_path / "again.png"
    wrote = [line for line in proc.stdout.splitlines() if line.startswith(f"emu: wrote {shot}: ")][0]
    shot_opts = wrote.split(": ", 2)[2].split()
    r = subprocess.run([str(BUILD / "render"), str(ROOT / "tests/scenes/default.scene"), *shot_opts, "-o", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert read_png_indexed(out)[2] == pixels


def test_help_lists_the_keys():
    proc = subprocess.run([str(BUILD / "emu"), "--help"], capture_output=True, text=True)
    assert "V print the camera" in proc.stdout and "S or F12 save a screenshot" in proc.stdout


def test_make_help_says_what_make_run_walks():
    """`make help` names the scene `make run` walks: freedoom2.wad:MAP01 when the WAD is installed
    (the Makefile's run rule looks for it first), the built-in scene only without it."""
    out = subprocess.run(["make", "-s", "--no-print-directory", "help"], cwd=ROOT, capture_output=True, text=True,
                         timeout=60).stdout
    line = next(l for l in out.splitlines() if l.startswith("make run "))
    assert "freedoom2.wad:MAP01" in line, line
    rule = (ROOT / "Makefile").read_text()
    assert "scene=freedoom2.wad:MAP01" in rule
