#!/usr/bin/env python3
"""Instructions per frame on the Cortex-M3 (QEMU mps2-an385) for the bench and open views.

For each view of tests/bench_views.json (bench views and open views): build the firmware with the
view's scene built in (make firmware SCENE=... FULL=1 ARM_OUT=build/bench-m3/NAME, objects shared),
and for every render mode (tools/bench.py's render_modes: those build/render takes, which the
firmware's --mode parses with the same table) run it under qemu-system-arm at the fixed view
(--at, --angle; --frames N+1 --no-stream --no-tick), the world alone (--no-objects) and with
things, with the instruction-counting plugin (build/insn_count.so). A frame's count is the
instructions between the firmware's frame markers: one frame's input, render, present and
frame-done hook (the work build/render's --repeat difference measures in make bench). The first
frame is left out and the median of the other N taken (identical frames give identical counts).

Stages: the plugin's profile= gives the instructions run at each address inside the frames,
which tools/bench_profile.py names with arm-none-eabi-addr2line and groups as on x86-64; the
Cortex-M3 has no divide of 64-bit numbers, so libgcc's (__aeabi_ldivmod, __aeabi_uldivmod and
what they call) is a stage of its own there (arithmetic helpers). The profile covers every frame
of the run, the first too.

Frames per second are what a count implies at 48 MHz if the core retired one instruction per
cycle: an assumption - a real Cortex-M3 spends extra cycles on taken branches, wait states and
multi-cycle multiplies and divides, so real rates are lower by a factor that depends on the part.

Prints the Markdown tables, writes them to build/bench-m3.md, the figures to build/bench-m3.json,
and its section of docs/benchmarks.md. A benchmark, not a test: it asserts nothing about speed.
"""
import argparse
import collections
import concurrent.futures
import datetime
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
BUILD = ROOT / "build"
sys.path.insert(0, str(ROOT / "tools"))
import armelf  # noqa: E402
import bench  # noqa: E402
import bench_doc  # noqa: E402
import bench_profile  # noqa: E402

ADDR2LINE = "arm-none-eabi-addr2line"


def make(*args):
    proc = subprocess.run(["make", "-s", "--no-print-directory", *args], cwd=ROOT, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"bench_m3: make {' '.join(args)} failed:\n{proc.stdout}{proc.stderr}")


def symbol(elf, name):
    try:
        return armelf.symbol(elf, name)
    except LookupError as e:
        sys.exit(f"bench_m3: {e}")


def count(elf, args, out, profile=None):
    """Per-frame instruction counts of one QEMU run, and with profile {address: runs in frames}."""
    plugin = (f"{BUILD / 'insn_count.so'},begin={symbol(elf, 'fw_mark_frame_begin'):#x},"
              f"end={symbol(elf, 'fw_mark_frame_end'):#x},out={out}" + (f",profile={profile}" if profile else ""))
    cmd = ["qemu-system-arm", "-M", "mps2-an385", "-nographic", "-monitor", "none", "-serial", "null",
           "-semihosting-config", "enable=on,target=native", "-kernel", str(elf), "-plugin", plugin,
           "-append", " ".join(args)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        sys.exit(f"bench_m3: {' '.join(cmd)} exited {proc.returncode}:\n{proc.stderr}")
    rows = [line.split() for line in Path(out).read_text().splitlines() if not line.startswith("#")]
    runs = {}
    if profile:
        for line in Path(profile).read_text().splitlines():
            if not line.startswith("#"):
                a, n = line.split()
                runs[int(a, 16)] = runs.get(int(a, 16), 0) + int(n)
    return [int(r[1]) for r in rows], runs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--views", default=str(bench.VIEWS_FILE), help="views file (bench and open lists)")
    ap.add_argument("--frames", type=int, default=2, metavar="N", help="frames counted after the first (default 2)")
    ap.add_argument("--first", type=int, default=0, metavar="K", help="only the first K views")
    ap.add_argument("-j", "--jobs", type=int, default=2, help="QEMU runs at once (default 2)")
    ap.add_argument("--out", default=str(BUILD / "bench-m3.md"))
    opt = ap.parse_args()
    started, t0 = datetime.datetime.now().astimezone(), time.time()

    data = json.loads(Path(opt.views).read_text())
    views = [dict(v, set="bench") for v in data["views"]] + [dict(v, set="open") for v in data.get("open", [])]
    if opt.first:
        views = views[:opt.first]
    modes = bench.render_modes()
    print(f"bench_m3: modes {', '.join(modes)} (from build/render --help)", file=sys.stderr, flush=True)
    make("insn-plugin")
    obj = BUILD / "bench-m3" / "obj"
    elves = {}
    for v in views:
        name = v["scene"].replace(":", "_").replace("/", "_")
        if name not in elves:
            out_dir = BUILD / "bench-m3" / name
            make("firmware", f"SCENE={v['scene']}", f"ARM_OUT={out_dir}", f"ARM_OBJ={obj}", "STREAM=raw", "FULL=1",
                 "FW_MODES=direct,spans,painter,columns", "RAM_BYTES=16777216")
            elves[name] = out_dir / "firmware.elf"

    tasks = [(i, m, w) for i in range(len(views)) for m in modes for w in ("world", "things", "flat")]

    def one(task):
        i, m, w = task
        v = views[i]
        elf = elves[v["scene"].replace(":", "_").replace("/", "_")]
        tag = f"{i}_{m}_{w}"
        args = ["--at", v["at"], "--angle", v["angle"], "--mode", m, "--frames", str(opt.frames + 1),
                "--no-stream", "--no-tick"] + (["--look", str(v["look"])] if v.get("look") else []) + \
               (["--no-objects"] if w in ("world", "flat") else []) + (["--flat"] if w == "flat" else [])
        counts, runs = count(elf, args, elf.parent / f"insns_{tag}.txt", elf.parent / f"profile_{tag}.txt")
        per_frame = statistics.median(counts[1:]) if len(counts) > 1 else counts[0]
        frames = len(counts)
        prof = bench_profile.from_addresses(elf, {a: n / frames for a, n in runs.items()}, addr2line=ADDR2LINE)
        return task, (per_frame, prof, counts)

    res, t1 = {}, time.time()
    with concurrent.futures.ThreadPoolExecutor(max_workers=opt.jobs) as pool:
        for (task, r) in pool.map(one, tasks):
            res[task] = r
            i, m, w = task
            print(f"bench_m3: [{len(res)}/{len(tasks)} {time.time() - t1:.0f} s] {bench.view_name(views[i])} {m} {w}: "
                  f"{r[0]:,.0f} instructions per frame", file=sys.stderr, flush=True)

    sum_lines, stats = bench.summary_table(views, modes, res)
    shares, sums = bench.stage_shares(views, modes, res)
    top_lines, unclassified = bench.top_functions(modes, sums, views)
    flat_lines, flat_stats = bench.flat_table(views, modes, res)
    elapsed = time.time() - t0
    n_bench = sum(v["set"] == "bench" for v in views)
    fps = "; ".join(f"{m}: median {48e6 / stats[m]['things']['median']:.1f} fps, slowest view "
                    f"{48e6 / stats[m]['things']['max']:.1f} fps" for m in modes)
    text = "\n".join([
        "### Instructions per frame, Cortex-M3",
        "",
        f"{len(views)} views: {n_bench} bench views and {len(views) - n_bench} open views (tests/bench_views.json). "
        f"Firmware built with FULL=1 (every feature) and each view's scene built in; QEMU mps2-an385 with "
        f"build/insn_count.so, instructions between the firmware's frame markers, median of frames 2 to "
        f"{opt.frames + 1} (--frames {opt.frames + 1} --no-stream --no-tick); world alone is --no-objects. "
        f"p95: nearest rank. Modes: {', '.join(modes)}.",
        "",
        *sum_lines,
        "",
        "Textured against flat (--flat, the same scene in its flat colours), world alone:",
        "",
        *flat_lines,
        "",
        f"At 48 MHz and one instruction per cycle (an upper bound on a real part), with things: {fps}.",
        "",
        "### Stages of the frame, Cortex-M3",
        "",
        "As on x86-64: the mean over the views of each stage's share, in brackets its share of all views' frames "
        "summed; from the plugin's instructions per address (profile=), named by arm-none-eabi-addr2line. "
        "Arithmetic helpers here are mostly libgcc's 64-bit divide.",
        "",
        *bench.stage_table(modes, shares),
        "",
        *top_lines,
        "",
        ("Functions in no stage's list (counted as other): " + "; ".join(unclassified) + "."
         if unclassified else "Every function with instructions is in a stage's list."),
        "",
        "### Per view, Cortex-M3 (instructions per frame)",
        "",
        *bench.view_table(views, modes, res),
        "",
        f"Run: {started:%Y-%m-%d %H:%M %Z}, {elapsed / 60:.1f} minutes ({opt.jobs} QEMU runs at once).",
    ]) + "\n"
    print(text)
    Path(opt.out).write_text(text)
    figures = {"date": started.isoformat(timespec="seconds"), "seconds": round(elapsed), "modes": modes,
               "stats": stats, "textured_vs_flat": flat_stats,
               "stages": {f"{m} {w}": {s: {"mean": a, "of_sum": b} for s, (a, b) in v.items()}
                          for (m, w), v in shares.items()},
               "views": [{"view": bench.view_name(v), "set": v["set"],
                          **{f"{m} {w}": res[(i, m, w)][0] for m in modes for w in ("world", "things")},
                          "counts": {f"{m} {w}": res[(i, m, w)][2] for m in modes for w in ("world", "things")}}
                         for i, v in enumerate(views)]}
    Path(opt.out).with_suffix(".json").write_text(json.dumps(figures, indent=1) + "\n")
    if Path(opt.out) == BUILD / "bench-m3.md":
        bench_doc.write("m3")


if __name__ == "__main__":
    main()
