#!/usr/bin/env python3
"""seeds_link.py OUTDIR - seeds for tests/fuzz/fuzz_link.c, in its input format.

Real streams: build/fltool walks tests/scenes/default.scene for 12 frames and encodes
them (as they come, with a short keyframe interval, without pixel CRC-32, and one frame
as a raw keyframe). Each frame costs the receiver milliseconds under the sanitizers, so
a seed holds a few messages of a stream: raw-mode seeds are such stretches as sent
(from the start, mid-stream without a base, in chunks, cut, with a byte damaged, after
garbage) and a receiver's acks and requests; framed-mode seeds are the messages decoded
back into type, frame number and payload (also fixed up by the harness, as whole
bodies, with a wrong frame check, after a HELLO with window 1); round-trip seeds are
short drawing-command sequences. Run from the repository root. Standard library only."""
import os
import struct
import subprocess
import sys
import tempfile
import zlib

FLTOOL = "build/fltool"
SCENE = "tests/scenes/default.scene"
FRAME_BYTES = 320 * 200

MODE_RAW, MODE_FRAMED, MODE_ROUND_TRIP = 0, 1, 2
CTL_FRAME_NO, CTL_FIXUP, CTL_PAD, CTL_NO_CRC, CTL_DAMAGE = 0x08, 0x10, 0x20, 0x40, 0x80
TYPE_BODY = 7  # framed: the payload is a whole message body


def run(*args):
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)


def cobs_decode(seg):
    out, i = bytearray(), 0
    while i < len(seg):
        code = seg[i]
        out += seg[i + 1:i + code]
        i += code
        if code != 0xFF and i < len(seg):
            out.append(0)
    return bytes(out)


def messages(stream):
    """(type, frame number, payload) of every message of a clean stream."""
    out = []
    for seg in stream.split(b"\0"):
        if not seg:
            continue
        m = cobs_decode(seg)
        n = m[6] | m[7] << 8 | m[8] << 16
        assert len(m) == 9 + n + 4, "not a clean stream"
        out.append((m[1], struct.unpack_from("<I", m, 2)[0], m[9:9 + n]))
    return out


def cobs_encode(data):
    out, block = bytearray(), bytearray()
    for b in data:
        if b == 0:
            out += bytes([len(block) + 1]) + block
            block = bytearray()
        else:
            block.append(b)
            if len(block) == 254:
                out += b"\xff" + block
                block = bytearray()
    out += bytes([len(block) + 1]) + block
    return bytes(out)


def message(typ, no, payload):
    """One message on the wire (docs/frame-link.md, sections 1 and 2)."""
    body = struct.pack("<BBI", 1, typ, no) + struct.pack("<I", len(payload))[:3] + payload
    return cobs_encode(body + struct.pack("<I", zlib.crc32(body))) + b"\0"


def segments(stream):
    """The messages of a stream as sent: COBS bytes and delimiter each."""
    return [seg + b"\0" for seg in stream.split(b"\0")[:-1] if seg]


def framed(msgs, ctl_extra=0, numbered=True, body=False):
    out = bytearray([MODE_FRAMED])
    for typ, no, payload in msgs:
        if body:  # header and payload as they were; the harness adds CRC and COBS
            hdr = struct.pack("<BBI", 1, typ, no) + struct.pack("<I", len(payload))[:3]
            payload = hdr + payload
            typ = TYPE_BODY
        ctl = typ | (CTL_FRAME_NO if numbered else 0)
        if typ in (3, 4):
            ctl |= ctl_extra
        out.append(ctl)
        if numbered:
            out += struct.pack("<I", no)
        out += struct.pack("<H", len(payload)) + payload
    return bytes(out)


def raw(stream, chunk_knob=0, chunk_seed=0):
    return bytes([MODE_RAW, chunk_knob, chunk_seed]) + stream


def round_trip(knobs, start, scratch, key_interval, frames):
    """frames: (ctl, [6-byte commands], damage or None)."""
    out = bytearray([MODE_ROUND_TRIP + 3 * knobs])
    out += struct.pack("<IHB", start, scratch, key_interval)
    for ctl, ops, damage in frames:
        ctl |= len(ops) | (0x40 if damage else 0)
        out.append(ctl)
        for op in ops:
            out += bytes(op)
        if damage:
            out += struct.pack("<HB", *damage)
    return bytes(out)


# drawing commands: kind, a, b, c, d, colour (fuzz_link.c, draw())
SKY = (6, 0, 0, 0, 0, 12)
FLOOR = (0, 0, 128, 255, 255, 40)
FLOOR_R = (0, 200, 128, 255, 255, 41)
WALL = (1, 60, 40, 8, 160, 77)
WALL2 = (1, 150, 30, 0xF8, 140, 90)
DIAMOND = (7, 128, 100, 80, 0, 200)
SCROLL_L = (3, 0xFD, 0, 0, 0, 12)
SCROLL_UP = (4, 0, 0xFE, 0, 0, 40)
NOISE = (2, 10, 10, 255, 255, 0x0F)
COLUMNS = (5, 0, 20, 0, 10, 100)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    outdir = sys.argv[1]
    os.makedirs(outdir, exist_ok=True)
    if not os.path.exists(FLTOOL):
        run("make", FLTOOL)

    seeds = {}
    with tempfile.TemporaryDirectory() as tmp:
        walk = os.path.join(tmp, "walk")
        os.mkdir(walk)
        run(FLTOOL, "walk", SCENE, "--frames", "12", "--out", walk)
        info, pal = os.path.join(walk, "frames.jsonl"), os.path.join(walk, "palette.bin")

        def encode(frames_raw, *opts):
            out = os.path.join(tmp, "stream%d.bin" % len(os.listdir(tmp)))
            run(FLTOOL, "encode", frames_raw, "--out", out, "--info", info, "--palette", pal, *opts)
            with open(out, "rb") as f:
                return f.read()

        frames_raw = os.path.join(walk, "frames.raw")
        stream = encode(frames_raw)
        stream_k4 = encode(frames_raw, "--key-interval", "4")
        stream_nocrc = encode(frames_raw, "--no-crc")
        one = os.path.join(tmp, "one.raw")
        with open(frames_raw, "rb") as f, open(one, "wb") as g:
            g.write(f.read(FRAME_BYTES))
        stream_rawkey = encode(one, "--scratch", "40")  # does not fit: a raw keyframe

    # Every frame decoded costs the receiver a few milliseconds under the sanitizers
    # and libFuzzer's tracing: seeds carry a few frames each, from different places.
    msgs, segs = messages(stream), segments(stream)
    hp = segs[:2]                         # hello, palette
    f = segs[2:]                          # frame 0 (a keyframe), deltas after it
    k4, nocrc = segments(stream_k4), segments(stream_nocrc)

    # raw: the streams as a receiver sees them
    seeds["raw-start"] = raw(b"".join(hp + f[:3]))
    seeds["raw-start-chunks"] = raw(b"".join(hp + f[:3]), 3, 7)
    seeds["raw-bytewise"] = raw(b"".join(hp + f[:1]), 1, 1)
    seeds["raw-mid-stream"] = raw(b"".join(f[5:8]), 20, 2)  # deltas without their base
    seeds["raw-key-interval-4"] = raw(b"".join(k4[:2] + k4[2 + 3:2 + 6]), 32, 5)
    seeds["raw-no-crc"] = raw(b"".join(nocrc[:2 + 3]))
    seeds["raw-cut"] = raw(b"".join(hp + f[:1]) + f[1][len(f[1]) // 2:] + b"".join(f[2:4]), 16, 3)
    damaged = bytearray(f[1])
    damaged[len(damaged) // 2] ^= 0x10    # a delta lost: the next has no base, a request goes back
    seeds["raw-damaged"] = raw(b"".join(hp + f[:1]) + bytes(damaged) + b"".join(f[2:4]))
    # what a receiver sends back (acks, keyframe and palette requests) and a short
    # message of a type that does not travel that way: the sender's reader takes the
    # same bytes in raw mode
    back = b"".join(message(t, no, p) for t, no, p in
                    [(5, 0, b"\0\0\0\0\0"), (6, 3, b"\x03\0\0\0\0"), (5, 4, b"\x01\xff\xff\xff\xff"),
                     (6, 5, b"\x02\x04\0\0\0"), (4, 6, b"\0\0\0\0\0"), (1, 7, b"\0" * 5)])
    seeds["raw-back-channel"] = raw(back + b"".join(hp[:1]), 2, 9)
    seeds["raw-garbage-then-stream"] = raw(bytes(range(1, 200)) + b"".join(hp + f[:1]), 5, 5)

    # framed: the messages, framed again by the harness
    frames = msgs[2:]
    seeds["framed-start"] = framed(msgs[:5])
    seeds["framed-fixup"] = framed(msgs[:2] + frames[:3], CTL_FIXUP)
    seeds["framed-frames-fixup-auto-numbers"] = framed(frames[:3], CTL_FIXUP, numbered=False)
    seeds["framed-frames-no-crc"] = framed(frames[:3], CTL_FIXUP | CTL_NO_CRC)
    seeds["framed-bodies"] = framed(msgs[:4], body=True)
    # a raw keyframe's header and first rows; the harness repeats them to 64,000 pixels
    # (a 64 KB seed would make every input up to 64 KB long)
    typ, no, payload = messages(stream_rawkey)[2]
    rawkey = bytes([typ | CTL_FRAME_NO | CTL_PAD]) + struct.pack("<IH", no, 32 + 640) + payload[:32 + 640]
    seeds["framed-rawkey"] = framed(msgs[:2]) + rawkey
    seeds["framed-rawkey-fixup"] = framed(msgs[:2]) + bytes([rawkey[0] | CTL_FIXUP]) + rawkey[1:]
    nocrc_msgs = messages(stream_nocrc)
    seeds["framed-no-crc-stream"] = framed(nocrc_msgs[:5])
    # a frame without pixel CRC-32 whose frame check is off: only the check can stop it
    typ, no, payload = nocrc_msgs[2]
    wrong = payload[:27] + struct.pack("<I", struct.unpack_from("<I", payload, 27)[0] ^ 1) + payload[31:]
    seeds["framed-no-crc-wrong-check"] = framed(nocrc_msgs[:2] + [(typ, no, wrong)] + nocrc_msgs[3:4])
    # window 1: keyframe requests on the first drop and after two more (section 6)
    typ, no, hello = msgs[0]
    seeds["framed-window-1-no-base"] = framed([(typ, no, hello[:8] + b"\x01" + hello[9:])] + frames[1:7])
    typ, no, payload = frames[0]
    dmg = bytearray(framed(msgs[:2]))
    dmg += bytes([typ | CTL_FRAME_NO | CTL_DAMAGE]) + struct.pack("<IHBH", no, 20, 0x41, len(payload)) + payload
    dmg += framed(frames[1:3])[1:]
    seeds["framed-damaged"] = bytes(dmg)

    # round trip: synthetic pictures through the encoder and back (2 frames at most)
    scene = [SKY, FLOOR, WALL, WALL2]
    seeds["rt-walk"] = round_trip(1 | 2 | 8, 0, 0, 0, [(0, scene, None), (0, [SCROLL_L, DIAMOND], None)])
    seeds["rt-walk-up"] = round_trip(1 | 2 | 8, 0, 0, 0, [(0, scene + [DIAMOND], None), (0, [SCROLL_UP], None)])
    seeds["rt-unaligned-keyint"] = round_trip(4 | 8, 0xFFFFFFFF, 8192, 1,
                                              [(0, scene, None), (0, [FLOOR_R], None)])
    seeds["rt-small-scratch"] = round_trip(8, 100, 600, 0,
                                           [(0, scene + [NOISE], None), (0, [COLUMNS], None)])
    seeds["rt-wrong-base-shown"] = round_trip(1 | 8, 7, 0, 0, [(0, scene, None), (2 << 3, [DIAMOND], None)])
    # the wrong base differs from the frame before in row 37 (colour ^ 0x55): a new frame
    # with that row is coded "same as the base" and must be dropped by the frame check
    row37 = [(0, 0, 48, 255, 0, 12 ^ 0x55), (0, 200, 48, 69, 0, 12 ^ 0x55)]
    seeds["rt-wrong-base-dropped"] = round_trip(1 | 2 | 8, 7, 0, 0, [(0, [SKY], None), (2 << 3, row37, None)])
    # damage on the line: the palette (asked for again), a keyframe (the delta after it
    # has no base, a keyframe is asked for)
    seeds["rt-palette-lost"] = round_trip(1 | 2 | 8, 50, 0, 0, [(0, scene, (400, 0x20)), (0, [SCROLL_L], None)])
    seeds["rt-keyframe-lost"] = round_trip(1 | 2 | 8, 50, 0, 0, [(0, scene, (40, 0x20)), (0, [SCROLL_L], None)])
    # no acks, a full window given up after the timeout, a skipped frame number
    seeds["rt-no-back-channel"] = round_trip(16 | 1 << 5, 0x7FFFFFFF, 4096, 0,
                                             [(0, scene, None), (3 << 3, [SCROLL_UP], None)])
    seeds["rt-hello-no-crc"] = round_trip(8, 3, 0, 0, [(0x20, scene, None), (0x80 | 0x20, [WALL], None)])

    for name, data in seeds.items():
        with open(os.path.join(outdir, "link-" + name + ".bin"), "wb") as f:
            f.write(data)
    print("%d seeds in %s" % (len(seeds), outdir))


if __name__ == "__main__":
    main()
