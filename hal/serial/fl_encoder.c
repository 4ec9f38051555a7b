/* fl_encoder.c - the sending end of the frame link (runs on the target): hello
 * (with the scene's name and blob CRC), palette, keyframe or delta per frame, acks and keyframe requests from the
 * receiver, and the flow-control window. docs/frame-link.md, "Sender". */
#include "fl_internal.h"

#define BACK_BYTES 5 /* ACK and KEYREQ payloads */

void fl_enc_init(fl_encoder *e, fl_put_fn put, void *ctx, uint8_t *scratch, uint32_t scratch_bytes)
{
    uint8_t *p = (uint8_t *)e;
    for (uint32_t i = 0; i < sizeof *e; i++) p[i] = 0;
    e->key_interval = 64;
    e->window = 4;
    e->ack_timeout_ms = 500;
    fl_writer_init(&e->w, put, ctx);
    e->scratch = scratch;
    e->scratch_bytes = scratch_bytes;
    fl_reader_init(&e->rx, e->rx_buf, sizeof e->rx_buf);
}

static uint32_t next_frame_no(const fl_encoder *e)
{
    return e->sent_any ? e->last_sent + 1 : 0;
}

void fl_enc_scene(fl_encoder *e, const char *name, uint32_t blob_crc)
{
    uint32_t n = 0;
    /* only printable ASCII goes on the wire: the receiver refuses a HELLO with anything else */
    for (; name && name[n] && n < FL_SCENE_NAME_MAX; n++)
        e->scene_name[n] = fl_name_char_ok((uint8_t)name[n]) ? name[n] : '?';
    e->scene_len = (uint8_t)n;
    e->scene_crc = blob_crc;
}

void fl_enc_hello(fl_encoder *e)
{
    uint8_t h[FL_HELLO_MAX];
    h[0] = FL_VERSION;
    fl_put16(h + 1, FL_W);
    fl_put16(h + 3, FL_H);
    h[5] = 8;
    fl_put16(h + 6, e->key_interval > 0xFFFF ? 0xFFFF : e->key_interval);
    h[8] = e->window;
    h[9] = (1u << FL_METHOD_EDGE) | (1u << FL_METHOD_COPY); /* the methods this encoder sends */
    fl_put32(h + FL_HELLO_CAPS, e->scene_crc);
    h[FL_HELLO_CAPS + 4] = e->scene_len;
    for (uint32_t i = 0; i < e->scene_len; i++) h[FL_HELLO_MIN + i] = (uint8_t)e->scene_name[i];
    fl_writer_message(&e->w, FL_MSG_HELLO, next_frame_no(e), h, FL_HELLO_MIN + e->scene_len);
    e->bytes = e->w.bytes;
    e->force_key = 1; /* a hello starts a session: the receiver forgets its base */
}

void fl_enc_palette(fl_encoder *e, const uint8_t *rgb)
{
    e->palette = rgb;
    e->want_palette = 0;
    fl_writer_message(&e->w, FL_MSG_PALETTE, next_frame_no(e), rgb, FL_PALETTE_BYTES);
    e->bytes = e->w.bytes;
}

static void window_push(fl_encoder *e, uint32_t frame_no)
{
    if (e->in_count == FL_WINDOW_MAX) { /* forget the oldest */
        e->in_head = (uint8_t)((e->in_head + 1) % FL_WINDOW_MAX);
        e->in_count--;
    }
    e->inflight[(e->in_head + e->in_count) % FL_WINDOW_MAX] = frame_no;
    e->in_count++;
}

/* Would this picture's coding overflow the scratch buffer? Judged from a
 * sample of its rows (fl_estimate_transitions) at 6 bits a transition (coded
 * frames measured at 0.7 to 3 bits a transition flat-shaded, 9 to 13
 * textured), only when the last frame went raw or filled a quarter of the
 * buffer: a frame that overflows anyway is sent raw after the attempt. */
/* Whether a picture is one for the COPY coding (textured) rather than the EDGE
 * coding (flat-shaded): its transitions, sampled, say the edge coding would
 * pass FL_EDGE_BYTES_MAX or the scratch buffer. A frame after a small edge-coded
 * one is taken for flat without the sample. */
#define FL_EDGE_BYTES_MAX 4096u
static int predict_copy(const fl_encoder *e, const uint8_t *pixels, const uint8_t *base, uint32_t cap)
{
    if (e->sent_any && e->last_coded && e->last_coded < cap / 4 && e->last_coded < FL_EDGE_BYTES_MAX / 4) return 0;
    uint32_t est = fl_estimate_transitions(pixels, base) / 8u * 6u;
    return est > cap || est > FL_EDGE_BYTES_MAX;
}

int fl_enc_frame(fl_encoder *e, uint32_t frame_no, const uint8_t *pixels, const uint8_t *base, uint32_t base_no,
                 const fl_frame_info *info)
{
    if (e->want_palette && e->palette) fl_enc_palette(e, e->palette);
    int key = !base || !e->sent_any || base_no != e->last_sent || e->force_key ||
              (e->key_interval && e->since_key + 1 >= e->key_interval);
    /* payload: info, flags, frame check, [base], method, picture */
    uint32_t pre = FL_FRAME_PRE + (key ? 0u : 4u) + 1u;
    uint32_t coded = 0, check = 0;
    if (e->scratch && e->scratch_bytes > pre) {
        uint32_t cap = e->scratch_bytes - pre;
        if (cap > FL_PAYLOAD_MAX - pre) cap = FL_PAYLOAD_MAX - pre;
        if (!predict_copy(e, pixels, key ? 0 : base, cap))
            coded = fl_code_picture(&e->coder, pixels, key ? 0 : base, e->scratch + pre, cap, &check);
    }
    e->last_coded = coded;
    uint8_t head[FL_FRAME_PRE + 5];
    fl_info_pack(head, info);
    head[FL_INFO_BYTES] = info->no_crc ? 0u : 1u;
    uint32_t k = FL_FRAME_PRE;
    if (!key) {
        fl_put32(head + k, base_no);
        k += 4;
    }
    if (coded) { /* flat-shaded: the edge coding, from the scratch buffer */
        fl_put32(head + FL_INFO_BYTES + 1, check);
        head[k] = FL_METHOD_EDGE;
        fl_writer_begin(&e->w, key ? FL_MSG_KEYFRAME : FL_MSG_DELTA, frame_no, pre + coded);
        fl_writer_bytes(&e->w, head, pre);
        fl_writer_bytes(&e->w, e->scratch + pre, coded);
    } else { /* textured: the copy coding, streamed, checked by the pixel hash */
        fl_put32(head + FL_INFO_BYTES + 1, fl_pixel_hash(pixels));
        head[k] = FL_METHOD_COPY;
        fl_writer_begin(&e->w, key ? FL_MSG_KEYFRAME : FL_MSG_DELTA, frame_no, FL_LEN_STREAMED);
        fl_writer_bytes(&e->w, head, pre);
        fl_copy_encode(&e->copy, pixels, key ? 0 : base, e->match_hash, &e->w);
        e->coder.hashes_valid = 0; /* the copy model took the edge coder's memory */
        e->copy_frames++;
    }
    fl_writer_end(&e->w);
    e->bytes = e->w.bytes;
    e->frames++;
    if (key) {
        e->keyframes++;
        e->last_key = frame_no;
        e->since_key = 0;
        e->force_key = 0;
    } else {
        e->deltas++;
        e->since_key++;
    }
    e->last_sent = frame_no;
    e->sent_any = 1;
    window_push(e, frame_no);
    return key ? FL_MSG_KEYFRAME : FL_MSG_DELTA;
}

static void on_ack(fl_encoder *e, uint32_t frame_no)
{
    e->acks++;
    while (e->in_count && (int32_t)(e->inflight[e->in_head] - frame_no) <= 0) {
        e->in_head = (uint8_t)((e->in_head + 1) % FL_WINDOW_MAX);
        e->in_count--;
    }
}

void fl_enc_receive(fl_encoder *e, const uint8_t *p, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        int r = fl_reader_byte(&e->rx, p[i]);
        if (r == 0) continue;
        fl_msg m;
        if (r < 0 || fl_msg_check(e->rx.buf, e->rx.len, &m) != FL_R_NONE || m.len != BACK_BYTES) {
            e->rx_bad++;
            continue;
        }
        if (m.type == FL_MSG_ACK) {
            on_ack(e, m.frame_no);
        } else if (m.type == FL_MSG_KEYREQ) {
            uint8_t flags = m.payload[0];
            if (flags & 2u) {
                e->palette_reqs++;
                e->want_palette = 1;
            }
            if (flags & 1u) {
                e->keyreqs++;
                /* a request about a frame before the last keyframe is answered by it */
                if (!e->sent_any || (int32_t)(m.frame_no - e->last_key) >= 0) e->force_key = 1;
            }
        } else {
            e->rx_bad++;
        }
    }
}

int fl_enc_may_send(fl_encoder *e, uint32_t now_ms)
{
    uint32_t win = e->window < 1 ? 1u : (e->window > FL_WINDOW_MAX ? FL_WINDOW_MAX : e->window);
    if (e->in_count < win) {
        e->stalled = 0;
        return 1;
    }
    if (!e->stalled) {
        e->stalled = 1;
        e->stall_since_ms = now_ms;
        return 0;
    }
    if (now_ms - e->stall_since_ms >= e->ack_timeout_ms) {
        /* the oldest frame's ack was lost (or the receiver is slow): give that one
         * frame up, not the window, so that a slow receiver is sent one frame
         * more per timeout, not a window more, and its backlog stays bounded */
        e->timeouts++;
        e->in_head = (uint8_t)((e->in_head + 1) % FL_WINDOW_MAX);
        e->in_count--;
        e->stalled = 0;
        return 1;
    }
    return 0;
}
