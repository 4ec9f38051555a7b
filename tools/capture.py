#!/usr/bin/env python3
"""capture.py - capture frames from the frame link over a serial port (pyserial).

    tools/capture.py --port URL --frames N --out DIR [--baud B] [--timeout S] [--no-png]
    tools/capture.py --render FRAME [--out DIR]

URL is anything pyserial opens: a device (/dev/ttyUSB0), a pty (/dev/pts/3), or a TCP socket
(socket://127.0.0.1:5555). The stream is decoded by tools/framelink.py, the Python twin of the
C decoder: acks and keyframe requests go back on the same port, and a frame is kept only if it
passed every check (its message CRC, and its rebuilt pixels against the CRC-32 the sender put in
it). Writes, in DIR:

    frame_NNNNN.png   each frame (8-bit palette PNG: the palette indices survive exactly)
    frames.jsonl      one JSON object per frame: its number, CRC-32, whether it was a keyframe,
                      the camera exactly as the firmware used it (x, y, z and angle as exact
                      decimals of their 16.16 values, look in pixels; raw 16.16 integers too),
                      the render and present modes, the world's time (`time_ms`: objects, doors and
                      animated textures), the scene the sender named in its hello
                      (`scene`, `scene_crc32`: the CRC-32 of its compiled blob), and `render_args`:
                      the arguments that make build/render reproduce the frame bit for bit, the
                      scene first (run from the repository's root), and `stream_end`: the bytes
                      received from the start of the stream up to and including the delimiter
                      that ended the frame's message (where it was accepted)
    summary.json      the decoder's counters, frames_captured, frames_no_palette: frames that
                      passed every check before any palette came, which are not captured (there
                      are no true colours for them; the decoder asks the sender for the palette),
                      and the scene the last hello named (`scene`, `scene_crc32`)

--render FRAME reproduces captured frame FRAME (its number) of the capture in DIR (default: the
current folder) in one command: it compiles the scene with build/bspc as the firmware build does,
warns when the blob's CRC-32 differs from the captured one (the scene changed since), renders the
frame with build/render and the frame's render_args, and compares it with the captured PNG.
Exits 0 when the pixels match, 1 when they differ or the frame cannot be rendered.

Exits 0 when N frames were captured, 1 when the stream ended or went quiet first.
"""
import argparse
import json
import os
import sys
import time
import zlib
from fractions import Fraction
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import framelink  # noqa: E402

MODES = ["spans", "painter", "direct", "columns"]  # render.h's render_mode numbers
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


def frame_record(ev, hello=None):
    """A frames.jsonl record for a frame event; hello: the session's hello event (its scene)."""
    scene = hello["scene"] if hello else ""
    info = ev["info"]
    cam = {k: fx_decimal(info[k]) for k in ("x", "y", "z", "angle")}
    mode = MODES[info["mode"]] if info["mode"] < len(MODES) else str(info["mode"])
    present = PRESENTS[info["present"]] if info["present"] < len(PRESENTS) else str(info["present"])
    t = info.get("time_ms", 0)
    return {
        "frame": ev["frame"],
        "crc32": info["crc32"],
        "keyframe": bool(ev["keyframe"]),
        "camera": {**cam, "look": info["look"]},
        "camera_raw": {k: info[k] for k in ("x", "y", "z", "angle")},
        "mode": mode,
        "present": present,
        "time_ms": t,
        "scene": scene,
        "scene_crc32": hello["scene_crc32"] if hello else "00000000",
        "render_args": ([scene] if scene else []) + ["--at", f"{cam['x']},{cam['y']},{cam['z']}", "--angle", cam["angle"],
                        "--look", str(info["look"]), "--mode", mode, "--present", present, "--time", str(t)],
    }


def write_png(path, pixels, palette, width=framelink.W, height=framelink.H):
    """8-bit palette PNG (colour type 3, unfiltered rows, the 256-entry palette as received)."""
    from PIL import Image  # only the PNG outputs need it
    im = Image.frombytes("P", (width, height), bytes(pixels[:width * height]))
    im.putpalette(bytes(palette))
    im.save(path)


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
    hello = None
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
                if ev["event"] == "hello":
                    hello = ev
                    if ev["scene"]:
                        print(f"capture: the sender draws scene {ev['scene']} (blob CRC-32 {ev['scene_crc32']})",
                              file=log)
                elif ev["event"] == "palette":
                    palette = ev["palette"]
                elif ev["event"] == "frame" and got < frames and palette is None:
                    if no_palette == 0:
                        print(f"capture: frame {ev['frame']} arrived before any palette: frames are not "
                              "captured until a palette arrives", file=log)
                    no_palette += 1
                elif ev["event"] == "frame" and got < frames:
                    rec = frame_record(ev, hello)
                    rec["stream_end"] = at
                    if png:
                        write_png(out / f"frame_{ev['frame']:05d}.png", ev["pixels"], palette)
                    jl.write(json.dumps(rec) + "\n")
                    jl.flush()
                    got += 1
                    if got % 25 == 0:
                        print(f"capture: {got}/{frames} frames", file=log, flush=True)
    summary = dict(dec.counters, frames_captured=got, frames_no_palette=no_palette,
                   scene=hello["scene"] if hello else "", scene_crc32=hello["scene_crc32"] if hello else "00000000")
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    return summary


class SocketPort:
    """socket://HOST:PORT with the part of pyserial's interface capture uses. pyserial's own socket
    handler drops what it has read when the peer closes within the same read() (a short stream
    from make run-firmware PORT=tcp:N ends that way) and discards what has arrived as it opens."""

    def __init__(self, url, timeout=0.2):
        import socket
        host, _, port = url[len("socket://"):].rpartition(":")
        self.sock = socket.create_connection((host, int(port)), timeout=10)
        self.sock.settimeout(timeout)

    def read(self, n):
        import socket
        import serial  # pyserial: its exception, as its ports raise
        try:
            data = self.sock.recv(n)
        except socket.timeout:
            return b""
        except OSError as e:
            raise serial.SerialException(str(e))
        if not data:
            raise serial.SerialException("socket disconnected")
        return data

    def write(self, data):
        try:
            self.sock.sendall(data)
        except OSError:
            pass  # the sender went away: nothing to tell it

    def close(self):
        self.sock.close()


def open_port(url, baud):
    """A port for url: a socket:// URL as SocketPort, anything else through pyserial."""
    if url.startswith("socket://"):
        return SocketPort(url)
    import serial  # pyserial
    return serial.serial_for_url(url, baudrate=baud, timeout=0.2)


ROOT = Path(__file__).resolve().parent.parent


def render_frame(out, frame, log=sys.stderr):
    """Reproduce captured frame `frame` of the capture in `out` (see --render). Returns 0 when the
    pixels build/render draws match the captured ones, 1 otherwise."""
    import subprocess
    import tempfile
    out = Path(out)
    try:
        recs = [json.loads(line) for line in (out / "frames.jsonl").read_text().splitlines() if line.strip()]
    except (OSError, ValueError) as e:
        print(f"capture: {out / 'frames.jsonl'}: {e}", file=log)
        return 1
    rec = next((r for r in recs if r["frame"] == frame), None)
    if rec is None:
        print(f"capture: frame {frame} is not in {out / 'frames.jsonl'}", file=log)
        return 1
    scene = rec.get("scene", "")
    if not scene:
        print(f"capture: frame {frame}: the sender named no scene in its hello: nothing to render it from",
              file=log)
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        # a scene spec names a file as the firmware build saw it: from the repository's root
        spec = scene
        path = scene.split(":", 1)[0] if not scene.endswith(".bsc") else scene
        if not Path(path).is_absolute() and not Path(path).exists() and (ROOT / path).exists():
            spec = str(ROOT / scene)
        bsc = Path(tmp) / "scene.bsc"
        if spec.endswith(".bsc"):
            bsc = Path(spec)
        else:  # as mk/scene.mk's scene_bsc_recipe does
            proc = subprocess.run([str(ROOT / "build/bspc"), spec, "-o", str(bsc)], capture_output=True, text=True)
            if proc.returncode != 0:
                print(f"capture: build/bspc {spec}: {proc.stderr.strip()}", file=log)
                return 1
        try:
            crc = f"{zlib.crc32(bsc.read_bytes()):08x}"
        except OSError as e:
            print(f"capture: {bsc}: {e}", file=log)
            return 1
        if crc != rec.get("scene_crc32"):
            print(f"capture: warning: {scene} compiles to a blob with CRC-32 {crc}, the capture's was "
                  f"{rec.get('scene_crc32')}: the scene (or the compiler) changed since", file=log)
        raw = Path(tmp) / "frame.raw"
        args = [str(bsc)] + rec["render_args"][1:] + ["--raw", str(raw)]
        proc = subprocess.run([str(ROOT / "build/render"), *args], capture_output=True, text=True)
        if proc.returncode != 0:
            print(f"capture: build/render {' '.join(args)}: {proc.stderr.strip()}", file=log)
            return 1
        drawn = raw.read_bytes()
    captured = read_png_pixels(out / f"frame_{frame:05d}.png")
    got = f"{zlib.crc32(drawn):08x}"
    print(f"capture: frame {frame}: build/render {' '.join(rec['render_args'])} draws CRC-32 {got}; "
          f"captured {rec['crc32']}", file=log)
    same = got == rec["crc32"] and (captured is None or captured == drawn)
    if captured is None:
        print(f"capture: no PNG of frame {frame}: compared by CRC-32 alone", file=log)
    print(f"capture: frame {frame}: {'match' if same else 'MISMATCH'}", file=log)
    return 0 if same else 1


def read_png_pixels(path):
    """The palette indices of an 8-bit palette PNG, or None if absent or not one."""
    from PIL import Image
    try:
        with Image.open(path) as im:
            return im.tobytes() if im.mode == "P" else None
    except OSError:
        return None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="See the module docstring (tools/capture.py) for the output files.")
    ap.add_argument("--port", help="pyserial URL: /dev/ttyX, /dev/pts/N, socket://HOST:PORT")
    ap.add_argument("--frames", type=int, help="frames to capture")
    ap.add_argument("--out", help="output folder (with --render: the capture's, default .)")
    ap.add_argument("--render", type=int, metavar="FRAME",
                    help="reproduce captured frame FRAME with build/render and compare (see above)")
    ap.add_argument("--baud", type=int, default=115200, help="serial speed (default 115200)")
    ap.add_argument("--timeout", type=float, default=10.0, help="give up after this many quiet seconds")
    ap.add_argument("--no-png", action="store_true", help="write frames.jsonl only")
    a = ap.parse_args(argv)
    if a.render is not None:
        return render_frame(a.out or ".", a.render)
    if not (a.port and a.frames is not None and a.out):
        ap.error("--port, --frames and --out are required to capture")
    import serial  # pyserial
    try:
        port = open_port(a.port, a.baud)
    except (serial.SerialException, ValueError, OSError) as e:
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
