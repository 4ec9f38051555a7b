/* cover.c - the coverage bit mask: clearing it, walking a row's runs, filling
 * what is free (the tests and sets, called per polygon row, are inline in
 * cover.h). */
#include "cover.h"

void cov_clear(cov_mask *m)
{
    for (int y = 0; y < VIEW_H; y++) {
        for (int i = 0; i < COV_WORDS; i++) m->bits[y][i] = 0;
        m->open[y] = COV_ALL_OPEN;
    }
    m->full_rows = 0;
}

void cov_complement(cov_mask *dst, const cov_mask *src)
{
    dst->full_rows = 0;
    for (int y = 0; y < VIEW_H; y++) {
        uint16_t open = 0;
        for (int i = 0; i < COV_WORDS; i++) {
            uint32_t b = src->bits[y][i]; /* read first: dst may be src */
            dst->bits[y][i] = ~b;
            open |= (uint16_t)((b != 0) << i);
        }
        dst->open[y] = open;
        dst->full_rows += open == 0;
    }
}

/* The first pixel in [x, x1) whose bit, xor flip, is set; x1 if none. */
static int next_bit(const uint32_t *row, int x, int x1, uint32_t flip)
{
    if (x >= x1) return x1;
    int i = x >> 5;
    uint32_t w = (row[i] ^ flip) & (0xFFFFFFFFu << (x & 31));
    int last = (x1 - 1) >> 5;
    while (!w) {
        if (++i > last) return x1;
        w = row[i] ^ flip;
    }
    int at = (i << 5) + __builtin_ctz(w);
    return at < x1 ? at : x1;
}

int cov_next_clear(const cov_mask *m, int y, int x, int x1)
{
    return next_bit(m->bits[y], x, x1, 0xFFFFFFFFu);
}

int cov_next_set(const cov_mask *m, int y, int x, int x1)
{
    return next_bit(m->bits[y], x, x1, 0);
}

static inline int clamp_w(int x)
{
    return x < 0 ? 0 : (x > VIEW_W ? VIEW_W : x);
}

int cov_box_covered(const cov_mask *m, int y0, int y1, int x0, int x1)
{
    x0 = clamp_w(x0);
    x1 = clamp_w(x1);
    if (y0 < 0) y0 = 0;
    if (y1 > VIEW_H) y1 = VIEW_H;
    for (int y = y0; y < y1; y++)
        if (!cov_all(m, y, x0, x1)) return 0;
    return 1;
}

void cov_line_set(uint32_t *line, int x0, int x1)
{
    x0 = clamp_w(x0);
    x1 = clamp_w(x1);
    if (x1 <= x0) return;
    int w0 = x0 >> 5, w1 = (x1 - 1) >> 5;
    uint32_t first = 0xFFFFFFFFu << (x0 & 31), last = 0xFFFFFFFFu >> (31 - ((x1 - 1) & 31));
    if (w0 == w1) {
        line[w0] |= first & last;
        return;
    }
    line[w0] |= first;
    for (int w = w0 + 1; w < w1; w++) line[w] = 0xFFFFFFFFu;
    line[w1] |= last;
}

/* Words of row y that became full: out of the row's summary. */
static inline void close_words(cov_mask *m, int y, uint32_t full)
{
    if (!full || !m->open[y]) return;
    m->open[y] = (uint16_t)(m->open[y] & ~full);
    if (!m->open[y]) m->full_rows++;
}

/* cov_fill's work, inlined into it and into cov_fill_rows' loop. */
static inline __attribute__((always_inline)) uint32_t fill_row(cov_mask *m, const rast_target *t, int y, int x0, int x1,
                                                               const uint32_t *keep, const tex_paint *paint,
                                                               int textured, uint32_t id)
{
    x0 = clamp_w(x0);
    x1 = clamp_w(x1);
    if (x1 <= x0 || !m->open[y]) return 0;
    uint32_t *line = m->bits[y];
    int w0 = x0 >> 5, w1 = (x1 - 1) >> 5;
    uint32_t first = 0xFFFFFFFFu << (x0 & 31), last = 0xFFFFFFFFu >> (31 - ((x1 - 1) & 31));
    uint32_t full = 0; /* words this fill completes */
    if (!keep) {       /* the common case first: nothing of [x0, x1) set yet, one span */
        uint32_t taken = w0 == w1 ? line[w0] & first & last : (line[w0] & first) | (line[w1] & last);
        for (int w = w0 + 1; w < w1 && !taken; w++) taken |= line[w];
        if (!taken) {
            if (w0 == w1) {
                full = (uint32_t)((line[w0] |= first & last) == 0xFFFFFFFFu) << w0;
            } else {
                full = (uint32_t)((line[w0] |= first) == 0xFFFFFFFFu) << w0;
                for (int w = w0 + 1; w < w1; w++) line[w] = 0xFFFFFFFFu;
                full |= cov_inner_words(w0, w1);
                full |= (uint32_t)((line[w1] |= last) == 0xFFFFFFFFu) << w1;
            }
            rast_span_as(t, y, x0, x1, paint, id, textured);
            close_words(m, y, full);
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
        full |= (uint32_t)(line[w] == 0xFFFFFFFFu) << w;
        int base = w * 32;
        if (free == 0xFFFFFFFFu) { /* a whole free word */
            if (base != run1) {
                if (run1 > run0) rast_span_as(t, y, run0, run1, paint, id, textured);
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
                if (run1 > run0) rast_span_as(t, y, run0, run1, paint, id, textured);
                run0 = base + s;
            }
            run1 = base + e;
            drawn += (uint32_t)(e - s);
        }
    }
    if (run1 > run0) rast_span_as(t, y, run0, run1, paint, id, textured);
    close_words(m, y, full);
    return drawn;
}

uint32_t cov_fill(cov_mask *m, const rast_target *t, int y, int x0, int x1, const uint32_t *keep,
                  const tex_paint *paint, uint32_t id)
{
    if (rast_textured_paint(t, paint)) return fill_row(m, t, y, x0, x1, keep, paint, 1, id);
    return fill_row(m, t, y, x0, x1, keep, paint, 0, id);
}

uint32_t cov_fill_rows(cov_mask *m, const rast_target *t, int top, int bottom, const int16_t *lo, const int16_t *hi,
                       const tex_paint *paint, uint32_t id)
{
    uint32_t drawn = 0;
    if (rast_textured_paint(t, paint)) {
        for (int y = top; y < bottom; y++)
            if (lo[y] < hi[y]) drawn += fill_row(m, t, y, lo[y], hi[y], 0, paint, 1, id);
    } else {
        for (int y = top; y < bottom; y++)
            if (lo[y] < hi[y]) drawn += fill_row(m, t, y, lo[y], hi[y], 0, paint, 0, id);
    }
    return drawn;
}
