/* scene_file.h - getting a compiled scene into memory for a host program. */
#ifndef HOST_SCENE_FILE_H
#define HOST_SCENE_FILE_H

#include <stddef.h>
#include <stdint.h>
#include "bspc.h"

/* spec is a compiled scene file (recognised by its magic) or a source the
 * compiler takes (text scene, file.wad:MAP01), compiled on the fly with opt.
 * On success returns 0 and a malloc'd, 4-aligned *blob; on failure -1 and a
 * message naming the file and the problem in err. */
int scene_file_load(const char *spec, const bspc_options *opt, uint8_t **blob, size_t *len, char *err, size_t errlen);

/* The loader's verdict on blob[0..len) as one line naming the file, the item
 * (a header field, a section, a record and its index) and the problem
 * ("FILE: compiled scene rejected: segs record 3: index out of range"). */
void scene_file_describe_error(const char *spec, const uint8_t *blob, size_t len, const scene_error *se, char *err,
                               size_t errlen);

#endif
