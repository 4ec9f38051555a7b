/* main.c - the Cortex-M3 firmware's hooks into the shared main loop (hal/mps2,
 * hal/bare/bare_main.h).
 *
 * The work area is the one the build sized for the scene. Each frame's engine
 * step runs between the two frame markers the instruction-counting plugin
 * watches (tools/qemu_plugin/insn_count.c), and the shown page is streamed
 * over UART0. After the last frame, main returns: startup.c exits through
 * semihosting with main's return value as QEMU's exit status.
 *
 * Exit status: 0 done; 2 the built-in scene is invalid; 3 a fault (startup.c);
 * 4 the scene needs more work memory than the build has; 5 bad run-time
 * options (args.h); 6 the frame link failed.
 *
 * The build (mk/mps2.mk) generates the scene file: the compiled scene blob
 * (read in place from flash), its name, the camera path's name and the work
 * area (section .work in RAM, hal/mps2/mps2.ld) sized for the scene by a
 * sizing image of this firmware.
 */
#include <stdint.h>

#include "bare_main.h"
#include "crc32.h"
#include "hal.h"
#include "hal_mps2.h"
#include "log.h"
#include "mps2.h"
#include "semihost.h"
#include "stream.h"
#include "tick.h"

#define FW_EXIT_LINK 6

/* ---- the work area, from the generated scene file (mk/mps2.mk) ----------- */
extern uint8_t fw_work[];
extern const uint32_t fw_work_bytes;

/* ---- frame markers for the instruction counter ---------------------------
 * Called right before and right after each frame's engine step. noipa keeps
 * the calls (the compiler may not see that they do nothing) and the two
 * bodies differ so they are never folded into one address. The plugin is
 * given their addresses (arm-none-eabi-nm). */
volatile uint32_t fw_mark_frame, fw_mark_done;

__attribute__((noinline, noipa, used)) void fw_mark_frame_begin(uint32_t frame)
{
    fw_mark_frame = frame;
}

__attribute__((noinline, noipa, used)) void fw_mark_frame_end(uint32_t frame)
{
    fw_mark_done = frame + 1u;
}

static void mps2_options(const fw_args *a)
{
    if (a->no_tick) tick_stop();
}

static void mps2_fault(void)
{
    __asm__ volatile("udf #0");
}

static bare_work mps2_work(uint32_t need)
{
    (void)need;
    return (bare_work){fw_work, fw_work_bytes, fw_work_bytes};
}

/* mk/mps2.mk's sizing image reads "needs N bytes of work memory" from this line. */
static void mps2_work_refused(uint32_t need, uint32_t avail)
{
    log_printf("firmware: the scene %s needs %u bytes of work memory; this build has %u "
               "(rebuild with make firmware SCENE=...)\n",
               fw_scene_name, (unsigned)need, (unsigned)avail);
}

static stream_acks acks_of(int a)
{
    return a == ARGS_ACKS_ON ? STREAM_ACKS_ON : a == ARGS_ACKS_OFF ? STREAM_ACKS_OFF : STREAM_ACKS_AUTO;
}

static int mps2_start(const bare_run *r)
{
    const fw_args *a = &r->args;
    mps2_set_path(r->fixed_view ? 0 : r->path);
    /* the ack timeout runs on the tick: without it a silent receiver would stall the firmware */
    stream_set_acks(a->no_tick ? STREAM_ACKS_OFF : acks_of(a->acks));
    /* Once a frame-link stream is on the UART, text goes to the semihosting
     * console only: text between its messages would cost the receiver a bad
     * message. Errors before that point go to both. */
    if (!a->no_stream && !stream_text_ok()) log_set_sinks(LOG_TO_SEMIHOST);
    /* the blob's CRC names exactly what was built in: the hello carries it, a capture checks it */
    uint32_t scene_crc = crc_update(0, fw_scene, fw_scene_len);
    log_printf("firmware: mps2-an385 Cortex-M3; scene %s (%u bytes, CRC-32 %08x, work %u of %u bytes, world state %u); "
               "%s %u frames; mode %s, present %s; stream %s\n",
               fw_scene_name, (unsigned)fw_scene_len, (unsigned)scene_crc, (unsigned)r->need, (unsigned)r->avail,
               (unsigned)obj_state_bytes(&r->e.sc), r->fixed_view ? "fixed view," : r->path->name, (unsigned)r->frames,
               render_mode_name(r->e.mode), hal_present_name(r->e.present), a->no_stream ? "off" : stream_kind());
    if (!a->no_stream && stream_begin(&r->e, fw_scene_name, scene_crc) != 0) {
        log_printf("firmware: the frame link did not start\n");
        return FW_EXIT_LINK;
    }
    return 0;
}

static int mps2_frame_out(const bare_run *r, uint32_t f)
{
    if (!r->args.no_stream && stream_frame(&r->e, f) != 0) {
        log_printf("firmware: the frame link failed at frame %u\n", (unsigned)f);
        return FW_EXIT_LINK;
    }
    return 0;
}

static int mps2_finish(const bare_run *r)
{
    const fw_args *a = &r->args;
    if (!a->no_stream) {
        stream_end(r->frames);
        if (stream_summary()[0]) log_printf("firmware: %s\n", stream_summary());
    }
    uint32_t ms = hal_ticks_ms() - r->t0;
    /* QEMU discards what a pty's reader has not read yet when it exits: give the
     * reader time to drain the stream (needs the tick). */
    if (a->linger_ms > 0 && !a->no_tick)
        for (uint32_t start = hal_ticks_ms(); hal_ticks_ms() - start < (uint32_t)a->linger_ms;) {
        }
    uint32_t stack = (uint32_t)((uintptr_t)__stack_top - (uintptr_t)__stack_limit), unused = mps2_stack_unused();
    log_printf("firmware: done, %u frames in %u ms (SysTick); stack used %u of %u bytes%s\n", (unsigned)r->frames,
               (unsigned)ms, (unsigned)(stack - unused), (unsigned)stack,
               unused ? "" : " (all of it: it may have overflowed; rebuild with a larger STACK_BYTES)");
    return BARE_EXIT_OK;
}

static const bare_target mps2_target = {
    .name = "firmware",
    .offered = ARGS_STREAM | ARGS_NO_TICK,
    .log = log_printf,
    .options = mps2_options,
    .fault = mps2_fault,
    .work = mps2_work,
    .work_refused = mps2_work_refused,
    .start = mps2_start,
    .frame_begin = fw_mark_frame_begin,
    .frame_end = fw_mark_frame_end,
    .frame_out = mps2_frame_out,
    .finish = mps2_finish,
};

int main(void)
{
    static char cmdline[256];
    mps2_board_init();
    if (sh_get_cmdline(cmdline, sizeof cmdline) != 0) cmdline[0] = '\0';
    return bare_main(&mps2_target, cmdline);
}
