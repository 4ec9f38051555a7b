/* board_image.c - the display board's whole flash image (build/arm/display-board.bin).
 *
 *   board_image BOOT.bin APP.bin OUT.bin
 *
 * OUT is the 4 MiB flash of hal/board/board_layout.h: the bootloader at 0, 0xFF
 * up to the application slot, and the slot as a DFU download of APP leaves it.
 * The slot is not assembled by hand: APP is downloaded, block by block, into
 * firmware/dfu's own device state machine (dfu_device.c) over the in-memory
 * loopback transport (host/flash/dfu_loopback.c) with the slot's geometry, by
 * the host engine build/flash uses (host/flash/dfu_host.c), and the slot is
 * what the device's flash holds after manifestation: the application, erased
 * bytes, and the valid mark the device itself wrote. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../hal/board/board_layout.h"
#include "dfu/dfu_device.h"
#include "flash/dfu_host.h"
#include "flash/dfu_loopback.h"

#define FLASH_BYTES (BOARD_SLOT_ADDR + BOARD_SLOT_BYTES)

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        return NULL;
    }
    unsigned char *buf = NULL;
    size_t cap = 0, n = 0, k;
    do {
        if (n == cap) {
            cap = cap ? cap * 2 : 65536;
            unsigned char *b = realloc(buf, cap);
            if (!b) {
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = b;
        }
        k = fread(buf + n, 1, cap - n, f);
        n += k;
    } while (k > 0);
    fclose(f);
    *len = n;
    return buf;
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: board_image BOOT.bin APP.bin OUT.bin\n");
        return 2;
    }
    size_t boot_len, app_len;
    unsigned char *boot = slurp(argv[1], &boot_len), *app = slurp(argv[2], &app_len);
    if (!boot || !app) return 1;
    if (boot_len > BOARD_BOOT_BYTES) {
        fprintf(stderr, "board_image: the bootloader is %zu bytes; it has %u\n", boot_len, BOARD_BOOT_BYTES);
        return 1;
    }
    static dfu_loopback lb;
    if (dfu_loop_init(&lb, NULL, BOARD_SLOT_BYTES, BOARD_PAGE_BYTES, 1) != 0) {
        fprintf(stderr, "board_image: cannot set up the DFU device\n");
        return 1;
    }
    dfu_transport t = dfu_loop_transport(&lb);
    dfu_host_opts o;
    memset(&o, 0, sizeof o);
    dfu_host_report r;
    if (dfu_host_download(&t, app, app_len, &o, &r) != DFU_HOST_OK) {
        fprintf(stderr, "board_image: the download into the slot failed: %s\n", r.msg);
        return 1;
    }
    dfu_app_info_t info;
    if (!dfu_app_check(&lb.flash, &info) || info.length != app_len) {
        fprintf(stderr, "board_image: the slot holds no valid application after the download\n");
        return 1;
    }
    unsigned char *img = malloc(FLASH_BYTES);
    if (!img) return 1;
    memset(img, 0xFF, FLASH_BYTES);
    memcpy(img, boot, boot_len);
    memcpy(img + BOARD_SLOT_ADDR, lb.mem, BOARD_SLOT_BYTES);
    FILE *f = fopen(argv[3], "wb");
    if (!f || fwrite(img, 1, FLASH_BYTES, f) != FLASH_BYTES || fclose(f) != 0) {
        perror(argv[3]);
        return 1;
    }
    printf("board_image: %s: bootloader %zu bytes at 0x0, application %zu bytes at 0x%08x, valid mark at "
           "0x%08x (CRC-32 0x%08x)\n",
           argv[3], boot_len, app_len, BOARD_SLOT_ADDR, BOARD_SLOT_ADDR + BOARD_SLOT_BYTES - BOARD_PAGE_BYTES,
           (unsigned)info.crc);
    free(img);
    free(boot);
    free(app);
    dfu_loop_free(&lb);
    return 0;
}
