"""The float reference renderer (tools/refrender.py) and the id-buffer comparison (tools/accuracy.py).

The reference is checked on cases worked out by hand (a square room seen from its centre: which
wall fills which half of the screen, and the rows where the ceiling, wall and floor meet, from the
camera model), on its eye-sector lookup, on reading WAD maps numbered as bspc numbers them, and
against build/render on a few views. accuracy.py is checked on synthetic buffers.
"""
import json
import math
import struct
import sys

import numpy as np
import pytest

from conftest import ROOT, freedoom, program, run

sys.path.insert(0, str(ROOT / "tools"))
import accuracy  # noqa: E402
import refrender  # noqa: E402

PY = sys.executable
DEFAULT = str(ROOT / "tests" / "scenes" / "default.scene")
WALL, FLOOR, CEIL = 1 << 24, 2 << 24, 3 << 24

ROOM = """\
sector room floor=0 ceil=128
wall   0   0   0 256 room
wall   0 256 256 256 room
wall 256 256 256   0 room
wall 256   0   0   0 room
player 128 128 0
"""


@pytest.fixture
def room(tmp_path):
    path = tmp_path / "room.scene"
    path.write_text(ROOM)
    return str(path)


def expected_room_column(px, look=0):
    """Analytic ids of column px of the room seen from its centre at a diagonal angle: the wall
    128 units away straight ahead across, eye 41 above the floor, ceiling 87 above the eye.
    At 45 degrees off the walls, a ray with xv sees its wall at forward depth
    t = 128 * sqrt(2) / (1 + |xv|); row py is ceiling while (100 + look - py - 0.5) / 160 * t > 87,
    floor while it is < -41."""
    xv = (px + 0.5 - 160) / 160
    t = 128 * math.sqrt(2) / (1 + abs(xv))
    top = max(0, math.ceil(99.5 + look - 160 * 87 / t))            # first wall row
    bottom = min(199, math.floor(99.5 + look + 160 * 41 / t))       # last wall row
    return top, bottom


@pytest.mark.parametrize("k", range(4))
def test_square_room_diagonal_views(room, k):
    """Facing a corner, the left half of the screen is one wall, the right half the next one
    clockwise; ceiling above and floor below the wall at the rows the camera model gives."""
    ids = refrender.render_ids(room, 128, 128, angle=45 + 90 * k)
    assert ids.shape == (200, 320) and ids.dtype == np.uint32
    left, right = (1 - k) % 4, (2 - k) % 4          # wall numbers; the room is on their front
    for px in range(320):
        wall = left if px < 160 else right
        top, bottom = expected_room_column(px)
        col = ids[:, px]
        assert (col[:top] == CEIL | 0).all(), px
        assert (col[top:bottom + 1] == WALL | (2 * wall)).all(), px
        assert (col[bottom + 1:] == FLOOR | 0).all(), px


def test_square_room_hand_figures(room):
    """A few of the rows worked out by hand: the centre column sees the corner at forward depth
    128*sqrt(2)/(1 + 1/320) = 180.45: ceiling rows 0..22, floor rows 136..199; the edge column
    (depth 90.65) has no ceiling and floor from row 172."""
    ids = refrender.render_ids(room, 128, 128, angle=45)
    col = ids[:, 159] >> 24
    assert (col[:23] == 3).all() and col[23] == 1 and col[135] == 1 and (col[136:] == 2).all()
    col = ids[:, 0] >> 24
    assert (col[:172] == 1).all() and (col[172:] == 2).all()


def test_square_room_look_and_straight_ahead(room):
    """Looking up 30 pixels moves every boundary 30 rows down; facing east the whole width is
    the east wall (its ends are at +-45 degrees, beyond the outermost pixel centres)."""
    base = refrender.render_ids(room, 128, 128, angle=45)
    up = refrender.render_ids(room, 128, 128, angle=45, look=30)
    for px in (0, 100, 159, 160, 319):
        top, bottom = expected_room_column(px, look=30)
        assert (up[top:bottom + 1, px] >> 24 == 1).all()
        assert (top == 0 or up[top - 1, px] == CEIL) and (bottom == 199 or up[bottom + 1, px] == FLOOR)
    assert (up[30:, :] == base[:-30, :]).all()
    east = refrender.render_ids(room, 128, 128, angle=0)
    assert set(np.unique(east[100])) == {WALL | 4}
    # eye height: the floor + 41 by default, absolute when given
    assert refrender.eye_height(room, 128, 128) == 41
    assert (refrender.render_ids(room, 128, 128, 41, angle=45) == base).all()


def test_eye_sector_lookup():
    cases = {(96, 160): 0, (576, 128): 1, (800, 200): 2, (160, 392): 3, (160, 500): 4,
             (256, -16): 5, (256, -48): 6, (160, -200): 7,
             (752, 320): None,       # inside the square pillar of the court
             (256, -160): None,      # inside the diamond pillar of the pit
             (-500, 0): None, (2000, 2000): None}
    for (x, y), sec in cases.items():
        assert refrender.sector_at(DEFAULT, x, y) == sec, (x, y)
        assert refrender.eye_sector(DEFAULT, x, y) == sec
    assert refrender.eye_height(DEFAULT, 576, 128) == 8 + 41
    assert refrender.eye_height(DEFAULT, -500, 0) == 41
    # on a wall or a vertex: one of the sectors that meet there, and no crash
    assert refrender.sector_at(DEFAULT, 512, 128) in (0, 1)
    assert refrender.sector_at(DEFAULT, 512, 64) in (0, 1, None)
    assert refrender.sector_at(DEFAULT, 0, 0) in (0, None)


def test_eye_on_a_wall_or_vertex():
    """The eye exactly on the hall/corridor opening looking east sees the corridor's floor and
    ceiling; on a vertex, a full frame without holes."""
    ids = refrender.render_ids(DEFAULT, 512, 128, 49, angle=0)
    assert ids[199, 160] == FLOOR | 1 and ids[0, 160] == CEIL | 1
    assert (ids >> 24 != 0).all()
    ids = refrender.render_ids(DEFAULT, 512, 192, angle=200)
    assert (ids >> 24 != 0).all()


def test_seen_from_the_back_side_and_outside():
    """The hall/corridor opening (wall 8, corridor on its front) seen from the hall is side 1;
    from outside the map one-sided walls are culled and there is no floor in none."""
    ids = refrender.render_ids(DEFAULT, 400, 128, angle=0)
    assert ids[199, 160] == FLOOR | 0                      # the hall's floor at one's feet
    assert WALL | (8 * 2 + 1) in ids[:, 160]               # the corridor's raised lower step
    assert WALL | (8 * 2) not in ids
    out = refrender.render_ids(DEFAULT, -200, 160, 41, angle=0)
    assert WALL | (7 * 2) not in out and WALL | (7 * 2 + 1) not in out  # the hall's west wall
    assert out[100, 160] == WALL | (13 * 2)     # through hall and corridor: the court's east wall
    # the ray enters the hall at x = 0, 200 units ahead: rows 0..4 above its ceiling (160) and
    # rows 133.. below its floor see the planes from behind: nothing
    assert (out[:5, 160] == 0).all() and (out[133:, 160] == 0).all()
    assert out[5, 160] == CEIL | 0 and out[132, 160] == FLOOR | 0


SKY_STEP = """\
sector yard floor=0 ceil=256 {sky}
sector low  floor=0 ceil=128 sky
wall   0   0   0 256 yard
wall   0 256 256 256 yard
wall 256 256 256   0 yard low
wall 256   0   0   0 yard
wall 256 256 384 256 low
wall 384 256 384   0 low
wall 384   0 256   0 low
player 128 128 0
"""


def test_sky_rule(tmp_path):
    """Between two sky ceilings there is no upper wall: from the high yard (eye 100 units up, the
    step 128 units ahead) rows 0..64 of the centre column go over the step (height > 128 there)
    and see sky at once; without the yard's sky they see the upper wall (wall 2, front)."""
    sky, plain = tmp_path / "sky.scene", tmp_path / "plain.scene"
    sky.write_text(SKY_STEP.format(sky="sky"))
    plain.write_text(SKY_STEP.format(sky=""))
    far = refrender.render_ids(str(sky), 128, 128, 100, angle=0, sky_owner="far")
    near = refrender.render_ids(str(sky), 128, 128, 100, angle=0)
    wall = refrender.render_ids(str(plain), 128, 128, 100, angle=0)
    assert (far[:65, 160] == CEIL | 1).all() and (near[:65, 160] == CEIL | 0).all()
    assert (wall[:65, 160] == WALL | 4).all()
    for ids in (far, near, wall):           # below the step: into the low sector, its far wall
        assert ids[100, 160] == WALL | (5 * 2) and ids[199, 160] == FLOOR | 1
    assert (far[65:] == near[65:]).all()


def test_text_scene_numbers_are_rounded_like_bspc(tmp_path):
    assert refrender.fx_round("0.5") == 0.5
    assert refrender.fx_round("100.25") == 100.25
    assert refrender.fx_round("0.00000762939453125") == 1 / 65536       # exactly half a step: up
    assert refrender.fx_round("-0.00000762939453125") == -1 / 65536     # ties away from zero
    assert refrender.fx_round("0.0000076") == 0
    m = refrender.load(DEFAULT)
    assert m.nlines == 55 and m.nsectors == 8
    assert (m.front[8], m.back[8]) == (1, 0) and m.back[0] == -1 and m.sky[2]


def test_freedoom_map01_linedefs_numbered_like_bspc():
    freedoom("freedoom2.wad")
    proc = run([program("bspc", sanitized=False), "freedoom2.wad:MAP01", "--stats", "-o", "/dev/null"])
    m = refrender.load("freedoom2.wad:MAP01")
    assert m.nlines == json.loads(proc.stdout)["input_walls"] == 1069
    assert m.player == (-192.0, -160.0, 0.0)
    assert refrender.sector_at(m, -192, -160) is not None


# ---- a hand-made WAD: a room with an alcove, a zero-length linedef, a back sidedef ----------

def make_wad(path):
    """PWAD with MAP01: room (sector 0) 256x256, alcove (sector 1, raised floor, lowered
    ceiling) east of it behind a two-sided linedef whose front (sidedef 0) is the alcove.
    Linedef 2 has zero length (two vertices at one point): bspc skips it, so the two-sided
    linedef 4 is wall 3 and the alcove's back wall, linedef 8, is wall 7."""
    verts = [(0, 0), (0, 256), (256, 256), (256, 160), (256, 96), (256, 0), (320, 160), (320, 96),
             (0, 256)]
    ROOM_S, ALC_S = 0, 1
    lines = [  # v1, v2, front sector, back sector
        (0, 1, ROOM_S, None), (1, 2, ROOM_S, None), (1, 8, ROOM_S, None), (2, 3, ROOM_S, None),
        (4, 3, ALC_S, ROOM_S), (4, 5, ROOM_S, None), (5, 0, ROOM_S, None),
        (3, 6, ALC_S, None), (6, 7, ALC_S, None), (7, 4, ALC_S, None)]
    sides, linedefs = b"", b""
    for i, (v1, v2, f, b) in enumerate(lines):
        ids = []
        for sec in (f, b):
            if sec is None:
                ids.append(0xFFFF)
                continue
            ids.append(len(sides) // 30)
            sides += struct.pack("<hh8s8s8sH", 0, 0, b"-", b"-", b"STARTAN3", sec)
        linedefs += struct.pack("<HHHHHHH", v1, v2, 4 if b is not None else 1, 0, 0, *ids)
    sectors = struct.pack("<hh8s8shhh", 0, 128, b"FLOOR4_8", b"CEIL3_5", 160, 0, 0) + \
        struct.pack("<hh8s8shhh", 32, 96, b"FLOOR4_8", b"CEIL3_5", 160, 0, 0)
    things = struct.pack("<hhhHH", 64, 128, 0, 1, 7)
    vertexes = b"".join(struct.pack("<hh", x, y) for x, y in verts)
    lumps = [(b"MAP01", b""), (b"THINGS", things), (b"LINEDEFS", linedefs), (b"SIDEDEFS", sides),
             (b"VERTEXES", vertexes), (b"SECTORS", sectors)]
    body, directory, pos = b"", b"", 12
    for name, data in lumps:
        directory += struct.pack("<II8s", pos, len(data), name)
        body += data
        pos += len(data)
    path.write_bytes(b"PWAD" + struct.pack("<II", len(lumps), pos) + body + directory)


def test_hand_made_wad_numbering(tmp_path):
    wad = tmp_path / "t.wad"
    make_wad(wad)
    spec = f"{wad}:MAP01"
    m = refrender.load(spec)
    proc = run([program("bspc", sanitized=False), spec, "--stats", "-o", "/dev/null"])
    assert m.nlines == json.loads(proc.stdout)["input_walls"] == 9
    assert (m.front[3], m.back[3]) == (1, 0)
    ids = refrender.render_ids(spec, 64, 128, angle=0)
    assert ids[100, 160] == WALL | (7 * 2)          # the alcove's back wall, through the opening
    assert ids[40, 160] == WALL | (3 * 2 + 1)       # the opening's upper step, its back side
    assert ids[60, 160] == CEIL | 1                 # the alcove's ceiling, through the opening
    assert ids[130, 160] == WALL | (3 * 2 + 1)      # and its lower step
    assert ids[199, 160] == FLOOR | 0 and ids[0, 160] == CEIL | 0
    # build/render draws the same ids
    out = tmp_path / "c.bin"
    run([program("render"), spec, "--at", "64,128", "--angle", "0", "--ids", out])
    c = accuracy.read_ids(out)
    assert accuracy.differ(ids, c) < 0.005
    assert accuracy.walls_matched(ids, c) >= 0.995


VIEWS = [(DEFAULT, "96,160", "20"), (DEFAULT, "600,128", "0"), (DEFAULT, "256,-200", "90"),
         ("freedoom2.wad:MAP01", "-192,-160", "0"), ("freedoom2.wad:MAP01", "300,200", "45"),
         ("freedoom2.wad:MAP01", "1561,886", "271")]             # sky over a missing upper wall


@pytest.mark.parametrize("scene,at,angle", VIEWS)
def test_agrees_with_build_render(tmp_path, scene, at, angle):
    """Where build/render shows a wall, the reference shows the same wall (>= 99.5%), and the
    whole frames agree on >= 99.5% of the pixels (the sky over a missing upper wall counted as
    the near sector's ceiling, as build/render draws it)."""
    if scene.endswith("MAP01"):
        freedoom("freedoom2.wad")
    out = tmp_path / "c.bin"
    cam = json.loads(run([program("render", sanitized=False), scene, "--at", at, "--angle", angle,
                          "--ids", out]).stdout)["camera"]
    c = accuracy.read_ids(out)
    x, y = at.split(",")
    ref = refrender.render_ids(scene, x, y, None, angle, sky_owner="near")
    assert cam["z"] == refrender.eye_height(scene, float(x), float(y))
    assert accuracy.walls_matched(ref, c) >= 0.995
    assert accuracy.differ(ref, c) <= 0.005


def test_cli(tmp_path):
    ids, png = tmp_path / "r.bin", tmp_path / "r.png"
    run([PY, ROOT / "tools" / "refrender.py", DEFAULT, "--at", "-100,160,41", "--angle", "0",
         "--ids", ids, "--png", png])
    assert ids.stat().st_size == 320 * 200 * 4
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    a = accuracy.read_ids(ids)
    assert (a == refrender.render_ids(DEFAULT, -100, 160, 41, 0)).all()
    run([PY, ROOT / "tools" / "refrender.py", DEFAULT, "--ids", ids])          # the player start
    assert (accuracy.read_ids(ids) == refrender.render_ids(DEFAULT, 96, 160, None, 20)).all()
    bad = run([PY, ROOT / "tools" / "refrender.py", tmp_path / "none.scene", "--ids", ids], check=False)
    assert bad.returncode == 1 and "none.scene" in bad.stderr


# ---- accuracy.py ----------------------------------------------------------------------------

def two_walls(edge):
    a = np.full((200, 320), WALL | 2, np.uint32)
    a[:, edge:] = WALL | 4
    a[:50] = CEIL | 0
    a[150:] = FLOOR | 0
    return a


def test_accuracy_identical():
    a = two_walls(100)
    r = accuracy.compare(a, a.copy())
    assert r["differ"] == 0 and r["edge_displacement"] == 0
    assert r["none_a"] == r["none_b"] == 0
    assert r["walls_a_matched"] == r["walls_b_matched"] == 1.0


def test_accuracy_shifted_edge():
    a, b = two_walls(100), two_walls(101)
    assert accuracy.edge_displacement(a, b) == 1
    assert accuracy.differ(a, b) == pytest.approx(100 / 64000)       # one column of 100 wall rows
    assert accuracy.edge_displacement(a, two_walls(107)) == 7
    assert accuracy.walls_matched(a, b) == pytest.approx(1 - 100 / 32000)   # 100 of 100x320


def test_accuracy_moved_horizontal_edge():
    """An edge between rows that moved down by one row is a displacement of 1, as one that moved
    sideways by one column is."""
    a = two_walls(100)
    b = a.copy()
    b[150] = a[149]                       # the walls reach one row lower in B
    assert accuracy.differ(a, b) == pytest.approx(320 / 64000)
    assert accuracy.edge_displacement(a, b) == 1
    b[150:153] = a[149]                   # three rows lower
    assert accuracy.edge_displacement(a, b) == 3


def test_accuracy_missing_edge_and_nothing():
    a = two_walls(100)
    b = a.copy()
    b[:, 100:] = WALL | 2                 # the second wall is gone from B: its edge has no match
    assert accuracy.edge_displacement(a, b) == 320
    c = a.copy()
    c[10, 5:8] = 0                        # a hole of three kind-0 pixels
    r = accuracy.compare(a, c)
    assert r["none_a"] == 0 and r["none_b"] == 3
    assert r["differ_pixels"] == 3 and r["edge_displacement"] == 320
    assert accuracy.edge_displacement(np.zeros((200, 320), np.uint32), np.zeros((200, 320), np.uint32)) == 0


def test_accuracy_cli(tmp_path):
    a, b = two_walls(100), two_walls(103)
    a.astype("<u4").tofile(tmp_path / "a.bin")
    b.astype("<u4").tofile(tmp_path / "b.bin")
    proc = run([PY, ROOT / "tools" / "accuracy.py", tmp_path / "a.bin", tmp_path / "b.bin", "--json"])
    r = json.loads(proc.stdout)
    assert r["edge_displacement"] == 3 and r["differ_pixels"] == 300 and r["none_a"] == 0
    proc = run([PY, ROOT / "tools" / "accuracy.py", tmp_path / "a.bin", tmp_path / "b.bin"])
    assert "edge displacement" in proc.stdout
    (tmp_path / "short.bin").write_bytes(b"\0" * 100)
    bad = run([PY, ROOT / "tools" / "accuracy.py", tmp_path / "short.bin", tmp_path / "b.bin"], check=False)
    assert bad.returncode == 1 and "short.bin" in bad.stderr
