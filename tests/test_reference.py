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

from conftest import ROOT, freedoom, program, run, write_pwad_map

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

def make_wad(path, things=None):
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
    things = struct.pack("<hhhHH", 64, 128, 0, 1, 7) + (things or b"")
    vertexes = b"".join(struct.pack("<hh", x, y) for x, y in verts)
    write_pwad_map(path, things, linedefs, sides, vertexes, sectors)


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
    from PIL import Image
    with Image.open(png) as im:   # the false-colour picture of exactly these ids
        assert (im.mode, im.size) == ("RGB", (320, 200))
        assert (np.asarray(im) == refrender.false_colour(a)).all()
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


# ---- objects (docs/objects.md) --------------------------------------------------------------

OBJ = 4 << 24
BOX_ROOM = ROOM.replace("player 128 128 0\n", "") + """\
model crate
part box w=32 d=32 h=32
end
model tri
part prism sides=4 r={r} h=32
end
model stack
part box w=32 d=32 h=16
part box w=32 d=32 h=16 at=0,0,16
end
object crate 128 128
player 32 128 0
"""


@pytest.fixture
def box_room(tmp_path):
    path = tmp_path / "box.scene"
    path.write_text(BOX_ROOM.format(r=16 * math.sqrt(2)))
    return str(path)


def silhouette(ids, obj=0):
    rows, cols = np.nonzero(ids == OBJ | obj)
    return rows.min(), rows.max(), cols.min(), cols.max(), rows.size


def test_box_straight_ahead(box_room):
    """A 32-unit crate on the floor, its near face 80 units ahead (x 112..144, y 112..144, eye at
    (32, 128, 41)). Columns: the near face spans +-16 units at depth 80, xv in [-0.2, 0.2], pixel
    centres 127.5..191.5: columns 128..191. Rows: the top face is seen from above; its far edge at
    depth 112, 9 units below the eye, is at row centre 100 + 160 * 9 / 112 = 112.86 (first row
    113); the near face's bottom edge at depth 80, 41 below, at 100 + 82 = 182.0, a centre exactly
    on the edge, which the top-left rule gives to the floor below (last row 181). Row 113's centre
    (113.5) meets the top face at depth 9 * 160 / 13.5 = 106.67, where its +-16 units are +-24
    pixels: columns 136..183."""
    ids = refrender.render_ids(box_room, 32, 128, angle=0)
    top, bottom, left, right, n = silhouette(ids)
    assert (top, bottom, left, right) == (113, 181, 128, 191)
    assert (ids[118:182, 128:192] == OBJ).all()          # the near face: rows 118..181
    row = np.nonzero(ids[113] == OBJ)[0]
    assert (row.min(), row.max()) == (136, 183)
    assert ids[182, 160] == FLOOR | 0 and ids[112, 160] == WALL | 4
    # the same object seen from the far side of the room: mirrored; without objects: no object
    back = refrender.render_ids(box_room, 224, 128, angle=180)
    assert silhouette(back)[:4] == (113, 181, 128, 191)
    assert not (refrender.render_ids(box_room, 32, 128, angle=0, objects=[]) >> 24 == 4).any()


def test_objects_argument_and_order(box_room):
    """objects= replaces the scene's: tuples or build/render's JSON dicts; ids are the list
    positions; the nearer object hides the farther one wherever they overlap."""
    near = (0, 80, 128, 0, 0)                       # near face at x 64: depth 32
    far = {"model": 0, "x": 200, "y": 140, "z": 0, "yaw": 0}
    ids = refrender.render_ids(box_room, 32, 128, angle=0, objects=[far, near])
    # at depth 32 the near crate's face spans +-16 / 32 * 160 = 80 pixels: columns 80..239
    assert silhouette(ids, 1)[2:4] == (80, 239)
    # the far crate (depth 152..184) shows only above the near one: rows whose ray passes over
    # the near crate's top (32 units up, 9 below the eye: row centre < 100 + 160 * 9 / 64 = 122.5)
    rows = np.nonzero((ids == OBJ | 0).any(axis=1))[0]
    assert rows.size and rows.max() < 123
    assert (ids == OBJ | 0).sum() < (refrender.render_ids(box_room, 32, 128, angle=0,
                                                           objects=[far]) == OBJ).sum()


def test_prism_and_yaw(box_room):
    """A square prism of circumradius 16 sqrt 2 turned by 45 degrees is the crate (up to the
    rounding of its vertices to 16.16); a crate turned by 90 degrees is itself."""
    ref = refrender.render_ids(box_room, 32, 128, angle=0)
    prism = refrender.render_ids(box_room, 32, 128, angle=0, objects=[(1, 128, 128, 0, 45)])
    assert (prism != ref).sum() <= 4
    turned = refrender.render_ids(box_room, 32, 128, angle=0, objects=[(0, 128, 128, 0, 90)])
    assert (turned == ref).all()
    # a yaw of 45: the crate's corner points at the eye; its silhouette is sqrt 2 wider, the
    # corner edge nearest at depth 96 - 16 sqrt 2, the side corners at depth 96, +-22.63 units:
    # +-37.71 pixels, centres 122.29..197.71: columns 122..197
    diag = refrender.render_ids(box_room, 32, 128, angle=0, objects=[(0, 128, 128, 0, 45)])
    assert silhouette(diag)[2:4] == (122, 197)


def test_multi_part_model(box_room):
    """Two stacked boxes are one object: the same silhouette and id as the 32-unit crate."""
    ref = refrender.render_ids(box_room, 32, 128, angle=0)
    stack = refrender.render_ids(box_room, 32, 128, angle=0, objects=[(2, 128, 128, 0, 0)])
    assert (stack == ref).all()


def test_eye_inside_near_plane_and_behind_walls(box_room):
    """An eye inside a crate sees none of it (its faces are all back faces); a crate behind the
    eye or outside the room (beyond the east wall) is not drawn."""
    inside = refrender.render_ids(box_room, 128, 128, 20, angle=0)
    assert not (inside >> 24 == 4).any()
    behind = refrender.render_ids(box_room, 200, 128, angle=0, objects=[(0, 150, 128, 0, 0)])
    assert not (behind >> 24 == 4).any()
    outside = refrender.render_ids(box_room, 32, 128, angle=0, objects=[(0, 300, 128, 0, 0)])
    assert not (outside >> 24 == 4).any()
    # a crate 16.5 units ahead: on the centre column its near face from row 187 (its top edge,
    # 9 below the eye, at row centre 100 + 160 * 9 / 16.5 = 187.3), its top face up to row 130
    # (the far edge: 100 + 160 * 9 / 48.5 = 129.7), and the east wall above that (row 129
    # reaches it 160.5 ahead, 41 - 160.5 * 29.5 / 160 = 11.4 units up)
    close = refrender.render_ids(box_room, 95.5, 128, angle=0)
    assert (close[130:, 160] == OBJ).all() and close[129, 160] == WALL | 4


def test_object_states_paths(tmp_path):
    """Paths as docs/objects.md defines them: a circle of radius 100 and period 4000 ms at
    t = 1000 is a quarter turn (origin at centre + (0, 100), facing west: yaw 180); a line path
    at a quarter period is half way out; spin adds degrees per second; z is the floor."""
    scene = tmp_path / "paths.scene"
    scene.write_text(ROOM.replace("ceil=128", "ceil=128").replace("player 128 128 0\n", "") + """\
model m
part box w=8 d=8 h=8
end
object m 128 128 path=circle:100:4000
object m 50 60 z=10 yaw=5 path=line:40:-20:2000 spin=90
player 32 32 0
""")
    s = refrender.object_states(str(scene), 1000)
    assert s[0][0] == 0 and s[0][1:4] == pytest.approx((128, 228, 0)) and s[0][4] == pytest.approx(180)
    assert s[1][1:] == pytest.approx((90, 40, 10, 5 + 90))           # at the far end
    s = refrender.object_states(str(scene), 500)
    assert s[1][1:3] == pytest.approx((70, 50)) and s[0][1:3] == pytest.approx((128 + 50 * 2 ** .5,
                                                                                128 + 50 * 2 ** .5))
    assert refrender.object_states(str(scene), 4000)[0][1:3] == pytest.approx((228, 128))


def test_door_ceilings(tmp_path):
    """A closed door (ceiling = floor) is a wall; given its open ceiling the room beyond shows."""
    scene = tmp_path / "door.scene"
    scene.write_text("""\
sector a floor=0 ceil=128
sector d floor=0 ceil=0 door=100
sector b floor=0 ceil=128
wall 0 0 0 128 a
wall 0 128 128 128 a
wall 128 128 128 80 a
wall 128 80 128 48 a d
wall 128 48 128 0 a
wall 128 0 0 0 a
wall 128 80 144 80 d
wall 144 80 144 48 d b
wall 144 48 128 48 d
wall 144 128 256 128 b
wall 256 128 256 0 b
wall 256 0 144 0 b
wall 144 0 144 48 b
wall 144 80 144 128 b
player 64 64 0
""")
    m = refrender.load(str(scene))
    assert list(m.open_h) == [128, 100, 128]
    shut = refrender.render_ids(str(scene), 20, 64, angle=0)
    assert shut[100, 160] == WALL | (3 * 2)
    open_ = refrender.render_ids(str(scene), 20, 64, angle=0, ceilings={"1": 100})
    assert open_[100, 160] == WALL | (10 * 2)                   # b's east wall through the door
    # the door's top, 59 above the eye at depth 108: rows whose centre is above
    # 100 - 160 * 59 / 108 = 12.6 see the upper step over it, the next the door's own ceiling
    assert (open_[:13, 160] == WALL | (3 * 2)).all() and open_[13, 160] == CEIL | 1


def test_object_statements_errors(tmp_path):
    bad = {"part box w=1 d=1 h=1\n": "part outside a model",
           "model m\npart cone r=1\nend\n": "box' or 'prism",
           "model m\npart prism sides=2 r=1 h=1\nend\n": "3..16",
           "object nosuch 1 1\n": "unknown model",
           "model m\npart box w=1 d=1 h=1\n": "no 'end'"}
    for text, msg in bad.items():
        path = tmp_path / "bad.scene"
        path.write_text(ROOM + text)
        refrender._cache.pop(str(path), None)
        with pytest.raises(ValueError, match=msg):
            refrender.load(str(path))


def test_wad_things_become_objects(tmp_path):
    """Things of tools/bspc/things.txt in skill 3 and not multiplayer-only are objects, in THINGS
    order, boxes of their radius and height on the floor under them (the alcove's is 32 up); the
    compiled scene has the same objects, and build/render draws them where the reference does."""
    table = refrender.read_things_table()
    r, h, _ = table[3004]
    things = (struct.pack("<hhhHH", 160, 100, 90, 3004, 7)         # object 0, yaw 90
              + struct.pack("<hhhHH", 160, 160, 0, 3004, 1)        # skill 1 only: left out
              + struct.pack("<hhhHH", 160, 60, 0, 3004, 7 | 0x10)  # multiplayer only: left out
              + struct.pack("<hhhHH", 288, 128, 45, 3004, 2)       # object 1, in the alcove
              + struct.pack("<hhhHH", 100, 100, 0, 11, 7))         # a deathmatch start: not one
    wad = tmp_path / "things.wad"
    make_wad(wad, things)
    spec = f"{wad}:MAP01"
    m = refrender.load(spec)
    assert len(m.models) == 1 and len(m.objects) == 2
    verts = m.models[0].parts[0][0]
    assert verts.min(axis=0).tolist() == [-r, -r, 0] and verts.max(axis=0).tolist() == [r, r, h]
    states = refrender.object_states(spec, 0)
    assert states == [(0, 160, 100, 0, 90), (0, 288, 128, 32, 45)]
    out = tmp_path / "c.bin"
    j = json.loads(run([program("render"), spec, "--at", "32,128", "--angle", "0", "--ids", out]).stdout)
    assert [(o["model"], o["x"], o["y"], o["z"], o["yaw"]) for o in j["objects"]] == states
    ids = refrender.render_ids(spec, 32, 128, angle=0)
    assert OBJ | 0 in ids and OBJ | 1 in ids
    assert accuracy.differ(ids, accuracy.read_ids(out)) < 0.005
