/* fuzz_common.h - what the engine harnesses share (tests/fuzz/fuzz_{text,wad,scene,render}.c):
 * a fuzz input as a file for the compiler, which reads files, and a frame of a
 * compiled scene through the firmware's own entry points (engine.h). */
#ifndef FUZZ_COMMON_H
#define FUZZ_COMMON_H

#include "fuzz_util.h"

/* A camera and a time, as raw as the fuzzer gives them: the renderer must take
 * any (it clamps the eye into the world box and the look). */
typedef struct {
    int32_t x, y, z, angle, look;
    uint32_t t_ms;
} fuzz_view;
#define FUZZ_VIEW_BYTES 24

/* Read a fuzz_view from the first FUZZ_VIEW_BYTES of data (little-endian). */
fuzz_view fuzz_view_from(const uint8_t *data);

/* Compile spec quietly. Returns 0 and a malloc'd blob, or -1; a refusal must say
 * which file it refuses (the message names spec's file), or the harness stops. */
int fuzz_compile(const char *spec, const char *file, uint8_t **blob, size_t *len);

/* The input as this process's temporary file ending in suffix, compiled (map: the
 * map to take from a WAD, NULL for a text scene). 0 and the blob, or -1. */
int fuzz_compile_input(const uint8_t *data, size_t size, const char *suffix, const char *map, uint8_t **blob,
                       size_t *len);

/* Load blob as the firmware does and draw it in every mode, from view (NULL: the
 * player start) at view->t_ms with the objects and doors moved there.
 * trusted: the blob came from the compiler, so it must load, and no frame may
 * drop a polygon (render_stats.overflow: the proven bounds hold). Otherwise the
 * loader may refuse it, and whatever it accepts must draw without a fault. */
void fuzz_draw(const uint8_t *blob, size_t len, const fuzz_view *view, int trusted);

#endif
