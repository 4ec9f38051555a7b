/* cover.c - the coverage bit mask: clearing it and walking a row's runs (the
 * tests and sets, called per polygon row, are inline in cover.h). */
#include "cover.h"

void cov_clear(cov_mask *m)
{
    for (int y = 0; y < VIEW_H; y++) {
        for (int i = 0; i < COV_WORDS; i++) m->bits[y][i] = 0;
        m->open[y] = COV_ALL_OPEN;
    }
    m->full_rows = 0;
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
