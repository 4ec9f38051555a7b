"""The COPY picture coding's decoder (method 3; hal/serial/fl_copy.c), the Python twin of
fl_copy_decode, written from docs/frame-link.md ("Copy coding"): copies from the picture
itself and from the base frame, and literals, range-coded with adaptive bits.

decode_copy(data, base) -> bytearray(64,000), or raises CopyError on data the C decoder
refuses too.
"""

W, H = 320, 200
FRAME_BYTES = W * H
OFF_BASE = FRAME_BYTES
PROB_BITS, MOVE_BITS = 11, 4
PROB_ONE = 1 << PROB_BITS
TOP = 1 << 24
NEAR = (1, W, W - 1, W + 1)

# the model's layout (fl_copy.c's P_*)
K_LIT, K_REP0, K_REP, K_NEAR, K_NEW, K_N = range(6)
P_IS_COPY = 0
P_IS_REP0 = P_IS_COPY + K_N
P_IS_REP = P_IS_REP0 + K_N
P_IS_NEAR = P_IS_REP + K_N
P_IN_BASE = P_IS_NEAR + K_N
P_REP_TREE = P_IN_BASE + K_N
P_NEAR_TREE = P_REP_TREE + 4 * K_N
P_DY = P_NEAR_TREE + 4 * K_N
P_DX = P_DY + 16
P_DY_HI = P_DX + 16
P_DX_HI = P_DY_HI + 64
P_LEN = P_DX_HI + 64
P_LEN_HI = P_LEN + 32 * 4
P_LIT = P_LEN_HI + 64 * 4
P_END = P_LIT + 8 * 256


class CopyError(Exception):
    """Data fl_copy_decode refuses."""


class _Bits:
    """The binary range decoder: bytes past the end read as 0 and are counted."""

    def __init__(self, data):
        self.data, self.i, self.over = data, 0, 0
        self.range = 0xFFFFFFFF
        if self._byte() != 0:
            raise CopyError("first byte not 0")
        self.code = 0
        for _ in range(4):
            self.code = (self.code << 8) | self._byte()

    def _byte(self):
        if self.i < len(self.data):
            b = self.data[self.i]
            self.i += 1
            return b
        self.over += 1
        return 0

    def _norm(self):
        if self.range < TOP:
            self.range = (self.range << 8) & 0xFFFFFFFF
            self.code = ((self.code << 8) | self._byte()) & 0xFFFFFFFF

    def bit(self, p, k):
        bound = (self.range >> PROB_BITS) * p[k]
        if self.code < bound:
            self.range = bound
            p[k] += (PROB_ONE - p[k]) >> MOVE_BITS
            b = 0
        else:
            self.code -= bound
            self.range -= bound
            p[k] -= p[k] >> MOVE_BITS
            b = 1
        self._norm()
        return b

    def direct(self, n):
        v = 0
        for _ in range(n):
            self.range >>= 1
            b = 1 if self.code >= self.range else 0
            if b:
                self.code -= self.range
            v = (v << 1) | b
            self._norm()
        return v

    def tree(self, p, k, n):
        m = 1
        for _ in range(n):
            m = m * 2 + self.bit(p, k + m)
        return m - (1 << n)

    def gamma(self, p, nb, tree_bits, hi):
        """A number >= 1: its bit length, two adaptive bits below the top one, the rest plain;
        0 for a bit length over 20 (damaged)."""
        n = self.tree(p, nb, tree_bits)
        if n == 0:
            return 1
        if n > 20:
            return 0
        k = min(n, 2)
        rest = n - k
        v = (1 << k) | self.tree(p, hi + 3 * n, k)
        return (v << rest) | self.direct(rest)


def _copy_ok(pos, off, length, delta):
    if off < 1 or length == 0 or length > FRAME_BYTES - pos:
        return False
    return pos - off >= (-OFF_BASE if delta else 0)


def _zig(z):
    return -((z + 1) // 2) if z & 1 else z // 2


def decode_copy(data, base=None):
    """The picture of a COPY frame's data (a delta against base, 64,000 bytes, or a keyframe)."""
    rc = _Bits(bytes(data))
    delta = base is not None
    p = [PROB_ONE // 2] * P_END
    rep = [OFF_BASE if delta else W, 1, W, OFF_BASE - 1 if delta else W + 1]
    out = bytearray(FRAME_BYTES)
    pos, state = 0, K_LIT
    while pos < FRAME_BYTES:
        if rc.over:
            raise CopyError("data ended")
        if not rc.bit(p, P_IS_COPY + state):
            left = out[pos - 1] if pos else 0
            out[pos] = rc.tree(p, P_LIT + (left >> 5) * 256, 8)
            pos += 1
            state = K_LIT
            continue
        if rc.bit(p, P_IS_REP0 + state):
            kind, off = K_REP0, rep[0]
        elif rc.bit(p, P_IS_REP + state):
            kind = K_REP
            i = rc.tree(p, P_REP_TREE + 4 * state, 2) + 1
            if i > 3:
                raise CopyError("recent offset 4")
            rep.insert(0, rep.pop(i))
            off = rep[0]
        else:
            if rc.bit(p, P_IS_NEAR + state):
                kind = K_NEAR
                off = NEAR[rc.tree(p, P_NEAR_TREE + 4 * state, 2)]
            else:
                kind = K_NEW
                in_base = rc.bit(p, P_IN_BASE + state)
                zy = rc.gamma(p, P_DY, 4, P_DY_HI)
                zx = rc.gamma(p, P_DX, 4, P_DX_HI)
                if not zy or not zx or zy - 1 > 2 * H or zx - 1 > W:
                    raise CopyError("offset out of range")
                zy, zx = zy - 1, zx - 1
                dy = _zig(zy) if in_base else zy
                d = dy * W + _zig(zx)
                if not in_base and d == 0:  # the escape: the rest of the picture plain
                    if rc.over:
                        raise CopyError("data ended")
                    raw = rc.data[rc.i:]
                    if len(raw) != FRAME_BYTES - pos:
                        raise CopyError("plain rest of the wrong size")
                    out[pos:] = raw
                    return out
                off = OFF_BASE - d if in_base else d
            rep = [off] + rep[:3]
        length = rc.gamma(p, P_LEN + 32 * (kind - 1), 5, P_LEN_HI + 64 * (kind - 1))
        if not _copy_ok(pos, off, length, delta):
            raise CopyError("copy outside the picture")
        q = pos - off
        if q < 0:  # from the base, maybe running on into this frame
            k = min(-q, length)
            out[pos:pos + k] = base[q + OFF_BASE:q + OFF_BASE + k]
            pos, length, q = pos + k, length - k, 0
        if off >= length:
            out[pos:pos + length] = out[q:q + length]
        else:  # overlapping: a forward copy repeats the run
            for j in range(length):
                out[pos + j] = out[q + j]
        pos += length
        state = kind
    if rc.over or rc.i != len(rc.data):
        raise CopyError("bytes left over or missing")
    return out
