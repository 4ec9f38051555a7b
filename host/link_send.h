/* link_send.h - the host's frame-link present (prefix link_): build/emu --link
 * and build/render --link send the frames they draw to a display board over a
 * tty, a pty or a TCP socket (port.h), as the firmware does over its UART
 * (hal/mps2/stream_fl.c): hello, palette, then keyframes and deltas against the
 * last frame sent; acks and keyframe requests read back without blocking and
 * fed to the encoder.
 *
 * Flow control never holds up the caller: link_frame does not wait. A frame
 * goes out only when the receiver's window has room (fl_enc_may_send, once the
 * receiver has answered) and the message before it has left; otherwise it is
 * not sent (counted in skipped), and the next frame sent is a delta against
 * the last frame that was. A frame message is coded whole into a queue and
 * written as fast as the port takes it, over as many link_frame calls as that
 * needs: never half-written and given up. link_finish (the end of a run) waits,
 * bounded: for the queue to empty, for room to send the last frame drawn if it
 * was skipped, and for the acks of the frames in flight.
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
#define LINK_PENDING 4096   /* bytes from the receiver read at a time */
/* The queue of bytes for the port: a frame message (at most FL_MSG_MAX before
 * COBS, which adds a byte in 254) and the palette and hello messages before
 * it, with room to spare. */
#define LINK_OUT_BYTES (2u * (FL_MSG_MAX + FL_MSG_MAX / 254u + 2u))

typedef struct {
    const char *port; /* as given, for messages */
    int fd;
    int failed;    /* the link stopped (err says why) */
    int closed;    /* the receiver closed its end */
    int heard;     /* the receiver has sent something intact: flow control is on */
    int have_prev; /* prev holds frame prev_no, the last one sent */
    uint32_t prev_no;
    int have_held; /* held holds frame held_no, the last one drawn, skipped */
    uint32_t held_no;
    int palette_sent;
    uint32_t skipped; /* frames drawn and not sent: the link was behind */
    char err[256];
    uint32_t npending;
    uint8_t pending[LINK_PENDING];
    uint32_t out_at, out_len; /* the queue: out[out_at..out_len) still to write */
    uint32_t out_moved_ms;    /* when the port last took bytes of it (or it filled) */
    uint8_t out[LINK_OUT_BYTES];
    uint8_t palette[FL_PALETTE_BYTES];
    uint8_t prev[FL_FRAME_BYTES];
    uint8_t held[FL_FRAME_BYTES];
    uint8_t held_palette[FL_PALETTE_BYTES];
    fl_frame_info held_info;
    fl_encoder enc;
    _Alignas(4) uint8_t scratch[LINK_SCRATCH_BYTES];
    int32_t match_hash[FL_CP_HASH]; /* the COPY coder's match finder */
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
 * is new or changed), without waiting: when the link is behind (the receiver's
 * window is full, or the last message is still being written) the frame is not
 * sent but kept, in case it is the last (link_finish), and counted in skipped.
 * info: camera and modes; its crc is computed here. A delta against the last
 * frame sent, or a keyframe when one is due (framelink.h: fl_enc_frame); frame
 * numbers must increase. Returns 0 (sent or skipped), or -1 when the link has
 * stopped (link_error says why). */
int link_frame(link_sender *l, uint32_t frame_no, const uint8_t *pixels, const uint8_t *palette,
               const fl_frame_info *info);

/* The end of a run: write out the queue; send the last frame drawn if it was
 * skipped, once the window has room (at most the ack timeout); then wait, at
 * most the ack timeout, for the frames in flight to be acknowledged (a receiver
 * that closes its end has nothing more to say). Returns 0, or -1 when the link
 * had stopped. */
int link_finish(link_sender *l);

/* Why the link stopped ("PORT: ..."), or NULL while it works. */
const char *link_error(const link_sender *l);

/* The counters: one line for people, and the members of a JSON object
 * ("link": {...}, without the braces' key). */
void link_print_summary(const link_sender *l, FILE *f);
void link_print_json(const link_sender *l, FILE *f);

void link_close(link_sender *l);

#endif
