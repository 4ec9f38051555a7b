#!/usr/bin/env python3
"""make bench: instructions per frame on x86-64 for the bench views and the open views of
tests/bench_views.json, per render mode, the world alone and with things.

Instructions per frame of build/render: valgrind's callgrind counts instructions, so a figure
repeats from run to run to within a few instructions per frame (the C library's paths vary slightly
with where things are loaded). Per view, mode and world (--no-objects) or things:
(Ir of --repeat N+1 - Ir of --repeat 1) / N (N = --frames, default 10), which leaves out loading
the scene, the first frame and writing the output. Scenes are compiled once to build/bench/ first
so that callgrind does not also measure the compiler.

The modes are those build/render takes (render_modes: the words of its --help's --mode paragraph
that `build/render --mode WORD` accepts), so a mode added to build/render is measured here with no
edit. Statistics over all views: median, 95th percentile (nearest rank) and maximum.

Stages: callgrind also records the instructions per instruction address (--dump-instr=yes); the
same difference gives each address's instructions per frame, which tools/bench_profile.py groups
into the stages of the frame. A stage's share is given two ways: the mean over the views of its
share of each view's frame (every view weighs the same), and its share of all the views' frames
summed (expensive views weigh more).

Textured and flat: the bench views are WAD maps, which build/render draws textured, so every table
but the textured-against-flat one is of textured frames. That table gives, per mode, the world alone
(--no-objects) textured and again with --flat (the same scene in flat colours), and the ratio per
view; a line gives the issue's goal figure, MAP01's start in mode direct, world alone, textured and
flat.

Also, as before: overdraw and the VRAM writes and modelled bus cycles of each present mode for the
bench views, and instructions per frame with 0, 10 and 100 objects in a generated scene (see
object_bench).

Prints the Markdown tables, writes them to build/bench.md and the figures to build/bench.json, and
rewrites docs/benchmarks.md (tools/bench_doc.py). A benchmark, not a test: it asserts nothing.
`tools/bench.py --objects-only` measures only the objects (build/bench-objects.md).
"""
import argparse
import collections
import concurrent.futures
import datetime
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_doc  # noqa: E402
import bench_profile  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
RENDER = BUILD / "render"
PRESENTS = ["flip", "copy8", "copy16", "copy32"]
VIEWS_FILE = ROOT / "tests/bench_views.json"
MAP01_START = ("freedoom2.wad:MAP01", "-192,-160", "0")


# ---- the modes ------------------------------------------------------------------------------

def render_modes(render=RENDER):
    """The render modes `render` takes, in the order its --help names them: every word of the
    --mode paragraph of its --help that it accepts as `--mode WORD` (it checks the mode before it
    reaches --help, so no scene is needed). BENCH_MODES="a b" in the environment overrides."""
    if os.environ.get("BENCH_MODES"):
        return os.environ["BENCH_MODES"].split()
    if not Path(render).exists():
        raise SystemExit(f"bench: {render} is not built (make {Path(render).relative_to(ROOT)})")
    text = subprocess.run([str(render), "--help"], capture_output=True, text=True, check=True).stdout
    para, inside = [], False
    for line in text.splitlines():
        opt = re.match(r"^\s+(-\S+)", line)
        if opt:
            inside = opt.group(1) == "--mode"
            line = line.split("--mode", 1)[1] if inside else line
        if inside:
            para.append(line)
    words = list(dict.fromkeys(re.findall(r"[a-z][a-z0-9_-]*", " ".join(para))))
    modes = [w for w in words if subprocess.run([str(render), "--mode", w, "--help"], capture_output=True).returncode == 0]
    if not modes:
        raise SystemExit(f"bench: found no render mode in {render} --help")
    return modes


def __getattr__(name):
    # bench.MODES (tools/report.py): looked up when first used, from build/render
    if name == "MODES":
        globals()["MODES"] = render_modes()
        return globals()["MODES"]
    raise AttributeError(name)


# ---- running build/render ---------------------------------------------------------------------

def compiled(scene, out_dir):
    out = out_dir / (scene.replace(":", "_").replace("/", "_") + ".bsc")
    # a blob older than the compiler may be of an older format version
    if not out.exists() or out.stat().st_mtime < (BUILD / "bspc").stat().st_mtime:
        subprocess.run([str(BUILD / "bspc"), scene, "-o", str(out)], check=True, capture_output=True)
    return out


def camera(view):
    return ["--at", view["at"], "--angle", view["angle"]] + (["--look", str(view["look"])] if view.get("look") else [])


def render_json(scene, view, *extra, render=RENDER):
    out = subprocess.run([str(render), str(scene), *camera(view), *extra], check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out)


def callgrind(scene, view, mode, repeat, *extra, render=RENDER, profile=False):
    """One callgrind run of `render`: its total Ir, and with profile the per-address figures of
    bench_profile.read_callgrind."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cg.out"
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                        *(["--dump-instr=yes"] if profile else []), str(render), str(scene), *camera(view),
                        "--mode", mode, "--repeat", str(repeat), *extra],
                       check=True, capture_output=True, text=True)
        if profile:
            return bench_profile.read_callgrind(out, render)
        for line in out.read_text().splitlines():
            m = re.match(r"^(?:summary|totals): (\d+)", line)
            if m:
                return int(m.group(1))
    raise RuntimeError("no callgrind summary")


def instructions(scene, view, mode, repeat, *extra, render=RENDER):
    """Instructions callgrind counts for one run of `render` (a build/render binary)."""
    return callgrind(scene, view, mode, repeat, *extra, render=render)


def frame_profile(scene, view, mode, n, *extra, render=RENDER):
    """(instructions per frame, bench_profile.Profile of one frame): (run of N+1 frames - run of
    one) / N, in total and per instruction address."""
    t1, a1, o1, _ = callgrind(scene, view, mode, 1, *extra, render=render, profile=True)
    tn, an, on, entries = callgrind(scene, view, mode, n + 1, *extra, render=render, profile=True)
    off = bench_profile.load_offset(render, entries)
    per_addr = {a - off: (an.get(a, 0) - a1.get(a, 0)) / n for a in set(a1) | set(an)}
    per_lib = {f: (on.get(f, 0) - o1.get(f, 0)) / n for f in set(o1) | set(on)}
    prof = bench_profile.from_addresses(render, {a: v for a, v in per_addr.items() if v},
                                        {f: v for f, v in per_lib.items() if v})
    return (tn - t1) / n, prof


# ---- statistics -----------------------------------------------------------------------------

def p95(values):
    """95th percentile, nearest rank: the smallest value at least 95% of the values do not exceed."""
    s = sorted(values)
    return s[max(0, math.ceil(0.95 * len(s)) - 1)]


def summary(values):
    return {"median": statistics.median(values), "p95": p95(values), "max": max(values), "n": len(values)}


def k(v):
    """Instructions as the tables show them: thousands (K) or millions (M)."""
    return f"{v / 1e6:.2f} M" if abs(v) >= 1e6 else f"{v / 1e3:.0f} K"


# ---- the views ------------------------------------------------------------------------------

def load_views():
    """The bench views ("views": player starts) then the open views ("open") of tests/bench_views.json."""
    data = json.loads(VIEWS_FILE.read_text())
    return ([dict(v, set="bench") for v in data["views"]] + [dict(v, set="open") for v in data.get("open", [])])


def view_name(v):
    return f"{v['scene']} @ {v['at']} {v['angle']}°" + (f" look {v['look']}" if v.get("look") else "")


def frame_instructions(scene, view, mode, n, *extra, render=RENDER):
    """Instructions per frame alone (no profile): (run of N+1 frames - run of one) / N."""
    return (instructions(scene, view, mode, n + 1, *extra, render=render) -
            instructions(scene, view, mode, 1, *extra, render=render)) / n


def measure_views(views, modes, n, jobs, bench_dir):
    """{(view index, mode, "world"|"things"|"flat"): (Ir per frame, Profile or None)}, jobs
    callgrind pairs at once. "world" and "things" are the frames build/render draws (textured for
    a WAD map), "flat" the world alone with --flat (no profile: only its total is reported)."""
    scenes = [compiled(v["scene"], bench_dir) for v in views]
    tasks = [(i, m, w) for i in range(len(views)) for m in modes for w in ("world", "things", "flat")]
    out, done, t0 = {}, 0, time.time()

    def one(task):
        i, m, w = task
        if w == "flat":
            return task, (frame_instructions(scenes[i], views[i], m, n, "--no-objects", "--flat"), None)
        return task, frame_profile(scenes[i], views[i], m, n, *(["--no-objects"] if w == "world" else []))

    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        for task, res in pool.map(one, tasks):
            out[task] = res
            done += 1
            i, m, w = task
            print(f"bench: [{done}/{len(tasks)} {time.time() - t0:.0f} s] {view_name(views[i])} {m} {w}: "
                  f"{res[0]:,.0f} instructions per frame", file=sys.stderr, flush=True)
    return out


# ---- tables -----------------------------------------------------------------------------------

def summary_table(views, modes, res):
    lines = ["| mode | world alone: median | p95 | max | with things: median | p95 | max | MAP01 start: things - world |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    stats = {}
    m01 = next((i for i, v in enumerate(views) if (v["scene"], v["at"], v["angle"]) == MAP01_START), None)
    for m in modes:
        w = summary([res[(i, m, "world")][0] for i in range(len(views))])
        t = summary([res[(i, m, "things")][0] for i in range(len(views))])
        d = res[(m01, m, "things")][0] - res[(m01, m, "world")][0] if m01 is not None else None
        stats[m] = {"world": w, "things": t, "map01_things_minus_world": d}
        lines.append(f"| {m} | {w['median']:,.0f} | {w['p95']:,.0f} | {w['max']:,.0f} | {t['median']:,.0f} | "
                     f"{t['p95']:,.0f} | {t['max']:,.0f} | {'-' if d is None else f'{d:+,.0f}'} |")
    starts = [i for i, v in enumerate(views) if v["set"] == "bench"]
    if starts and len(starts) < len(views):
        lines += ["", f"The {len(starts)} bench views alone (player starts), median world alone / with things: " + "; ".join(
            f"{m} {statistics.median(res[(i, m, 'world')][0] for i in starts):,.0f} / "
            f"{statistics.median(res[(i, m, 'things')][0] for i in starts):,.0f}" for m in modes) + "."]
    return lines, stats


def flat_table(views, modes, res):
    """Textured against flat, the world alone: per mode the median, p95 and max of each over the
    views, and of the per-view ratio textured / flat. Returns (lines, {mode: figures})."""
    lines = ["| mode | textured: median | p95 | max | flat (--flat): median | p95 | max | "
             "textured / flat per view: median | max |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    stats = {}
    for m in modes:
        tex = [res[(i, m, "world")][0] for i in range(len(views))]
        flat = [res[(i, m, "flat")][0] for i in range(len(views))]
        ratio = [t / f for t, f in zip(tex, flat) if f]
        t, f = summary(tex), summary(flat)
        r = summary(ratio) if ratio else None
        stats[m] = {"textured": t, "flat": f, "ratio": r}
        lines.append(f"| {m} | {t['median']:,.0f} | {t['p95']:,.0f} | {t['max']:,.0f} | {f['median']:,.0f} | "
                     f"{f['p95']:,.0f} | {f['max']:,.0f} | " +
                     (f"{r['median']:.2f} | {r['max']:.2f} |" if r else "- | - |"))
    return lines, stats


CHOCOLATE_MAP01 = 1.32e6   # issue 17: Chocolate Doom's whole renderer on the MAP01 start view


def goal_line(views, res, mode="direct"):
    """The issue's goal figure: MAP01's start, world alone, `mode`, textured and flat and their
    ratio (None when the view or the mode was not measured)."""
    m01 = next((i for i, v in enumerate(views) if (v["scene"], v["at"], v["angle"]) == MAP01_START), None)
    if m01 is None or (m01, mode, "world") not in res:
        return None, None
    tex, flat = res[(m01, mode, "world")][0], res[(m01, mode, "flat")][0]
    fig = {"mode": mode, "textured": tex, "flat": flat, "ratio": tex / flat if flat else None}
    line = (f"Goal figure (issue 17): freedoom2.wad:MAP01 start (--at {MAP01_START[1]} --angle {MAP01_START[2]}), "
            f"world alone (--no-objects), mode {mode}: textured **{tex:,.0f}**, flat {flat:,.0f} instructions per "
            f"frame, textured / flat **{fig['ratio']:.2f}** (goal: at most {CHOCOLATE_MAP01 / 1e6:.2f} M, Chocolate "
            f"Doom's whole renderer on the same view, and at most 2).")
    return line, fig


def stage_shares(views, modes, res):
    """{(mode, world): {stage: (mean share over views, share of the sum)}}, and the profiles summed."""
    shares, sums = {}, {}
    for m in modes:
        for w in ("world", "things"):
            per_view = [res[(i, m, w)][1] for i in range(len(views))]
            total = collections.Counter()
            for p in per_view:
                total.update(p.functions)
            summed = bench_profile.Profile(total)
            st_sum, all_ = summed.stages(), summed.total()
            mean = {s: statistics.mean(p.stages()[s] / p.total() if p.total() else 0 for p in per_view)
                    for s in bench_profile.STAGES}
            shares[(m, w)] = {s: (mean[s], st_sum[s] / all_ if all_ else 0) for s in bench_profile.STAGES}
            sums[(m, w)] = summed
    return shares, sums


def stage_table(modes, shares):
    cols = [(m, w) for m in modes for w in ("world", "things")]
    head = "| stage | " + " | ".join(f"{m}, {'world alone' if w == 'world' else 'with things'}" for m, w in cols) + " |"
    lines = [head, "|---|" + "---:|" * len(cols)]
    for s in bench_profile.STAGES:
        lines.append(f"| {s} | " + " | ".join(f"{shares[c][s][0]:.1%} ({shares[c][s][1]:.1%})" for c in cols) + " |")
    return lines


def top_functions(modes, sums, views, top=12):
    lines = ["| mode | functions with the most instructions, with things (share of all views' frames summed) |",
             "|---|---|"]
    for m in modes:
        p = sums[(m, "things")]
        all_ = p.total() or 1
        cells = ", ".join(f"{f} {n / all_:.1%}" for (f, _), n in p.functions.most_common(top))
        lines.append(f"| {m} | {cells} |")
    unc = collections.Counter()
    for (m, w), p in sums.items():
        for key, n in p.unclassified().items():
            unc[key] = max(unc[key], n / (p.total() or 1))
    notes = [f"{f} ({path}) up to {share:.1%}" for (f, path), share in unc.most_common() if share >= 0.001]
    return lines, notes


def view_table(views, modes, res):
    head = "| view | set | " + " | ".join(f"{m} world | {m} things" for m in modes) + " |"
    lines = [head, "|---|---|" + "---:|---:|" * len(modes)]
    for i, v in enumerate(views):
        cells = " | ".join(f"{res[(i, m, 'world')][0]:,.0f} | {res[(i, m, 'things')][0]:,.0f}" for m in modes)
        lines.append(f"| {view_name(v)} | {v['set']} | {cells} |")
    return lines


def writes_table(views, modes, bench_dir):
    """Overdraw and, per present mode, VRAM write transactions and bus cycles (build/render's
    counters, no callgrind), with things, for the bench views."""
    head = "| view | " + " | ".join(f"{m} overdraw | {m} VRAM writes flip / copy8 / copy32 | {m} bus cycles flip / copy8 / copy32"
                                    for m in modes) + " |"
    lines = [head, "|---|" + "---:|---:|---:|" * len(modes)]
    for v in views:
        if v["set"] != "bench":
            continue
        scene = compiled(v["scene"], bench_dir)
        cells = []
        for m in modes:
            j = {p: render_json(scene, v, "--mode", m, "--present", p) for p in PRESENTS}
            cells.append(f"{j['flip']['overdraw']:.3f} | " +
                         " / ".join(f"{j[p]['vram_writes']:,}" for p in ("flip", "copy8", "copy32")) + " | " +
                         " / ".join(f"{j[p]['bus_cycles']:,}" for p in ("flip", "copy8", "copy32")))
        lines.append(f"| {view_name(v)} | " + " | ".join(cells) + " |")
    return lines


# ---- objects ------------------------------------------------------------------------------

OBJECT_COUNTS = [0, 10, 100]
OBJECT_VIEW = {"at": "32,1024,240", "angle": "0"}
OBJECT_LOOK = "-60"          # the horizon 60 rows up: the eye looks down over the objects
ROOM = 2048


def object_scene(out_dir):
    """The bench room with the models of tests/scenes/objects.scene (their model lines)."""
    models, keep = [], False
    for line in (ROOT / "tests/scenes/objects.scene").read_text().splitlines():
        word = line.split("#", 1)[0].split()[:1]
        keep = keep or word == ["model"]
        if keep:
            models.append(line)
        if word == ["end"]:
            keep = False
    text = ["# generated by tools/bench.py: one room and the models of tests/scenes/objects.scene",
            "sector room floor=0 ceil=512 floor_color=sand:7 ceil_color=grey:6",
            f"wall 0 0 0 {ROOM} room mid=red:8", f"wall 0 {ROOM} {ROOM} {ROOM} room mid=red:10",
            f"wall {ROOM} {ROOM} {ROOM} 0 room mid=red:8", f"wall {ROOM} 0 0 0 room mid=red:10",
            f"player 32 {ROOM // 2} 0", *models]
    path = out_dir / "objects_bench.scene"
    path.write_text("\n".join(text) + "\n")
    return path


def object_placements(n):
    """n objects on a fan of rows in front of the eye (32, 1024): row k at distance 300 + 150 k,
    its objects spread evenly within 30 degrees either side of the view axis, so every one is
    inside the 45-degree frustum, at least 40 units from its neighbours, and short of the far
    wall; models and yaws cycle deterministically."""
    out, k = [], 0
    while len(out) < n:
        dist = 300 + 150 * k
        per_row = min(n - len(out), max(1, int(dist * math.radians(60) / 60)))
        for i in range(per_row):
            a = math.radians(-30 + 60 * (i + 0.5) / per_row)
            x, y = 32 + dist * math.cos(a), ROOM / 2 + dist * math.sin(a)
            j = len(out)
            out.append((j % 3, round(x, 2), round(y, 2), 0, (37 * j) % 360))
        k += 1
    return out


def object_bench(out_dir, modes, n=2):
    source = object_scene(out_dir)
    scene = out_dir / "objects_bench.bsc"       # compiled afresh: the models may have changed
    subprocess.run([str(BUILD / "bspc"), str(source), "-o", str(scene)], check=True, capture_output=True)
    rows = []
    for count in OBJECT_COUNTS:
        path = out_dir / f"objects_{count}.txt"
        path.write_text("".join(f"object {m} {x} {y} {z} {yaw}\n" for m, x, y, z, yaw in object_placements(count)))
        extra = ["--objects", str(path), "--look", OBJECT_LOOK]
        row = {"n": count}
        for mode in modes:
            ir = (instructions(scene, OBJECT_VIEW, mode, n + 1, *extra) -
                  instructions(scene, OBJECT_VIEW, mode, 1, *extra)) // n
            j = render_json(scene, OBJECT_VIEW, "--mode", mode, *extra)
            row[mode] = {"ir": ir, "overdraw": j["overdraw"], "visible": j.get("objects_visible", "?"),
                         "faces": j.get("object_faces", "?")}
        rows.append(row)
        print(f"bench: {count} objects: " + " / ".join(f"{m} {row[m]['ir']:,}" for m in modes) +
              f" instructions per frame, {row[modes[0]]['visible']} visible", file=sys.stderr, flush=True)
    lines = ["| objects placed | objects_visible | object_faces | " +
             " | ".join(f"{m} Ir/frame | {m} Ir per visible object | {m} overdraw" for m in modes) + " |",
             "|---|---:|---:|" + "---:|---:|---:|" * len(modes)]
    for r in rows:
        first = r[modes[0]]
        cells = []
        for m in modes:
            s, base = r[m], rows[0][m]["ir"]
            per = f"{(s['ir'] - base) // s['visible']:,}" if isinstance(s["visible"], int) and s["visible"] else "-"
            cells.append(f"{s['ir']:,} | {per} | {s['overdraw']:.3f}")
        lines.append(f"| {r['n']} | {first['visible']} | {first['faces']} | " + " | ".join(cells) + " |")
    lines += ["", f"Objects: build/render build/bench/{source.name} --at {OBJECT_VIEW['at']} --angle {OBJECT_VIEW['angle']} "
              f"--look {OBJECT_LOOK} --objects build/bench/objects_N.txt (scene and files generated by "
              f"tools/bench.py); Ir per visible object is the increase over the frame without objects."]
    return "\n".join(lines) + "\n", rows


# ---- main -------------------------------------------------------------------------------------

def main(argv=None):
    ap = argparse.ArgumentParser(prog="bench.py", description="make bench: instructions per frame (callgrind, "
                                 "x86-64) per render mode over the bench and open views, the stages of the frame, "
                                 "write counts, and 0, 10 and 100 objects.")
    ap.add_argument("--objects-only", action="store_true",
                    help="measure only the objects (writes build/bench-objects.md)")
    ap.add_argument("--frames", type=int, default=10, metavar="N",
                    help="instructions per frame = (run of N+1 frames - run of 1) / N (default 10)")
    ap.add_argument("-j", "--jobs", type=int, default=2, help="callgrind runs at once (default 2)")
    ap.add_argument("--views", type=int, default=0, metavar="K", help="only the first K views (a quick look)")
    ap.add_argument("--scene", action="append", default=[], metavar="WAD:MAP",
                    help="only the views of this scene (repeatable; a quick look)")
    args = ap.parse_args(argv)
    started, t0 = datetime.datetime.now().astimezone(), time.time()
    bench_dir = BUILD / "bench"
    bench_dir.mkdir(parents=True, exist_ok=True)
    modes = render_modes()
    print(f"bench: modes {', '.join(modes)} (from build/render --help)", file=sys.stderr, flush=True)
    if args.objects_only:
        text, _ = object_bench(bench_dir, modes)
        (BUILD / "bench-objects.md").write_text(text)
        print(text)
        return
    views = load_views()
    if args.scene:
        views = [v for v in views if v["scene"] in args.scene]
    if args.views:
        views = views[:args.views]
    res = measure_views(views, modes, args.frames, args.jobs, bench_dir)
    sum_lines, stats = summary_table(views, modes, res)
    flat_lines, flat_stats = flat_table(views, modes, res)
    goal, goal_fig = goal_line(views, res)
    shares, sums = stage_shares(views, modes, res)
    top_lines, unclassified = top_functions(modes, sums, views)
    n_bench = sum(v["set"] == "bench" for v in views)
    obj_text, obj_rows = object_bench(bench_dir, modes)
    writes = writes_table(views, modes, bench_dir)
    elapsed = time.time() - t0

    text = "\n".join([
        "### Instructions per frame, x86-64",
        "",
        f"{len(views)} views: {n_bench} bench views (player starts) and {len(views) - n_bench} open views "
        f"(tests/bench_views.json). Instructions per frame = (Ir of --repeat {args.frames + 1} - Ir of --repeat 1) / "
        f"{args.frames}, callgrind, build/render; world alone is --no-objects. p95: nearest rank. Modes: those "
        f"build/render --help names and accepts ({', '.join(modes)}). The views are WAD maps, drawn textured: "
        f"every table but the next one is of textured frames.",
        "",
        *sum_lines,
        "",
        "### Textured against flat, x86-64, world alone",
        "",
        "The same views and frames, world alone (--no-objects): as build/render draws them (textured), and with "
        "--flat (the same scene in its flat colours). Ratio: each view's textured frame over its flat frame.",
        "",
        *flat_lines,
        "",
        *([goal, ""] if goal else []),
        "### Stages of the frame, x86-64",
        "",
        "Share of each stage: the mean over the views of the stage's share of the view's frame, and in brackets "
        "its share of all the views' frames summed (expensive views weigh more). From callgrind's instructions per "
        "address, by the function that holds the address (inlined code counts for the function it was written in; "
        "fixed.h and wide128.h helpers for the function they were inlined into); tools/bench_profile.py names the "
        "functions of each stage.",
        "",
        *stage_table(modes, shares),
        "",
        *top_lines,
        "",
        ("Functions in no stage's list (counted as other): " + "; ".join(unclassified) + "."
         if unclassified else "Every function with instructions is in a stage's list."),
        "",
        "### Per view, x86-64 (instructions per frame)",
        "",
        *view_table(views, modes, res),
        "",
        "### Overdraw and write counts (bench views, with things)",
        "",
        *writes,
        "",
        "### Objects",
        "",
        obj_text,
        f"Run: {started:%Y-%m-%d %H:%M %Z}, {elapsed / 60:.1f} minutes (callgrind, {args.jobs} at once).",
    ]) + "\n"
    (BUILD / "bench.md").write_text(text)
    figures = {"date": started.isoformat(timespec="seconds"), "seconds": round(elapsed), "frames": args.frames,
               "modes": modes, "stats": stats, "textured_vs_flat": flat_stats, "goal_map01": goal_fig,
               "stages": {f"{m} {w}": {s: {"mean": a, "of_sum": b} for s, (a, b) in v.items()}
                          for (m, w), v in shares.items()},
               "views": [{"view": view_name(v), "set": v["set"],
                          **{f"{m} {w}": res[(i, m, w)][0] for m in modes for w in ("world", "things", "flat")}}
                         for i, v in enumerate(views)],
               "objects": obj_rows}
    (BUILD / "bench.json").write_text(json.dumps(figures, indent=1) + "\n")
    bench_doc.write("x86")
    print(text)


if __name__ == "__main__":
    main()
