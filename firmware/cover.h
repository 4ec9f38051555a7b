/* cover.h - exact per-row pixel coverage of the 320x200 screen (prefix cov_).
 *
 * One bit per pixel, 40 bytes per scan line (8,000 bytes for the screen): a
 * front-to-back renderer records here which pixels are already taken, asks
 * whether a run of a row is wholly taken, and walks the free runs of a row.
 * Unlike a list of intervals it never forgets anything and never runs out of
 * room, so what it answers is exact. Bit (x & 31) of word x / 32 is pixel x. */
#ifndef COVER_H
#define COVER_H

#include <stdint.h>
#include "raster.h"
#include "view.h"

#define COV_WORDS (VIEW_W / 32)

_Static_assert(VIEW_W % 32 == 0 && COV_WORDS <= 16, "a row is whole words, at most 16");

typedef struct {
    uint32_t bits[VIEW_H][COV_WORDS];
    uint16_t open[VIEW_H]; /* bit i: word i of the row has a clear bit */
    uint16_t full_rows;    /* rows with every pixel set */
} cov_mask;

void cov_clear(cov_mask *m);

/* dst set exactly where src is clear (dst may be src). */
void cov_complement(cov_mask *dst, const cov_mask *src);

/* A run touches its two end words bit by bit; the words between are whole, so
 * they are set, and tested, through the row's word summary (open) alone. */
#define COV_ALL_OPEN ((uint16_t)((1u << COV_WORDS) - 1u))


/* Words w0 < i < w1, as summary bits. */
static inline uint32_t cov_inner_words(int w0, int w1)
{
    return w1 - w0 > 1 ? ((1u << w1) - (2u << w0)) : 0;
}

/* 1 if every pixel of [x0, x1) on row y is set (an empty run: 1). 0 <= x0, x1 <= VIEW_W. */
static inline int cov_all(const cov_mask *m, int y, int x0, int x1)
{
    uint32_t open = m->open[y];
    if (x1 <= x0 || !open) return 1;
    const uint32_t *row = m->bits[y];
    int w0 = x0 >> 5, w1 = (x1 - 1) >> 5;
    uint32_t first = 0xFFFFFFFFu << (x0 & 31), last = 0xFFFFFFFFu >> (31 - ((x1 - 1) & 31));
    if (w0 == w1) return (row[w0] & first & last) == (first & last);
    return (row[w0] & first) == first && (row[w1] & last) == last && !(open & cov_inner_words(w0, w1));
}

/* Set [x0, x1) on row y (an empty run: nothing). */
static inline void cov_set(cov_mask *m, int y, int x0, int x1)
{
    uint32_t open = m->open[y];
    if (x1 <= x0 || !open) return;
    uint32_t *row = m->bits[y];
    int w0 = x0 >> 5, w1 = (x1 - 1) >> 5;
    uint32_t first = 0xFFFFFFFFu << (x0 & 31), last = 0xFFFFFFFFu >> (31 - ((x1 - 1) & 31));
    if (w0 == w1) first &= last;
    if ((row[w0] |= first) == 0xFFFFFFFFu) open &= ~(1u << w0);
    if (w1 > w0) {
        for (int i = w0 + 1; i < w1; i++) row[i] = 0xFFFFFFFFu;
        open &= ~cov_inner_words(w0, w1);
        if ((row[w1] |= last) == 0xFFFFFFFFu) open &= ~(1u << w1);
    }
    m->open[y] = (uint16_t)open;
    if (!open) m->full_rows++;
}


/* The first pixel of [x, x1) on row y that is clear (cov_next_clear) or set
 * (cov_next_set); x1 if there is none. */
int cov_next_clear(const cov_mask *m, int y, int x, int x1);
int cov_next_set(const cov_mask *m, int y, int x, int x1);

static inline int cov_row_full(const cov_mask *m, int y)
{
    return m->open[y] == 0;
}

/* 1 once every pixel of the screen is set. */
static inline int cov_full(const cov_mask *m)
{
    return m->full_rows == VIEW_H;
}

/* 1 if every pixel of [x0, x1) on every row of [y0, y1) is set (clamped to the
 * screen; an empty box: 1). */
int cov_box_covered(const cov_mask *m, int y0, int y1, int x0, int x1);

/* Fill the pixels of [x0, x1) on row y that are neither set nor set in keep (a
 * row mask of pixels to leave alone, or NULL) in its paint with id, one span per
 * run (a free word at a time where it can), and set them. Returns the pixels
 * written. */
uint32_t cov_fill(cov_mask *m, const rast_target *t, int y, int x0, int x1, const uint32_t *keep,
                  const tex_paint *paint, uint32_t id);

/* cov_fill for rows [top, bottom) of a polygon, row y from lo[y] to hi[y]. */
uint32_t cov_fill_rows(cov_mask *m, const rast_target *t, int top, int bottom, const int16_t *lo, const int16_t *hi,
                       const tex_paint *paint, uint32_t id);

/* Set [x0, x1) in a row mask of COV_WORDS words. */
void cov_line_set(uint32_t *line, int x0, int x1);

#endif
