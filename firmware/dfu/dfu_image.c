/* dfu_image.c - parse, check and build the DFU 1.1 file suffix (see dfu_image.h).
 * Pure functions over caller buffers; freestanding, no libc. */
#include "dfu_image.h"

#include "crc32.h"

static uint16_t rd16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void wr16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

uint32_t dfu_suffix_crc(const uint8_t *data, size_t n)
{
    /* crc_update() is zlib's crc32(): preset ~0 and a final complement. The suffix
     * CRC has the preset but no final complement, hence the ~. */
    return ~crc_update(0, data, n);
}

dfu_image_err dfu_image_parse(const uint8_t *data, size_t len, dfu_image_t *out)
{
    dfu_image_t img;
    img.payload = data;
    img.payload_len = 0;
    img.bcd_device = img.id_product = img.id_vendor = img.bcd_dfu = 0;
    img.suffix_len = 0;
    img.crc_stored = img.crc_computed = 0;
    dfu_image_err err = DFU_IMAGE_OK;

    if (data == NULL || len < DFU_SUFFIX_LEN) {
        err = DFU_IMAGE_TOO_SHORT;
        goto done;
    }
    const uint8_t *s = data + len - DFU_SUFFIX_LEN;
    img.bcd_device = rd16(s + 0);
    img.id_product = rd16(s + 2);
    img.id_vendor = rd16(s + 4);
    img.bcd_dfu = rd16(s + 6);
    img.suffix_len = s[11];
    img.crc_stored = rd32(s + 12);
    if (s[8] != 'U' || s[9] != 'F' || s[10] != 'D') {
        err = DFU_IMAGE_NO_SIGNATURE;
        goto done;
    }
    /* DFU 1.1 defines exactly 16 suffix bytes; a longer bLength would silently
     * take the end of the firmware for suffix. */
    if (img.suffix_len != DFU_SUFFIX_LEN) {
        err = DFU_IMAGE_BAD_LENGTH;
        goto done;
    }
    img.crc_computed = dfu_suffix_crc(data, len - 4);
    if (img.crc_computed != img.crc_stored) {
        err = DFU_IMAGE_BAD_CRC;
        goto done;
    }
    if (img.bcd_dfu != DFU_SUFFIX_BCD_DFU) {
        err = DFU_IMAGE_BAD_VERSION;
        goto done;
    }
    img.payload_len = len - img.suffix_len;
    if (img.payload_len == 0) err = DFU_IMAGE_EMPTY;
done:
    if (out) *out = img;
    return err;
}

dfu_image_err dfu_image_match(const dfu_image_t *img, uint16_t vid, uint16_t pid)
{
    if (img->id_vendor != DFU_ID_ANY && img->id_vendor != vid) return DFU_IMAGE_WRONG_VENDOR;
    if (img->id_product != DFU_ID_ANY && img->id_product != pid) return DFU_IMAGE_WRONG_PRODUCT;
    return DFU_IMAGE_OK;
}

const char *dfu_image_strerror(dfu_image_err e)
{
    switch (e) {
    case DFU_IMAGE_OK: return "valid DFU image";
    case DFU_IMAGE_TOO_SHORT: return "too short to hold a DFU suffix (truncated, or not a DFU image)";
    case DFU_IMAGE_NO_SIGNATURE:
        return "no DFU suffix signature \"UFD\" at the end (truncated, or a raw binary: add a suffix with "
               "--add-suffix)";
    case DFU_IMAGE_BAD_LENGTH: return "DFU suffix length field (bLength) is not 16, the length of a DFU 1.1 suffix";
    case DFU_IMAGE_BAD_CRC: return "CRC mismatch: the file is corrupted";
    case DFU_IMAGE_BAD_VERSION:
        return "DFU suffix bcdDFU is not 0x0100 (not a DFU 1.1 image; DfuSe files are not supported)";
    case DFU_IMAGE_EMPTY: return "no firmware before the DFU suffix";
    case DFU_IMAGE_WRONG_VENDOR: return "made for another vendor id (idVendor in the suffix)";
    case DFU_IMAGE_WRONG_PRODUCT: return "made for another product id (idProduct in the suffix)";
    }
    return "unknown image error";
}

void dfu_suffix_build(uint8_t out[DFU_SUFFIX_LEN], const uint8_t *payload, size_t n, uint16_t vid, uint16_t pid,
                      uint16_t bcd_device)
{
    wr16(out + 0, bcd_device);
    wr16(out + 2, pid);
    wr16(out + 4, vid);
    wr16(out + 6, DFU_SUFFIX_BCD_DFU);
    out[8] = 'U';
    out[9] = 'F';
    out[10] = 'D';
    out[11] = DFU_SUFFIX_LEN;
    uint32_t crc = ~dfu_suffix_crc(payload, n); /* back to zlib form to continue it */
    uint32_t v = ~crc_update(crc, out, 12);
    out[12] = (uint8_t)v;
    out[13] = (uint8_t)(v >> 8);
    out[14] = (uint8_t)(v >> 16);
    out[15] = (uint8_t)(v >> 24);
}
