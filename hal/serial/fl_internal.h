/* fl_internal.h - what the frame link's files share and nobody else needs. */
#ifndef FL_INTERNAL_H
#define FL_INTERNAL_H

#include "framelink.h"

static inline void fl_put16(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}
static inline void fl_put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}
static inline uint32_t fl_get16(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8;
}
static inline uint32_t fl_get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* HELLO payload: the capabilities (FL_HELLO_CAPS bytes: all a sender before
 * scene names sent), then the scene's blob CRC (u32), its name's length (u8)
 * and the name. */
#define FL_HELLO_CAPS 10
#define FL_HELLO_MIN (FL_HELLO_CAPS + 5)
#define FL_HELLO_MAX (FL_HELLO_MIN + FL_SCENE_NAME_MAX)

static inline int fl_name_char_ok(uint8_t c)
{
    return c >= 0x20 && c <= 0x7E;
}

/* Writer: begin a message (header), add payload bytes, end it (CRC, delimiter). */
void fl_writer_init(fl_writer *w, fl_put_fn put, void *ctx);
void fl_writer_begin(fl_writer *w, uint8_t type, uint32_t frame_no, uint32_t payload_len);
void fl_writer_bytes(fl_writer *w, const uint8_t *p, uint32_t n);
void fl_writer_end(fl_writer *w);
/* Payload bytes the message CRC does not cover (a RAW_HASH frame's pixels):
 * stuffed straight from p, no copy. */
void fl_writer_direct(fl_writer *w, const uint8_t *p, uint32_t n);
/* A whole message with a small payload. */
void fl_writer_message(fl_writer *w, uint8_t type, uint32_t frame_no, const uint8_t *payload, uint32_t n);

/* Reader: feed one byte. Returns 0 (nothing yet), 1 (a segment ended with a
 * structurally complete message of r->len bytes in r->buf) or -reason (a
 * non-empty segment ended and was bad; r->len is then 0: no part of it can be
 * taken for a message). */
void fl_reader_init(fl_reader *r, uint8_t *buf, uint32_t cap);
int fl_reader_byte(fl_reader *r, uint8_t b);

/* Check a reassembled message: CRC, version, length. Returns FL_R_NONE and the
 * header fields, or the reason it is bad. */
typedef struct {
    uint8_t type;
    uint32_t frame_no;
    const uint8_t *payload;
    uint32_t len;
} fl_msg;
/* How many leading bytes of a message of len bytes (CRC included) its CRC
 * covers: all but the CRC, or for a RAW_HASH keyframe the header and the
 * payload up to its method byte (docs/frame-link.md, "Framing"). */
uint32_t fl_msg_crc_bytes(const uint8_t *buf, uint32_t len);
fl_reason fl_msg_check(const uint8_t *buf, uint32_t len, fl_msg *m);

#endif
