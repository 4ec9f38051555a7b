/* fl_copy.c - the COPY picture coding (method 3) for textured frames: the
 * picture in raster order as copies and literals, range-coded with adaptive
 * binary models. docs/frame-link.md, "Copy coding".
 *
 * A copy takes a run of pixels from somewhere already known: this frame's own
 * pixels (the one to the left for a run of one colour, the row above for a
 * texel taller than a pixel, or any offset) or the base frame (the frame shown
 * before: a turn shifts most of it sideways, distant walls barely change). Four
 * recent offsets are kept, so a shift that holds across a wall costs a few
 * bits per run. A literal is one palette index, coded against the pixel above,
 * because a texture's neighbouring texels sit on the same colour ramp.
 *
 * Both ends reset the models with every picture: a picture decodes from its
 * own bytes and its base alone. The encoder streams its bytes (LZMA's carry
 * handling: a byte is held back only while a carry can still reach it), so the
 * sender needs no buffer for the coded picture. A picture that codes worse than
 * its raw size gives up: an escape, then the remaining pixels as plain bytes,
 * so a coded picture never passes 64,000 bytes by more than FL_CP_SLACK. */
#include "fl_internal.h"

#define PROB_BITS 11
#define PROB_ONE (1u << PROB_BITS)
#define MOVE_BITS 4
#define TOP (1u << 24)

/* offsets: src = pos - off in the virtual line [base (64,000) | this frame] */
#define OFF_BASE ((int32_t)FL_FRAME_BYTES)
static const int32_t near_off[4] = {1, FL_W, FL_W - 1, FL_W + 1};

/* ---- the model ----------------------------------------------------------- */

static void model_reset(fl_copy_model *m, int delta)
{
    for (uint32_t i = 0; i < FL_CP_PROBS; i++) m->p[i] = (uint16_t)(PROB_ONE / 2);
    m->rep[0] = delta ? OFF_BASE : FL_W;
    m->rep[1] = 1;
    m->rep[2] = FL_W;
    m->rep[3] = delta ? OFF_BASE - 1 : FL_W + 1;
}

static void rep_use(fl_copy_model *m, uint32_t i)
{
    int32_t o = m->rep[i];
    for (; i > 0; i--) m->rep[i] = m->rep[i - 1];
    m->rep[0] = o;
}

static void rep_push(fl_copy_model *m, int32_t off)
{
    m->rep[3] = m->rep[2];
    m->rep[2] = m->rep[1];
    m->rep[1] = m->rep[0];
    m->rep[0] = off;
}

/* A copy from src (virtual) of len pixels is possible: inside the picture, and
 * in the base only when there is one. */
static inline int copy_ok(uint32_t pos, int32_t off, uint32_t len, int delta)
{
    if (off < 1 || len == 0 || len > FL_FRAME_BYTES - pos) return 0;
    return (int32_t)pos - off >= (delta ? -OFF_BASE : 0);
}

/* ---- encoder --------------------------------------------------------------- */

typedef struct {
    uint64_t low;
    uint32_t range, pending; /* bytes held back: cache, then pending - 1 times 0xFF */
    uint8_t cache;
    uint32_t out; /* bytes emitted */
    uint32_t n;
    fl_writer *w;
    uint8_t buf[64];
} rc_enc;

static void enc_byte(rc_enc *r, uint8_t b)
{
    r->buf[r->n++] = b;
    r->out++;
    if (r->n == sizeof r->buf) {
        fl_writer_direct(r->w, r->buf, r->n);
        r->n = 0;
    }
}

static void shift_low(rc_enc *r)
{
    if ((uint32_t)r->low < 0xFF000000u || (r->low >> 32) != 0) {
        uint8_t carry = (uint8_t)(r->low >> 32);
        uint8_t b = r->cache;
        do {
            enc_byte(r, (uint8_t)(b + carry));
            b = 0xFF;
        } while (--r->pending != 0);
        r->cache = (uint8_t)(r->low >> 24);
    }
    r->pending++;
    r->low = (uint32_t)r->low << 8;
}

static inline void enc_bit(rc_enc *r, uint16_t *p, uint32_t bit)
{
    uint32_t bound = (r->range >> PROB_BITS) * *p;
    if (!bit) {
        r->range = bound;
        *p = (uint16_t)(*p + ((PROB_ONE - *p) >> MOVE_BITS));
    } else {
        r->low += bound;
        r->range -= bound;
        *p = (uint16_t)(*p - (*p >> MOVE_BITS));
    }
    while (r->range < TOP) {
        r->range <<= 8;
        shift_low(r);
    }
}

static void enc_direct(rc_enc *r, uint32_t v, uint32_t nbits)
{
    while (nbits--) {
        r->range >>= 1;
        if ((v >> nbits) & 1u) r->low += r->range;
        while (r->range < TOP) {
            r->range <<= 8;
            shift_low(r);
        }
    }
}

static void enc_tree(rc_enc *r, uint16_t *p, uint32_t v, uint32_t nbits)
{
    uint32_t m = 1;
    while (nbits--) {
        uint32_t b = (v >> nbits) & 1u;
        enc_bit(r, p + m, b);
        m = m * 2 + b;
    }
}

static void enc_flush(rc_enc *r)
{
    for (int i = 0; i < 5; i++) shift_low(r);
    if (r->n) fl_writer_direct(r->w, r->buf, r->n);
    r->n = 0;
}

/* A number v >= 1 as its bit length (tree, nb_probs: 2^bits entries) and the
 * bits below the top one: the first two adaptive (hi: 3 per length), the rest plain. */
static void enc_gamma(rc_enc *r, uint16_t *nb, uint32_t tree_bits, uint16_t *hi, uint32_t v)
{
    uint32_t n = 0;
    while ((v >> n) > 1u) n++; /* v in [2^n, 2^(n+1)) */
    enc_tree(r, nb, n, tree_bits);
    if (n == 0) return;
    uint32_t k = n < 2 ? n : 2u, rest = n - k;
    enc_tree(r, hi + 3 * n, (v >> rest) & ((1u << k) - 1u), k);
    enc_direct(r, v & ((1u << rest) - 1u), rest);
}

static inline uint8_t vpix(const uint8_t *px, const uint8_t *base, int32_t q)
{
    return q < 0 ? base[q + OFF_BASE] : px[q];
}

/* How many pixels from pos on equal those at pos - off (overlapping runs read
 * the picture itself, as the decoder's forward copy does). */
static uint32_t match_len(const uint8_t *px, const uint8_t *base, uint32_t pos, int32_t off, uint32_t max)
{
    int32_t q = (int32_t)pos - off;
    const uint8_t *d = px + pos;
    uint32_t n = 0;
    if (q < 0) {
        const uint8_t *s = base + q + OFF_BASE;
        uint32_t lim = (uint32_t)-q < max ? (uint32_t)-q : max;
        while (n < lim && s[n] == d[n]) n++;
        if (n < lim) return n;
    }
    const uint8_t *s = px + q; /* s[n] lies in this frame from here on */
    while (n < max && s[n] == d[n]) n++;
    return n;
}

static inline uint32_t hash4(const uint8_t *p)
{
    uint32_t v = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    return (v * 0x9E3779B1u) >> (32 - FL_CP_HASH_BITS);
}

static void lit_encode(rc_enc *r, fl_copy_model *m, const uint8_t *px, uint32_t pos)
{
    uint8_t up = pos >= FL_W ? px[pos - FL_W] : 0;
    enc_tree(r, m->p + FL_CP_LIT + FL_CP_LIT_CTX(up), (uint8_t)(px[pos] - up), 8);
}

uint32_t fl_copy_encode(fl_copy_model *m, const uint8_t *px, const uint8_t *base, int32_t *hash, fl_writer *w)
{
    rc_enc r = {0};
    r.range = 0xFFFFFFFFu;
    r.pending = 1;
    r.w = w;
    int delta = base != 0;
    model_reset(m, delta);
    if (hash) {
        for (uint32_t i = 0; i < FL_CP_HASH; i++) hash[i] = INT32_MIN;
        if (delta)
            for (uint32_t i = 0; i + 4 <= FL_FRAME_BYTES; i++) hash[hash4(base + i)] = (int32_t)i - OFF_BASE;
    }
    uint32_t pos = 0, state = 0;
    while (pos < FL_FRAME_BYTES) {
        uint32_t left = FL_FRAME_BYTES - pos;
        if (r.out > pos + FL_CP_SLACK) { /* worse than raw: escape, the rest plain */
            enc_bit(&r, m->p + FL_CP_IS_COPY + state, 1);
            enc_bit(&r, m->p + FL_CP_IS_REP0 + state, 0);
            enc_bit(&r, m->p + FL_CP_IS_REP, 0);
            enc_bit(&r, m->p + FL_CP_IS_NEAR, 0);
            enc_bit(&r, m->p + FL_CP_IN_BASE, 0);
            enc_gamma(&r, m->p + FL_CP_DY, 4, m->p + FL_CP_DY_HI, 1); /* dy 0 */
            enc_gamma(&r, m->p + FL_CP_DX, 4, m->p + FL_CP_DX_HI, 1); /* dx 0: offset 0 */
            enc_flush(&r);
            fl_writer_direct(w, px + pos, left);
            return r.out + left;
        }
        /* candidates: the recent offsets, the neighbours, a hashed position */
        uint32_t best_len = 0, best_kind = 0, best_i = 0;
        int32_t best_off = 0;
        for (uint32_t i = 0; i < 4; i++) {
            int32_t off = m->rep[i];
            if (!copy_ok(pos, off, 1, delta)) continue;
            uint32_t l = match_len(px, base, pos, off, left);
            uint32_t need = i == 0 ? 1u : 2u;
            if (l >= need && l > best_len) {
                best_len = l;
                best_kind = 1;
                best_i = i;
                best_off = off;
            }
        }
        for (uint32_t i = 0; i < 4; i++) {
            int32_t off = near_off[i];
            if (off == m->rep[0] || off == m->rep[1] || off == m->rep[2] || off == m->rep[3]) continue;
            if (!copy_ok(pos, off, 1, delta)) continue;
            uint32_t l = match_len(px, base, pos, off, left);
            if (l >= 2 && l > best_len + 1) {
                best_len = l;
                best_kind = 2;
                best_i = i;
                best_off = off;
            }
        }
        if (hash && left >= 4) {
            int32_t q = hash[hash4(px + pos)];
            if (q != INT32_MIN) {
                int32_t off = (int32_t)pos - q;
                if (copy_ok(pos, off, 1, delta) && off != m->rep[0] && off != m->rep[1] && off != m->rep[2] &&
                    off != m->rep[3]) {
                    uint32_t l = match_len(px, base, pos, off, left);
                    if (l >= 6 && l > best_len + 4) {
                        best_len = l;
                        best_kind = 3;
                        best_off = off;
                    }
                }
            }
        }
        if (best_len == 0) {
            enc_bit(&r, m->p + FL_CP_IS_COPY + state, 0);
            lit_encode(&r, m, px, pos);
            if (hash && left >= 4) hash[hash4(px + pos)] = (int32_t)pos;
            pos++;
            state = 0;
            continue;
        }
        enc_bit(&r, m->p + FL_CP_IS_COPY + state, 1);
        enc_bit(&r, m->p + FL_CP_IS_REP0 + state, best_kind == 1 && best_i == 0);
        if (best_kind == 1 && best_i == 0) {
            /* rep0 */
        } else {
            enc_bit(&r, m->p + FL_CP_IS_REP, best_kind == 1);
            if (best_kind == 1) {
                enc_tree(&r, m->p + FL_CP_REP_TREE, best_i - 1, 2); /* 0..2: rep1..rep3 */
                rep_use(m, best_i);
            } else {
                enc_bit(&r, m->p + FL_CP_IS_NEAR, best_kind == 2);
                if (best_kind == 2) {
                    enc_tree(&r, m->p + FL_CP_NEAR_TREE, best_i, 2);
                } else {
                    /* a new offset: where, as rows and columns */
                    int32_t q = (int32_t)pos - best_off, in_base = q < 0;
                    int32_t d = in_base ? q + OFF_BASE - (int32_t)pos : best_off; /* base: motion; else back */
                    enc_bit(&r, m->p + FL_CP_IN_BASE, (uint32_t)in_base);
                    /* d = dy * 320 + dx with dx in -160..159 */
                    int32_t dy = (d + 160 + 320 * 400) / 320 - 400, dx = d - dy * 320;
                    uint32_t zy = in_base ? (dy < 0 ? (uint32_t)(-2 * dy) - 1u : (uint32_t)(2 * dy)) : (uint32_t)dy;
                    uint32_t zx = dx < 0 ? (uint32_t)(-2 * dx) - 1u : (uint32_t)(2 * dx);
                    enc_gamma(&r, m->p + FL_CP_DY, 4, m->p + FL_CP_DY_HI, zy + 1u);
                    enc_gamma(&r, m->p + FL_CP_DX, 4, m->p + FL_CP_DX_HI, zx + 1u);
                }
                rep_push(m, best_off);
            }
        }
        enc_gamma(&r, m->p + FL_CP_LEN + (best_kind == 1 && best_i == 0 ? 0u : 32u), 5, m->p + FL_CP_LEN_HI, best_len);
        if (hash)
            for (uint32_t i = 0; i < best_len && pos + i + 4 <= FL_FRAME_BYTES; i++)
                hash[hash4(px + pos + i)] = (int32_t)(pos + i);
        pos += best_len;
        state = 1;
    }
    enc_flush(&r);
    return r.out;
}

/* ---- decoder --------------------------------------------------------------- */

typedef struct {
    uint32_t range, code;
    const uint8_t *p, *end;
    uint32_t over; /* bytes read past the end */
} rc_dec;

static inline uint8_t next_byte(rc_dec *r)
{
    if (r->p < r->end) return *r->p++;
    r->over++;
    return 0;
}

static inline uint32_t dec_bit(rc_dec *r, uint16_t *p)
{
    uint32_t bound = (r->range >> PROB_BITS) * *p, bit;
    if (r->code < bound) {
        r->range = bound;
        *p = (uint16_t)(*p + ((PROB_ONE - *p) >> MOVE_BITS));
        bit = 0;
    } else {
        r->code -= bound;
        r->range -= bound;
        *p = (uint16_t)(*p - (*p >> MOVE_BITS));
        bit = 1;
    }
    if (r->range < TOP) {
        r->range <<= 8;
        r->code = r->code << 8 | next_byte(r);
    }
    return bit;
}

static uint32_t dec_direct(rc_dec *r, uint32_t nbits)
{
    uint32_t v = 0;
    while (nbits--) {
        r->range >>= 1;
        uint32_t b = r->code >= r->range;
        if (b) r->code -= r->range;
        v = v << 1 | b;
        if (r->range < TOP) {
            r->range <<= 8;
            r->code = r->code << 8 | next_byte(r);
        }
    }
    return v;
}

static uint32_t dec_tree(rc_dec *r, uint16_t *p, uint32_t nbits)
{
    uint32_t m = 1;
    for (uint32_t i = 0; i < nbits; i++) m = m * 2 + dec_bit(r, p + m);
    return m - (1u << nbits);
}

/* 0 for a damaged length (more than 31 bits) */
static uint32_t dec_gamma(rc_dec *r, uint16_t *nb, uint32_t tree_bits, uint16_t *hi)
{
    uint32_t n = dec_tree(r, nb, tree_bits);
    if (n == 0) return 1;
    if (n > 20) return 0;
    uint32_t k = n < 2 ? n : 2u, rest = n - k;
    uint32_t v = 1u << k | dec_tree(r, hi + 3 * n, k);
    return v << rest | dec_direct(r, rest);
}

int fl_copy_decode(fl_copy_model *m, const uint8_t *in, uint32_t n, const uint8_t *base, uint8_t *out)
{
    rc_dec r;
    r.p = in;
    r.end = in + n;
    r.over = 0;
    r.range = 0xFFFFFFFFu;
    if (next_byte(&r) != 0) return -1; /* the encoder's first byte is always 0 */
    r.code = 0;
    for (int i = 0; i < 4; i++) r.code = r.code << 8 | next_byte(&r);
    int delta = base != 0;
    model_reset(m, delta);
    uint32_t pos = 0, state = 0;
    while (pos < FL_FRAME_BYTES) {
        if (r.over) return -1;
        if (!dec_bit(&r, m->p + FL_CP_IS_COPY + state)) {
            uint8_t up = pos >= FL_W ? out[pos - FL_W] : 0;
            out[pos] = (uint8_t)(up + dec_tree(&r, m->p + FL_CP_LIT + FL_CP_LIT_CTX(up), 8));
            pos++;
            state = 0;
            continue;
        }
        int32_t off;
        uint32_t rep0 = dec_bit(&r, m->p + FL_CP_IS_REP0 + state);
        if (rep0) {
            off = m->rep[0];
        } else if (dec_bit(&r, m->p + FL_CP_IS_REP)) {
            uint32_t i = dec_tree(&r, m->p + FL_CP_REP_TREE, 2) + 1u;
            if (i > 3) return -1;
            rep_use(m, i);
            off = m->rep[0];
        } else {
            if (dec_bit(&r, m->p + FL_CP_IS_NEAR)) {
                off = near_off[dec_tree(&r, m->p + FL_CP_NEAR_TREE, 2)];
            } else {
                uint32_t in_base = dec_bit(&r, m->p + FL_CP_IN_BASE);
                uint32_t zy = dec_gamma(&r, m->p + FL_CP_DY, 4, m->p + FL_CP_DY_HI);
                uint32_t zx = dec_gamma(&r, m->p + FL_CP_DX, 4, m->p + FL_CP_DX_HI);
                if (!zy-- || !zx-- || zy > 2u * FL_H || zx > FL_W) return -1;
                int32_t dy = in_base ? ((zy & 1u) ? -(int32_t)(zy + 1u) / 2 : (int32_t)(zy / 2u)) : (int32_t)zy;
                int32_t dx = (zx & 1u) ? -(int32_t)(zx + 1u) / 2 : (int32_t)(zx / 2u);
                int32_t d = dy * FL_W + dx;
                if (!in_base && d == 0) { /* the escape: the rest of the picture plain */
                    if (r.over) return -1;
                    const uint8_t *raw = r.p;
                    if ((uint32_t)(r.end - raw) != FL_FRAME_BYTES - pos) return -1;
                    for (; pos < FL_FRAME_BYTES; pos++) out[pos] = *raw++;
                    return 0;
                }
                off = in_base ? OFF_BASE - d : d;
            }
            rep_push(m, off);
        }
        uint32_t len = dec_gamma(&r, m->p + FL_CP_LEN + (rep0 ? 0u : 32u), 5, m->p + FL_CP_LEN_HI);
        if (!copy_ok(pos, off, len, delta)) return -1;
        int32_t q = (int32_t)pos - off;
        uint8_t *d = out + pos;
        pos += len;
        if (q < 0) { /* from the base, maybe running on into this frame */
            const uint8_t *s = base + q + OFF_BASE;
            uint32_t k = (uint32_t)-q < len ? (uint32_t)-q : len;
            for (uint32_t i = 0; i < k; i++) d[i] = s[i];
            d += k;
            len -= k;
            q = 0;
        }
        const uint8_t *s = out + q;
        for (uint32_t i = 0; i < len; i++) d[i] = s[i];
        state = 1;
    }
    /* every byte read, none past the end (the encoder's flush leaves none over) */
    return r.over || r.p != r.end ? -1 : 0;
}
