/* bspc.h - the BSP compiler as a library (prefix bspc_): source scene in, compiled
 * blob (firmware/scene_format.h) out. Used by build/bspc and by build/render,
 * which compiles a source scene on the fly. */
#ifndef BSPC_H
#define BSPC_H

#include <stddef.h>
#include <stdint.h>

#include "needs.h"

typedef enum { BSPC_SPLIT_FEWEST, BSPC_SPLIT_BALANCED, BSPC_SPLIT_MIXED } bspc_split;

/* Textures kept between the compiles of the maps of one WAD (look_cache.c). */
typedef struct bspc_look_cache bspc_look_cache;
bspc_look_cache *bspc_look_cache_new(void);
void bspc_look_cache_free(bspc_look_cache *c);

typedef struct {
    bspc_split split;            /* default BSPC_SPLIT_MIXED */
    int verbose;                 /* progress and warnings on stderr */
    int flat;                    /* leave a WAD map's look out (docs/textures.md): flat colours only */
    bspc_look_cache *look_cache; /* NULL, or textures kept from the maps compiled before */
} bspc_options;

typedef struct {
    uint32_t input_walls; /* linedefs read */
    uint32_t segs;        /* wall pieces written */
    uint32_t splits;      /* segs cut by partitions */
    uint32_t leaves, nodes, vertices;
    uint32_t max_depth;              /* nodes on the longest root-to-leaf path */
    double mean_depth;               /* mean over leaves */
    double build_ms;                 /* wall-clock milliseconds for the tree build and blob write */
    uint32_t models, objects, doors; /* docs/objects.md */
    uint32_t sprites, sprite_sets;   /* docs/objects.md, "Sprites": images and sets in the blob */
    uint64_t sprite_texels;          /* their texels (bytes of SCN_SEC_TEXELS) */
    uint64_t sprite_mask_bytes;      /* SCN_SEC_SPRMASK */
    uint64_t sprite_bytes;           /* texels, mask and the two sections' records */
    needs_report needs;              /* what the scene needs (docs/needs.md), as written in the blob */
} bspc_stats;

/* Default options. */
bspc_options bspc_defaults(void);

/* Compile the scene named by spec: "path.scene" (the text format, docs/scene-format.md)
 * or "path.wad:MAP01" / "path.wad:E1M1" (a Doom-format map; a WAD named without a folder
 * is also looked for in $DOOMWADDIR and /usr/share/games/doom). On success returns 0 and
 * *blob (malloc'd, caller frees) and *len; stats may be NULL. On failure returns -1 and
 * writes into err a one-line message naming the file, the item and the problem. */
int bspc_compile(const char *spec, const bspc_options *opt, uint8_t **blob, size_t *len, bspc_stats *stats, char *err,
                 size_t errlen);

/* Resolve a WAD file name as bspc_compile does; returns 0 and the path in out, or -1. */
int bspc_find_wad(const char *name, char *out, size_t outlen);

/* What a scene spec names: the one reading of its form. */
typedef enum {
    BSPC_SPEC_FILE,   /* a file: a text scene, or a compiled scene */
    BSPC_SPEC_WAD,    /* "x.wad": a WAD without a map */
    BSPC_SPEC_WAD_MAP /* "x.wad:MAP01": a map in a WAD */
} bspc_spec_kind;

/* The kind of spec; *wadlen (may be NULL) gets the length of the WAD's name. */
bspc_spec_kind bspc_spec(const char *spec, size_t *wadlen);

/* The maps of the WAD named by wad (found as bspc_compile finds it), in the
 * order of its directory, separated by spaces ("MAP01 MAP02"; "" when it has
 * none). Returns the number of maps, or -1 with a message in err. When out is
 * too small the list ends in "...". */
int bspc_list_maps(const char *wad, char *out, size_t outlen, char *err, size_t errlen);

/* A text scene's model names, in the order the compiler numbers the models
 * (that of its 'model' lines), read by the compiler's own parser. Returns the
 * count and a malloc'd *names (caller frees); 0 for a scene that is not a
 * text scene (a compiled scene, a WAD map: they keep no names) or does not
 * parse; -1 out of memory. */
typedef struct {
    char name[32];
} bspc_name;
int bspc_model_names(const char *spec, bspc_name **names);

#endif
