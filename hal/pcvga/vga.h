/* vga.h - the PC's VGA, programmed through its registers (prefix vga_): no BIOS.
 *
 * Two layouts of the same 256 KB (four 64 KB planes) behind the window at
 * 0xA0000:
 *   chained   mode 13h: 320x200, 256 colours, one byte a pixel, linear at
 *             0xA0000 (pitch 320); the chain-4 logic picks the plane from the
 *             address. One 64,000-byte page: what the copy present modes show.
 *   unchained the same timing with chain-4 off ("mode X"): pixel (x, y) is in
 *             plane x & 3 at byte y * 80 + x / 4 of the page, a byte write
 *             reaches every plane the sequencer's map mask enables (one write,
 *             up to 4 pixels), and the CRTC start address picks the page shown:
 *             two 16,000-byte pages (per plane), for page flipping.
 * The DAC holds 6 bits per gun: vga_load_dac drops the low 2 bits of each
 * 8-bit value. */
#ifndef PCVGA_VGA_H
#define PCVGA_VGA_H

#include <stdint.h>

#define VGA_WINDOW ((uint8_t *)0xA0000)
#define VGA_PLANAR_PAGE_BYTES 16000u /* 80 x 200 bytes a plane */

void vga_set_mode13h(void);            /* chained 320x200x256, display start 0, page cleared */
void vga_set_unchained(void);          /* from mode 13h: chain-4 off, byte addressing, all 256 KB cleared */
void vga_load_dac(const uint8_t *rgb); /* 256 entries, 8 bits per gun */
void vga_map_mask(unsigned planes);    /* bit p: writes reach plane p */
void vga_set_start(uint32_t offset); /* CRTC start address (unchained: a page's byte offset), set at vertical retrace */
uint32_t vga_start(void);
/* Read an unchained page at offset back into a linear 320x200 frame (reads
 * plane by plane through the read map select). */
void vga_read_unchained(uint32_t offset, uint8_t *frame);

#endif
