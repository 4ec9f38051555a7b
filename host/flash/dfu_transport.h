/* dfu_transport.h - what the host's DFU engine (dfu_host.c) needs from a USB
 * connection (prefix dfu_xfer_/DFU_XFER_): class control transfers to the DFU
 * interface with a timeout, a sleep, a USB reset and a wait for re-enumeration.
 * Two implementations: libusb-1.0 (dfu_libusb.c) for real devices, and a loopback
 * (dfu_loopback.c) that calls the device state machine directly. */
#ifndef DFU_TRANSPORT_H
#define DFU_TRANSPORT_H

#include <stdint.h>

/* Errors a transport returns (negative); success is >= 0. */
enum dfu_xfer_err {
    DFU_XFER_OK = 0,
    DFU_XFER_STALL = -1,     /* the device stalled the request */
    DFU_XFER_TIMEOUT = -2,   /* no answer within the timeout */
    DFU_XFER_NO_DEVICE = -3, /* the device is gone (unplugged, reset away) */
    DFU_XFER_IO = -4,        /* any other USB error (see last_error) */
};

/* The DFU functional descriptor of the interface in use. */
typedef struct dfu_func_desc {
    uint8_t attributes; /* DFU_ATTR_* */
    uint16_t detach_timeout_ms;
    uint16_t transfer_size;
    uint16_t bcd_dfu;
    /* The largest image the device takes, in bytes; 0 = not reported. DFU 1.1 has
     * no field for it: the loopback reports its application area, a USB device
     * does not yet (its own check stalls the first block past the end). */
    uint32_t app_capacity;
} dfu_func_desc;

typedef struct dfu_transport {
    void *ctx;
    /* One control transfer to the DFU interface: bm_request_type DFU_REQTYPE_OUT
     * (data holds length bytes) or DFU_REQTYPE_IN (data receives up to length bytes).
     * Returns the bytes transferred, or a DFU_XFER_* error. */
    int (*control)(void *ctx, uint8_t bm_request_type, uint8_t b_request, uint16_t w_value, uint8_t *data,
                   uint16_t length, unsigned timeout_ms);
    /* Wait this long (the device's bwPollTimeout). */
    void (*sleep_ms)(void *ctx, uint32_t ms);
    /* USB reset of the device; DFU_XFER_OK, or an error (NO_DEVICE is normal when
     * the device re-enumerates as something else). */
    int (*reset)(void *ctx);
    /* After a reset or a detach: wait up to timeout_ms for the device to come back
     * and reopen it. Returns 1 when it is back with a DFU interface (runtime or DFU
     * mode), 0 when it is back without one, or a DFU_XFER_* error (TIMEOUT). */
    int (*reenumerate)(void *ctx, unsigned timeout_ms);
    /* The functional descriptor of the interface currently open. */
    void (*functional)(void *ctx, dfu_func_desc *out);
    /* Detail of the last error ("LIBUSB_ERROR_IO"), or "". */
    const char *(*last_error)(void *ctx);
} dfu_transport;

#endif
