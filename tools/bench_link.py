#!/usr/bin/env python3
"""bench_link.py - how many bytes a frame costs on the frame link, and what the encoder costs.

For a fly-through of freedoom2.wad:MAP01 (build/fltool walk: the firmware's own camera and
collision, 20 frames per second, an autopilot following the corridors from the player start;
or any file of raw 64,000-byte frames given with --raw), it reports:

  * the mean bytes per frame on the wire (COBS, header, frame information, CRC: everything the
    UART carries) with a keyframe every N frames, for several N, beside raw (64,000) and zlib
    at level 9 - on each frame alone, and on each frame XORed with the frame before (the first
    frame alone) - and the frames per second 115,200 baud (8N1: 11,520 bytes/s) carries;
  * the encoder's instructions per frame on x86-64 (callgrind: fltool bench with --repeat 3
    minus --repeat 1, halved; the whole fl_enc_frame: scan, coding, frame check, COBS, message
    CRC), and what a pixel CRC-32 of the 64,000 bytes (firmware/crc32.c, fl_frame_info.crc) would
    add: the firmware does not send one (no_crc), the frame check in every frame message protects
    the frame end to end;
  * the sending side's cost on the Cortex-M3, per frame of the textured and of the flat walk:
    the encoder with its frame check (QEMU mps2-an385 with build/insn_count.so, tools/flbench_m3:
    the frames in slices of 40, each slice starting with a keyframe, checked to send the very
    bytes the host encoder sends) beside the render of the same camera by the rendering
    firmware (make firmware SCENE=... into build/bench-link/fw, default modes and stream: run
    with --at/--angle/--look of the frame's camera, --frames 2 --no-stream --no-tick, the second
    frame's count between fw_mark_frame_begin and fw_mark_frame_end, as tools/qemu_plugin/
    bench_m3.py counts), and their ratio against the goal of issue 18 (at most 10%);
  * the renderer's instructions per frame on x86-64 for a sample of the same frames (build/render
    with each frame's camera, --repeat 3 minus --repeat 1, halved), for the ratio;
  * textured against flat: the walk draws a WAD map textured (the tables above are of those
    frames); the same walk again with --flat (the same cameras), and for each the bytes per frame
    as the host sends them (the COPY coding with its match finder) and as the firmware does
    (without one), against zlib -9 of each frame alone (issue 27's goal: at most 0.6 x), and the
    frames per second that 115,200 baud, 1 Mbaud and 4 Mbaud (8N1) and USB full speed carry.

Usage: bench_link.py [--raw FRAMES.raw] [--frames 200] [--out build/bench-link.md] [--no-m3]
                     [--m3-every K] [--jobs 2]
(make bench-link).
"""
import argparse
import concurrent.futures
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import zlib
from decimal import Decimal
from pathlib import Path

import armelf

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"
FRAME = 64000
BAUD_BYTES = 115200 // 10
FIRMWARE_SCRATCH = 8192     # hal/mps2/stream_fl.c's SCRATCH_BYTES
# (name, payload bytes per second): a UART at 8N1 carries baud / 10 bytes; USB full speed (12 Mbit/s)
# at most 19 bulk packets of 64 bytes per 1 ms frame, its ceiling for a CDC serial port
LINKS = [("115,200 baud", 115200 // 10), ("1 Mbaud", 1_000_000 // 10), ("4 Mbaud", 4_000_000 // 10),
         ("USB full speed (12 Mbit/s, bulk)", 19 * 64 * 1000)]


def sh(args, **kw):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, check=True, **kw)


def callgrind(args):
    """Instructions executed by a program under callgrind."""
    proc = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null"] + [str(a) for a in args],
                          capture_output=True, text=True, check=True)
    m = re.search(r"Collected\s*:\s*(\d+)", proc.stderr)
    if not m:
        raise RuntimeError(proc.stderr[-2000:])
    return int(m.group(1))


def link_sizes(fltool, raw, info, palette, key_interval, tmp, scratch=None, match_finder=True):
    stream = tmp / f"stream_k{key_interval}.bin"
    args = [fltool, "encode", raw, "--out", stream, "--key-interval", key_interval, "--sizes"]
    if scratch:
        args += ["--scratch", scratch]
    if not match_finder:
        args += ["--no-match-finder"]
    if info:
        args += ["--info", info]
    if palette:
        args += ["--palette", palette]
    out = sh(args).stdout
    sizes = [json.loads(l) for l in out.splitlines()]
    total = stream.stat().st_size
    return sizes, total - sum(s["bytes"] for s in sizes)


def m3_counts(frames_raw, n, fltool):
    """Encoder and CRC instructions per frame on the Cortex-M3, in slices of 40 frames."""
    bench = BUILD / "flbench"
    bench.mkdir(parents=True, exist_ok=True)
    plugin = BUILD / "insn_count.so"
    enc, crc = [], []
    for start in range(0, n, 40):
        count = min(40, n - start)
        (bench / "frames.raw").write_bytes(frames_raw[start * FRAME:(start + count) * FRAME])
        sh(["make", "-s", "--no-print-directory", "build/flbench/m3.elf"], cwd=ROOT)
        elf = bench / "m3.elf"
        addr = {name: f"{a:#x}" for name, (a, _) in armelf.symbols(elf).items()}
        out = bench / "insns.txt"
        proc = subprocess.run(["qemu-system-arm", "-M", "mps2-an385", "-nographic", "-monitor", "none", "-serial",
                               "null", "-semihosting-config", "enable=on,target=native", "-kernel", str(elf), "-plugin",
                               f"{plugin},begin={addr['fl_mark_begin']},end={addr['fl_mark_end']},out={out}"],
                              capture_output=True, text=True, timeout=600)
        if proc.returncode != 0:
            raise RuntimeError(proc.stderr)
        said = [l for l in (proc.stdout + proc.stderr).splitlines() if l.startswith("stream bytes")]
        host = sh([fltool, "digest", bench / "frames.raw"]).stdout.strip()
        if said != [host]:
            raise RuntimeError(f"the Cortex-M3 sent other bytes than the host: {said} vs {host}")
        rows = [l.split() for l in out.read_text().splitlines() if l and not l.startswith("#")]
        counts = [int(r[1]) for r in rows]
        enc += counts[:count]
        crc += counts[count:2 * count]
    return enc, crc


MODE_NAMES = {0: "spans", 1: "painter", 2: "direct", 3: "columns"}  # firmware/render.c: mode_names, by number


def firmware_elf(scene):
    """The rendering firmware for scene, as make firmware builds it (default modes, frame-link stream)."""
    out = BUILD / "bench-link" / "fw"
    sh(["make", "-s", "--no-print-directory", "firmware", f"SCENE={scene}", f"ARM_OUT={out}"], cwd=ROOT)
    return out / "firmware.elf"


def m3_render(elf, lines, flat, every, jobs):
    """Cortex-M3 instructions of the firmware's frame (input, render, present; no stream) at the camera of
    every every-th line of frames.jsonl: {frame: count}."""
    syms = armelf.symbols(elf)
    plugin = (f"{BUILD / 'insn_count.so'},begin={syms['fw_mark_frame_begin'][0]:#x},"
              f"end={syms['fw_mark_frame_end'][0]:#x}")
    tmp = elf.parent / "insns"
    tmp.mkdir(exist_ok=True)

    def one(line):
        c, k = line["camera"], line["frame"]
        exact = [f"{Decimal(v):f}" for v in (c["x"], c["y"], c["z"])]  # 16.16 values: exact decimals
        args = ["--at", ",".join(exact), "--angle", f"{Decimal(c['angle']):f}", "--look", str(c["look"]),
                "--mode", MODE_NAMES[line["mode"]], "--frames", "2", "--no-stream", "--no-tick"] + \
               (["--flat"] if flat else [])
        out = tmp / f"{'flat' if flat else 'tex'}_{k}.txt"
        proc = subprocess.run(["qemu-system-arm", "-M", "mps2-an385", "-nographic", "-monitor", "none", "-serial",
                               "null", "-semihosting-config", "enable=on,target=native", "-kernel", str(elf),
                               "-plugin", f"{plugin},out={out}", "-append", " ".join(args)],
                              capture_output=True, text=True, timeout=600)
        if proc.returncode != 0:
            raise RuntimeError(f"firmware at frame {k}'s camera: {proc.stderr[-2000:]}")
        counts = [int(r.split()[1]) for r in out.read_text().splitlines() if r and not r.startswith("#")]
        return k, counts[-1]

    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        return dict(pool.map(one, lines[::every]))


def cost_rows(walks, enc, render):
    """Per walk: the encoder (with its frame check) against the render of the same frames, and the goal."""
    out = ["| frames | M3 render (median / max) | M3 encoder + frame check (median / max) | "
           "encoder / render (median / worst frame) | goal: at most 10% |",
           "|---|---:|---:|---:|---|"]
    verdicts = []
    for name, _ in walks:
        r = render[name]
        e = {k: enc[name][k] for k in r}
        ratios = [e[k] / r[k] for k in r]
        med = statistics.median(ratios)
        worst = max(r, key=lambda k: e[k] / r[k])
        if med <= 0.10:
            verdict = f"met: {(0.10 - med) * 100:.1f} points under"
        else:
            verdict = (f"missed by {(med - 0.10) * 100:.1f} points (the encoder would need "
                       f"{fmt(statistics.median(e.values()) - 0.10 * statistics.median(r.values()))} fewer "
                       f"instructions a frame at the medians)")
        verdicts.append(f"- {name}: {verdict}; worst frame {worst}: {e[worst] / r[worst] * 100:.1f}% "
                        f"({fmt(e[worst])} of {fmt(r[worst])}).")
        out.append(f"| {name} | {fmt(statistics.median(r.values()))} / {fmt(max(r.values()))} | "
                   f"**{fmt(statistics.median(e.values()))}** / {fmt(max(e.values()))} | **{med * 100:.1f}%** / "
                   f"{max(ratios) * 100:.1f}% | {'met' if med <= 0.10 else 'missed'} |")
    return out, verdicts


def render_cost(render, scene, lines, sample):
    """x86 instructions of build/render per frame for a sample of the walk's cameras."""
    costs = []
    for l in lines[::max(1, len(lines) // sample)][:sample]:
        c = l["camera"]
        cam = ["--at", f"{c['x']},{c['y']},{c['z']}", "--angle", str(c["angle"]), "--look", str(c["look"])]
        one = callgrind([render, scene, *cam, "--repeat", 1])
        three = callgrind([render, scene, *cam, "--repeat", 3])
        costs.append((three - one) / 2)
    return costs


SENDERS = [("host (build/emu, build/render: COPY with its match finder)", True),
           ("firmware (hal/mps2/stream_fl.c: COPY without one)", False)]


def textured_rows(fltool, walks, tmp):
    """Per walk (name, DIR of fltool walk) and sender: (walk, sender, mean bytes per frame, max,
    zlib -9 of each frame alone) with a keyframe every 64 frames and the firmware's scratch."""
    rows = []
    for name, d in walks:
        raw = (d / "frames.raw").read_bytes()
        alone = statistics.mean(len(zlib.compress(raw[k:k + FRAME], 9)) for k in range(0, len(raw), FRAME))
        for who, mf in SENDERS:
            sizes, _ = link_sizes(fltool, d / "frames.raw", d / "frames.jsonl", d / "palette.bin", 64, tmp,
                                  FIRMWARE_SCRATCH, mf)
            b = [s["bytes"] for s in sizes]
            rows.append((name, who, statistics.mean(b), max(b), alone))
    return rows


def textured_table(rows, n, scene):
    out = [f"## Textured and flat frames: {n} frames of the fly-through of {scene}\n",
           "The same walk (the same cameras) drawn textured (fltool walk's default for a WAD map) and with --flat. "
           f"Keyframe every 64 frames, the firmware's {FIRMWARE_SCRATCH:,}-byte scratch (flat frames are "
           "edge-coded in it; textured frames go with the COPY coding, streamed). Frames per second: the link's "
           "bytes per second over the mean bytes per frame (8N1 UARTs carry baud / 10 bytes per second; USB full "
           "speed at most 19 bulk packets of 64 bytes per millisecond, 1,216,000 bytes per second).\n",
           "| frames | sender | mean bytes/frame | max | / zlib -9 alone | " +
           " | ".join(f"fps at {name}" for name, _ in LINKS) + " |",
           "|---|---|---:|---:|---:|" + "---:|" * len(LINKS)]
    for name, who, mean, mx, alone in rows:
        out.append(f"| {name} | {who} | **{mean:,.0f}** | {fmt(mx)} | {mean / alone:.2f} | " +
                   " | ".join(f"{bps / mean:.1f}" for _, bps in LINKS) + " |")
    tex = [r for r in rows if "flat" not in r[0]]
    flat = [r for r in rows if "flat" in r[0]]
    out.append("")
    for name, who, mean, _, alone in tex:
        out.append(f"- Goal (issue 27): textured frames at most 0.6 x zlib -9 of each frame alone "
                   f"({0.6 * alone:,.0f} bytes): {who.split(' (')[0]} {mean:,.0f}, {mean / alone:.2f} x zlib: "
                   f"{'met' if mean <= 0.6 * alone else 'missed'}.")
    for name, who, mean, _, _ in flat:
        out.append(f"- Goal (issue 27): flat frames at most 265 bytes: {who.split(' (')[0]} {mean:,.0f}: "
                   f"{'met' if mean <= 265 else 'missed'}.")
    return out


def fmt(n):
    return f"{n:,.0f}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--raw", help="raw frames (64,000 bytes each) instead of a MAP01 walk")
    ap.add_argument("--info", help="frames.jsonl for --raw (cameras)")
    ap.add_argument("--scene", default="freedoom2.wad:MAP01")
    ap.add_argument("--frames", type=int, default=200, help="frames of the walk (default 200)")
    ap.add_argument("--out", default=str(BUILD / "bench-link.md"))
    ap.add_argument("--no-m3", action="store_true", help="skip the Cortex-M3 counts")
    ap.add_argument("--no-callgrind", action="store_true", help="skip the x86 instruction counts")
    ap.add_argument("--render-sample", type=int, default=8, help="walk frames whose x86 render cost is measured")
    ap.add_argument("--m3-every", type=int, default=1, metavar="K",
                    help="render every K-th walk frame on the Cortex-M3 for the ratio (default 1: all)")
    ap.add_argument("-j", "--jobs", type=int, default=2, help="QEMU runs at once (default 2)")
    a = ap.parse_args(argv)

    fltool = BUILD / "fltool"
    work = BUILD / "bench-link"
    work.mkdir(parents=True, exist_ok=True)
    lines, palette = [], None
    walks = []
    if a.raw:
        raw_path, info = Path(a.raw), a.info
    else:
        sh([fltool, "walk", a.scene, "--frames", a.frames, "--out", work])
        (work / "flat").mkdir(exist_ok=True)
        sh([fltool, "walk", a.scene, "--frames", a.frames, "--out", work / "flat", "--flat"])
        walks = [("textured", work), ("flat (--flat)", work / "flat")]
        raw_path, info, palette = work / "frames.raw", work / "frames.jsonl", work / "palette.bin"
    if info:
        lines = [json.loads(l) for l in Path(info).read_text().splitlines()]
    raw = raw_path.read_bytes()
    n = len(raw) // FRAME
    frames = [raw[k * FRAME:(k + 1) * FRAME] for k in range(n)]

    # ---- bytes ------------------------------------------------------------------------
    alone = [len(zlib.compress(f, 9)) for f in frames]
    xored = [alone[0]] + [len(zlib.compress(bytes(x ^ y for x, y in zip(frames[k], frames[k - 1])), 9))
                          for k in range(1, n)]
    rows = []
    for ki in (64, 16, 8, 1, 0):
        sizes, once = link_sizes(fltool, raw_path, info, palette, ki, work)
        b = [s["bytes"] for s in sizes]
        keys = [s["bytes"] for s in sizes if s["type"] == "key"]
        rows.append((ki, statistics.mean(b), max(b), len(keys), statistics.mean(keys) if keys else 0, once))
    mean64 = rows[0][1]

    out = []
    out.append(f"# Frame link: {n} frames of {'a fly-through of ' + a.scene if not a.raw else raw_path}\n")
    if walks:
        out.append("The frames as fltool walk draws them: textured for a WAD map (the flat walk: the last section).\n")
    out.append("Bytes per frame on the wire (everything the UART carries for a frame message: COBS, header, "
               "frame information, frame check, CRC), beside raw frames and zlib at level 9; frames per second "
               "at 115,200 baud (8N1, 11,520 bytes/s).\n")
    out.append("| coding | mean bytes/frame | max | keyframes (mean bytes) | fps at 115,200 baud |")
    out.append("|---|---|---|---|---|")
    out.append(f"| raw frames | {fmt(FRAME)} | {fmt(FRAME)} | - | {BAUD_BYTES / FRAME:.2f} |")
    out.append(f"| zlib -9, each frame alone | {fmt(statistics.mean(alone))} | {fmt(max(alone))} | - | "
               f"{BAUD_BYTES / statistics.mean(alone):.1f} |")
    out.append(f"| zlib -9, each frame XOR the one before | {fmt(statistics.mean(xored))} | {fmt(max(xored))} | - | "
               f"{BAUD_BYTES / statistics.mean(xored):.1f} |")
    for ki, mean, mx, nk, mk, once in rows:
        what = {0: "keyframe only when needed", 1: "every frame a keyframe"}.get(ki, f"keyframe every {ki}")
        out.append(f"| frame link, {what} | **{mean:,.1f}** | {fmt(mx)} | {nk} ({fmt(mk)}) | {BAUD_BYTES / mean:.1f} |")
    out.append(f"\nOnce per stream: hello and palette, {rows[0][5]} bytes. Goal: at most about 570 bytes per frame "
               f"(20 fps) and no more than zlib -9: the link needs {mean64 / statistics.mean(xored) * 100:.0f}% of zlib "
               f"on the XOR and {mean64 / statistics.mean(alone) * 100:.0f}% of zlib on frames alone.\n")

    # ---- instructions --------------------------------------------------------------------
    if not a.no_callgrind and shutil.which("valgrind"):
        one = callgrind([fltool, "bench", raw_path, "--repeat", 1])
        three = callgrind([fltool, "bench", raw_path, "--repeat", 3])
        enc = (three - one) / (2 * n)
        one_c = callgrind([fltool, "bench", raw_path, "--repeat", 1, "--crc"])
        three_c = callgrind([fltool, "bench", raw_path, "--repeat", 3, "--crc"])
        crc = (three_c - one_c) / (2 * n) - enc
        out.append("Instructions per frame on x86-64 (the encoder: fl_enc_frame, everything from the pixels to "
                   "the bytes handed to the UART, the frame check included: row hashes of a coded frame, the word "
                   "hash of a raw one (RAW_HASH); a pixel CRC-32, crc_update over the 64,000 bytes for "
                   "fl_frame_info.crc, is what a sender would add to send one: the firmware does not, it sets "
                   "no_crc):\n")
        out.append("| where | encoder + frame check | pixel CRC-32 (not sent) | renderer (direct) | encoder / renderer |")
        out.append("|---|---|---|---|---|")
        rend = render_cost(BUILD / "render", a.scene, lines, a.render_sample) if lines and not a.raw else []
        rmed = statistics.median(rend) if rend else 0
        ratio = f"{enc / rmed * 100:.1f}%" if rmed else "-"
        out.append(f"| x86-64 (callgrind, textured) | **{fmt(enc)}** | {fmt(crc)} | {fmt(rmed) if rmed else '-'} "
                   f"(median of {len(rend)} frames) | {ratio} |")
    if not a.no_m3 and shutil.which("qemu-system-arm") and (BUILD / "insn_count.so").exists():
        sets = walks or [("frames", None)]
        enc3, crc3, rend3 = {}, {}, {}
        for name, d in sets:
            data = raw if d is None else (d / "frames.raw").read_bytes()
            e3, c3 = m3_counts(data, n, fltool)
            enc3[name] = dict(enumerate(e3))
            crc3[name] = c3
        out.append(f"\n## The sending side's cost on the Cortex-M3\n")
        out.append("Instructions per frame on the Cortex-M3 (QEMU mps2-an385, build/insn_count.so). Encoder + frame "
                   "check: fl_enc_frame in tools/flbench_m3 (the firmware's 8,192-byte scratch, keyframe every 64, "
                   "no_crc as the firmware sends; the frames in slices of 40, each starting with a keyframe; bytes "
                   "handed to the UART are counted, not sent), which sent exactly the bytes the host encoder sends. "
                   "Render: the rendering firmware as make firmware builds it for the scene (build/bench-link/fw), "
                   "run at the frame's camera (--at, --angle, --look, the walk's render mode, --flat for the flat "
                   "walk, --frames 2 --no-stream --no-tick), the second frame's instructions between its frame "
                   "markers (input, render, present: as tools/qemu_plugin/bench_m3.py counts). The firmware renders "
                   "things from their initial state; the walk's things may have moved on by a frame.\n")
        if walks and lines:
            elf = firmware_elf(a.scene)
            for name, d in walks:
                rend3[name] = m3_render(elf, lines[:n], "flat" in name, a.m3_every, a.jobs)
            sample = (f"every frame ({n})" if a.m3_every == 1 else
                      f"every {a.m3_every}th frame ({len(rend3[walks[0][0]])} of {n}; --m3-every)")
            out.append(f"Frames compared: {sample}.\n")
            rows, verdicts = cost_rows(walks, enc3, rend3)
            out += rows
            out.append("\nGoal (issue 18): encoder plus frame check at most 10% of the frame's render, judged on the "
                       "median over the frames of the per-frame ratio:\n")
            out += verdicts
        else:
            for name, _ in sets:
                e = list(enc3[name].values())
                out.append(f"- {name}: encoder + frame check median {fmt(statistics.median(e))}, max {fmt(max(e))}")
        c_all = [c for v in crc3.values() for c in v]
        out.append(f"\nA pixel CRC-32 (not sent by the firmware) would add {fmt(statistics.mean(c_all))} a frame.")
    if walks:
        out.append("")
        out += textured_table(textured_rows(fltool, walks, work), n, a.scene)
    text = "\n".join(out) + "\n"
    Path(a.out).write_text(text)
    print(text)


if __name__ == "__main__":
    sys.exit(main())
