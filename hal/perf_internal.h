/* perf_internal.h - the hook by which hal/fb.c (and targets that write the
 * framebuffer themselves) feed the performance counters of hal/perf.c.
 * Not part of the target contract: firmware/ never includes this file.
 */
#ifndef HAL_PERF_INTERNAL_H
#define HAL_PERF_INTERNAL_H

#include <stdint.h>

/* Where a write transaction lands. */
enum { HAL_DEST_SYSMEM = 0, HAL_DEST_VRAM = 1 };

/* Record `count` write transactions of `width_bytes` (1, 2 or 4) to `dest`
 * (HAL_DEST_*). is_copy: 1 when made by the present copy, 0 when drawing.
 * Updates writes, bytes, writes8/16/32, vram/sysmem writes, copy writes and
 * the modelled cycle count. Any other width is ignored. */
void hal_perf_add_writes(unsigned width_bytes, int dest, uint32_t count, int is_copy);

/* Record `count` pixels drawn by the renderer (HAL_EV_PIXELS). */
void hal_perf_add_pixels(uint32_t count);

/* Record one span fill in one call: n8, n16 and n32 transactions of each width
 * to dest, covering `pixels` pixels with `bytes` = n8 + 2 n16 + 4 n32 bytes (the
 * pixel count on a linear surface, a quarter of it or so on a planar one; the
 * caller knows it without the sum). The same totals as the separate calls, for
 * a fraction of the cost per span: kept in 32-bit sums until hal_perf_fold.
 * Contract: pixels <= 320 (one clipped row) and n8 + n16 + n32 <= bytes <= pixels. */
void hal_perf_add_span(int dest, uint32_t n8, uint32_t n16, uint32_t n32, uint32_t pixels, uint32_t bytes);

/* Add the span sums to the 64-bit totals and the cycle count. hal_present calls
 * it once per frame; every reader of the counters calls it first. */
void hal_perf_fold(void);

#endif
