#!/usr/bin/env python3
"""capture.py - capture frames from the frame link over a serial port (pyserial).

    tools/capture.py --port URL --frames N --out DIR [--baud B] [--timeout S] [--no-png]

URL is anything pyserial opens: a device (/dev/ttyUSB0), a pty (/dev/pts/3), or a TCP socket
(socket://127.0.0.1:5555). The stream is decoded by tools/framelink.py, the Python twin of the
C decoder: acks and keyframe requests go back on the same port, and a frame is kept only if it
passed every check (its message CRC, and its rebuilt pixels against the CRC-32 the sender put in
it). Writes, in DIR:

    frame_NNNNN.png   each frame (8-bit palette PNG: the palette indices survive exactly)
    frames.jsonl      one JSON object per frame: its number, CRC-32, whether it was a keyframe,
                      the camera exactly as the firmware used it (x, y, z and angle as exact
                      decimals of their 16.16 values, look in pixels; raw 16.16 integers too),
                      the render and present modes, and `render_args`: the arguments that make
                      build/render reproduce the frame bit for bit, and `stream_end`: the bytes
                      received from the start of the stream up to and including the delimiter
                      that ended the frame's message (where it was accepted)
    summary.json      the decoder's counters, frames_captured, and frames_no_palette: frames that
                      passed every check before any palette came, which are not captured (there
                      are no true colours for them; the decoder asks the sender for the palette)

Exits 0 when N frames were captured, 1 when the stream ended or went quiet first.
"""
import argparse
import json
import os
import struct
import sys
import time
import zlib
from fractions import Fraction
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import framelink  # noqa: E402

MODES = ["spans", "painter", "direct"]  # render.h's render_mode numbers
PRESENTS = ["flip", "copy8", "copy16", "copy32"]


def fx_decimal(raw):
    """The exact decimal of a 16.16 value (every such value has a finite one)."""
    v = Fraction(raw, 65536)
    sign = "-" if v < 0 else ""
    v = abs(v)
    whole = v.numerator // v.denominator
    frac = v - whole
    if frac == 0:
        return f"{sign}{whole}"
    digits = ""
    while frac:
        frac *= 10
        d = frac.numerator // frac.denominator
        digits += str(d)
        frac -= d
    return f"{sign}{whole}.{digits}"


def frame_record(ev):
    info = ev["info"]
    cam = {k: fx_decimal(info[k]) for k in ("x", "y", "z", "angle")}
    mode = MODES[info["mode"]] if info["mode"] < len(MODES) else str(info["mode"])
    present = PRESENTS[info["present"]] if info["present"] < len(PRESENTS) else str(info["present"])
    return {
        "frame": ev["frame"],
        "crc32": info["crc32"],
        "keyframe": bool(ev["keyframe"]),
        "camera": {**cam, "look": info["look"]},
        "camera_raw": {k: info[k] for k in ("x", "y", "z", "angle")},
        "mode": mode,
        "present": present,
        "render_args": ["--at", f"{cam['x']},{cam['y']},{cam['z']}", "--angle", cam["angle"],
                        "--look", str(info["look"]), "--mode", mode, "--present", present],
    }


def write_png(path, pixels, palette, width=framelink.W, height=framelink.H):
    """8-bit palette PNG (colour type 3)."""
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    raw = b"".join(b"\x00" + bytes(pixels[y * width:(y + 1) * width]) for y in range(height))
    data = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 3, 0, 0, 0)) +
            chunk(b"PLTE", bytes(palette)) + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
    Path(path).write_bytes(data)


def feed_at(dec, data):
    """Feed `data` to the decoder; yield (event, offset) for each event, offset the stream's byte
    count just past the delimiter that completed the event's message (events happen only at
    delimiters, so the data is fed a segment at a time)."""
    start = 0
    while start < len(data):
        z = data.find(b"\0", start)
        end = len(data) if z < 0 else z + 1
        evs = dec.feed(data[start:end])
        for ev in evs:
            yield ev, dec.counters["bytes"]
        start = end


def capture(port, frames, out, png=True, timeout=10.0, log=sys.stderr):
    """Capture `frames` frames from an open pyserial port into `out`; returns the counters."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    dec = framelink.Decoder(back=port.write)
    palette = None  # none yet: frames before the first palette are not captured (no true colours)
    no_palette = 0
    got = 0
    last = time.monotonic()
    import serial  # pyserial
    with open(out / "frames.jsonl", "w") as jl:
        while got < frames:
            try:
                data = port.read(4096)
            except serial.SerialException:  # the other end closed the port: the stream ended
                print(f"capture: the stream ended after {got} frames", file=log)
                break
            if not data:
                if time.monotonic() - last > timeout:
                    print(f"capture: nothing received for {timeout:g} s after {got} frames", file=log)
                    break
                continue
            last = time.monotonic()
            for ev, at in feed_at(dec, data):
                if ev["event"] == "palette":
                    palette = ev["palette"]
                elif ev["event"] == "frame" and got < frames and palette is None:
                    if no_palette == 0:
                        print(f"capture: frame {ev['frame']} arrived before any palette: frames are not "
                              "captured until a palette arrives", file=log)
                    no_palette += 1
                elif ev["event"] == "frame" and got < frames:
                    rec = frame_record(ev)
                    rec["stream_end"] = at
                    if png:
                        write_png(out / f"frame_{ev['frame']:05d}.png", ev["pixels"], palette)
                    jl.write(json.dumps(rec) + "\n")
                    jl.flush()
                    got += 1
                    if got % 25 == 0:
                        print(f"capture: {got}/{frames} frames", file=log, flush=True)
    summary = dict(dec.counters, frames_captured=got, frames_no_palette=no_palette)
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    return summary


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="See the module docstring (tools/capture.py) for the output files.")
    ap.add_argument("--port", required=True, help="pyserial URL: /dev/ttyX, /dev/pts/N, socket://HOST:PORT")
    ap.add_argument("--frames", type=int, required=True, help="frames to capture")
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--baud", type=int, default=115200, help="serial speed (default 115200)")
    ap.add_argument("--timeout", type=float, default=10.0, help="give up after this many quiet seconds")
    ap.add_argument("--no-png", action="store_true", help="write frames.jsonl only")
    a = ap.parse_args(argv)
    import serial  # pyserial
    try:
        port = serial.serial_for_url(a.port, baudrate=a.baud, timeout=0.2)
    except (serial.SerialException, ValueError) as e:
        print(f"capture: {a.port}: {e}", file=sys.stderr)
        return 1
    try:
        s = capture(port, a.frames, a.out, png=not a.no_png, timeout=a.timeout)
    finally:
        port.close()
    print(f"capture: {s['frames_captured']} frames to {a.out}; counters {json.dumps(s)}", file=sys.stderr)
    return 0 if s["frames_captured"] >= a.frames else 1


if __name__ == "__main__":
    sys.exit(main())
