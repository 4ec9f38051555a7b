/* fl_framing.c - messages on the wire: header, CRC-32, COBS stuffing with a
 * 0x00 delimiter after every message (writer and streaming reader), and the
 * frame information's byte layout. docs/frame-link.md, "Framing". */
#include "crc32.h"
#include "fl_internal.h"

/* ---- writer ----------------------------------------------------------------- */

void fl_writer_init(fl_writer *w, fl_put_fn put, void *ctx)
{
    w->put = put;
    w->ctx = ctx;
    w->crc = 0;
    w->bytes = 0;
    w->n = 0;
}

static void flush_block(fl_writer *w, uint8_t code)
{
    w->blk[0] = code;
    if (w->put) w->put(w->ctx, w->blk, (uint32_t)w->n + 1);
    w->bytes += (uint32_t)w->n + 1;
    w->n = 0;
}

/* COBS-stuff n bytes (no CRC update). */
static void stuff(fl_writer *w, const uint8_t *p, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        uint8_t b = p[i];
        if (b == 0) {
            flush_block(w, (uint8_t)(w->n + 1));
        } else {
            w->blk[++w->n] = b;
            if (w->n == 254) flush_block(w, 0xFF);
        }
    }
}

/* The first zero byte in [p, end), or end: a word at a time where p is aligned. */
static const uint8_t *find_zero(const uint8_t *p, const uint8_t *end)
{
    typedef uint32_t u32a __attribute__((may_alias));
    while (p < end && ((uintptr_t)p & 3u)) {
        if (!*p) return p;
        p++;
    }
    const u32a *w = (const u32a *)(const void *)p;
    const u32a *wend = (const u32a *)(const void *)(p + ((uint32_t)(end - p) & ~3u));
    /* four words per test (one load-multiple on a Cortex-M3): a word's
     * (v - 0x01010101) & ~v & 0x80808080 is nonzero exactly when it holds a
     * zero byte, so the OR of four says whether any of them does */
    for (; w + 4 <= wend; w += 4) {
        uint32_t a = w[0], b = w[1], c = w[2], d = w[3];
        uint32_t z = ((a - 0x01010101u) & ~a) | ((b - 0x01010101u) & ~b) | ((c - 0x01010101u) & ~c) |
                     ((d - 0x01010101u) & ~d);
        if (z & 0x80808080u) break; /* then the word loop below finds which */
    }
    for (; w < wend; w++) {
        uint32_t v = *w;
        if ((v - 0x01010101u) & ~v & 0x80808080u) break; /* a zero byte in v */
    }
    for (p = (const uint8_t *)w; p < end; p++)
        if (!*p) return p;
    return end;
}

typedef uint32_t fl_u32a __attribute__((may_alias));

/* The zero bytes of v: 0x80 in each, exactly (no borrow from a byte below). */
static inline uint32_t zero_bytes(uint32_t v)
{
    return ~(((v & 0x7F7F7F7Fu) + 0x7F7F7F7Fu) | v | 0x7F7F7F7Fu);
}

/* find_zero for data whose every word lies inside it (start and length
 * multiples of four): p need not be aligned, the word holding it is read with
 * the bytes before p masked off, so a zero costs no byte loop. */
static const uint8_t *find_zero_words(const uint8_t *p, const uint8_t *end)
{
    const fl_u32a *w = (const fl_u32a *)(const void *)((uintptr_t)p & ~(uintptr_t)3);
    uint32_t m = zero_bytes(*w) & (0xFFFFFFFFu << (8u * ((uintptr_t)p & 3u)));
    if (!m) {
        for (w++; (const uint8_t *)(w + 4) <= end; w += 4) { /* as find_zero's */
            uint32_t a = w[0], b = w[1], c = w[2], d = w[3];
            uint32_t z = ((a - 0x01010101u) & ~a) | ((b - 0x01010101u) & ~b) | ((c - 0x01010101u) & ~c) |
                         ((d - 0x01010101u) & ~d);
            if (z & 0x80808080u) break;
        }
        for (; (const uint8_t *)w < end && !(m = zero_bytes(*w)); w++) {
        }
        if (!m) return end;
    }
    const uint8_t *z = (const uint8_t *)w + (__builtin_ctz(m) >> 3);
    return z < end ? z : end;
}

/* COBS-stuff n bytes (no CRC update) without copying them: a block's bytes
 * go to put straight from p, after those buffered before them; only a block
 * the data ends in is buffered. */
void fl_writer_direct(fl_writer *w, const uint8_t *p, uint32_t n)
{
    const uint8_t *end = p + n;
    int words = (((uintptr_t)p | n) & 3u) == 0;
    while (p < end) {
        uint32_t room = 254u - w->n, left = (uint32_t)(end - p);
        const uint8_t *lim = p + (left < room ? left : room), *z = words ? find_zero_words(p, lim) : find_zero(p, lim);
        uint32_t run = (uint32_t)(z - p);
        if (z == lim && z == end && run < room) { /* the data ends inside this block: keep it */
            for (uint32_t i = 0; i < run; i++) w->blk[++w->n] = p[i];
            return;
        }
        uint32_t full = z == lim && run == room; /* no zero: a full block */
        w->blk[0] = (uint8_t)(full ? 0xFFu : w->n + run + 1u);
        if (w->put) {
            w->put(w->ctx, w->blk, (uint32_t)w->n + 1);
            if (run) w->put(w->ctx, p, run);
        }
        w->bytes += (uint32_t)w->n + 1 + run;
        w->n = 0;
        p = z + (full ? 0 : 1);
    }
}

void fl_writer_bytes(fl_writer *w, const uint8_t *p, uint32_t n)
{
    w->crc = crc_update(w->crc, p, n);
    stuff(w, p, n);
}

void fl_writer_begin(fl_writer *w, uint8_t type, uint32_t frame_no, uint32_t payload_len)
{
    uint8_t h[FL_HEADER_BYTES];
    h[0] = FL_VERSION;
    h[1] = type;
    fl_put32(h + 2, frame_no);
    h[6] = (uint8_t)payload_len;
    h[7] = (uint8_t)(payload_len >> 8);
    h[8] = (uint8_t)(payload_len >> 16);
    w->crc = 0;
    w->n = 0;
    fl_writer_bytes(w, h, FL_HEADER_BYTES);
}

void fl_writer_end(fl_writer *w)
{
    uint8_t c[FL_CRC_BYTES];
    fl_put32(c, w->crc);
    stuff(w, c, FL_CRC_BYTES);
    flush_block(w, (uint8_t)(w->n + 1)); /* the last block; its phantom zero is not data */
    uint8_t z = 0;
    if (w->put) w->put(w->ctx, &z, 1);
    w->bytes++;
}

void fl_writer_message(fl_writer *w, uint8_t type, uint32_t frame_no, const uint8_t *payload, uint32_t n)
{
    fl_writer_begin(w, type, frame_no, n);
    fl_writer_bytes(w, payload, n);
    fl_writer_end(w);
}

/* ---- reader ----------------------------------------------------------------- */

void fl_reader_init(fl_reader *r, uint8_t *buf, uint32_t cap)
{
    r->buf = buf;
    r->cap = cap;
    r->len = 0;
    r->left = 0;
    r->last_code = 0;
    r->started = 0;
    r->broken = 0;
}

static inline void append(fl_reader *r, uint8_t b)
{
    if (r->len < r->cap)
        r->buf[r->len++] = b;
    else
        r->broken = FL_R_LONG;
}

int fl_reader_byte(fl_reader *r, uint8_t b)
{
    if (b == 0) {
        int res = 0;
        if (r->started) {
            if (r->broken)
                res = -(int)r->broken;
            else if (r->left)
                res = -(int)FL_R_FRAMING; /* the last block was cut short */
            else
                res = 1;
        }
        r->started = 0;
        r->broken = 0;
        r->left = 0;
        r->last_code = 0;
        if (res != 1) r->len = 0;
        return res;
    }
    if (!r->started) {
        r->started = 1;
        r->len = 0;
    }
    if (r->broken) return 0;
    if (r->left == 0) { /* a code byte: the previous block's phantom zero is data unless it was full */
        if (r->last_code && r->last_code != 0xFF) append(r, 0);
        r->last_code = b;
        r->left = (uint8_t)(b - 1);
    } else {
        append(r, b);
        r->left--;
    }
    return 0;
}

/* A streamed COPY frame: its length field, type and method byte say so. */
static int is_streamed(const uint8_t *buf, uint32_t len)
{
    uint32_t plen = (uint32_t)buf[6] | (uint32_t)buf[7] << 8 | (uint32_t)buf[8] << 16;
    if (plen != FL_LEN_STREAMED || (buf[1] != FL_MSG_KEYFRAME && buf[1] != FL_MSG_DELTA)) return 0;
    uint32_t pre = FL_HEADER_BYTES + FL_FRAME_PRE + (buf[1] == FL_MSG_DELTA ? 4u : 0u) + 1u;
    return len > pre + FL_CRC_BYTES && buf[pre - 1] == FL_METHOD_COPY;
}

uint32_t fl_msg_crc_bytes(const uint8_t *buf, uint32_t len)
{
    uint32_t pre = FL_HEADER_BYTES + FL_FRAME_PRE + 1;
    if (len == pre + FL_FRAME_BYTES + FL_CRC_BYTES && buf[1] == FL_MSG_KEYFRAME && buf[pre - 1] == FL_METHOD_RAW_HASH)
        return pre;
    if (len >= FL_HEADER_BYTES && is_streamed(buf, len)) return pre + (buf[1] == FL_MSG_DELTA ? 4u : 0u);
    return len - FL_CRC_BYTES;
}

fl_reason fl_msg_check(const uint8_t *buf, uint32_t len, fl_msg *m)
{
    if (len < FL_HEADER_BYTES + FL_CRC_BYTES) return FL_R_SHORT;
    if (crc_update(0, buf, fl_msg_crc_bytes(buf, len)) != fl_get32(buf + len - FL_CRC_BYTES)) return FL_R_CRC;
    if (buf[0] != FL_VERSION) return FL_R_VERSION;
    uint32_t plen = (uint32_t)buf[6] | (uint32_t)buf[7] << 8 | (uint32_t)buf[8] << 16;
    if (plen == FL_LEN_STREAMED && is_streamed(buf, len)) plen = len - FL_HEADER_BYTES - FL_CRC_BYTES;
    if (plen != len - FL_HEADER_BYTES - FL_CRC_BYTES || plen > FL_PAYLOAD_MAX) return FL_R_LENGTH;
    m->type = buf[1];
    m->frame_no = fl_get32(buf + 2);
    m->payload = buf + FL_HEADER_BYTES;
    m->len = plen;
    return FL_R_NONE;
}

/* ---- frame information -------------------------------------------------------- */

void fl_info_pack(uint8_t *o, const fl_frame_info *in)
{
    fl_put32(o + 0, (uint32_t)in->x);
    fl_put32(o + 4, (uint32_t)in->y);
    fl_put32(o + 8, (uint32_t)in->z);
    fl_put32(o + 12, (uint32_t)in->angle);
    fl_put32(o + 16, (uint32_t)in->look);
    o[20] = in->mode;
    o[21] = in->present;
    fl_put32(o + 22, in->crc);
    fl_put32(o + 26, in->time_ms);
}

void fl_info_unpack(fl_frame_info *out, const uint8_t *i)
{
    out->x = (int32_t)fl_get32(i + 0);
    out->y = (int32_t)fl_get32(i + 4);
    out->z = (int32_t)fl_get32(i + 8);
    out->angle = (int32_t)fl_get32(i + 12);
    out->look = (int32_t)fl_get32(i + 16);
    out->mode = i[20];
    out->present = i[21];
    out->crc = fl_get32(i + 22);
    out->time_ms = fl_get32(i + 26);
}
