"""Moving objects and doors (docs/objects.md) in build/render against the reference renderer.

tests/scenes/objects.scene has two halves of a hall (same floor, different ceilings: a two-sided
line objects straddle), a pillar, a step up to a dais, a window onto a sky garden and a door to a
closet, and five models (a crate, an octagonal barrel, a three-part tower, a low slab, a
triangular spike). Random configurations put 6 to 12 objects in it (on the floors, near walls,
straddling the hall's middle line, near the eye, overlapping on screen; never inside a wall or
one another, whose interpenetration the renderer's per-span ordering does not claim to draw) and
render them with the sanitized build/render --objects FILE in mode spans: each pixel written
once, the id buffer equal to the reference's (tools/refrender.py given the JSON's objects) on at
least 99.5% of the pixels, and no object pixel where the reference has no pixel of that object
within one pixel (an object drawn over a nearer surface). Paths (--time), doors (--door, and
--time with the eye by a door) and Freedoom's MAP01 with its things are checked the same way.
"""
import json
import math
import random
import statistics
import sys

import numpy as np
import pytest

from conftest import ROOT, freedoom, program, render, run

sys.path.insert(0, str(ROOT / "tools"))
import refrender  # noqa: E402

SCENE = str(ROOT / "tests" / "scenes" / "objects.scene")
OBJ = 4 << 24
MIN_AGREE = 0.995
SEEDS, PER_SEED = 25, 8          # 200 random configurations

# (xmin, ymin, xmax, ymax, floor) of the rooms objects and eyes go in
HALL = (0, 0, 512, 384, 0)
DAIS = (512, 0, 768, 384, 24)
GARDEN = (0, 400, 512, 640, 0)
CLOSET = (-256, 96, -16, 288, 0)
STRADDLE_X = 256                 # the hall's two-sided middle line: same floor on both sides
PILLAR = (384, 224, 416, 256, 0)
DOOR = 5                         # the door sector, closed at 0, open at 112


def _model_sizes():
    m = refrender.load(SCENE)
    out = []
    for model in m.models:
        v = np.concatenate([verts for verts, _ in model.parts])
        out.append((float(np.hypot(v[:, 0], v[:, 1]).max()), float(v[:, 2].max())))
    return out


def _walls():
    m = refrender.load(SCENE)
    keep = ~((m.x1 == STRADDLE_X) & (m.x2 == STRADDLE_X))
    return np.stack([m.x1[keep], m.y1[keep], m.x2[keep], m.y2[keep]], 1)


def _dist_to_walls(walls, x, y):
    ax, ay, bx, by = walls.T
    wx, wy = bx - ax, by - ay
    u = np.clip(((x - ax) * wx + (y - ay) * wy) / (wx * wx + wy * wy), 0, 1)
    return float(np.hypot(ax + u * wx - x, ay + u * wy - y).min())


def _inside(room, x, y, margin):
    x0, y0, x1, y1, _ = room
    return x0 + margin <= x <= x1 - margin and y0 + margin <= y <= y1 - margin


def _floor_at(x, y):
    for room in (HALL, DAIS, GARDEN, CLOSET):
        if _inside(room, x, y, 0):
            return room[4]
    raise AssertionError((x, y))


def random_configuration(rng):
    """An eye (x, y, angle) and 6..12 objects [(model, x, y, z, yaw)], as decimal strings
    rounded to 1/1000 so the files say exactly what is placed."""
    sizes, walls = _model_sizes(), _walls()
    eye_room = rng.choice([HALL, HALL, HALL, DAIS])
    while True:
        ex, ey = rng.uniform(eye_room[0], eye_room[2]), rng.uniform(eye_room[1], eye_room[3])
        if _dist_to_walls(walls, ex, ey) > 4 and not _inside(PILLAR, ex, ey, 0):
            break
    angle = rng.uniform(0, 360)
    fx, fy = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    placed = []
    for _ in range(rng.randint(6, 12)):
        for _attempt in range(200):
            model = rng.randrange(len(sizes))
            r, _h = sizes[model]
            how = rng.random()
            if how < 0.35:                       # in front of the eye, some very near it
                d = rng.uniform(r + 3, r + rng.choice([12, 60, 250]))
                s = rng.uniform(-0.8, 0.8) * d
                x, y = ex + d * fx - s * fy, ey + d * fy + s * fx
            elif how < 0.5:                      # by a wall, a fraction of a unit to a few off it
                w = walls[rng.randrange(len(walls))]
                t = rng.uniform(0, 1)
                nx, ny = w[3] - w[1], -(w[2] - w[0])
                n = math.hypot(nx, ny)
                off = r + rng.uniform(0.25, 4)
                x, y = w[0] + t * (w[2] - w[0]) + off * nx / n, w[1] + t * (w[3] - w[1]) + off * ny / n
            elif how < 0.62:                     # straddling the hall's middle line
                x, y = STRADDLE_X + rng.uniform(-0.7, 0.7) * r, rng.uniform(0, 384)
            else:
                room = rng.choice([HALL, HALL, DAIS, GARDEN, CLOSET])
                x, y = rng.uniform(room[0], room[2]), rng.uniform(room[1], room[3])
            x, y = round(x, 3), round(y, 3)
            if not any(_inside(room, x, y, 0) for room in (HALL, DAIS, GARDEN, CLOSET)) or \
                    _inside(PILLAR, x, y, 0):
                continue
            if _dist_to_walls(walls, x, y) < r + 0.2:
                continue
            if math.hypot(x - ex, y - ey) < r + 2:
                continue
            if any(math.hypot(x - px, y - py) < r + sizes[pm][0] + 0.2 for pm, px, py, _, _ in placed):
                continue
            placed.append((model, x, y, _floor_at(x, y), round(rng.uniform(0, 360), 3)))
            break
    return (round(ex, 3), round(ey, 3), round(angle, 3)), placed


def write_objects(path, objects, names=None):
    lines = ["# written by tests/test_objects.py"]
    for model, x, y, z, yaw in objects:
        lines.append(f"object {names[model] if names else model} {x} {y} {z} {yaw}")
    path.write_text("\n".join(lines) + "\n")


def c_render(tmp_path, scene, *extra, at=None, angle=None, mode="spans"):
    out = tmp_path / "c.ids"
    j = render(scene, "--mode", mode, "--ids", out, *extra, at=at, angle=angle)
    return j, np.frombuffer(out.read_bytes(), dtype="<u4").reshape(200, 320)


def reference_for(scene, j):
    cam = j["camera"]
    return refrender.render_ids(scene, cam["x"], cam["y"], cam["z"], cam["angle"], cam["look"],
                                objects=j["objects"], ceilings=j.get("ceilings", {}))


def misplaced_object_pixels(c, ref):
    """Pixels where C shows object k while the reference has no pixel of object k within one
    pixel (rows and columns alike): an object drawn where a nearer surface is, beyond an edge's
    rounding. Returns (rows, cols)."""
    bad = np.zeros(c.shape, bool)
    wrong = (c != ref) & ((c >> 24) == 4)
    for k in np.unique(c[wrong]):
        mine = np.pad(ref == k, 1)
        near = np.zeros(c.shape, bool)
        for dy in (0, 1, 2):
            for dx in (0, 1, 2):
                near |= mine[dy:dy + 200, dx:dx + 320]
        bad |= wrong & (c == k) & ~near
    return np.nonzero(bad)


AGREEMENT = []                    # per configuration, for the summary below


@pytest.mark.parametrize("seed", range(SEEDS))
def test_random_configurations(seed, tmp_path):
    rng = random.Random(1000 + seed)
    names = [m.name for m in refrender.load(SCENE).models]
    failures = []
    for i in range(PER_SEED):
        (ex, ey, angle), objects = random_configuration(rng)
        path = tmp_path / f"objects{i}.txt"
        write_objects(path, objects, names if i % 2 else None)   # by name and by number
        j, c = c_render(tmp_path, SCENE, "--objects", path, at=f"{ex},{ey}", angle=str(angle))
        tag = (f"seed {seed} configuration {i}: build/render {SCENE} --at {ex},{ey} --angle {angle} "
               f"--objects {path}")
        assert len(j["objects"]) == len(objects), tag
        for (model, x, y, z, yaw), o in zip(objects, j["objects"]):
            assert (o["model"], o["x"], o["y"], o["z"], o["yaw"]) == \
                pytest.approx((model, x, y, z, yaw), abs=1 / 65536), tag
        if j["overdraw"] != 1.0 or j["pixels_written"] != 64000:
            failures.append(f"{tag}: overdraw {j['overdraw']}, pixels_written {j['pixels_written']}")
        ref = reference_for(SCENE, j)
        agree = float((c == ref).mean())
        AGREEMENT.append(agree)
        if agree < MIN_AGREE:
            failures.append(f"{tag}: {agree:.4%} of pixels agree with the reference")
        rows, cols = misplaced_object_pixels(c, ref)
        if rows.size:
            failures.append(f"{tag}: {rows.size} object pixels where the reference has a nearer "
                            f"surface (e.g. row {rows[0]} column {cols[0]}: C {c[rows[0], cols[0]]:#x}, "
                            f"reference {ref[rows[0], cols[0]]:#x})")
    assert not failures, "\n".join(failures)


def test_random_configurations_summary():
    """Runs after the configurations (file order): prints min and median agreement."""
    if not AGREEMENT:
        pytest.skip("no configuration ran")
    print(f"\nobjects: {len(AGREEMENT)} configurations, agreement min {min(AGREEMENT):.4%}, "
          f"median {statistics.median(AGREEMENT):.4%}")


def test_configurations_are_varied():
    """The generator does what the header says: every model, objects straddling the middle
    line, within a few units of walls, near the eye, on the dais, and overlapping on screen."""
    rng = random.Random(1000)
    sizes, walls = _model_sizes(), _walls()
    seen = {"models": set(), "straddle": 0, "by_wall": 0, "near_eye": 0, "dais": 0, "overlap": 0,
            "off_screen_edge": 0}
    for _ in range(PER_SEED * 3):
        (ex, ey, angle), objects = random_configuration(rng)
        fx, fy = math.cos(math.radians(angle)), math.sin(math.radians(angle))
        spans = []                        # screen columns covered by each object's bounding circle
        for model, x, y, z, _ in objects:
            r = sizes[model][0]
            seen["models"].add(model)
            seen["straddle"] += abs(x - STRADDLE_X) < r
            seen["by_wall"] += _dist_to_walls(walls, x, y) < r + 4
            seen["near_eye"] += math.hypot(x - ex, y - ey) < r + 20
            seen["dais"] += z == 24
            depth, side = (x - ex) * fx + (y - ey) * fy, (x - ex) * fy - (y - ey) * fx
            if depth > r:
                lo, hi = 160 + 160 * (side - r) / depth, 160 + 160 * (side + r) / depth
                seen["off_screen_edge"] += lo < 0 < hi or lo < 320 < hi
                spans.append((lo, hi))
        seen["overlap"] += any(a[0] < b[1] and b[0] < a[1] and max(a[0], b[0]) < 320 and min(a[1], b[1]) > 0
                               for i, a in enumerate(spans) for b in spans[:i])
    assert seen["models"] == set(range(len(sizes)))
    assert min(v for k, v in seen.items() if k != "models") > 0, seen


# ---- paths and doors ----------------------------------------------------------------------

def _yaw_diff(a, b):
    return abs((a - b + 180) % 360 - 180)


@pytest.mark.parametrize("t", [0, 1000, 2000, 2999, 4000, 6500, 8000, 123457])
def test_paths_at_time(t, tmp_path):
    """--time moves the scene's objects along their paths as docs/objects.md defines them (the
    closed forms of refrender.object_states), and the frame agrees with the reference."""
    j, c = c_render(tmp_path, SCENE, "--time", t, at="40,40", angle="45")
    want = refrender.object_states(SCENE, t)
    assert len(j["objects"]) == len(want)
    for i, (o, (model, x, y, z, yaw)) in enumerate(zip(j["objects"], want)):
        assert o["model"] == model, i
        assert math.hypot(o["x"] - x, o["y"] - y) < 1 / 16 and o["z"] == z, (i, t, o, (x, y, z))
        assert _yaw_diff(o["yaw"], yaw) < 1 / 16, (i, t, o["yaw"], yaw)
    assert j["overdraw"] == 1.0 and j["pixels_written"] == 64000
    ref = reference_for(SCENE, j)
    assert (c == ref).mean() >= MIN_AGREE
    assert misplaced_object_pixels(c, ref)[0].size == 0


def test_paths_move(tmp_path):
    """The circling slab (object 3) and the spike going to and fro (object 4) are somewhere else
    at a quarter period; the static ones stay put."""
    a = render(SCENE, "--time", 0)["objects"]
    b = render(SCENE, "--time", 2000)["objects"]
    assert a[0] == b[0] and a[1] == b[1] and a[5] == b[5]
    assert math.hypot(b[3]["x"] - a[3]["x"], b[3]["y"] - a[3]["y"]) > 60      # 48 * sqrt 2
    assert b[4]["y"] - a[4]["y"] == pytest.approx(128, abs=1 / 16)             # 2/3 of the way
    assert render(SCENE)["objects"] == a


@pytest.mark.parametrize("h", [0, 56, 112])
def test_door_option(h, tmp_path):
    """--door opens the closet's door: the JSON reports the ceiling, the frame agrees with the
    reference given it, and the crate in the closet shows under a door open by 56 or more."""
    j, c = c_render(tmp_path, SCENE, "--door", f"{DOOR}={h}", at="40,192", angle="180")
    assert j["ceilings"] == ({} if h == 0 else {str(DOOR): h})
    assert j["overdraw"] == 1.0 and j["pixels_written"] == 64000
    ref = reference_for(SCENE, j)
    assert (c == ref).mean() >= MIN_AGREE
    assert misplaced_object_pixels(c, ref)[0].size == 0
    assert ((c == OBJ | 5).any()) == (h > 0)


@pytest.mark.parametrize("t,h", [(0, 0), (250, 32), (500, 64), (2000, 112), (3500, 112)])
def test_door_opens_with_time(t, h, tmp_path):
    """With the eye 40 units from the door (within 64) from time 0, the door rises at 128 units
    per second to 112 and stays open for 3 s (docs/objects.md)."""
    j, c = c_render(tmp_path, SCENE, "--time", t, at="40,192", angle="180")
    assert float(j["ceilings"].get(str(DOOR), 0)) == pytest.approx(h, abs=1 / 16), j["ceilings"]
    ref = reference_for(SCENE, j)
    assert (c == ref).mean() >= MIN_AGREE


def test_no_objects_and_scene_objects(tmp_path):
    j, c = c_render(tmp_path, SCENE, "--no-objects", at="100,100", angle="30")
    assert j["objects"] == [] and not ((c >> 24) == 4).any()
    assert (c == refrender.render_ids(SCENE, 100, 100, None, 30, objects=[])).mean() >= MIN_AGREE
    j, c = c_render(tmp_path, SCENE, at="100,100", angle="30")
    assert len(j["objects"]) == 6 and ((c >> 24) == 4).any()
    assert j["objects_visible"] >= 1 and j["object_faces"] >= 1
    ref = refrender.render_ids(SCENE, 100, 100, None, 30)          # the scene's own at time 0
    assert (c == ref).mean() >= MIN_AGREE
    assert (reference_for(SCENE, j) == ref).all()


def test_painter_draws_objects_too(tmp_path):
    """Painter mode is the measured baseline, not exact: it draws the objects, roughly where
    the reference has them."""
    j, c = c_render(tmp_path, SCENE, at="100,100", angle="30", mode="painter")
    ref = reference_for(SCENE, j)
    obj = (ref >> 24) == 4
    assert obj.any() and (c[obj] == ref[obj]).mean() > 0.9


# ---- option errors ------------------------------------------------------------------------

@pytest.mark.parametrize("text,message", [
    ("object crate 1 2 3\n", ":1: expected 'object MODEL X Y Z YAW'"),
    ("# fine\nobject nosuch 1 2 0 0\n", ":2: model 'nosuch'"),
    ("object 99 1 2 0 0\n", ":1: model '99'"),
    ("\nobject crate 1 2 0 east\n", ":2: YAW 'east' is not a number"),
    ("object crate 1 2 -20000 0\n", ":1: Z outside the height range"),
    ("object crate 40000 2 0 0\n", ":1: X, Y outside the world box"),
    ("thing crate 1 2 0 0\n", ":1: expected"),
])
def test_objects_file_errors(text, message, tmp_path):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    proc = run([program("render"), SCENE, "--objects", path], check=False)
    assert proc.returncode == 1 and f"{path}{message}" in proc.stderr, proc.stderr


@pytest.mark.parametrize("args,message", [
    (["--door", "1=50"], "sector 1 is not a door"),
    (["--door", f"{DOOR}=200"], "between 0 (closed) and 112 (open)"),
    (["--door", "5"], "expected SECTOR=H"),
    (["--time", "-5"], "--time '-5'"),
    (["--objects", "/nonexistent/o.txt"], "/nonexistent/o.txt"),
    (["--objects", "x", "--no-objects"], "exclude each other"),
])
def test_option_errors(args, message):
    proc = run([program("render"), SCENE, *args], check=False)
    assert proc.returncode in (1, 2) and message in proc.stderr, proc.stderr


def test_help_documents_the_options():
    out = run([program("render"), "--help"]).stdout
    for opt in ("--time MS", "--objects FILE", "--no-objects", "--door SECTOR=H", "\"objects\"",
                "\"ceilings\""):
        assert opt in out


def test_model_names_only_from_text_scenes(tmp_path):
    """A compiled scene keeps no model names: numbers work, names are refused with a reason."""
    bsc = tmp_path / "objects.bsc"
    run([program("bspc"), SCENE, "-o", bsc])
    path = tmp_path / "o.txt"
    path.write_text("object 2 100 100 0 10\n")
    j = render(bsc, "--objects", path)
    assert j["objects"] == [{"model": 2, "x": 100, "y": 100, "z": 0, "yaw": 10}]
    path.write_text("object tower 100 100 0 10\n")
    proc = run([program("render"), bsc, "--objects", path], check=False)
    assert proc.returncode == 1 and "only a text scene's models have names" in proc.stderr


# ---- Freedoom's MAP01: its things as objects ------------------------------------------------

MAP01 = "freedoom2.wad:MAP01"
MAP01_VIEWS = [(None, None), ("-192,-160", "90"), ("300,200", "45"), ("1561,886", "271")]


@pytest.mark.parametrize("at,angle", MAP01_VIEWS)
def test_map01_things(at, angle, tmp_path):
    """MAP01's things are objects (sprites, and its see-through middle textures after them):
    build/render draws them without a sanitizer report in the default mode, and the frame agrees
    with the reference given the JSON's objects (the first view is the player start, the others
    look at more things)."""
    freedoom("freedoom2.wad")
    j, c = c_render(tmp_path, MAP01, at=at, angle=angle, mode="columns")  # the mode that draws sprites' holes
    m = refrender.load(MAP01)
    assert len(j["objects"]) == len(m.objects) > 0
    assert j["overdraw"] == 1.0 and j["pixels_written"] == 64000
    ref = reference_for(MAP01, j)
    agree = float((c == ref).mean())
    assert agree >= MIN_AGREE, f"{agree:.4%}"
    assert misplaced_object_pixels(c, ref)[0].size == 0
    # the things as the reference reads them are the things the compiler placed
    for o, (model, x, y, z, yaw) in zip(j["objects"], refrender.object_states(MAP01, 0)):
        assert (o["x"], o["y"], o["z"]) == (x, y, z) and _yaw_diff(o["yaw"], yaw) == 0


BATTLE = str(ROOT / "tests/scenes/battle.scene")


@pytest.mark.parametrize("t", [0, 3000, 8000, 20000, 61000])
@pytest.mark.parametrize("view", [("0,-900,500", "90", "0"), ("0,-1500", "90", "60"), ("-600,300,700", "-20", "-40")])
def test_battle_demo(view, t, tmp_path):
    """The space-battle demo: ships on their paths at time t, all independent of one another."""
    at, angle, look = view
    j, c = c_render(tmp_path, BATTLE, "--time", str(t), "--look", look, at=at, angle=angle)
    assert j["overdraw"] == 1.0 and j["pixels_written"] == 64000
    assert j["objects_visible"] >= 5
    ref = reference_for(BATTLE, j)
    same = float((c == ref).mean())
    assert same >= 0.995, f"only {same:.4%} of pixels agree with the reference"
    rows, _ = misplaced_object_pixels(c, ref)
    assert rows.size == 0, f"{rows.size} object pixels where the reference has a nearer surface"


# ---- doors over time, the player walking (build/fltool walk --keys: eng_step frame by frame) ----

DOOR_BOX = (-16, 160, 0, 224)    # the door sector of objects.scene (xmin, ymin, xmax, ymax)
DOOR_OPEN, DOOR_SPEED, DOOR_WAIT_MS, DOOR_REACH = 112, 128, 3000, 64   # docs/objects.md


def door_triggered(raw_x, raw_y):
    """docs/objects.md: the player within 64 units of a door wall, or in the door; decided on
    the 1/16 grid. The door is a box, so that is the distance to the box."""
    gx, gy = raw_x >> 12, raw_y >> 12
    x0, y0, x1, y1 = (v * 16 for v in DOOR_BOX)
    dx, dy = max(x0 - gx, 0, gx - x1), max(y0 - gy, 0, gy - y1)
    return dx * dx + dy * dy <= (DOOR_REACH * 16) ** 2


def door_model(triggered, dt):
    """The door's ceiling (16.16) after each frame, from the rules written out millisecond by
    millisecond: rise at 128 units/s while triggered; once open, stay open 3 s from the last
    triggered frame, then fall at 128 units/s; triggered again while falling, rise again."""
    rate = DOOR_SPEED << 16                              # 16.16 units per 1000 ms
    full = -(-(DOOR_OPEN << 16) * 1000 // rate)          # ms from closed to open
    travel, wait, out = 0, 0, []
    for trig in triggered:
        if trig:
            wait, travel = DOOR_WAIT_MS, min(full, travel + dt)
        else:
            for _ in range(dt):
                if wait and travel == full:
                    wait -= 1
                else:
                    wait, travel = 0, max(0, travel - 1)
        out.append(min(DOOR_OPEN << 16, travel * rate // 1000))
    return out


@pytest.mark.parametrize("dt", [50, 29])
def test_door_timing_while_walking(tmp_path, dt):
    """The player walks up to the closet's door, waits, leaves, comes back while it closes and
    leaves again, frame by frame through the engine (build/fltool walk --keys). Each frame's
    door ceiling is what the rules give for the positions the walk went through, and the named
    moments fall where the rules put them: open 875 ms after the first triggered frame, open
    for 3 s after the last, then closed 875 ms later."""
    per_s = 1000 // dt
    script = (f"b*{per_s // 3},-*{per_s * 3 // 2},f*{per_s // 2},-*{per_s * 5 // 2},"
              f"b*{per_s // 2},-*{per_s * 3 // 2},f*{per_s // 2},-*{per_s * 5}")
    run([program("fltool"), "walk", SCENE, "--keys", script, "--dt", dt, "--out", tmp_path])
    frames = [json.loads(line) for line in (tmp_path / "frames.jsonl").read_text().splitlines()]
    assert [f["t_ms"] for f in frames] == [dt * (n + 1) for n in range(len(frames))]
    trig = [door_triggered(f["raw"][0], f["raw"][1]) for f in frames]
    got = [round(float(f["ceilings"].get(str(DOOR), 0)) * 65536) for f in frames]
    # the walk does what the script means: near, away (long enough to close partly), near, away
    runs = [k for k in range(1, len(trig)) if trig[k] != trig[k - 1]]
    assert trig[0] is False and len(runs) == 4, runs
    first, leave1, back, leave2 = runs
    assert got == door_model(trig, dt)

    full_ms, rate = -(-DOOR_OPEN * 1000 // DOOR_SPEED), DOOR_SPEED << 16
    opened = first + -(-full_ms // dt) - 1                  # the frame it reaches 112
    assert all(g == 0 for g in got[:first])
    assert got[opened] == DOOR_OPEN << 16 and got[opened - 1] < DOOR_OPEN << 16
    assert all(0 < g < DOOR_OPEN << 16 for g in got[first:opened])
    # open from then until 3 s after the last triggered frame, then falling
    last = leave1 - 1
    stays = last + DOOR_WAIT_MS // dt                       # the last frame the 3 s cover whole
    assert all(g == DOOR_OPEN << 16 for g in got[opened:stays + 1])
    assert got[stays + 1] < DOOR_OPEN << 16
    # back while it falls: it rises again from where it was, at the same speed
    assert 0 < got[back - 1] < DOOR_OPEN << 16
    assert got[back] - got[back - 1] == pytest.approx(dt * rate / 1000, abs=1)
    # after the second visit: open 3 s, then closed the travel time later
    last = leave2 - 1
    stays = last + DOOR_WAIT_MS // dt
    closed = last + -(-(DOOR_WAIT_MS + full_ms) // dt)      # the first frame that ends past both
    assert got[stays] == DOOR_OPEN << 16 and got[stays + 1] < DOOR_OPEN << 16
    assert got[closed] == 0 and got[closed - 1] > 0
    assert all(g == 0 for g in got[closed:])
