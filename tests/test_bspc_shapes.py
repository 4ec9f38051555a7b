"""Rooms of every shape the compiler must take (issue 19): floor polygons beyond the renderer's 64
corners (a convex 65-gon, a 200-gon, a 2,000-wall star), nested rooms, and walls that cross.

Scenes are generated here in the text format (docs/scene-format.md). Where a scene compiles, its
frames in every render mode are checked against the float reference renderer (tools/refrender.py)
as tests/test_extreme.py does: no empty pixel where the reference sees a surface, and the share
of differing pixels and the edge displacement within the strict bounds. Where it is refused, the
one-line message is checked. Every compile and render runs the sanitized build (build/san).
"""
import math
import struct
import sys

import numpy as np
import pytest

from conftest import RENDER_MODES, ROOT, program, render, run, write_pwad_map

sys.path.insert(0, str(ROOT / "tools"))
import accuracy  # noqa: E402
import refrender  # noqa: E402

STRICT_DIFFER, STRICT_EDGE = 0.005, 1
HEAD = "sector a floor=0 ceil=128 floor_color=sand:7 ceil_color=grey:6\n"


def ring(points, sector="a"):
    """Walls round a clockwise ring of points, each a different shade so edges show in the ids."""
    n = len(points)
    return "".join(f"wall {x0} {y0} {x1} {y1} {sector} mid=red:{6 + k % 6}\n"
                   for k, ((x0, y0), (x1, y1)) in enumerate(zip(points, points[1:] + points[:1])))


def polygon(n, r, r_odd=None):
    """n corners clockwise on a circle of radius r (odd corners on r_odd: a star)."""
    pts = []
    for k in range(n):
        rk = r if r_odd is None or k % 2 == 0 else r_odd
        a = -2 * math.pi * k / n
        pts.append((round(rk * math.cos(a)), round(rk * math.sin(a))))
    return pts


def leaf_corners(blob):
    """The most corners of any leaf floor polygon in a compiled scene (firmware/scene_format.h:
    the header's section table starts at byte 44; scn_leaf is first_seg, num_segs, sector,
    first_pvert, num_pverts)."""
    off, count = struct.unpack_from("<II", blob, 44 + 8 * 5)  # SCN_SEC_LEAVES
    return max(struct.unpack_from("<5I", blob, off + 20 * i)[4] for i in range(count))


def check_frames(scene, views, tmp_path):
    """Each view in each mode against the reference: no holes, strict bounds."""
    failures = []
    for at, angle in views:
        x, y = at
        runs = {}
        for mode in RENDER_MODES:
            out = tmp_path / f"{mode}.ids"
            j = render(scene, "--mode", mode, "--ids", out, at=f"{x},{y}", angle=str(angle))
            runs[mode] = (j, np.frombuffer(out.read_bytes(), dtype="<u4").reshape(200, 320))
        z = float(runs["spans"][0]["camera"]["z"])
        ref = refrender.render_ids(scene, x, y, z, float(angle), 0)
        surface = (ref >> 24) != 0
        for mode, (j, ids) in runs.items():
            holes = int(np.count_nonzero(((ids >> 24) == 0) & surface))
            share = accuracy.differ(ref, ids)
            edge = accuracy.edge_displacement(ref, ids)
            if holes or share > STRICT_DIFFER or edge > STRICT_EDGE:
                failures.append(f"{scene} at {at} angle {angle} mode {mode}: {holes} empty pixels, "
                                f"differ {share:.5f}, edge displacement {edge}")
    assert not failures, "\n".join(failures)


def compile_ok(scene, tmp_path):
    out = tmp_path / "out.bsc"
    run([program("bspc"), scene, "-o", out])
    return out.read_bytes()


@pytest.mark.parametrize("name,points,views", [
    ("65-gon", polygon(65, 400), [((0, 0), 30), ((-300, 50), 0), ((200, -200), 135)]),
    ("200-gon", polygon(200, 600), [((0, 0), 200), ((-500, 0), 10), ((300, 300), 250)]),
    ("star", polygon(2000, 2000, 1999), [((0, 0), 45), ((-1800, 100), 5), ((1500, -900), 160)]),
])
def test_rooms_beyond_64_corners_compile_and_render(name, points, views, tmp_path):
    """Convex rooms of 65 and 200 walls and a star of 2,000 walls (its middle leaf had 141 corners)
    used to be refused ("floor polygon has N vertices, more than the renderer's 64"); their big
    leaves are now cut into pieces of at most 64 corners, and the frames match the reference."""
    scene = tmp_path / f"{name}.scene"
    scene.write_text(HEAD + ring(points) + "player 0 0 30\n")
    blob = compile_ok(scene, tmp_path)
    assert leaf_corners(blob) <= 64
    check_frames(str(scene), views, tmp_path)


def nested_squares(m, step=16):
    """m concentric square rooms, the outermost first; each wall between two rooms is two-sided,
    and the floors step by 8 so that every room edge shows. No wall crosses another."""
    lines = [f"sector s{i} floor={(i % 4) * 8} ceil=256 floor_color=sand:{4 + i % 8} ceil_color=grey:6\n"
             for i in range(m)]
    for i in range(m):
        h = step * (m - i)
        corners = [(-h, -h), (-h, h), (h, h), (h, -h)]  # clockwise
        for (x0, y0), (x1, y1) in zip(corners, corners[1:] + corners[:1]):
            if i == 0:
                lines.append(f"wall {x0} {y0} {x1} {y1} s0 mid=red:8\n")
            else:
                lines.append(f"wall {x0} {y0} {x1} {y1} s{i} s{i - 1} lower=red:7 upper=red:6 "
                             f"back_lower=red:5 back_upper=red:6\n")
    return "".join(lines) + "player 1 1 30\n"


def test_nested_rooms_compile_and_render(tmp_path):
    """150 concentric square rooms (1,196 wall sides) need 7,104 wall pieces: every partition cuts
    the rooms around it. The budget was 2 per side + 4,096 (6,488) and refused them with
    "walls that cross each other?"; it is now sides x (log2 sides + 2) + 4,096 (17,252)."""
    scene = tmp_path / "nested.scene"
    scene.write_text(nested_squares(150))
    compile_ok(scene, tmp_path)
    check_frames(str(scene), [((1, 1), 30), ((-1000, 700), 340), ((2300, -2300), 135)], tmp_path)


CROSSING = HEAD + """\
sector b floor=16 ceil=128 floor_color=green:7 ceil_color=grey:6
wall 0 0 0 512 a mid=red:8
wall 0 512 512 512 a mid=red:9
wall 512 512 512 0 a mid=red:10
wall 512 0 0 0 a mid=red:11
wall 400 100 400 300 b mid=blue:8
wall 400 300 600 300 b mid=blue:9
wall 600 300 600 100 b mid=blue:10
wall 600 100 400 100 b mid=blue:11
player 100 200 0
"""


def test_crossing_walls_are_refused(tmp_path):
    """The issue's example: a 512 x 512 room and a second room at (400,100)-(600,300) cutting
    through its east wall. It compiled, and rendered 1,462 empty pixels from (100, 200); it is
    refused naming both walls' lines and the first crossing point."""
    scene = tmp_path / "cross.scene"
    scene.write_text(CROSSING)
    proc = run([program("bspc"), scene, "-o", tmp_path / "out.bsc"], check=False)
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        f"bspc: {scene}:5: wall crosses the wall of line 8 at (512, 300)"], proc.stderr
    assert not (tmp_path / "out.bsc").exists()
    # build/render compiles text scenes with the same checks
    proc = run([program("render"), scene], check=False)
    assert proc.returncode != 0 and "wall crosses the wall of line 8 at (512, 300)" in proc.stderr


def test_walls_that_touch_or_divide_nothing_may_cross(tmp_path):
    """A corner on another wall touches it without crossing, and a wall with the same sector on
    both sides (Doom's trigger lines; freedoom2.wad MAP20's linedef 1647 crosses linedef 1575)
    divides nothing: both compile, and the frame matches the reference."""
    scene = tmp_path / "touch.scene"
    scene.write_text(HEAD + ring([(0, 0), (0, 512), (512, 512), (512, 0)]) +
                     "sector b floor=16 ceil=96 floor_color=green:7 ceil_color=grey:6\n" +
                     ring([(256, 0), (200, 100), (312, 100)], "b").replace(" b mid", " b a mid") +
                     "wall 100 300 400 300 a a\nwall 250 200 250 450 a a\nplayer 100 400 300\n")
    compile_ok(scene, tmp_path)
    check_frames(str(scene), [((100, 400), 300), ((450, 450), 225)], tmp_path)


def wad_two_rooms(path):
    """The crossing example as a PWAD: room 0 (linedefs 0-3) and room 1 (linedefs 4-7)."""
    rooms = [[(0, 0), (0, 512), (512, 512), (512, 0)], [(400, 100), (400, 300), (600, 300), (600, 100)]]
    verts = [v for r in rooms for v in r]
    linedefs = b"".join(struct.pack("<HHHHHHH", 4 * r + i, 4 * r + (i + 1) % 4, 1, 0, 0, 4 * r + i, 0xFFFF)
                        for r in range(2) for i in range(4))
    sides = b"".join(struct.pack("<hh8s8s8sH", 0, 0, b"-", b"-", b"STARTAN3", i // 4) for i in range(8))
    sectors = b"".join(struct.pack("<hh8s8shhh", f, 128, b"FLOOR4_8", b"CEIL3_5", 160, 0, 0) for f in (0, 16))
    things = struct.pack("<hhhHH", 100, 200, 0, 1, 7)
    write_pwad_map(path, things, linedefs, sides, b"".join(struct.pack("<hh", x, y) for x, y in verts), sectors)


def test_crossing_linedefs_in_a_wad_are_refused(tmp_path):
    wad = tmp_path / "cross.wad"
    wad_two_rooms(wad)
    proc = run([program("bspc"), f"{wad}:MAP01", "-o", tmp_path / "out.bsc"], check=False)
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        f"bspc: {wad}:MAP01: linedef 2 crosses linedef 5 at (512, 300)"], proc.stderr


def test_budget_overflow_says_what_it_is(tmp_path):
    """200 walls with the same sector on both sides crossing one another (accepted: they divide
    nothing) cut each other into ~10,000 pieces, beyond the budget of 404 sides x (9 + 2) + 4,096:
    the message names the budget, not a guess."""
    s = 4000
    walls = "".join(f"wall {40 + k * 39} 10 {47 + k * 39} {s - 10} a a\n"
                    f"wall 10 {43 + k * 39} {s - 10} {35 + k * 39} a a\n" for k in range(100))
    scene = tmp_path / "many.scene"
    scene.write_text(HEAD + ring([(0, 0), (0, s), (s, s), (s, 0)]) + walls + "player 5 5 45\n")
    proc = run([program("bspc"), scene, "-o", tmp_path / "out.bsc"], check=False)
    assert proc.returncode == 1, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "the tree cuts the 404 wall sides into more than 8540 pieces, the " \
        "compiler's budget (sides x (log2 sides + 2) + 4,096" in lines[0], proc.stderr
    assert "cross" not in lines[0].split("budget")[0], lines[0]
