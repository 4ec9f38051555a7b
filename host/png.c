/* png.c - minimal PNG encoder: colour type 3 (palette), one IDAT holding a zlib
 * stream of stored (uncompressed) deflate blocks. The palette indices survive
 * exactly, so tests can read frames back pixel for pixel. */
#include "png.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "crc32.h"

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

static int write_chunk(FILE *f, const char *type, const uint8_t *data, uint32_t len)
{
    uint8_t head[8];
    put32(head, len);
    memcpy(head + 4, type, 4);
    uint32_t crc = crc_update(0, head + 4, 4);
    crc = crc_update(crc, data, len);
    uint8_t tail[4];
    put32(tail, crc);
    return (fwrite(head, 1, 8, f) == 8 && (len == 0 || fwrite(data, 1, len, f) == len) &&
            fwrite(tail, 1, 4, f) == 4) ? 0 : -1;
}

/* zlib stream of stored blocks around raw[0..n). */
static uint8_t *zlib_stored(const uint8_t *raw, uint32_t n, uint32_t *out_len)
{
    uint32_t blocks = n / 65535u + 1u;
    uint8_t *z = malloc(2u + n + blocks * 5u + 4u);
    if (!z) return NULL;
    uint32_t o = 0, a = 1, b = 0;
    z[o++] = 0x78;
    z[o++] = 0x01;
    for (uint32_t pos = 0;;) {
        uint32_t len = n - pos > 65535u ? 65535u : n - pos;
        int last = pos + len == n;
        z[o++] = (uint8_t)last;
        z[o++] = (uint8_t)len;
        z[o++] = (uint8_t)(len >> 8);
        z[o++] = (uint8_t)~len;
        z[o++] = (uint8_t)(~len >> 8);
        memcpy(z + o, raw + pos, len);
        o += len;
        pos += len;
        if (last) break;
    }
    for (uint32_t i = 0; i < n; i++) {
        a = (a + raw[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    put32(z + o, (b << 16) | a);
    *out_len = o + 4;
    return z;
}

int png_write_indexed(const char *path, const uint8_t *pixels, int width, int height, const uint8_t *rgb)
{
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    uint32_t raw_len = (uint32_t)(width + 1) * (uint32_t)height;
    uint8_t *raw = malloc(raw_len);
    if (!raw) return -1;
    for (int y = 0; y < height; y++) {
        raw[(size_t)y * (width + 1)] = 0; /* filter: none */
        memcpy(raw + (size_t)y * (width + 1) + 1, pixels + (size_t)y * width, (size_t)width);
    }
    uint32_t zlen = 0;
    uint8_t *z = zlib_stored(raw, raw_len, &zlen);
    free(raw);
    if (!z) return -1;
    uint8_t ihdr[13];
    put32(ihdr, (uint32_t)width);
    put32(ihdr + 4, (uint32_t)height);
    ihdr[8] = 8;  /* bit depth */
    ihdr[9] = 3;  /* palette */
    ihdr[10] = ihdr[11] = ihdr[12] = 0;
    FILE *f = fopen(path, "wb");
    int rc = -1;
    if (f) {
        rc = (fwrite(sig, 1, 8, f) == 8 && write_chunk(f, "IHDR", ihdr, 13) == 0 &&
              write_chunk(f, "PLTE", rgb, 768) == 0 && write_chunk(f, "IDAT", z, zlen) == 0 &&
              write_chunk(f, "IEND", NULL, 0) == 0) ? 0 : -1;
        if (fclose(f) != 0) rc = -1;
    }
    free(z);
    return rc;
}
