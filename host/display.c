/* display.c - build/display: the display board. Reads the frame link from a
 * serial port (a tty, a pty, a TCP socket, or a captured stream file), decodes
 * it with the one C decoder (hal/serial), answers with acks and keyframe
 * requests, and shows each frame that passed every check in an SDL window or
 * writes it as a PNG file. Prints what it received. */
#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "framelink.h"
#include "hal.h"
#include "hal_sdl.h"
#include "png.h"
#include "port.h"

static const char usage[] =
    "usage: display PORT [--png DIR] [--frames N] [--idle-timeout S] [--baud B] [--window] [--json]\n"
    "\n"
    "Receive the frame link (docs/frame-link.md) on PORT and show its frames.\n"
    "PORT is a serial device or pty (/dev/ttyUSB0, /dev/pts/3: set raw at --baud), a TCP\n"
    "socket (socket://127.0.0.1:5555), a file holding a captured stream, or - (stdin).\n"
    "Acks and keyframe requests go back on the same port (not to files or stdin).\n"
    "\n"
    "  --png DIR          write each frame shown as DIR/frame_NNNNN.png (frame number)\n"
    "  --window           show the frames in an SDL window (the default without --png;\n"
    "                     Esc or closing the window stops)\n"
    "  --frames N         stop after N frames shown (default: until the stream ends)\n"
    "  --idle-timeout S   stop when nothing arrives for S seconds (default 10)\n"
    "  --baud B           serial speed for a tty (default 115200)\n"
    "  --json             print the final counters and the scene the sender named (scene,\n"
    "                     scene_crc32: its compiled blob's CRC-32) as one JSON object on stdout\n"
    "  -h, --help         this text\n"
    "\n"
    "A frame is shown only if its message passed its CRC and its rebuilt pixels match\n"
    "the CRC-32 the sender put in it; damaged frames are counted and dropped. Frames\n"
    "that arrive before any palette are not shown (counted; the palette is asked for).\n"
    "Exits 1 when the input ended or went quiet without a frame shown and it held no\n"
    "frame-link message, bad messages, or frames without a palette; and when a --png\n"
    "file cannot be written (DIR is checked before anything is received).\n";

typedef struct {
    int fd;
    int writable; /* acks can go back */
    const char *png_dir;
    int window;
    long max_frames;
    uint64_t frame_bytes; /* wire bytes of the frame messages shown (approx: bytes between frames) */
    uint64_t bytes_at_last;
    long shown;
    long no_palette; /* frames that passed every check but came before any palette */
    int have_palette;
    uint8_t palette[HAL_PALETTE_BYTES];
    int quit;
    int write_failed; /* a --png file could not be written: the run ends and fails */
    fl_decoder dec;
} board;

static void put_back(void *ctx, const uint8_t *p, uint32_t n)
{
    board *b = ctx;
    if (!b->writable) return;
    while (n > 0) {
        ssize_t w = write(b->fd, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return; /* the sender went away: nothing to tell it */
        p += w;
        n -= (uint32_t)w;
    }
}

/* A board that has never been given a palette has nothing true to show: its
 * DAC holds no colours of the sender's. It keeps the pixels out of sight until
 * a palette arrives (the decoder asks the sender for one) rather than show
 * them in made-up colours. */
static int palette_missing(board *b, const fl_event *ev)
{
    if (b->have_palette) return 0;
    if (b->no_palette++ == 0)
        fprintf(stderr,
                "display: frame %u arrived before any palette: frames are not shown until a palette "
                "arrives\n",
                (unsigned)ev->frame_no);
    return 1;
}

/* The frame as DIR/frame_NNNNN.png; 0, or -1 after saying why. */
static int write_png(const board *b, const fl_event *ev)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/frame_%05u.png", b->png_dir, (unsigned)ev->frame_no);
    if (png_write_indexed(path, b->dec.frame, FL_W, FL_H, b->palette) == 0) return 0;
    fprintf(stderr, "display: %s: cannot write: %s; stopping\n", path, strerror(errno));
    return -1;
}

static void show_frame(board *b, const fl_event *ev)
{
    if (b->write_failed || palette_missing(b, ev)) return;
    /* a frame asked for as a file and lost is not shown: the run stops and fails */
    if (b->png_dir && write_png(b, ev) != 0) {
        b->write_failed = 1;
        b->quit = 1;
        return;
    }
    b->shown++;
    b->frame_bytes += b->dec.count.bytes - b->bytes_at_last;
    b->bytes_at_last = b->dec.count.bytes;
    if (b->window) {
        hal_set_palette(b->palette);
        uint8_t *page = hal_target_vram(0);
        for (int i = 0; i < FL_FRAME_BYTES; i++) page[i] = b->dec.frame[i];
        hal_target_set_display_start(0);
        hal_frame_done();
        if (hal_input() & HAL_KEY_QUIT) b->quit = 1;
    }
    if (b->max_frames > 0 && b->shown >= b->max_frames) b->quit = 1;
}

static void on_event(void *ctx, const fl_event *ev)
{
    board *b = ctx;
    switch (ev->kind) {
    case FL_EV_PALETTE:
        memcpy(b->palette, ev->palette, sizeof b->palette);
        b->have_palette = 1;
        break;
    case FL_EV_FRAME: show_frame(b, ev); break;
    case FL_EV_HELLO:
        if (ev->hello.scene_name[0])
            fprintf(stderr, "display: the sender draws scene %s (blob CRC-32 %08x)\n", ev->hello.scene_name,
                    (unsigned)ev->hello.scene_crc);
        break;
    default: break;
    }
}

/* s as a JSON string's contents (the decoder let only printable ASCII through). */
static void json_chars(const char *s)
{
    for (; *s; s++) printf(*s == '"' || *s == '\\' ? "\\%c" : "%c", *s);
}

static void print_summary(const board *b, int json)
{
    const fl_counters *c = &b->dec.count;
    const fl_hello *h = &b->dec.hello; /* the last HELLO's ("", 0 when none came or it named no scene) */
    unsigned long per_frame = b->shown ? (unsigned long)(b->frame_bytes / (uint64_t)b->shown) : 0;
    if (json) {
        printf("{\"frames_shown\": %ld, \"frames_no_palette\": %ld, \"frames_dropped\": %u, "
               "\"frames_missed\": %u, \"msgs_ok\": %u, \"msgs_bad\": %u, \"resyncs\": %u, "
               "\"keyreqs_sent\": %u, \"palreqs_sent\": %u, \"acks_sent\": %u, \"bytes\": %u, "
               "\"bytes_per_frame\": %lu, \"hellos\": %u, \"scene\": \"",
               b->shown, b->no_palette, c->frames_dropped, c->frames_missed, c->msgs_ok, c->msgs_bad, c->resyncs,
               c->keyreqs_sent, c->palreqs_sent, c->acks_sent, c->bytes, per_frame, c->hellos);
        json_chars(h->scene_name);
        printf("\", \"scene_crc32\": \"%08x\"}\n", (unsigned)h->scene_crc);
    } else {
        fprintf(stderr,
                "display: %ld frames shown, %ld not shown for want of a palette, %u bad messages, "
                "%u frames dropped, %u missed, %u resyncs, %u keyframe requests, %u bytes (%lu per frame "
                "shown)\n",
                b->shown, b->no_palette, c->msgs_bad, c->frames_dropped, c->frames_missed, c->resyncs, c->keyreqs_sent,
                c->bytes, per_frame);
        if (h->scene_name[0])
            fprintf(stderr, "display: scene %s, blob CRC-32 %08x\n", h->scene_name, (unsigned)h->scene_crc);
    }
}

/* n with thousands separators, for messages a person reads. */
static const char *grouped(uint32_t n, char *out, size_t len)
{
    char digits[16];
    int nd = snprintf(digits, sizeof digits, "%u", (unsigned)n);
    size_t o = 0;
    for (int i = 0; i < nd && o + 2 < len; i++) {
        if (i > 0 && (nd - i) % 3 == 0) out[o++] = ',';
        out[o++] = digits[i];
    }
    out[o] = '\0';
    return out;
}

/* Exit status of a session: 1 when nothing was shown and the input gave a
 * reason to doubt it was a frame link at all (no good message, bad ones, or
 * frames without a palette); a clean stream that carried no frame is no fault. */
static int verdict(const board *b, const char *port)
{
    const fl_counters *c = &b->dec.count;
    const char *name = strcmp(port, "-") ? port : "stdin";
    char nbytes[32];
    grouped(c->bytes, nbytes, sizeof nbytes);
    if (b->write_failed) return 1; /* said when it happened */
    if (b->shown > 0) return 0;
    if (c->msgs_ok == 0) {
        fprintf(stderr, "display: %s: no frame-link message in %s bytes (%u bad messages)\n", name, nbytes,
                c->msgs_bad);
        return 1;
    }
    if (b->no_palette > 0) {
        fprintf(stderr, "display: %s: %ld frames but no palette in %s bytes: nothing shown\n", name, b->no_palette,
                nbytes);
        return 1;
    }
    if (c->msgs_bad > 0 || c->frames_dropped > 0) {
        fprintf(stderr, "display: %s: no frame shown: %u good and %u bad messages, %u frames dropped, in %s bytes\n",
                name, c->msgs_ok, c->msgs_bad, c->frames_dropped, nbytes);
        return 1;
    }
    return 0;
}

/* --png DIR, made if missing: a folder this program can write into, found
 * before the link opens, not after each frame has failed to be written. */
static int png_dir_ready(const char *dir)
{
    struct stat st;
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "display: --png %s: cannot create: %s\n", dir, strerror(errno));
        return -1;
    }
    if (stat(dir, &st) != 0) { /* a dangling symbolic link, say */
        fprintf(stderr, "display: --png %s: cannot use: %s\n", dir, strerror(errno));
        return -1;
    }
    if (!S_ISDIR(st.st_mode)) {
        fprintf(stderr, "display: --png %s: exists and is not a directory\n", dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK) != 0) {
        fprintf(stderr, "display: --png %s: cannot write into it: %s\n", dir, strerror(errno));
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    static board b;
    static uint8_t frame[FL_FRAME_BYTES], work[FL_DEC_WORK_BYTES];
    const char *port = NULL;
    long idle_s = 10, baud = PORT_DEFAULT_BAUD;
    int json = 0, want_window = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(a, "--json")) {
            json = 1;
        } else if (!strcmp(a, "--window")) {
            want_window = 1;
        } else if (i + 1 < argc && !strcmp(a, "--png")) {
            b.png_dir = argv[++i];
        } else if (i + 1 < argc && !strcmp(a, "--frames")) {
            b.max_frames = atol(argv[++i]);
        } else if (i + 1 < argc && !strcmp(a, "--idle-timeout")) {
            idle_s = atol(argv[++i]);
        } else if (i + 1 < argc && !strcmp(a, "--baud")) {
            baud = atol(argv[++i]);
        } else if (a[0] == '-' && a[1] != '\0') {
            fprintf(stderr, "display: unknown option or missing value: '%s' (see --help)\n", a);
            return 2;
        } else if (!port) {
            port = a;
        } else {
            fprintf(stderr, "display: more than one port given: '%s'\n", a);
            return 2;
        }
    }
    if (!port) {
        fprintf(stderr, "display: no port given (see --help)\n");
        return 2;
    }
    if (b.png_dir && png_dir_ready(b.png_dir) != 0) return 1;
    b.window = want_window || !b.png_dir;
    if (b.window && hal_sdl_init(HAL_SDL_DEFAULT_SCALE, "bspvga display board") != 0) {
        fprintf(stderr, "display: no window: %s%s\n", hal_sdl_error(),
                b.png_dir ? "" : " (use --png DIR to write the frames as files)");
        if (!b.png_dir) return 1;
        b.window = 0;
    }
    char err[512];
    b.fd = port_open(port, baud, &b.writable, err, sizeof err);
    if (b.fd < 0) {
        fprintf(stderr, "display: %s\n", err);
        return 1;
    }
    fl_dec_init(&b.dec, frame, work, on_event, &b, put_back, &b);

    uint8_t buf[4096];
    while (!b.quit) {
        struct pollfd p = {b.fd, POLLIN, 0};
        int r = poll(&p, 1, (int)(idle_s * 1000));
        if (r < 0 && errno == EINTR) continue;
        if (r == 0) {
            fprintf(stderr, "display: nothing received for %ld s; stopping\n", idle_s);
            break;
        }
        ssize_t n = read(b.fd, buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break; /* end of stream (EOF, or EIO when a pty's other end closes) */
        fl_dec_feed(&b.dec, buf, (uint32_t)n);
    }
    print_summary(&b, json);
    if (b.window) hal_sdl_quit();
    if (b.fd > 0) close(b.fd);
    return verdict(&b, port);
}
