/* fuzz_link.c - libFuzzer harness for the frame link's receiver (hal/serial/,
 * docs/frame-link.md).
 *
 * Random bytes almost never get through COBS and the message CRC-32, so the first
 * input byte (mod 3) picks one of three ways to use the rest:
 *
 *   0 raw         [chunk knob u8][chunk seed u8][stream...]
 *                 the stream goes to fl_dec_feed as it is, in chunks whose sizes come
 *                 from a generator seeded by the two knob bytes (mutating the stream
 *                 does not move the chunk boundaries); the same bytes also go to the
 *                 encoder's back-channel reader (fl_enc_receive).
 *   1 framed      a sequence of messages, each
 *                   [ctl u8][frame u32 if ctl & 0x08][damage u16 pos, u8 xor if ctl & 0x80]
 *                   [len u16][payload: len bytes]
 *                 ctl & 7 is the type (7: the payload is a whole message body, header
 *                 included, to which only CRC and COBS are added); the harness frames
 *                 it with fl_writer (right header, CRC-32, COBS; a frame payload whose
 *                 method byte is COPY streamed, length field 0xFFFFFF, and its CRC, as a
 *                 RAW_HASH keyframe's, over the header and payload up to the method
 *                 byte), so arbitrary payloads reach the message handling and the picture
 *                 decoders (fl_decode_picture, fl_copy_decode). 0x10 "fix up" a frame
 *                 message: method (COPY if the method byte & 3 is 3; a padded raw-size
 *                 keyframe RAW_HASH if it is 2, else RAW; else edge), flags, the base
 *                 number of the frame shown, and the frame check and pixel CRC-32 of what
 *                 its picture decodes to (the harness's own call of the picture decoder),
 *                 after which the decoder must show that picture; 0x20 pad the payload
 *                 by repeating it: to a raw keyframe's size, or for a COPY picture with
 *                 as many bytes as the pixels its decoding stops at leave (the plain tail
 *                 of the escape); 0x40 with fix-up: no pixel CRC-32.
 *   2 round trip  [start frame number u32][scratch u16][key interval u8, | 16: the COPY
 *                 coder's match finder] then frames
 *                   [ctl u8][ctl & 7 drawing commands of 6 bytes]
 *                   [damage: u16 position from the end, u8 xor if ctl & 0x40]
 *                 up to MAX_RT frames drawn from commands (flat shapes, scrolling,
 *                 textures, noise), sent by fl_enc (keyframes and deltas, edge-coded or
 *                 COPY, the escape of noise), the receiver's acks and keyframe requests fed
 *                 back to the sender; ctl picks the base (the true previous frame, none,
 *                 a wrong one), a skipped frame number, no pixel CRC-32, line damage and
 *                 a HELLO; the first byte / 3 holds the global knobs: HELLO and palette
 *                 first, unaligned pixels, back channel connected, no acks, window.
 *
 * Checked on every event (abort() on failure):
 *   - a frame shown matches the frame check and, when sent, the pixel CRC-32 that its
 *     message promised (both computed here as docs/frame-link.md defines them, apart
 *     from fl_codec.c and firmware/crc32.c; the pixel hash for RAW_HASH and COPY); its
 *     message is intact (its CRC over the span section 2 says); a delta is shown only
 *     on the frame it names as base; the event's info is the message's; a raw
 *     keyframe shows its bytes, a fixed-up frame what the harness decoded; in the round
 *     trip, the frame shown is bit-exact the frame sent with its number;
 *   - a frame is dropped for a reason its message allows (no base: a delta off the
 *     frame shown; decode: a coded picture, edge or COPY, keyframe or delta on the
 *     frame shown; frame check: not a raw keyframe that passes its checks);
 *   - the frame buffer changes only when a frame is shown (compared with a shadow copy
 *     on every drop, at the end, and on the first few other events);
 *   - frames the harness knows to be good (fixed up with this file's frame check, or
 *     sent intact by the encoder onto the right base) are shown, so fl_frame_check and
 *     the encoder's check must agree with the definition; a raw keyframe that passes
 *     its checks is never dropped;
 *   - counters agree with the events (shown, dropped, bad, good, resyncs, hellos,
 *     palettes, keyframe and palette requests, acks), shown + dropped + missed spans
 *     the frame numbers of a session numbered upwards, bytes fed, good + bad =
 *     non-empty segments;
 *   - the round trip's encoder sends edge-coded pictures with their length and COPY
 *     ones streamed, never a raw fallback, and counts as COPY frames the COPY messages
 *     that arrive (all of them when nothing was damaged);
 *   - every message sent back is intact (decoded by this file's own COBS reader) and
 *     says what happened: an ack per frame message, a keyframe request exactly when
 *     section 6 says (the first drop, and again after window + 1 more), palette
 *     requests; after a keyframe request the sender's next frame is a keyframe.
 * The frame, work and picture buffers are exact-size malloc blocks, so ASan catches any
 * access outside them. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fl_internal.h"
#include "framelink.h"
#include "fuzz_util.h"

/* Decoding a frame costs the receiver a few milliseconds under the sanitizers and
 * libFuzzer's tracing: a few frames per input keep an execution fast. */
#define MAX_MSGS 24   /* framed: messages per input */
#define MAX_REBUILT 3 /* framed: frame messages per input that are decoded (more are left out) */
#define MAX_PADS 2    /* framed: 64 KB messages per input */
#define MAX_RT 2      /* round trip: frames per input (a keyframe and a delta) */
#define LINE_BYTES (2u * FL_MSG_MAX + 4096u)

/* ---- input cursor ---------------------------------------------------------------- */

typedef struct {
    const uint8_t *p;
    size_t n;
} cursor;

static int take(cursor *c, uint8_t *out, size_t k)
{
    if (c->n < k) return 0;
    memcpy(out, c->p, k);
    c->p += k;
    c->n -= k;
    return 1;
}

static uint32_t u8_or0(cursor *c)
{
    uint8_t b = 0;
    take(c, &b, 1);
    return b;
}

static uint32_t u16_or0(cursor *c)
{
    uint8_t b[2] = {0, 0};
    take(c, b, 2);
    return fl_get16(b);
}

static uint32_t u32_or0(cursor *c)
{
    uint8_t b[4] = {0, 0, 0, 0};
    take(c, b, 4);
    return fl_get32(b);
}

/* ---- the frame check, as docs/frame-link.md defines it (independent of fl_codec.c,
 * which it checks; the CRC-32 is fuzz_util.h's ref_crc) ----------------------------- */

UNTRACED static uint32_t ref_mix(uint32_t h)
{
    uint32_t g = h * 0x9E3779B1u;
    return g ^ (g >> 16);
}

UNTRACED static uint32_t ref_frame_check(const uint8_t *px)
{
    uint32_t f = 0;
    for (int y = 0; y < FL_H; y++) {
        const uint8_t *row = px + y * FL_W;
        uint32_t h = ref_mix(0x811C9DC5u ^ row[0]);
        for (uint32_t x = 1; x < FL_W; x++)
            if (row[x] != row[x - 1]) h = ref_mix(h ^ (x * 256u + row[x]));
        f = ref_mix(f ^ h);
    }
    f ^= f >> 16;
    f *= 0x85EBCA6Bu;
    f ^= f >> 13;
    f *= 0xC2B2AE35u;
    return f ^ (f >> 16);
}

/* ---- harness state ---------------------------------------------------------------- */

enum { EXPECT_ANY, EXPECT_SHOW, EXPECT_DROP };

typedef struct {
    fl_decoder *d;
    uint8_t *frame, *work, *shadow;
    int have_shown; /* the events' view: a frame shown since the last HELLO */
    uint32_t shown_no;

    uint32_t n_hello, n_palette, n_frame, n_drop, n_bad, n_keyreq, n_other;

    /* back channel, decoded by our own COBS reader */
    uint8_t back_seg[64];
    uint32_t back_len;
    int back_overrun;
    uint32_t back_ack_shown, back_ack_dropped, back_keyreq, back_palreq;
    fl_encoder *back_to; /* round trip: the sender that hears the receiver */

    /* a session numbered upwards: shown + dropped + missed spans its frame numbers */
    int sess_any, sess_up;
    uint32_t sess_first, sess_last, sess_base;

    /* the message being fed (framed, round trip) */
    int expect;
    fl_reason expect_reason;
    const uint8_t *expect_px; /* EXPECT_SHOW after a fix-up: the picture the frame must be */
    uint32_t copy_msgs;       /* intact frame messages of method COPY (shown or dropped) */
    int keyreq_since_frame;   /* a keyframe request went back since the last frame was sent */
    uint32_t spot_checks;

    /* what docs/frame-link.md, section 6, says the receiver does next */
    int last_bad; /* a bad segment since the last good message */
    uint32_t resyncs;
    int waiting_key; /* a keyframe was asked for and has not come */
    uint32_t waiting_drops, window;
    int keyreq_due; /* the drop just reported must be followed by a request */
    int have_palette;
    uint32_t palette_wait, palreqs;
    int ack_pending; /* the ack of the frame message being handled went back */
    uint32_t ack_no, ack_status, keyreq_no;

    /* round trip: the frames sent, by number */
    uint32_t sent_n;
    uint32_t sent_no[MAX_RT];
    uint8_t *sent_px[MAX_RT];
} harness;

static uint8_t *g_frame, *g_work, *g_shadow, *g_pic, *g_pic2, *g_payload, *g_line;
static uint8_t *g_page_a[2], *g_page_u[2], *g_wrong, *g_sent[MAX_RT];
static fl_decoder *g_dec;
static fl_encoder *g_enc;
static fl_coder *g_coder;
static fl_copy_model *g_copy;
static int32_t *g_match; /* the COPY coder's match finder (FL_CP_HASH entries) */
static uint32_t g_line_len;

static void setup_once(void)
{
    if (g_dec) return;
    /* exact sizes: ASan reports any access outside what the API says it may touch */
    g_frame = fuzz_alloc(FL_FRAME_BYTES);
    g_work = fuzz_alloc(FL_DEC_WORK_BYTES);
    g_shadow = fuzz_alloc(FL_FRAME_BYTES);
    g_pic = fuzz_alloc(FL_FRAME_BYTES);
    g_pic2 = fuzz_alloc(FL_FRAME_BYTES);
    g_payload = fuzz_alloc(FL_PAYLOAD_MAX + 64);
    g_line = fuzz_alloc(LINE_BYTES);
    for (int i = 0; i < 2; i++) {
        g_page_a[i] = fuzz_alloc(FL_FRAME_BYTES);
        g_page_u[i] = fuzz_alloc(FL_FRAME_BYTES + 1);
    }
    g_wrong = fuzz_alloc(FL_FRAME_BYTES);
    for (int i = 0; i < MAX_RT; i++) g_sent[i] = fuzz_alloc(FL_FRAME_BYTES);
    g_dec = fuzz_alloc(sizeof *g_dec);
    g_enc = fuzz_alloc(sizeof *g_enc);
    g_coder = fuzz_alloc(sizeof *g_coder);
    g_copy = fuzz_alloc(sizeof *g_copy);
    g_match = fuzz_alloc(FL_CP_HASH * sizeof *g_match);
}

UNTRACED static int frame_unchanged(const harness *h)
{
    return memcmp(h->frame, h->shadow, FL_FRAME_BYTES) == 0;
}

/* The same on events that can come by the thousand (garbage): the first few per input,
 * so that an execution stays fast; drops and the end are always checked. */
static void spot_check_unchanged(harness *h)
{
    if (h->spot_checks >= 32) return;
    h->spot_checks++;
    REQUIRE(frame_unchanged(h));
}

static void counters_agree(const harness *h)
{
    const fl_counters *k = &h->d->count;
    REQUIRE(k->frames_shown == h->n_frame);
    REQUIRE(k->frames_dropped == h->n_drop);
    REQUIRE(k->msgs_bad == h->n_bad);
    REQUIRE(k->hellos == h->n_hello);
    REQUIRE(k->palettes == h->n_palette);
    REQUIRE(k->keyreqs_sent == h->n_keyreq);
    REQUIRE(k->msgs_ok == h->n_hello + h->n_palette + h->n_frame + h->n_drop + h->n_other);
    REQUIRE(k->resyncs == h->resyncs);
    REQUIRE(k->acks_sent == (h->d->send_acks ? h->n_frame + h->n_drop : 0u));
}

static void session_start(harness *h)
{
    const fl_counters *k = &h->d->count;
    h->sess_any = 0;
    h->sess_up = 1;
    h->sess_base = k->frames_shown + k->frames_dropped + k->frames_missed;
}

/* A frame message passed its layout checks (shown or dropped). */
static void session_frame(harness *h, uint32_t no)
{
    const fl_counters *k = &h->d->count;
    if (!h->sess_any) {
        h->sess_any = 1;
        h->sess_first = h->sess_last = no;
    } else if ((int32_t)(no - h->sess_last) > 0) {
        h->sess_last = no;
    } else {
        h->sess_up = 0; /* repeated or older numbers: the identity no longer holds */
    }
    if (h->sess_up)
        REQUIRE(k->frames_shown + k->frames_dropped + k->frames_missed - h->sess_base ==
                h->sess_last - h->sess_first + 1u);
}

/* The message the decoder is handling: still in its reassembly buffer. */
typedef struct {
    uint8_t type;
    uint32_t frame_no;
    const uint8_t *pl;
    uint32_t plen;
    uint32_t pre; /* info, flags, check, [base], method */
    uint8_t flags, method;
    int streamed; /* length field 0xFFFFFF: the payload runs to the CRC */
    uint32_t check, crc, base_no;
} frame_msg;

/* The RAW_HASH frame check, written from docs/frame-link.md. */
static uint32_t ref_pixel_hash(const uint8_t *px)
{
    uint32_t h = 0x811C9DC5u;
    for (uint32_t i = 0; i < FL_FRAME_BYTES; i += 4) {
        uint32_t w = (uint32_t)px[i] | (uint32_t)px[i + 1] << 8 | (uint32_t)px[i + 2] << 16 | (uint32_t)px[i + 3] << 24;
        h = (w ^ (h >> 19 | h << 13)) * 0x9E3779B1u;
    }
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    h *= 0xC2B2AE35u;
    return h ^ (h >> 16);
}

/* The check a frame message carries, of these pixels: the pixel hash for the methods
 * whose pictures the message CRC leaves out (RAW_HASH, COPY), else the frame check. */
static uint32_t ref_check_of(uint8_t method, const uint8_t *px)
{
    return method == FL_METHOD_RAW_HASH || method == FL_METHOD_COPY ? ref_pixel_hash(px) : ref_frame_check(px);
}

static int is_raw_method(uint8_t method)
{
    return method == FL_METHOD_RAW || method == FL_METHOD_RAW_HASH;
}

/* The message's layout, as docs/frame-link.md, section 2, has it (apart from
 * fl_framing.c): a KEYFRAME or DELTA whose length field is 0xFFFFFF, with at least one
 * picture byte and method COPY, is streamed (its payload runs to the CRC); its CRC, and
 * that of a RAW_HASH keyframe of exactly 64,000 pixel bytes, covers the header and the
 * payload up to the method byte; any other message's covers all but the CRC. */
static void current_frame_msg(const harness *h, frame_msg *m)
{
    const uint8_t *b = h->d->rx.buf;
    uint32_t len = h->d->rx.len;
    REQUIRE(len >= FL_HEADER_BYTES + FL_CRC_BYTES);
    m->type = b[1];
    REQUIRE(m->type == FL_MSG_KEYFRAME || m->type == FL_MSG_DELTA);
    m->pre = FL_FRAME_PRE + (m->type == FL_MSG_DELTA ? 4u : 0u) + 1u;
    uint32_t field = (uint32_t)b[6] | (uint32_t)b[7] << 8 | (uint32_t)b[8] << 16;
    uint32_t mpre = FL_HEADER_BYTES + m->pre; /* header, info, flags, check, [base], method */
    uint8_t mb = len >= mpre ? b[mpre - 1] : 0xFFu;
    m->streamed = field == 0xFFFFFFu && len > mpre + FL_CRC_BYTES && mb == FL_METHOD_COPY;
    int raw_hash = m->type == FL_MSG_KEYFRAME && len == mpre + FL_FRAME_BYTES + FL_CRC_BYTES &&
                   mb == FL_METHOD_RAW_HASH;
    REQUIRE(ref_crc(b, raw_hash || m->streamed ? mpre : len - FL_CRC_BYTES) == fl_get32(b + len - FL_CRC_BYTES));
    REQUIRE(b[0] == FL_VERSION);
    uint32_t plen = m->streamed ? len - FL_HEADER_BYTES - FL_CRC_BYTES : field;
    REQUIRE(plen == len - FL_HEADER_BYTES - FL_CRC_BYTES && plen <= FL_PAYLOAD_MAX);
    m->frame_no = fl_get32(b + 2);
    m->pl = b + FL_HEADER_BYTES;
    m->plen = plen;
    REQUIRE(plen >= m->pre);
    m->flags = m->pl[FL_INFO_BYTES];
    REQUIRE((m->flags & ~1u) == 0);
    m->check = fl_get32(m->pl + FL_INFO_BYTES + 1);
    m->crc = fl_get32(m->pl + 22);
    m->base_no = m->type == FL_MSG_DELTA ? fl_get32(m->pl + FL_FRAME_PRE) : 0;
    m->method = m->pl[m->pre - 1];
    REQUIRE(m->method <= FL_METHOD_COPY);
    if (is_raw_method(m->method)) REQUIRE(m->type == FL_MSG_KEYFRAME && plen == m->pre + FL_FRAME_BYTES);
    /* round trip: the encoder sends edge-coded pictures with their length, COPY streamed */
    if (h->sent_n) REQUIRE(m->method == FL_METHOD_COPY ? m->streamed : m->method == FL_METHOD_EDGE && !m->streamed);
}

/* The ack of a frame message goes back before its event. */
static void check_ack(harness *h, uint32_t no, uint32_t status)
{
    if (!h->d->send_acks) return;
    REQUIRE(h->ack_pending && h->ack_no == no && h->ack_status == status);
    h->ack_pending = 0;
}

static void on_frame(harness *h, const fl_event *ev)
{
    frame_msg m;
    current_frame_msg(h, &m);
    REQUIRE(ev->type == m.type && ev->frame_no == m.frame_no);
    REQUIRE(ev->keyframe == (m.type == FL_MSG_KEYFRAME));

    /* shown only if it passed every check it carries */
    uint32_t crc = ref_crc(h->frame, FL_FRAME_BYTES);
    REQUIRE(ref_check_of(m.method, h->frame) == m.check);
    if (m.flags & 1u) REQUIRE(crc == m.crc);
    if (is_raw_method(m.method)) REQUIRE(memcmp(h->frame, m.pl + m.pre, FL_FRAME_BYTES) == 0);
    if (m.type == FL_MSG_DELTA) REQUIRE(h->have_shown && m.base_no == h->shown_no);
    /* fixed up: what the harness's own call of the picture decoder made of it */
    if (h->expect == EXPECT_SHOW && h->expect_px) REQUIRE(memcmp(h->frame, h->expect_px, FL_FRAME_BYTES) == 0);

    /* what the event says */
    fl_frame_info want;
    fl_info_unpack(&want, m.pl);
    REQUIRE(ev->info.x == want.x && ev->info.y == want.y && ev->info.z == want.z);
    REQUIRE(ev->info.angle == want.angle && ev->info.look == want.look);
    REQUIRE(ev->info.mode == want.mode && ev->info.present == want.present);
    REQUIRE(ev->info.crc == crc && ev->info.no_crc == !(m.flags & 1u));
    REQUIRE(h->d->have_frame && h->d->shown_no == m.frame_no);

    /* round trip: the very frame sent with that number */
    if (h->sent_n) {
        uint32_t i = 0;
        while (i < h->sent_n && h->sent_no[i] != m.frame_no) i++;
        REQUIRE(i < h->sent_n);
        REQUIRE(memcmp(h->frame, h->sent_px[i], FL_FRAME_BYTES) == 0);
    }
    REQUIRE(h->expect != EXPECT_DROP);
    h->expect = EXPECT_ANY;
    h->expect_px = NULL;
    h->copy_msgs += m.method == FL_METHOD_COPY;

    memcpy(h->shadow, h->frame, FL_FRAME_BYTES);
    h->have_shown = 1;
    h->shown_no = m.frame_no;
    session_frame(h, m.frame_no);
    check_ack(h, m.frame_no, 0);
    h->waiting_key = 0; /* a frame shown ends the wait */
    if (!h->have_palette && h->palette_wait++ % 64u == 0) h->palreqs++;
}

static void on_drop(harness *h, const fl_event *ev)
{
    frame_msg m;
    current_frame_msg(h, &m);
    REQUIRE(ev->type == m.type && ev->frame_no == m.frame_no);
    REQUIRE(frame_unchanged(h));
    int on_base = h->have_shown && m.base_no == h->shown_no;
    switch (ev->reason) {
    case FL_R_NO_BASE: REQUIRE(m.type == FL_MSG_DELTA && !on_base); break;
    case FL_R_DECODE:
        /* coded pictures only (edge, COPY), keyframes or deltas on the frame shown */
        REQUIRE((m.method == FL_METHOD_EDGE || m.method == FL_METHOD_COPY) && (m.type == FL_MSG_KEYFRAME || on_base));
        break;
    case FL_R_FRAME_CRC:
        REQUIRE(m.type == FL_MSG_KEYFRAME || on_base);
        if (is_raw_method(m.method)) {
            /* a raw keyframe is its own reconstruction: dropped only if it fails a check */
            const uint8_t *px = m.pl + m.pre;
            REQUIRE(ref_check_of(m.method, px) != m.check || ((m.flags & 1u) && ref_crc(px, FL_FRAME_BYTES) != m.crc));
        }
        break;
    default: REQUIRE(0);
    }
    REQUIRE(h->expect != EXPECT_SHOW);
    if (h->expect == EXPECT_DROP) REQUIRE(ev->reason == h->expect_reason);
    h->expect = EXPECT_ANY;
    h->expect_px = NULL;
    h->copy_msgs += m.method == FL_METHOD_COPY;
    session_frame(h, m.frame_no);
    check_ack(h, m.frame_no, 1);
    /* ask for a keyframe once; again after more than window + 1 further drops */
    if (!h->waiting_key || ++h->waiting_drops > h->window + 1u) {
        h->waiting_key = 1;
        h->waiting_drops = 0;
        h->keyreq_due = 1;
    }
}

static void on_event(void *ctx, const fl_event *ev)
{
    harness *h = ctx;
    REQUIRE(!h->keyreq_due || ev->kind == FL_EV_KEYREQ);
    if (ev->kind != FL_EV_BAD && ev->kind != FL_EV_KEYREQ) {
        h->resyncs += (uint32_t)h->last_bad;
        h->last_bad = 0;
    }
    switch (ev->kind) {
    case FL_EV_HELLO:
        h->n_hello++;
        REQUIRE(ev->type == FL_MSG_HELLO);
        h->have_shown = 0; /* a new session: the old frame is no base */
        h->waiting_key = 0;
        h->window = ev->hello.window ? ev->hello.window : 4u;
        REQUIRE(!h->d->have_frame);
        spot_check_unchanged(h);
        session_start(h);
        break;
    case FL_EV_PALETTE:
        h->n_palette++;
        h->have_palette = 1;
        REQUIRE(ev->type == FL_MSG_PALETTE && ev->palette);
        REQUIRE(h->d->rx.len == FL_HEADER_BYTES + FL_PALETTE_BYTES + FL_CRC_BYTES);
        REQUIRE(memcmp(ev->palette, h->d->rx.buf + FL_HEADER_BYTES, FL_PALETTE_BYTES) == 0);
        spot_check_unchanged(h);
        break;
    case FL_EV_FRAME:
        h->n_frame++;
        on_frame(h, ev);
        break;
    case FL_EV_DROP:
        h->n_drop++;
        on_drop(h, ev);
        break;
    case FL_EV_BAD:
        h->n_bad++;
        h->last_bad = 1;
        REQUIRE(ev->reason >= FL_R_FRAMING && ev->reason <= FL_R_PAYLOAD);
        spot_check_unchanged(h);
        break;
    case FL_EV_KEYREQ:
        h->n_keyreq++;
        h->keyreq_since_frame = 1;
        REQUIRE(h->keyreq_due && ev->frame_no == h->keyreq_no);
        h->keyreq_due = 0;
        break;
    case FL_EV_OTHER:
        h->n_other++;
        REQUIRE(ev->type == FL_MSG_ACK || ev->type == FL_MSG_KEYREQ);
        spot_check_unchanged(h);
        break;
    default: REQUIRE(0);
    }
    counters_agree(h);
}

/* One COBS segment of the back channel: it must be an intact ACK or KEYREQ. */
static void back_message(harness *h, const uint8_t *seg, uint32_t n)
{
    uint8_t m[64];
    uint32_t len = 0, i = 0;
    while (i < n) {
        uint32_t code = seg[i++];
        REQUIRE(code != 0 && i + code - 1 <= n);
        for (uint32_t k = 1; k < code; k++) m[len++] = seg[i++];
        if (code != 0xFF && i < n) m[len++] = 0;
    }
    REQUIRE(len == FL_HEADER_BYTES + 5 + FL_CRC_BYTES);
    REQUIRE(ref_crc(m, len - FL_CRC_BYTES) == fl_get32(m + len - FL_CRC_BYTES));
    REQUIRE(m[0] == FL_VERSION && m[6] == 5 && m[7] == 0 && m[8] == 0);
    uint32_t no = fl_get32(m + 2), showing = fl_get32(m + FL_HEADER_BYTES + 1);
    uint8_t b0 = m[FL_HEADER_BYTES];
    if (m[1] == FL_MSG_ACK) {
        /* sent before the frame's event: the harness still has the old state */
        REQUIRE(b0 <= 1 && !h->ack_pending);
        h->ack_pending = 1;
        h->ack_no = no;
        h->ack_status = b0;
        if (b0 == 0) {
            h->back_ack_shown++;
            REQUIRE(showing == no);
        } else {
            h->back_ack_dropped++;
            REQUIRE(showing == (h->have_shown ? h->shown_no : 0xFFFFFFFFu));
        }
    } else {
        REQUIRE(m[1] == FL_MSG_KEYREQ);
        REQUIRE(b0 == 1 || b0 == 3 || b0 == 2);
        if (b0 & 1u) {
            h->back_keyreq++;
            h->keyreq_no = no;
        } else {
            h->back_palreq++;
        }
        REQUIRE(!!(b0 & 2u) == !h->d->have_palette || !(b0 & 1u));
        /* sent after the event of the frame it is about */
        REQUIRE(showing == (h->have_shown ? h->shown_no : 0xFFFFFFFFu));
    }
}

static void back_put(void *ctx, const uint8_t *p, uint32_t n)
{
    harness *h = ctx;
    for (uint32_t i = 0; i < n; i++) {
        if (p[i] == 0) {
            REQUIRE(h->back_len > 0 && !h->back_overrun);
            back_message(h, h->back_seg, h->back_len);
            h->back_len = 0;
        } else if (h->back_len < sizeof h->back_seg) {
            h->back_seg[h->back_len++] = p[i];
        } else {
            h->back_overrun = 1;
        }
    }
    if (h->back_to) fl_enc_receive(h->back_to, p, n);
}

static void harness_init(harness *h, int send_acks)
{
    memset(h, 0, sizeof *h);
    h->d = g_dec;
    h->frame = g_frame;
    h->work = g_work;
    h->shadow = g_shadow;
    /* start from known contents: the decoder must not depend on what was there before,
     * and the run must not depend on the previous input */
    memset(g_frame, 0x5A, FL_FRAME_BYTES);
    memset(g_shadow, 0x5A, FL_FRAME_BYTES);
    memset(g_work, 0xA5, FL_DEC_WORK_BYTES);
    fl_dec_init(h->d, g_frame, g_work, on_event, h, back_put, h);
    h->d->send_acks = (uint8_t)send_acks;
    h->window = 4;
    session_start(h);
}

static void feed(harness *h, const uint8_t *p, uint32_t n)
{
    fl_dec_feed(h->d, p, n);
}

static void harness_end(harness *h, uint32_t fed, uint32_t frame_msgs)
{
    const fl_counters *k = &h->d->count;
    counters_agree(h);
    REQUIRE(frame_unchanged(h));
    REQUIRE(k->bytes == fed);
    REQUIRE(k->frames_shown + k->frames_dropped <= frame_msgs);
    REQUIRE(h->back_len == 0); /* every message sent back was finished */
    REQUIRE(h->back_ack_shown == (h->d->send_acks ? k->frames_shown : 0u));
    REQUIRE(h->back_ack_dropped == (h->d->send_acks ? k->frames_dropped : 0u));
    REQUIRE(h->back_keyreq == k->keyreqs_sent);
    REQUIRE(h->back_palreq == k->palreqs_sent);
    REQUIRE(k->palreqs_sent == h->palreqs);
    REQUIRE(!h->keyreq_due && !h->ack_pending);
    REQUIRE(h->d->have_frame == h->have_shown);
    if (h->have_shown) REQUIRE(h->d->shown_no == h->shown_no);
}

/* ---- mode 0: raw bytes ---------------------------------------------------------- */

static void run_raw(cursor *c)
{
    harness h;
    harness_init(&h, 1);
    uint32_t knob = u8_or0(c), seed = u8_or0(c) * 0x01000193u + 1u;
    uint32_t fed = 0, segments = 0;
    int started = 0;
    for (size_t i = 0; i < c->n; i++) {
        if (c->p[i])
            started = 1;
        else if (started)
            segments++, started = 0;
    }
    while (c->n) {
        uint32_t k = knob ? 1u + xorshift(&seed) % (knob * 8u) : (uint32_t)c->n;
        if (k > c->n) k = (uint32_t)c->n;
        feed(&h, c->p, k);
        fed += k;
        c->p += k;
        c->n -= k;
    }
    harness_end(&h, fed, segments);
    REQUIRE(h.d->count.msgs_ok + h.d->count.msgs_bad == segments);
}

/* The sender's back-channel reader takes the same outside bytes. */
static void run_raw_sender(const uint8_t *p, size_t n)
{
    fl_encoder *e = g_enc;
    fl_enc_init(e, NULL, NULL, NULL, 0);
    fl_enc_receive(e, p, (uint32_t)n);
    REQUIRE(e->in_count == 0 && e->frames == 0);
    REQUIRE(fl_enc_may_send(e, 0));
}

/* ---- mode 1: messages framed by the harness ------------------------------------- */

static void line_put(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)ctx;
    REQUIRE(g_line_len + n <= LINE_BYTES);
    memcpy(g_line + g_line_len, p, n);
    g_line_len += n;
}

static uint32_t frame_pre(uint32_t type)
{
    return FL_FRAME_PRE + (type == FL_MSG_DELTA ? 4u : 0u) + 1u; /* info, flags, check, [base], method */
}

/* A picture decoder run by the harness, on an exact-size copy of the picture bytes (ASan
 * catches a read past them; in the receiver they are followed by more of its work
 * memory). Returns what the decoder returns. */
static int harness_decode(uint8_t method, const uint8_t *pic, uint32_t n, const uint8_t *base, uint8_t *out)
{
    uint8_t *in = fuzz_copy_exact(pic, n);
    int r = method == FL_METHOD_COPY ? fl_copy_decode(g_copy, in, n, base, out)
                                     : fl_decode_picture(g_coder, in, n, base, out);
    free(in);
    return r;
}

/* The pixel a COPY picture's decoding stops at (64,000: it reached the end), found
 * from two decodings into outputs that start out different: the pixels before it are
 * decoded alike, the one it stops at is not written. At the escape, the decoder wants
 * exactly the picture's remaining pixels after the coded bytes. */
static uint32_t copy_stop(const uint8_t *pic, uint32_t n, const uint8_t *base)
{
    memset(g_pic, 0x00, FL_FRAME_BYTES);
    memset(g_pic2, 0xFF, FL_FRAME_BYTES);
    harness_decode(FL_METHOD_COPY, pic, n, base, g_pic);
    harness_decode(FL_METHOD_COPY, pic, n, base, g_pic2);
    uint32_t i = 0;
    while (i < FL_FRAME_BYTES && g_pic[i] == g_pic2[i]) i++;
    return i;
}

/* The pad of a COPY frame message: the picture bytes given are taken for a coding that
 * ends in the escape, and are followed by as many plain pixels as it leaves (repeating
 * them), so that arbitrary coded prefixes reach the escape's plain tail. Returns the
 * payload's new length. */
static uint32_t copy_pad(const harness *h, uint32_t type, uint8_t *pl, uint32_t n)
{
    uint32_t pre = frame_pre(type);
    if (type == FL_MSG_DELTA && !h->have_shown) return n; /* no base to decode against */
    uint32_t tail = FL_FRAME_BYTES - copy_stop(pl + pre, n - pre, type == FL_MSG_DELTA ? h->shadow : NULL);
    if (n + tail > FL_PAYLOAD_MAX) return n;
    for (uint32_t i = 0; i < tail; i++) pl[n + i] = n > pre ? pl[pre + i % (n - pre)] : 0u;
    return n + tail;
}

/* Make a frame message's payload pass: method, flags, base, and the check and CRC of
 * what the picture decodes to. Sets what the decoder must then do. The method: COPY if
 * the payload's method byte & 3 is 3; a keyframe padded to a raw keyframe's size goes
 * RAW_HASH if it is 2, else RAW; anything else edge-coded. */
static void fix_up(harness *h, uint8_t type, uint8_t *pl, uint32_t n, int pad, int no_crc)
{
    uint32_t pre = frame_pre(type);
    if (n < pre) return;
    uint8_t mb = pl[pre - 1] & 3u;
    int raw = pad && type == FL_MSG_KEYFRAME && n == pre + FL_FRAME_BYTES && mb != FL_METHOD_COPY;
    uint8_t method = mb == FL_METHOD_COPY ? FL_METHOD_COPY
                     : raw                ? (mb == FL_METHOD_RAW_HASH ? FL_METHOD_RAW_HASH : FL_METHOD_RAW)
                                          : FL_METHOD_EDGE;
    pl[FL_INFO_BYTES] = no_crc ? 0u : 1u;
    pl[pre - 1] = method;
    if (type == FL_MSG_DELTA && h->have_shown) fl_put32(pl + FL_FRAME_PRE, h->shown_no);
    const uint8_t *px = pl + pre;
    if (type == FL_MSG_DELTA && !h->have_shown) {
        h->expect = EXPECT_DROP;
        h->expect_reason = FL_R_NO_BASE;
        return;
    }
    if (!raw) {
        if (harness_decode(method, pl + pre, n - pre, type == FL_MSG_DELTA ? h->shadow : NULL, g_pic)) {
            h->expect = EXPECT_DROP;
            h->expect_reason = FL_R_DECODE;
            return;
        }
        px = g_pic;
    }
    fl_put32(pl + FL_INFO_BYTES + 1, ref_check_of(method, px));
    fl_put32(pl + 22, ref_crc(px, FL_FRAME_BYTES));
    h->expect = EXPECT_SHOW;
    h->expect_px = px;
}

/* A frame message as a sender writes it (docs/frame-link.md, section 2): a COPY
 * picture streamed (length field 0xFFFFFF), a RAW_HASH keyframe's pixels and a COPY
 * picture outside the message CRC (fl_writer_direct, from an exact-size copy). */
static void write_frame_msg(fl_writer *w, uint8_t type, uint32_t frame_no, const uint8_t *pl, uint32_t n)
{
    uint32_t pre = frame_pre(type);
    uint8_t mb = n >= pre ? pl[pre - 1] : 0xFFu;
    int streamed = n > pre && mb == FL_METHOD_COPY;
    int raw_hash = type == FL_MSG_KEYFRAME && n == pre + FL_FRAME_BYTES && mb == FL_METHOD_RAW_HASH;
    if (!streamed && !raw_hash) {
        fl_writer_message(w, type, frame_no, pl, n);
        return;
    }
    fl_writer_begin(w, type, frame_no, streamed ? FL_LEN_STREAMED : n);
    fl_writer_bytes(w, pl, pre);
    uint8_t *pic = fuzz_copy_exact(pl + pre, n - pre);
    fl_writer_direct(w, pic, n - pre);
    free(pic);
    fl_writer_end(w);
}

static void run_framed(cursor *c)
{
    harness h;
    harness_init(&h, 1);
    fl_writer w;
    uint32_t fed = 0, frame_msgs = 0, rebuilt = 0, frame_no = 0, pads = 0;
    for (int msg = 0; msg < MAX_MSGS && c->n; msg++) {
        uint32_t ctl = u8_or0(c), type = ctl & 7u;
        if (ctl & 0x08u)
            frame_no = u32_or0(c);
        else
            frame_no++;
        uint32_t dpos = 0, dxor = 0;
        if (ctl & 0x80u) {
            dpos = u16_or0(c);
            dxor = u8_or0(c);
        }
        uint32_t n = u16_or0(c);
        if (n > c->n) n = (uint32_t)c->n;
        memcpy(g_payload, c->p, n);
        c->p += n;
        c->n -= n;

        int is_frame = type == FL_MSG_KEYFRAME || type == FL_MSG_DELTA ||
                       (type == 7u && n >= 2 && (g_payload[1] == FL_MSG_KEYFRAME || g_payload[1] == FL_MSG_DELTA));
        /* deltas without their base are cheap (dropped before decoding): only the
         * frames the receiver rebuilds are limited */
        int on_base = type == FL_MSG_DELTA && h.have_shown &&
                      ((ctl & 0x10u) || (n >= FL_FRAME_PRE + 4u && fl_get32(g_payload + FL_FRAME_PRE) == h.shown_no));
        int costly = is_frame && (type != FL_MSG_DELTA || on_base);
        if (costly && rebuilt >= MAX_REBUILT) continue;
        rebuilt += (uint32_t)costly;
        int pad = (ctl & 0x20u) && pads < MAX_PADS;
        int frame_type = type == FL_MSG_KEYFRAME || type == FL_MSG_DELTA;
        /* a COPY picture (the method byte that fix-up or the writer takes for COPY) */
        int copy = frame_type && n >= frame_pre(type) &&
                   ((ctl & 0x10u) ? (g_payload[frame_pre(type) - 1] & 3u) == FL_METHOD_COPY
                                  : g_payload[frame_pre(type) - 1] == FL_METHOD_COPY);
        h.expect = EXPECT_ANY;
        h.expect_px = NULL;
        if (pad && copy) {
            n = copy_pad(&h, type, g_payload, n); /* the escape's plain tail */
            pads++;
        } else if (pad) {
            /* a raw keyframe's size (a delta's: one no receiver takes); for a whole body,
             * the largest message, or one byte more */
            uint32_t want = type == 7u ? FL_MSG_MAX - FL_CRC_BYTES + (n & 1u)
                                       : FL_FRAME_PRE + 1u + FL_FRAME_BYTES + (type == FL_MSG_DELTA ? 4u : 0u);
            for (uint32_t i = n; i < want; i++) g_payload[i] = n ? g_payload[i % n] : 0;
            n = want;
            pads++;
        }
        if ((ctl & 0x10u) && frame_type) fix_up(&h, (uint8_t)type, g_payload, n, pad, ctl & 0x40u);
        frame_msgs += (uint32_t)is_frame;

        g_line_len = 0;
        fl_writer_init(&w, line_put, NULL);
        if (type == 7u) {
            fl_writer_bytes(&w, g_payload, n);
            fl_writer_end(&w);
        } else if (frame_type) {
            write_frame_msg(&w, (uint8_t)type, frame_no, g_payload, n);
        } else {
            fl_writer_message(&w, (uint8_t)type, frame_no, g_payload, n);
        }
        REQUIRE(w.bytes == g_line_len && g_line[g_line_len - 1] == 0);
        if (dxor) {
            g_line[dpos % g_line_len] ^= (uint8_t)dxor;
            h.expect = EXPECT_ANY;
            h.expect_px = NULL;
        }
        feed(&h, g_line, g_line_len);
        fed += g_line_len;
        REQUIRE(h.expect == EXPECT_ANY); /* what was expected happened */
    }
    harness_end(&h, fed, frame_msgs);
}

/* ---- mode 2: encoder -> decoder ------------------------------------------------- */

static void clip_box(int *x0, int *y0, int *x1, int *y1)
{
    if (*x0 < 0) *x0 = 0;
    if (*y0 < 0) *y0 = 0;
    if (*x1 > FL_W) *x1 = FL_W;
    if (*y1 > FL_H) *y1 = FL_H;
}

/* A texel of a 16 x 16 texture: a ramp of 16 colours from col, chosen by a hash of the
 * texel and col (as textures are: the same texel wherever the texture repeats). */
UNTRACED static inline uint8_t texel(uint32_t u, uint32_t v, uint8_t col)
{
    uint32_t t = ((u & 15u) | (v & 15u) << 4 | (uint32_t)col << 8) * 0x9E3779B1u;
    return (uint8_t)(col + ((t ^ t >> 15) >> 12 & 15u));
}

/* One drawing command: flat-shaded shapes, noise, scrolling (edges that move), and
 * textured and noisy pictures (which the encoder sends with the COPY coding). */
UNTRACED static void draw(uint8_t *px, const uint8_t *op, uint32_t *rng)
{
    int a = op[1], b = op[2], cc = op[3], dd = op[4];
    uint8_t col = op[5];
    int x0 = a * FL_W / 256, y0 = b * FL_H / 256;
    uint32_t kind = op[0] & 15u;
    switch (kind > 9u ? kind & 7u : kind) {
    case 0: { /* rectangle */
        int x1 = x0 + cc + 1, y1 = y0 + dd + 1;
        clip_box(&x0, &y0, &x1, &y1);
        for (int y = y0; y < y1; y++) memset(px + y * FL_W + x0, col, (size_t)(x1 - x0));
        break;
    }
    case 1: { /* a slanted wall: both sides move by a slope per row */
        int slope = (int8_t)cc, h = dd * FL_H / 256 + 1;
        for (int y = y0; y < y0 + h && y < FL_H; y++) {
            int l = x0 + slope * (y - y0) / 8, r = l + 8 + dd - slope * (y - y0) / 16;
            if (l < 0) l = 0;
            if (r > FL_W) r = FL_W;
            if (l < r) memset(px + y * FL_W + l, col, (size_t)(r - l));
        }
        break;
    }
    case 2: { /* noise from a few colours */
        int x1 = x0 + cc / 2 + 1, y1 = y0 + dd / 2 + 1;
        clip_box(&x0, &y0, &x1, &y1);
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) px[y * FL_W + x] = (uint8_t)(xorshift(rng) & col);
        break;
    }
    case 3: { /* horizontal scroll */
        int dx = (int8_t)a % FL_W;
        for (int y = 0; y < FL_H; y++) {
            uint8_t *row = px + y * FL_W;
            if (dx > 0) {
                memmove(row + dx, row, (size_t)(FL_W - dx));
                memset(row, col, (size_t)dx);
            } else if (dx < 0) {
                memmove(row, row - dx, (size_t)(FL_W + dx));
                memset(row + FL_W + dx, col, (size_t)-dx);
            }
        }
        break;
    }
    case 4: { /* vertical scroll */
        int dy = (int8_t)b % FL_H;
        if (dy > 0) {
            memmove(px + dy * FL_W, px, (size_t)(FL_H - dy) * FL_W);
            memset(px, col, (size_t)dy * FL_W);
        } else if (dy < 0) {
            memmove(px, px - dy * FL_W, (size_t)(FL_H + dy) * FL_W);
            memset(px + (FL_H + dy) * FL_W, col, (size_t)-dy * FL_W);
        }
        break;
    }
    case 5: /* columns: a transition every few pixels, up to one at every pixel */
        for (int y = y0; y < FL_H && y < y0 + dd + 1; y++)
            for (int x = x0; x < FL_W; x += 1 + cc % 16) px[y * FL_W + x] = (uint8_t)(col + (x & 1));
        break;
    case 6: /* the whole frame */ memset(px, col, FL_FRAME_BYTES); break;
    case 8: { /* a textured wall from (x0, y0) to the right edge, dd * 200 / 256 + 1 rows: a
               * texture of texels 1 + (cc & 7) wide, 1 + (cc >> 3 & 7) high, whose width
               * grows by one pixel every 64 columns if cc & 64 (a wall seen at an angle) */
        int sx = 1 + (cc & 7), sy = 1 + (cc >> 3 & 7), y1 = y0 + dd * FL_H / 256 + 1;
        if (y1 > FL_H) y1 = FL_H;
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < FL_W; x++) {
                int w = sx + ((cc & 64) ? (x - x0) / 64 : 0);
                px[y * FL_W + x] = texel((uint32_t)((x - x0) / w), (uint32_t)((y - y0) / sy), col);
            }
        break;
    }
    case 9: { /* noise from a few colours over (cc + 1) * 320 / 256 by (dd + 1) * 200 / 256
               * pixels (all of them: 255, 255): random bytes (col 255) make the COPY
               * coding give up (its escape) */
        int x1 = x0 + (cc + 1) * FL_W / 256, y1 = y0 + (dd + 1) * FL_H / 256;
        clip_box(&x0, &y0, &x1, &y1);
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) px[y * FL_W + x] = (uint8_t)(xorshift(rng) >> 7 & col);
        break;
    }
    default: { /* a diamond */
        int r = cc / 2;
        for (int y = y0 - r; y <= y0 + r; y++) {
            if (y < 0 || y >= FL_H) continue;
            int w = r - (y > y0 ? y - y0 : y0 - y), l = x0 - w, rr = x0 + w + 1;
            if (l < 0) l = 0;
            if (rr > FL_W) rr = FL_W;
            if (l < rr) memset(px + y * FL_W + l, col, (size_t)(rr - l));
        }
        break;
    }
    }
}

static void run_round_trip(cursor *c, uint32_t knobs)
{
    int hello0 = knobs & 1u, palette0 = knobs & 2u, unaligned = knobs & 4u, connected = knobs & 8u;
    int send_acks = !(knobs & 16u);
    uint32_t window = (knobs >> 5) & 3u; /* 0: the default */
    harness h;
    harness_init(&h, send_acks);
    uint32_t no = u32_or0(c), scratch_bytes = u16_or0(c) % 16384u, kb = u8_or0(c), key_interval = kb % 16u;
    if (scratch_bytes == 0) scratch_bytes = 8192;
    uint8_t *scratch = fuzz_alloc(scratch_bytes);
    uint8_t palette[FL_PALETTE_BYTES];
    for (uint32_t i = 0; i < FL_PALETTE_BYTES; i++) palette[i] = (uint8_t)(i * 7u + no);

    fl_encoder *e = g_enc;
    fl_enc_init(e, line_put, NULL, scratch, scratch_bytes);
    e->key_interval = key_interval;
    if (kb & 16u) e->match_hash = g_match; /* the COPY coder's match finder (hosts) */
    if (window) e->window = (uint8_t)window;
    h.back_to = connected ? e : NULL;

    uint8_t *page[2];
    for (int i = 0; i < 2; i++) page[i] = unaligned ? g_page_u[i] + 1 : g_page_a[i];
    memset(page[1], 0, FL_FRAME_BYTES);

    uint32_t fed = 0, rng = no | 1u, prev_no = 0, sent = 0, keys = 0;
    int prev_tail_damaged = 0, damaged = 0;
    g_line_len = 0;
    if (hello0) fl_enc_hello(e);
    if (palette0) fl_enc_palette(e, palette);
    for (uint32_t i = 0; i < MAX_RT && c->n; i++) {
        uint32_t ctl = u8_or0(c), base_mode = (ctl >> 3) & 3u;
        uint8_t *px = page[i & 1u], *prev = page[(i + 1u) & 1u];
        memcpy(px, prev, FL_FRAME_BYTES);
        for (uint32_t k = 0; k < (ctl & 7u); k++) {
            uint8_t op[6] = {0, 0, 0, 0, 0, 0};
            if (!take(c, op, sizeof op)) break;
            draw(px, op, &rng);
        }
        uint32_t dpos = 0, dxor = 0;
        if (ctl & 0x40u) {
            dpos = u16_or0(c);
            dxor = u8_or0(c);
        }
        if (ctl & 0x80u) fl_enc_hello(e);

        uint32_t frame_no = i ? prev_no + 1u + (base_mode == 3u) : no;
        const uint8_t *base = prev;
        if (i == 0 || base_mode == 1u) {
            base = NULL;
        } else if (base_mode == 2u) {
            /* pixels that are not what was sent before: the receiver must not show a
             * wrong frame built on them */
            memcpy(g_wrong, prev, FL_FRAME_BYTES);
            for (uint32_t x = 0; x < FL_W; x++) g_wrong[(i * 37u % FL_H) * FL_W + x] ^= 0x55u;
            base = g_wrong;
        }
        fl_frame_info info;
        memset(&info, 0, sizeof info);
        info.x = (int32_t)xorshift(&rng);
        info.y = (int32_t)xorshift(&rng);
        info.z = (int32_t)(frame_no * 41u);
        info.angle = (int32_t)(xorshift(&rng) % (360u << 16));
        info.look = (int32_t)(xorshift(&rng) % 201u) - 100;
        info.mode = (uint8_t)(ctl & 1u);
        info.present = (uint8_t)(ctl >> 1 & 3u);
        info.no_crc = (uint8_t)((ctl >> 5) & 1u);
        /* without the pixel CRC-32 the field is not looked at: send garbage in it */
        info.crc = info.no_crc ? xorshift(&rng) : ref_crc(px, FL_FRAME_BYTES);

        memcpy(g_sent[i], px, FL_FRAME_BYTES);
        h.sent_px[i] = g_sent[i];
        h.sent_no[i] = frame_no;
        h.sent_n = i + 1;

        int keyreq = connected && h.keyreq_since_frame;
        int type = fl_enc_frame(e, frame_no, px, base, prev_no, &info);
        REQUIRE(type == FL_MSG_KEYFRAME || type == FL_MSG_DELTA);
        if (keyreq || !base || (ctl & 0x80u)) REQUIRE(type == FL_MSG_KEYFRAME);
        keys += type == FL_MSG_KEYFRAME;
        sent++;
        h.keyreq_since_frame = 0;

        /* intact, and not run together with damage before it: the receiver must show
         * it unless it is a delta on a base the receiver does not have or that was not
         * what was sent */
        int intact = !dxor && !prev_tail_damaged;
        int good_base = base == prev && h.have_shown && h.shown_no == prev_no;
        h.expect = intact && (type == FL_MSG_KEYFRAME || good_base) ? EXPECT_SHOW : EXPECT_ANY;
        if (dxor) { /* counted from the end: the frame message is the last thing sent */
            dpos = g_line_len - 1u - dpos % g_line_len;
            g_line[dpos] ^= (uint8_t)dxor;
        }
        prev_tail_damaged = dxor && dpos == g_line_len - 1u;
        damaged |= dxor != 0;
        feed(&h, g_line, g_line_len);
        fed += g_line_len;
        REQUIRE(h.expect == EXPECT_ANY);
        if (connected && h.keyreq_since_frame) REQUIRE(e->force_key); /* heard: the next is a keyframe */
        g_line_len = 0;
        /* flow control: an intact frame's ack empties the window; a full window's
         * oldest frame is given up after the timeout, and one more frame may go */
        uint32_t now = i * 20u, timeouts = e->timeouts, in_flight = e->in_count;
        if (!fl_enc_may_send(e, now)) {
            REQUIRE(!(connected && send_acks && intact));
            REQUIRE(e->in_count >= e->window);
            REQUIRE(!fl_enc_may_send(e, now + e->ack_timeout_ms - 1u));
            REQUIRE(fl_enc_may_send(e, now + e->ack_timeout_ms));
            REQUIRE(e->timeouts == timeouts + 1u && e->in_count == in_flight - 1u);
        }
        prev_no = frame_no;
    }
    if (g_line_len) { /* a hello or palette with no frame after it */
        feed(&h, g_line, g_line_len);
        fed += g_line_len;
        g_line_len = 0;
    }
    harness_end(&h, fed, sent);
    REQUIRE(e->frames == sent && e->keyframes == keys && e->deltas == sent - keys);
    /* textured and noisy frames go COPY, never raw; every COPY frame message sent arrives
     * (its method byte is under the CRC: no damage makes one of another) */
    REQUIRE(e->raw_fallbacks == 0 && e->copy_frames <= sent);
    REQUIRE(damaged ? h.copy_msgs <= e->copy_frames : h.copy_msgs == e->copy_frames);
    if (connected) {
        REQUIRE(e->rx_bad == 0);
        REQUIRE(e->acks == h.back_ack_shown + h.back_ack_dropped);
        REQUIRE(e->keyreqs == h.back_keyreq);
    }
    free(scratch);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    setup_once();
    cursor c = {data + 1, size - 1};
    switch (data[0] % 3u) {
    case 0:
        run_raw_sender(data + 1, size - 1);
        run_raw(&c);
        break;
    case 1: run_framed(&c); break;
    default: run_round_trip(&c, data[0] / 3u); break;
    }
    return 0;
}
