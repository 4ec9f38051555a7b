/* wad_look.c - a WAD map's look (docs/textures.md): PLAYPAL, COLORMAP, the wall
 * textures composed from their patches (TEXTURE1/2, PNAMES), flats, the sky,
 * each side's texture mapping and each sector's planes, and the colours of
 * the flat-shaded view and of things taken from the same data. Patches are
 * decoded by patch.c; the things' sprite images are built by sprites.c.
 *
 * Only what the map uses is composed and stored, each name once. Every byte
 * read from the WAD is bounds-checked: a damaged lump of a texture the map
 * uses is refused with a message naming the file, the lump and the problem.
 * Doubles are fine here (the compiler runs on the host).
 */
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "anims.h"
#include "bspc_int.h"
#include "wad_bytes.h"
#include "look_cache.h"
#include "patch.h"
#include "wad_look_int.h"

enum { BAD_NONE, BAD_COUNT, BAD_ENTRY };

/* the last lump of that name in [from, to), or ndir */
static uint32_t find_lump(const bs_wadlook *L, const char *name, uint32_t from, uint32_t to)
{
    for (uint32_t i = to; i-- > from;)
        if (strcmp(L->dir[i].name, name) == 0) return i;
    return L->ndir;
}

int bs_wl_load_lump(const bs_wadlook *L, uint32_t i, uint32_t min, uint8_t **out, char *err, size_t errlen)
{
    const bs_wadlump *e = &L->dir[i];
    *out = NULL;
    if (e->pos > L->flen || e->size > L->flen - e->pos)
        return bs_fail(err, errlen, "%s: lump %s runs past the end of the file", L->wad, e->name);
    if (e->size < min)
        return bs_fail(err, errlen, "%s: lump %s is %u bytes, shorter than %u", L->wad, e->name, e->size, min);
    uint8_t *b = malloc((size_t)e->size + 1);
    if (!b) return bs_fail(err, errlen, "%s: out of memory", L->wad);
    if (fseek(L->f, (long)e->pos, SEEK_SET) != 0 || fread(b, 1, e->size, L->f) != e->size) {
        free(b);
        return bs_fail(err, errlen, "%s: cannot read lump %s", L->wad, e->name);
    }
    *out = b;
    return 0;
}

static uint8_t nearest(const uint8_t pal[768], double r, double g, double b)
{
    double best = 1e30;
    int bi = 0;
    for (int i = 0; i < 256; i++) {
        double dr = pal[3 * i] - r, dg = pal[3 * i + 1] - g, db = pal[3 * i + 2] - b;
        double d = dr * dr + dg * dg + db * db;
        if (d < best) {
            best = d;
            bi = i;
        }
    }
    return (uint8_t)bi;
}

/* ---- storing textures ---- */

static int log2_floor(uint32_t v)
{
    int b = 0;
    while ((2u << b) <= v) b++;
    return b;
}

static int log2_ceil(uint32_t v)
{
    int b = 0;
    while ((1u << b) < v) b++;
    return b;
}

/* Room for one more texture of n texels in the look; 0, or -1 with a message. */
static int texture_room(bs_wadlook *L, uint32_t n, char *err, size_t errlen)
{
    bs_look *lk = L->lk;
    if (lk->ntex >= SCN_TEX_NONE) return bs_fail(err, errlen, "%s: more than %u textures", L->wad, SCN_TEX_NONE);
    if ((uint64_t)lk->ntexels + n > UINT32_MAX / 2 || bs_grow(&lk->texels, &lk->txcap, lk->ntexels + n, 1) ||
        bs_grow(&lk->tex, &lk->tcap, lk->ntex + 1, sizeof *lk->tex))
        return bs_fail(err, errlen, "%s: out of memory", L->wad);
    return 0;
}

/* Append a texture from a column-major w x h picture: 2^floor(log2 w) columns,
 * rows padded to 2^ceil(log2 h) by repeating from the top (docs/textures.md). */
static int store(bs_wadlook *L, const char *name, const uint8_t *pic, uint32_t w, uint32_t h, uint16_t *out, char *err,
                 size_t errlen)
{
    bs_look *lk = L->lk;
    int wb = log2_floor(w), hb = log2_ceil(h);
    if (wb > SCN_TEX_MAX_BITS || hb > SCN_TEX_MAX_BITS)
        return bs_fail(err, errlen, "%s: texture %s is %u x %u, larger than %d x %d", L->wad, name, w, h,
                       1 << SCN_TEX_MAX_BITS, 1 << SCN_TEX_MAX_BITS);
    uint32_t cols = 1u << wb, rows = 1u << hb, n = cols << hb;
    if (texture_room(L, n, err, errlen)) return -1;
    uint8_t *t = lk->texels + lk->ntexels;
    uint32_t hist[256] = {0};
    for (uint32_t u = 0; u < cols; u++) {
        const uint8_t *col = pic + u * h;
        uint8_t *dst = t + (u << hb);
        for (uint32_t v = 0; v < h; v++) hist[col[v]]++;
        for (uint32_t v = 0; v < rows; v += h) memcpy(dst + v, col, rows - v < h ? rows - v : h);
    }
    uint64_t sum[3] = {0, 0, 0}; /* exact, as the double sums they replace were */
    for (int c = 0; c < 256; c++)
        for (int k = 0; k < 3; k++) sum[k] += (uint64_t)hist[c] * lk->palette[3 * c + k];
    scn_texture *x = &lk->tex[lk->ntex];
    x->first = lk->ntexels;
    x->wbits = (uint8_t)wb;
    x->hbits = (uint8_t)hb;
    x->reserved = 0;
    x->height = (uint16_t)h;
    x->mask = SCN_TEX_NONE;
    double mean[3];
    for (int k = 0; k < 3; k++) mean[k] = (double)sum[k] / ((double)cols * h);
    x->colour = nearest(lk->palette, mean[0], mean[1], mean[2]);
    lk->ntexels += n;
    *out = (uint16_t)lk->ntex++;
    return 0;
}

/* Append a texture kept from an earlier map of the WAD: what store gave then. */
static int store_kept(bs_wadlook *L, const lc_entry *e, uint16_t *out, char *err, size_t errlen)
{
    bs_look *lk = L->lk;
    uint32_t n = (1u << e->rec.wbits) << e->rec.hbits;
    if (texture_room(L, n, err, errlen)) return -1;
    memcpy(lk->texels + lk->ntexels, e->texels, n);
    lk->tex[lk->ntex] = e->rec;
    lk->tex[lk->ntex].first = lk->ntexels;
    lk->ntexels += n;
    *out = (uint16_t)lk->ntex++;
    return 0;
}

/* ---- pictures (Doom's patch format, patch.c) ---- */

/* a texture's patch: the rows of each post inside the column-major w x h picture, at (ox, oy) */
typedef struct {
    uint8_t *pic;
    int32_t h, ox, oy;
} tex_draw;

static void tex_post(void *ctx, int32_t c, uint32_t top, const uint8_t *src, uint32_t len)
{
    const tex_draw *d = ctx;
    int32_t y0 = d->oy + (int32_t)top, k0 = y0 < 0 ? -y0 : 0, k1 = (int32_t)len;
    if (y0 + k1 > d->h) k1 = d->h - y0;
    if (k0 < k1) memcpy(d->pic + (d->ox + c) * d->h + y0 + k0, src + k0, (size_t)(k1 - k0));
}

/* the same rows marked 1: where a texture is opaque */
static void cover_post(void *ctx, int32_t c, uint32_t top, const uint8_t *src, uint32_t len)
{
    const tex_draw *d = ctx;
    int32_t y0 = d->oy + (int32_t)top, k0 = y0 < 0 ? -y0 : 0, k1 = (int32_t)len;
    (void)src;
    if (y0 + k1 > d->h) k1 = d->h - y0;
    if (k0 < k1) memset(d->pic + (d->ox + c) * d->h + y0 + k0, 1, (size_t)(k1 - k0));
}

/* Draw patch data p[0..size) into the column-major w x h picture at (ox, oy),
 * clipped (the columns outside it are not read). what names the lump. */
static int draw_patch(const bs_wadlook *L, const uint8_t *p, uint32_t size, const char *what, uint8_t *pic, int32_t w,
                      int32_t h, int32_t ox, int32_t oy, int cover, char *err, size_t errlen)
{
    tex_draw d = {pic, h, ox, oy};
    return bs_patch_walk(p, size, L->wad, what, -ox, w - ox, cover ? cover_post : tex_post, &d, err, errlen);
}

/* the texels of a patch: how many, and the sums of their colours' components */
typedef struct {
    const uint8_t *palette;
    uint64_t count;
    double sum[3];
} mean_acc;

static void mean_post(void *ctx, int32_t c, uint32_t top, const uint8_t *src, uint32_t len)
{
    (void)c;
    (void)top;
    mean_acc *m = ctx;
    m->count += len;
    for (uint32_t k = 0; k < len; k++)
        for (int g = 0; g < 3; g++) m->sum[g] += m->palette[3 * src[k] + g];
}

/* ---- wall textures ---- */

static const char *const texdef_lump[2] = {"TEXTURE1", "TEXTURE2"};

/* The number of definitions lump t declares, or -1 if they cannot fit it. */
static int64_t texdef_count(const bs_wadlook *L, int t)
{
    if (!L->tdef[t]) return 0;
    uint32_t n = rd32(L->tdef[t]);
    return n > (L->tdsize[t] - 4) / 4 ? -1 : (int64_t)n;
}

/* Index TEXTURE1 then TEXTURE2 once, in Doom's search order, up to the first
 * entry that a search would refuse (noted in bad_*): a name found in the index
 * is the one the search finds, and a name not in it meets the refusal first. */
static int index_texdefs(bs_wadlook *L)
{
    if (L->texdefs.e) return 0;
    int64_t n[2] = {texdef_count(L, 0), texdef_count(L, 1)};
    if (nt_init(&L->texdefs, (uint32_t)((n[0] > 0 ? n[0] : 0) + (n[1] > 0 ? n[1] : 0)))) return -1;
    L->texdef_n0 = n[0] > 0 ? (uint32_t)n[0] : 0;
    L->bad_kind = BAD_NONE;
    for (int t = 0; t < 2; t++) {
        if (n[t] < 0) {
            L->bad_kind = BAD_COUNT;
            L->bad_lump = t;
            return 0;
        }
        const uint8_t *d = L->tdef[t];
        uint32_t sz = L->tdsize[t];
        for (uint32_t i = 0; i < (uint32_t)n[t]; i++) {
            uint32_t o = rd32(d + 4 + 4 * i);
            if (o > sz || sz - o < 22) {
                L->bad_kind = BAD_ENTRY;
                L->bad_lump = t;
                L->bad_entry = i;
                return 0;
            }
            char nm[9];
            name8(nm, d + o);
            nt_put(&L->texdefs, nm, t ? L->texdef_n0 + i : i, 0);
        }
    }
    return 0;
}

/* Find name in TEXTURE1 then TEXTURE2 (the first definition wins, as in Doom):
 * the lump number (0, 1) and the definition's offset, or -1. */
static int find_texdef(bs_wadlook *L, const char *name, int *which, uint32_t *off, char *err, size_t errlen)
{
    if (index_texdefs(L)) return bs_fail(err, errlen, "%s: out of memory", L->wad);
    uint32_t k = nt_get(&L->texdefs, name);
    if (k != NT_NONE) {
        *which = k >= L->texdef_n0;
        uint32_t i = *which ? k - L->texdef_n0 : k;
        *off = rd32(L->tdef[*which] + 4 + 4 * i);
        return 1;
    }
    int t = L->bad_lump;
    uint32_t sz = L->tdsize[t];
    if (L->bad_kind == BAD_COUNT)
        return bs_fail(err, errlen, "%s: lump %s: %u textures do not fit its %u bytes", L->wad, texdef_lump[t],
                       rd32(L->tdef[t]), sz);
    if (L->bad_kind == BAD_ENTRY)
        return bs_fail(err, errlen, "%s: lump %s: texture %u at offset %u runs past the end (%u bytes)", L->wad,
                       texdef_lump[t], L->bad_entry, rd32(L->tdef[t] + 4 + 4 * L->bad_entry), sz);
    return 0;
}

/* The directory and the flats by name, once (the last of a name wins). */
static int index_lumps(bs_wadlook *L)
{
    if (L->lumps.e) return 0;
    if (nt_init(&L->lumps, L->ndir)) return -1;
    for (uint32_t i = 0; i < L->ndir; i++) nt_put(&L->lumps, L->dir[i].name, i, 1);
    return 0;
}

/* Wall texture name composed of its patches into a new w x h picture (*pic,
 * column-major; cover: 1 where a patch covers it, 0 in a hole). 1 if composed,
 * 0 if the WAD has no such texture, -1 with a message. */
static int compose_pic(bs_wadlook *L, const char *name, int cover, uint8_t **out, int32_t *pw, int32_t *ph, char *err,
                       size_t errlen)
{
    const char *const *lumpname = texdef_lump;
    if (index_lumps(L)) return bs_fail(err, errlen, "%s: out of memory", L->wad);
    int which = 0;
    uint32_t off = 0;
    *out = NULL;
    int f = find_texdef(L, name, &which, &off, err, errlen);
    if (f <= 0) return f;
    const uint8_t *d = L->tdef[which] + off;
    uint32_t room = L->tdsize[which] - off;
    int32_t w = rds16(d + 12), h = rds16(d + 14);
    uint32_t np = rd16(d + 20);
    if (w <= 0 || h <= 0 || w > 4096 || h > 4096)
        return bs_fail(err, errlen, "%s: lump %s: texture %s: size %d x %d", L->wad, lumpname[which], name, w, h);
    if (22u + 10u * np > room)
        return bs_fail(err, errlen, "%s: lump %s: texture %s: %u patches run past the end of the lump", L->wad,
                       lumpname[which], name, np);
    uint8_t *pic = calloc((size_t)w * (size_t)h, 1);
    if (!pic) return bs_fail(err, errlen, "%s: out of memory", L->wad);
    int rc = 0;
    for (uint32_t k = 0; k < np && rc == 0; k++) {
        const uint8_t *mp = d + 22 + 10 * k;
        int32_t ox = rds16(mp), oy = rds16(mp + 2);
        uint32_t pi = rd16(mp + 4);
        if (pi >= L->npnames) {
            rc = bs_fail(err, errlen, "%s: lump %s: texture %s: patch %u: PNAMES entry %u out of range (%u names)",
                         L->wad, lumpname[which], name, k, pi, L->npnames);
            break;
        }
        char pn[9];
        name8(pn, L->pnames + 4 + 8 * pi);
        uint32_t li = nt_get(&L->lumps, pn);
        if (li == NT_NONE) {
            rc = bs_fail(err, errlen, "%s: texture %s: patch %s (PNAMES entry %u) is not in the WAD", L->wad, name, pn,
                         pi);
            break;
        }
        uint8_t *p;
        rc = bs_wl_load_lump(L, li, 0, &p, err, errlen);
        if (rc == 0) rc = draw_patch(L, p, L->dir[li].size, pn, pic, w, h, ox, oy, cover, err, errlen);
        free(p);
    }
    if (rc < 0) {
        free(pic);
        return -1;
    }
    *out = pic;
    *pw = w;
    *ph = h;
    return 1;
}

static int compose_wall(bs_wadlook *L, const char *name, uint16_t *out, char *err, size_t errlen)
{
    uint8_t *pic;
    int32_t w, h;
    int f = compose_pic(L, name, 0, &pic, &w, &h, err, errlen);
    if (f <= 0) {
        *out = SCN_TEX_NONE;
        return f;
    }
    int rc = store(L, name, pic, (uint32_t)w, (uint32_t)h, out, err, errlen);
    free(pic);
    return rc < 0 ? -1 : 1;
}

int bs_look_mask(bs_wadlook *L, uint16_t tex, char *err, size_t errlen)
{
    bs_look *lk = L->lk;
    if (tex >= lk->ntex || lk->tex[tex].mask != SCN_TEX_NONE) return 0;
    const char *name = NULL;
    for (uint32_t i = 0; i < L->nused && !name; i++)
        if (L->used[i].kind == KIND_WALL && L->used[i].tex == tex) name = L->used[i].name;
    if (!name) return 0;
    uint8_t *pic;
    int32_t w, h;
    int f = compose_pic(L, name, 1, &pic, &w, &h, err, errlen);
    if (f <= 0) return f;
    /* the columns the texture shows (up to the largest power of two, as store keeps them) */
    int32_t shown = 1 << log2_floor((uint32_t)w);
    int holes = memchr(pic, 0, (size_t)shown * (size_t)h) != NULL;
    uint16_t m = SCN_TEX_NONE;
    int rc = holes ? store(L, name, pic, (uint32_t)w, (uint32_t)h, &m, err, errlen) : 0;
    free(pic);
    if (rc < 0) return -1;
    lk->tex[tex].mask = m;
    return 0;
}

/* ---- flats ---- */

static int is_flat_start(const char *n)
{
    return strcmp(n, "F_START") == 0 || strcmp(n, "FF_START") == 0;
}
static int is_flat_end(const char *n)
{
    return strcmp(n, "F_END") == 0 || strcmp(n, "FF_END") == 0;
}

/* the lumps between F_START/F_END or FF_START/FF_END, listed on the first call */
static int list_flats(bs_wadlook *L)
{
    if (L->flats) return 0;
    L->flats = malloc(sizeof *L->flats * (L->ndir + 1));
    if (!L->flats) return -1;
    int in = 0;
    for (uint32_t i = 0; i < L->ndir; i++) {
        const char *n = L->dir[i].name;
        if (is_flat_start(n))
            in = 1;
        else if (is_flat_end(n))
            in = 0;
        else if (in)
            L->flats[L->nflats++] = i;
    }
    if (nt_init(&L->flat_name, L->nflats)) {
        free(L->flats);
        L->flats = NULL;
        L->nflats = 0;
        return -1;
    }
    for (uint32_t k = 0; k < L->nflats; k++) nt_put(&L->flat_name, L->dir[L->flats[k]].name, L->flats[k], 1);
    return 0;
}

/* the last flat of that name between the markers, or ndir */
static uint32_t find_flat(const bs_wadlook *L, const char *name)
{
    uint32_t li = nt_get(&L->flat_name, name);
    return li == NT_NONE ? L->ndir : li;
}

static int compose_flat(bs_wadlook *L, const char *name, uint16_t *out, char *err, size_t errlen)
{
    if (list_flats(L)) return bs_fail(err, errlen, "%s: out of memory", L->wad);
    uint32_t li = find_flat(L, name);
    if (li == L->ndir) {
        *out = SCN_TEX_NONE;
        return 0;
    }
    uint8_t *p;
    if (bs_wl_load_lump(L, li, 4096, &p, err, errlen)) return -1;
    uint8_t pic[4096];
    for (int u = 0; u < 64; u++)
        for (int v = 0; v < 64; v++) pic[u * 64 + v] = p[v * 64 + u]; /* the lump is row-major */
    free(p);
    return store(L, name, pic, 64, 64, out, err, errlen) ? -1 : 1;
}

static int texture(bs_wadlook *L, const char *name, int kind, uint16_t *out, char *err, size_t errlen);

/* A frame of an animation, for bs_anim_store: stored as any texture is. */
static int anim_frame(void *ctx, int flat, const char *name, uint16_t *out, char *err, size_t errlen)
{
    return texture(ctx, name, flat ? KIND_FLAT : KIND_WALL, out, err, errlen);
}

/* A texture of this kind and name: its index, stored on first use; unknown
 * names and "-" give SCN_TEX_NONE (an unknown name warned once). The first use
 * of a frame of an animation stores its whole sequence, in order (anims.c). */
static int texture(bs_wadlook *L, const char *name, int kind, uint16_t *out, char *err, size_t errlen)
{
    *out = SCN_TEX_NONE;
    if (!name[0] || strcmp(name, "-") == 0) return 0;
    uint32_t h = bs_name_hash(name);
    for (uint32_t i = 0; i < L->nused; i++)
        if (L->used[i].hash == h && L->used[i].kind == kind && strcmp(L->used[i].name, name) == 0) {
            *out = L->used[i].tex;
            return 0;
        }
    const bs_anim_seq *q = L->anim_busy ? NULL : bs_anim_of(L->anims, kind == KIND_FLAT, name);
    if (q) {
        L->anim_busy = 1;
        int rc = bs_anim_store(q, L->lk, anim_frame, L, L->opt, L->wad, err, errlen);
        L->anim_busy = 0;
        return rc ? -1 : texture(L, name, kind, out, err, errlen);
    }
    bspc_look_cache *cache = L->opt->look_cache;
    const lc_entry *e = cache ? lc_find(cache, L->wadpath, kind, name) : NULL;
    int f;
    if (e) {
        f = e->known && store_kept(L, e, out, err, errlen) ? -1 : e->known;
    } else {
        f = kind == KIND_WALL ? compose_wall(L, name, out, err, errlen) : compose_flat(L, name, out, err, errlen);
        /* a cache out of memory only makes the next map compose it again */
        if (cache && f >= 0)
            (void)lc_put(cache, kind, name, f, f ? &L->lk->tex[*out] : NULL,
                         f ? L->lk->texels + L->lk->tex[*out].first : NULL);
    }
    if (f < 0) return -1;
    if (f == 0)
        bs_warn(L->opt, "%s: unknown %s '%s': drawn flat", L->wad, kind == KIND_WALL ? "texture" : "flat", name);
    if (bs_grow(&L->used, &L->ucap, L->nused + 1, sizeof *L->used))
        return bs_fail(err, errlen, "%s: out of memory", L->wad);
    used_name *u = &L->used[L->nused++];
    snprintf(u->name, sizeof u->name, "%s", name);
    u->hash = bs_name_hash(u->name);
    u->kind = kind;
    u->tex = *out;
    return 0;
}

/* ---- light ---- */

/* The light table at a middle distance (256 units) per docs/textures.md. */
static int middle_table(int lightnum, int wall)
{
    if (lightnum < 0) lightnum = 0;
    if (lightnum > 15) lightnum = 15;
    int start = (15 - lightnum) * 4;
    int t = wall ? start - 2560 / 256 / 2 : start - 160 / (256 / 16 + 1) / 2;
    return t < 0 ? 0 : t > SCN_LIGHT_MAPS - 1 ? SCN_LIGHT_MAPS - 1 : t;
}

static uint8_t lit(const bs_wadlook *L, uint16_t tex, int lightnum, int wall)
{
    uint8_t base = tex == SCN_TEX_NONE ? L->neutral : L->lk->tex[tex].colour;
    return L->lk->lights[middle_table(lightnum, wall) * 256 + base];
}

/* ---- the map ---- */

static const char *sky_for(const char *map)
{
    static const char *sky[4] = {"SKY1", "SKY2", "SKY3", "SKY4"};
    if (strncmp(map, "MAP", 3) == 0) {
        int n = atoi(map + 3);
        return n < 12 ? sky[0] : n < 21 ? sky[1] : sky[2];
    }
    if (map[0] == 'E' && map[1] >= '1' && map[1] <= '4') return sky[map[1] - '1'];
    return sky[0];
}

int bs_look_open(FILE *f, const char *wadpath, size_t flen, const bs_wadlump *dir, uint32_t ndir, const char *map,
                 bs_scene *s, uint32_t nsectors, uint32_t nlinedefs, const bspc_options *opt, bs_wadlook **out,
                 char *err, size_t errlen)
{
    *out = NULL;
    bs_wadlook tmp = {
        .f = f, .flen = flen, .dir = dir, .ndir = ndir, .wad = s->name, .opt = opt, .s = s, .lk = &s->look};
    static const char *need[] = {"PLAYPAL", "COLORMAP", "PNAMES", "TEXTURE1"};
    uint32_t at[4];
    char missing[64] = "";
    for (int i = 0; i < 4; i++) {
        at[i] = find_lump(&tmp, need[i], 0, ndir);
        if (at[i] == ndir) snprintf(missing + strlen(missing), sizeof missing - strlen(missing), " %s", need[i]);
    }
    tmp.wadpath = wadpath;
    if (missing[0]) {
        bs_note(opt, "%s: no%s in the WAD: the scene is flat-shaded", s->name, missing);
        return 0;
    }
    bs_wadlook *L = malloc(sizeof *L);
    if (!L) return bs_fail(err, errlen, "%s: out of memory", s->name);
    *L = tmp;
    bs_look *lk = &s->look;
    uint8_t *b = NULL;
    if (bs_wl_load_lump(L, at[0], 768, &b, err, errlen)) goto fail;
    memcpy(lk->palette, b, 768);
    free(b);
    if (bs_wl_load_lump(L, at[1], 256 * SCN_LIGHT_MAPS, &lk->lights, err, errlen)) goto fail;
    if (bs_wl_load_lump(L, at[2], 4, &L->pnames, err, errlen)) goto fail;
    L->npnames = rd32(L->pnames);
    if (L->npnames > (dir[at[2]].size - 4) / 8) {
        bs_fail(err, errlen, "%s: lump PNAMES: %u names do not fit its %u bytes", s->name, L->npnames, dir[at[2]].size);
        goto fail;
    }
    if (bs_wl_load_lump(L, at[3], 4, &L->tdef[0], err, errlen)) goto fail;
    L->tdsize[0] = dir[at[3]].size;
    uint32_t t2 = find_lump(L, "TEXTURE2", 0, ndir);
    if (t2 != ndir) {
        if (bs_wl_load_lump(L, t2, 4, &L->tdef[1], err, errlen)) goto fail;
        L->tdsize[1] = dir[t2].size;
    }
    if (!(L->anims = bs_anim_find(dir, ndir, L->tdef, L->tdsize, opt, s->name))) {
        bs_fail(err, errlen, "%s: out of memory", s->name);
        goto fail;
    }
    lk->doom_palette = 1;
    lk->sky_tex = SCN_TEX_NONE;
    L->sky_name = sky_for(map);
    L->neutral = nearest(lk->palette, 128, 128, 128);
    L->nlines_cap = nlinedefs;
    lk->sides = calloc(2 * (size_t)nlinedefs + 2, sizeof *lk->sides);
    lk->planes = calloc((size_t)nsectors + 1, sizeof *lk->planes);
    if (!lk->sides || !lk->planes) {
        bs_fail(err, errlen, "%s: out of memory", s->name);
        goto fail;
    }
    for (uint32_t i = 0; i < 2 * nlinedefs + 2; i++)
        lk->sides[i].tex[0] = lk->sides[i].tex[1] = lk->sides[i].tex[2] = SCN_TEX_NONE;
    /* model faces: Doom's fake contrast as one light level (4 tables) either way of the box's own colour */
    for (int c = 0; c < 256; c++) {
        lk->shade[0][c] = lk->lights[8 * 256 + c];
        lk->shade[1][c] = lk->lights[4 * 256 + c];
        lk->shade[2][c] = (uint8_t)c;
    }
    *out = L;
    return 0;
fail:
    bs_look_close(L);
    return -1;
}

int bs_look_sector(bs_wadlook *L, uint32_t i, const uint8_t rec[26], char *err, size_t errlen)
{
    bs_sector *c = &L->s->sectors[i];
    bs_look *lk = L->lk;
    char fl[9], ce[9];
    name8(fl, rec + 4);
    name8(ce, rec + 12);
    scn_plane *p = &lk->planes[i];
    if (texture(L, fl, KIND_FLAT, &p->floor_tex, err, errlen)) return -1;
    int lightnum = c->light >> 4;
    c->floor_color = lit(L, p->floor_tex, lightnum, 0);
    if (c->flags & SCN_SECTOR_SKY) {
        p->ceil_tex = SCN_TEX_NONE;
        if (lk->sky_tex == SCN_TEX_NONE) {
            uint16_t t;
            if (texture(L, L->sky_name, KIND_WALL, &t, err, errlen)) return -1;
            lk->sky_tex = t;
        }
        c->ceil_color = lk->sky_tex == SCN_TEX_NONE ? L->neutral : lk->tex[lk->sky_tex].colour;
    } else {
        if (texture(L, ce, KIND_FLAT, &p->ceil_tex, err, errlen)) return -1;
        c->ceil_color = lit(L, p->ceil_tex, lightnum, 0);
    }
    return 0;
}

int bs_look_side(bs_wadlook *L, uint32_t li, int k, const uint8_t rec[30], unsigned line_flags, char *err,
                 size_t errlen)
{
    bs_scene *s = L->s;
    bs_line *l = &s->lines[li];
    if (li >= L->nlines_cap) return bs_fail(err, errlen, "%s: internal error: side of line %u", L->wad, li);
    scn_side *sd = &L->lk->sides[2 * li + (uint32_t)k];
    char name[3][9];
    name8(name[SCN_PART_UPPER], rec + 4);
    name8(name[SCN_PART_LOWER], rec + 12);
    name8(name[SCN_PART_MIDDLE], rec + 20);
    for (int part = 0; part < 3; part++)
        if (texture(L, name[part], KIND_WALL, &sd->tex[part], err, errlen)) return -1;

    /* the column mapping: u(P) = U . (P - O) + xoff, O the side's first vertex */
    uint32_t o = k ? l->v2 : l->v1, e = k ? l->v1 : l->v2;
    double ox = s->vx[o] / 65536.0, oy = s->vy[o] / 65536.0;
    double dx = s->vx[e] / 65536.0 - ox, dy = s->vy[e] / 65536.0 - oy, len = sqrt(dx * dx + dy * dy);
    double one = 1073741824.0; /* 2^30 */
    sd->ux = (int32_t)llround(dx / len * one);
    sd->uy = (int32_t)llround(dy / len * one);
    double xoff = rds16(rec), yoff = rds16(rec + 2);
    /* every texture wraps at a power of two <= 1024 columns, so u0 is kept modulo
     * 1024 units: the same columns, and no overflow for far-off lines */
    double u0 = xoff * 65536.0 - ((double)sd->ux * s->vx[o] + (double)sd->uy * s->vy[o]) / one;
    int64_t m = 1024LL * 65536;
    int64_t iu = llround(u0) % m;
    sd->u0 = (int32_t)(iu < 0 ? iu + m : iu);
    sd->row_off = (int32_t)(yoff * 65536.0);
    sd->flags = (uint8_t)(((line_flags & 8u) ? SCN_SIDE_UNPEG_TOP : 0) |
                          ((line_flags & 16u) ? SCN_SIDE_UNPEG_BOTTOM : 0));
    sd->light_adj = (int8_t)(dy == 0 ? -1 : dx == 0 ? 1 : 0);

    int lightnum = (s->sectors[l->sector[k]].light >> 4) + sd->light_adj;
    uint8_t cm = lit(L, sd->tex[SCN_PART_MIDDLE], lightnum, 1);
    l->color[k][SCN_PART_MIDDLE] = cm;
    l->color[k][SCN_PART_UPPER] = sd->tex[SCN_PART_UPPER] == SCN_TEX_NONE
                                      ? cm
                                      : lit(L, sd->tex[SCN_PART_UPPER], lightnum, 1);
    l->color[k][SCN_PART_LOWER] = sd->tex[SCN_PART_LOWER] == SCN_TEX_NONE
                                      ? cm
                                      : lit(L, sd->tex[SCN_PART_LOWER], lightnum, 1);
    return 0;
}

/* ---- sprites ---- */

static int is_sprite_start(const char *n)
{
    return strcmp(n, "S_START") == 0 || strcmp(n, "SS_START") == 0;
}
static int is_sprite_end(const char *n)
{
    return strcmp(n, "S_END") == 0 || strcmp(n, "SS_END") == 0;
}

int bs_wl_list_sprites(bs_wadlook *L)
{
    if (L->sprites) return 0;
    L->sprites = malloc(sizeof *L->sprites * (L->ndir + 1));
    if (!L->sprites) return -1;
    int in = 0;
    for (uint32_t i = 0; i < L->ndir; i++) {
        const char *n = L->dir[i].name;
        if (is_sprite_start(n))
            in = 1;
        else if (is_sprite_end(n))
            in = 0;
        else if (in)
            L->sprites[L->nsprites++] = i;
    }
    return 0;
}

uint8_t bs_look_thing_colour(bs_wadlook *L, const char prefix[4], uint8_t fallback)
{
    if (!L->have_def_palette) {
        bs_palette(L->def_palette);
        L->have_def_palette = 1;
    }
    const uint8_t *def = L->def_palette;
    uint8_t colour = nearest(L->lk->palette, def[3 * fallback], def[3 * fallback + 1], def[3 * fallback + 2]);
    if (bs_wl_list_sprites(L)) return colour; /* out of memory: things.txt's colour */
    for (uint32_t k = 0; k < L->nsprites; k++) {
        uint32_t i = L->sprites[k];
        const char *n = L->dir[i].name;
        if (n[0] == prefix[0] && strncmp(n, prefix, 4) == 0 && n[4] == 'A' && (n[5] == '0' || n[5] == '1')) {
            uint8_t *p;
            char msg[300];
            mean_acc m = {L->lk->palette, 0, {0, 0, 0}};
            int rc = bs_wl_load_lump(L, i, 0, &p, msg, sizeof msg);
            if (rc == 0) rc = bs_patch_walk(p, L->dir[i].size, L->wad, n, 0, INT32_MAX, mean_post, &m, msg, sizeof msg);
            if (rc == 0 && m.count)
                colour = nearest(L->lk->palette, m.sum[0] / (double)m.count, m.sum[1] / (double)m.count,
                                 m.sum[2] / (double)m.count);
            else
                bs_warn(L->opt, "%s: sprite %s: %s; the box keeps things.txt's colour", L->wad, n,
                        rc ? msg : "no opaque pixels");
            free(p);
            break;
        }
    }
    return colour;
}

uint8_t bs_scene_shade(const bs_scene *s, uint8_t c, int delta)
{
    if (!s->look.doom_palette) return bs_shade(c, delta);
    return s->look.shade[delta < 0 ? 0 : delta > 0 ? 2 : 1][c];
}

void bs_look_close(bs_wadlook *L)
{
    if (!L) return;
    bs_look *lk = L->lk;
    if (lk->doom_palette && lk->ntex > 0 && !(L->opt && L->opt->flat)) lk->present = 1;
    free(L->pnames);
    free(L->tdef[0]);
    free(L->tdef[1]);
    free(L->used);
    free(L->flats);
    free(L->sprites);
    bs_wl_sprites_free(L);
    nt_free(&L->lumps);
    nt_free(&L->flat_name);
    nt_free(&L->texdefs);
    bs_anim_free(L->anims);
    free(L);
}
