"""See-through middle textures (docs/textures.md "See-through middle textures") in the reference
(tools/refrender.py, tools/reflook.py), and build/render against it.

The reference on its own: its middle textures' coverage, composed from TEXTURE1, PNAMES and the
patches, agrees with the posts of the patch decoded here by hand from the WAD's bytes; its objects
are numbered as bspc numbers them (after the things', in line order, side 0 before side 1, one
model each after the things' models), which build/render's JSON shows; in a view of a grate, the
pixels of the grate's quad are the object exactly where the texel the ray meets is covered (the
column and row worked out here from the line, the sidedef and the pegging), and the world behind
(the floor, walls) through the holes.

Then build/render (modes columns and direct, which draw middle textures with their holes) against
the reference on Freedoom views of grates: each frame's ids agree on at least 99.5% of the pixels,
both show the grate and the floor behind it through its holes, and the grate's colours are within
one texel and one light step of the reference's on at least 99% of its pixels.
"""
import json
import math
import struct
import sys

import numpy as np
import pytest

from conftest import ROOT, freedoom, program, run

sys.path.insert(0, str(ROOT / "tools"))
import reflook  # noqa: E402
import refrender  # noqa: E402

OBJ = 4 << 24
# (map, the grate's object, camera X,Y[,Z], angle, look): a grate in front of the eye, the floor
# behind it seen through its holes. MAP01: the slats of AQMETL29 round the garden (line 676,
# side 0), seen from 196 units up (a step above the garden's floor 112, the slats 136..200)
# looking down; E1M1: the bars of MIDBARS3 (line 136, side 0) and the grid of AQMETL27 (line 611,
# side 0) from the eye's height.
GRATES = [("freedoom2.wad:MAP01", 113, "1090,760,196", "100", -30),
          ("freedoom1.wad:E1M1", 169, "2268,557", "171", 0),
          ("freedoom1.wad:E1M1", 198, "1430,-150", "165", 0)]
GRATE_IDS = [f"{s}#{o}@{a},{g},{k}" for s, o, a, g, k in GRATES]
MIN_SAME = 0.995     # of each frame's pixels
MIN_QUAD = 0.98     # of the pixels of the grate's quad
MIN_TEX = 0.99       # of the compared middle texture pixels within one texel and one light step


def wad_spec(spec):
    wad, _, name = spec.rpartition(":")
    return f"{freedoom(wad)}:{name}"


def directory(data):
    n, ofs = struct.unpack_from("<II", data, 4)
    out = {}
    for i in range(n):
        pos, size, name = struct.unpack_from("<II8s", data, ofs + 16 * i)
        out[name.rstrip(b"\0").decode().upper()] = (pos, size)        # the last of a name wins
    return out


def texture_def(data, d, name):
    """TEXTURE1's (then TEXTURE2's) definition of name, read here: (width, height, [(originx,
    originy, patch name)])."""
    pos, _ = d["PNAMES"]
    (npn,) = struct.unpack_from("<i", data, pos)
    pnames = [data[pos + 4 + 8 * i:pos + 12 + 8 * i].rstrip(b"\0").decode().upper() for i in range(npn)]
    for lump in ("TEXTURE1", "TEXTURE2"):
        if lump not in d:
            continue
        t, _ = d[lump]
        (n,) = struct.unpack_from("<i", data, t)
        for k in range(n):
            (ofs,) = struct.unpack_from("<i", data, t + 4 + 4 * k)
            base = t + ofs
            if data[base:base + 8].rstrip(b"\0").decode().upper() != name:
                continue
            w, h = struct.unpack_from("<hh", data, base + 12)
            (npatch,) = struct.unpack_from("<h", data, base + 20)
            pats = [struct.unpack_from("<hhh", data, base + 22 + 10 * j) for j in range(npatch)]
            return w, h, [(ox, oy, pnames[pi]) for ox, oy, pi in pats]
    raise KeyError(name)


def hand_column(data, d, patch, c):
    """Column c of a patch lump, decoded here: {row: texel} of its posts."""
    pos, _ = d[patch]
    (cofs,) = struct.unpack_from("<I", data, pos + 8 + 4 * c)
    p, out = pos + cofs, {}
    while data[p] != 0xFF:
        top, n = data[p], data[p + 1]
        for r in range(n):
            out[top + r] = data[p + 3 + r]
        p += n + 4
    return out


# ---- the reference on its own -------------------------------------------------------------

@pytest.mark.parametrize("wad,spec,name", [("freedoom1.wad", "E1M1", "MIDBARS3"),
                                           ("freedoom2.wad", "MAP01", "AQMETL29")])
def test_coverage_against_hand_decoded_patch(wad, spec, name):
    """A grate's coverage (Look.mid_texture) at every column of its patches: covered exactly at
    the rows a post of some patch covers, clipped to the texture (decoded here from the patch's
    bytes), and its texels there the posts' bytes (the last patch over the earlier); the texture
    has holes in its shown columns, so it is a see-through middle texture."""
    path = freedoom(wad)
    data = path.read_bytes()
    d = directory(data)
    width, height, pats = texture_def(data, d, name)
    lk = reflook.look_of(refrender.load(f"{path}:{spec}"))
    tex, cover = lk.mid_texture(name)
    assert (tex.width, tex.height) == (cover.width, cover.height) == (width, height)
    want_cover = np.zeros((width, height), bool)
    want_tex = np.zeros((width, height), np.int64)
    for ox, oy, patch in pats:
        pw = struct.unpack_from("<h", data, d[patch][0])[0]
        for c in range(pw):
            x = ox + c
            if not 0 <= x < width:
                continue
            for r, texel in hand_column(data, d, patch, c).items():
                if 0 <= oy + r < height:
                    want_cover[x, oy + r] = True
                    want_tex[x, oy + r] = texel
    assert (cover.cols == want_cover).all(), np.argwhere(cover.cols != want_cover)[:10]
    assert (tex.cols[want_cover] == want_tex[want_cover]).all()
    shown = 1 << (width.bit_length() - 1)
    holes = int((~want_cover[:shown]).sum())
    print(f"{name}: {width} x {height}, {len(pats)} patch(es), {holes} holes")
    assert 0 < holes < shown * height
    # one column by hand, spelled out: the first column with both a post and a hole
    assert len(pats) == 1
    c = next(c for c in range(shown) if want_cover[c].any() and not want_cover[c].all())
    ox, oy, patch = pats[-1]
    posts = hand_column(data, d, patch, c - ox)
    assert [bool(cover.texel(c, v)) for v in range(height)] == \
        [(v - oy) in posts for v in range(height)]


@pytest.mark.parametrize("wad,spec,count,things", [("freedoom2.wad", "MAP01", 23, 101),
                                                   ("freedoom1.wad", "E1M1", 35, 169)])
def test_numbering_against_bspc(wad, spec, count, things, tmp_path):
    """The middle texture objects follow the things' objects, in line order, side 0 before side
    1, each with its own model after the things' models; build/render's JSON lists them with the
    reference's model, position (the line's middle, z the height of row 0 less the y offset) and
    yaw 0."""
    full = f"{freedoom(wad)}:{spec}"
    m = refrender.load(full)
    mids = [d for d in m.mids if d is not None]
    assert m.nthings == things and len(mids) == count and len(m.objects) == things + count
    assert [d.obj for d in mids] == list(range(things, things + count))
    assert [(d.line, d.side) for d in mids] == sorted((d.line, d.side) for d in mids)
    nthing_models = len(m.models) - count
    assert [d.model for d in mids] == list(range(nthing_models, len(m.models)))
    assert all(m.mids[i] is None and m.objects[i].model < nthing_models for i in range(things))
    j = json.loads(run([program("render"), full, "--ids", tmp_path / "f.ids"]).stdout)
    assert len(j["objects"]) == len(m.objects)
    for d, o in zip(mids, j["objects"][things:]):
        got = (o["model"], o["x"], o["y"], o["z"], o["yaw"])
        assert got == (d.model, d.x, d.y, d.top, 0), (d.line, d.side)
        # the quad: the line from end to end, the heights within the opening
        a, b = int(m.front[d.line]), int(m.back[d.line])
        assert max(m.floor[a], m.floor[b]) <= d.zb < d.zt <= min(m.ceil[a], m.ceil[b])


def quad_pixels(v, o):
    """The pixels of view v whose centre ray (the tie-break sample) meets object o's quad from
    its front before the world and before any other object, worked out here from the side's
    line: (mask, u, row) with u and row the texel column and row met there (docs/textures.md)."""
    m, d = v.scene, v.mids[o].mid
    i = d.line
    ax, ay, bx, by = m.x1[i], m.y1[i], m.x2[i], m.y2[i]
    if d.side:
        ax, ay, bx, by = bx, by, ax, ay
    ln = math.hypot(bx - ax, by - ay)
    ux, uy = (bx - ax) / ln, (by - ay) / ln
    # E + t (dx, dy) = A + s (B - A)
    det = v.dx * (ay - by) - v.dy * (ax - bx)
    t = ((ax - v.x) * (ay - by) - (ay - v.y) * (ax - bx)) / det
    s = (v.dx * (ay - v.y) - v.dy * (ax - v.x)) / det
    h = v.z + v.yv[:, None] * t[None, :]
    u = (v.x + t * v.dx - ax) * ux + (v.y + t * v.dy - ay) * uy + d.xoff
    row = d.top + d.yoff - h
    facing = (bx - ax) * (v.y - ay) - (by - ay) * (v.x - ax) < 0
    on = facing & ((s >= 0) & (s <= 1) & (t > 0))[None, :] & (h >= d.zb) & (h <= d.zt)
    t2 = np.broadcast_to(t[None, :], on.shape)
    on &= (t2 < v.t) & ((v.obj == o) | (v.obj_t > t2))
    return on, np.broadcast_to(u[None, :], on.shape), row


@pytest.mark.parametrize("spec,o,at,angle,look", GRATES, ids=GRATE_IDS)
def test_grate_pixels_in_the_reference(spec, o, at, angle, look):
    """In the grate's quad the reference shows the object exactly where the texel met is
    covered (column u and row worked out here), and what lies behind (the floor, walls: kinds 2
    and 1) through the holes; the View's exact (u, v) are those."""
    full = wad_spec(spec)
    x, y, z = (at.split(",") + [None])[:3]
    v = refrender.cast_view(full, x, y, z, angle, look)
    mid = v.mids[o].mid
    on, u, row = quad_pixels(v, o)
    covered = mid.cover.texel(np.floor(u).astype(np.int64), np.floor(row).astype(np.int64)) != 0
    mine = v.ids == OBJ | o
    assert (mine == (on & covered)).all(), np.argwhere(mine != (on & covered))[:10]
    assert np.allclose(v.mid_u[mine], u[mine]) and np.allclose(v.mid_v[mine], row[mine])
    behind = v.ids[on & ~covered] >> 24
    print(f"{spec}#{o}: {int(on.sum())} pixels in the quad, {int(mine.sum())} the grate's; through "
          f"its holes {int((behind == 2).sum())} floor, {int((behind == 1).sum())} wall")
    assert mine.sum() > 1000 and (behind == 2).sum() > 100 and (behind == 1).sum() + (behind == 2).sum() > 500
    # the holes show what the world shows there without the objects (but for things behind)
    world = refrender.cast_view(full, x, y, z, angle, look, objects=[])
    holes = on & ~covered & (v.obj < 0)
    assert holes.sum() > 500 and (v.ids[holes] == world.ids[holes]).all()


# ---- build/render against it --------------------------------------------------------------

def render_view(full, at, angle, look, mode, tmp_path):
    ids, raw = tmp_path / "f.ids", tmp_path / "f.raw"
    j = json.loads(run([program("render"), full, "--at", at, "--angle", angle, "--look", str(look),
                        "--mode", mode, "--ids", ids, "--raw", raw]).stdout)
    assert j.get("overflow", 0) == 0
    return j, np.fromfile(ids, "<u4").reshape(200, 320), np.fromfile(raw, np.uint8).reshape(200, 320)


@pytest.mark.parametrize("mode", ["columns", "direct"])
@pytest.mark.parametrize("spec,o,at,angle,look", GRATES, ids=GRATE_IDS)
def test_grate_against_renderer(spec, o, at, angle, look, mode, tmp_path):
    """build/render's ids agree with the reference's on at least 99.5% of the frame and on at
    least 98% of the grate's quad (the renderer's texel column and row are interpolated along a
    row between exact samples every 8 columns, TEX_SUBDIV_BITS: a pixel whose centre falls within
    a few hundredths of a texel of a bar's edge may take the other side; close up, as E1M1's bars
    here, that is about 1% of the quad); in the quad both show the grate (kind 4, the object's
    number) and, through its holes, the floor behind; and of the reference's grate pixels the
    frame shows at least 95% as the same object, at least 99% of those within one texel and one
    light step of the reference's colour (tools/reflook.py)."""
    full = wad_spec(spec)
    j, ids, frame = render_view(full, at, angle, look, mode, tmp_path)
    c = j["camera"]
    v = refrender.cast_view(full, c["x"], c["y"], c["z"], c["angle"], c["look"], objects=j["objects"])
    same = float((ids == v.ids).mean())
    on, _, _ = quad_pixels(v, o)
    in_quad = float((ids[on] == v.ids[on]).mean())
    print(f"{spec}#{o} {mode}: {same:.4%} same, {in_quad:.4%} in the grate's quad")
    assert same >= MIN_SAME and in_quad >= MIN_QUAD
    for buf in (ids, v.ids):
        assert (buf[on] == OBJ | o).sum() > 1000
        assert ((buf[on] >> 24) == 2).sum() > 100
    e = reflook.expect(v)
    ok, compared, counts = reflook.compare(e, frame, ids)
    mine = v.ids == OBJ | o
    assert (e.cat[mine] == reflook.CAT_MID).all()
    n_ok, n = int((ok & mine).sum()), int((compared & mine).sum())
    print(f"  grate colours: {n_ok} of {n} acceptable (all middle textures: {counts['midtex']})")
    assert n >= 0.95 * mine.sum() and n_ok >= MIN_TEX * n
    ok_all, n_all = counts["midtex"]
    assert ok_all >= MIN_TEX * n_all


def test_light_and_texel_by_hand():
    """One grate pixel's colour worked out here: the texel of MIDBARS3 at the View's (u, v), under
    light table start - min(47, floor(2560 / t)) // 2 of the side's sector (E1M1 line 136 runs
    along y: one level brighter), at the pixel's depth t."""
    full = wad_spec("freedoom1.wad:E1M1")
    v = refrender.cast_view(full, 2268, 557, None, 171)
    e = reflook.expect(v)
    mid = v.mids[169].mid
    assert (mid.line, mid.side, mid.name, mid.adj) == (136, 0, "MIDBARS3", 1)
    py, px = np.argwhere(v.ids == OBJ | 169)[len(np.argwhere(v.ids == OBJ | 169)) // 2]
    t = v.obj_t[py, px]
    light = e.look.sector_light[mid.sector]
    start = (15 - min(15, (light >> 4) + 1)) * 4
    table = min(31, max(0, start - min(47, math.floor(2560 / t)) // 2))
    texel = mid.tex.cols[math.floor(v.mid_u[py, px]) & 63, math.floor(v.mid_v[py, px]) % 72]
    assert e.table[py, px] == table
    assert e.colour[py, px] == e.look.lights[table][texel]
    assert e.look.names[e.tex[py, px]] == ("MIDBARS3", "mid")
