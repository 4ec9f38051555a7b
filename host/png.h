/* png.h - writing 8-bit palette PNG files (host only, libpng). */
#ifndef HOST_PNG_H
#define HOST_PNG_H

#include <stdint.h>

/* Write a width x height image of palette indices with a 256-entry RGB palette
 * (768 bytes, 8 bits per gun). Returns 0, or -1 with errno set. */
int png_write_indexed(const char *path, const uint8_t *pixels, int width, int height, const uint8_t *rgb);

#endif
