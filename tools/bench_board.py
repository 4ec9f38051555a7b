#!/usr/bin/env python3
"""The display board's cost per frame on the Cortex-M3 (QEMU mps2-an385, hal/board).

The rendering firmware, built for freedoom2.wad:MAP01 (make firmware SCENE=... ARM_OUT=build/bench-board/fw),
streams its MAP01 camera path over TCP into the display board booted from build/arm/display-board.bin,
textured and with --flat, with the board's QEMU running the instruction-counting plugin
(build/insn_count.so). The board marks each link message from its first byte to the end of its
handling (fw_mark_frame_begin/end in hal/board/main.c): receiving the bytes (the UART interrupt
and ring), COBS, the message CRC, rebuilding the frame into the hidden page, the frame check and
pixel CRC-32, the flip and the ack. The board's log names the message (seg) of each frame shown.

Frames per second assume one instruction per cycle at the AN385's 25 MHz: an upper bound; a
real core spends extra cycles on branches, loads and wait states.

Prints a Markdown table and writes it to --out. A benchmark: it asserts nothing about speed.
"""
import argparse
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
sys.path.insert(0, str(ROOT / "tools"))
from armelf import symbol  # noqa: E402
from boardrig import ARM, Board, finish_sender, frames_of, sender  # noqa: E402

HZ = 25_000_000


def run_case(fw_elf, frames, flat, tmp):
    board_elf = ARM / "display-board.elf"
    counts = tmp / f"board-insns{'-flat' if flat else ''}.txt"
    plugin = (f"{BUILD / 'insn_count.so'},begin={symbol(board_elf, 'fw_mark_frame_begin'):#x},"
              f"end={symbol(board_elf, 'fw_mark_frame_end'):#x},out={counts}")
    board = Board(ARM / "display-board.bin", f"--frames {frames}", tmp=tmp, plugin=plugin)
    try:
        snd = sender(fw_elf, board.tcp_port, f"--frames {frames} --acks on" + (" --flat" if flat else ""))
        board.wait_for(r"board: done:[^\n]*\n", 600)
        sent = finish_sender(snd, frames)
        board.qmp("quit")
        board.wait(60)
    finally:
        board.kill()
    shown = frames_of(board.text)
    if len(shown) != frames:
        sys.exit(f"bench_board: the board showed {len(shown)} of {frames} frames:\n{board.text}")
    rows = [line.split() for line in counts.read_text().splitlines() if not line.startswith("#")]
    per_seg = [int(r[1]) for r in rows]  # begin..end of each marked message
    key = [per_seg[f["seg"]] for f in shown if f["key"]]
    delta = [per_seg[f["seg"]] for f in shown if not f["key"]]
    every = key + delta
    summary = board.text[board.text.index("board: done:"):].splitlines()[0]
    return dict(sent=[l for l in sent.splitlines() if "link:" in l][0], frames=frames, median=statistics.median(every), max=max(every),
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
    for flat in (False, True):
        r = run_case(fw_out / "firmware.elf", a.frames, flat, tmp)
        lines.append(f"| {'flat' if flat else 'textured'} | {r['frames']} | {r['keys']} | {r['median']:,.0f} | "
                     f"{r['max']:,} | {r['key_median']:,.0f} | {r['delta_median']:,.0f} | "
                     f"{HZ / r['median']:.1f} | {HZ / r['max']:.1f} |")
        print(r["sent"], file=sys.stderr)
        print(r["summary"], file=sys.stderr)
    text = "\n".join(lines) + "\n"
    print(text)
    Path(a.out).write_text(text)


if __name__ == "__main__":
    main()
