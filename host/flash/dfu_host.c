/* dfu_host.c - the host's DFU 1.1 download engine (see dfu_host.h). */
#include "dfu_host.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "crc32.h"
#include "dfu/dfu_image.h"
#include "dfu/dfu_proto.h"

#define DEFAULT_TIMEOUT_MS 5000u
#define DEFAULT_REENUM_MS 10000u
#define MAX_POLLS 100000u

typedef struct eng {
    const dfu_transport *t;
    const dfu_host_opts *o;
    dfu_host_report *r;
    unsigned timeout_ms, reenum_ms;
    dfu_func_desc desc;
    int last_xfer;   /* the last transport error, 0 if none */
    int sent_dnload; /* a DNLOAD with data reached the device */
} eng;

typedef struct dstat {
    uint8_t status, state;
    uint32_t poll_ms;
} dstat;

const char *dfu_host_strerror(dfu_host_err e)
{
    switch (e) {
    case DFU_HOST_OK: return "ok";
    case DFU_HOST_BAD_IMAGE: return "image rejected";
    case DFU_HOST_BAD_ARGS: return "invalid arguments";
    case DFU_HOST_NO_DEVICE: return "device vanished";
    case DFU_HOST_TIMEOUT: return "device timed out";
    case DFU_HOST_IO: return "USB error";
    case DFU_HOST_DEVICE_ERROR: return "device reported an error";
    case DFU_HOST_PROTOCOL: return "DFU protocol error";
    }
    return "unknown error";
}

static void say(eng *e, int level, const char *fmt, ...)
{
    if (!e->o || !e->o->log || e->o->verbose < level) return;
    char line[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    e->o->log(e->o->user, line);
}

/* The first failure wins; later notes are appended with append(). */
static void fail(eng *e, dfu_host_err err, const char *fmt, ...)
{
    if (e->r->err != DFU_HOST_OK) return;
    e->r->err = err;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e->r->msg, sizeof e->r->msg, fmt, ap);
    va_end(ap);
}

static void append(eng *e, const char *fmt, ...)
{
    size_t used = strlen(e->r->msg);
    if (used + 1 >= sizeof e->r->msg) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e->r->msg + used, sizeof e->r->msg - used, fmt, ap);
    va_end(ap);
}

static dfu_host_err xfer_host_err(int x)
{
    switch (x) {
    case DFU_XFER_NO_DEVICE: return DFU_HOST_NO_DEVICE;
    case DFU_XFER_TIMEOUT: return DFU_HOST_TIMEOUT;
    case DFU_XFER_STALL: return DFU_HOST_PROTOCOL;
    default: return DFU_HOST_IO;
    }
}

static void fail_xfer(eng *e, int x, const char *fmt, ...)
{
    char during[200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(during, sizeof during, fmt, ap);
    va_end(ap);
    const char *detail = e->t->last_error ? e->t->last_error(e->t->ctx) : "";
    switch (x) {
    case DFU_XFER_NO_DEVICE:
        fail(e, DFU_HOST_NO_DEVICE, "the device vanished (unplugged or reset) during %s", during);
        break;
    case DFU_XFER_TIMEOUT:
        fail(e, DFU_HOST_TIMEOUT, "the device did not answer within %u ms during %s", e->timeout_ms, during);
        break;
    case DFU_XFER_STALL: fail(e, DFU_HOST_PROTOCOL, "the device stalled %s", during); break;
    default: fail(e, DFU_HOST_IO, "USB error during %s%s%s", during, *detail ? ": " : "", detail); break;
    }
}

static int req(eng *e, uint8_t type, uint8_t request, uint16_t value, uint8_t *data, uint16_t len)
{
    int x = e->t->control(e->t->ctx, type, request, value, data, len, e->timeout_ms);
    if (x < 0) e->last_xfer = x;
    say(e, 2, "  %s wValue=%u wLength=%u -> %d", dfu_request_name(request), value, len, x);
    return x;
}

static void sleep_ms(eng *e, uint32_t ms)
{
    if (ms) e->t->sleep_ms(e->t->ctx, ms);
}

static int getstatus(eng *e, dstat *s)
{
    uint8_t b[DFU_GETSTATUS_LEN];
    int x = req(e, DFU_REQTYPE_IN, DFU_REQ_GETSTATUS, 0, b, sizeof b);
    if (x < 0) return x;
    if (x < (int)sizeof b) {
        e->last_xfer = DFU_XFER_IO;
        return DFU_XFER_IO;
    }
    s->status = b[0];
    s->poll_ms = (uint32_t)b[1] | (uint32_t)b[2] << 8 | (uint32_t)b[3] << 16;
    s->state = b[4];
    if (e->r->err == DFU_HOST_OK) {
        e->r->dev_status = s->status;
        e->r->dev_state = s->state;
    }
    say(e, 2, "  GETSTATUS: %s, %s, bwPollTimeout %u ms", dfu_status_name(s->status), dfu_state_name(s->state),
        (unsigned)s->poll_ms);
    return 0;
}

static void fail_device(eng *e, const dstat *s, const char *fmt, ...)
{
    char where[200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(where, sizeof where, fmt, ap);
    va_end(ap);
    fail(e, DFU_HOST_DEVICE_ERROR, "the device reported %s (%s) %s, in state %s", dfu_status_name(s->status),
         dfu_status_text(s->status), where, dfu_state_name(s->state));
}

/* After a failure: bring a reachable device back to dfuIDLE (CLRSTATUS out of
 * dfuERROR, ABORT out of a transfer), so that the next attempt starts clean. */
static void recover(eng *e)
{
    if (e->last_xfer == DFU_XFER_NO_DEVICE) {
        /* Manifestation writes the valid mark; a device gone during it may or may
         * not have written it, and only the device can tell. */
        if (e->r->manifest_started)
            append(e, ". The device had the whole image and was checking it and marking it "
                      "valid: it may have finished (then it runs the new firmware when "
                      "reconnected) or not (then it stays in its bootloader); reconnect it to "
                      "see which, and run the download again if it stays in its bootloader");
        else if (e->sent_dnload)
            append(e, ". No firmware was marked valid: after reconnecting, the device stays in "
                      "its bootloader; run the download again");
        return;
    }
    dstat s;
    for (int i = 0; i < 4; i++) {
        if (getstatus(e, &s) < 0) {
            append(e, "; the device did not answer GETSTATUS afterwards");
            return;
        }
        if (s.state == DFU_STATE_ERROR) {
            say(e, 1, "sending CLRSTATUS");
            if (req(e, DFU_REQTYPE_OUT, DFU_REQ_CLRSTATUS, 0, NULL, 0) < 0) return;
            append(e, "; sent CLRSTATUS");
        } else if (s.state == DFU_STATE_DNLOAD_IDLE || s.state == DFU_STATE_UPLOAD_IDLE) {
            say(e, 1, "sending ABORT");
            if (req(e, DFU_REQTYPE_OUT, DFU_REQ_ABORT, 0, NULL, 0) < 0) return;
            append(e, "; sent ABORT");
        } else if (s.state == DFU_STATE_DNBUSY || s.state == DFU_STATE_MANIFEST || s.state == DFU_STATE_DNLOAD_SYNC ||
                   s.state == DFU_STATE_MANIFEST_SYNC) {
            sleep_ms(e, s.poll_ms);
        } else {
            break;
        }
    }
    if (s.state == DFU_STATE_IDLE) append(e, "; the device is back in dfuIDLE");
    if (e->sent_dnload)
        append(e, ". No firmware was marked valid: the device stays in its bootloader; run the "
                  "download again");
}

static int reset_and_wait(eng *e, const char *why)
{
    say(e, 1, "USB reset (%s), waiting up to %u ms for the device to re-enumerate", why, e->reenum_ms);
    int x = e->t->reset(e->t->ctx);
    if (x < 0 && x != DFU_XFER_NO_DEVICE)
        say(e, 1, "reset: %s", e->t->last_error ? e->t->last_error(e->t->ctx) : "failed");
    x = e->t->reenumerate(e->t->ctx, e->reenum_ms);
    if (x >= 0) {
        e->last_xfer = 0;
        if (x == 1) e->t->functional(e->t->ctx, &e->desc);
    }
    return x;
}

/* Run-time mode: DETACH, reset unless the device detaches itself, wait for it to
 * come back in DFU mode. */
static int detach(eng *e, uint8_t state)
{
    uint16_t tmo = e->desc.detach_timeout_ms ? e->desc.detach_timeout_ms : 1000;
    say(e, 1, "the device is in run-time mode (%s): DETACH", dfu_state_name(state));
    int x = req(e, DFU_REQTYPE_OUT, DFU_REQ_DETACH, tmo, NULL, 0);
    if (x < 0 && x != DFU_XFER_NO_DEVICE) {
        fail_xfer(e, x, "DETACH");
        return -1;
    }
    if (!(e->desc.attributes & DFU_ATTR_WILL_DETACH)) {
        say(e, 1, "USB reset to enter DFU mode");
        e->t->reset(e->t->ctx);
    }
    x = e->t->reenumerate(e->t->ctx, e->reenum_ms);
    if (x < 0) {
        fail(e, x == DFU_XFER_TIMEOUT ? DFU_HOST_TIMEOUT : xfer_host_err(x),
             "the device did not come back in DFU mode within %u ms after DETACH", e->reenum_ms);
        return -1;
    }
    if (x == 0) {
        fail(e, DFU_HOST_PROTOCOL, "the device came back after DETACH without a DFU interface");
        return -1;
    }
    e->last_xfer = 0;
    e->t->functional(e->t->ctx, &e->desc);
    return 0;
}

/* An image larger than the device's application area is refused before the first
 * DNLOAD, which would erase the old valid mark. */
static int fits(eng *e, size_t len)
{
    uint32_t cap = e->desc.app_capacity;
    if (cap == 0 || len <= cap) return 1;
    fail(e, DFU_HOST_BAD_IMAGE,
         "the image's %zu bytes of firmware do not fit the device's "
         "application area of %u bytes; nothing was sent, the device keeps its firmware",
         len, (unsigned)cap);
    return 0;
}

/* Bring the device to dfuIDLE from wherever it is. */
static int to_idle(eng *e)
{
    dstat s = {0, 0, 0};
    int detached = 0;
    for (int tries = 0; tries < 16; tries++) {
        int x = getstatus(e, &s);
        if (x < 0) {
            fail_xfer(e, x, "GETSTATUS (asking the device for its state)");
            return -1;
        }
        switch (s.state) {
        case DFU_STATE_IDLE: return 0;
        case DFU_STATE_APP_IDLE:
        case DFU_STATE_APP_DETACH:
            if (detached) {
                fail(e, DFU_HOST_PROTOCOL, "the device stayed in run-time mode (%s) after DETACH",
                     dfu_state_name(s.state));
                return -1;
            }
            if (detach(e, s.state) < 0) return -1;
            detached = 1;
            break;
        case DFU_STATE_ERROR:
            say(e, 1, "the device is in dfuERROR with %s (%s): CLRSTATUS", dfu_status_name(s.status),
                dfu_status_text(s.status));
            if ((x = req(e, DFU_REQTYPE_OUT, DFU_REQ_CLRSTATUS, 0, NULL, 0)) < 0) {
                fail_xfer(e, x, "CLRSTATUS");
                return -1;
            }
            break;
        case DFU_STATE_DNLOAD_IDLE:
        case DFU_STATE_UPLOAD_IDLE:
            say(e, 1, "the device is in %s from an earlier transfer: ABORT", dfu_state_name(s.state));
            if ((x = req(e, DFU_REQTYPE_OUT, DFU_REQ_ABORT, 0, NULL, 0)) < 0) {
                fail_xfer(e, x, "ABORT");
                return -1;
            }
            break;
        case DFU_STATE_DNLOAD_SYNC:
        case DFU_STATE_DNBUSY:
        case DFU_STATE_MANIFEST_SYNC:
        case DFU_STATE_MANIFEST: sleep_ms(e, s.poll_ms ? s.poll_ms : 1); break;
        case DFU_STATE_MANIFEST_WAIT_RESET:
            if ((x = reset_and_wait(e, "the device waits for a reset")) != 1) {
                fail(e, DFU_HOST_TIMEOUT, "the device did not come back in DFU mode after a reset");
                return -1;
            }
            break;
        default: fail(e, DFU_HOST_PROTOCOL, "the device reports an unknown state %u", s.state); return -1;
        }
    }
    fail(e, DFU_HOST_PROTOCOL, "the device did not reach dfuIDLE (last: %s, %s)", dfu_state_name(s.state),
         dfu_status_name(s.status));
    return -1;
}

/* After a DNLOAD block: poll until the device has written it (dfuDNLOAD-IDLE). */
static int wait_block(eng *e, uint32_t blk)
{
    dstat s;
    for (unsigned polls = 0; polls < MAX_POLLS; polls++) {
        int x = getstatus(e, &s);
        if (x < 0) {
            fail_xfer(e, x, "GETSTATUS after block %u of %u", blk + 1, e->r->blocks_total);
            return -1;
        }
        if (s.status != DFU_STATUS_OK || s.state == DFU_STATE_ERROR) {
            size_t end = e->r->bytes_done + e->r->transfer_size;
            if (end > e->r->payload_len) end = e->r->payload_len;
            fail_device(e, &s, "while writing block %u of %u (image bytes %zu..%zu)", blk + 1, e->r->blocks_total,
                        e->r->bytes_done, end - 1);
            return -1;
        }
        switch (s.state) {
        case DFU_STATE_DNLOAD_IDLE: return 0;
        case DFU_STATE_DNBUSY:
        case DFU_STATE_DNLOAD_SYNC:
            sleep_ms(e, s.poll_ms); /* the device asked for this much time */
            break;
        default:
            fail(e, DFU_HOST_PROTOCOL, "after block %u the device is in %s, not dfuDNLOAD-IDLE", blk + 1,
                 dfu_state_name(s.state));
            return -1;
        }
    }
    fail(e, DFU_HOST_TIMEOUT, "the device stayed busy with block %u", blk + 1);
    return -1;
}

/* The zero-length DNLOAD and the manifestation phase. */
static int manifest(eng *e, uint32_t blk)
{
    int tolerant = (e->desc.attributes & DFU_ATTR_MANIFEST_TOLERANT) != 0;
    dstat s;
    say(e, 1, "end of image: zero-length DNLOAD, manifestation (device is %smanifestation-tolerant)",
        tolerant ? "" : "not ");
    int x = req(e, DFU_REQTYPE_OUT, DFU_REQ_DNLOAD, (uint16_t)blk, NULL, 0);
    if (x == DFU_XFER_STALL && getstatus(e, &s) == 0) {
        fail_device(e, &s, "when told the download was complete");
        return -1;
    }
    if (x < 0) {
        fail_xfer(e, x, "the final zero-length DNLOAD");
        return -1;
    }
    e->r->manifest_started = 1;
    for (unsigned polls = 0; polls < MAX_POLLS; polls++) {
        x = getstatus(e, &s);
        if (x < 0) {
            if (!tolerant && polls > 0) {
                say(e, 1,
                    "no answer during manifestation (normal for a device that is not "
                    "manifestation-tolerant)");
                e->last_xfer = 0;
                return 0;
            }
            fail_xfer(e, x, "GETSTATUS during manifestation");
            return -1;
        }
        if (s.status != DFU_STATUS_OK || s.state == DFU_STATE_ERROR) {
            fail_device(e, &s, "during manifestation (checking the received image and marking it valid)");
            return -1;
        }
        switch (s.state) {
        case DFU_STATE_MANIFEST_SYNC:
        case DFU_STATE_MANIFEST: sleep_ms(e, s.poll_ms); break;
        case DFU_STATE_IDLE:
        case DFU_STATE_MANIFEST_WAIT_RESET: e->r->manifested = 1; return 0;
        default:
            fail(e, DFU_HOST_PROTOCOL, "during manifestation the device is in %s", dfu_state_name(s.state));
            return -1;
        }
    }
    fail(e, DFU_HOST_TIMEOUT, "manifestation did not finish");
    return -1;
}

/* Reset so that the bootloader checks and runs the new firmware, and see it come back. */
static void finish(eng *e)
{
    dfu_host_report *r = e->r;
    int x = reset_and_wait(e, "to run the new firmware");
    if (x < 0) {
        r->reenumerated = -1;
        append(e,
               "; the device did not re-enumerate within %u ms (an application without USB "
               "does not)",
               e->reenum_ms);
        return;
    }
    r->reenumerated = x;
    if (x == 0) {
        append(e, "; the device re-enumerated without a DFU interface (the new firmware runs)");
        return;
    }
    dstat s;
    if (getstatus(e, &s) < 0) {
        append(e, "; the device re-enumerated but did not answer GETSTATUS");
        return;
    }
    r->final_state = s.state;
    if (s.state == DFU_STATE_ERROR) {
        fail(e, DFU_HOST_DEVICE_ERROR,
             "after the reset the device reports %s (%s): it did not accept the new firmware and "
             "stays in DFU mode",
             dfu_status_name(s.status), dfu_status_text(s.status));
    } else if (s.state == DFU_STATE_APP_IDLE || s.state == DFU_STATE_APP_DETACH) {
        append(e, "; the device re-enumerated and runs the new firmware (%s)", dfu_state_name(s.state));
    } else {
        append(e, "; the device re-enumerated in DFU mode (%s)", dfu_state_name(s.state));
    }
}

static void report_init(dfu_host_report *r, size_t len)
{
    memset(r, 0, sizeof *r);
    r->reenumerated = -1;
    r->payload_len = len;
}

static void engine_init(eng *e, const dfu_transport *t, const dfu_host_opts *o, dfu_host_report *r)
{
    static const dfu_host_opts none;
    memset(e, 0, sizeof *e);
    e->t = t;
    e->o = o ? o : &none;
    e->r = r;
    e->timeout_ms = e->o->timeout_ms ? e->o->timeout_ms : DEFAULT_TIMEOUT_MS;
    e->reenum_ms = e->o->reenum_timeout_ms ? e->o->reenum_timeout_ms : DEFAULT_REENUM_MS;
    t->functional(t->ctx, &e->desc);
}

dfu_host_err dfu_host_download(const dfu_transport *t, const uint8_t *payload, size_t len, const dfu_host_opts *o,
                               dfu_host_report *r)
{
    eng e;
    report_init(r, len);
    engine_init(&e, t, o, r);
    if (len == 0) {
        fail(&e, DFU_HOST_BAD_IMAGE, "no firmware bytes to download");
        return r->err;
    }
    r->payload_crc = crc_update(0, payload, len);
    uint16_t want = e.o->transfer_size;
    if (want && e.desc.transfer_size && want > e.desc.transfer_size) {
        fail(&e, DFU_HOST_BAD_ARGS, "transfer size %u is larger than the device's wTransferSize %u", want,
             e.desc.transfer_size);
        return r->err;
    }
    if (!fits(&e, len)) return r->err;
    if (to_idle(&e) < 0) {
        recover(&e);
        return r->err;
    }
    if (!fits(&e, len)) /* the descriptor may have changed with DETACH */
        return r->err;
    if (!(e.desc.attributes & DFU_ATTR_CAN_DNLOAD)) {
        fail(&e, DFU_HOST_BAD_ARGS, "the device does not accept downloads (bitCanDnload is 0)");
        return r->err;
    }
    uint16_t ts = want ? want : e.desc.transfer_size;
    if (ts == 0) {
        fail(&e, DFU_HOST_BAD_ARGS, "the device's wTransferSize is 0: give --transfer-size");
        return r->err;
    }
    if (e.desc.transfer_size && ts > e.desc.transfer_size) {
        fail(&e, DFU_HOST_BAD_ARGS, "transfer size %u is larger than the device's wTransferSize %u", ts,
             e.desc.transfer_size);
        return r->err;
    }
    r->transfer_size = ts;
    r->blocks_total = (uint32_t)((len + ts - 1) / ts);
    if (r->blocks_total > 0xFFFFu) say(&e, 1, "%u blocks: the 16-bit block number wraps around", r->blocks_total);
    uint8_t *buf = malloc(ts);
    if (!buf) {
        fail(&e, DFU_HOST_IO, "out of memory");
        return r->err;
    }
    say(&e, 1, "downloading %zu bytes in %u blocks of %u bytes", len, r->blocks_total, ts);
    uint32_t blk = 0;
    for (size_t off = 0; off < len; blk++) {
        uint16_t n = (uint16_t)(len - off < ts ? len - off : ts);
        memcpy(buf, payload + off, n);
        int x = req(&e, DFU_REQTYPE_OUT, DFU_REQ_DNLOAD, (uint16_t)blk, buf, n);
        if (x >= 0) e.sent_dnload = 1;
        dstat s;
        if (x == DFU_XFER_STALL && getstatus(&e, &s) == 0) {
            fail_device(&e, &s, "and refused block %u of %u", blk + 1, r->blocks_total);
            goto failed;
        }
        if (x < 0) {
            fail_xfer(&e, x, "DNLOAD of block %u of %u (image bytes %zu..%zu)", blk + 1, r->blocks_total, off,
                      off + n - 1);
            goto failed;
        }
        if (wait_block(&e, blk) < 0) goto failed;
        off += n;
        r->blocks_done = blk + 1;
        r->bytes_done = off;
        if (e.o->progress) e.o->progress(e.o->user, off, len);
    }
    free(buf);
    buf = NULL;
    if (manifest(&e, blk) < 0) goto failed;
    snprintf(r->msg, sizeof r->msg, "downloaded %zu bytes in %u blocks of %u bytes; %s", len, r->blocks_total, ts,
             r->manifested ? "the device verified the image and marked it valid"
                           : "manifestation not confirmed by the device");
    finish(&e);
    return r->err;
failed:
    free(buf);
    recover(&e);
    return r->err;
}

dfu_host_err dfu_host_flash(const dfu_transport *t, const uint8_t *file, size_t len, uint16_t vid, uint16_t pid,
                            const dfu_host_opts *o, dfu_host_report *r)
{
    dfu_image_t img;
    dfu_image_err ie = dfu_image_parse(file, len, &img);
    if (ie == DFU_IMAGE_OK) ie = dfu_image_match(&img, vid, pid);
    if (ie != DFU_IMAGE_OK) {
        report_init(r, 0);
        r->err = DFU_HOST_BAD_IMAGE;
        if (ie == DFU_IMAGE_BAD_CRC)
            snprintf(r->msg, sizeof r->msg, "%s (suffix dwCRC 0x%08x, computed 0x%08x)", dfu_image_strerror(ie),
                     (unsigned)img.crc_stored, (unsigned)img.crc_computed);
        else if (ie == DFU_IMAGE_WRONG_VENDOR || ie == DFU_IMAGE_WRONG_PRODUCT)
            snprintf(r->msg, sizeof r->msg, "%s: the image is for %04x:%04x, the device is %04x:%04x",
                     dfu_image_strerror(ie), img.id_vendor, img.id_product, vid, pid);
        else
            snprintf(r->msg, sizeof r->msg, "%s", dfu_image_strerror(ie));
        return r->err;
    }
    return dfu_host_download(t, img.payload, img.payload_len, o, r);
}
