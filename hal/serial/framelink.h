/* framelink.h - the frame link: the serial protocol that streams rendered
 * 320x200x8 frames from a target to a display board (prefix fl_).
 * Specification: docs/frame-link.md. This is the only C implementation; the
 * Python twin of the decoder is tools/framelink.py.
 *
 * Freestanding C11, integer only, no libc, no allocation, no globals: all state
 * lives in caller-owned structs. Little-endian targets only (x86, Cortex-M).
 *
 * Wire format in one breath: every message is COBS-encoded and ends with a 0x00
 * byte; decoded, it is a 9-byte header (version, type, frame number, payload
 * length), the payload, and a CRC-32 (crc_update) of header and payload.
 * Frames travel as keyframes or as deltas against the frame sent just before,
 * coded row by row as colour transitions predicted from the row above (an
 * adaptive binary range coder); every frame message carries fl_frame_info
 * (camera, modes, the world's time, the CRC-32 of the 64,000 pixel bytes
 * unless the sender opts out) and a frame check computed by the encoder; the
 * receiver checks both on the reconstructed frame before it shows it.
 *
 * Files: fl_framing.c (COBS, header, CRC), fl_codec.c (picture coding),
 * fl_encoder.c (sender), fl_decoder.c (receiver).
 */
#ifndef FRAMELINK_H
#define FRAMELINK_H

#include <stdint.h>

#define FL_VERSION                                                                                                     \
    4 /* 2: method RAW_HASH (its message CRC leaves the pixels to the frame check); 3: the time;
                       * 4: method COPY, streamed (length FL_LEN_STREAMED) */
#define FL_W 320
#define FL_H 200
#define FL_FRAME_BYTES (FL_W * FL_H)
#define FL_PALETTE_BYTES 768

#define FL_HEADER_BYTES 9 /* version, type, frame u32, payload length u24 */
#define FL_CRC_BYTES 4
#define FL_INFO_BYTES 30          /* fl_frame_info on the wire (without no_crc) */
#define FL_FRAME_PRE 35           /* info, flags, frame check: the start of every frame payload */
#define FL_PAYLOAD_MAX 65536u     /* largest payload a receiver accepts */
#define FL_LEN_STREAMED 0xFFFFFFu /* length field of a COPY frame: the payload runs to the CRC */
#define FL_MSG_MAX (FL_HEADER_BYTES + FL_PAYLOAD_MAX + FL_CRC_BYTES)
#define FL_WINDOW_MAX 32     /* largest flow-control window */
#define FL_SCENE_NAME_MAX 63 /* longest scene name a HELLO carries */

/* Message types. */
enum {
    FL_MSG_HELLO = 1,    /* sender -> receiver: version and capabilities */
    FL_MSG_PALETTE = 2,  /* sender -> receiver: 256 x RGB, 8 bits per gun */
    FL_MSG_KEYFRAME = 3, /* sender -> receiver: a whole frame */
    FL_MSG_DELTA = 4,    /* sender -> receiver: a frame as a change of a named base frame */
    FL_MSG_ACK = 5,      /* receiver -> sender: frame handled (flow control) */
    FL_MSG_KEYREQ = 6    /* receiver -> sender: please send a keyframe (and/or the palette) */
};

/* Picture coding methods (the payload byte before the picture data). */
/* RAW_HASH: the 64,000 pixel bytes of a keyframe as they are; the frame check is
 * fl_pixel_hash (not fl_frame_check), and the message CRC covers the header and the
 * payload before the pixels only: the hash protects them, at a fraction of a CRC's cost. */
enum { FL_METHOD_RAW = 0, FL_METHOD_EDGE = 1, FL_METHOD_RAW_HASH = 2, FL_METHOD_COPY = 3 };

/* What the receiver knows about a frame besides its pixels. */
typedef struct {
    int32_t x, y, z;  /* camera, 16.16 map units (view.h: camera) */
    int32_t angle;    /* degrees, 16.16 */
    int32_t look;     /* pixels */
    uint8_t mode;     /* render mode (render.h) */
    uint8_t present;  /* present mode (hal.h) */
    uint32_t crc;     /* crc_update(0, pixels, 64000) */
    uint8_t no_crc;   /* sender: nonzero if crc was not computed (the link's own frame
                          * check still protects the frame; the receiver fills crc in) */
    uint32_t time_ms; /* the world's time (engine.h: t_ms): objects, doors, animated textures */
} fl_frame_info;

/* Sender capabilities and the scene it draws (the HELLO payload). */
typedef struct {
    uint8_t version; /* protocol version the sender speaks */
    uint16_t width, height;
    uint8_t gun_bits;                       /* palette bits per gun: 8 */
    uint16_t key_interval;                  /* a keyframe at least every this many frames (0: only when needed) */
    uint8_t window;                         /* frames the sender keeps in flight unacknowledged */
    uint8_t methods;                        /* bit per FL_METHOD_* it may use */
    uint32_t scene_crc;                     /* crc_update(0, blob) of the scene's compiled blob; 0: not said */
    char scene_name[FL_SCENE_NAME_MAX + 1]; /* printable ASCII, NUL-terminated; "": not said */
} fl_hello;

/* Output: the callee must take all n bytes (copy them out; p is reused). */
typedef void (*fl_put_fn)(void *ctx, const uint8_t *p, uint32_t n);

/* ---- framing (shared by both ends) --------------------------------------- */

/* Streaming COBS writer: one 254-byte block buffered at a time. */
typedef struct {
    fl_put_fn put; /* may be NULL: bytes are counted, not sent */
    void *ctx;
    uint32_t crc;     /* running crc_update state of the message */
    uint32_t bytes;   /* encoded bytes written so far (counter) */
    uint8_t n;        /* data bytes in blk[1..] */
    uint8_t blk[255]; /* blk[0] is the code byte */
} fl_writer;

/* Streaming COBS reader: reassembles one message at a time into buf. */
typedef struct {
    uint8_t *buf;
    uint32_t cap, len;
    uint8_t left;      /* data bytes left in the current COBS block */
    uint8_t last_code; /* code byte of the current block (0: none yet) */
    uint8_t started;   /* a non-delimiter byte arrived since the last delimiter */
    uint8_t broken;    /* fl_reason why this segment can no longer be a good message, 0 if none */
} fl_reader;

/* ---- the picture coder's working memory (both ends) ----------------------- */

#define FL_ROW_EDGES (FL_W)   /* transitions a row can have (< 320) */
typedef struct {              /* three arrays back to back: pk[k + FL_ROW_EDGES] is dv[k] */
    int32_t pk[FL_ROW_EDGES]; /* next row's predicted position * 256 + the colour right of the edge */
    int32_t dv[FL_ROW_EDGES]; /* 256 * how far the edge moved since the row above (0 if unknown) */
    int32_t vc[FL_ROW_EDGES]; /* velocity class 0..3 (docs/frame-link.md) */
    uint32_t n;
} fl_edges;

#define FL_CTX_COUNT 162
#define FL_CACHE 4
typedef struct {
    fl_edges edges[2];        /* the row above and the row being coded */
    int32_t at[FL_ROW_EDGES]; /* the row's transitions, x * 256 + colour */
    uint16_t p[FL_CTX_COUNT]; /* adaptive model: probability of a 0 bit, in 1/4096 */
    uint8_t cache[FL_CACHE];  /* colours, most recently coded first */
    uint8_t hashes_valid;     /* encoder: row_hash holds the rows of hashes_of */
    const uint8_t *hashes_of;
    uint32_t row_hash[FL_H];
} fl_coder;

/* ---- the COPY coding's model (both ends; fl_copy.c) ------------------------- */

#define FL_CP_PROBS 3072   /* adaptive bit probabilities (their layout: fl_copy.c) */
#define FL_CP_SLACK 256u   /* a coded picture is at most 64,000 + this + a few bytes */
#define FL_CP_HASH_BITS 16 /* the encoder's optional match finder: 2^16 positions */
#define FL_CP_HASH (1u << FL_CP_HASH_BITS)

typedef struct {
    uint16_t p[FL_CP_PROBS];
    int32_t rep[4]; /* the recent offsets, most recent first */
} fl_copy_model;

/* ---- encoder (the sender: runs on the target) ----------------------------- */

typedef struct {
    /* set by fl_enc_init; the fields in this group may be changed between frames */
    uint32_t key_interval;   /* keyframe at least every N frames (0: only when needed). Default 64 */
    uint8_t window;          /* max frames in flight unacknowledged (1..FL_WINDOW_MAX). Default 4 */
    uint32_t ack_timeout_ms; /* a full window that long without an ack is given up. Default 500 */

    fl_writer w;
    uint8_t *scratch; /* caller's buffer for one coded frame message */
    uint32_t scratch_bytes;
    const uint8_t *palette; /* last palette sent (kept to answer palette requests) */

    /* link state */
    uint8_t sent_any, force_key, want_palette, stalled;
    uint32_t last_sent;               /* frame number of the last frame sent */
    uint32_t last_key;                /* frame number of the last keyframe sent */
    uint32_t since_key;               /* frames sent since that keyframe */
    uint32_t last_coded;              /* coded bytes of the last frame's picture (0: it went raw) */
    uint32_t inflight[FL_WINDOW_MAX]; /* numbers of the frames sent and not yet acknowledged (FIFO) */
    uint8_t in_head, in_count;
    uint32_t stall_since_ms;

    /* the scene named in HELLO (fl_enc_scene) */
    uint32_t scene_crc;
    uint8_t scene_len;
    char scene_name[FL_SCENE_NAME_MAX];

    /* counters */
    uint32_t frames, keyframes, deltas, raw_fallbacks, bytes;
    uint32_t copy_frames; /* frames whose picture went with method COPY */
    uint32_t acks, keyreqs, palette_reqs, timeouts, rx_bad;

    /* receiving acks and keyframe requests */
    fl_reader rx;
    uint8_t rx_buf[64];

    int32_t *match_hash; /* FL_CP_HASH entries for the COPY coder's match finder, or NULL */
    union {              /* one picture coder at a time */
        fl_coder coder;
        fl_copy_model copy;
    };
} fl_encoder;

/* Start a sender. put receives every encoded byte. scratch holds one coded frame
 * message while it is built (>= 1024 bytes; 8 KB is ample for flat-shaded
 * frames: a frame whose coding does not fit is sent as a raw keyframe, 64 KB on
 * the wire, streamed straight from the pixels). Sends nothing. */
void fl_enc_init(fl_encoder *e, fl_put_fn put, void *ctx, uint8_t *scratch, uint32_t scratch_bytes);

/* Name the scene the frames are drawn from, for the HELLOs sent after it: its
 * name (NUL-terminated; the first FL_SCENE_NAME_MAX bytes are kept, a byte that
 * is not printable ASCII becomes '?'; NULL: none) and crc_update(0, blob, len)
 * of its compiled blob. A sender that never calls it names no scene ("", 0). */
void fl_enc_scene(fl_encoder *e, const char *name, uint32_t blob_crc);

/* Send HELLO (capabilities and scene; frame field = next frame number). */
void fl_enc_hello(fl_encoder *e);

/* Send the palette (768 bytes, r g b, 8 bits per gun). The pointer is kept to
 * answer a receiver's palette request: it must stay valid. */
void fl_enc_palette(fl_encoder *e, const uint8_t *rgb);

/* Send frame frame_no (64,000 bytes, pitch 320). base is the previous frame this
 * encoder sent, number base_no (on a target: the other VRAM page), or NULL. A
 * delta is sent when base is that frame and no keyframe is due (first frame,
 * receiver request, key_interval); otherwise a keyframe. info->crc must be
 * crc_update(0, pixels, 64000). pixels and base should be word-aligned (any
 * alignment works, slower). Sends a requested palette first.
 * Returns the message type sent (FL_MSG_KEYFRAME or FL_MSG_DELTA). */
int fl_enc_frame(fl_encoder *e, uint32_t frame_no, const uint8_t *pixels, const uint8_t *base, uint32_t base_no,
                 const fl_frame_info *info);

/* Bytes from the receiver (any chunking): acks and keyframe/palette requests. */
void fl_enc_receive(fl_encoder *e, const uint8_t *p, uint32_t n);

/* Flow control: may the next frame be sent now? Yes while fewer than `window`
 * frames sent are unacknowledged; a window that stays full for ack_timeout_ms
 * (clock now_ms, any epoch, wraps) is given up (counted in timeouts) and
 * sending resumes. */
int fl_enc_may_send(fl_encoder *e, uint32_t now_ms);

/* ---- decoder (the receiver: display board, tests) ------------------------- */

/* Bytes of work memory a decoder needs: one message and one reconstruction. */
#define FL_DEC_WORK_BYTES (FL_MSG_MAX + FL_FRAME_BYTES)

typedef enum {
    FL_EV_HELLO,   /* hello: capabilities in ev->hello */
    FL_EV_PALETTE, /* palette: ev->palette (768 bytes) */
    FL_EV_FRAME,   /* a frame passed every check and is now in the frame buffer */
    FL_EV_DROP,    /* a frame message arrived intact but was not shown (ev->reason) */
    FL_EV_BAD,     /* a damaged or invalid message was discarded (ev->reason) */
    FL_EV_KEYREQ,  /* the decoder sent a keyframe request (ev->frame_no: the frame it could not show) */
    FL_EV_OTHER    /* an intact message for the other direction (ack/keyreq): ignored */
} fl_event_kind;

typedef enum {
    FL_R_NONE,
    FL_R_FRAMING,  /* COBS structure broken */
    FL_R_SHORT,    /* shorter than header + CRC */
    FL_R_LONG,     /* longer than FL_MSG_MAX */
    FL_R_CRC,      /* message CRC mismatch */
    FL_R_VERSION,  /* unsupported protocol version */
    FL_R_LENGTH,   /* header length disagrees with the message */
    FL_R_TYPE,     /* unknown message type */
    FL_R_PAYLOAD,  /* payload size or layout invalid for its type */
    FL_R_NO_BASE,  /* delta whose base frame is not the frame shown */
    FL_R_DECODE,   /* picture data inconsistent */
    FL_R_FRAME_CRC /* reconstructed frame does not match its frame check or CRC-32 */
} fl_reason;

typedef struct {
    fl_event_kind kind;
    fl_reason reason;
    uint8_t type;           /* message type */
    uint32_t frame_no;      /* header frame number */
    uint8_t keyframe;       /* FRAME: it was a keyframe */
    fl_frame_info info;     /* FRAME; DROP: as sent (not trustworthy) */
    fl_hello hello;         /* HELLO */
    const uint8_t *palette; /* PALETTE */
} fl_event;

typedef void (*fl_event_fn)(void *ctx, const fl_event *ev);

typedef struct {
    uint32_t bytes;    /* bytes fed */
    uint32_t msgs_ok;  /* messages that passed framing, CRC, header and layout checks */
    uint32_t msgs_bad; /* non-empty segments that failed them (never acted on) */
    uint32_t resyncs;  /* good messages right after one or more bad ones */
    uint32_t frames_shown;
    uint32_t frames_dropped; /* intact frame messages not shown (no base, decode, frame CRC) */
    uint32_t frames_missed;  /* frame numbers skipped between intact frame messages */
    uint32_t keyreqs_sent;   /* keyframe requests sent */
    uint32_t palreqs_sent;   /* palette-only requests sent */
    uint32_t acks_sent;
    uint32_t palettes, hellos;
} fl_counters;

typedef struct {
    uint8_t *frame; /* caller's 64,000 bytes: the frame shown */
    uint8_t *recon; /* reconstruction (in work, or the hidden page: fl_dec_init_pages) */
    fl_reader rx;
    fl_event_fn on_event;
    void *ev_ctx;
    fl_writer back;    /* receiver -> sender messages */
    uint8_t send_acks; /* default 1 */
    uint8_t flip;      /* fl_dec_init_pages: a frame is shown by swapping frame and recon */

    uint8_t have_frame, have_palette, have_hello, waiting_key, last_bad, have_seen;
    uint8_t window;         /* from hello (default 4) */
    uint32_t shown_no;      /* number of the frame in the frame buffer */
    uint32_t seen_no;       /* highest frame number seen in an intact frame message */
    uint32_t waiting_drops; /* frames dropped since the last keyframe request */
    uint32_t palette_wait;  /* frames shown without a palette */
    fl_frame_info shown_info;
    fl_hello hello;
    uint8_t palette[FL_PALETTE_BYTES];
    fl_counters count;
    uint8_t want_crc; /* default 1: every frame shown gets its pixel CRC-32 (info.crc), sent or not */

    union { /* one picture coder at a time */
        fl_coder coder;
        fl_copy_model copy;
    };
} fl_decoder;

/* Start a receiver. frame: 64,000 bytes, written only with frames that passed
 * every check. work: FL_DEC_WORK_BYTES. on_event (may be NULL) is called for
 * every event. back_put (may be NULL) receives the acks and keyframe requests
 * the decoder sends to the sender. */
void fl_dec_init(fl_decoder *d, uint8_t *frame, uint8_t *work, fl_event_fn on_event, void *ev_ctx, fl_put_fn back_put,
                 void *back_ctx);

/* Bytes of work memory a page-flipping decoder needs: one message. */
#define FL_DEC_PAGES_WORK_BYTES (FL_MSG_MAX)

/* Start a receiver that rebuilds each frame straight into a hidden page and
 * shows it by a flip, with no 64,000-byte copy: page0 and page1 (64,000 bytes
 * each) take turns. d->frame is the page shown (page0 at first), d->recon the
 * hidden one, which holds anything, even a frame that failed its checks. work:
 * FL_DEC_PAGES_WORK_BYTES. Otherwise as fl_dec_init. */
void fl_dec_init_pages(fl_decoder *d, uint8_t *page0, uint8_t *page1, uint8_t *work, fl_event_fn on_event, void *ev_ctx,
                       fl_put_fn back_put, void *back_ctx);

/* Feed received bytes, any chunking. Events are reported as messages complete. */
void fl_dec_feed(fl_decoder *d, const uint8_t *p, uint32_t n);

/* ---- building blocks (exposed for tests and tools) ------------------------ */

/* Frame information to and from its 26 wire bytes. */
void fl_info_pack(uint8_t *out, const fl_frame_info *info);
void fl_info_unpack(fl_frame_info *info, const uint8_t *in);

/* Code a picture (method EDGE): the range-coded bits for pixels, a delta
 * against base when base != NULL. Writes at most cap bytes to out; returns the
 * byte count, or 0 if it did not fit. *check receives fl_frame_check(pixels)
 * when it fits; a picture that does not is given up at the row it overflows
 * in (its frame goes raw, checked by fl_pixel_hash), and the coder keeps no
 * row hashes from it. */
uint32_t fl_code_picture(fl_coder *c, const uint8_t *pixels, const uint8_t *base, uint8_t *out, uint32_t cap,
                         uint32_t *check);

/* The frame check: a 32-bit hash of every row's colour transitions (docs/frame-link.md,
 * "Frame check"), which the encoder gets almost free from its scan. */
uint32_t fl_frame_check(const uint8_t *pixels);

/* The frame check of a RAW_HASH frame: a multiplicative hash of the pixels'
 * 32-bit little-endian words (docs/frame-link.md, "Frame check"). Any change
 * confined to one word always changes it. */
uint32_t fl_pixel_hash(const uint8_t *pixels);

/* About how many colour transitions a picture has that a delta against base
 * (NULL: none) would code: those of every 16th row that differs from base,
 * times 16. Cheap (13 rows); the encoder uses it to send a frame that would
 * not fit its scratch buffer raw without trying to code it first. */
uint32_t fl_estimate_transitions(const uint8_t *pixels, const uint8_t *base);

/* Decode a method-EDGE picture of n bytes into out (64,000), with base for a
 * delta (NULL: keyframe). Returns 0, or -1 if the data is inconsistent. */
int fl_decode_picture(fl_coder *c, const uint8_t *in, uint32_t n, const uint8_t *base, uint8_t *out);

/* Code a picture (method COPY) straight into the message w has begun, as
 * bytes the message CRC does not cover (fl_writer_direct); base: the previous
 * frame for a delta, or NULL. hash: FL_CP_HASH entries of work memory for the
 * match finder, or NULL (fewer, shorter copies). Returns the bytes written, at
 * most FL_FRAME_BYTES + FL_CP_SLACK + 16. */
uint32_t fl_copy_encode(fl_copy_model *m, const uint8_t *pixels, const uint8_t *base, int32_t *hash, fl_writer *w);

/* Decode a method-COPY picture of n bytes into out (64,000), with base for a
 * delta (NULL: keyframe). Returns 0, or -1 if the data is inconsistent: a copy
 * from outside the picture, a length past its end, bytes left over or missing. */
int fl_copy_decode(fl_copy_model *m, const uint8_t *in, uint32_t n, const uint8_t *base, uint8_t *out);

#endif
