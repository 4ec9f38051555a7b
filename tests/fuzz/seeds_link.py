#!/usr/bin/env python3
"""seeds_link.py OUTDIR - seeds for tests/fuzz/fuzz_link.c, in its input format.

Real streams: build/fltool walks tests/scenes/default.scene (flat-shaded) for 12 frames
and encodes them (as they come, with a short keyframe interval, without pixel CRC-32),
and encodes textured pictures drawn here (a wall and a floor of repeating textures,
then the same moved sideways: COPY keyframes and deltas, with and without the match
finder) and a picture of random bytes (a COPY keyframe that takes the escape). Each
frame costs the receiver milliseconds under the sanitizers, so a seed holds a few
messages of a stream: raw-mode seeds are such stretches as sent (from the start,
mid-stream without a base, in chunks, cut, with a byte damaged, after garbage) and a
receiver's acks and requests; framed-mode seeds are the messages decoded back into
type, frame number and payload (also fixed up by the harness, as whole bodies, with a
wrong frame check, after a HELLO with window 1, raw keyframes padded by the harness,
the coded start of the escaping COPY picture whose plain tail the harness adds);
round-trip seeds are short drawing-command sequences (flat shapes, textures, noise).
Run from the repository root. Standard library only."""
import os
import struct
import subprocess
import sys
import tempfile
import zlib

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))

FLTOOL = "build/fltool"
SCENE = "tests/scenes/default.scene"
FRAME_BYTES = 320 * 200

W, H = 320, 200
MODE_RAW, MODE_FRAMED, MODE_ROUND_TRIP = 0, 1, 2
KEYFRAME, DELTA = 3, 4
METHOD_RAW, METHOD_EDGE, METHOD_RAW_HASH, METHOD_COPY = 0, 1, 2, 3
LEN_STREAMED = 0xFFFFFF
FRAME_PRE = 35  # info, flags, frame check
VERSION = None  # the protocol version the tools speak: read from their first stream
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


def pre_of(typ):
    """A frame payload's bytes up to and including its method byte."""
    return FRAME_PRE + (4 if typ == DELTA else 0) + 1


def messages(stream):
    """(type, frame number, payload) of every message of a clean stream; a streamed
    (COPY) frame's payload runs to the CRC."""
    global VERSION
    out = []
    for seg in stream.split(b"\0"):
        if not seg:
            continue
        m = cobs_decode(seg)
        VERSION = VERSION or m[0]
        n = m[6] | m[7] << 8 | m[8] << 16
        if n == LEN_STREAMED:
            n = len(m) - 13
            assert m[1] in (KEYFRAME, DELTA) and m[9 + pre_of(m[1]) - 1] == METHOD_COPY, "not a COPY frame"
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


def header(typ, no, n):
    return struct.pack("<BBI", VERSION, typ, no) + struct.pack("<I", n)[:3]


def message(typ, no, payload, flip=None):
    """One message on the wire (docs/frame-link.md, sections 1 and 2): a COPY frame
    streamed, its CRC (and a RAW_HASH keyframe's) over the header and the payload up to
    the method byte. flip: a byte of header and payload damaged after the CRC."""
    pre = pre_of(typ)
    method = payload[pre - 1] if typ in (KEYFRAME, DELTA) and len(payload) >= pre else None
    streamed = method == METHOD_COPY and len(payload) > pre
    raw_hash = typ == KEYFRAME and method == METHOD_RAW_HASH and len(payload) == pre + W * H
    body = header(typ, no, LEN_STREAMED if streamed else len(payload)) + payload
    crc = zlib.crc32(body[:9 + pre] if streamed or raw_hash else body)
    if flip is not None:
        body = bytearray(body)
        body[flip] ^= 0x04
    return cobs_encode(body + struct.pack("<I", crc)) + b"\0"


def segments(stream):
    """The messages of a stream as sent: COBS bytes and delimiter each."""
    return [seg + b"\0" for seg in stream.split(b"\0")[:-1] if seg]


def framed(msgs, ctl_extra=0, numbered=True, body=False):
    out = bytearray([MODE_FRAMED])
    for typ, no, payload in msgs:
        if body:  # header (with the length) and payload; the harness adds CRC and COBS
            payload = header(typ, no, len(payload)) + payload
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
    """frames: (ctl, [6-byte commands], damage or None). key_interval | 16: the COPY
    coder's match finder."""
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
TEXTURE = (8, 0, 0, 1 | 1 << 3, 255, 64)             # the whole frame: texels 2 x 2
WALL_TEX = (8, 40, 40, 3 | 2 << 3 | 64, 150, 96)     # texels 4 x 3, wider to the right
WALL_TEX_LOW = (8, 40, 100, 3 | 2 << 3 | 64, 120, 96)  # the same from row 78 on
BIG_NOISE = (9, 0, 0, 255, 255, 0xFF)                # every pixel a random byte
MATCH_FINDER = 16                                    # round_trip key_interval bit


def lcg(seed):
    while True:
        seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF
        yield seed >> 16


def texture(seed, base):
    g = lcg(seed)
    return [bytes(base + next(g) % 24 for _ in range(16)) for _ in range(16)]


def textured(shift):
    """A textured picture: a sky, a wall of 4 x 3 texels (3 wide from column 200), a floor
    of 2 x 2 texels; shift moves the textures sideways (a turn)."""
    wall, floor = texture(1, 64), texture(2, 160)
    rows = []
    for y in range(H):
        if y < 40:
            rows.append(bytes([12]) * W)
        elif y < 160:
            t = wall[(y - 40) // 3 % 16]
            rows.append(bytes(t[(x + shift) // (4 if x + shift < 200 else 3) % 16] for x in range(W)))
        else:
            t = floor[y // 2 % 16]
            rows.append(bytes(t[(x + shift) // 2 % 16] for x in range(W)))
    return b"".join(rows)


def noise(seed):
    g = lcg(seed)
    return bytes(next(g) & 0xFF for _ in range(W * H))


def copy_escape_prefix(payload, pixels):
    """A COPY keyframe's picture that took the escape, without its plain tail: (coded
    bytes, the pixel the tail starts at). The tail is the longest end of the picture that
    is the pixels' end; a coded byte that happens to equal the pixel before it would
    make it one too long: the split is right when the coded bytes with any other tail
    decode to the pixels before it and that tail (tools/framelink_copy.py)."""
    from framelink_copy import CopyError, decode_copy
    pic = payload[pre_of(KEYFRAME):]
    pos = W * H - 1
    while pos > 0 and pic[len(pic) - (W * H - pos + 1):] == pixels[pos - 1:]:
        pos -= 1
    for pos in range(pos, min(pos + 8, W * H)):
        coded, zeros = pic[:len(pic) - (W * H - pos)], bytes(W * H - pos)
        try:
            if decode_copy(coded + zeros) == pixels[:pos] + zeros:
                return coded, pos
        except CopyError:
            pass
    raise AssertionError("no escape in the COPY picture")


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
            pixels0 = f.read(FRAME_BYTES)
            g.write(pixels0)
        stream_flatcopy = encode(one, "--scratch", "40")  # does not fit: a COPY keyframe
        tex = os.path.join(tmp, "textured.raw")  # a keyframe and two deltas (turning)
        with open(tex, "wb") as g:
            g.write(textured(0) + textured(3) + textured(8))
        # with the match finder, as hosts send, and a HELLO that names a scene
        stream_tex = encode(tex, "--scene", "textured", "--scene-crc", "1234abcd")
        stream_tex_fw = encode(tex, "--no-match-finder", "--no-crc")  # as the firmware sends
        noisy = os.path.join(tmp, "noise.raw")
        noise_px = noise(7)
        with open(noisy, "wb") as g:
            g.write(noise_px)
        stream_noise = encode(noisy)  # codes worse than raw: the escape

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
    # (a 64 KB seed would make every input up to 64 KB long). The encoder sends no raw
    # keyframes since COPY; receivers still take RAW_HASH (with its short CRC) and RAW.
    typ, no, payload = messages(stream_flatcopy)[2]
    for name, method in (("rawkey", METHOD_RAW_HASH), ("rawkey-raw", METHOD_RAW)):
        pl = payload[:FRAME_PRE] + bytes([method]) + pixels0[:636]
        rawkey = bytes([typ | CTL_FRAME_NO | CTL_PAD]) + struct.pack("<IH", no, len(pl)) + pl
        seeds["framed-" + name] = framed(msgs[:2]) + rawkey
        seeds["framed-%s-fixup" % name] = framed(msgs[:2]) + bytes([rawkey[0] | CTL_FIXUP]) + rawkey[1:]
    seeds["framed-flat-copy"] = framed(msgs[:2] + messages(stream_flatcopy)[2:3])
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
    # window 2, no acks: the timeout gives up the oldest frame in flight, one stays
    seeds["rt-no-back-channel-window-2"] = round_trip(16 | 2 << 5, 5, 0, 0, [(0, scene, None), (0, [SCROLL_UP], None)])
    seeds["rt-hello-no-crc"] = round_trip(8, 3, 0, 0, [(0x20, scene, None), (0x80 | 0x20, [WALL], None)])

    # COPY: textured pictures (a keyframe and deltas, sent as they come), random bytes
    # (the escape), damaged where the message CRC does not look (the coded picture)
    tseg, tmsg = segments(stream_tex), messages(stream_tex)
    fwseg, fwmsg = segments(stream_tex_fw), messages(stream_tex_fw)  # no match finder, no pixel CRC-32
    assert all(m[2][pre_of(m[0]) - 1] == METHOD_COPY for m in tmsg[2:] + fwmsg[2:]), "textured frames not COPY"
    seeds["raw-copy-start"] = raw(b"".join(tseg[:4]))
    seeds["raw-copy-firmware-chunks"] = raw(b"".join(fwseg[:4]), 40, 11)
    typ, no, payload = tmsg[2]
    for name, at in (("picture", 9 + len(payload) - 30), ("info", 9 + 20)):
        seeds["raw-copy-damaged-" + name] = raw(b"".join(tseg[:2]) + message(typ, no, payload, at) + tseg[3])
    seeds["framed-copy"] = framed(tmsg[:4])
    seeds["framed-copy-fixup"] = framed(tmsg[:4], CTL_FIXUP)
    seeds["framed-copy-no-crc-fixup"] = framed(tmsg[2:5], CTL_FIXUP | CTL_NO_CRC)
    seeds["framed-copy-bodies"] = framed(tmsg[:4], body=True)  # with their length and a whole CRC
    typ, no, payload = tmsg[2]
    dmg = bytearray(framed(tmsg[:2]))
    dmg += bytes([typ | CTL_FRAME_NO | CTL_DAMAGE]) + struct.pack("<IHBH", no, 200, 0x10, len(payload)) + payload
    dmg += framed(tmsg[3:4])[1:]
    seeds["framed-copy-damaged"] = bytes(dmg)
    wrong = payload[:FRAME_PRE - 4] + struct.pack("<I", struct.unpack_from("<I", payload, FRAME_PRE - 4)[0] ^ 1)
    seeds["framed-copy-wrong-check"] = framed(tmsg[:2] + [(typ, no, wrong + payload[FRAME_PRE:])] + tmsg[3:4])
    # edge-coded pictures' bytes fixed up as COPY (method byte 3): arbitrary coded bytes
    edge_as_copy = [(t, n, p[:pre_of(t) - 1] + bytes([METHOD_COPY]) + p[pre_of(t):]) for t, n, p in frames[:3]]
    seeds["framed-edge-as-copy-fixup"] = framed(msgs[:2] + edge_as_copy, CTL_FIXUP)
    # the escaping picture's coded start: fix-up pads it with the plain tail
    typ, no, payload = messages(stream_noise)[2]
    coded, pos = copy_escape_prefix(payload, noise_px)
    pl = payload[:pre_of(typ)] + coded
    seeds["framed-copy-escape-pad"] = framed(msgs[:2]) + bytes([typ | CTL_FRAME_NO | CTL_FIXUP | CTL_PAD]) + \
        struct.pack("<IH", no, len(pl)) + pl

    # round trip with textures and noise: COPY keyframes and deltas (from the base moved,
    # from the frame itself), the escape in a keyframe and in a delta
    seeds["rt-textured"] = round_trip(1 | 2 | 8, 0, 0, 0, [(0, [TEXTURE], None), (0, [SCROLL_L], None)])
    seeds["rt-textured-match-finder"] = round_trip(1 | 2 | 8, 9, 0, MATCH_FINDER,
                                                   [(0, [SKY, WALL_TEX], None), (0, [SCROLL_L], None)])
    seeds["rt-textured-small-scratch-unaligned"] = round_trip(4 | 8, 40, 300, MATCH_FINDER | 3,
                                                              [(0, [TEXTURE, DIAMOND], None), (0, [SCROLL_L], None)])
    seeds["rt-noise-escape"] = round_trip(1 | 2 | 8, 1, 0, MATCH_FINDER,
                                          [(0, [BIG_NOISE], None), (0, [SCROLL_L], None)])
    seeds["rt-noise-escape-delta"] = round_trip(1 | 2 | 8, 1, 0, 0, [(0, [SKY], None), (0, [BIG_NOISE], None)])
    # a COPY keyframe damaged in its coded picture (dropped; the keyframe asked for
    # comes next); COPY deltas onto a wrong base (row 37 ^ 0x55): shown where the coding
    # never looks at that row, dropped by the pixel hash where it copies it
    seeds["rt-copy-damaged"] = round_trip(1 | 2 | 8, 70, 0, 0, [(0, [TEXTURE], (30, 0x08)), (0, [SCROLL_L], None)])
    seeds["rt-copy-wrong-base-shown"] = round_trip(1 | 8, 7, 0, 0, [(0, [TEXTURE], None), (2 << 3, [SCROLL_UP], None)])
    row37_sky = [op[:5] + (12,) for op in row37]
    seeds["rt-copy-wrong-base-dropped"] = round_trip(1 | 2 | 8, 7, 0, MATCH_FINDER,
                                                     [(0, [TEXTURE] + row37_sky, None),
                                                      (2 << 3, row37 + [WALL_TEX_LOW], None)])

    for name, data in seeds.items():
        with open(os.path.join(outdir, "link-" + name + ".bin"), "wb") as f:
            f.write(data)
    print("%d seeds in %s" % (len(seeds), outdir))


if __name__ == "__main__":
    main()
