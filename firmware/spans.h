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

/* Bytes of work memory spans_render needs for this scene (0 if it would not fit
 * in 32 bits: the caller must refuse the scene). */
uint32_t span_work_bytes(const scene *s);

void spans_render(const scene *sc, const view_xform *v, const rast_target *t, render_stats *st, void *work,
                  uint32_t work_bytes);

#endif
