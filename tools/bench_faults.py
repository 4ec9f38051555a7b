#!/usr/bin/env python3
"""make bench-faults: the firmware under QEMU streams its fly-through over TCP through a relay that
damages the stream (bit flips, dropped bytes, truncated messages in equal shares) at several rates
per byte; tools/capture.py receives it. Per rate: frames sent, frames accepted, frames dropped, bad
messages, resynchronisations, keyframe requests, and the figure that matters: damaged frames
accepted (a frame accepted under a number whose CRC-32 differs from the clean run's). A benchmark:
it prints figures, asserts nothing (tests/test_capture.py does)."""
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tools"))
import serial  # noqa: E402

import capture  # noqa: E402
from linkrig import FaultyRelay, Firmware  # noqa: E402

FRAMES = 204
RATES = [0, 1e-5, 1e-4, 1e-3, 1e-2]


def run(rate, tmp):
    fw = Firmware("tcp", f"--frames {FRAMES} --linger 1000 --acks on", tmp=tmp)
    relay = FaultyRelay(int(fw.port.rsplit(":", 1)[1]), rate, seed=11)
    port = serial.serial_for_url(relay.port, baudrate=115200, timeout=0.2)
    try:
        s = capture.capture(port, FRAMES, Path(tmp) / f"r{rate}", png=False, timeout=15,
                            log=open("/dev/null", "w"))
    finally:
        port.close()
    fw.wait(timeout=300)
    fw.kill()
    recs = [json.loads(l) for l in (Path(tmp) / f"r{rate}" / "frames.jsonl").read_text().splitlines()]
    return s, recs, relay


def main():
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        truth = None
        for rate in RATES:
            s, recs, relay = run(rate, tmp)
            if rate == 0:
                truth = {r["frame"]: r["crc32"] for r in recs}
            damaged = sum(1 for r in recs if truth.get(r["frame"]) != r["crc32"])
            rows.append((rate, relay.flips + relay.drops + relay.truncations, s, len(recs), damaged))
            print(f"bench-faults: rate {rate:g}: {len(recs)}/{FRAMES} frames accepted", file=sys.stderr, flush=True)
    lines = ["| damage rate per byte | damage events | frames sent | accepted | dropped | bad messages | resyncs "
             "| keyframe requests | damaged frames accepted |", "|---|---|---|---|---|---|---|---|---|"]
    for rate, events, s, got, damaged in rows:
        lines.append(f"| {rate:g} | {events} | {FRAMES} | {got} | {s['frames_dropped']} | {s['msgs_bad']} | "
                     f"{s['resyncs']} | {s['keyreqs_sent']} | {damaged} |")
    text = "\n".join(lines) + "\n"
    (ROOT / "build" / "bench-faults.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
