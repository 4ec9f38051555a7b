/* crc32.h - CRC-32 (IEEE 802.3, reflected, as zlib's crc32()) for compiled scenes,
 * frames and the frame link (prefix crc_). */
#ifndef CRC32_H
#define CRC32_H

#include <stddef.h>
#include <stdint.h>

/* Continue a CRC: start with crc = 0, feed bytes in any number of calls. */
uint32_t crc_update(uint32_t crc, const uint8_t *p, size_t n);

#endif
