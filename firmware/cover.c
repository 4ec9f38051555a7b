/* cover.c - the written-pixel mask and filling what is still free. */
#include "cover.h"

void cov_reset(cov_mask *c)
{
    for (int y = 0; y < VIEW_H; y++) {
        for (int w = 0; w < COV_WORDS; w++) c->bits[y][w] = 0;
        c->open[y] = VIEW_W;
    }
    c->full_rows = 0;
}

/* The bits of word w that lie in [x0, x1), x0 < x1. */
static inline uint32_t word_range(int w, int x0, int x1)
{
    int lo = x0 - w * 32, hi = x1 - w * 32; /* [lo, hi) within the word, possibly beyond it */
    uint32_t m = lo <= 0 ? 0xFFFFFFFFu : (0xFFFFFFFFu << lo);
    if (hi < 32) m &= (1u << hi) - 1u;
    return m;
}

static inline int clamp_w(int x)
{
    return x < 0 ? 0 : (x > VIEW_W ? VIEW_W : x);
}

int cov_box_covered(const cov_mask *c, int y0, int y1, int x0, int x1)
{
    x0 = clamp_w(x0);
    x1 = clamp_w(x1);
    if (y0 < 0) y0 = 0;
    if (y1 > VIEW_H) y1 = VIEW_H;
    if (x1 <= x0) return 1;
    int w0 = x0 >> 5, w1 = (x1 - 1) >> 5;
    for (int y = y0; y < y1; y++) {
        if (c->open[y] == 0) continue;
        for (int w = w0; w <= w1; w++) {
            uint32_t want = word_range(w, x0, x1);
            if ((c->bits[y][w] & want) != want) return 0;
        }
    }
    return 1;
}

void cov_line_set(uint32_t *line, int x0, int x1)
{
    x0 = clamp_w(x0);
    x1 = clamp_w(x1);
    if (x1 <= x0) return;
    for (int w = x0 >> 5; w <= (x1 - 1) >> 5; w++) line[w] |= word_range(w, x0, x1);
}

int dbg_calls, dbg_empty, dbg_spans;
static void take(cov_mask *c, int y, int n)
{
    c->open[y] = (int16_t)(c->open[y] - n);
    if (c->open[y] == 0) c->full_rows++;
}

void cov_claim(cov_mask *c, int y, const uint32_t *m, uint32_t (*claim)[COV_WORDS])
{
    int n = 0;
    for (int w = 0; w < COV_WORDS; w++) {
        uint32_t fresh = m[w] & ~c->bits[y][w];
        c->bits[y][w] |= fresh;
        claim[y][w] |= fresh;
        n += __builtin_popcount(fresh);
    }
    if (n) take(c, y, n);
}

void cov_release(cov_mask *c, uint32_t (*claim)[COV_WORDS])
{
    for (int y = 0; y < VIEW_H; y++) {
        int n = 0;
        for (int w = 0; w < COV_WORDS; w++) {
            c->bits[y][w] &= ~claim[y][w];
            n += __builtin_popcount(claim[y][w]);
        }
        if (n && c->open[y] == 0) c->full_rows--;
        c->open[y] = (int16_t)(c->open[y] + n);
    }
}

uint32_t cov_fill(cov_mask *c, const rast_target *t, int y, int x0, int x1, const uint32_t *keep, uint8_t colour,
                  uint32_t id)
{
    x0 = clamp_w(x0);
    x1 = clamp_w(x1);
    if (x1 <= x0 || c->open[y] == 0) return 0;
    uint32_t *line = c->bits[y];
    int w0 = x0 >> 5, w1 = (x1 - 1) >> 5;
    uint32_t first = 0xFFFFFFFFu << (x0 & 31), last = 0xFFFFFFFFu >> (31 - ((x1 - 1) & 31));
    if (!keep) { /* the common case first: nothing of [x0, x1) written yet, one span */
        uint32_t taken = line[w0] & first;
        for (int w = w0 + 1; w < w1; w++) taken |= line[w];
        if (w0 != w1) taken |= line[w1] & last;
        else taken &= last;
        if (!taken) {
            if (w0 == w1) {
                line[w0] |= first & last;
            } else {
                line[w0] |= first;
                for (int w = w0 + 1; w < w1; w++) line[w] = 0xFFFFFFFFu;
                line[w1] |= last;
            }
            rast_span(t, y, x0, x1, colour, id);
            take(c, y, x1 - x0);
            return (uint32_t)(x1 - x0);
        }
    }
    int run0 = 0, run1 = 0; /* the run being gathered: runs that meet across words are one span */
    uint32_t drawn = 0;
    for (int w = w0; w <= w1; w++) {
        uint32_t free = ~line[w];
        if (w == w0) free &= first;
        if (w == w1) free &= last;
        if (keep) free &= ~keep[w];
        if (!free) continue;
        line[w] |= free;
        int base = w * 32;
        if (free == 0xFFFFFFFFu) { /* the common case: a whole free word */
            if (base != run1) {
                if (run1 > run0) rast_span(t, y, run0, run1, colour, id);
                run0 = base;
            }
            run1 = base + 32;
            drawn += 32;
            continue;
        }
        while (free) {
            int s = __builtin_ctz(free);
            uint32_t carry = free + (free & (0u - free)); /* the run's bits cleared, the bit after it set */
            int e = carry ? __builtin_ctz(carry) : 32;
            free &= carry;
            if (base + s != run1) {
                if (run1 > run0) rast_span(t, y, run0, run1, colour, id);
                run0 = base + s;
            }
            run1 = base + e;
            drawn += (uint32_t)(e - s);
        }
    }
    if (run1 > run0) rast_span(t, y, run0, run1, colour, id);
    if (drawn) take(c, y, (int)drawn);
    return drawn;
}
