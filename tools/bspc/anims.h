/* anims.h - Doom's animated wall textures and flats and its scrolling walls, as
 * a WAD holds them (prefix bs_anim_; docs/textures.md, "Animation").
 *
 * Doom's built-in table (P_InitPicAnims) names each sequence by its first and
 * last frame; the frames are what lies between them in the WAD's own order:
 * texture numbers (TEXTURE1, then TEXTURE2) or the flats' lump order. A
 * sequence counts only when both ends exist and it has two frames or more.
 * wad_look.c stores every frame of a sequence, one after the other, the first
 * time the map uses any of them, and records it here for SCN_SEC_ANIMS. */
#ifndef BS_ANIMS_H
#define BS_ANIMS_H

#include <stdint.h>

#include "bspc_int.h"

typedef struct {
    int flat;         /* 1: flats, 0: wall textures */
    uint32_t n;       /* frames, 2 .. SCN_ANIM_MAX_FRAMES */
    char (*names)[9]; /* the frames' names, in the WAD's order */
    uint32_t phase;   /* the WAD's number of the first frame, modulo n */
    uint32_t tics;    /* tics a frame shows */
} bs_anim_seq;

typedef struct bs_anims bs_anims;

/* The sequences this WAD holds: dir[0..ndir) its directory, tdef[k] and
 * tdsize[k] TEXTURE1 and TEXTURE2 (NULL and 0 when absent), read as Doom
 * numbers them up to the first entry that does not fit its lump. NULL only
 * when out of memory. */
bs_anims *bs_anim_find(const bs_wadlump *dir, uint32_t ndir, uint8_t *const tdef[2], const uint32_t tdsize[2],
                       const bspc_options *opt, const char *wad);
/* The sequence that has a frame of that kind (flat 1, wall 0) and name, or NULL. */
const bs_anim_seq *bs_anim_of(const bs_anims *a, int flat, const char *name);
void bs_anim_free(bs_anims *a);

/* Store the frames of sequence q in order with store(ctx, q->flat, name, &index)
 * (the look's store-or-find of one texture: 0 or -1 with a message) and, if
 * they came out one after another, add the record to lk; a sequence whose
 * frames did not (a frame the WAD cannot give, or one stored before) is left
 * out with a warning and its frames stand still. 0, or -1 with a message in err. */
typedef int (*bs_anim_store_fn)(void *ctx, int flat, const char *name, uint16_t *index, char *err, size_t errlen);
int bs_anim_store(const bs_anim_seq *q, bs_look *lk, bs_anim_store_fn store, void *ctx, const bspc_options *opt,
                  const char *wad, char *err, size_t errlen);

/* Doom's line special 48 moves its front sidedef's texture: one flag per
 * sidedef (nsidedefs of them, calloc'd) for the front sidedef of every such
 * linedef (14-byte LINEDEFS records), so that every line sharing the sidedef
 * scrolls. NULL when no linedef scrolls or out of memory (*oom set then). */
uint8_t *bs_anim_scrolling(const uint8_t *linedefs, uint32_t nlinedefs, uint32_t nsidedefs, int *oom);

#endif
