/* spans.h - render mode "spans": zero overdraw with sorted spans (prefix spans_).
 *
 * The BSP tree is walked front to back; every visible leaf's surfaces (floor,
 * ceiling, wall parts) enter per-scan-line edge lists keyed by BSP order - the
 * order in which their leaf was reached, so a smaller key is nearer (Quake's
 * final choice, Black Book ch. 67). A scan over the edge lists keeps a stack of
 * the surfaces active at the current x, sorted by key, with a background surface
 * at the bottom; each surface counts its edges (the state counter), so edges
 * that cross through rounding cannot leave a surface half active. Spans are
 * collected per surface and drawn one surface at a time: every pixel is written
 * exactly once.
 *
 * Coverage (seed 001, "Drawing polygons front to back") is a bit per pixel
 * (cover.h): the pixels polygons on the lists already claim, so a polygon
 * wholly behind them adds no edges and the walk stops once every pixel is
 * claimed.
 *
 * Memory: all state lives in a caller-supplied work area of fixed-size pools
 * (edges, surfaces, 1/z planes), sized by the build (SPANS_POOL_*), or smaller
 * when the compiler proved the scene never needs that many (docs/needs.md).
 * When a pool is full the frame is drawn in batches: what the pools hold is
 * drawn, every pixel it fills is marked, and the walk goes on behind it; later
 * batches fill only unmarked pixels. The frame is the same as with pools of
 * any size, and no polygon is dropped.
 */
#ifndef SPANS_H
#define SPANS_H

#include <stdint.h>
#include "objects.h"
#include "raster.h"
#include "render_stats.h"
#include "scene.h"
#include "view.h"

/* World edges and surfaces one batch holds (a build may set them: -D or its
 * scene header). The defaults hold every view of the Freedoom maps measured so
 * far in one batch on the host (at most 1,688 edges and 514 surfaces). */
#ifndef SPANS_POOL_EDGES
#define SPANS_POOL_EDGES 2048u
#endif
#ifndef SPANS_POOL_SURFACES
#define SPANS_POOL_SURFACES 640u
#endif

/* Bytes of work memory spans_render needs for this scene and w's objects (w
 * NULL: none; see render_work_bytes), 0 if it would not fit in 32 bits: the
 * caller must refuse the scene. The world's part is fixed: min(the scene's
 * proven bound, SPANS_POOL_*) edges and surfaces. Objects add, for every face
 * of every object (all could be in view at once), a surface, its
 * clipping-maximal edges and a 1/z plane, a plane for every world surface of a
 * batch, and an entry per object for those in the frustum. */
uint32_t spans_work_bytes(const scene *s, const world_state *w);

/* w: doors and objects (NULL: the static world). Objects (docs/objects.md):
 * the walk finds, for each object in the frustum, the first visited leaf whose
 * bounding box its box touches (kmin); its faces enter the same edge lists,
 * behind world surfaces of smaller keys and sorted by 1/z against those of
 * kmin and beyond and against other objects (obj_draw.h); a batch drawn before
 * the walk ends holds them as silent surfaces, which own their pixels but fill
 * nothing, and the last batch draws them; on lines with an object the top of the stack is also checked
 * for being overtaken along the line, so objects that reach into walls or into
 * each other are cut where they cross. Without objects the scan is the
 * key-only scan above, instruction for instruction. */
void spans_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                  void *work, uint32_t work_bytes);

#endif
