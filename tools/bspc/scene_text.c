/* scene_text.c - reader of the project's text scene format (docs/scene-format.md).
 *
 * One statement per line, '#' starts a comment:
 *   sector [NAME] floor=H ceil=H [floor_color=C] [ceil_color=C] [light=L] [sky]
 *   wall X1 Y1 X2 Y2 FRONT [BACK] [mid=C] [upper=C] [lower=C]
 *        [back_mid=C] [back_upper=C] [back_lower=C]
 *   player X Y ANGLE
 *   model NAME / part box|prism KEY=VALUE... / end
 *   object MODEL X Y [z=Z] [yaw=DEG] [path=...] [spin=DEG_PER_S]
 *   look on|off   (off: the camera never looks up or down; docs/needs.md)
 * (models and objects: docs/objects.md; sectors also take door=H).
 * Numbers are decimal (fractions allowed) and become 16.16, rounded to nearest.
 * Every error names the file, the line and the problem.
 */
#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bspc_int.h"
#include "fxtext.h"
#include "scene_file.h"

#define MAX_TOK 32

typedef struct {
    const char *path;
    int line;
    char *err;
    size_t errlen;
    bs_scene *s;
    uint32_t *vhash; /* vertex index + 1 */
    uint32_t hcap;
    uint32_t *shash;        /* sector index + 1 by name: the first sector of each name */
    uint32_t scap, shashed; /* its size (a power of two); sectors entered so far */
    int in_model;           /* between 'model' and 'end' */
    const char *stmt;       /* the statement being read, for messages of helpers shared by several */
} parser;

static int perr(parser *p, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static int perr(parser *p, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return bs_fail(p->err, p->errlen, "%s:%d: %s", p->path, p->line, msg);
}

static int parse_int(const char *t, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(t, &end, 0);
    if (end == t || *end || errno || v < lo || v > hi) return -1;
    *out = v;
    return 0;
}

static int parse_color(parser *p, const char *key, const char *val, uint8_t *out)
{
    long v;
    if (isdigit((unsigned char)val[0])) {
        if (parse_int(val, 0, 255, &v))
            return perr(p, "%s: %s=%s: a colour is a palette index 0..255 or NAME[:SHADE]", p->stmt, key, val);
        *out = (uint8_t)v;
        return 0;
    }
    int c = bs_color_by_name(val);
    if (c < 0)
        return perr(p,
                    "%s: %s=%s: unknown colour (a palette index 0..255, or a ramp name such as "
                    "red or red:12, shade 0..15)",
                    p->stmt, key, val);
    *out = (uint8_t)c;
    return 0;
}

static int valid_name(const char *t)
{
    if (!isalpha((unsigned char)t[0]) && t[0] != '_') return 0;
    for (const char *c = t; *c; c++)
        if (!isalnum((unsigned char)*c) && *c != '_' && *c != '-' && *c != '.') return 0;
    return strlen(t) < 32;
}

/* Enter the sectors declared since the last call into p->shash (a name already
 * there keeps its first sector), growing it to at least twice their number. */
static int sector_index(parser *p)
{
    const bs_scene *s = p->s;
    if ((uint64_t)s->nsectors * 2 + 2 > p->scap) {
        uint32_t cap = p->scap ? p->scap : 64;
        while ((uint64_t)s->nsectors * 2 + 2 > cap) cap *= 2;
        uint32_t *h = calloc(cap, sizeof *h);
        if (!h) return -1;
        free(p->shash);
        p->shash = h;
        p->scap = cap;
        p->shashed = 0;
    }
    for (; p->shashed < s->nsectors; p->shashed++) {
        const char *name = s->sectors[p->shashed].name;
        uint32_t h = bs_name_hash(name) & (p->scap - 1);
        while (p->shash[h] && strcmp(s->sectors[p->shash[h] - 1].name, name) != 0) h = (h + 1) & (p->scap - 1);
        if (!p->shash[h]) p->shash[h] = p->shashed + 1;
    }
    return 0;
}

/* The first sector named t among those entered (1), or 0. */
static int named_sector(const parser *p, const char *t, uint32_t *out)
{
    for (uint32_t h = bs_name_hash(t) & (p->scap - 1); p->shash[h]; h = (h + 1) & (p->scap - 1))
        if (strcmp(p->s->sectors[p->shash[h] - 1].name, t) == 0) {
            *out = p->shash[h] - 1;
            return 1;
        }
    return 0;
}

static int find_sector(parser *p, const char *t, uint32_t *out)
{
    bs_scene *s = p->s;
    if (isdigit((unsigned char)t[0])) {
        long v;
        if (parse_int(t, 0, 0x7FFFFFFF, &v) == 0 && (uint32_t)v < s->nsectors) {
            *out = (uint32_t)v;
            return 0;
        }
        return perr(p, "wall: unknown sector %s (%u sector(s) declared above this line)", t, s->nsectors);
    }
    if (sector_index(p)) return perr(p, "out of memory");
    if (named_sector(p, t, out)) return 0;
    return perr(p, "wall: unknown sector '%s' (sectors must be declared before the walls that use them)", t);
}

static uint32_t hash_xy(int32_t x, int32_t y)
{
    uint32_t h = (uint32_t)x * 0x9E3779B1u ^ ((uint32_t)y * 0x85EBCA77u);
    h ^= h >> 15;
    return h * 0xC2B2AE3Du;
}

static int vertex_of(parser *p, int32_t x, int32_t y, uint32_t *out)
{
    bs_scene *s = p->s;
    if ((s->nverts + 1) * 2 > p->hcap) {
        uint32_t nc = p->hcap ? p->hcap * 2 : 1024;
        uint32_t *nh = calloc(nc, sizeof *nh);
        if (!nh) return perr(p, "out of memory");
        for (uint32_t i = 0; i < s->nverts; i++) {
            uint32_t h = hash_xy(s->vx[i], s->vy[i]) & (nc - 1);
            while (nh[h]) h = (h + 1) & (nc - 1);
            nh[h] = i + 1;
        }
        free(p->vhash);
        p->vhash = nh;
        p->hcap = nc;
    }
    uint32_t h = hash_xy(x, y) & (p->hcap - 1);
    while (p->vhash[h]) {
        uint32_t i = p->vhash[h] - 1;
        if (s->vx[i] == x && s->vy[i] == y) {
            *out = i;
            return 0;
        }
        h = (h + 1) & (p->hcap - 1);
    }
    uint32_t i = bs_scene_add_vertex(s, x, y);
    if (i == SCN_NONE) return perr(p, "out of memory");
    p->vhash[h] = i + 1;
    *out = i;
    return 0;
}

/* coordinate token -> 16.16 within the proven range */
static int coord(parser *p, const char *what, const char *t, int32_t *out)
{
    int64_t v;
    if (fxtext_parse64(t, &v)) return perr(p, "%s: '%s' is not a number", what, t);
    if (v > BS_COORD_RAW_MAX || v < -BS_COORD_RAW_MAX)
        return perr(p, "%s = %s out of range (|coordinate| <= %d)", what, t, SCN_COORD_MAX);
    *out = (int32_t)v;
    return 0;
}

static int height(parser *p, const char *what, const char *t, int32_t *out)
{
    int64_t v;
    if (fxtext_parse64(t, &v)) return perr(p, "sector: %s=%s is not a number", what, t);
    if (v > BS_HEIGHT_RAW_MAX || v < -BS_HEIGHT_RAW_MAX)
        return perr(p, "sector: %s=%s out of range (|height| <= %d)", what, t, SCN_HEIGHT_MAX);
    *out = (int32_t)v;
    return 0;
}

static int do_sector(parser *p, char **tok, int n)
{
    bs_scene *s = p->s;
    bs_sector sec;
    memset(&sec, 0, sizeof sec);
    sec.src_line = p->line;
    sec.light = 255;
    sec.floor_color = (uint8_t)(BS_RAMP_BROWN * 16 + 8);
    sec.ceil_color = (uint8_t)(BS_RAMP_GREY * 16 + 9);
    int i = 1, have_floor = 0, have_ceil = 0, seen_fc = 0, seen_cc = 0, seen_light = 0, have_door = 0;
    if (i < n && !strchr(tok[i], '=') && strcmp(tok[i], "sky") != 0) {
        if (!valid_name(tok[i]))
            return perr(p,
                        "sector: bad name '%s' (a letter or '_' first, then letters, digits, "
                        "'_', '-', '.'; up to 31 characters)",
                        tok[i]);
        uint32_t k;
        if (sector_index(p)) return perr(p, "out of memory");
        if (named_sector(p, tok[i], &k))
            return perr(p, "sector: name '%s' already used by sector %u (line %d)", tok[i], k, s->sectors[k].src_line);
        strcpy(sec.name, tok[i]);
        i++;
    }
    for (; i < n; i++) {
        char *t = tok[i];
        if (strcmp(t, "sky") == 0) {
            sec.flags |= SCN_SECTOR_SKY;
            continue;
        }
        char *eq = strchr(t, '=');
        if (!eq) return perr(p, "sector: unexpected '%s' (expected KEY=VALUE or sky)", t);
        *eq = 0;
        const char *val = eq + 1;
        long lv;
        if (strcmp(t, "floor") == 0) {
            if (have_floor++) return perr(p, "sector: floor given twice");
            if (height(p, "floor", val, &sec.floor_h)) return -1;
        } else if (strcmp(t, "ceil") == 0) {
            if (have_ceil++) return perr(p, "sector: ceil given twice");
            if (height(p, "ceil", val, &sec.ceil_h)) return -1;
        } else if (strcmp(t, "floor_color") == 0) {
            if (seen_fc++) return perr(p, "sector: floor_color given twice");
            if (parse_color(p, t, val, &sec.floor_color)) return -1;
        } else if (strcmp(t, "ceil_color") == 0) {
            if (seen_cc++) return perr(p, "sector: ceil_color given twice");
            if (parse_color(p, t, val, &sec.ceil_color)) return -1;
        } else if (strcmp(t, "light") == 0) {
            if (seen_light++) return perr(p, "sector: light given twice");
            if (parse_int(val, 0, 255, &lv)) return perr(p, "sector: light=%s: expected 0..255", val);
            sec.light = (uint8_t)lv;
        } else if (strcmp(t, "door") == 0) {
            if (have_door++) return perr(p, "sector: door given twice");
            if (height(p, "door", val, &sec.open_h)) return -1;
            sec.flags |= SCN_SECTOR_DOOR;
        } else {
            return perr(p,
                        "sector: unknown key '%s' (floor, ceil, floor_color, ceil_color, light, sky, "
                        "door)",
                        t);
        }
    }
    if (!have_floor) return perr(p, "sector: missing floor=HEIGHT");
    if (!have_ceil) return perr(p, "sector: missing ceil=HEIGHT");
    if (sec.ceil_h < sec.floor_h) return perr(p, "sector: ceil is below floor");
    if (have_door && sec.open_h < sec.ceil_h)
        return perr(p, "sector: door=H is below ceil (the open ceiling of a door is at or above its "
                       "closed one)");
    if (have_door)
        s->ndoors++;
    else
        sec.open_h = sec.ceil_h;
    if (bs_grow(&s->sectors, &s->scap, s->nsectors + 1, sizeof sec)) return perr(p, "out of memory");
    s->sectors[s->nsectors++] = sec;
    return 0;
}

static int do_wall(parser *p, char **tok, int n)
{
    bs_scene *s = p->s;
    if (n < 6) return perr(p, "wall: expected 'wall X1 Y1 X2 Y2 FRONT [BACK] [mid=C] [upper=C] [lower=C]'");
    bs_line ln;
    memset(&ln, 0, sizeof ln);
    ln.src_line = p->line;
    int32_t x1, y1, x2, y2;
    if (coord(p, "wall: x1", tok[1], &x1) || coord(p, "wall: y1", tok[2], &y1) || coord(p, "wall: x2", tok[3], &x2) ||
        coord(p, "wall: y2", tok[4], &y2))
        return -1;
    if (x1 == x2 && y1 == y2) return perr(p, "wall: zero length (start and end are the same point)");
    if (find_sector(p, tok[5], &ln.sector[0])) return -1;
    ln.sector[1] = SCN_NONE;
    int i = 6;
    if (i < n && !strchr(tok[i], '=')) {
        if (find_sector(p, tok[i], &ln.sector[1])) return -1;
        i++;
    }
    int have[6] = {0};
    uint8_t col[6];
    static const char *keys[6] = {"upper", "mid", "lower", "back_upper", "back_mid", "back_lower"};
    for (; i < n; i++) {
        char *eq = strchr(tok[i], '=');
        if (!eq) return perr(p, "wall: unexpected '%s' (expected KEY=COLOUR)", tok[i]);
        *eq = 0;
        int k;
        for (k = 0; k < 6; k++)
            if (strcmp(tok[i], keys[k]) == 0) break;
        if (k == 6)
            return perr(p,
                        "wall: unknown key '%s' (mid, upper, lower, back_mid, back_upper, "
                        "back_lower)",
                        tok[i]);
        if (have[k]++) return perr(p, "wall: %s given twice", keys[k]);
        if (parse_color(p, keys[k], eq + 1, &col[k])) return -1;
        if (k >= 3 && ln.sector[1] == SCN_NONE)
            return perr(p, "wall: %s given but the wall is one-sided (no BACK sector)", keys[k]);
    }
    uint8_t mid = have[1] ? col[1] : (uint8_t)(BS_RAMP_GREY * 16 + 10);
    ln.color[0][SCN_PART_MIDDLE] = mid;
    ln.color[0][SCN_PART_UPPER] = have[0] ? col[0] : mid;
    ln.color[0][SCN_PART_LOWER] = have[2] ? col[2] : mid;
    ln.color[1][SCN_PART_MIDDLE] = have[4] ? col[4] : ln.color[0][SCN_PART_MIDDLE];
    ln.color[1][SCN_PART_UPPER] = have[3] ? col[3] : ln.color[0][SCN_PART_UPPER];
    ln.color[1][SCN_PART_LOWER] = have[5] ? col[5] : ln.color[0][SCN_PART_LOWER];
    if (vertex_of(p, x1, y1, &ln.v1) || vertex_of(p, x2, y2, &ln.v2)) return -1;
    if (bs_grow(&s->lines, &s->lcap, s->nlines + 1, sizeof ln)) return perr(p, "out of memory");
    s->lines[s->nlines++] = ln;
    return 0;
}

static int do_player(parser *p, char **tok, int n)
{
    bs_scene *s = p->s;
    if (n != 4) return perr(p, "player: expected 'player X Y ANGLE' (angle in degrees, 0 = east)");
    if (s->has_player) return perr(p, "player: a second player start (the first is on line %d)", s->player_line);
    int64_t a;
    if (coord(p, "player: x", tok[1], &s->player_x) || coord(p, "player: y", tok[2], &s->player_y)) return -1;
    if (fxtext_parse64(tok[3], &a)) return perr(p, "player: angle '%s' is not a number", tok[3]);
    const int64_t turn = (int64_t)360 << 16;
    a %= turn;
    if (a < 0) a += turn;
    s->player_angle = (int32_t)a;
    s->has_player = 1;
    s->player_line = p->line;
    return 0;
}

/* ---- models and objects (docs/objects.md) ---- */

static const bs_model *cur_model(parser *p)
{
    return &p->s->models[p->s->nmodels - 1];
}

static int do_model(parser *p, char **tok, int n)
{
    bs_scene *s = p->s;
    if (n != 2) return perr(p, "model: expected 'model NAME'");
    if (!valid_name(tok[1]))
        return perr(p,
                    "model: bad name '%s' (a letter or '_' first, then letters, digits, '_', '-', "
                    "'.'; up to 31 characters)",
                    tok[1]);
    for (uint32_t k = 0; k < s->nmodels; k++)
        if (strcmp(s->models[k].name, tok[1]) == 0)
            return perr(p, "model: name '%s' already used by model %u (line %d)", tok[1], k, s->models[k].src_line);
    char msg[300];
    if (bs_model_begin(s, tok[1], p->line, msg, sizeof msg)) return perr(p, "model: %s", msg);
    p->in_model = 1;
    return 0;
}

/* a model-space size: > 0 and at most the model box's width */
static int model_size(parser *p, const char *key, const char *val, int32_t *out)
{
    int64_t v;
    if (fxtext_parse64(val, &v)) return perr(p, "part: %s=%s is not a number", key, val);
    if (v <= 0 || v > 2 * (int64_t)SCN_MODEL_MAX * 65536)
        return perr(p, "part: %s=%s out of range (0 < %s <= %d)", key, val, key, 2 * SCN_MODEL_MAX);
    *out = (int32_t)v;
    return 0;
}

static int do_part(parser *p, char **tok, int n)
{
    if (n < 2 || (strcmp(tok[1], "box") != 0 && strcmp(tok[1], "prism") != 0))
        return perr(p, "part: expected 'part box w=W d=D h=H ...' or 'part prism sides=N r=R h=H ...'");
    int box = strcmp(tok[1], "box") == 0;
    bs_mpart pt;
    memset(&pt, 0, sizeof pt);
    pt.box = box;
    pt.sides = box ? 4 : 0;
    enum { K_W, K_D, K_H, K_R, K_SIDES, K_AT, K_COLOR, K_TOP, K_BOTTOM, K_SIDE, K_N };
    static const char *keys[K_N] = {"w", "d", "h", "r", "sides", "at", "color", "top", "bottom", "side"};
    int have[K_N] = {0};
    uint8_t col[K_N];
    for (int i = 2; i < n; i++) {
        char *eq = strchr(tok[i], '=');
        if (!eq) return perr(p, "part: unexpected '%s' (expected KEY=VALUE)", tok[i]);
        *eq = 0;
        const char *val = eq + 1;
        int k;
        for (k = 0; k < K_N; k++)
            if (strcmp(tok[i], keys[k]) == 0) break;
        if (k == K_N || (box && (k == K_R || k == K_SIDES)) || (!box && (k == K_W || k == K_D)))
            return perr(p, "part %s: unknown key '%s' (%s, at, color, top, bottom, side)", tok[1], tok[i],
                        box ? "w, d, h" : "sides, r, h");
        if (have[k]++) return perr(p, "part: %s given twice", keys[k]);
        long lv;
        switch (k) {
        case K_W:
            if (model_size(p, "w", val, &pt.w)) return -1;
            break;
        case K_D:
            if (model_size(p, "d", val, &pt.d)) return -1;
            break;
        case K_H:
            if (model_size(p, "h", val, &pt.h)) return -1;
            break;
        case K_R:
            if (model_size(p, "r", val, &pt.r)) return -1;
            break;
        case K_SIDES:
            if (parse_int(val, 3, SCN_MAX_FACE_VERTS, &lv))
                return perr(p, "part: sides=%s: expected a whole number 3..%d", val, SCN_MAX_FACE_VERTS);
            pt.sides = (int)lv;
            break;
        case K_AT: {
            char buf[128];
            snprintf(buf, sizeof buf, "%s", val);
            char *c[3] = {buf, NULL, NULL};
            for (int j = 1; j < 3; j++) {
                c[j] = c[j - 1] ? strchr(c[j - 1], ',') : NULL;
                if (c[j]) *c[j]++ = 0;
            }
            if (!c[1] || !c[2] || strchr(c[2], ',')) return perr(p, "part: at=%s: expected at=X,Y,Z", val);
            for (int j = 0; j < 3; j++) {
                int64_t v;
                if (fxtext_parse64(c[j], &v)) return perr(p, "part: at=%s: '%s' is not a number", val, c[j]);
                if (v > (int64_t)SCN_MODEL_MAX * 65536 || v < -(int64_t)SCN_MODEL_MAX * 65536)
                    return perr(p, "part: at=%s out of range (|coordinate| <= %d)", val, SCN_MODEL_MAX);
                pt.at[j] = (int32_t)v;
            }
            break;
        }
        default:
            if (parse_color(p, keys[k], val, &col[k])) return -1;
        }
    }
    static const int need_box[3] = {K_W, K_D, K_H}, need_prism[3] = {K_SIDES, K_R, K_H};
    for (int j = 0; j < 3; j++) {
        int k = box ? need_box[j] : need_prism[j];
        if (!have[k]) return perr(p, "part %s: missing %s=", tok[1], keys[k]);
    }
    uint8_t base = have[K_COLOR] ? col[K_COLOR] : (uint8_t)(BS_RAMP_GREY * 16 + 10);
    pt.top = have[K_TOP] ? col[K_TOP] : base;
    pt.bottom = have[K_BOTTOM] ? col[K_BOTTOM] : base;
    pt.side = have[K_SIDE] ? col[K_SIDE] : base;
    char msg[300];
    if (bs_model_add_part(p->s, &pt, msg, sizeof msg)) {
        if (strncmp(msg, "part", 4) == 0) return perr(p, "%s", msg);
        return perr(p, "part: %s", msg);
    }
    return 0;
}

static int find_model(parser *p, const char *t, uint32_t *out)
{
    bs_scene *s = p->s;
    if (isdigit((unsigned char)t[0])) {
        long v;
        if (parse_int(t, 0, 0x7FFFFFFF, &v) == 0 && (uint32_t)v < s->nmodels) {
            *out = (uint32_t)v;
            return 0;
        }
        return perr(p, "object: unknown model %s (%u model(s) declared above this line)", t, s->nmodels);
    }
    for (uint32_t i = 0; i < s->nmodels; i++)
        if (strcmp(s->models[i].name, t) == 0) {
            *out = i;
            return 0;
        }
    return perr(p, "object: unknown model '%s' (models must be declared before the objects that use them)", t);
}

/* "A:B[:C...]" -> its fields, in place; returns the count */
static int split_colons(char *t, char **f, int max)
{
    int n = 0;
    while (n < max) {
        f[n++] = t;
        t = strchr(t, ':');
        if (!t) break;
        *t++ = 0;
    }
    return t ? max + 1 : n;
}

static int period(parser *p, const char *t, uint32_t *out)
{
    char *end;
    errno = 0;
    long v = isdigit((unsigned char)t[0]) ? strtol(t, &end, 10) : 0;
    if (!isdigit((unsigned char)t[0]) || *end || errno || v < 1 || v > (long)BS_PERIOD_MAX_MS)
        return perr(p, "object: period %s: expected whole milliseconds 1..%u", t, BS_PERIOD_MAX_MS);
    *out = (uint32_t)v;
    return 0;
}

static int do_look(parser *p, char **tok, int n)
{
    if (n != 2 || (strcmp(tok[1], "on") != 0 && strcmp(tok[1], "off") != 0))
        return perr(p, "look: expected 'look on' or 'look off'");
    p->s->no_look = strcmp(tok[1], "off") == 0;
    return 0;
}

static int do_object(parser *p, char **tok, int n)
{
    bs_scene *s = p->s;
    if (n < 4)
        return perr(p, "object: expected 'object MODEL X Y [z=Z] [yaw=DEG] [path=circle:R:PERIOD_MS | "
                       "path=line:DX:DY:PERIOD_MS] [spin=DEG_PER_S]'");
    if (s->nobjects >= SCN_MAX_OBJECTS) return perr(p, "object: more than %d objects", SCN_MAX_OBJECTS);
    bs_object o;
    memset(&o, 0, sizeof o);
    o.src_line = p->line;
    o.path = SCN_PATH_NONE;
    if (find_model(p, tok[1], &o.model)) return -1;
    if (coord(p, "object: x", tok[2], &o.x) || coord(p, "object: y", tok[3], &o.y)) return -1;
    int have_z = 0, have_yaw = 0, have_path = 0, have_spin = 0;
    for (int i = 4; i < n; i++) {
        char *eq = strchr(tok[i], '=');
        if (!eq) return perr(p, "object: unexpected '%s' (expected KEY=VALUE)", tok[i]);
        *eq = 0;
        char *val = eq + 1;
        int64_t v;
        if (strcmp(tok[i], "z") == 0) {
            if (have_z++) return perr(p, "object: z given twice");
            if (fxtext_parse64(val, &v)) return perr(p, "object: z=%s is not a number", val);
            if (v > BS_HEIGHT_RAW_MAX || v < -BS_HEIGHT_RAW_MAX)
                return perr(p, "object: z=%s out of range (|height| <= %d)", val, SCN_HEIGHT_MAX);
            o.z = (int32_t)v;
            o.has_z = 1;
        } else if (strcmp(tok[i], "yaw") == 0) {
            if (have_yaw++) return perr(p, "object: yaw given twice");
            if (fxtext_parse64(val, &v)) return perr(p, "object: yaw=%s is not a number", val);
            const int64_t turn = (int64_t)360 << 16;
            v %= turn;
            if (v < 0) v += turn;
            o.yaw = (int32_t)v;
        } else if (strcmp(tok[i], "spin") == 0) {
            if (have_spin++) return perr(p, "object: spin given twice");
            if (fxtext_parse64(val, &v)) return perr(p, "object: spin=%s is not a number", val);
            if (v > (int64_t)BS_SPIN_MAX * 65536 || v < -(int64_t)BS_SPIN_MAX * 65536)
                return perr(p, "object: spin=%s out of range (|degrees per second| <= %d)", val, BS_SPIN_MAX);
            o.spin = (int32_t)v;
        } else if (strcmp(tok[i], "path") == 0) {
            if (have_path++) return perr(p, "object: path given twice");
            char text[128];
            snprintf(text, sizeof text, "%s", val);
            char *f[5];
            int nf = split_colons(val, f, 4);
            int64_t a, b;
            if (strcmp(f[0], "circle") == 0 && nf == 3) {
                if (fxtext_parse64(f[1], &a))
                    return perr(p, "object: path=%s: radius '%s' is not a number", text, f[1]);
                /* no larger circle fits in the world box, and the radius is stored in 32 bits */
                if (a <= 0 || a > BS_COORD_RAW_MAX)
                    return perr(p, "object: path=%s: radius out of range (0 < R <= %d)", text, SCN_COORD_MAX);
                if (period(p, f[2], &o.period_ms)) return -1;
                o.path = SCN_PATH_CIRCLE;
                o.pa = (int32_t)a;
            } else if (strcmp(f[0], "line") == 0 && nf == 4) {
                if (fxtext_parse64(f[1], &a) || fxtext_parse64(f[2], &b))
                    return perr(p, "object: path=%s: DX and DY must be numbers", text);
                /* stored in 32 bits: a longer step would wrap before the box check below */
                if (a > BS_COORD_RAW_MAX || a < -BS_COORD_RAW_MAX || b > BS_COORD_RAW_MAX || b < -BS_COORD_RAW_MAX)
                    return perr(p, "object: path=%s: DX and DY out of range (|D| <= %d)", text, SCN_COORD_MAX);
                if (a == 0 && b == 0) return perr(p, "object: path=%s has zero length", text);
                if (period(p, f[3], &o.period_ms)) return -1;
                o.path = SCN_PATH_LINE;
                o.pa = (int32_t)a;
                o.pb = (int32_t)b;
            } else {
                return perr(p, "object: path=%s: expected circle:R:PERIOD_MS or line:DX:DY:PERIOD_MS", text);
            }
        } else {
            return perr(p, "object: unknown key '%s' (z, yaw, path, spin)", tok[i]);
        }
    }
    /* every point of the path stays in the world box */
    int64_t lo[2] = {o.x, o.y}, hi[2] = {o.x, o.y};
    if (o.path == SCN_PATH_CIRCLE) {
        for (int k = 0; k < 2; k++) {
            lo[k] -= o.pa;
            hi[k] += o.pa;
        }
    } else if (o.path == SCN_PATH_LINE) {
        int64_t d[2] = {o.pa, o.pb};
        for (int k = 0; k < 2; k++) {
            if (d[k] < 0)
                lo[k] += d[k];
            else
                hi[k] += d[k];
        }
    }
    for (int k = 0; k < 2; k++)
        if (lo[k] < -BS_COORD_RAW_MAX || hi[k] > BS_COORD_RAW_MAX)
            return perr(p, "object: its path leaves the world box (|coordinate| <= %d)", SCN_COORD_MAX);
    if (bs_grow(&s->objects, &s->ocap, s->nobjects + 1, sizeof o)) return perr(p, "out of memory");
    s->objects[s->nobjects++] = o;
    return 0;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Duplicated walls: the same two points, in either direction. */
static int check_duplicates(parser *p)
{
    bs_scene *s = p->s;
    if (s->nlines < 2) return 0;
    struct pair {
        uint64_t key;
        uint64_t idx;
    } *a = malloc(sizeof *a * s->nlines);
    if (!a) return perr(p, "out of memory");
    for (uint32_t i = 0; i < s->nlines; i++) {
        uint64_t v1 = s->lines[i].v1, v2 = s->lines[i].v2;
        if (v1 > v2) {
            uint64_t t = v1;
            v1 = v2;
            v2 = t;
        }
        a[i].key = (v1 << 32) | v2;
        a[i].idx = i;
    }
    qsort(a, s->nlines, sizeof *a, cmp_u64); /* by key only; equal keys are ordered below */
    int rc = 0;
    for (uint32_t i = 1; i < s->nlines; i++) {
        if (a[i].key == a[i - 1].key) {
            uint32_t i0 = (uint32_t)a[i - 1].idx, i1 = (uint32_t)a[i].idx;
            if (i0 > i1) {
                uint32_t t = i0;
                i0 = i1;
                i1 = t;
            }
            p->line = s->lines[i1].src_line;
            rc = perr(p, "wall: duplicates the wall on line %d (same two points%s)", s->lines[i0].src_line,
                      s->lines[i0].v1 == s->lines[i1].v1 ? "" : ", reversed");
            break;
        }
    }
    free(a);
    return rc;
}

int bs_read_text(const char *path, bs_scene *s, const bspc_options *opt, char *err, size_t errlen)
{
    (void)opt;
    FILE *f = fopen(path, "rb");
    if (!f) return bs_fail(err, errlen, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode)) { /* a folder opens; only its read fails */
        fclose(f);
        return bs_fail(err, errlen, "%s: is a directory, not a scene file", path);
    }
    char *buf = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len + 4096 + 1 > cap) {
            cap = cap ? cap * 2 : 65536;
            char *nb = realloc(buf, cap);
            if (!nb) {
                free(buf);
                fclose(f);
                return bs_fail(err, errlen, "%s: out of memory", path);
            }
            buf = nb;
        }
        size_t got = fread(buf + len, 1, 4096, f);
        len += got;
        if (got < 4096) break;
    }
    int ioerr = ferror(f) ? errno : 0;
    fclose(f);
    if (ioerr) {
        free(buf);
        return bs_fail(err, errlen, "%s: read error: %s", path, strerror(ioerr));
    }
    buf[len] = 0;
    if (strlen(buf) != len) {
        /* binary: say what it is not, and what it is when it is a compiled scene */
        int compiled = scene_file_is_compiled((const uint8_t *)buf, len);
        free(buf);
        if (compiled)
            return bs_fail(err, errlen,
                           "%s: a compiled scene, not a source to compile (bspc --config reads "
                           "one; build/render draws it)",
                           path);
        return bs_fail(err, errlen,
                       "%s: not a scene: not text (contains NUL bytes), and its magic is not "
                       "\"BSCN\" (a compiled scene's)",
                       path);
    }

    snprintf(s->name, sizeof s->name, "%s", path);
    s->is_text = 1;
    s->player_sector = SCN_NONE;
    parser p = {path, 0, err, errlen, s, NULL, 0, NULL, 0, 0, 0, ""};
    int rc = 0;
    char *line = buf;
    if (!strncmp(line, "\xef\xbb\xbf", 3)) line += 3; /* a UTF-8 byte-order mark, as some editors write */
    while (line && rc == 0) {
        /* a line ends in LF, CRLF or a lone CR (old Mac editors) */
        char *next = line + strcspn(line, "\r\n");
        if (!*next)
            next = NULL;
        else {
            int crlf = next[0] == '\r' && next[1] == '\n';
            *next = 0;
            next += 1 + crlf;
        }
        p.line++;
        char *hash = strchr(line, '#');
        if (hash) *hash = 0;
        char *tok[MAX_TOK];
        int n = 0;
        for (char *c = line; *c && rc == 0;) {
            while (*c && isspace((unsigned char)*c)) *c++ = 0;
            if (!*c) break;
            if (n == MAX_TOK) {
                rc = perr(&p, "too many words on one line (at most %d)", MAX_TOK);
                break;
            }
            tok[n++] = c;
            while (*c && !isspace((unsigned char)*c)) c++;
        }
        if (rc || n == 0) {
            line = next;
            continue;
        }
        p.stmt = tok[0];
        if (p.in_model) {
            if (strcmp(tok[0], "part") == 0)
                rc = do_part(&p, tok, n);
            else if (strcmp(tok[0], "end") == 0) {
                char msg[300];
                if (n != 1)
                    rc = perr(&p, "end: unexpected '%s'", tok[1]);
                else if (bs_model_end(s, msg, sizeof msg))
                    rc = perr(&p, "end: %s", msg);
                p.in_model = 0;
            } else
                rc = perr(&p, "%s: not allowed inside model '%s' (line %d): 'end' missing?", tok[0],
                          cur_model(&p)->name, cur_model(&p)->src_line);
        } else if (strcmp(tok[0], "sector") == 0)
            rc = do_sector(&p, tok, n);
        else if (strcmp(tok[0], "wall") == 0)
            rc = do_wall(&p, tok, n);
        else if (strcmp(tok[0], "player") == 0)
            rc = do_player(&p, tok, n);
        else if (strcmp(tok[0], "model") == 0)
            rc = do_model(&p, tok, n);
        else if (strcmp(tok[0], "object") == 0)
            rc = do_object(&p, tok, n);
        else if (strcmp(tok[0], "look") == 0)
            rc = do_look(&p, tok, n);
        else if (strcmp(tok[0], "part") == 0 || strcmp(tok[0], "end") == 0)
            rc = perr(&p, "%s: outside a model (start one with 'model NAME')", tok[0]);
        else
            rc = perr(&p, "unknown statement '%s' (expected sector, wall, player, model, object or look)", tok[0]);
        line = next;
    }
    free(buf);
    free(p.vhash);
    free(p.shash);
    if (rc) return rc;
    if (p.in_model)
        return bs_fail(err, errlen, "%s:%d: model '%s': 'end' missing", path, cur_model(&p)->src_line,
                       cur_model(&p)->name);
    /* what is missing is missing at the end of the file: its last line */
    if (s->nlines == 0) return bs_fail(err, errlen, "%s:%d: end of file: no walls", path, p.line);
    if (!s->has_player)
        return bs_fail(err, errlen, "%s:%d: end of file: no player start (add 'player X Y ANGLE')", path, p.line);
    return check_duplicates(&p);
}
