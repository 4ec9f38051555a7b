/* bspc.h - the BSP compiler as a library (prefix bspc_): source scene in, compiled
 * blob (firmware/scene_format.h) out. Used by build/bspc and by build/render,
 * which compiles a source scene on the fly. */
#ifndef BSPC_H
#define BSPC_H

#include <stddef.h>
#include <stdint.h>

#include "needs.h"

typedef enum { BSPC_SPLIT_FEWEST, BSPC_SPLIT_BALANCED, BSPC_SPLIT_MIXED } bspc_split;

typedef struct {
    bspc_split split; /* default BSPC_SPLIT_MIXED */
    int verbose;      /* progress and warnings on stderr */
    int flat;         /* leave a WAD map's look out (docs/textures.md): flat colours only */
} bspc_options;

typedef struct {
    uint32_t input_walls; /* linedefs read */
    uint32_t segs;        /* wall pieces written */
    uint32_t splits;      /* segs cut by partitions */
    uint32_t leaves, nodes, vertices;
    uint32_t max_depth;   /* nodes on the longest root-to-leaf path */
    double mean_depth;    /* mean over leaves */
    double build_ms;      /* wall-clock milliseconds for the tree build and blob write */
    uint32_t models, objects, doors; /* docs/objects.md */
    needs_report needs;              /* what the scene needs (docs/needs.md), as written in the blob */
} bspc_stats;

/* Default options. */
bspc_options bspc_defaults(void);

/* Compile the scene named by spec: "path.scene" (the text format, docs/scene-format.md)
 * or "path.wad:MAP01" / "path.wad:E1M1" (a Doom-format map; a WAD named without a folder
 * is also looked for in $DOOMWADDIR and /usr/share/games/doom). On success returns 0 and
 * *blob (malloc'd, caller frees) and *len; stats may be NULL. On failure returns -1 and
 * writes into err a one-line message naming the file, the item and the problem. */
int bspc_compile(const char *spec, const bspc_options *opt, uint8_t **blob, size_t *len,
                 bspc_stats *stats, char *err, size_t errlen);

/* Resolve a WAD file name as bspc_compile does; returns 0 and the path in out, or -1. */
int bspc_find_wad(const char *name, char *out, size_t outlen);

#endif
