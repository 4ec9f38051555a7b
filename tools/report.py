#!/usr/bin/env python3
"""make report: error against run time, per render mode and precision-knob configuration.

Each configuration is a build/knob/NAME/render built by mk/report.mk with the knob flags in
build/knob/NAME/flags ("default" has none). For each configuration and render mode (every mode
build/render takes):

- error, over the views of tests/bench_views.json and every view of the extreme scenes'
  manifests (tests/scenes/extreme/*.json): the surface-id buffer against the reference renderer's
  (tools/refrender.py), with tools/accuracy.py's figures: the share of differing pixels, and the
  displacement of each differing pixel from its surface in the other buffer (320 when that surface
  is not within accuracy.SEARCH pixels: a sliver one buffer lacks, or a larger shift);
- texel-and-light error, over the bench views (all 20 player starts unless --tex-views N): the
  share of pixels NOT within one texel and one light step of the reference's colour
  (tools/reflook.py's compare, as tools/texcompare.py does: walls, floors, ceilings and sky with a
  texture, the world alone), per view, then its mean and worst over the views. The knobs of
  firmware/texture.h are about this error; the surface-id error above does not see them;
- run time, over the bench views only: instructions per frame with callgrind, as tools/bench.py
  counts them ((Ir of --repeat 3 - Ir of --repeat 1) / 2); the bench views are WAD maps, so these
  are textured frames;
- run time on the Cortex-M3, over the first bench views (--m3-views N, default 8): each
  configuration's firmware under QEMU with the instruction-counting plugin, mode columns
  (tools/report_m3.py). There a divide is costly, which the reciprocal knobs are for.

Writes OUT/report.md (default build/report/): a summary per render mode (the best configurations
by error, by texel-and-light error and by instructions, on x86-64 and the Cortex-M3, the default's
place in each, and those no other beats on both error and instructions), a table of every point,
OUT/error_vs_ir.png (mean differing share, worst edge displacement and mean texel-and-light error
against median instructions per frame, a column per mode and one for the Cortex-M3, on log axes with
a band for exact zeros; the Pareto front joined and ringed, it and the default named where a name
fits without covering another label or a point, "lower left is better" on every plot), and a
per-scene table of the extreme scenes for the default configuration. Reference id buffers are kept
in OUT/ref/, and every measured figure in OUT/cache.json keyed by the binary's and the scene's
contents (the firmware's: its sources and flags), so a re-run only measures what changed. Progress
goes to stderr: tasks and configurations done, and the time left at the mean so far. A report, not
a test: it asserts nothing about the figures.

usage: tools/report.py [--configs NAME ...] [--views N] [--tex-views N] [--m3-views N] [--no-ir] [--jobs N]
                       [--out DIR]
"""
import argparse
import concurrent.futures as cf
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import accuracy  # noqa: E402
import bench  # noqa: E402
import reflook  # noqa: E402
import refrender  # noqa: E402
import report_m3  # noqa: E402
import texcompare  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
KNOB = BUILD / "knob"
EXTREME = ROOT / "tests" / "scenes" / "extreme"
MODES = bench.MODES
DEFAULT = "default"
CAP = accuracy.CAP
CACHE_VERSION = 1


def log(msg):
    print(f"report: {msg}", file=sys.stderr, flush=True)


def digest(data):
    return hashlib.sha1(data).hexdigest()


def file_digest(path):
    return digest(Path(path).read_bytes())


# ---- views -----------------------------------------------------------------------------------

def load_views():
    """The bench views, then every view of every extreme manifest that parses (a manifest that
    does not is reported and left out: they are written alongside)."""
    views = []
    for v in json.loads((ROOT / "tests/bench_views.json").read_text())["views"]:
        views.append({"set": "bench", "group": "bench", "scene": v["scene"], "source": None,
                      "name": f"{v['scene']} @ {v['at']} {v['angle']}°",
                      "at": v["at"], "angle": v["angle"], "look": 0})
    for path in sorted(EXTREME.glob("*.json")):
        try:
            m = json.loads(path.read_text())
            scene = path.parent / m["scene"]
            if not scene.is_file():
                raise ValueError(f"no scene {scene}")
            for v in m["views"]:
                views.append({"set": "extreme", "group": path.stem, "scene": str(scene), "source": scene,
                              "name": f"{path.stem}/{v['name']}", "at": str(v["at"]), "angle": str(v["angle"]),
                              "look": int(v.get("look") or 0)})
        except (ValueError, KeyError, TypeError) as e:
            log(f"{path.name}: left out ({e})")
    return views


def compiled(view, out_dir):
    """The view's scene compiled by build/bspc once (a text scene again when it changes)."""
    src = view["source"]
    if src is None:
        return bench.compiled(view["scene"], out_dir)
    out = out_dir / (Path(src).stem + ".bsc")
    newest = max(Path(src).stat().st_mtime, (BUILD / "bspc").stat().st_mtime)  # a new compiler: a new blob
    if not out.exists() or out.stat().st_mtime < newest:
        subprocess.run([str(BUILD / "bspc"), str(src), "-o", str(out)], check=True, capture_output=True)
    return out


def scene_key(view):
    """What the view's picture depends on besides the camera: the map's contents."""
    return view["scene"] if view["source"] is None else file_digest(view["source"])


def camera_args(view):
    """The view's camera, and the world alone: the knobs are about the world's precision, and the
    report's figures stay comparable with those of scenes without objects."""
    return ["--at", view["at"], "--angle", view["angle"], "--no-objects"] + \
        (["--look", str(view["look"])] if view["look"] else [])


# ---- the reference ---------------------------------------------------------------------------

def reference(view, z, ref_dir):
    """The reference id buffer of a view (eye height z as the C renderer used it), cached."""
    key = digest(json.dumps([scene_key(view), view["at"], view["angle"], view["look"], z,
                             file_digest(refrender.__file__)]).encode())[:16]
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in view["name"])[:80]
    path = ref_dir / f"{safe}.{key}.bin"
    if not path.exists():
        x, y = (float(c) for c in view["at"].split(",")[:2])
        ids = refrender.render_ids(view["scene"], x, y, z, float(view["angle"]), view["look"], objects=[])
        tmp = path.with_suffix(".tmp")
        refrender.write_ids(tmp, ids)
        tmp.replace(path)
    return path


def _reference_task(args):
    view, z, ref_dir = args
    return str(reference(view, z, ref_dir))


# ---- measuring one point -----------------------------------------------------------------------

def _error_task(args):
    """Render one view with one binary and mode; compare with the reference. Runs in a worker."""
    render, bsc, view, mode, ref_path = args
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "ids.bin"
        proc = subprocess.run([str(render), str(bsc), *camera_args(view), "--mode", mode, "--ids", str(out)],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            # a render that fails shows nothing: counted as every pixel wrong, and reported
            return {"differ": 1.0, "edge": CAP, "hist": [], "failed": proc.returncode}
        ids = accuracy.read_ids(out)
    ref = accuracy.read_ids(ref_path)
    d = accuracy.edge_distances(ref, ids)
    return {
        "differ": accuracy.differ(ref, ids),
        "edge": int(d.max()) if d.size else 0,
        "hist": sparse_hist(d),
    }


def _texerr_task(args):
    """One bench view: the reference's texels and light (once), then each (render, mode)'s frame of
    the view against it. Returns, per render, {"bad": share of compared pixels not within one
    texel and one light step, "compared": pixels compared}. Runs in a worker."""
    view, bsc, runs = args
    e = texcompare.reference(view["scene"], view["at"], view["angle"], view["look"])
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        raw, idf = Path(tmp) / "frame.raw", Path(tmp) / "frame.ids"
        for render, mode in runs:
            proc = subprocess.run([str(render), str(bsc), *camera_args(view), "--mode", mode, "--raw", str(raw),
                                   "--ids", str(idf)], capture_output=True, text=True)
            if proc.returncode != 0:
                out.append({"bad": 1.0, "compared": 0, "failed": proc.returncode})
                continue
            _, _, counts = reflook.compare(e, np.fromfile(raw, np.uint8), np.fromfile(idf, "<u4"))
            ok, n = counts["all"]
            out.append({"bad": 1.0 - ok / n if n else 0.0, "compared": n})
    return out


def sparse_hist(distances):
    """[[distance, count], ...] for the distances that occur (most views have few differing pixels)."""
    counts = np.bincount(np.minimum(distances, CAP), minlength=CAP + 1) if distances.size else np.zeros(0, int)
    return [[int(v), int(n)] for v, n in enumerate(counts) if n]


def dense_hist(pairs):
    hist = np.zeros(CAP + 1, dtype=np.int64)
    for v, n in pairs:
        hist[v] += n
    return hist


def _ir_task(args):
    render, bsc, view, mode = args
    cg_view = {"at": view["at"], "angle": view["angle"]}
    return (bench.instructions(bsc, cg_view, mode, 3, "--no-objects", render=render)
            - bench.instructions(bsc, cg_view, mode, 1, "--no-objects", render=render)) // 2


class Cache:
    """Measured figures by key, in one JSON file; written after every batch. Only the entries this
    run used are written back, so figures of binaries since rebuilt do not pile up."""

    def __init__(self, path):
        self.path = path
        self.data = {}
        self.used = {}
        try:
            d = json.loads(path.read_text())
            if d.get("version") == CACHE_VERSION:
                self.data = d["entries"]
        except (OSError, ValueError, KeyError):
            pass

    def get(self, key):
        value = self.data.get(key)
        if value is not None:
            self.used[key] = value
        return value

    def put(self, key, value):
        self.data[key] = self.used[key] = value

    def save(self):
        tmp = self.path.with_suffix(".tmp")
        tmp.write_text(json.dumps({"version": CACHE_VERSION, "entries": self.used}))
        tmp.replace(self.path)


def duration(seconds):
    """A short human duration: 45 s, 3 min 20 s, 1 h 05 min."""
    s = int(round(seconds))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"


def progress(what, done, total, elapsed, groups=None):
    """One progress line: tasks done of total, the configurations finished (groups: the
    configuration of each task, in order), the time so far and the time left at the mean so far."""
    line = f"{what}: {done}/{total}"
    if groups:
        last = {g: i for i, g in enumerate(groups)}
        line += f", configurations {sum(i < done for i in last.values())}/{len(last)} done"
    line += f", {duration(elapsed)}"
    if done < total:
        line += f", about {duration(elapsed / done * (total - done))} left"
    return line


def run_tasks(pool, fn, tasks, what, every=25, groups=None):
    """Map fn over tasks in the pool, in order, logging progress (groups: see progress)."""
    out, t0 = [], time.time()
    for i, r in enumerate(pool.map(fn, tasks), 1):
        out.append(r)
        if i % every == 0 or i == len(tasks):
            log(progress(what, i, len(tasks), time.time() - t0, groups))
    return out


# ---- summaries -------------------------------------------------------------------------------

def hist_percentile(hist, q):
    """The q-th percentile (nearest rank) of the values counted in hist (index = value)."""
    total = sum(hist)
    if total == 0:
        return 0
    rank = max(1, int(np.ceil(q / 100.0 * total)))
    acc = 0
    for v, n in enumerate(hist):
        acc += n
        if acc >= rank:
            return v
    return len(hist) - 1


def summarise(config, flags, mode, views, errors, irs, tex=()):
    """One point: the figures of a configuration and mode over the views; tex: the texel-and-light
    errors (_texerr_task's) of the views measured for it, with the views' names."""
    differ = [e["differ"] for e in errors]
    bench_differ = [e["differ"] for e, v in zip(errors, views) if v["set"] == "bench"]
    ext_differ = [e["differ"] for e, v in zip(errors, views) if v["set"] == "extreme"]
    hist = dense_hist([pair for e in errors for pair in e["hist"]]).tolist()
    worst = max(range(len(errors)), key=lambda i: (errors[i]["differ"], errors[i]["edge"])) if errors else None
    return {
        "config": config, "flags": flags, "mode": mode,
        "ir": int(statistics.median(irs)) if irs else None,
        "views": len(errors),
        "mean_differ": float(np.mean(differ)) if differ else 0.0,
        "mean_differ_bench": float(np.mean(bench_differ)) if bench_differ else None,
        "mean_differ_extreme": float(np.mean(ext_differ)) if ext_differ else None,
        "worst_differ": max(differ) if differ else 0.0,
        "worst_view": views[worst]["name"] if worst is not None else "",
        "worst_edge": max((e["edge"] for e in errors), default=0),
        "worst_moved_edge": max((v for v, n in enumerate(hist[:CAP]) if n), default=0),
        "p99_edge": hist_percentile(hist, 99),
        "views_at_cap": sum(1 for e in errors if e["edge"] >= CAP),
        "failed": [views[i]["name"] for i, e in enumerate(errors) if e.get("failed") is not None],
        "tex_views": len(tex),
        "tex_bad_mean": float(np.mean([t["bad"] for t, _ in tex])) if tex else None,
        "tex_bad_worst": max(t["bad"] for t, _ in tex) if tex else None,
        "tex_worst_view": max(tex, key=lambda p: p[0]["bad"])[1] if tex else "",
    }


def pct(x, digits=3):
    return "—" if x is None else f"{100 * x:.{digits}f}%"


def rank(points, p, key):
    """p's place (1 = best, lowest) among points by key; ties share the better place."""
    return 1 + sum(1 for q in points if q[key] < p[key])


def best(points, key, shown=4):
    """The configurations with the lowest key, ties named together (the default first)."""
    low = min(p[key] for p in points)
    names = sorted((p["config"] for p in points if p[key] == low), key=lambda c: c != DEFAULT)
    more = f" and {len(names) - shown} more" if len(names) > shown else ""
    return ", ".join(names[:shown]) + more


def pareto(points):
    """The points no other point beats on both error and instructions (lower left of the plot)."""
    return [p for p in points
            if not any(q["ir"] <= p["ir"] and q["mean_differ"] <= p["mean_differ"] and
                       (q["ir"], q["mean_differ"]) != (p["ir"], p["mean_differ"]) for q in points)]


def summary_lines(points):
    """Per render mode: the best configuration by error, by texel-and-light error and by
    instructions, the default's place in each, and the configurations worth choosing."""
    lines = ["## Summary", ""]
    for mode in dict.fromkeys(p["mode"] for p in points):
        pts = [p for p in points if p["mode"] == mode]
        n = len(pts)
        lines.append(f"- **{mode}**: least error: {best(pts, 'mean_differ')} "
                     f"({pct(min(p['mean_differ'] for p in pts))} of pixels differ)")
        tex = [p for p in pts if p["tex_bad_mean"] is not None]
        if tex:
            low = min(p["tex_bad_mean"] for p in tex)
            lines[-1] += f"; fewest texels off: {best(tex, 'tex_bad_mean')} ({pct(low)})"
        timed = [p for p in pts if p["ir"] is not None]
        if timed:
            lines[-1] += f"; fewest instructions: {best(timed, 'ir')} ({min(p['ir'] for p in timed):,} per frame)"
        lines[-1] += "."
        d = next((p for p in pts if p["config"] == DEFAULT), None)
        if d is not None:
            where = [f"error {rank(pts, d, 'mean_differ')} of {n} ({pct(d['mean_differ'])})"]
            if d["tex_bad_mean"] is not None:
                where.append(f"texels off {rank(tex, d, 'tex_bad_mean')} of {len(tex)} ({pct(d['tex_bad_mean'])})")
            if d["ir"] is not None:
                where.append(f"instructions {rank(timed, d, 'ir')} of {len(timed)} ({d['ir']:,})")
            lines.append(f"  The default's place (1 = lowest): " + ", ".join(where) + ".")
        if len(timed) > 1:
            edge = sorted(pareto(timed), key=lambda p: p["ir"])
            lines.append("  Not beaten on both error and instructions by any other (the lower-left edge of the "
                         "plot): " + ", ".join(p["config"] for p in edge) + ".")
        on_m3 = [dict(p, ir=p["m3_ir"]) for p in pts if p.get("m3_ir") is not None]
        if on_m3:
            low = min(p["ir"] for p in on_m3)
            line = f"  On the Cortex-M3: fewest instructions: {best(on_m3, 'ir')} ({low:,} per frame)"
            if d is not None and d.get("m3_ir") is not None:
                line += f"; the default {rank(on_m3, dict(d, ir=d['m3_ir']), 'ir')} of {len(on_m3)} ({d['m3_ir']:,})"
            if len(on_m3) > 1:
                line += "; not beaten on both: " + ", ".join(
                    p["config"] for p in sorted(pareto(on_m3), key=lambda p: p["ir"]))
            lines.append(line + ".")
    return lines + [""]


def write_markdown(path, points, per_scene, views, configs, png_name, no_ir, tex_names=(), m3_names=()):
    """The report: how it was measured, every point, the default's extreme scenes."""
    n_bench = sum(1 for v in views if v["set"] == "bench")
    groups = sorted({v["group"] for v in views if v["set"] == "extreme"})
    n_ext = len(views) - n_bench
    default_ir = {p["mode"]: p["ir"] for p in points if p["config"] == DEFAULT}
    default_m3 = next((p.get("m3_ir") for p in points if p["config"] == DEFAULT and p.get("m3_ir")), None)
    lines = [
        "# Error against run time",
        "",
        *summary_lines(points),
        f"Views: {n_bench} bench views (tests/bench_views.json) and {n_ext} views of {len(groups)} extreme "
        f"scenes (tests/scenes/extreme/). Error: each view's surface ids against tools/refrender.py "
        f"(tools/accuracy.py): the share of differing pixels, and the displacement of edges: for each "
        f"differing pixel, the distance in pixels (rows or columns) to its surface in the other buffer, 320 "
        f"when that is not within {accuracy.SEARCH} pixels. Run time: "
        + ("not measured (--no-ir)." if no_ir else
           "instructions per frame on x86-64 (callgrind, (Ir of --repeat 3 - Ir of --repeat 1) / 2), "
           "the median over the bench views.")
        + (f" On the Cortex-M3 (mode {report_m3.MODE}, the board's): the firmware built with each configuration's "
           f"flags, under QEMU (mps2-an385) with the instruction-counting plugin, the world alone, the median over "
           f"{len(m3_names)} bench views: " + ", ".join(m3_names) + " (tools/report_m3.py)." if m3_names else ""),
        "",
        "Columns: *mean differ* over all views (and over the bench and extreme views apart), *worst differ* "
        "and the view it is on, *worst edge* the largest displacement on any view (320: a surface one "
        "buffer lacks there, such as a sliver of wall, or a shift of more than "
        f"{accuracy.SEARCH} pixels), *worst moved edge* the largest displacement below that (an edge both "
        "buffers have, moved), *p99 edge* the 99th percentile of the displacements of all differing pixels "
        "pooled over the views, *views at 320* the views with a displacement of 320.",
        "",
        (f"Texel-and-light error (*texels off*): the share of compared pixels whose colour is not within one "
         f"texel and one light step of the reference's (tools/reflook.py's compare, as tools/texcompare.py does: "
         f"wall, floor, ceiling and sky pixels with a texture, the world alone), the mean over {len(tex_names)} "
         f"bench views and the worst view: " + ", ".join(tex_names) + ". The texture knobs (texsub*, texrecip*, "
         f"texlight*) change only this error; the surface-id error above is the geometry's."
         if tex_names else "Texel-and-light error: not measured (--tex-views 0)."),
        "",
        f"![error against instructions per frame]({png_name})",
        "",
        "| config | flags | mode | median Ir/frame | vs default | Cortex-M3 | vs default | mean differ | bench "
        "| extreme | worst differ | worst view | worst edge px | worst moved edge px | p99 edge px | views at 320 "
        "| texels off: mean | worst | worst texel view |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    for p in points:
        base = default_ir.get(p["mode"])
        rel = "—" if p["ir"] is None or not base else f"{100.0 * (p['ir'] - base) / base:+.1f}%"
        name = f"**{p['config']}**" if p["config"] == DEFAULT else p["config"]
        m3 = p.get("m3_ir")
        m3_rel = "—" if m3 is None or not default_m3 else f"{100.0 * (m3 - default_m3) / default_m3:+.1f}%"
        lines.append(
            f"| {name} | {p['flags'] or '—'} | {p['mode']} | {'—' if p['ir'] is None else format(p['ir'], ',')} "
            f"| {rel} | {'—' if m3 is None else format(m3, ',')} | {m3_rel} | {pct(p['mean_differ'])} | {pct(p['mean_differ_bench'])} | {pct(p['mean_differ_extreme'])} "
            f"| {pct(p['worst_differ'], 2)} | {p['worst_view']} | {p['worst_edge']} | {p['worst_moved_edge']} "
            f"| {p['p99_edge']} "
            f"| {p['views_at_cap']} | {pct(p['tex_bad_mean'])} | {pct(p['tex_bad_worst'], 2)} "
            f"| {p['tex_worst_view'] or '—'} |")
    failed = [(p["config"], p["mode"], n) for p in points for n in p["failed"]]
    if failed:
        lines += ["", f"Failed renders (counted as every pixel differing, displacement 320): {len(failed)}: "
                  + "; ".join(f"{c}/{m} {n}" for c, m, n in failed[:20]) + ("; ..." if len(failed) > 20 else "")]
    if per_scene:
        shown = [m for m in MODES if any(m in row for row in per_scene.values())]
        lines += [
            "",
            f"## Extreme scenes, configuration {DEFAULT}",
            "",
            "Worst share of differing pixels and worst edge displacement over each scene's views.",
            "",
            "| scene | views | " + " | ".join(f"{m} worst differ | {m} worst edge px" for m in shown) + " |",
            "|---|---:|" + "---:|---:|" * len(shown),
        ]
        for scene, row in per_scene.items():
            cells = " | ".join(f"{pct(row[m]['differ'], 2)} | {row[m]['edge']}" if m in row else "— | —"
                               for m in shown)
            lines.append(f"| {scene} | {row['views']} | {cells} |")
    lines += ["", "Configurations (mk/report.mk): " +
              "; ".join(f"{c} = {configs[c] or '(no flags)'}" for c in configs) + "."]
    path.write_text("\n".join(lines) + "\n")


def family(config, flags):
    """The knob a configuration turns, for the plot's colours."""
    if config == DEFAULT:
        return "default"
    knobs = {f.split("=")[0].lstrip("-D") for f in flags.split()}
    if len(knobs) > 1 and "FX_SIN_LERP" not in knobs:
        return "combined"
    return {"VIEW_SUBPIXEL_BITS": "subpixel bits", "RAST_STEP_BITS": "edge step bits",
            "VIEW_RECIP_BITS": "reciprocal table", "VIEW_SHIFT": "view-space bits",
            "FX_SIN_BITS": "sine table", "FX_SIN_LERP": "sine table",
            "TEX_SUBDIV_BITS": "texture span subdivision", "TEX_RECIP_BITS": "texture reciprocal table",
            "TEX_LIGHT_BITS": "light steps", "CFG_FLAT": "flat (no textures)"}.get(sorted(knobs)[0], "other")


def front(xy):
    """Indices of the points (x, y) that no other point beats on both (lower left): the Pareto front,
    in order of x."""
    order = sorted(range(len(xy)), key=lambda i: (xy[i][0], xy[i][1]))
    out, low = [], None
    for i in order:
        if low is None or xy[i][1] < low:
            out.append(i)
            low = xy[i][1]
    return out


def _overlaps(a, b):
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def _place_labels(fig, ax, items, taken, fontsize=8):
    """Write each label (x, y, text, colour) beside its point, at the first of a ring of offsets,
    growing outwards, where its box (measured by the renderer) meets no box already taken (other
    labels, and the markers) and stays inside the axes; a label with no such place within reach is
    left out. Returns the boxes written (display pixels), which are added to taken."""
    from matplotlib.text import Text
    renderer = fig.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    written = []
    for x, y, text, colour in items:
        for r in (6, 14, 24, 36, 50, 66):
            placed = None
            for dx, dy, ha, va in ((r, 0, "left", "center"), (0, r, "center", "bottom"), (-r, 0, "right", "center"),
                                   (0, -r, "center", "top"), (r, r, "left", "bottom"), (-r, r, "right", "bottom"),
                                   (-r, -r, "right", "top"), (r, -r, "left", "top")):
                t = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset pixels", ha=ha, va=va,
                                fontsize=fontsize, color=colour, annotation_clip=False,
                                arrowprops=dict(arrowstyle="-", color=colour, lw=0.5, alpha=0.7) if r > 6 else None)
                t.update_positions(renderer)
                box = Text.get_window_extent(t, renderer).padded(1)  # the text alone, not its leader line
                inside = frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
                if inside and not any(_overlaps(box, b) for b in taken):
                    placed = box
                    break
                t.remove()
            if placed is not None:
                taken.append(placed)
                written.append(placed)
                break
    return written


def plot(path, points, no_ir):
    """Error against run time, per render mode (a column each, x86-64 instructions) and for mode
    columns on the Cortex-M3 (a column more, when measured), for each error figure (a row each): the
    mean share of differing pixels, the largest displacement of an edge both buffers have, and the
    texel-and-light error. Each figure is on a log axis, with a band below it for the points at
    exactly 0 (a log axis has no 0). In each plot the Pareto front (no other configuration has both
    fewer instructions and less error) is joined by a line and its points ringed; the default is a
    star. Only the front and the default are named beside their points, where a name fits without
    covering another or a point; every point's figures are in report.md. Returns the label boxes
    written, per plot (display pixels), and the figure's texts."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import ticker

    fams = sorted({family(p["config"], p["flags"]) for p in points} - {"default"})
    colours = {f: plt.get_cmap("tab10")(i % 10) for i, f in enumerate(fams)}
    colours["default"] = "black"
    panels = [(m, "ir", f"mode {m}, x86-64") for m in MODES if any(p["mode"] == m for p in points)]
    if not no_ir and any(p.get("m3_ir") is not None for p in points):
        panels.append((next(p["mode"] for p in points if p.get("m3_ir") is not None), "m3_ir",
                       f"mode {report_m3.MODE}, Cortex-M3"))
    order = {c: i for i, c in enumerate(dict.fromkeys(p["config"] for p in points))}
    rows = [("mean_differ", "mean share of pixels differing\nfrom the reference (%)", 100.0),
            ("worst_moved_edge", f"worst edge displacement (px),\nbelow 320 (found within {accuracy.SEARCH} px)", 1.0)]
    if any(p.get("tex_bad_mean") is not None for p in points):
        rows.append(("tex_bad_mean", "mean share of pixels not within one\ntexel and one light step (%)", 100.0))
    fig = plt.figure(figsize=(6.5 * len(panels) + 1.5, 5.2 * len(rows)), dpi=100)
    grid = fig.add_gridspec(2 * len(rows), len(panels), height_ratios=[5, 0.6] * len(rows), hspace=0.1, wspace=0.14)
    better = "lower is better \u2193" if no_ir else "lower left is better \u2199"
    fig.suptitle(f"Precision knobs: error against the reference renderer vs. instructions per frame ({better})",
                 fontsize=13)
    handles = [plt.Line2D([], [], marker="*", color="gold", markeredgecolor="black", markersize=15, linestyle="",
                          label="default")]
    handles += [plt.Line2D([], [], marker="o", color=colours[f], linestyle="", label=f) for f in fams]
    handles.append(plt.Line2D([], [], marker="o", markerfacecolor="none", markeredgecolor="crimson", markersize=11,
                              color="crimson", linestyle="--", label="Pareto front (named)"))
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 7), fontsize=9, title="knob",
               title_fontsize=9, frameon=False)
    fig.subplots_adjust(left=0.07, right=0.99, top=0.94, bottom=0.1)
    placements = []
    for row, (key, ylabel, scale) in enumerate(rows):
        values = [p[key] * scale for p in points if p.get(key) is not None]
        positive = [v for v in values if v > 0]
        # whole decades, at least one, so that the log axis has labelled ticks
        lo = 10.0 ** np.floor(np.log10(min(positive) / 1.5)) if positive else 0.1
        hi = 10.0 ** np.ceil(np.log10(max(positive) * 1.5)) if positive else 10.0
        for col, (mode, xkey, title) in enumerate(panels):
            ax = fig.add_subplot(grid[2 * row, col])
            zero = fig.add_subplot(grid[2 * row + 1, col], sharex=ax)
            pts = [p for p in points if p["mode"] == mode and p.get(key) is not None and
                   (no_ir or p.get(xkey) is not None)]
            xy = [(order[p["config"]] if no_ir else p[xkey], p[key] * scale) for p in pts]
            on_front = set(front(xy)) if not no_ir else set()
            for p, (x, y) in zip(pts, xy):
                target = ax if y > 0 else zero
                if p["config"] == DEFAULT:
                    target.scatter([x], [y], marker="*", s=380, c="gold", edgecolors="black", linewidths=1.3, zorder=5)
                else:
                    target.scatter([x], [y], marker="o", s=40, color=colours[family(p["config"], p["flags"])],
                                   edgecolors="black", linewidths=0.4, zorder=3)
            fx = sorted((xy[i] for i in on_front), key=lambda t: t[0])
            for target, part in ((ax, [t for t in fx if t[1] > 0]), (zero, [t for t in fx if t[1] <= 0])):
                if part:
                    target.scatter([t[0] for t in part], [t[1] for t in part], s=520, facecolors="none",
                                   edgecolors="crimson", linewidths=1.4, zorder=6)
                if len(part) > 1:
                    target.step([t[0] for t in part], [t[1] for t in part], where="post", color="crimson",
                                linestyle="--", linewidth=1.0, zorder=2)
            ax.set_yscale("log")
            ax.set_ylim(lo, hi)
            ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
            ax.yaxis.set_minor_formatter(ticker.NullFormatter())
            ax.margins(x=0.15)
            ax.grid(True, which="both", alpha=0.3)
            ax.tick_params(labelbottom=False)
            ax.text(0.98, 0.97, better, transform=ax.transAxes, ha="right", va="top", fontsize=10,
                    color="dimgray", bbox=dict(boxstyle="round", fc="white", ec="lightgray", alpha=0.9))
            zero.set_ylim(-1, 1)
            zero.set_yticks([0])
            zero.set_yticklabels(["0"])
            zero.grid(True, axis="x", alpha=0.3)
            if col == 0:
                ax.set_ylabel(ylabel)
            if row == 0:
                ax.set_title(title)
            if row == len(rows) - 1:
                zero.set_xlabel("configuration (instructions not measured: --no-ir)" if no_ir else
                                "median instructions per frame" +
                                (" (QEMU plugin)" if xkey == "m3_ir" else " (callgrind)"))
            else:
                zero.tick_params(labelbottom=False)
            named = [(i, p) for i, p in enumerate(pts) if i in on_front or p["config"] == DEFAULT]
            placements.append((ax, zero, [(xy[i], p) for i, p in named], [xy[i] for i in range(len(pts))]))
    fig.canvas.draw()  # the layout is final: labels are measured and placed in display pixels
    boxes = []
    for ax, zero, named, allxy in placements:
        taken = []
        for target in (ax, zero):
            for x, y in allxy:  # the markers, as boxes of their size
                if (y > 0) == (target is ax):
                    px, py = target.transData.transform((x, y))
                    taken.append(matplotlib.transforms.Bbox([[px - 14, py - 14], [px + 14, py + 14]]))  # a ring's size
        written = []
        for target in (ax, zero):
            items = [(x, y, p["config"], colours[family(p["config"], p["flags"])]) for (x, y), p in named
                     if (y > 0) == (target is ax)]
            own = [b for b in taken]
            written += _place_labels(fig, target, items, own)
            taken = own
        boxes.append(written)
    fig.savefig(path, dpi=fig.dpi)
    texts = [t.get_text() for t in fig.findobj(matplotlib.text.Text)]
    plt.close(fig)
    return {"labels": boxes, "texts": texts}


# ---- main ------------------------------------------------------------------------------------

def main(argv=None):
    ap = argparse.ArgumentParser(prog="report.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("--configs", nargs="+", default=[DEFAULT],
                    help="configuration names (build/knob/NAME/render); the first named 'default' is marked")
    ap.add_argument("--views", type=int, default=0, help="only the first N views (bench views first)")
    ap.add_argument("--tex-views", type=int, default=None, metavar="N",
                    help="texel-and-light error over the first N bench views (default: all; 0: none)")
    ap.add_argument("--no-ir", action="store_true", help="no instruction counts (no callgrind, no Cortex-M3)")
    ap.add_argument("--m3-views", type=int, default=8, metavar="N",
                    help="instructions per frame on the Cortex-M3 (QEMU) over the first N bench views, mode "
                         f"{report_m3.MODE} (default 8; 0: none)")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel workers")
    ap.add_argument("--knob-dir", type=Path, default=KNOB, help="where the configurations' binaries are")
    ap.add_argument("--out", type=Path, default=BUILD / "report", help="output folder")
    args = ap.parse_args(argv)

    t_start = time.time()
    configs = {}
    for c in args.configs:
        render = args.knob_dir / c / "render"
        if not render.exists():
            log(f"{render} is missing: make {render.relative_to(ROOT) if render.is_relative_to(ROOT) else render}")
            return 2
        flags_file = args.knob_dir / c / "flags"
        configs[c] = flags_file.read_text().strip() if flags_file.exists() else ""
    views = load_views()
    if args.views:
        views = views[:args.views]
    out = args.out
    (out / "ref").mkdir(parents=True, exist_ok=True)
    bsc_dir = BUILD / "report" / "bsc"
    bsc_dir.mkdir(parents=True, exist_ok=True)
    cache = Cache(out / "cache.json")
    log(f"{len(configs)} configurations x {len(MODES)} modes, {len(views)} views "
        f"({sum(v['set'] == 'bench' for v in views)} bench), {args.jobs} workers")

    bscs = [compiled(v, bsc_dir) for v in views]
    default_render = args.knob_dir / (DEFAULT if DEFAULT in configs else args.configs[0]) / "render"
    # the eye height the C renderer uses (the floor under the eye + 41 unless given) is the one
    # the reference is asked for, as tests/test_accuracy.py does
    zs = []
    for v, bsc in zip(views, bscs):
        j = json.loads(subprocess.run([str(default_render), str(bsc), *camera_args(v)], check=True,
                                      capture_output=True, text=True).stdout)
        zs.append(float(j["camera"]["z"]))
    with cf.ProcessPoolExecutor(max_workers=args.jobs) as pool:
        refs = run_tasks(pool, _reference_task, [(v, z, out / "ref") for v, z in zip(views, zs)],
                         "reference id buffers")
        bin_digest = {c: file_digest(args.knob_dir / c / "render") for c in configs}
        view_keys = [digest(json.dumps([scene_key(v), v["at"], v["angle"], v["look"]]).encode()) for v in views]
        ref_keys = {r: file_digest(r) for r in refs}
        accuracy_digest = file_digest(accuracy.__file__)[:12]

        # error: every configuration, mode and view
        errors = {}
        todo, todo_keys = [], []
        for c in configs:
            for m in MODES:
                for i, v in enumerate(views):
                    key = f"error:{bin_digest[c]}:{m}:{view_keys[i]}:{ref_keys[refs[i]]}:{accuracy_digest}"
                    hit = cache.get(key)
                    if hit is None:
                        todo.append((args.knob_dir / c / "render", bscs[i], v, m, refs[i]))
                        todo_keys.append((c, m, i, key))
                    errors[(c, m, i)] = hit
        log(f"error: {len(todo)} renders to compare ({len(errors) - len(todo)} cached)")
        for (c, m, i, key), r in zip(todo_keys, run_tasks(pool, _error_task, todo, "error", every=100,
                                                             groups=[k[0] for k in todo_keys])):
            errors[(c, m, i)] = r
            cache.put(key, r)
        cache.save()

        # texel and light: every configuration and mode on the bench views that are WAD maps
        tex_views = [i for i, v in enumerate(views) if v["set"] == "bench" and ".wad:" in v["scene"].lower()]
        if args.tex_views is not None:
            tex_views = tex_views[:args.tex_views]
        look_digest = (file_digest(reflook.__file__) + file_digest(refrender.__file__))[:24]
        texerr, tasks, task_keys = {}, [], []
        for i in tex_views:
            runs, keys = [], []
            for c in configs:
                for m in MODES:
                    key = f"tex:{bin_digest[c]}:{m}:{view_keys[i]}:{look_digest}"
                    hit = cache.get(key)
                    texerr[(c, m, i)] = hit
                    if hit is None:
                        runs.append((args.knob_dir / c / "render", m))
                        keys.append((c, m, key))
            if runs:
                tasks.append((views[i], bscs[i], runs))
                task_keys.append((i, keys))
        log(f"texels and light: {sum(len(k) for _, k in task_keys)} frames to compare over {len(tex_views)} views "
            f"({sum(r is not None for r in texerr.values())} cached)")
        for (i, keys), results in zip(task_keys, run_tasks(pool, _texerr_task, tasks, "texels and light", every=5)):
            for (c, m, key), r in zip(keys, results):
                texerr[(c, m, i)] = r
                cache.put(key, r)
        cache.save()

    # run time: every configuration and mode on the bench views
    irs = {}
    if not args.no_ir:
        todo, todo_keys = [], []
        for c in configs:
            for m in MODES:
                for i, v in enumerate(views):
                    if v["set"] != "bench":
                        continue
                    key = f"ir:{bin_digest[c]}:{m}:{view_keys[i]}"
                    hit = cache.get(key)
                    if hit is None:
                        todo.append((args.knob_dir / c / "render", bscs[i], v, m))
                        todo_keys.append((c, m, i, key))
                    irs[(c, m, i)] = hit
        log(f"instructions per frame: {len(todo)} callgrind pairs ({len(irs) - len(todo)} cached)")
        with cf.ThreadPoolExecutor(max_workers=args.jobs) as pool:
            for (c, m, i, key), r in zip(todo_keys, run_tasks(pool, _ir_task, todo, "callgrind", every=20,
                                                                 groups=[k[0] for k in todo_keys])):
                irs[(c, m, i)] = r
                cache.put(key, r)
        cache.save()

    # run time on the Cortex-M3: every configuration's firmware, mode columns, the first bench views
    m3, m3_views = {}, []
    if not args.no_ir and args.m3_views > 0:
        m3_views = [v for v in views if v["set"] == "bench"][:args.m3_views]
        log(f"Cortex-M3: {len(configs)} configurations x {len(m3_views)} views, mode {report_m3.MODE}")
        m3 = report_m3.measure(configs, m3_views, out / "m3", cache, log, jobs=args.jobs)

    points = []
    for c in configs:
        for m in MODES:
            errs = [errors[(c, m, i)] for i in range(len(views))]
            ir = [irs[(c, m, i)] for i, v in enumerate(views) if (c, m, i) in irs]
            tex = [(texerr[(c, m, i)], views[i]["name"]) for i in tex_views]
            points.append(summarise(c, configs[c], m, views, errs, ir, tex))
            points[-1]["m3_ir"] = int(statistics.median(m3[c])) if c in m3 and m == report_m3.MODE else None
    per_scene = {}
    if DEFAULT in configs:
        for i, v in enumerate(views):
            if v["set"] != "extreme":
                continue
            row = per_scene.setdefault(v["group"], {"views": 0, **{m: {"differ": 0.0, "edge": 0} for m in MODES}})
            row["views"] += 1
            for m in MODES:
                e = errors[(DEFAULT, m, i)]
                row[m]["differ"] = max(row[m]["differ"], e["differ"])
                row[m]["edge"] = max(row[m]["edge"], e["edge"])

    png = out / "error_vs_ir.png"
    plot(png, points, args.no_ir)
    write_markdown(out / "report.md", points, per_scene, views, configs, png.name, args.no_ir,
                   [views[i]["name"] for i in tex_views], [v["name"] for v in m3_views])
    (out / "points.json").write_text(json.dumps({"points": points, "per_scene": per_scene}, indent=1))
    log(f"wrote {out / 'report.md'} and {png} in {time.time() - t_start:.0f} s")
    print((out / "report.md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
