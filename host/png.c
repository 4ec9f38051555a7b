/* png.c - palette PNG files through libpng: colour type 3, 8 bits, the palette
 * as given. Rows are stored unfiltered (PNG's advice for palette images, and
 * what the tests' small readers expect), deflated at zlib's best level: a flat
 * frame is a few kilobytes, not the 64 KB of stored blocks. */
#include "png.h"

#include <errno.h>
/* by its folder: -Ihost would otherwise find this module's own png.h */
#include <libpng/png.h>
#include <setjmp.h>
#include <stdio.h>

/* libpng reports errors by longjmp; the caller gets -1 with errno set. */
static int png_encode(FILE *f, const uint8_t *pixels, int width, int height, const uint8_t *rgb)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    if (!png) return -1;
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return -1;
    }
    png_color pal[256];
    for (int i = 0; i < 256; i++) {
        pal[i].red = rgb[3 * i];
        pal[i].green = rgb[3 * i + 1];
        pal[i].blue = rgb[3 * i + 2];
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, PNG_COLOR_TYPE_PALETTE, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_PLTE(png, info, pal, 256);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
    png_set_compression_level(png, 9);
    png_write_info(png, info);
    for (int y = 0; y < height; y++) png_write_row(png, pixels + (size_t)y * (size_t)width);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return 0;
}

int png_write_indexed(const char *path, const uint8_t *pixels, int width, int height, const uint8_t *rgb)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    int rc = png_encode(f, pixels, width, height, rgb);
    int saved = errno;
    if (fclose(f) != 0 && rc == 0) return -1;
    if (rc != 0) errno = saved ? saved : EIO;
    return rc;
}
