"""What a scene needs (docs/needs.md): the compiler's analysis, builds for one scene, and the bounds.

- bspc --needs finds exactly the features a scene uses, for hand-made scenes that each leave
  something out;
- the per-frame bounds hold: over many cameras (inside, outside, on lines, at every height and
  look), no frame puts more world edges or surfaces on its lists than the scene's needs record
  allows, and no frame drops a polygon for a full pool;
- builds for one scene (make scene-host / build/scene/NAME/render) draw every view of the bench
  list and of the tests bit-identical to the full build, in both modes, and refuse a scene that
  needs more than they provide, naming what is missing.
"""
import json
import random
import struct
import subprocess
import sys

import pytest

from conftest import RENDER_MODES, ROOT, WADDIR, program, run

sys.path.insert(0, str(ROOT / "tools"))
import armelf  # noqa: E402

BENCH = json.loads((ROOT / "tests" / "bench_views.json").read_text())["views"]
EXTREME = sorted((ROOT / "tests" / "scenes" / "extreme").glob("*.json"))
GOLDEN = json.loads((ROOT / "tests" / "golden" / "frames.json").read_text())["frames"]
NEED = {"objects": 1, "doors": 2, "two-sided walls": 4, "height changes": 8, "sky steps": 16,
        "look up/down": 32, "y-clipping": 64}

ROOM = "sector a floor=0 ceil=128\n" \
       "wall 0 0 0 256 a\nwall 0 256 256 256 a\nwall 256 256 256 0 a\nwall 256 0 0 0 a\nplayer 64 64 45\n"
TWO_ROOMS = "sector a floor=0 ceil=128{a}\nsector b floor={bf} ceil={bc}{b}\n" \
            "wall 0 0 0 256 a\nwall 0 256 256 256 a\nwall 256 0 0 0 a\n" \
            "wall 256 256 256 0 a b\n" \
            "wall 256 256 512 256 b\nwall 512 256 512 0 b\nwall 512 0 256 0 b\nplayer 64 64 0\n"


def scene_name(spec):
    return spec.split("/")[-1].replace(".", "_").replace(":", "-")


def needs_of(spec, tmp_path):
    """bspc's --stats figures and --needs feature table ({name: needed}) for spec."""
    out = run([program("bspc", sanitized=False), spec, "-o", tmp_path / "x.bsc", "--needs", "--stats"]).stdout
    stats = json.loads(out.strip().splitlines()[-1])
    features = {}
    for line in out.splitlines():
        for name in NEED:
            if line.strip().startswith(name + " "):
                features[name] = line.strip()[len(name):].split()[0] == "yes"
    assert set(features) == set(NEED), out
    return stats, features


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


@pytest.mark.parametrize("text, want", [
    (ROOM, {"y-clipping", "look up/down"}),
    (ROOM + "look off\n", {"y-clipping"}),
    (TWO_ROOMS.format(a="", b="", bf=0, bc=128), {"y-clipping", "look up/down", "two-sided walls"}),
    (TWO_ROOMS.format(a="", b="", bf=16, bc=128), {"y-clipping", "look up/down", "two-sided walls", "height changes"}),
    (TWO_ROOMS.format(a=" sky", b=" sky", bf=0, bc=100),
     {"y-clipping", "look up/down", "two-sided walls", "height changes", "sky steps"}),
    (TWO_ROOMS.format(a=" sky", b="", bf=0, bc=100), {"y-clipping", "look up/down", "two-sided walls", "height changes"}),
    (TWO_ROOMS.format(a="", b=" door=128", bf=0, bc=0),
     {"y-clipping", "look up/down", "two-sided walls", "height changes", "doors"}),
    (ROOM + "model m\npart box w=8 d=8 h=8\nend\nobject m 100 100\n", {"y-clipping", "look up/down", "objects"}),
])
def test_features_found(tmp_path, text, want):
    stats, features = needs_of(write(tmp_path, "s.scene", text), tmp_path)
    assert {k for k, v in features.items() if v} == want
    assert stats["features"] == sum(NEED[k] for k in want)
    assert 0 < stats["max_edges"] <= stats["all_edges"]


def test_look_statement_errors(tmp_path):
    proc = run([program("bspc"), write(tmp_path, "s.scene", ROOM + "look sideways\n"), "-o", tmp_path / "x.bsc"],
               check=False)
    assert proc.returncode != 0 and "s.scene:7: look: expected 'look on' or 'look off'" in proc.stderr


def test_look_off_keeps_the_horizon(tmp_path):
    s = write(tmp_path, "s.scene", ROOM + "look off\n")
    proc = run([program("render"), s, "--look", "20"], check=False)
    assert proc.returncode != 0 and "keeps its horizon level" in proc.stderr


# ---- the bounds hold -----------------------------------------------------------

BOUND_SCENES = ["tests/scenes/default.scene", "tests/scenes/extreme/pillars.scene",
                "tests/scenes/extreme/deep_sector.scene", "freedoom2.wad:MAP01", "freedoom1.wad:E1M4"]


@pytest.mark.parametrize("spec", BOUND_SCENES)
def test_bounds_hold_for_any_camera(tmp_path, spec):
    """Random cameras over the whole map box and beyond it, at heights from below the lowest floor
    to above the highest ceiling: edges and surfaces stay within the needs record, no overflow."""
    if spec.endswith(":MAP01") or ".wad" in spec:
        if not (WADDIR / spec.split(":")[0]).exists():
            pytest.skip(f"{spec} not installed")
    bsc = tmp_path / "s.bsc"
    stats = json.loads(run([program("bspc", sanitized=False), spec, "-o", bsc, "--stats"]).stdout)
    verts = bounds_box(bsc)
    rng = random.Random(7)
    worst = 0
    for i in range(60):
        x = rng.uniform(verts[0] - 64, verts[1] + 64)
        y = rng.uniform(verts[2] - 64, verts[3] + 64)
        z = rng.uniform(-600, 600)
        args = ["--at", f"{x:.3f},{y:.3f},{z:.3f}", "--angle", f"{rng.uniform(0, 360):.3f}",
                "--look", str(rng.randint(-100, 100)), "--no-objects"]
        out = json.loads(run([program("render", sanitized=False), bsc, *args]).stdout)
        assert out["overflow"] == 0, args
        assert out["edges"] <= stats["max_edges"], args
        worst = max(worst, out["edges"])
    print(f"{spec}: most edges seen {worst} of the proven {stats['max_edges']} (every polygon: {stats['all_edges']})")


def bounds_box(bsc):
    """x0, x1, y0, y1 of a compiled scene's vertices, in units (read from the blob's vertex section)."""
    data = bsc.read_bytes()
    off, count = struct.unpack_from("<II", data, 44)
    xs, ys = [], []
    for i in range(count):
        x, y = struct.unpack_from("<ii", data, off + 8 * i)
        xs.append(x / 65536)
        ys.append(y / 65536)
    return min(xs), max(xs), min(ys), max(ys)


# ---- builds for one scene --------------------------------------------------------

def scene_build(spec):
    """build/scene/NAME/render for spec (make scene-host's renderer), built if needed."""
    rel = f"build/scene/{scene_name(spec)}"
    proc = subprocess.run(["make", "-s", "--no-print-directory", "-j4", f"SCENE={spec}", f"{rel}/render"], cwd=ROOT,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return ROOT / rel


def views():
    """(scene, [render arguments]) for every view of the bench list and of the tests."""
    for v in BENCH:
        yield v["scene"], ["--at", v["at"], "--angle", v["angle"]]
    for g in GOLDEN:
        cam = (["--at", g["at"]] if g.get("at") else []) + (["--angle", g["angle"]] if g.get("angle") else [])
        yield g["scene"], cam
    for manifest in EXTREME:
        m = json.loads(manifest.read_text())
        for v in m["views"]:
            yield f"tests/scenes/extreme/{m['scene']}", ["--at", v["at"], "--angle", str(v["angle"]),
                                                          "--look", str(v.get("look", 0))]
    for spec in ("tests/scenes/objects.scene", "tests/scenes/battle.scene", "freedoom2.wad:MAP01"):
        for t in (0, 2500, 9000):
            yield spec, ["--time", str(t)]
            yield spec, ["--time", str(t), "--angle", "200", "--look", "-30"]


def by_scene():
    groups = {}
    for spec, args in views():
        groups.setdefault(spec, []).append(args)
    return sorted(groups.items())


@pytest.mark.parametrize("spec, cams", by_scene(), ids=[s for s, _ in by_scene()])
def test_scene_build_is_bit_identical(spec, cams):
    if ".wad" in spec and not (WADDIR / spec.split(":")[0]).exists():
        pytest.skip(f"{spec} not installed")
    out = scene_build(spec)
    bsc = out / "scene.bsc"
    config = (out / "scene_config.h").read_text()
    for args in cams:
        for mode in RENDER_MODES:
            full = json.loads(run([program("render", sanitized=False), bsc, "--mode", mode, *args]).stdout)
            mine = json.loads(run([out / "render", bsc, "--mode", mode, *args]).stdout)
            assert mine["crc32"] == full["crc32"], (spec, mode, args)
            assert mine["overflow"] == full["overflow"] == 0
            assert mine["build_features"] == mine["features"] == full["features"], config


def test_scene_build_refuses_what_it_leaves_out(tmp_path):
    """A build for the default scene (no objects, no doors) refuses a scene with objects, naming them;
    a build for a small scene refuses a bigger one by its edge bound."""
    out = scene_build("tests/scenes/default.scene")
    proc = run([out / "render", "tests/scenes/objects.scene"], check=False)
    assert proc.returncode != 0
    assert "tests/scenes/objects.scene: the scene needs objects, which this build leaves out" in proc.stderr
    small = write(tmp_path, "small.scene",
                  TWO_ROOMS.format(a="", b="", bf=16, bc=128))  # same features as default.scene, fewer edges
    small_out = scene_build(small)
    proc = run([small_out / "render", "tests/scenes/default.scene"], check=False)
    assert proc.returncode != 0
    assert "the scene needs" in proc.stderr and "this build provides" in proc.stderr, proc.stderr


def test_scene_build_is_smaller(tmp_path):
    """The Cortex-M firmware built for the default scene (no objects, doors or sky) has less code
    than the full build with the same scene."""
    sizes = {}
    for full in ("", "1"):
        out = "build/" + ("arm-needs-full" if full else "arm-needs-scene")
        subprocess.run(["make", "-s", "--no-print-directory", "-j4", "firmware", f"ARM_OUT={out}",
                        f"FULL={full}", "RAM_BYTES=16777216"], cwd=ROOT, check=True, capture_output=True, timeout=900)
        sec = armelf.sections(ROOT / out / "firmware.elf")
        sizes[bool(full)] = sec[".text"] + sec.get(".rodata", 0)
    assert sizes[False] < sizes[True], sizes
