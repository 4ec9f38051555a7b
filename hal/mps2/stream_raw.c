/* stream_raw.c - frames over UART0 uncompressed (see stream.h; STREAM=raw).
 *
 * Little-endian records, each starting with a 4-byte tag; no framing, no acks:
 *   "RAWP" + 768 palette bytes                                        (once, first)
 *   "RAWF" + frame u32, x, y, z, angle i32 (16.16), look i32, mode u8,
 *          present u8, 2 zero bytes, crc32 u32, time_ms u32 (the engine's t_ms),
 *          then 64,000 pixel bytes (each frame)
 *   "RAWE" + frames u32                                               (at the end)
 * Text (log.h) may stand between records. tests/test_firmware.py reads it.
 */
#include "stream.h"

#include "crc32.h"
#include "hal.h"
#include "uart.h"

static void put32(uint32_t v)
{
    for (int i = 0; i < 4; i++) uart_putc((uint8_t)(v >> (8 * i)));
}

const char *stream_kind(void)
{
    return "raw";
}

int stream_text_ok(void)
{
    return 1;
}

const char *stream_summary(void)
{
    return "";
}

void stream_set_acks(stream_acks mode)
{
    (void)mode; /* no acks in this encoding */
}

int stream_begin(const engine *e, const char *scene_name, uint32_t scene_crc)
{
    (void)e;
    (void)scene_name; /* raw records have no place for the scene */
    (void)scene_crc;
    uart_write("RAWP", 4);
    uart_write(hal_get_palette(), HAL_PALETTE_BYTES);
    return 0;
}

int stream_frame(const engine *e, uint32_t frame_no)
{
    const uint8_t *page = hal_shown_page();
    uart_write("RAWF", 4);
    put32(frame_no);
    put32((uint32_t)e->cam.view.x);
    put32((uint32_t)e->cam.view.y);
    put32((uint32_t)e->cam.view.z);
    put32((uint32_t)e->cam.view.angle_deg);
    put32((uint32_t)e->cam.view.look);
    put32((uint32_t)e->mode | (uint32_t)e->present << 8);
    put32(crc_update(0, page, HAL_PAGE_BYTES));
    put32(e->t_ms);
    uart_write(page, HAL_PAGE_BYTES);
    return 0;
}

void stream_end(uint32_t frames)
{
    uart_write("RAWE", 4);
    put32(frames);
    uart_flush();
}
