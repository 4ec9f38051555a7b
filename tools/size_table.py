#!/usr/bin/env python3
"""Flash and RAM of the Cortex-M firmware, full build against builds for one scene (docs/needs.md).

For the default scene, freedoom2.wad:MAP01, the largest Freedoom map (most linedefs) and the
objects demo (tests/scenes/battle.scene): `make firmware SCENE=... FULL=1` (every feature) and
`make firmware SCENE=...` (only what the scene needs, buffers sized to its proven bounds), each
measured with arm-none-eabi-size -A:
  flash = .text (code and read-only data, the compiled scene included) + .ARM.exidx + .data's image
  RAM   = .data + .bss + .work (the renderer's work area)
Writes build/size.md (the table make bench prints and the README quotes).

usage: tools/size_table.py [--out build/size.md] [--scenes SPEC ...]
"""
import argparse
import json
import os
import struct
import subprocess
import sys
from pathlib import Path

import armelf

ROOT = Path(__file__).resolve().parent.parent
WADDIR = Path(os.environ.get("DOOMWADDIR", "/usr/share/games/doom"))
FEATURES = ["objects", "doors", "two-sided walls", "height changes", "sky steps", "look up/down", "y-clipping"]


def largest_map():
    """The Freedoom map with the most linedefs, as file.wad:MAP."""
    best = (0, None)
    for wad in ("freedoom1.wad", "freedoom2.wad"):
        path = WADDIR / wad
        if not path.exists():
            continue
        data = path.read_bytes()
        n, off = struct.unpack_from("<II", data, 4)
        current = None
        for i in range(n):
            pos, size, name = struct.unpack_from("<II8s", data, off + 16 * i)
            name = name.rstrip(b"\0").decode("ascii", "replace")
            if size == 0 and (name.startswith("MAP") or (len(name) == 4 and name[0] == "E" and name[2] == "M")):
                current = name
            elif name == "LINEDEFS" and current:
                best = max(best, (size // 14, f"{wad}:{current}"))
    return best[1]


def make(*args):
    proc = subprocess.run(["make", "-s", "--no-print-directory", "-j4", *args], cwd=ROOT, capture_output=True,
                          text=True)
    if proc.returncode != 0:
        sys.exit(f"size_table: make {' '.join(args)} failed:\n{proc.stdout}{proc.stderr}")


def measure(spec, full):
    name = spec.split("/")[-1].replace(".", "_").replace(":", "-")
    out = f"build/size/{name}-{'full' if full else 'scene'}"
    make("firmware", f"SCENE={spec}", f"ARM_OUT={out}", f"FULL={'1' if full else ''}")
    elf = ROOT / out / "firmware.elf"
    sec = armelf.sections(elf)
    blob = armelf.symbols(elf).get("fw_scene", (0, 0))[1]
    flash = sec.get(".text", 0) + sec.get(".ARM.exidx", 0) + sec.get(".data", 0)
    ram = sec.get(".data", 0) + sec.get(".bss", 0) + sec.get(".work", 0)
    return {"flash": flash, "ram": ram, "work": sec.get(".work", 0), "blob": blob, "code": flash - blob}


def needs(spec):
    out = subprocess.run([str(ROOT / "build" / "bspc"), spec, "-o", "/dev/null", "--stats"], capture_output=True,
                         text=True, check=True).stdout
    return json.loads(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(ROOT / "build" / "size.md"))
    ap.add_argument("--scenes", nargs="*")
    a = ap.parse_args()
    scenes = a.scenes or [s for s in ("tests/scenes/default.scene", "freedoom2.wad:MAP01", largest_map(),
                                      "tests/scenes/battle.scene") if s]
    rows = ["| scene | build | flash (bytes) | of it code | RAM (bytes) | of it work area | left out |",
            "|---|---|---:|---:|---:|---:|---|"]
    notes = []
    for spec in scenes:
        print(f"size_table: {spec}", file=sys.stderr, flush=True)
        st = needs(spec)
        left = [f for i, f in enumerate(FEATURES) if not st["features"] & (1 << i)]
        full, mine = measure(spec, True), measure(spec, False)
        rows.append(f"| {spec} | full | {full['flash']:,} | {full['code']:,} | {full['ram']:,} | {full['work']:,} | - |")
        rows.append(f"| | for the scene | {mine['flash']:,} ({mine['flash'] - full['flash']:+,}) | {mine['code']:,} | "
                    f"{mine['ram']:,} ({mine['ram'] - full['ram']:+,}) | {mine['work']:,} | "
                    f"{', '.join(left) or 'nothing'} |")
        notes.append(f"- {spec}: world edges per frame {st['max_edges']:,} proven, {st['all_edges']:,} if every "
                     f"polygon could show at once; surfaces {st['max_surfaces']:,} / {st['all_surfaces']:,}; "
                     f"tree depth {st['max_depth']}")
    text = "\n".join(["Cortex-M3 firmware (mps2-an385, -O2, arm-none-eabi-size -A): flash = .text (code, "
                      "read-only data and the compiled scene) + .ARM.exidx + .data; RAM = .data + .bss + "
                      ".work (the renderer's work area, sized by the firmware itself). \"For the scene\" is "
                      "make firmware SCENE=...; \"full\" is the same with FULL=1.", "", *rows, "",
                      "Per-frame bounds the work area is sized from (bspc --needs):", *notes, ""])
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(text)
    print(text)


if __name__ == "__main__":
    main()
