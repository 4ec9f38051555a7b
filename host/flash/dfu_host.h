/* dfu_host.h - the host side of a USB DFU 1.1 download (prefix dfu_host_): validate
 * the image, bring the device to dfuIDLE (DETACH from run-time mode, CLRSTATUS out of
 * dfuERROR, ABORT out of an old transfer), DNLOAD blocks, GETSTATUS polling that
 * waits the device's bwPollTimeout, manifestation (tolerant or not), USB reset and a
 * wait for re-enumeration. Errors leave the device cleaned up (CLRSTATUS/ABORT) where
 * it can still be reached. Written against dfu_transport only. */
#ifndef DFU_HOST_H
#define DFU_HOST_H

#include <stddef.h>
#include <stdint.h>

#include "dfu_transport.h"

typedef enum dfu_host_err {
    DFU_HOST_OK = 0,
    DFU_HOST_BAD_IMAGE,    /* the image was rejected; nothing was sent */
    DFU_HOST_BAD_ARGS,     /* e.g. a transfer size the device does not take; nothing sent */
    DFU_HOST_NO_DEVICE,    /* the device vanished during the operation */
    DFU_HOST_TIMEOUT,      /* the device stopped answering */
    DFU_HOST_IO,           /* another USB error */
    DFU_HOST_DEVICE_ERROR, /* the device reported an error status (errWRITE ...) */
    DFU_HOST_PROTOCOL,     /* the device is in a state the protocol does not allow here */
} dfu_host_err;

typedef struct dfu_host_opts {
    uint16_t transfer_size;                    /* bytes per DNLOAD; 0 = the device's wTransferSize */
    unsigned timeout_ms;                       /* per control transfer (0: 5000) */
    unsigned reenum_timeout_ms;                /* wait for the device after the final reset (0: 10000) */
    int verbose;                               /* 1: steps, 2: every request */
    void (*log)(void *user, const char *line); /* progress and verbose lines */
    void (*progress)(void *user, size_t done, size_t total);
    void *user;
} dfu_host_opts;

typedef struct dfu_host_report {
    dfu_host_err err;
    char msg[640];          /* what happened, for a person (no trailing newline) */
    uint8_t dev_status;     /* the last bStatus seen */
    uint8_t dev_state;      /* the last bState seen */
    uint16_t transfer_size; /* bytes per block used */
    uint32_t blocks_total, blocks_done;
    size_t bytes_done, payload_len;
    uint32_t payload_crc; /* CRC-32 (zlib) of the firmware bytes sent */
    int manifest_started; /* the device took the final zero-length DNLOAD */
    int manifested;       /* the device confirmed manifestation (tolerant) */
    int reenumerated;     /* 1 back with DFU interface, 0 back without, -1 not seen */
    uint8_t final_state;  /* state after re-enumeration, when it has DFU */
} dfu_host_report;

/* Validate the whole DFU file (suffix, CRC, vid:pid) and only then download its
 * firmware. Returns the error code (also in r->err). */
dfu_host_err dfu_host_flash(const dfu_transport *t, const uint8_t *file, size_t len, uint16_t vid, uint16_t pid,
                            const dfu_host_opts *o, dfu_host_report *r);

/* Download raw firmware bytes (no suffix) to the device. */
dfu_host_err dfu_host_download(const dfu_transport *t, const uint8_t *payload, size_t len, const dfu_host_opts *o,
                               dfu_host_report *r);

const char *dfu_host_strerror(dfu_host_err e);

#endif
