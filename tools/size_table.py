#!/usr/bin/env python3
"""Flash and RAM of the Cortex-M3 firmware (hal/mps2) for the default scene, freedoom2.wad:MAP01,
freedoom2.wad:MAP12 (the largest Freedoom map), freedoom1.wad:E1M1, and whether each fits the
board's RAM (RAM_BYTES in mk/mps2.mk, 200,000 bytes).

Each scene is built twice, as `make firmware SCENE=...` builds it (only the features the scene
needs, the render modes of FW_MODES) and with FULL=1 (every feature), both with RAM to spare
(RAM_BYTES=16777216) so that a build that would be refused still links and can be measured:
  flash = .text (code, read-only data and the compiled scene, read in place) + .ARM.exidx + .data's image
  RAM   = all of it, from the image's symbols (hal/mps2/mps2.ld's __ram_need): the stack, both VRAM
          pages, the palette and display-start register, .data, .bss and the work area
The world state (objects, ceilings, doors; part of the work area) and the stack's high-water mark
come from one frame of each image under QEMU (its start and end lines).
Writes build/size.md (the table make bench prints and the README quotes).

usage: tools/size_table.py [--out build/size.md] [--scenes SPEC ...]
"""
import argparse
import re
import subprocess
import sys
from pathlib import Path

import armelf

ROOT = Path(__file__).resolve().parent.parent
SCENES = ["tests/scenes/default.scene", "freedoom2.wad:MAP01", "freedoom2.wad:MAP12", "freedoom1.wad:E1M1"]
ROOM = 16777216  # RAM_BYTES of the measuring builds: PSRAM's 16 MB


def board_ram():
    """RAM_BYTES's default in mk/mps2.mk."""
    m = re.search(r"^RAM_BYTES \?= (\d+)", (ROOT / "mk" / "mps2.mk").read_text(), re.M)
    return int(m.group(1))


def make(*args):
    proc = subprocess.run(["make", "-s", "--no-print-directory", "-j2", *args], cwd=ROOT, capture_output=True,
                          text=True)
    if proc.returncode != 0:
        sys.exit(f"size_table: make {' '.join(args)} failed:\n{proc.stdout}{proc.stderr}")


def run_one_frame(elf):
    """(world state bytes, stack bytes used) from one frame under QEMU."""
    proc = subprocess.run(["qemu-system-arm", "-M", "mps2-an385", "-nographic", "-monitor", "none",
                           "-semihosting-config", "enable=on,target=native", "-kernel", str(elf), "-serial", "null",
                           "-append", "--frames 1 --no-stream --no-tick"], capture_output=True, text=True, timeout=300)
    world = re.search(r"world state (\d+)", proc.stderr)
    stack = re.search(r"stack used (\d+) of", proc.stderr)
    if proc.returncode != 0 or not world or not stack:
        sys.exit(f"size_table: {elf} did not run one frame:\n{proc.stderr}")
    return int(world.group(1)), int(stack.group(1))


def measure(spec, full):
    name = spec.split("/")[-1].replace(".", "_").replace(":", "-")
    out = f"build/size/{name}-{'full' if full else 'scene'}"
    make("firmware", f"SCENE={spec}", f"ARM_OUT={out}", f"FULL={'1' if full else ''}", f"RAM_BYTES={ROOM}")
    elf = ROOT / out / "firmware.elf"
    sec, sym = armelf.sections(elf), armelf.symbols(elf)
    addr = {k: v[0] for k, v in sym.items()}
    world, stack_used = run_one_frame(elf)
    return {
        "flash": sec.get(".text", 0) + sec.get(".ARM.exidx", 0) + sec.get(".data", 0),
        "blob": sym.get("fw_scene", (0, 0))[1],
        "ram": addr["__ram_need"],
        "stack": addr["__stack_top"] - addr["__stack_limit"],
        "stack_used": stack_used,
        "display": addr["__display_end"] - addr["mps2_vram0"],
        "data_bss": addr["__work_start"] - addr["__display_end"],
        "work": addr["__work_end"] - addr["__work_start"],
        "world": world,
    }


def row(spec, build, m, have):
    fits = "yes" if m["ram"] <= have else f"no: {m['ram'] - have:+,}"
    return (f"| {spec} | {build} | {m['flash']:,} | {m['blob']:,} | **{m['ram']:,}** | {fits} | "
            f"{m['stack']:,} ({m['stack_used']:,} used) | {m['display']:,} | {m['data_bss']:,} | {m['world']:,} | "
            f"{m['work'] - m['world']:,} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(ROOT / "build" / "size.md"))
    ap.add_argument("--scenes", nargs="*")
    a = ap.parse_args()
    have = board_ram()
    rows = [f"| scene | build | flash | of it the scene | RAM | fits {have:,} | stack | VRAM pages, palette | "
            f".data + .bss | world state | render work |",
            "|---|---|---:|---:|---:|---|---:|---:|---:|---:|---:|"]
    for spec in a.scenes or SCENES:
        print(f"size_table: {spec}", file=sys.stderr, flush=True)
        rows.append(row(spec, "for the scene", measure(spec, False), have))
        rows.append(row("", "full", measure(spec, True), have))
    text = "\n".join([f"Cortex-M3 firmware (mps2-an385, -O2), bytes. Flash = .text (code, read-only data and the "
                      f"compiled scene, read in place) + .ARM.exidx + .data's image. RAM = all of it: stack, both "
                      f"VRAM pages with the palette and display-start register, .data + .bss, and the work area "
                      f"(world state + the renderer's work, as the firmware sizes it for the render modes built "
                      f"in). \"For the scene\" is make firmware SCENE=...; \"full\" the same with FULL=1; the board "
                      f"has {have:,} bytes of RAM (RAM_BYTES), and make firmware refuses a build that needs more.",
                      "", *rows, ""])
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(text)
    print(text)


if __name__ == "__main__":
    main()
