/* scene_fixture.h - the unit tests' scenes written inline: a text scene put in a
 * temporary file and compiled with bspc_compile (prefix fixture_). */
#ifndef SCENE_FIXTURE_H
#define SCENE_FIXTURE_H

#include <stddef.h>
#include <stdint.h>

#include "bspc.h"
#include "scene.h"

/* text in a new temporary file; returns its path (malloc'd, the caller unlinks
 * and frees it). */
char *fixture_write_temp(const char *text);

/* Compile text as a scene file would be (opt NULL: the defaults); bspc_compile's
 * result, the message in err (printed too on failure). st may be NULL. */
int fixture_compile_text(const char *text, const bspc_options *opt, uint8_t **blob, size_t *len, bspc_stats *st,
                         char *err, size_t errlen);

/* Compile and load text; both must succeed. *blob is the caller's to free;
 * returns its length. */
uint32_t fixture_load_text(const char *text, uint8_t **blob, scene *s);

#endif
