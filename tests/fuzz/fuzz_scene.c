/* fuzz_scene.c - the compiled-scene loader (firmware/scene.c, the firmware's own
 * code) fed arbitrary blobs; whatever it accepts is drawn in every mode from the
 * player start and from a camera taken from the input, under ASan and UBSan: a
 * blob the loader passes must never make the renderer fault or read out of bounds.
 *
 * Input: one flags byte, FUZZ_VIEW_BYTES of camera, then the blob. Flag bit 0
 * rewrites the blob's CRC-32 (and bit 1 its total length) to match, so that the
 * fuzzer's changes reach the checks behind the CRC instead of stopping there. */
#include <stddef.h>
#include <string.h>

#include "crc32.h"
#include "fuzz_common.h"
#include "scene_format.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 + FUZZ_VIEW_BYTES || size - 1 - FUZZ_VIEW_BYTES > (4u << 20)) return 0;
    uint8_t flags = data[0];
    fuzz_view view = fuzz_view_from(data + 1);
    size_t len = size - 1 - FUZZ_VIEW_BYTES;
    uint8_t *blob = fuzz_copy_exact(data + 1 + FUZZ_VIEW_BYTES, len);
    if (len >= sizeof(scn_header)) {
        if (flags & 2) wr32(blob + offsetof(scn_header, total_bytes), (uint32_t)len);
        /* over the length the header declares, as the loader reads it, when that lies in the blob */
        uint32_t total = rd32(blob + offsetof(scn_header, total_bytes));
        if (total < 16 || total > len) total = (uint32_t)len;
        if (flags & 1) wr32(blob + offsetof(scn_header, crc32), crc_update(0, blob + 16, total - 16));
    }
    fuzz_draw(blob, len, NULL, 0);
    fuzz_draw(blob, len, &view, 0);
    free(blob);
    return 0;
}
