#!/usr/bin/env python3
"""make bench: figures for the fixed list of views in tests/bench_views.json.

Per view and render mode: instructions per frame of build/render (valgrind's callgrind, which counts
instructions, so the figure repeats exactly from run to run), overdraw, and, per present mode, VRAM
write transactions and modelled bus cycles. Instructions per frame = (Ir of --repeat 3 - Ir of
--repeat 1) / 2, which leaves out loading the scene and writing files. Scenes are compiled once to
build/bench/ first so that callgrind does not also measure the compiler.

Prints a Markdown table and writes it to build/bench.md. A benchmark, not a test: it asserts nothing.
"""
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
RENDER = BUILD / "render"
MODES = ["spans", "painter"]
PRESENTS = ["flip", "copy8", "copy16", "copy32"]


def compiled(scene, out_dir):
    out = out_dir / (scene.replace(":", "_").replace("/", "_") + ".bsc")
    if not out.exists():
        subprocess.run([str(BUILD / "bspc"), scene, "-o", str(out)], check=True, capture_output=True)
    return out


def render_json(scene, view, *extra, render=RENDER):
    out = subprocess.run([str(render), str(scene), "--at", view["at"], "--angle", view["angle"], *extra],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def instructions(scene, view, mode, repeat, render=RENDER):
    """Instructions callgrind counts for one run of `render` (a build/render binary)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cg.out"
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(render), str(scene),
                        "--at", view["at"], "--angle", view["angle"], "--mode", mode, "--repeat", str(repeat)],
                       check=True, capture_output=True, text=True)
        for line in out.read_text().splitlines():
            m = re.match(r"^(?:summary|totals): (\d+)", line)
            if m:
                return int(m.group(1))
    raise RuntimeError("no callgrind summary")


def main():
    views = json.loads((ROOT / "tests/bench_views.json").read_text())["views"]
    bench_dir = BUILD / "bench"
    bench_dir.mkdir(parents=True, exist_ok=True)
    rows, per_mode = [], {m: [] for m in MODES}
    for i, view in enumerate(views, 1):
        scene = compiled(view["scene"], bench_dir)
        row = {"view": f"{view['scene']} @ {view['at']} {view['angle']}°"}
        for mode in MODES:
            ir = (instructions(scene, view, mode, 3) - instructions(scene, view, mode, 1)) // 2
            j = render_json(scene, view, "--mode", mode)
            row[mode] = {"ir": ir, "overdraw": j["overdraw"], "vram": {}, "bus": {}}
            for p in PRESENTS:
                jp = render_json(scene, view, "--mode", mode, "--present", p)
                row[mode]["vram"][p] = jp["vram_writes"]
                row[mode]["bus"][p] = jp["bus_cycles"]
            per_mode[mode].append(ir)
        rows.append(row)
        print(f"bench: {i}/{len(views)} {row['view']}: spans {row['spans']['ir']:,} / painter "
              f"{row['painter']['ir']:,} instructions per frame", file=sys.stderr, flush=True)

    lines = ["| view | spans Ir/frame | painter Ir/frame | painter overdraw | spans VRAM writes flip / copy8 / copy32 "
             "| spans bus cycles flip / copy8 / copy32 |", "|---|---|---|---|---|---|"]
    for r in rows:
        s, p = r["spans"], r["painter"]
        lines.append(f"| {r['view']} | {s['ir']:,} | {p['ir']:,} | {p['overdraw']:.3f} | "
                     f"{s['vram']['flip']:,} / {s['vram']['copy8']:,} / {s['vram']['copy32']:,} | "
                     f"{s['bus']['flip']:,} / {s['bus']['copy8']:,} / {s['bus']['copy32']:,} |")
    spans_od = {r["spans"]["overdraw"] for r in rows}
    summary = [
        "",
        f"Views: {len(rows)}. Median instructions per frame (x86-64, callgrind): spans "
        f"{int(statistics.median(per_mode['spans'])):,}, painter {int(statistics.median(per_mode['painter'])):,}; "
        f"spans overdraw on every view: {', '.join(f'{o:.3f}' for o in sorted(spans_od))}; painter median overdraw "
        f"{statistics.median(r['painter']['overdraw'] for r in rows):.3f}.",
    ]
    text = "\n".join(lines + summary) + "\n"
    (BUILD / "bench.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
