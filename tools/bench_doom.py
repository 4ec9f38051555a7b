#!/usr/bin/env python3
"""bench_doom.py - make bench-doom: Chocolate Doom's instructions per frame beside build/render's,
at the same player starts (callgrind, x86-64).

Chocolate Doom (Debian's chocolate-doom) plays a demo that stands still at a map's player start
(tools/doomcompare.py writes it: skill 3, unturned, as the demo sees the start) with -timedemo,
under callgrind, four times: two demo lengths, each with -noblit (drawn, not shown) and with
-nodraw (not drawn). For a length L the drawing costs noblit(L) - nodraw(L): what start-up, level
load and the game's tics cost cancels out. Two lengths take out the screen melt, which runs once
before the first tic: the cost of one frame is
    ((noblit(L2) - nodraw(L2)) - (noblit(L1) - nodraw(L1))) / (L2 - L1).
The screen is 320x200 with screenblocks 11 (the whole screen is the view, no status bar) and high
detail. Doom's frame includes its sprites (the things) and the player's weapon.

build/render draws the same start (no --at: the player start with Doom's eye height), in its
default mode unless --mode says, textured, with things and world alone (--no-objects): (Ir of
--repeat N+1 - Ir of --repeat 1) / N, the scene compiled beforehand (tools/bench.py).

Prints a Markdown table, writes it to build/bench-doom.md and the figures to build/bench-doom.json,
and puts the table in docs/benchmarks.md (section doom, tools/bench_doc.py). A benchmark, not a
test: it asserts nothing.
"""
import argparse
import concurrent.futures
import datetime
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench  # noqa: E402
import bench_doc  # noqa: E402
import doomcompare  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
# the 20 bench maps (tests/bench_views.json) and five more the issue names: big, open starts
EXTRA_MAPS = ("freedoom2.wad:MAP12", "freedoom1.wad:E3M7", "freedoom2.wad:MAP15", "freedoom2.wad:MAP29",
              "freedoom1.wad:E3M3")
DEMO_TICS = (10, 30)
TIMEOUT = 600


def start_maps():
    """The maps whose player starts are measured: the bench views' maps, then EXTRA_MAPS."""
    maps = [v["scene"] for v in bench.load_views() if v["set"] == "bench"]
    return list(dict.fromkeys(maps + list(EXTRA_MAPS)))


def callgrind_total(cmd, cwd=None, env=None, timeout=TIMEOUT):
    """Instructions callgrind counts for one run of cmd (any exit status: -timedemo ends with an error)."""
    with tempfile.TemporaryDirectory(prefix="bench-doom-") as tmp:
        out = Path(tmp) / "cg.out"
        proc = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *cmd], cwd=cwd,
                              env=env, capture_output=True, text=True, timeout=timeout)
        if not out.exists():
            raise RuntimeError(f"callgrind wrote nothing for {' '.join(cmd)}:\n{proc.stderr[-600:]}")
        for line in out.read_text().splitlines():
            m = re.match(r"^(?:summary|totals): (\d+)", line)
            if m:
                return int(m.group(1)), proc.stdout + proc.stderr
    raise RuntimeError(f"no callgrind summary for {' '.join(cmd)}")


def chocolate_run(wad, mapname, tics, how):
    """Instructions of one chocolate-doom -timedemo run of a standing-still demo; how: noblit or nodraw."""
    episode, mapnum = doomcompare.map_numbers(mapname)
    with tempfile.TemporaryDirectory(prefix="bench-doom-") as tmp:
        t = Path(tmp)
        (t / "stand.lmp").write_bytes(doomcompare.demo_lump(episode, mapnum, tics))
        (t / "default.cfg").write_text(doomcompare.GAME_CFG + "detaillevel 0\n")
        (t / "chocolate-doom.cfg").write_text(doomcompare.VIDEO_CFG)
        env = dict(os.environ, SDL_VIDEODRIVER="dummy", SDL_AUDIODRIVER="dummy", HOME=tmp, XDG_DATA_HOME=tmp,
                   XDG_CONFIG_HOME=tmp)
        cmd = [doomcompare.find_chocolate(), "-iwad", os.path.abspath(wad), "-timedemo", "stand.lmp", f"-{how}",
               "-config", "default.cfg", "-extraconfig", "chocolate-doom.cfg", "-nosound", "-nomusic", "-nogui",
               "-nograbmouse"]
        total, log = callgrind_total(cmd, cwd=tmp, env=env)
        if f"timed {tics} gametics" not in log:
            raise RuntimeError(f"chocolate-doom did not play {mapname}'s {tics}-tic demo ({how}):\n{log[-600:]}")
        return total


def chocolate_frame(spec, run=chocolate_run):
    """Chocolate Doom's instructions per frame at SPEC's player start, and the four run totals."""
    wad, mapname = spec.rsplit(":", 1)
    wad = doomcompare.find_wad(wad)
    runs = {(n, how): run(wad, mapname, n, how) for n in DEMO_TICS for how in ("noblit", "nodraw")}
    return frame_cost(runs), runs


def frame_cost(runs):
    """Instructions of one drawn frame from the four runs {(tics, "noblit"|"nodraw"): Ir}."""
    l1, l2 = DEMO_TICS
    drawn = {n: runs[(n, "noblit")] - runs[(n, "nodraw")] for n in DEMO_TICS}
    return (drawn[l2] - drawn[l1]) / (l2 - l1)


def default_mode():
    """The mode build/render draws in when none is asked for (its JSON names it)."""
    out = subprocess.run([str(bench.RENDER), "tests/scenes/default.scene"], cwd=ROOT, capture_output=True, text=True,
                         check=True).stdout
    return json.loads(out)["mode"]


def ours_frame(spec, mode, frames, bench_dir, *extra):
    """build/render's instructions per frame at SPEC's player start (no camera given)."""
    scene = bench.compiled(spec, bench_dir)

    def ir(repeat):
        total, _ = callgrind_total([str(bench.RENDER), str(scene), "--mode", mode, "--repeat", str(repeat), *extra])
        return total

    return (ir(frames + 1) - ir(1)) / frames


def measure(maps, mode, frames, jobs, bench_dir, progress=True):
    """{spec: {"doom", "things", "world", "doom_runs"}}, jobs callgrind runs at once."""
    tasks = [(s, w) for s in maps for w in ("doom", "things", "world")]
    out = {s: {} for s in maps}
    t0 = time.time()

    def one(task):
        spec, what = task
        if what == "doom":
            cost, runs = chocolate_frame(spec)
            return task, {"doom": cost, "doom_runs": {f"{n} {h}": v for (n, h), v in runs.items()}}
        extra = ["--no-objects"] if what == "world" else []
        return task, {what: ours_frame(spec, mode, frames, bench_dir, *extra)}

    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        for done, ((spec, _), got) in enumerate(pool.map(one, tasks), 1):
            out[spec].update(got)
            if progress:
                print(f"bench-doom: {done}/{len(tasks)} ({time.time() - t0:.0f} s)", file=sys.stderr, flush=True)
    return out


def table(maps, res, mode):
    lines = [f"| start | Chocolate Doom | {mode}, with things | ratio | {mode}, world alone | ratio |",
             "|---|---:|---:|---:|---:|---:|"]
    for s in maps:
        r = res[s]
        lines.append(f"| {s} | {r['doom']:,.0f} | {r['things']:,.0f} | {r['things'] / r['doom']:.2f} | "
                     f"{r['world']:,.0f} | {r['world'] / r['doom']:.2f} |")
    return lines


def summary(maps, res):
    things = [res[s]["things"] / res[s]["doom"] for s in maps]
    world = [res[s]["world"] / res[s]["doom"] for s in maps]
    return {"starts": len(maps),
            "things_ratio": {"min": min(things), "median": statistics.median(things), "max": max(things),
                             "at_most_1": sum(r <= 1.0 for r in things)},
            "world_ratio": {"min": min(world), "median": statistics.median(world), "max": max(world),
                            "at_most_1": sum(r <= 1.0 for r in world)},
            "doom_median": statistics.median(res[s]["doom"] for s in maps),
            "things_median": statistics.median(res[s]["things"] for s in maps),
            "world_median": statistics.median(res[s]["world"] for s in maps)}


def main(argv=None):
    ap = argparse.ArgumentParser(prog="bench_doom.py", description="make bench-doom: Chocolate Doom's "
                                 "instructions per frame beside build/render's at the same player starts "
                                 "(callgrind, x86-64).")
    ap.add_argument("--mode", help="build/render's mode (default: its own default mode)")
    ap.add_argument("--frames", type=int, default=10, metavar="N",
                    help="build/render: (run of N+1 frames - run of 1) / N (default 10)")
    ap.add_argument("-j", "--jobs", type=int, default=2, help="callgrind runs at once (default 2)")
    ap.add_argument("--map", action="append", default=[], metavar="WAD:MAP",
                    help="only this map's start (repeatable; a quick look; the document is not rewritten)")
    args = ap.parse_args(argv)
    if args.frames < 1 or args.jobs < 1:
        ap.error("--frames and --jobs must be at least 1")
    if not bench.RENDER.exists():
        raise SystemExit(f"bench-doom: {bench.RENDER} is not built (make build/render)")
    doomcompare.find_chocolate()
    started, t0 = datetime.datetime.now().astimezone(), time.time()
    bench_dir = BUILD / "bench"
    bench_dir.mkdir(parents=True, exist_ok=True)
    maps = args.map or start_maps()
    if not args.mode:
        args.mode = default_mode()
    res = measure(maps, args.mode, args.frames, args.jobs, bench_dir)
    s = summary(maps, res)
    tr, wr = s["things_ratio"], s["world_ratio"]
    text = "\n".join([
        f"{len(maps)} player starts, standing and unturned as a demo sees them: the 20 bench maps "
        f"(tests/bench_views.json) and {', '.join(EXTRA_MAPS)}. Instructions per frame on x86-64 (callgrind).",
        "",
        f"Chocolate Doom: Debian's chocolate-doom, -timedemo of a demo standing still at the start, "
        f"{DEMO_TICS[0]} and {DEMO_TICS[1]} tics, each with -noblit and with -nodraw; one frame = the difference "
        f"of the (noblit - nodraw) differences over the difference in tics (start-up, level load and the screen "
        f"melt cancel out). 320x200, screenblocks 11 (the whole screen is the view), high detail. **Doom's frame "
        f"includes its sprites and the player's weapon**; it has no id buffer, counters or fixed-point exactness "
        f"checks to feed.",
        "",
        f"build/render: mode {args.mode}, textured, the same start (Doom's eye height), (Ir of --repeat "
        f"{args.frames + 1} - Ir of --repeat 1) / {args.frames}; with things (boxes, docs/objects.md) and world "
        f"alone (--no-objects). Ratio: ours over Chocolate Doom's.",
        "",
        *table(maps, res, args.mode),
        "",
        f"With things / Chocolate Doom: {tr['min']:.2f} to {tr['max']:.2f}, median **{tr['median']:.2f}**; "
        f"{tr['at_most_1']} of {len(maps)} starts at most 1.0. World alone / Chocolate Doom: {wr['min']:.2f} to "
        f"{wr['max']:.2f}, median {wr['median']:.2f}; {wr['at_most_1']} of {len(maps)} at most 1.0. Medians: "
        f"Chocolate Doom {s['doom_median']:,.0f}, ours with things {s['things_median']:,.0f}, world alone "
        f"{s['world_median']:,.0f}.",
        "",
        f"Run: {started:%Y-%m-%d %H:%M %Z}, {(time.time() - t0) / 60:.1f} minutes (callgrind, {args.jobs} at once).",
    ]) + "\n"
    (BUILD / "bench-doom.md").write_text(text)
    (BUILD / "bench-doom.json").write_text(json.dumps(
        {"date": started.isoformat(timespec="seconds"), "mode": args.mode, "demo_tics": DEMO_TICS,
         "summary": s, "starts": {m: res[m] for m in maps}}, indent=1) + "\n")
    if not args.map:
        bench_doc.write("doom")
    print(text)


if __name__ == "__main__":
    main()
