/* wad_look_int.h - the open look of a WAD map (wad_look.c), shared with the
 * sprites' builder (sprites.c). Private to those two files. */
#ifndef BSPC_WAD_LOOK_INT_H
#define BSPC_WAD_LOOK_INT_H

#include <stdint.h>
#include <stdio.h>

#include "anims.h"
#include "bspc_int.h"
#include "name_table.h"

/* A sprite set asked for by a thing type: its sprite, frame and flags, and
 * what became of it. */
typedef struct {
    char sprite[4];
    char frame;
    uint8_t flags;          /* SCN_SPRSET_* */
    uint32_t set1;          /* 1 + its index in bs_look.sprsets; 0: the type stays a box */
    int32_t radius, height; /* whole units: the box around its images (set1 != 0) */
} bs_wl_sprset;

enum { KIND_WALL, KIND_FLAT };

typedef struct {
    char name[9];
    int kind;
    uint16_t tex;  /* SCN_TEX_NONE: unknown (warned once) */
    uint32_t hash; /* of name: most entries are told apart by it alone */
} used_name;

struct bs_wadlook {
    FILE *f;
    size_t flen;
    const bs_wadlump *dir;
    uint32_t ndir;
    const char *wad; /* the scene spec, for messages */
    const bspc_options *opt;
    bs_scene *s;
    bs_look *lk;
    uint8_t *pnames;
    uint32_t npnames;
    uint8_t *tdef[2];
    uint32_t tdsize[2];
    used_name *used;
    uint32_t nused, ucap;
    uint32_t nlines_cap; /* sides has room for 2 * nlines_cap */
    const char *sky_name;
    uint8_t neutral;   /* palette index of a mid grey, for parts without a texture */
    uint32_t *flats;   /* the lumps between flat markers, in directory order (found once) */
    uint32_t nflats;   /* valid once flats is set */
    uint32_t *sprites; /* the same for the sprite markers */
    uint32_t nsprites;
    name_table lumps;     /* the directory, the last of a name winning (lumps.e NULL until needed) */
    name_table flat_name; /* the flats, the same */
    name_table texdefs;   /* TEXTURE1 then TEXTURE2 up to the first bad entry, the first winning:
                           * entry i of TEXTURE1 is i, entry i of TEXTURE2 is texdef_n0 + i */
    uint32_t texdef_n0;
    int bad_kind;             /* what stopped that indexing: BAD_NONE, BAD_COUNT or BAD_ENTRY ... */
    int bad_lump;             /* ... in TEXTURE1 (0) or TEXTURE2 (1) ... */
    uint32_t bad_entry;       /* ... at this entry */
    uint8_t def_palette[768]; /* the flat-shaded palette (bs_palette), for things.txt's colours */
    int have_def_palette;
    const char *wadpath; /* the file, as the look cache knows it */
    bs_anims *anims;     /* the WAD's animated textures and flats (anims.c) */
    int anim_busy;       /* storing a sequence's frames */
    /* the things' sprites (sprites.c) */
    uint32_t *image_of; /* [ndir]: 1 + the scn_sprite of lump i, 0 while not stored */
    bs_wl_sprset *sets; /* the sprite sets asked for, in order of first use */
    uint32_t nsets, setcap;
};

/* Read lump i whole (at least min bytes); malloc'd into *out. 0, or -1 with
 * a message naming the WAD and the lump. */
int bs_wl_load_lump(const bs_wadlook *L, uint32_t i, uint32_t min, uint8_t **out, char *err, size_t errlen);
/* List the lumps between S_START/S_END or SS_START/SS_END into L->sprites
 * (directory order) on the first call; 0, or -1 out of memory. */
int bs_wl_list_sprites(bs_wadlook *L);
/* Free what sprites.c kept in L. */
void bs_wl_sprites_free(bs_wadlook *L);

#endif
