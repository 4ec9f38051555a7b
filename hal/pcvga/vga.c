/* vga.c - mode 13h and its unchained form, the DAC, the start address (see vga.h).
 * The register values are those of the VGA's standard mode 13h. */
#include "vga.h"

#include "io.h"

#define MISC_WRITE 0x3C2
#define SEQ_INDEX 0x3C4
#define SEQ_DATA 0x3C5
#define DAC_WRITE_INDEX 0x3C8
#define DAC_DATA 0x3C9
#define GC_INDEX 0x3CE
#define GC_DATA 0x3CF
#define CRTC_INDEX 0x3D4
#define CRTC_DATA 0x3D5
#define AC_INDEX 0x3C0
#define INPUT_STATUS_1 0x3DA
#define STATUS_VRETRACE 0x08u

#define SEQ_MAP_MASK 0x02
#define SEQ_MEMORY_MODE 0x04
#define GC_READ_MAP 0x04
#define CRTC_START_HI 0x0C
#define CRTC_START_LO 0x0D
#define CRTC_VRETRACE_END 0x11
#define CRTC_UNDERLINE 0x14
#define CRTC_MODE_CONTROL 0x17
#define AC_VIDEO_ENABLE 0x20
#define RETRACE_POLLS 1000000u /* bound on a wait for retrace: never hang on an odd VGA */

static const uint8_t misc_13h = 0x63;
static const uint8_t seq_13h[5] = {0x03, 0x01, 0x0F, 0x00, 0x0E};
static const uint8_t crtc_13h[25] = {0x5F, 0x4F, 0x50, 0x82, 0x54, 0x80, 0xBF, 0x1F, 0x00, 0x41, 0x00, 0x00, 0x00,
                                     0x00, 0x00, 0x00, 0x9C, 0x0E, 0x8F, 0x28, 0x40, 0x96, 0xB9, 0xA3, 0xFF};
static const uint8_t gc_13h[9] = {0x00, 0x00, 0x00, 0x00, 0x00, 0x40, 0x05, 0x0F, 0xFF};
static const uint8_t ac_13h[21] = {0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A,
                                   0x0B, 0x0C, 0x0D, 0x0E, 0x0F, 0x41, 0x00, 0x0F, 0x00, 0x00};

static void reg_out(uint16_t index_port, uint8_t index, uint8_t value)
{
    io_out8(index_port, index);
    io_out8((uint16_t)(index_port + 1), value);
}

static uint8_t reg_in(uint16_t index_port, uint8_t index)
{
    io_out8(index_port, index);
    return io_in8((uint16_t)(index_port + 1));
}

static void clear_window(uint32_t bytes)
{
    volatile uint32_t *w = (volatile uint32_t *)(void *)VGA_WINDOW;
    for (uint32_t i = 0; i < bytes / 4u; i++) w[i] = 0;
}

void vga_set_mode13h(void)
{
    io_out8(MISC_WRITE, misc_13h);
    reg_out(SEQ_INDEX, 0, 0x01); /* synchronous reset while the clocking changes */
    for (uint8_t i = 1; i < sizeof seq_13h; i++) reg_out(SEQ_INDEX, i, seq_13h[i]);
    reg_out(SEQ_INDEX, 0, seq_13h[0]);
    /* registers 0-7 are write-protected until bit 7 of the vertical retrace end is clear */
    reg_out(CRTC_INDEX, CRTC_VRETRACE_END, crtc_13h[CRTC_VRETRACE_END] & 0x7Fu);
    for (uint8_t i = 0; i < sizeof crtc_13h; i++) reg_out(CRTC_INDEX, i, crtc_13h[i]);
    for (uint8_t i = 0; i < sizeof gc_13h; i++) reg_out(GC_INDEX, i, gc_13h[i]);
    (void)io_in8(INPUT_STATUS_1); /* the attribute controller's flip-flop to "index" */
    for (uint8_t i = 0; i < sizeof ac_13h; i++) {
        io_out8(AC_INDEX, i);
        io_out8(AC_INDEX, ac_13h[i]);
    }
    (void)io_in8(INPUT_STATUS_1);
    io_out8(AC_INDEX, AC_VIDEO_ENABLE);
    clear_window(64000u);
}

void vga_set_unchained(void)
{
    reg_out(SEQ_INDEX, SEQ_MEMORY_MODE, 0x06);    /* chain-4 off, odd/even off, 256 KB */
    reg_out(CRTC_INDEX, CRTC_UNDERLINE, 0x00);    /* doubleword addressing off */
    reg_out(CRTC_INDEX, CRTC_MODE_CONTROL, 0xE3); /* byte addressing */
    vga_map_mask(0x0Fu);
    clear_window(65536u); /* every plane at once */
}

void vga_load_dac(const uint8_t *rgb)
{
    io_out8(DAC_WRITE_INDEX, 0);
    for (int i = 0; i < 768; i++) io_out8(DAC_DATA, (uint8_t)(rgb[i] >> 2));
}

void vga_map_mask(unsigned planes)
{
    reg_out(SEQ_INDEX, SEQ_MAP_MASK, (uint8_t)(planes & 0x0Fu));
}

/* The start address is latched at the start of vertical retrace: set it during
 * the display, then wait for the retrace, so the next frame is not drawn into
 * the page still being scanned out. Both waits are bounded. */
void vga_set_start(uint32_t offset)
{
    for (uint32_t n = 0; n < RETRACE_POLLS && (io_in8(INPUT_STATUS_1) & STATUS_VRETRACE); n++) {
    }
    reg_out(CRTC_INDEX, CRTC_START_HI, (uint8_t)(offset >> 8));
    reg_out(CRTC_INDEX, CRTC_START_LO, (uint8_t)offset);
    for (uint32_t n = 0; n < RETRACE_POLLS && !(io_in8(INPUT_STATUS_1) & STATUS_VRETRACE); n++) {
    }
}

uint32_t vga_start(void)
{
    return (uint32_t)reg_in(CRTC_INDEX, CRTC_START_HI) << 8 | reg_in(CRTC_INDEX, CRTC_START_LO);
}

void vga_read_unchained(uint32_t offset, uint8_t *frame)
{
    const volatile uint8_t *mem = VGA_WINDOW + offset;
    for (unsigned plane = 0; plane < 4; plane++) {
        reg_out(GC_INDEX, GC_READ_MAP, (uint8_t)plane);
        for (uint32_t y = 0; y < 200; y++)
            for (uint32_t k = 0; k < 80; k++) frame[y * 320 + k * 4 + plane] = mem[y * 80 + k];
    }
}
