#!/usr/bin/env python3
"""The display board's cost per frame on the Cortex-M3 (QEMU mps2-an385, hal/board).

The rendering firmware, built for freedoom2.wad:MAP01 (make firmware SCENE=... ARM_OUT=build/bench-board/fw),
streams its MAP01 camera path over TCP into the display board booted from build/arm/display-board.bin,
textured and with --flat, with the board's QEMU running the instruction-counting plugin
(build/insn_count.so). The board marks each link message from its first byte to the end of its
handling (fw_mark_frame_begin/end in hal/board/main.c): receiving the bytes (the UART interrupt
and ring), COBS, the message CRC, rebuilding the frame into the hidden page, the frame check (and
the pixel CRC-32 when the sender sent one), the flip and the ack. The board runs with --log-frames:
its line per frame names the message (seg) of each frame shown; the CRC-32 of the page that line
gives is computed after the end mark, outside the count.

Frames per second assume one instruction per cycle at the AN385's 25 MHz: an upper bound; a
real core spends extra cycles on branches, loads and wait states.

Prints a Markdown table and writes it to --out. A benchmark: it asserts nothing about speed.
"""
import argparse
import bisect
import collections
import re
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
sys.path.insert(0, str(ROOT / "tools"))
from armelf import symbol  # noqa: E402
from boardrig import ARM, Board, Sender, frames_of  # noqa: E402

HZ = 25_000_000


# Where the instructions inside the marks go, by the object file the code comes from (the
# link map), from the plugin's profile=.
RECEIVE = "UART receive (interrupt, ring) and the main loop"
PARTS = [(RECEIVE, ("hal/mps2/uart.o", "hal/board/main.o")),
         ("picture decoder of method COPY (hal/serial/fl_copy.c)", ("hal/serial/fl_copy.o",)),
         ("rest of the decoder (hal/serial: COBS, message check, EDGE pictures, frame check)", ("hal/serial/",)),
         ("CRC-32 (message CRC, pixel CRC-32; firmware/crc32.c)", ("firmware/crc32.o",))]
OTHER = "other"


def code_ranges(map_file):
    """[(start, end, object)] of the .text input sections in the link map."""
    ranges, pending = [], None
    for line in Path(map_file).read_text().splitlines():
        m = re.match(r"^ \.text(\.\S+)?\s*(0x[0-9a-f]+\s+0x[0-9a-f]+\s+(\S+))?$", line)
        if m:
            pending = None
            if m.group(2):
                start, size = (int(v, 16) for v in m.group(2).split()[:2])
                ranges.append((start, start + size, m.group(3)))
            else:
                pending = True
            continue
        if pending:
            m = re.match(r"^\s+(0x[0-9a-f]+)\s+(0x[0-9a-f]+)\s+(\S+)$", line)
            if m:
                start, size = int(m.group(1), 16), int(m.group(2), 16)
                ranges.append((start, start + size, m.group(3)))
            pending = None
    return sorted(ranges)


def profile_parts(map_file, profile):
    """{part label: instructions} from the plugin's profile (address runs) of one run."""
    ranges = code_ranges(map_file)
    starts = [r[0] for r in ranges]
    parts = collections.Counter()
    for line in Path(profile).read_text().splitlines():
        if line.startswith("#"):
            continue
        addr, runs = (int(v, 0) for v in line.split())
        i = bisect.bisect_right(starts, addr) - 1
        obj = ranges[i][2] if i >= 0 and addr < ranges[i][1] else "?"
        parts[next((label for label, keys in PARTS if any(k in obj for k in keys)), OTHER)] += runs
    return parts


def irq_entries(elf, profile):
    """Runs of the UART receive interrupt's first instruction inside the marks."""
    addr = symbol(elf, "uart0_rx_irq") & ~1
    for line in Path(profile).read_text().splitlines():
        if not line.startswith("#") and int(line.split()[0], 0) == addr:
            return int(line.split()[1])
    return 0


def run_case(fw_elf, frames, flat, tmp):
    board_elf = ARM / "display-board.elf"
    counts = tmp / f"board-insns{'-flat' if flat else ''}.txt"
    profile = tmp / f"board-profile{'-flat' if flat else ''}.txt"
    plugin = (f"{BUILD / 'insn_count.so'},begin={symbol(board_elf, 'fw_mark_frame_begin'):#x},"
              f"end={symbol(board_elf, 'fw_mark_frame_end'):#x},out={counts},profile={profile}")
    board = Board(ARM / "display-board.bin", f"--frames {frames} --log-frames", tmp=tmp, plugin=plugin)
    snd = None
    try:
        snd = Sender(fw_elf, board.tcp_port, f"--frames {frames} --acks on" + (" --flat" if flat else ""), tmp=tmp)
        sent = snd.finish(frames, 600)
        board.wait_for(r"board: done:[^\n]*\n", 600)
        snd.kill()
        board.qmp("quit")
        board.wait(60)
    finally:
        board.kill()
        if snd:
            snd.kill()
    shown = frames_of(board.text)
    if len(shown) != frames:
        sys.exit(f"bench_board: the board showed {len(shown)} of {frames} frames:\n{board.text}")
    rows = [line.split() for line in counts.read_text().splitlines() if not line.startswith("#")]
    per_seg = [int(r[1]) for r in rows]  # begin..end of each marked message
    key = [per_seg[f["seg"]] for f in shown if f["key"]]
    delta = [per_seg[f["seg"]] for f in shown if not f["key"]]
    every = key + delta
    summary = board.text[board.text.index("board: done:"):].splitlines()[0]
    received = int(re.search(r"(\d+) bytes, \d+ UART overruns", summary).group(1))
    return dict(received=received, irqs=irq_entries(board_elf, profile),
                parts=profile_parts(ARM / "display-board.map", profile), segs=len(per_seg),
                sent=[l for l in sent.splitlines() if "link:" in l][0], frames=frames,
                median=statistics.median(every), max=max(every),
                key_median=statistics.median(key) if key else 0, delta_median=statistics.median(delta) if delta else 0,
                keys=len(key), summary=summary)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--scene", default="freedoom2.wad:MAP01")
    ap.add_argument("--out", default=str(BUILD / "bench-board.md"))
    a = ap.parse_args()
    fw_out = BUILD / "bench-board" / "fw"
    subprocess.run(["make", "-s", "--no-print-directory", "firmware", f"SCENE={a.scene}", f"ARM_OUT={fw_out}"],
                   cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["make", "-s", "--no-print-directory", "display-board", "insn-plugin"], cwd=ROOT, check=True,
                   stdout=subprocess.DEVNULL)
    tmp = BUILD / "bench-board"
    lines = [f"Display board (hal/board) on the Cortex-M3: instructions per frame shown, {a.scene} camera path "
             f"({a.frames} frames from the rendering firmware over TCP; build/insn_count.so between the board's "
             f"marks; fps = 25 MHz / instructions, at one instruction per cycle)", "",
             "| look | frames | keyframes | median insns/frame | max | keyframe median | delta median | fps at 25 MHz (median) | fps (max) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    results = []
    for flat in (False, True):
        r = run_case(fw_out / "firmware.elf", a.frames, flat, tmp)
        results.append((flat, r))
        lines.append(f"| {'flat' if flat else 'textured'} | {r['frames']} | {r['keys']} | {r['median']:,.0f} | "
                     f"{r['max']:,} | {r['key_median']:,.0f} | {r['delta_median']:,.0f} | "
                     f"{HZ / r['median']:.1f} | {HZ / r['max']:.1f} |")
        print(r["sent"], file=sys.stderr)
        print(r["summary"], file=sys.stderr)
    lines += ["", "Where they go (the plugin's profile, by the object file the code comes from; all marked messages, hello and palette too, "
              "per frame shown):", "", "| part | " + " | ".join("flat" if f else "textured" for f, _ in results) + " |",
              "|---|" + "---:|" * len(results)]
    for label in [p for p, _ in PARTS] + [OTHER]:
        cells = []
        for _, r in results:
            total = sum(r["parts"].values())
            cells.append(f"{r['parts'][label] / r['frames']:,.0f} ({100 * r['parts'][label] / total:.0f}%)")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines += ["", "Receiving: " + "; ".join(
        f"{'flat' if f else 'textured'}: {r['received']:,} bytes, {r['irqs']:,} of their receive interrupts inside "
        f"the marks, {r['parts'][RECEIVE] / max(r['irqs'], 1):.1f} instructions of the UART receive part per byte "
        f"there" for f, r in results) + "."]
    text = "\n".join(lines) + "\n"
    print(text)
    Path(a.out).write_text(text)


if __name__ == "__main__":
    main()
