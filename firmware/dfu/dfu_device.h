/* dfu_device.h - the device side of USB DFU 1.1: a bootloader's DFU state machine
 * (prefix dfu_dev_/dfu_app_). Freestanding C11: no libc, no malloc, no floating
 * point; all state lives in a caller-owned dfu_dev_t, and the flash is reached only
 * through the caller's callbacks.
 *
 * How a bootloader uses it:
 *   at reset:     dfu_app_check(&flash, &info) -> jump to the application if valid,
 *                 else (or when asked to stay) run DFU: dfu_dev_init(...)
 *   control EP0:  class requests to the DFU interface -> dfu_dev_request(...)
 *   main loop:    dfu_dev_poll(&dev, ms) (does the erasing/programming work)
 *   USB reset:    dfu_dev_bus_reset(&dev, ms); if dfu_dev_state() is appIDLE, start
 *                 the application.
 *
 * The flash region (dfu_flash_t) is laid out as
 *   [0, size - page_size)           the application image
 *   [size - page_size, size)        the valid mark: a 16-byte trailer at the start
 *                                   of the last page (magic, length, CRC-32, check)
 * The first block of a download erases the valid mark before any application page
 * is touched; the mark is written last, in manifestation, only after the whole image
 * has been received, programmed, read back and its CRC matched. So an interrupted,
 * aborted or failed download leaves no valid mark and the device stays in DFU mode
 * (dfuERROR, errFIRMWARE, after a reset), never half-flashed. */
#ifndef DFU_DEVICE_H
#define DFU_DEVICE_H

#include <stdint.h>

#include "dfu_proto.h"

#define DFU_MAX_TRANSFER 4096u /* the largest wTransferSize this machine buffers */
#define DFU_TRAILER_LEN 16u
#define DFU_TRAILER_MAGIC 0x50415642u /* "BVAP" little-endian */

/* The caller's flash region. Offsets are relative to the region. Each callback
 * returns 0 on success, anything else on failure. program() is only given ranges
 * inside one page that was erased this session, in increasing order, each byte
 * once; erased flash reads 0xFF. */
typedef struct dfu_flash {
    void *ctx;
    uint32_t size;      /* bytes: a multiple of page_size, at least two pages */
    uint32_t page_size; /* the erase unit, at least DFU_TRAILER_LEN bytes */
    int (*erase)(void *ctx, uint32_t offset);
    int (*program)(void *ctx, uint32_t offset, const uint8_t *src, uint32_t n);
    int (*read)(void *ctx, uint32_t offset, uint8_t *dst, uint32_t n);
} dfu_flash_t;

typedef struct dfu_dev_config {
    uint8_t attributes;         /* DFU_ATTR_*: what the functional descriptor says */
    uint16_t transfer_size;     /* wTransferSize, 1..DFU_MAX_TRANSFER */
    uint16_t detach_timeout_ms; /* wDetachTimeOut */
    uint32_t program_ms;        /* bwPollTimeout for programming one block */
    uint32_t erase_ms;          /* ... plus this much per page the block erases first */
    uint32_t manifest_ms;       /* bwPollTimeout for manifestation */
} dfu_dev_config_t;

typedef struct dfu_dev {
    dfu_dev_config_t cfg;
    dfu_flash_t flash;
    uint8_t state;          /* enum dfu_state */
    uint8_t status;         /* enum dfu_status */
    uint8_t work;           /* pending work (internal) */
    uint8_t manifested;     /* manifestation finished this session */
    uint8_t invalidated;    /* the valid mark was erased this session */
    uint8_t detach_pending; /* DETACH with bitWillDetach: caller should re-attach */
    uint16_t next_block;    /* wBlockNum expected next */
    uint16_t block_len;     /* bytes in block[] waiting to be programmed */
    uint32_t busy_until;    /* end of dfuDNBUSY / dfuMANIFEST, appDETACH deadline */
    uint32_t poll_ms;       /* bwPollTimeout of the last GETSTATUS answer */
    uint32_t received;      /* image bytes programmed and verified this session */
    uint32_t erased_end;    /* application pages below this offset are erased */
    uint32_t crc;           /* CRC-32 (zlib form) of the bytes received */
    uint32_t upload_pos, upload_len;
    uint8_t block[DFU_MAX_TRANSFER];
} dfu_dev_t;

typedef enum dfu_dev_result {
    DFU_DEV_ACK = 0,   /* request handled (data stage in *actual for IN) */
    DFU_DEV_STALL = 1, /* stall the control pipe (the state says why) */
} dfu_dev_result;

/* The application's valid mark, as found in flash. */
typedef struct dfu_app_info {
    uint32_t length; /* bytes of application */
    uint32_t crc;    /* their CRC-32 (zlib form) */
} dfu_app_info_t;

/* 1 if the region holds a valid mark whose length fits and whose CRC matches the
 * application bytes, else 0 (info, if given, is filled either way, 0 when absent). */
int dfu_app_check(const dfu_flash_t *flash, dfu_app_info_t *info);

/* The largest image the region takes. */
uint32_t dfu_app_capacity(const dfu_flash_t *flash);

/* Power-on. Returns -1 if the configuration or flash geometry is unusable, else 0.
 * State: appIDLE if a valid application is present and stay_in_dfu is 0 (the
 * bootloader would run it), dfuIDLE if valid and stay_in_dfu, otherwise dfuERROR
 * with errFIRMWARE (corrupt or missing firmware: stay in DFU mode). */
int dfu_dev_init(dfu_dev_t *d, const dfu_dev_config_t *cfg, const dfu_flash_t *flash, int stay_in_dfu, uint32_t now_ms);

/* One class request. For OUT requests data holds wLength bytes; for IN requests data
 * has room for wLength bytes and *actual receives how many were written. A request
 * that is not valid in the current state stalls; in DFU mode the state becomes
 * dfuERROR (status errSTALLEDPKT, or the reason, e.g. errADDRESS). */
dfu_dev_result dfu_dev_request(dfu_dev_t *d, uint32_t now_ms, uint8_t bm_request_type, uint8_t b_request,
                               uint16_t w_value, uint16_t w_length, uint8_t *data, uint16_t *actual);

/* Main loop: do pending programming/manifestation and end timed states. */
void dfu_dev_poll(dfu_dev_t *d, uint32_t now_ms);

/* A USB reset: appDETACH (before its deadline) enters DFU mode; in DFU mode the
 * device checks its firmware and runs it (appIDLE) if valid, else dfuERROR with
 * errFIRMWARE; an unfinished download is abandoned. */
void dfu_dev_bus_reset(dfu_dev_t *d, uint32_t now_ms);

static inline uint8_t dfu_dev_state(const dfu_dev_t *d)
{
    return d->state;
}
static inline uint8_t dfu_dev_status(const dfu_dev_t *d)
{
    return d->status;
}

#endif
