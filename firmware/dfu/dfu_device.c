/* dfu_device.c - the DFU 1.1 device state machine of the bootloader (see
 * dfu_device.h): request handling per state, the dfuDNBUSY/dfuMANIFEST work done
 * from the main loop, the staged write with the valid mark written last, and the
 * boot-time firmware check. Freestanding, no libc, integer only. */
#include "dfu_device.h"

#include "crc32.h"

enum { WORK_NONE = 0, WORK_BLOCK = 1, WORK_MANIFEST = 2 };

#define CHUNK 64u /* read-back buffer on the stack */

static int due(uint32_t now, uint32_t t)
{
    return (int32_t)(now - t) >= 0;
}

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint32_t trailer_offset(const dfu_flash_t *f)
{
    return f->size - f->page_size;
}

uint32_t dfu_app_capacity(const dfu_flash_t *f)
{
    return trailer_offset(f);
}

static int geometry_ok(const dfu_flash_t *f)
{
    return f && f->erase && f->program && f->read && f->page_size >= DFU_TRAILER_LEN && f->size / f->page_size >= 2u &&
           f->size % f->page_size == 0u;
}

/* CRC-32 of flash [0, n), read back through the callback; -1 on a read failure. */
static int flash_crc(const dfu_flash_t *f, uint32_t n, uint32_t *crc)
{
    uint8_t buf[CHUNK];
    uint32_t c = 0;
    for (uint32_t off = 0; off < n;) {
        uint32_t k = n - off < CHUNK ? n - off : CHUNK;
        if (f->read(f->ctx, off, buf, k) != 0) return -1;
        c = crc_update(c, buf, k);
        off += k;
    }
    *crc = c;
    return 0;
}

static void trailer_build(uint8_t t[DFU_TRAILER_LEN], uint32_t length, uint32_t crc)
{
    put32(t + 0, DFU_TRAILER_MAGIC);
    put32(t + 4, length);
    put32(t + 8, crc);
    put32(t + 12, crc_update(0, t, 12));
}

int dfu_app_check(const dfu_flash_t *f, dfu_app_info_t *info)
{
    uint8_t t[DFU_TRAILER_LEN];
    if (info) info->length = info->crc = 0;
    if (!geometry_ok(f) || f->read(f->ctx, trailer_offset(f), t, DFU_TRAILER_LEN) != 0) return 0;
    if (get32(t) != DFU_TRAILER_MAGIC || get32(t + 12) != crc_update(0, t, 12)) return 0;
    uint32_t length = get32(t + 4), crc = get32(t + 8), actual;
    if (info) {
        info->length = length;
        info->crc = crc;
    }
    if (length == 0 || length > trailer_offset(f)) return 0;
    if (flash_crc(f, length, &actual) != 0) return 0;
    return actual == crc;
}

/* ---- the session ------------------------------------------------------------------ */

static void session_reset(dfu_dev_t *d)
{
    d->work = WORK_NONE;
    d->manifested = 0;
    d->invalidated = 0;
    d->block_len = 0;
    d->received = 0;
    d->erased_end = 0;
    d->crc = 0;
    d->poll_ms = 0;
    d->upload_pos = d->upload_len = 0;
}

static void enter_error(dfu_dev_t *d, uint8_t status)
{
    d->state = DFU_STATE_ERROR;
    d->status = status;
    d->work = WORK_NONE;
}

/* After a reset or at power-on in DFU mode: run a valid application, else stay. */
static void boot(dfu_dev_t *d, int stay_in_dfu)
{
    session_reset(d);
    d->detach_pending = 0;
    d->status = DFU_STATUS_OK;
    if (dfu_app_check(&d->flash, 0))
        d->state = stay_in_dfu ? DFU_STATE_IDLE : DFU_STATE_APP_IDLE;
    else
        enter_error(d, DFU_STATUS_ERR_FIRMWARE);
}

int dfu_dev_init(dfu_dev_t *d, const dfu_dev_config_t *cfg, const dfu_flash_t *flash, int stay_in_dfu, uint32_t now_ms)
{
    (void)now_ms;
    if (!d || !cfg || !geometry_ok(flash) || cfg->transfer_size == 0 || cfg->transfer_size > DFU_MAX_TRANSFER)
        return -1;
    d->cfg = *cfg;
    d->flash = *flash;
    d->busy_until = 0;
    d->next_block = 0;
    boot(d, stay_in_dfu);
    return 0;
}

/* Erase one page and check that it reads blank. */
static uint8_t erase_page(const dfu_flash_t *f, uint32_t page)
{
    uint8_t buf[CHUNK];
    if (f->erase(f->ctx, page) != 0) return DFU_STATUS_ERR_ERASE;
    for (uint32_t off = 0; off < f->page_size;) {
        uint32_t k = f->page_size - off < CHUNK ? f->page_size - off : CHUNK;
        if (f->read(f->ctx, page + off, buf, k) != 0) return DFU_STATUS_ERR_CHECK_ERASED;
        for (uint32_t i = 0; i < k; i++)
            if (buf[i] != 0xFFu) return DFU_STATUS_ERR_CHECK_ERASED;
        off += k;
    }
    return DFU_STATUS_OK;
}

/* Program n bytes at off (inside one erased page) and read them back. */
static uint8_t program_verify(const dfu_flash_t *f, uint32_t off, const uint8_t *src, uint32_t n)
{
    uint8_t buf[CHUNK];
    if (f->program(f->ctx, off, src, n) != 0) return DFU_STATUS_ERR_WRITE;
    for (uint32_t done = 0; done < n;) {
        uint32_t k = n - done < CHUNK ? n - done : CHUNK;
        if (f->read(f->ctx, off + done, buf, k) != 0) return DFU_STATUS_ERR_VERIFY;
        for (uint32_t i = 0; i < k; i++)
            if (buf[i] != src[done + i]) return DFU_STATUS_ERR_VERIFY;
        done += k;
    }
    return DFU_STATUS_OK;
}

/* dfuDNBUSY work: the valid mark goes first, then pages are erased as the image
 * reaches them, the block programmed and verified. */
static uint8_t do_block(dfu_dev_t *d)
{
    const dfu_flash_t *f = &d->flash;
    uint8_t st;
    if (!d->invalidated) {
        if ((st = erase_page(f, trailer_offset(f))) != DFU_STATUS_OK) return st;
        d->invalidated = 1;
    }
    uint32_t off = d->received, end = d->received + d->block_len;
    const uint8_t *src = d->block;
    while (off < end) {
        if (off >= d->erased_end) {
            if ((st = erase_page(f, d->erased_end)) != DFU_STATUS_OK) return st;
            d->erased_end += f->page_size;
        }
        uint32_t n = (d->erased_end < end ? d->erased_end : end) - off;
        if ((st = program_verify(f, off, src, n)) != DFU_STATUS_OK) return st;
        off += n;
        src += n;
    }
    d->crc = crc_update(d->crc, d->block, d->block_len);
    d->received = end;
    d->block_len = 0;
    return DFU_STATUS_OK;
}

/* dfuMANIFEST work: read the whole image back, compare its CRC with what was
 * received, then write the valid mark (the commit point) and check it. */
static uint8_t do_manifest(dfu_dev_t *d)
{
    const dfu_flash_t *f = &d->flash;
    uint32_t crc;
    uint8_t t[DFU_TRAILER_LEN];
    if (d->received == 0 || !d->invalidated) return DFU_STATUS_ERR_NOTDONE;
    if (flash_crc(f, d->received, &crc) != 0 || crc != d->crc) return DFU_STATUS_ERR_VERIFY;
    trailer_build(t, d->received, d->crc);
    uint8_t st = program_verify(f, trailer_offset(f), t, DFU_TRAILER_LEN);
    if (st != DFU_STATUS_OK) return st;
    return dfu_app_check(f, 0) ? DFU_STATUS_OK : DFU_STATUS_ERR_VERIFY;
}

void dfu_dev_poll(dfu_dev_t *d, uint32_t now)
{
    uint8_t st;
    switch (d->state) {
    case DFU_STATE_APP_DETACH:
        if (due(now, d->busy_until)) d->state = DFU_STATE_APP_IDLE;
        break;
    case DFU_STATE_DNBUSY:
        if (d->work == WORK_BLOCK) {
            d->work = WORK_NONE;
            if ((st = do_block(d)) != DFU_STATUS_OK) {
                enter_error(d, st);
                break;
            }
        }
        if (due(now, d->busy_until)) d->state = DFU_STATE_DNLOAD_SYNC;
        break;
    case DFU_STATE_MANIFEST:
        if (d->work == WORK_MANIFEST) {
            d->work = WORK_NONE;
            if ((st = do_manifest(d)) != DFU_STATUS_OK) {
                enter_error(d, st);
                break;
            }
            d->manifested = 1;
        }
        if (due(now, d->busy_until))
            d->state = (d->cfg.attributes & DFU_ATTR_MANIFEST_TOLERANT) ? DFU_STATE_MANIFEST_SYNC
                                                                        : DFU_STATE_MANIFEST_WAIT_RESET;
        break;
    default: break;
    }
}

void dfu_dev_bus_reset(dfu_dev_t *d, uint32_t now)
{
    switch (d->state) {
    case DFU_STATE_APP_IDLE: break;
    case DFU_STATE_APP_DETACH:
        d->detach_pending = 0;
        if (due(now, d->busy_until)) {
            d->state = DFU_STATE_APP_IDLE;
        } else {
            session_reset(d);
            d->state = DFU_STATE_IDLE;
            d->status = DFU_STATUS_OK;
        }
        break;
    default: boot(d, 0); break;
    }
}

/* ---- requests ------------------------------------------------------------------------ */

static dfu_dev_result stall(dfu_dev_t *d, uint8_t status)
{
    switch (d->state) {
    case DFU_STATE_APP_IDLE:
    case DFU_STATE_MANIFEST_WAIT_RESET: break; /* no state change */
    case DFU_STATE_APP_DETACH: d->state = DFU_STATE_APP_IDLE; break;
    default: enter_error(d, status); break;
    }
    return DFU_DEV_STALL;
}

static uint32_t block_poll_ms(const dfu_dev_t *d)
{
    uint32_t ps = d->flash.page_size, end = d->received + d->block_len, pages = 0;
    if (end > d->erased_end) pages = (end - d->erased_end + ps - 1u) / ps;
    if (!d->invalidated) pages++;
    return d->cfg.program_ms + pages * d->cfg.erase_ms;
}

static dfu_dev_result getstatus(dfu_dev_t *d, uint32_t now, uint16_t w_length, uint8_t *data, uint16_t *actual)
{
    uint32_t poll = 0;
    switch (d->state) {
    case DFU_STATE_DNLOAD_SYNC:
        if (d->block_len) {
            poll = block_poll_ms(d);
            d->work = WORK_BLOCK;
            d->state = DFU_STATE_DNBUSY;
        } else {
            d->state = DFU_STATE_DNLOAD_IDLE;
        }
        break;
    case DFU_STATE_MANIFEST_SYNC:
        if (!d->manifested) {
            poll = d->cfg.manifest_ms;
            d->work = WORK_MANIFEST;
            d->state = DFU_STATE_MANIFEST;
        } else {
            session_reset(d);
            d->state = DFU_STATE_IDLE;
        }
        break;
    default: break;
    }
    if (poll > DFU_POLL_TIMEOUT_MAX) poll = DFU_POLL_TIMEOUT_MAX;
    d->poll_ms = poll;
    d->busy_until = now + poll;
    uint8_t r[DFU_GETSTATUS_LEN] = {d->status, (uint8_t)poll, (uint8_t)(poll >> 8), (uint8_t)(poll >> 16), d->state, 0};
    uint16_t n = w_length < DFU_GETSTATUS_LEN ? w_length : DFU_GETSTATUS_LEN;
    for (uint16_t i = 0; i < n; i++) data[i] = r[i];
    *actual = n;
    return DFU_DEV_ACK;
}

static dfu_dev_result dnload(dfu_dev_t *d, uint16_t w_value, uint16_t w_length, const uint8_t *data)
{
    if (!(d->cfg.attributes & DFU_ATTR_CAN_DNLOAD)) return stall(d, DFU_STATUS_ERR_STALLEDPKT);
    if (w_length == 0) {
        if (d->state != DFU_STATE_DNLOAD_IDLE) return stall(d, DFU_STATUS_ERR_NOTDONE); /* nothing received yet */
        d->state = DFU_STATE_MANIFEST_SYNC;
        d->manifested = 0;
        return DFU_DEV_ACK;
    }
    if (w_length > d->cfg.transfer_size) return stall(d, DFU_STATUS_ERR_STALLEDPKT);
    if (d->state == DFU_STATE_IDLE) {
        session_reset(d); /* a new download starts */
    } else if (w_value != d->next_block) {
        return stall(d, DFU_STATUS_ERR_ADDRESS); /* block out of sequence */
    }
    if (w_length > dfu_app_capacity(&d->flash) - d->received)
        return stall(d, DFU_STATUS_ERR_ADDRESS); /* image larger than the region */
    for (uint16_t i = 0; i < w_length; i++) d->block[i] = data[i];
    d->block_len = w_length;
    d->next_block = (uint16_t)(w_value + 1u);
    d->state = DFU_STATE_DNLOAD_SYNC;
    return DFU_DEV_ACK;
}

static dfu_dev_result upload(dfu_dev_t *d, uint16_t w_length, uint8_t *data, uint16_t *actual)
{
    if (!(d->cfg.attributes & DFU_ATTR_CAN_UPLOAD) || w_length > d->cfg.transfer_size)
        return stall(d, DFU_STATUS_ERR_STALLEDPKT);
    if (d->state == DFU_STATE_IDLE) {
        dfu_app_info_t info;
        session_reset(d);
        d->upload_len = dfu_app_check(&d->flash, &info) ? info.length : 0;
    }
    uint32_t left = d->upload_len - d->upload_pos;
    uint16_t n = left < w_length ? (uint16_t)left : w_length;
    if (n && d->flash.read(d->flash.ctx, d->upload_pos, data, n) != 0) return stall(d, DFU_STATUS_ERR_UNKNOWN);
    d->upload_pos += n;
    *actual = n;
    d->state = n < w_length ? DFU_STATE_IDLE : DFU_STATE_UPLOAD_IDLE; /* short frame ends it */
    return DFU_DEV_ACK;
}

dfu_dev_result dfu_dev_request(dfu_dev_t *d, uint32_t now, uint8_t bm_request_type, uint8_t b_request, uint16_t w_value,
                               uint16_t w_length, uint8_t *data, uint16_t *actual)
{
    uint16_t dummy;
    if (!actual) actual = &dummy;
    *actual = 0;
    dfu_dev_poll(d, now); /* end a timed state that is over */

    int in = b_request == DFU_REQ_UPLOAD || b_request == DFU_REQ_GETSTATUS || b_request == DFU_REQ_GETSTATE;
    if (b_request > DFU_REQ_ABORT || bm_request_type != (in ? DFU_REQTYPE_IN : DFU_REQTYPE_OUT) || (w_length && !data))
        return stall(d, DFU_STATUS_ERR_STALLEDPKT);

    uint8_t s = d->state;
    switch (b_request) {
    case DFU_REQ_GETSTATUS:
        if (s == DFU_STATE_DNBUSY || s == DFU_STATE_MANIFEST) break; /* the host must wait bwPollTimeout */
        return getstatus(d, now, w_length, data, actual);
    case DFU_REQ_GETSTATE:
        if (s == DFU_STATE_DNBUSY || s == DFU_STATE_MANIFEST) break;
        if (w_length) {
            data[0] = s;
            *actual = 1;
        }
        return DFU_DEV_ACK;
    case DFU_REQ_DETACH:
        if (s != DFU_STATE_APP_IDLE) break;
        d->state = DFU_STATE_APP_DETACH;
        d->busy_until = now + (w_value < d->cfg.detach_timeout_ms ? w_value : d->cfg.detach_timeout_ms);
        d->detach_pending = (d->cfg.attributes & DFU_ATTR_WILL_DETACH) ? 1 : 0;
        return DFU_DEV_ACK;
    case DFU_REQ_DNLOAD:
        if (s != DFU_STATE_IDLE && s != DFU_STATE_DNLOAD_IDLE) break;
        return dnload(d, w_value, w_length, data);
    case DFU_REQ_UPLOAD:
        if (s != DFU_STATE_IDLE && s != DFU_STATE_UPLOAD_IDLE) break;
        return upload(d, w_length, data, actual);
    case DFU_REQ_CLRSTATUS:
        if (s != DFU_STATE_ERROR) break;
        session_reset(d);
        d->state = DFU_STATE_IDLE;
        d->status = DFU_STATUS_OK;
        return DFU_DEV_ACK;
    case DFU_REQ_ABORT:
        if (s != DFU_STATE_IDLE && s != DFU_STATE_DNLOAD_IDLE && s != DFU_STATE_UPLOAD_IDLE) break;
        session_reset(d);
        d->state = DFU_STATE_IDLE;
        return DFU_DEV_ACK;
    default: break;
    }
    return stall(d, DFU_STATUS_ERR_STALLEDPKT);
}
