#!/usr/bin/env python3
"""make mutate: mutation testing of firmware/, firmware/dfu/ and hal/serial/.

universalmutator's regexp rules (universal, c, c_like) make every mutant of each source file; a seeded
shuffle picks them in a fixed order, and mutants are tried in that order until --sample of them have
built. Each mutant is written into a private copy of the tree (build/mutate/tree: the working tree is
never touched, so other builds and tests can run beside it), only the sanitized programs that the
file's tests need are rebuilt there, and those tests run with a timeout:

  killed     a test failed (or a golden frame's CRC-32 changed, or a sanitizer stopped it)
  timeout    a test ran past its timeout (counted as caught: the mutant never finishes)
  survived   every test passed
  no-build   the mutant does not compile (not counted in the score, not in the sample)
  equivalent the mutant is in EQUIVALENT: it cannot change what the program does (the table gives
             why); it is not built or run, it counts in the sample, and is reported apart

The score is (killed + timeout) / (killed + timeout + survived + equivalent), the raw score; the score
excluding equivalents leaves them out of the denominator. Both are reported. A survivor in UNREACHED
(code the host build does not compile or reach) stays a survivor; the report says where that code runs. It writes build/mutate/report.md (the
counts per file and every survivor with its diff), build/mutate/results.json and, unless --no-doc,
the "mutate" section of docs/benchmarks.md. A benchmark, not part of make test.
"""
import argparse
import contextlib
import io
import json
import os
import random
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SOURCES = ("firmware/*.c", "firmware/dfu/*.c", "hal/serial/*.c")
RULES = ["universal.rules", "c.rules", "c_like.rules"]

# The golden frames of tests/golden/frames.json in the render modes and present paths of
# tests/test_golden.py: tests/scenes/default.scene's untextured views and freedoom2.wad MAP01's textured
# ones with the map's things as objects (each frame renders in about 0.1 s with the sanitizers).
GOLDEN = "golden"
GOLDEN_MODES = [("direct", "flip"), ("direct", "copy16"), ("spans", "flip"), ("spans", "copy32"),
                ("painter", "copy8")]
RENDERER = [GOLDEN, "test_objects", "test_ranges"]
# The fast tests that cover each file, cheapest first (the run stops at the first that fails).
TESTS = {
    "hal/serial/": ["test_framelink"],
    "firmware/dfu/": ["test_dfu"],
    "firmware/crc32.c": [GOLDEN, "test_dfu", "test_framelink"],
    "firmware/fixed.c": [GOLDEN, "test_fixed", "test_view"],
    "firmware/view.c": [GOLDEN, "test_view"],
    "firmware/clip.c": [GOLDEN, "test_clip"],
    "firmware/raster.c": ["test_clip", GOLDEN, "test_objects", "test_ranges"],
    "firmware/cover.c": [GOLDEN, "test_cover"],
    "firmware/scene.c": [GOLDEN, "test_bsp", "test_scene"],
    "firmware/camera.c": [GOLDEN, "test_collide", "test_objects"],
    "firmware/collide.c": ["test_collide", "test_objects"],
    "firmware/collide_geom.c": ["test_collide_geom", "test_collide", "test_objects"],
    "firmware/collide_sight.c": ["test_collide", "test_objects"],
    "firmware/objects.c": [GOLDEN, "test_objects"],
    "firmware/obj_draw.c": [GOLDEN, "test_objects"],
    "firmware/engine.c": [GOLDEN, "test_objects", "test_ranges", "test_scene"],
    "firmware/surfaces.c": ["test_surfaces", *RENDERER],
    "firmware/eye.c": ["test_eye", *RENDERER],
    "firmware/texture.c": ["test_texture", *RENDERER],
    "firmware/": RENDERER,
}


# Mutants shown to be equivalent, keyed by file and the original and mutated lines (stripped), so an
# entry follows its line when code above it moves and lapses when the line changes. Each reason is the
# argument that no input tells the mutant apart from the original.
EQUIVALENT = {
    ("firmware/collide_sight.c", "(void)state;", "/*(void)state;*/"):
        "a cast to void that only silences the unused-parameter warning: no code either way",
    ("firmware/direct.c", "for (int y = face.top; y < face.bottom; y++) {",
     "for (int y = face.top; y != face.bottom; y++) {"):
        "draw_face's rows: face_build keeps a face only when top < bottom, and y steps by one from top, "
        "so y < bottom and y != bottom agree on every row",
    ("hal/serial/fl_codec.c",
     "enc_colour(r, s->c, SET_KEEP, col, j + 1 < rn ? (ref->pk[j + 1] & 0xFF) : -1,",
     "enc_colour(r, s->c, SET_KEEP, col, j + 1 != rn ? (ref->pk[j + 1] & 0xFF) : -1,"):
        "enc_op's branch reads ref->pk[j], so j < rn there (j == rn is the branch above): j + 1 <= rn, "
        "where j + 1 < rn and j + 1 != rn agree",
    ("firmware/scene.c", "for (uint32_t i = 0; i < s->nsectors; i++) {",
     "for (uint32_t i = 0; i != s->nsectors; i++) {"):
        "i counts up by one from 0 and nothing else changes it: i < n and i != n end the loop at the same i",
    ("firmware/spans.c", "screen_pt a = pts[i], b = pts[(i + 1 == n) ? 0 : i + 1];",
     "screen_pt a = pts[i], b = pts[(i + 1 >= n) ? 0 : i + 1];"):
        "inside for (i = 0; i < n; i++): i + 1 <= n, where i + 1 == n and i + 1 >= n agree",
    ("firmware/dfu/dfu_proto.c",
     'return status < sizeof status_texts / sizeof status_texts[0] ? status_texts[status] : "unknown status code";',
     'return status < sizeof status_texts / sizeof status_texts[(0-1)] ? status_texts[status] : "unknown status code";'):
        "sizeof does not evaluate its operand: status_texts[-1] has the element type, the same size as "
        "status_texts[0]",
    ("firmware/obj_draw.c", "#define NORM_HI ((int64_t)1 << 30)", "#define NORM_HI ((int64_t)1 <!= 30)"):
        "NORM_HI is never expanded (obj_draw.c and every header): the macro's text is never compiled",
}


# Mutants in code that the host build the fast tests run does not compile or reach, keyed as EQUIVALENT.
# They are not equivalent: they stay survivors and count against the score; the report says where
# the code runs, so that a reader does not look for a missing host test.
UNREACHED = {
    ("hal/serial/fl_codec.c", '"    cmpeq   r7, %[bc]\\n"', '/*"    cmpeq   r7, %[bc]\\n"*/'):
        "Cortex-M3 assembly (__ARM_ARCH_7M__ && __thumb2__): compiled only for the M3 firmware, whose "
        "tests run under QEMU (tests/test_firmware.py and the link tests), not among the fast ones",
    ("firmware/raster.c",
     "int64_t step = floor_div(dx * (2 << RAST_STEP_BITS) + dy, 2 * dy) * (1 << (16 - RAST_STEP_BITS));",
     "int64_t step = floor_div(dx * (0 << RAST_STEP_BITS) + dy, 2 * dy) * (1 << (16 - RAST_STEP_BITS));"):
        "compiled only with RAST_STEP_BITS > 0, a precision knob of make report (mk/report.mk); the "
        "default build steps edges exactly",
    ("firmware/engine.c", "return (e->world.ceil || e->world.objs) ? &e->world : 0;",
     "return (e->world.ceil || e->world.objs) ? &e->world : 1;"):
        "the 0 arm runs only in a build without objects and doors (CFG_OBJECTS and CFG_DOORS 0: the "
        "firmware built for a scene that needs neither); the host build has both, so obj_init always "
        "sets ceil and objs",
}


def unreached_note(rel, original, mutant):
    return UNREACHED.get((rel, original.strip(), mutant.strip()))


def equivalent_reason(rel, original, mutant):
    return EQUIVALENT.get((rel, original.strip(), mutant.strip()))


def tests_for(rel):
    for key in sorted(TESTS, key=len, reverse=True):
        if rel == key or (key.endswith("/") and rel.startswith(key)):
            return TESTS[key]
    return RENDERER


def source_files(patterns):
    out = []
    for pat in patterns:
        out += sorted(str(p.relative_to(ROOT)) for p in ROOT.glob(pat) if p.is_file())
    return sorted(set(out))


def mutants_of(rel):
    """[(file, line number, mutated line, rule)] for one source file."""
    from universalmutator import mutator
    lines = (ROOT / rel).read_text().splitlines(keepends=True)
    with contextlib.redirect_stdout(io.StringIO()):
        found = mutator.mutants_regexp(lines, ruleFiles=RULES, ignorePatterns=[], ignoreStringOnly=True)
    return [(rel, n, text, rule[0]) for n, text, rule, _ in found]


def copy_tree(dst):
    """The sources of the working tree (tracked and untracked, not ignored) into dst, keeping
    their times, and the sanitized objects of build/san beside them, so make rebuilds only what
    is out of date."""
    files = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                           cwd=ROOT, capture_output=True, check=True).stdout.decode().split("\0")
    for rel in filter(None, files):
        src = ROOT / rel
        if src.is_file():
            (dst / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dst / rel)
    for sub in ("build/san/obj", "build/gen"):
        if (ROOT / sub).is_dir() and not (dst / sub).exists():
            shutil.copytree(ROOT / sub, dst / sub, symlinks=True)
    # Keep the unit tests' objects between builds (make would delete them as intermediates).
    (dst / "build").mkdir(exist_ok=True)
    (dst / "build/keep.mk").write_text(".SECONDARY:\n")


def sync_tree(dst):
    """Bring dst's sources up to the working tree's where they differ (a kept scratch tree)."""
    files = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                           cwd=ROOT, capture_output=True, check=True).stdout.decode().split("\0")
    for rel in filter(None, files):
        src, out = ROOT / rel, dst / rel
        if src.is_file() and (not out.exists() or out.read_bytes() != src.read_bytes()):
            out.parent.mkdir(parents=True, exist_ok=True)
            # a fresh time, so make rebuilds objects left from an interrupted mutant
            shutil.copyfile(src, out)


def programs(tests):
    return sorted({"build/san/render" if t == GOLDEN else f"build/san/{t}" for t in tests})


def build(tree, targets, log):
    proc = subprocess.run(["make", "-f", "Makefile", "-f", "build/keep.mk", "-j2", *targets], cwd=tree,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    log.write(proc.stdout)
    return proc.returncode == 0


def golden_views():
    return json.loads((ROOT / "tests/golden/frames.json").read_text())["frames"]


def run_test(tree, name, timeout):
    """'pass', 'fail' or 'timeout' for one unit test or the golden frames."""
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1", UBSAN_OPTIONS="halt_on_error=1")
    deadline = time.monotonic() + timeout
    cmds = []
    if name == GOLDEN:
        for view in golden_views():
            cam = (["--at", view["at"], "--angle", view["angle"]] if view["at"] else [])
            for mode, present in GOLDEN_MODES:
                painter = mode == "painter"
                want = (view.get(f"{mode}_crc32", view["crc32"]), view["painter_overdraw"] if painter else 1.0)
                # a WAD's map is found by build/render in DOOMWADDIR, as tests/test_golden.py passes it
                scene = view["scene"] if ".wad:" in view["scene"] else str(tree / view["scene"])
                cmds.append(([str(tree / "build/san/render"), scene, *cam, "--mode", mode, "--present", present],
                             want))
    else:
        cmds.append(([str(tree / "build/san" / name)], None))
    for cmd, want in cmds:
        left = deadline - time.monotonic()
        if left <= 0:
            return "timeout"
        try:
            proc = subprocess.run(cmd, cwd=tree, capture_output=True, text=True, timeout=left, env=env)
        except subprocess.TimeoutExpired:
            return "timeout"
        if proc.returncode != 0:
            return "fail"
        if want is not None:
            try:
                frame = json.loads(proc.stdout)
                # tests/conftest.py's render() also refuses a frame whose pools ran full; the
                # overdraw is tests/test_golden.py's second check (the painter's is recorded)
                if (frame["crc32"], frame["overdraw"]) != want or frame.get("overflow", 0) != 0:
                    return "fail"
            except (ValueError, KeyError):
                return "fail"
    return "pass"


def fmt_time(s):
    s = int(s)
    return f"{s // 60}m{s % 60:02d}s"


def diff_of(m, original):
    rel, n, text, _ = m
    return f"--- {rel}:{n}\n-{original[n - 1].rstrip()}\n+{text.rstrip()}"


def run(args):
    files = args.files or source_files(SOURCES)
    for rel in files:
        if not (ROOT / rel).is_file():
            sys.exit(f"mutate: no such source file: {rel}")
    every = []
    for rel in files:
        every += mutants_of(rel)
    if args.match:
        import re
        pat = re.compile(args.match)
        every = [m for m in every if pat.search(m[2])]
    random.Random(args.seed).shuffle(every)
    print(f"mutate: {len(every)} mutants of {len(files)} files; sampling {args.sample} that build (seed {args.seed})")
    if not every:
        sys.exit("mutate: no mutants")

    out = Path(args.out)
    tree = out / "tree"
    out.mkdir(parents=True, exist_ok=True)
    if not args.keep_tree and tree.exists():
        shutil.rmtree(tree)
    if tree.exists():
        sync_tree(tree)
    else:
        copy_tree(tree)
    log = open(out / "build.log", "w")

    # The baseline: the unmutated tree must build and pass every test used, which also gives each
    # test's time (its timeout is a multiple of it).
    used = sorted({t for rel in files for t in (args.tests or tests_for(rel))})
    t0 = time.monotonic()
    print(f"mutate: building {' '.join(programs(used))} in {tree}")
    if not build(tree, programs(used), log):
        sys.exit(f"mutate: the unmutated tree does not build (see {out / 'build.log'})")
    base = {}
    for t in used:
        s = time.monotonic()
        if run_test(tree, t, 600) != "pass":
            sys.exit(f"mutate: {t} fails on the unmutated tree")
        base[t] = time.monotonic() - s
    print(f"mutate: baseline built and passed in {fmt_time(time.monotonic() - t0)}: "
          + ", ".join(f"{t} {base[t]:.1f}s" for t in used))

    originals = {rel: (ROOT / rel).read_text().splitlines(keepends=True) for rel in files}
    results = []
    start = time.monotonic()
    try:
        try_mutants(args, every, tree, originals, base, log, results, start)
    except KeyboardInterrupt:
        # Ctrl-C: the report of the mutants run so far (the scratch file was restored)
        print("mutate: interrupted; reporting the mutants run so far")
    log.close()
    elapsed = time.monotonic() - t0
    report(args, out, files, len(every), results, elapsed)


def try_mutants(args, every, tree, originals, base, log, results, start):
    for m in every:
        if sum(r["status"] != "no-build" for r in results) >= args.sample:
            break
        rel, n, text, rule = m
        why = equivalent_reason(rel, originals[rel][n - 1], text)
        if why:
            results.append({"file": rel, "line": n, "mutant": text.rstrip("\n"), "rule": rule,
                            "original": originals[rel][n - 1].rstrip("\n"), "status": "equivalent", "by": None,
                            "seconds": 0, "reason": why})
            done = sum(r["status"] != "no-build" for r in results)
            print(f"[{done}/{args.sample}] {rel}:{n} equivalent (EQUIVALENT)", flush=True)
            continue
        lines = list(originals[rel])
        lines[n - 1] = text
        path = tree / rel
        tests = args.tests or tests_for(rel)
        s = time.monotonic()
        try:
            path.write_text("".join(lines))
            status, by = "survived", None
            # each test's program is built just before it runs: a mutant killed by the first
            # test costs no link of the others
            for t in tests:
                if not build(tree, programs([t]), log):
                    status = "no-build"
                    break
                r = run_test(tree, t, max(args.min_timeout, args.timeout_factor * base[t]))
                if r != "pass":
                    status, by = ("killed" if r == "fail" else "timeout"), t
                    break
        finally:
            path.write_text("".join(originals[rel]))
        took = time.monotonic() - s
        results.append({"file": rel, "line": n, "mutant": text.rstrip("\n"), "rule": rule,
                        "original": originals[rel][n - 1].rstrip("\n"), "status": status, "by": by,
                        "seconds": round(took, 2)})
        done = sum(r["status"] != "no-build" for r in results)
        rate = (time.monotonic() - start) / max(done, 1)
        left = rate * (args.sample - done)
        print(f"[{done}/{args.sample}] {rel}:{n} {status}{' by ' + by if by else ''} ({took:.1f}s, "
              f"~{fmt_time(left)} left)", flush=True)


def counts(rows):
    c = {k: 0 for k in ("killed", "timeout", "survived", "equivalent", "no-build")}
    for r in rows:
        c[r["status"]] += 1
    return c


def score_of(c, equivalents=True):
    """(score, denominator): caught over every sampled mutant, or (equivalents=False) over those not
    known to be equivalent."""
    scored = c["killed"] + c["timeout"] + c["survived"] + (c["equivalent"] if equivalents else 0)
    return (c["killed"] + c["timeout"]) / scored if scored else 0.0, scored


def report(args, out, files, total, results, elapsed):
    c = counts(results)
    score, scored = score_of(c)
    score_ne, scored_ne = score_of(c, equivalents=False)
    command = "make mutate" + (f" MUTATE_SAMPLE={args.sample}" if args.sample != DEFAULT_SAMPLE else "") + \
        (f" MUTATE_SEED={args.seed}" if args.seed != DEFAULT_SEED else "")
    summary = [f"Mutants of {len(files)} files (firmware/, firmware/dfu/, hal/serial/): {total}, made by "
               f"universalmutator's regexp rules ({', '.join(RULES)}). A seeded shuffle (seed {args.seed}) "
               f"picks them; {scored} that built were run against the fast tests of their file "
               f"(tools/mutate.py's TESTS: cmocka unit tests, and the golden CRC-32s of "
               f"tests/golden/frames.json's views, tests/scenes/default.scene's and freedoom2.wad MAP01's textured "
               f"ones with objects, in the five render modes of tests/test_golden.py), "
               f"built with ASan and UBSan.",
               "",
               f"**Score: {score_ne:.1%}** of the {scored_ne} mutants not known to be equivalent caught "
               f"(killed {c['killed']}, timed out {c['timeout']}, survived {c['survived']}); raw score "
               f"{score:.1%} of all {scored} sampled, counting the {c['equivalent']} equivalent ones "
               f"(tools/mutate.py's EQUIVALENT, each with its reason below) as not caught. {c['no-build']} more "
               f"did not compile and are not counted. Run time {fmt_time(elapsed)}.",
               "",
               "| file | mutants | caught | survived | equivalent | no-build |",
               "| --- | ---: | ---: | ---: | ---: | ---: |"]
    for rel in files:
        rows = [r for r in results if r["file"] == rel]
        if rows:
            k = counts(rows)
            summary.append(f"| {rel} | {len(rows) - k['no-build']} | {k['killed'] + k['timeout']} | "
                           f"{k['survived']} | {k['equivalent']} | {k['no-build']} |")
    survivors = [r for r in results if r["status"] == "survived"]
    body = [f"# Mutation testing\n\nCommand: `{command}` (tools/mutate.py), "
            f"{time.strftime('%Y-%m-%d')}.\n", *summary, "", "## Survivors", ""]
    for r in sorted(survivors, key=lambda r: (r["file"], r["line"])):
        note = unreached_note(r["file"], r["original"], r["mutant"])
        body += [f"{r['file']}:{r['line']} (tests: {', '.join(args.tests or tests_for(r['file']))})"
                 + (f": not reached by the fast tests: {note}" if note else ""),
                 "```diff", f"-{r['original']}", f"+{r['mutant']}", "```", ""]
    if not survivors:
        body.append("None.")
    equivalents = sorted((r for r in results if r["status"] == "equivalent"), key=lambda r: (r["file"], r["line"]))
    body += ["", "## Equivalent mutants (not run)", ""]
    for r in equivalents:
        body += [f"{r['file']}:{r['line']}: {r['reason']}", "```diff", f"-{r['original']}", f"+{r['mutant']}",
                 "```", ""]
    if not equivalents:
        body.append("None.")
    (out / "report.md").write_text("\n".join(body) + "\n")
    (out / "results.json").write_text(json.dumps({"seed": args.seed, "sample": args.sample, "mutants": total,
                                                   "score": score, "score_excluding_equivalents": score_ne, "counts": c, "seconds": round(elapsed),
                                                   "results": results}, indent=1) + "\n")
    surv_lines = []
    for r in sorted(survivors, key=lambda r: (r["file"], r["line"])):
        note = unreached_note(r["file"], r["original"], r["mutant"])
        surv_lines.append(f"- {r['file']}:{r['line']}: `{r['original'].strip()}` -> `{r['mutant'].strip()}`"
                          + (f" (not reached by the fast tests: {note})" if note else ""))
    eq_lines = [f"- {r['file']}:{r['line']}: `{r['original'].strip()}` -> `{r['mutant'].strip()}`: {r['reason']}"
                for r in sorted(results, key=lambda r: (r["file"], r["line"])) if r["status"] == "equivalent"]
    (out / "summary.md").write_text("\n".join(summary) + "\n\nSurvivors (the diffs are in build/mutate/report.md):\n\n"
                                    + ("\n".join(surv_lines) if surv_lines else "None.")
                                    + "\n\nEquivalent (not run):\n\n" + ("\n".join(eq_lines) if eq_lines else "None.")
                                    + "\n")
    print(f"mutate: score {score_ne:.1%} excluding {c['equivalent']} equivalent, raw {score:.1%} "
          f"({c['killed'] + c['timeout']} of {scored} caught; {c['survived']} survived, "
          f"{c['no-build']} did not build) in {fmt_time(elapsed)}; report in {out / 'report.md'}")
    if not args.no_doc:
        sys.path.insert(0, str(ROOT / "tools"))
        import bench_doc
        bench_doc.write("mutate")
        print(f"mutate: docs/benchmarks.md updated")


DEFAULT_SAMPLE = 40
DEFAULT_SEED = 19


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sample", type=int, default=int(os.environ.get("MUTATE_SAMPLE") or DEFAULT_SAMPLE),
                    help=f"mutants to run that build (env MUTATE_SAMPLE; default {DEFAULT_SAMPLE}: about"
                         f" ten minutes on 2 idle cores)")
    ap.add_argument("--seed", type=int, default=int(os.environ.get("MUTATE_SEED") or DEFAULT_SEED),
                    help=f"seed of the shuffle that picks the mutants (env MUTATE_SEED; default {DEFAULT_SEED})")
    ap.add_argument("--files", nargs="+", metavar="FILE",
                    help="mutate only these source files (relative to the tree; default: " + " ".join(SOURCES) + ")")
    ap.add_argument("--match", metavar="REGEX", help="only mutants whose mutated line matches REGEX")
    ap.add_argument("--tests", nargs="+", metavar="TEST",
                    help=f"run these tests (test_NAME from tests/unit, or '{GOLDEN}') instead of the file's own")
    ap.add_argument("--timeout-factor", type=float, default=5.0,
                    help="a test times out after this many times its unmutated run time (default 5)")
    ap.add_argument("--min-timeout", type=float, default=20.0, help="but never under this many seconds (default 20)")
    ap.add_argument("--out", default=str(ROOT / "build/mutate"), help="report and scratch tree (default build/mutate)")
    ap.add_argument("--keep-tree", action="store_true",
                    help="reuse the scratch tree and its objects from the last run (sources are synced)")
    ap.add_argument("--no-doc", action="store_true", help="do not update docs/benchmarks.md")
    args = ap.parse_args(argv)
    if args.sample < 1:
        ap.error("--sample must be at least 1")
    run(args)


if __name__ == "__main__":
    main()
