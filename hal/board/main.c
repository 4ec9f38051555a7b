/* main.c - the display board (hal/board): a Cortex-M3 that receives the frame
 * link (hal/serial) on UART0 and shows each frame that passes the decoder's
 * checks by flipping its display start to the page the frame was rebuilt in.
 *
 * The decoder rebuilds a frame straight into the hidden VRAM page (a keyframe
 * from scratch, a delta onto the shown page), checks it (message CRC, frame
 * check, pixel CRC-32 when sent), and only then is the page flipped: a frame
 * that fails any check is never shown. Acks and keyframe requests go back on
 * UART0's transmitter. Each frame shown is logged on semihosting, one line:
 *   board: frame N crc32 0xC shown page P camera X Y Z ANGLE look L mode M present Q key K seg S
 * (camera in raw 16.16, as the frame info carries it; seg: the message's
 * number among the segments marked for the instruction counter).
 *
 * Options (semihosting command line, board_args.h): --frames N: after N frames
 * shown, log a summary line and idle (WFI) for ever, so that a debugger or QMP
 * can still read the pages; without it, run until QEMU is stopped.
 *
 * Memory: the two pages, palette and display-start register (.display,
 * hal/mps2/mps2.ld) and one message buffer; no 64,000-byte copy per frame.
 */
#include <stdint.h>

#include "board_args.h"
#include "framelink.h"
#include "log.h"
#include "mps2.h"
#include "semihost.h"
#include "uart.h"

#define BOARD_EXIT_ARGS 5

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
    log_printf("board: frame %u crc32 0x%08x shown page %u camera %d %d %d %d look %d mode %u present %u key %u "
               "seg %u\n",
               (unsigned)ev->frame_no, (unsigned)in->crc, (unsigned)mps2_display_start, (int)in->x, (int)in->y,
               (int)in->z, (int)in->angle, (int)in->look, (unsigned)in->mode, (unsigned)in->present,
               (unsigned)ev->keyframe, (unsigned)seg);
}

static void log_summary(void)
{
    const fl_counters *c = &dec.count;
    uint32_t stack = (uint32_t)((uintptr_t)__stack_top - (uintptr_t)__stack_limit);
    log_printf("board: done: %u frames shown, %u dropped, %u missed, %u bad messages, %u resyncs, "
               "%u keyframe requests, %u acks, %u bytes, %u UART overruns; stack used %u of %u bytes\n",
               (unsigned)c->frames_shown, (unsigned)c->frames_dropped, (unsigned)c->frames_missed,
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
    uart_init();
    log_printf("board: mps2-an385 display board; frame link on UART0; pages 0x%08x 0x%08x, display start 0x%08x; "
               "%s\n",
               (unsigned)(uintptr_t)mps2_vram0, (unsigned)(uintptr_t)mps2_vram1,
               (unsigned)(uintptr_t)&mps2_display_start, args.frames ? "showing a set number of frames" : "running");

    uint32_t seg = 0;
    int in_seg = 0;
    for (;;) {
        uint8_t buf[64];
        uint32_t n = 0;
        int c, end = 0;
        /* a chunk of what has arrived, up to a message's delimiter */
        while (n < sizeof buf && (c = uart_getc()) >= 0) {
            buf[n++] = (uint8_t)c;
            if (c == 0) {
                end = 1;
                break;
            }
        }
        if (n == 0) {
            /* sleep until a byte comes; with interrupts masked across the check, one
             * that arrives just before the WFI still wakes it */
            __asm__ volatile("cpsid i" ::: "memory");
            if (!uart_rx_ready()) __asm__ volatile("wfi");
            __asm__ volatile("cpsie i" ::: "memory");
            continue;
        }
        if (!in_seg) {
            if (end && n == 1) continue; /* an empty segment: nothing to mark */
            fw_mark_frame_begin(seg);
            in_seg = 1;
        }
        fl_dec_feed(&dec, buf, n);
        if (!end) continue;
        fw_mark_frame_end(seg);
        in_seg = 0;
        if (shown.pending) {
            shown.pending = 0;
            log_frame(&shown.ev, seg);
            if (args.frames && dec.count.frames_shown >= args.frames) break;
        }
        seg++;
    }
    log_summary();
    for (;;) __asm__ volatile("wfi"); /* the pages stay readable (QMP pmemsave) */
}
