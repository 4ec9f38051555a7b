#!/usr/bin/env python3
"""How the open views of tests/bench_views.json beyond the three issue 16 names were picked:
the most expensive of a deterministic sample of random in-map views.

For every map of freedoom1.wad and freedoom2.wad, --per-map views are drawn with random.Random(seed
+ map index): a point within the map's bounds that lies in a sector (tools/refrender.py's
sector_at) whose ceiling is at least 8 units above the eye (floor + 41), and a random angle. Every
view is rendered natively (build/render --no-objects --mode spans, the world alone) and ranked by
the edges it put on the edge lists; the --callgrind best of them are measured with callgrind
((Ir of --repeat 3 - Ir of --repeat 1) / 2) and printed, most expensive first, one map at most once.

Prints JSON entries for tests/bench_views.json's "open" list; it changes no file.
"""
import argparse
import json
import random
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench  # noqa: E402
import refrender  # noqa: E402

MAPS = [f"freedoom1.wad:E{e}M{m}" for e in range(1, 5) for m in range(1, 10)] + \
       [f"freedoom2.wad:MAP{m:02d}" for m in range(1, 33)]


def sample(spec, rng, n):
    m = refrender.load(spec)
    xs = list(m.x1) + list(m.x2)
    ys = list(m.y1) + list(m.y2)
    out, tries = [], 0
    while len(out) < n and tries < 200 * n:
        tries += 1
        x, y = rng.uniform(min(xs), max(xs)), rng.uniform(min(ys), max(ys))
        s = refrender.sector_at(m, x, y)
        if s is None or m.ceil[s] - (m.floor[s] + refrender.EYE_HEIGHT) < 8:
            continue
        out.append({"scene": spec, "at": f"{x:.2f},{y:.2f}", "angle": f"{rng.uniform(0, 360):.2f}"})
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--per-map", type=int, default=24)
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--callgrind", type=int, default=12)
    ap.add_argument("--show", type=int, default=6)
    opt = ap.parse_args()
    bench_dir = bench.BUILD / "bench"
    bench_dir.mkdir(parents=True, exist_ok=True)
    ranked = []
    for i, spec in enumerate(MAPS):
        try:
            views = sample(spec, random.Random(opt.seed + i), opt.per_map)
            scene = bench.compiled(spec, bench_dir)
        except (OSError, ValueError, subprocess.CalledProcessError) as e:
            print(f"bench_open: {spec}: left out ({e})", file=sys.stderr)
            continue
        for v in views:
            j = bench.render_json(scene, v, "--no-objects", "--mode", "spans")
            ranked.append((j["edges"], v))
        print(f"bench_open: {spec}: {len(views)} views, most edges {max((e for e, w in ranked if w['scene'] == spec), default=0)}",
              file=sys.stderr, flush=True)
    ranked.sort(key=lambda t: -t[0])
    measured = []
    for edges, v in ranked[:opt.callgrind]:
        scene = bench.compiled(v["scene"], bench_dir)
        ir = (bench.instructions(scene, v, "spans", 3, "--no-objects") -
              bench.instructions(scene, v, "spans", 1, "--no-objects")) // 2
        measured.append((ir, edges, v))
        print(f"bench_open: {v['scene']} @ {v['at']} {v['angle']}: {edges} edges, {ir:,} instructions per frame",
              file=sys.stderr, flush=True)
    measured.sort(key=lambda t: -t[0])
    seen, out = set(), []
    for ir, edges, v in measured:
        if v["scene"] in seen:
            continue
        seen.add(v["scene"])
        out.append(dict(v, note=f"random in-map view (tools/bench_open.py --seed {opt.seed} --per-map {opt.per_map}): "
                                f"{ir:,} instructions per frame, spans, world alone, when picked"))
    print(json.dumps(out[:opt.show], indent=1))


if __name__ == "__main__":
    main()
