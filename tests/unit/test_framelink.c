/* test_framelink.c - the frame link (hal/serial): round trips of keyframes and
 * deltas on real frames (a walk through freedoom2.wad:MAP01 rendered by the
 * engine on the null target, the previous frame on the other VRAM page as the
 * base, as on the target) and on synthetic extremes; any chunking of the byte
 * stream; fault injection (bit flips, dropped and inserted bytes, truncated
 * messages at 1e-5..1e-2 per byte, both directions, hundreds of frames) with
 * the invariant that no frame shown differs from the frame sent with its
 * number; resynchronisation, counters, keyframe requests, the flow-control
 * window, the raw fallback, a delta against the wrong base, garbage input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bspc.h"
#include "crc32.h"
#include "engine.h"
#include "fl_internal.h"
#include "framelink.h"
#include "hal.h"
#include "hal_null.h"

#define NF 48 /* frames of the walk */

static uint8_t *walk; /* NF frames */
static uint32_t walk_crc[NF];
static fl_frame_info walk_info[NF];

/* ---- helpers -------------------------------------------------------------- */

static uint32_t rng_state = 1;
static uint32_t rnd(void)
{
    uint32_t x = rng_state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    return rng_state = x;
}

typedef struct {
    uint8_t *p;
    size_t len, cap;
} buf;

static void buf_put(void *ctx, const uint8_t *p, uint32_t n)
{
    buf *b = ctx;
    if (b->len + n > b->cap) {
        b->cap = (b->len + n) * 2 + 1024;
        b->p = realloc(b->p, b->cap);
    }
    memcpy(b->p + b->len, p, n);
    b->len += n;
}

/* What the decoder did, for comparisons and invariants. */
typedef struct {
    fl_decoder *d;
    const uint32_t *sent_crc; /* by frame number */
    uint32_t nsent;
    uint32_t shown, dropped, keyreqs, bad, wrong;
    int have_first;
    uint32_t first_seen, last_seen, last_shown;
    uint32_t log_hash; /* of every event's kind, frame number and reason */
} watch;

static void on_event(void *ctx, const fl_event *ev)
{
    watch *w = ctx;
    w->log_hash = (w->log_hash ^ (uint32_t)ev->kind) * 16777619u;
    w->log_hash = (w->log_hash ^ ev->frame_no) * 16777619u;
    w->log_hash = (w->log_hash ^ (uint32_t)ev->reason) * 16777619u;
    if (ev->kind == FL_EV_FRAME || ev->kind == FL_EV_DROP) {
        if (!w->have_first) w->first_seen = ev->frame_no;
        w->have_first = 1;
        w->last_seen = ev->frame_no;
    }
    switch (ev->kind) {
    case FL_EV_FRAME: {
        w->shown++;
        w->last_shown = ev->frame_no;
        uint32_t crc = crc_update(0, w->d->frame, FL_FRAME_BYTES);
        /* the frame shown is the frame sent with that number, bit for bit */
        if (ev->frame_no >= w->nsent || crc != w->sent_crc[ev->frame_no] || crc != ev->info.crc) w->wrong++;
        break;
    }
    case FL_EV_DROP: w->dropped++; break;
    case FL_EV_KEYREQ: w->keyreqs++; break;
    case FL_EV_BAD: w->bad++; break;
    default: break;
    }
}

typedef struct {
    fl_decoder dec;
    uint8_t frame[FL_FRAME_BYTES];
    uint8_t work[FL_DEC_WORK_BYTES];
    watch w;
    buf back;
} receiver;

static receiver *receiver_new(const uint32_t *sent_crc, uint32_t nsent)
{
    receiver *r = calloc(1, sizeof *r);
    r->w.d = &r->dec;
    r->w.sent_crc = sent_crc;
    r->w.nsent = nsent;
    r->w.log_hash = 2166136261u;
    fl_dec_init(&r->dec, r->frame, r->work, on_event, &r->w, buf_put, &r->back);
    return r;
}

static void receiver_free(receiver *r)
{
    free(r->back.p);
    free(r);
}

/* Frame accounting: every frame number from the first seen to the last seen is
 * shown, dropped, or missed (lost in a damaged message). */
static void check_accounting(const receiver *r)
{
    const fl_counters *c = &r->dec.count;
    assert_int_equal(r->w.wrong, 0);
    assert_int_equal(c->frames_shown, r->w.shown);
    assert_int_equal(c->frames_dropped, r->w.dropped);
    assert_int_equal(c->keyreqs_sent, r->w.keyreqs);
    assert_int_equal(c->msgs_bad, r->w.bad);
    if (r->w.have_first)
        assert_int_equal(c->frames_shown + c->frames_dropped + c->frames_missed, r->w.last_seen - r->w.first_seen + 1);
}

static fl_frame_info info_for(const uint8_t *px, uint32_t k)
{
    fl_frame_info i;
    memset(&i, 0, sizeof i);
    i.x = (int32_t)(k * 65536u);
    i.y = -(int32_t)k;
    i.z = 41 << 16;
    i.angle = (int32_t)(k * 1000u);
    i.look = (int32_t)(k % 7) - 3;
    i.mode = (uint8_t)(k & 1);
    i.present = (uint8_t)(k % 4);
    i.crc = crc_update(0, px, FL_FRAME_BYTES);
    return i;
}

/* ---- the walk ------------------------------------------------------------- */

static int setup(void **state)
{
    (void)state;
    uint8_t *blob;
    size_t len;
    char err[512];
    bspc_options opt = bspc_defaults();
    if (bspc_compile("freedoom2.wad:MAP01", &opt, &blob, &len, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    static engine e;
    hal_null_reset();
    if (eng_init(&e, blob, (uint32_t)len, NULL) != SCENE_OK) return -1;
    /* flat colours: runs and deltas the codec's paths all take (textured frames
     * are mostly raw runs; make bench-link measures those) */
    e.flat = 1;
    uint32_t need = eng_work_bytes(&e);
    void *work = malloc(need);
    if (eng_set_work(&e, work, need)) return -1;
    walk = malloc((size_t)NF * FL_FRAME_BYTES);
    for (int k = 0; k < NF; k++) {
        /* forward, with turns and a look up and down: edges that move, appear and end */
        uint32_t keys = HAL_KEY_FORWARD;
        if (k >= 12 && k < 20) keys |= HAL_KEY_TURN_LEFT;
        if (k >= 30 && k < 34) keys |= HAL_KEY_LOOK_UP;
        if (k >= 36 && k < 44) keys |= HAL_KEY_TURN_RIGHT | HAL_KEY_STRAFE_LEFT;
        eng_step(&e, keys, 50);
        /* flip mode: the frame just drawn is shown, the one before is on the other page */
        assert_true(hal_shown_page() == hal_target_vram(hal_target_display_start()));
        if (k)
            assert_memory_equal(hal_target_vram(1 - hal_target_display_start()),
                                walk + (size_t)(k - 1) * FL_FRAME_BYTES, FL_FRAME_BYTES);
        memcpy(walk + (size_t)k * FL_FRAME_BYTES, hal_shown_page(), FL_FRAME_BYTES);
        const camera *c = &e.cam.view;
        walk_info[k] = info_for(hal_shown_page(), (uint32_t)k);
        walk_info[k].x = c->x;
        walk_info[k].y = c->y;
        walk_info[k].z = c->z;
        walk_info[k].angle = c->angle_deg;
        walk_info[k].look = c->look;
        walk_crc[k] = walk_info[k].crc;
    }
    free(work);
    free(blob);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    free(walk);
    return 0;
}

static const uint8_t *wf(uint32_t k)
{
    return walk + (size_t)(k % NF) * FL_FRAME_BYTES;
}

/* ---- tests -------------------------------------------------------------- */

/* Encode the walk with keyframes every key_interval; the stream in out. */
static void encode_walk(buf *out, uint32_t key_interval, uint32_t *keys)
{
    static fl_encoder enc;
    static uint8_t scratch[16384];
    fl_enc_init(&enc, buf_put, out, scratch, sizeof scratch);
    enc.key_interval = key_interval;
    fl_enc_hello(&enc);
    fl_enc_palette(&enc, hal_get_palette());
    for (uint32_t k = 0; k < NF; k++) {
        int t = fl_enc_frame(&enc, k, wf(k), k ? wf(k - 1) : NULL, k - 1, &walk_info[k]);
        assert_true(t == FL_MSG_KEYFRAME || t == FL_MSG_DELTA);
        assert_int_equal(t == FL_MSG_KEYFRAME, k == 0 || (key_interval && k % key_interval == 0));
    }
    assert_int_equal(enc.frames, NF);
    assert_int_equal(enc.raw_fallbacks, 0);
    if (keys) *keys = enc.keyframes;
}

static void test_walk_round_trip(void **state)
{
    (void)state;
    for (uint32_t ki = 0; ki <= 16; ki += 8) {
        buf s = {0};
        uint32_t keys;
        encode_walk(&s, ki, &keys);
        receiver *r = receiver_new(walk_crc, NF);
        fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
        check_accounting(r);
        const fl_counters *c = &r->dec.count;
        assert_int_equal(c->frames_shown, NF);
        assert_int_equal(c->msgs_ok, NF + 2);
        assert_int_equal(c->msgs_bad, 0);
        assert_int_equal(c->hellos, 1);
        assert_int_equal(c->palettes, 1);
        assert_int_equal(c->bytes, s.len);
        assert_int_equal(c->acks_sent, NF);
        assert_memory_equal(r->frame, wf(NF - 1), FL_FRAME_BYTES);
        assert_memory_equal(r->dec.palette, hal_get_palette(), FL_PALETTE_BYTES);
        /* the information arrives as sent */
        assert_int_equal(r->dec.shown_info.x, walk_info[NF - 1].x);
        assert_int_equal(r->dec.shown_info.angle, walk_info[NF - 1].angle);
        assert_int_equal(r->dec.shown_info.look, walk_info[NF - 1].look);
        assert_int_equal(r->dec.shown_info.crc, walk_crc[NF - 1]);
        /* flat-shaded frames are small: well under the 570 bytes a frame that
         * 20 frames per second at 115,200 baud allow */
        print_message("key interval %u: %u keyframes, %.1f bytes per frame\n", ki, keys, (double)s.len / NF);
        assert_true(s.len / NF < 570);
        receiver_free(r);
        free(s.p);
    }
}

static void test_any_chunking(void **state)
{
    (void)state;
    buf s = {0};
    encode_walk(&s, 16, NULL);
    uint32_t ref_hash = 0;
    for (int mode = 0; mode < 7; mode++) {
        receiver *r = receiver_new(walk_crc, NF);
        static const uint32_t sizes[] = {1, 2, 3, 7, 255, 4096};
        size_t off = 0;
        rng_state = 77;
        while (off < s.len) {
            size_t n = mode < 6 ? sizes[mode] : 1 + rnd() % 600;
            if (n > s.len - off) n = s.len - off;
            fl_dec_feed(&r->dec, s.p + off, (uint32_t)n);
            off += n;
        }
        check_accounting(r);
        assert_int_equal(r->dec.count.frames_shown, NF);
        if (mode == 0) ref_hash = r->w.log_hash;
        assert_int_equal(r->w.log_hash, ref_hash);
        receiver_free(r);
    }
    free(s.p);
}

/* Damage bytes at rate 1/per: kind 0 flips a bit, 1 drops the byte, 2 inserts a
 * random byte, 3 cuts a run of up to 40 bytes (a truncated message), 4 any. */
static void damage(const uint8_t *in, size_t n, buf *out, uint32_t per, int kind)
{
    out->len = 0;
    for (size_t i = 0; i < n; i++) {
        if (per && rnd() % per == 0) {
            int k = kind == 4 ? (int)(rnd() % 4) : kind;
            uint8_t b = in[i];
            if (k == 0) {
                b ^= (uint8_t)(1u << (rnd() % 8));
                buf_put(out, &b, 1);
            } else if (k == 1) {
                /* dropped */
            } else if (k == 2) {
                uint8_t x = (uint8_t)rnd();
                buf_put(out, &x, 1);
                buf_put(out, &b, 1);
            } else {
                i += rnd() % 40;
            }
            continue;
        }
        buf_put(out, &in[i], 1);
    }
}

/* A live link over a noisy line, both ways: the sender reacts to acks and
 * keyframe requests. Frames 0..nframes-1 (the walk, round and round), the last
 * `clean` of them over a clean line. */
static void noisy_link(uint32_t per, int kind, uint32_t nframes, uint32_t clean, uint32_t seed, fl_counters *out_counts,
                       uint32_t *out_keyframes)
{
    static fl_encoder enc;
    static uint8_t scratch[16384];
    uint32_t *sent = calloc(nframes, sizeof *sent);
    for (uint32_t k = 0; k < nframes; k++) sent[k] = walk_crc[k % NF];
    buf fwd = {0}, noisy = {0};
    receiver *r = receiver_new(sent, nframes);
    fl_enc_init(&enc, buf_put, &fwd, scratch, sizeof scratch);
    enc.key_interval = 0; /* keyframes only when asked: the requests must do the work */
    rng_state = seed;
    fl_enc_hello(&enc);
    fl_enc_palette(&enc, hal_get_palette());
    for (uint32_t k = 0; k < nframes; k++) {
        uint32_t p = k + clean >= nframes ? 0 : per;
        fl_frame_info info = walk_info[k % NF];
        fl_enc_frame(&enc, k, wf(k), k ? wf(k - 1) : NULL, k - 1, &info);
        damage(fwd.p, fwd.len, &noisy, p, kind);
        fwd.len = 0;
        fl_dec_feed(&r->dec, noisy.p, (uint32_t)noisy.len);
        damage(r->back.p, r->back.len, &noisy, p, kind);
        r->back.len = 0;
        fl_enc_receive(&enc, noisy.p, (uint32_t)noisy.len);
    }
    check_accounting(r);
    /* after the noise, the link recovers: the last frame is shown */
    assert_int_equal(r->w.last_shown, nframes - 1);
    assert_memory_equal(r->frame, wf(nframes - 1), FL_FRAME_BYTES);
    *out_counts = r->dec.count;
    *out_keyframes = enc.keyframes;
    /* the sender heard the receiver */
    assert_true(enc.acks > 0);
    receiver_free(r);
    free(fwd.p);
    free(noisy.p);
    free(sent);
}

/* Page flipping (fl_dec_init_pages, the display board's decoder): fed the same
 * damaged stream, it sends the same events and counts the same as the copying
 * decoder, shows exactly the same frames, each in the page that was hidden
 * until then, and never writes the page on show while a frame is rebuilt. */
static void test_page_flipping(void **state)
{
    (void)state;
    buf s = {0}, d = {0};
    encode_walk(&s, 16, NULL);
    rng_state = 4242;
    damage(s.p, s.len, &d, 3000, 4);
    receiver *ref = receiver_new(walk_crc, NF);
    fl_dec_feed(&ref->dec, d.p, (uint32_t)d.len);

    receiver *r = receiver_new(walk_crc, NF);
    uint8_t *pages = malloc(2u * FL_FRAME_BYTES);
    memset(pages, 0x5A, 2u * FL_FRAME_BYTES);
    uint8_t *msg = malloc(FL_DEC_PAGES_WORK_BYTES);
    fl_dec_init_pages(&r->dec, pages, pages + FL_FRAME_BYTES, msg, on_event, &r->w, buf_put, &r->back);
    assert_ptr_equal(r->dec.frame, pages);
    uint32_t shown_before = 0, flips = 0;
    uint8_t *on_show = r->dec.frame;
    uint32_t shown_crc = crc_update(0, on_show, FL_FRAME_BYTES);
    for (size_t off = 0; off < d.len; off += 40) {
        uint32_t n = (uint32_t)(d.len - off < 40 ? d.len - off : 40);
        fl_dec_feed(&r->dec, d.p + off, n);
        if (r->dec.count.frames_shown != shown_before) {
            /* a frame was shown, in the other page (40 bytes hold the end of one frame message
             * at most: the shortest is 46 bytes on the wire) */
            assert_true(r->dec.frame != on_show);
            assert_true(r->dec.frame == pages || r->dec.frame == pages + FL_FRAME_BYTES);
            assert_true(r->dec.recon == on_show);
            flips++;
        } else {
            /* nothing shown: the page on show is untouched */
            assert_true(r->dec.frame == on_show);
            assert_int_equal(crc_update(0, on_show, FL_FRAME_BYTES), shown_crc);
        }
        shown_before = r->dec.count.frames_shown;
        on_show = r->dec.frame;
        shown_crc = crc_update(0, on_show, FL_FRAME_BYTES);
    }
    check_accounting(r);
    assert_int_equal(flips, r->dec.count.frames_shown);
    assert_true(r->dec.count.frames_shown > NF / 2);
    assert_true(r->dec.count.msgs_bad > 0);
    assert_int_equal(r->w.log_hash, ref->w.log_hash);
    assert_memory_equal(&r->dec.count, &ref->dec.count, sizeof r->dec.count);
    assert_int_equal(r->back.len, ref->back.len);
    assert_memory_equal(r->back.p, ref->back.p, r->back.len);
    assert_memory_equal(r->dec.frame, ref->frame, FL_FRAME_BYTES);
    free(msg);
    free(pages);
    receiver_free(r);
    receiver_free(ref);
    free(s.p);
    free(d.p);
}

static void test_fault_injection(void **state)
{
    (void)state;
    static const uint32_t pers[] = {100000, 10000, 1000, 100};
    static const char *kinds[] = {"bit flips", "dropped bytes", "inserted bytes", "truncations", "mixed"};
    for (int kind = 0; kind < 5; kind++) {
        for (int pi = 0; pi < 4; pi++) {
            fl_counters c;
            uint32_t keys;
            noisy_link(pers[pi], kind, 240, 12, 1000u + (uint32_t)(kind * 10 + pi), &c, &keys);
            print_message("%-14s 1/%-6u: shown %3u dropped %3u missed %3u bad %4u resyncs %3u keyreqs %3u keyframes "
                          "%3u\n",
                          kinds[kind], pers[pi], c.frames_shown, c.frames_dropped, c.frames_missed, c.msgs_bad,
                          c.resyncs, c.keyreqs_sent, keys);
            if (pers[pi] <= 1000) {
                /* damage was seen, the receiver found the next boundary, lost
                 * bases were asked for */
                assert_true(c.msgs_bad > 0);
                assert_true(c.resyncs > 0);
                assert_true(c.keyreqs_sent > 0);
                assert_true(keys > 1);
            }
        }
    }
}

static void test_keyframe_request(void **state)
{
    (void)state;
    static fl_encoder enc;
    static uint8_t scratch[16384];
    buf fwd = {0};
    receiver *r = receiver_new(walk_crc, NF);
    fl_enc_init(&enc, buf_put, &fwd, scratch, sizeof scratch);
    enc.key_interval = 0;
    fl_enc_hello(&enc);
    fl_enc_palette(&enc, hal_get_palette());
    for (uint32_t k = 0; k < 12; k++) {
        fl_enc_frame(&enc, k, wf(k), k ? wf(k - 1) : NULL, k - 1, &walk_info[k]);
        if (k == 5) fwd.len = 0; /* frame 5 lost on the line */
        fl_dec_feed(&r->dec, fwd.p, (uint32_t)fwd.len);
        fwd.len = 0;
        if (k == 6) {
            /* frame 6 is a delta on 5, which the receiver never had: dropped, keyframe asked for */
            assert_int_equal(r->dec.count.frames_dropped, 1);
            assert_int_equal(r->dec.count.keyreqs_sent, 1);
            assert_int_equal(r->dec.count.frames_missed, 1);
        }
        fl_enc_receive(&enc, r->back.p, (uint32_t)r->back.len);
        r->back.len = 0;
        if (k == 6) assert_int_equal(enc.force_key, 1);
        if (k == 7) assert_int_equal(enc.last_key, 7); /* answered with a keyframe */
    }
    check_accounting(r);
    assert_int_equal(r->dec.count.frames_shown, 10);
    assert_int_equal(r->dec.count.keyreqs_sent, 1);
    assert_int_equal(enc.keyframes, 2);
    assert_int_equal(enc.keyreqs, 1);
    assert_memory_equal(r->frame, wf(11), FL_FRAME_BYTES);
    receiver_free(r);
    free(fwd.p);
}

static void test_flow_control(void **state)
{
    (void)state;
    static fl_encoder enc;
    static uint8_t scratch[16384];
    buf fwd = {0};
    receiver *r = receiver_new(walk_crc, NF);
    fl_enc_init(&enc, buf_put, &fwd, scratch, sizeof scratch);
    enc.window = 3;
    enc.ack_timeout_ms = 100;
    fl_enc_hello(&enc);
    fl_enc_palette(&enc, hal_get_palette());
    uint32_t now = 1000;
    /* three frames in flight, then the window is full */
    for (uint32_t k = 0; k < 3; k++) {
        assert_true(fl_enc_may_send(&enc, now));
        fl_enc_frame(&enc, k, wf(k), k ? wf(k - 1) : NULL, k - 1, &walk_info[k]);
    }
    assert_false(fl_enc_may_send(&enc, now));
    assert_false(fl_enc_may_send(&enc, now + 50));
    /* the receiver acknowledges frames 0 and 1 */
    fl_dec_feed(&r->dec, fwd.p, (uint32_t)fwd.len);
    fwd.len = 0;
    assert_int_equal(r->dec.count.acks_sent, 3);
    /* the ack of frame 1 alone: acks are cumulative */
    size_t ack_len = r->back.len / 3; /* three acks of equal length */
    assert_int_equal(r->back.len % 3, 0);
    fl_enc_receive(&enc, r->back.p + ack_len, (uint32_t)ack_len); /* the ack of frame 1 */
    assert_int_equal(enc.in_count, 1);
    assert_true(fl_enc_may_send(&enc, now + 60));
    fl_enc_frame(&enc, 3, wf(3), wf(2), 2, &walk_info[3]);
    fl_enc_frame(&enc, 4, wf(4), wf(3), 3, &walk_info[4]);
    assert_false(fl_enc_may_send(&enc, now + 60));
    /* an ack that is lost: after the timeout the oldest frame is given up, one
     * frame may go, and the window is full again (a slow receiver is not
     * flooded with a window of frames per timeout) */
    assert_false(fl_enc_may_send(&enc, now + 100));
    assert_false(fl_enc_may_send(&enc, now + 159));
    assert_true(fl_enc_may_send(&enc, now + 160));
    assert_int_equal(enc.timeouts, 1);
    assert_int_equal(enc.in_count, 2);
    fl_enc_frame(&enc, 5, wf(5), wf(4), 4, &walk_info[5]);
    assert_false(fl_enc_may_send(&enc, now + 160));
    assert_false(fl_enc_may_send(&enc, now + 259));
    assert_true(fl_enc_may_send(&enc, now + 260));
    assert_int_equal(enc.timeouts, 2);
    fl_enc_frame(&enc, 6, wf(6), wf(5), 5, &walk_info[6]);
    /* the clock may wrap */
    enc.in_count = 0;
    for (uint32_t k = 7; k < 10; k++) fl_enc_frame(&enc, k, wf(k), wf(k - 1), k - 1, &walk_info[k]);
    assert_false(fl_enc_may_send(&enc, 0xFFFFFFF0u));
    assert_true(fl_enc_may_send(&enc, 0xFFFFFFF0u + 120u));
    /* stale and garbage acks change nothing */
    uint32_t before = enc.in_count;
    fl_enc_receive(&enc, r->back.p, (uint32_t)ack_len); /* ack of frame 0 again */
    assert_int_equal(enc.in_count, before);
    uint8_t junk[] = {1, 2, 3, 0, 0, 0x55, 0};
    fl_enc_receive(&enc, junk, sizeof junk);
    assert_true(enc.rx_bad >= 2);
    receiver_free(r);
    free(fwd.p);
}

/* Synthetic extremes straight through the picture coder: every frame decodes
 * to itself, with and without a base, from aligned and unaligned memory (the
 * word-at-a-time and the byte paths give the same bytes). */
static void test_synthetic_pictures(void **state)
{
    (void)state;
    enum { NS = 9 };
    uint8_t *mem = malloc((size_t)(NS + 1) * FL_FRAME_BYTES + 64);
    uint8_t *f = mem + 8; /* word-aligned */
    rng_state = 5;
    for (int s = 0; s < NS; s++) {
        uint8_t *p = f + (size_t)s * FL_FRAME_BYTES;
        for (int y = 0; y < FL_H; y++)
            for (int x = 0; x < FL_W; x++) {
                uint8_t v;
                switch (s) {
                case 0: v = 0; break;                                                 /* empty */
                case 1: v = 255; break;                                               /* one colour */
                case 2: v = (uint8_t)(x & 1); break;                                  /* a transition at every pixel */
                case 3: v = (uint8_t)((x + y) & 1); break;                            /* checkerboard */
                case 4: v = (uint8_t)(x * 7 / 320 + y / 50); break;                   /* blocks */
                case 5: v = (uint8_t)(x > y * 3 / 2 ? 3 : 9); break;                  /* a slanted edge */
                case 6: v = (uint8_t)(x > 160 + (y % 40) - 20 ? x / 40 : 200); break; /* zig-zag */
                case 7: v = (uint8_t)rnd(); break;                                    /* noise */
                default: v = (uint8_t)(x == 319 || y == 199 ? 17 : 4); break;         /* edges at the borders */
                }
                p[y * FL_W + x] = v;
            }
    }
    static fl_coder ce, cd, cu;
    uint8_t *out = malloc(1 << 20), *out2 = malloc(1 << 20), *rec = malloc(FL_FRAME_BYTES);
    uint8_t *un = malloc(2 * FL_FRAME_BYTES + 16);
    for (int s = 0; s < NS; s++)
        for (int b = -1; b < NS; b++) {
            const uint8_t *px = f + (size_t)s * FL_FRAME_BYTES, *base = b < 0 ? NULL : f + (size_t)b * FL_FRAME_BYTES;
            uint32_t check, check2;
            uint32_t n = fl_code_picture(&ce, px, base, out, 1 << 20, &check);
            assert_true(n > 0);
            assert_int_equal(check, fl_frame_check(px));
            memset(rec, 0xEE, FL_FRAME_BYTES);
            assert_int_equal(fl_decode_picture(&cd, out, n, base, rec), 0);
            assert_memory_equal(rec, px, FL_FRAME_BYTES);
            /* the same from odd addresses */
            uint8_t *upx = un + 1, *ubase = un + 1 + FL_FRAME_BYTES;
            memcpy(upx, px, FL_FRAME_BYTES);
            if (base) memcpy(ubase, base, FL_FRAME_BYTES);
            uint32_t n2 = fl_code_picture(&cu, upx, base ? ubase : NULL, out2, 1 << 20, &check2);
            assert_int_equal(n2, n);
            assert_memory_equal(out2, out, n);
            assert_int_equal(check2, check);
            /* too little room: 0, never a partial picture; the coder gives up
             * mid-frame and its next delta against these pixels is still right */
            if (n > 1) {
                assert_int_equal(fl_code_picture(&ce, px, base, out, n - 1, &check2), 0);
                const uint8_t *nx = f + (size_t)((s + 1) % NS) * FL_FRAME_BYTES;
                uint32_t m = fl_code_picture(&ce, nx, px, out2, 1 << 20, &check2);
                assert_true(m > 0);
                assert_int_equal(check2, fl_frame_check(nx));
                memset(rec, 0xEE, FL_FRAME_BYTES);
                assert_int_equal(fl_decode_picture(&cd, out2, m, px, rec), 0);
                assert_memory_equal(rec, nx, FL_FRAME_BYTES);
            }
            /* truncated data never decodes to the frame silently */
            if (n > 8 && fl_decode_picture(&cd, out, n / 2, base, rec) == 0)
                assert_true(fl_frame_check(rec) != check || memcmp(rec, px, FL_FRAME_BYTES) == 0);
        }
    free(out);
    free(out2);
    free(rec);
    free(un);
    free(mem);
}

/* Frames whose edge coding does not fit the scratch buffer go with method COPY,
 * streamed (noise: through its escape, the rest of the picture plain). */
static void test_copy_fallback(void **state)
{
    (void)state;
    static fl_encoder enc;
    static uint8_t scratch[200];
    uint8_t *noise = malloc(FL_FRAME_BYTES);
    rng_state = 9;
    for (int i = 0; i < FL_FRAME_BYTES; i++) noise[i] = (uint8_t)rnd();
    uint32_t crcs[4] = {walk_crc[0], walk_crc[1], crc_update(0, noise, FL_FRAME_BYTES), walk_crc[3]};
    buf s = {0};
    receiver *r = receiver_new(crcs, 4);
    fl_enc_init(&enc, buf_put, &s, scratch, sizeof scratch);
    fl_frame_info i2 = info_for(noise, 2);
    fl_enc_frame(&enc, 0, wf(0), NULL, 0, &walk_info[0]);
    fl_enc_frame(&enc, 1, wf(1), wf(0), 0, &walk_info[1]);
    fl_enc_frame(&enc, 2, noise, wf(1), 1, &i2);
    fl_enc_frame(&enc, 3, wf(3), noise, 2, &walk_info[3]);
    assert_true(enc.copy_frames >= 1);
    assert_int_equal(enc.raw_fallbacks, 0);
    fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
    check_accounting(r);
    assert_int_equal(r->dec.count.frames_shown, 4);
    assert_memory_equal(r->frame, wf(3), FL_FRAME_BYTES);
    receiver_free(r);
    free(s.p);
    free(noise);
}

/* A delta coded against a base that is not the frame the receiver has (the
 * sender's base page was changed behind its back) is caught by the frame
 * check and never shown; with no pixel CRC sent too. */
static void test_wrong_base(void **state)
{
    (void)state;
    for (int no_crc = 0; no_crc < 2; no_crc++) {
        static fl_encoder enc;
        static uint8_t scratch[16384];
        buf s = {0};
        receiver *r = receiver_new(walk_crc, NF);
        fl_enc_init(&enc, buf_put, &s, scratch, sizeof scratch);
        uint8_t *fake = malloc(FL_FRAME_BYTES);
        memcpy(fake, wf(1), FL_FRAME_BYTES);
        memset(fake + 100 * FL_W, 7, 40 * FL_W); /* not what frame 1 was */
        fl_frame_info i0 = walk_info[0], i1 = walk_info[1];
        i0.no_crc = i1.no_crc = (uint8_t)no_crc;
        if (no_crc) i0.crc = i1.crc = 0;
        fl_enc_frame(&enc, 0, wf(0), NULL, 0, &i0);
        fl_enc_frame(&enc, 1, wf(1), wf(0), 0, &i1);
        /* frame 2 = frame 1's pixels where the fake base has them: the coder
         * says "same as base" for rows that are not */
        memcpy(fake, wf(2), FL_FRAME_BYTES);
        memcpy(fake + 100 * FL_W, wf(1) + 100 * FL_W, 40 * FL_W);
        fl_frame_info i2b = info_for(fake, 2);
        i2b.no_crc = (uint8_t)no_crc;
        if (no_crc) i2b.crc = 0;
        uint8_t *base_lie = malloc(FL_FRAME_BYTES);
        memcpy(base_lie, fake, FL_FRAME_BYTES); /* the base claimed to be frame 1 */
        uint32_t sent[3] = {walk_crc[0], walk_crc[1], crc_update(0, fake, FL_FRAME_BYTES)};
        r->w.sent_crc = sent;
        r->w.nsent = 3;
        fl_enc_frame(&enc, 2, fake, base_lie, 1, &i2b);
        fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
        /* the delta said: every row as the base; the receiver's base is frame 1 */
        assert_int_equal(r->w.wrong, 0);
        if (memcmp(fake, wf(1), FL_FRAME_BYTES) != 0) {
            assert_int_equal(r->dec.count.frames_shown, 2);
            assert_int_equal(r->dec.count.frames_dropped, 1);
            assert_int_equal(r->dec.count.keyreqs_sent, 1);
        }
        assert_memory_equal(r->frame, wf(1), FL_FRAME_BYTES);
        if (no_crc) assert_int_equal(r->dec.shown_info.crc, walk_crc[1]); /* filled in by the receiver */
        check_accounting(r);
        receiver_free(r);
        free(s.p);
        free(fake);
        free(base_lie);
    }
}

/* Garbage, damaged headers, other versions, truncated and oversized messages:
 * counted, never acted on, no crash. */
static void test_bad_input(void **state)
{
    (void)state;
    uint32_t none[1] = {0};
    receiver *r = receiver_new(none, 0);
    rng_state = 3;
    uint8_t *g = malloc(200000);
    for (int i = 0; i < 200000; i++) g[i] = (uint8_t)rnd();
    fl_dec_feed(&r->dec, g, 200000);
    assert_int_equal(r->dec.count.frames_shown, 0);
    assert_true(r->dec.count.msgs_bad > 0);
    /* an oversized segment: no delimiter for more than a message can hold */
    memset(g, 1, 200000);
    fl_dec_feed(&r->dec, g, 200000);
    uint8_t z = 0;
    fl_dec_feed(&r->dec, &z, 1);
    fl_dec_feed(&r->dec, &z, 1); /* an empty segment: nothing */
    check_accounting(r);
    uint32_t bad = r->dec.count.msgs_bad;
    /* a good message after the garbage: resync */
    static fl_encoder enc;
    static uint8_t scratch[4096];
    buf s = {0};
    fl_enc_init(&enc, buf_put, &s, scratch, sizeof scratch);
    fl_enc_hello(&enc);
    fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
    assert_int_equal(r->dec.count.hellos, 1);
    assert_int_equal(r->dec.hello.width, FL_W);
    assert_int_equal(r->dec.count.resyncs, (uint32_t)(bad > 0));
    /* a message of another version, with a good CRC: refused */
    s.len = 0;
    fl_enc_hello(&enc);
    uint8_t dec_msg[64];
    /* undo COBS by hand for this small message (no zero in it but the header's) */
    fl_reader rd;
    fl_reader_init(&rd, dec_msg, sizeof dec_msg);
    int res = 0;
    for (size_t i = 0; i < s.len; i++) res = fl_reader_byte(&rd, s.p[i]);
    assert_int_equal(res, 1);
    dec_msg[0] = FL_VERSION + 1; /* a version this decoder does not speak */
    fl_writer w;
    buf v = {0};
    fl_writer_init(&w, buf_put, &v);
    fl_writer_bytes(&w, dec_msg, rd.len - 4); /* header + payload, stuffed again */
    fl_writer_end(&w);                        /* with a CRC that matches */
    uint32_t before = r->dec.count.msgs_bad;
    fl_dec_feed(&r->dec, v.p, (uint32_t)v.len);
    assert_int_equal(r->dec.count.msgs_bad, before + 1);
    assert_int_equal(r->dec.count.hellos, 1);
    check_accounting(r);
    free(v.p);
    free(s.p);
    free(g);
    receiver_free(r);
}

/* A frame message whose picture bytes are random but whose message CRC is
 * right (as if the CRC had been fooled): decoded or not, never shown. */
static void test_forged_pictures(void **state)
{
    (void)state;
    uint32_t none[1] = {0};
    receiver *r = receiver_new(none, 1);
    static fl_encoder enc;
    static uint8_t scratch[16384];
    buf s = {0};
    fl_enc_init(&enc, buf_put, &s, scratch, sizeof scratch);
    rng_state = 11;
    for (int t = 0; t < 300; t++) {
        uint8_t payload[FL_FRAME_PRE + 5 + 200];
        uint32_t n = FL_FRAME_PRE + 1 + rnd() % 200;
        for (uint32_t i = 0; i < n; i++) payload[i] = (uint8_t)rnd();
        payload[FL_INFO_BYTES] = (uint8_t)(rnd() & 1); /* flags */
        payload[FL_FRAME_PRE] = FL_METHOD_EDGE;        /* keyframe: method after the check */
        s.len = 0;
        fl_writer_message(&enc.w, FL_MSG_KEYFRAME, (uint32_t)t, payload, n);
        fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
    }
    assert_int_equal(r->dec.count.frames_shown, 0);
    assert_int_equal(r->dec.count.frames_dropped, 300);
    assert_int_equal(r->w.wrong, 0);
    receiver_free(r);
    free(s.p);
}

/* COBS: blocks of 254 and 255 bytes, zeros at block edges, one byte at a time. */
static void test_framing(void **state)
{
    (void)state;
    static uint8_t msg[2000], got[4096];
    for (uint32_t len = 0; len < 800; len += (len < 520 ? 1 : 37)) {
        for (int pat = 0; pat < 3; pat++) {
            for (uint32_t i = 0; i < len; i++)
                msg[i] = pat == 0 ? (uint8_t)(i % 255 + 1) : pat == 1 ? 0 : (uint8_t)(i % 3 ? 5 : 0);
            buf s = {0};
            fl_writer w;
            fl_writer_init(&w, buf_put, &s);
            fl_writer_message(&w, FL_MSG_PALETTE, len, msg, len);
            for (size_t i = 0; i + 1 < s.len; i++) assert_int_not_equal(s.p[i], 0);
            assert_int_equal(s.p[s.len - 1], 0);
            assert_true(s.len <=
                        len + FL_HEADER_BYTES + FL_CRC_BYTES + 2 + (len + 13) / 254 + 1); /* bounded overhead */
            fl_reader rd;
            fl_reader_init(&rd, got, sizeof got);
            int res = 0;
            for (size_t i = 0; i < s.len; i++) res = fl_reader_byte(&rd, s.p[i]);
            assert_int_equal(res, 1);
            assert_int_equal(rd.len, len + FL_HEADER_BYTES + FL_CRC_BYTES);
            assert_memory_equal(got + FL_HEADER_BYTES, msg, len);
            free(s.p);
        }
    }
}


/* ---- any address ------------------------------------------------------------ */

/* The frame check, the transition estimate and the coded picture depend on the
 * pixels only, not on where they lie: the scans read whole words only where both
 * frames are word-aligned (UBSan halts on a misaligned word read), bytes
 * elsewhere, and the two must agree. Every offset within two words. */
static void test_any_address(void **state)
{
    (void)state;
    uint8_t *px = malloc(FL_FRAME_BYTES), *base = malloc(FL_FRAME_BYTES);
    uint8_t *upx = malloc(FL_FRAME_BYTES + 32), *ubase = malloc(FL_FRAME_BYTES + 32);
    uint8_t *out = malloc(1 << 18), *out2 = malloc(1 << 18);
    for (int i = 0; i < FL_FRAME_BYTES; i++) {
        int x = i % FL_W, y = i / FL_W;
        px[i] = (uint8_t)(x > 100 + y / 2 ? (x / 9) & 7 : (y / 7) & 3);
        base[i] = (uint8_t)(rnd() % 50 == 0 ? rnd() & 7 : px[i]);
    }
    static fl_coder c0;
    uint32_t check, check2;
    uint32_t n = fl_code_picture(&c0, px, base, out, 1 << 18, &check);
    assert_true(n > 0);
    uint32_t est = fl_estimate_transitions(px, base), est0 = fl_estimate_transitions(px, NULL);
    for (int off = 0; off < 2 * (int)sizeof(long); off++)
        for (int boff = 0; boff < 2 * (int)sizeof(long); boff += off ? 2 * (int)sizeof(long) : 1) {
            memcpy(upx + off, px, FL_FRAME_BYTES);
            memcpy(ubase + boff, base, FL_FRAME_BYTES);
            assert_int_equal(fl_frame_check(upx + off), check);
            assert_int_equal(fl_estimate_transitions(upx + off, NULL), est0);
            assert_int_equal(fl_estimate_transitions(upx + off, ubase + boff), est);
            static fl_coder cu; /* fresh, as c0 was */
            memset(&cu, 0, sizeof cu);
            assert_int_equal(fl_code_picture(&cu, upx + off, ubase + boff, out2, 1 << 18, &check2), n);
            assert_memory_equal(out2, out, n);
            assert_int_equal(check2, check);
        }
    free(px);
    free(base);
    free(upx);
    free(ubase);
    free(out);
    free(out2);
}

/* ---- every reader's bound: messages of cap - 1, cap and cap + 1 bytes ---------- */

/* COBS as docs/frame-link.md writes it, independent of fl_writer: blocks of at
 * most 254 data bytes, each after a code byte, then the 0x00 delimiter. */
static void cobs_message(buf *out, const uint8_t *p, uint32_t n)
{
    uint8_t blk[255];
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (p[i] == 0) { /* a block ended by a zero */
            blk[0] = (uint8_t)(k + 1);
            buf_put(out, blk, k + 1);
            k = 0;
            continue;
        }
        blk[++k] = p[i];
        if (k == 254) { /* a full block: no zero ends it */
            blk[0] = 0xFF;
            buf_put(out, blk, 255);
            k = 0;
        }
    }
    blk[0] = (uint8_t)(k + 1);
    buf_put(out, blk, k + 1);
    uint8_t z = 0;
    buf_put(out, &z, 1);
}

/* n bytes of pattern pat: no zero, all zeros, zeros every 3, a zero at the end */
static void pattern(uint8_t *p, uint32_t n, int pat)
{
    for (uint32_t i = 0; i < n; i++)
        p[i] = pat == 0   ? (uint8_t)(i % 255 + 1)
               : pat == 1 ? 0
               : pat == 2 ? (uint8_t)(i % 3 ? i : 0)
                          : (uint8_t)(i + 1 < n ? 7 : 0);
}

/* fl_reader over a buffer of exactly cap bytes (malloc'd, so that ASan sees a
 * byte past it): messages up to cap bytes arrive whole, one more is refused as
 * too long and writes nothing past the buffer, leaves no bytes to be read, and the
 * reader takes the next message. */
static void test_reader_bound(void **state)
{
    (void)state;
    static const uint32_t caps[] = {1, 2, 3, 253, 254, 255, 256, 508, 509, 1000};
    uint8_t *msg = malloc(1100);
    for (size_t c = 0; c < sizeof caps / sizeof caps[0]; c++) {
        uint32_t cap = caps[c];
        for (int pat = 0; pat < 4; pat++) {
            for (uint32_t n = cap - 1; n <= cap + 1; n++) {
                uint8_t *rbuf = malloc(cap);
                buf s = {0};
                pattern(msg, n, pat);
                cobs_message(&s, msg, n);
                cobs_message(&s, msg, cap - 1); /* a message that fits, after it */
                fl_reader rd;
                fl_reader_init(&rd, rbuf, cap);
                int res = 0, got = 0;
                size_t i = 0;
                for (; i < s.len && !res; i++) res = fl_reader_byte(&rd, s.p[i]);
                if (n <= cap) {
                    assert_int_equal(res, 1);
                    assert_int_equal(rd.len, n);
                    assert_memory_equal(rbuf, msg, n);
                } else {
                    assert_int_equal(res, -(int)FL_R_LONG);
                    assert_int_equal(rd.len, 0); /* nothing of the refused segment is left to read */
                }
                assert_true(rd.len <= cap);
                for (res = 0; i < s.len; i++) res = fl_reader_byte(&rd, s.p[i]), got += res == 1;
                assert_int_equal(got, 1);
                assert_int_equal(rd.len, cap - 1);
                assert_memory_equal(rbuf, msg, cap - 1);
                free(s.p);
                free(rbuf);
            }
        }
    }
    free(msg);
}

static fl_reason last_reason;
static fl_event_kind last_kind;
static void note_event(void *ctx, const fl_event *ev)
{
    (void)ctx;
    last_kind = ev->kind;
    last_reason = ev->reason;
}

/* A keyframe message of header + payload + CRC = len bytes with a good CRC. */
static void message_of(buf *s, uint32_t len, uint8_t type)
{
    uint32_t n = len - FL_HEADER_BYTES - FL_CRC_BYTES;
    uint8_t *payload = malloc(n);
    pattern(payload, n, 2);
    fl_writer w;
    fl_writer_init(&w, buf_put, s);
    fl_writer_message(&w, type, 7, payload, n);
    free(payload);
}

/* The decoder's message buffer (FL_MSG_MAX), in both its set-ups: the page
 * flipper's work memory is that buffer alone, malloc'd to its size. A message
 * one byte too long is refused as too long; the longest one is read whole and
 * refused only for what it says (a keyframe of random bytes). */
static void test_decoder_message_bound(void **state)
{
    (void)state;
    uint8_t *pages = malloc(2u * FL_FRAME_BYTES);
    uint8_t *work = malloc(FL_DEC_PAGES_WORK_BYTES);
    receiver *r = receiver_new(NULL, 0);
    for (int flip = 0; flip < 2; flip++) {
        fl_decoder *d = flip ? &r->dec : malloc(sizeof *d);
        if (flip)
            fl_dec_init_pages(d, pages, pages + FL_FRAME_BYTES, work, note_event, NULL, NULL, NULL);
        else
            fl_dec_init(d, r->frame, r->work, note_event, NULL, NULL, NULL);
        for (uint32_t len = FL_MSG_MAX - 1; len <= FL_MSG_MAX + 1; len++) {
            buf s = {0};
            message_of(&s, len, FL_MSG_KEYFRAME);
            uint32_t bad = d->count.msgs_bad;
            last_reason = FL_R_NONE;
            last_kind = FL_EV_OTHER;
            fl_dec_feed(d, s.p, (uint32_t)s.len);
            assert_true(last_kind == FL_EV_BAD || last_kind == FL_EV_DROP);
            if (len > FL_MSG_MAX) {
                assert_int_equal(d->count.msgs_bad, bad + 1);
                assert_int_equal(last_kind, FL_EV_BAD);
                assert_int_equal(last_reason, FL_R_LONG);
            } else {
                assert_int_not_equal(last_reason, FL_R_LONG);
                assert_int_not_equal(last_reason, FL_R_FRAMING);
            }
            assert_true(d->rx.len <= FL_MSG_MAX);
            free(s.p);
        }
        if (!flip) free(d);
    }
    receiver_free(r);
    free(work);
    free(pages);
}

/* The sender's back-channel reader (rx_buf, 64 bytes): messages of 63, 64 and
 * 65 bytes are each one bad message (no back message is that long), nothing
 * past rx_buf changes, and a keyframe request after them is taken. */
static void test_encoder_back_bound(void **state)
{
    (void)state;
    static fl_encoder enc;
    static uint8_t scratch[4096];
    fl_enc_init(&enc, NULL, NULL, scratch, sizeof scratch);
    const size_t after = offsetof(fl_encoder, rx_buf) + sizeof enc.rx_buf;
    uint8_t *before = malloc(sizeof enc - after);
    memcpy(before, (uint8_t *)&enc + after, sizeof enc - after);
    uint32_t cap = sizeof enc.rx_buf;
    for (uint32_t len = cap - 1; len <= cap + 1; len++) {
        buf s = {0};
        message_of(&s, len, FL_MSG_ACK);
        uint32_t bad = enc.rx_bad;
        for (size_t i = 0; i < s.len; i++) fl_enc_receive(&enc, s.p + i, 1);
        assert_int_equal(enc.rx_bad, bad + 1);
        assert_true(enc.rx.len <= cap);
        assert_memory_equal((uint8_t *)&enc + after, before, sizeof enc - after);
        free(s.p);
    }
    buf s = {0};
    uint8_t req[5] = {1, 0, 0, 0, 0};
    fl_writer w;
    fl_writer_init(&w, buf_put, &s);
    fl_writer_message(&w, FL_MSG_KEYREQ, 0, req, sizeof req);
    uint32_t bad = enc.rx_bad;
    fl_enc_receive(&enc, s.p, (uint32_t)s.len);
    assert_int_equal(enc.rx_bad, bad);
    assert_int_equal(enc.keyreqs, 1);
    free(s.p);
    free(before);
}

/* Re-seal a frame message (COBS-encoded, delimiter included) with another
 * frame check and a message CRC that matches: a message that arrives intact
 * but describes other pixels than it carries. */
static void reseal(buf *msg, uint32_t check)
{
    static uint8_t m[FL_MSG_MAX];
    fl_reader rd;
    fl_reader_init(&rd, m, sizeof m);
    int res = 0;
    for (size_t i = 0; i < msg->len; i++) res = fl_reader_byte(&rd, msg->p[i]);
    assert_int_equal(res, 1);
    uint8_t *pl = m + FL_HEADER_BYTES;
    pl[FL_INFO_BYTES + 1] = (uint8_t)check;
    pl[FL_INFO_BYTES + 2] = (uint8_t)(check >> 8);
    pl[FL_INFO_BYTES + 3] = (uint8_t)(check >> 16);
    pl[FL_INFO_BYTES + 4] = (uint8_t)(check >> 24);
    uint32_t covered = fl_msg_crc_bytes(m, rd.len), body = rd.len - FL_CRC_BYTES;
    fl_writer w;
    msg->len = 0;
    fl_writer_init(&w, buf_put, msg);
    fl_writer_bytes(&w, m, covered);
    fl_writer_direct(&w, m + covered, body - covered);
    fl_writer_end(&w);
}

/* Frame a (word-aligned) with one pixel changed at i, to any other value. */
static void flip(uint8_t *dst, const uint8_t *a, uint32_t i)
{
    memcpy(dst, a, FL_FRAME_BYTES);
    dst[i] = (uint8_t)(a[i] + 1 + rnd() % 255);
}

/* Send `shown` under the frame check of `drawn` (they differ in one pixel):
 * the decoder must refuse it (FL_R_FRAME_CRC) and keep the frame before. */
static void expect_refused(receiver *r, fl_encoder *enc, buf *s, uint32_t no, const uint8_t *shown, uint32_t check)
{
    static fl_frame_info info = {.no_crc = 1};
    s->len = 0;
    fl_enc_frame(enc, no, shown, 0, 0, &info);
    reseal(s, check);
    uint32_t shown_before = r->dec.count.frames_shown, dropped = r->dec.count.frames_dropped;
    fl_dec_feed(&r->dec, s->p, (uint32_t)s->len);
    assert_int_equal(r->dec.count.frames_shown, shown_before);
    assert_int_equal(r->dec.count.frames_dropped, dropped + 1);
}

/* The end-to-end check without the pixel CRC-32: a frame that differs from the
 * frame drawn in a single pixel, anywhere, is never shown. Coded (EDGE: the
 * transition hash) and textured (COPY: the pixel hash) frames; every pixel for
 * the pixel hash, the edges and a random sample through the decoder. */
static void test_single_pixel_detected(void **state)
{
    (void)state;
    static _Alignas(8) uint8_t flat[FL_FRAME_BYTES], tex[FL_FRAME_BYTES], bad[FL_FRAME_BYTES];
    rng_state = 23;
    for (int y = 0; y < FL_H; y++)
        for (int x = 0; x < FL_W; x++) {
            flat[y * FL_W + x] = (uint8_t)(x < 100 + y / 4 ? 3 : x < 250 ? 0 : 77);
            tex[y * FL_W + x] = (uint8_t)rnd();
        }
    /* the pixel hash: every pixel */
    uint32_t h = fl_pixel_hash(tex);
    memcpy(bad, tex, FL_FRAME_BYTES);
    for (uint32_t i = 0; i < FL_FRAME_BYTES; i++) {
        uint8_t keep = bad[i];
        bad[i] = (uint8_t)(keep ^ (1u << (i % 8)));
        assert_true(fl_pixel_hash(bad) != h);
        bad[i] = keep;
    }
    /* through the decoder: corners, first and last rows and columns, a sample */
    uint32_t where[64 + 40 + 200], n = 0;
    for (uint32_t x = 0; x < FL_W; x += 10) where[n++] = x, where[n++] = (FL_H - 1) * FL_W + x;
    for (uint32_t y = 0; y < FL_H; y += 10) where[n++] = y * FL_W, where[n++] = y * FL_W + FL_W - 1;
    while (n < sizeof where / sizeof where[0]) where[n++] = rnd() % FL_FRAME_BYTES;
    uint32_t none[1] = {0};
    receiver *r = receiver_new(none, 0);
    r->dec.send_acks = 0;
    static fl_encoder enc;
    static uint8_t small[8192], large[70000];
    buf s = {0};
    for (int raw = 0; raw < 2; raw++) {
        const uint8_t *a = raw ? tex : flat;
        fl_enc_init(&enc, buf_put, &s, raw ? small : large, raw ? sizeof small : sizeof large);
        uint32_t check = raw ? fl_pixel_hash(a) : fl_frame_check(a);
        for (uint32_t k = 0; k < n; k++) {
            flip(bad, a, where[k]);
            expect_refused(r, &enc, &s, k, bad, check);
            assert_int_equal(enc.copy_frames, raw ? k + 1 : 0);
        }
    }
    /* and the same frames with their own checks are shown */
    s.len = 0;
    static fl_frame_info info = {.no_crc = 1};
    fl_enc_frame(&enc, 1000, tex, 0, 0, &info);
    fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
    assert_int_equal(r->dec.count.frames_shown, 1);
    assert_memory_equal(r->dec.frame, tex, FL_FRAME_BYTES);
    assert_int_equal(r->dec.shown_info.crc, crc_update(0, tex, FL_FRAME_BYTES)); /* filled in by the receiver */
    free(s.p);
    receiver_free(r);
}

/* fl_writer_direct (no copy) stuffs exactly as fl_writer_bytes: any length,
 * alignment, bytes already buffered, zeros at every block edge. */
static void test_direct_stuffing(void **state)
{
    (void)state;
    static _Alignas(8) uint8_t data[1200];
    rng_state = 5;
    for (int pat = 0; pat < 4; pat++) {
        for (uint32_t i = 0; i < sizeof data; i++)
            data[i] = pat == 0   ? (uint8_t)(i % 255 + 1)
                      : pat == 1 ? 0
                      : pat == 2 ? (uint8_t)(i % 7 ? 9 : 0)
                                 : (uint8_t)(rnd() % 3 ? rnd() : 0);
        for (uint32_t head = 0; head < 260; head += (head < 8 ? 1 : 61)) {
            for (uint32_t off = 0; off < 4; off++) {
                for (uint32_t len = 0; len < 1100; len += (len < 520 ? 1 : 97)) {
                    buf a = {0}, b = {0};
                    fl_writer wa, wb;
                    fl_writer_init(&wa, buf_put, &a);
                    fl_writer_init(&wb, buf_put, &b);
                    for (uint32_t k = 0; k < head; k++) {
                        uint8_t c = (uint8_t)(k % 5 ? k : 0);
                        fl_writer_bytes(&wa, &c, 1);
                        fl_writer_bytes(&wb, &c, 1);
                    }
                    uint32_t crc = wa.crc;
                    fl_writer_bytes(&wa, data + off, len);
                    wa.crc = crc; /* direct bytes are outside the CRC */
                    fl_writer_direct(&wb, data + off, len);
                    fl_writer_end(&wa);
                    fl_writer_end(&wb);
                    assert_int_equal(a.len, b.len);
                    assert_int_equal(wa.bytes, wb.bytes);
                    assert_memory_equal(a.p, b.p, a.len);
                    free(a.p);
                    free(b.p);
                }
                if (pat != 3 || head > 8) break;
            }
        }
    }
}

/* ---- HELLO: the scene's name and blob CRC ------------------------------------ */

/* Feed one HELLO with payload pl (n bytes) to r; returns whether it was taken. */
static int feed_hello(receiver *r, const uint8_t *pl, uint32_t n)
{
    buf b = {0};
    fl_writer w;
    fl_writer_init(&w, buf_put, &b);
    fl_writer_message(&w, FL_MSG_HELLO, 0, pl, n);
    uint32_t before = r->dec.count.hellos;
    fl_dec_feed(&r->dec, b.p, (uint32_t)b.len);
    free(b.p);
    return r->dec.count.hellos == before + 1;
}

static void test_hello_scene(void **state)
{
    (void)state;
    uint32_t none[1] = {0};
    receiver *r = receiver_new(none, 0);
    static fl_encoder enc;
    static uint8_t scratch[1024];
    buf s = {0};
    fl_enc_init(&enc, buf_put, &s, scratch, sizeof scratch);
    /* a sender that names no scene */
    fl_enc_hello(&enc);
    fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
    assert_int_equal(r->dec.count.hellos, 1);
    assert_string_equal(r->dec.hello.scene_name, "");
    assert_int_equal(r->dec.hello.scene_crc, 0);
    /* named */
    s.len = 0;
    fl_enc_scene(&enc, "freedoom2.wad:MAP01", 0xDEADBEEFu);
    fl_enc_hello(&enc);
    fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
    assert_int_equal(r->dec.count.hellos, 2);
    assert_string_equal(r->dec.hello.scene_name, "freedoom2.wad:MAP01");
    assert_int_equal(r->dec.hello.scene_crc, 0xDEADBEEFu);
    assert_int_equal(r->dec.hello.width, FL_W);
    /* too long: the first 63 bytes; bytes that are not printable ASCII become '?' */
    char longname[200];
    memset(longname, 'a', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    longname[0] = '\n';
    longname[1] = (char)0xC3;
    s.len = 0;
    fl_enc_scene(&enc, longname, 7);
    fl_enc_hello(&enc);
    fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
    assert_int_equal(r->dec.count.hellos, 3);
    assert_int_equal(strlen(r->dec.hello.scene_name), FL_SCENE_NAME_MAX);
    assert_memory_equal(r->dec.hello.scene_name, "??aaa", 5);
    /* NULL: no scene again */
    s.len = 0;
    fl_enc_scene(&enc, NULL, 0);
    fl_enc_hello(&enc);
    fl_dec_feed(&r->dec, s.p, (uint32_t)s.len);
    assert_string_equal(r->dec.hello.scene_name, "");
    assert_int_equal(r->dec.count.msgs_bad, 0);

    /* the 10-byte HELLO of a sender from before scene names: taken, no scene */
    uint8_t pl[FL_HELLO_MAX + 8] = {FL_VERSION, 64, 1, 200, 0, 8, 16, 0, 4, 3};
    assert_true(feed_hello(r, pl, FL_HELLO_CAPS));
    assert_string_equal(r->dec.hello.scene_name, "");
    assert_int_equal(r->dec.hello.window, 4);
    /* a good one by hand, then each way of breaking it */
    pl[10] = 0x78, pl[11] = 0x56, pl[12] = 0x34, pl[13] = 0x12;
    pl[14] = 3;
    memcpy(pl + 15, "abc", 3);
    assert_true(feed_hello(r, pl, 18));
    assert_string_equal(r->dec.hello.scene_name, "abc");
    assert_int_equal(r->dec.hello.scene_crc, 0x12345678u);
    uint32_t bad = r->dec.count.msgs_bad;
    assert_false(feed_hello(r, pl, 17)); /* shorter than its length byte says */
    assert_false(feed_hello(r, pl, 19)); /* longer */
    assert_false(feed_hello(r, pl, 11)); /* between the two layouts */
    assert_false(feed_hello(r, pl, 14));
    pl[16] = 0; /* a NUL in the name */
    assert_false(feed_hello(r, pl, 18));
    pl[16] = 0x7F; /* not printable */
    assert_false(feed_hello(r, pl, 18));
    pl[16] = 0x80;
    assert_false(feed_hello(r, pl, 18));
    pl[14] = FL_SCENE_NAME_MAX + 1; /* too long, though consistent */
    memset(pl + 15, 'x', FL_SCENE_NAME_MAX + 1);
    assert_false(feed_hello(r, pl, FL_HELLO_MIN + FL_SCENE_NAME_MAX + 1));
    assert_int_equal(r->dec.count.msgs_bad, bad + 8);
    assert_string_equal(r->dec.hello.scene_name, "abc"); /* a refused HELLO changes nothing */
    pl[14] = FL_SCENE_NAME_MAX;
    assert_true(feed_hello(r, pl, FL_HELLO_MAX));
    assert_int_equal(strlen(r->dec.hello.scene_name), FL_SCENE_NAME_MAX);
    free(s.p);
    receiver_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_walk_round_trip),
        cmocka_unit_test(test_any_chunking),
        cmocka_unit_test(test_fault_injection),
        cmocka_unit_test(test_keyframe_request),
        cmocka_unit_test(test_flow_control),
        cmocka_unit_test(test_synthetic_pictures),
        cmocka_unit_test(test_copy_fallback),
        cmocka_unit_test(test_wrong_base),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_forged_pictures),
        cmocka_unit_test(test_framing),
        cmocka_unit_test(test_any_address),
        cmocka_unit_test(test_single_pixel_detected),
        cmocka_unit_test(test_direct_stuffing),
        cmocka_unit_test(test_page_flipping),
        cmocka_unit_test(test_hello_scene),
        cmocka_unit_test(test_reader_bound),
        cmocka_unit_test(test_decoder_message_bound),
        cmocka_unit_test(test_encoder_back_bound),
    };
    return cmocka_run_group_tests_name("framelink", tests, setup, teardown);
}
