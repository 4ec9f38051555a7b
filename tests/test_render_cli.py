"""build/render: the headless renderer's contract (flags, JSON, outputs, counters, errors)."""
import json
import struct

import pytest

from conftest import ROOT, program, read_png_indexed, render, run

DEFAULT = str(ROOT / "tests/scenes/default.scene")


@pytest.fixture(scope="module")
def compiled(tmp_path_factory):
    out = tmp_path_factory.mktemp("bsc") / "default.bsc"
    run([program("bspc"), DEFAULT, "-o", out])
    return out


def test_help():
    proc = run([program("render"), "--help"])
    for flag in ("--at", "--angle", "--mode", "--present", "--raw", "--ids", "--repeat", "-o"):
        assert flag in proc.stdout


def test_json_counters_and_camera_echo(compiled):
    j = render(str(compiled), at="100.3,-20.5", angle="33.25")
    for key in ("crc32", "pixels_written", "overdraw", "vram_writes", "sysmem_writes", "copy_writes",
                "bus_cycles", "camera", "mode", "present"):
        assert key in j
    # decimals are rounded to 16.16 and echoed exactly as used
    assert j["camera"]["x"] == round(100.3 * 65536) / 65536
    assert j["camera"]["y"] == -20.5
    assert j["camera"]["angle"] == 33.25
    assert j["mode"] == "columns" and j["present"] == "flip"  # the defaults
    assert len(j["crc32"]) == 8


def test_source_and_compiled_give_the_same_frame(compiled):
    a = render(DEFAULT)
    b = render(str(compiled))
    assert a["crc32"] == b["crc32"] and a["camera"] == b["camera"]


@pytest.mark.parametrize("present,copy_writes,vram", [
    ("flip", 0, None), ("copy8", 64000, 64000), ("copy16", 32000, 32000), ("copy32", 16000, 16000)])
def test_present_modes_count_like_the_book(compiled, present, copy_writes, vram):
    j = render(str(compiled), "--present", present)
    assert j["copy_writes"] == copy_writes
    if vram is not None:
        # copy modes draw into system memory: the only VRAM writes are the copy's
        assert j["vram_writes"] == vram
        assert j["sysmem_writes"] > 0
    else:
        assert j["sysmem_writes"] == 0 and j["vram_writes"] > 0
    assert j["bus_cycles"] == j["vram_writes"] * j["bus_model"]["vram_cycles"] + \
        j["sysmem_writes"] * j["bus_model"]["sysmem_cycles"]


WIDTH_KEY = {1: "writes8", 2: "writes16", 4: "writes32"}


@pytest.mark.parametrize("mode", ["direct", "painter"])
@pytest.mark.parametrize("present,width", [("copy8", 1), ("copy16", 2), ("copy32", 4)])
def test_copy_adds_exactly_one_page_of_writes(compiled, mode, present, width):
    """The same frame drawn for flip and for a copy mode: the drawing is the same writes (in
    VRAM for flip, in system memory for a copy), so the difference is the copy alone, derived
    from the mode: 64,000 bytes in 64,000 / width writes of that width, all into VRAM."""
    flip = render(str(compiled), "--mode", mode, "--present", "flip")
    copy = render(str(compiled), "--mode", mode, "--present", present)
    n = 64000 // width
    for j in (flip, copy):
        assert j["bytes"] == j["writes8"] + 2 * j["writes16"] + 4 * j["writes32"]
        assert j["writes"] == j["writes8"] + j["writes16"] + j["writes32"]
        assert j["writes"] == j["vram_writes"] + j["sysmem_writes"]
    # page flip writes nothing: the drawing is every write, and it writes each drawn pixel once
    assert flip["copy_writes"] == 0 and flip["sysmem_writes"] == 0
    assert flip["bytes"] == flip["pixels_written"]
    assert copy["copy_writes"] == n and copy["vram_writes"] == n
    assert copy["sysmem_writes"] == flip["vram_writes"]
    assert copy["writes"] - flip["writes"] == n
    assert copy["bytes"] - flip["bytes"] == 64000
    for w, key in WIDTH_KEY.items():
        assert copy[key] - flip[key] == (n if w == width else 0), key
    bus = copy["bus_model"]
    assert copy["bus_cycles"] == flip["vram_writes"] * bus["sysmem_cycles"] + n * bus["vram_cycles"]


@pytest.mark.parametrize("present", ["flip", "copy16"])
def test_counters_are_per_frame(compiled, present):
    """--repeat N reports the last frame's counters: the same as one frame, not N times them."""
    one = render(str(compiled), "--present", present)
    three = render(str(compiled), "--present", present, "--repeat", "3")
    assert three["frames"] == 3
    for key in ("writes", "bytes", "writes8", "writes16", "writes32", "vram_writes", "sysmem_writes",
                "copy_writes", "bus_cycles"):
        assert three[key] == one[key], key


def test_present_modes_show_the_same_frame(compiled):
    crcs = {render(str(compiled), "--present", p)["crc32"] for p in ("flip", "copy8", "copy16", "copy32")}
    assert len(crcs) == 1


def test_outputs_agree(compiled, tmp_path):
    png, raw, ids = tmp_path / "f.png", tmp_path / "f.bin", tmp_path / "ids.bin"
    j = render(str(compiled), "-o", png, "--raw", raw, "--ids", ids)
    frame = raw.read_bytes()
    assert len(frame) == 64000
    import zlib
    assert "%08x" % zlib.crc32(frame) == j["crc32"]
    w, h, pixels, palette = read_png_indexed(png)
    assert (w, h) == (320, 200) and pixels == frame and len(palette) == 768
    idbuf = ids.read_bytes()
    assert len(idbuf) == 64000 * 4
    vals = struct.unpack("<64000I", idbuf)
    kinds = {v >> 24 for v in vals}
    assert kinds <= {0, 1, 2, 3}  # nothing, walls, floors, ceilings
    assert {1, 2, 3} <= kinds
    # every wall pixel's id names a linedef side (index = line * 2 + side)
    assert all((v & 0xFFFFFF) < 1 << 20 for v in vals)


@pytest.mark.parametrize("scene", [DEFAULT, "freedoom2.wad:MAP01"])
def test_png_is_compressed_and_decodes_to_the_raw_frame(scene, tmp_path):
    """host/png.c deflates: a frame of few colours is a small fraction of its 64,000 pixels (stored
    blocks made every frame 64 KB), and any decoder (Pillow here) gives back the same palette indices
    as --raw, in colour type 3 with the 256-entry palette."""
    from PIL import Image
    png, raw = tmp_path / "f.png", tmp_path / "f.bin"
    render(scene, "-o", png, "--raw", raw)
    frame = raw.read_bytes()
    limit = 8000 if scene == DEFAULT else 32000
    assert png.stat().st_size < limit, png.stat().st_size
    with Image.open(png) as im:
        assert (im.format, im.mode, im.size) == ("PNG", "P", (320, 200))
        assert im.tobytes() == frame
        assert len(im.getpalette()) == 768
        palette = bytes(im.getpalette())
    assert read_png_indexed(png)[3] == palette


def test_repeat_renders_the_same_frame(compiled):
    one = render(str(compiled))
    many = render(str(compiled), "--repeat", "5")
    assert one["crc32"] == many["crc32"] and one["pixels_written"] == many["pixels_written"]
    assert many["frames"] == 5


@pytest.mark.parametrize("args,needle", [
    (["--at", "1"], "--at"),
    (["--at", "1,2,3,4"], "--at"),
    (["--at", "99999,0"], "--at"),
    (["--angle", "east"], "--angle"),
    (["--mode", "raytrace"], "--mode"),
    (["--present", "copy64"], "--present"),
    (["--repeat", "0"], "--repeat"),
    (["--bogus"], "--bogus"),
])
def test_bad_arguments(compiled, args, needle):
    proc = run([program("render"), compiled, *args], check=False)
    assert proc.returncode != 0 and needle in proc.stderr


def test_missing_scene_file(tmp_path):
    proc = run([program("render"), tmp_path / "nope.bsc"], check=False)
    assert proc.returncode != 0 and "nope.bsc" in proc.stderr


@pytest.mark.parametrize("damage", ["truncate", "crc", "magic", "version"])
def test_damaged_compiled_scene_is_refused(compiled, tmp_path, damage):
    data = bytearray(compiled.read_bytes())
    if damage == "truncate":
        data = data[:len(data) // 2]
    elif damage == "crc":
        data[len(data) // 2] ^= 0x40
    elif damage == "magic":
        data[0] ^= 0xFF
    else:
        data[4] = 99
    bad = tmp_path / "bad.bsc"
    bad.write_bytes(bytes(data))
    proc = run([program("render"), bad], check=False)
    assert proc.returncode != 0
    assert "bad.bsc" in proc.stderr
    if damage != "magic":  # a wrong magic is read as a text scene, which then fails to parse
        assert {"truncate": "truncated", "crc": "CRC", "version": "version"}[damage] in proc.stderr


# ---- argument checks and messages (issue 19: a newcomer's first hour) ----------------------------

def render_refused(*args, status=2):
    proc = run([program("render"), *args], check=False)
    assert proc.returncode == status, (args, proc.returncode, proc.stderr)
    assert proc.stdout == "", proc.stdout  # no JSON for a refused run
    assert proc.stderr.count("\n") == 1 and "Sanitizer" not in proc.stderr, proc.stderr
    return proc.stderr


def test_unknown_option_is_named_as_unknown():
    # last on the line, where 'needs a value' was said before
    assert "unknown option '--bogus'" in render_refused(DEFAULT, "--bogus")
    assert "unknown option '--bogus'" in render_refused(DEFAULT, "--bogus", "1")
    assert "needs a value" in render_refused(DEFAULT, "--at")


@pytest.mark.parametrize("at", [",1,2", "1,2,", "1,,2", "1", "1,2,3,4", "", "1e-9,0", "0x10,0", "1,two"])
def test_at_syntax(at):
    err = render_refused(DEFAULT, "--at", at)
    assert "two or three decimal numbers" in err and "outside" not in err


@pytest.mark.parametrize("at", ["-32768,0", "0,32768", "1,2,-32768", "99999,0"])
def test_at_range_says_what_it_checks(at):
    assert "above -32768 and below 32768" in render_refused(DEFAULT, "--at", at)


def test_at_range_edges_accepted():
    j = render(DEFAULT, at="-32767.99,32767.99")
    assert j["camera"]["x"] == round(-32767.99 * 65536) / 65536


@pytest.mark.parametrize("look,needle", [("", "whole number"), ("x", "whole number"), ("1.5", "whole number"),
                                         ("101", "-100..100")])
def test_look_syntax_and_range(look, needle):
    assert needle in render_refused(DEFAULT, "--look", look)


@pytest.mark.parametrize("flag", ["-o", "--raw", "--ids"])
def test_unwritable_output_fails_before_rendering(tmp_path, flag):
    err = render_refused(DEFAULT, flag, str(tmp_path / "no" / "such" / "x.png"), status=1)
    assert f"{flag} " in err and "cannot write there" in err
    err = render_refused(DEFAULT, flag, str(tmp_path), status=1)  # a folder
    assert "Is a directory" in err


def test_output_written_and_json_printed(tmp_path):
    out = tmp_path / "new.png"
    j = render(DEFAULT, "-o", str(out))
    assert out.exists() and len(j["crc32"]) == 8


def test_camera_outside_every_sector_warns(compiled):
    for scene in (DEFAULT, str(compiled)):
        proc = run([program("render"), scene, "--at", "30000,30000"])
        assert proc.returncode == 0
        assert "warning: the camera is outside every sector" in proc.stderr
        json.loads(proc.stdout)
        inside = run([program("render"), scene])
        assert inside.stderr == ""


def test_directory_as_scene(tmp_path):
    err = render_refused(str(tmp_path), status=1)
    assert "is a directory" in err and "read" not in err


def test_objects_line_with_a_nul_byte(tmp_path):
    objs = tmp_path / "objs.txt"
    objs.write_bytes(b"# fine\nobject 0 96 160 0 0\x00 junk\n")
    err = render_refused(str(ROOT / "tests/scenes/objects.scene"), "--objects", str(objs), status=1)
    assert ":2: holds a NUL byte" in err and "longer" not in err


def test_objects_line_length_limit_kept(tmp_path):
    objs = tmp_path / "objs.txt"
    objs.write_text("#" + "x" * 1021 + "\n" + "#" + "x" * 1022 + "\n")
    err = render_refused(str(ROOT / "tests/scenes/objects.scene"), "--objects", str(objs), status=1)
    assert ":2: line longer than 1022 characters" in err
