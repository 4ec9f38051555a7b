"""Texturing changes colours only: a flat build and a textured build draw the same surfaces.

build/flat/render is build/render compiled with CFG_FLAT=1 (the Makefile): the texture code is left
out and every scene is drawn in its flat colours. For each render mode, over the bench views of WAD
maps (tests/bench_views.json) with their things, the textured frame of build/render, the same
build's `--flat` frame and the flat build's frame must give identical surface-id buffers; the two
flat frames must be identical pixel for pixel, and the textured frame must differ from them (it is
textured). The flat build must carry no texture code.
"""
import json
import subprocess

import pytest

from conftest import BUILD, ROOT, program, run

MODES = ["direct", "spans", "painter", "columns"]
# Modes that sample a wall's texture at every 8th column and step between (texture.c's
# TEX_SUBDIV_BITS); columns samples every column exactly (tex_column), so its walls differ by
# design and test_renderer_against_reference (test_textures_ref.py) holds it to the reference.
SPAN_MODES = ["direct", "spans", "painter"]


def flat_render():
    run(["make", "-C", ROOT, "--no-print-directory", "build/flat/render"], env=None)
    return str(BUILD / "flat" / "render")


def bench_views():
    views = json.loads((ROOT / "tests" / "bench_views.json").read_text())
    out = []
    for group in (views["views"], views["open"]):
        out += [v for v in group if ".wad:" in v["scene"]]
    return out


VIEWS = bench_views()[::3]  # every third: starts and open views of several maps


def draw(render, view, mode, tmp_path, tag, *extra):
    ids, raw = tmp_path / f"{tag}.ids", tmp_path / f"{tag}.raw"
    args = [render, view["scene"], "--mode", mode, "--ids", ids, "--raw", raw, *extra]
    if view.get("at"):
        args += ["--at", view["at"], "--angle", str(view["angle"])]
    out = json.loads(run(args).stdout)
    return out, ids.read_bytes(), raw.read_bytes()


def test_flat_build_has_no_texture_code():
    symbols = subprocess.run(["nm", flat_render()], capture_output=True, text=True, check=True).stdout
    assert "tex_span" not in symbols and "rast_textured" not in symbols
    assert "tex_span" in subprocess.run(["nm", program("render", sanitized=False)], capture_output=True,
                                        text=True, check=True).stdout


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("view", VIEWS, ids=lambda v: f"{v['scene']}@{v.get('at', 'start')}")
def test_same_surfaces_textured_and_flat(view, mode, tmp_path):
    render, flat = program("render"), flat_render()
    tex, tex_ids, tex_raw = draw(render, view, mode, tmp_path, "tex")
    rflat, rflat_ids, rflat_raw = draw(render, view, mode, tmp_path, "rflat", "--flat")
    bflat, bflat_ids, bflat_raw = draw(flat, view, mode, tmp_path, "bflat")
    assert (tex["textured"], rflat["textured"], bflat["textured"]) == (1, 0, 0)
    assert tex_ids == rflat_ids, "texturing changed which surface a pixel shows"
    # the flat build has no texture code, so no sprites or see-through middle textures: it draws those
    # objects as their boxes and quads (docs/objects.md); every other pixel is the same surface
    import numpy as np
    t, b = np.frombuffer(tex_ids, "<u4"), np.frombuffer(bflat_ids, "<u4")
    world = ((t >> 24) != 4) & ((b >> 24) != 4)
    assert np.array_equal(t[world], b[world]), "the flat build shows other surfaces"
    if not ((t >> 24) == 4).any():
        assert rflat_raw == bflat_raw, "--flat and the flat build draw different colours"
    assert tex_raw != rflat_raw, "the textured frame is not textured"
    for out in (tex, rflat, bflat):
        assert out["overdraw"] == 1.0 or mode == "painter"
        assert out["overflow"] == 0


@pytest.mark.parametrize("view", VIEWS, ids=lambda v: f"{v['scene']}@{v.get('at', 'start')}")
def test_texels_do_not_depend_on_the_mode(view, tmp_path):
    """The texel of a pixel depends on the pixel alone, not on how a mode cut its row into spans:
    where two modes show the same surface, they show the same colour."""
    import numpy as np
    render = program("render")
    frames = {}
    for mode in SPAN_MODES:
        _, ids, raw = draw(render, view, mode, tmp_path, mode)
        frames[mode] = (np.frombuffer(ids, "<u4"), np.frombuffer(raw, np.uint8))
    ids0, raw0 = frames["direct"]
    for mode in ("spans", "painter"):
        ids, raw = frames[mode]
        # objects left out: mode spans draws a sprite thing as its box in flat colour (docs/objects.md)
        objects = ((ids >> 24) == 4) | ((ids0 >> 24) == 4)
        same = (ids == ids0) & ~objects
        assert (same | objects).mean() > 0.9  # painter sorts objects inexactly by design; most pixels compare
        assert np.array_equal(raw[same], raw0[same]), f"{mode}: {(raw[same] != raw0[same]).sum()} pixels differ"
