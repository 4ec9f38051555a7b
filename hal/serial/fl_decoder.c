/* fl_decoder.c - the receiving end of the frame link: reassembles messages from
 * bytes in any chunking, checks them, rebuilds keyframes and deltas (a delta
 * only onto the exact base frame it names), checks the rebuilt frame against
 * its CRC-32 before showing it, counts everything, and answers with acks and
 * keyframe requests. docs/frame-link.md, "Receiver". */
#include "crc32.h"
#include "fl_internal.h"

#define BACK_BYTES 5

void fl_dec_init(fl_decoder *d, uint8_t *frame, uint8_t *work, fl_event_fn on_event, void *ev_ctx, fl_put_fn back_put,
                 void *back_ctx)
{
    uint8_t *p = (uint8_t *)d;
    for (uint32_t i = 0; i < sizeof *d; i++) p[i] = 0;
    d->frame = frame;
    d->recon = work + FL_MSG_MAX;
    fl_reader_init(&d->rx, work, FL_MSG_MAX);
    d->on_event = on_event;
    d->ev_ctx = ev_ctx;
    fl_writer_init(&d->back, back_put, back_ctx);
    d->send_acks = 1;
    d->want_crc = 1;
    d->window = 4;
}

void fl_dec_init_pages(fl_decoder *d, uint8_t *page0, uint8_t *page1, uint8_t *work, fl_event_fn on_event, void *ev_ctx,
                       fl_put_fn back_put, void *back_ctx)
{
    fl_dec_init(d, page0, work, on_event, ev_ctx, back_put, back_ctx);
    d->recon = page1;
    d->flip = 1;
}

static void emit(fl_decoder *d, fl_event *ev)
{
    if (d->on_event) d->on_event(d->ev_ctx, ev);
}

static void event0(fl_event *ev, fl_event_kind k)
{
    uint8_t *p = (uint8_t *)ev;
    for (uint32_t i = 0; i < sizeof *ev; i++) p[i] = 0;
    ev->kind = k;
}

static void send_back(fl_decoder *d, uint8_t type, uint32_t frame_no, uint8_t b0)
{
    uint8_t pl[BACK_BYTES];
    pl[0] = b0;
    fl_put32(pl + 1, d->have_frame ? d->shown_no : 0xFFFFFFFFu);
    fl_writer_message(&d->back, type, frame_no, pl, BACK_BYTES);
}

/* A frame could not be shown for want of a good base: ask for a keyframe, once,
 * and again only if the keyframe has not come after more than a window of
 * frames (the request or the keyframe may have been lost). */
static void want_key(fl_decoder *d, uint32_t frame_no)
{
    if (d->waiting_key && ++d->waiting_drops <= (uint32_t)d->window + 1u) return;
    d->waiting_key = 1;
    d->waiting_drops = 0;
    d->count.keyreqs_sent++;
    send_back(d, FL_MSG_KEYREQ, frame_no, (uint8_t)(1u | (d->have_palette ? 0u : 2u)));
    fl_event ev;
    event0(&ev, FL_EV_KEYREQ);
    ev.frame_no = frame_no;
    emit(d, &ev);
}

static void bad(fl_decoder *d, fl_reason why)
{
    d->count.msgs_bad++;
    d->last_bad = 1;
    fl_event ev;
    event0(&ev, FL_EV_BAD);
    ev.reason = why;
    emit(d, &ev);
}

/* A message that passed every check; the first after bad ones is a resync. */
static void good(fl_decoder *d)
{
    d->count.msgs_ok++;
    if (d->last_bad) d->count.resyncs++;
    d->last_bad = 0;
}

static void frame_msg(fl_decoder *d, const fl_msg *m)
{
    int key = m->type == FL_MSG_KEYFRAME;
    uint32_t pre = FL_FRAME_PRE + (key ? 0u : 4u) + 1u;
    if (m->len < pre) {
        bad(d, FL_R_PAYLOAD);
        return;
    }
    fl_frame_info info;
    fl_info_unpack(&info, m->payload);
    uint8_t flags = m->payload[FL_INFO_BYTES];
    info.no_crc = (uint8_t) !(flags & 1u);
    uint32_t check = fl_get32(m->payload + FL_INFO_BYTES + 1);
    uint8_t method = m->payload[pre - 1];
    uint32_t base_no = key ? 0 : fl_get32(m->payload + FL_FRAME_PRE);
    const uint8_t *pic = m->payload + pre;
    uint32_t n = m->len - pre;
    int raw = method == FL_METHOD_RAW || method == FL_METHOD_RAW_HASH;
    if ((flags & ~1u) || method > FL_METHOD_COPY || (raw && (!key || n != FL_FRAME_BYTES))) {
        bad(d, FL_R_PAYLOAD);
        return;
    }
    good(d);

    /* frame numbers never seen (lost in damaged messages) */
    if (d->have_seen && (int32_t)(m->frame_no - d->seen_no) > 0) d->count.frames_missed += m->frame_no - d->seen_no - 1;
    if (!d->have_seen || (int32_t)(m->frame_no - d->seen_no) > 0) d->seen_no = m->frame_no;
    d->have_seen = 1;

    fl_reason why = FL_R_NONE;
    if (!key && !(d->have_frame && base_no == d->shown_no)) {
        why = FL_R_NO_BASE;
    } else if (raw) {
        for (uint32_t i = 0; i < FL_FRAME_BYTES; i++) d->recon[i] = pic[i];
    } else if (method == FL_METHOD_COPY) {
        if (fl_copy_decode(&d->copy, pic, n, key ? 0 : d->frame, d->recon)) why = FL_R_DECODE;
    } else if (fl_decode_picture(&d->coder, pic, n, key ? 0 : d->frame, d->recon)) {
        why = FL_R_DECODE;
    }
    if (why == FL_R_NONE) {
        /* end to end: the frame check always, the pixel CRC-32 when it was sent */
        uint32_t got = method == FL_METHOD_RAW_HASH || method == FL_METHOD_COPY ? fl_pixel_hash(d->recon)
                                                                                : fl_frame_check(d->recon);
        uint32_t crc = !info.no_crc || d->want_crc ? crc_update(0, d->recon, FL_FRAME_BYTES) : 0u;
        if (got != check || (!info.no_crc && crc != info.crc))
            why = FL_R_FRAME_CRC;
        else
            info.crc = crc;
    }

    fl_event ev;
    if (why == FL_R_NONE) {
        /* shown: it passed every check */
        if (d->flip) {
            uint8_t *shown = d->recon;
            d->recon = d->frame;
            d->frame = shown;
        } else {
            for (uint32_t i = 0; i < FL_FRAME_BYTES; i++) d->frame[i] = d->recon[i];
        }
        d->have_frame = 1;
        d->shown_no = m->frame_no;
        d->shown_info = info;
        d->waiting_key = 0;
        d->count.frames_shown++;
        if (d->send_acks) {
            send_back(d, FL_MSG_ACK, m->frame_no, 0);
            d->count.acks_sent++;
        }
        event0(&ev, FL_EV_FRAME);
        ev.keyframe = (uint8_t)key;
    } else {
        d->count.frames_dropped++;
        if (d->send_acks) {
            send_back(d, FL_MSG_ACK, m->frame_no, 1);
            d->count.acks_sent++;
        }
        event0(&ev, FL_EV_DROP);
        ev.reason = why;
    }
    ev.type = m->type;
    ev.frame_no = m->frame_no;
    ev.info = info;
    emit(d, &ev);
    if (why != FL_R_NONE)
        want_key(d, m->frame_no);
    else if (!d->have_palette && !d->waiting_key) {
        /* frames but no palette: ask for it (once per keyframe interval of frames) */
        if (d->palette_wait++ % 64u == 0) {
            d->count.palreqs_sent++;
            send_back(d, FL_MSG_KEYREQ, m->frame_no, 2);
        }
    }
}

/* A HELLO's payload into h: the capabilities alone (a sender from before scene
 * names: no scene), or with the scene, whose name must have the length it
 * says, at most FL_SCENE_NAME_MAX, all printable. Returns 0, or -1 if invalid. */
static int hello_unpack(fl_hello *h, const uint8_t *p, uint32_t n)
{
    if (n != FL_HELLO_CAPS &&
        (n < FL_HELLO_MIN || n != FL_HELLO_MIN + (uint32_t)p[FL_HELLO_CAPS + 4] || n > FL_HELLO_MAX))
        return -1;
    uint32_t len = n == FL_HELLO_CAPS ? 0 : n - FL_HELLO_MIN;
    for (uint32_t i = 0; i < len; i++)
        if (!fl_name_char_ok(p[FL_HELLO_MIN + i])) return -1;
    h->version = p[0];
    h->width = (uint16_t)fl_get16(p + 1);
    h->height = (uint16_t)fl_get16(p + 3);
    h->gun_bits = p[5];
    h->key_interval = (uint16_t)fl_get16(p + 6);
    h->window = p[8];
    h->methods = p[9];
    h->scene_crc = n == FL_HELLO_CAPS ? 0 : fl_get32(p + FL_HELLO_CAPS);
    for (uint32_t i = 0; i < len; i++) h->scene_name[i] = (char)p[FL_HELLO_MIN + i];
    h->scene_name[len] = '\0';
    return 0;
}

/* By bytes: a struct copy this size becomes a memcpy call, and the targets link no libc. */
static void hello_copy(fl_hello *to, const fl_hello *from)
{
    uint8_t *t = (uint8_t *)to;
    const uint8_t *f = (const uint8_t *)from;
    for (uint32_t i = 0; i < sizeof *to; i++) t[i] = f[i];
}

static void message(fl_decoder *d, const uint8_t *buf, uint32_t len)
{
    fl_msg m;
    fl_reason why = fl_msg_check(buf, len, &m);
    if (why != FL_R_NONE) {
        bad(d, why);
        return;
    }
    fl_event ev;
    switch (m.type) {
    case FL_MSG_HELLO:
        if (hello_unpack(&d->hello, m.payload, m.len)) break;
        good(d);
        d->count.hellos++;
        d->have_hello = 1;
        d->window = d->hello.window ? d->hello.window : 4;
        /* a new session: frame numbers start again, the old frame is no base */
        d->have_frame = 0;
        d->have_seen = 0;
        d->waiting_key = 0;
        event0(&ev, FL_EV_HELLO);
        ev.type = m.type;
        ev.frame_no = m.frame_no;
        hello_copy(&ev.hello, &d->hello);
        emit(d, &ev);
        return;
    case FL_MSG_PALETTE:
        if (m.len != FL_PALETTE_BYTES) break;
        good(d);
        d->count.palettes++;
        for (uint32_t i = 0; i < FL_PALETTE_BYTES; i++) d->palette[i] = m.payload[i];
        d->have_palette = 1;
        event0(&ev, FL_EV_PALETTE);
        ev.type = m.type;
        ev.frame_no = m.frame_no;
        ev.palette = d->palette;
        emit(d, &ev);
        return;
    case FL_MSG_KEYFRAME:
    case FL_MSG_DELTA: frame_msg(d, &m); return;
    case FL_MSG_ACK:
    case FL_MSG_KEYREQ:
        if (m.len != BACK_BYTES) break;
        good(d);
        event0(&ev, FL_EV_OTHER);
        ev.type = m.type;
        ev.frame_no = m.frame_no;
        emit(d, &ev);
        return;
    default: bad(d, FL_R_TYPE); return;
    }
    bad(d, FL_R_PAYLOAD);
}

void fl_dec_feed(fl_decoder *d, const uint8_t *p, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        d->count.bytes++;
        int r = fl_reader_byte(&d->rx, p[i]);
        if (r == 0) continue;
        if (r < 0)
            bad(d, (fl_reason)-r);
        else
            message(d, d->rx.buf, d->rx.len);
    }
}
