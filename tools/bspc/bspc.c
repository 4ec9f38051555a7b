/* bspc.c - the compiler's library entry points (bspc.h): resolve the scene spec,
 * read and validate the scene, build the tree, remove T-junctions, write the blob. */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"
#include "crc32.h"
#include "geom.h"
#include "scene.h"
#include "scene_file.h"

bspc_options bspc_defaults(void)
{
    bspc_options o;
    o.split = BSPC_SPLIT_MIXED;
    o.verbose = 0;
    o.flat = 0;
    o.look_cache = NULL;
    return o;
}

static int readable(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    fclose(f);
    return 1;
}

int bspc_find_wad(const char *name, char *out, size_t outlen)
{
    if (!name || !*name || !out || outlen == 0) return -1;
    if (readable(name) || strchr(name, '/')) {
        if (!readable(name) || strlen(name) >= outlen) return -1;
        snprintf(out, outlen, "%s", name);
        return 0;
    }
    const char *dirs[2] = {getenv("DOOMWADDIR"), "/usr/share/games/doom"};
    for (int i = 0; i < 2; i++) {
        if (!dirs[i] || !*dirs[i]) continue;
        int n = snprintf(out, outlen, "%s/%s", dirs[i], name);
        if (n > 0 && (size_t)n < outlen && readable(out)) return 0;
    }
    return -1;
}

static int ends_with_wad(const char *s, size_t n)
{
    return n >= 4 && s[n - 4] == '.' && tolower((unsigned char)s[n - 3]) == 'w' &&
           tolower((unsigned char)s[n - 2]) == 'a' && tolower((unsigned char)s[n - 1]) == 'd';
}

bspc_spec_kind bspc_spec(const char *spec, size_t *wadlen)
{
    size_t sl = strlen(spec);
    const char *colon = strrchr(spec, ':');
    bspc_spec_kind k = BSPC_SPEC_FILE;
    if (colon && ends_with_wad(spec, (size_t)(colon - spec))) {
        k = BSPC_SPEC_WAD_MAP;
        sl = (size_t)(colon - spec);
    } else if (ends_with_wad(spec, sl)) {
        k = BSPC_SPEC_WAD;
    }
    if (wadlen) *wadlen = sl;
    return k;
}

int bspc_model_names(const char *spec, bspc_name **names)
{
    *names = NULL;
    if (bspc_spec(spec, NULL) != BSPC_SPEC_FILE || scene_file_probe(spec)) return 0;
    bs_scene s;
    memset(&s, 0, sizeof s);
    bspc_options opt = bspc_defaults();
    char err[8];
    int n = 0;
    if (bs_read_text(spec, &s, &opt, err, sizeof err) == 0 && s.nmodels > 0) {
        *names = malloc(sizeof **names * s.nmodels);
        n = *names ? (int)s.nmodels : -1;
        for (int i = 0; i < n; i++) snprintf((*names)[i].name, sizeof(*names)[i].name, "%s", s.models[i].name);
    }
    bs_scene_free(&s);
    return n;
}

static uint32_t walk_sector(const bs_tree *t, int32_t x, int32_t y)
{
    uint32_t n = t->root;
    while (n != SCN_NONE && !(n & SCN_LEAF_BIT)) {
        const bs_node *N = &t->nodes[n];
        n = N->child[bs_side(&t->plines[N->pline], N->rev, x, y) >= 0 ? 0 : 1];
    }
    return n == SCN_NONE ? SCN_NONE : t->leaves[n & ~SCN_LEAF_BIT].sector;
}

/* An object without a height rests on the floor under it: the floor of its
 * leaf's sector, as the renderer finds it (the player start does the same), or
 * by winding number where the leaf has no sector. A map thing in neither is
 * dropped. */
static void place_objects(bs_scene *s, const bs_tree *t, const bspc_options *opt)
{
    uint32_t kept = 0, dropped = 0;
    for (uint32_t i = 0; i < s->nobjects; i++) {
        bs_object o = s->objects[i];
        if (!o.has_z) {
            uint32_t sec = walk_sector(t, o.x, o.y);
            if (sec == SCN_NONE) sec = bs_point_sector(s, o.x, o.y);
            if (sec == SCN_NONE) {
                if (dropped++ < 10) bs_warn(opt, "%s: thing %d is inside no sector; left out", s->name, o.src_line);
                continue;
            }
            o.z = s->sectors[sec].floor_h;
            o.has_z = 1;
        }
        s->objects[kept++] = o;
    }
    if (dropped) bs_note(opt, "%s: %u thing(s) inside no sector left out", s->name, dropped);
    s->nobjects = kept;
}

/* a * b mod the CRC-32 polynomial, in crc_update's reflected bit order (bit 31
 * holds x^0) */
static uint32_t crc_mulmod(uint32_t a, uint32_t b)
{
    uint32_t p = 0;
    for (uint32_t m = 1u << 31; m; m >>= 1) {
        if (a & m) p ^= b;
        b = (b & 1u) ? (b >> 1) ^ 0xEDB88320u : b >> 1;
    }
    return p;
}

/* x^(8 n) mod the polynomial: what n bytes after a message multiply its CRC's
 * linear part by */
static uint32_t crc_zeros(uint64_t n)
{
    uint32_t r = 1u << 31, sq = 1u << 23; /* x^0, x^8 */
    for (; n; n >>= 1) {
        if (n & 1u) r = crc_mulmod(r, sq);
        sq = crc_mulmod(sq, sq);
    }
    return r;
}

/* The CRC of a message whose n bytes (n <= 256) changed from old to new, with
 * after more bytes behind them, from its CRC before and without reading the
 * rest: the CRC is linear, so the change adds the linear part of old ^ new,
 * carried through the bytes after it. */
static uint32_t crc_patch(uint32_t crc, const uint8_t *old, const uint8_t *new, uint32_t n, uint64_t after)
{
    uint8_t d[256], z[256] = {0};
    for (uint32_t i = 0; i < n; i++) d[i] = old[i] ^ new[i];
    return crc ^ crc_mulmod(crc_update(0, d, n) ^ crc_update(0, z, n), crc_zeros(after));
}

/* Analyse the blob just written (as the renderer will read it) and write what
 * it needs into its needs record; the CRC covers the record. */
static int fill_needs(const bs_scene *s, uint8_t *blob, size_t len, needs_report *r, char *err, size_t errlen)
{
    scene sc;
    scene_error se;
    if (scene_parse(&sc, blob, (uint32_t)len, &se) != SCENE_OK)
        return bs_fail(err, errlen, "%s: internal error: the compiled scene does not parse (%s, %s record %u)", s->name,
                       scene_status_text(se.status), scene_section_name(se.section), se.index);
    if (needs_analyse(&sc, !s->no_look, r)) return bs_fail(err, errlen, "%s: out of memory", s->name);
    const scn_header *h = (const scn_header *)(const void *)blob;
    uint32_t at = h->sec[SCN_SEC_NEEDS].offset, crc = h->crc32;
    _Static_assert(sizeof r->needs <= 256, "crc_patch takes up to 256 bytes");
    crc = crc_patch(crc, blob + at, (const uint8_t *)&r->needs, sizeof r->needs, len - at - sizeof r->needs);
    memcpy(blob + at, &r->needs, sizeof r->needs);
    memcpy(blob + 12, &crc, 4);
    return 0;
}

int bspc_compile(const char *spec, const bspc_options *opt_in, uint8_t **blob, size_t *len, bspc_stats *stats,
                 char *err, size_t errlen)
{
    bspc_options opt = opt_in ? *opt_in : bspc_defaults();
    if (err && errlen) err[0] = 0;
    if (!spec || !*spec || !blob || !len) return bs_fail(err, errlen, "bspc: no input scene given");
    *blob = NULL;
    *len = 0;

    bs_scene s;
    bs_tree t;
    memset(&s, 0, sizeof s);
    memset(&t, 0, sizeof t);
    int rc = -1;

    /* "file.wad:MAP01" or a text scene */
    size_t wl;
    bspc_spec_kind kind = bspc_spec(spec, &wl);
    if (kind != BSPC_SPEC_FILE) {
        char wadname[1024], path[1100];
        if (wl >= sizeof wadname) return bs_fail(err, errlen, "%s: file name too long", spec);
        memcpy(wadname, spec, wl);
        wadname[wl] = 0;
        if (bspc_find_wad(wadname, path, sizeof path))
            return bs_fail(err, errlen,
                           "%s: cannot find %s (looked in the current folder, "
                           "$DOOMWADDIR and /usr/share/games/doom)",
                           spec, wadname);
        if (kind == BSPC_SPEC_WAD || !spec[wl + 1]) {
            char maps[200];
            if (bspc_list_maps(wadname, maps, sizeof maps, err, errlen) < 0) return -1;
            if (kind == BSPC_SPEC_WAD)
                return bs_fail(err, errlen, "%s: name a map in the WAD as %s:MAP (its maps: %s)", spec, spec,
                               *maps ? maps : "none");
            return bs_fail(err, errlen, "%s: no map named after the ':' (its maps: %s)", spec, *maps ? maps : "none");
        }
        if (bs_read_wad(path, spec + wl + 1, spec, &s, &opt, err, errlen)) goto out;
    } else {
        if (bs_read_text(spec, &s, &opt, err, errlen)) goto out;
    }

    if (bs_check_ranges(&s, err, errlen)) goto out;
    if (s.is_text && bs_check_closed(&s, err, errlen)) goto out;
    if (bs_check_crossings(&s, err, errlen)) goto out;
    s.player_sector = bs_player_sector(&s);
    if (s.player_sector == SCN_NONE && s.is_text) {
        char b1[32], b2[32];
        bs_fail(err, errlen, "%s:%d: player at (%s, %s) is not inside any sector", s.name, s.player_line,
                bs_fxstr(s.player_x, b1), bs_fxstr(s.player_y, b2));
        goto out;
    }

    /* objects resting on the floor must stand in a sector (text scenes: an error) */
    for (uint32_t i = 0; s.is_text && i < s.nobjects; i++) {
        const bs_object *o = &s.objects[i];
        if (o->has_z || bs_point_sector(&s, o->x, o->y) != SCN_NONE) continue;
        char b1[32], b2[32];
        bs_fail(err, errlen, "%s:%d: object at (%s, %s) is not inside any sector (give z=Z)", s.name, o->src_line,
                bs_fxstr(o->x, b1), bs_fxstr(o->y, b2));
        goto out;
    }

    double t0 = bs_now_ms();
    if (bs_build(&s, &opt, &t, err, errlen)) goto out;
    double t_tree = bs_now_ms();
    if (bs_tjunc_segs(&t, s.name, err, errlen) || bs_tjunc_polys(&t, err, errlen)) goto out;
    double t_tj = bs_now_ms();

    if (bs_split_big_leaves(&t, s.name, err, errlen)) goto out;

    uint64_t dsum = 0;
    t.max_depth = 0;
    for (uint32_t i = 0; i < t.nleaves; i++) {
        dsum += t.leaves[i].depth;
        if (t.leaves[i].depth > t.max_depth) t.max_depth = t.leaves[i].depth;
    }
    t.mean_depth = t.nleaves ? (double)dsum / t.nleaves : 0.0;
    if (t.max_depth > SCN_MAX_DEPTH) {
        bs_fail(err, errlen, "%s: BSP tree %u nodes deep, deeper than %d (try --split balanced)", s.name, t.max_depth,
                SCN_MAX_DEPTH);
        goto out;
    }
    {
        /* the sector the renderer will find: that of the player's leaf (it can
         * differ from the winding-number answer in maps with overlapping sectors) */
        uint32_t walked = walk_sector(&t, s.player_x, s.player_y);
        if (s.player_sector == SCN_NONE)
            bs_warn(&opt,
                    "%s: player start is inside no closed sector; using the sector of its "
                    "leaf (%d)",
                    s.name, (int)walked);
        else if (walked != s.player_sector)
            bs_warn(&opt,
                    "%s: player start: sector %u by its walls, sector %u by its leaf; using "
                    "the leaf's",
                    s.name, s.player_sector, walked);
        if (walked != SCN_NONE) s.player_sector = walked;
    }
    place_objects(&s, &t, &opt);
    bs_sprites_prune(&s);
    if (bs_write_blob(&s, &t, blob, len, err, errlen)) goto out;
    needs_report needs;
    if (fill_needs(&s, *blob, *len, &needs, err, errlen)) goto out;
    double t1 = bs_now_ms();
    bs_note(&opt, "%s: times: tree %.2f ms, T-junctions %.2f ms, blob %.2f ms", s.name, t_tree - t0, t_tj - t_tree,
            t1 - t_tj);

    bs_note(&opt,
            "%s: %u linedefs, %u segs (%u partition splits, %u T-junction splits), %u nodes, "
            "%u leaves, %u vertices, depth %u (mean %.2f), %u polygon vertices inserted, %.2f ms",
            s.name, s.nlines, t.nsegs, t.part_splits, t.tj_splits, t.nnodes, t.nleaves, t.nverts, t.max_depth,
            t.mean_depth, t.tj_pverts, t1 - t0);
    bs_note(&opt, "%s: %u models (%u vertices, %u faces), %u objects, %u doors", s.name, s.nmodels, s.nmverts, s.nfaces,
            s.nobjects, s.ndoors);
    if (s.look.present && s.look.nsprsets)
        bs_note(&opt, "%s: %u sprite sets, %u sprite images", s.name, s.look.nsprsets, s.look.nsprites);
    if (stats) {
        memset(stats, 0, sizeof *stats);
        stats->input_walls = s.nlines;
        stats->segs = t.nsegs;
        stats->splits = t.part_splits; /* T-junction pieces are in segs, not here */
        stats->leaves = t.nleaves;
        stats->nodes = t.nnodes;
        stats->vertices = t.nverts;
        stats->max_depth = t.max_depth;
        stats->mean_depth = t.mean_depth;
        stats->build_ms = t1 - t0;
        stats->models = s.nmodels;
        stats->objects = s.nobjects;
        stats->doors = s.ndoors;
        if (s.look.present) {
            const bs_look *lk = &s.look;
            stats->sprites = lk->nsprites;
            stats->sprite_sets = lk->nsprsets;
            for (uint32_t i = 0; i < lk->nsprites; i++)
                stats->sprite_texels += (uint64_t)lk->sprites[i].width * lk->sprites[i].height;
            stats->sprite_mask_bytes = 4ull * lk->nsprmask;
            stats->sprite_bytes = stats->sprite_texels + stats->sprite_mask_bytes + sizeof(scn_sprite) * lk->nsprites +
                                  sizeof(scn_sprset) * lk->nsprsets;
        }
        stats->needs = needs;
    }
    rc = 0;
out:
    if (rc) { /* a refusal hands back no blob (one may have been written before the failing step) */
        free(*blob);
        *blob = NULL;
        *len = 0;
    }
    bs_tree_free(&t);
    bs_scene_free(&s);
    return rc;
}
