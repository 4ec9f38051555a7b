"""The benchmark tools (tools/bench.py, tools/bench_profile.py, tools/bench_doc.py) on small
inputs: the modes come from build/render, a frame's stages add up to its instructions, inlined
helpers count for their caller, the percentile, the document keeps the section it was not given;
and the firmware's --no-objects draws build/render's --no-objects frame."""
import json
import os
import shutil
import stat
import subprocess
import sys

import pytest

from conftest import BUILD, ROOT

sys.path.insert(0, str(ROOT / "tools"))
import bench  # noqa: E402
import bench_doc  # noqa: E402
import bench_profile as bp  # noqa: E402


def fake_render(tmp_path, modes, help_text):
    """A stand-in for build/render that prints help_text and accepts --mode M for M in modes."""
    path = tmp_path / "render"
    path.write_text("#!/bin/sh\n"
                    f"if [ \"$1\" = --mode ]; then case \"$2\" in {'|'.join(modes)}) ;; *) exit 1;; esac; fi\n"
                    f"cat <<'EOF'\n{help_text}\nEOF\n")
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return path


def test_modes_are_those_render_names_and_accepts(tmp_path, monkeypatch):
    monkeypatch.delenv("BENCH_MODES", raising=False)
    help_text = ("usage: render SCENE\n  --angle DEG        view angle, default 0\n"
                 "  --mode MODE        direct (the default: front to back), spans (zero\n"
                 "                     overdraw) or painter (back to front)\n"
                 "  --present P        flip | copy8")
    fake = fake_render(tmp_path, ["direct", "spans", "painter"], help_text)
    assert bench.render_modes(fake) == ["direct", "spans", "painter"]
    # words of other options' paragraphs are not modes even when accepted
    fake = fake_render(tmp_path, ["spans", "painter", "flip"], help_text)
    assert bench.render_modes(fake) == ["spans", "painter"]
    monkeypatch.setenv("BENCH_MODES", "painter")
    assert bench.render_modes(fake) == ["painter"]


def test_modes_of_the_built_renderer(monkeypatch):
    monkeypatch.delenv("BENCH_MODES", raising=False)
    modes = bench.render_modes(BUILD / "render")
    assert {"spans", "painter"} <= set(modes)
    for m in modes:
        assert subprocess.run([str(BUILD / "render"), "--mode", m, "--help"], capture_output=True).returncode == 0


def test_p95_nearest_rank():
    assert bench.p95(list(range(1, 21))) == 19
    assert bench.p95(list(range(100, 0, -1))) == 95
    assert bench.p95([7]) == 7
    s = bench.summary([3, 1, 2, 10])
    assert (s["median"], s["p95"], s["max"]) == (2.5, 10, 10)


def test_textured_against_flat_table_and_goal_figure():
    views = [{"scene": "freedoom1.wad:E1M1", "at": "-160,304", "angle": "0"},
             {"scene": bench.MAP01_START[0], "at": bench.MAP01_START[1], "angle": bench.MAP01_START[2]}]
    res = {(0, "direct", "world"): (300.0, None), (0, "direct", "flat"): (100.0, None),
           (1, "direct", "world"): (1_000.0, None), (1, "direct", "flat"): (800.0, None)}
    lines, stats = bench.flat_table(views, ["direct"], res)
    s = stats["direct"]
    assert (s["textured"]["median"], s["textured"]["max"]) == (650.0, 1_000.0)
    assert (s["flat"]["median"], s["flat"]["max"]) == (450.0, 800.0)
    assert (s["ratio"]["median"], s["ratio"]["max"]) == (pytest.approx(2.125), 3.0)
    assert lines[-1] == "| direct | 650 | 1,000 | 1,000 | 450 | 800 | 800 | 2.12 | 3.00 |"
    line, fig = bench.goal_line(views, res)
    assert (fig["textured"], fig["flat"], fig["ratio"]) == (1_000.0, 800.0, 1.25)
    assert "textured **1,000**, flat 800" in line and "**1.25**" in line
    # no MAP01 start, or no direct mode measured: no goal figure
    assert bench.goal_line(views[:1], res) == (None, None)
    assert bench.goal_line(views, res, mode="spans") == (None, None)


def test_inlined_helpers_count_for_their_caller():
    chain = [("w128_mul", "firmware/wide128.h"), ("objd_front", "firmware/obj_draw.c")]
    assert bp.function_of(chain) == ("objd_front", "firmware/obj_draw.c")
    assert bp.stage_of(*bp.function_of(chain)) == bp.OBJECTS
    # an inlined .c function keeps its own stage: coverage inlined into add_polygon
    assert bp.stage_of(*bp.function_of([("cover", "firmware/spans.c"), ("add_polygon", "firmware/spans.c")])) == bp.COVER
    # no inline record: the outermost function, in the file it was seen in elsewhere
    assert bp.function_of([("objd_front", "firmware/wide128.h")], {"objd_front": "firmware/obj_draw.c"}) == \
        ("objd_front", "firmware/obj_draw.c")
    assert bp.stage_of("clip_plane.isra.0", "firmware/clip.c") == bp.XFORM
    assert bp.stage_of("wall_span", "firmware/texture.c") == bp.TEXTURE
    assert bp.stage_of("__aeabi_ldivmod", "??") == bp.ARITH
    assert bp.stage_of("brand_new", "firmware/brand_new.c") == bp.OTHER
    assert bp.Profile({("brand_new", "firmware/brand_new.c"): 5, ("scan_line", "firmware/spans.c"): 7}).unclassified() == \
        {("brand_new", "firmware/brand_new.c"): 5}


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind missing: run make deps")
def test_stages_add_up_to_the_frame(tmp_path):
    scene = tmp_path / "objects.bsc"
    subprocess.run([str(BUILD / "bspc"), str(ROOT / "tests/scenes/objects.scene"), "-o", str(scene)], check=True,
                   capture_output=True)
    view = {"at": "128,192", "angle": "0"}
    for mode in bench.render_modes():
        ir, prof = bench.frame_profile(scene, view, mode, 2)
        assert ir > 10_000
        assert abs(prof.total() - ir) < 1, mode
        stages = prof.stages()
        assert abs(sum(stages.values()) - ir) < 1
        assert set(stages) <= set(bp.STAGES)
        assert stages[bp.FILL] > 0 and stages[bp.XFORM] > 0 and stages[bp.OBJECTS] > 0, (mode, stages)
        # the exact difference: the same as callgrind's totals alone
        assert ir == (bench.instructions(scene, view, mode, 3) - bench.instructions(scene, view, mode, 1)) / 2


def test_document_keeps_the_other_section(tmp_path, monkeypatch):
    doc, x86, m3 = tmp_path / "benchmarks.md", tmp_path / "bench.md", tmp_path / "bench-m3.md"
    monkeypatch.setattr(bench_doc, "DOC", doc)
    monkeypatch.setattr(bench_doc, "SECTIONS", {"x86": ("x86", "make bench", "tools/bench.py", x86),
                                                "m3": ("M3", "make bench-m3", "m3.py", m3)})
    x86.write_text("x86 figures one\n")
    bench_doc.write("x86")
    assert "x86 figures one" in doc.read_text() and "Not run yet: `make bench-m3`" in doc.read_text()
    m3.write_text("m3 figures\n")
    x86.unlink()
    bench_doc.write("m3")
    text = doc.read_text()
    assert "x86 figures one" in text and "m3 figures" in text and "Not run yet" not in text


QEMU = shutil.which("qemu-system-arm")


@pytest.mark.skipif(QEMU is None, reason="qemu-system-arm missing: run make deps")
def test_firmware_no_objects_draws_the_world_alone(tmp_path):
    out = BUILD / "test-bench-noobj"
    proc = subprocess.run(["make", "-s", "-j2", "--no-print-directory", "firmware", "SCENE=tests/scenes/objects.scene",
                           f"ARM_OUT={out}", "STREAM=raw", "FULL=1"], cwd=ROOT, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    elf = out / "firmware.elf"
    view = ["--at", "128,192", "--angle", "0"]

    def host(*extra):
        p = subprocess.run([str(BUILD / "render"), str(out / "scene.bsc"), *view, *extra], capture_output=True,
                           text=True, check=True)
        return int(json.loads(p.stdout)["crc32"], 16)

    def firmware(*extra):
        uart = tmp_path / "uart.bin"
        p = subprocess.run([QEMU, "-M", "mps2-an385", "-nographic", "-monitor", "none", "-semihosting-config",
                            "enable=on,target=native", "-kernel", str(elf), "-serial", f"file:{uart}",
                            "-append", " ".join([*view, "--frames", "1", *extra])],
                           capture_output=True, timeout=120)
        assert p.returncode == 0, p.stderr
        sys.path.insert(0, str(ROOT / "tests"))
        from test_firmware import raw_frames
        frames, _ = raw_frames(uart.read_bytes())
        return frames[0][0]["crc32"]

    alone, things = host("--no-objects"), host()
    assert alone != things                  # objects are in view: the option has something to leave out
    assert firmware("--no-objects") == alone
    assert firmware() == things


def test_document_keeps_sections_no_generator_writes(tmp_path, monkeypatch):
    # the other targets' figures (make bench-bsp, bench-size, ...) sit in sections of their own
    doc, x86 = tmp_path / "benchmarks.md", tmp_path / "bench.md"
    monkeypatch.setattr(bench_doc, "DOC", doc)
    monkeypatch.setattr(bench_doc, "SECTIONS", {"x86": ("x86", "make bench", "tools/bench.py", x86)})
    doc.write_text("# old head\n<!-- section bsp -->\n## bsp figures\n<!-- end bsp -->\n")
    x86.write_text("x86 figures\n")
    bench_doc.write("x86")
    text = doc.read_text()
    assert "x86 figures" in text and "## bsp figures" in text
    assert text.index("x86 figures") < text.index("## bsp figures")


def test_doom_frame_cost_cancels_start_up_and_the_melt():
    """bench_doom's measure: start-up, level load and the screen melt cost the same in every run, the
    game's tics the same with and without drawing, so only the drawn frames are left."""
    import bench_doom
    l1, l2 = bench_doom.DEMO_TICS
    start, melt, tic, frame = 70_000_000, 9_000_000, 12_345, 1_331_000

    def run(wad, mapname, tics, how):
        assert (wad, mapname) == ("/w/freedoom2.wad", "MAP01")
        return start + tics * tic + ((melt + tics * frame) if how == "noblit" else 0)

    monkey_find = bench_doom.doomcompare.find_wad
    bench_doom.doomcompare.find_wad = lambda name: "/w/" + name
    try:
        cost, runs = bench_doom.chocolate_frame("freedoom2.wad:MAP01", run=run)
    finally:
        bench_doom.doomcompare.find_wad = monkey_find
    assert cost == frame
    assert sorted(runs) == [(l1, "noblit"), (l1, "nodraw"), (l2, "noblit"), (l2, "nodraw")]
    # one more instruction in the longer drawn run is 1 / (l2 - l1) more a frame
    runs[(l2, "noblit")] += l2 - l1
    assert bench_doom.frame_cost(runs) == frame + 1


def test_doom_starts_are_the_bench_maps_and_the_open_ones():
    import bench_doom
    maps = bench_doom.start_maps()
    bench_maps = {v["scene"] for v in bench.load_views() if v["set"] == "bench"}
    assert len(maps) == len(set(maps)) == 25
    assert bench_maps <= set(maps) and set(bench_doom.EXTRA_MAPS) <= set(maps)
