/* flash_main.c - build/flash: USB DFU 1.1 download of a firmware image with a DFU
 * suffix (libusb, or a simulated device with --loopback), and --add-suffix to make
 * such an image. The protocol is in dfu_host.c, the file format in
 * firmware/dfu/dfu_image.c, the transports in dfu_libusb.c and dfu_loopback.c. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../hal/board/board_layout.h"
#include "crc32.h"
#include "dfu/dfu_device.h"
#include "dfu/dfu_image.h"
#include "dfu/dfu_proto.h"
#include "dfu_host.h"
#include "dfu_libusb.h"
#include "dfu_loopback.h"

enum { EXIT_USAGE = 1, EXIT_IMAGE = 2, EXIT_DEVICE = 3, EXIT_DOWNLOAD = 4 };

#define MAX_FILE (256u << 20)
/* the loopback is the display board's application slot (hal/board/board_layout.h):
 * an image it takes is one board_image and the board take, and no larger */
#define LOOP_FLASH_SIZE BOARD_SLOT_BYTES
#define LOOP_PAGE_SIZE BOARD_PAGE_BYTES
/* The project's own device (the pid.codes test id the docs use): the loopback
 * enumerates as it, as the real board would, whatever the image's suffix says. */
#define LOOP_VID 0x1209u
#define LOOP_PID 0x0001u

static void usage(FILE *f)
{
    fputs("build/flash - download firmware to a device over USB DFU 1.1\n"
          "\n"
          "Usage:\n"
          "  build/flash IMAGE.dfu --device VID:PID [--serial SN] [options]\n"
          "  build/flash IMAGE.dfu --loopback [--device VID:PID] [options]\n"
          "  build/flash --add-suffix IN.bin --vid VID --pid PID [--bcd-device BCD] -o OUT.dfu\n"
          "  build/flash --check IMAGE.dfu [--device VID:PID]\n"
          "  build/flash --list\n"
          "  build/flash --help\n"
          "\n"
          "Download (the first form). IMAGE is a DFU file: the firmware binary followed by a\n"
          "16-byte DFU suffix (make one with --add-suffix). The whole file is checked first -\n"
          "suffix signature, length, CRC, DFU version, and that the VID:PID it names is the\n"
          "device's (or FFFF, any) - and a corrupted or truncated file is refused before\n"
          "anything is sent. Then the device is brought to DFU mode (DETACH from its\n"
          "application, CLRSTATUS out of an error, ABORT of an old transfer), the firmware goes\n"
          "out in DNLOAD blocks, each followed by GETSTATUS polls that wait as long as the\n"
          "device asks (bwPollTimeout), the device checks the whole image and marks it valid\n"
          "(manifestation), and is reset; build/flash waits for it to come back and says what\n"
          "it runs. If a download fails part way, the device stays in its bootloader with no\n"
          "application marked valid (never half of one): run the same command again.\n"
          "\n"
          "  --device VID:PID     the device, in hex as lsusb shows it (e.g. 1209:0001)\n"
          "  --serial SN          which one, when several devices with that VID:PID are attached\n"
          "  --transfer-size N    bytes per DNLOAD block (default and maximum: the device's\n"
          "                       wTransferSize)\n"
          "  --timeout MS         how long to wait for each USB request (default 5000)\n"
          "  --reenum-timeout MS  how long to wait for the device after a reset (default 10000)\n"
          "  -v, --verbose        say each step; twice (-vv): every DFU request\n"
          "  --list               list the attached devices that have a DFU interface\n"
          "\n"
          "Without hardware. --loopback downloads into a simulated device instead of USB: the\n"
          "project's own bootloader state machine (firmware/dfu/) over 4 MiB of RAM flash in\n"
          "4 KiB pages, wTransferSize 4096, with simulated time, so you can watch a download\n"
          "succeed (add -v) and see what the device holds afterwards. It is the project's\n"
          "device, 1209:0001, so an image made for another VID:PID is refused as by the real\n"
          "one. --loopback-unplug-after N unplugs the simulated device after N requests,\n"
          "to show what an interrupted download leaves behind.\n"
          "\n"
          "Making an image. --add-suffix IN.bin --vid VID --pid PID -o OUT.dfu appends the DFU\n"
          "suffix to a raw binary (VID, PID and --bcd-device in hex, FFFF = any; bcdDevice\n"
          "defaults to FFFF). --check IMAGE.dfu validates an image and prints its suffix.\n"
          "\n"
          "Permissions. On Linux an ordinary user may not open USB devices: install the udev\n"
          "rule given in docs/flashing.md, or run as root.\n"
          "\n"
          "Exit status: 0 done; 1 usage error; 2 image rejected (nothing was sent);\n"
          "3 device not found, several found (use --serial), or no permission;\n"
          "4 the download failed (device error, timeout, device vanished).\n"
          "\n"
          "Examples:\n"
          "  build/flash --add-suffix firmware.bin --vid 1209 --pid 0001 -o firmware.dfu\n"
          "  build/flash firmware.dfu --loopback -v\n"
          "  build/flash firmware.dfu --device 1209:0001\n"
          "  build/flash firmware.dfu --device 1209:0001 --serial 0042 --transfer-size 1024\n"
          "\n"
          "More: docs/flashing.md (image format, what the bootloader guarantees).\n",
          f);
}

static int parse_hex16(const char *s, uint16_t *out)
{
    char *end;
    if (!s || !*s) return -1;
    errno = 0;
    unsigned long v = strtoul(s, &end, 16);
    if (errno || *end || v > 0xFFFFu || s[0] == '-' || s[0] == '+') return -1;
    *out = (uint16_t)v;
    return 0;
}

static int parse_vidpid(const char *s, uint16_t *vid, uint16_t *pid)
{
    char buf[32];
    const char *colon = s ? strchr(s, ':') : NULL;
    if (!colon || (size_t)(colon - s) >= sizeof buf) return -1;
    memcpy(buf, s, (size_t)(colon - s));
    buf[colon - s] = 0;
    return parse_hex16(buf, vid) || parse_hex16(colon + 1, pid) ? -1 : 0;
}

static int parse_uint(const char *s, unsigned long max, unsigned long *out)
{
    char *end;
    errno = 0;
    if (!s || !*s || s[0] == '-') return -1;
    unsigned long v = strtoul(s, &end, 10);
    if (errno || *end || v > max) return -1;
    *out = v;
    return 0;
}

/* Read a whole file; on failure print "flash: PATH: why" and return -1. */
static int read_file(const char *path, uint8_t **data, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "flash: %s: cannot open: %s\n", path, strerror(errno));
        return -1;
    }
    size_t cap = 1 << 16, n = 0;
    uint8_t *buf = malloc(cap);
    for (;;) {
        if (!buf) {
            fprintf(stderr, "flash: %s: out of memory\n", path);
            fclose(f);
            return -1;
        }
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap) break;
        if (cap >= MAX_FILE) {
            fprintf(stderr, "flash: %s: larger than %u MiB, not a firmware image\n", path, MAX_FILE >> 20);
            free(buf);
            fclose(f);
            return -1;
        }
        cap *= 2;
        uint8_t *nb = realloc(buf, cap);
        if (!nb) free(buf);
        buf = nb;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        fprintf(stderr, "flash: %s: read error\n", path);
        free(buf);
        return -1;
    }
    *data = buf;
    *len = n;
    return 0;
}

static void print_suffix(FILE *f, const char *path, size_t len, const dfu_image_t *img)
{
    fprintf(f,
            "%s: DFU image, %zu bytes of firmware + %u-byte suffix: idVendor %04x, idProduct %04x, "
            "bcdDevice %04x, bcdDFU %04x, dwCRC 0x%08x (ok), firmware CRC-32 0x%08x\n",
            path, img->payload_len, img->suffix_len, img->id_vendor, img->id_product, img->bcd_device, img->bcd_dfu,
            (unsigned)img->crc_stored, (unsigned)crc_update(0, img->payload, img->payload_len));
    (void)len;
}

/* Validate IMAGE (and its VID:PID when known); print "flash: IMAGE: problem". */
static int check_image(const char *path, const uint8_t *data, size_t len, int have_dev, uint16_t vid, uint16_t pid,
                       dfu_image_t *img)
{
    dfu_image_err e = dfu_image_parse(data, len, img);
    if (e == DFU_IMAGE_OK && have_dev) e = dfu_image_match(img, vid, pid);
    if (e == DFU_IMAGE_OK) return 0;
    fprintf(stderr, "flash: %s: %s", path, dfu_image_strerror(e));
    if (e == DFU_IMAGE_BAD_CRC)
        fprintf(stderr, " (suffix dwCRC 0x%08x, computed 0x%08x)", (unsigned)img->crc_stored,
                (unsigned)img->crc_computed);
    else if (e == DFU_IMAGE_WRONG_VENDOR || e == DFU_IMAGE_WRONG_PRODUCT)
        fprintf(stderr, ": the image is for %04x:%04x, the device is %04x:%04x", img->id_vendor, img->id_product, vid,
                pid);
    else if (e == DFU_IMAGE_TOO_SHORT)
        fprintf(stderr, " (%zu bytes)", len);
    else if (e == DFU_IMAGE_BAD_LENGTH) /* the field as found, so the message names the value */
        fprintf(stderr, " (bLength %u, file %zu bytes)", img->suffix_len, len);
    else if (e == DFU_IMAGE_BAD_VERSION)
        fprintf(stderr, " (bcdDFU %04x)", img->bcd_dfu);
    fprintf(stderr, "; nothing was sent to the device\n");
    return -1;
}

static int add_suffix(const char *in, const char *out, int have_vid, uint16_t vid, int have_pid, uint16_t pid,
                      uint16_t bcd)
{
    if (!in || !out || !have_vid || !have_pid) {
        fprintf(stderr, "flash: --add-suffix needs IN.bin, --vid, --pid and -o OUT.dfu (see --help)\n");
        return EXIT_USAGE;
    }
    uint8_t *data;
    size_t len;
    if (read_file(in, &data, &len) != 0) return EXIT_IMAGE;
    dfu_image_t img;
    if (len == 0) {
        fprintf(stderr, "flash: %s: empty file, nothing to make an image of\n", in);
        free(data);
        return EXIT_IMAGE;
    }
    if (dfu_image_parse(data, len, &img) == DFU_IMAGE_OK) {
        fprintf(stderr, "flash: %s: already ends with a valid DFU suffix; not adding a second one\n", in);
        free(data);
        return EXIT_IMAGE;
    }
    uint8_t suffix[DFU_SUFFIX_LEN];
    dfu_suffix_build(suffix, data, len, vid, pid, bcd);
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", out);
    FILE *f = fopen(tmp, "wb");
    int ok = f && fwrite(data, 1, len, f) == len && fwrite(suffix, 1, sizeof suffix, f) == sizeof suffix;
    if (f && fclose(f) != 0) ok = 0;
    if (!ok || rename(tmp, out) != 0) {
        fprintf(stderr, "flash: %s: cannot write: %s\n", out, strerror(errno));
        remove(tmp);
        free(data);
        return EXIT_IMAGE;
    }
    free(data);
    if (read_file(out, &data, &len) != 0) return EXIT_IMAGE;
    if (check_image(out, data, len, 0, 0, 0, &img) != 0) {
        free(data);
        return EXIT_IMAGE;
    }
    print_suffix(stdout, out, len, &img);
    free(data);
    return 0;
}

static void log_line(void *user, const char *line)
{
    (void)user;
    fprintf(stderr, "flash: %s\n", line);
}

static void progress(void *user, size_t done, size_t total)
{
    int *last = user;
    int pct = (int)(done * 100 / total);
    if (pct / 10 != *last / 10 || done == total) {
        fprintf(stderr, "flash: %3d%% (%zu of %zu bytes)\n", pct, done, total);
        *last = pct;
    }
}

static int report_download(const char *path, dfu_host_err err, const dfu_host_report *r)
{
    if (err == DFU_HOST_OK) {
        printf("%s: %s\n", path, r->msg);
        return 0;
    }
    fprintf(stderr, "flash: %s: %s\n", path, r->msg);
    if (err == DFU_HOST_BAD_IMAGE) return EXIT_IMAGE;
    if (err == DFU_HOST_BAD_ARGS) return EXIT_USAGE;
    return EXIT_DOWNLOAD;
}

static const char *req_names[] = {"DETACH", "DNLOAD", "UPLOAD", "GETSTATUS", "CLRSTATUS", "GETSTATE", "ABORT"};

static int run_loopback(const char *path, const uint8_t *data, size_t len, const dfu_image_t *img, int have_dev,
                        uint16_t vid, uint16_t pid, const dfu_host_opts *o, long unplug_after)
{
    if (have_dev && (vid != LOOP_VID || pid != LOOP_PID)) {
        fprintf(stderr, "flash: no device found for %04x:%04x: the loopback device is %04x:%04x\n", vid, pid, LOOP_VID,
                LOOP_PID);
        return EXIT_DEVICE;
    }
    vid = LOOP_VID;
    pid = LOOP_PID;
    static dfu_loopback lb;
    if (dfu_loop_init(&lb, NULL, LOOP_FLASH_SIZE, LOOP_PAGE_SIZE, 0) != 0) {
        fprintf(stderr, "flash: cannot set up the loopback device\n");
        return EXIT_DEVICE;
    }
    lb.vanish_after = unplug_after;
    printf("loopback: simulated DFU device %04x:%04x, %u KiB flash (%u KiB for the application), "
           "wTransferSize %u, state %s (%s)\n",
           vid, pid, LOOP_FLASH_SIZE >> 10, dfu_app_capacity(&lb.flash) >> 10, lb.cfg.transfer_size,
           dfu_state_name(lb.dev.state), dfu_status_name(lb.dev.status));
    dfu_transport t = dfu_loop_transport(&lb);
    dfu_host_report r;
    uint32_t t0 = lb.now_ms;
    dfu_host_err err = dfu_host_flash(&t, data, len, vid, pid, o, &r);
    int rc = report_download(path, err, &r);
    if (lb.vanished) {
        printf("loopback: the device was unplugged after %lu requests; plugging it in again\n", lb.requests);
        dfu_loop_power_cycle(&lb, 0);
    }
    dfu_app_info_t info;
    int valid = dfu_app_check(&lb.flash, &info);
    int holds_image = valid && info.length == img->payload_len &&
                      info.crc == crc_update(0, img->payload, img->payload_len);
    if (err == DFU_HOST_NO_DEVICE && holds_image) {
        /* The host lost the device after it had marked the image valid: what the
         * device holds is the verdict, not the interrupted conversation. */
        printf("%s: the download completed on the device before it was unplugged: it holds the "
               "image, marked valid, and runs it\n",
               path);
        rc = 0;
    }
    printf("loopback: %lu requests (", lb.requests);
    for (int i = 0; i < 7; i++) printf("%s%s %lu", i ? ", " : "", req_names[i], lb.by_request[i]);
    printf("), %lu stalls, %lu resets; simulated time %u ms, of which %lu ms waiting bwPollTimeout\n", lb.stalls,
           lb.resets, lb.now_ms - t0, lb.slept_ms);
    if (valid)
        printf("loopback: device state %s; application valid: %u bytes, CRC-32 0x%08x (the image's "
               "firmware: 0x%08x)\n",
               dfu_state_name(lb.dev.state), info.length, info.crc,
               (unsigned)crc_update(0, img->payload, img->payload_len));
    else
        printf("loopback: device state %s (%s); no valid application: the device stays in its "
               "bootloader\n",
               dfu_state_name(lb.dev.state), dfu_status_name(lb.dev.status));
    dfu_loop_free(&lb);
    return rc;
}

/* The command line, as parsed. */
typedef struct {
    const char *serial, *add_in, *out, *check;
    uint16_t vid, pid;        /* --device (or the loopback's own ids) */
    uint16_t svid, spid, bcd; /* --vid, --pid, --bcd-device for --add-suffix */
    int have_dev, have_vid, have_pid, loopback, list, verbose;
    long unplug_after;
    unsigned long ts, timeout, reenum;
} flash_args;

enum {
    O_DEVICE = 256,
    O_SERIAL,
    O_TS,
    O_TIMEOUT,
    O_REENUM,
    O_LOOP,
    O_UNPLUG,
    O_ADD,
    O_VID,
    O_PID,
    O_BCD,
    O_CHECK,
    O_LIST
};

/* One option c with its argument arg: -1 to go on, else the exit code (0 after --help). */
static int parse_option(int c, const char *arg, const char *given, flash_args *a)
{
    unsigned long ul;
    switch (c) {
    case 'h': usage(stdout); return 0;
    case 'v': a->verbose++; break;
    case 'o': a->out = arg; break;
    case O_DEVICE:
        if (parse_vidpid(arg, &a->vid, &a->pid) != 0) {
            fprintf(stderr, "flash: --device wants VID:PID in hex, like 1209:0001 (got \"%s\")\n", arg);
            return EXIT_USAGE;
        }
        a->have_dev = 1;
        break;
    case O_SERIAL: a->serial = arg; break;
    case O_TS:
        if (parse_uint(arg, 65535, &a->ts) != 0 || a->ts == 0) {
            fprintf(stderr, "flash: --transfer-size wants a number of bytes, 1..65535 (got \"%s\")\n", arg);
            return EXIT_USAGE;
        }
        break;
    case O_TIMEOUT:
    case O_REENUM:
        if (parse_uint(arg, 3600000, &ul) != 0 || ul == 0) {
            fprintf(stderr, "flash: %s wants milliseconds, 1..3600000 (got \"%s\")\n",
                    c == O_TIMEOUT ? "--timeout" : "--reenum-timeout", arg);
            return EXIT_USAGE;
        }
        *(c == O_TIMEOUT ? &a->timeout : &a->reenum) = ul;
        break;
    case O_LOOP: a->loopback = 1; break;
    case O_UNPLUG:
        if (parse_uint(arg, 100000000, &ul) != 0) {
            fprintf(stderr, "flash: --loopback-unplug-after wants a number of requests\n");
            return EXIT_USAGE;
        }
        a->unplug_after = (long)ul;
        break;
    case O_ADD: a->add_in = arg; break;
    case O_VID:
    case O_PID:
    case O_BCD: {
        uint16_t v;
        if (parse_hex16(arg, &v) != 0) {
            fprintf(stderr, "flash: %s wants a 16-bit hex number like 1209 (got \"%s\")\n",
                    c == O_VID   ? "--vid"
                    : c == O_PID ? "--pid"
                                 : "--bcd-device",
                    arg);
            return EXIT_USAGE;
        }
        if (c == O_VID) {
            a->svid = v;
            a->have_vid = 1;
        } else if (c == O_PID) {
            a->spid = v;
            a->have_pid = 1;
        } else
            a->bcd = v;
        break;
    }
    case O_CHECK: a->check = arg; break;
    case O_LIST: a->list = 1; break;
    default:
        fprintf(stderr, "flash: unknown or incomplete option \"%s\" (see build/flash --help)\n", given);
        return EXIT_USAGE;
    }
    return -1;
}

/* The options (argv[optind..] are left for the image): -1 to go on, else the exit code. */
static int parse_args(int argc, char **argv, flash_args *a)
{
    static const struct option opts[] = {
        {"help", no_argument, 0, 'h'},
        {"verbose", no_argument, 0, 'v'},
        {"device", required_argument, 0, O_DEVICE},
        {"serial", required_argument, 0, O_SERIAL},
        {"transfer-size", required_argument, 0, O_TS},
        {"timeout", required_argument, 0, O_TIMEOUT},
        {"reenum-timeout", required_argument, 0, O_REENUM},
        {"loopback", no_argument, 0, O_LOOP},
        {"loopback-unplug-after", required_argument, 0, O_UNPLUG},
        {"add-suffix", required_argument, 0, O_ADD},
        {"vid", required_argument, 0, O_VID},
        {"pid", required_argument, 0, O_PID},
        {"bcd-device", required_argument, 0, O_BCD},
        {"output", required_argument, 0, 'o'},
        {"check", required_argument, 0, O_CHECK},
        {"list", no_argument, 0, O_LIST},
        {0, 0, 0, 0},
    };
    memset(a, 0, sizeof *a);
    a->bcd = 0xFFFF;
    a->unplug_after = -1;
    int c;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "hvo:", opts, NULL)) != -1) {
        int rc = parse_option(c, optarg, argv[optind - 1], a);
        if (rc >= 0) return rc;
    }
    return -1;
}

/* The image to download or --check, and that a device was named: NULL after a message. */
static const char *image_path(const flash_args *a, int argc, char **argv)
{
    const char *path = a->check;
    if (!path) {
        if (optind != argc - 1) {
            fprintf(stderr, optind >= argc ? "flash: no image given (see build/flash --help)\n"
                                           : "flash: give exactly one image (see build/flash --help)\n");
            return NULL;
        }
        path = argv[optind];
    }
    if (!a->check && !a->loopback && !a->have_dev) {
        fprintf(stderr, "flash: which device? give --device VID:PID (build/flash --list shows "
                        "DFU devices), or --loopback to try without hardware\n");
        return NULL;
    }
    return path;
}

static void print_functional(uint16_t vid, uint16_t pid, const dfu_func_desc *d)
{
    fprintf(stderr,
            "flash: opened %04x:%04x: bmAttributes 0x%02x (%s%s%s%s), wTransferSize %u, "
            "wDetachTimeOut %u ms, bcdDFU %04x\n",
            vid, pid, d->attributes, d->attributes & DFU_ATTR_CAN_DNLOAD ? "download" : "no download",
            d->attributes & DFU_ATTR_CAN_UPLOAD ? ", upload" : "",
            d->attributes & DFU_ATTR_MANIFEST_TOLERANT ? ", manifestation-tolerant" : "",
            d->attributes & DFU_ATTR_WILL_DETACH ? ", will detach" : "", d->transfer_size, d->detach_timeout_ms,
            d->bcd_dfu);
}

/* The download to a real device through libusb: the exit code. */
static int run_usb(const char *path, const uint8_t *data, size_t len, const flash_args *a, const dfu_host_opts *o)
{
    char msg[4096];
    dfu_usb *u;
    dfu_usb_err ue = dfu_usb_open(&u, a->vid, a->pid, a->serial, a->verbose, msg, sizeof msg);
    if (ue != DFU_USB_OK) {
        fprintf(stderr, "flash: %s\n", msg);
        return EXIT_DEVICE;
    }
    dfu_transport t = dfu_usb_transport(u);
    dfu_func_desc d;
    t.functional(t.ctx, &d);
    if (a->verbose) print_functional(a->vid, a->pid, &d);
    dfu_host_report r;
    dfu_host_err err = dfu_host_flash(&t, data, len, a->vid, a->pid, o, &r);
    int rc = report_download(path, err, &r);
    /* what the user can do about the two failures a device causes */
    if (err == DFU_HOST_NO_DEVICE)
        fprintf(stderr, "flash: the device disconnected; reconnect it (it stays in its "
                        "bootloader) and run the same command again\n");
    else if (err == DFU_HOST_TIMEOUT)
        fprintf(stderr, "flash: the device stopped answering; a longer --timeout may help a slow "
                        "device, otherwise reconnect it and run again\n");
    dfu_usb_close(u);
    return rc;
}

int main(int argc, char **argv)
{
    flash_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    if (a.add_in) {
        if (optind < argc) {
            fprintf(stderr, "flash: unexpected argument \"%s\" with --add-suffix\n", argv[optind]);
            return EXIT_USAGE;
        }
        return add_suffix(a.add_in, a.out, a.have_vid, a.svid, a.have_pid, a.spid, a.bcd);
    }
    if (a.list) return dfu_usb_list(stdout) ? 0 : EXIT_DEVICE;
    const char *path = image_path(&a, argc, argv);
    if (!path) return EXIT_USAGE;

    uint8_t *data;
    size_t len;
    if (read_file(path, &data, &len) != 0) return EXIT_IMAGE;
    dfu_image_t img;
    int match = a.have_dev;
    if (a.loopback && !a.have_dev) {
        a.vid = LOOP_VID; /* the simulated device's ids, checked as a real device's */
        a.pid = LOOP_PID;
        match = 1;
    }
    if (check_image(path, data, len, match, a.vid, a.pid, &img) != 0) {
        free(data);
        return EXIT_IMAGE;
    }
    if (a.check) {
        print_suffix(stdout, path, len, &img);
        free(data);
        return 0;
    }

    int last_pct = -100;
    dfu_host_opts o;
    memset(&o, 0, sizeof o);
    o.transfer_size = (uint16_t)a.ts;
    o.timeout_ms = (unsigned)a.timeout;
    o.reenum_timeout_ms = (unsigned)a.reenum;
    o.verbose = a.verbose;
    o.log = log_line;
    o.progress = a.verbose ? progress : NULL;
    o.user = &last_pct;
    if (a.verbose) print_suffix(stderr, path, len, &img);

    if (a.loopback)
        rc = run_loopback(path, data, len, &img, a.have_dev, a.vid, a.pid, &o, a.unplug_after);
    else
        rc = run_usb(path, data, len, &a, &o);
    free(data);
    return rc;
}
