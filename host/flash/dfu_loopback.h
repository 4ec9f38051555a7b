/* dfu_loopback.h - a DFU transport without USB (prefix dfu_loop_): the host engine's
 * control transfers call the device state machine (firmware/dfu/dfu_device.c)
 * directly, over a RAM flash, with a fake clock that only moves when the host sleeps
 * (bwPollTimeout) or waits for re-enumeration. Counts every request, and injects
 * faults: the device vanishing or timing out after N requests, failing or corrupting
 * flash operations (through a hook). Used by the unit tests and by build/flash
 * --loopback. */
#ifndef DFU_LOOPBACK_H
#define DFU_LOOPBACK_H

#include <stddef.h>
#include <stdint.h>

#include "dfu/dfu_device.h"
#include "dfu_transport.h"

typedef enum dfu_loop_op { DFU_LOOP_ERASE, DFU_LOOP_PROGRAM, DFU_LOOP_READ } dfu_loop_op;

/* What a flash hook decides for an operation about to happen. */
enum {
    DFU_LOOP_PASS = 0,    /* do it */
    DFU_LOOP_FAIL = 1,    /* do nothing, report failure */
    DFU_LOOP_CORRUPT = 2, /* do it with one bit flipped, report success */
};

typedef struct dfu_loopback {
    dfu_dev_t dev;
    dfu_dev_config_t cfg;
    dfu_flash_t flash;
    uint8_t *mem;       /* the RAM flash, flash.size bytes */
    uint32_t now_ms;    /* the fake clock */
    uint32_t reenum_ms; /* simulated time to re-enumerate (default 300) */
    /* counters */
    unsigned long requests;      /* control transfers that reached the device */
    unsigned long by_request[7]; /* ... per bRequest */
    unsigned long stalls, resets, erases, programs, reads;
    unsigned long slept_ms; /* total time the host slept */
    /* faults: after this many requests the device vanishes (NO_DEVICE) or stops
     * answering (TIMEOUT); -1 = never */
    long vanish_after, timeout_after;
    /* the request with this number (0-based count) fails once with an I/O error and
     * never reaches the device; -1 = never */
    long io_error_at;
    int vanished;
    int (*flash_hook)(void *user, dfu_loop_op op, uint32_t offset, const uint8_t *src, uint32_t n);
    void *hook_user;
    /* log of requests for tests: the last few bRequest values */
    char last_error[64];
} dfu_loopback;

/* The default device: download+upload, manifestation-tolerant, wTransferSize 4096,
 * 4 MiB flash in 4 KiB pages, program 5 ms per block, erase 20 ms per page,
 * manifestation 100 ms. */
dfu_dev_config_t dfu_loop_default_config(void);

/* Create a loopback device with an erased flash of flash_size bytes in pages of
 * page_size; it powers on (dfu_dev_init) with stay_in_dfu. Returns 0, or -1 (bad
 * geometry or configuration, out of memory). */
int dfu_loop_init(dfu_loopback *lb, const dfu_dev_config_t *cfg, uint32_t flash_size, uint32_t page_size,
                  int stay_in_dfu);
void dfu_loop_free(dfu_loopback *lb);

/* Unplug and plug in again: clears the faults, powers the device on again from what
 * its flash holds (a valid application: appIDLE, else dfuERROR/errFIRMWARE). */
void dfu_loop_power_cycle(dfu_loopback *lb, int stay_in_dfu);

dfu_transport dfu_loop_transport(dfu_loopback *lb);

#endif
