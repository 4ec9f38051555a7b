/* fuzz_wad.c - the WAD map reader fed arbitrary WAD files, through the whole
 * compile of the map MAP01 (seeds: single-map WADs, see tools/fuzz.py): a refusal
 * names the file; a map the compiler accepts, the firmware's loader must accept
 * and draw from the player start without dropping a polygon. */
#include <string.h>

#include "fuzz_common.h"

/* A small map's five lumps; larger inputs only slow the run down. */
#define WAD_MAX (192 * 1024)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > WAD_MAX) return 0;
    const char *path = fuzz_temp_file(data, size, ".wad");
    if (!path) return 0;
    char spec[300];
    snprintf(spec, sizeof spec, "%s:MAP01", path);
    uint8_t *blob;
    size_t len;
    if (fuzz_compile(spec, path, &blob, &len) == 0) {
        fuzz_draw(blob, len, NULL, 1);
        free(blob);
    }
    return 0;
}
