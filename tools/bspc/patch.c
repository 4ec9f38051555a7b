/* patch.c - Doom's patch format: header and posts (patch.h). */
#include "patch.h"

#include "bspc_int.h"
#include "wad_bytes.h"

int bs_patch_info_read(const uint8_t *p, uint32_t size, const char *wad, const char *what, bs_patch_info *info,
                       char *err, size_t errlen)
{
    if (size < 8)
        return bs_fail(err, errlen, "%s: patch %s: %u bytes, shorter than its 8-byte header", wad, what, size);
    int32_t pw = rds16(p), ph = rds16(p + 2);
    if (pw <= 0 || ph <= 0 || (uint64_t)8 + 4u * (uint64_t)pw > size)
        return bs_fail(err, errlen, "%s: patch %s: size %d x %d does not fit its %u bytes", wad, what, pw, ph, size);
    info->width = pw;
    info->height = ph;
    info->left = rds16(p + 4);
    info->top = rds16(p + 6);
    return 0;
}

int bs_patch_walk(const uint8_t *p, uint32_t size, const char *wad, const char *what, int32_t c0, int32_t c1,
                  bs_patch_post_fn post, void *ctx, char *err, size_t errlen)
{
    bs_patch_info info;
    if (bs_patch_info_read(p, size, wad, what, &info, err, errlen)) return -1;
    if (c0 < 0) c0 = 0;
    if (c1 > info.width) c1 = info.width;
    for (int32_t c = c0; c < c1; c++) {
        uint32_t at = rd32(p + 8 + 4 * c);
        for (;;) { /* at grows by at least 4 a post */
            if (at >= size)
                return bs_fail(err, errlen, "%s: patch %s: column %d runs past the end of the lump", wad, what, c);
            uint32_t top = p[at];
            if (top == 0xFF) break;
            if ((uint64_t)at + 3 > size)
                return bs_fail(err, errlen, "%s: patch %s: column %d: post header past the end", wad, what, c);
            uint32_t len = p[at + 1];
            if ((uint64_t)at + 3 + len > size)
                return bs_fail(err, errlen,
                               "%s: patch %s: column %d: post of %u bytes at %u runs past the end (%u bytes)", wad,
                               what, c, len, at, size);
            post(ctx, c, top, p + at + 3, len);
            at += len + 4;
        }
    }
    return 0;
}
