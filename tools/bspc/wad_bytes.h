/* wad_bytes.h - reading a WAD's fields: little-endian integers and the 8-byte
 * lump and texture names (NUL padded, compared upper case). Shared by the WAD
 * reader, its look, the patch decoder and the animation table. */
#ifndef BSPC_WAD_BYTES_H
#define BSPC_WAD_BYTES_H

#include <ctype.h>
#include <stdint.h>

static inline uint16_t rd16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static inline int16_t rds16(const uint8_t *p)
{
    return (int16_t)rd16(p);
}

static inline uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* A name field: 8 bytes, NUL padded, into out upper case. */
static inline void name8(char out[9], const uint8_t *p)
{
    int i;
    for (i = 0; i < 8 && p[i]; i++) out[i] = (char)toupper(p[i]);
    out[i] = 0;
}

#endif
