/* fuzz_dfu.c - libFuzzer harness for the DFU image parser and the bootloader's DFU
 * state machine (firmware/dfu/).
 *
 * The first input byte (mod 3) picks what the rest is:
 *
 *   0 file     a DFU file, given to dfu_image_parse in an exact-size copy.
 *   1 suffix   [vid u16][pid u16][bcdDevice u16][edit u8][edits: (at u8, xor u8) x (edit & 3)]
 *              [cut u8 if edit & 8][payload...]: the harness appends a correct suffix
 *              to the payload (dfu_suffix_build), which must then parse, and flips
 *              bytes near the end, optionally puts a correct CRC back (edit & 4, so
 *              that bLength and bcdDFU are reached) and cuts the file short.
 *   2 device   [attributes u8][transfer u8][geometry u8][flash u8][clock u32][ops...]
 *              a bootloader (attributes, timing, wTransferSize, flash geometry and what
 *              the flash holds at power-on taken from the first bytes; also
 *              configurations it must refuse) over an in-memory flash of a few KB,
 *              driven by requests, polls, clock steps, USB resets, power cycles and
 *              flash faults (failing or corrupting erases and programs, failing reads),
 *              one op a byte or three (see run_device).
 *
 * Checked (abort() on failure):
 *   file, suffix: the result and every field agree with an implementation of
 *   dfu_image.h written here; data[0..len) is an exact malloc block (ASan reports any
 *   read outside it); on success the payload lies at the start of the buffer,
 *   payload_len + suffix_len == len, crc_computed == crc_stored, and a suffix rebuilt
 *   with dfu_suffix_build over the payload with the parsed ids parses again with the
 *   same fields (the very same bytes when bLength is 16); dfu_image_match agrees.
 *   device: the flash callbacks are only asked for whole pages in range, programs
 *   within one page erased in this download, in increasing order, each byte once,
 *   reads in range; the valid mark is written only over exactly the bytes the host
 *   sent in this download, read back; whenever flash holds a valid mark (checked here
 *   independently), the application bytes are the ones last committed; dfu_app_check
 *   agrees; the application states are only reached with a valid application; a
 *   stalled request in DFU mode leaves dfuERROR; answers (GETSTATUS, GETSTATE,
 *   UPLOAD) say what the device holds and never write past wLength (the data buffer
 *   is an exact malloc block). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dfu_device.h"
#include "dfu_image.h"
#include "dfu_proto.h"
#include "fuzz_util.h"

#define MAX_OPS 256

typedef struct {
    const uint8_t *p;
    size_t n;
} cursor;

static uint32_t next8(cursor *c)
{
    if (!c->n) return 0;
    c->n--;
    return *c->p++;
}

static uint32_t next16(cursor *c)
{
    uint32_t v = next8(c);
    return v | next8(c) << 8;
}

static uint32_t next32(cursor *c)
{
    uint32_t v = next16(c);
    return v | next16(c) << 16;
}

/* ======================================================================== */
/* The file format                                                          */
/* ======================================================================== */

/* dfu_image.h's checks in its order: what dfu_image_parse must answer. */
static dfu_image_err ref_parse(const uint8_t *d, size_t len, uint32_t *crc)
{
    *crc = 0;
    if (len < DFU_SUFFIX_LEN) return DFU_IMAGE_TOO_SHORT;
    const uint8_t *s = d + len - DFU_SUFFIX_LEN;
    if (s[8] != 0x55 || s[9] != 0x46 || s[10] != 0x44) return DFU_IMAGE_NO_SIGNATURE;
    if (s[11] != DFU_SUFFIX_LEN) return DFU_IMAGE_BAD_LENGTH;
    *crc = ~ref_crc(d, len - 4); /* preset ~0, no final complement */
    if (*crc != rd32(s + 12)) return DFU_IMAGE_BAD_CRC;
    if ((s[6] | s[7] << 8) != DFU_SUFFIX_BCD_DFU) return DFU_IMAGE_BAD_VERSION;
    if (len == s[11]) return DFU_IMAGE_EMPTY;
    return DFU_IMAGE_OK;
}

static void check_match(const dfu_image_t *img, uint16_t vid, uint16_t pid)
{
    dfu_image_err want = DFU_IMAGE_OK;
    if (img->id_vendor != DFU_ID_ANY && img->id_vendor != vid)
        want = DFU_IMAGE_WRONG_VENDOR;
    else if (img->id_product != DFU_ID_ANY && img->id_product != pid)
        want = DFU_IMAGE_WRONG_PRODUCT;
    REQUIRE(dfu_image_match(img, vid, pid) == want);
    REQUIRE(dfu_image_strerror(want)[0] != 0);
}

/* Parse data[0..len) (an exact malloc block) and check everything the header says. */
static dfu_image_err check_file(const uint8_t *d, size_t len, uint16_t vid, uint16_t pid)
{
    dfu_image_t img;
    memset(&img, 0xA5, sizeof img);
    dfu_image_err err = dfu_image_parse(d, len, &img);
    uint32_t crc;
    REQUIRE(err == ref_parse(d, len, &crc));
    const char *msg = dfu_image_strerror(err);
    REQUIRE(msg && msg[0]);
    REQUIRE(dfu_image_parse(d, len, NULL) == err);

    if (err == DFU_IMAGE_TOO_SHORT) {
        REQUIRE(img.payload_len == 0 && img.suffix_len == 0 && img.crc_stored == 0 && img.crc_computed == 0);
        REQUIRE(img.bcd_device == 0 && img.id_product == 0 && img.id_vendor == 0 && img.bcd_dfu == 0);
        return err;
    }
    const uint8_t *s = d + len - DFU_SUFFIX_LEN;
    REQUIRE(img.bcd_device == (s[0] | s[1] << 8) && img.id_product == (s[2] | s[3] << 8));
    REQUIRE(img.id_vendor == (s[4] | s[5] << 8) && img.bcd_dfu == (s[6] | s[7] << 8));
    REQUIRE(img.suffix_len == s[11] && img.crc_stored == rd32(s + 12));
    if (err == DFU_IMAGE_OK || err >= DFU_IMAGE_BAD_CRC) REQUIRE(img.crc_computed == crc);
    REQUIRE(dfu_suffix_crc(d, len - 4) == ~ref_crc(d, len - 4));
    check_match(&img, (uint16_t)vid, (uint16_t)pid);
    check_match(&img, img.id_vendor, img.id_product);
    if (err != DFU_IMAGE_OK) return err;

    /* the payload is the start of the buffer and the suffix the rest of it */
    REQUIRE(img.payload == d && img.payload_len > 0);
    REQUIRE(img.payload_len + img.suffix_len == len && img.suffix_len >= DFU_SUFFIX_LEN);
    REQUIRE(img.crc_computed == img.crc_stored && img.bcd_dfu == DFU_SUFFIX_BCD_DFU);

    /* a suffix rebuilt over the payload with the parsed ids parses the same */
    size_t n = img.payload_len, len2 = n + DFU_SUFFIX_LEN;
    uint8_t *f = malloc(len2);
    if (!f) abort();
    memcpy(f, img.payload, n);
    dfu_suffix_build(f + n, img.payload, n, img.id_vendor, img.id_product, img.bcd_device);
    dfu_image_t again;
    REQUIRE(dfu_image_parse(f, len2, &again) == DFU_IMAGE_OK);
    REQUIRE(again.payload == f && again.payload_len == n && again.suffix_len == DFU_SUFFIX_LEN);
    REQUIRE(again.id_vendor == img.id_vendor && again.id_product == img.id_product);
    REQUIRE(again.bcd_device == img.bcd_device && again.bcd_dfu == DFU_SUFFIX_BCD_DFU);
    if (img.suffix_len == DFU_SUFFIX_LEN) REQUIRE(len2 == len && memcmp(f, d, len) == 0);
    free(f);
    return err;
}

static void run_file(const uint8_t *p, size_t n)
{
    uint8_t *d = fuzz_copy_exact(p, n);
    check_file(d, n, 0x1209, 0x0001);
    free(d);
}

static void run_suffix(cursor *c)
{
    uint32_t vid = next16(c), pid = next16(c), bcd = next16(c), edit = next8(c);
    uint8_t edits[3][2];
    for (uint32_t i = 0; i < (edit & 3u); i++) {
        edits[i][0] = (uint8_t)next8(c);
        edits[i][1] = (uint8_t)next8(c);
    }
    uint32_t cut = edit & 8u ? next8(c) : 0;
    size_t n = c->n, len = n + DFU_SUFFIX_LEN;

    uint8_t *f = malloc(len);
    if (!f) abort();
    if (n) memcpy(f, c->p, n);
    dfu_suffix_build(f + n, c->p, n, (uint16_t)vid, (uint16_t)pid, (uint16_t)bcd);
    REQUIRE(check_file(f, len, (uint16_t)vid, (uint16_t)pid) == (n ? DFU_IMAGE_OK : DFU_IMAGE_EMPTY));
    dfu_image_t img;
    dfu_image_parse(f, len, &img);
    REQUIRE(img.id_vendor == vid && img.id_product == pid && img.bcd_device == bcd);
    REQUIRE(dfu_image_match(&img, (uint16_t)vid, (uint16_t)pid) == DFU_IMAGE_OK);

    /* damage near the end: the suffix and the last payload bytes */
    for (uint32_t i = 0; i < (edit & 3u); i++) f[len - 1 - edits[i][0] % (len < 32 ? len : 32)] ^= edits[i][1];
    if (edit & 4u) wr32(f + len - 4, dfu_suffix_crc(f, len - 4));
    len -= cut % (len + 1);
    uint8_t *g = fuzz_copy_exact(f, len); /* exact again after the cut */
    free(f);
    check_file(g, len, (uint16_t)vid, (uint16_t)pid);
    free(g);
}

/* ======================================================================== */
/* The device                                                               */
/* ======================================================================== */

enum { OP_ERASE, OP_PROGRAM, OP_READ, OP_KINDS };

typedef struct {
    uint8_t *mem;
    uint32_t size, page;
    uint32_t *prog_end;    /* per page: bytes programmed so far since its erase */
    uint32_t *erase_epoch; /* per page: the download it was erased in (0: none) */
    uint32_t epoch;        /* the current download (bumped when one starts) */
    uint32_t gen;          /* bumped on every change of mem */
    int quiet;             /* the harness reading: no faults, no contract */

    /* one armed fault: the countdown-th next operation of a kind fails or corrupts */
    int fault_kind, fault_corrupt;
    uint32_t fault_count;
    uint32_t rng;

    /* the host's view */
    uint8_t *img; /* the bytes sent in this download */
    uint32_t img_len;
    uint8_t *com; /* the application last committed (or found at power-on) */
    uint32_t com_len;
    int com_valid;
    uint32_t commits;
} fake_flash;

/* 0: do it; 1: fail; 2: corrupt. */
static int fault(fake_flash *f, int kind)
{
    if (f->quiet || f->fault_kind != kind) return 0;
    if (f->fault_count--) return 0;
    f->fault_kind = -1;
    return f->fault_corrupt && kind != OP_READ ? 2 : 1;
}

static uint32_t trailer_at(const fake_flash *f)
{
    return f->size - f->page;
}

/* The valid mark, as dfu_device.h describes it, checked here: 1 and the length if the
 * region holds an application whose CRC matches it. */
UNTRACED static int ref_valid(const fake_flash *f, uint32_t *length)
{
    const uint8_t *t = f->mem + trailer_at(f);
    *length = 0;
    if (rd32(t) != DFU_TRAILER_MAGIC || rd32(t + 12) != ref_crc(t, 12)) return 0;
    uint32_t n = rd32(t + 4);
    if (n == 0 || n > trailer_at(f)) return 0;
    if (ref_crc(f->mem, n) != rd32(t + 8)) return 0;
    *length = n;
    return 1;
}

/* A valid mark's own fields check out (whatever the application bytes are). */
static int mark_present(const fake_flash *f)
{
    const uint8_t *t = f->mem + trailer_at(f);
    return rd32(t) == DFU_TRAILER_MAGIC && rd32(t + 12) == ref_crc(t, 12);
}

static int cb_erase(void *ctx, uint32_t off)
{
    fake_flash *f = ctx;
    REQUIRE(off < f->size && off % f->page == 0);
    uint32_t p = off / f->page;
    if (p < f->size / f->page - 1u) REQUIRE(!mark_present(f)); /* the mark goes first */
    int h = fault(f, OP_ERASE);
    if (h == 1) return -1;
    memset(f->mem + off, 0xFF, f->page);
    if (h == 2) f->mem[off + xorshift(&f->rng) % f->page] = 0x7E;
    f->prog_end[p] = 0;
    f->erase_epoch[p] = f->epoch;
    f->gen++;
    return 0;
}

static void commit(fake_flash *f, const uint8_t *t)
{
    /* the valid mark: over exactly the bytes the host sent, now in flash */
    REQUIRE(rd32(t) == DFU_TRAILER_MAGIC && rd32(t + 12) == ref_crc(t, 12));
    REQUIRE(rd32(t + 4) == f->img_len && f->img_len > 0);
    REQUIRE(rd32(t + 8) == ref_crc(f->img, f->img_len));
    REQUIRE(memcmp(f->mem, f->img, f->img_len) == 0);
    memcpy(f->com, f->img, f->img_len);
    f->com_len = f->img_len;
    f->com_valid = 1;
    f->commits++;
}

static int cb_program(void *ctx, uint32_t off, const uint8_t *src, uint32_t n)
{
    fake_flash *f = ctx;
    REQUIRE(off < f->size && n <= f->size - off && n > 0);
    uint32_t p = off / f->page, in = off % f->page;
    REQUIRE(in + n <= f->page);                              /* one page */
    REQUIRE(f->erase_epoch[p] == f->epoch && f->epoch != 0); /* erased in this download */
    REQUIRE(in >= f->prog_end[p]);                           /* upwards, each byte once */
    if (off == trailer_at(f)) {
        REQUIRE(n == DFU_TRAILER_LEN);
        commit(f, src);
    } else {
        REQUIRE(!mark_present(f));
    }
    int h = fault(f, OP_PROGRAM);
    if (h == 1) return -1;
    for (uint32_t i = 0; i < n; i++) f->mem[off + i] &= src[i]; /* programming clears bits */
    if (h == 2) f->mem[off + xorshift(&f->rng) % n] ^= (uint8_t)(1u << (xorshift(&f->rng) & 7u));
    f->prog_end[p] = in + n;
    f->gen++;
    return 0;
}

static int cb_read(void *ctx, uint32_t off, uint8_t *dst, uint32_t n)
{
    fake_flash *f = ctx;
    REQUIRE(off <= f->size && n <= f->size - off);
    if (fault(f, OP_READ)) return -1;
    memcpy(dst, f->mem + off, n);
    return 0;
}

static int app_state(uint8_t s)
{
    return s == DFU_STATE_APP_IDLE || s == DFU_STATE_APP_DETACH;
}

/* What must hold between any two steps. */
static void check_device(fake_flash *f, const dfu_dev_t *d, const dfu_flash_t *fl, uint32_t *seen_gen)
{
    REQUIRE(d->state <= DFU_STATE_ERROR && d->status <= DFU_STATUS_ERR_STALLEDPKT);
    REQUIRE(d->state == DFU_STATE_ERROR || d->status == DFU_STATUS_OK);
    REQUIRE(d->received <= dfu_app_capacity(fl) && d->block_len <= d->cfg.transfer_size);
    REQUIRE(d->upload_pos <= d->upload_len && d->upload_len <= dfu_app_capacity(fl));
    REQUIRE(dfu_state_name(d->state) && dfu_status_name(d->status) && dfu_status_text(d->status));
    if (*seen_gen == f->gen && !app_state(d->state)) return;
    *seen_gen = f->gen;
    uint32_t n;
    int valid = ref_valid(f, &n);
    dfu_app_info_t info;
    f->quiet = 1;
    REQUIRE(dfu_app_check(fl, &info) == valid);
    f->quiet = 0;
    if (valid) {
        REQUIRE(info.length == n);
        /* never half-flashed: a valid mark means the bytes last committed */
        REQUIRE(f->com_valid && n == f->com_len && memcmp(f->mem, f->com, n) == 0);
    }
    if (app_state(d->state)) REQUIRE(valid);
}

static const uint16_t transfer_sizes[8] = {1, 7, 16, 64, 100, 256, 1024, DFU_MAX_TRANSFER};
static const uint32_t page_sizes[8] = {16, 32, 64, 128, 256, 512, 1024, 48};

static void run_device(cursor *c)
{
    uint32_t attr = next8(c), tb = next8(c), geo = next8(c), init = next8(c), now = next32(c);

    dfu_dev_config_t cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.attributes = (uint8_t)(attr & 0x0Fu);
    cfg.transfer_size = transfer_sizes[tb & 7u];
    cfg.detach_timeout_ms = 1000;
    cfg.program_ms = 5;
    cfg.erase_ms = 20;
    cfg.manifest_ms = 100;
    switch (attr >> 4 & 7u) { /* timing: the defaults of the loopback device, or extremes */
    case 1:
        cfg.detach_timeout_ms = 0;
        cfg.program_ms = cfg.erase_ms = cfg.manifest_ms = 0;
        break;
    case 2: /* longer than bwPollTimeout can say */
        cfg.program_ms = 0xFFFFF0u;
        cfg.erase_ms = 0x1000000u;
        cfg.manifest_ms = 0x7FFFFFFFu;
        break;
    case 3:
        cfg.detach_timeout_ms = 0xFFFF;
        cfg.erase_ms = 1;
        break;
    default: break;
    }
    uint32_t page = page_sizes[geo & 7u], pages = 2u + (geo >> 3 & 7u);

    fake_flash f;
    memset(&f, 0, sizeof f);
    f.size = pages * page;
    f.page = page;
    f.mem = malloc(f.size);
    f.img = malloc(f.size);
    f.com = malloc(f.size);
    f.prog_end = calloc(pages, sizeof *f.prog_end);
    f.erase_epoch = calloc(pages, sizeof *f.erase_epoch);
    if (!f.mem || !f.img || !f.com || !f.prog_end || !f.erase_epoch) abort();
    f.fault_kind = -1;
    f.rng = init * 0x01000193u + now;
    dfu_flash_t fl = {&f, f.size, f.page, cb_erase, cb_program, cb_read};

    /* what the flash holds at power-on */
    uint32_t cap = f.size - f.page, len = 1u + (init >> 3) * 97u % cap;
    memset(f.mem, 0xFF, f.size);
    switch (init & 7u) {
    case 1: /* a valid application */
    case 2: /* ... whose bytes do not match the mark */
    case 3: /* ... whose mark is longer than the region */
        for (uint32_t i = 0; i < len; i++) f.mem[i] = (uint8_t)xorshift(&f.rng);
        uint8_t *t = f.mem + cap;
        wr32(t, DFU_TRAILER_MAGIC);
        wr32(t + 4, (init & 7u) == 3u ? cap + 1u : len);
        wr32(t + 8, ref_crc(f.mem, len) ^ ((init & 7u) == 2u ? 1u : 0u));
        wr32(t + 12, ref_crc(t, 12));
        break;
    case 4: /* garbage */
        for (uint32_t i = 0; i < f.size; i++) f.mem[i] = (uint8_t)xorshift(&f.rng);
        break;
    default: /* blank */ break;
    }
    uint32_t n0;
    if (ref_valid(&f, &n0)) {
        memcpy(f.com, f.mem, n0);
        f.com_len = n0;
        f.com_valid = 1;
    }

    dfu_dev_t *d = malloc(sizeof *d);
    if (!d) abort();
    if (attr & 0x80u) { /* configurations the device must refuse */
        dfu_flash_t bad = fl;
        dfu_dev_config_t badc = cfg;
        switch (attr >> 4 & 7u) {
        case 0: badc.transfer_size = 0; break;
        case 1: badc.transfer_size = DFU_MAX_TRANSFER + 1u; break;
        case 2: bad.size = bad.page_size; break;
        case 3: bad.size = bad.page_size * 2u + 1u; break;
        case 4:
            bad.page_size = DFU_TRAILER_LEN - 1u;
            bad.size = bad.page_size * 4u;
            break;
        case 5: bad.erase = NULL; break;
        case 6: bad.read = NULL; break;
        default: bad.program = NULL; break;
        }
        REQUIRE(dfu_dev_init(d, &badc, &bad, 0, now) == -1);
        REQUIRE(dfu_dev_init(d, &cfg, NULL, 0, now) == -1);
        goto out;
    }
    REQUIRE(dfu_dev_init(d, &cfg, &fl, init & 0x80u, now) == 0);
    uint32_t seen_gen = ~0u;
    check_device(&f, d, &fl, &seen_gen);
    uint32_t data_rng = now ^ 0x5bd1e995u;

    for (int op = 0; op < MAX_OPS && c->n; op++) {
        uint32_t o = next8(c);
        if (o < 0x80u) {
            /* a class request */
            uint8_t req = (uint8_t)(o & 7u);
            int in = req == DFU_REQ_UPLOAD || req == DFU_REQ_GETSTATUS || req == DFU_REQ_GETSTATE;
            uint8_t type = (uint8_t)((in ? DFU_REQTYPE_IN : DFU_REQTYPE_OUT) ^ (o & 8u ? 0x80u : 0u));
            uint32_t v = next8(c), wl;
            switch (o >> 4 & 7u) {
            case 0: wl = 0; break;
            case 1: wl = DFU_GETSTATUS_LEN; break;
            case 2: wl = 1; break;
            case 3: wl = cfg.transfer_size; break;
            case 4: wl = cfg.transfer_size + 1u; break;
            case 5: wl = next8(c); break;
            case 6: wl = next8(c) * 16u; break;
            default: wl = 0xFFFF; break;
            }
            uint16_t value = (uint16_t)v;
            if (req == DFU_REQ_DNLOAD) value = (uint16_t)(d->next_block + (uint32_t)(int8_t)v);
            if (req == DFU_REQ_DETACH) value = (uint16_t)(v * 16u);
            uint8_t *data = wl ? malloc(wl) : NULL; /* exact: ASan sees any write past wLength */
            if (wl && !data) abort();
            for (uint32_t i = 0; i < wl; i++) data[i] = (uint8_t)xorshift(&data_rng);

            REQUIRE(dfu_request_name(req) != NULL);
            uint8_t before = d->state;
            uint32_t up_before = d->upload_pos;
            uint16_t actual = 0xBEEF;
            dfu_dev_result r = dfu_dev_request(d, now, type, req, value, (uint16_t)wl, data, &actual);
            if (r == DFU_DEV_STALL) {
                REQUIRE(d->state == DFU_STATE_APP_IDLE || d->state == DFU_STATE_MANIFEST_WAIT_RESET ||
                        d->state == DFU_STATE_ERROR);
            } else {
                REQUIRE(r == DFU_DEV_ACK && actual <= wl);
                if (!in) REQUIRE(actual == 0);
                if (req == DFU_REQ_GETSTATUS) {
                    REQUIRE(actual == (wl < DFU_GETSTATUS_LEN ? wl : DFU_GETSTATUS_LEN));
                    if (actual >= 1) REQUIRE(data[0] == d->status);
                    if (actual >= 5) REQUIRE(data[4] == d->state);
                    if (actual >= 6) REQUIRE(data[5] == 0);
                } else if (req == DFU_REQ_GETSTATE) {
                    REQUIRE(actual == (wl ? 1u : 0u));
                    if (wl) REQUIRE(data[0] == d->state);
                } else if (req == DFU_REQ_UPLOAD) {
                    /* the application's bytes, from where the last upload stopped */
                    uint32_t start = before == DFU_STATE_IDLE ? 0u : up_before, n;
                    REQUIRE(d->upload_pos == start + actual);
                    if (actual) {
                        REQUIRE(ref_valid(&f, &n) && start + actual <= n);
                        REQUIRE(memcmp(data, f.mem + start, actual) == 0);
                    }
                } else if (req == DFU_REQ_DNLOAD && wl) {
                    /* a block taken: part of this download */
                    if (before == DFU_STATE_IDLE) {
                        f.img_len = 0;
                        f.epoch++;
                    }
                    REQUIRE(f.img_len + wl <= cap);
                    memcpy(f.img + f.img_len, data, wl);
                    f.img_len += wl;
                }
            }
            free(data);
        } else if (o < 0xA0u) {
            /* milliseconds, or up to hours (the clock wraps; deadlines must not care) */
            now += o & 16u ? ((o & 15u) + 1u) << 20 : ((o & 15u) + 1u) * 8u;
        } else if (o < 0xB0u) {
            dfu_dev_poll(d, now);
        } else if (o < 0xC0u) {
            dfu_dev_bus_reset(d, now);
        } else if (o < 0xC8u) {
            /* power cut and power-on: the flash keeps what it has */
            f.epoch++;
            now += 1000;
            REQUIRE(dfu_dev_init(d, &cfg, &fl, o & 1u, now) == 0);
        } else {
            uint32_t k = o - 0xC8u;
            f.fault_kind = (int)(k % OP_KINDS);
            f.fault_corrupt = (int)(k / OP_KINDS & 1u);
            f.fault_count = next8(c) & 15u;
        }
        check_device(&f, d, &fl, &seen_gen);
    }
out:
    free(d);
    free(f.mem);
    free(f.img);
    free(f.com);
    free(f.prog_end);
    free(f.erase_epoch);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    cursor c = {data + 1, size - 1};
    switch (data[0] % 3u) {
    case 0: run_file(data + 1, size - 1); break;
    case 1: run_suffix(&c); break;
    default: run_device(&c); break;
    }
    return 0;
}
