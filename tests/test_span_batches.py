"""Modes spans, direct and columns with pools of a few polygons draw the same frames as with the default
pools.

build/tinypools/render is build/render compiled with SPANS_POOL_EDGES=72 and SPANS_POOL_SURFACES=6,
CFG_DIRECT_FACES=3 and CFG_DIRECT_EDGES=90, CFG_COLS_PLANES=4 (the Makefile): in mode spans nearly
every frame fills its pools many times, so it is drawn in many batches (firmware/spans.c); in mode
direct the faces of all but an object or so do not fit, so they are worked out again wherever they
are needed (firmware/direct.c); in mode columns nearly every seg finds the visplanes full and draws
them early (firmware/columns.c). All count these in `flushes`. Over many views of Freedoom maps with their things, and of the space-battle
tests/scenes/objects.scene at several times, both builds must give the same frame CRC and the same surface-id buffer,
with overdraw exactly 1.000 and no polygon dropped.
"""
import json
import random
import struct

import pytest

from conftest import BUILD, ROOT, WADDIR, program, run

MAPS = ["freedoom2.wad:MAP01", "freedoom2.wad:MAP12", "freedoom1.wad:E1M1", "freedoom1.wad:E2M3",
        "freedoom1.wad:E3M7"]
VIEWS_PER_MAP = 24


def tiny_render():
    path = BUILD / "tinypools" / "render"
    run(["make", "-C", ROOT, "--no-print-directory", "build/tinypools/render"], env=None)
    return str(path)


def vertices(bsc):
    """The scene's vertices in units (read from the blob's vertex section)."""
    data = bsc.read_bytes()
    off, count = struct.unpack_from("<II", data, 44)
    return [(x / 65536, y / 65536) for x, y in
            (struct.unpack_from("<ii", data, off + 8 * i) for i in range(count))]


def cameras(bsc, n, seed):
    """The start, then eyes near random vertices (most inside the map, some in the void beside
    it), any angle, some looking up or down."""
    rng = random.Random(seed)
    verts = vertices(bsc)
    cams = [[]]
    while len(cams) < n:
        x, y = rng.choice(verts)
        x += rng.uniform(-96, 96)
        y += rng.uniform(-96, 96)
        look = rng.choice([0, 0, rng.randint(-100, 100)])
        cams.append(["--at", f"{x:.3f},{y:.3f}", "--angle", f"{rng.uniform(0, 360):.3f}", "--look", str(look)])
    return cams


def frame(render, scene, args, ids, mode):
    out = json.loads(run([render, scene, "--mode", mode, *args, "--ids", ids]).stdout)
    assert out["overflow"] == 0, (scene, args)
    assert out["pixels_written"] == 0 or out["overdraw"] == 1.0, (scene, args, out["overdraw"])
    return out, ids.read_bytes()


def compare(tiny, scene, cams, tmp_path, mode):
    """Both builds over cams; returns the tiny build's flushes (early batches, objects recomputed)."""
    flushes = 0
    for args in cams:
        a, ids_a = frame(program("render", sanitized=False), scene, args, tmp_path / "a.bin", mode)
        b, ids_b = frame(tiny, scene, args, tmp_path / "b.bin", mode)
        assert a["crc32"] == b["crc32"], (scene, args)
        assert ids_a == ids_b, (scene, args)
        assert a["objects_visible"] == b["objects_visible"], (scene, args)
        flushes += b["flushes"]
    return flushes


@pytest.mark.parametrize("mode", ["spans", "direct", "columns"])
@pytest.mark.parametrize("spec", MAPS)
def test_tiny_pools_draw_the_same_frames(spec, mode, tmp_path):
    if not (WADDIR / spec.split(":")[0]).exists():
        pytest.skip(f"{spec} not installed")
    tiny = tiny_render()
    bsc = tmp_path / "s.bsc"
    run([program("bspc", sanitized=False), spec, "-o", bsc])
    flushes = compare(tiny, bsc, cameras(bsc, VIEWS_PER_MAP, sum(map(ord, spec))), tmp_path, mode)
    # the comparison means something only if the small pools really made the frames batch
    assert flushes >= VIEWS_PER_MAP, flushes


@pytest.mark.parametrize("mode", ["spans", "direct"])
def test_tiny_pools_moving_objects(mode, tmp_path):
    """tests/scenes/objects.scene: objects on their paths at several times (the space-battle
    demo's world is too small to fill even these pools)."""
    tiny = tiny_render()
    bsc = tmp_path / "s.bsc"
    run([program("bspc", sanitized=False), ROOT / "tests" / "scenes" / "objects.scene", "-o", bsc])
    cams = [c + ["--time", str(t)] for c in cameras(bsc, 8, 5) for t in (0, 1700, 6100)]
    # meaningful only if the small pools were really used up (spans: in every frame)
    assert compare(tiny, bsc, cams, tmp_path, mode) >= (len(cams) if mode == "spans" else len(cams) // 2)
