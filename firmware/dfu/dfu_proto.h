/* dfu_proto.h - the USB DFU 1.1 protocol as both sides see it (prefix dfu_/DFU_):
 * class requests, device states, status codes, functional-descriptor attributes,
 * and their names for messages. Shared by the device state machine
 * (firmware/dfu/dfu_device.c) and the host flasher (host/flash/). */
#ifndef DFU_PROTO_H
#define DFU_PROTO_H

#include <stdint.h>

/* bmRequestType of DFU class requests: class, interface recipient. */
#define DFU_REQTYPE_OUT 0x21u /* host to device */
#define DFU_REQTYPE_IN 0xA1u  /* device to host */

/* bRequest (DFU 1.1, table 3.2). */
enum dfu_request {
    DFU_REQ_DETACH = 0,
    DFU_REQ_DNLOAD = 1,
    DFU_REQ_UPLOAD = 2,
    DFU_REQ_GETSTATUS = 3,
    DFU_REQ_CLRSTATUS = 4,
    DFU_REQ_GETSTATE = 5,
    DFU_REQ_ABORT = 6,
};

/* bState (DFU 1.1, section 6.1.2). 0 and 1 are run-time (application) states. */
enum dfu_state {
    DFU_STATE_APP_IDLE = 0,
    DFU_STATE_APP_DETACH = 1,
    DFU_STATE_IDLE = 2,
    DFU_STATE_DNLOAD_SYNC = 3,
    DFU_STATE_DNBUSY = 4,
    DFU_STATE_DNLOAD_IDLE = 5,
    DFU_STATE_MANIFEST_SYNC = 6,
    DFU_STATE_MANIFEST = 7,
    DFU_STATE_MANIFEST_WAIT_RESET = 8,
    DFU_STATE_UPLOAD_IDLE = 9,
    DFU_STATE_ERROR = 10,
};

/* bStatus (DFU 1.1, section 6.1.2). */
enum dfu_status {
    DFU_STATUS_OK = 0x00,
    DFU_STATUS_ERR_TARGET = 0x01,
    DFU_STATUS_ERR_FILE = 0x02,
    DFU_STATUS_ERR_WRITE = 0x03,
    DFU_STATUS_ERR_ERASE = 0x04,
    DFU_STATUS_ERR_CHECK_ERASED = 0x05,
    DFU_STATUS_ERR_PROG = 0x06,
    DFU_STATUS_ERR_VERIFY = 0x07,
    DFU_STATUS_ERR_ADDRESS = 0x08,
    DFU_STATUS_ERR_NOTDONE = 0x09,
    DFU_STATUS_ERR_FIRMWARE = 0x0A,
    DFU_STATUS_ERR_VENDOR = 0x0B,
    DFU_STATUS_ERR_USBR = 0x0C,
    DFU_STATUS_ERR_POR = 0x0D,
    DFU_STATUS_ERR_UNKNOWN = 0x0E,
    DFU_STATUS_ERR_STALLEDPKT = 0x0F,
};

/* GETSTATUS answers 6 bytes: bStatus, bwPollTimeout (24-bit little-endian, ms),
 * bState, iString. */
#define DFU_GETSTATUS_LEN 6u
#define DFU_POLL_TIMEOUT_MAX 0xFFFFFFu

/* DFU functional descriptor (type 0x21, 9 bytes): bmAttributes bits. */
#define DFU_DESC_FUNCTIONAL 0x21u
#define DFU_ATTR_CAN_DNLOAD 0x01u
#define DFU_ATTR_CAN_UPLOAD 0x02u
#define DFU_ATTR_MANIFEST_TOLERANT 0x04u
#define DFU_ATTR_WILL_DETACH 0x08u
#define DFU_BCD_VERSION 0x0110u

/* Interface class/subclass/protocol of a DFU interface. */
#define DFU_IF_CLASS 0xFEu
#define DFU_IF_SUBCLASS 0x01u
#define DFU_IF_PROTOCOL_RUNTIME 0x01u
#define DFU_IF_PROTOCOL_DFU_MODE 0x02u

/* "dfuDNLOAD-IDLE", "appIDLE" ...; "unknown state" outside the range. */
const char *dfu_state_name(unsigned state);
/* "OK", "errWRITE" ...; "unknown status" outside the range. */
const char *dfu_status_name(unsigned status);
/* One line saying what a status means, in the spirit of the specification. */
const char *dfu_status_text(unsigned status);
/* "DNLOAD", "GETSTATUS" ... */
const char *dfu_request_name(unsigned request);

#endif
