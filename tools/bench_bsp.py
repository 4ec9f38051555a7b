#!/usr/bin/env python3
"""bench_bsp.py - BSP build benchmark over the 68 Freedoom maps (make bench-bsp).

Runs build/bspc --stats on every map of freedoom1.wad (E1M1..E4M9) and
freedoom2.wad (MAP01..MAP32) with each split strategy, one process per map.
Then it runs bspc --all (one process per WAD, as zdbsp and glbsp run), bspc
--all -j JOBS (that many maps at once) and zdbsp, --repeat times each in
turns, and glbsp once, when they are installed. It reads the nodes shipped
inside the Freedoom WADs and prints one table of totals: splits, leaves
(subsectors), max depth and build time (wall clock and the processes' user +
system time; for the runs in turns, the medians). A second table times bspc
on three generated scenes that once took seconds (a grid of 3,600 sectors, a
room with a 10,000-wall zigzag side, a convex 10,000-gon room). The tables go
to stdout and to build/bench-bsp.md.

For the other builders the figures come from the lumps they write:
splits = SEGS - linedef sides, leaves = SSECTORS, depth from NODES.
Python 3 standard library only.
"""
import argparse
import json
import math
import os
import resource
import shutil
import struct
import subprocess
import sys
import tempfile
import time

WADS = ("freedoom1.wad", "freedoom2.wad")
WAD_DIRS = (os.environ.get("DOOMWADDIR", ""), "/usr/share/games/doom")
MAP_LUMPS = {"THINGS", "LINEDEFS", "SIDEDEFS", "VERTEXES", "SEGS", "SSECTORS", "NODES",
             "SECTORS", "REJECT", "BLOCKMAP", "BEHAVIOR", "SCRIPTS"}


def find_wad(name):
    for d in WAD_DIRS:
        if d and os.path.isfile(os.path.join(d, name)):
            return os.path.join(d, name)
    return None


def is_map_name(n):
    return (len(n) == 4 and n[0] == "E" and n[2] == "M" and n[1].isdigit() and n[3].isdigit()) or \
           (len(n) == 5 and n.startswith("MAP") and n[3:].isdigit())


def read_wad(path):
    """{map name: {lump name: bytes}} in file order."""
    with open(path, "rb") as f:
        data = f.read()
    magic, n, ofs = struct.unpack_from("<4sII", data, 0)
    if magic not in (b"IWAD", b"PWAD"):
        raise ValueError(f"{path}: not a WAD")
    maps, cur = {}, None
    for i in range(n):
        pos, size, name = struct.unpack_from("<II8s", data, ofs + 16 * i)
        name = name.split(b"\0")[0].decode("ascii", "replace").upper()
        if is_map_name(name):
            cur = maps.setdefault(name, {})
        elif cur is not None and name in MAP_LUMPS:
            cur[name] = data[pos:pos + size]
        else:
            cur = None
    return maps


def sides_of(lumps, skip_zero_length=False):
    """linedef sides of a map (bspc skips zero-length linedefs, so it may ask to)"""
    ld, vx = lumps["LINEDEFS"], lumps["VERTEXES"]
    sides = 0
    for i in range(len(ld) // 14):
        v1, v2 = struct.unpack_from("<HH", ld, 14 * i)
        s0, s1 = struct.unpack_from("<HH", ld, 14 * i + 10)
        if skip_zero_length and 4 * max(v1, v2) + 4 <= len(vx) and \
                vx[4 * v1:4 * v1 + 4] == vx[4 * v2:4 * v2 + 4]:
            continue
        sides += (s0 != 0xFFFF) + (s1 != 0xFFFF)
    return sides


def node_figures(lumps):
    """(segs, leaves, max depth) of a map's NODES/SSECTORS/SEGS, classic or ZDBSP XNOD."""
    nodes_lump = lumps.get("NODES", b"")
    if nodes_lump[:4] == b"XNOD":
        d, p = nodes_lump, 4
        orgv, newv = struct.unpack_from("<II", d, p)
        p += 8 + 8 * newv
        (nss,) = struct.unpack_from("<I", d, p)
        p += 4 + 4 * nss
        (nsegs,) = struct.unpack_from("<I", d, p)
        p += 4 + 11 * nsegs
        (nn,) = struct.unpack_from("<I", d, p)
        p += 4
        children = []
        for i in range(nn):
            c0, c1 = struct.unpack_from("<II", d, p + 20)
            children.append((c0, c1))
            p += 28
        leafbit = 0x80000000
    else:
        nsegs = len(lumps.get("SEGS", b"")) // 12
        nss = len(lumps.get("SSECTORS", b"")) // 4
        nn = len(nodes_lump) // 28
        children = [struct.unpack_from("<HH", nodes_lump, 28 * i + 24) for i in range(nn)]
        leafbit = 0x8000
    depth = 0
    if nn:
        stack = [(nn - 1, 1)]
        while stack:
            n, d = stack.pop()
            depth = max(depth, d)
            for c in children[n]:
                if not c & leafbit and c < nn:
                    stack.append((c, d + 1))
    return nsegs, nss, depth


def wad_totals(maps_by_wad, built_paths):
    tot = {"maps": 0, "splits": 0, "segs": 0, "leaves": 0, "max_depth": 0}
    for wadname, maps in maps_by_wad.items():
        out = read_wad(built_paths[wadname]) if built_paths else maps
        for m, lumps in maps.items():
            segs, leaves, depth = node_figures(out[m])
            tot["maps"] += 1
            tot["splits"] += segs - sides_of(lumps)
            tot["segs"] += segs
            tot["leaves"] += leaves
            tot["max_depth"] = max(tot["max_depth"], depth)
    return tot


def bspc_totals():
    return {"maps": 0, "splits": 0, "tjunc": 0, "segs": 0, "leaves": 0, "max_depth": 0,
            "build_ms": 0.0, "failed": []}


def add_stats(tot, st, lumps):
    tot["maps"] += 1
    tot["splits"] += st["splits"]
    tot["segs"] += st["segs"]
    tot["tjunc"] += st["segs"] - st["splits"] - sides_of(lumps, True)
    tot["leaves"] += st["leaves"]
    tot["max_depth"] = max(tot["max_depth"], st["max_depth"])
    tot["build_ms"] += st["build_ms"]


def run_bspc(bspc, wads, maps_by_wad, strategy, tmp):
    """bspc on each map, one process per map"""
    tot = bspc_totals()
    out = os.path.join(tmp, "out.bsc")
    c0, t0 = children_cpu(), time.perf_counter()
    for wadname, maps in maps_by_wad.items():
        for m, lumps in maps.items():
            spec = f"{wads[wadname]}:{m}"
            r = subprocess.run([bspc, spec, "--split", strategy, "--stats", "-o", out],
                               capture_output=True, text=True)
            if r.returncode != 0:
                tot["failed"].append(f"{wadname}:{m}: {r.stderr.strip()}")
                continue
            add_stats(tot, json.loads(r.stdout), lumps)
    tot["wall_s"], tot["cpu_s"] = time.perf_counter() - t0, children_cpu() - c0
    return tot


def run_bspc_all(bspc, wads, maps_by_wad, strategy, tmp, jobs=1):
    """bspc --all -j jobs on each WAD, one process per WAD"""
    tot = bspc_totals()
    outdir = os.path.join(tmp, f"all{jobs}")
    os.makedirs(outdir, exist_ok=True)
    c0, t0 = children_cpu(), time.perf_counter()
    for wadname, maps in maps_by_wad.items():
        r = subprocess.run([bspc, wads[wadname], "--all", "-j", str(jobs), "--split", strategy, "--stats",
                            "-o", outdir], capture_output=True, text=True)
        if r.returncode != 0:
            tot["failed"].append(f"{wadname}: {r.stderr.strip()[-200:]}")
        for line in r.stdout.splitlines():
            st = json.loads(line)
            add_stats(tot, st, maps[st["map"]])
    tot["wall_s"], tot["cpu_s"] = time.perf_counter() - t0, children_cpu() - c0
    return tot


def run_external(cmd_for, wads, tmp, label):
    """another builder on each WAD: (the WADs it wrote or None, wall s, cpu s)"""
    built = {}
    c0, t0 = children_cpu(), time.perf_counter()
    for wadname, path in wads.items():
        outp = os.path.join(tmp, f"{label}-{wadname}")
        r = subprocess.run(cmd_for(path, outp), capture_output=True, text=True)
        if r.returncode != 0 or not os.path.isfile(outp):
            print(f"bench-bsp: {label} failed on {wadname}: {r.stderr.strip()[:200]}",
                  file=sys.stderr)
            return None, time.perf_counter() - t0, children_cpu() - c0
        built[wadname] = outp
    return built, time.perf_counter() - t0, children_cpu() - c0


def median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2] if len(xs) % 2 else (xs[len(xs) // 2 - 1] + xs[len(xs) // 2]) / 2


# ---- generated scenes (text format, docs/scene-format.md) --------------------

def grid_scene(n=60, cell=64):
    """n x n square sectors of differing floors and ceilings, each wall between
    two of them two-sided."""
    out = [f"sector c{i}_{j} floor={((i * 7 + j * 3) % 5) * 8} ceil={128 + ((i + j) % 3) * 16}"
           for j in range(n) for i in range(n)]
    o = -n * cell // 2

    def at(k):
        return o + k * cell
    for j in range(n):  # walls along x = at(i); the front (right) side is east going north
        for i in range(n + 1):
            x, y0, y1 = at(i), at(j), at(j + 1)
            if i == 0:
                out.append(f"wall {x} {y0} {x} {y1} c0_{j}")
            elif i == n:
                out.append(f"wall {x} {y1} {x} {y0} c{n - 1}_{j}")
            else:
                out.append(f"wall {x} {y0} {x} {y1} c{i}_{j} c{i - 1}_{j}")
    for i in range(n):  # walls along y = at(j); the front side is north going west
        for j in range(n + 1):
            y, x0, x1 = at(j), at(i), at(i + 1)
            if j == 0:
                out.append(f"wall {x1} {y} {x0} {y} c{i}_0")
            elif j == n:
                out.append(f"wall {x0} {y} {x1} {y} c{i}_{n - 1}")
            else:
                out.append(f"wall {x1} {y} {x0} {y} c{i}_{j} c{i}_{j - 1}")
    out.append(f"player {o + cell // 2} {o + cell // 2} 0")
    return "\n".join(out) + "\n"


def zigzag_scene(walls=10000, step=6, amp=16):
    """One room whose south side is a zigzag of walls - 3 walls (teeth step
    units wide, amp deep), closed by three straight walls."""
    k = walls - 3
    x0 = -k * step // 2
    pts = [(x0 + i * step, 0 if i % 2 == 0 else amp) for i in range(k + 1)][::-1]
    out = ["sector room floor=0 ceil=128"]
    out += [f"wall {a[0]} {a[1]} {b[0]} {b[1]} room" for a, b in zip(pts, pts[1:])]
    w, e, top = pts[-1][0], pts[0][0], 512
    out += [f"wall {w} {pts[-1][1]} {w} {top} room", f"wall {w} {top} {e} {top} room",
            f"wall {e} {top} {e} {pts[0][1]} room", "player 0 256 90"]
    return "\n".join(out) + "\n"


def ngon_scene(n=10000, r=30000):
    """A convex room of n walls (a regular n-gon, vertices on 1/10000 units)."""
    p = [(r * math.cos(-2 * math.pi * i / n), r * math.sin(-2 * math.pi * i / n)) for i in range(n)]
    out = ["sector room floor=0 ceil=128"]
    out += [f"wall {p[i][0]:.4f} {p[i][1]:.4f} {p[(i + 1) % n][0]:.4f} {p[(i + 1) % n][1]:.4f} room"
            for i in range(n)]
    out.append("player 0 0 0")
    return "\n".join(out) + "\n"


GENERATED = (("grid of 3,600 sectors", "grid.scene", grid_scene),
             ("zigzag of 10,000 walls", "zigzag.scene", zigzag_scene),
             ("convex 10,000-gon", "ngon.scene", ngon_scene))


def children_cpu():
    """user + system seconds of the finished child processes"""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_generated(bspc, tmp):
    """One row per generated scene: walls, outcome, figures, wall time."""
    rows = []
    for label, fname, make in GENERATED:
        path = os.path.join(tmp, fname)
        with open(path, "w") as f:
            f.write(make())
        c0, t0 = children_cpu(), time.perf_counter()
        r = subprocess.run([bspc, path, "--stats", "-o", os.path.join(tmp, "gen.bsc")],
                           capture_output=True, text=True)
        times = (f"{time.perf_counter() - t0:.2f}", f"{children_cpu() - c0:.2f}")
        if r.returncode == 0:
            st = json.loads(r.stdout)
            rows.append((label, st["input_walls"], "compiled", st["splits"], st["leaves"],
                         st["max_depth"], *times))
        else:
            msg = r.stderr.strip().splitlines()[-1] if r.stderr.strip() else "failed"
            rows.append((label, "-", "refused: " + msg.replace(path, fname), "-", "-", "-", *times))
    return rows


def table(head, rows):
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(f"{v:,}" if isinstance(v, int) else str(v) for v in r) + " |")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bspc", default="build/bspc")
    ap.add_argument("--out", default="build/bench-bsp.md")
    ap.add_argument("--strategies", default="fewest,balanced,mixed")
    ap.add_argument("--repeat", type=int, default=3,
                    help="runs of bspc --all and zdbsp, taking turns; their medians are shown")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                    help="bspc --all -j JOBS gets a row too when above 1 (default: the processors)")
    args = ap.parse_args()
    if args.repeat < 1 or args.jobs < 1:
        ap.error("--repeat and --jobs must be at least 1")

    wads = {w: find_wad(w) for w in WADS}
    missing = [w for w, p in wads.items() if not p]
    if missing:
        print(f"bench-bsp: {', '.join(missing)} not found (apt-get install freedoom)", file=sys.stderr)
        return 1
    if not os.access(args.bspc, os.X_OK):
        print(f"bench-bsp: {args.bspc} not built", file=sys.stderr)
        return 1
    maps_by_wad = {w: read_wad(p) for w, p in wads.items()}
    nmaps = sum(len(m) for m in maps_by_wad.values())

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for s in args.strategies.split(","):
            t = run_bspc(args.bspc, wads, maps_by_wad, s, tmp)
            note = f"build + blob {t['build_ms'] / 1000:.2f} s"
            if t["failed"]:
                note += f"; {len(t['failed'])} map(s) failed: " + "; ".join(t["failed"][:3])
            rows.append((f"bspc --split {s}", t["maps"], t["splits"], t["tjunc"], t["segs"],
                         t["leaves"], t["max_depth"], f"{t['wall_s']:.2f}", f"{t['cpu_s']:.2f}",
                         "one process per map; " + note))
        # the whole-WAD runs, in turns, so that a busy moment weighs on both alike
        zd = shutil.which("zdbsp")
        walls = {"all": [], "allj": [], "zdbsp": []}
        cpus = {"all": [], "allj": [], "zdbsp": []}
        built = None
        for _ in range(args.repeat):
            if args.jobs > 1:
                tj = run_bspc_all(args.bspc, wads, maps_by_wad, "mixed", tmp, args.jobs)
                walls["allj"].append(tj["wall_s"])
                cpus["allj"].append(tj["cpu_s"])
            t = run_bspc_all(args.bspc, wads, maps_by_wad, "mixed", tmp)
            walls["all"].append(t["wall_s"])
            cpus["all"].append(t["cpu_s"])
            if zd:
                built, wall, cpu = run_external(lambda i, o: ["zdbsp", "-o", o, i], wads, tmp, "zdbsp")
                walls["zdbsp"].append(wall)
                cpus["zdbsp"].append(cpu)
        note = f"one process per WAD, median of {args.repeat}"
        if t["failed"]:
            note += f"; {len(t['failed'])} failed: " + "; ".join(t["failed"][:2])
        rows.append(("bspc --all (mixed)", t["maps"], t["splits"], t["tjunc"], t["segs"], t["leaves"],
                     t["max_depth"], f"{median(walls['all']):.2f}", f"{median(cpus['all']):.2f}", note))
        if args.jobs > 1:
            rows.append((f"bspc --all -j {args.jobs} (mixed)", tj["maps"], tj["splits"], tj["tjunc"], tj["segs"],
                         tj["leaves"], tj["max_depth"], f"{median(walls['allj']):.2f}",
                         f"{median(cpus['allj']):.2f}", f"{args.jobs} maps at once; " + note))
        if built:
            z = wad_totals(maps_by_wad, built)
            rows.append(("zdbsp (defaults)", z["maps"], z["splits"], "-", z["segs"], z["leaves"],
                         z["max_depth"], f"{median(walls['zdbsp']):.2f}", f"{median(cpus['zdbsp']):.2f}",
                         f"one process per WAD, median of {args.repeat}; with blockmap and reject"))
        if shutil.which("glbsp"):
            built, wall, cpu = run_external(lambda i, o: ["glbsp", "-q", "-n", i, "-o", o], wads, tmp,
                                            "glbsp")
            if built:
                t = wad_totals(maps_by_wad, built)
                rows.append(("glbsp -n (normal nodes)", t["maps"], t["splits"], "-", t["segs"],
                             t["leaves"], t["max_depth"], f"{wall:.2f}", f"{cpu:.2f}",
                             "one process per WAD; also builds GL nodes"))
        t = wad_totals(maps_by_wad, None)
        rows.append(("nodes shipped in Freedoom", t["maps"], t["splits"], "-", t["segs"],
                     t["leaves"], t["max_depth"], "-", "-", "read from the WADs"))
        gen_rows = run_generated(args.bspc, tmp)

    head = ("builder", "maps", "splits", "T-junction splits", "segs", "leaves", "max depth",
            "time (s)", "cpu (s)", "notes")
    lines = [f"# BSP build over the {nmaps} Freedoom maps", "",
             "splits: segs cut by partitions (for the other builders: segs - linedef sides). "
             "bspc also splits segs at T-junctions (vertices on a seg's interior, and split "
             "points made on one side of a two-sided line), counted apart; the others do not. "
             "time: wall clock, process start and WAD reading included; cpu: the processes' "
             "user + system time.", "",
             *table(head, rows), "", "## Generated scenes", "",
             "bspc (default strategy, one process each) on scenes made by tools/bench_bsp.py. "
             "time: wall clock; cpu: user + system time of the bspc process.", "",
             *table(("scene", "walls", "outcome", "splits", "leaves", "max depth", "time (s)",
                     "cpu (s)"),
                    gen_rows)]
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    with open(args.out, "w") as f:
        f.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
