/* fuzz_wad.c - the WAD map reader fed arbitrary WAD files, through the whole
 * compile of the map MAP01 (seeds: single-map WADs, see tools/fuzz.py): a refusal
 * names the file; a map the compiler accepts, the firmware's loader must accept
 * and draw from the player start without dropping a polygon. */
#include "fuzz_common.h"

/* A small map's five lumps; larger inputs only slow the run down. */
#define WAD_MAX (192 * 1024)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t *blob;
    size_t len;
    if (size <= WAD_MAX && fuzz_compile_input(data, size, ".wad", "MAP01", &blob, &len) == 0) {
        fuzz_draw(blob, len, NULL, 1);
        free(blob);
    }
    return 0;
}
