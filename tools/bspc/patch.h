/* patch.h - Doom's picture format, the patch (prefix bs_patch_): an 8-byte
 * header (width, height, left and top offsets, int16 each), a table of one
 * 32-bit offset per column, and at each offset the column's posts: a top row,
 * a length, a pad byte, the texels and a pad byte, until a top of 0xFF. Wall
 * textures are composed of patches and sprites are patches (wad_look.c,
 * sprites.c). Every byte read is bounds-checked; a damaged patch is described
 * in a message naming the WAD, the lump and the column. */
#ifndef BSPC_PATCH_H
#define BSPC_PATCH_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    int32_t width, height; /* > 0 */
    int32_t left, top;     /* the origin: left columns right of column 0, top rows above row 0 */
} bs_patch_info;

/* Read and check the header of patch p[0..size) (its width, height and column
 * table fit the lump): 0, or -1 with "WAD: patch WHAT: ..." in err. */
int bs_patch_info_read(const uint8_t *p, uint32_t size, const char *wad, const char *what, bs_patch_info *info,
                       char *err, size_t errlen);

/* A post of column col: len texels src from row top down (rows may pass the
 * patch's height: the caller clips). */
typedef void (*bs_patch_post_fn)(void *ctx, int32_t col, uint32_t top, const uint8_t *src, uint32_t len);

/* Check the header, then visit the posts of columns [c0, c1) (clamped to the
 * patch's columns; the others are not read), column by column, top to bottom
 * as stored. 0, or -1 with a message for a post or column that runs past the
 * end of the lump. */
int bs_patch_walk(const uint8_t *p, uint32_t size, const char *wad, const char *what, int32_t c0, int32_t c1,
                  bs_patch_post_fn post, void *ctx, char *err, size_t errlen);

#endif
