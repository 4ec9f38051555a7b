/* boot.c - the display board's DFU bootloader (hal/board): the image in the
 * first 64 KiB of flash, with its own vector table at 0.
 *
 * At reset it asks firmware/dfu's dfu_app_check whether the application slot
 * (board_layout.h) holds an application marked valid by a DFU download: the
 * 16-byte mark at the start of the slot's last page, whose length and CRC-32
 * must match the application bytes; and boot_vectors.h whether its vector table
 * can be started (stack in RAM, reset handler in the image). If so, it points VTOR at the application's
 * vector table, loads MSP from it and jumps to its reset handler. If not, it
 * says why on semihosting and exits with BOOT_EXIT_NO_APP: a real board would
 * stay in DFU mode and wait for a download over USB, which the emulated board
 * does not have.
 *
 * It touches no peripheral: the application starts from a board as reset left
 * it (no interrupt enabled, no SysTick running). */
#include <stdarg.h>
#include <stdint.h>

#include "board_layout.h"
#include "boot_vectors.h"
#include "crc32.h"
#include "dfu/dfu_device.h"
#include "format.h"
#include "log.h"
#include "mps2.h"

#define BOOT_EXIT_NO_APP 7

static const uint8_t *slot(void)
{
    return (const uint8_t *)(uintptr_t)BOARD_SLOT_ADDR;
}

static int slot_read(void *ctx, uint32_t offset, uint8_t *dst, uint32_t n)
{
    (void)ctx;
    const uint8_t *p = slot() + offset;
    for (uint32_t i = 0; i < n; i++) dst[i] = p[i];
    return 0;
}

/* The bootloader never writes: only a DFU session (not on this board) would. */
static int slot_erase(void *ctx, uint32_t offset)
{
    (void)ctx, (void)offset;
    return -1;
}

static int slot_program(void *ctx, uint32_t offset, const uint8_t *src, uint32_t n)
{
    (void)ctx, (void)offset, (void)src, (void)n;
    return -1;
}

static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void fmt_line(char *buf, uint32_t size, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void fmt_line(char *buf, uint32_t size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fmt_format(buf, (int)size, fmt, ap);
    va_end(ap);
}

/* Why dfu_app_check refused the slot, for the log. */
static void say_why(const dfu_app_info_t *info, char *why, uint32_t size)
{
    const uint8_t *mark = slot() + BOARD_SLOT_BYTES - BOARD_PAGE_BYTES;
    if (info->length == 0 && get32(mark) == 0xFFFFFFFFu) {
        fmt_line(why, size, "no valid mark: the mark page at 0x%08x is erased",
                 (unsigned)(BOARD_SLOT_ADDR + BOARD_SLOT_BYTES - BOARD_PAGE_BYTES));
    } else if (info->length == 0) {
        fmt_line(why, size, "the valid mark at 0x%08x is damaged",
                 (unsigned)(BOARD_SLOT_ADDR + BOARD_SLOT_BYTES - BOARD_PAGE_BYTES));
    } else if (info->length > BOARD_SLOT_BYTES - BOARD_PAGE_BYTES) {
        fmt_line(why, size, "the mark's length %u is larger than the slot", (unsigned)info->length);
    } else {
        fmt_line(why, size, "the application's CRC-32 0x%08x does not match the mark's 0x%08x (%u bytes)",
                 (unsigned)crc_update(0, slot(), info->length), (unsigned)info->crc, (unsigned)info->length);
    }
}

__attribute__((noreturn)) static void start_app(const uint32_t *vectors)
{
    SCB_VTOR = (uint32_t)(uintptr_t)vectors;
    __asm__ volatile("dsb\n isb" ::: "memory");
    __asm__ volatile("msr msp, %0\n"
                     "bx %1\n" ::"r"(vectors[0]),
                     "r"(vectors[1])
                     : "memory");
    __builtin_unreachable();
}

int main(void)
{
    static char why[160];
    log_set_sinks(LOG_TO_SEMIHOST);
    dfu_flash_t flash = {
        .ctx = 0,
        .size = BOARD_SLOT_BYTES,
        .page_size = BOARD_PAGE_BYTES,
        .erase = slot_erase,
        .program = slot_program,
        .read = slot_read,
    };
    dfu_app_info_t info;
    if (dfu_app_check(&flash, &info)) {
        const uint32_t *vectors = (const uint32_t *)(uintptr_t)BOARD_SLOT_ADDR;
        const char *refusal = boot_vectors_refusal(vectors[0], vectors[1], BOARD_SLOT_ADDR, info.length);
        if (refusal) {
            log_printf("bootloader: the application (%u bytes, CRC-32 0x%08x) cannot be started: %s "
                       "(stack 0x%08x, reset 0x%08x); staying in DFU mode\n",
                       (unsigned)info.length, (unsigned)info.crc, refusal, (unsigned)vectors[0], (unsigned)vectors[1]);
            return BOOT_EXIT_NO_APP;
        }
        log_printf("bootloader: application valid (%u bytes, CRC-32 0x%08x); starting it at 0x%08x\n",
                   (unsigned)info.length, (unsigned)info.crc, (unsigned)vectors[1]);
        start_app(vectors);
    }
    say_why(&info, why, sizeof why);
    log_printf("bootloader: no valid application in the slot (%s); staying in DFU mode\n", why);
    return BOOT_EXIT_NO_APP;
}
