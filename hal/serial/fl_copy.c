/* fl_copy.c - the COPY picture coding (method 3) for textured frames: the
 * picture in raster order as copies and literals, range-coded with adaptive
 * binary models. docs/frame-link.md, "Copy coding".
 *
 * A copy takes a run of pixels from somewhere already known: this frame's own
 * pixels (the one to the left for a run of one colour, the row above for a
 * texel taller than a pixel, or any offset) or the base frame (the frame shown
 * before: a turn shifts most of it sideways, distant walls barely change). Four
 * recent offsets are kept, so a shift that holds across a wall costs a few
 * bits per run. A literal is one palette index in the context of the pixel to
 * its left's colour ramp (the top three bits of its index).
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
#define MOVE_BITS 4 /* not less: a probability then stays >= 15/2048, so one byte renormalises */
#define TOP (1u << 24)

/* The model's bit probabilities, by what they decide. A token's kind (literal,
 * rep0, another recent offset, a neighbour, a new offset) is the context of the
 * next token's first decisions. */
enum {
    K_LIT,
    K_REP0,
    K_REP,
    K_NEAR,
    K_NEW,
    K_N,
    P_IS_COPY = 0,                      /* [kind] */
    P_IS_REP0 = P_IS_COPY + K_N,        /* [kind] */
    P_IS_REP = P_IS_REP0 + K_N,         /* [kind] */
    P_IS_NEAR = P_IS_REP + K_N,         /* [kind] */
    P_IN_BASE = P_IS_NEAR + K_N,        /* [kind] */
    P_REP_TREE = P_IN_BASE + K_N,       /* [kind][4]: which other recent offset */
    P_NEAR_TREE = P_REP_TREE + 4 * K_N, /* [kind][4]: which neighbour */
    P_DY = P_NEAR_TREE + 4 * K_N,       /* [16]: a new offset's rows, bit length */
    P_DX = P_DY + 16,                   /* [16]: its columns */
    P_DY_HI = P_DX + 16,                /* [64]: the two bits below the top one, per length */
    P_DX_HI = P_DY_HI + 64,
    P_LEN = P_DX_HI + 64,      /* [copy kind 1..4][32]: a copy's length, bit length */
    P_LEN_HI = P_LEN + 32 * 4, /* [copy kind][64] */
    P_LIT = P_LEN_HI + 64 * 4, /* [8][256]: a literal, by the top bits of the pixel left of it (its colour ramp) */
    P_END = P_LIT + 8 * 256
};
_Static_assert(P_END <= FL_CP_PROBS, "the model fits fl_copy_model");
#define LIT_CTX(left) (P_LIT + ((uint32_t)(left) >> 5) * 256u)

/* offsets: src = pos - off in the virtual line [base (64,000) | this frame] */
#define OFF_BASE ((int32_t)FL_FRAME_BYTES)
#define NEAR_N 4
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

/* The encoder's choice: the copy that saves the most bits against literals,
 * by rough costs in bits (a literal about 6; a copy its kind and its length). */
#define LIT_BITS 6
typedef struct {
    uint32_t kind, i, len;
    int32_t off, gain;
} cand;

static inline uint32_t len_bits(uint32_t len)
{
    uint32_t n = 0;
    while ((len >> n) > 1u) n++;
    return 2u * n + 1u;
}

static void consider(cand *b, uint32_t kind, uint32_t i, int32_t off, uint32_t len)
{
    static const uint8_t kind_bits[K_N] = {0, 3, 7, 10, 30}; /* measured on textured walks */
    int32_t gain = (int32_t)(len * LIT_BITS) - (int32_t)(kind_bits[kind] + len_bits(len));
    if (len && gain > b->gain) {
        b->kind = kind;
        b->i = i;
        b->len = len;
        b->off = off;
        b->gain = gain;
    }
}

static inline int is_rep(const fl_copy_model *m, int32_t off)
{
    return off == m->rep[0] || off == m->rep[1] || off == m->rep[2] || off == m->rep[3];
}

static inline uint32_t hash4(const uint8_t *p)
{
    uint32_t v = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    return (v * 0x9E3779B1u) >> (32 - FL_CP_HASH_BITS);
}

static void lit_encode(rc_enc *r, fl_copy_model *m, const uint8_t *px, uint32_t pos)
{
    enc_tree(r, m->p + LIT_CTX(pos ? px[pos - 1] : 0), px[pos], 8);
}


uint32_t fl_copy_encode(fl_copy_model *m, const uint8_t *px, const uint8_t *base, int32_t *hash, fl_writer *w)
{
    rc_enc r; /* no initialiser: freestanding targets have no memset */
    r.low = 0;
    r.range = 0xFFFFFFFFu;
    r.pending = 1;
    r.cache = 0;
    r.out = 0;
    r.n = 0;
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
            enc_bit(&r, m->p + P_IS_COPY + state, 1);
            enc_bit(&r, m->p + P_IS_REP0 + state, 0);
            enc_bit(&r, m->p + P_IS_REP + state, 0);
            enc_bit(&r, m->p + P_IS_NEAR + state, 0);
            enc_bit(&r, m->p + P_IN_BASE + state, 0);
            enc_gamma(&r, m->p + P_DY, 4, m->p + P_DY_HI, 1); /* dy 0 */
            enc_gamma(&r, m->p + P_DX, 4, m->p + P_DX_HI, 1); /* dx 0: offset 0 */
            enc_flush(&r);
            fl_writer_direct(w, px + pos, left);
            return r.out + left;
        }
        /* candidates: the recent offsets, the neighbours, a hashed position */
        cand best = {0, 0, 0, 0, 0};
        uint8_t here = px[pos];
        for (uint32_t i = 0; i < 4; i++) {
            int32_t off = m->rep[i];
            if (copy_ok(pos, off, 1, delta) && vpix(px, base, (int32_t)pos - off) == here)
                consider(&best, i == 0 ? K_REP0 : K_REP, i, off, match_len(px, base, pos, off, left));
        }
        for (uint32_t i = 0; i < NEAR_N; i++) {
            int32_t off = near_off[i];
            if (copy_ok(pos, off, 1, delta) && vpix(px, base, (int32_t)pos - off) == here && !is_rep(m, off))
                consider(&best, K_NEAR, i, off, match_len(px, base, pos, off, left));
        }
        if (hash && left >= 4) {
            int32_t q = hash[hash4(px + pos)];
            int32_t off = q == INT32_MIN ? 0 : (int32_t)pos - q;
            if (copy_ok(pos, off, 1, delta) && !is_rep(m, off))
                consider(&best, K_NEW, 0, off, match_len(px, base, pos, off, left));
        }
        uint32_t best_len = best.len, best_i = best.i;
        int32_t best_off = best.off;
        if (best_len == 0) {
            enc_bit(&r, m->p + P_IS_COPY + state, 0);
            lit_encode(&r, m, px, pos);
            if (hash && left >= 4) hash[hash4(px + pos)] = (int32_t)pos;
            pos++;
            state = K_LIT;
            continue;
        }
        uint32_t kind = best.kind; /* K_REP0 .. K_NEW: consider() named it */
        enc_bit(&r, m->p + P_IS_COPY + state, 1);
        enc_bit(&r, m->p + P_IS_REP0 + state, kind == K_REP0);
        if (kind != K_REP0) {
            enc_bit(&r, m->p + P_IS_REP + state, kind == K_REP);
            if (kind == K_REP) {
                enc_tree(&r, m->p + P_REP_TREE + 4 * state, best_i - 1, 2); /* 0..2: rep1..rep3 */
                rep_use(m, best_i);
            } else {
                enc_bit(&r, m->p + P_IS_NEAR + state, kind == K_NEAR);
                if (kind == K_NEAR) {
                    enc_tree(&r, m->p + P_NEAR_TREE + 4 * state, best_i, 2);
                } else {
                    /* a new offset: where, as rows and columns */
                    int32_t q = (int32_t)pos - best_off, in_base = q < 0;
                    int32_t d = in_base ? q + OFF_BASE - (int32_t)pos : best_off; /* base: motion; else back */
                    enc_bit(&r, m->p + P_IN_BASE + state, (uint32_t)in_base);
                    /* d = dy * 320 + dx with dx in -160..159 */
                    int32_t dy = (d + 160 + 320 * 400) / 320 - 400, dx = d - dy * 320;
                    uint32_t zy = in_base ? (dy < 0 ? (uint32_t)(-2 * dy) - 1u : (uint32_t)(2 * dy)) : (uint32_t)dy;
                    uint32_t zx = dx < 0 ? (uint32_t)(-2 * dx) - 1u : (uint32_t)(2 * dx);
                    enc_gamma(&r, m->p + P_DY, 4, m->p + P_DY_HI, zy + 1u);
                    enc_gamma(&r, m->p + P_DX, 4, m->p + P_DX_HI, zx + 1u);
                }
                rep_push(m, best_off);
            }
        }
        enc_gamma(&r, m->p + P_LEN + 32 * (kind - 1), 5, m->p + P_LEN_HI + 64 * (kind - 1), best_len);
        if (hash)
            for (uint32_t i = 0; i < best_len && pos + i + 4 <= FL_FRAME_BYTES; i++)
                hash[hash4(px + pos + i)] = (int32_t)(pos + i);
        pos += best_len;
        state = kind;
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

#define HOT static inline __attribute__((always_inline))

HOT uint8_t next_byte(rc_dec *r)
{
    if (r->p < r->end) return *r->p++;
    r->over++;
    return 0;
}

HOT uint32_t dec_bit(rc_dec *r, uint16_t *p)
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

HOT uint32_t dec_direct(rc_dec *r, uint32_t nbits)
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

HOT uint32_t dec_tree(rc_dec *r, uint16_t *p, uint32_t nbits)
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

/* n bytes from s to d, a word at a time: d is at least 4 bytes past s, or
 * in another buffer (words may be unaligned: x86 and the Cortex-M3 take them). */
HOT void copy_words(uint8_t *d, const uint8_t *s, uint32_t n)
{
    for (; n >= 4; n -= 4, d += 4, s += 4) {
        uint32_t w;
        __builtin_memcpy(&w, s, 4);
        __builtin_memcpy(d, &w, 4);
    }
    while (n--) *d++ = *s++;
}

/* n bytes of v (a run of one colour: a copy from the pixel to the left) */
HOT void fill(uint8_t *d, uint8_t v, uint32_t n)
{
    uint32_t w = v * 0x01010101u;
    for (; n >= 4; n -= 4, d += 4) __builtin_memcpy(d, &w, 4);
    while (n--) *d++ = v;
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
    uint32_t pos = 0, state = K_LIT;
    while (pos < FL_FRAME_BYTES) {
        if (r.over) return -1;
        if (!dec_bit(&r, m->p + P_IS_COPY + state)) {
            out[pos] = (uint8_t)dec_tree(&r, m->p + LIT_CTX(pos ? out[pos - 1] : 0), 8);
            pos++;
            state = K_LIT;
            continue;
        }
        int32_t off;
        uint32_t kind;
        if (dec_bit(&r, m->p + P_IS_REP0 + state)) {
            kind = K_REP0;
            off = m->rep[0];
        } else if (dec_bit(&r, m->p + P_IS_REP + state)) {
            kind = K_REP;
            uint32_t i = dec_tree(&r, m->p + P_REP_TREE + 4 * state, 2) + 1u;
            if (i > 3) return -1;
            rep_use(m, i);
            off = m->rep[0];
        } else {
            if (dec_bit(&r, m->p + P_IS_NEAR + state)) {
                kind = K_NEAR;
                off = near_off[dec_tree(&r, m->p + P_NEAR_TREE + 4 * state, 2)];
            } else {
                kind = K_NEW;
                uint32_t in_base = dec_bit(&r, m->p + P_IN_BASE + state);
                uint32_t zy = dec_gamma(&r, m->p + P_DY, 4, m->p + P_DY_HI);
                uint32_t zx = dec_gamma(&r, m->p + P_DX, 4, m->p + P_DX_HI);
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
        uint32_t len = dec_gamma(&r, m->p + P_LEN + 32 * (kind - 1), 5, m->p + P_LEN_HI + 64 * (kind - 1));
        if (!copy_ok(pos, off, len, delta)) return -1;
        int32_t q = (int32_t)pos - off;
        uint8_t *d = out + pos;
        pos += len;
        if (q < 0) { /* from the base, maybe running on into this frame */
            uint32_t k = (uint32_t)-q < len ? (uint32_t)-q : len;
            copy_words(d, base + q + OFF_BASE, k);
            d += k;
            len -= k;
            q = 0;
        }
        if (off == 1)
            fill(d, d[-1], len);
        else if ((uint32_t)off >= 4u)
            copy_words(d, out + q, len);
        else
            for (uint32_t i = 0; i < len; i++) d[i] = out[q + i];
        state = kind;
    }
    /* every byte read, none past the end (the encoder's flush leaves none over) */
    return r.over || r.p != r.end ? -1 : 0;
}
