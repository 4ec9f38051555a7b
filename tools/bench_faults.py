#!/usr/bin/env python3
"""make bench-faults: the firmware under QEMU streams its fly-through over TCP through a relay that
damages the stream (bit flips, dropped bytes, truncated messages in equal shares) at several rates
per byte; tools/capture.py receives it. Each rate is RUNS fly-throughs (a QEMU run each, the relay
seeded differently each time), summed. Per rate: frames sent (as the firmware reports), frames
accepted, frames dropped, bad messages, resynchronisations, keyframe requests sent by the receiver
and heard by the firmware; the outages (from the first damaged byte after an accepted frame to the
next accepted frame: tests/linkrig.py outages()) with the frames lost in each and the
resynchronisation time, the bytes the receiver took from the first damaged byte until it accepted
an intact frame again as time on a 115,200 8N1 link (11,520 bytes/s), both measured from the
relay's damage offsets and the capture's accept offsets; the runs in which the firmware stopped
hearing the receiver (the back direction is relayed intact); and the figure that matters: damaged
frames accepted (a frame accepted under a number whose CRC-32 differs from the clean run's).
A benchmark: it prints figures (the table also to build/bench-faults.md, every run's figures,
damage offsets and outages to build/bench-faults.json), asserts nothing
(tests/test_capture.py does).

    tools/bench_faults.py [--runs N] [--rates 0,R,...] [--elf FIRMWARE] [--json FILE]
    tools/bench_faults.py --from-json build/bench-faults.json    (the tables again, from a saved run)
"""
import argparse
import io
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tools"))
import serial  # noqa: E402

import capture  # noqa: E402
from linkrig import LINK_BYTES_PER_S, FaultyRelay, Firmware, firmware_link, outages  # noqa: E402

FRAMES = 204  # the default camera path: beyond it the firmware stands still (identical frames)
RUNS = 5
RATES = [0, 1e-5, 1e-4, 1e-3, 1e-2]


def run(rate, seed, out, elf=None):
    fw = Firmware("tcp", f"--frames {FRAMES} --linger 1000 --acks on", elf=elf)
    relay = FaultyRelay(int(fw.port.rsplit(":", 1)[1]), rate, seed=seed)
    port = serial.serial_for_url(relay.port, baudrate=115200, timeout=0.2)
    try:
        s = capture.capture(port, FRAMES, out, png=False, timeout=15, log=io.StringIO())
    finally:
        port.close()
    fw.wait(timeout=300)
    fw.kill()
    relay.join()
    recs = [json.loads(line) for line in (out / "frames.jsonl").read_text().splitlines()]
    return s, recs, relay, firmware_link_of(fw)


def firmware_link_of(fw):
    link = firmware_link("".join(fw.log))
    if not link:
        sys.exit("bench-faults: the firmware did not report its link figures:\n" + "".join(fw.log))
    return link


def median(xs):
    xs = sorted(xs)
    n = len(xs)
    return None if not n else (xs[n // 2] if n % 2 else (xs[n // 2 - 1] + xs[n // 2]) / 2)


def fmt(v):
    """A count or a median of counts (a half shows as .5), or milliseconds (whole)."""
    if isinstance(v, float) and v * 2 == int(v * 2) and v < 1000:
        return f"{v:g}"
    return f"{round(v):,}"


def outage_cells(outs):
    """The table's cells for a list of outages: their number (and how many were still open when
    the run ended), frames lost and resync time as median / max over those that ended."""
    closed = [o for o in outs if o["end"] is not None]
    still = len(outs) - len(closed)
    lost = [o["frames_lost"] for o in closed]
    ms = [o["ms"] for o in closed]
    n_out = f"{len(outs)}" + (f" ({still} open at the end)" if still else "")
    lost_s = f"{fmt(median(lost))} / {fmt(max(lost))}" if lost else "-"
    ms_s = f"{round(median(ms)):,} / {round(max(ms)):,} ms" if ms else "-"
    return n_out, lost_s, ms_s


def tables(rates, detail):
    """The two Markdown tables (all runs; the outages of the runs whose back channel held)."""
    lines = ["| damage rate per byte | damage events | frames sent | accepted | dropped | bad messages | resyncs "
             "| keyframe requests sent / heard | outages | frames lost per outage, median / max "
             "| resync time, median / max | back channel stalled | damaged frames accepted |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for rate in rates:
        runs = [r for r in detail if r["rate"] == rate]

        def tot(part, key=None):
            return sum((r[part][key] if key else (len(r[part]) if part == "damage" else r[part])) for r in runs)
        n_out, lost_s, ms_s = outage_cells([o for r in runs for o in r["outages"]])
        lines.append(f"| {rate:g} | {tot('damage'):,} | {tot('firmware', 'frames_sent'):,} | {tot('accepted'):,} "
                     f"| {tot('receiver', 'frames_dropped'):,} | {tot('receiver', 'msgs_bad'):,} "
                     f"| {tot('receiver', 'resyncs'):,} "
                     f"| {tot('receiver', 'keyreqs_sent'):,} / {tot('firmware', 'keyreqs_heard'):,} "
                     f"| {n_out} | {lost_s} | {ms_s} | {tot('back_channel_stalled')} of {len(runs)} runs "
                     f"| {tot('damaged_accepted')} |")
    lines += ["", "The outages of the runs whose back channel held (the firmware heard every ack and request):", "",
              "| damage rate per byte | runs | outages | frames lost per outage, median / max "
              "| resync time, median / max |", "|---|---|---|---|---|"]
    for rate in rates:
        held = [r for r in detail if r["rate"] == rate and not r["back_channel_stalled"]]
        n_out, lost_s, ms_s = outage_cells([o for r in held for o in r["outages"]])
        lines.append(f"| {rate:g} | {len(held)} | {n_out} | {lost_s} | {ms_s} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=RUNS, help=f"fly-throughs per rate (default {RUNS})")
    ap.add_argument("--rates", default=",".join(f"{r:g}" for r in RATES), help="damage rates per byte (0 first)")
    ap.add_argument("--elf", help="the firmware to run (default build/arm/firmware.elf)")
    ap.add_argument("--json", default=str(ROOT / "build" / "bench-faults.json"),
                    help="every run's figures, damage offsets and outages (default build/bench-faults.json)")
    ap.add_argument("--from-json", metavar="FILE", help="run nothing: print the tables of a run's --json file")
    a = ap.parse_args(argv)
    if a.from_json:
        saved = json.loads(Path(a.from_json).read_text())
        print(tables(saved["rates"], saved["runs_detail"]))
        return
    rates = [float(r) for r in a.rates.split(",")]
    if rates[0] != 0:
        sys.exit("bench-faults: the first rate must be 0 (the clean run gives each frame's true CRC-32)")
    t0 = time.monotonic()
    detail = []
    with tempfile.TemporaryDirectory() as tmp:
        truth = None
        for rate in rates:
            for k in range(a.runs):
                seed = 11 + k
                s, recs, relay, link = run(rate, seed, Path(tmp) / f"r{rate}-{k}", a.elf)
                if truth is None:
                    truth = {r["frame"]: r["crc32"] for r in recs}
                damaged = sum(1 for r in recs if truth.get(r["frame"]) != r["crc32"])
                o = outages([d for d, _ in relay.damage], [(r["stream_end"], r["frame"]) for r in recs],
                            link["frames_sent"])
                # the back direction is relayed intact: a firmware that heard fewer acks than the
                # receiver sent stopped hearing it (and so answered no keyframe request after that)
                stalled = link["acks_heard"] < s["acks_sent"]
                detail.append({"rate": rate, "seed": seed, "accepted": len(recs), "damaged_accepted": damaged,
                               "back_channel_stalled": stalled, "firmware": link, "receiver": s,
                               "relay": {"bytes_to_receiver": relay.sent, "bytes_back": relay.back},
                               "damage": relay.damage, "outages": o})
                print(f"bench-faults: rate {rate:g} run {k + 1}/{a.runs}: {len(recs)}/{link['frames_sent']} frames "
                      f"accepted, {relay.events} damage events, {len(o)} outages"
                      f"{', back channel stalled' if stalled else ''} ({time.monotonic() - t0:.0f} s)",
                      file=sys.stderr, flush=True)
    text = tables(rates, detail)
    took = time.monotonic() - t0
    (ROOT / "build" / "bench-faults.md").write_text(text)
    Path(a.json).write_text(json.dumps({"runs": a.runs, "rates": rates, "link_bytes_per_s": LINK_BYTES_PER_S,
                                        "runs_detail": detail}) + "\n")
    print(text)
    print(f"bench-faults: {len(rates)} rates x {a.runs} runs of the {FRAMES}-frame fly-through in {took:.0f} s",
          file=sys.stderr)


if __name__ == "__main__":
    main()
