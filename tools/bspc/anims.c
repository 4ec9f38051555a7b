/* anims.c - Doom's animated wall textures and flats, and scrolling walls, as a
 * WAD holds them (see anims.h; docs/textures.md, "Animation").
 *
 * The frame rule is Doom's P_UpdateSpecials: at level time T tics, texture or
 * flat number i of a sequence [base, base + n) shows base + ((T / speed + i)
 * mod n). i is the WAD's own number, so the scene keeps base mod n as the
 * sequence's phase: frame k (number base + k) then shows frame
 * (T / speed + phase + k) mod n, whatever index the scene gives the frames. */
#include "anims.h"
#include "wad_bytes.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

/* Doom's table (P_InitPicAnims), first and last frame by name; 8 tics a frame. */
static const struct {
    int flat;
    const char *first, *last;
} doom_anims[] = {
    {1, "NUKAGE1", "NUKAGE3"},   {1, "FWATER1", "FWATER4"},   {1, "SWATER1", "SWATER4"},   {1, "LAVA1", "LAVA4"},
    {1, "BLOOD1", "BLOOD3"},     {1, "RROCK05", "RROCK08"},   {1, "SLIME01", "SLIME04"},   {1, "SLIME05", "SLIME08"},
    {1, "SLIME09", "SLIME12"},   {0, "BLODGR1", "BLODGR4"},   {0, "SLADRIP1", "SLADRIP3"}, {0, "BLODRIP1", "BLODRIP4"},
    {0, "FIREWALA", "FIREWALL"}, {0, "GSTFONT1", "GSTFONT3"}, {0, "FIRELAV3", "FIRELAVA"}, {0, "FIREMAG1", "FIREMAG3"},
    {0, "FIREBLU1", "FIREBLU2"}, {0, "ROCKRED1", "ROCKRED3"}, {0, "BFALL1", "BFALL4"},     {0, "SFALL1", "SFALL4"},
    {0, "WFALL1", "WFALL4"},     {0, "DBRAIN1", "DBRAIN4"},
};
#define DOOM_ANIMS (sizeof doom_anims / sizeof doom_anims[0])
#define DOOM_TICS 8u

struct bs_anims {
    bs_anim_seq seq[DOOM_ANIMS];
    uint32_t nseq;
};

/* The wall textures by Doom's number: TEXTURE1's entries, then TEXTURE2's
 * numbered after TEXTURE1's declared count, up to the first entry whose
 * definition does not fit its lump (wad_look.c's index stops there too). */
typedef struct {
    char (*name)[9];
    uint32_t n;
} tex_list;

static int list_textures(tex_list *t, uint8_t *const tdef[2], const uint32_t tdsize[2])
{
    uint32_t count[2] = {0, 0}, total = 0;
    t->name = NULL;
    t->n = 0;
    for (int k = 0; k < 2; k++) {
        if (!tdef[k] || tdsize[k] < 4) continue;
        count[k] = rd32(tdef[k]);
        if (count[k] > (tdsize[k] - 4) / 4) { /* the declared entries do not fit: nothing from here is found */
            count[k] = 0;
            if (k == 0) return 0;
        }
        total += count[k];
    }
    t->name = malloc(sizeof *t->name * ((size_t)total + 1));
    if (!t->name) return -1;
    for (int k = 0; k < 2; k++)
        for (uint32_t i = 0; i < count[k]; i++) {
            uint32_t o = rd32(tdef[k] + 4 + 4 * i);
            if (o > tdsize[k] || tdsize[k] - o < 22) return 0;
            name8(t->name[t->n++], tdef[k] + o);
        }
    return 0;
}

/* Doom's number of a texture name: the first of the name, or -1. */
static int64_t texture_number(const tex_list *t, const char *name)
{
    for (uint32_t i = 0; i < t->n; i++)
        if (strcmp(t->name[i], name) == 0) return i;
    return -1;
}

/* The last lump of a name (Doom's W_CheckNumForName), or -1. */
static int64_t last_lump(const bs_wadlump *dir, uint32_t ndir, const char *name)
{
    for (uint32_t i = ndir; i-- > 0;)
        if (strcmp(dir[i].name, name) == 0) return i;
    return -1;
}

static int fill(bs_anim_seq *q, int flat, uint32_t n, int64_t base)
{
    q->flat = flat;
    q->n = n;
    q->tics = DOOM_TICS;
    q->phase = (uint32_t)(((base % n) + n) % n);
    q->names = malloc(sizeof *q->names * n);
    return q->names ? 0 : -1;
}

bs_anims *bs_anim_find(const bs_wadlump *dir, uint32_t ndir, uint8_t *const tdef[2], const uint32_t tdsize[2],
                       const bspc_options *opt, const char *wad)
{
    bs_anims *a = calloc(1, sizeof *a);
    tex_list t;
    if (!a || list_textures(&t, tdef, tdsize)) {
        free(a);
        return NULL;
    }
    /* Doom's flat numbers count from the lump after F_START (R_InitFlats) */
    int64_t fstart = last_lump(dir, ndir, "F_START");
    if (fstart < 0) fstart = last_lump(dir, ndir, "FF_START");
    for (uint32_t d = 0; d < DOOM_ANIMS; d++) {
        int flat = doom_anims[d].flat;
        int64_t first, last;
        if (flat) {
            first = last_lump(dir, ndir, doom_anims[d].first);
            last = last_lump(dir, ndir, doom_anims[d].last);
        } else {
            first = texture_number(&t, doom_anims[d].first);
            last = texture_number(&t, doom_anims[d].last);
        }
        if (first < 0 || last < 0) continue; /* another game's, or another episode's */
        if (last - first + 1 < 2 || last - first + 1 > SCN_ANIM_MAX_FRAMES) {
            bs_warn(opt, "%s: animation %s .. %s: %lld frames in the WAD's order: it stands still", wad,
                    doom_anims[d].first, doom_anims[d].last, (long long)(last - first + 1));
            continue;
        }
        uint32_t n = (uint32_t)(last - first + 1);
        int ok = 1;
        for (int64_t i = first; flat && i <= last; i++) ok = ok && dir[i].size >= 4096;
        if (!ok) {
            bs_warn(opt, "%s: animation %s .. %s: a lump between them is no flat: it stands still", wad,
                    doom_anims[d].first, doom_anims[d].last);
            continue;
        }
        bs_anim_seq *q = &a->seq[a->nseq];
        if (fill(q, flat, n, flat ? first - (fstart + 1) : first)) {
            bs_anim_free(a);
            a = NULL;
            break;
        }
        for (uint32_t k = 0; k < n; k++)
            snprintf(q->names[k], sizeof q->names[k], "%s", flat ? dir[first + k].name : t.name[first + k]);
        a->nseq++;
    }
    free(t.name);
    return a;
}

const bs_anim_seq *bs_anim_of(const bs_anims *a, int flat, const char *name)
{
    for (uint32_t i = 0; a && i < a->nseq; i++) {
        const bs_anim_seq *q = &a->seq[i];
        if (q->flat != flat) continue;
        for (uint32_t k = 0; k < q->n; k++)
            if (strcmp(q->names[k], name) == 0) return q;
    }
    return NULL;
}

void bs_anim_free(bs_anims *a)
{
    if (!a) return;
    for (uint32_t i = 0; i < a->nseq; i++) free(a->seq[i].names);
    free(a);
}

int bs_anim_store(const bs_anim_seq *q, bs_look *lk, bs_anim_store_fn store, void *ctx, const bspc_options *opt,
                  const char *wad, char *err, size_t errlen)
{
    uint16_t first = SCN_TEX_NONE;
    int apart = 0;
    for (uint32_t k = 0; k < q->n; k++) {
        uint16_t t;
        if (store(ctx, q->flat, q->names[k], &t, err, errlen)) return -1;
        if (k == 0) first = t;
        if (t == SCN_TEX_NONE || first == SCN_TEX_NONE || t != first + k) apart = 1;
    }
    /* the records stay sorted and apart: every frame is stored after the last sequence */
    uint32_t end = lk->nanims ? lk->anims[lk->nanims - 1].first + lk->anims[lk->nanims - 1].count : 0;
    if (apart || first < end) {
        bs_warn(opt, "%s: animation %s .. %s: its frames are not one after another in the scene: it stands still", wad,
                q->names[0], q->names[q->n - 1]);
        return 0;
    }
    if (bs_grow(&lk->anims, &lk->acap, lk->nanims + 1, sizeof *lk->anims))
        return bs_fail(err, errlen, "%s: out of memory", wad);
    lk->anims[lk->nanims++] = (scn_anim){first, (uint16_t)q->n, (uint16_t)q->phase, (uint16_t)q->tics, 0};
    return 0;
}

uint8_t *bs_anim_scrolling(const uint8_t *linedefs, uint32_t nlinedefs, uint32_t nsidedefs, int *oom)
{
    uint8_t *flag = NULL;
    *oom = 0;
    for (uint32_t i = 0; i < nlinedefs; i++) {
        const uint8_t *r = linedefs + 14 * i;
        uint32_t special = (uint32_t)r[6] | (uint32_t)r[7] << 8, front = (uint32_t)r[10] | (uint32_t)r[11] << 8;
        if (special != 48 || front >= nsidedefs) continue;
        if (!flag && !(flag = calloc(nsidedefs, 1))) {
            *oom = 1;
            return NULL;
        }
        flag[front] = 1;
    }
    return flag;
}
