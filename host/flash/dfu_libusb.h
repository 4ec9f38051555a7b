/* dfu_libusb.h - the libusb-1.0 DFU transport (prefix dfu_usb_): find the device by
 * VID:PID (and serial number), open and claim its DFU interface, read its DFU
 * functional descriptor, and carry the engine's control transfers; after a reset,
 * find the device again where it was plugged in. Every failure comes with a message a
 * person can act on: no device (and what DFU devices are attached), no permission
 * (the udev rule in docs/flashing.md), interface busy, timeout, device vanished. */
#ifndef DFU_LIBUSB_H
#define DFU_LIBUSB_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "dfu_transport.h"

typedef struct dfu_usb dfu_usb;

typedef enum dfu_usb_err {
    DFU_USB_OK = 0,
    DFU_USB_NOT_FOUND, /* no device with that VID:PID (and serial), or no DFU interface */
    DFU_USB_AMBIGUOUS, /* several match: --serial needed */
    DFU_USB_ACCESS,    /* no permission */
    DFU_USB_BUSY,      /* interface claimed by another program */
    DFU_USB_ERROR,     /* anything else */
} dfu_usb_err;

/* Open the DFU interface of the device vid:pid (serial may be NULL). On failure *out
 * is NULL and msg holds the explanation. */
dfu_usb_err dfu_usb_open(dfu_usb **out, uint16_t vid, uint16_t pid, const char *serial, int verbose, char *msg,
                         size_t msglen);
void dfu_usb_close(dfu_usb *u);
dfu_transport dfu_usb_transport(dfu_usb *u);

/* Print the attached devices that have a DFU interface, one a line; returns how many. */
int dfu_usb_list(FILE *f);

#endif
