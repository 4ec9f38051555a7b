/* main.c - the display board (hal/board): a Cortex-M3 that receives the frame
 * link (hal/serial) on UART0 and shows each frame that passes the decoder's
 * checks by flipping its display start to the page the frame was rebuilt in.
 *
 * The UART's receive interrupt puts the bytes in a ring and notes where each
 * message ends (hal/mps2/uart.c); the main loop sleeps until there is
 * something to take and hands the decoder the ring's contiguous spans in place,
 * each up to a message's delimiter at most, with no copy and no call per byte.
 * The decoder rebuilds a frame straight into the hidden VRAM page (a keyframe
 * from scratch, a delta onto the shown page), checks it (message CRC, frame
 * check, pixel CRC-32 when sent), and only then is the page flipped: a frame
 * that fails any check is never shown. Acks and keyframe requests go back on
 * UART0's transmitter. It computes no CRC-32 of a frame the sender sent none
 * for (want_crc 0): the log below does, after the frame's handling.
 *
 * Options (semihosting command line, board_args.h): --frames N: after N frames
 * shown, log a summary line and idle (WFI) for ever, so that a debugger or QMP
 * can still read the pages; without it, run until QEMU is stopped.
 * --log-frames: one line per frame shown, on semihosting:
 *   board: frame N crc32 0xC shown page P camera X Y Z ANGLE look L mode M present Q key K seg S
 * (crc32: of the page shown, the sender's CRC-32 if it sent one, else computed
 * here after the marked span; camera in raw 16.16, as the frame info carries
 * it; seg: the message's number among the segments marked for the instruction
 * counter). Without it, a line of counters every BOARD_LOG_EVERY frames.
 *
 * Memory: the two pages, palette and display-start register (.display,
 * hal/mps2/mps2.ld), one message buffer and the UART's receive ring
 * (UART_RX_RING, mk/board.mk); no 64,000-byte copy per frame.
 */
#include <stdint.h>

#include "board_args.h"
#include "crc32.h"
#include "framelink.h"
#include "log.h"
#include "mps2.h"
#include "semihost.h"
#include "uart.h"

#define BOARD_EXIT_ARGS 5
#define BOARD_LOG_EVERY 1000u /* frames between counter lines without --log-frames */

/* ---- markers for the instruction counter (tools/qemu_plugin/insn_count.c) --
 * begin: the first byte of a link message (a segment up to its 0x00
 * delimiter); end: right after the delimiter has been fed, i.e. the message is
 * handled (a frame rebuilt, checked, flipped and acked). noipa keeps the calls. */
volatile uint32_t board_mark_seg, board_mark_done;

__attribute__((noinline, noipa, used)) void fw_mark_frame_begin(uint32_t seg)
{
    board_mark_seg = seg;
}

__attribute__((noinline, noipa, used)) void fw_mark_frame_end(uint32_t seg)
{
    board_mark_done = seg + 1u;
}

/* ---- the link ------------------------------------------------------------ */
static fl_decoder dec;
/* one reassembled message (the decoder's work for a page-flipping receiver) */
static uint8_t msg_work[FL_DEC_PAGES_WORK_BYTES] __attribute__((aligned(4)));

/* What a shown frame leaves for the main loop to log (outside the marked span). */
static struct {
    uint8_t pending;
    fl_event ev;
} shown;

static void back_put(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)ctx;
    uart_write(p, n);
}

static void on_event(void *ctx, const fl_event *ev)
{
    (void)ctx;
    if (ev->kind == FL_EV_FRAME) {
        mps2_display_start = dec.frame == mps2_vram1 ? 1u : 0u;
        shown.ev = *ev;
        shown.pending = 1;
    } else if (ev->kind == FL_EV_PALETTE) {
        for (uint32_t i = 0; i < FL_PALETTE_BYTES; i++) mps2_palette[i] = ev->palette[i];
    }
}

static void log_frame(const fl_event *ev, uint32_t seg)
{
    const fl_frame_info *in = &ev->info;
    /* the sender's CRC-32, which the decoder checked the page against, or the page's own */
    uint32_t crc = in->no_crc ? crc_update(0, dec.frame, FL_FRAME_BYTES) : in->crc;
    log_printf("board: frame %u crc32 0x%08x shown page %u camera %d %d %d %d look %d mode %u present %u key %u "
               "seg %u time %u\n",
               (unsigned)ev->frame_no, (unsigned)crc, (unsigned)mps2_display_start, (int)in->x, (int)in->y, (int)in->z,
               (int)in->angle, (int)in->look, (unsigned)in->mode, (unsigned)in->present, (unsigned)ev->keyframe,
               (unsigned)seg, (unsigned)in->time_ms);
}

static void log_counters(const char *what)
{
    const fl_counters *c = &dec.count;
    uint32_t stack = (uint32_t)((uintptr_t)__stack_top - (uintptr_t)__stack_limit);
    log_printf("board: %s: %u frames shown, %u dropped, %u missed, %u bad messages, %u resyncs, "
               "%u keyframe requests, %u acks, %u bytes, %u UART overruns; stack used %u of %u bytes\n",
               what, (unsigned)c->frames_shown, (unsigned)c->frames_dropped, (unsigned)c->frames_missed,
               (unsigned)c->msgs_bad, (unsigned)c->resyncs, (unsigned)c->keyreqs_sent, (unsigned)c->acks_sent,
               (unsigned)c->bytes, (unsigned)uart_rx_overruns(), (unsigned)(stack - mps2_stack_unused()),
               (unsigned)stack);
}

int main(void)
{
    static char cmdline[256], err[96];
    board_args args;

    log_set_sinks(LOG_TO_SEMIHOST); /* UART0 carries the link only */
    if (sh_get_cmdline(cmdline, sizeof cmdline) != 0) cmdline[0] = '\0';
    if (board_args_parse(&args, cmdline, err, sizeof err) != 0) {
        log_printf("board: %s\n", err);
        return BOARD_EXIT_ARGS;
    }
    mps2_display_start = 0;
    fl_dec_init_pages(&dec, mps2_vram0, mps2_vram1, msg_work, on_event, 0, back_put, 0);
    dec.want_crc = 0; /* a frame's CRC-32 only when the sender sent one to check; the log computes its own */
    uart_init();
    log_printf("board: mps2-an385 display board; frame link on UART0; pages 0x%08x 0x%08x, display start 0x%08x; "
               "%s\n",
               (unsigned)(uintptr_t)mps2_vram0, (unsigned)(uintptr_t)mps2_vram1,
               (unsigned)(uintptr_t)&mps2_display_start, args.frames ? "showing a set number of frames" : "running");

    uint32_t seg = 0;
    int in_seg = 0;
    for (;;) {
        uart_rx_wait();
        const uint8_t *p;
        uint32_t n;
        int end;
        /* what has come, a contiguous span of the ring at a time, each up to a
         * message's delimiter at most */
        while ((n = uart_rx_span(&p, &end)) != 0) {
            if (!in_seg) {
                if (end && n == 1) { /* an empty segment: nothing to mark */
                    uart_rx_done(n);
                    continue;
                }
                fw_mark_frame_begin(seg);
                in_seg = 1;
            }
            fl_dec_feed(&dec, p, n);
            uart_rx_done(n);
            if (!end) continue;
            fw_mark_frame_end(seg);
            in_seg = 0;
            if (shown.pending) {
                shown.pending = 0;
                uint32_t k = dec.count.frames_shown;
                if (args.log_frames)
                    log_frame(&shown.ev, seg);
                else if (k % BOARD_LOG_EVERY == 0)
                    log_counters("so far");
                if (args.frames && k >= args.frames) goto done;
            }
            seg++;
        }
    }
done:
    log_counters("done");
    for (;;) __asm__ volatile("wfi"); /* the pages stay readable (QMP pmemsave) */
}
