"""The precision knobs and make report (mk/report.mk, tools/report.py), cheaply: every knob
configuration compiles warning-free and an out-of-range value is refused; configuration "default"
draws exactly what build/render draws while a coarse one draws something else and further from
the reference; and the report's tables and figure come out of a tiny run without callgrind and
out of fake points with instruction counts."""
import json
import subprocess
import sys

import numpy as np
import pytest

from conftest import BUILD, RENDER_MODES, ROOT, SAN_ENV, render, run

sys.path.insert(0, str(ROOT / "tools"))
import accuracy  # noqa: E402
import refrender  # noqa: E402
import report  # noqa: E402
import report_m3  # noqa: E402

KNOB = BUILD / "knob"
VIEW = {"scene": "freedoom1.wad:E1M4", "at": "896,-1760", "angle": "135"}
CFLAGS = ["-std=c11", "-Wall", "-Wextra", "-Wshadow", "-Wstrict-prototypes", "-Wno-missing-field-initializers",
          "-Werror", "-ffreestanding", "-mgeneral-regs-only", "-Ifirmware", "-Ihal", "-fsyntax-only"]


def configs():
    out = subprocess.run(["make", "-s", "--no-print-directory", "report-configs"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    table = dict(line.split(":", 1) for line in out.splitlines() if ":" in line)
    return {name.strip(): flags.split() for name, flags in table.items()}


def knob_render(config, sanitized=True):
    path = KNOB / config / ("san/render" if sanitized else "render")
    if not path.exists():
        pytest.fail(f"{path} is missing: make {path.relative_to(ROOT)}")
    return path


def firmware_sources():
    tables = BUILD / "gen" / "fx_tables.c"
    if not tables.exists():
        pytest.fail(f"{tables} is missing: run make first")
    return sorted(str(p) for p in (ROOT / "firmware").glob("*.c")) + [str(tables)]


def test_every_configuration_compiles():
    table = configs()
    assert "default" in table and not table["default"] and len(table) >= 5
    knobs = {f.split("=")[0] for flags in table.values() for f in flags}
    assert len(knobs) >= 4, knobs
    srcs = firmware_sources()
    procs = {name: subprocess.Popen(["cc", *CFLAGS, *flags, *srcs], cwd=ROOT, stderr=subprocess.PIPE, text=True)
             for name, flags in table.items()}
    errors = {name: p.communicate()[1] for name, p in procs.items()}
    bad = {name: err for name, err in errors.items() if procs[name].returncode != 0 or err.strip()}
    assert not bad, "\n".join(f"{n}:\n{e}" for n, e in bad.items())


@pytest.mark.parametrize("flag", ["-DVIEW_SUBPIXEL_BITS=17", "-DRAST_STEP_BITS=3", "-DVIEW_RECIP_BITS=13",
                                  "-DVIEW_SHIFT=15", "-DFX_SIN_BITS=13", "-DFX_SIN_LERP=2",
                                  "-DTEX_SUBDIV_BITS=7", "-DTEX_RECIP_BITS=3", "-DTEX_RECIP_BITS=13",
                                  "-DTEX_LIGHT_BITS=0", "-DTEX_LIGHT_BITS=6"])
def test_out_of_range_knob_is_refused(flag):
    proc = subprocess.run(["cc", *CFLAGS, flag, "firmware/view.c", "firmware/raster.c", "firmware/fixed.c",
                           "firmware/texture.c"],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode != 0 and "#error" in proc.stderr, proc.stderr


def ids_of(binary, tmp_path, mode):
    out = tmp_path / f"{binary.parent.name}-{mode}.ids"
    proc = run([binary, VIEW["scene"], "--at", VIEW["at"], "--angle", VIEW["angle"], "--mode", mode, "--ids", out],
               env=SAN_ENV)
    return json.loads(proc.stdout), accuracy.read_ids(out)


@pytest.mark.parametrize("mode", RENDER_MODES)
def test_default_is_exact_and_a_coarse_knob_is_not(mode, tmp_path):
    plain = render(VIEW["scene"], "--mode", mode, at=VIEW["at"], angle=VIEW["angle"], sanitized=False)
    default_json, default_ids = ids_of(knob_render("default", sanitized=False), tmp_path, mode)
    coarse_json, coarse_ids = ids_of(knob_render("subpix0"), tmp_path, mode)
    assert default_json["crc32"] == plain["crc32"]
    assert coarse_json["crc32"] != plain["crc32"]
    x, y = (float(c) for c in VIEW["at"].split(","))
    ref = refrender.render_ids(VIEW["scene"], x, y, float(plain["camera"]["z"]), float(VIEW["angle"]))
    assert accuracy.differ(ref, coarse_ids) > accuracy.differ(ref, default_ids)
    assert accuracy.edge_displacement(ref, coarse_ids) > accuracy.edge_displacement(ref, default_ids)
    # whole-pixel vertices still leave no gap and no pixel drawn twice
    assert int(np.count_nonzero((coarse_ids >> 24) == 0)) == 0
    if mode != "painter":
        assert coarse_json["overdraw"] == 1.0 and coarse_json["pixels_written"] == 64000


def test_report_runs_on_one_view_without_callgrind(tmp_path):
    for c in ("default", "subpix0", "texlight2"):
        knob_render(c, sanitized=False)
    proc = subprocess.run([sys.executable, str(ROOT / "tools/report.py"), "--configs", "default", "subpix0", "texlight2",
                           "--views", "1", "--no-ir", "--jobs", "1", "--out", str(tmp_path)],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "report:" in proc.stderr
    md = (tmp_path / "report.md").read_text()
    for row in ("| **default** | — | spans |", "| **default** | — | painter |",
                "| subpix0 | -DVIEW_SUBPIXEL_BITS=0 | spans |", "| subpix0 | -DVIEW_SUBPIXEL_BITS=0 | painter |"):
        assert row in md, md
    assert (tmp_path / "error_vs_ir.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    points = {(p["config"], p["mode"]): p for p in json.loads((tmp_path / "points.json").read_text())["points"]}
    assert points[("default", "spans")]["views"] == 1
    assert points[("subpix0", "spans")]["mean_differ"] > points[("default", "spans")]["mean_differ"]
    assert any((tmp_path / "ref").glob("*.bin"))
    # the texel-and-light error of the one view (a WAD map): 2 light steps of 32 are coarser than all
    # of them, and do not move a surface
    assert points[("default", "spans")]["tex_views"] == 1
    assert points[("texlight2", "spans")]["tex_bad_mean"] > points[("default", "spans")]["tex_bad_mean"] + 0.05
    assert points[("texlight2", "spans")]["mean_differ"] == points[("default", "spans")]["mean_differ"]


def test_report_writes_tables_and_figure_from_fake_points(tmp_path):
    views = [{"set": "bench", "group": "bench", "name": "a"}, {"set": "extreme", "group": "s1", "name": "s1/v"}]
    errors = [{"differ": 0.01, "edge": 2, "hist": [[2, 99]]},
              {"differ": 0.03, "edge": report.CAP, "hist": [[1, 50], [report.CAP, 1]], "failed": 1}]
    tex = [({"bad": 0.001, "compared": 64000}, "a"), ({"bad": 0.005, "compared": 60000}, "b")]
    points = [report.summarise("default", "", "spans", views, errors, [1000, 3000], tex),
              report.summarise("cheap", "-DRAST_STEP_BITS=8 -DVIEW_RECIP_BITS=8", "painter", views, errors[:1], [500])]
    assert points[0]["ir"] == 2000 and points[0]["worst_differ"] == 0.03 and points[0]["worst_view"] == "s1/v"
    assert points[0]["mean_differ_bench"] == 0.01 and points[0]["p99_edge"] == 2 and points[0]["failed"] == ["s1/v"]
    per_scene = {"s1": {"views": 1, "spans": {"differ": 0.03, "edge": 320}, "painter": {"differ": 0.0, "edge": 0}}}
    points[0]["m3_ir"], points[1]["m3_ir"] = 9000, None
    drawn = report.plot(tmp_path / "p.png", points, no_ir=False)
    assert any("lower left is better" in t for t in drawn["texts"])
    assert "mode columns, Cortex-M3" in drawn["texts"]
    report.write_markdown(tmp_path / "r.md", points, per_scene, views,
                          {"default": "", "cheap": points[1]["flags"]}, "p.png", no_ir=False, tex_names=["a", "b"],
                          m3_names=["a"])
    md = (tmp_path / "r.md").read_text()
    assert "| **default** | — | spans | 2,000 | +0.0% | 9,000 | +0.0% | 2.000% |" in md, md
    assert "On the Cortex-M3 (mode columns" in md
    assert "| s1 | 1 | 3.00% | 320 | 0.00% | 0 |" in md, md
    assert "| 1 | 0.300% | 0.50% | b |" in md, md            # texels off: mean, worst, its view
    assert "| 0 | — | — | — |" in md, md                      # not measured for the second point
    assert points[1]["tex_bad_mean"] is None
    assert "Failed renders" in md
    assert (tmp_path / "p.png").stat().st_size > 10000
    assert report.hist_percentile([0, 0, 5], 99) == 2 and report.hist_percentile([0] * 4, 99) == 0
    assert points[0]["worst_moved_edge"] == 2 and points[0]["worst_edge"] == report.CAP
    assert report.sparse_hist(np.array([3, 3, 400])) == [[3, 2], [report.CAP, 1]]


def test_pareto_front_is_the_lower_left_edge():
    xy = [(3, 0.1), (1, 0.5), (2, 0.5), (2, 0.2), (4, 0.0), (5, 0.0)]
    assert report.front(xy) == [1, 3, 0, 4]  # by instructions; (2, 0.5) and (5, 0) are beaten
    assert report.front([]) == [] and report.front([(1, 1)]) == [0]


def test_plot_names_the_front_without_overlapping_labels(tmp_path):
    # 34 configurations crowded as the knobs crowd them: many nearly equal, a few far apart
    rng = np.random.default_rng(7)
    points = []
    for i in range(34):
        ir = int(2_000_000 * (1 + 0.002 * rng.standard_normal())) if i % 5 else int(2_000_000 * (0.7 + 0.1 * i / 5))
        differ = 0.0 if i % 7 == 0 else float(10 ** rng.uniform(-5, -2))
        p = fake_point("default" if i == 0 else f"k{i}", "spans", ir, differ,
                       "" if i == 0 else f"-DRAST_STEP_BITS={4 + i % 12}", tex=float(10 ** rng.uniform(-4, -1)),
                       edge=int(rng.integers(0, 30)))
        p["m3_ir"] = ir * 3
        points.append(dict(p, mode="columns"))
    drawn = report.plot(tmp_path / "p.png", points, no_ir=False)
    named = [b for boxes in drawn["labels"] for b in boxes]
    assert len(named) >= 6  # the default and the front of each plot are named
    for boxes in drawn["labels"]:
        for i, a in enumerate(boxes):
            for b in boxes[i + 1:]:
                assert not report._overlaps(a, b), (a, b)
    assert any("lower left is better" in t for t in drawn["texts"])


def test_report_counts_a_configuration_on_the_cortex_m3_and_caches_it(tmp_path, monkeypatch):
    cache, logs = report.Cache(tmp_path / "cache.json"), []
    got = report_m3.measure({"recip8": "-DVIEW_RECIP_BITS=8"}, [VIEW], tmp_path / "m3", cache, logs.append)
    assert 100_000 < got["recip8"][0] < 20_000_000, got
    assert "-DVIEW_RECIP_BITS=8" in (tmp_path / "m3" / "recip8" / "obj" / "modes").read_text()  # the knob
    assert any("1/1 configurations" in line for line in logs), logs

    def no_build(*args):
        raise AssertionError("built again")

    monkeypatch.setattr(report_m3, "build", no_build)
    again = report_m3.measure({"recip8": "-DVIEW_RECIP_BITS=8"}, [VIEW], tmp_path / "m3", cache, logs.append)
    assert again == got


def test_progress_gives_configurations_done_and_time_left():
    groups = ["a"] * 4 + ["b"] * 4 + ["c"] * 2
    line = report.progress("error", 4, 10, 8.0, groups)
    assert line == "error: 4/10, configurations 1/3 done, 8 s, about 12 s left", line
    assert report.progress("error", 3, 10, 8.0, groups).startswith("error: 3/10, configurations 0/3 done")
    assert report.progress("callgrind", 10, 10, 200.0, groups) == \
        "callgrind: 10/10, configurations 3/3 done, 3 min 20 s"
    assert report.progress("texels", 1, 3, 4000.0) == "texels: 1/3, 1 h 06 min, about 2 h 13 min left"


def fake_point(config, mode, ir, differ, flags="", tex=None, edge=0):
    return {"config": config, "flags": flags, "mode": mode, "ir": ir, "views": 1, "mean_differ": differ,
            "mean_differ_bench": differ, "mean_differ_extreme": None, "worst_differ": differ, "worst_view": "v",
            "worst_edge": edge, "worst_moved_edge": edge, "p99_edge": edge, "views_at_cap": 0, "failed": [],
            "tex_views": 1 if tex is not None else 0, "tex_bad_mean": tex, "tex_bad_worst": tex,
            "tex_worst_view": "v" if tex is not None else ""}


def test_report_summary_names_the_best_and_the_default_place(tmp_path):
    points = [fake_point("default", "spans", 1000, 0.0, tex=0.01),
              fake_point("fine", "spans", 1200, 0.0, "-DVIEW_SUBPIXEL_BITS=8", tex=0.005),
              fake_point("cheap", "spans", 800, 0.02, "-DRAST_STEP_BITS=8", tex=0.2, edge=3),
              fake_point("worse", "spans", 900, 0.03, "-DRAST_STEP_BITS=6", tex=0.3, edge=5),
              fake_point("default", "painter", 5000, 0.001, tex=0.01),
              fake_point("cheap", "painter", 4000, 0.0, "-DRAST_STEP_BITS=8", tex=0.01)]
    assert [p["config"] for p in report.pareto([p for p in points if p["mode"] == "spans"])] == ["default", "cheap"]
    views = [{"set": "bench", "group": "bench", "name": "v"}]
    report.write_markdown(tmp_path / "r.md", points, {}, views,
                          {"default": "", "fine": "x", "cheap": "y", "worse": "z"}, "p.png", no_ir=False,
                          tex_names=["v"])
    md = (tmp_path / "r.md").read_text()
    summary = md[md.index("## Summary"):md.index("| config |")]
    assert "- **spans**: least error: default, fine (0.000% of pixels differ); fewest texels off: fine (0.500%); " \
           "fewest instructions: cheap (800 per frame)." in summary, summary
    assert "The default's place (1 = lowest): error 1 of 4 (0.000%), texels off 2 of 4 (1.000%), " \
           "instructions 3 of 4 (1,000)." in summary, summary
    assert "(the lower-left edge of the plot): cheap, default." in summary, summary
    assert "- **painter**: least error: cheap (0.000% of pixels differ)" in summary, summary
    assert "error 2 of 2 (0.100%)" in summary, summary
    # zeros go to the band below each log axis, and a row with nothing above zero still draws
    report.plot(tmp_path / "p.png", points, no_ir=False)
    report.plot(tmp_path / "q.png", [fake_point("default", "spans", None, 0.0)], no_ir=True)
    assert (tmp_path / "p.png").stat().st_size > 10000 and (tmp_path / "q.png").stat().st_size > 10000
