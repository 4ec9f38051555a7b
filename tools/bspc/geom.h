/* geom.h - exact 2-D predicates of the BSP compiler (prefix bs_): side of a
 * point relative to a line, line-line intersection rounded to 16.16.
 *
 * Tolerance. Split points are rounded to the 16.16 grid, so a point made on a
 * line lies up to sqrt(2)/2 raw units (1 raw = 1/65536 map unit) off it. A point
 * is therefore "on" a line when its distance to the line is at most BS_EPS raw
 * units; the test is exact: |cross| <= thr with cross = (P - A) x d computed in
 * 64 or 128 bits (d reduced by the gcd of its components, so whole-unit maps
 * stay in 64 bits) and thr = isqrt(BS_EPS^2 * |d|^2) computed once per line. Two points
 * of a map on integer coordinates are never closer than 1/|d| units to a line
 * that misses them (about 2 raw units for the longest possible line), so the
 * tolerance merges nothing that a map means to keep apart.
 */
#ifndef BSPC_GEOM_H
#define BSPC_GEOM_H

#include "bspc_int.h"

#define BS_EPS 2 /* raw units */

/* Set up a line through (x, y) along (dx, dy): directions wider than 32 bits
 * are reduced (exactly when possible) so the line can be stored in scn_node. */
void bs_pline_set(bs_pline *L, int32_t x, int32_t y, int64_t dx, int64_t dy);

/* Signed cross product (P - A) x d (reduced d): positive on the right (front). */
static inline bs_i128 bs_cross(const bs_pline *L, int32_t px, int32_t py)
{
    return (bs_i128)((int64_t)px - L->x) * L->rdy - (bs_i128)((int64_t)py - L->y) * L->rdx;
}

/* +1 front (right of the direction), -1 back, 0 on the line (within BS_EPS). */
static inline int bs_side(const bs_pline *L, uint32_t rev, int32_t px, int32_t py)
{
    int s;
    if (L->small) { /* |P - A| < 2^33, |d| < 2^29: each product < 2^62 */
        int64_t c = ((int64_t)px - L->x) * L->rdy - ((int64_t)py - L->y) * L->rdx;
        s = (c > L->thr) ? 1 : (c < -L->thr) ? -1 : 0;
    } else {
        bs_i128 c = bs_cross(L, px, py);
        s = (c > L->thr) ? 1 : (c < -(bs_i128)L->thr) ? -1 : 0;
    }
    return rev ? -s : s;
}

/* Intersection of lines a and b rounded to the nearest 16.16 point (ties toward
 * +infinity). The result depends only on the pair {a, b}, not on the order, so
 * every caller that meets the same two lines gets the same point bit for bit.
 * Returns -1 if the lines are parallel. Results outside int32 are clamped. */
int bs_intersect(const bs_pline *lines, uint32_t a, uint32_t b, int32_t *x, int32_t *y);

/* floor(sqrt(v)) for v < 2^126. */
uint64_t bs_isqrt(bs_u128 v);

#endif
