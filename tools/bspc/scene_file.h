/* scene_file.h - a scene from any source into memory (prefix scene_file_): a
 * compiled scene file as it is, a text scene or a WAD map compiled on the fly.
 * Part of the compiler's library, so that build/bspc and the host programs
 * (build/render, build/emu, build/fltool) read scenes the same way. */
#ifndef SCENE_FILE_H
#define SCENE_FILE_H

#include <stddef.h>
#include <stdint.h>
#include "bspc.h"
#include "scene.h"

/* spec is a compiled scene file (recognised by its magic) or a source the
 * compiler takes (text scene, file.wad:MAP01), compiled on the fly with opt.
 * On success returns 0 and a malloc'd, 4-aligned *blob; on failure -1 and a
 * message naming the file and the problem in err. */
int scene_file_load(const char *spec, const bspc_options *opt, uint8_t **blob, size_t *len, char *err, size_t errlen);

/* 1 when data[0..n) starts with a compiled scene's magic: the one test of it. */
int scene_file_is_compiled(const uint8_t *data, size_t n);

/* 1 when the file at path starts with a compiled scene's magic (0 when it
 * does not, or cannot be read). */
int scene_file_probe(const char *path);

/* The loader's verdict on blob[0..len) as one line naming the file, the item
 * (a header field, a section, a record and its index) and the problem
 * ("FILE: compiled scene rejected: segs record 3: index out of range"). */
void scene_file_describe_error(const char *spec, const uint8_t *blob, size_t len, const scene_error *se, char *err,
                               size_t errlen);

#endif
