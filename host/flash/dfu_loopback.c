/* dfu_loopback.c - the loopback DFU transport and its RAM flash (see dfu_loopback.h). */
#include "dfu_loopback.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dfu/dfu_proto.h"

static int hook(dfu_loopback *lb, dfu_loop_op op, uint32_t off, const uint8_t *src, uint32_t n)
{
    return lb->flash_hook ? lb->flash_hook(lb->hook_user, op, off, src, n) : DFU_LOOP_PASS;
}

static int fl_erase(void *ctx, uint32_t off)
{
    dfu_loopback *lb = ctx;
    lb->erases++;
    if (off % lb->flash.page_size || off >= lb->flash.size) return -1;
    int h = hook(lb, DFU_LOOP_ERASE, off, NULL, lb->flash.page_size);
    if (h == DFU_LOOP_FAIL) return -1;
    memset(lb->mem + off, 0xFF, lb->flash.page_size);
    if (h == DFU_LOOP_CORRUPT) lb->mem[off + lb->flash.page_size / 2] = 0x7F;
    return 0;
}

static int fl_program(void *ctx, uint32_t off, const uint8_t *src, uint32_t n)
{
    dfu_loopback *lb = ctx;
    lb->programs++;
    if (off > lb->flash.size || n > lb->flash.size - off) return -1;
    int h = hook(lb, DFU_LOOP_PROGRAM, off, src, n);
    if (h == DFU_LOOP_FAIL) return -1;
    for (uint32_t i = 0; i < n; i++) lb->mem[off + i] &= src[i]; /* flash programming only clears bits */
    if (h == DFU_LOOP_CORRUPT && n) lb->mem[off + n / 2] ^= 0x01;
    return 0;
}

static int fl_read(void *ctx, uint32_t off, uint8_t *dst, uint32_t n)
{
    dfu_loopback *lb = ctx;
    lb->reads++;
    if (off > lb->flash.size || n > lb->flash.size - off) return -1;
    if (hook(lb, DFU_LOOP_READ, off, NULL, n) == DFU_LOOP_FAIL) return -1;
    memcpy(dst, lb->mem + off, n);
    return 0;
}

dfu_dev_config_t dfu_loop_default_config(void)
{
    dfu_dev_config_t c;
    memset(&c, 0, sizeof c);
    c.attributes = DFU_ATTR_CAN_DNLOAD | DFU_ATTR_CAN_UPLOAD | DFU_ATTR_MANIFEST_TOLERANT;
    c.transfer_size = 4096;
    c.detach_timeout_ms = 1000;
    c.program_ms = 5;
    c.erase_ms = 20;
    c.manifest_ms = 100;
    return c;
}

int dfu_loop_init(dfu_loopback *lb, const dfu_dev_config_t *cfg, uint32_t flash_size, uint32_t page_size,
                  int stay_in_dfu)
{
    memset(lb, 0, sizeof *lb);
    lb->cfg = cfg ? *cfg : dfu_loop_default_config();
    lb->mem = malloc(flash_size ? flash_size : 1);
    if (!lb->mem) return -1;
    memset(lb->mem, 0xFF, flash_size);
    lb->flash.ctx = lb;
    lb->flash.size = flash_size;
    lb->flash.page_size = page_size;
    lb->flash.erase = fl_erase;
    lb->flash.program = fl_program;
    lb->flash.read = fl_read;
    lb->reenum_ms = 300;
    lb->vanish_after = lb->timeout_after = lb->io_error_at = -1;
    lb->now_ms = 1000;
    if (dfu_dev_init(&lb->dev, &lb->cfg, &lb->flash, stay_in_dfu, lb->now_ms) != 0) {
        free(lb->mem);
        lb->mem = NULL;
        return -1;
    }
    return 0;
}

void dfu_loop_free(dfu_loopback *lb)
{
    free(lb->mem);
    lb->mem = NULL;
}

void dfu_loop_power_cycle(dfu_loopback *lb, int stay_in_dfu)
{
    lb->vanished = 0;
    lb->vanish_after = lb->timeout_after = lb->io_error_at = -1;
    lb->now_ms += 1000;
    dfu_dev_init(&lb->dev, &lb->cfg, &lb->flash, stay_in_dfu, lb->now_ms);
}

static int lb_control(void *ctx, uint8_t type, uint8_t request, uint16_t value, uint8_t *data, uint16_t length,
                      unsigned timeout_ms)
{
    dfu_loopback *lb = ctx;
    if (lb->vanish_after >= 0 && (long)lb->requests >= lb->vanish_after) lb->vanished = 1;
    if (lb->vanished) {
        snprintf(lb->last_error, sizeof lb->last_error, "loopback: device unplugged");
        return DFU_XFER_NO_DEVICE;
    }
    if (lb->timeout_after >= 0 && (long)lb->requests >= lb->timeout_after) {
        lb->now_ms += timeout_ms;
        snprintf(lb->last_error, sizeof lb->last_error, "loopback: device does not answer");
        return DFU_XFER_TIMEOUT;
    }
    if (lb->io_error_at >= 0 && (long)lb->requests == lb->io_error_at) {
        lb->io_error_at = -1;
        snprintf(lb->last_error, sizeof lb->last_error, "loopback: I/O error");
        return DFU_XFER_IO;
    }
    lb->requests++;
    if (request < 7) lb->by_request[request]++;
    dfu_dev_poll(&lb->dev, lb->now_ms);
    uint16_t actual = 0;
    dfu_dev_result res = dfu_dev_request(&lb->dev, lb->now_ms, type, request, value, length, data, &actual);
    if (res == DFU_DEV_STALL) {
        lb->stalls++;
        snprintf(lb->last_error, sizeof lb->last_error, "loopback: stall");
        return DFU_XFER_STALL;
    }
    return (type & 0x80u) ? actual : length;
}

static void lb_sleep(void *ctx, uint32_t ms)
{
    dfu_loopback *lb = ctx;
    lb->now_ms += ms;
    lb->slept_ms += ms;
    dfu_dev_poll(&lb->dev, lb->now_ms);
}

static int lb_reset(void *ctx)
{
    dfu_loopback *lb = ctx;
    if (lb->vanished) return DFU_XFER_NO_DEVICE;
    lb->resets++;
    dfu_dev_bus_reset(&lb->dev, lb->now_ms);
    return DFU_XFER_OK;
}

static int lb_reenumerate(void *ctx, unsigned timeout_ms)
{
    dfu_loopback *lb = ctx;
    if (lb->vanished) {
        lb->now_ms += timeout_ms;
        return DFU_XFER_TIMEOUT;
    }
    lb->now_ms += lb->reenum_ms;
    if (lb->dev.detach_pending) /* bitWillDetach: the device re-attached by itself */
        dfu_dev_bus_reset(&lb->dev, lb->now_ms);
    dfu_dev_poll(&lb->dev, lb->now_ms);
    return 1;
}

static void lb_functional(void *ctx, dfu_func_desc *out)
{
    dfu_loopback *lb = ctx;
    out->attributes = lb->cfg.attributes;
    out->detach_timeout_ms = lb->cfg.detach_timeout_ms;
    out->transfer_size = lb->cfg.transfer_size;
    out->bcd_dfu = DFU_BCD_VERSION;
    out->app_capacity = dfu_app_capacity(&lb->flash);
}

static const char *lb_last_error(void *ctx)
{
    return ((dfu_loopback *)ctx)->last_error;
}

dfu_transport dfu_loop_transport(dfu_loopback *lb)
{
    dfu_transport t = {lb, lb_control, lb_sleep, lb_reset, lb_reenumerate, lb_functional, lb_last_error};
    return t;
}
