/* scene_file.c - read a compiled scene, or compile a source one on the fly. */
#include "scene_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "scene.h"

#define SCENE_FILE_MAX (256u << 20) /* larger than any scene the format can index sensibly */

static int read_whole(const char *path, uint8_t **data, size_t *len, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    size_t cap = 1 << 16, n = 0;
    uint8_t *buf = malloc(cap);
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (n < cap) break;
        if (cap >= SCENE_FILE_MAX) {
            free(buf);
            buf = NULL;
            snprintf(err, errlen, "%s: file larger than %u bytes", path, SCENE_FILE_MAX);
            fclose(f);
            return -1;
        }
        uint8_t *nb = realloc(buf, cap * 2);
        if (!nb) free(buf);
        buf = nb;
        cap *= 2;
    }
    int bad = ferror(f);
    fclose(f);
    if (!buf || bad) {
        free(buf);
        snprintf(err, errlen, "%s: read failed", path);
        return -1;
    }
    *data = buf;
    *len = n;
    return 0;
}

int scene_file_load(const char *spec, const bspc_options *opt, uint8_t **blob, size_t *len, char *err, size_t errlen)
{
    /* "file.wad:MAP01" names a map inside a WAD: always a source. */
    const char *colon = strrchr(spec, ':');
    int is_wad_map = colon && colon > spec && colon - spec >= 4 && strncasecmp(colon - 4, ".wad", 4) == 0;
    if (!is_wad_map) {
        uint8_t *data;
        size_t n;
        if (read_whole(spec, &data, &n, err, errlen) != 0) return -1;
        uint32_t magic = n >= 4 ? (uint32_t)data[0] | (uint32_t)data[1] << 8 | (uint32_t)data[2] << 16 | (uint32_t)data[3] << 24 : 0;
        if (magic == SCN_MAGIC) {
            *blob = data;
            *len = n;
            return 0;
        }
        free(data);
    }
    return bspc_compile(spec, opt, blob, len, NULL, err, errlen);
}

void scene_file_describe_error(const char *spec, const scene_error *se, char *err, size_t errlen)
{
    const char *st = scene_status_text(se->status);
    if (se->status == SCENE_ERR_BUILD && se->index < SCENE_ITEM_EDGES)
        snprintf(err, errlen, "%s: the scene needs %s, which this build leaves out (it was built for another "
                 "scene; see docs/needs.md)", spec, scene_item_name(se->index));
    else if (se->status == SCENE_ERR_BUILD)
        snprintf(err, errlen, "%s: the scene needs %s %u; this build provides %u (it was built for another "
                 "scene; see docs/needs.md)", spec, scene_item_name(se->index), se->need, se->have);
    else if (se->section >= 0)
        snprintf(err, errlen, "%s: compiled scene rejected: %s in %s record %u", spec, st,
                 scene_section_name(se->section), se->index);
    else
        snprintf(err, errlen, "%s: compiled scene rejected: %s", spec, st);
}
