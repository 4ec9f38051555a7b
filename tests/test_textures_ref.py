"""Texels and light against the reference (tools/reflook.py, tools/texcompare.py; docs/textures.md).

The reference is checked first on its own: its per-pixel surfaces are refrender's (the id buffer
of cast_view is render_ids'), its composition of a texture agrees with a patch column decoded here
by hand from the WAD, its light follows Doom's tables on figures worked out by hand, and the
comparison passes the reference's own frame (100%) and fails it moved by 3 pixels.

Then build/render's frame of every bench view, in mode columns (the default) and in mode direct, (tests/bench_views.json, the 20 player starts and
the 7 open views, all on Freedoom maps) must be acceptable on at least 99% of the compared pixels:
within one texel and one light step of the reference (walls, floors, ceilings, sky with a texture;
the renderer's object pixels left out). A view whose scene the renderer draws flat is skipped: the
render JSON says "textured": false, or (when the JSON has no such key) the compiled scene does not
need SCN_NEED_TEXTURES (its needs record, firmware/scene_format.h). BSPVGA_TEXREF=1 in the
environment compares every view whatever the scene says (a flat frame then fails, as it should).
"""
import os
import json
import struct
import sys

import numpy as np
import pytest

from conftest import ROOT, WADDIR, freedoom, program, render, run

sys.path.insert(0, str(ROOT / "tools"))
import reflook  # noqa: E402
import refrender  # noqa: E402
import texcompare  # noqa: E402

BENCH = json.loads((ROOT / "tests/bench_views.json").read_text())
VIEWS = BENCH["views"] + BENCH["open"]
IDS = [f"{v['scene']}@{v['at']},{v['angle']}" for v in VIEWS]
GOAL = 0.99
SCN_SEC_NEEDS, SCN_NEED_TEXTURES = 13, 1 << 7


def scene_path(spec):
    wad, _, name = spec.rpartition(":")
    return f"{freedoom(wad)}:{name}"


# ---- the reference on its own -------------------------------------------------------------

SELF_VIEWS = ["freedoom2.wad:MAP01", "freedoom1.wad:E1M1", "freedoom2.wad:MAP04"]


@pytest.mark.parametrize("spec", SELF_VIEWS)
def test_self_check(spec):
    """The reference's own colours are all acceptable; moved 3 pixels right or down they are not
    (measured, right and down: MAP01 84% and 74%, E1M1 73% and 65%, MAP04 81% and 64%), so the
    check can fail."""
    v = next(v for v in VIEWS if v["scene"] == spec)
    e = texcompare.reference(scene_path(spec), v["at"], v["angle"])
    ok, compared, counts = reflook.compare(e, e.colour)
    assert counts["all"][1] > 32000 and counts["all"][0] == counts["all"][1]
    for axis in (0, 1):
        _, _, moved = reflook.compare(e, np.roll(e.colour, 3, axis=axis))
        share = moved["all"][0] / moved["all"][1]
        print(f"{spec} moved 3 px along axis {axis}: {share:.2%}")
        assert share < 0.9


def test_ids_unchanged():
    """cast_view's ids are render_ids' (the surface reference is the one the other tests check),
    and its walls, floors and ceilings carry the line, part and depth the colours need."""
    v = VIEWS[10]
    spec = scene_path(v["scene"])
    x, y = (float(c) for c in v["at"].split(","))
    view = refrender.cast_view(spec, x, y, None, float(v["angle"]), objects=[])
    assert (view.ids == refrender.render_ids(spec, x, y, None, float(v["angle"]), objects=[])).all()
    kind = view.ids >> 24
    assert ((view.line >= 0) == (kind == 1) | (view.part == 3)).all()
    assert np.isfinite(view.t[kind > 0]).all() and (view.t[kind > 0] > 0).all()


def _directory(data):
    n, ofs = struct.unpack_from("<II", data, 4)
    out = {}
    for i in range(n):
        pos, size, name = struct.unpack_from("<II8s", data, ofs + 16 * i)
        out[name.rstrip(b"\0").decode()] = (pos, size)           # the last of a name wins
    return out


def test_composition_against_hand_decoded_patch():
    """A multi-patch texture of freedoom2 (the first in TEXTURE1 whose second patch starts right of
    column 0): at each of its patches' columns, the composed texels equal the patch's posts decoded
    here, where no later patch covers them; and the texture wraps as docs/textures.md says."""
    path = freedoom("freedoom2.wad")
    data = path.read_bytes()
    d = _directory(data)
    pos, _ = d["PNAMES"]
    (npn,) = struct.unpack_from("<i", data, pos)
    pnames = [data[pos + 4 + 8 * i:pos + 12 + 8 * i].rstrip(b"\0").decode().upper() for i in range(npn)]
    t1, _ = d["TEXTURE1"]
    (ntex,) = struct.unpack_from("<i", data, t1)
    for k in range(1, ntex):
        (ofs,) = struct.unpack_from("<i", data, t1 + 4 + 4 * k)
        base = t1 + ofs
        name = data[base:base + 8].rstrip(b"\0").decode().upper()
        width, height = struct.unpack_from("<hh", data, base + 12)
        (npatch,) = struct.unpack_from("<h", data, base + 20)
        pats = [struct.unpack_from("<hhh", data, base + 22 + 10 * j) for j in range(npatch)]
        if npatch >= 2 and pats[1][0] > 0:
            break
    m = refrender.load(f"{path}:MAP01")
    look = reflook.look_of(m)
    tex = look.texture(look.number(name, False))
    assert (tex.width, tex.height) == (width, height)
    checked = 0
    for j, (ox, oy, pi) in enumerate(pats):
        ppos, _ = d[pnames[pi]]
        pw = struct.unpack_from("<h", data, ppos)[0]
        for c in (0, pw // 2, pw - 1):
            x = ox + c
            if not 0 <= x < width:
                continue
            (cofs,) = struct.unpack_from("<I", data, ppos + 8 + 4 * c)
            p = ppos + cofs
            while data[p] != 0xFF:
                top, n = data[p], data[p + 1]
                for r in range(n):
                    y = oy + top + r
                    later = any(lx <= x < lx + struct.unpack_from("<h", data, d[pnames[lp]][0])[0]
                                for lx, _, lp in pats[j + 1:])
                    if 0 <= y < height and not later:
                        assert tex.cols[x, y] == data[p + 3 + r], (name, x, y)
                        checked += 1
                p += n + 4
    print(f"{name}: {width}x{height}, {npatch} patches, {checked} texels checked")
    assert checked > 100, (name, checked)
    # wrap: columns at the largest power of two not above the width, rows padded from the top
    wpow = 1 << (width.bit_length() - 1)
    u = np.arange(wpow)
    assert (tex.texel(u + wpow, 5) == tex.cols[u, 5]).all()
    hpow = 1 << (height - 1).bit_length()
    assert (tex.texel(u, np.full(wpow, hpow)) == tex.cols[u, 0]).all()
    if hpow > height:
        assert (tex.texel(u, np.full(wpow, height)) == tex.cols[u, 0]).all()


def test_light_rules_by_hand():
    """Doom's tables on hand-worked figures: light 160 (lightnum 10, start 20); a wall at depth
    80: 2560 / 80 = 32 -> table 20 - 16 = 4; at depth 30: min(47, 85) -> 20 - 23 -> 0; a plane at
    depth 80: 160 / (5 + 1) = 26 -> 20 - 13 = 7; at 4000: 160 / 128 = 1 -> 20 - 0 = 20. Fake
    contrast: along x one level darker (start 24), along y one brighter (16)."""
    start = reflook.light_start(np.array([160, 160, 160]), np.array([0, -1, 1]))
    assert list(start) == [20, 24, 16]
    assert list(reflook.wall_table(np.array([20, 20]), np.array([80.0, 30.0]))) == [4, 0]
    assert list(reflook.plane_table(np.array([20, 20]), np.array([80.0, 4000.0]))) == [7, 20]
    assert reflook.light_start(np.array([255]), np.array([1]))[0] == 0       # clamped at 15


# ---- the renderer against it --------------------------------------------------------------

_needs = {}


def scene_textured(spec, j, tmp_path):
    """Whether build/render draws SPEC textured: the JSON's "textured" if it has one, else
    whether the compiled scene needs SCN_NEED_TEXTURES."""
    if os.environ.get("BSPVGA_TEXREF") == "1":
        return True
    if "textured" in j:
        return bool(j["textured"])
    if spec not in _needs:
        out = tmp_path / "scene.bsc"
        run([program("bspc"), spec, "-o", out])
        blob = out.read_bytes()
        off, count = struct.unpack_from("<II", blob, 44 + 8 * SCN_SEC_NEEDS)
        _needs[spec] = count >= 1 and bool(struct.unpack_from("<I", blob, off)[0] & SCN_NEED_TEXTURES)
    return _needs[spec]


@pytest.mark.parametrize("mode", ["columns", "direct"])
@pytest.mark.parametrize("view", VIEWS, ids=IDS)
def test_renderer_against_reference(view, mode, tmp_path):
    spec = scene_path(view["scene"])
    raw, ids = tmp_path / "frame.raw", tmp_path / "frame.ids"
    j = render(spec, "--raw", raw, "--ids", ids, "--look", str(view.get("look", 0)), "--mode", mode,
               at=view["at"], angle=view["angle"])
    if not scene_textured(spec, j, tmp_path):
        pytest.skip(f"{view['scene']}: build/render draws this scene flat (the render JSON's "
                    "\"textured\" is false or absent, and the compiled scene does not need "
                    "SCN_NEED_TEXTURES)")
    e = texcompare.reference(spec, view["at"], view["angle"], view.get("look", 0))
    frame = np.fromfile(raw, np.uint8)
    buf = np.fromfile(ids, "<u4")
    ok, compared, counts = reflook.compare(e, frame, buf)
    share = counts["all"][0] / counts["all"][1]
    kinds = ", ".join(f"{k} {a}/{n}" for k, (a, n) in counts.items() if k != "all" and n)
    print(f"{view['scene']} {view['at']} {view['angle']} {mode}: {share:.3%} of {counts['all'][1]} ({kinds})")
    if share < GOAL:
        diff = ROOT / "build" / "texref" / (IDS[VIEWS.index(view)].replace("/", "_").replace(":", "_") + f"-{mode}.png")
        diff.parent.mkdir(parents=True, exist_ok=True)
        refrender.write_png_rgb(diff, reflook.diff_rgb(e, frame, ok, compared))
        pytest.fail(f"{share:.3%} acceptable, below {GOAL:.0%} ({kinds}); failures in red: {diff}")
