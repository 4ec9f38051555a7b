/* scene_file.c - read a compiled scene, or compile a source one on the fly. */
#include "scene_file.h"

#include <errno.h>
#include <sys/stat.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "crc32.h"

#define SCENE_FILE_MAX (256u << 20) /* larger than any scene the format can index sensibly */

static int read_whole(const char *path, uint8_t **data, size_t *len, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    /* a folder opens for reading, and only the first read fails */
    struct stat st;
    if (fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode)) {
        snprintf(err, errlen, "%s: is a directory, not a scene file", path);
        fclose(f);
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
    int bad = ferror(f) ? errno : 0;
    fclose(f);
    if (!buf || bad) {
        snprintf(err, errlen, "%s: %s", path, bad ? strerror(bad) : "out of memory");
        free(buf);
        return -1;
    }
    *data = buf;
    *len = n;
    return 0;
}

int scene_file_is_compiled(const uint8_t *data, size_t n)
{
    return n >= 4 && ((uint32_t)data[0] | (uint32_t)data[1] << 8 | (uint32_t)data[2] << 16 | (uint32_t)data[3] << 24) ==
                         SCN_MAGIC;
}

int scene_file_probe(const char *path)
{
    FILE *f = fopen(path, "rb");
    uint8_t m[4];
    if (!f) return 0;
    size_t n = fread(m, 1, sizeof m, f);
    fclose(f);
    return scene_file_is_compiled(m, n);
}

int scene_file_load(const char *spec, const bspc_options *opt, uint8_t **blob, size_t *len, char *err, size_t errlen)
{
    /* A WAD, with a map named or not, is a source: the compiler finds it on its
     * search path and explains what is missing. */
    if (bspc_spec(spec, NULL) == BSPC_SPEC_FILE) {
        uint8_t *data;
        size_t n;
        if (read_whole(spec, &data, &n, err, errlen) != 0) return -1;
        if (scene_file_is_compiled(data, n)) {
            /* The loader takes a blob in a larger buffer (a flash sector); a file is
             * exactly what bspc wrote, so bytes past total_bytes mean it is damaged.
             * A short file and a version this build does not read are the loader's
             * to report. */
            const scn_header *h = (const scn_header *)(const void *)data;
            if (n >= sizeof(scn_header) && h->version == SCN_VERSION && h->total_bytes < n) {
                snprintf(err, errlen,
                         "%s: compiled scene rejected: header: total_bytes = %u, but the file "
                         "has %zu bytes (bytes appended, or the header is damaged)",
                         spec, h->total_bytes, n);
                free(data);
                return -1;
            }
            *blob = data;
            *len = n;
            return 0;
        }
        free(data);
    }
    return bspc_compile(spec, opt, blob, len, NULL, err, errlen);
}

/* A refusal of the header itself (the loader's section -1): the field the loader
 * names (scene_error.index, SCENE_FIELD_*) with its value. */
static void describe_header(const scn_header *h, size_t len, const scene_error *se, char *out, size_t n)
{
    switch (se->index) {
    case SCENE_FIELD_MAGIC:
        snprintf(out, n, "header: magic 0x%08x, expected 0x%08x (\"BSCN\")", h->magic, SCN_MAGIC);
        break;
    case SCENE_FIELD_VERSION:
        snprintf(out, n, "header: unsupported version %u (this program reads version %u: recompile the scene)",
                 h->version, SCN_VERSION);
        break;
    case SCENE_FIELD_HEADER_BYTES:
        snprintf(out, n, "header: header_bytes = %u, expected %zu", h->header_bytes, sizeof(scn_header));
        break;
    case SCENE_FIELD_TOTAL_BYTES:
        if (se->status == SCENE_ERR_SHORT)
            snprintf(out, n, "truncated: header total_bytes = %u, but the file has %zu bytes", h->total_bytes, len);
        else if (h->total_bytes & 3u)
            snprintf(out, n, "header: total_bytes = %u is not a multiple of 4", h->total_bytes);
        else
            snprintf(out, n, "header: total_bytes = %u, less than the header's %zu", h->total_bytes,
                     sizeof(scn_header));
        break;
    case SCENE_FIELD_FLAGS: snprintf(out, n, "header: flags = 0x%x, expected 0 (reserved)", h->flags); break;
    case SCENE_FIELD_CRC:
        snprintf(out, n, "bad CRC-32: header crc32 = 0x%08x, but bytes [16, %u) give 0x%08x (the file is damaged)",
                 h->crc32, h->total_bytes, crc_update(0, (const uint8_t *)h + 16, h->total_bytes - 16));
        break;
    case SCENE_FIELD_PLAYER_SECTOR:
        snprintf(out, n, "header: player_sector = %u out of range (%u sectors)", h->player_sector,
                 h->sec[SCN_SEC_SECTORS].count);
        break;
    case SCENE_FIELD_PLAYER_START:
        snprintf(out, n, "header: player start out of range (|coordinate| <= %d)", SCN_COORD_MAX);
        break;
    case SCENE_FIELD_ROOT:
        if (se->status == SCENE_ERR_TREE)
            snprintf(out, n, "header: root is a leaf, but there are %u nodes (not a tree)",
                     h->sec[SCN_SEC_NODES].count);
        else if (h->root & SCN_LEAF_BIT)
            snprintf(out, n, "header: root = leaf %u out of range (%u leaves)", h->root & ~SCN_LEAF_BIT,
                     h->sec[SCN_SEC_LEAVES].count);
        else
            snprintf(out, n, "header: root = node %u out of range (%u nodes)", h->root, h->sec[SCN_SEC_NODES].count);
        break;
    case SCENE_FIELD_MAX_DEPTH:
        if (h->max_depth > SCN_MAX_DEPTH)
            snprintf(out, n, "header: max_depth = %u, deeper than %d", h->max_depth, SCN_MAX_DEPTH);
        else
            snprintf(out, n, "header: max_depth = %u, but the tree is deeper", h->max_depth);
        break;
    default: snprintf(out, n, "%s", scene_status_text(se->status));
    }
}

/* A section the loader refused (SCENE_ERR_SECTION): where it lies, or its count. */
static void describe_section(const scn_header *h, int i, char *out, size_t n)
{
    const char *name = scene_section_name(i);
    uint32_t off = h->sec[i].offset, count = h->sec[i].count;
    if (off & 3u)
        snprintf(out, n, "%s section: offset %u is not a multiple of 4", name, off);
    else if (off < h->header_bytes)
        snprintf(out, n, "%s section: offset %u lies inside the header", name, off);
    else if (i == SCN_SEC_PALETTE && count != 256)
        snprintf(out, n, "%s section: %u entries, expected 256", name, count);
    else if (i == SCN_SEC_NEEDS && count != 1)
        snprintf(out, n, "%s section: %u records, expected 1", name, count);
    else if (i == SCN_SEC_LOOK && count > 1)
        snprintf(out, n, "%s section: %u records, expected 0 or 1", name, count);
    else if (i > SCN_SEC_LOOK && h->sec[SCN_SEC_LOOK].count == 0 && count != 0)
        snprintf(out, n, "%s section: %u records in a scene without a look section, expected 0", name, count);
    else if (i == SCN_SEC_LIGHTS && count != SCN_LIGHT_MAPS)
        snprintf(out, n, "%s section: %u tables, expected %d", name, count, SCN_LIGHT_MAPS);
    else if (i == SCN_SEC_TEXTURES && count == 0)
        snprintf(out, n, "%s section: no textures in a scene with a look", name);
    else if (i == SCN_SEC_SIDES && count != 2u * h->sec[SCN_SEC_LINES].count)
        snprintf(out, n, "%s section: %u records, expected 2 per line (%u lines)", name, count,
                 h->sec[SCN_SEC_LINES].count);
    else if (i == SCN_SEC_PLANES && count != h->sec[SCN_SEC_SECTORS].count)
        snprintf(out, n, "%s section: %u records, expected 1 per sector (%u sectors)", name, count,
                 h->sec[SCN_SEC_SECTORS].count);
    else
        snprintf(out, n, "%s section: %u records from offset %u run past the end of the scene (total_bytes %u)", name,
                 count, off, h->total_bytes);
}

void scene_file_describe_error(const char *spec, const uint8_t *blob, size_t len, const scene_error *se, char *err,
                               size_t errlen)
{
    const char *st = scene_status_text(se->status);
    /* the loader refuses a blob shorter than the header before reading any field */
    const scn_header *h = blob && len >= sizeof(scn_header) ? (const scn_header *)(const void *)blob : NULL;
    char what[300];
    if (se->status == SCENE_ERR_BUILD && se->index < SCENE_ITEM_EDGES)
        snprintf(err, errlen,
                 "%s: the scene needs %s, which this build leaves out (it was built for another "
                 "scene; see docs/needs.md)",
                 spec, scene_item_name(se->index));
    else if (se->status == SCENE_ERR_BUILD)
        snprintf(err, errlen,
                 "%s: the scene needs %s %u; this build provides %u (it was built for another "
                 "scene; see docs/needs.md)",
                 spec, scene_item_name(se->index), se->need, se->have);
    else if (se->status == SCENE_ERR_SHORT && !h)
        snprintf(err, errlen, "%s: compiled scene rejected: truncated: %zu bytes, shorter than the %zu-byte header",
                 spec, len, sizeof(scn_header));
    else if (se->status == SCENE_ERR_SECTION && h && se->section >= 0 && se->section < SCN_SEC_COUNT) {
        describe_section(h, se->section, what, sizeof what);
        snprintf(err, errlen, "%s: compiled scene rejected: %s", spec, what);
    } else if (se->section >= 0)
        snprintf(err, errlen, "%s: compiled scene rejected: %s record %u: %s", spec, scene_section_name(se->section),
                 se->index, st);
    else if (h) {
        describe_header(h, len, se, what, sizeof what);
        snprintf(err, errlen, "%s: compiled scene rejected: %s", spec, what);
    } else
        snprintf(err, errlen, "%s: compiled scene rejected: %s", spec, st);
}
