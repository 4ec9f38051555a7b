"""framelink.py - the Python twin of the frame-link decoder (hal/serial, docs/frame-link.md).

Pure Python and the standard library. Feed it bytes in any chunking, as they come from
pyserial or a file; it reassembles COBS-framed messages, checks them, rebuilds keyframes
and deltas (a delta only onto the exact base frame it names), checks every rebuilt frame
against its CRC-32 before showing it, counts, and produces the receiver's acks and keyframe
requests. Bit-exact with the C decoder (fl_decoder.c): the same events, in the same order,
and the same counters for the same byte stream (tests/test_framelink.py checks it).

    from framelink import Decoder
    dec = Decoder(back=ser.write)          # back: where acks / keyframe requests go (optional)
    for ev in dec.feed(ser.read(4096)):
        if ev["event"] == "frame":
            show(ev["pixels"], dec.palette, ev["info"])

Events are dicts; "event" is one of hello, palette, frame, drop, bad, keyreq, other
(see Decoder.feed). A frame event carries its pixels (64,000 bytes): one read can complete
several frames, and dec.frame is only the last of them. dec.counters is a dict.

Also: encode_message() (a whole framed message, for tests and senders), train() (the
model's initial probabilities from streams, docs/frame-link.md "Model").
"""
import struct
import zlib

from framelink_copy import CopyError, decode_copy

VERSION = 4
W, H = 320, 200
FRAME_BYTES = W * H
PALETTE_BYTES = 768
HEADER_BYTES = 9
CRC_BYTES = 4
INFO_BYTES = 30
FRAME_PRE = 35
PAYLOAD_MAX = 65536
MSG_MAX = HEADER_BYTES + PAYLOAD_MAX + CRC_BYTES

MSG_HELLO, MSG_PALETTE, MSG_KEYFRAME, MSG_DELTA, MSG_ACK, MSG_KEYREQ = 1, 2, 3, 4, 5, 6
METHOD_RAW, METHOD_EDGE, METHOD_RAW_HASH, METHOD_COPY = 0, 1, 2, 3
LEN_STREAMED = 0xFFFFFF  # the length field of a COPY frame: the payload runs to the CRC
HELLO_CAPS = 10          # the capabilities: all a HELLO held before scene names
HELLO_MIN = HELLO_CAPS + 5  # then the scene's blob CRC (u32), its name's length (u8), the name
SCENE_NAME_MAX = 63
BACK_BYTES = 5

REASONS = ["none", "framing", "short", "long", "crc", "version", "length", "type", "payload",
           "no_base", "decode", "frame_crc"]
R_FRAMING, R_SHORT, R_LONG, R_CRC, R_VERSION, R_LENGTH, R_TYPE, R_PAYLOAD, R_NO_BASE, R_DECODE, R_FRAME_CRC = \
    range(1, 12)

# ---- picture coding (fl_codec.c) ------------------------------------------------------
D_MAX = 8
NPOS_BITS = 9
CACHE = 4
TOTAL_BITS = 12
ROW_SAME, ROW_TRIV, ROW_CODED, ROW_CODED_C0 = range(4)
ROW_KINDS = 4
OP_K0, OP_UP, OP_DOWN, OP_KEEP, OP_END, OP_NEW, OP_EOL = range(7)
OPS = 7
COL_CAND0, COL_CAND1, COL_CACHE0 = 0, 1, 2
COL_LITERAL = COL_CACHE0 + CACHE
COLS = COL_LITERAL + 1
SET_C0, SET_KEEP, SET_NEW = 0, 1, 2
PREV_START, PREV_K0, PREV_KD, PREV_END, PREV_NEW = range(5)

# The frequency tables: (name, contexts, symbols), in the order of fl_tables.inc.
TABLES = [("row", 8, ROW_KINDS), ("op", 20, OPS), ("noedge", 1, 2), ("move", 4, 2 * D_MAX + 1),
          ("kc", 4, 2), ("col", 3, COLS), ("npos", 1, NPOS_BITS)]
T = {}
_off = 0
for _name, _nctx, _nsym in TABLES:
    T[_name] = (_off, _nsym)
    _off += _nctx * (_nsym + 1)
T_END = _off


def table_offset(name, ctx=0):
    off, n = T[name]
    return off + ctx * (n + 1)


def _read_tables():
    """The cumulative frequency tables, from hal/serial/fl_tables.inc (one source for C and Python)."""
    import os
    import re
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "hal", "serial", "fl_tables.inc")
    with open(path) as f:
        text = re.sub(r"/\*.*?\*/", " ", f.read(), flags=re.S)
    vals = [int(t) for t in text.replace(",", " ").split()]
    if len(vals) != T_END:
        raise ValueError(f"{path}: {len(vals)} values, expected {T_END}")
    return vals


CUM = _read_tables()


class DecodeError(Exception):
    pass


def vclass(v):
    return 1 if v == 0 else (2 if v in (1, -1) else 3)


class _Range:
    """The range decoder (fl_codec.c); bytes past the end read as 0."""
    __slots__ = ("data", "pos", "range", "code", "stats")

    def __init__(self, data, stats=None):
        self.data = data
        self.pos = 0
        self.range = 0xFFFFFFFF
        self.code = 0
        self.stats = stats
        for _ in range(4):
            self.code = (self.code << 8) | self._byte()

    def _byte(self):
        if self.pos < len(self.data):
            b = self.data[self.pos]
            self.pos += 1
            return b
        return 0

    def _norm(self):
        while self.range < (1 << 24):
            self.range = (self.range << 8) & 0xFFFFFFFF
            self.code = ((self.code << 8) | self._byte()) & 0xFFFFFFFF

    def sym(self, t, n):
        q = self.range >> TOTAL_BITS
        s = 0
        while s < n and self.code >= q * CUM[t + s + 1]:
            s += 1
        if s == n:
            raise DecodeError("code outside every symbol")
        self.code -= q * CUM[t + s]
        self.range = q * (CUM[t + s + 1] - CUM[t + s])
        self._norm()
        if self.stats is not None:
            self.stats[t + s] += 1
        return s

    def bits(self, n):
        """A value of n bits (n <= 8), all values equally likely: one step."""
        q = self.range >> n
        v = self.code // q
        if v >> n:
            raise DecodeError("code outside every value")
        self.code -= q * v
        self.range = q
        self._norm()
        return v


def _cache_put(cache, col):
    k = 0
    while k < CACHE - 1 and cache[k] != col:
        k += 1
    del cache[k]
    cache.insert(0, col)


def _colour(rc, cache, sset, cand0, cand1, ex0, ex1):
    if cand0 in (ex0, ex1):
        cand0 = -1
    if cand1 in (ex0, ex1, cand0):
        cand1 = -1
    s = rc.sym(table_offset("col", sset), COLS)
    if s == COL_CAND0:
        if cand0 < 0:
            raise DecodeError("no such candidate")
        return cand0
    if s == COL_CAND1:
        if cand1 < 0:
            raise DecodeError("no such candidate")
        return cand1
    if s == COL_LITERAL:
        col = rc.bits(8)
        if col in (ex0, ex1, cand0, cand1):
            raise DecodeError("literal colour is excluded")
    else:
        rank = s - COL_CACHE0
        col = -1
        for m in cache:
            if m in (ex0, ex1, cand0, cand1):
                continue
            if rank == 0:
                col = m
                break
            rank -= 1
        if col < 0:
            raise DecodeError("no such cache entry")
    _cache_put(cache, col)
    return col


M32 = 0xFFFFFFFF


def _mix(h):
    h = (h * 0x9E3779B1) & M32
    return h ^ (h >> 16)


def _fmix(h):
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & M32
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & M32
    return h ^ (h >> 16)


ROW_HASH0 = 0x811C9DC5


def _transitions(row):
    """Packed transitions x * 256 + colour of a row (bytes-like of 320)."""
    out = []
    cur = row[0]
    for x in range(1, W):
        v = row[x]
        if v != cur:
            cur = v
            out.append(x * 256 + v)
    return out


def _row_hash(c0, at):
    h = _mix(ROW_HASH0 ^ c0)
    for a in at:
        h = _mix(h ^ a)
    return h


def frame_check(frame):
    """The frame check of 64,000 pixel bytes (fl_frame_check)."""
    f = 0
    for y in range(H):
        row = frame[y * W:(y + 1) * W]
        f = _mix(f ^ _row_hash(row[0], _transitions(row)))
    return _fmix(f)


def pixel_hash(frame):
    """The frame check of a RAW_HASH frame (fl_pixel_hash): each little-endian 32-bit word
    v, h = (v ^ (h rotated right by 19)) * 0x9E3779B1, then _fmix."""
    h = ROW_HASH0
    for (v,) in struct.iter_unpack("<I", bytes(frame)):
        h = ((v ^ (h >> 19 | h << 13)) * 0x9E3779B1) & M32
    return _fmix(h)


# Edges of a row: three lists, pk (next row's predicted x * 256 + colour), dv (256 * the
# movement since the row above), vc (velocity class, 0 unknown).

def _advance(ref):
    pk, dv, vc = ref
    return [p + d for p, d in zip(pk, dv)], dv, [v if v else 1 for v in vc]


def _dec_trivial(out, o, ref, c0):
    a0, cur = 0, c0
    at = []
    for pk in ref[0]:
        x, col = pk >> 8, pk & 255
        if x <= a0 or x >= W or col == cur:
            raise DecodeError("predicted row is not a row")
        out[o + a0:o + x] = bytes((cur,)) * (x - a0)
        at.append(pk)
        a0, cur = x, col
    out[o + a0:o + W] = bytes((cur,)) * (W - a0)
    return at


def _dec_row(rc, cache, out, y, ref, c0ref, c0_changed):
    """Decode a ROW_CODED(_C0) row y into out. Returns (its edges, its packed transitions)."""
    rpk, rdv, rvc = ref
    rn = len(rpk)
    o = y * W
    above = out[o - W:o] if y else None
    npk, ndv, nvc, at = [], [], [], []
    a0 = 0
    cur = c0ref
    if c0_changed:
        cur = _colour(rc, cache, SET_C0, (rpk[0] & 255) if rn else -1, -1, c0ref, c0ref)
    prev = PREV_START
    j = 0
    while True:
        if j == rn:
            op = OP_EOL if rc.sym(table_offset("noedge"), 2) else OP_NEW
        else:
            op = rc.sym(table_offset("op", rvc[j] * 5 + prev), OPS)
        if op == OP_EOL:
            break
        if op == OP_END:
            j += 1
            prev = PREV_END
            continue
        if op == OP_NEW:
            ln = rc.sym(table_offset("npos"), NPOS_BITS) + 1
            dist = (1 << (ln - 1)) | rc.bits(ln - 1)
            x = a0 + dist
            if x >= W:
                raise DecodeError("new transition beyond the row")
            col = _colour(rc, cache, SET_NEW, above[x] if above is not None else -1,
                          (rpk[j] & 255) if j < rn else -1, cur, cur)
            npk.append(x * 256 + col)
            ndv.append(0)
            nvc.append(0)
            prev = PREV_NEW
        else:
            p, pc, vc = rpk[j] >> 8, rpk[j] & 255, rvc[j]
            col = pc
            if op == OP_K0:
                d = 0
            elif op in (OP_UP, OP_DOWN):
                d = 1 if op == OP_UP else -1
            else:
                d = rc.sym(table_offset("move", vc), 2 * D_MAX + 1) - D_MAX
                changed = 1
                if (d > 1 or d < -1) and pc != cur:
                    changed = rc.sym(table_offset("kc", vc), 2)
                if changed:
                    col = _colour(rc, cache, SET_KEEP, (rpk[j + 1] & 255) if j + 1 < rn else -1,
                                  (rpk[j + 2] & 255) if j + 2 < rn else -1, cur, pc)
            x = p + d
            if x <= a0 or x >= W or col == cur:
                raise DecodeError("edge out of order or not a transition")
            dv = rdv[j] + d * 256
            npk.append(x * 256 + col + dv)
            ndv.append(dv)
            nvc.append(vclass(dv >> 8))
            j += 1
            prev = PREV_KD if d else PREV_K0
        at.append(x * 256 + col)
        out[o + a0:o + x] = bytes((cur,)) * (x - a0)
        a0, cur = x, col
    out[o + a0:o + W] = bytes((cur,)) * (W - a0)
    return (npk, ndv, nvc), at


def decode_picture(data, base=None, stats=None):
    """Decode method-EDGE picture data; base (64,000 bytes) for a delta. Returns (the frame
    as a bytearray, its frame check), or raises DecodeError. stats, if given, is a list of
    T_END counters, one per table entry: the symbols decoded (training)."""
    rc = _Range(data, stats)
    cache = list(range(CACHE))
    out = bytearray(FRAME_BYTES)
    ref = ([], [], [])
    c0ref = 0
    kind = ROW_CODED
    delta = 4 if base is not None else 0
    f = 0
    for y in range(H):
        o = y * W
        kind = rc.sym(table_offset("row", delta + kind), ROW_KINDS)
        if kind == ROW_SAME:
            if base is None:
                raise DecodeError("same-as-base row in a keyframe")
            out[o:o + W] = base[o:o + W]
            at = _transitions(out[o:o + W])
            ref = (list(at), [0] * len(at), [0] * len(at))
        elif kind == ROW_TRIV:
            at = _dec_trivial(out, o, ref, c0ref)
            ref = _advance(ref)
        else:
            ref, at = _dec_row(rc, cache, out, y, ref, c0ref, kind == ROW_CODED_C0)
        c0ref = out[o]
        f = _mix(f ^ _row_hash(c0ref, at))
    return out, _fmix(f)


def tables_from_counts(stats):
    """Cumulative tables (out of 4096) from symbol counts: every symbol keeps a frequency of
    at least 1; the rest is shared in proportion to (count + 1/2)."""
    out = []
    for name, nctx, n in TABLES:
        for ctx in range(nctx):
            off = table_offset(name, ctx)
            counts = [stats[off + k] + 0.5 for k in range(n)]
            tot = sum(counts)
            freq = [max(1, int(c * (4096 - n) / tot)) for c in counts]
            freq[freq.index(max(freq))] += 4096 - sum(freq)
            cum = [0]
            for fq in freq:
                cum.append(cum[-1] + fq)
            out.append(cum)
    return out


# ---- framing (fl_framing.c) -------------------------------------------------------------

def crc32(data):
    return zlib.crc32(data) & 0xFFFFFFFF


def cobs_encode(data):
    out = bytearray()
    blk = bytearray()
    for b in data:
        if b == 0:
            out.append(len(blk) + 1)
            out += blk
            blk = bytearray()
        else:
            blk.append(b)
            if len(blk) == 254:
                out.append(0xFF)
                out += blk
                blk = bytearray()
    out.append(len(blk) + 1)
    out += blk
    return bytes(out)


def encode_message(mtype, frame_no, payload, version=VERSION):
    """A whole message on the wire: COBS(header + payload + CRC-32) + 0x00."""
    n = len(payload)
    head = bytes((version, mtype)) + struct.pack("<I", frame_no & 0xFFFFFFFF) + bytes((n & 255, (n >> 8) & 255,
                                                                                         (n >> 16) & 255))
    body = head + bytes(payload)
    covered = crc_bytes(body + bytes(CRC_BYTES))
    return cobs_encode(body + struct.pack("<I", crc32(body[:covered]))) + b"\x00"


def unpack_info(b):
    x, y, z, angle, look, mode, present, crc, t = struct.unpack("<iiiiiBBII", bytes(b[:INFO_BYTES]))
    return {"x": x, "y": y, "z": z, "angle": angle, "look": look, "mode": mode, "present": present,
            "crc32": f"{crc:08x}", "no_crc": 0 if b[INFO_BYTES] & 1 else 1, "time_ms": t}


class _Reader:
    """Streaming COBS reader (fl_reader)."""

    def __init__(self, cap):
        self.cap = cap
        self.buf = bytearray()
        self.left = 0
        self.last_code = 0
        self.started = False
        self.broken = 0

    def byte(self, b):
        """0: nothing yet; 1: a structurally complete message in self.buf; -reason: a bad segment."""
        if b == 0:
            res = 0
            if self.started:
                if self.broken:
                    res = -self.broken
                elif self.left:
                    res = -R_FRAMING
                else:
                    res = 1
            self.started = False
            self.broken = 0
            self.left = 0
            self.last_code = 0
            return res
        if not self.started:
            self.started = True
            self.buf = bytearray()
        if self.broken:
            return 0
        if self.left == 0:
            if self.last_code and self.last_code != 0xFF:
                self._append(0)
            self.last_code = b
            self.left = b - 1
        else:
            self._append(b)
            self.left -= 1
        return 0

    def _append(self, b):
        if len(self.buf) < self.cap:
            self.buf.append(b)
        else:
            self.broken = R_LONG


def _streamed(buf):
    """A streamed COPY frame: its length field, type and method byte say so."""
    if (buf[6] | buf[7] << 8 | buf[8] << 16) != LEN_STREAMED or buf[1] not in (MSG_KEYFRAME, MSG_DELTA):
        return False
    pre = HEADER_BYTES + FRAME_PRE + (4 if buf[1] == MSG_DELTA else 0) + 1
    return len(buf) > pre + CRC_BYTES and buf[pre - 1] == METHOD_COPY


def crc_bytes(buf):
    """How many leading bytes of a message (CRC included) its CRC covers: all but the CRC, or
    for a RAW_HASH keyframe and a COPY frame the header and the payload up to its method byte
    (fl_msg_crc_bytes)."""
    pre = HEADER_BYTES + FRAME_PRE + 1
    if len(buf) == pre + FRAME_BYTES + CRC_BYTES and buf[1] == MSG_KEYFRAME and buf[pre - 1] == METHOD_RAW_HASH:
        return pre
    if _streamed(buf):
        return pre + (4 if buf[1] == MSG_DELTA else 0)
    return len(buf) - CRC_BYTES


def check_message(buf):
    """(None, (type, frame_no, payload)) or (reason, None) - fl_msg_check."""
    n = len(buf)
    if n < HEADER_BYTES + CRC_BYTES:
        return R_SHORT, None
    if crc32(bytes(buf[:crc_bytes(buf)])) != struct.unpack_from("<I", buf, n - CRC_BYTES)[0]:
        return R_CRC, None
    if buf[0] != VERSION:
        return R_VERSION, None
    plen = buf[6] | buf[7] << 8 | buf[8] << 16
    if plen == LEN_STREAMED and _streamed(buf):
        plen = n - HEADER_BYTES - CRC_BYTES
    if plen != n - HEADER_BYTES - CRC_BYTES or plen > PAYLOAD_MAX:
        return R_LENGTH, None
    return None, (buf[1], struct.unpack_from("<I", buf, 2)[0], bytes(buf[HEADER_BYTES:n - CRC_BYTES]))


# ---- the receiver (fl_decoder.c) -----------------------------------------------------------

COUNTERS = ["bytes", "msgs_ok", "msgs_bad", "resyncs", "frames_shown", "frames_dropped", "frames_missed",
            "keyreqs_sent", "palreqs_sent", "acks_sent", "palettes", "hellos"]


def _gt(a, b):
    """a after b in 32-bit frame-number arithmetic."""
    d = (a - b) & 0xFFFFFFFF
    return d != 0 and d < 0x80000000


def unpack_hello(pl):
    """A HELLO payload as a dict, or None if invalid: the 10 capability bytes alone (a sender from
    before scene names: no scene), or followed by the scene's blob CRC, the name's length (at most
    63, exactly the bytes that follow) and the name (printable ASCII)."""
    if len(pl) == HELLO_CAPS:
        crc, name = 0, b""
    elif HELLO_MIN <= len(pl) <= HELLO_MIN + SCENE_NAME_MAX and len(pl) == HELLO_MIN + pl[HELLO_CAPS + 4]:
        crc, name = struct.unpack_from("<I", pl, HELLO_CAPS)[0], pl[HELLO_MIN:]
        if any(c < 0x20 or c > 0x7E for c in name):
            return None
    else:
        return None
    ver, w, h, gun, ki, win, methods = struct.unpack_from("<BHHBHBB", pl)
    return {"version": ver, "width": w, "height": h, "gun_bits": gun, "key_interval": ki, "window": win,
            "methods": methods, "scene": name.decode("ascii"), "scene_crc32": f"{crc:08x}"}


def pack_hello(key_interval=64, window=4, methods=3, scene="", scene_crc=0):
    """A HELLO payload as fl_enc_hello sends it (scene truncated and made printable likewise)."""
    name = bytes(c if 0x20 <= c <= 0x7E else 0x3F for c in scene.encode("utf-8")[:SCENE_NAME_MAX])
    return (struct.pack("<BHHBHBB", VERSION, W, H, 8, min(key_interval, 0xFFFF), window, methods) +
            struct.pack("<IB", scene_crc, len(name)) + name)


class Decoder:
    """The receiving end. back(bytes), if given, receives the acks and keyframe requests."""

    def __init__(self, back=None, send_acks=True, stats=None):
        self.back = back
        self.send_acks = send_acks
        self.stats = stats
        self.rx = _Reader(MSG_MAX)
        self.frame = bytes(FRAME_BYTES)
        self.palette = None
        self.hello = None
        self.shown_info = None
        self.counters = {k: 0 for k in COUNTERS}
        self.back_bytes = 0
        self.have_frame = False
        self.waiting_key = False
        self.last_bad = False
        self.have_seen = False
        self.window = 4
        self.shown_no = 0
        self.seen_no = 0
        self.waiting_drops = 0
        self.palette_wait = 0
        self._events = []

    # -- output
    def _send_back(self, mtype, frame_no, b0):
        shown = self.shown_no if self.have_frame else 0xFFFFFFFF
        msg = encode_message(mtype, frame_no, bytes((b0,)) + struct.pack("<I", shown))
        self.back_bytes += len(msg)
        if self.back:
            self.back(msg)

    def _emit(self, ev):
        self._events.append(ev)

    def _ok(self):
        self.counters["msgs_ok"] += 1
        if self.last_bad:
            self.counters["resyncs"] += 1
        self.last_bad = False

    def _bad(self, why):
        self.counters["msgs_bad"] += 1
        self.last_bad = True
        self._emit({"event": "bad", "reason": REASONS[why]})

    def _want_key(self, frame_no):
        if self.waiting_key:
            self.waiting_drops += 1
            if self.waiting_drops <= self.window + 1:
                return
        self.waiting_key = True
        self.waiting_drops = 0
        self.counters["keyreqs_sent"] += 1
        self._send_back(MSG_KEYREQ, frame_no, 1 | (0 if self.palette is not None else 2))
        self._emit({"event": "keyreq", "frame": frame_no})

    # -- messages
    def _frame_msg(self, mtype, frame_no, pl):
        key = mtype == MSG_KEYFRAME
        pre = FRAME_PRE + (0 if key else 4) + 1
        if len(pl) < pre:
            return self._bad(R_PAYLOAD)
        info = unpack_info(pl)
        flags = pl[INFO_BYTES]
        check = struct.unpack_from("<I", pl, INFO_BYTES + 1)[0]
        method = pl[pre - 1]
        base_no = 0 if key else struct.unpack_from("<I", pl, FRAME_PRE)[0]
        pic = pl[pre:]
        raw = method in (METHOD_RAW, METHOD_RAW_HASH)
        if flags & ~1 or method > METHOD_COPY or (raw and (not key or len(pic) != FRAME_BYTES)):
            return self._bad(R_PAYLOAD)
        self._ok()
        if self.have_seen and _gt(frame_no, self.seen_no):
            self.counters["frames_missed"] += (frame_no - self.seen_no - 1) & 0xFFFFFFFF
        if not self.have_seen or _gt(frame_no, self.seen_no):
            self.seen_no = frame_no
        self.have_seen = True

        why = None
        recon = None
        if not key and not (self.have_frame and base_no == self.shown_no):
            why = R_NO_BASE
        elif raw:
            recon = pic
            got = pixel_hash(recon) if method == METHOD_RAW_HASH else frame_check(recon)
        elif method == METHOD_COPY:
            try:
                recon = decode_copy(pic, None if key else self.frame)
                got = pixel_hash(recon)
            except CopyError:
                why = R_DECODE
        else:
            try:
                recon, got = decode_picture(pic, None if key else self.frame, self.stats)
            except (DecodeError, IndexError):
                why = R_DECODE
        if why is None:
            crc = crc32(bytes(recon))
            if got != check or (not info["no_crc"] and crc != int(info["crc32"], 16)):
                why = R_FRAME_CRC
            else:
                info["crc32"] = f"{crc:08x}"

        if why is None:
            self.frame = bytes(recon)
            self.have_frame = True
            self.shown_no = frame_no
            self.shown_info = info
            self.waiting_key = False
            self.counters["frames_shown"] += 1
            if self.send_acks:
                self._send_back(MSG_ACK, frame_no, 0)
                self.counters["acks_sent"] += 1
            self._emit({"event": "frame", "frame": frame_no, "keyframe": int(key), "info": info, "pixels": self.frame})
        else:
            self.counters["frames_dropped"] += 1
            if self.send_acks:
                self._send_back(MSG_ACK, frame_no, 1)
                self.counters["acks_sent"] += 1
            self._emit({"event": "drop", "frame": frame_no, "type": mtype, "reason": REASONS[why]})
        if why is not None:
            self._want_key(frame_no)
        elif self.palette is None and not self.waiting_key:
            if self.palette_wait % 64 == 0:
                self.counters["palreqs_sent"] += 1
                self._send_back(MSG_KEYREQ, frame_no, 2)
            self.palette_wait += 1

    def _message(self, buf):
        why, msg = check_message(buf)
        if why is not None:
            return self._bad(why)
        mtype, frame_no, pl = msg
        if mtype == MSG_HELLO:
            hello = unpack_hello(pl)
            if hello is None:
                return self._bad(R_PAYLOAD)
            self._ok()
            self.counters["hellos"] += 1
            self.hello = hello
            win = hello["window"]
            self.window = win if win else 4
            self.have_frame = False
            self.have_seen = False
            self.waiting_key = False
            self._emit({"event": "hello", "frame": frame_no, **self.hello})
        elif mtype == MSG_PALETTE:
            if len(pl) != PALETTE_BYTES:
                return self._bad(R_PAYLOAD)
            self._ok()
            self.counters["palettes"] += 1
            self.palette = pl
            self._emit({"event": "palette", "frame": frame_no, "crc32": f"{crc32(pl):08x}", "palette": pl})
        elif mtype in (MSG_KEYFRAME, MSG_DELTA):
            self._frame_msg(mtype, frame_no, pl)
        elif mtype in (MSG_ACK, MSG_KEYREQ):
            if len(pl) != BACK_BYTES:
                return self._bad(R_PAYLOAD)
            self._ok()
            self._emit({"event": "other", "frame": frame_no, "type": mtype})
        else:
            self._bad(R_TYPE)

    def feed(self, data):
        """Feed bytes; returns the events they completed, in order:
        {"event": "hello", "frame", "version", "width", "height", "gun_bits", "key_interval", "window", "methods",
         "scene": name ("" when not said), "scene_crc32": 8 hex digits of the scene blob's CRC-32 ("00000000": not said)}
        {"event": "palette", "frame", "crc32", "palette": 768 bytes}
        {"event": "frame", "frame", "keyframe",
         "info": {x, y, z, angle, look, mode, present, crc32, no_crc, time_ms},
         "pixels": the 64,000 bytes shown}      (.frame is the latest frame shown, after the whole call)
        {"event": "drop", "frame", "type", "reason"}   an intact frame message not shown
        {"event": "bad", "reason"}                     a damaged or invalid message discarded
        {"event": "keyreq", "frame"}                   a keyframe request was sent
        {"event": "other", "frame", "type"}            an intact ack or keyframe request (other direction)"""
        self._events = []
        rx = self.rx
        for b in bytes(data):
            self.counters["bytes"] += 1
            r = rx.byte(b)
            if r == 0:
                continue
            if r < 0:
                self._bad(-r)
            else:
                self._message(rx.buf)
        ev, self._events = self._events, []
        return ev


def train(streams):
    """The picture coder's frequency tables from byte streams (docs/frame-link.md, "Model"):
    decode them, count each table's symbols, and return the tables (lists of cumulative
    frequencies) for hal/serial/fl_tables.inc."""
    stats = [0] * T_END
    for data in streams:
        Decoder(stats=stats).feed(data)
    return tables_from_counts(stats)


def format_tables(tables):
    lines = ["/* fl_tables.inc - the picture coder's cumulative frequency tables, out of 4096, in the",
             " * order of fl_codec.c's T_* (generated by tools/framelink.py --train; docs/frame-link.md). */"]
    lines += [", ".join(str(v) for v in cum) + "," for cum in tables]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    import argparse
    import json
    import sys
    ap = argparse.ArgumentParser(description="Decode a frame-link byte stream; print events as JSON lines.")
    ap.add_argument("stream", help="file with the byte stream ('-' for stdin)")
    ap.add_argument("--chunk", type=int, default=4096)
    ap.add_argument("--frames-out", help="append every shown frame's 64,000 bytes to this file")
    ap.add_argument("--train", nargs="*", metavar="STREAM",
                    help="instead: print fl_tables.inc trained on STREAM and these streams")
    a = ap.parse_args()
    if a.train is not None:
        sys.stdout.write(format_tables(train([open(p, "rb").read() for p in [a.stream] + a.train])))
        sys.exit(0)
    data = sys.stdin.buffer.read() if a.stream == "-" else open(a.stream, "rb").read()
    dec = Decoder()
    fo = open(a.frames_out, "wb") if a.frames_out else None
    for off in range(0, len(data), a.chunk):
        for ev in dec.feed(data[off:off + a.chunk]):
            ev.pop("palette", None)
            pixels = ev.pop("pixels", None)
            print(json.dumps(ev))
            if fo and pixels is not None:
                fo.write(pixels)
    print(json.dumps({"counters": dec.counters, "back_bytes": dec.back_bytes}))
