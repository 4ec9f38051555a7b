"""WAD things drawn as sprites (docs/objects.md "Sprites") in the reference (tools/refrender.py,
tools/reflook.py), and build/render against it.

The reference on its own, on a PWAD built here: three sectors in a row along x (a room, a 32-unit
step across the whole width, a hall with a square pillar), its own PLAYPAL, COLORMAP (table t maps
colour c to (c + 8 t) mod 256, so a pixel's colour gives its table away), a wall texture and a flat,
and sprites whose patches are made here from known texel arrays: an imp (TROO, frame A) with five
lumps for eight rotations (A1, A2A8, A3A7, A4A6, A5: three of them shown mirrored), each image of
another width and with holes (columns with two posts, one post running past the image's height);
a lost soul (SKUL A0, full-bright: one image for every rotation); a barrel (BAR1) with rotations
1..7 only, which stays a box. The checks: the image at a depth of 160 (one texel per pixel) and 80
(two), pixel for pixel, against the texel arrays, holes showing the world behind; the cut at the
floor; the rotation picked from each of 8 directions and a mirrored lump flipped; a step and a
pillar between the eye and the sprite hiding exactly the pixels whose rays they block (worked out
here from the geometry); nothing nearer than 4 units; the objects' numbering and models; a later
lump of a name winning; the texel and light table of each sprite pixel.

Then build/render (modes direct and columns) against the reference on Freedoom views that
show sprites, ids and colours. These need a renderer that draws sprites.
"""
import json
import math
import struct
import sys

import numpy as np
import pytest

from conftest import ROOT, freedoom, program, run, wad_image

sys.path.insert(0, str(ROOT / "tools"))
import reflook  # noqa: E402
import refrender  # noqa: E402
import texcompare  # noqa: E402

OBJ = 4 << 24
IMP, SOUL, BARREL = 3001, 3006, 2035


# ---- patches made from texel arrays, and read back by hand --------------------------------

def make_patch(texels, opaque, left, top, overhang=()):
    """A patch lump of texels[u][v] where opaque[u][v]; each run of opaque texels in a column is
    a post. overhang: columns whose last post runs 3 texels past the image's height."""
    w, h = len(texels), len(texels[0])
    cols = []
    for u in range(w):
        col, v = b"", 0
        while v < h:
            if not opaque[u][v]:
                v += 1
                continue
            start = v
            while v < h and opaque[u][v]:
                v += 1
            data = bytes(texels[u][start:v])
            if v == h and u in overhang:
                data += bytes([77, 77, 77])
            col += bytes([start, len(data), 0]) + data + b"\0"
        cols.append(col + b"\xff")
    head = struct.pack("<hhhh", w, h, left, top)
    table, body, at = b"", b"", 8 + 4 * w
    for c in cols:
        table += struct.pack("<I", at + len(body))
        body += c
    return head + table + body


def decode_patch(data):
    """By hand: (width, height, left, top, texels[u][v] or None where no post covers it)."""
    w, h, left, top = struct.unpack_from("<hhhh", data)
    pic = [[None] * h for _ in range(w)]
    for u in range(w):
        at = struct.unpack_from("<I", data, 8 + 4 * u)[0]
        while data[at] != 0xFF:
            row, n = data[at], data[at + 1]
            for k in range(n):
                if row + k < h:
                    pic[u][row + k] = data[at + 3 + k]
            at += n + 4
    return w, h, left, top, pic


def image(w, h, seed):
    """Texels and opacity of a w x h image: texel 1 + (u * 7 + v * 3 + seed) % 200; holes: a
    diagonal band, a hole in the middle of column 2 (two posts), and the top-right corner."""
    texels = [[1 + (u * 7 + v * 3 + seed) % 200 for v in range(h)] for u in range(w)]
    opaque = [[not ((u + v + seed) % 9 == 0 or (u == 2 and h // 3 <= v < h // 2)
                    or (u >= w - 3 and v < 3)) for v in range(h)] for u in range(w)]
    return texels, opaque


# The imp's five lumps: (name, width, height, left, top); heights past top reach below the floor.
IMP_LUMPS = [("TROOA1", 20, 40, 9, 37), ("TROOA2A8", 22, 40, 10, 37), ("TROOA3A7", 24, 40, 12, 37),
             ("TROOA4A6", 26, 40, 14, 37), ("TROOA5", 28, 40, 13, 37)]
SOUL_LUMP = ("SKULA0", 16, 18, 8, 30)
BARREL_LUMPS = [(f"BAR1A{r}", 12, 20, 6, 20) for r in range(1, 8)]     # no rotation 8: a box


def sprite_lumps():
    """[(name, bytes)] and {name: (texels, opaque, left, top)} of the sprites."""
    lumps, known = [], {}
    for k, (name, w, h, left, top) in enumerate(IMP_LUMPS + [SOUL_LUMP] + BARREL_LUMPS):
        tx, op = image(w, h, k)
        known[name] = (tx, op, left, top)
        lumps.append((name, make_patch(tx, op, left, top, overhang=(1, w - 2))))
    return lumps, known


# ---- the PWAD -----------------------------------------------------------------------------

ROOM_LIGHT, STEP_LIGHT, HALL_LIGHT = 112, 160, 208
PILLAR = (500, 520, -140, -104)   # x0, x1, y0, y1


def map_lumps(things):
    """Room (sector 0) x 0..400, step (1) x 400..440 floor 32, hall (2) x 440..1024, all
    y -256..256, ceilings 256; a square pillar (no sector) in the hall."""
    v = [(0, -256), (0, 256), (400, 256), (400, -256), (440, 256), (440, -256), (1024, 256),
         (1024, -256)]
    x0, x1, y0, y1 = PILLAR
    v += [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    lines = [(0, 1, 0, None), (1, 2, 0, None), (3, 0, 0, None), (2, 3, 0, 1),       # room
             (2, 4, 1, None), (5, 3, 1, None), (4, 5, 1, 2),                         # step
             (4, 6, 2, None), (6, 7, 2, None), (7, 5, 2, None),                      # hall
             (8, 9, 2, None), (9, 10, 2, None), (10, 11, 2, None), (11, 8, 2, None)]  # pillar
    sides, linedefs = b"", b""
    for a, b, f, bk in lines:
        ids = []
        for sec in (f, bk):
            if sec is None:
                ids.append(0xFFFF)
                continue
            ids.append(len(sides) // 30)
            two = bk is not None
            sides += struct.pack("<hh8s8s8sH", 0, 0, b"-", b"WALLT" if two else b"-",
                                 b"-" if two else b"WALLT", sec)
        linedefs += struct.pack("<HHHHHHH", a, b, 4 if bk is not None else 1, 0, 0, *ids)
    sectors = b"".join(struct.pack("<hh8s8shhh", f, 256, b"FLOORA", b"FLOORA", light, 0, 0)
                       for f, light in ((0, ROOM_LIGHT), (32, STEP_LIGHT), (0, HALL_LIGHT)))
    return [("MAP01", b""), ("THINGS", things), ("LINEDEFS", linedefs), ("SIDEDEFS", sides),
            ("VERTEXES", b"".join(struct.pack("<hh", x, y) for x, y in v)), ("SECTORS", sectors)]


def thing(x, y, angle, typ, flags=7):
    return struct.pack("<hhhHH", x, y, angle, typ, flags)


# object 0: an imp in the hall facing west; 1: a lost soul in the room; 2: a barrel in the hall;
# (a deathmatch start and a skill-1 imp are not objects); 3: a second imp in the room
THINGS = (thing(100, 0, 0, 1) + thing(560, -100, 180, IMP) + thing(50, 200, 0, 11)
          + thing(200, 200, 90, SOUL) + thing(900, 150, 0, BARREL) + thing(600, 0, 0, IMP, 1)
          + thing(200, -200, 0, IMP))


def look_lumps():
    playpal = bytes((c * 3 + k) % 256 for _ in range(14) for c in range(256) for k in range(3))
    colormap = bytes((c + 8 * t) % 256 for t in range(34) for c in range(256))
    wall = make_patch([[(u + v) % 256 for v in range(64)] for u in range(64)],
                      [[True] * 64 for _ in range(64)], 0, 0)
    pnames = struct.pack("<i8s", 1, b"WALLP")
    texture1 = struct.pack("<ii", 1, 8) + struct.pack("<8sihhihh", b"WALLT", 0, 64, 64, 0, 1, 0) \
        + struct.pack("<hhhhh", 0, 0, 0, 1, 0)
    return [("PLAYPAL", playpal), ("COLORMAP", colormap), ("PNAMES", pnames),
            ("TEXTURE1", texture1), ("WALLP", wall), ("F_START", b""), ("FLOORA", bytes(range(64)) * 64),
            ("F_END", b"")]


@pytest.fixture(scope="module")
def pwad(tmp_path_factory):
    """(spec, {lump name: (texels, opaque, left, top)}): the PWAD, with an early TROOA5 that the
    later one of the name replaces."""
    spr, known = sprite_lumps()
    decoy = make_patch([[9] * 40 for _ in range(28)], [[True] * 40 for _ in range(28)], 13, 37)
    lumps = (map_lumps(THINGS) + look_lumps() + [("S_START", b""), ("TROOA5", decoy)] + spr
             + [("S_END", b"")])
    path = tmp_path_factory.mktemp("sprites") / "sprites.wad"
    path.write_bytes(wad_image(lumps))
    return f"{path}:MAP01", known


def expected_image(known, name, mirrored=False):
    """(opaque (w, h) bool, texels (w, h)) of a lump, decoded by hand from its bytes."""
    tx, op, left, top = known[name]
    w, h, l2, t2, pic = decode_patch(make_patch(tx, op, left, top, overhang=(1, len(tx) - 2)))
    assert (w, h, l2, t2) == (len(tx), len(tx[0]), left, top)
    opaque = np.array([[p is not None for p in col] for col in pic])
    texels = np.array([[p or 0 for p in col] for col in pic])
    if mirrored:
        opaque, texels = opaque[::-1], texels[::-1]
    return opaque, texels, left, top


# ---- the reference on its own -------------------------------------------------------------

def test_objects_models_and_sets(pwad):
    """Objects in THINGS order; the imp and the lost soul have sprite sets (the soul's one image
    for all 8 rotations, full-bright), the barrel (7 of 8 rotations) none; a sprite thing's box
    is its images' (radius the largest of left and width - left, height the largest top), the
    barrel's things.txt's; as bspc --flat compiles it, every thing is its things.txt box."""
    spec, _ = pwad
    m = refrender.load(spec)
    assert m.textured
    assert [(o.x, o.y) for o in m.objects] == [(560, -100), (200, 200), (900, 150), (200, -200)]
    imp, soul, barrel, imp2 = m.sprites
    assert barrel is None and imp2 is imp
    assert [im.name for im, _ in imp.images] == ["TROOA1", "TROOA2A8", "TROOA3A7", "TROOA4A6",
                                                 "TROOA5", "TROOA4A6", "TROOA3A7", "TROOA2A8"]
    assert [mir for _, mir in imp.images] == [False] * 5 + [True] * 3
    assert not imp.bright and soul.bright and {im.name for im, _ in soul.images} == {"SKULA0"}
    assert (imp.radius, imp.height) == (max(max(l, w - l) for _, w, _, l, _ in IMP_LUMPS), 37)
    assert (soul.radius, soul.height) == (8, 30)
    table = refrender.read_things_table()
    sizes = [(p[0].max(axis=0)[0], p[0].max(axis=0)[2]) for mo in m.models for p in mo.parts]
    assert sizes == [(imp.radius, 37), (8, 30), (table[BARREL][0], table[BARREL][1])]
    assert [o.model for o in m.objects] == [0, 1, 2, 0]
    flat = refrender.load(spec, flat=True)
    assert not flat.textured and flat.sprites == [None] * 4
    assert [(p[0].max(axis=0)[0], p[0].max(axis=0)[2]) for mo in flat.models for p in mo.parts] == \
        [table[t][:2] for t in (IMP, SOUL, BARREL)]


def one_to_one(spec, obj, x, y, yaw, dist=160, z=None):
    """The view from dist units west of (x, y) looking east (eye height z, None: 41) with
    object obj (a JSON-style list: the others out of the map) at (x, y) on the room's floor."""
    objs = [{"model": 0, "x": x, "y": y, "z": 0, "yaw": yaw} if i == obj else
            {"model": 0, "x": -5000, "y": 0, "z": 0, "yaw": 0} for i in range(obj + 1)]
    return refrender.cast_view(spec, x - dist, y, z, 0, objects=objs)


@pytest.mark.parametrize("dist", [160, 80])
def test_image_against_hand_decoded_patch(pwad, dist):
    """At depth 160 one texel is one pixel, at 80 two by two: the image's top-left texel at
    pixel (160 - left s, 100 + (41 - top) s), s = 160 / depth (eye 41 above the floor). The sprite
    has exactly the pixels of opaque texels above the floor; its holes, its part below the floor
    and the overhanging posts show the world (the view without objects)."""
    spec, known = pwad
    s = 160 // dist
    v = one_to_one(spec, 0, 300, -100, 180, dist)           # seen from the front: TROOA1
    world = refrender.cast_view(spec, 300 - dist, -100, None, 0, objects=[]).ids
    opaque, texels, left, top = expected_image(known, "TROOA1")
    py0, px0 = 100 + 41 * s - top * s, 160 - left * s      # the image's top-left pixel
    want = world.copy()
    for u in range(opaque.shape[0]):
        for r in range(top):                                # rows below the origin: cut
            if opaque[u, r]:
                py, px = py0 + r * s, px0 + u * s
                want[py:py + s, px:px + s] = OBJ | 0
    assert (v.ids == want).all(), np.argwhere(v.ids != want)[:10]
    assert int(((v.ids >> 24) == 4).sum()) == s * s * int(opaque[:, :top].sum())
    assert v.sprites[0].image.name == "TROOA1" and v.sprites[0].zc == dist
    # the View's texel of each sprite pixel
    on = v.ids == OBJ
    py, px = np.nonzero(on)
    assert (v.spr_col[on] == (px - px0) // s).all()
    assert (v.spr_row[on] == (py - py0) // s).all()
    assert (texels[v.spr_col[on], v.spr_row[on]] > 0).all()
    assert (v.spr_col[~on] == -1).all()


def test_rotations_and_mirroring(pwad):
    """The imp (yaw 90, facing north) seen from 8 directions 160 units away: from direction
    phi = 45 k, theta - yaw + 202.5 = 45 k + 292.5, so r = (k + 6) mod 8 and Doom's rotation
    r + 1; rotations 6, 7, 8 show the lumps of 4, 3, 2 mirrored: the same rectangle, columns
    right to left."""
    spec, known = pwad
    lump_of = {1: ("TROOA1", False), 2: ("TROOA2A8", False), 3: ("TROOA3A7", False),
               4: ("TROOA4A6", False), 5: ("TROOA5", False), 6: ("TROOA4A6", True),
               7: ("TROOA3A7", True), 8: ("TROOA2A8", True)}
    ox, oy = 200, 0
    seen = set()
    for k in range(8):
        phi = 45 * k
        ex, ey = ox + 160 * math.cos(math.radians(phi)), oy + 160 * math.sin(math.radians(phi))
        objs = [{"model": 0, "x": ox, "y": oy, "z": 0, "yaw": 90}]
        v = refrender.cast_view(spec, ex, ey, None, (phi + 180) % 360, objects=objs)
        rot = (k + 6) % 8 + 1
        name, mirrored = lump_of[rot]
        d = v.sprites[0]
        assert (d.rotation + 1, d.image.name, d.mirrored) == (rot, name, mirrored), k
        opaque, _, left, top = expected_image(known, name, mirrored)
        got = np.zeros_like(opaque)
        sub = v.ids[141 - top:141, 160 - left:160 - left + opaque.shape[0]]
        got[:, :top] = (sub == OBJ).T
        assert (got[:, :top] == opaque[:, :top]).all(), (k, name, mirrored)
        assert int((v.ids == OBJ).sum()) == int(opaque[:, :top].sum())
        seen.add((name, mirrored))
    assert len(seen) == 8


def test_one_image_for_every_rotation_and_full_bright(pwad):
    """The lost soul's SKULA0 from any side; its pixels are light table 0 whatever its depth."""
    spec, known = pwad
    opaque, texels, left, top = expected_image(known, "SKULA0")
    for phi in (0, 100, 200, 300):
        ex, ey = 200 + 160 * math.cos(math.radians(phi)), 160 * math.sin(math.radians(phi))
        objs = [{"model": 0, "x": -5000, "y": 0, "z": 0, "yaw": 0},
                {"model": 1, "x": 200, "y": 0, "z": 0, "yaw": 30}]
        v = refrender.cast_view(spec, ex, ey, None, (phi + 180) % 360, objects=objs)
        assert v.sprites[1].image.name == "SKULA0" and not v.sprites[1].mirrored
        assert int((v.ids == OBJ | 1).sum()) == int(opaque[:, :top].sum())
        e = reflook.expect(v)
        on = v.ids == OBJ | 1
        assert (e.cat[on] == reflook.CAT_SPRITE).all() and (e.table[on] == 0).all()
        assert (e.colour[on] == texels[v.spr_col[on], v.spr_row[on]]).all()   # table 0: c


def pillar_blocks(xv, ex, ey, t_max):
    """Whether the 2-D ray from (ex, ey) along (1, -xv) (angle 0) crosses the pillar before
    depth t_max."""
    x0, x1, y0, y1 = PILLAR
    ta, tb = (x0 - ex), min(x1 - ex, t_max)                 # depths inside the x range
    if xv == 0:
        return y0 <= ey <= y1 and ta <= tb
    lo, hi = sorted(((ey - y0) / xv, (ey - y1) / xv))      # depths inside the y range
    return max(ta, lo) <= min(tb, hi)


def test_clipped_by_a_step_and_a_pillar(pwad):
    """The scene's imp (object 0, at (560, -100) facing west: TROOA1) from (380, -100) looking
    east: depth 180. Between them the step (floor 32 from x = 400 to 440) hides the rows whose
    ray is below 32 at x = 440 (41 + yv * 60 < 32), and the pillar (x 500..520, y -140..-104)
    the columns whose ray crosses it. Every other opaque texel above the floor is the sprite's;
    hidden ones show the step's riser or floor, or the pillar."""
    spec, known = pwad
    ex, ey = 380, -100
    v = refrender.cast_view(spec, ex, ey, None, 0)
    world = refrender.cast_view(spec, ex, ey, None, 0, objects=[])
    others = refrender.object_states(spec, 0)
    others[0] = (0, -5000, 0, 0, 0)                       # the imp moved out of the map
    rest = refrender.cast_view(spec, ex, ey, None, 0, objects=others).ids
    d = v.sprites[0]
    assert d.image.name == "TROOA1" and d.zc == 180 and d.xc == 0
    opaque, _, left, top = expected_image(known, "TROOA1")
    xv = (np.arange(320) + 0.5 + refrender.TIE_DX - 160) / 160
    yv = (100 - (np.arange(200) + 0.5 + refrender.TIE_DY)) / 160
    step_hidden = 41 + yv * (440 - ex) < 32
    pillar_hidden = np.array([pillar_blocks(c, ex, ey, 180) for c in xv])
    shown = hidden_step = hidden_pillar = 0
    for py in range(200):
        hgt = 41 + yv[py] * 180
        r = math.floor(top - hgt)
        for px in range(320):
            u = math.floor(xv[px] * 180 + left)
            on = 0 <= u < opaque.shape[0] and 0 <= r < opaque.shape[1] and hgt >= 0 and opaque[u, r]
            blocked = step_hidden[py] or pillar_hidden[px]
            assert (v.ids[py, px] == OBJ) == (on and not blocked), (py, px)
            if on and not blocked:
                shown += 1
            elif on:
                # what hides it: the step's riser (line 3, seen from the room: side 0) or its
                # floor (sector 1); the pillar's west or north face (lines 13, 12)
                assert world.t[py, px] < 180
                if step_hidden[py]:
                    assert v.ids[py, px] in (1 << 24 | 3 * 2, 2 << 24 | 1), (py, px)
                    hidden_step += 1
                else:
                    assert v.ids[py, px] in (1 << 24 | 13 * 2, 1 << 24 | 12 * 2), (py, px)
                    hidden_pillar += 1
    print(f"shown {shown}, behind the step {hidden_step}, behind the pillar {hidden_pillar}")
    assert shown > 100 and hidden_step > 50 and hidden_pillar > 50
    # elsewhere the view is the one without this sprite
    assert (v.ids[v.ids != OBJ] == rest[v.ids != OBJ]).all()


def test_nearer_than_4_units_is_not_drawn(pwad):
    """At depth 4 (the eye 20 above the floor: the image's rows 14..19 fill the screen) the
    sprite is drawn, at 3.9375 not at all."""
    spec, _ = pwad
    assert ((one_to_one(spec, 0, 300, -100, 180, 4, z=20).ids >> 24) == 4).sum() > 10000
    assert not ((one_to_one(spec, 0, 300, -100, 180, 3.9375, z=20).ids >> 24) == 4).any()


def test_a_box_where_the_sprite_is_not_usable(pwad):
    """The barrel (rotations 1..7 only) is its box: the same pixels as in the flat reading."""
    spec, _ = pwad
    v = refrender.cast_view(spec, 800, 150, None, 0)
    flat = refrender.cast_view(refrender.load(spec, flat=True), 800, 150, None, 0)
    mine = (v.ids == OBJ | 2) | (flat.ids == OBJ | 2)
    assert mine.sum() > 1500 and (v.ids[mine] == flat.ids[mine]).all()
    assert v.sprites[2] is None and (v.spr_col[v.ids == OBJ | 2] == -1).all()


def test_sprites_in_front_of_one_another(pwad):
    """Two imps (objects 0 and 3) on one line of sight: the nearer one's opaque texels win, the
    farther one shows through its holes; at one depth the lower object number wins."""
    spec, known = pwad
    far = {"model": 0, "x": 360, "y": -100, "z": 0, "yaw": 180}
    near = {"model": 0, "x": 300, "y": -100, "z": 0, "yaw": 180}
    out = {"model": 0, "x": -5000, "y": 0, "z": 0, "yaw": 0}
    v = refrender.cast_view(spec, 140, -100, None, 0, objects=[far, out, out, near])
    alone = refrender.cast_view(spec, 140, -100, None, 0, objects=[far]).ids
    front = one_to_one(spec, 3, 300, -100, 180).ids
    assert (front == OBJ | 3).sum() > 300 and ((front == OBJ | 3) == (v.ids == OBJ | 3)).all()
    behind = v.ids == OBJ | 0
    assert behind.sum() > 30 and (alone[behind] == OBJ).all()
    assert ((alone == OBJ) & (front != OBJ | 3)).sum() == behind.sum()
    tie = refrender.cast_view(spec, 140, -100, None, 0, objects=[near, out, out, near]).ids
    assert (tie == OBJ | 0).sum() == (front == OBJ | 3).sum() and not (tie == OBJ | 3).any()


def test_texel_and_light(pwad):
    """reflook: each sprite pixel's texel is the hand-decoded one, its table the light of walls
    at depth 180 in the hall (light 208: lightnum 13, start 8; 2560 / 180 = 14.2 -> 8 - 14 // 2
    = 1; not the room's, where the eye is: start 32), its colour lights[1][texel] = texel + 8;
    compare() takes the sprite pixels where the frame's ids show the same object, and the 27
    candidates include the exact colour."""
    spec, known = pwad
    v = refrender.cast_view(spec, 380, -100, None, 0)
    e = reflook.expect(v)
    _, texels, left, top = expected_image(known, "TROOA1")
    on = v.ids == OBJ
    assert on.sum() > 100 and (e.cat[on] == reflook.CAT_SPRITE).all()
    assert (e.cat[~on] != reflook.CAT_SPRITE).all()
    assert (e.table[on] == 1).all()
    col, row = v.spr_col[on], v.spr_row[on]
    assert (e.colour[on] == (texels[col, row] + 8) % 256).all()
    assert (e.cand[on] == e.colour[on][:, None]).any(axis=1).all()
    assert e.look.names[e.tex[on][0]] == ("TROOA1", "sprite")
    ok, compared, counts = reflook.compare(e, e.colour, v.ids)
    assert counts["sprite"] == (int(on.sum()), int(on.sum())) and ok[compared].all()
    other = v.ids.copy()
    other[on] = OBJ | 7
    _, compared, counts = reflook.compare(e, e.colour, other)
    assert counts["sprite"] == (0, 0) and not compared[on].any()
    assert reflook.sprite_table(e.look, v.sprites[0]) == 1


def test_cli_colours_include_sprites(pwad, tmp_path):
    """refrender --raw writes the sprite's colours; --flat draws the box (no colour there)."""
    spec, _ = pwad
    raw, ids = tmp_path / "f.raw", tmp_path / "f.ids"
    run([sys.executable, ROOT / "tools/refrender.py", spec, "--at", "300,-100", "--angle", "0",
         "--raw", raw, "--ids", ids])
    v = refrender.cast_view(spec, 300, -100, None, 0)
    assert (np.fromfile(ids, "<u4").reshape(200, 320) == v.ids).all()
    assert (np.fromfile(raw, np.uint8).reshape(200, 320) == reflook.expect(v).colour).all()
    run([sys.executable, ROOT / "tools/refrender.py", spec, "--at", "300,-100", "--angle", "0",
         "--raw", raw, "--ids", ids, "--flat"])
    flat_ids = np.fromfile(ids, "<u4").reshape(200, 320)
    assert ((flat_ids >> 24) == 4).sum() > (v.ids == OBJ).sum()
    assert (np.fromfile(raw, np.uint8).reshape(200, 320)[(flat_ids >> 24) == 4] == 0).all()


def test_freedoom_lump_against_hand_decoding():
    """A real sprite: freedoom2.wad MAP01's object 0 (a zombieman, POSS A) put 160 units ahead of
    the eye (in an open hall, both on floor 16) shows, one texel a pixel, the posts of POSSA1 as
    decoded here by hand when it faces the eye, and those of POSSA2A8 flipped when seen in
    rotation 8 (yaw 225), wherever the world does not come nearer."""
    path = freedoom("freedoom2.wad")
    data = path.read_bytes()
    n, ofs = struct.unpack_from("<II", data, 4)
    lumps = {}
    for i in range(n):
        pos, size, name = struct.unpack_from("<II8s", data, ofs + 16 * i)
        lumps[name.rstrip(b"\0").decode()] = data[pos:pos + size]
    m = refrender.load(f"{path}:MAP01")
    assert m.sprites[0].sprite == "POSS"
    ex, ey, floor = 1912, -164, 16
    world = refrender.cast_view(m, ex, ey, None, 0, objects=[])
    assert world.z == floor + 41
    for yaw, name, mirrored in ((180, "POSSA1", False), (225, "POSSA2A8", True)):
        objs = [{"model": 0, "x": ex + 160, "y": ey, "z": floor, "yaw": yaw}]
        v = refrender.cast_view(m, ex, ey, None, 0, objects=objs)
        assert v.sprites[0].image.name == name and v.sprites[0].mirrored == mirrored
        w, h, left, top, pic = decode_patch(lumps[name])
        checked = 0
        for u in range(w):
            for r in range(min(h, top)):                   # rows below the origin are cut
                py, px = 141 - top + r, 160 - left + u
                if not (0 <= py < 200 and 0 <= px < 320) or world.t[py, px] <= 160:
                    continue
                src = pic[w - 1 - u][r] if mirrored else pic[u][r]
                assert (v.ids[py, px] == OBJ) == (src is not None), (name, u, r)
                checked += 1
        print(f"{name}: {checked} texels checked")
        assert checked > 1000


# ---- build/render against it --------------------------------------------------------------

EXACT_MODES = ["direct", "columns"]  # mode spans sorts whole faces: it draws a thing as its box (docs/objects.md)
SPRITE_VIEWS = [("freedoom2.wad:MAP01", None, None), ("freedoom2.wad:MAP01", "300,200", "45"),
                ("freedoom2.wad:MAP01", "600,713", "35"), ("freedoom2.wad:MAP01", "1652,1281", "202"),
                ("freedoom1.wad:E1M1", "1073,1384", "357"), ("freedoom1.wad:E1M1", "821,1009", "60")]
VIEW_IDS = [f"{s}@{a or 'start'},{g or ''}" for s, a, g in SPRITE_VIEWS]
MIN_SAME = 0.999         # of each frame's pixels, as tests/test_accuracy.py
MAX_OBJ_SHARE = 0.005    # of the pixels where either side shows an object, over all views
MIN_TEX = 0.99           # of the compared sprite pixels within one texel and one light step


def render_view(spec, at, angle, mode, tmp_path):
    wad, _, name = spec.rpartition(":")
    full = f"{freedoom(wad)}:{name}"
    cam = (["--at", at] if at else []) + (["--angle", angle] if angle else [])
    ids, raw = tmp_path / "f.ids", tmp_path / "f.raw"
    j = json.loads(run([program("render"), full, *cam, "--mode", mode, "--ids", ids, "--raw", raw]).stdout)
    assert j.get("overflow", 0) == 0
    return full, j, np.fromfile(ids, "<u4").reshape(200, 320), np.fromfile(raw, np.uint8).reshape(200, 320)


@pytest.mark.parametrize("mode", EXACT_MODES)
def test_render_ids_against_reference(mode, tmp_path):
    """build/render's ids on views that show sprites: each frame agrees with the reference on at
    least 99.9% of its pixels, and over all views at most 0.5% of the pixels where either shows
    an object differ (a sprite's edges fall on texel boundaries, which pixel centres rarely meet
    exactly)."""
    total = bad = sprite_px = 0
    report, worst = [], 1.0
    for spec, at, angle in SPRITE_VIEWS:
        full, j, ids, _ = render_view(spec, at, angle, mode, tmp_path)
        c = j["camera"]
        v = refrender.cast_view(full, c["x"], c["y"], c["z"], c["angle"], c["look"], objects=j["objects"])
        same = float((ids == v.ids).mean())
        obj = ((v.ids >> 24) == 4) | ((ids >> 24) == 4)
        n, d = int(obj.sum()), int((obj & (ids != v.ids)).sum())
        total, bad, sprite_px = total + n, bad + d, sprite_px + int((v.spr_col >= 0).sum())
        report.append(f"{spec}@{at},{angle}: {same:.4%} same, {d} of {n} object pixels differ")
        worst = min(worst, same)
    print("\n".join(report))
    assert sprite_px > 20000
    assert worst >= MIN_SAME, "; ".join(report)
    assert bad <= MAX_OBJ_SHARE * total, "; ".join(report)


@pytest.mark.parametrize("mode", ["columns", "direct"])
def test_render_sprite_colours_against_reference(mode, tmp_path):
    """build/render's textured frame on the sprite pixels: of the reference's sprite pixels, at
    least 95% are the same object in the frame's ids and so compared, and at least 99% of those
    are within one texel and one light step of the reference (tools/reflook.py)."""
    ref_px = compared_px = ok_px = 0
    for spec, at, angle in SPRITE_VIEWS[1:]:
        full, j, ids, frame = render_view(spec, at, angle, mode, tmp_path)
        e = texcompare.reference(full, at, angle, 0, objects=j["objects"])
        _, _, counts = reflook.compare(e, frame, ids)
        ok, n = counts["sprite"]
        ref_px += int((e.cat == reflook.CAT_SPRITE).sum())
        compared_px += n
        ok_px += ok
        print(f"{spec}@{at},{angle} {mode}: sprite pixels {ok}/{n} acceptable")
    assert ref_px > 20000
    assert compared_px >= 0.95 * ref_px, \
        f"only {compared_px} of {ref_px} sprite pixels drawn as the same object"
    assert ok_px >= MIN_TEX * compared_px, f"{ok_px} of {compared_px} sprite pixels acceptable"


# ---- build/render on the crafted map --------------------------------------------------------

PWAD_VIEWS = [(380, -100, 0),    # the imp behind the step and beside the pillar
              (700, 150, 180),   # the barrel (a box: its sprite has 7 of 8 rotations) and the imps beyond
              (140, -100, 0)]    # along the room, both imps and the soul


@pytest.mark.parametrize("mode", EXACT_MODES)
def test_render_clips_sprites_and_boxes_as_the_reference(pwad, mode, tmp_path):
    """build/render on the crafted map, compiled by bspc: the imp hidden by the step and the
    pillar where the reference hides it, and sprites and a box (the barrel) in one frame sorted
    against each other and the world as the reference sorts them."""
    spec, _ = pwad
    bsc = tmp_path / "p.bsc"
    run([program("bspc"), spec, "-o", bsc])
    kinds = set()
    for x, y, angle in PWAD_VIEWS:
        ids_path = tmp_path / "p.ids"
        j = json.loads(run([program("render"), bsc, "--at", f"{x},{y}", "--angle", str(angle), "--mode", mode,
                            "--ids", ids_path]).stdout)
        ids = np.fromfile(ids_path, "<u4").reshape(200, 320)
        c = j["camera"]
        v = refrender.cast_view(spec, c["x"], c["y"], c["z"], c["angle"], c["look"], objects=j["objects"])
        same = float((ids == v.ids).mean())
        assert same >= 0.999, f"{x},{y} {angle}: only {same:.4%} of pixels agree"
        shown = {int(i) & 0xFFFFFF for i in np.unique(ids[(ids >> 24) == 4])}
        kinds |= {"sprite" if v.sprites[i] is not None else "box" for i in shown}
    assert kinds == {"sprite", "box"}, kinds
