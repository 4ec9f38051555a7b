"""build/bspc: every Freedoom map compiles with every strategy; the stats contract; clear errors."""
import json
import re
import shutil
import sys

import pytest

from conftest import ROOT, freedoom, program, room_lumps, run, wad_image, write_pwad_map

MAPS = [f"freedoom1.wad:E{e}M{m}" for e in range(1, 5) for m in range(1, 10)] + \
       [f"freedoom2.wad:MAP{m:02d}" for m in range(1, 33)]


def stats(spec, *extra, sanitized=False):
    proc = run([program("bspc", sanitized), spec, "--stats", "-o", "/dev/null", *extra])
    assert proc.stdout.count("\n") == 1
    return json.loads(proc.stdout)


def test_68_maps():
    assert len(MAPS) == 68


@pytest.mark.parametrize("split", ["fewest", "balanced", "mixed"])
def test_all_freedoom_maps_compile(split):
    freedoom("freedoom1.wad"), freedoom("freedoom2.wad")
    for spec in MAPS:
        s = stats(spec, "--split", split)
        for key in ("input_walls", "segs", "splits", "leaves", "nodes", "max_depth", "mean_depth", "build_ms",
                    "models", "objects"):
            assert key in s, (spec, key)
        assert s["leaves"] == s["nodes"] + 1, spec
        assert s["segs"] >= s["input_walls"], spec
        assert 1 <= s["max_depth"] <= 255, spec


def test_sanitized_compile_of_a_large_map():
    s = stats("freedoom2.wad:MAP01", sanitized=True)
    assert s["leaves"] > 100


def test_stats_count_models_and_objects(tmp_path):
    """--stats counts the models and objects (docs/objects.md); a Doom map's things are objects."""
    path = tmp_path / "objects.scene"
    path.write_text(ROOM.format(name="a", far=256, floor=0, ceil=64) +
                    "model crate\npart box w=32 d=32 h=32\nend\n"
                    "model post\npart prism sides=6 r=4 h=40\npart box w=16 d=16 h=2 at=0,0,40\nend\n"
                    "object crate 100 100\nobject post 50 50 yaw=45\nobject crate 200 200 z=8 path=circle:20:1000\n")
    s = stats(path, sanitized=True)
    assert (s["models"], s["objects"]) == (2, 3)
    s = stats(str(ROOT / "tests/scenes/default.scene"))
    assert (s["models"], s["objects"]) == (0, 0)
    freedoom("freedoom2.wad")
    s = stats("freedoom2.wad:MAP01")
    assert s["objects"] > 50 and 0 < s["models"] < s["objects"]


def test_help():
    proc = run([program("bspc"), "--help"])
    for flag in ("--split", "--stats", "-o"):
        assert flag in proc.stdout


def test_missing_lump_and_map(tmp_path):
    proc = run([program("bspc"), "freedoom2.wad:MAP99", "-o", tmp_path / "x.bsc"], check=False)
    assert proc.returncode != 0 and "MAP99" in proc.stderr
    proc = run([program("bspc"), tmp_path / "none.wad:MAP01"], check=False)
    assert proc.returncode != 0 and "none.wad" in proc.stderr


# ---- the ranges the renderer proves safe (docs/ranges.md): refused with the item named ----------

ROOM = "sector {name} floor={floor} ceil={ceil}\n" \
       "wall 0 0 0 {far} a\nwall 0 {far} {far} {far} a\nwall {far} {far} {far} 0 a\nwall {far} 0 0 0 a\n" \
       "player 1 1 0\n"


@pytest.mark.parametrize("values, line, message", [
    (dict(far=32768, floor=0, ceil=64), 2, "= 32768 out of range (|coordinate| <= 32767)"),
    (dict(far=256, floor=-16384, ceil=64), 1, "floor=-16384 out of range (|height| <= 16383)"),
    (dict(far=256, floor=0, ceil=16384), 1, "ceil=16384 out of range (|height| <= 16383)"),
    (dict(far=256, floor=64, ceil=0), 1, "ceil is below floor"),
    (dict(far=0, floor=0, ceil=64), 2, "zero length"),
])
def test_text_scene_out_of_range(tmp_path, values, line, message):
    path = tmp_path / "bad.scene"
    path.write_text(ROOM.format(name="a", **values))
    proc = run([program("bspc"), path, "-o", tmp_path / "bad.bsc"], check=False)
    assert proc.returncode == 1, proc.stderr
    assert f"bad.scene:{line}:" in proc.stderr and message in proc.stderr, proc.stderr
    assert not (tmp_path / "bad.bsc").exists()


def wad_room(path, x0, y0, x1, y1, floor, ceil):
    """A PWAD whose MAP01 is one rectangular one-sided room."""
    write_pwad_map(path, *room_lumps(x0, y0, x1, y1, floor, ceil).values())


@pytest.mark.parametrize("room, message", [
    ((-32768, 0, 256, 256, 0, 128), "vertex 0: x = -32768 out of range (|coordinate| <= 32767)"),
    ((0, 0, 256, 256, 0, 20000), "sector 0: floor 0 / ceiling 20000 out of range (|height| <= 16383)"),
])
def test_wad_out_of_range(tmp_path, room, message):
    wad = tmp_path / "bad.wad"
    wad_room(wad, *room)
    proc = run([program("bspc"), f"{wad}:MAP01", "-o", tmp_path / "bad.bsc"], check=False)
    assert proc.returncode == 1, proc.stderr
    assert f"bad.wad:MAP01: {message}" in proc.stderr, proc.stderr


def test_extremes_of_the_ranges_compile(tmp_path):
    """The limits themselves are inside: a room from -32767 to 32767, heights +-16383."""
    path = tmp_path / "edge.scene"
    path.write_text("sector a floor=-16383 ceil=16383\n"
                    "wall -32767 -32767 -32767 32767 a\nwall -32767 32767 32767 32767 a\n"
                    "wall 32767 32767 32767 -32767 a\nwall 32767 -32767 -32767 -32767 a\nplayer 0 0 0\n")
    run([program("bspc"), path, "-o", tmp_path / "edge.bsc"])
    wad = tmp_path / "edge.wad"
    wad_room(wad, -32767, -32767, 32767, 32767, -16383, 16383)
    run([program("bspc"), f"{wad}:MAP01", "-o", tmp_path / "edge2.bsc"])


# ---- finding maps, and text files as editors write them (issue 19) -------------------------------

def test_list_maps_of_a_wad(tmp_path):
    proc = run([program("bspc"), "--list", "freedoom2.wad"])
    assert proc.stdout.split() == [f"MAP{i:02d}" for i in range(1, 33)]
    full = run([program("bspc"), "--list", str(freedoom("freedoom2.wad"))])
    assert full.stdout == proc.stdout
    bad = run([program("bspc"), "--list", str(tmp_path / "none.wad")], check=False)
    assert bad.returncode == 1 and "cannot find" in bad.stderr


@pytest.mark.parametrize("prog", ["bspc", "render"])
@pytest.mark.parametrize("spec,needles", [
    ("freedoom2.wad", ["name a map in the WAD as freedoom2.wad:MAP", "its maps: MAP01 MAP02"]),
    ("freedoom2.wad:MAP99", ["no map MAP99", "its maps: MAP01 MAP02", "MAP32"]),
    ("nosuch.wad", ["cannot find nosuch.wad", "$DOOMWADDIR"]),
])
def test_wad_named_without_a_map_or_with_a_wrong_one(prog, spec, needles):
    proc = run([program(prog), spec], check=False)
    assert proc.returncode == 1 and proc.stderr.count("\n") == 1, proc.stderr
    for n in needles:
        assert n in proc.stderr, proc.stderr
    assert "No such file" not in proc.stderr


def test_list_maps_of_a_pwad(tmp_path):
    wad = tmp_path / "one.wad"
    write_pwad_map(wad, b"", b"", b"", b"", b"")
    assert run([program("bspc"), "--list", str(wad)]).stdout == "MAP01\n"


@pytest.mark.parametrize("name,transform", [
    ("bom", lambda t: b"\xef\xbb\xbf" + t),
    ("cr", lambda t: t.replace(b"\n", b"\r")),
    ("crlf", lambda t: t.replace(b"\n", b"\r\n")),
    ("bom-crlf", lambda t: b"\xef\xbb\xbf" + t.replace(b"\n", b"\r\n")),
])
def test_text_scene_line_ends_and_byte_order_mark(tmp_path, name, transform):
    src = ROOT / "tests/scenes/objects.scene"
    want = run([program("bspc"), src, "-o", tmp_path / "want.bsc"])
    assert want.returncode == 0
    odd = tmp_path / f"{name}.scene"
    odd.write_bytes(transform(src.read_bytes()))
    run([program("bspc"), odd, "-o", tmp_path / "got.bsc"])
    assert (tmp_path / "got.bsc").read_bytes() == (tmp_path / "want.bsc").read_bytes()


def test_line_numbers_with_cr_line_ends(tmp_path):
    odd = tmp_path / "cr.scene"
    odd.write_bytes(b"# a comment\r\r# another\rbogus\r")
    proc = run([program("bspc"), odd], check=False)
    assert f"{odd}:4: unknown statement 'bogus'" in proc.stderr, proc.stderr


def test_directory_as_input(tmp_path):
    proc = run([program("bspc"), tmp_path], check=False)
    assert proc.returncode == 1 and "is a directory" in proc.stderr and "read" not in proc.stderr


def test_model_names_of_a_crlf_scene_for_render_objects(tmp_path):
    """build/render --objects resolves names with the compiler's own parser, so a scene with
    CRLF line ends names its models as bspc reads them."""
    odd = tmp_path / "crlf.scene"
    odd.write_bytes((ROOT / "tests/scenes/objects.scene").read_bytes().replace(b"\n", b"\r\n"))
    objs = tmp_path / "objs.txt"
    objs.write_text("object barrel 100 100 0 0\n")
    by_name = json.loads(run([program("render"), odd, "--objects", objs]).stdout)
    objs.write_text("object 1 100 100 0 0\n")
    by_number = json.loads(run([program("render"), odd, "--objects", objs]).stdout)
    assert by_name["objects"][0]["model"] == 1 and by_name["crc32"] == by_number["crc32"]


def compile_instructions(tmp_path, name, text):
    """Instructions callgrind counts for one compile of a text scene (release build)."""
    if shutil.which("valgrind") is None:
        pytest.skip("valgrind missing: run make deps")
    scene = tmp_path / name
    scene.write_text(text)
    proc = run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={tmp_path / 'cg.out'}",
                program("bspc", sanitized=False), scene, "-o", tmp_path / "x.bsc"])
    return int(re.search(r"Collected : (\d+)", proc.stderr).group(1))


# The generated scenes of make bench-bsp. Instruction bounds, not times: a
# 3,600-sector grid took 4.78e9 (sector names searched one by one, the wall
# bound's walk testing every seg in every leaf) and now 0.50e9; a 10,000-wall
# zigzag took 5.08e9 and now 0.73e9.
@pytest.mark.parametrize("case, bound", [("grid", 1.2e9), ("zigzag", 1.6e9)])
def test_generated_scenes_compile_in_few_instructions(tmp_path, case, bound):
    sys.path.insert(0, str(ROOT / "tools"))
    import bench_bsp  # noqa: E402 (tools/ is not a package)
    make = {"grid": bench_bsp.grid_scene, "zigzag": bench_bsp.zigzag_scene}[case]
    assert compile_instructions(tmp_path, f"{case}.scene", make()) < bound


# ---- every map of a WAD in one run (bspc WAD --all) ----------------------------------------------

def write_pwad(path, maps):
    """A PWAD of maps {name: lumps}, in order."""
    path.write_bytes(wad_image([item for name, lumps in maps.items() for item in [(name, b"")] + list(lumps.items())]))


def test_all_maps_of_a_wad_in_one_run(tmp_path):
    """Each map's blob is the one a run for that map alone writes, under the default name, and --stats
    gives a line per map naming it."""
    wad = tmp_path / "pair.wad"
    write_pwad(wad, {"MAP01": room_lumps(0, 0, 256, 256), "MAP02": room_lumps(-512, 0, 0, 384)})
    out = tmp_path / "out"
    out.mkdir()
    proc = run([program("bspc"), wad, "--all", "-o", out, "--stats"])
    lines = [json.loads(x) for x in proc.stdout.splitlines()]
    assert [x["map"] for x in lines] == ["MAP01", "MAP02"] and all(x["leaves"] >= 1 for x in lines)
    assert "2 of 2 maps compiled" in proc.stderr
    for m in ("MAP01", "MAP02"):
        run([program("bspc"), f"{wad}:{m}", "-o", tmp_path / f"{m}.bsc"])
        assert (out / f"pair-{m}.bsc").read_bytes() == (tmp_path / f"{m}.bsc").read_bytes()


def test_all_maps_go_on_past_a_refused_one(tmp_path):
    wad = tmp_path / "mixed.wad"
    write_pwad(wad, {"MAP01": room_lumps(-32768, 0, 256, 256), "MAP02": room_lumps(0, 0, 256, 256)})
    proc = run([program("bspc", sanitized=True), wad, "--all", "-o", tmp_path], check=False)
    assert proc.returncode == 1
    assert "mixed.wad:MAP01: vertex 0: x = -32768 out of range" in proc.stderr, proc.stderr
    assert "1 of 2 maps compiled" in proc.stderr
    assert not (tmp_path / "mixed-MAP01.bsc").exists() and (tmp_path / "mixed-MAP02.bsc").stat().st_size > 0


@pytest.mark.parametrize("args, needle", [
    (["scene.scene", "--all"], "is not a WAD file name"),
    (["freedoom2.wad", "--all", "--needs"], "--needs and --config take one"),
])
def test_all_maps_refuses_what_it_cannot_do(args, needle):
    proc = run([program("bspc"), *args], check=False)
    assert proc.returncode == 2 and needle in proc.stderr, proc.stderr


@pytest.mark.parametrize("where, needle", [("none", "No such file or directory"), ("file", "not a folder")])
def test_all_maps_needs_a_folder_to_write_to(tmp_path, where, needle):
    out = tmp_path / where
    if where == "file":
        out.write_text("x")
    proc = run([program("bspc"), "freedoom2.wad", "--all", "-o", out], check=False)
    assert proc.returncode == 1 and proc.stderr == f"bspc: {out}: {needle}\n", proc.stderr
    assert list(tmp_path.iterdir()) == ([out] if where == "file" else [])


def test_all_maps_share_textures_and_write_what_single_runs_write(tmp_path):
    """The textures kept from one map for the next (the look cache) give each map the blob a run of
    its own gives, warnings and all."""
    out = tmp_path / "all"
    out.mkdir()
    proc = run([program("bspc", sanitized=True), "freedoom2.wad", "--all", "-o", out, "-v"])
    assert "32 of 32 maps compiled" in proc.stderr and "Sanitizer" not in proc.stderr
    for m in ("MAP01", "MAP02", "MAP17", "MAP32"):
        one = run([program("bspc"), f"freedoom2.wad:{m}", "-o", tmp_path / "one.bsc", "-v"])
        assert (out / f"freedoom2-{m}.bsc").read_bytes() == (tmp_path / "one.bsc").read_bytes(), m
        warned = [x for x in one.stderr.splitlines() if "unknown" in x]
        assert all(w in proc.stderr for w in warned), m


def test_all_maps_on_several_threads_write_what_one_writes(tmp_path):
    """-j 3: the same files and the same --stats lines (but the build times) as one thread, sanitized."""
    runs = {}
    for j in (1, 3):
        out = tmp_path / f"j{j}"
        out.mkdir()
        proc = run([program("bspc", sanitized=j > 1), "freedoom1.wad", "--all", "-o", out, "-j", j, "--stats"])
        assert "36 of 36 maps compiled" in proc.stderr and "Sanitizer" not in proc.stderr
        stats = [re.sub(r'"build_ms": [0-9.]+', "", x) for x in proc.stdout.splitlines()]
        runs[j] = (stats, {p.name: p.read_bytes() for p in out.iterdir()})
    assert runs[1] == runs[3]


@pytest.mark.parametrize("args, needle", [
    (["freedoom2.wad:MAP01", "-j", "2"], "-j is for --all"),
    (["freedoom2.wad", "--all", "-j", "0"], "-j needs a number of maps to compile at once, 1 to 64"),
    (["freedoom2.wad", "--all", "-j", "2x"], "-j needs a number"),
    (["freedoom2.wad", "--all", "-j"], "-j needs a number"),
])
def test_all_maps_threads_option_is_checked(args, needle):
    proc = run([program("bspc"), *args], check=False)
    assert proc.returncode == 2 and needle in proc.stderr, proc.stderr
