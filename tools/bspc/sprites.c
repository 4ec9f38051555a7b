/* sprites.c - the sprites of a WAD map's things (docs/objects.md, "Sprites").
 *
 * A thing type of tools/bspc/things.txt names its sprite and the frame of its
 * spawn state. In a textured scene the frame's images become a sprite set:
 * the lumps between the sprite markers named SSSSFR or SSSSFRFR (sprite SSSS,
 * frame F, rotation R: 0 for every rotation, or 1..8; the second pair names a
 * rotation that shows the same lump mirrored), a later lump of a name
 * replacing an earlier one. Each lump is decoded once a scene into an
 * scn_sprite: column-major texels appended to the look's texels and one
 * opacity bit per texel. Only the spawn frames of the types the map's things
 * have are stored, and after the build (bs_sprites_prune) only those of the
 * things that stayed in the scene.
 *
 * A damaged patch is refused, as for textures; an image the format cannot
 * hold (larger than SCN_SPRITE_MAX, or a box around it beyond the model
 * limits) leaves its type a box, with a warning (-v).
 */
#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"
#include "patch.h"
#include "wad_look_int.h"

/* the image a sprite set uses for a rotation (0..7) */
typedef struct {
    uint32_t lump; /* directory index, or ndir */
    int mirror;
} rot_lump;

static int is_rot(char c)
{
    return c >= '0' && c <= '8';
}

/* Put lump (mirrored or not) at Doom rotation r (0: all of them) of want. */
static void install(rot_lump want[9], int r, uint32_t lump, int mirror)
{
    want[r].lump = lump;
    want[r].mirror = mirror;
}

/* The lumps of frame F of sprite S by Doom rotation (0..8), from the lumps
 * between the markers in directory order (a later lump of a name, or another
 * lump naming the same rotation, replaces the earlier). */
static void find_rotations(const bs_wadlook *L, const char sprite[4], char frame, rot_lump want[9])
{
    for (int r = 0; r < 9; r++) want[r] = (rot_lump){L->ndir, 0};
    for (uint32_t k = 0; k < L->nsprites; k++) {
        uint32_t i = L->sprites[k];
        const char *n = L->dir[i].name;
        size_t len = strlen(n);
        if ((len != 6 && len != 8) || memcmp(n, sprite, 4) != 0 || !is_rot(n[5])) continue;
        if (len == 8 && !is_rot(n[7])) continue;
        if (n[4] == frame) install(want, n[5] - '0', i, 0);
        if (len == 8 && n[6] == frame) install(want, n[7] - '0', i, 1);
    }
}

/* What a post draws: texels and opacity bits of an image of height h. */
typedef struct {
    uint8_t *texels;
    uint32_t *mask;
    uint32_t h, words; /* words of mask a column */
    uint64_t clipped;  /* texels of posts below the image's height, left out */
} image_draw;

static void image_post(void *ctx, int32_t c, uint32_t top, const uint8_t *src, uint32_t len)
{
    image_draw *d = ctx;
    for (uint32_t k = 0; k < len; k++) {
        uint32_t v = top + k;
        if (v >= d->h) {
            d->clipped += len - k;
            return;
        }
        d->texels[(uint32_t)c * d->h + v] = src[k];
        d->mask[(uint32_t)c * d->words + (v >> 5)] |= 1u << (v & 31);
    }
}

/* The scn_sprite of lump i, decoded and stored on first use: 1 and *out; 0
 * when the format cannot hold it (warned); -1 with a message. */
static int sprite_image(bs_wadlook *L, uint32_t i, uint16_t *out, char *err, size_t errlen)
{
    if (!L->image_of) {
        L->image_of = calloc((size_t)L->ndir + 1, sizeof *L->image_of);
        if (!L->image_of) return bs_fail(err, errlen, "%s: out of memory", L->wad);
    }
    if (L->image_of[i]) {
        *out = (uint16_t)(L->image_of[i] - 1);
        return 1;
    }
    const char *name = L->dir[i].name;
    uint8_t *p;
    if (bs_wl_load_lump(L, i, 0, &p, err, errlen)) return -1;
    uint32_t size = L->dir[i].size;
    bs_patch_info pi;
    if (bs_patch_info_read(p, size, L->wad, name, &pi, err, errlen)) {
        free(p);
        return -1;
    }
    int32_t reach = pi.left > pi.width - pi.left ? pi.left : pi.width - pi.left;
    const char *why = NULL;
    if (pi.width > SCN_SPRITE_MAX || pi.height > SCN_SPRITE_MAX)
        why = "larger than the sprite limit";
    else if (reach > SCN_MODEL_MAX || pi.top > SCN_MODEL_MAX || pi.left < -SCN_MODEL_MAX || pi.top < -SCN_MODEL_MAX)
        why = "offsets beyond the model limits";
    if (why) {
        bs_warn(L->opt,
                "%s: sprite %s: %d x %d, offsets %d, %d: %s (%d x %d, |offset| and reach <= %d): its things "
                "are drawn as boxes",
                L->wad, name, pi.width, pi.height, pi.left, pi.top, why, SCN_SPRITE_MAX, SCN_SPRITE_MAX, SCN_MODEL_MAX);
        free(p);
        return 0;
    }
    bs_look *lk = L->lk;
    uint32_t w = (uint32_t)pi.width, h = (uint32_t)pi.height, words = (h + 31) >> 5;
    uint32_t n = w * h, nm = w * words;
    if (lk->nsprites >= 0xFFFFu) {
        free(p);
        return bs_fail(err, errlen, "%s: more than %u sprite images", L->wad, 0xFFFFu);
    }
    if ((uint64_t)lk->ntexels + n > UINT32_MAX / 2 || (uint64_t)lk->nsprmask + nm > UINT32_MAX / 8 ||
        bs_grow(&lk->texels, &lk->txcap, lk->ntexels + n, 1) ||
        bs_grow(&lk->sprmask, &lk->smcap, lk->nsprmask + nm, sizeof *lk->sprmask) ||
        bs_grow(&lk->sprites, &lk->spcap, lk->nsprites + 1, sizeof *lk->sprites)) {
        free(p);
        return bs_fail(err, errlen, "%s: out of memory", L->wad);
    }
    image_draw d = {lk->texels + lk->ntexels, lk->sprmask + lk->nsprmask, h, words, 0};
    memset(d.texels, 0, n);
    memset(d.mask, 0, (size_t)nm * sizeof *d.mask);
    int rc = bs_patch_walk(p, size, L->wad, name, 0, pi.width, image_post, &d, err, errlen);
    free(p);
    if (rc) return -1;
    if (d.clipped)
        bs_warn(L->opt, "%s: sprite %s: %llu texels of posts below its height (%u rows) left out", L->wad, name,
                (unsigned long long)d.clipped, h);
    scn_sprite *sp = &lk->sprites[lk->nsprites];
    sp->first = lk->ntexels;
    sp->mask = lk->nsprmask;
    sp->width = (uint16_t)w;
    sp->height = (uint16_t)h;
    sp->left = (int16_t)pi.left;
    sp->top = (int16_t)pi.top;
    lk->ntexels += n;
    lk->nsprmask += nm;
    *out = (uint16_t)lk->nsprites++;
    L->image_of[i] = *out + 1u;
    return 1;
}

/* Build the set of e (its sprite, frame and flags set): e->set1 and the box,
 * or e->set1 = 0 for a type that stays a box. */
static int build_set(bs_wadlook *L, bs_wl_sprset *e, char *err, size_t errlen)
{
    e->set1 = 0;
    if (bs_wl_list_sprites(L)) return bs_fail(err, errlen, "%s: out of memory", L->wad);
    rot_lump want[9];
    find_rotations(L, e->sprite, e->frame, want);
    rot_lump rot[SCN_SPRITE_ROTS];
    if (want[0].lump != L->ndir) {
        for (int r = 1; r <= 8; r++)
            if (want[r].lump != L->ndir) {
                bs_note(L->opt, "%s: sprite %.4s frame %c has a rotation-0 image and rotation %d: using %s for all",
                        L->wad, e->sprite, e->frame, r, L->dir[want[0].lump].name);
                break;
            }
        for (int r = 0; r < SCN_SPRITE_ROTS; r++) rot[r] = want[0];
    } else {
        char missing[24] = "";
        for (int r = 1; r <= 8; r++) {
            if (want[r].lump == L->ndir)
                snprintf(missing + strlen(missing), sizeof missing - strlen(missing), " %d", r);
            rot[r - 1] = want[r];
        }
        if (missing[0]) {
            bs_note(L->opt,
                    "%s: sprite %.4s frame %c: no rotation-0 image and no rotation%s: its things are drawn as "
                    "boxes",
                    L->wad, e->sprite, e->frame, missing);
            return 0;
        }
    }
    scn_sprset set;
    memset(&set, 0, sizeof set);
    set.flags = e->flags;
    int32_t radius = 1, height = 1;
    for (int r = 0; r < SCN_SPRITE_ROTS; r++) {
        int got = sprite_image(L, rot[r].lump, &set.image[r], err, errlen);
        if (got <= 0) return got;
        const scn_sprite *sp = &L->lk->sprites[set.image[r]];
        int32_t reach = sp->left > sp->width - sp->left ? sp->left : sp->width - sp->left;
        if (reach > radius) radius = reach;
        if (sp->top > height) height = sp->top;
        if (rot[r].mirror) set.mirror |= (uint8_t)(1u << r);
    }
    bs_look *lk = L->lk;
    if (bs_grow(&lk->sprsets, &lk->sscap, lk->nsprsets + 1, sizeof *lk->sprsets))
        return bs_fail(err, errlen, "%s: out of memory", L->wad);
    lk->sprsets[lk->nsprsets++] = set;
    e->set1 = lk->nsprsets;
    e->radius = radius;
    e->height = height;
    return 0;
}

int bs_look_thing_sprite(bs_wadlook *L, const char sprite[4], char frame, unsigned flags, uint32_t *set1,
                         int32_t *radius, int32_t *height, char *err, size_t errlen)
{
    *set1 = 0;
    /* sprites only in a scene that keeps its look (bs_look_close's rule) */
    if (!L || (L->opt && L->opt->flat) || !L->lk->doom_palette || L->lk->ntex == 0) return 0;
    bs_wl_sprset *e = NULL;
    for (uint32_t k = 0; k < L->nsets && !e; k++)
        if (memcmp(L->sets[k].sprite, sprite, 4) == 0 && L->sets[k].frame == frame && L->sets[k].flags == flags)
            e = &L->sets[k];
    if (!e) {
        if (bs_grow(&L->sets, &L->setcap, L->nsets + 1, sizeof *L->sets))
            return bs_fail(err, errlen, "%s: out of memory", L->wad);
        e = &L->sets[L->nsets++];
        memset(e, 0, sizeof *e);
        memcpy(e->sprite, sprite, 4);
        e->frame = frame;
        e->flags = (uint8_t)flags;
        if (build_set(L, e, err, errlen)) {
            L->nsets--;
            return -1;
        }
    }
    *set1 = e->set1;
    *radius = e->radius;
    *height = e->height;
    return 0;
}

void bs_wl_sprites_free(bs_wadlook *L)
{
    free(L->image_of);
    free(L->sets);
    L->image_of = NULL;
    L->sets = NULL;
    L->nsets = L->setcap = 0;
}

void bs_sprites_prune(bs_scene *s)
{
    bs_look *lk = &s->look;
    if (lk->nsprsets == 0) return;
    uint32_t *set_new = calloc(lk->nsprsets, sizeof *set_new);
    uint32_t *img_new = calloc((size_t)lk->nsprites + 1, sizeof *img_new);
    if (!set_new || !img_new) { /* out of memory: everything stays (unused records are harmless) */
        free(set_new);
        free(img_new);
        return;
    }
    for (uint32_t i = 0; i < s->nobjects; i++)
        if (s->objects[i].sprset1) set_new[s->objects[i].sprset1 - 1] = 1;
    /* sets in order, and the images they use in their order */
    uint32_t nsets = 0, nimg = 0;
    for (uint32_t k = 0; k < lk->nsprsets; k++) {
        if (!set_new[k]) continue;
        set_new[k] = ++nsets;
        for (int r = 0; r < SCN_SPRITE_ROTS; r++) img_new[lk->sprsets[k].image[r]] = 1;
    }
    /* images keep their order: texels and mask words move down, each after the one kept before it */
    uint32_t tx = lk->nsprites ? lk->sprites[0].first : lk->ntexels, mk = 0;
    for (uint32_t i = 0; i < lk->nsprites; i++) {
        if (!img_new[i]) continue;
        scn_sprite sp = lk->sprites[i];
        uint32_t n = (uint32_t)sp.width * sp.height, nm = (uint32_t)sp.width * (((uint32_t)sp.height + 31) >> 5);
        memmove(lk->texels + tx, lk->texels + sp.first, n);
        memmove(lk->sprmask + mk, lk->sprmask + sp.mask, (size_t)nm * sizeof *lk->sprmask);
        sp.first = tx;
        sp.mask = mk;
        tx += n;
        mk += nm;
        lk->sprites[nimg] = sp;
        img_new[i] = ++nimg;
    }
    if (lk->nsprites) lk->ntexels = tx;
    lk->nsprites = nimg;
    lk->nsprmask = mk;
    uint32_t kept = 0;
    for (uint32_t k = 0; k < lk->nsprsets; k++) {
        if (!set_new[k]) continue;
        scn_sprset q = lk->sprsets[k];
        for (int r = 0; r < SCN_SPRITE_ROTS; r++) q.image[r] = (uint16_t)(img_new[q.image[r]] - 1);
        lk->sprsets[kept++] = q;
    }
    lk->nsprsets = kept;
    for (uint32_t i = 0; i < s->nobjects; i++)
        if (s->objects[i].sprset1) s->objects[i].sprset1 = set_new[s->objects[i].sprset1 - 1];
    free(set_new);
    free(img_new);
}
