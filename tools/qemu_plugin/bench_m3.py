#!/usr/bin/env python3
"""Instructions per frame on the Cortex-M3 (QEMU mps2-an385) for the bench views.

For each view of tests/bench_views.json (or --views FILE): build the firmware with the view's
scene built in (make firmware SCENE=... ARM_OUT=build/bench-m3/NAME, objects shared), run it under
qemu-system-arm at the fixed view (--at, --angle; --frames N --no-stream --no-tick) with the
instruction-counting plugin (build/insn_count.so), and take the instructions between the
firmware's frame markers: one frame's input, render, present and frame-done hook (the same work
as build/render's --repeat difference in make bench). Identical frames give identical counts; the
median of N is reported. Frames per second are what the count implies at 48 MHz and 133 MHz if
the core retired one instruction per cycle: an assumption - a real Cortex-M3 spends extra cycles
on taken branches (pipeline refill), loads and stores to slower memory (wait states), and
multi-cycle multiplies and divides, so real rates are lower by a factor that depends on the part.

Prints a Markdown table, writes it to build/bench-m3.md and the figures to build/bench-m3.json.
A benchmark, not a test: it asserts nothing about speed.
"""
import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
BUILD = ROOT / "build"
sys.path.insert(0, str(ROOT / "tools"))
import armelf  # noqa: E402
CLOCKS = (48_000_000, 133_000_000)


def make(*args):
    proc = subprocess.run(["make", "-s", "--no-print-directory", *args], cwd=ROOT, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"bench_m3: make {' '.join(args)} failed:\n{proc.stdout}{proc.stderr}")


def symbol(elf, name):
    try:
        return armelf.symbol(elf, name)
    except LookupError as e:
        sys.exit(f"bench_m3: {e}")


def count(elf, args, out):
    plugin = (f"{BUILD / 'insn_count.so'},begin={symbol(elf, 'fw_mark_frame_begin'):#x},"
              f"end={symbol(elf, 'fw_mark_frame_end'):#x},out={out}")
    cmd = ["qemu-system-arm", "-M", "mps2-an385", "-nographic", "-monitor", "none", "-serial", "null",
           "-semihosting-config", "enable=on,target=native", "-kernel", str(elf), "-plugin", plugin,
           "-append", " ".join(args)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    if proc.returncode != 0:
        sys.exit(f"bench_m3: {' '.join(cmd)} exited {proc.returncode}:\n{proc.stderr}")
    rows = [line.split() for line in Path(out).read_text().splitlines() if not line.startswith("#")]
    return [int(r[1]) for r in rows], proc.stderr


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--views", default=str(ROOT / "tests" / "bench_views.json"))
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--mode", default="spans", choices=["spans", "painter"])
    ap.add_argument("--out", default=str(BUILD / "bench-m3.md"))
    opt = ap.parse_args()

    views = json.loads(Path(opt.views).read_text())["views"]
    make("insn-plugin")
    obj = BUILD / "bench-m3" / "obj"
    results = []
    for v in views:
        name = v["scene"].replace(":", "_").replace("/", "_")
        out_dir = BUILD / "bench-m3" / name
        make("firmware", f"SCENE={v['scene']}", f"ARM_OUT={out_dir}", f"ARM_OBJ={obj}", "STREAM=raw", "FULL=1",
             "FW_MODES=direct,spans,painter", "RAM_BYTES=16777216")
        elf = out_dir / "firmware.elf"
        counts, log = count(elf, ["--at", v["at"], "--angle", v["angle"], "--mode", opt.mode,
                                  "--frames", str(opt.frames), "--no-stream", "--no-tick"], out_dir / "insns.txt")
        work = next((ln for ln in log.splitlines() if "work " in ln), "")
        med = int(statistics.median(counts))
        results.append(dict(scene=v["scene"], at=v["at"], angle=v["angle"], mode=opt.mode, insns=med,
                            counts=counts, fps={str(c): c / med for c in CLOCKS}, log=work))
        print(f"{v['scene']} @ {v['at']} {v['angle']}: {med:,} instructions/frame", file=sys.stderr)

    lines = [f"| view | Cortex-M3 instructions/frame ({opt.mode}) | fps at 48 MHz | fps at 133 MHz |",
             "|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r['scene']} @ {r['at']} {r['angle']}° | {r['insns']:,} | "
                     f"{48e6 / r['insns']:.1f} | {133e6 / r['insns']:.1f} |")
    med = statistics.median(r["insns"] for r in results)
    lines += ["", f"Views: {len(results)}. Median {med:,.0f} instructions per frame on the Cortex-M3 (QEMU "
              f"mps2-an385, TCG plugin count between the firmware's frame markers): {48e6 / med:.1f} fps at 48 MHz, "
              f"{133e6 / med:.1f} fps at 133 MHz, assuming one instruction per cycle (a real core needs more "
              "cycles: branches, wait states, multi-cycle multiply and divide)."]
    text = "\n".join(lines) + "\n"
    print(text)
    Path(opt.out).write_text(text)
    Path(opt.out).with_suffix(".json").write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
