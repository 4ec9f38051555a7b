/* args.h - run-time options of the bare-metal firmwares (prefix args_), read
 * from the command line their boot gives them: hal/mps2's semihosting command
 * line, hal/pcvga's multiboot command line (QEMU: -append "OPTIONS" for both).
 * The first word is the program's name and is skipped. Options (same spelling
 * and rounding as build/render); those marked with a feature exist only on the
 * targets that offer it (args_parse's offered), elsewhere they are refused:
 *
 *   --frames N          render N frames (default: the camera path's length)
 *   --path NAME         the camera path: default or map01 (default: the build's)
 *   --at X,Y[,Z]        a fixed view instead of a path: the eye at X,Y (decimals
 *                       rounded to 16.16, ties away from zero); Z absolute, or by
 *                       default the floor under the eye + 41. Each frame is then
 *                       rendered from the same camera (eng_render, no movement).
 *   --angle DEG         the fixed view's angle (default: the player start's)
 *   --look PX           the fixed view's vertical look, pixels
 *   --mode spans|painter, --present flip|copy8|copy16|copy32
 *   --no-objects        a fixed view (at the player start unless --at) of the
 *                       world alone, as build/render --no-objects draws it
 *   --flat              draw a textured scene in its flat colours (build/render --flat)
 *   --linger MS         wait MS ms after the last frame before exiting
 *   --fault             (tests) cause a processor fault after start-up, to show
 *                       the fault handler's report and exit status
 *   --no-stream         [ARGS_STREAM] render without sending frames (for
 *                       instruction counts)
 *   --acks auto|on|off  [ARGS_STREAM] frame-link flow control (default auto)
 *   --wait              [ARGS_WAIT] after the last frame, wait for a byte from
 *                       the serial port before exiting (so a test can take the
 *                       screen first)
 *   --no-tick [ARGS_NO_TICK]          stop the SysTick (no tick interrupts: instruction counts
 *                       of identical frames are then identical; hal_ticks_ms stays 0;
 *                       frame-link flow control is off, as its timeout needs the tick)
 */
#ifndef BARE_ARGS_H
#define BARE_ARGS_H

#include <stdint.h>

typedef struct {
    int32_t frames;    /* -1: the path's length */
    int32_t linger_ms; /* wait this long after the last frame before exiting (0) */
    const char *path;  /* NULL: the build's */
    int have_at, have_z, have_angle;
    int32_t x, y, z, angle_deg; /* 16.16 */
    int32_t look;
    int mode, present; /* -1: the engine's defaults */
    int no_stream, no_tick, fault, wait, no_objects, flat;
    int acks; /* ARGS_ACKS_* */
} fw_args;

/* Options only some targets have: args_parse's offered. */
#define ARGS_STREAM 1u  /* --no-stream, --acks: a frame stream */
#define ARGS_NO_TICK 2u /* --no-tick: a tick that can be stopped */
#define ARGS_WAIT 4u    /* --wait: a serial port to wait on */

enum { ARGS_ACKS_AUTO, ARGS_ACKS_ON, ARGS_ACKS_OFF };

/* Parse line (modified in place: words are NUL-terminated where they stand);
 * offered: the ARGS_* features this target has. Returns 0, or -1 with a message
 * in err. */
int args_parse(fw_args *a, char *line, unsigned offered, char *err, int errsize);

/* Decimal text to 16.16, exactly as the host tools round (tools/bspc/fxtext.c).
 * Returns 0, or -1 if malformed or out of range. */
int args_parse_fx(const char *s, int32_t *out);

#endif
