/* fl_codec.c - the picture coding of the frame link (method EDGE), and the
 * frame check.
 *
 * Each row of a 320x200 frame is coded as its colour transitions, predicted
 * from the transitions of the row above: an edge keeps its colour and moves by
 * what it moved the row before. A row that is exactly as predicted is one
 * symbol; otherwise each edge of the row above is one symbol when it continues
 * exactly or moves by one pixel, and new, ended, recoloured and further moved
 * edges take a few more. A delta also says, per row, whether the row equals
 * the base frame's row. The symbols are range coded with fixed frequency
 * tables (fl_tables.inc, measured on fly-throughs of other maps than the
 * benchmark's): one multiply per symbol, no adaptation, so the encoder stays
 * cheap. The grammar is docs/frame-link.md, "Picture coding";
 * tools/framelink.py decodes the same symbols.
 *
 * Encoder cost per frame: one word-at-a-time pass over the pixels (on a
 * Cortex-M3 four words per load-multiple), which also yields the transitions
 * and the row hashes of the frame check, plus about one symbol per transition
 * of the rows that are not exactly as predicted. */
#include <stddef.h>

#include "framelink.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "framelink: little-endian targets only"
#endif

#define D_MAX 8     /* largest |movement| of an edge that continues */
#define NPOS_BITS 9 /* positions 1..319 */
#define TOTAL_BITS 12

/* Symbols. */
enum { ROW_SAME, ROW_TRIV, ROW_CODED, ROW_CODED_C0, ROW_KINDS };
enum { OP_K0, OP_UP, OP_DOWN, OP_KEEP, OP_END, OP_NEW, OP_EOL, OPS }; /* UP: +1 pixel, DOWN: -1 */
enum { COL_CAND0, COL_CAND1, COL_CACHE0, COL_LITERAL = COL_CACHE0 + FL_CACHE, COLS };
enum { SET_C0 = 0, SET_KEEP = 1, SET_NEW = 2 };
enum { PREV_START = 0, PREV_K0 = 1, PREV_KD = 2, PREV_END = 3, PREV_NEW = 4 };

/* Frequency tables (cumulative, out of 4096), one after the other:
 *   T_ROW    8 x 5   [delta * 4 + previous row kind] row kind
 *   T_OP    20 x 8   [vc * 5 + prev] what the next edge of the row above does
 *   T_NOEDGE 1 x 3   no edge left: OP_NEW (0) or OP_EOL (1)
 *   T_MOVE   4 x 18  [vc] OP_KEEP: the movement + 8 (0..16)
 *   T_KC     4 x 3   [vc] moved two or more pixels: colour kept (0) or changed (1)
 *   T_COL    3 x 8   [set] a colour
 *   T_NPOS   1 x 10  bit length - 1 of a new transition's distance from the last */
enum {
    T_ROW = 0,
    T_OP = T_ROW + 8 * (ROW_KINDS + 1),
    T_NOEDGE = T_OP + 20 * (OPS + 1),
    T_MOVE = T_NOEDGE + 3,
    T_KC = T_MOVE + 4 * 18,
    T_COL = T_KC + 4 * 3,
    T_NPOS = T_COL + 3 * (COLS + 1),
    T_END = T_NPOS + 10
};

static const uint16_t cum[] = {
#include "fl_tables.inc"
};
_Static_assert(sizeof cum / sizeof cum[0] == T_END, "fl_tables.inc: wrong size");

#define FORCE_INLINE static inline __attribute__((always_inline))

/* ---- shared helpers ---------------------------------------------------------- */

/* Velocity class of an edge that moved by v since the row above (0: unknown). */
FORCE_INLINE int32_t vclass(int v)
{
    return v == 0 ? 1 : ((unsigned)(v + 1) <= 2u ? 2 : 3);
}

/* Edges: pk = next row's predicted position * 256 + colour, dv = 256 * how far
 * the edge moved since the row above (its position is (pk - dv) >> 8). */
FORCE_INLINE void put_edge(fl_edges *e, uint32_t k, int32_t pk, int32_t dv, int32_t vc)
{
    e->pk[k] = pk;
    e->dv[k] = dv;
    e->vc[k] = vc;
}

/* Edge j of ref continues at a = x * 256 + colour: edge k of out. */
FORCE_INLINE void continue_edge(const fl_edges *ref, uint32_t j, fl_edges *out, uint32_t k, int32_t a)
{
    int32_t dv = ref->dv[j] + ((a >> 8) - (ref->pk[j] >> 8)) * 256; /* + 256 * the movement off the prediction */
    put_edge(out, k, a + dv, dv, vclass(dv >> 8));
}

/* Edges of a row from its transitions, movement unknown (a row copied from the base). */
static void edges_of_transitions(fl_edges *e, const int32_t *at, uint32_t n)
{
    for (uint32_t k = 0; k < n; k++) put_edge(e, k, at[k], 0, 0);
    e->n = n;
}

/* Every edge continues exactly as predicted (a trivial row): in place. */
static void advance_edges(fl_edges *e)
{
    for (uint32_t k = 0; k < e->n; k++) {
        e->pk[k] += e->dv[k];
        if (!e->vc[k]) e->vc[k] = 1;
    }
}

static void cache_reset(fl_coder *c)
{
    for (int i = 0; i < FL_CACHE; i++) c->cache[i] = (uint8_t)i;
}

static void cache_put(fl_coder *c, int col)
{
    uint8_t *m = c->cache;
    int k = 0;
    while (k < FL_CACHE - 1 && m[k] != col) k++;
    for (; k > 0; k--) m[k] = m[k - 1];
    m[0] = (uint8_t)col;
}

/* ---- the frame check ------------------------------------------------------ */

FORCE_INLINE uint32_t mix(uint32_t h)
{
    h *= 0x9E3779B1u;
    return h ^ (h >> 16);
}

#define ROW_HASH0 0x811C9DC5u

static uint32_t fmix(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    h *= 0xC2B2AE35u;
    return h ^ (h >> 16);
}

/* ---- scanning rows -------------------------------------------------------- */

/* Word-at-a-time access to pixel rows (320 bytes: a whole number of words). */
typedef unsigned long fl_word __attribute__((may_alias));
#define WB ((int)sizeof(fl_word))
#define NW (FL_W / WB)
#define ONES ((fl_word) ~(fl_word)0 / 0xFF)

/* The first word in [w, end) that differs from bc, or end: the common case,
 * kept tight (one compare and branch per word; on a Cortex-M3 four words per
 * load-multiple under one IT block). */
FORCE_INLINE const fl_word *skip_equal(const fl_word *w, const fl_word *end, fl_word bc)
{
#if defined(__ARM_ARCH_7M__) && defined(__thumb2__) && !defined(FL_NO_ASM)
    /* stops at the first word that differs, or where fewer than four are left */
    const fl_word *end4 = end - 3;
    register const fl_word *p __asm__("r0") = w;
    __asm__ volatile("1:  cmp     %[p], %[end4]\n"
                     "    bhs     2f\n"
                     "    ldmia   %[p]!, {r4, r5, r6, r7}\n"
                     "    cmp     r4, %[bc]\n"
                     "    ittt    eq\n"
                     "    cmpeq   r5, %[bc]\n"
                     "    cmpeq   r6, %[bc]\n"
                     "    cmpeq   r7, %[bc]\n"
                     "    beq     1b\n"
                     "    subs    %[p], #16\n" /* which of the four */
                     "    cmp     r4, %[bc]\n"
                     "    bne     2f\n"
                     "    adds    %[p], #4\n"
                     "    cmp     r5, %[bc]\n"
                     "    bne     2f\n"
                     "    adds    %[p], #4\n"
                     "    cmp     r6, %[bc]\n"
                     "    it      eq\n"
                     "    addeq   %[p], #4\n"
                     "2:\n"
                     : [p] "+r"(p)
                     : [end4] "r"(end4), [bc] "r"(bc)
                     : "r4", "r5", "r6", "r7", "cc", "memory");
    if (p < end4) return p;
    w = p;
#else
    while (w + 4 <= end) {
        if (w[0] != bc) return w;
        if (w[1] != bc) return w + 1;
        if (w[2] != bc) return w + 2;
        if (w[3] != bc) return w + 3;
        w += 4;
    }
#endif
    while (w < end && *w == bc) w++;
    return w;
}

/* The transitions of a row, packed as x * 256 + colour (x = 1..319, where the
 * colour changes; the colour from there on), and the row's hash for the frame
 * check. Returns their count. */
static uint32_t scan_row(const uint8_t *row, int aligned, int32_t *at, uint32_t *hash)
{
    uint32_t n = 0, h = mix(ROW_HASH0 ^ row[0]);
    if (!aligned) {
        uint8_t cur = row[0];
        for (int x = 1; x < FL_W; x++)
            if (row[x] != cur) {
                cur = row[x];
                at[n] = x * 256 + cur;
                h = mix(h ^ (uint32_t)at[n++]);
            }
        *hash = h;
        return n;
    }
    const fl_word *w = (const fl_word *)(const void *)row, *end = w + NW;
    fl_word bc = (fl_word)row[0] * ONES;
    for (;;) {
        w = skip_equal(w, end, bc);
        if (w == end) break;
        /* a word with transitions: byte i of t = v ^ (v << 8 | the byte before)
         * is nonzero where one is */
        fl_word v = *w, t = v ^ ((v << 8) | (bc >> (8 * (WB - 1))));
        int32_t x0 = (int32_t)((const uint8_t *)w - row) * 256;
        do {
            int sh = __builtin_ctzl(t) & ~7;
            int32_t a = x0 + (sh << 5) + (int32_t)((v >> sh) & 0xFF);
            at[n++] = a;
            h = mix(h ^ (uint32_t)a);
            t &= ~((fl_word)0xFF << sh);
        } while (t);
        bc = (v >> (8 * (WB - 1))) * ONES;
        w++;
    }
    *hash = h;
    return n;
}

static int rows_equal(const uint8_t *a, const uint8_t *b, int aligned)
{
    if (!aligned) {
        for (int x = 0; x < FL_W; x++)
            if (a[x] != b[x]) return 0;
        return 1;
    }
#if defined(__ARM_ARCH_7M__) && defined(__thumb2__) && !defined(FL_NO_ASM)
    register const uint8_t *u __asm__("r0") = a;
    register const uint8_t *v __asm__("r1") = b;
    uint32_t same;
    const uint8_t *end = a + FL_W;
    __asm__ volatile("1:  ldmia   %[u]!, {r4, r5, r6, r7}\n"
                     "    ldmia   %[v]!, {r8, r9, r10, r11}\n"
                     "    cmp     r4, r8\n"
                     "    ittt    eq\n"
                     "    cmpeq   r5, r9\n"
                     "    cmpeq   r6, r10\n"
                     "    cmpeq   r7, r11\n"
                     "    bne     2f\n"
                     "    cmp     %[u], %[end]\n"
                     "    bne     1b\n"
                     "    mov     %[same], #1\n"
                     "    b       3f\n"
                     "2:  mov     %[same], #0\n"
                     "3:\n"
                     : [u] "+r"(u), [v] "+r"(v), [same] "=r"(same)
                     : [end] "r"(end)
                     : "r4", "r5", "r6", "r7", "r8", "r9", "r10", "r11", "cc", "memory");
    return (int)same;
#else
    const fl_word *u = (const fl_word *)(const void *)a, *v = (const fl_word *)(const void *)b;
    for (int i = 0; i < NW; i += 4)
        if (u[i] != v[i] || u[i + 1] != v[i + 1] || u[i + 2] != v[i + 2] || u[i + 3] != v[i + 3]) return 0;
    return 1;
#endif
}

uint32_t fl_frame_check(const uint8_t *px)
{
    int32_t at[FL_W];
    int aligned = ((uintptr_t)px & (uintptr_t)(WB - 1)) == 0;
    uint32_t f = 0, h;
    for (int y = 0; y < FL_H; y++) {
        scan_row(px + y * FL_W, aligned, at, &h);
        f = mix(f ^ h);
    }
    return fmix(f);
}

/* The RAW_HASH frame check: h = (word ^ (h rotated right by 19)) * odd, over the
 * 16,000 words, then fmix. Each step is a bijection of h, so a difference that
 * one word makes is never undone by the words after it; the rotation carries
 * the high bits (which a multiply never moves down) back into the low ones.
 * Two instructions a word on a Cortex-M3 (eor with a rotated operand, mul). */
uint32_t fl_pixel_hash(const uint8_t *px)
{
    uint32_t h = ROW_HASH0;
    if ((uintptr_t)px & 3u) {
        for (uint32_t i = 0; i < FL_FRAME_BYTES; i += 4) {
            uint32_t v = (uint32_t)px[i] | (uint32_t)px[i + 1] << 8 | (uint32_t)px[i + 2] << 16 |
                         (uint32_t)px[i + 3] << 24;
            h = (v ^ (h >> 19 | h << 13)) * 0x9E3779B1u;
        }
        return fmix(h);
    }
    typedef uint32_t u32a __attribute__((may_alias));
    const u32a *w = (const u32a *)(const void *)px, *end = w + FL_FRAME_BYTES / 4;
    for (; w < end; w += 4) {
        h = (w[0] ^ (h >> 19 | h << 13)) * 0x9E3779B1u;
        h = (w[1] ^ (h >> 19 | h << 13)) * 0x9E3779B1u;
        h = (w[2] ^ (h >> 19 | h << 13)) * 0x9E3779B1u;
        h = (w[3] ^ (h >> 19 | h << 13)) * 0x9E3779B1u;
    }
    return fmix(h);
}

/* Colour transitions of one row: the nonzero bytes of each word XOR the same
 * word shifted by one pixel. */
static uint32_t count_transitions(const uint8_t *row)
{
    uint32_t n = 0;
    for (int x = 1; x < FL_W; x++) n += row[x] != row[x - 1];
    return n;
}

static uint32_t count_transitions_words(const uint8_t *row)
{
    typedef uint32_t u32a __attribute__((may_alias));
    const u32a *w = (const u32a *)(const void *)row;
    uint32_t n = 0, prev = (uint32_t)row[0];
    for (int i = 0; i < FL_W / 4; i++) {
        uint32_t v = w[i], t = v ^ (v << 8 | prev);
        prev = v >> 24;
        t |= t >> 4;
        t |= t >> 2;
        t |= t >> 1;
        n += ((t & 0x01010101u) * 0x01010101u) >> 24;
    }
    return n;
}

uint32_t fl_estimate_transitions(const uint8_t *px, const uint8_t *base)
{
    int aligned = (((uintptr_t)px | (uintptr_t)(base ? base : px)) & (uintptr_t)(WB - 1)) == 0;
    uint32_t n = 0;
    for (int y = 4; y < FL_H; y += 16) {
        const uint8_t *row = px + y * FL_W;
        if (base && rows_equal(row, base + y * FL_W, aligned)) continue;
        n += aligned ? count_transitions_words(row) : count_transitions(row);
    }
    return n * 16;
}

/* ======================================================================== */
/* Encoder                                                                  */
/* ======================================================================== */

/* The range coder (as LZMA's, with the carry propagated back into the output
 * buffer instead of LZMA's cache byte, so low fits in 32 bits). */
typedef struct {
    uint32_t low, range;
    uint8_t *p, *end, *start;
    uint8_t overflow;
} rc_enc;

/* low wrapped: add one to the bytes already out (the coded value stays below
 * 1, so the carry never runs past the first byte). */
static __attribute__((noinline)) void rc_carry(uint8_t *start, uint8_t *p)
{
    while (p > start && *--p == 0xFF) *p = 0;
    if (p >= start) (*p)++;
}

static __attribute__((noinline)) void rc_norm(rc_enc *r)
{
    do {
        if (r->p < r->end)
            *r->p++ = (uint8_t)(r->low >> 24);
        else
            r->overflow = 1;
        r->low <<= 8;
        r->range <<= 8;
    } while (r->range < (1u << 24));
}

FORCE_INLINE void rc_add(rc_enc *r, uint32_t add)
{
    uint32_t low = r->low + add;
    if (low < r->low && !r->overflow) rc_carry(r->start, r->p);
    r->low = low;
}

/* Symbol s of the table at t. */
FORCE_INLINE void rc_sym(rc_enc *r, int t, int s)
{
    uint32_t q = r->range >> TOTAL_BITS, lo = cum[t + s];
    if (lo) rc_add(r, q * lo);
    r->range = q * (cum[t + s + 1] - lo);
    if (r->range < (1u << 24)) rc_norm(r);
}

/* v, 0 <= v < 2^n (n <= 8), all values equally likely: one step. */
static void rc_bits(rc_enc *r, uint32_t v, int n)
{
    uint32_t q = r->range >> n;
    v &= (1u << n) - 1;
    if (v) rc_add(r, q * v);
    r->range = q;
    if (r->range < (1u << 24)) rc_norm(r);
}

/* Finish: pick the value in [low, low + range) with the most trailing zero
 * bytes, write it out, and drop the trailing zero bytes but the first (the
 * decoder reads zeros past the end). Returns the byte count. */
static uint32_t rc_finish(rc_enc *r)
{
    uint64_t low = r->low, hi = low + r->range - 1, v = low;
    for (int k = 32; k > 0; k -= 8) {
        uint64_t mask = ((uint64_t)1 << k) - 1;
        v = (low + mask) & ~mask;
        if (v <= hi) break;
        v = low;
    }
    if ((v >> 32) && !r->overflow) rc_carry(r->start, r->p);
    for (int i = 3; i >= 0; i--) {
        if (r->p < r->end)
            *r->p++ = (uint8_t)(v >> (8 * i));
        else
            r->overflow = 1;
    }
    /* at least one byte: 0 means "did not fit" */
    while (r->p > r->start + 1 && r->p[-1] == 0) r->p--;
    return (uint32_t)(r->p - r->start);
}

/* Code colour col, known to differ from ex0 and ex1, given up to two
 * candidate colours (negative: none). */
static void enc_colour(rc_enc *r, fl_coder *c, int set, int col, int cand0, int cand1, int ex0, int ex1)
{
    int t = T_COL + set * (COLS + 1);
    if (cand0 == ex0 || cand0 == ex1) cand0 = -1;
    if (cand1 == ex0 || cand1 == ex1 || cand1 == cand0) cand1 = -1;
    if (col == cand0) {
        rc_sym(r, t, COL_CAND0);
        return;
    }
    if (col == cand1) {
        rc_sym(r, t, COL_CAND1);
        return;
    }
    int rank = 0;
    for (int k = 0; k < FL_CACHE; k++) {
        int m = c->cache[k];
        if (m == ex0 || m == ex1 || m == cand0 || m == cand1) continue;
        if (m == col) {
            rc_sym(r, t, COL_CACHE0 + rank);
            cache_put(c, col);
            return;
        }
        rank++;
    }
    rc_sym(r, t, COL_LITERAL);
    rc_bits(r, (uint32_t)col, 8);
    cache_put(c, col);
}

/* The row coder's state: the common case (an edge continues exactly as
 * predicted) is coded in enc_row's loop; everything else goes through enc_op. */
typedef struct {
    rc_enc r;
    fl_coder *c;
    const int32_t *at;    /* the row's transitions */
    const fl_edges *ref;  /* the row above's edges */
    fl_edges *out;        /* this row's edges */
    const uint8_t *above; /* the row above's pixels, or NULL */
    uint32_t na, rn;      /* transitions, reference edges */
    uint32_t i, j, no;    /* next transition, next reference edge, edges out */
    int c0, prev;
} row_enc;

/* One operation other than "the edge continues exactly as predicted" (which
 * enc_row has ruled out for (i, j)). Returns 1 at the end of the row. */
static __attribute__((noinline)) int enc_op(row_enc *s)
{
    rc_enc *r = &s->r;
    const int32_t *at = s->at;
    const fl_edges *ref = s->ref;
    uint32_t i = s->i, j = s->j, na = s->na, rn = s->rn;
    int a0 = i ? at[i - 1] >> 8 : 0, cur = i ? at[i - 1] & 0xFF : s->c0;
    if (j == rn) {
        rc_sym(r, T_NOEDGE, i == na);
        if (i == na) return 1;
    } else {
        int32_t pk = ref->pk[j];
        int p = pk >> 8, vc = ref->vc[j], t = T_OP + (vc * 5 + s->prev) * (OPS + 1);
        if (i < na) {
            int32_t a = at[i];
            int d = (a >> 8) - p;
            if ((unsigned)(d + D_MAX) <= 2u * D_MAX) { /* the edge continues, moved or recoloured */
                int col = a & 0xFF, pc = pk & 0xFF;
                if (col == pc && (d == 1 || d == -1)) {
                    rc_sym(r, t, d > 0 ? OP_UP : OP_DOWN);
                } else {
                    rc_sym(r, t, OP_KEEP);
                    rc_sym(r, T_MOVE + vc * 18, d + D_MAX);
                    int changed = col != pc;
                    if (d > 1 || d < -1) {
                        if (pc != cur) rc_sym(r, T_KC + vc * 3, changed);
                    }
                    if (changed)
                        enc_colour(r, s->c, SET_KEEP, col, j + 1 < rn ? (ref->pk[j + 1] & 0xFF) : -1,
                                   j + 2 < rn ? (ref->pk[j + 2] & 0xFF) : -1, cur, pc);
                }
                continue_edge(ref, j, s->out, s->no++, a);
                s->prev = d ? PREV_KD : PREV_K0;
                s->i = i + 1;
                s->j = j + 1;
                return 0;
            }
        }
        if (i == na) { /* end of row: the edges left end here */
            rc_sym(r, t, OP_EOL);
            return 1;
        }
        if (p < (at[i] >> 8)) { /* this edge has ended */
            rc_sym(r, t, OP_END);
            s->j = j + 1;
            s->prev = PREV_END;
            return 0;
        }
        rc_sym(r, t, OP_NEW);
    }
    /* a new transition */
    int x = at[i] >> 8, col = at[i] & 0xFF;
    unsigned dist = (unsigned)(x - a0);
    int len = 32 - __builtin_clz(dist);
    rc_sym(r, T_NPOS, len - 1);
    rc_bits(r, dist & ((1u << (len - 1)) - 1), len - 1);
    enc_colour(r, s->c, SET_NEW, col, s->above ? s->above[x] : -1, j < rn ? (ref->pk[j] & 0xFF) : -1, cur, cur);
    put_edge(s->out, s->no++, at[i], 0, 0);
    s->prev = PREV_NEW;
    s->i = i + 1;
    return 0;
}

/* Code one row against the reference edges s->ref, after its ROW_CODED or
 * ROW_CODED_C0 symbol. s->out receives the row's edges. */
/* Symbol sym of table t, with the coder's hot state in the caller's locals. */
FORCE_INLINE void sym_local(rc_enc *r, uint32_t *low, uint32_t *range, const uint16_t *t, int sym)
{
    uint32_t q = *range >> TOTAL_BITS, lo = t[sym];
    if (lo) {
        uint32_t nl = *low + q * lo;
        if (nl < *low && !r->overflow) rc_carry(r->start, r->p);
        *low = nl;
    }
    *range = q * (t[sym + 1] - lo);
    if (*range < (1u << 24)) {
        r->low = *low;
        r->range = *range;
        rc_norm(r);
        *low = r->low;
        *range = r->range;
    }
}

#define NE FL_ROW_EDGES /* p[NE] is the dv of the edge whose pk is p[0], p[2 * NE] its vc */
_Static_assert(offsetof(fl_edges, dv) == NE * sizeof(int32_t) && offsetof(fl_edges, vc) == 2 * NE * sizeof(int32_t),
               "fl_edges: three arrays back to back");

static __attribute__((noinline)) void enc_row(row_enc *s, int c0ref)
{
    const int32_t *at = s->at, *rpk = s->ref->pk;
    if (s->c0 != c0ref) enc_colour(&s->r, s->c, SET_C0, s->c0, s->rn ? (rpk[0] & 0xFF) : -1, -1, c0ref, c0ref);
    /* pointers into the transitions, the edges above and the edges out: every
     * per-edge value is at a fixed offset from them */
    const int32_t *ap = at, *ae = at + s->na, *rp = rpk, *re = rpk + s->rn;
    int32_t *op = s->out->pk;
    uint32_t low = s->r.low, range = s->r.range;
    int prev = PREV_START;
    for (;;) {
        if (rp < re) {
            int32_t vc = rp[2 * NE];
            const uint16_t *t = cum + T_OP + (vc * 5 + prev) * (OPS + 1);
            if (ap < ae) {
                /* the edge continues exactly as predicted, or one pixel off with
                 * its colour: the common cases, coded here */
                int32_t a = *ap, diff = a - *rp;
                if (diff == 0) { /* OP_K0, the first symbol: low stays */
                    range = (range >> TOTAL_BITS) * t[1];
                    if (range < (1u << 24)) {
                        s->r.low = low;
                        s->r.range = range;
                        rc_norm(&s->r);
                        low = s->r.low;
                        range = s->r.range;
                    }
                    int32_t dv = rp[NE];
                    op[0] = a + dv;
                    op[NE] = dv;
                    op[2 * NE] = vc + (vc == 0);
                    ap++;
                    rp++;
                    op++;
                    prev = PREV_K0;
                    continue;
                }
                if (diff == 256 || diff == -256) {
                    sym_local(&s->r, &low, &range, t, diff > 0 ? OP_UP : OP_DOWN);
                    int32_t dv = rp[NE] + diff;
                    op[0] = a + dv;
                    op[NE] = dv;
                    op[2 * NE] = vclass(dv >> 8);
                    ap++;
                    rp++;
                    op++;
                    prev = PREV_KD;
                    continue;
                }
            } else { /* no transition left: the row ends */
                sym_local(&s->r, &low, &range, t, OP_EOL);
                break;
            }
        } else if (ap == ae) {
            sym_local(&s->r, &low, &range, cum + T_NOEDGE, 1);
            break;
        }
        s->r.low = low;
        s->r.range = range;
        s->i = (uint32_t)(ap - at);
        s->j = (uint32_t)(rp - rpk);
        s->no = (uint32_t)(op - s->out->pk);
        s->prev = prev;
        int end = enc_op(s);
        ap = at + s->i;
        rp = rpk + s->j;
        op = s->out->pk + s->no;
        prev = s->prev;
        low = s->r.low;
        range = s->r.range;
        if (end) break;
    }
    s->r.low = low;
    s->r.range = range;
    s->out->n = (uint32_t)(op - s->out->pk);
}

/* After row y: is the picture's coding on course to overflow cap? Checked every
 * 8 rows from row GIVE_UP_FROM on: the bytes so far, spread over all the rows,
 * above GIVE_UP_MARGIN / 4 of cap. A frame that would overflow is given up a
 * fraction of the way in instead of at its last rows (its frame goes raw); one
 * whose detail sits in its top rows may be given up though it would fit. */
#define GIVE_UP_FROM 31
#define GIVE_UP_MARGIN 5
FORCE_INLINE int gives_up(const rc_enc *r, uint32_t cap, int y)
{
    if (y < GIVE_UP_FROM || (y & 7) != 7) return 0;
    uint32_t used = (uint32_t)(r->p - r->start);
    return used * (4u * FL_H) > cap * GIVE_UP_MARGIN * (uint32_t)(y + 1);
}

uint32_t fl_code_picture(fl_coder *c, const uint8_t *px, const uint8_t *base, uint8_t *out, uint32_t cap,
                         uint32_t *check)
{
    cache_reset(c);
    row_enc s;
    rc_enc *r = &s.r;
    r->low = 0;
    r->range = 0xFFFFFFFFu;
    r->p = r->start = out;
    r->end = out + cap;
    r->overflow = 0;
    s.c = c;
    s.at = c->at;
    int aligned = (((uintptr_t)px | (uintptr_t)(base ? base : px)) & (uintptr_t)(WB - 1)) == 0;
    /* the row hashes kept from the last picture are the base's only if that
     * picture was base: otherwise rows are compared in full */
    int hashes = base != 0 && c->hashes_of == base && c->hashes_valid;
    fl_edges *ref = &c->edges[0], *nxt = &c->edges[1];
    ref->n = 0;
    int c0ref = 0, kind = ROW_CODED, trow = T_ROW + (base ? 4 : 0) * (ROW_KINDS + 1);
    uint32_t f = 0;
    for (int y = 0; y < FL_H; y++) {
        const uint8_t *row = px + y * FL_W;
        uint32_t h, na = scan_row(row, aligned, c->at, &h);
        f = mix(f ^ h);
        int same = base && (!hashes || c->row_hash[y] == h) && rows_equal(row, base + y * FL_W, aligned);
        c->row_hash[y] = h;
        if (r->overflow) { /* no room: the frame goes raw, with another check */
            c->hashes_valid = 0;
            return 0;
        }
        int c0 = row[0], t = trow + kind * (ROW_KINDS + 1);
        if (same) {
            kind = ROW_SAME;
        } else if (c0 == c0ref && na == ref->n) {
            uint32_t i = 0;
            while (i < na && c->at[i] == ref->pk[i]) i++;
            kind = i == na ? ROW_TRIV : ROW_CODED;
        } else {
            kind = c0 == c0ref ? ROW_CODED : ROW_CODED_C0;
        }
        rc_sym(r, t, kind);
        if (kind == ROW_SAME) {
            edges_of_transitions(ref, c->at, na);
        } else if (kind == ROW_TRIV) {
            advance_edges(ref);
        } else {
            s.ref = ref;
            s.out = nxt;
            s.above = y ? row - FL_W : 0;
            s.na = na;
            s.rn = ref->n;
            s.c0 = c0;
            enc_row(&s, c0ref);
            fl_edges *tmp = ref;
            ref = nxt;
            nxt = tmp;
        }
        c0ref = c0;
        if (gives_up(r, cap, y)) {
            c->hashes_valid = 0;
            return 0;
        }
    }
    *check = fmix(f);
    c->hashes_of = px;
    c->hashes_valid = 1;
    if (r->overflow) return 0;
    uint32_t n = rc_finish(r);
    return r->overflow ? 0 : n;
}

/* ======================================================================== */
/* Decoder                                                                  */
/* ======================================================================== */

typedef struct {
    uint32_t range, code;
    const uint8_t *p, *end;
    int bad; /* the data left the coder's range: corrupt */
} rc_dec;

static inline uint32_t rd_byte(rc_dec *r)
{
    return r->p < r->end ? *r->p++ : 0u;
}

static void rd_norm(rc_dec *r)
{
    while (r->range < (1u << 24)) {
        r->range <<= 8;
        r->code = (r->code << 8) | rd_byte(r);
    }
}

/* A symbol of the table at t with n symbols. */
static int rd_sym(rc_dec *r, int t, int n)
{
    uint32_t q = r->range >> TOTAL_BITS;
    int s = 0;
    while (s < n && r->code >= q * cum[t + s + 1]) s++;
    if (s == n) { /* in the sliver above q * 4096: no symbol */
        r->bad = 1;
        s = 0;
    }
    r->code -= q * cum[t + s];
    r->range = q * (uint32_t)(cum[t + s + 1] - cum[t + s]);
    rd_norm(r);
    return s;
}

static uint32_t rd_bits(rc_dec *r, int n)
{
    uint32_t q = r->range >> n, v = r->code / q;
    if (v >> n) { /* in the sliver above q << n */
        r->bad = 1;
        v = 0;
    }
    r->code -= q * v;
    r->range = q;
    rd_norm(r);
    return v;
}

/* Returns the colour, or -1 if the data is inconsistent. */
static int dec_colour(rc_dec *r, fl_coder *c, int set, int cand0, int cand1, int ex0, int ex1)
{
    if (cand0 == ex0 || cand0 == ex1) cand0 = -1;
    if (cand1 == ex0 || cand1 == ex1 || cand1 == cand0) cand1 = -1;
    int s = rd_sym(r, T_COL + set * (COLS + 1), COLS), col = -1;
    if (s == COL_CAND0) return cand0;
    if (s == COL_CAND1) return cand1;
    if (s == COL_LITERAL) {
        col = (int)rd_bits(r, 8);
        if (col == ex0 || col == ex1 || col == cand0 || col == cand1) return -1;
    } else {
        int rank = s - COL_CACHE0;
        for (int k = 0; k < FL_CACHE; k++) {
            int m = c->cache[k];
            if (m == ex0 || m == ex1 || m == cand0 || m == cand1) continue;
            if (rank-- == 0) {
                col = m;
                break;
            }
        }
        if (col < 0) return -1;
    }
    cache_put(c, col);
    return col;
}

/* Decode a ROW_CODED / ROW_CODED_C0 row into row[0..319]; out receives its
 * edges. Returns 0 or -1. */
static int dec_row(rc_dec *r, fl_coder *c, uint8_t *row, const uint8_t *above, const fl_edges *ref, int c0ref,
                   int c0_changed, fl_edges *out)
{
    uint32_t j = 0, no = 0, rn = ref->n;
    int a0 = 0, cur = c0ref;
    if (c0_changed) {
        cur = dec_colour(r, c, SET_C0, rn ? (ref->pk[0] & 0xFF) : -1, -1, c0ref, c0ref);
        if (cur < 0) return -1;
    }
    int prev = PREV_START;
    for (;;) {
        int x, col, op;
        if (r->bad) return -1;
        if (j == rn) {
            op = rd_sym(r, T_NOEDGE, 2) ? OP_EOL : OP_NEW;
        } else {
            op = rd_sym(r, T_OP + (ref->vc[j] * 5 + prev) * (OPS + 1), OPS);
        }
        if (op == OP_EOL) break;
        if (op == OP_END) {
            j++;
            prev = PREV_END;
            continue;
        }
        if (op == OP_NEW) {
            int len = rd_sym(r, T_NPOS, NPOS_BITS) + 1;
            int dist = (int)((1u << (len - 1)) | rd_bits(r, len - 1));
            x = a0 + dist;
            if (x >= FL_W) return -1;
            col = dec_colour(r, c, SET_NEW, above ? above[x] : -1, j < rn ? (ref->pk[j] & 0xFF) : -1, cur, cur);
            if (col < 0) return -1;
            put_edge(out, no++, x * 256 + col, 0, 0);
            prev = PREV_NEW;
        } else {
            int32_t pk = ref->pk[j];
            int p = pk >> 8, pc = pk & 0xFF, vc = ref->vc[j], d;
            col = pc;
            if (op == OP_K0) {
                d = 0;
            } else if (op == OP_UP || op == OP_DOWN) {
                d = op == OP_UP ? 1 : -1;
            } else {
                d = rd_sym(r, T_MOVE + vc * 18, 2 * D_MAX + 1) - D_MAX;
                int changed = 1;
                if ((d > 1 || d < -1) && pc != cur) changed = rd_sym(r, T_KC + vc * 3, 2);
                if (changed) {
                    col = dec_colour(r, c, SET_KEEP, j + 1 < rn ? (ref->pk[j + 1] & 0xFF) : -1,
                                     j + 2 < rn ? (ref->pk[j + 2] & 0xFF) : -1, cur, pc);
                    if (col < 0) return -1;
                }
            }
            x = p + d;
            if (x <= a0 || x >= FL_W || col == cur) return -1;
            continue_edge(ref, j, out, no++, x * 256 + col);
            j++;
            prev = d ? PREV_KD : PREV_K0;
        }
        for (int k = a0; k < x; k++) row[k] = (uint8_t)cur;
        a0 = x;
        cur = col;
    }
    for (int k = a0; k < FL_W; k++) row[k] = (uint8_t)cur;
    out->n = no;
    return r->bad ? -1 : 0;
}

/* A ROW_TRIV row: every edge of the row above where predicted. */
static int dec_trivial(uint8_t *row, const fl_edges *ref, int c0)
{
    int a0 = 0, cur = c0;
    for (uint32_t j = 0; j < ref->n; j++) {
        int x = ref->pk[j] >> 8, col = ref->pk[j] & 0xFF;
        if (x <= a0 || x >= FL_W || col == cur) return -1;
        for (int k = a0; k < x; k++) row[k] = (uint8_t)cur;
        a0 = x;
        cur = col;
    }
    for (int k = a0; k < FL_W; k++) row[k] = (uint8_t)cur;
    return 0;
}

int fl_decode_picture(fl_coder *c, const uint8_t *in, uint32_t n, const uint8_t *base, uint8_t *out)
{
    rc_dec r;
    r.p = in;
    r.end = in + n;
    r.range = 0xFFFFFFFFu;
    r.code = 0;
    r.bad = 0;
    for (int i = 0; i < 4; i++) r.code = (r.code << 8) | rd_byte(&r);
    cache_reset(c);
    c->hashes_valid = 0;
    fl_edges *ref = &c->edges[0], *nxt = &c->edges[1];
    ref->n = 0;
    int c0ref = 0, kind = ROW_CODED, trow = T_ROW + (base ? 4 : 0) * (ROW_KINDS + 1);
    for (int y = 0; y < FL_H; y++) {
        uint8_t *row = out + y * FL_W;
        kind = rd_sym(&r, trow + kind * (ROW_KINDS + 1), ROW_KINDS);
        if (r.bad) return -1;
        if (kind == ROW_SAME) {
            if (!base) return -1;
            const uint8_t *b = base + y * FL_W;
            for (int x = 0; x < FL_W; x++) row[x] = b[x];
            uint32_t h;
            edges_of_transitions(ref, c->at, scan_row(row, 0, c->at, &h));
        } else if (kind == ROW_TRIV) {
            if (dec_trivial(row, ref, c0ref)) return -1;
            advance_edges(ref);
        } else {
            if (dec_row(&r, c, row, y ? row - FL_W : 0, ref, c0ref, kind == ROW_CODED_C0, nxt)) return -1;
            fl_edges *t = ref;
            ref = nxt;
            nxt = t;
        }
        c0ref = row[0];
    }
    return r.bad ? -1 : 0;
}
