/* link_send.c - the host's frame-link present (see link_send.h). */
#include "link_send.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "crc32.h"
#include "port.h"

static uint32_t now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint32_t)((uint64_t)t.tv_sec * 1000u + (uint64_t)t.tv_nsec / 1000000u);
}

static void stop(link_sender *l, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void stop(link_sender *l, const char *fmt, ...)
{
    if (l->failed) return;
    l->failed = 1;
    int n = snprintf(l->err, sizeof l->err, "%s: ", l->port);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(l->err + n, sizeof l->err - (size_t)n, fmt, ap);
    va_end(ap);
}

static int receiver_gone(int err)
{
    return err == EPIPE || err == ECONNRESET || err == EIO || err == ENOTCONN || err == ENXIO;
}

/* Take what the receiver sent, without waiting, into pending. EOF: it closed
 * its end. */
static void read_back(link_sender *l)
{
    while (!l->closed && l->npending < sizeof l->pending) {
        ssize_t n = read(l->fd, l->pending + l->npending, sizeof l->pending - l->npending);
        if (n > 0) {
            l->npending += (uint32_t)n;
        } else if (n < 0 && errno == EINTR) {
            continue;
        } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            return;
        } else {
            l->closed = 1; /* EOF, or EIO from a pty whose other end closed */
        }
    }
}

/* Everything the receiver has sent so far, to the encoder. */
static void feed_back(link_sender *l)
{
    fl_encoder *e = &l->enc;
    uint32_t before = e->acks + e->keyreqs + e->palette_reqs;
    for (;;) {
        read_back(l);
        int full = l->npending == sizeof l->pending;
        if (l->npending) fl_enc_receive(e, l->pending, l->npending);
        l->npending = 0;
        if (!full || l->closed) break;
    }
    if (e->acks + e->keyreqs + e->palette_reqs != before) l->heard = 1;
}

/* Write the queue out as far as the port takes it. With wait_ms, wait on the
 * port (reading what comes back meanwhile) up to that long for it to take the
 * rest. A port that takes nothing for LINK_STALL_MS stops the link. */
static void drain(link_sender *l, uint32_t wait_ms)
{
    uint32_t t0 = now_ms();
    while (l->out_at < l->out_len && !l->failed) {
        ssize_t w = write(l->fd, l->out + l->out_at, l->out_len - l->out_at);
        if (w > 0) {
            l->out_at += (uint32_t)w;
            l->out_moved_ms = now_ms();
            continue;
        }
        if (w < 0 && errno == EINTR) continue;
        if (w < 0 && receiver_gone(errno)) {
            stop(l, "the receiver went away (%s)", strerror(errno));
            return;
        }
        if (w < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
            stop(l, "cannot write: %s", strerror(errno));
            return;
        }
        uint32_t now = now_ms(), idle = now - l->out_moved_ms, spent = now - t0;
        if (idle >= LINK_STALL_MS) {
            stop(l, "the receiver took no bytes for %d s", LINK_STALL_MS / 1000);
            return;
        }
        if (spent >= wait_ms) return;
        uint32_t left = wait_ms - spent;
        if (left > LINK_STALL_MS - idle) left = LINK_STALL_MS - idle;
        struct pollfd pf = {l->fd, (short)(POLLOUT | (l->npending < sizeof l->pending ? POLLIN : 0)), 0};
        int r = poll(&pf, 1, (int)left);
        if (r < 0 && errno != EINTR) {
            stop(l, "cannot wait on it: %s", strerror(errno));
            return;
        }
        if (r > 0 && (pf.revents & POLLIN)) read_back(l);
        if (r > 0 && (pf.revents & (POLLERR | POLLHUP | POLLNVAL)) && !(pf.revents & POLLOUT)) {
            stop(l, "the receiver went away");
            return;
        }
    }
    if (l->out_at == l->out_len) l->out_at = l->out_len = 0;
}

/* The encoder's output: into the queue, written out by drain. A queue that
 * cannot take it (never expected: LINK_OUT_BYTES holds two frame messages) is
 * first written out, waiting on the port. */
static void put(void *ctx, const uint8_t *p, uint32_t n)
{
    link_sender *l = ctx;
    while (n > 0 && !l->failed) {
        if (l->out_len == 0) l->out_moved_ms = now_ms(); /* the stall clock starts with the bytes */
        uint32_t room = (uint32_t)sizeof l->out - l->out_len;
        if (room == 0) {
            drain(l, LINK_STALL_MS);
            continue;
        }
        uint32_t k = n < room ? n : room;
        memcpy(l->out + l->out_len, p, k);
        l->out_len += k;
        p += k;
        n -= k;
    }
}

int link_open(link_sender *l, const char *port, long baud, char *err, size_t errlen)
{
    memset(l, 0, sizeof *l);
    l->port = port;
    int writable;
    l->fd = port_open(port, baud, &writable, err, errlen);
    if (l->fd < 0) return -1;
    if (!writable) {
        snprintf(err, errlen, "%s: frames cannot be sent on it (expected a tty, a pty or socket://HOST:PORT)", port);
        if (l->fd > 0) close(l->fd);
        return -1;
    }
    int flags = fcntl(l->fd, F_GETFL);
    if (flags < 0 || fcntl(l->fd, F_SETFL, flags | O_NONBLOCK) != 0) {
        snprintf(err, errlen, "%s: cannot make it non-blocking: %s", port, strerror(errno));
        close(l->fd);
        return -1;
    }
    signal(SIGPIPE, SIG_IGN);
    fl_enc_init(&l->enc, put, l, l->scratch, sizeof l->scratch);
    l->enc.match_hash = l->match_hash; /* textured frames: fewer bytes for more work than a target affords */
    return 0;
}

int link_hello(link_sender *l, const char *scene, const uint8_t *blob, size_t blob_len)
{
    if (l->failed) return -1;
    fl_enc_scene(&l->enc, scene, crc_update(0, blob, blob_len));
    fl_enc_hello(&l->enc);
    drain(l, 0);
    return l->failed ? -1 : 0;
}

/* Code the frame into the queue (its palette first when new or changed): a
 * delta against prev, the last frame sent, or a keyframe (fl_enc_frame). */
static void send_frame(link_sender *l, uint32_t frame_no, const uint8_t *pixels, const uint8_t *palette,
                       const fl_frame_info *info)
{
    if (!l->palette_sent || memcmp(l->palette, palette, sizeof l->palette)) {
        memcpy(l->palette, palette, sizeof l->palette); /* the encoder keeps the pointer for requests */
        fl_enc_palette(&l->enc, l->palette);
        l->palette_sent = 1;
    }
    fl_frame_info fi = *info;
    fi.crc = crc_update(0, pixels, FL_FRAME_BYTES);
    fi.no_crc = 0;
    fl_enc_frame(&l->enc, frame_no, pixels, l->have_prev ? l->prev : NULL, l->prev_no, &fi);
    memcpy(l->prev, pixels, sizeof l->prev);
    l->have_prev = 1;
    l->prev_no = frame_no;
}

/* May a frame go now? Not while the last message is being written, nor, once
 * the receiver has answered (as the firmware's AUTO), while its window is full
 * (fl_enc_may_send gives a full window up after the ack timeout). */
static int may_send(link_sender *l)
{
    return l->out_len == 0 && (!l->heard || fl_enc_may_send(&l->enc, now_ms()));
}

int link_frame(link_sender *l, uint32_t frame_no, const uint8_t *pixels, const uint8_t *palette,
               const fl_frame_info *info)
{
    if (l->failed) return -1;
    drain(l, 0);
    feed_back(l);
    if (l->closed) stop(l, "the receiver closed the link");
    if (l->failed) return -1;
    if (!may_send(l)) { /* the link is behind: this frame stays here */
        memcpy(l->held, pixels, sizeof l->held);
        memcpy(l->held_palette, palette, sizeof l->held_palette);
        l->held_info = *info;
        l->held_no = frame_no;
        l->have_held = 1;
        l->skipped++;
        return 0;
    }
    l->have_held = 0;
    send_frame(l, frame_no, pixels, palette, info);
    drain(l, 0);
    return l->failed ? -1 : 0;
}

/* The whole queue written out, however long the port takes, unless it takes
 * nothing for LINK_STALL_MS. */
static void drain_all(link_sender *l)
{
    while (l->out_len && !l->failed) drain(l, LINK_STALL_MS);
}

int link_finish(link_sender *l)
{
    drain_all(l);
    feed_back(l);
    if (l->have_held) { /* the last frame drawn was skipped: it goes once there is room */
        uint32_t t0 = now_ms();
        int room = 0;
        while (!l->failed && !l->closed && !(room = may_send(l)) && now_ms() - t0 < LINK_STALL_MS) {
            if (l->out_len) {
                drain(l, l->enc.ack_timeout_ms);
            } else {
                struct pollfd pf = {l->fd, POLLIN, 0};
                if (poll(&pf, 1, (int)l->enc.ack_timeout_ms) < 0 && errno != EINTR) {
                    stop(l, "cannot wait for acks: %s", strerror(errno));
                    break;
                }
            }
            feed_back(l);
        }
        if (room && !l->failed && !l->closed) {
            send_frame(l, l->held_no, l->held, l->held_palette, &l->held_info);
            l->have_held = 0;
            l->skipped--;
            drain_all(l);
        }
    }
    uint32_t t0 = now_ms();
    feed_back(l);
    while (!l->failed && !l->closed && l->enc.in_count > 0) {
        uint32_t spent = now_ms() - t0;
        if (spent >= l->enc.ack_timeout_ms) break;
        struct pollfd pf = {l->fd, POLLIN, 0};
        if (poll(&pf, 1, (int)(l->enc.ack_timeout_ms - spent)) < 0 && errno != EINTR) break;
        feed_back(l);
    }
    return l->failed ? -1 : 0;
}

const char *link_error(const link_sender *l)
{
    return l->failed ? l->err : NULL;
}

void link_print_summary(const link_sender *l, FILE *f)
{
    const fl_encoder *e = &l->enc;
    fprintf(f,
            "link %s: %u frames (%u keyframes, %u deltas, %u raw), %u skipped, %u bytes; %u acks, %u keyframe "
            "requests, %u timeouts, %u bad messages received\n",
            l->port, (unsigned)e->frames, (unsigned)e->keyframes, (unsigned)e->deltas, (unsigned)e->raw_fallbacks,
            (unsigned)l->skipped, (unsigned)e->bytes, (unsigned)e->acks, (unsigned)e->keyreqs, (unsigned)e->timeouts,
            (unsigned)e->rx_bad);
}

void link_print_json(const link_sender *l, FILE *f)
{
    const fl_encoder *e = &l->enc;
    fputs("{\"port\": \"", f);
    for (const char *p = l->port; *p; p++) {
        if (*p == '"' || *p == '\\') fputc('\\', f);
        if ((unsigned char)*p >= 0x20) fputc(*p, f);
    }
    fprintf(f,
            "\", \"bytes\": %u, \"frames\": %u, \"keyframes\": %u, \"deltas\": %u, \"raw\": %u, \"skipped\": %u, "
            "\"acks\": %u, \"keyreqs\": %u, \"palette_reqs\": %u, \"timeouts\": %u, \"rx_bad\": %u, \"error\": %s}",
            (unsigned)e->bytes, (unsigned)e->frames, (unsigned)e->keyframes, (unsigned)e->deltas,
            (unsigned)e->raw_fallbacks, (unsigned)l->skipped, (unsigned)e->acks, (unsigned)e->keyreqs,
            (unsigned)e->palette_reqs, (unsigned)e->timeouts, (unsigned)e->rx_bad, l->failed ? "true" : "false");
}

void link_close(link_sender *l)
{
    /* what the receiver said last, read: a socket closed with bytes unread is
     * reset, and its reset can cost the receiver the bytes it has not read yet */
    if (l->fd > 0 && !l->closed) read_back(l);
    if (l->fd > 0) close(l->fd);
    l->fd = -1;
}
