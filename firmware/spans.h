/* spans.h - render mode "spans": zero overdraw with sorted spans (prefix span_).
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
 * Per-scan-line coverage (seed 001, "Drawing polygons front to back") records
 * the pixels already claimed by nearer polygons: a polygon wholly behind them
 * adds no edges, and the walk stops as soon as every line is covered.
 *
 * Memory: all state lives in a caller-supplied work area. span_work_bytes()
 * returns what a scene can need in the worst case for any camera: every polygon
 * the scene has, each with the most edges clipping can give it, could be visible
 * at once. No pool can run out mid-frame, so there is no silent limit.
 */
#ifndef SPANS_H
#define SPANS_H

#include <stdint.h>
#include "render.h"
#include "scene.h"
#include "view.h"

/* Bytes of work memory spans_render needs for this scene and w's objects (w
 * NULL: none; see render_work_bytes), 0 if it would not fit in 32 bits: the
 * caller must refuse the scene. Objects add, for every face of every object
 * (all could be in view at once), a surface, its clipping-maximal edges and a
 * 1/z plane, plus a plane for every world surface and a key per leaf. */
uint32_t span_work_bytes(const scene *s, const world_state *w);

/* w: doors and objects (NULL: the static world). Objects are drawn after the
 * walk (docs/objects.md): each one whose box touches a visited leaf enters the
 * same edge lists, sorted against world surfaces by the key range of its
 * visited leaves and, inside that range, and against other objects, by 1/z
 * (obj_draw.h); on lines with an object the top of the stack is also checked
 * for being overtaken along the line, so objects that reach into walls or into
 * each other are cut where they cross. Without objects the scan is the
 * key-only scan above, instruction for instruction. */
void spans_render(const scene *sc, const world_state *w, const view_xform *v, const rast_target *t, render_stats *st,
                  void *work, uint32_t work_bytes);

#endif
