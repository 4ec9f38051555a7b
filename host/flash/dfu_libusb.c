/* dfu_libusb.c - the libusb-1.0 DFU transport (see dfu_libusb.h). */
#define _POSIX_C_SOURCE 200809L
#include "dfu_libusb.h"

#include <libusb.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dfu/dfu_proto.h"

#define UDEV_HINT                                                                                                      \
    "install the udev rule from docs/flashing.md (section \"Permissions\"), "                                          \
    "replug the device, or run as root"

struct dfu_usb {
    libusb_context *ctx;
    libusb_device_handle *h;
    uint16_t vid, pid;
    char serial[128]; /* the serial asked for ("" = any) */
    uint8_t bus, address, ports[8];
    int nports;
    int intf, alt, claimed, verbose;
    dfu_func_desc desc;
    char last_error[512];
};

typedef struct dfu_if {
    int intf, alt;
    uint8_t protocol; /* 1 run-time, 2 DFU mode */
    int has_func;
    dfu_func_desc desc;
} dfu_if;

static void msgf(char *msg, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, n, fmt, ap);
    va_end(ap);
}

static void catf(char *msg, size_t n, const char *fmt, ...)
{
    size_t used = strlen(msg);
    if (used + 1 >= n) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg + used, n - used, fmt, ap);
    va_end(ap);
}

static uint64_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u;
}

static void nap_ms(uint32_t ms)
{
    struct timespec ts = {(time_t)(ms / 1000u), (long)(ms % 1000u) * 1000000L};
    while (nanosleep(&ts, &ts) != 0) {
    }
}

/* The DFU functional descriptor among class descriptors (bLength, bDescriptorType...). */
static int parse_functional(const unsigned char *p, int n, dfu_func_desc *d)
{
    while (p && n >= 2) {
        int len = p[0];
        if (len < 2 || len > n) break;
        if (p[1] == DFU_DESC_FUNCTIONAL && len >= 7) {
            d->attributes = p[2];
            d->detach_timeout_ms = (uint16_t)(p[3] | p[4] << 8);
            d->transfer_size = (uint16_t)(p[5] | p[6] << 8);
            d->bcd_dfu = len >= 9 ? (uint16_t)(p[7] | p[8] << 8) : 0x0100;
            return 1;
        }
        p += len;
        n -= len;
    }
    return 0;
}

/* The first DFU interface (class 0xFE, subclass 1) of the device's configuration. */
static int find_dfu_if(libusb_device *dev, dfu_if *out)
{
    struct libusb_config_descriptor *cfg = NULL;
    if (libusb_get_active_config_descriptor(dev, &cfg) != 0 && libusb_get_config_descriptor(dev, 0, &cfg) != 0)
        return 0;
    int found = 0;
    for (int i = 0; i < cfg->bNumInterfaces && !found; i++) {
        const struct libusb_interface *itf = &cfg->interface[i];
        for (int a = 0; a < itf->num_altsetting && !found; a++) {
            const struct libusb_interface_descriptor *d = &itf->altsetting[a];
            if (d->bInterfaceClass != DFU_IF_CLASS || d->bInterfaceSubClass != DFU_IF_SUBCLASS) continue;
            memset(out, 0, sizeof *out);
            out->intf = d->bInterfaceNumber;
            out->alt = d->bAlternateSetting;
            out->protocol = d->bInterfaceProtocol;
            out->has_func = parse_functional(d->extra, d->extra_length, &out->desc) ||
                            parse_functional(cfg->extra, cfg->extra_length, &out->desc);
            found = 1;
        }
    }
    libusb_free_config_descriptor(cfg);
    return found;
}

static void read_serial(libusb_device *dev, char *buf, size_t n, int *access_denied)
{
    struct libusb_device_descriptor dd;
    libusb_device_handle *h;
    buf[0] = 0;
    if (libusb_get_device_descriptor(dev, &dd) != 0 || !dd.iSerialNumber) return;
    int r = libusb_open(dev, &h);
    if (r != 0) {
        if (r == LIBUSB_ERROR_ACCESS && access_denied) *access_denied = 1;
        return;
    }
    if (libusb_get_string_descriptor_ascii(h, dd.iSerialNumber, (unsigned char *)buf, (int)n) < 0) buf[0] = 0;
    libusb_close(h);
}

static void port_path(libusb_device *dev, char *buf, size_t n)
{
    uint8_t ports[8];
    int np = libusb_get_port_numbers(dev, ports, 8);
    msgf(buf, n, "%u-", libusb_get_bus_number(dev));
    for (int i = 0; i < np; i++) catf(buf, n, i ? ".%u" : "%u", ports[i]);
}

/* One line per attached DFU device into msg; returns the count. */
static int describe_dfu_devices(libusb_context *ctx, char *msg, size_t n, const char *prefix)
{
    libusb_device **list;
    ssize_t cnt = libusb_get_device_list(ctx, &list);
    int found = 0;
    if (cnt < 0) return 0;
    for (ssize_t i = 0; i < cnt; i++) {
        struct libusb_device_descriptor dd;
        dfu_if di;
        if (libusb_get_device_descriptor(list[i], &dd) != 0 || !find_dfu_if(list[i], &di)) continue;
        char serial[128], path[40];
        int denied = 0;
        read_serial(list[i], serial, sizeof serial, &denied);
        port_path(list[i], path, sizeof path);
        catf(msg, n, "%s%04x:%04x at port %s (bus %03u device %03u), %s, serial %s%s", prefix, dd.idVendor,
             dd.idProduct, path, libusb_get_bus_number(list[i]), libusb_get_device_address(list[i]),
             di.protocol == DFU_IF_PROTOCOL_DFU_MODE ? "DFU mode" : "run-time mode",
             serial[0] ? serial : (denied ? "unreadable (no permission)" : "none"),
             di.has_func ? "" : ", no DFU functional descriptor");
        found++;
    }
    libusb_free_device_list(list, 1);
    return found;
}

int dfu_usb_list(FILE *f)
{
    libusb_context *ctx;
    int r = libusb_init(&ctx);
    if (r != 0) {
        fprintf(f, "libusb cannot be initialised: %s\n", libusb_strerror((enum libusb_error)r));
        return 0;
    }
    char buf[4096] = "";
    int n = describe_dfu_devices(ctx, buf, sizeof buf, "\n  ");
    if (n)
        fprintf(f, "DFU devices attached:%s\n", buf);
    else
        fprintf(f, "no DFU devices attached\n");
    libusb_exit(ctx);
    return n;
}

static dfu_usb_err open_claim(dfu_usb *u, libusb_device *dev, const dfu_if *di, char *msg, size_t n)
{
    struct libusb_device_descriptor dd;
    libusb_get_device_descriptor(dev, &dd);
    int r = libusb_open(dev, &u->h);
    if (r == LIBUSB_ERROR_ACCESS) {
        msgf(msg, n, "permission denied opening %04x:%04x (bus %03u device %03u): " UDEV_HINT, dd.idVendor,
             dd.idProduct, libusb_get_bus_number(dev), libusb_get_device_address(dev));
        return DFU_USB_ACCESS;
    }
    if (r != 0) {
        msgf(msg, n, "cannot open %04x:%04x: %s", dd.idVendor, dd.idProduct, libusb_strerror((enum libusb_error)r));
        return r == LIBUSB_ERROR_NO_DEVICE ? DFU_USB_NOT_FOUND : DFU_USB_ERROR;
    }
    libusb_set_auto_detach_kernel_driver(u->h, 1);
    r = libusb_claim_interface(u->h, di->intf);
    if (r != 0) {
        libusb_close(u->h);
        u->h = NULL;
        if (r == LIBUSB_ERROR_BUSY) {
            msgf(msg, n,
                 "the DFU interface %d of %04x:%04x is in use by another program (another "
                 "flasher?)",
                 di->intf, dd.idVendor, dd.idProduct);
            return DFU_USB_BUSY;
        }
        if (r == LIBUSB_ERROR_ACCESS) {
            msgf(msg, n, "permission denied claiming the DFU interface of %04x:%04x: " UDEV_HINT, dd.idVendor,
                 dd.idProduct);
            return DFU_USB_ACCESS;
        }
        msgf(msg, n, "cannot claim the DFU interface of %04x:%04x: %s", dd.idVendor, dd.idProduct,
             libusb_strerror((enum libusb_error)r));
        return DFU_USB_ERROR;
    }
    u->claimed = 1;
    if (di->alt != 0) libusb_set_interface_alt_setting(u->h, di->intf, di->alt);
    u->intf = di->intf;
    u->alt = di->alt;
    u->vid = dd.idVendor;
    u->pid = dd.idProduct;
    if (di->has_func) {
        u->desc = di->desc;
    } else {
        /* no functional descriptor: assume the least (download only, not tolerant) */
        memset(&u->desc, 0, sizeof u->desc);
        u->desc.attributes = DFU_ATTR_CAN_DNLOAD;
        u->desc.transfer_size = 1024;
        u->desc.bcd_dfu = 0x0100;
    }
    u->bus = libusb_get_bus_number(dev);
    u->address = libusb_get_device_address(dev);
    u->nports = libusb_get_port_numbers(dev, u->ports, 8);
    if (u->nports < 0) u->nports = 0;
    return DFU_USB_OK;
}

dfu_usb_err dfu_usb_open(dfu_usb **out, uint16_t vid, uint16_t pid, const char *serial, int verbose, char *msg,
                         size_t n)
{
    *out = NULL;
    msg[0] = 0;
    dfu_usb *u = calloc(1, sizeof *u);
    if (!u) {
        msgf(msg, n, "out of memory");
        return DFU_USB_ERROR;
    }
    u->verbose = verbose;
    if (serial) snprintf(u->serial, sizeof u->serial, "%s", serial);
    int r = libusb_init(&u->ctx);
    if (r != 0) {
        msgf(msg, n, "no device found for %04x:%04x: libusb cannot reach USB (%s)", vid, pid,
             libusb_strerror((enum libusb_error)r));
        free(u);
        return DFU_USB_NOT_FOUND;
    }
    libusb_device **list;
    ssize_t cnt = libusb_get_device_list(u->ctx, &list);
    if (cnt < 0) {
        msgf(msg, n, "no device found for %04x:%04x: cannot list USB devices (%s)", vid, pid,
             libusb_strerror((enum libusb_error)cnt));
        libusb_exit(u->ctx);
        free(u);
        return DFU_USB_NOT_FOUND;
    }
    libusb_device *chosen = NULL;
    int matches = 0, serial_mismatch = 0, denied = 0;
    char serials[512] = "";
    for (ssize_t i = 0; i < cnt; i++) {
        struct libusb_device_descriptor dd;
        if (libusb_get_device_descriptor(list[i], &dd) != 0 || dd.idVendor != vid || dd.idProduct != pid) continue;
        char sn[128];
        read_serial(list[i], sn, sizeof sn, &denied);
        if (u->serial[0] && strcmp(sn, u->serial) != 0) {
            serial_mismatch++;
            catf(serials, sizeof serials, "%s%s", serial_mismatch > 1 ? ", " : "", sn[0] ? sn : "(unreadable)");
            continue;
        }
        catf(serials, sizeof serials, "%s%s", matches ? ", " : "", sn[0] ? sn : "(unreadable)");
        matches++;
        if (!chosen) chosen = list[i];
    }
    dfu_usb_err err = DFU_USB_OK;
    dfu_if di;
    if (matches == 0) {
        if (serial_mismatch)
            msgf(msg, n, "no device found for %04x:%04x with serial number \"%s\" (attached: %s)", vid, pid, u->serial,
                 serials);
        else
            msgf(msg, n, "no device found for %04x:%04x", vid, pid);
        if (serial_mismatch && denied) catf(msg, n, "; some serial numbers could not be read: " UDEV_HINT);
        char others[3000] = "";
        int k = describe_dfu_devices(u->ctx, others, sizeof others, "\n  ");
        if (k)
            catf(msg, n, ". DFU devices attached:%s", others);
        else
            catf(msg, n,
                 ". No DFU devices are attached (%zd USB devices seen); check the cable and "
                 "that the device is in its bootloader",
                 cnt);
        err = DFU_USB_NOT_FOUND;
    } else if (matches > 1) {
        msgf(msg, n, "%d devices match %04x:%04x; choose one with --serial (serial numbers: %s)", matches, vid, pid,
             serials);
        if (denied) catf(msg, n, "; some serial numbers could not be read: " UDEV_HINT);
        err = DFU_USB_AMBIGUOUS;
    } else if (!find_dfu_if(chosen, &di)) {
        msgf(msg, n, "the device %04x:%04x has no DFU interface (class 0xFE, subclass 0x01)", vid, pid);
        err = DFU_USB_NOT_FOUND;
    } else {
        err = open_claim(u, chosen, &di, msg, n);
    }
    libusb_free_device_list(list, 1);
    if (err != DFU_USB_OK) {
        libusb_exit(u->ctx);
        free(u);
        return err;
    }
    *out = u;
    return DFU_USB_OK;
}

static void release(dfu_usb *u)
{
    if (u->h) {
        if (u->claimed) libusb_release_interface(u->h, u->intf);
        libusb_close(u->h);
    }
    u->h = NULL;
    u->claimed = 0;
}

void dfu_usb_close(dfu_usb *u)
{
    if (!u) return;
    release(u);
    libusb_exit(u->ctx);
    free(u);
}

static int map_err(dfu_usb *u, int r, const char *what)
{
    snprintf(u->last_error, sizeof u->last_error, "%s: %s", what, libusb_error_name(r));
    switch (r) {
    case LIBUSB_ERROR_TIMEOUT: return DFU_XFER_TIMEOUT;
    case LIBUSB_ERROR_PIPE: return DFU_XFER_STALL;
    case LIBUSB_ERROR_NO_DEVICE:
    case LIBUSB_ERROR_NOT_FOUND: return DFU_XFER_NO_DEVICE;
    default: return DFU_XFER_IO;
    }
}

static int usb_control(void *ctx, uint8_t type, uint8_t request, uint16_t value, uint8_t *data, uint16_t length,
                       unsigned timeout_ms)
{
    dfu_usb *u = ctx;
    if (!u->h) {
        snprintf(u->last_error, sizeof u->last_error, "device not open");
        return DFU_XFER_NO_DEVICE;
    }
    int r = libusb_control_transfer(u->h, type, request, value, (uint16_t)u->intf, data, length, timeout_ms);
    if (r < 0) return map_err(u, r, dfu_request_name(request));
    return r;
}

static void usb_sleep(void *ctx, uint32_t ms)
{
    (void)ctx;
    nap_ms(ms);
}

static int usb_reset(void *ctx)
{
    dfu_usb *u = ctx;
    if (!u->h) return DFU_XFER_NO_DEVICE;
    int r = libusb_reset_device(u->h);
    return r == 0 ? DFU_XFER_OK : map_err(u, r, "reset");
}

/* Is dev where our device was plugged in? */
static int same_port(dfu_usb *u, libusb_device *dev)
{
    uint8_t ports[8];
    int np = libusb_get_port_numbers(dev, ports, 8);
    return u->nports > 0 && np == u->nports && libusb_get_bus_number(dev) == u->bus &&
           memcmp(ports, u->ports, (size_t)np) == 0;
}

static int usb_reenumerate(void *ctx, unsigned timeout_ms)
{
    dfu_usb *u = ctx;
    release(u);
    uint64_t start = now_ms();
    nap_ms(500); /* let the old device go before looking for the new one */
    char msg[512];
    for (;;) {
        libusb_device **list;
        ssize_t cnt = libusb_get_device_list(u->ctx, &list);
        libusb_device *found = NULL;
        for (ssize_t i = 0; i < cnt && !found; i++) {
            struct libusb_device_descriptor dd;
            if (libusb_get_device_descriptor(list[i], &dd) != 0) continue;
            if (same_port(u, list[i])) {
                found = list[i];
            } else if (u->nports == 0 && dd.idVendor == u->vid && dd.idProduct == u->pid) {
                char sn[128];
                read_serial(list[i], sn, sizeof sn, NULL);
                if (!u->serial[0] || strcmp(sn, u->serial) == 0) found = list[i];
            }
        }
        int result = DFU_XFER_TIMEOUT;
        if (found) {
            dfu_if di;
            if (!find_dfu_if(found, &di)) {
                result = 0;
            } else {
                dfu_usb_err e = open_claim(u, found, &di, msg, sizeof msg);
                if (e == DFU_USB_OK) {
                    result = 1;
                } else {
                    snprintf(u->last_error, sizeof u->last_error, "%s", msg);
                    result = e == DFU_USB_ACCESS ? DFU_XFER_IO : DFU_XFER_TIMEOUT;
                }
            }
        }
        if (cnt >= 0) libusb_free_device_list(list, 1);
        if (result >= 0 || result == DFU_XFER_IO) return result;
        if (now_ms() - start >= timeout_ms) {
            snprintf(u->last_error, sizeof u->last_error, "the device did not re-enumerate within %u ms", timeout_ms);
            return DFU_XFER_TIMEOUT;
        }
        nap_ms(100);
    }
}

static void usb_functional(void *ctx, dfu_func_desc *out)
{
    *out = ((dfu_usb *)ctx)->desc;
}

static const char *usb_last_error(void *ctx)
{
    return ((dfu_usb *)ctx)->last_error;
}

dfu_transport dfu_usb_transport(dfu_usb *u)
{
    dfu_transport t = {u, usb_control, usb_sleep, usb_reset, usb_reenumerate, usb_functional, usb_last_error};
    return t;
}
