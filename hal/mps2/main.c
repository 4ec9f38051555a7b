/* main.c - the Cortex-M3 firmware's main loop (hal/mps2).
 *
 * Validate the built-in scene, hand the engine the work area the build sized
 * for it, then for each frame of the scripted camera path: step the engine
 * between the two frame markers the instruction-counting plugin watches
 * (tools/qemu_plugin/insn_count.c), and stream the shown page over UART0.
 * After the last frame, return 0: startup.c exits through semihosting with
 * main's return value as QEMU's exit status.
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

#include "args.h"
#include "campath.h"
#include "crc32.h"
#include "engine.h"
#include "fixed_view.h"
#include "hal.h"
#include "hal_mps2.h"
#include "log.h"
#include "mps2.h"
#include "scene_refusal.h"
#include "semihost.h"
#include "stream.h"
#include "tick.h"

#define FW_EXIT_OK 0
#define FW_EXIT_SCENE 2
#define FW_EXIT_WORK 4
#define FW_EXIT_ARGS 5
#define FW_EXIT_LINK 6

/* ---- from the generated scene file (mk/mps2.mk) ------------------------- */
extern const uint8_t fw_scene[];
extern const uint32_t fw_scene_len;
extern const char fw_scene_name[];
extern const char fw_campath_name[];
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

static stream_acks acks_of(int a)
{
    return a == ARGS_ACKS_ON ? STREAM_ACKS_ON : a == ARGS_ACKS_OFF ? STREAM_ACKS_OFF : STREAM_ACKS_AUTO;
}

int main(void)
{
    static engine e;
    static char cmdline[256], err[128];
    static fw_args args;

    mps2_board_init();
    if (sh_get_cmdline(cmdline, sizeof cmdline) != 0) cmdline[0] = '\0';
    if (args_parse(&args, cmdline, ARGS_STREAM | ARGS_NO_TICK, err, sizeof err) != 0) {
        log_printf("firmware: %s\n", err);
        return FW_EXIT_ARGS;
    }
    const campath *path = campath_find(args.path ? args.path : fw_campath_name);
    if (!path) {
        log_printf("firmware: no camera path named '%s' (default, map01)\n", args.path ? args.path : fw_campath_name);
        return FW_EXIT_ARGS;
    }
    if (args.no_tick) tick_stop();
    if (args.fault) __asm__ volatile("udf #0");
    int fixed_view = fixed_view_wanted(&args);

    scene_error se;
    scene_status st = eng_init(&e, fw_scene, fw_scene_len, &se);
    if (st != SCENE_OK) {
        static char why[240]; /* with the prefix, within a log line (256) */
        scene_refusal_format(why, sizeof why, fw_scene_name, st, &se);
        log_printf("firmware: %s\n", why);
        return FW_EXIT_SCENE;
    }
    uint32_t need = eng_work_bytes(&e);
    if (eng_set_work(&e, fw_work, fw_work_bytes) != 0) {
        log_printf("firmware: the scene %s needs %u bytes of work memory; this build has %u "
                   "(rebuild with make firmware SCENE=...)\n",
                   fw_scene_name, (unsigned)need, (unsigned)fw_work_bytes);
        return FW_EXIT_WORK;
    }
    if (args.mode >= 0) e.mode = (render_mode)args.mode;
    e.flat = (uint8_t)args.flat;
    if (args.present >= 0) e.present = (hal_present_mode)args.present;
    if (fixed_view) fixed_view_apply(&e, &args);

    uint32_t frames = args.frames >= 0 ? (uint32_t)args.frames : campath_frames(path);
    mps2_set_path(fixed_view ? 0 : path);
    /* the ack timeout runs on the tick: without it a silent receiver would stall the firmware */
    stream_set_acks(args.no_tick ? STREAM_ACKS_OFF : acks_of(args.acks));
    /* Once a frame-link stream is on the UART, text goes to the semihosting
     * console only: text between its messages would cost the receiver a bad
     * message. Errors before that point go to both. */
    if (!args.no_stream && !stream_text_ok()) log_set_sinks(LOG_TO_SEMIHOST);
    /* the blob's CRC names exactly what was built in: the hello carries it, a capture checks it */
    uint32_t scene_crc = crc_update(0, fw_scene, fw_scene_len);
    log_printf("firmware: mps2-an385 Cortex-M3; scene %s (%u bytes, CRC-32 %08x, work %u of %u bytes, world state %u); "
               "%s %u frames; mode %s, present %s; stream %s\n",
               fw_scene_name, (unsigned)fw_scene_len, (unsigned)scene_crc, (unsigned)need, (unsigned)fw_work_bytes,
               (unsigned)obj_state_bytes(&e.sc),
               fixed_view ? "fixed view," : path->name, (unsigned)frames, render_mode_name(e.mode),
               hal_present_name(e.present), args.no_stream ? "off" : stream_kind());

    if (!args.no_stream && stream_begin(&e, fw_scene_name, scene_crc) != 0) {
        log_printf("firmware: the frame link did not start\n");
        return FW_EXIT_LINK;
    }
    uint32_t t0 = hal_ticks_ms();
    for (uint32_t f = 0; f < frames; f++) {
        uint32_t input = hal_input();
        fw_mark_frame_begin(f);
        if (fixed_view) {
            eng_render(&e, 0);
            hal_frame_done();
        } else {
            eng_step(&e, input, campath_dt_ms(f));
        }
        fw_mark_frame_end(f);
        if (!args.no_stream && stream_frame(&e, f) != 0) {
            log_printf("firmware: the frame link failed at frame %u\n", (unsigned)f);
            return FW_EXIT_LINK;
        }
    }
    if (!args.no_stream) {
        stream_end(frames);
        if (stream_summary()[0]) log_printf("firmware: %s\n", stream_summary());
    }
    uint32_t ms = hal_ticks_ms() - t0;
    /* QEMU discards what a pty's reader has not read yet when it exits: give the
     * reader time to drain the stream (needs the tick). */
    if (args.linger_ms > 0 && !args.no_tick)
        for (uint32_t start = hal_ticks_ms(); hal_ticks_ms() - start < (uint32_t)args.linger_ms;) {
        }
    uint32_t stack = (uint32_t)((uintptr_t)__stack_top - (uintptr_t)__stack_limit), unused = mps2_stack_unused();
    log_printf("firmware: done, %u frames in %u ms (SysTick); stack used %u of %u bytes%s\n", (unsigned)frames,
               (unsigned)ms, (unsigned)(stack - unused), (unsigned)stack,
               unused ? "" : " (all of it: it may have overflowed; rebuild with a larger STACK_BYTES)");
    return FW_EXIT_OK;
}
