/* boot_vectors.c - the bootloader's check of an application's vector table (see
 * boot_vectors.h). */
#include "boot_vectors.h"

#include "board_layout.h"

const char *boot_vectors_refusal(uint32_t sp, uint32_t reset, uint32_t app_addr, uint32_t app_len)
{
    if (app_len < 8) return "the application is too short to hold a vector table";
    /* the stack grows down from sp: its first push lands just below it, so sp
     * may be the RAM's end but not its start; the core ignores sp's low 2 bits,
     * which a linker never sets */
    if (sp <= BOARD_RAM_ORIGIN || sp > BOARD_RAM_END || (sp & 3u)) return "its initial stack pointer is not in RAM";
    if (!(reset & 1u)) return "its reset vector lacks the Thumb bit";
    uint32_t pc = reset & ~1u;
    /* the first instruction (at least 2 bytes) lies inside the application */
    if (pc < app_addr || pc - app_addr > app_len - 2u) return "its reset vector points outside the application";
    return 0;
}
