/* stream_fl.c - frames over UART0 with the frame link (see stream.h;
 * STREAM=framelink; the protocol: hal/serial/framelink.h, docs/frame-link.md).
 *
 * Hello and palette first; then every frame as a keyframe or as a delta against
 * the frame sent just before it. In flip mode that frame is still on the hidden
 * VRAM page (the page the next frame will be drawn into), so deltas cost no copy;
 * in the copy modes both pages are not kept, and frames go as keyframes.
 *
 * Flow control: acks and keyframe requests arrive through the UART's RX
 * interrupt ring (uart.h) and are fed to the encoder before every frame; while
 * its ack window is full the firmware waits (the encoder gives a silent window
 * up after its ack timeout, measured on hal_ticks_ms). See stream.h for AUTO.
 * Transmission itself never overruns: uart_putc waits for TX-not-full.
 */
#include "stream.h"

#include <stdarg.h>

#include "fl_engine_info.h"
#include "framelink.h"
#include "hal.h"
#include "format.h"
#include "log.h"
#include "uart.h"

#define SCRATCH_BYTES 8192 /* one coded frame message (framelink.h: ample for flat-shaded frames) */

static fl_encoder enc;
static _Alignas(4) uint8_t scratch[SCRATCH_BYTES];
static struct {
    stream_acks acks;
    int heard;        /* the receiver has sent something intact */
    int have_prev;    /* a frame was sent ... */
    uint32_t prev_no; /* ... with this number */
    int prev_flip;    /* ... in flip mode (so it is on the hidden page now) */
} st;

static void put(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)ctx;
    uart_write(p, n);
}

static void poll_rx(void)
{
    uint8_t buf[32];
    uint32_t n = 0;
    int c;
    uint32_t before = enc.acks + enc.keyreqs + enc.palette_reqs;
    while ((c = uart_getc()) >= 0) {
        buf[n++] = (uint8_t)c;
        if (n == sizeof buf) {
            fl_enc_receive(&enc, buf, n);
            n = 0;
        }
    }
    if (n) fl_enc_receive(&enc, buf, n);
    if (enc.acks + enc.keyreqs + enc.palette_reqs != before) st.heard = 1;
}

static int flow_control(void)
{
    return st.acks == STREAM_ACKS_ON || (st.acks == STREAM_ACKS_AUTO && st.heard);
}

const char *stream_kind(void)
{
    return "framelink";
}

int stream_text_ok(void)
{
    return 0;
}

void stream_set_acks(stream_acks mode)
{
    st.acks = mode;
}

int stream_begin(const engine *e, const char *scene_name, uint32_t scene_crc)
{
    (void)e;
    st.heard = 0;
    st.have_prev = 0;
    fl_enc_init(&enc, put, 0, scratch, sizeof scratch);
    fl_enc_scene(&enc, scene_name, scene_crc);
    fl_enc_hello(&enc);
    fl_enc_palette(&enc, hal_get_palette()); /* mps2_palette: stays valid */
    return 0;
}

int stream_frame(const engine *e, uint32_t frame_no)
{
    poll_rx();
    if (flow_control()) {
        while (!fl_enc_may_send(&enc, hal_ticks_ms())) poll_rx();
    }
    const uint8_t *page = hal_shown_page();
    fl_frame_info info = fl_engine_info(e);
    /* the frame check carries the end-to-end check at a fraction of the
     * pixel CRC-32's cost (640 K instructions a frame on the Cortex-M3);
     * the receiver fills the CRC in */
    info.no_crc = 1;
    const uint8_t *base = 0;
    if (st.have_prev && st.prev_flip && e->present == HAL_PRESENT_FLIP && st.prev_no == frame_no - 1u)
        base = hal_target_vram(1 - hal_target_display_start());
    fl_enc_frame(&enc, frame_no, page, base, frame_no - 1u, &info);
    st.have_prev = 1;
    st.prev_no = frame_no;
    st.prev_flip = e->present == HAL_PRESENT_FLIP;
    return 0;
}

void stream_end(uint32_t frames)
{
    if (frames && flow_control()) {
        uint32_t t0 = hal_ticks_ms();
        while (enc.in_count > 0 && hal_ticks_ms() - t0 < enc.ack_timeout_ms) poll_rx();
    }
    uart_flush();
}

static void format(char *buf, int size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fmt_format(buf, size, fmt, ap);
    va_end(ap);
}

const char *stream_summary(void)
{
    static char line[200];
    format(line, sizeof line,
           "link: %u frames (%u keyframes, %u deltas, %u raw), %u bytes; %u acks, %u keyframe requests, "
           "%u timeouts, %u bad messages received",
           (unsigned)enc.frames, (unsigned)enc.keyframes, (unsigned)enc.deltas, (unsigned)enc.raw_fallbacks,
           (unsigned)enc.bytes, (unsigned)enc.acks, (unsigned)enc.keyreqs, (unsigned)enc.timeouts,
           (unsigned)enc.rx_bad);
    return line;
}
