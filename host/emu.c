/* emu.c - build/emu: the host-emulated run. The firmware engine on the SDL target:
 * a window scaled up, keyboard input, counters on demand. Without a display it
 * says so and renders a short scripted fly-through to PNG files instead. With
 * --link it also sends its frames over the frame link to a display board,
 * never waiting for it: a frame the link is not ready for is skipped
 * (link_send.h), and the game's clock stays real time. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "engine.h"
#include "fxtext.h"
#include "hal.h"
#include "hal_sdl.h"
#include "fl_engine_info.h"
#include "link_send.h"
#include "png.h"
#include "port.h"
#include "scene_start.h"

extern const uint8_t default_scene[];
extern const uint32_t default_scene_len;
/* the built-in scene's source (the Makefile compiles it into build/default.bsc) */
#define DEFAULT_SCENE_NAME "tests/scenes/default.scene"

static const char usage[] =
    "usage: emu [SCENE] [--scale N] [--frames N] [--headless] [--out DIR] [--flat] [--link PORT]\n"
    "\n"
    "Walk through SCENE (default: the built-in scene) in a window.\n"
    "SCENE is a compiled scene, a text scene, or FILE.wad:MAP (e.g. freedoom2.wad:MAP01).\n"
    "\n"
    "Keys: Up/Down move, Left/Right turn, Alt+Left/Right or ',' '.' strafe,\n"
    "      PgUp/PgDn or A/Z fly, Home/End or Q/W look up/down, Shift run,\n"
    "      M render mode, P present mode (flip, copy8, copy16, copy32),\n"
    "      C print counters, V print the camera as build/render options\n"
    "      (--at X,Y,Z --angle A --look L), S or F12 save a screenshot PNG\n"
    "      (emu-shot-NNN.png in the current folder, or in --out DIR), Esc quit.\n"
    "\n"
    "  --scale N     window size factor, 1..8 (default 3)\n"
    "  --flat        draw a textured scene (a WAD map) in flat colours\n"
    "  --frames N    quit after N frames (default: run until Esc; headless: 36)\n"
    "  --headless    do not open a window: render a fly-through (a turn on the spot)\n"
    "                to PNG files\n"
    "  --out DIR     where the headless fly-through goes (default build/flythrough;\n"
    "                with --link, PNG files only when --out is given)\n"
    "  --link PORT   also send the frames over the frame link (docs/frame-link.md) to\n"
    "                a display board: PORT as build/display takes it, a tty or pty\n"
    "                (set raw at --baud) or socket://HOST:PORT. The game never waits\n"
    "                for the board: a frame drawn while the link is behind is not\n"
    "                sent (skipped). Headless, the fly-through then runs in real time.\n"
    "                The counters gain the link's bytes, frames, keyframes, deltas,\n"
    "                skipped frames and acks\n"
    "  --baud B      serial speed for a tty PORT (default 115200)\n"
    "  -h, --help    this text\n";

_Static_assert(HAL_SDL_MAX_SCALE == 8, "--help names the largest --scale");

#define FLY_FRAMES 36
#define FLY_STEP_MS 83 /* a tenth of a turn per frame at the camera's turn speed */

static link_sender *linked; /* --link: the display board the frames also go to */

static void print_counters(const engine *e)
{
    printf("frame %u mode %s present %s:", e->frame, render_mode_name(e->mode), hal_present_name(e->present));
    for (int ev = 0; ev < HAL_EV_COUNT; ev++)
        printf(" %s=%llu", hal_event_name((hal_event)ev), (unsigned long long)hal_perf_event((hal_event)ev));
    printf(" bus_cycles=%llu", (unsigned long long)hal_perf_tsc());
    if (linked) {
        const fl_encoder *en = &linked->enc;
        printf(" link_bytes=%u link_frames=%u link_keyframes=%u link_deltas=%u link_skipped=%u link_acks=%u "
               "link_timeouts=%u",
               (unsigned)en->bytes, (unsigned)en->frames, (unsigned)en->keyframes, (unsigned)en->deltas,
               (unsigned)linked->skipped, (unsigned)en->acks, (unsigned)en->timeouts);
    }
    printf("\n");
    fflush(stdout);
}

/* One frame: drawn and presented (eng_step), then sent when linked (or
 * skipped: link_frame never waits). 0, or -1 after a message when the link
 * stopped. */
static int step(engine *e, uint32_t input, uint32_t dt_ms)
{
    eng_step(e, input, dt_ms);
    if (!linked) return 0;
    fl_frame_info info = fl_engine_info(e);
    if (link_frame(linked, e->frame - 1u, hal_shown_page(), hal_get_palette(), &info) == 0) return 0;
    fprintf(stderr, "emu: --link %s\n", link_error(linked));
    return -1;
}

/* The frames in flight acknowledged (at most the ack timeout): 0, or 1 after
 * a message when the link had stopped. */
static int finish_link(void)
{
    if (!linked || link_finish(linked) == 0) return 0;
    fprintf(stderr, "emu: --link %s\n", link_error(linked));
    return 1;
}

/* The camera of the last frame as build/render options, into out. */
static void view_options(const engine *e, char *out, size_t n)
{
    char x[48], y[48], z[48], a[48];
    fxtext_format(e->cam.view.x, x, sizeof x);
    fxtext_format(e->cam.view.y, y, sizeof y);
    fxtext_format(e->cam.view.z, z, sizeof z);
    fxtext_format(e->cam.view.angle_deg, a, sizeof a);
    snprintf(out, n, "--at %s,%s,%s --angle %s --look %d", x, y, z, a, (int)e->cam.view.look);
}

/* The camera and time of the last frame, as build/render options. */
static void print_view(const engine *e)
{
    char opts[300];
    view_options(e, opts, sizeof opts);
    printf("emu: frame %u as build/render draws it: %s --time %u\n", e->frame - 1u, opts, (unsigned)e->t_ms);
    fflush(stdout);
}

/* The frame shown, as the next free emu-shot-NNN.png in dir; the camera goes
 * with it on stdout, so build/render can draw the same view. 0, or -1 after a
 * message. */
static int screenshot(const engine *e, const char *dir)
{
    char path[4096];
    for (int i = 0; i < 1000; i++) {
        snprintf(path, sizeof path, "%s/emu-shot-%03d.png", dir, i);
        struct stat st;
        if (stat(path, &st) == 0) continue;
        if (png_write_indexed(path, hal_shown_page(), HAL_WIDTH, HAL_HEIGHT, hal_get_palette()) != 0) {
            fprintf(stderr, "emu: %s: cannot write: %s\n", path, strerror(errno));
            return -1;
        }
        char opts[300];
        view_options(e, opts, sizeof opts);
        printf("emu: wrote %s: %s --time %u\n", path, opts, (unsigned)e->t_ms);
        fflush(stdout);
        return 0;
    }
    fprintf(stderr, "emu: %s: 1000 screenshots there already\n", dir);
    return -1;
}

static int run_window(engine *e, long frames, const char *shots)
{
    uint32_t last = hal_ticks_ms();
    for (long n = 0; frames <= 0 || n < frames; n++) {
        uint32_t input = hal_input();
        if (input & HAL_KEY_QUIT) break;
        uint32_t now = hal_ticks_ms();
        uint32_t dt = now - last;
        last = now;
        if (dt < 1) dt = 1;
        if (dt > 100) dt = 100;
        hal_perf_reset();
        if (step(e, input, dt) != 0) return 1;
        if (input & HAL_KEY_PRINT_COUNTERS) print_counters(e);
        if (input & HAL_KEY_PRINT_VIEW) print_view(e);
        if (input & HAL_KEY_SCREENSHOT) screenshot(e, shots);
    }
    return 0;
}

static uint64_t mono_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000u + (uint64_t)t.tv_nsec / 1000000u;
}

/* Linked, the fly-through keeps to its game clock (a frame every FLY_STEP_MS
 * from start): the board shows it at its speed, as the window would, and a
 * board that keeps up with the game is sent every frame. */
static void wait_for_frame_time(uint64_t start, long i)
{
    uint64_t due = start + (uint64_t)i * FLY_STEP_MS, now = mono_ms();
    if (now >= due) return;
    struct timespec d = {(time_t)((due - now) / 1000u), (long)((due - now) % 1000u) * 1000000L};
    while (nanosleep(&d, &d) != 0 && errno == EINTR) {
    }
}

/* frames of a turn on the spot; to PNG files in dir unless dir is NULL */
static int run_headless(engine *e, const char *dir, long frames)
{
    if (dir && mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "emu: %s: cannot create: %s\n", dir, strerror(errno));
        return 1;
    }
    char path[4096];
    uint64_t start = mono_ms();
    for (long i = 0; i < frames; i++) {
        if (linked) wait_for_frame_time(start, i);
        hal_perf_reset();
        if (step(e, i == 0 ? 0 : HAL_KEY_TURN_LEFT, i == 0 ? 1 : FLY_STEP_MS) != 0) return 1;
        if (!dir) continue;
        snprintf(path, sizeof path, "%s/frame_%03ld.png", dir, i);
        if (png_write_indexed(path, hal_shown_page(), HAL_WIDTH, HAL_HEIGHT, hal_get_palette()) != 0) {
            fprintf(stderr, "emu: %s: cannot write: %s\n", path, strerror(errno));
            return 1;
        }
    }
    if (finish_link() != 0) return 1;
    if (dir)
        printf("emu: wrote %ld frames of a turn around the start to %s/frame_000.png .. frame_%03ld.png\n", frames, dir,
               frames - 1);
    print_counters(e);
    print_view(e);
    return 0;
}

/* A decimal whole number, all of s: 0, or -1. */
static int whole_number(const char *s, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (end == s || *end || errno) return -1;
    *out = v;
    return 0;
}

static int is_option_with_value(const char *a)
{
    return !strcmp(a, "--scale") || !strcmp(a, "--frames") || !strcmp(a, "--out") || !strcmp(a, "--link") ||
           !strcmp(a, "--baud");
}

int main(int argc, char **argv)
{
    const char *spec = NULL, *out = NULL, *port = NULL;
    long frames = 0, baud = PORT_DEFAULT_BAUD;
    int scale = HAL_SDL_DEFAULT_SCALE, headless = 0, flat = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(argv[i], "--flat")) {
            flat = 1;
        } else if (!strcmp(argv[i], "--headless")) {
            headless = 1;
        } else if (i + 1 < argc && !strcmp(argv[i], "--scale")) {
            long v;
            if (whole_number(argv[++i], &v) != 0 || v < 1 || v > HAL_SDL_MAX_SCALE) {
                fprintf(stderr, "emu: --scale '%s': expected a whole number 1..%d\n", argv[i], HAL_SDL_MAX_SCALE);
                return 2;
            }
            scale = (int)v;
        } else if (i + 1 < argc && !strcmp(argv[i], "--frames")) {
            if (whole_number(argv[++i], &frames) != 0 || frames < 1) {
                fprintf(stderr, "emu: --frames '%s': expected a whole number of frames, 1 or more\n", argv[i]);
                return 2;
            }
        } else if (i + 1 < argc && !strcmp(argv[i], "--out")) {
            out = argv[++i];
        } else if (i + 1 < argc && !strcmp(argv[i], "--link")) {
            port = argv[++i];
        } else if (i + 1 < argc && !strcmp(argv[i], "--baud")) {
            char *end;
            baud = strtol(argv[++i], &end, 10);
            if (*end || baud <= 0) {
                fprintf(stderr, "emu: --baud '%s': expected a speed in bits per second\n", argv[i]);
                return 2;
            }
        } else if (is_option_with_value(argv[i])) {
            fprintf(stderr, "emu: option %s needs a value\n", argv[i]);
            return 2;
        } else if (argv[i][0] == '-') {
            fprintf(stderr, "emu: unknown option '%s' (see --help)\n", argv[i]);
            return 2;
        } else if (!spec) {
            spec = argv[i];
        } else {
            fprintf(stderr, "emu: more than one scene given: '%s'\n", argv[i]);
            return 2;
        }
    }

    char err[512];
    /* the port first: a PORT that does not open is a bad option, found before any work */
    static link_sender the_link;
    if (port) {
        if (link_open(&the_link, port, baud, err, sizeof err) != 0) {
            fprintf(stderr, "emu: --link %s\n", err);
            return 2;
        }
        linked = &the_link;
    }
    static engine e;
    scene_start st;
    bspc_options opt = bspc_defaults();
    if (scene_start_load(&st, &e, spec, &opt, default_scene, default_scene_len, err, sizeof err) != 0) {
        fprintf(stderr, "emu: %s\n", err);
        return 1;
    }
    e.flat = (uint8_t)flat;

    int rc = 0;
    if (linked && link_hello(linked, spec ? spec : DEFAULT_SCENE_NAME, st.data, st.len) != 0) {
        fprintf(stderr, "emu: --link %s\n", link_error(linked));
        rc = 1;
    } else if (!headless && hal_sdl_init(scale, "bspvga") == 0) {
        rc = run_window(&e, frames, out ? out : ".");
        if (rc == 0) rc = finish_link();
        hal_sdl_quit();
    } else {
        if (!headless) fprintf(stderr, "emu: %s; rendering a fly-through headless instead\n", hal_sdl_error());
        if (!out && !linked) out = "build/flythrough";
        rc = run_headless(&e, out, frames > 0 ? frames : FLY_FRAMES);
    }
    if (linked) {
        link_print_summary(linked, stdout);
        link_close(linked);
    }
    scene_start_close(&st);
    return rc;
}
