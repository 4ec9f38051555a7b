/* look_cache.h - the textures of one WAD kept from one map's compile to the
 * next (prefix lc_; bspc --all): a texture the maps share is composed from its
 * patches and stored once. What a map gets from the cache is byte for byte
 * what composing it again gives, as the WAD (and so its palette) is the same. */
#ifndef BSPC_LOOK_CACHE_H
#define BSPC_LOOK_CACHE_H

#include <stdint.h>

#include "bspc.h"
#include "scene_format.h"

typedef struct {
    char name[9];
    int kind;        /* wad_look.c's KIND_WALL or KIND_FLAT */
    uint32_t hash;   /* of name */
    int known;       /* 0: not in the WAD (each map warns of it itself) */
    scn_texture rec; /* as stored (its first texel is each scene's own) */
    uint8_t *texels; /* (1 << wbits) << hbits of them */
} lc_entry;

/* The entry of that kind and name for wad, or NULL. A cache filled from
 * another WAD is emptied first. */
const lc_entry *lc_find(bspc_look_cache *c, const char *wad, int kind, const char *name);
/* Keep a texture (texels NULL and known 0 for a name not in the WAD); 0, or
 * -1 when out of memory (nothing is kept: the compile goes on without). */
int lc_put(bspc_look_cache *c, int kind, const char *name, int known, const scn_texture *rec, const uint8_t *texels);

#endif
