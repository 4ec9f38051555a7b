/* anim.h - textures by time (prefix anim_): Doom's animated wall textures and
 * flats, and its scrolling walls (docs/textures.md, "Animation"). The texture
 * a side's part or a sector's plane names goes through anim_tex wherever a
 * paint is made (surfaces.c, columns.c), so every render mode draws the same
 * frame; a build whose scene has no animation (CFG_ANIM 0) keeps none of it. */
#ifndef ANIM_H
#define ANIM_H

#include <stdint.h>
#include "build_config.h"
#include "objects.h"
#include "scene.h"

/* The level time in tics the world w is at (0 without w: the world as compiled). */
static inline uint32_t anim_tic(const world_state *w)
{
    return CFG_ANIM && w ? w->tic : 0u;
}

/* The texture shown at level time tic in place of texture tex (an scn_texture
 * index or SCN_TEX_NONE): Doom's P_UpdateSpecials, frame first + k showing
 * first + ((tic / tics + phase + k) mod count). The loader keeps the sequences
 * apart, so at most one holds tex; tic < 2^28 and phase + k < 2^7: no sum wraps. */
static inline uint32_t anim_tex(const scene *sc, uint32_t tic, uint32_t tex)
{
    if (!CFG_ANIM) return tex;
    for (uint32_t i = 0; i < sc->nanims; i++) {
        const scn_anim *a = &sc->anims[i];
        uint32_t k = tex - a->first; /* below first wraps to a large k */
        if (k < a->count) return a->first + (tic / a->tics + a->phase + k) % a->count;
    }
    return tex;
}

/* What a side's texture column gains by level time tic, 16.16 (docs/textures.md):
 * a scrolling side one unit a tic, modulo 2^16 units, a multiple of every
 * texture's width, so the wrap of the sum changes no column. */
static inline uint32_t anim_scroll(const scn_side *sd, uint32_t tic)
{
    return CFG_ANIM && (sd->flags & SCN_SIDE_SCROLL) ? tic << 16 : 0u;
}

#endif
