/* cover.h - which pixels of the frame are already written (prefix cov_): one bit
 * per pixel, 320 bits a scan line. This is seed 001's per-scan-line span list
 * kept as a bit mask: exact (nothing is ever forgotten, so a front-to-back
 * renderer that fills only uncovered pixels writes each pixel exactly once),
 * of a fixed size (8,400 bytes) whatever the scene, and searched a 32-pixel word
 * at a time (count-trailing-zeros finds where a run of free pixels starts and
 * ends: RBIT + CLZ on a Cortex-M3, BSF on a 386). */
#ifndef COVER_H
#define COVER_H

#include <stdint.h>
#include "raster.h"
#include "view.h"

#define COV_WORDS (VIEW_W / 32)

_Static_assert(VIEW_W % 32 == 0, "a scan line is a whole number of 32-bit words");

typedef struct {
    uint32_t bits[VIEW_H][COV_WORDS]; /* bit x % 32 of word x / 32: pixel x written */
    int16_t open[VIEW_H];             /* pixels of the line not yet written */
    int16_t full_rows;                /* lines with open == 0 */
} cov_mask;

void cov_reset(cov_mask *c);

static inline int cov_full(const cov_mask *c)
{
    return c->full_rows == VIEW_H;
}

/* 1 if every pixel of [x0, x1) on every line of [y0, y1) is written (clamped to
 * the screen; an empty box is covered). */
int cov_box_covered(const cov_mask *c, int y0, int y1, int x0, int x1);

/* Write the pixels of [x0, x1) on line y that are neither written nor set in
 * keep (a line mask of pixels to leave alone, or NULL) in colour with id, one
 * span per run, and mark them written. Returns the pixels written. */
uint32_t cov_fill(cov_mask *c, const rast_target *t, int y, int x0, int x1, const uint32_t *keep, uint8_t colour,
                  uint32_t id);

/* Set [x0, x1) in a line mask of COV_WORDS words. */
void cov_line_set(uint32_t *line, int x0, int x1);

/* Mark the pixels of line mask m on line y as taken without writing them (a
 * later pass will), and record them in claim (a mask of the whole screen).
 * cov_release hands every claimed pixel back as unwritten. */
void cov_claim(cov_mask *c, int y, const uint32_t *m, uint32_t (*claim)[COV_WORDS]);
void cov_release(cov_mask *c, uint32_t (*claim)[COV_WORDS]);

#endif
