/* link_send.h - the host's frame-link present (prefix link_): build/emu --link
 * and build/render --link send the frames they draw to a display board over a
 * tty, a pty or a TCP socket (port.h), as the firmware does over its UART
 * (hal/mps2/stream_fl.c): hello, palette, then keyframes and deltas against the
 * frame sent before; acks and keyframe requests read back without blocking and
 * fed to the encoder; a full ack window waited out on the port, at most the
 * encoder's ack timeout.
 *
 * A receiver that goes away (closed socket, closed pty, EPIPE) or takes no
 * bytes for LINK_STALL_MS stops the link with a message naming the port; no
 * call blocks longer than that, and no SIGPIPE is raised. Knows nothing of the
 * engine: the caller fills the frame's camera and modes (fl_engine_info.h). */
#ifndef LINK_SEND_H
#define LINK_SEND_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "framelink.h"

/* One coded frame message: a textured frame's coding can pass 8 KB (the
 * firmware's scratch) and even 64 KB (tools/bench_link.py); with more room
 * than a raw frame message no frame falls back to raw. */
#define LINK_SCRATCH_BYTES 70000
#define LINK_STALL_MS 10000 /* a receiver that takes no byte for this long is given up */
#define LINK_PENDING 4096   /* bytes from the receiver kept while a frame is written */

typedef struct {
    const char *port; /* as given, for messages */
    int fd;
    int failed;    /* the link stopped (err says why) */
    int closed;    /* the receiver closed its end */
    int heard;     /* the receiver has sent something intact: flow control is on */
    int have_prev; /* prev holds frame prev_no, the last one sent */
    uint32_t prev_no;
    int palette_sent;
    char err[256];
    uint32_t npending;
    uint8_t pending[LINK_PENDING];
    uint8_t palette[FL_PALETTE_BYTES];
    uint8_t prev[FL_FRAME_BYTES];
    fl_encoder enc;
    _Alignas(4) uint8_t scratch[LINK_SCRATCH_BYTES];
} link_sender;

/* Open PORT (port.h) for sending. Returns 0, or -1 with a message in err: PORT
 * does not open, or is not one frames can be sent on (stdin, a file). Ignores
 * SIGPIPE for the process: a vanished receiver is reported by link_frame. */
int link_open(link_sender *l, const char *port, long baud, char *err, size_t errlen);

/* Start the session: the HELLO message (the one place that sends it), naming
 * the scene as it was given (a file or WAD:MAP) and the CRC-32 of its compiled
 * blob, so that what the receiver records reproduces the frames. */
int link_hello(link_sender *l, const char *scene, const uint8_t *blob, size_t blob_len);

/* Send frame frame_no (64,000 pixels) in palette (768 bytes; sent first when it
 * is new or changed). info: camera and modes; its crc is computed here. A delta
 * when the previous frame sent was frame_no - 1. Returns 0, or -1 when the link
 * has stopped (link_error says why). */
int link_frame(link_sender *l, uint32_t frame_no, const uint8_t *pixels, const uint8_t *palette,
               const fl_frame_info *info);

/* Wait, at most the ack timeout, for the frames in flight to be acknowledged
 * (a receiver that closes its end has nothing more to say). Returns 0, or -1
 * when the link had stopped. */
int link_finish(link_sender *l);

/* Why the link stopped ("PORT: ..."), or NULL while it works. */
const char *link_error(const link_sender *l);

/* The counters: one line for people, and the members of a JSON object
 * ("link": {...}, without the braces' key). */
void link_print_summary(const link_sender *l, FILE *f);
void link_print_json(const link_sender *l, FILE *f);

void link_close(link_sender *l);

#endif
