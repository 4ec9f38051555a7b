/* wad.c - reader of Doom-format maps from a WAD file (IWAD or PWAD).
 *
 * A map is the marker lump (MAP01, E1M1, ...) followed by THINGS, LINEDEFS,
 * SIDEDEFS, VERTEXES, SEGS, SSECTORS, NODES, SECTORS, REJECT, BLOCKMAP in any
 * order; only THINGS, LINEDEFS, SIDEDEFS, VERTEXES and SECTORS are read (the
 * shipped nodes are ignored: this compiler builds its own). A BEHAVIOR lump
 * marks a Hexen-format map, which is refused. Every index is validated.
 *
 * Things listed in tools/bspc/things.txt (built in as things_txt.h) become
 * objects on box models, and sectors opened by door specials become doors
 * (docs/objects.md). The WAD's palette, textures, flats and sprites give the
 * scene its look and colours (wad_look.c, docs/textures.md).
 */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"
#include "things_txt.h" /* bs_things_txt[], bs_things_txt_len: tools/bspc/things.txt */

typedef bs_wadlump lump;

static uint16_t rd16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }
static int16_t rds16(const uint8_t *p) { return (int16_t)rd16(p); }
static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static const char *map_lumps[] = {"THINGS",  "LINEDEFS", "SIDEDEFS", "VERTEXES", "SEGS",
                                  "SSECTORS", "NODES",   "SECTORS",  "REJECT",   "BLOCKMAP",
                                  "BEHAVIOR", "SCRIPTS", NULL};

static int is_map_lump(const char *n)
{
    for (int i = 0; map_lumps[i]; i++)
        if (strcmp(n, map_lumps[i]) == 0) return 1;
    return 0;
}

/* read n bytes at offset pos */
static int read_at(FILE *f, uint32_t pos, uint32_t n, uint8_t *buf)
{
    if (fseek(f, (long)pos, SEEK_SET) != 0) return -1;
    return fread(buf, 1, n, f) == n ? 0 : -1;
}

/* texture/flat name field: 8 bytes, NUL padded, upper case */
static void name8(char out[9], const uint8_t *p)
{
    int i;
    for (i = 0; i < 8 && p[i]; i++) out[i] = (char)toupper(p[i]);
    out[i] = 0;
}

/* ---- things (docs/objects.md) ---- */

typedef struct {
    uint16_t type;
    int32_t radius, height; /* whole units */
    uint8_t colour;
    uint8_t table_colour; /* things.txt's colour: kinds share a model by it, as tools/refrender.py counts them */
    char sprite[4];  /* Doom's sprite name */
    int coloured;    /* colour taken from the sprite (or PLAYPAL's nearest) */
} thing_kind;

/* Parse the built-in table into kinds[] (at most cap); returns the count, or -1
 * with a message (a broken table is a build mistake, but it is reported). */
static int read_thing_table(thing_kind *kinds, int cap, char *err, size_t errlen)
{
    int n = 0, lineno = 0;
    size_t at = 0, len = bs_things_txt_len;
    while (at < len) {
        char line[256];
        size_t k = 0;
        while (at < len && bs_things_txt[at] != '\n') {
            if (k < sizeof line - 1) line[k++] = (char)bs_things_txt[at];
            at++;
        }
        at++;
        line[k] = 0;
        lineno++;
        char *hash = strchr(line, '#');
        if (hash) *hash = 0;
        char *col[7];
        int nc = 0;
        char *save = NULL;
        for (char *c = strtok_r(line, " \t\r", &save); c && nc < 7; c = strtok_r(NULL, " \t\r", &save))
            col[nc++] = c;
        if (nc == 0) continue;
        long v[3];
        int bad = nc != 6 || strlen(col[4]) != 4;
        for (int j = 0; j < 4 && !bad; j++) bad = !isupper((unsigned char)col[4][j]) && !isdigit((unsigned char)col[4][j]);
        for (int j = 0; j < 3 && !bad; j++) {
            char *end;
            errno = 0;
            v[j] = strtol(col[j], &end, 10);
            bad = *end || errno || v[j] < (j ? 1 : 0) || v[j] > (j == 0 ? 65535 : SCN_MODEL_MAX);
        }
        int colour = -1;
        if (!bad) {
            if (isdigit((unsigned char)col[3][0])) {
                char *end;
                long c = strtol(col[3], &end, 0);
                colour = (*end || c < 0 || c > 255) ? -1 : (int)c;
            } else {
                colour = bs_color_by_name(col[3]);
            }
            bad = colour < 0;
        }
        if (bad)
            return bs_fail(err, errlen, "things.txt:%d: expected 'type radius height colour sprite name' "
                           "(radius 1..%d)", lineno, SCN_MODEL_MAX);
        if (n == cap) return bs_fail(err, errlen, "things.txt: more than %d thing types", cap);
        kinds[n] = (thing_kind){(uint16_t)v[0], (int32_t)v[1], (int32_t)v[2], (uint8_t)colour, (uint8_t)colour, {0}, 0};
        memcpy(kinds[n++].sprite, col[4], 4);
    }
    return n;
}

#define THING_SKILL3 0x0002u  /* present on skill 3 ("hurt me plenty") */
#define THING_MULTI_ONLY 0x0010u

/* Things of listed types, on skill 3 and in single player, become objects, one
 * box model per distinct (radius, height, colour), models in order of first use. */
static int read_things(bs_scene *s, bs_wadlook *look, const uint8_t *recs, uint32_t count, const char *display,
                       const bspc_options *opt, char *err, size_t errlen)
{
    enum { MAX_KINDS = 512 };
    thing_kind *kinds = malloc(sizeof *kinds * MAX_KINDS);
    uint32_t *model_of = malloc(sizeof *model_of * MAX_KINDS);
    if (!kinds || !model_of) {
        free(kinds);
        free(model_of);
        return bs_fail(err, errlen, "%s: out of memory", display);
    }
    char msg[300];
    int nk = read_thing_table(kinds, MAX_KINDS, msg, sizeof msg);
    int rc = 0;
    if (nk < 0) {
        rc = bs_fail(err, errlen, "%s: %s", display, msg);
        goto done;
    }
    for (int k = 0; k < nk; k++) model_of[k] = SCN_NONE;
    uint32_t unknown = 0, skipped = 0;
    for (uint32_t i = 0; i < count; i++) {
        const uint8_t *r = recs + 10 * i;
        int x = rds16(r), y = rds16(r + 2), a = rds16(r + 4);
        uint16_t type = rd16(r + 6), flags = rd16(r + 8);
        int k;
        for (k = 0; k < nk; k++)
            if (kinds[k].type == type) break;
        if (k == nk) {
            if (type != 1 && type != 2 && type != 3 && type != 4 && type != 11 && type != 14) unknown++;
            continue;
        }
        if (!(flags & THING_SKILL3) || (flags & THING_MULTI_ONLY)) continue;
        if (x == -32768 || y == -32768) {
            bs_warn(opt, "%s: thing %u: coordinate -32768 out of range, left out", display, i);
            skipped++;
            continue;
        }
        if (look && !kinds[k].coloured) {
            kinds[k].colour = bs_look_thing_colour(look, kinds[k].sprite, kinds[k].colour);
            kinds[k].coloured = 1;
        }
        /* kinds sharing a size and things.txt colour share a model (the first one's sprite colours it) */
        for (int j = 0; j < nk && model_of[k] == SCN_NONE; j++)
            if (model_of[j] != SCN_NONE && kinds[j].radius == kinds[k].radius &&
                kinds[j].height == kinds[k].height && kinds[j].table_colour == kinds[k].table_colour)
                model_of[k] = model_of[j];
        if (model_of[k] == SCN_NONE) {
            bs_mpart p;
            memset(&p, 0, sizeof p);
            p.box = 1;
            p.sides = 4;
            p.w = p.d = kinds[k].radius * 2 * 65536;
            p.h = kinds[k].height * 65536;
            p.top = p.bottom = p.side = kinds[k].colour;
            if (bs_model_begin(s, NULL, 0, msg, sizeof msg) || bs_model_add_part(s, &p, msg, sizeof msg) ||
                bs_model_end(s, msg, sizeof msg)) {
                rc = bs_fail(err, errlen, "%s: thing type %u: %s", display, type, msg);
                goto done;
            }
            model_of[k] = s->nmodels - 1;
        }
        if (s->nobjects >= SCN_MAX_OBJECTS) {
            rc = bs_fail(err, errlen, "%s: more than %d things become objects", display, SCN_MAX_OBJECTS);
            goto done;
        }
        if (bs_grow(&s->objects, &s->ocap, s->nobjects + 1, sizeof *s->objects)) {
            rc = bs_fail(err, errlen, "%s: out of memory", display);
            goto done;
        }
        bs_object *o = &s->objects[s->nobjects++];
        memset(o, 0, sizeof *o);
        o->model = model_of[k];
        o->x = x * 65536;
        o->y = y * 65536;
        a %= 360;
        if (a < 0) a += 360;
        o->yaw = a * 65536;
        o->path = SCN_PATH_NONE;
        o->src_line = (int)i;
    }
    if (unknown) bs_note(opt, "%s: %u thing(s) of types not in things.txt left out", display, unknown);
    if (skipped) bs_note(opt, "%s: %u thing(s) out of range left out", display, skipped);
done:
    free(kinds);
    free(model_of);
    return rc;
}

/* ---- doors ---- */

static int is_manual_door(unsigned special)
{
    static const unsigned specials[] = {1, 26, 27, 28, 31, 32, 33, 34, 117, 118};
    for (size_t i = 0; i < sizeof specials / sizeof specials[0]; i++)
        if (special == specials[i]) return 1;
    return 0;
}

/* Sectors opened by a door special become doors: the back sector of a manual
 * door's line, or, for the switched and walked-over doors (63, 90), every
 * sector with the line's non-zero tag. A door opens to the lowest ceiling of
 * the sectors across its two-sided lines minus 4 (Doom's
 * P_FindLowestCeilingSurrounding), never below its closed ceiling. */
static int find_doors(bs_scene *s, const uint8_t *lines, uint32_t nl, const uint8_t *sides,
                      const uint8_t *sectors, const char *display, char *err, size_t errlen)
{
    uint32_t ns = s->nsectors;
    uint8_t *door = calloc(ns + 1, 1);
    int32_t *lowest = malloc(sizeof *lowest * (ns + 1));
    if (!door || !lowest) {
        free(door);
        free(lowest);
        return bs_fail(err, errlen, "%s: out of memory", display);
    }
    for (uint32_t i = 0; i < nl; i++) {
        const uint8_t *r = lines + 14 * i;
        unsigned special = rd16(r + 6), tag = rd16(r + 8), back = rd16(r + 12);
        if (is_manual_door(special)) {
            /* zero-length lines were skipped before their sectors were checked */
            if (back != 0xFFFF && rd16(sides + 30 * back + 28) < ns) door[rd16(sides + 30 * back + 28)] = 1;
        } else if ((special == 63 || special == 90) && tag != 0) {
            for (uint32_t k = 0; k < ns; k++)
                if (rd16(sectors + 26 * k + 24) == tag) door[k] = 1;
        }
    }
    for (uint32_t k = 0; k < ns; k++) lowest[k] = INT32_MAX;
    for (uint32_t i = 0; i < nl; i++) {
        const uint8_t *r = lines + 14 * i;
        unsigned front = rd16(r + 10), back = rd16(r + 12);
        if (back == 0xFFFF) continue;
        uint32_t a = rd16(sides + 30 * front + 28), b = rd16(sides + 30 * back + 28);
        if (a >= ns || b >= ns) continue;
        if (s->sectors[b].ceil_h < lowest[a]) lowest[a] = s->sectors[b].ceil_h;
        if (s->sectors[a].ceil_h < lowest[b]) lowest[b] = s->sectors[a].ceil_h;
    }
    for (uint32_t k = 0; k < ns; k++) {
        if (!door[k]) continue;
        bs_sector *c = &s->sectors[k];
        int32_t open = c->ceil_h;
        if (lowest[k] != INT32_MAX && lowest[k] - 4 * 65536 > open) open = lowest[k] - 4 * 65536;
        c->flags |= SCN_SECTOR_DOOR;
        c->open_h = open;
        s->ndoors++;
    }
    free(door);
    free(lowest);
    return 0;
}

int bs_read_wad(const char *wadpath, const char *map, const char *display, bs_scene *s,
                const bspc_options *opt, char *err, size_t errlen)
{
    snprintf(s->name, sizeof s->name, "%s", display);
    s->is_text = 0;
    s->player_sector = SCN_NONE;
    FILE *f = fopen(wadpath, "rb");
    if (!f) return bs_fail(err, errlen, "%s: cannot open %s: %s", display, wadpath, strerror(errno));
    int rc = -1;
    lump *dir = NULL;
    uint8_t *vused = NULL, *dirbuf = NULL;
    bs_wadlook *look = NULL;
    enum { L_THINGS, L_LINEDEFS, L_SIDEDEFS, L_VERTEXES, L_SECTORS, L_N };
    uint8_t *ld[L_N] = {0};
    uint8_t hdr[12];
    long flen = -1;
    if (fseek(f, 0, SEEK_END) == 0) flen = ftell(f);
    if (flen < 12 || read_at(f, 0, 12, hdr)) {
        bs_fail(err, errlen, "%s: %s is not a WAD file (%ld bytes, shorter than the 12-byte header)", display,
                wadpath, flen < 0 ? 0L : flen);
        goto out;
    }
    if (memcmp(hdr, "IWAD", 4) != 0 && memcmp(hdr, "PWAD", 4) != 0) {
        char magic[5];
        for (int i = 0; i < 4; i++) magic[i] = isprint(hdr[i]) ? (char)hdr[i] : '?';
        magic[4] = 0;
        bs_fail(err, errlen, "%s: %s is not a WAD file (header magic '%s', not IWAD or PWAD)", display, wadpath,
                magic);
        goto out;
    }
    size_t len = (size_t)flen;
    uint32_t nlumps = rd32(hdr + 4), dirofs = rd32(hdr + 8);
    if (dirofs > len || nlumps > (len - dirofs) / 16) {
        bs_fail(err, errlen, "%s: %s: lump directory (%u lumps at offset %u) runs past the end of "
                "the file (%zu bytes)", display, wadpath, nlumps, dirofs, len);
        goto out;
    }
    dir = calloc(nlumps + 1, sizeof *dir);
    dirbuf = malloc((size_t)nlumps * 16 + 1);
    if (!dir || !dirbuf) {
        bs_fail(err, errlen, "%s: out of memory", display);
        goto out;
    }
    if (read_at(f, dirofs, nlumps * 16, dirbuf)) {
        bs_fail(err, errlen, "%s: %s: cannot read the lump directory", display, wadpath);
        goto out;
    }
    for (uint32_t i = 0; i < nlumps; i++) {
        const uint8_t *e = dirbuf + 16 * i;
        dir[i].pos = rd32(e);
        dir[i].size = rd32(e + 4);
        name8(dir[i].name, e + 8);
    }
    char want[9];
    size_t ml = strlen(map);
    if (ml > 8) {
        bs_fail(err, errlen, "%s: map name '%s' is longer than 8 characters", display, map);
        goto out;
    }
    memset(want, 0, sizeof want);
    for (size_t i = 0; i < ml; i++) want[i] = (char)toupper((unsigned char)map[i]);
    uint32_t marker = nlumps;
    for (uint32_t i = nlumps; i-- > 0;) /* the last one wins, as in the engine */
        if (strcmp(dir[i].name, want) == 0) {
            marker = i;
            break;
        }
    if (marker == nlumps) {
        char maps[200];
        if (bspc_list_maps(wadpath, maps, sizeof maps, err, errlen) >= 0)
            bs_fail(err, errlen, "%s: no map %s in %s (its maps: %s)", display, want, wadpath, *maps ? maps : "none");
        goto out;
    }
    static const char *need[L_N] = {"THINGS", "LINEDEFS", "SIDEDEFS", "VERTEXES", "SECTORS"};
    static const uint32_t recsz[L_N] = {10, 14, 30, 4, 26};
    uint32_t cnt[L_N] = {0};
    for (uint32_t i = marker + 1; i < nlumps && is_map_lump(dir[i].name); i++) {
        if (strcmp(dir[i].name, "BEHAVIOR") == 0) {
            bs_fail(err, errlen, "%s: Hexen-format map (has a BEHAVIOR lump): only Doom-format maps "
                    "are supported", display);
            goto out;
        }
        for (int k = 0; k < L_N; k++) {
            if (strcmp(dir[i].name, need[k]) != 0 || ld[k]) continue;
            if (dir[i].pos > len || dir[i].size > len - dir[i].pos) {
                bs_fail(err, errlen, "%s: %s lump runs past the end of the file", display, need[k]);
                goto out;
            }
            if (dir[i].size % recsz[k] != 0) {
                bs_fail(err, errlen, "%s: %s lump size %u is not a multiple of %u bytes", display,
                        need[k], dir[i].size, recsz[k]);
                goto out;
            }
            ld[k] = malloc(dir[i].size + 1);
            if (!ld[k]) {
                bs_fail(err, errlen, "%s: out of memory", display);
                goto out;
            }
            if (read_at(f, dir[i].pos, dir[i].size, ld[k])) {
                bs_fail(err, errlen, "%s: cannot read the %s lump", display, need[k]);
                goto out;
            }
            cnt[k] = dir[i].size / recsz[k];
        }
    }
    for (int k = 0; k < L_N; k++)
        if (!ld[k]) {
            bs_fail(err, errlen, "%s: map has no %s lump", display, need[k]);
            goto out;
        }

    /* sectors */
    if (cnt[L_SECTORS] == 0) {
        bs_fail(err, errlen, "%s: map has no sectors", display);
        goto out;
    }
    if (bs_look_open(f, len, dir, nlumps, want, s, cnt[L_SECTORS], cnt[L_LINEDEFS], opt, &look, err, errlen))
        goto out;
    s->sectors = calloc(cnt[L_SECTORS], sizeof *s->sectors);
    if (!s->sectors) {
        bs_fail(err, errlen, "%s: out of memory", display);
        goto out;
    }
    s->scap = s->nsectors = cnt[L_SECTORS];
    for (uint32_t i = 0; i < cnt[L_SECTORS]; i++) {
        const uint8_t *r = ld[L_SECTORS] + 26 * i;
        bs_sector *c = &s->sectors[i];
        int fh = rds16(r), ch = rds16(r + 2);
        if (fh > SCN_HEIGHT_MAX || fh < -SCN_HEIGHT_MAX || ch > SCN_HEIGHT_MAX ||
            ch < -SCN_HEIGHT_MAX) {
            bs_fail(err, errlen, "%s: sector %u: floor %d / ceiling %d out of range (|height| <= %d)",
                    display, i, fh, ch, SCN_HEIGHT_MAX);
            goto out;
        }
        c->floor_h = fh * 65536;
        c->ceil_h = ch * 65536;
        int light = rds16(r + 20);
        if (light < 0) light = 0;
        if (light > 255) light = 255;
        c->light = (uint8_t)light;
        char fflat[9], cflat[9];
        name8(fflat, r + 4);
        name8(cflat, r + 12);
        c->floor_color = bs_flat_color(fflat, light, 0);
        if (strncmp(cflat, "F_SKY", 5) == 0) {
            c->flags |= SCN_SECTOR_SKY;
            c->ceil_color = bs_sky_color();
        } else {
            c->ceil_color = bs_flat_color(cflat, light, 1);
        }
        if (look && bs_look_sector(look, i, r, err, errlen)) goto out;
    }

    /* vertices: all of them, in lump order (unused ones are dropped by the build) */
    uint32_t nv = cnt[L_VERTEXES];
    s->vx = malloc(sizeof(int32_t) * (nv + 1));
    s->vy = malloc(sizeof(int32_t) * (nv + 1));
    vused = calloc(nv + 1, 1);
    if (!s->vx || !s->vy || !vused) {
        bs_fail(err, errlen, "%s: out of memory", display);
        goto out;
    }
    s->vcap = s->nverts = nv;
    for (uint32_t i = 0; i < nv; i++) {
        s->vx[i] = rds16(ld[L_VERTEXES] + 4 * i) * 65536;
        s->vy[i] = rds16(ld[L_VERTEXES] + 4 * i + 2) * 65536;
    }

    /* linedefs */
    uint32_t nl = cnt[L_LINEDEFS], nsd = cnt[L_SIDEDEFS];
    s->lines = calloc(nl + 1, sizeof *s->lines);
    if (!s->lines) {
        bs_fail(err, errlen, "%s: out of memory", display);
        goto out;
    }
    s->lcap = nl + 1;
    uint32_t skipped = 0;
    for (uint32_t i = 0; i < nl; i++) {
        const uint8_t *r = ld[L_LINEDEFS] + 14 * i;
        uint32_t v1 = rd16(r), v2 = rd16(r + 2);
        uint32_t sd[2] = {rd16(r + 10), rd16(r + 12)};
        if (v1 >= nv || v2 >= nv) {
            bs_fail(err, errlen, "%s: linedef %u: vertex %u out of range (have %u)", display, i,
                    v1 >= nv ? v1 : v2, nv);
            goto out;
        }
        if (sd[0] == 0xFFFF) {
            bs_fail(err, errlen, "%s: linedef %u: no front sidedef", display, i);
            goto out;
        }
        for (int k = 0; k < 2; k++)
            if (sd[k] != 0xFFFF && sd[k] >= nsd) {
                bs_fail(err, errlen, "%s: linedef %u: sidedef %u out of range (have %u)", display, i,
                        sd[k], nsd);
                goto out;
            }
        if (s->vx[v1] == s->vx[v2] && s->vy[v1] == s->vy[v2]) {
            bs_warn(opt, "%s: linedef %u: zero length, skipped", display, i);
            skipped++;
            continue;
        }
        bs_line *l = &s->lines[s->nlines];
        l->v1 = v1;
        l->v2 = v2;
        l->src_line = (int)i;
        l->sector[0] = l->sector[1] = SCN_NONE;
        int64_t dx = ((int64_t)s->vx[v2] - s->vx[v1]) / 65536, dy = ((int64_t)s->vy[v2] - s->vy[v1]) / 65536;
        /* fake contrast as in Doom: walls running east-west a shade lighter,
         * north-south a shade darker */
        int contrast = (dy == 0) ? 1 : (dx == 0) ? -1 : 0;
        for (int k = 0; k < 2; k++) {
            if (sd[k] == 0xFFFF) continue;
            const uint8_t *sr = ld[L_SIDEDEFS] + 30 * sd[k];
            uint32_t sec = rd16(sr + 28);
            if (sec >= s->nsectors) {
                bs_fail(err, errlen, "%s: linedef %u: sidedef %u: sector %u out of range (have %u)",
                        display, i, sd[k], sec, s->nsectors);
                goto out;
            }
            l->sector[k] = sec;
            int light = s->sectors[sec].light;
            char up[9], lo[9], mid[9];
            name8(up, sr + 4);
            name8(lo, sr + 12);
            name8(mid, sr + 20);
            int has_mid = mid[0] && strcmp(mid, "-") != 0;
            uint8_t cm = has_mid ? bs_wall_color(mid, light, contrast) : bs_neutral_color(light);
            l->color[k][SCN_PART_MIDDLE] = cm;
            l->color[k][SCN_PART_UPPER] =
                (up[0] && strcmp(up, "-") != 0) ? bs_wall_color(up, light, contrast) : cm;
            l->color[k][SCN_PART_LOWER] =
                (lo[0] && strcmp(lo, "-") != 0) ? bs_wall_color(lo, light, contrast) : cm;
            if (look && bs_look_side(look, s->nlines, k, sr, rd16(r + 4), err, errlen)) goto out;
        }
        vused[v1] = vused[v2] = 1;
        s->nlines++;
    }
    if (skipped) bs_note(opt, "%s: skipped %u zero-length linedef(s)", display, skipped);
    if (s->nlines == 0) {
        bs_fail(err, errlen, "%s: map has no linedefs", display);
        goto out;
    }
    for (uint32_t i = 0; i < nv; i++)
        if (vused[i] && s->vx[i] == -32768 * 65536) {
            bs_fail(err, errlen, "%s: vertex %u: x = -32768 out of range (|coordinate| <= %d)",
                    display, i, SCN_COORD_MAX);
            goto out;
        } else if (vused[i] && s->vy[i] == -32768 * 65536) {
            bs_fail(err, errlen, "%s: vertex %u: y = -32768 out of range (|coordinate| <= %d)",
                    display, i, SCN_COORD_MAX);
            goto out;
        }

    /* player 1 start: the last one, as in Doom (each spawns the player; the
     * earlier ones are left behind as "voodoo dolls") */
    for (uint32_t i = cnt[L_THINGS]; i-- > 0;) {
        const uint8_t *r = ld[L_THINGS] + 10 * i;
        if (rd16(r + 6) != 1) continue;
        int x = rds16(r), y = rds16(r + 2), a = rds16(r + 4);
        s->player_x = x * 65536;
        s->player_y = y * 65536;
        a %= 360;
        if (a < 0) a += 360;
        s->player_angle = a * 65536;
        s->has_player = 1;
        s->player_line = (int)i;
        if (x == -32768 || y == -32768) {
            bs_fail(err, errlen, "%s: thing %u (player start): coordinate out of range", display, i);
            goto out;
        }
        break;
    }
    if (!s->has_player) {
        bs_fail(err, errlen, "%s: no player start (no thing of type 1)", display);
        goto out;
    }
    /* every sidedef and sector index was checked by the linedef loop above */
    if (find_doors(s, ld[L_LINEDEFS], nl, ld[L_SIDEDEFS], ld[L_SECTORS], display, err, errlen)) goto out;
    if (read_things(s, look, ld[L_THINGS], cnt[L_THINGS], display, opt, err, errlen)) goto out;
    rc = 0;
out:
    bs_look_close(look);
    for (int k = 0; k < L_N; k++) free(ld[k]);
    free(vused);
    free(dir);
    free(dirbuf);
    fclose(f);
    return rc;
}
