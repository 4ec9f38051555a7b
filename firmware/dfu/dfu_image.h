/* dfu_image.h - the DFU file format (prefix dfu_image_/dfu_suffix_): a firmware
 * binary followed by the DFU 1.1 suffix (specification appendix B):
 *
 *   offset from the suffix start   field          size  value
 *    0                             bcdDevice       2    firmware release, or 0xFFFF (any)
 *    2                             idProduct       2    product id, or 0xFFFF (any)
 *    4                             idVendor        2    vendor id, or 0xFFFF (any)
 *    6                             bcdDFU          2    0x0100
 *    8                             ucDfuSignature  3    'U' 'F' 'D' (the bytes 0x55 0x46 0x44)
 *   11                             bLength         1    16 (the suffix length, dwCRC included;
 *                                                       any other value is refused)
 *   12                             dwCRC           4    CRC of the whole file but dwCRC
 *
 * All fields little-endian. dwCRC is the CRC-32 of the IEEE polynomial, reflected,
 * register preset to 0xFFFFFFFF and, as the specification's reference code does it,
 * NOT complemented at the end: it is the bitwise complement of zlib's crc32() of the
 * same bytes. The suffix is checked on the host and never sent to the device.
 *
 * dfu_image_parse() is pure (no allocation, no I/O, reads only data[0..len)) so that
 * it can be fuzzed on its own. Freestanding, no libc. */
#ifndef DFU_IMAGE_H
#define DFU_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#define DFU_SUFFIX_LEN 16u
#define DFU_SUFFIX_BCD_DFU 0x0100u
#define DFU_ID_ANY 0xFFFFu

typedef enum dfu_image_err {
    DFU_IMAGE_OK = 0,
    DFU_IMAGE_TOO_SHORT,     /* shorter than a suffix */
    DFU_IMAGE_NO_SIGNATURE,  /* no "UFD": no suffix, or the file is truncated */
    DFU_IMAGE_BAD_LENGTH,    /* bLength is not 16 (the DFU 1.1 suffix) */
    DFU_IMAGE_BAD_CRC,       /* dwCRC does not match the file: corrupted */
    DFU_IMAGE_BAD_VERSION,   /* bcdDFU is not 0x0100 (e.g. 0x011A, a DfuSe file) */
    DFU_IMAGE_EMPTY,         /* no firmware bytes before the suffix */
    DFU_IMAGE_WRONG_VENDOR,  /* idVendor neither 0xFFFF nor the device's */
    DFU_IMAGE_WRONG_PRODUCT, /* idProduct neither 0xFFFF nor the device's */
} dfu_image_err;

typedef struct dfu_image {
    const uint8_t *payload; /* the firmware bytes (points into the parsed buffer) */
    size_t payload_len;
    uint16_t bcd_device, id_product, id_vendor, bcd_dfu;
    uint8_t suffix_len;    /* bLength */
    uint32_t crc_stored;   /* dwCRC as found in the file */
    uint32_t crc_computed; /* dwCRC as computed over the file */
} dfu_image_t;

/* Validate a whole DFU file: length, signature, bLength, CRC, bcdDFU, a non-empty
 * payload, in that order; the first failure is returned. On return *out holds
 * whatever could be read (all zero when too short), on success everything. */
dfu_image_err dfu_image_parse(const uint8_t *data, size_t len, dfu_image_t *out);

/* Does a parsed image target the device vid:pid? 0xFFFF in the suffix matches any. */
dfu_image_err dfu_image_match(const dfu_image_t *img, uint16_t vid, uint16_t pid);

/* A short message for an error ("CRC mismatch: the file is corrupted", ...). */
const char *dfu_image_strerror(dfu_image_err e);

/* The dwCRC value of the first n bytes of a file (everything but dwCRC itself). */
uint32_t dfu_suffix_crc(const uint8_t *data, size_t n);

/* Make the 16-byte suffix for payload[0..n): out must hold 16 bytes and is the
 * suffix to append; the CRC covers payload and the first 12 suffix bytes. */
void dfu_suffix_build(uint8_t out[DFU_SUFFIX_LEN], const uint8_t *payload, size_t n, uint16_t vid, uint16_t pid,
                      uint16_t bcd_device);

#endif
