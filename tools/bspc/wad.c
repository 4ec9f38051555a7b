/* wad.c - reader of Doom-format maps from a WAD file (IWAD or PWAD).
 *
 * A map is the marker lump (MAP01, E1M1, ...) followed by THINGS, LINEDEFS,
 * SIDEDEFS, VERTEXES, SEGS, SSECTORS, NODES, SECTORS, REJECT, BLOCKMAP in any
 * order; only THINGS, LINEDEFS, SIDEDEFS, VERTEXES and SECTORS are read (the
 * shipped nodes are ignored: this compiler builds its own). A BEHAVIOR lump
 * marks a Hexen-format map, which is refused. Every index is validated.
 *
 * Things listed in tools/bspc/things.txt (built in as things_txt.h) become
 * objects on box models, drawn as their sprites in a textured scene
 * (sprites.c), and sectors opened by door specials become doors
 * (docs/objects.md). The WAD's palette, textures, flats and sprites give the
 * scene its look and colours (wad_look.c, docs/textures.md).
 */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "anims.h"
#include "bspc_int.h"
#include "wad_bytes.h"
#include "things_txt.h" /* bs_things_txt[], bs_things_txt_len: tools/bspc/things.txt */

typedef bs_wadlump lump;

static const char *map_lumps[] = {"THINGS",  "LINEDEFS", "SIDEDEFS", "VERTEXES", "SEGS",    "SSECTORS", "NODES",
                                  "SECTORS", "REJECT",   "BLOCKMAP", "BEHAVIOR", "SCRIPTS", NULL};

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

/* ---- things (docs/objects.md) ---- */

typedef struct {
    uint16_t type;
    int32_t radius, height; /* whole units */
    uint8_t colour;
    uint8_t table_colour; /* things.txt's colour: kinds share a model by it, as tools/refrender.py counts them */
    char sprite[4];       /* Doom's sprite name */
    char frame;           /* the letter of its spawn state's frame */
    uint8_t sprflags;     /* SCN_SPRSET_BRIGHT: that state is full-bright */
    int coloured;         /* colour taken from the sprite (or PLAYPAL's nearest) */
    int looked;           /* its sprite set was asked for (sprset1, mr, mh set) */
    uint32_t sprset1;     /* 1 + its sprite set; 0: drawn as its box */
    int32_t mr, mh;       /* its model's radius and height: the table's, or the box around its sprite */
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
        char *col[8];
        int nc = 0;
        char *save = NULL;
        for (char *c = strtok_r(line, " \t\r", &save); c && nc < 8; c = strtok_r(NULL, " \t\r", &save)) col[nc++] = c;
        if (nc == 0) continue;
        long v[3];
        int bad = nc != 7 || strlen(col[4]) != 4;
        /* the frame: a letter, '*' after it when full-bright */
        if (!bad) bad = !(col[5][0] >= 'A' && col[5][0] <= 'Z') || (col[5][1] && (col[5][1] != '*' || col[5][2]));
        for (int j = 0; j < 4 && !bad; j++)
            bad = !isupper((unsigned char)col[4][j]) && !isdigit((unsigned char)col[4][j]);
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
            return bs_fail(err, errlen,
                           "things.txt:%d: expected 'type radius height colour sprite frame name' "
                           "(radius 1..%d, frame a letter A..Z, '*' after it when full-bright)",
                           lineno, SCN_MODEL_MAX);
        if (n == cap) return bs_fail(err, errlen, "things.txt: more than %d thing types", cap);
        thing_kind *t = &kinds[n++];
        memset(t, 0, sizeof *t);
        t->type = (uint16_t)v[0];
        t->radius = t->mr = (int32_t)v[1];
        t->height = t->mh = (int32_t)v[2];
        t->colour = t->table_colour = (uint8_t)colour;
        memcpy(t->sprite, col[4], 4);
        t->frame = col[5][0];
        t->sprflags = col[5][1] == '*' ? SCN_SPRSET_BRIGHT : 0;
    }
    return n;
}

#define THING_SKILL3 0x0002u /* present on skill 3 ("hurt me plenty") */
#define THING_MULTI_ONLY 0x0010u

/* Things of listed types, on skill 3 and in single player, become objects, one
 * box model per distinct (radius, height, colour), models in order of first use.
 * In a textured scene a type drawn as its sprite has the box around its images
 * (docs/objects.md, "Sprites"). */
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
        thing_kind *t = &kinds[k];
        if (look && !t->coloured) {
            t->colour = bs_look_thing_colour(look, t->sprite, t->colour);
            t->coloured = 1;
        }
        if (look && !t->looked) {
            int32_t sr = 0, sh = 0;
            if (bs_look_thing_sprite(look, t->sprite, t->frame, t->sprflags, &t->sprset1, &sr, &sh, msg, sizeof msg)) {
                rc = bs_fail(err, errlen, "%s", msg);
                goto done;
            }
            if (t->sprset1) {
                t->mr = sr;
                t->mh = sh;
            }
            t->looked = 1;
        }
        /* kinds sharing a size and things.txt colour share a model (the first one's sprite colours it) */
        for (int j = 0; j < nk && model_of[k] == SCN_NONE; j++)
            if (model_of[j] != SCN_NONE && kinds[j].mr == t->mr && kinds[j].mh == t->mh &&
                kinds[j].table_colour == t->table_colour)
                model_of[k] = model_of[j];
        if (model_of[k] == SCN_NONE) {
            bs_mpart p;
            memset(&p, 0, sizeof p);
            p.box = 1;
            p.sides = 4;
            p.w = p.d = t->mr * 2 * 65536;
            p.h = t->mh * 65536;
            p.top = p.bottom = p.side = t->colour;
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
        o->sprset1 = t->sprset1;
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
static int find_doors(bs_scene *s, const uint8_t *lines, uint32_t nl, const uint8_t *sides, const uint8_t *sectors,
                      const char *display, char *err, size_t errlen)
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

/* ---- the map's lumps ---- */

enum { L_THINGS, L_LINEDEFS, L_SIDEDEFS, L_VERTEXES, L_SECTORS, L_N };
static const char *const need[L_N] = {"THINGS", "LINEDEFS", "SIDEDEFS", "VERTEXES", "SECTORS"};

/* One map being read: the open WAD, its directory and the lumps read so far,
 * shared by the per-lump readers below (as Doom's P_Load* share the level). */
typedef struct {
    FILE *f;
    size_t len; /* file size */
    const char *wadpath, *display;
    const bspc_options *opt;
    char *err;
    size_t errlen;
    lump *dir;
    uint8_t *dirbuf;
    uint32_t nlumps;
    char want[9];      /* the map marker's name, upper case */
    uint8_t *ld[L_N];  /* the lumps this reader uses, NULL until found */
    uint32_t cnt[L_N]; /* their record counts */
    uint8_t *vused;    /* [nverts]: the vertex ends a kept linedef */
    bs_wadlook *look;  /* textures and light tables; NULL with --flat */
    uint8_t *scroll;   /* [nsidedefs]: moved by a scrolling line (anims.h), or NULL: none is */
} wad_map;

/* The 12-byte header and the lump directory. */
static int wad_read_dir(wad_map *m)
{
    uint8_t hdr[12];
    long flen = -1;
    if (fseek(m->f, 0, SEEK_END) == 0) flen = ftell(m->f);
    if (flen < 12 || read_at(m->f, 0, 12, hdr))
        return bs_fail(m->err, m->errlen, "%s: %s is not a WAD file (%ld bytes, shorter than the 12-byte header)",
                       m->display, m->wadpath, flen < 0 ? 0L : flen);
    if (memcmp(hdr, "IWAD", 4) != 0 && memcmp(hdr, "PWAD", 4) != 0) {
        char magic[5];
        for (int i = 0; i < 4; i++) magic[i] = isprint(hdr[i]) ? (char)hdr[i] : '?';
        magic[4] = 0;
        return bs_fail(m->err, m->errlen, "%s: %s is not a WAD file (header magic '%s', not IWAD or PWAD)", m->display,
                       m->wadpath, magic);
    }
    m->len = (size_t)flen;
    uint32_t nlumps = rd32(hdr + 4), dirofs = rd32(hdr + 8);
    if (dirofs > m->len || nlumps > (m->len - dirofs) / 16)
        return bs_fail(m->err, m->errlen,
                       "%s: %s: lump directory (%u lumps at offset %u) runs past the end of "
                       "the file (%zu bytes)",
                       m->display, m->wadpath, nlumps, dirofs, m->len);
    m->nlumps = nlumps;
    m->dir = calloc(nlumps + 1, sizeof *m->dir);
    m->dirbuf = malloc((size_t)nlumps * 16 + 1);
    if (!m->dir || !m->dirbuf) return bs_fail(m->err, m->errlen, "%s: out of memory", m->display);
    if (read_at(m->f, dirofs, nlumps * 16, m->dirbuf))
        return bs_fail(m->err, m->errlen, "%s: %s: cannot read the lump directory", m->display, m->wadpath);
    for (uint32_t i = 0; i < nlumps; i++) {
        const uint8_t *e = m->dirbuf + 16 * i;
        m->dir[i].pos = rd32(e);
        m->dir[i].size = rd32(e + 4);
        name8(m->dir[i].name, e + 8);
    }
    return 0;
}

/* The index of the map's marker lump, or -1 with a message naming the maps
 * the WAD has. */
static int64_t wad_find_marker(wad_map *m, const char *map)
{
    size_t ml = strlen(map);
    if (ml > 8) return bs_fail(m->err, m->errlen, "%s: map name '%s' is longer than 8 characters", m->display, map);
    memset(m->want, 0, sizeof m->want);
    for (size_t i = 0; i < ml; i++) m->want[i] = (char)toupper((unsigned char)map[i]);
    for (uint32_t i = m->nlumps; i-- > 0;) /* the last one wins, as in the engine */
        if (strcmp(m->dir[i].name, m->want) == 0) return i;
    char maps[200];
    if (bspc_list_maps(m->wadpath, maps, sizeof maps, m->err, m->errlen) >= 0)
        bs_fail(m->err, m->errlen, "%s: no map %s in %s (its maps: %s)", m->display, m->want, m->wadpath,
                *maps ? maps : "none");
    return -1;
}

/* Read lump i as lump kind k, checking it lies in the file and holds whole records. */
static int wad_read_lump(wad_map *m, uint32_t i, int k)
{
    static const uint32_t recsz[L_N] = {10, 14, 30, 4, 26};
    const lump *d = &m->dir[i];
    if (d->pos > m->len || d->size > m->len - d->pos)
        return bs_fail(m->err, m->errlen, "%s: %s lump runs past the end of the file", m->display, need[k]);
    if (d->size % recsz[k] != 0)
        return bs_fail(m->err, m->errlen, "%s: %s lump size %u is not a multiple of %u bytes", m->display, need[k],
                       d->size, recsz[k]);
    m->ld[k] = malloc(d->size + 1);
    if (!m->ld[k]) return bs_fail(m->err, m->errlen, "%s: out of memory", m->display);
    if (read_at(m->f, d->pos, d->size, m->ld[k]))
        return bs_fail(m->err, m->errlen, "%s: cannot read the %s lump", m->display, need[k]);
    m->cnt[k] = d->size / recsz[k];
    return 0;
}

/* The lumps after the marker, up to the first one that is not a map lump:
 * the first of each kind this reader uses is read; all must be there. */
static int wad_read_map_lumps(wad_map *m, uint32_t marker)
{
    for (uint32_t i = marker + 1; i < m->nlumps && is_map_lump(m->dir[i].name); i++) {
        if (strcmp(m->dir[i].name, "BEHAVIOR") == 0)
            return bs_fail(m->err, m->errlen,
                           "%s: Hexen-format map (has a BEHAVIOR lump): only Doom-format maps "
                           "are supported",
                           m->display);
        for (int k = 0; k < L_N; k++)
            if (strcmp(m->dir[i].name, need[k]) == 0 && !m->ld[k] && wad_read_lump(m, i, k)) return -1;
    }
    for (int k = 0; k < L_N; k++)
        if (!m->ld[k]) return bs_fail(m->err, m->errlen, "%s: map has no %s lump", m->display, need[k]);
    return 0;
}

/* Sectors: heights, light, flat colours and the sky (P_LoadSectors). */
static int wad_load_sectors(wad_map *m, bs_scene *s)
{
    uint32_t n = m->cnt[L_SECTORS];
    s->sectors = calloc(n, sizeof *s->sectors);
    if (!s->sectors) return bs_fail(m->err, m->errlen, "%s: out of memory", m->display);
    s->scap = s->nsectors = n;
    for (uint32_t i = 0; i < n; i++) {
        const uint8_t *r = m->ld[L_SECTORS] + 26 * i;
        bs_sector *c = &s->sectors[i];
        int fh = rds16(r), ch = rds16(r + 2);
        if (fh > SCN_HEIGHT_MAX || fh < -SCN_HEIGHT_MAX || ch > SCN_HEIGHT_MAX || ch < -SCN_HEIGHT_MAX)
            return bs_fail(m->err, m->errlen, "%s: sector %u: floor %d / ceiling %d out of range (|height| <= %d)",
                           m->display, i, fh, ch, SCN_HEIGHT_MAX);
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
        if (m->look && bs_look_sector(m->look, i, r, m->err, m->errlen)) return -1;
    }
    return 0;
}

/* Vertices: all of them, in lump order (unused ones are dropped by the build;
 * only the used ones are range-checked, by wad_check_vertexes). */
static int wad_load_vertexes(wad_map *m, bs_scene *s)
{
    uint32_t nv = m->cnt[L_VERTEXES];
    s->vx = malloc(sizeof(int32_t) * (nv + 1));
    s->vy = malloc(sizeof(int32_t) * (nv + 1));
    m->vused = calloc(nv + 1, 1);
    if (!s->vx || !s->vy || !m->vused) return bs_fail(m->err, m->errlen, "%s: out of memory", m->display);
    s->vcap = s->nverts = nv;
    for (uint32_t i = 0; i < nv; i++) {
        s->vx[i] = rds16(m->ld[L_VERTEXES] + 4 * i) * 65536;
        s->vy[i] = rds16(m->ld[L_VERTEXES] + 4 * i + 2) * 65536;
    }
    return 0;
}

/* One side of linedef i (scene line l): its sector and wall colours
 * (P_LoadSideDefs); sd was range-checked by the caller. */
static int wad_load_side(wad_map *m, bs_scene *s, bs_line *l, uint32_t i, int k, uint32_t sd, int contrast,
                         unsigned line_flags)
{
    const uint8_t *sr = m->ld[L_SIDEDEFS] + 30 * sd;
    uint32_t sec = rd16(sr + 28);
    if (sec >= s->nsectors)
        return bs_fail(m->err, m->errlen, "%s: linedef %u: sidedef %u: sector %u out of range (have %u)", m->display, i,
                       sd, sec, s->nsectors);
    l->sector[k] = sec;
    int light = s->sectors[sec].light;
    char up[9], lo[9], mid[9];
    name8(up, sr + 4);
    name8(lo, sr + 12);
    name8(mid, sr + 20);
    int has_mid = mid[0] && strcmp(mid, "-") != 0;
    uint8_t cm = has_mid ? bs_wall_color(mid, light, contrast) : bs_neutral_color(light);
    l->color[k][SCN_PART_MIDDLE] = cm;
    l->color[k][SCN_PART_UPPER] = (up[0] && strcmp(up, "-") != 0) ? bs_wall_color(up, light, contrast) : cm;
    l->color[k][SCN_PART_LOWER] = (lo[0] && strcmp(lo, "-") != 0) ? bs_wall_color(lo, light, contrast) : cm;
    if (m->look && bs_look_side(m->look, s->nlines, k, sr, line_flags, m->err, m->errlen)) return -1;
    if (m->look && m->scroll && m->scroll[sd]) s->look.sides[2 * s->nlines + (uint32_t)k].flags |= SCN_SIDE_SCROLL;
    return 0;
}

/* Linedef i becomes the next scene line unless it has zero length (then 1 is
 * returned); its vertex and sidedef indices are checked first (P_LoadLineDefs). */
static int wad_load_linedef(wad_map *m, bs_scene *s, uint32_t i)
{
    const uint8_t *r = m->ld[L_LINEDEFS] + 14 * i;
    uint32_t nv = s->nverts, nsd = m->cnt[L_SIDEDEFS];
    uint32_t v1 = rd16(r), v2 = rd16(r + 2);
    uint32_t sd[2] = {rd16(r + 10), rd16(r + 12)};
    if (v1 >= nv || v2 >= nv)
        return bs_fail(m->err, m->errlen, "%s: linedef %u: vertex %u out of range (have %u)", m->display, i,
                       v1 >= nv ? v1 : v2, nv);
    if (sd[0] == 0xFFFF) return bs_fail(m->err, m->errlen, "%s: linedef %u: no front sidedef", m->display, i);
    for (int k = 0; k < 2; k++)
        if (sd[k] != 0xFFFF && sd[k] >= nsd)
            return bs_fail(m->err, m->errlen, "%s: linedef %u: sidedef %u out of range (have %u)", m->display, i, sd[k],
                           nsd);
    if (s->vx[v1] == s->vx[v2] && s->vy[v1] == s->vy[v2]) {
        bs_warn(m->opt, "%s: linedef %u: zero length, skipped", m->display, i);
        return 1;
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
    for (int k = 0; k < 2; k++)
        if (sd[k] != 0xFFFF && wad_load_side(m, s, l, i, k, sd[k], contrast, rd16(r + 4))) return -1;
    m->vused[v1] = m->vused[v2] = 1;
    s->nlines++;
    return 0;
}

/* Linedefs with their sidedefs; zero-length ones are left out with a note. */
static int wad_load_linedefs(wad_map *m, bs_scene *s)
{
    uint32_t nl = m->cnt[L_LINEDEFS];
    s->lines = calloc(nl + 1, sizeof *s->lines);
    if (!s->lines) return bs_fail(m->err, m->errlen, "%s: out of memory", m->display);
    s->lcap = nl + 1;
    uint32_t skipped = 0;
    for (uint32_t i = 0; i < nl; i++) {
        int r = wad_load_linedef(m, s, i);
        if (r < 0) return -1;
        skipped += (uint32_t)r;
    }
    if (skipped) bs_note(m->opt, "%s: skipped %u zero-length linedef(s)", m->display, skipped);
    if (s->nlines == 0) return bs_fail(m->err, m->errlen, "%s: map has no linedefs", m->display);
    return 0;
}

/* -32768 has no negation in 16 bits, so a used vertex may not sit there
 * (|coordinate| <= SCN_COORD_MAX). */
static int wad_check_vertexes(wad_map *m, const bs_scene *s)
{
    for (uint32_t i = 0; i < s->nverts; i++)
        if (m->vused[i] && s->vx[i] == -32768 * 65536)
            return bs_fail(m->err, m->errlen, "%s: vertex %u: x = -32768 out of range (|coordinate| <= %d)", m->display,
                           i, SCN_COORD_MAX);
        else if (m->vused[i] && s->vy[i] == -32768 * 65536)
            return bs_fail(m->err, m->errlen, "%s: vertex %u: y = -32768 out of range (|coordinate| <= %d)", m->display,
                           i, SCN_COORD_MAX);
    return 0;
}

/* Player 1 start: the last one, as in Doom (each spawns the player; the
 * earlier ones are left behind as "voodoo dolls"). */
static int wad_load_player(wad_map *m, bs_scene *s)
{
    for (uint32_t i = m->cnt[L_THINGS]; i-- > 0;) {
        const uint8_t *r = m->ld[L_THINGS] + 10 * i;
        if (rd16(r + 6) != 1) continue;
        int x = rds16(r), y = rds16(r + 2), a = rds16(r + 4);
        s->player_x = x * 65536;
        s->player_y = y * 65536;
        a %= 360;
        if (a < 0) a += 360;
        s->player_angle = a * 65536;
        s->has_player = 1;
        s->player_line = (int)i;
        if (x == -32768 || y == -32768)
            return bs_fail(m->err, m->errlen, "%s: thing %u (player start): coordinate out of range", m->display, i);
        return 0;
    }
    return bs_fail(m->err, m->errlen, "%s: no player start (no thing of type 1)", m->display);
}

/* The map's lumps, read in P_SetupLevel's spirit: sectors first (the sides
 * refer to them), then vertices, linedefs with their sides, the player, the
 * doors and the things. */
static int wad_load_map(wad_map *m, const char *map, bs_scene *s)
{
    if (wad_read_dir(m)) return -1;
    int64_t marker = wad_find_marker(m, map);
    if (marker < 0 || wad_read_map_lumps(m, (uint32_t)marker)) return -1;
    if (m->cnt[L_SECTORS] == 0) return bs_fail(m->err, m->errlen, "%s: map has no sectors", m->display);
    if (bs_look_open(m->f, m->wadpath, m->len, m->dir, m->nlumps, m->want, s, m->cnt[L_SECTORS], m->cnt[L_LINEDEFS],
                     m->opt, &m->look, m->err, m->errlen))
        return -1;
    int oom;
    m->scroll = bs_anim_scrolling(m->ld[L_LINEDEFS], m->cnt[L_LINEDEFS], m->cnt[L_SIDEDEFS], &oom);
    if (oom) return bs_fail(m->err, m->errlen, "%s: out of memory", m->display);
    if (wad_load_sectors(m, s) || wad_load_vertexes(m, s) || wad_load_linedefs(m, s) || wad_check_vertexes(m, s) ||
        wad_load_player(m, s))
        return -1;
    /* every sidedef and sector index was checked by wad_load_linedefs */
    if (find_doors(s, m->ld[L_LINEDEFS], m->cnt[L_LINEDEFS], m->ld[L_SIDEDEFS], m->ld[L_SECTORS], m->display, m->err,
                   m->errlen))
        return -1;
    if (bs_mid_masks(s, m->look, m->opt, m->err, m->errlen)) return -1;
    if (read_things(s, m->look, m->ld[L_THINGS], m->cnt[L_THINGS], m->display, m->opt, m->err, m->errlen)) return -1;
    return bs_mid_objects(s, m->look, m->display, m->opt, m->err, m->errlen);
}

int bs_read_wad(const char *wadpath, const char *map, const char *display, bs_scene *s, const bspc_options *opt,
                char *err, size_t errlen)
{
    snprintf(s->name, sizeof s->name, "%s", display);
    s->is_text = 0;
    s->player_sector = SCN_NONE;
    wad_map m = {.wadpath = wadpath, .display = display, .opt = opt, .err = err, .errlen = errlen};
    m.f = fopen(wadpath, "rb");
    if (!m.f) return bs_fail(err, errlen, "%s: cannot open %s: %s", display, wadpath, strerror(errno));
    int rc = wad_load_map(&m, map, s) ? -1 : 0;
    bs_look_close(m.look);
    for (int k = 0; k < L_N; k++) free(m.ld[k]);
    free(m.vused);
    free(m.scroll);
    free(m.dir);
    free(m.dirbuf);
    fclose(m.f);
    return rc;
}
