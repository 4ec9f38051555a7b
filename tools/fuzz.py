#!/usr/bin/env python3
"""make fuzz / make fuzz-smoke: run the libFuzzer harnesses (tests/fuzz/, mk/fuzz.mk).

    tools/fuzz.py [--time S] [--jobs N] [NAME ...]   each harness S seconds (default 60), N at once
    tools/fuzz.py --smoke [NAME ...]                 every seed and kept regression once, then a few
                                                     seconds of fuzzing each (part of make test)

Each harness starts from its seeds (real inputs, made afresh in build/fuzz/seeds/NAME: the
project's scenes, compiled scenes, single-map WADs cut from Freedoom, frame-link streams, DFU
images), the crashes kept as regressions (tests/fuzz/regress/NAME/) and the corpus it grew on
earlier runs (build/fuzz/corpus/NAME). A crash leaves its input in build/fuzz/crashes/NAME/ and
makes the run fail; once fixed, the input belongs in tests/fuzz/regress/NAME/. The figures
of the last run of each harness (executions, executions per second, coverage, corpus; from its
log, build/fuzz/NAME.log) go to build/fuzz/report.md."""
import argparse
import concurrent.futures
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
FUZZ = BUILD / "fuzz"
NAMES = ["text", "wad", "scene", "render", "link", "dfu"]
# Longest input each harness is given (None: libFuzzer's own choice from the seeds).
MAX_LEN = {"text": 16384, "wad": 196608, "scene": 65536, "render": 16409, "link": None, "dfu": None}
WADDIR = Path(os.environ.get("DOOMWADDIR", "/usr/share/games/doom"))
VIEW = struct.Struct("<iiiiiI")  # fuzz_common.h: fuzz_view (x, y, z, angle, look, t_ms)
MAP_LUMPS = ("THINGS", "LINEDEFS", "SIDEDEFS", "VERTEXES", "SECTORS")


def scene_texts():
    return sorted((ROOT / "tests/scenes").glob("*.scene")) + sorted((ROOT / "tests/scenes/extreme").glob("*.scene"))


def seed_text(out):
    for p in scene_texts():
        shutil.copy(p, out / p.name)


def compiled(p, tmp):
    bsc = Path(tmp) / (p.stem + ".bsc")
    r = subprocess.run([BUILD / "bspc", p, "-o", bsc], capture_output=True)
    return bsc.read_bytes() if r.returncode == 0 else None


def views():
    """Cameras (16.16) near the default scenes' player starts, inside and far outside the box."""
    one = 1 << 16
    return [VIEW.pack(0, 0, 41 * one, 0, 0, 0), VIEW.pack(128 * one, 96 * one, 60 * one, 45 * one, 20, 2500),
            VIEW.pack(-32767 * one, 32767 * one, -16383 * one, 359 * one, -100, 7000),
            VIEW.pack(300 * one + 5, -40 * one, 8 * one, 271 * one, 100, 123456)]


def seed_scene(out):
    """flags byte (bit 0: fix the CRC, bit 1: fix the length), a camera, a compiled scene."""
    with tempfile.TemporaryDirectory() as tmp:
        for i, p in enumerate(scene_texts()):
            blob = compiled(p, tmp)
            if blob:
                (out / (p.stem + ".in")).write_bytes(bytes([3]) + views()[i % 4] + blob)


def seed_render(out):
    """a camera and a time, a scene choice, a scene text (fuzz_render.c)."""
    for i, p in enumerate(scene_texts()):
        for k, v in enumerate(views()):
            (out / f"{p.stem}-{k}.in").write_bytes(v + bytes([i]) + p.read_bytes())
        (out / f"pool-{i}.in").write_bytes(views()[i % 4] + bytes([i]))


def pwad(lumps):
    body, directory, pos = b"", b"", 12
    for name, data in lumps:
        directory += struct.pack("<II8s", pos, len(data), name.encode())
        body += data
        pos += len(data)
    return b"PWAD" + struct.pack("<II", len(lumps), pos) + body + directory


def wad_maps(path, limit):
    """The `limit` smallest maps of a WAD, each as a PWAD holding just MAP01's five lumps."""
    d = path.read_bytes()
    n, off = struct.unpack_from("<II", d, 4)
    ents = [struct.unpack_from("<II8s", d, off + 16 * i) for i in range(n)]
    names = [e[2].rstrip(b"\0").decode("latin-1") for e in ents]
    maps = []
    for i, name in enumerate(names):
        if i + 1 < n and names[i + 1] == "THINGS":
            lumps = {names[j]: d[ents[j][0]:ents[j][0] + ents[j][1]] for j in range(i + 1, min(i + 11, n))}
            if all(k in lumps for k in MAP_LUMPS):
                maps.append((sum(len(lumps[k]) for k in MAP_LUMPS), name, lumps))
    for _, name, lumps in sorted(maps)[:limit]:
        yield name, pwad([("MAP01", b"")] + [(k, lumps[k]) for k in MAP_LUMPS])


def two_rooms():
    """Two rooms joined by a door sector with a step: two-sided walls, a door, heights."""
    verts = [(0, 0), (0, 256), (128, 256), (128, 0), (144, 0), (144, 256), (272, 256), (272, 0)]
    side = lambda sec: struct.pack("<hh8s8s8sH", 0, 0, b"-", b"-", b"STARTAN3", sec)
    sides, lines = [], []

    def line(a, b, front, back=None, special=0):
        sides.append(side(front))
        right = len(sides) - 1
        left = 0xFFFF
        if back is not None:
            sides.append(side(back))
            left = len(sides) - 1
        lines.append(struct.pack("<HHHHHHH", a, b, 4 if back is not None else 1, special, 0, right, left))
    line(0, 1, 0), line(1, 2, 0), line(3, 0, 0)
    line(2, 3, 0, 1, special=1)
    line(2, 5, 1), line(4, 3, 1)
    line(5, 4, 2, 1, special=1)
    line(5, 6, 2), line(6, 7, 2), line(7, 4, 2)
    sectors = [struct.pack("<hh8s8shhh", f, c, b"FLOOR4_8", b"CEIL3_5", 160, 0, 0)
               for f, c in ((0, 128), (24, 24), (24, 160))]
    things = struct.pack("<hhhHH", 64, 128, 0, 1, 7) + struct.pack("<hhhHH", 200, 128, 90, 3001, 7)
    return pwad([("MAP01", b""), ("THINGS", things), ("LINEDEFS", b"".join(lines)), ("SIDEDEFS", b"".join(sides)),
                 ("VERTEXES", b"".join(struct.pack("<hh", x, y) for x, y in verts)),
                 ("SECTORS", b"".join(sectors))])


def seed_wad(out):
    (out / "two_rooms.wad").write_bytes(two_rooms())
    for wad in ("freedoom1.wad", "freedoom2.wad"):
        if (WADDIR / wad).exists():
            for name, data in wad_maps(WADDIR / wad, 2):
                (out / f"{Path(wad).stem}-{name}.wad").write_bytes(data)


def make_seeds(name):
    out = FUZZ / "seeds" / name
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    script = ROOT / "tests/fuzz" / f"seeds_{name}.py"
    if script.exists():
        subprocess.run([sys.executable, script, out], cwd=ROOT, check=True)
    else:
        globals()[f"seed_{name}"](out)
    return out


STAT = re.compile(r"stat::(\w+):\s*(\d+)")
COV = re.compile(r"cov: (\d+) ft: (\d+) corp: (\d+)/")
DONE = re.compile(r"Done (\d+) runs in (\d+) second")
CRASH = re.compile(r"^(==\d+==ERROR|SUMMARY: |.*Test unit written to)", re.M)


def figures(name, log):
    """A run's figures, from libFuzzer's own log of it."""
    text = log.read_text(errors="replace")
    stats = {k: int(v) for k, v in STAT.findall(text)}
    cov, done = COV.findall(text), DONE.findall(text)
    return dict(name=name, log=log, execs=stats.get("number_of_executed_units", 0),
                per_sec=stats.get("average_exec_per_sec", 0), rss=stats.get("peak_rss_mb", 0),
                seconds=int(done[-1][1]) if done else 0, cov=int(cov[-1][0]) if cov else 0,
                ft=int(cov[-1][1]) if cov else 0, corpus=int(cov[-1][2]) if cov else 0,
                crashed=bool(CRASH.search(text)) or not done)


def run_harness(name, seconds, corpus, log, seeds):
    """One libFuzzer run (its output in log); returns its figures, crashed if it did not end cleanly."""
    regress = ROOT / "tests/fuzz/regress" / name
    crashes = FUZZ / "crashes" / name
    crashes.mkdir(parents=True, exist_ok=True)
    corpus.mkdir(parents=True, exist_ok=True)
    cmd = [str(FUZZ / f"fuzz_{name}"), f"-max_total_time={seconds}", "-timeout=25", "-rss_limit_mb=2560",
           "-print_final_stats=1", f"-artifact_prefix={crashes}/", str(corpus), str(seeds)]
    if MAX_LEN[name]:
        cmd.insert(1, f"-max_len={MAX_LEN[name]}")
    if regress.is_dir():
        cmd.append(str(regress))
    with tempfile.TemporaryDirectory() as tmp:
        with open(log, "w") as f:
            rc = subprocess.run(cmd, cwd=ROOT, stdout=f, stderr=subprocess.STDOUT,
                                env=dict(os.environ, TMPDIR=tmp)).returncode
    r = figures(name, log)
    r["crashed"] = r["crashed"] or rc != 0
    return r


def replay(name, seeds):
    """Every seed and regression input once (libFuzzer runs a corpus before fuzzing; -runs=0 stops there)."""
    dirs = [seeds] + [d for d in [ROOT / "tests/fuzz/regress" / name] if d.is_dir()]
    with tempfile.TemporaryDirectory() as tmp:
        r = subprocess.run([str(FUZZ / f"fuzz_{name}"), "-runs=0", *map(str, dirs)], cwd=ROOT,
                           capture_output=True, text=True, env=dict(os.environ, TMPDIR=tmp))
    if r.returncode != 0:
        sys.stderr.write(r.stderr[-4000:])
    return r.returncode == 0


def report():
    """The table of the last full run of every harness (build/fuzz/NAME.log)."""
    lines = ["| harness | seconds | executions | per second | coverage (edges) | features | corpus | peak RSS MB | crash |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name in NAMES:
        log = FUZZ / f"{name}.log"
        if log.exists():
            r = figures(name, log)
            lines.append(f"| {name} | {r['seconds']} | {r['execs']:,} | {r['per_sec']:,} | {r['cov']:,} | "
                         f"{r['ft']:,} | {r['corpus']:,} | {r['rss']:,} | {'yes: ' + str(log) if r['crashed'] else 'none'} |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("names", nargs="*", metavar="NAME", help=f"harnesses to run (default all: {' '.join(NAMES)})")
    ap.add_argument("--time", type=int, default=60, help="seconds per harness (default 60)")
    ap.add_argument("--jobs", type=int, default=2, help="harnesses run at once (default 2)")
    ap.add_argument("--smoke", action="store_true", help="replay seeds and regressions, then fuzz 3 s each")
    a = ap.parse_args()
    names = a.names or NAMES
    unknown = [n for n in names if n not in NAMES]
    if unknown:
        ap.error(f"unknown harness {', '.join(unknown)} (there are: {' '.join(NAMES)})")
    if a.time < 1:
        ap.error("--time must be at least 1 second")
    for n in names:
        if not (FUZZ / f"fuzz_{n}").exists():
            sys.exit(f"fuzz: {FUZZ / f'fuzz_{n}'} is missing: build it with make fuzz-build")

    if a.smoke:
        seeds = {n: make_seeds(n) for n in names}
        failed = [n for n in names if not replay(n, seeds[n])]
        for n in failed:
            print(f"fuzz-smoke: {n}: a seed or kept regression fails (above)", file=sys.stderr)
        with tempfile.TemporaryDirectory() as tmp:
            rows = [run_harness(n, 3, Path(tmp) / n, Path(tmp) / f"{n}.log", seeds[n]) for n in names if n not in failed]
            for r in rows:
                if r["crashed"]:
                    sys.stderr.write(r["log"].read_text(errors="replace")[-4000:])
        for r in rows:
            ok = not r["crashed"]
            print(f"fuzz-smoke: {r['name']}: {r['execs']:,} executions, {'ok' if ok else 'CRASH (above)'}")
            if not ok:
                failed.append(r["name"])
        return 1 if failed else 0

    print(f"fuzz: {len(names)} harnesses, {a.time} s each, {a.jobs} at once", flush=True)
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        futures = {pool.submit(run_harness, n, a.time, FUZZ / "corpus" / n, FUZZ / f"{n}.log", make_seeds(n)): n for n in names}
        rows = []
        for f in concurrent.futures.as_completed(futures):
            r = f.result()
            rows.append(r)
            print(f"fuzz: {r['name']}: {r['execs']:,} executions in {r['seconds']} s, coverage {r['cov']:,}, "
                  f"{'CRASH: see ' + str(r['log']) if r['crashed'] else 'no crash'}", flush=True)
    table = report()
    (FUZZ / "report.md").write_text(table)
    print(table)
    return 1 if any(r["crashed"] for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
