/* test_dfu.c - USB DFU 1.1: the host engine (host/flash/dfu_host.c) against the
 * device state machine (firmware/dfu/dfu_device.c) over the loopback transport, and
 * the image/suffix parser (firmware/dfu/dfu_image.c) on its own.
 *
 * What is shown: a download succeeds at every transfer size from 64 to 4096 and the
 * application is marked valid with the image's CRC; a damaged image is refused before
 * any request reaches the device; device errors (write, verify, erase, blank check,
 * address) end in CLRSTATUS and a clear message; a download interrupted after any
 * number of requests, or by a power cut before any flash operation (also a torn one),
 * never leaves a half-written application marked valid, and a retry succeeds;
 * bwPollTimeout is honoured (fake clock); requests that are invalid in a state stall
 * and, in DFU mode, lead to dfuERROR. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "crc32.h"
#include "dfu/dfu_device.h"
#include "dfu/dfu_image.h"
#include "dfu/dfu_proto.h"
#include "flash/dfu_host.h"
#include "flash/dfu_loopback.h"

#define VID 0x1209u
#define PID 0x0001u
#define FLASH_SIZE (64u * 1024u)
#define PAGE 1024u

static dfu_loopback lb;

/* ---- helpers -------------------------------------------------------------------- */

static uint32_t rng_state;
static uint32_t rng(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return rng_state >> 8;
}

static uint8_t *payload_make(size_t n, uint32_t seed)
{
    uint8_t *p = malloc(n ? n : 1);
    rng_state = seed;
    for (size_t i = 0; i < n; i++) p[i] = (uint8_t)rng();
    return p;
}

static uint8_t *image_make(const uint8_t *p, size_t n, uint16_t vid, uint16_t pid, size_t *len)
{
    uint8_t *f = malloc(n + DFU_SUFFIX_LEN);
    memcpy(f, p, n);
    dfu_suffix_build(f + n, p, n, vid, pid, 0x0102);
    *len = n + DFU_SUFFIX_LEN;
    return f;
}

/* Put a correct CRC on a file whose suffix was edited. */
static void recrc(uint8_t *f, size_t len)
{
    uint32_t c = dfu_suffix_crc(f, len - 4);
    f[len - 4] = (uint8_t)c;
    f[len - 3] = (uint8_t)(c >> 8);
    f[len - 2] = (uint8_t)(c >> 16);
    f[len - 1] = (uint8_t)(c >> 24);
}

static dfu_dev_config_t config(uint16_t ts, uint8_t attrs)
{
    dfu_dev_config_t c = dfu_loop_default_config();
    c.transfer_size = ts;
    c.attributes = attrs;
    return c;
}

static void lb_open(const dfu_dev_config_t *cfg, uint32_t flash_size, uint32_t page)
{
    dfu_loop_free(&lb);
    assert_int_equal(dfu_loop_init(&lb, cfg, flash_size, page, 0), 0);
}

static void lb_default(void)
{
    dfu_dev_config_t c = config(256, DFU_ATTR_CAN_DNLOAD | DFU_ATTR_CAN_UPLOAD | DFU_ATTR_MANIFEST_TOLERANT);
    lb_open(&c, FLASH_SIZE, PAGE);
}

static dfu_host_err flash_file(const uint8_t *f, size_t len, uint16_t ts, dfu_host_report *r)
{
    dfu_transport t = dfu_loop_transport(&lb);
    dfu_host_opts o;
    memset(&o, 0, sizeof o);
    o.transfer_size = ts;
    return dfu_host_flash(&t, f, len, VID, PID, &o, r);
}

static dfu_host_err flash_payload(const uint8_t *p, size_t n, uint16_t ts, dfu_host_report *r)
{
    size_t len;
    uint8_t *f = image_make(p, n, VID, PID, &len);
    dfu_host_err e = flash_file(f, len, ts, r);
    free(f);
    return e;
}

/* The application in flash is valid and is exactly p[0..n). */
static void assert_app_is(const uint8_t *p, size_t n)
{
    dfu_app_info_t info;
    assert_int_equal(dfu_app_check(&lb.flash, &info), 1);
    assert_int_equal(info.length, n);
    assert_int_equal(info.crc, crc_update(0, p, n));
    assert_memory_equal(lb.mem, p, n);
}

static int app_valid(void)
{
    return dfu_app_check(&lb.flash, NULL);
}

static int rq(uint8_t type, uint8_t req, uint16_t value, uint8_t *data, uint16_t len)
{
    dfu_transport t = dfu_loop_transport(&lb);
    return t.control(t.ctx, type, req, value, data, len, 1000);
}

typedef struct st {
    uint8_t status, state;
    uint32_t poll;
} st;

static st getstatus(void)
{
    uint8_t b[6];
    assert_int_equal(rq(DFU_REQTYPE_IN, DFU_REQ_GETSTATUS, 0, b, 6), 6);
    st s = {b[0], b[4], (uint32_t)b[1] | (uint32_t)b[2] << 8 | (uint32_t)b[3] << 16};
    return s;
}

static uint8_t getstate(void)
{
    uint8_t b = 0xEE;
    assert_int_equal(rq(DFU_REQTYPE_IN, DFU_REQ_GETSTATE, 0, &b, 1), 1);
    return b;
}

static void advance(uint32_t ms)
{
    dfu_transport t = dfu_loop_transport(&lb);
    t.sleep_ms(t.ctx, ms);
}

static int setup(void **state)
{
    (void)state;
    memset(&lb, 0, sizeof lb);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    dfu_loop_free(&lb);
    return 0;
}

/* ---- the image format ------------------------------------------------------------- */

static void test_suffix_crc_convention(void **state)
{
    (void)state;
    /* CRC-32 of "123456789" is 0xCBF43926 (zlib); the DFU suffix CRC is its complement
     * (preset 0xFFFFFFFF, no final inversion). */
    const uint8_t check[] = "123456789";
    assert_int_equal(crc_update(0, check, 9), 0xCBF43926u);
    assert_int_equal(dfu_suffix_crc(check, 9), 0x340BC6D9u);

    uint8_t *p = payload_make(1000, 1);
    size_t len;
    uint8_t *f = image_make(p, 1000, VID, PID, &len);
    assert_int_equal(len, 1016);
    const uint8_t *s = f + 1000;
    assert_int_equal(s[0] | s[1] << 8, 0x0102); /* bcdDevice */
    assert_int_equal(s[2] | s[3] << 8, PID);
    assert_int_equal(s[4] | s[5] << 8, VID);
    assert_int_equal(s[6] | s[7] << 8, 0x0100); /* bcdDFU */
    assert_memory_equal(s + 8, "UFD", 3);
    assert_int_equal(s[11], 16);
    uint32_t stored = (uint32_t)s[12] | (uint32_t)s[13] << 8 | (uint32_t)s[14] << 16 | (uint32_t)s[15] << 24;
    assert_int_equal(stored, ~crc_update(0, f, len - 4));

    dfu_image_t img;
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_OK);
    assert_ptr_equal(img.payload, f);
    assert_int_equal(img.payload_len, 1000);
    assert_int_equal(img.id_vendor, VID);
    assert_int_equal(img.id_product, PID);
    assert_int_equal(img.bcd_device, 0x0102);
    assert_int_equal(img.crc_stored, img.crc_computed);
    assert_int_equal(dfu_image_match(&img, VID, PID), DFU_IMAGE_OK);
    assert_int_equal(dfu_image_match(&img, 0x1234, PID), DFU_IMAGE_WRONG_VENDOR);
    assert_int_equal(dfu_image_match(&img, VID, 0x0002), DFU_IMAGE_WRONG_PRODUCT);
    free(f);

    /* 0xFFFF matches any device */
    f = image_make(p, 1000, 0xFFFF, 0xFFFF, &len);
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_OK);
    assert_int_equal(dfu_image_match(&img, 0x0483, 0xDF11), DFU_IMAGE_OK);
    free(f);
    free(p);
}

static void test_parser_rejects_damage(void **state)
{
    (void)state;
    uint8_t *p = payload_make(300, 2);
    size_t len;
    uint8_t *f = image_make(p, 300, VID, PID, &len);
    dfu_image_t img;

    /* every truncation */
    for (size_t n = 0; n < len; n++) assert_int_not_equal(dfu_image_parse(f, n, &img), DFU_IMAGE_OK);
    assert_int_equal(dfu_image_parse(NULL, 0, &img), DFU_IMAGE_TOO_SHORT);
    assert_int_equal(dfu_image_parse(f, 15, &img), DFU_IMAGE_TOO_SHORT);
    assert_int_equal(dfu_image_parse(f, len - 1, &img), DFU_IMAGE_NO_SIGNATURE);

    /* every single-bit flip anywhere in the file */
    for (size_t i = 0; i < len; i++)
        for (int b = 0; b < 8; b++) {
            f[i] ^= (uint8_t)(1u << b);
            assert_int_not_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_OK);
            f[i] ^= (uint8_t)(1u << b);
        }
    /* a payload byte flip is a CRC error, a signature byte flip a missing signature */
    f[10] ^= 0x40;
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_BAD_CRC);
    assert_int_not_equal(img.crc_stored, img.crc_computed);
    f[10] ^= 0x40;
    f[len - 7] = 'X'; /* "UFD" -> "UXD" */
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_NO_SIGNATURE);
    f[len - 7] = 'F';
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_OK);

    /* fields damaged with the CRC made right: the field checks themselves */
    f[len - 5] = 15; /* bLength below 16 */
    recrc(f, len);
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_BAD_LENGTH);
    f[len - 5] = 255; /* fits, but would eat firmware bytes */
    recrc(f, len);
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_BAD_LENGTH);
    assert_int_equal(img.payload_len, 0);
    f[len - 5] = 17;
    recrc(f, len);
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_BAD_LENGTH);
    f[len - 5] = 16;
    f[len - 10] = 0x1A; /* bcdDFU 0x011A: DfuSe */
    f[len - 9] = 0x01;
    recrc(f, len);
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_BAD_VERSION);
    free(f);

    /* bLength longer than the file */
    f = image_make(p, 4, VID, PID, &len);
    f[len - 5] = 21;
    recrc(f, len);
    assert_int_equal(dfu_image_parse(f, len, &img), DFU_IMAGE_BAD_LENGTH);
    free(f);

    /* a suffix and nothing else */
    uint8_t only[DFU_SUFFIX_LEN];
    dfu_suffix_build(only, NULL, 0, VID, PID, 0xFFFF);
    assert_int_equal(dfu_image_parse(only, sizeof only, &img), DFU_IMAGE_EMPTY);
    free(p);

    for (int e = DFU_IMAGE_OK; e <= DFU_IMAGE_WRONG_PRODUCT; e++)
        assert_true(strlen(dfu_image_strerror((dfu_image_err)e)) > 5);
}

/* ---- downloads ------------------------------------------------------------------------ */

static void test_download_succeeds_all_transfer_sizes(void **state)
{
    (void)state;
    static const uint16_t sizes[] = {64, 100, 128, 256, 512, 777, 1000, 1024, 2048, 4096};
    static const size_t lens[] = {1, 63, 64, 1024, 5000, 20000, 60 * 1024};
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++) {
        for (size_t li = 0; li < sizeof lens / sizeof lens[0]; li++) {
            uint16_t ts = sizes[si];
            size_t n = lens[li];
            dfu_dev_config_t c = config(ts, DFU_ATTR_CAN_DNLOAD | DFU_ATTR_MANIFEST_TOLERANT);
            lb_open(&c, FLASH_SIZE + PAGE, PAGE);
            uint8_t *p = payload_make(n, (uint32_t)(si * 100 + li));
            dfu_host_report r;
            dfu_host_err e = flash_payload(p, n, 0, &r);
            if (e != DFU_HOST_OK) fail_msg("ts %u len %zu: %s", ts, n, r.msg);
            assert_app_is(p, n);
            uint32_t blocks = (uint32_t)((n + ts - 1) / ts);
            assert_int_equal(r.blocks_total, blocks);
            assert_int_equal(r.blocks_done, blocks);
            assert_int_equal(r.transfer_size, ts);
            assert_int_equal(r.payload_crc, crc_update(0, p, n));
            assert_int_equal(lb.by_request[DFU_REQ_DNLOAD], blocks + 1); /* + the empty one */
            assert_int_equal(lb.stalls, 0);
            assert_true(r.manifested);
            assert_int_equal(r.reenumerated, 1);
            assert_int_equal(r.final_state, DFU_STATE_APP_IDLE);
            assert_int_equal(dfu_dev_state(&lb.dev), DFU_STATE_APP_IDLE);
            free(p);
        }
    }
}

static void test_host_transfer_size_option(void **state)
{
    (void)state;
    lb_default(); /* the device takes 256 */
    uint8_t *p = payload_make(3000, 3);
    dfu_host_report r;
    assert_int_equal(flash_payload(p, 3000, 64, &r), DFU_HOST_OK);
    assert_int_equal(r.transfer_size, 64);
    assert_int_equal(lb.by_request[DFU_REQ_DNLOAD], (3000 + 63) / 64 + 1);
    assert_app_is(p, 3000);

    /* larger than the device's wTransferSize: refused before any request */
    lb_default();
    assert_int_equal(flash_payload(p, 3000, 512, &r), DFU_HOST_BAD_ARGS);
    assert_int_equal(lb.requests, 0);
    assert_non_null(strstr(r.msg, "wTransferSize 256"));
    free(p);
}

static void test_manifestation_not_tolerant(void **state)
{
    (void)state;
    dfu_dev_config_t c = config(512, DFU_ATTR_CAN_DNLOAD);
    lb_open(&c, FLASH_SIZE, PAGE);
    uint8_t *p = payload_make(9000, 4);
    dfu_host_report r;
    assert_int_equal(flash_payload(p, 9000, 0, &r), DFU_HOST_OK);
    assert_true(r.manifested); /* the device said dfuMANIFEST-WAIT-RESET */
    assert_int_equal(lb.resets, 1);
    assert_int_equal(r.final_state, DFU_STATE_APP_IDLE);
    assert_app_is(p, 9000);
    free(p);
}

static void test_detach_from_runtime(void **state)
{
    (void)state;
    lb_default();
    uint8_t *old = payload_make(4000, 5), *neu = payload_make(7000, 6);
    dfu_host_report r;
    assert_int_equal(flash_payload(old, 4000, 0, &r), DFU_HOST_OK);
    assert_int_equal(dfu_dev_state(&lb.dev), DFU_STATE_APP_IDLE); /* runs the application */
    unsigned long resets = lb.resets;
    assert_int_equal(flash_payload(neu, 7000, 0, &r), DFU_HOST_OK);
    assert_int_equal(lb.by_request[DFU_REQ_DETACH], 1);
    assert_int_equal(lb.resets - resets, 2); /* enter DFU + run */
    assert_app_is(neu, 7000);

    /* bitWillDetach: the device re-attaches by itself, the host does not reset it */
    dfu_dev_config_t c = config(256, DFU_ATTR_CAN_DNLOAD | DFU_ATTR_MANIFEST_TOLERANT | DFU_ATTR_WILL_DETACH);
    lb_open(&c, FLASH_SIZE, PAGE);
    assert_int_equal(flash_payload(old, 4000, 0, &r), DFU_HOST_OK);
    resets = lb.resets;
    assert_int_equal(flash_payload(neu, 7000, 0, &r), DFU_HOST_OK);
    assert_int_equal(lb.by_request[DFU_REQ_DETACH], 1);
    assert_int_equal(lb.resets - resets, 1);
    assert_app_is(neu, 7000);
    free(old);
    free(neu);
}

static void test_damaged_image_sends_nothing(void **state)
{
    (void)state;
    uint8_t *p = payload_make(2500, 7);
    size_t len;
    uint8_t *good = image_make(p, 2500, VID, PID, &len);
    uint8_t *f = malloc(len);
    int cases = 0;
    /* truncated at many lengths, single bits flipped at many places, a wrong device */
    for (size_t cut = 0; cut < len; cut += (cut < 40 ? 1 : 97)) {
        lb_default();
        dfu_host_report r;
        assert_int_equal(flash_file(good, cut, 0, &r), DFU_HOST_BAD_IMAGE);
        assert_int_equal(lb.requests, 0);
        cases++;
    }
    for (size_t i = 0; i < len; i += (i + 40 < len ? 61 : 1)) {
        memcpy(f, good, len);
        f[i] ^= (uint8_t)(1u << (i % 8));
        lb_default();
        dfu_host_report r;
        assert_int_equal(flash_file(f, len, 0, &r), DFU_HOST_BAD_IMAGE);
        assert_int_equal(lb.requests, 0);
        assert_int_equal(lb.erases + lb.programs, 0);
        assert_true(strlen(r.msg) > 10);
        cases++;
    }
    free(good);
    good = image_make(p, 2500, VID, 0x0BAD, &len);
    lb_default();
    dfu_host_report r;
    assert_int_equal(flash_file(good, len, 0, &r), DFU_HOST_BAD_IMAGE);
    assert_int_equal(lb.requests, 0);
    assert_non_null(strstr(r.msg, "1209:0bad"));
    assert_true(cases > 80);
    free(good);
    free(f);
    free(p);
}

/* ---- device errors -------------------------------------------------------------------- */

typedef struct fault {
    dfu_loop_op op;
    long nth;           /* the nth operation of that kind (0-based) */
    int action;         /* DFU_LOOP_FAIL or DFU_LOOP_CORRUPT */
    uint32_t at_offset; /* or: the first op at this offset (nth < 0) */
    long seen;
} fault;

static int fault_hook(void *user, dfu_loop_op op, uint32_t off, const uint8_t *src, uint32_t n)
{
    (void)src;
    (void)n;
    fault *f = user;
    if (op != f->op) return DFU_LOOP_PASS;
    if (f->nth >= 0 ? f->seen++ == f->nth : off == f->at_offset) return f->action;
    return DFU_LOOP_PASS;
}

static void device_error_case(dfu_loop_op op, long nth, uint32_t at, int action, uint8_t want_status)
{
    lb_default();
    uint8_t *old = payload_make(5000, 8), *p = payload_make(20000, 9);
    dfu_host_report r;
    assert_int_equal(flash_payload(old, 5000, 0, &r), DFU_HOST_OK);
    fault f = {op, nth, action, at, 0};
    lb.flash_hook = fault_hook;
    lb.hook_user = &f;
    unsigned long clr = lb.by_request[DFU_REQ_CLRSTATUS];
    assert_int_equal(flash_payload(p, 20000, 0, &r), DFU_HOST_DEVICE_ERROR);
    assert_int_equal(r.dev_status, want_status);
    assert_int_equal(r.dev_state, DFU_STATE_ERROR);
    assert_non_null(strstr(r.msg, dfu_status_name(want_status)));
    assert_non_null(strstr(r.msg, "CLRSTATUS"));
    assert_int_equal(lb.by_request[DFU_REQ_CLRSTATUS], clr + 1);
    assert_int_equal(dfu_dev_state(&lb.dev), DFU_STATE_IDLE); /* cleaned up */
    assert_false(app_valid());                                /* the old application was invalidated first */
    /* after a reset the device stays in DFU mode */
    dfu_dev_bus_reset(&lb.dev, lb.now_ms);
    assert_int_equal(dfu_dev_state(&lb.dev), DFU_STATE_ERROR);
    assert_int_equal(dfu_dev_status(&lb.dev), DFU_STATUS_ERR_FIRMWARE);
    /* the fault goes away: the retry succeeds */
    lb.flash_hook = NULL;
    assert_int_equal(flash_payload(p, 20000, 0, &r), DFU_HOST_OK);
    assert_app_is(p, 20000);
    free(old);
    free(p);
}

static void test_device_errors(void **state)
{
    (void)state;
    /* the 5th program call fails: errWRITE */
    device_error_case(DFU_LOOP_PROGRAM, 5, 0, DFU_LOOP_FAIL, DFU_STATUS_ERR_WRITE);
    /* programmed data reads back wrong: errVERIFY */
    device_error_case(DFU_LOOP_PROGRAM, 30, 0, DFU_LOOP_CORRUPT, DFU_STATUS_ERR_VERIFY);
    /* erase fails, erase leaves a non-blank page */
    device_error_case(DFU_LOOP_ERASE, 3, 0, DFU_LOOP_FAIL, DFU_STATUS_ERR_ERASE);
    device_error_case(DFU_LOOP_ERASE, 0, 0, DFU_LOOP_CORRUPT, DFU_STATUS_ERR_CHECK_ERASED);
    /* the valid mark itself cannot be written, in manifestation */
    device_error_case(DFU_LOOP_PROGRAM, -1, FLASH_SIZE - PAGE, DFU_LOOP_FAIL, DFU_STATUS_ERR_WRITE);
    device_error_case(DFU_LOOP_PROGRAM, -1, FLASH_SIZE - PAGE, DFU_LOOP_CORRUPT, DFU_STATUS_ERR_VERIFY);
}

/* A transport like the loopback's that does not report the application area, as a
 * USB device does not: the device's own check must refuse the overflow. */
static void functional_no_capacity(void *ctx, dfu_func_desc *out)
{
    dfu_loop_transport((dfu_loopback *)ctx).functional(ctx, out);
    out->app_capacity = 0;
}

static void test_image_too_large(void **state)
{
    (void)state;
    lb_default();
    size_t n = FLASH_SIZE - PAGE + 1; /* one byte more than the region takes */
    uint8_t *p = payload_make(n, 10);
    dfu_host_report r;
    /* an old application, then an oversized image: refused before any request, so
     * the old valid mark stays */
    assert_int_equal(flash_payload(p, 1000, 0, &r), DFU_HOST_OK);
    unsigned long before = lb.requests, erases = lb.erases;
    assert_int_equal(flash_payload(p, n, 0, &r), DFU_HOST_BAD_IMAGE);
    assert_non_null(strstr(r.msg, "do not fit"));
    assert_int_equal(lb.requests, before);
    assert_int_equal(lb.erases, erases);
    assert_app_is(p, 1000);

    /* without the size reported, the device stalls the block past its end */
    dfu_transport t = dfu_loop_transport(&lb);
    t.functional = functional_no_capacity;
    assert_int_equal(dfu_host_download(&t, p, n, NULL, &r), DFU_HOST_DEVICE_ERROR);
    assert_int_equal(r.dev_status, DFU_STATUS_ERR_ADDRESS);
    assert_non_null(strstr(r.msg, "errADDRESS"));
    assert_int_equal(dfu_dev_state(&lb.dev), DFU_STATE_IDLE);
    assert_false(app_valid());
    /* exactly the capacity fits */
    assert_int_equal(flash_payload(p, n - 1, 0, &r), DFU_HOST_OK);
    assert_app_is(p, n - 1);
    free(p);
}

static void test_transfer_error_then_abort(void **state)
{
    (void)state;
    lb_default();
    uint8_t *p = payload_make(4000, 18);
    dfu_host_report r;
    /* requests: GETSTATUS, CLRSTATUS, GETSTATUS, then DNLOAD/GETSTATUS x2 per block:
     * request 9 is the DNLOAD of block 3, which fails on the wire */
    lb.io_error_at = 9;
    assert_int_equal(flash_payload(p, 4000, 0, &r), DFU_HOST_IO);
    assert_non_null(strstr(r.msg, "USB error during DNLOAD of block 3"));
    assert_non_null(strstr(r.msg, "sent ABORT"));
    assert_non_null(strstr(r.msg, "stays in its bootloader"));
    assert_int_equal(lb.by_request[DFU_REQ_ABORT], 1);
    assert_int_equal(dfu_dev_state(&lb.dev), DFU_STATE_IDLE);
    assert_false(app_valid());
    assert_int_equal(flash_payload(p, 4000, 0, &r), DFU_HOST_OK);
    assert_app_is(p, 4000);
    free(p);
}

/* ---- interruptions ---------------------------------------------------------------------- */

/* After whatever happened, power-cycle and check: a valid application is exactly the
 * old or the new image; otherwise the device is in DFU mode. Then retry. */
static void check_after_interruption(const uint8_t *old, size_t old_n, const uint8_t *neu, size_t neu_n,
                                     int *saw_invalid, int *saw_old, int *saw_new)
{
    dfu_loop_power_cycle(&lb, 0);
    dfu_app_info_t info;
    if (dfu_app_check(&lb.flash, &info)) {
        assert_int_equal(dfu_dev_state(&lb.dev), DFU_STATE_APP_IDLE);
        if (old && info.length == old_n && memcmp(lb.mem, old, old_n) == 0) {
            (*saw_old)++;
        } else {
            assert_int_equal(info.length, neu_n);
            assert_memory_equal(lb.mem, neu, neu_n);
            (*saw_new)++;
        }
    } else {
        assert_int_equal(dfu_dev_state(&lb.dev), DFU_STATE_ERROR);
        assert_int_equal(dfu_dev_status(&lb.dev), DFU_STATUS_ERR_FIRMWARE);
        (*saw_invalid)++;
    }
    dfu_host_report r;
    assert_int_equal(flash_payload(neu, neu_n, 0, &r), DFU_HOST_OK);
    assert_app_is(neu, neu_n);
}

static void interrupt_all(int with_old, int timeout)
{
    uint8_t *old = payload_make(3000, 11), *neu = payload_make(6000, 12);
    dfu_host_report r;
    /* how many requests a whole download takes */
    lb_default();
    if (with_old) assert_int_equal(flash_payload(old, 3000, 0, &r), DFU_HOST_OK);
    unsigned long before = lb.requests;
    assert_int_equal(flash_payload(neu, 6000, 0, &r), DFU_HOST_OK);
    long total = (long)(lb.requests - before);
    assert_true(total > 40);
    int inval = 0, sold = 0, snew = 0;
    for (long k = 0; k <= total; k++) {
        lb_default();
        if (with_old) assert_int_equal(flash_payload(old, 3000, 0, &r), DFU_HOST_OK);
        if (timeout)
            lb.timeout_after = (long)lb.requests + k;
        else
            lb.vanish_after = (long)lb.requests + k;
        dfu_host_err e = flash_payload(neu, 6000, 0, &r);
        if (k < total) {
            /* the last requests are after the reset: the image is already committed */
            /* vanishing while the host waits for the device to re-enumerate after
             * DETACH shows as a timeout: the device never comes back */
            int waiting = strstr(r.msg, "did not come back") != NULL;
            if (e == DFU_HOST_OK)
                assert_true(r.manifested);
            else if (timeout || waiting)
                assert_int_equal(e, DFU_HOST_TIMEOUT);
            else
                assert_int_equal(e, DFU_HOST_NO_DEVICE);
            if (e != DFU_HOST_OK && !timeout && !waiting) assert_non_null(strstr(r.msg, "vanished"));
            if (e != DFU_HOST_OK && timeout) assert_non_null(strstr(r.msg, "did not answer"));
        } else {
            assert_int_equal(e, DFU_HOST_OK);
        }
        check_after_interruption(with_old ? old : NULL, 3000, neu, 6000, &inval, &sold, &snew);
    }
    assert_true(inval > 20);              /* most interruptions: nothing valid, in the bootloader */
    assert_true(snew >= 1);               /* interrupted after the commit: the new image */
    if (with_old) assert_true(sold >= 1); /* interrupted before the first block: the old image */
    free(old);
    free(neu);
}

static void test_interrupted_download_fresh(void **state)
{
    (void)state;
    interrupt_all(0, 0);
}

static void test_interrupted_download_over_old_app(void **state)
{
    (void)state;
    interrupt_all(1, 0);
}

static void test_timeouts_mid_download(void **state)
{
    (void)state;
    interrupt_all(1, 1);
}

/* Power cut before flash operation number n (optionally with that operation half
 * done): the snapshot of the flash at that moment must boot the old image, the new
 * one, or nothing - never a mix marked valid. */
typedef struct cut {
    long target, seen;
    int torn;
    uint8_t *snap;
    int taken;
} cut;

static int cut_hook(void *user, dfu_loop_op op, uint32_t off, const uint8_t *src, uint32_t n)
{
    cut *c = user;
    if (op == DFU_LOOP_READ) return DFU_LOOP_PASS;
    if (c->seen++ == c->target) {
        memcpy(c->snap, lb.mem, FLASH_SIZE);
        if (c->torn && op == DFU_LOOP_ERASE) memset(c->snap + off, 0xFF, PAGE / 2);
        if (c->torn && op == DFU_LOOP_PROGRAM)
            for (uint32_t i = 0; i < n / 2; i++) c->snap[off + i] &= src[i];
        c->taken = 1;
    }
    return DFU_LOOP_PASS;
}

static uint8_t *snap_mem;
static int snap_read(void *ctx, uint32_t off, uint8_t *dst, uint32_t n)
{
    (void)ctx;
    memcpy(dst, snap_mem + off, n);
    return 0;
}
static int snap_never(void *ctx, uint32_t off)
{
    (void)ctx;
    (void)off;
    return -1;
}
static int snap_never_prog(void *ctx, uint32_t off, const uint8_t *s, uint32_t n)
{
    (void)ctx;
    (void)off;
    (void)s;
    (void)n;
    return -1;
}

static void test_power_cut_at_every_flash_operation(void **state)
{
    (void)state;
    uint8_t *old = payload_make(2500, 13), *neu = payload_make(4500, 14);
    dfu_host_report r;
    cut c = {0, 0, 0, malloc(FLASH_SIZE), 0};
    snap_mem = c.snap;
    dfu_flash_t sf = {NULL, FLASH_SIZE, PAGE, snap_never, snap_never_prog, snap_read};
    int inval = 0, sold = 0, snew = 0;
    for (int torn = 0; torn < 2; torn++) {
        for (long target = 0;; target++) {
            lb_default();
            assert_int_equal(flash_payload(old, 2500, 0, &r), DFU_HOST_OK);
            c.target = target;
            c.seen = 0;
            c.torn = torn;
            c.taken = 0;
            lb.flash_hook = cut_hook;
            lb.hook_user = &c;
            assert_int_equal(flash_payload(neu, 4500, 0, &r), DFU_HOST_OK);
            if (!c.taken) break;
            dfu_app_info_t info;
            if (dfu_app_check(&sf, &info)) {
                if (info.length == 2500 && memcmp(c.snap, old, 2500) == 0) {
                    sold++;
                } else {
                    assert_int_equal(info.length, 4500);
                    assert_memory_equal(c.snap, neu, 4500);
                    snew++;
                }
            } else {
                inval++;
            }
            /* and the device booted from that snapshot stays in DFU mode or runs it */
            dfu_dev_t *d = malloc(sizeof *d);
            dfu_dev_config_t cfg = dfu_loop_default_config();
            assert_int_equal(dfu_dev_init(d, &cfg, &sf, 0, 0), 0);
            assert_int_equal(dfu_dev_state(d), dfu_app_check(&sf, NULL) ? DFU_STATE_APP_IDLE : DFU_STATE_ERROR);
            free(d);
        }
    }
    assert_true(inval > 10);
    assert_int_equal(sold, 1); /* cut before the valid mark was erased */
    assert_int_equal(snew, 0); /* the last operation is the valid mark: never before it */
    free(c.snap);
    free(old);
    free(neu);
}

/* ---- timing ------------------------------------------------------------------------------ */

static void test_poll_timeouts_honoured(void **state)
{
    (void)state;
    dfu_dev_config_t c = config(512, DFU_ATTR_CAN_DNLOAD | DFU_ATTR_MANIFEST_TOLERANT);
    c.program_ms = 50;
    c.erase_ms = 200;
    c.manifest_ms = 1700;
    lb_open(&c, FLASH_SIZE, PAGE);
    size_t n = 10000; /* 20 blocks of 512; 10 pages of 1024 */
    uint8_t *p = payload_make(n, 15);
    dfu_host_report r;
    assert_int_equal(flash_payload(p, n, 0, &r), DFU_HOST_OK);
    /* every block: 50 ms; every page: 200 ms (+1 page: the valid mark); manifestation */
    unsigned long want = 20 * 50 + (10 + 1) * 200 + 1700;
    assert_int_equal(lb.slept_ms, want);
    assert_int_equal(lb.stalls, 0);
    assert_app_is(p, n);

    /* a large bwPollTimeout (an erase of several seconds) is waited out too */
    c.erase_ms = 9000;
    lb_open(&c, FLASH_SIZE, PAGE);
    assert_int_equal(flash_payload(p, 1500, 0, &r), DFU_HOST_OK);
    assert_int_equal(lb.slept_ms, 3 * 50 + 3 * 9000 + 1700);
    free(p);
}

static void test_early_poll_stalls(void **state)
{
    (void)state;
    dfu_dev_config_t c = config(256, DFU_ATTR_CAN_DNLOAD | DFU_ATTR_MANIFEST_TOLERANT);
    c.program_ms = 30;
    c.erase_ms = 100;
    lb_open(&c, FLASH_SIZE, PAGE);
    assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_CLRSTATUS, 0, NULL, 0), 0); /* out of errFIRMWARE */
    uint8_t blk[256];
    memset(blk, 0x5A, sizeof blk);
    assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DNLOAD, 0, blk, 256), 256);
    st s = getstatus();
    assert_int_equal(s.state, DFU_STATE_DNBUSY);
    assert_int_equal(s.poll, 30 + 2 * 100); /* program + erase page and valid mark */
    advance(s.poll - 1);                    /* one millisecond early */
    assert_int_equal(rq(DFU_REQTYPE_IN, DFU_REQ_GETSTATUS, 0, blk, 6), DFU_XFER_STALL);
    s = getstatus();
    assert_int_equal(s.state, DFU_STATE_ERROR);
    assert_int_equal(s.status, DFU_STATUS_ERR_STALLEDPKT);
    assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_CLRSTATUS, 0, NULL, 0), 0);
    assert_int_equal(getstatus().state, DFU_STATE_IDLE);
    /* on time it works */
    assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DNLOAD, 0, blk, 256), 256);
    s = getstatus();
    advance(s.poll);
    s = getstatus();
    assert_int_equal(s.state, DFU_STATE_DNLOAD_IDLE);
    assert_int_equal(s.status, DFU_STATUS_OK);
}

/* ---- the state machine ---------------------------------------------------------------------- */

enum {
    S_APP_IDLE,
    S_APP_DETACH,
    S_IDLE,
    S_DNLOAD_SYNC,
    S_DNBUSY,
    S_DNLOAD_IDLE,
    S_MANIFEST_SYNC,
    S_MANIFEST,
    S_WAIT_RESET,
    S_UPLOAD_IDLE,
    S_ERROR,
    S_COUNT
};

/* A fresh device in the given state (transfer size 256, valid app of 3000 bytes for
 * the states that need one). */
static void drive(int s)
{
    uint8_t attrs = DFU_ATTR_CAN_DNLOAD | DFU_ATTR_CAN_UPLOAD | (s == S_WAIT_RESET ? 0 : DFU_ATTR_MANIFEST_TOLERANT);
    dfu_dev_config_t c = config(256, attrs);
    c.program_ms = 10;
    c.erase_ms = 10;
    c.manifest_ms = 10;
    lb_open(&c, FLASH_SIZE, PAGE);
    uint8_t blk[256];
    memset(blk, 0xA5, sizeof blk);
    if (s == S_APP_IDLE || s == S_APP_DETACH || s == S_UPLOAD_IDLE) {
        uint8_t *p = payload_make(3000, 16);
        dfu_host_report r;
        assert_int_equal(flash_payload(p, 3000, 0, &r), DFU_HOST_OK);
        free(p);
        assert_int_equal(getstate(), DFU_STATE_APP_IDLE);
        if (s == S_APP_DETACH) assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DETACH, 500, NULL, 0), 0);
        if (s == S_UPLOAD_IDLE) {
            dfu_dev_bus_reset(&lb.dev, lb.now_ms); /* app -> stays app: enter DFU via detach */
            assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DETACH, 500, NULL, 0), 0);
            dfu_dev_bus_reset(&lb.dev, lb.now_ms);
            assert_int_equal(getstate(), DFU_STATE_IDLE);
            assert_int_equal(rq(DFU_REQTYPE_IN, DFU_REQ_UPLOAD, 0, blk, 256), 256);
        }
    } else if (s != S_ERROR) {
        assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_CLRSTATUS, 0, NULL, 0), 0);
        if (s >= S_DNLOAD_SYNC) {
            assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DNLOAD, 0, blk, 256), 256);
            if (s >= S_DNBUSY) {
                st x = getstatus();
                assert_int_equal(x.state, DFU_STATE_DNBUSY);
                if (s >= S_DNLOAD_IDLE) {
                    advance(x.poll);
                    assert_int_equal(getstatus().state, DFU_STATE_DNLOAD_IDLE);
                }
            }
            if (s >= S_MANIFEST_SYNC) assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DNLOAD, 1, NULL, 0), 0);
            if (s >= S_MANIFEST) {
                st x = getstatus();
                assert_int_equal(x.state, DFU_STATE_MANIFEST);
                if (s == S_WAIT_RESET) {
                    advance(x.poll);
                    assert_int_equal(getstatus().state, DFU_STATE_MANIFEST_WAIT_RESET);
                }
            }
        }
    }
    static const uint8_t want[S_COUNT] = {DFU_STATE_APP_IDLE,      DFU_STATE_APP_DETACH, DFU_STATE_IDLE,
                                          DFU_STATE_DNLOAD_SYNC,   DFU_STATE_DNBUSY,     DFU_STATE_DNLOAD_IDLE,
                                          DFU_STATE_MANIFEST_SYNC, DFU_STATE_MANIFEST,   DFU_STATE_MANIFEST_WAIT_RESET,
                                          DFU_STATE_UPLOAD_IDLE,   DFU_STATE_ERROR};
    assert_int_equal(dfu_dev_state(&lb.dev), want[s]);
}

static void test_invalid_requests_stall(void **state)
{
    (void)state;
    /* requests that are valid per state (DFU 1.1 appendix A); "D0" = DNLOAD wLength 0 */
    enum { R_DETACH, R_DNLOAD, R_D0, R_UPLOAD, R_GETSTATUS, R_CLRSTATUS, R_GETSTATE, R_ABORT, R_N };
    static const char *const valid[S_COUNT] = {
        [S_APP_IDLE] = "DETACH GETSTATUS GETSTATE",
        [S_APP_DETACH] = "GETSTATUS GETSTATE",
        [S_IDLE] = "DNLOAD UPLOAD GETSTATUS GETSTATE ABORT",
        [S_DNLOAD_SYNC] = "GETSTATUS GETSTATE",
        [S_DNBUSY] = "",
        [S_DNLOAD_IDLE] = "DNLOAD D0 GETSTATUS GETSTATE ABORT",
        [S_MANIFEST_SYNC] = "GETSTATUS GETSTATE",
        [S_MANIFEST] = "",
        [S_WAIT_RESET] = "GETSTATUS GETSTATE",
        [S_UPLOAD_IDLE] = "UPLOAD GETSTATUS GETSTATE ABORT",
        [S_ERROR] = "GETSTATUS CLRSTATUS GETSTATE",
    };
    static const char *const rname[R_N] = {"DETACH",    "DNLOAD",    "D0",       "UPLOAD",
                                           "GETSTATUS", "CLRSTATUS", "GETSTATE", "ABORT"};
    static const uint8_t breq[R_N] = {DFU_REQ_DETACH,    DFU_REQ_DNLOAD,    DFU_REQ_DNLOAD,   DFU_REQ_UPLOAD,
                                      DFU_REQ_GETSTATUS, DFU_REQ_CLRSTATUS, DFU_REQ_GETSTATE, DFU_REQ_ABORT};
    int stalls = 0, acks = 0;
    for (int s = 0; s < S_COUNT; s++) {
        for (int q = 0; q < R_N; q++) {
            drive(s);
            uint8_t before = dfu_dev_state(&lb.dev);
            uint8_t buf[256];
            memset(buf, 0x3C, sizeof buf);
            int in = breq[q] == DFU_REQ_UPLOAD || breq[q] == DFU_REQ_GETSTATUS || breq[q] == DFU_REQ_GETSTATE;
            uint16_t len = q == R_DNLOAD || q == R_UPLOAD ? 256 : q == R_GETSTATUS ? 6 : q == R_GETSTATE ? 1 : 0;
            uint16_t value = q == R_DNLOAD || q == R_D0 ? 1 : q == R_DETACH ? 500 : 0;
            int x = rq(in ? DFU_REQTYPE_IN : DFU_REQTYPE_OUT, breq[q], value, buf, len);
            /* does the name appear as a whole word in the valid list? */
            const char *v = valid[s], *hit = strstr(v, rname[q]);
            while (hit && ((hit > v && hit[-1] != ' ') || (hit[strlen(rname[q])] != ' ' && hit[strlen(rname[q])] != 0)))
                hit = strstr(hit + 1, rname[q]);
            if (hit) {
                if (x < 0) fail_msg("state %s: %s should be accepted", dfu_state_name(before), rname[q]);
                acks++;
                continue;
            }
            if (x != DFU_XFER_STALL) fail_msg("state %s: %s should stall, got %d", dfu_state_name(before), rname[q], x);
            stalls++;
            uint8_t after = dfu_dev_state(&lb.dev);
            if (before == DFU_STATE_APP_IDLE || before == DFU_STATE_MANIFEST_WAIT_RESET || before == DFU_STATE_ERROR) {
                assert_int_equal(after, before);
            } else if (before == DFU_STATE_APP_DETACH) {
                assert_int_equal(after, DFU_STATE_APP_IDLE);
            } else {
                assert_int_equal(after, DFU_STATE_ERROR);
                assert_int_equal(dfu_dev_status(&lb.dev), q == R_D0 && before == DFU_STATE_IDLE
                                                              ? DFU_STATUS_ERR_NOTDONE
                                                              : DFU_STATUS_ERR_STALLEDPKT);
            }
            if (after == DFU_STATE_ERROR) {
                /* and CLRSTATUS brings it back */
                assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_CLRSTATUS, 0, NULL, 0), 0);
                assert_int_equal(getstate(), DFU_STATE_IDLE);
            }
        }
    }
    assert_true(stalls > 40);
    assert_true(acks > 20);

    /* wrong direction, unknown request, too long a block, out-of-sequence block */
    drive(S_IDLE);
    uint8_t b[512] = {0};
    assert_int_equal(rq(DFU_REQTYPE_IN, DFU_REQ_DNLOAD, 0, b, 16), DFU_XFER_STALL);
    assert_int_equal(getstatus().state, DFU_STATE_ERROR);
    drive(S_IDLE);
    assert_int_equal(rq(DFU_REQTYPE_OUT, 7, 0, NULL, 0), DFU_XFER_STALL);
    assert_int_equal(getstatus().status, DFU_STATUS_ERR_STALLEDPKT);
    drive(S_IDLE);
    assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DNLOAD, 0, b, 257), DFU_XFER_STALL);
    assert_int_equal(getstatus().state, DFU_STATE_ERROR);
    drive(S_DNLOAD_IDLE);
    assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DNLOAD, 5, b, 16), DFU_XFER_STALL);
    st s = getstatus();
    assert_int_equal(s.state, DFU_STATE_ERROR);
    assert_int_equal(s.status, DFU_STATUS_ERR_ADDRESS);
}

static void test_abort_and_reset_leave_no_valid_app(void **state)
{
    (void)state;
    /* ABORT in the middle of a download over a valid application */
    drive(S_APP_IDLE);
    assert_true(app_valid());
    assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DETACH, 500, NULL, 0), 0);
    dfu_dev_bus_reset(&lb.dev, lb.now_ms);
    assert_int_equal(getstate(), DFU_STATE_IDLE);
    uint8_t blk[256];
    memset(blk, 0x11, sizeof blk);
    assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_DNLOAD, 0, blk, 256), 256);
    st s = getstatus();
    advance(s.poll);
    assert_int_equal(getstatus().state, DFU_STATE_DNLOAD_IDLE);
    assert_false(app_valid()); /* the valid mark went first */
    assert_int_equal(rq(DFU_REQTYPE_OUT, DFU_REQ_ABORT, 0, NULL, 0), 0);
    assert_int_equal(getstate(), DFU_STATE_IDLE);
    assert_false(app_valid());
    /* a USB reset now: the firmware is not valid, the device stays in DFU mode */
    dfu_dev_bus_reset(&lb.dev, lb.now_ms);
    s = getstatus();
    assert_int_equal(s.state, DFU_STATE_ERROR);
    assert_int_equal(s.status, DFU_STATUS_ERR_FIRMWARE);

    /* a reset in dfuDNLOAD-IDLE */
    drive(S_DNLOAD_IDLE);
    dfu_dev_bus_reset(&lb.dev, lb.now_ms);
    assert_int_equal(dfu_dev_state(&lb.dev), DFU_STATE_ERROR);
    assert_int_equal(dfu_dev_status(&lb.dev), DFU_STATUS_ERR_FIRMWARE);

    /* appDETACH times out back to appIDLE; a reset after that does not enter DFU mode */
    drive(S_APP_DETACH);
    advance(501);
    assert_int_equal(getstate(), DFU_STATE_APP_IDLE);
    dfu_dev_bus_reset(&lb.dev, lb.now_ms);
    assert_int_equal(getstate(), DFU_STATE_APP_IDLE);
}

static void test_host_recovers_leftover_states(void **state)
{
    (void)state;
    uint8_t *p = payload_make(5000, 17);
    dfu_host_report r;
    static const int from[] = {S_ERROR,       S_IDLE,       S_DNLOAD_SYNC, S_DNLOAD_IDLE, S_MANIFEST_SYNC,
                               S_UPLOAD_IDLE, S_WAIT_RESET, S_APP_IDLE,    S_APP_DETACH};
    for (size_t i = 0; i < sizeof from / sizeof from[0]; i++) {
        drive(from[i]);
        if (flash_payload(p, 5000, 0, &r) != DFU_HOST_OK) fail_msg("from state %d: %s", from[i], r.msg);
        assert_app_is(p, 5000);
    }
    free(p);
}

static void test_upload_reads_back(void **state)
{
    (void)state;
    drive(S_UPLOAD_IDLE); /* 256 bytes of the 3000-byte application read */
    uint8_t *p = payload_make(3000, 16);
    uint8_t *got = malloc(3000 + 256);
    size_t n = 0;
    memcpy(got, lb.mem, 256); /* the first frame, as drive() read it */
    n = 256;
    for (;;) {
        int x = rq(DFU_REQTYPE_IN, DFU_REQ_UPLOAD, 0, got + n, 256);
        assert_true(x >= 0);
        n += (size_t)x;
        if (x < 256) break;
    }
    assert_int_equal(n, 3000);
    assert_memory_equal(got, p, 3000);
    assert_int_equal(getstate(), DFU_STATE_IDLE); /* the short frame ended it */
    free(got);
    free(p);
}

static void test_messages(void **state)
{
    (void)state;
    for (unsigned s = 0; s <= 10; s++) assert_string_not_equal(dfu_state_name(s), "unknown state");
    for (unsigned s = 0; s <= 15; s++) {
        assert_string_not_equal(dfu_status_name(s), "unknown status");
        assert_true(strlen(dfu_status_text(s)) > 5);
    }
    assert_string_equal(dfu_state_name(DFU_STATE_DNBUSY), "dfuDNBUSY");
    assert_string_equal(dfu_status_name(DFU_STATUS_ERR_CHECK_ERASED), "errCHECK_ERASED");
    assert_string_equal(dfu_state_name(99), "unknown state");
    /* a device that is unusable is refused by init */
    dfu_dev_t *d = malloc(sizeof *d);
    dfu_dev_config_t c = dfu_loop_default_config();
    dfu_flash_t f = {NULL, 1024, 1024, snap_never, snap_never_prog, snap_read};
    assert_int_equal(dfu_dev_init(d, &c, &f, 0, 0), -1); /* one page only */
    f.size = 4096;
    c.transfer_size = DFU_MAX_TRANSFER + 1;
    assert_int_equal(dfu_dev_init(d, &c, &f, 0, 0), -1);
    free(d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_suffix_crc_convention, setup, teardown),
        cmocka_unit_test_setup_teardown(test_parser_rejects_damage, setup, teardown),
        cmocka_unit_test_setup_teardown(test_download_succeeds_all_transfer_sizes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_host_transfer_size_option, setup, teardown),
        cmocka_unit_test_setup_teardown(test_manifestation_not_tolerant, setup, teardown),
        cmocka_unit_test_setup_teardown(test_detach_from_runtime, setup, teardown),
        cmocka_unit_test_setup_teardown(test_damaged_image_sends_nothing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_device_errors, setup, teardown),
        cmocka_unit_test_setup_teardown(test_image_too_large, setup, teardown),
        cmocka_unit_test_setup_teardown(test_transfer_error_then_abort, setup, teardown),
        cmocka_unit_test_setup_teardown(test_interrupted_download_fresh, setup, teardown),
        cmocka_unit_test_setup_teardown(test_interrupted_download_over_old_app, setup, teardown),
        cmocka_unit_test_setup_teardown(test_timeouts_mid_download, setup, teardown),
        cmocka_unit_test_setup_teardown(test_power_cut_at_every_flash_operation, setup, teardown),
        cmocka_unit_test_setup_teardown(test_poll_timeouts_honoured, setup, teardown),
        cmocka_unit_test_setup_teardown(test_early_poll_stalls, setup, teardown),
        cmocka_unit_test_setup_teardown(test_invalid_requests_stall, setup, teardown),
        cmocka_unit_test_setup_teardown(test_abort_and_reset_leave_no_valid_app, setup, teardown),
        cmocka_unit_test_setup_teardown(test_host_recovers_leftover_states, setup, teardown),
        cmocka_unit_test_setup_teardown(test_upload_reads_back, setup, teardown),
        cmocka_unit_test_setup_teardown(test_messages, setup, teardown),
    };
    return cmocka_run_group_tests_name("dfu", tests, NULL, NULL);
}
