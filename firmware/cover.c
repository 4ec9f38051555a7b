/* cover.c - the coverage bit mask: whole words at a time, partial words at the
 * ends of a run. */
#include "cover.h"

/* Bits [a, b) of a word, 0 <= a < b <= 32. */
static inline uint32_t word_bits(int a, int b)
{
    uint32_t hi = b == 32 ? 0xFFFFFFFFu : ((uint32_t)1 << b) - 1u;
    return hi & ~(((uint32_t)1 << a) - 1u);
}

void cov_clear(cov_mask *m)
{
    for (int y = 0; y < VIEW_H; y++) {
        for (int i = 0; i < COV_WORDS; i++) m->bits[y][i] = 0;
        m->full_words[y] = 0;
    }
    m->full_rows = 0;
}

int cov_all(const cov_mask *m, int y, int x0, int x1)
{
    if (x1 <= x0 || m->full_words[y] == COV_WORDS) return 1;
    const uint32_t *row = m->bits[y];
    int w0 = x0 >> 5, w1 = (x1 - 1) >> 5;
    if (w0 == w1) {
        uint32_t want = word_bits(x0 & 31, ((x1 - 1) & 31) + 1);
        return (row[w0] & want) == want;
    }
    uint32_t first = word_bits(x0 & 31, 32), last = word_bits(0, ((x1 - 1) & 31) + 1);
    if ((row[w0] & first) != first || (row[w1] & last) != last) return 0;
    for (int i = w0 + 1; i < w1; i++)
        if (row[i] != 0xFFFFFFFFu) return 0;
    return 1;
}

static inline void set_word(cov_mask *m, int y, int i, uint32_t bits)
{
    uint32_t old = m->bits[y][i], now = old | bits;
    m->bits[y][i] = now;
    if (now == 0xFFFFFFFFu && old != now && ++m->full_words[y] == COV_WORDS) m->full_rows++;
}

void cov_set(cov_mask *m, int y, int x0, int x1)
{
    if (x1 <= x0 || m->full_words[y] == COV_WORDS) return;
    int w0 = x0 >> 5, w1 = (x1 - 1) >> 5;
    if (w0 == w1) {
        set_word(m, y, w0, word_bits(x0 & 31, ((x1 - 1) & 31) + 1));
        return;
    }
    set_word(m, y, w0, word_bits(x0 & 31, 32));
    for (int i = w0 + 1; i < w1; i++) set_word(m, y, i, 0xFFFFFFFFu);
    set_word(m, y, w1, word_bits(0, ((x1 - 1) & 31) + 1));
}

/* The first pixel in [x, x1) whose bit, xor flip, is set; x1 if none. */
static int next_bit(const uint32_t *row, int x, int x1, uint32_t flip)
{
    if (x >= x1) return x1;
    int i = x >> 5;
    uint32_t w = (row[i] ^ flip) & word_bits(x & 31, 32);
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
