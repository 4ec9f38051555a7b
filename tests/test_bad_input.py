"""Clear errors: every kind of bad input is refused by the program that reads it with a non-zero
exit status, one message naming the file, the item and the problem, and no output file left
behind; and the frame-link decoder, which never refuses a stream, counts the bad messages.

Kinds (what is already tested elsewhere is not repeated here):
- compiled scenes (firmware/scene_format.h) given to build/render, build/bspc --config and
  build/fltool walk: truncated at several points, wrong magic, wrong version, bad CRC, total_bytes
  other than the file's size, sections out of range, header fields and record indices out of
  range (the record patched and the CRC-32 over [16, total) recomputed, so that the index check
  refuses it and not the CRC); tests/test_render_cli.py checks render's truncate/crc/magic/version
  loosely, tests/unit/test_scene.c the loader's status for each;
- text scenes (docs/scene-format.md) given to build/bspc and build/render: file:line:, the item and
  the problem; tests/test_bspc.py has the coordinate and height limits of the proven range;
- WAD maps: a missing lump of each kind, broken WAD files, lump sizes, indices out of range;
- frame-link streams (build/fltool decode): truncated and garbage, counted, never a crash;
  tests/test_framelink.py has random faults and other versions;
- DFU images (build/flash): the kinds tests/test_flash.py does not have.
"""
import json
import random
import struct
import zlib

import pytest

from conftest import ROOT, program, room_lumps, run, wad_image, write_pwad_map

DEFAULT = ROOT / "tests/scenes/default.scene"


def refused(args, *needles, status=1):
    """Run a program that must refuse its input: the status, one message line on stderr holding
    every needle, no sanitizer report. Returns the message."""
    proc = run(args, check=False)
    err = proc.stderr
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert proc.returncode == status, (args, proc.returncode, err)
    assert err.count("\n") == 1, err
    for needle in needles:
        assert needle in err, (needle, err)
    return err


# ---- compiled scenes ------------------------------------------------------------------------

HEADER_BYTES = 236  # sizeof(scn_header): 44 bytes, then 24 sections of 8
VERSION = 6  # SCN_VERSION
VERTICES, SECTORS, LINES, SEGS, NODES, LEAVES, PVERTS, PALETTE = range(8)
NEEDS = 13
LOOK, LIGHTS, TEXTURES, TEXELS, SIDES, PLANES = range(14, 20)
TEXTURE_BYTES, SIDE_BYTES = 12, 24
SEG_BYTES, NODE_BYTES, LEAF_BYTES, LINE_BYTES = 16, 56, 20, 24
LEAF_BIT = 0x80000000


@pytest.fixture(scope="module")
def compiled(tmp_path_factory):
    out = tmp_path_factory.mktemp("bsc") / "default.bsc"
    run([program("bspc"), DEFAULT, "-o", out])
    return out.read_bytes()


def u32(data, off):
    return struct.unpack_from("<I", data, off)[0]


def put32(data, off, value):
    struct.pack_into("<I", data, off, value)


def section(data, i):
    """(offset, count) of section i."""
    return struct.unpack_from("<II", data, 44 + 8 * i)


def fix_crc(data):
    """The CRC-32 (zlib's) over [16, total_bytes), so that a patch reaches the checks behind it."""
    put32(data, 12, zlib.crc32(bytes(data[16:u32(data, 8)])))


def truncate(n):
    return lambda d: d[:n(d)]


def header_field(off, value):
    def patch(d):
        put32(d, off, value(d) if callable(value) else value)
        fix_crc(d)
        return d
    return patch


def record_field(sec, rec_bytes, index, field_off, value):
    """Patch field_off of record index of section sec to value(data) and recompute the CRC."""
    def patch(d):
        put32(d, section(d, sec)[0] + rec_bytes * index + field_off, value(d))
        fix_crc(d)
        return d
    return patch


def first_node_child(d):
    """Byte offset of child[0] of the root node (the default scene has several nodes)."""
    return section(d, NODES)[0] + NODE_BYTES * u32(d, 36) + 48


def bad_crc(d):
    d[len(d) // 2] ^= 0x40
    return d


def set_version(d):
    d[4] = 99
    fix_crc(d)
    return d


def wrong_magic(d):
    d[0:4] = b"BSCX"
    return d


def appended(d):
    return d + b"\0" * 8


def patch_node_child(value):
    def patch(d):
        put32(d, first_node_child(d), value(d))
        fix_crc(d)
        return d
    return patch


# (id, damage, needles): the needles name the item and the problem
COMPILED = [
    ("truncated-after-magic", truncate(lambda d: 6), ["truncated", "6 bytes", f"{HEADER_BYTES}-byte header"]),
    ("truncated-in-header", truncate(lambda d: 100), ["truncated", "100 bytes", f"{HEADER_BYTES}-byte header"]),
    ("truncated-in-segs", truncate(lambda d: section(d, SEGS)[0] + 5), ["truncated", "header total_bytes"]),
    ("truncated-one-byte-short", truncate(lambda d: len(d) - 1), ["truncated", "header total_bytes"]),
    ("wrong-magic", wrong_magic, ["magic", "BSCN"]),
    ("wrong-version", set_version, ["header", "unsupported version 99", f"reads version {VERSION}"]),
    ("bad-crc", bad_crc, ["bad CRC-32", "header crc32", "damaged"]),
    ("total-bytes-beyond-file", header_field(8, lambda d: len(d) + 4),
     ["truncated", "header total_bytes"]),
    ("total-bytes-short-of-file", appended, ["header: total_bytes", "but the file has"]),
    ("total-bytes-not-multiple-of-4", lambda d: header_field(8, len(d) + 2)(d + b"\0\0"),
     ["header: total_bytes", "not a multiple of 4"]),
    ("header-bytes", header_field(4, lambda d: VERSION | (HEADER_BYTES - 4) << 16),
     [f"header: header_bytes = {HEADER_BYTES - 4}", f"expected {HEADER_BYTES}"]),
    ("flags", header_field(16, 1), ["header: flags = 0x1", "reserved"]),
    ("segs-offset-past-end", header_field(44 + 8 * SEGS, lambda d: len(d)),
     ["segs section", "run past the end"]),
    ("vertices-count-huge", header_field(44 + 8 * VERTICES + 4, 0xFFFFFFFF),
     ["vertices section", "4294967295 records", "run past the end"]),
    ("lines-offset-misaligned", header_field(44 + 8 * LINES, lambda d: section(d, LINES)[0] + 2),
     ["lines section", "not a multiple of 4"]),
    ("leaves-offset-in-header", header_field(44 + 8 * LEAVES, 8), ["leaves section", "inside the header"]),
    ("palette-count", header_field(44 + 8 * PALETTE + 4, 255), ["palette section", "255 entries, expected 256"]),
    ("needs-count", header_field(44 + 8 * NEEDS + 4, 0), ["needs section", "0 records, expected 1"]),
    ("player-sector", header_field(32, lambda d: section(d, SECTORS)[1]), ["header: player_sector", "out of range"]),
    ("root-node", header_field(36, lambda d: section(d, NODES)[1]), ["header: root = node", "out of range"]),
    ("root-leaf", header_field(36, lambda d: LEAF_BIT | section(d, LEAVES)[1]),
     ["header: root = leaf", "out of range"]),
    ("max-depth", header_field(40, 256), ["header: max_depth = 256", "deeper than 255"]),
    ("seg-vertex", record_field(SEGS, SEG_BYTES, 3, 0, lambda d: section(d, VERTICES)[1]),
     ["segs record 3", "index out of range"]),
    ("seg-line", record_field(SEGS, SEG_BYTES, 5, 8, lambda d: 0xFFFFFFFF), ["segs record 5", "index out of range"]),
    ("line-sector", record_field(LINES, LINE_BYTES, 2, 8, lambda d: section(d, SECTORS)[1]),
     ["lines record 2", "index out of range"]),
    ("leaf-first-seg", record_field(LEAVES, LEAF_BYTES, 1, 0, lambda d: section(d, SEGS)[1]),
     ["leaves record 1", "index out of range"]),
    ("leaf-sector", record_field(LEAVES, LEAF_BYTES, 0, 8, lambda d: section(d, SECTORS)[1] + 7),
     ["leaves record 0", "index out of range"]),
    ("node-child", patch_node_child(lambda d: section(d, NODES)[1]), ["nodes record", "index out of range"]),
    ("node-child-leaf", patch_node_child(lambda d: LEAF_BIT | section(d, LEAVES)[1]),
     ["nodes record", "index out of range"]),
    ("vertex-out-of-range", record_field(VERTICES, 8, 0, 0, lambda d: (32768 << 16)),
     ["vertices record 0", "outside the proven-safe range"]),
]


# damage to a textured scene's look (docs/textures.md): (id, damage, needles)
LOOK_DAMAGE = [
    ("side-texture-index", record_field(SIDES, SIDE_BYTES, 3, 16, lambda d: section(d, TEXTURES)[1]),
     ["sides record 3", "index out of range"]),
    ("texture-texels-past-end", record_field(TEXTURES, TEXTURE_BYTES, 2, 0, lambda d: section(d, TEXELS)[1]),
     ["textures record 2", "index out of range"]),
    ("texture-wbits", record_field(TEXTURES, TEXTURE_BYTES, 1, 4, lambda d: 11),
     ["textures record 1", "outside the proven-safe range"]),
    ("texture-height-zero", record_field(TEXTURES, TEXTURE_BYTES, 1, 8, lambda d: 0),
     ["textures record 1", "outside the proven-safe range"]),
    ("texture-taller-than-stored", record_field(TEXTURES, TEXTURE_BYTES, 1, 8, lambda d: 2048),
     ["textures record 1", "outside the proven-safe range"]),
    ("side-flags", record_field(SIDES, SIDE_BYTES, 5, 20, lambda d: 0x00080000),
     ["sides record 5", "outside the proven-safe range"]),
    ("plane-texture-index", record_field(PLANES, 4, 7, 0, lambda d: section(d, TEXTURES)[1] + 1),
     ["planes record 7", "index out of range"]),
    ("sky-texture-index", record_field(LOOK, 8, 0, 0, lambda d: section(d, TEXTURES)[1]),
     ["look record 0", "index out of range"]),
    ("sides-count", header_field(44 + 8 * SIDES + 4, lambda d: section(d, SIDES)[1] - 2),
     ["sides section", "expected 2 per line"]),
    ("lights-count", header_field(44 + 8 * LIGHTS + 4, 31), ["light tables section", "31 tables, expected 32"]),
    ("look-count", header_field(44 + 8 * LOOK + 4, 2), ["look section", "2 records, expected 0 or 1"]),
]


@pytest.fixture(scope="module")
def textured(tmp_path_factory):
    out = tmp_path_factory.mktemp("bsc") / "map01.bsc"
    run([program("bspc"), "freedoom2.wad:MAP01", "-o", out])
    return out.read_bytes()


@pytest.mark.parametrize("damage, needles", [c[1:] for c in LOOK_DAMAGE], ids=[c[0] for c in LOOK_DAMAGE])
@pytest.mark.parametrize("tool", ["render", "bspc"])
def test_damaged_look_is_refused(textured, tmp_path, tool, damage, needles):
    bad = tmp_path / "bad.bsc"
    bad.write_bytes(bytes(damage(bytearray(textured))))
    out = tmp_path / "out"
    args = [program("render"), bad, "-o", out] if tool == "render" else [program("bspc"), bad, "--config", out]
    err = refused(args, f"{tool}: {bad}: ", "compiled scene rejected", *needles)
    assert not out.exists()


@pytest.mark.parametrize("damage, needles", [c[1:] for c in COMPILED], ids=[c[0] for c in COMPILED])
@pytest.mark.parametrize("tool", ["render", "bspc", "fltool"])
def test_damaged_compiled_scene(compiled, tmp_path, tool, damage, needles):
    bad = tmp_path / "bad.bsc"
    bad.write_bytes(bytes(damage(bytearray(compiled))))
    out = tmp_path / "out"
    if tool == "render":
        args = [program("render"), bad, "-o", out]
    elif tool == "bspc":
        args = [program("bspc"), bad, "--config", out]
    else:
        out.mkdir()
        args = [program("fltool"), "walk", bad, "--frames", "1", "--out", out]
    err = refused(args, f"{tool}: {bad}: ", *needles)
    if damage is not wrong_magic:  # a file without the magic is not taken for a compiled scene
        assert "compiled scene rejected" in err, err
    assert not out.exists() or not any(out.iterdir()), "output left behind"


def test_a_good_compiled_scene_passes_the_same_checks(compiled, tmp_path):
    """The damage above is all that is wrong: the same file undamaged, with a recomputed CRC, loads."""
    good = tmp_path / "good.bsc"
    data = bytearray(compiled)
    fix_crc(data)
    good.write_bytes(bytes(data))
    run([program("render"), good, "-o", tmp_path / "f.png"])
    run([program("bspc"), good, "--config", tmp_path / "c.h"])
    assert (tmp_path / "f.png").exists() and (tmp_path / "c.h").exists()


def test_compiled_scene_is_not_a_source(compiled, tmp_path):
    """bspc compiles sources: a compiled scene given to it (without --config) is named as one."""
    bsc = tmp_path / "scene.bsc"
    bsc.write_bytes(compiled)
    refused([program("bspc"), bsc, "-o", tmp_path / "again.bsc"], f"{bsc}: a compiled scene, not a source")
    assert not (tmp_path / "again.bsc").exists()


# ---- text scenes ----------------------------------------------------------------------------

ROOM = ("sector room floor=0 ceil=128\n"
        "wall 0 0 0 256 room\nwall 0 256 256 256 room\nwall 256 256 256 0 room\nwall 256 0 0 0 room\n")
PLAYER = "player 64 64 0\n"

# (id, text, line, needles): every message is "FILE:LINE: " then the item and the problem
TEXT = [
    ("unclosed-sector", "sector room floor=0 ceil=128\nwall 0 0 0 256 room\nwall 0 256 256 256 room\n"
     "wall 256 256 256 0 room\n" + PLAYER, 2, ["sector 0 'room' is not closed", "at (0, 0)", "arrive", "leave"]),
    ("unclosed-two-sided", ROOM + "sector nook floor=8 ceil=120\nwall 256 96 320 96 nook\n"
     "wall 320 96 320 160 nook\nwall 320 160 256 160 nook\n" + PLAYER, 7, ["sector 1 'nook' is not closed"]),
    ("walls-face-away", "sector room floor=0 ceil=128\nwall 0 0 256 0 room\nwall 256 0 256 256 room\n"
     "wall 256 256 0 256 room\nwall 0 256 0 0 room\n" + PLAYER, 2, ["the walls of sector 0 'room' face away"]),
    ("zero-length-wall", ROOM + "wall 10 10 10 10 room\n" + PLAYER, 6, ["wall: zero length"]),
    ("zero-length-after-rounding", ROOM + "wall 10 10 10.000001 10 room\n" + PLAYER, 6, ["wall: zero length"]),
    ("duplicated-wall", ROOM + "wall 0 256 256 256 room\n" + PLAYER, 6,
     ["wall: duplicates the wall on line 3", "same two points)"]),
    ("duplicated-wall-reversed", ROOM + "wall 256 256 0 256 room\n" + PLAYER, 6,
     ["wall: duplicates the wall on line 3", "reversed"]),
    ("duplicated-after-rounding", ROOM + "wall 256 0.000001 256 256 room\n" + PLAYER, 6,
     ["wall: duplicates the wall on line 4"]),
    ("coordinate-fraction-beyond", ROOM + "wall 0 0 32767.5 0 room\n" + PLAYER, 6,
     ["wall: x2 = 32767.5 out of range", "|coordinate| <= 32767"]),
    ("coordinate-rounds-beyond", ROOM + "wall 0 -32767.00002 5 5 room\n" + PLAYER, 6,
     ["wall: y1 = -32767.00002 out of range"]),
    ("player-beyond", ROOM + "player 40000 0 0\n", 6, ["player: x = 40000 out of range"]),
    ("object-beyond", ROOM + "model m\npart box w=8 d=8 h=8\nend\nobject m 10 -40000 z=0\n" + PLAYER, 9,
     ["object: y = -40000 out of range"]),
    ("height-fraction-beyond", "sector room floor=0 ceil=16383.5\n", 1, ["sector: ceil=16383.5 out of range",
                                                                         "|height| <= 16383"]),
    ("door-beyond", "sector room floor=0 ceil=64 door=16384\n", 1, ["sector: door=16384 out of range"]),
    ("unknown-statement", ROOM + "floor 0\n" + PLAYER, 6, ["unknown statement 'floor'"]),
    ("unknown-key", "sector room floor=0 ceil=64 height=3\n", 1, ["sector: unknown key 'height'"]),
    ("bad-number-coordinate", ROOM + "wall 0 0 1x 5 room\n" + PLAYER, 6, ["wall: x2: '1x' is not a number"]),
    ("bad-number-height", "sector room floor=abc ceil=64\n", 1, ["sector: floor=abc is not a number"]),
    ("bad-number-angle", ROOM + "player 64 64 east\n", 6, ["player: angle 'east' is not a number"]),
    ("bad-colour", ROOM + "wall 0 0 5 5 room mid=pink\n" + PLAYER, 6, ["wall: mid=pink: unknown colour"]),
    ("bad-colour-index", "sector room floor=0 ceil=64 floor_color=300\n", 1,
     ["sector: floor_color=300: a colour is a palette index 0..255"]),
    ("unknown-sector-name", ROOM + "wall 0 0 5 5 kitchen\n" + PLAYER, 6, ["wall: unknown sector 'kitchen'"]),
    ("unknown-sector-number", ROOM + "wall 0 0 5 5 room 3\n" + PLAYER, 6, ["wall: unknown sector 3"]),
    ("sector-declared-below", "wall 0 0 0 256 room\nsector room floor=0 ceil=64\n", 1,
     ["wall: unknown sector 'room'", "declared before"]),
    ("missing-player", ROOM, 6, ["end of file: no player start"]),
    ("second-player", ROOM + PLAYER + PLAYER, 7, ["player: a second player start", "line 6"]),
    ("player-outside", ROOM + "player 300 300 0\n", 6, ["player at (300, 300) is not inside any sector"]),
    ("no-walls", "sector room floor=0 ceil=64\n" + PLAYER, 3, ["end of file: no walls"]),
    ("model-without-end", ROOM + PLAYER + "model m\npart box w=8 d=8 h=8\n", 7, ["model 'm': 'end' missing"]),
]


@pytest.mark.parametrize("text, line, needles", [c[1:] for c in TEXT], ids=[c[0] for c in TEXT])
@pytest.mark.parametrize("tool", ["bspc", "render"])
def test_bad_text_scene(tmp_path, tool, text, line, needles):
    path = tmp_path / "bad.scene"
    path.write_text(text)
    out = tmp_path / "out"
    refused([program(tool), path, "-o", out], f"{tool}: {path}:{line}: ", *needles)
    assert not out.exists(), "output left behind"


def test_binary_file_is_not_a_text_scene(tmp_path):
    path = tmp_path / "noise.scene"
    path.write_bytes(b"sector a floor=0 ceil=64\n\0\1\2")
    refused([program("bspc"), path, "-o", tmp_path / "out.bsc"], f"{path}: not a scene", "NUL bytes")
    assert not (tmp_path / "out.bsc").exists()


# ---- WAD maps -------------------------------------------------------------------------------

LUMPS = ("THINGS", "LINEDEFS", "SIDEDEFS", "VERTEXES", "SECTORS")


def wad_bytes(lumps, marker=b"MAP01", magic=b"PWAD"):
    """A WAD of the map marker and the lumps in order (name -> bytes), the directory at the end."""
    return wad_image([(marker, b"")] + list(lumps.items()), magic)


def without(name):
    return lambda: wad_bytes({k: v for k, v in room_lumps().items() if k != name})


def with_lump(name, data):
    def make():
        lumps = room_lumps()
        lumps[name] = data(lumps[name]) if callable(data) else data
        return wad_bytes(lumps)
    return make


def linedef0(v1=0, v2=1, front=0, back=0xFFFF):
    return with_lump("LINEDEFS", lambda d: struct.pack("<HHHHHHH", v1, v2, 1, 0, 0, front, back) + d[14:])


def lump_past_the_end():
    data = bytearray(wad_bytes(room_lumps()))
    dirofs = u32(data, 8)
    put32(data, dirofs + 16 * 2 + 4, 1 << 20)  # LINEDEFS' size, the entry after MAP01 and THINGS
    return bytes(data)


def hexen():
    lumps = room_lumps()
    lumps["BEHAVIOR"] = b"ACS\0"
    return wad_bytes(lumps)


# (id, make WAD bytes, map name, needles): the message starts "FILE.wad:MAP: "
WAD = [(f"missing-{name}", without(name), "MAP01", [f"map has no {name} lump"]) for name in LUMPS] + [
    ("truncated-directory", lambda: wad_bytes(room_lumps())[:200], "MAP01",
     ["lump directory (6 lumps at offset", "runs past the end of the file (200 bytes)"]),
    ("directory-beyond-end", lambda: wad_bytes(room_lumps())[:8] + struct.pack("<I", 1 << 30) +
     wad_bytes(room_lumps())[12:], "MAP01", ["lump directory", "runs past the end of the file"]),
    ("shorter-than-header", lambda: b"PWAD\1", "MAP01",
     ["not a WAD file (5 bytes, shorter than the 12-byte header)"]),
    ("bad-magic", lambda: wad_bytes(room_lumps(), magic=b"ZWAD"), "MAP01",
     ["not a WAD file (header magic 'ZWAD', not IWAD or PWAD)"]),
    ("lump-past-the-end", lump_past_the_end, "MAP01", ["LINEDEFS lump runs past the end of the file"]),
    ("linedefs-size", with_lump("LINEDEFS", lambda d: d + b"\0" * 3), "MAP01",
     ["LINEDEFS lump size 59 is not a multiple of 14 bytes"]),
    ("vertexes-size", with_lump("VERTEXES", lambda d: d + b"\0" * 2), "MAP01",
     ["VERTEXES lump size 18 is not a multiple of 4 bytes"]),
    ("things-size", with_lump("THINGS", lambda d: d + b"\0"), "MAP01",
     ["THINGS lump size 11 is not a multiple of 10"]),
    ("sidedefs-size", with_lump("SIDEDEFS", lambda d: d[:-1]), "MAP01",
     ["SIDEDEFS lump size 119 is not a multiple of 30"]),
    ("sectors-size", with_lump("SECTORS", lambda d: d + b"\0" * 2), "MAP01",
     ["SECTORS lump size 28 is not a multiple of 26"]),
    ("linedef-vertex", linedef0(v2=9), "MAP01", ["linedef 0: vertex 9 out of range (have 4)"]),
    ("linedef-front-sidedef", linedef0(front=77), "MAP01", ["linedef 0: sidedef 77 out of range (have 4)"]),
    ("linedef-back-sidedef", linedef0(back=55), "MAP01", ["linedef 0: sidedef 55 out of range (have 4)"]),
    ("linedef-no-front", linedef0(front=0xFFFF), "MAP01", ["linedef 0: no front sidedef"]),
    ("sidedef-sector", with_lump("SIDEDEFS", lambda d: d[:28] + struct.pack("<H", 5) + d[30:]), "MAP01",
     ["linedef 0: sidedef 0: sector 5 out of range (have 1)"]),
    ("no-sectors", with_lump("SECTORS", b""), "MAP01", ["map has no sectors"]),
    ("no-linedefs", with_lump("LINEDEFS", b""), "MAP01", ["map has no linedefs"]),
    ("no-player", with_lump("THINGS", struct.pack("<hhhHH", 128, 128, 0, 3001, 7)), "MAP01",
     ["no player start (no thing of type 1)"]),
    ("hexen", hexen, "MAP01", ["Hexen-format map", "BEHAVIOR"]),
    ("map-not-in-wad", lambda: wad_bytes(room_lumps()), "MAP02", ["no map MAP02 in"]),
    ("map-name-too-long", lambda: wad_bytes(room_lumps()), "MAP012345", ["map name 'MAP012345'", "longer than 8"]),
    ("no-map-name", lambda: wad_bytes(room_lumps()), "", ["no map named after the ':'"]),
]


@pytest.mark.parametrize("make, name, needles", [c[1:] for c in WAD], ids=[c[0] for c in WAD])
@pytest.mark.parametrize("tool", ["bspc", "render"])
def test_bad_wad_map(tmp_path, tool, make, name, needles):
    wad = tmp_path / "bad.wad"
    wad.write_bytes(make())
    out = tmp_path / "out"
    refused([program(tool), f"{wad}:{name}", "-o", out], f"{tool}: {wad}:{name}: ", *needles)
    assert not out.exists(), "output left behind"


def test_wad_without_a_map_name(tmp_path):
    wad = tmp_path / "room.wad"
    wad.write_bytes(wad_bytes(room_lumps()))
    refused([program("bspc"), wad, "-o", tmp_path / "out.bsc"], f"{wad}: name a map in the WAD")
    assert not (tmp_path / "out.bsc").exists()


def test_the_good_wad_compiles(tmp_path):
    """The damage above is all that is wrong with the WADs: the undamaged room compiles."""
    wad = tmp_path / "room.wad"
    wad.write_bytes(wad_bytes(room_lumps()))
    run([program("bspc"), f"{wad}:MAP01", "-o", tmp_path / "room.bsc"])
    write_pwad_map(tmp_path / "same.wad", *(room_lumps()[k] for k in LUMPS))
    assert (tmp_path / "same.wad").read_bytes() == wad.read_bytes()


# ---- frame-link streams ---------------------------------------------------------------------

@pytest.fixture(scope="module")
def stream(tmp_path_factory):
    """A clean stream of 4 frames of the default scene (hello, palette, frames), encoded by the C encoder."""
    out = tmp_path_factory.mktemp("walk")
    fltool = program("fltool", sanitized=False)
    run([fltool, "walk", DEFAULT, "--frames", 4, "--out", out])
    run([fltool, "encode", out / "frames.raw", "--info", out / "frames.jsonl", "--palette", out / "palette.bin",
         "--out", out / "stream.bin"])
    return (out / "stream.bin").read_bytes()


def decode(tmp_path, data):
    path = tmp_path / "in.bin"
    path.write_bytes(data)
    proc = run([program("fltool"), "decode", path])  # exits 0: a decoder takes whatever arrives
    assert proc.stderr == ""
    lines = [json.loads(line) for line in proc.stdout.splitlines()]
    counters = lines[-1]["counters"]
    assert counters["bytes"] == len(data)
    return lines[:-1], counters


def test_clean_stream(tmp_path, stream):
    _, c = decode(tmp_path, stream)
    assert (c["frames_shown"], c["msgs_bad"], c["hellos"], c["palettes"]) == (4, 0, 1, 1)


@pytest.mark.parametrize("kind", ["cut-in-last-frame", "cut-in-hello", "cut-then-resent", "garbage", "zeros",
                                  "empty", "garbage-then-stream"])
def test_bad_stream_is_counted(tmp_path, stream, kind):
    rng = random.Random(kind)
    garbage = bytes(rng.randrange(256) for _ in range(20000))
    data = {"cut-in-last-frame": stream[:-50], "cut-in-hello": stream[:10],
            "cut-then-resent": stream[:len(stream) // 2] + stream, "garbage": garbage, "zeros": bytes(1000),
            "empty": b"", "garbage-then-stream": garbage + b"\0" + stream}[kind]
    events, c = decode(tmp_path, data)
    bad = sum(e["event"] == "bad" for e in events)
    assert c["msgs_bad"] == bad
    if kind == "cut-in-last-frame":   # the last message never ends: it is not shown, nothing else is lost
        assert (c["frames_shown"], c["msgs_bad"]) == (3, 0)
    elif kind == "cut-in-hello":
        assert c["msgs_ok"] == 0 and c["frames_shown"] == 0
    elif kind == "cut-then-resent":   # the cut message runs into the next: one bad message, then all again
        assert c["msgs_bad"] == 1 and c["resyncs"] == 1 and c["frames_shown"] == 4
    elif kind == "garbage":
        assert c["msgs_bad"] > 0 and c["msgs_ok"] == 0 and c["frames_shown"] == 0
    elif kind == "garbage-then-stream":
        assert c["msgs_bad"] > 0 and c["frames_shown"] == 4
    else:
        assert c["msgs_ok"] == c["msgs_bad"] == c["frames_shown"] == 0


def test_missing_stream(tmp_path):
    frames = tmp_path / "frames.bin"
    refused([program("fltool"), "decode", tmp_path / "none.bin", "--frames-out", frames],
            f"fltool: {tmp_path / 'none.bin'}: cannot read: No such file")
    assert not frames.exists()


# ---- DFU images -----------------------------------------------------------------------------

def dfu(payload, vid=0x1209, pid=0x0001, bcd_dfu=0x0100, length=16):
    """A DFU 1.1 image (specification appendix B), built independently of the C code."""
    body = payload + struct.pack("<HHHH", 0xFFFF, pid, vid, bcd_dfu) + b"UFD" + bytes([length])
    return body + struct.pack("<I", zlib.crc32(body) ^ 0xFFFFFFFF)


# the kinds tests/test_flash.py::test_damaged_image_rejected does not have (it has a flipped bit, a bad
# dwCRC, a truncated image, a missing signature, an empty and a tiny file, another product id)
DFU = [
    ("wrong-version", dfu(b"\x11" * 1000, bcd_dfu=0x011A), ["bcdDFU is not 0x0100", "bcdDFU 011a"]),
    ("length-too-small", dfu(b"\x11" * 1000, length=8), ["bLength", "is not 16", "bLength 8"]),
    ("length-beyond-file", dfu(b"\x11" * 10, length=200), ["bLength", "is not 16", "bLength 200, file 26 bytes"]),
    ("no-firmware", dfu(b""), ["no firmware before the DFU suffix"]),
    ("another-vendor", dfu(b"\x11" * 1000, vid=0x1234), ["made for another vendor id", "1234:0001"]),
]


@pytest.mark.parametrize("blob, needles", [c[1:] for c in DFU], ids=[c[0] for c in DFU])
def test_bad_dfu_image(tmp_path, blob, needles):
    image = tmp_path / "bad.dfu"
    image.write_bytes(blob)
    refused([program("flash"), image, "--loopback", "--device", "1209:0001"], f"flash: {image}: ", *needles,
            "nothing was sent", status=2)


def test_add_suffix_refusal_leaves_no_output(tmp_path):
    image = tmp_path / "fw.dfu"
    image.write_bytes(dfu(b"\x22" * 100))
    out = tmp_path / "twice.dfu"
    refused([program("flash"), "--add-suffix", image, "--vid", "1209", "--pid", "0001", "-o", out],
            f"flash: {image}: ", "already ends with a valid DFU suffix", status=2)
    assert not out.exists()


def test_fltool_walk_creates_its_folder(tmp_path):
    """fltool walk --out DIR creates DIR and its missing parents, as the other programs do."""
    out = tmp_path / "a" / "b"
    run([program("fltool"), "walk", DEFAULT, "--frames", 2, "--out", out])
    assert (out / "frames.raw").stat().st_size == 2 * 64000
    assert len((out / "frames.jsonl").read_text().splitlines()) == 2


def test_fltool_walk_refuses_a_file_for_its_folder(tmp_path):
    """A path that is a file, or lies under one, is refused by name, and the file is left alone."""
    f = tmp_path / "file"
    f.write_text("x")
    for out in (f, f / "sub"):
        proc = run([program("fltool"), "walk", DEFAULT, "--frames", 1, "--out", out], check=False)
        assert proc.returncode == 1 and f"fltool: cannot create the folder {out}" in proc.stderr, proc.stderr
    assert f.read_text() == "x"
