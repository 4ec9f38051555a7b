/* crc_fast.c - crc_update of firmware/crc32.h (CRC-32, reflected 0xEDB88320)
 * for the compiler, eight bytes a step with eight 1 KB tables (slicing-by-8).
 * bspc checksums each blob of up to megabytes twice (when written, and when
 * parsed back; the needs record written after that patches the CRC,
 * bspc.c's crc_patch); the firmware keeps its 64-byte nibble table. */
#include "crc32.h"

static uint32_t crc_tab[8][256];
static int crc_ready;

static void crc_init(void)
{
    for (uint32_t i = 0; i < 256; i++) {
        uint32_t c = i;
        for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
        crc_tab[0][i] = c;
    }
    for (uint32_t i = 0; i < 256; i++)
        for (int t = 1; t < 8; t++) crc_tab[t][i] = (crc_tab[t - 1][i] >> 8) ^ crc_tab[0][crc_tab[t - 1][i] & 255u];
    crc_ready = 1;
}

uint32_t crc_update(uint32_t crc, const uint8_t *p, size_t n)
{
    if (!crc_ready) crc_init();
    crc = ~crc;
    for (; n >= 8; n -= 8, p += 8) {
        uint32_t lo = crc ^ ((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24);
        uint32_t hi = (uint32_t)p[4] | (uint32_t)p[5] << 8 | (uint32_t)p[6] << 16 | (uint32_t)p[7] << 24;
        crc = crc_tab[7][lo & 255u] ^ crc_tab[6][(lo >> 8) & 255u] ^ crc_tab[5][(lo >> 16) & 255u] ^
              crc_tab[4][lo >> 24] ^ crc_tab[3][hi & 255u] ^ crc_tab[2][(hi >> 8) & 255u] ^
              crc_tab[1][(hi >> 16) & 255u] ^ crc_tab[0][hi >> 24];
    }
    while (n--) crc = (crc >> 8) ^ crc_tab[0][(crc ^ *p++) & 255u];
    return ~crc;
}
