/* collide.h - the player against the world (prefix col_): walking with collision
 * and sliding, the floor under a point, and line of sight.
 *
 * The player is an upright cylinder: a circle of COL_RADIUS in the map plane and
 * COL_HEIGHT tall, standing on the highest floor its circle overlaps (Doom's
 * rule: over a ledge the player stands on the ledge), able to step up at most
 * COL_STEP and to step down any height. Walls are the segs of the compiled scene;
 * candidates are found by walking the BSP tree and visiting only the leaves whose
 * node bounding box overlaps the box of the move (or of the sight line).
 *
 * Ceilings are those of w (objects.h: doors move them; w NULL: as compiled), so
 * a closed door blocks like a wall with no opening and an open one lets the
 * player through. Objects do not collide.
 *
 * Geometry is exact integer arithmetic on a grid of 1/4096 map unit (16.16
 * coordinates shifted right by 4): every orientation and distance comparison is
 * decided exactly on that grid (64-bit products, 128-bit where a product of
 * products is compared), so the same input gives the same result on every target.
 */
#ifndef COLLIDE_H
#define COLLIDE_H

#include <stdint.h>
#include "fixed.h"
#include "objects.h"
#include "scene.h"

/* Doom's player. */
#define COL_RADIUS (16 * FX_ONE) /* circle radius */
#define COL_HEIGHT (56 * FX_ONE) /* needs this much between floor and ceiling */
#define COL_STEP (24 * FX_ONE)   /* highest step climbed */
#define COL_RADIUS_MIN FX_ONE    /* radii are clamped into [MIN, MAX] */
#define COL_RADIUS_MAX (1024 * FX_ONE)

typedef struct {
    fx_t radius; /* clamped into [COL_RADIUS_MIN, COL_RADIUS_MAX] */
    fx_t height; /* >= 0 (negative counts as 0) */
    fx_t step;   /* >= 0 (negative counts as 0) */
} col_body;

/* The Doom player: COL_RADIUS, COL_HEIGHT, COL_STEP. */
col_body col_player(void);

/* col_move result bits */
#define COL_BLOCKED 1u /* some part of the move was stopped or turned into a slide */
#define COL_STUCK 2u   /* a blocking wall the body already overlapped at the start held part of it */

/* Move the body at (*x, *y) by (dx, dy) (16.16; any values: the move is clamped
 * to +-2^33 raw and every position to +-SCN_COORD_MAX units), colliding with the
 * walls and sliding along them, and write the result back.
 *
 * A wall blocks when it is one-sided, or when it is two-sided and, seen from the
 * floor the body stood on at the start of the current sub-step (z): the higher
 * floor of its two sectors is more than step above z, or its opening (lower
 * ceiling - higher floor) is lower than height, or the lower ceiling is less than
 * height above z. The body may not come nearer than radius to a blocking wall;
 * where it overlaps several sectors, the lowest ceiling must still be height
 * above the highest floor. Since z is fixed for a sub-step, a sub-step climbs at
 * most one step (as each P_TryMove does in Doom).
 *
 * The move is cut into sub-steps no longer than min(radius, 16 units); each
 * sub-step is clear only if the whole straight path of the circle keeps its
 * distance (a swept test, not a test of the end point, so nothing tunnels and no
 * corner is cut). A blocked sub-step goes as far as it can (to 1/4096 of its
 * length), then the rest of it loses its component into the wall it met and is
 * tried again (up to 4 times per sub-step), pushed 1/64 unit off the wall so the
 * slide never scrapes into it. The result is never nearer than radius to a
 * blocking wall (on the 1/4096 grid), and the path never crosses a one-sided wall.
 *
 * A start that already overlaps a blocking wall (a bad player start, a point
 * placed by hand on a wall line or vertex) is allowed out: such a wall only
 * blocks moves that bring the centre nearer to it or take it across it.
 *
 * *floor_z (may be NULL) receives the floor the body stands on afterwards: the
 * highest floor of every sector its circle overlaps, which is the floor of the
 * leaf under the centre unless the circle overhangs a higher floor. body may be
 * NULL for col_player(); the value *floor_z holds on entry is kept only when the
 * body is over no sector at all. Returns COL_* bits.
 *
 * Cost: a box walk of the tree and one pass over the candidate segs per
 * sub-step, about 15 passes when a sub-step is blocked (the cut to 1/4096 and
 * the slide). Stack: under 3 KB on a Cortex-M3 (gcc -fstack-usage: 128
 * candidate seg indices, a tree-walk stack of CFG_MAX_DEPTH + 2 entries). */
uint32_t col_move(const scene *s, const world_state *w, const col_body *body, fx_t *x, fx_t *y, fx_t *floor_z,
                  int64_t dx, int64_t dy);

/* The floor of the sector of the leaf under (x, y) (scene_sector_at). Returns 1
 * and writes *floor, or returns 0 (no sector) and leaves *floor alone. */
int col_floor_at(const scene *s, fx_t x, fx_t y, fx_t *floor);

/* 1 if nothing blocks the 3-D segment from (x1, y1, z1) to (x2, y2, z2): a
 * one-sided wall it touches blocks (its end points included: grazing a corner
 * blocks); a two-sided wall blocks where the segment's height as it crosses is
 * above the lower ceiling or below the higher floor of the wall's two sectors
 * (a height exactly on the edge of the opening passes; a closed opening,
 * ceiling <= floor, blocks at every height). Exact on the 1/4096 grid; x, y any
 * fx_t (clamped to the world), z any fx_t. */
int col_line_of_sight(const scene *s, const world_state *w, fx_t x1, fx_t y1, fx_t z1, fx_t x2, fx_t y2, fx_t z2);

#endif
