/* board_layout.h - the display board's flash (QEMU mps2-an385's SSRAM1, 4 MiB
 * at 0, used as flash), fixed for every part of the board (hal/board/README.md):
 *   0x00000000  64 KiB       the DFU bootloader (boot.c), its vector table at 0
 *   0x00010000  4,128,768    the application slot: a dfu_flash_t region in pages
 *                            of 4,096; the application from its start (its vector
 *                            table at 0x00010000), the valid mark (dfu_device.c's
 *                            16-byte trailer) at the start of its last page,
 *                            0x003FF000.
 * mk/board.mk links with the same figures. */
#ifndef BOARD_LAYOUT_H
#define BOARD_LAYOUT_H

#define BOARD_BOOT_BYTES 0x00010000u
#define BOARD_SLOT_ADDR 0x00010000u
#define BOARD_SLOT_BYTES 4128768u
#define BOARD_PAGE_BYTES 4096u
/* the AN385's SSRAM2 and SSRAM3, 4 MiB at 0x20000000: where any application's stack may start */
#define BOARD_RAM_ORIGIN 0x20000000u
#define BOARD_RAM_END 0x20400000u

#endif
