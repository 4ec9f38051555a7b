"""Textures by time (docs/textures.md, "Animation"): Doom's animated flats and wall textures and its
scrolling walls, drawn at the engine's time.

- an animated flat shows the next frame's texels 8 tics later, the frame the reference renderer
  (tools/reflook.py, from the WAD) expects at that time, and wraps after its frames;
- a scrolling wall moves one texel a tic: its frame at tic k is the frame of the same side with its
  texture column moved k units by hand;
- a map without animations carries no animation section and no SCN_NEED_ANIM, one with them both,
  with the WAD's phase; its per-scene build says so;
- the loader refuses every animation record outside the format's limits, and takes the limits;
- a frame the firmware sent at a time with an animated wall in view is redrawn bit for bit by
  tools/capture.py --render (the frame link carries the time).
"""
import json
import math
import struct
import subprocess
import sys
import zlib

import numpy as np
import pytest

from conftest import ROOT, freedoom, program, render, run

sys.path.insert(0, str(ROOT / "tools"))
import texcompare  # noqa: E402

SEC_NEEDS, SEC_LOOK, SEC_LINES, SEC_VERTICES, SEC_SIDES, SEC_PLANES, SEC_LEAVES, SEC_PVERTS, SEC_TEXTURES = \
    13, 14, 2, 0, 18, 19, 5, 6, 16
SEC_ANIMS = 23
NEED_ANIM = 1 << 8
SIDE_SCROLL = 4
ANIM_MAX_FRAMES, ANIM_MAX_TICS = 64, 3500
KIND_WALL, KIND_FLOOR = 1, 2


def ms_of_tic(tic):
    """The first millisecond of level tic `tic` (floor(t * 35 / 1000) = tic)."""
    return math.ceil(tic * 1000 / 35)


def section(blob, i):
    return struct.unpack_from("<II", blob, 44 + 8 * i)


def anims(blob):
    off, n = section(blob, SEC_ANIMS)
    return [struct.unpack_from("<IHHHH", blob, off + 12 * i) for i in range(n)]


def features(blob):
    return struct.unpack_from("<I", blob, section(blob, SEC_NEEDS)[0])[0]


def fix_crc(data):
    total = struct.unpack_from("<I", data, 8)[0]
    data[12:16] = struct.pack("<I", zlib.crc32(bytes(data[16:total])) & 0xFFFFFFFF)
    return data


def compile_map(tmp_path, spec, name="m.bsc", *extra):
    out = tmp_path / name
    run([program("bspc", sanitized=False), spec, "-o", out, *extra])
    return out


@pytest.fixture(scope="module")
def map01(tmp_path_factory):
    freedoom("freedoom2.wad")
    return compile_map(tmp_path_factory.mktemp("anim"), "freedoom2.wad:MAP01")


def frame_and_ids(scene, tmp_path, *args, tag="f"):
    raw, ids = tmp_path / f"{tag}.raw", tmp_path / f"{tag}.ids"
    j = render(scene, *args, "--raw", raw, "--ids", ids)
    return j, np.fromfile(raw, np.uint8).reshape(200, 320), np.fromfile(ids, "<u4").reshape(200, 320)


# ---- an animated flat ---------------------------------------------------------------------------

def water_view(blob):
    """A camera over the largest leaf floored with the first frame of the scene's first animated flat
    sequence, looking down at it: (sector, first texture of the sequence, --at, --angle, --look)."""
    first, count, phase, tics, _ = next(a for a in anims(blob)
                                       if a[0] in {p for pl in planes(blob) for p in pl})
    poff, npl = section(blob, SEC_PLANES)
    loff, nl = section(blob, SEC_LEAVES)
    voff, _ = section(blob, SEC_PVERTS)
    best = None
    for i in range(nl):
        _, _, sec, fp, n = struct.unpack_from("<IIIII", blob, loff + 20 * i)
        if sec == 0xFFFFFFFF or n < 3 or struct.unpack_from("<H", blob, poff + 4 * sec)[0] != first:
            continue
        pts = [struct.unpack_from("<ii", blob, voff + 8 * (fp + k)) for k in range(n)]
        area = sum(pts[k][0] * pts[(k + 1) % n][1] - pts[(k + 1) % n][0] * pts[k][1] for k in range(n))
        if best is None or area > best[0]:
            cx = sum(p[0] for p in pts) / n / 65536
            cy = sum(p[1] for p in pts) / n / 65536
            best = (area, sec, f"{cx:.0f},{cy:.0f}")
    assert best, "no leaf shows the animated flat"
    return best[1], first, best[2], "90", "-60"


def planes(blob):
    off, n = section(blob, SEC_PLANES)
    return [struct.unpack_from("<HH", blob, off + 4 * i) for i in range(n)]


def wad_flat_phase(wad, first, count):
    """Doom's number of flat `first` (its lump after F_START) modulo count, read from the WAD."""
    data = wad.read_bytes()
    n, dirofs = struct.unpack_from("<II", data, 4)
    names = [struct.unpack_from("<II8s", data, dirofs + 16 * i)[2].split(b"\0")[0].decode("latin-1").upper()
             for i in range(n)]
    last = {name: i for i, name in enumerate(names)}
    return (last[first] - (last["F_START"] + 1)) % count


def test_animated_flat_changes_every_8_tics_and_wraps(map01, tmp_path):
    blob = map01.read_bytes()
    sector, first, at, angle, look = water_view(blob)
    rec = next(a for a in anims(blob) if a[0] == first)
    count, phase, tics = rec[1], rec[2], rec[3]
    assert (count, tics) == (4, 8)  # FWATER1..4, Doom's 8 tics a frame
    assert phase == wad_flat_phase(freedoom("freedoom2.wad"), "FWATER1", count)
    cam = ["--at", at, "--angle", angle, "--look", look]
    frames, floor = {}, None
    for k in range(count + 1):
        t = ms_of_tic(tics * k)
        _, frames[k], ids = frame_and_ids(map01, tmp_path, *cam, "--time", t, tag=f"w{k}")
        mine = ids == (KIND_FLOOR << 24 | sector)
        floor = mine if floor is None else floor
        assert (mine == floor).all()  # the same pixels are that floor at every time
        # the reference's texels and light at that time, from the WAD itself
        e = texcompare.reference("freedoom2.wad:MAP01", at, angle, look, time_ms=t)
        nums, n = np.unique(e.tex[floor], return_counts=True)
        assert e.look.names[nums[n.argmax()]] == (f"FWATER{(phase + k) % count + 1}", True), k
        assert n.max() > 0.99 * floor.sum()
        ok = e.accept(frames[k])
        assert ok[floor].mean() > 0.99, (k, ok[floor].mean())
        if k:
            # not the frame before: the floor changed to the next frame's texels
            before = texcompare.reference("freedoom2.wad:MAP01", at, angle, look, time_ms=ms_of_tic(tics * k - 1))
            assert before.accept(frames[k])[floor].mean() < 0.8
            assert (frames[k][floor] != frames[k - 1][floor]).mean() > 0.5
    assert floor.sum() > 10000
    # the sequence wraps after its frames; a tic before the change is still the frame before
    assert (frames[count][floor] == frames[0][floor]).all()
    _, late, _ = frame_and_ids(map01, tmp_path, *cam, "--time", ms_of_tic(tics) - 1, tag="late")
    assert (late[floor] == frames[0][floor]).all()


# ---- a scrolling wall ---------------------------------------------------------------------------

def scrolling_side(blob):
    """The first scrolling side and a camera 96 units in front of its middle, facing it."""
    soff, ns = section(blob, SEC_SIDES)
    side = next(i for i in range(ns) if blob[soff + 24 * i + 22] & SIDE_SCROLL)
    loff, _ = section(blob, SEC_LINES)
    voff, _ = section(blob, SEC_VERTICES)
    v1, v2 = struct.unpack_from("<II", blob, loff + 24 * (side // 2))
    (x1, y1), (x2, y2) = [[c / 65536 for c in struct.unpack_from("<ii", blob, voff + 8 * v)] for v in (v1, v2)]
    if side & 1:
        x1, y1, x2, y2 = x2, y2, x1, y1
    ln = math.hypot(x2 - x1, y2 - y1)
    nx, ny = (y2 - y1) / ln, -(x2 - x1) / ln  # the side's front is on the right
    cx, cy = (x1 + x2) / 2 + 96 * nx, (y1 + y2) / 2 + 96 * ny
    return side, f"{cx:.0f},{cy:.0f}", f"{math.degrees(math.atan2(-ny, -nx)) % 360:.0f}"


def test_scrolling_wall_moves_one_texel_a_tic(map01, tmp_path):
    """Doom's line special 48 adds a unit to its front side's texture offset every tic: the frame at
    tic k is the frame at the same time of the side standing still with its column moved k units."""
    blob = map01.read_bytes()
    side, at, angle = scrolling_side(blob)
    soff, _ = section(blob, SEC_SIDES)
    u0 = struct.unpack_from("<i", blob, soff + 24 * side + 8)[0]
    cam = ["--at", at, "--angle", angle, "--no-objects"]
    _, still, ids = frame_and_ids(map01, tmp_path, *cam, "--time", 0, tag="s0")
    wall = ids == (KIND_WALL << 24 | side)
    assert wall.sum() > 5000
    for k in (1, 2, 37):
        t = ms_of_tic(k)
        _, moved, _ = frame_and_ids(map01, tmp_path, *cam, "--time", t, tag=f"s{k}")
        by_hand = bytearray(blob)
        by_hand[soff + 24 * side + 22] &= ~SIDE_SCROLL & 0xFF
        struct.pack_into("<i", by_hand, soff + 24 * side + 8, u0 + (k << 16))
        bsc = tmp_path / f"hand{k}.bsc"
        bsc.write_bytes(fix_crc(by_hand))
        _, hand, _ = frame_and_ids(bsc, tmp_path, *cam, "--time", t, tag=f"h{k}")
        assert (moved == hand).all(), k
        assert (moved[wall] != still[wall]).mean() > 0.3, k
        if k < 8:  # nothing else has changed yet
            assert (moved[~wall] == still[~wall]).all()
        e = texcompare.reference("freedoom2.wad:MAP01", at, angle, 0, objects=[], time_ms=t)
        assert e.accept(moved)[wall].mean() > 0.99


# ---- what a map carries ---------------------------------------------------------------------------

def test_a_map_without_animation_carries_none(map01, tmp_path):
    """freedoom2 MAP07 has no animated texture or flat and no scrolling line: no animation section,
    no SCN_NEED_ANIM, no scrolling side; MAP01 has all three, and a per-scene build of each says so."""
    quiet = compile_map(tmp_path, "freedoom2.wad:MAP07", "map07.bsc").read_bytes()
    assert section(quiet, SEC_ANIMS)[1] == 0 and not features(quiet) & NEED_ANIM
    soff, ns = section(quiet, SEC_SIDES)
    assert ns > 0 and not any(quiet[soff + 24 * i + 22] & SIDE_SCROLL for i in range(ns))
    busy = map01.read_bytes()
    assert len(anims(busy)) >= 2 and features(busy) & NEED_ANIM
    flat = compile_map(tmp_path, "freedoom2.wad:MAP01", "flat.bsc", "--flat").read_bytes()
    assert section(flat, SEC_ANIMS)[1] == 0 and not features(flat) & NEED_ANIM
    text = compile_map(tmp_path, str(ROOT / "tests/scenes/default.scene"), "d.bsc").read_bytes()
    assert section(text, SEC_ANIMS)[1] == 0 and not features(text) & NEED_ANIM
    for spec, want in (("freedoom2.wad:MAP07", False), ("freedoom2.wad:MAP01", True)):
        bsc = tmp_path / "n.bsc"
        out = run([program("bspc", sanitized=False), spec, "-o", bsc, "--needs"]).stdout
        line = next(l for l in out.splitlines() if l.strip().startswith("animation "))
        assert line.split()[1] == ("yes" if want else "no"), line
        cfg = tmp_path / "cfg.h"
        run([program("bspc", sanitized=False), bsc, "--config", cfg])
        value = int(cfg.read_text().split("#define CFG_FEATURES ")[1].split("u")[0], 16)
        assert bool(value & NEED_ANIM) == want
    # every frame of a sequence is stored, one after another, and only once
    for first, count, phase, tics, reserved in anims(busy):
        assert count >= 2 and phase < count and tics == 8 and reserved == 0
        assert first + count <= section(busy, SEC_TEXTURES)[1]


def test_a_flat_shaded_frame_does_not_animate(map01):
    """--flat draws each part and plane in its one flat colour: the frame is the same at every time
    (docs/textures.md, "Animation")."""
    crcs = {render(str(map01), "--flat", "--time", t, "--no-objects")["crc32"] for t in (0, 229, 458, 5000)}
    assert len(crcs) == 1


# ---- the loader's limits ------------------------------------------------------------------------------

def patched(blob, rec, **fields):
    off = section(blob, SEC_ANIMS)[0] + 12 * rec
    d = bytearray(blob)
    layout = {"first": ("<I", 0), "count": ("<H", 4), "phase": ("<H", 6), "tics": ("<H", 8), "reserved": ("<H", 10)}
    for name, value in fields.items():
        fmt, at = layout[name]
        struct.pack_into(fmt, d, off + at, value)
    return fix_crc(d)


def loads(tmp_path, data, good):
    bad = tmp_path / "x.bsc"
    bad.write_bytes(bytes(data))
    proc = run([program("render"), bad, "--raw", tmp_path / "x.raw"], check=False)
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr
    if good:
        assert proc.returncode == 0, proc.stderr
    else:
        assert proc.returncode == 1 and "animations record" in proc.stderr, proc.stderr
    return proc.stderr


def test_loader_takes_the_limits_and_refuses_one_past(map01, tmp_path):
    blob = map01.read_bytes()
    recs = anims(blob)
    last = len(recs) - 1
    first, count, phase, tics, _ = recs[last]
    ntex = section(blob, SEC_TEXTURES)[1]
    # the last sequence may start right after the one before it and run to the last texture
    start = recs[last - 1][0] + recs[last - 1][1] if last else 0
    assert start + ANIM_MAX_FRAMES + 1 <= ntex, "the test needs room for the longest sequence"
    cases = [
        ({"tics": 1}, True), ({"tics": ANIM_MAX_TICS}, True),
        ({"tics": 0}, False), ({"tics": ANIM_MAX_TICS + 1}, False),
        ({"phase": count - 1}, True), ({"phase": count}, False), ({"phase": 0xFFFF}, False),
        ({"count": 2, "phase": 0}, True), ({"count": 1, "phase": 0}, False), ({"count": 0, "phase": 0}, False),
        ({"first": start, "count": ANIM_MAX_FRAMES}, True), ({"first": start, "count": ANIM_MAX_FRAMES + 1}, False),
        ({"first": ntex - 2, "count": 2, "phase": 1}, True),
        ({"reserved": 1}, False),
    ]
    for fields, good in cases:
        err = loads(tmp_path, patched(blob, last, **fields), good)
        if not good and "count" in fields and fields["count"] > ANIM_MAX_FRAMES:
            assert "outside the proven-safe range" in err
    # past the textures: an index
    err = loads(tmp_path, patched(blob, last, first=ntex - count + 1), False)
    assert f"animations record {last}: index out of range" in err
    err = loads(tmp_path, patched(blob, last, first=ntex - 1, count=2, phase=0), False)
    assert f"animations record {last}: index out of range" in err
    # sorted and apart: a sequence may not start inside or before the one before it
    assert last >= 1, "the test needs two sequences"
    err = loads(tmp_path, patched(blob, last, first=start - 1), False)
    assert "outside the proven-safe range" in err
    err = loads(tmp_path, patched(blob, last, first=recs[0][0]), False)
    assert "outside the proven-safe range" in err


def test_animations_without_a_look_are_refused(tmp_path):
    """A flat-shaded scene carries no animation: a count in its section is refused by name."""
    d = bytearray(compile_map(tmp_path, str(ROOT / "tests/scenes/default.scene"), "d.bsc").read_bytes())
    struct.pack_into("<II", d, 44 + 8 * SEC_ANIMS, 44 + 8 * 24, 1)
    bad = tmp_path / "bad.bsc"
    bad.write_bytes(bytes(fix_crc(d)))
    proc = run([program("render"), bad], check=False)
    assert proc.returncode == 1
    assert "animations section: 1 records in a scene without a look section, expected 0" in proc.stderr


# ---- a captured frame redrawn ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def firmware_map01():
    """The Cortex-M3 firmware with freedoom2 MAP01 built in (its fly-through, the frame link)."""
    out = ROOT / "build" / "firmware-test" / "arm-anim-map01"
    proc = subprocess.run(["make", "-s", "--no-print-directory", "-j2", "firmware", "SCENE=freedoom2.wad:MAP01",
                           f"ARM_OUT={out}"], cwd=ROOT, capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return out / "firmware.elf"


def test_captured_frame_with_an_animated_wall_redraws(firmware_map01, tmp_path):
    """The firmware's frames carry their time: a frame whose animated textures differ from time 0's
    is redrawn bit for bit by tools/capture.py --render (build/render --time)."""
    from linkrig import capture_run
    records = capture_run(firmware_map01, 24, tmp_path)
    assert [r["time_ms"] for r in records] == sorted(r["time_ms"] for r in records) and records[-1]["time_ms"] > 0
    # the last frame whose animation shows: drawn at time 0 it would differ
    for rec in reversed(records):
        at0 = list(rec["render_args"])
        at0[at0.index("--time") + 1] = "0"
        if render(*at0, sanitized=False)["crc32"] != rec["crc32"]:
            break
    else:
        pytest.fail("no captured frame shows an animated texture that changed")
    assert render(*rec["render_args"], sanitized=False)["crc32"] == rec["crc32"]
    ok = subprocess.run([sys.executable, str(ROOT / "tools/capture.py"), "--render", str(rec["frame"]), "--out",
                         str(tmp_path / "cap")], capture_output=True, text=True, cwd=ROOT)
    assert ok.returncode == 0 and f"frame {rec['frame']}: match" in ok.stderr, ok.stderr
