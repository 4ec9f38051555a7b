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
#include "view.h"

#define COV_WORDS (VIEW_W / 32)

_Static_assert(VIEW_W % 32 == 0, "a row is whole words");

typedef struct {
    uint32_t bits[VIEW_H][COV_WORDS];
    uint8_t full_words[VIEW_H]; /* words of the row with every bit set */
    uint16_t full_rows;         /* rows with every pixel set */
} cov_mask;

void cov_clear(cov_mask *m);

/* 1 if every pixel of [x0, x1) on row y is set (an empty run: 1). 0 <= x0, x1 <= VIEW_W. */
int cov_all(const cov_mask *m, int y, int x0, int x1);

/* Set [x0, x1) on row y (an empty run: nothing). */
void cov_set(cov_mask *m, int y, int x0, int x1);

/* The first pixel of [x, x1) on row y that is clear (cov_next_clear) or set
 * (cov_next_set); x1 if there is none. */
int cov_next_clear(const cov_mask *m, int y, int x, int x1);
int cov_next_set(const cov_mask *m, int y, int x, int x1);

static inline int cov_row_full(const cov_mask *m, int y)
{
    return m->full_words[y] == COV_WORDS;
}

/* 1 once every pixel of the screen is set. */
static inline int cov_full(const cov_mask *m)
{
    return m->full_rows == VIEW_H;
}

#endif
