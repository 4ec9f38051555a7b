/* fuzz_text.c - the scene text parser (docs/scene-format.md) fed arbitrary text,
 * through the whole compile: what the compiler refuses, it refuses with a message
 * naming the file; what it accepts, the firmware's loader must accept and draw
 * from the player start without dropping a polygon. */
#include "fuzz_common.h"

/* Larger texts only make each run slower, not the parser's paths more varied. */
#define TEXT_MAX 16384

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t *blob;
    size_t len;
    if (size <= TEXT_MAX && fuzz_compile_input(data, size, ".scene", NULL, &blob, &len) == 0) {
        fuzz_draw(blob, len, NULL, 1);
        free(blob);
    }
    return 0;
}
