/* crc_fast.c - crc_update of firmware/crc32.h (CRC-32, reflected 0xEDB88320)
 * for the compiler, by zlib's crc32: the same checksum, the same chaining
 * (both invert before and after), several bytes a step. bspc checksums each
 * blob of up to megabytes twice (when written, and when parsed back; the
 * needs record written after that patches the CRC, bspc.c's crc_patch); the
 * firmware keeps its 64-byte nibble table. */
#include <limits.h>
#include <zlib.h>

#include "crc32.h"

uint32_t crc_update(uint32_t crc, const uint8_t *p, size_t n)
{
    while (n > 0) { /* zlib takes an unsigned length */
        uInt k = n > UINT_MAX ? UINT_MAX : (uInt)n;
        crc = (uint32_t)crc32(crc, p, k);
        p += k;
        n -= k;
    }
    return crc;
}
