/* scene_check.c - validation of a source scene before the build: coordinate and
 * height ranges, closed and correctly facing sector boundaries (text scenes),
 * and the sector that holds the player start. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"

static void sector_label(const bs_scene *s, uint32_t i, char *buf, size_t n)
{
    if (s->sectors[i].name[0])
        snprintf(buf, n, "sector %u '%s'", i, s->sectors[i].name);
    else
        snprintf(buf, n, "sector %u", i);
}

int bs_check_ranges(const bs_scene *s, char *err, size_t errlen)
{
    char b1[32], b2[32];
    for (uint32_t i = 0; i < s->nlines; i++) {
        const bs_line *l = &s->lines[i];
        uint32_t vv[2] = {l->v1, l->v2};
        for (int k = 0; k < 2; k++) {
            int32_t x = s->vx[vv[k]], y = s->vy[vv[k]];
            if (x > BS_COORD_RAW_MAX || x < -BS_COORD_RAW_MAX || y > BS_COORD_RAW_MAX || y < -BS_COORD_RAW_MAX)
                return bs_fail(err, errlen, "%s: linedef %d: vertex %u (%s, %s) out of range (|coordinate| <= %d)",
                               s->name, l->src_line, vv[k], bs_fxstr(x, b1), bs_fxstr(y, b2), SCN_COORD_MAX);
        }
    }
    for (uint32_t i = 0; i < s->nsectors; i++) {
        const bs_sector *c = &s->sectors[i];
        if (c->floor_h > BS_HEIGHT_RAW_MAX || c->floor_h < -BS_HEIGHT_RAW_MAX || c->ceil_h > BS_HEIGHT_RAW_MAX ||
            c->ceil_h < -BS_HEIGHT_RAW_MAX)
            return bs_fail(err, errlen, "%s: sector %u: floor %s / ceiling %s out of range (|height| <= %d)", s->name,
                           i, bs_fxstr(c->floor_h, b1), bs_fxstr(c->ceil_h, b2), SCN_HEIGHT_MAX);
    }
    for (uint32_t i = 0; i < s->nsectors; i++) {
        const bs_sector *c = &s->sectors[i];
        if ((c->flags & SCN_SECTOR_DOOR) && (c->open_h < c->ceil_h || c->open_h > BS_HEIGHT_RAW_MAX))
            return bs_fail(err, errlen, "%s: sector %u: door opens to %s, below its ceiling %s or above %d", s->name, i,
                           bs_fxstr(c->open_h, b1), bs_fxstr(c->ceil_h, b2), SCN_HEIGHT_MAX);
    }
    for (uint32_t i = 0; i < s->nobjects; i++) {
        const bs_object *o = &s->objects[i];
        if (o->x > BS_COORD_RAW_MAX || o->x < -BS_COORD_RAW_MAX || o->y > BS_COORD_RAW_MAX ||
            o->y < -BS_COORD_RAW_MAX || (o->has_z && (o->z > BS_HEIGHT_RAW_MAX || o->z < -BS_HEIGHT_RAW_MAX)))
            return bs_fail(err, errlen, "%s: object %u at (%s, %s) outside the world box", s->name, i,
                           bs_fxstr(o->x, b1), bs_fxstr(o->y, b2));
    }
    if (s->has_player && (s->player_x > BS_COORD_RAW_MAX || s->player_x < -BS_COORD_RAW_MAX ||
                          s->player_y > BS_COORD_RAW_MAX || s->player_y < -BS_COORD_RAW_MAX))
        return bs_fail(err, errlen, "%s: player start (%s, %s) out of range (|coordinate| <= %d)", s->name,
                       bs_fxstr(s->player_x, b1), bs_fxstr(s->player_y, b2), SCN_COORD_MAX);
    return 0;
}

typedef struct {
    uint64_t key;  /* sector << 32 | vertex */
    int32_t delta; /* +1 a wall leaves the vertex, -1 one arrives */
    uint32_t line;
} endpoint;

static int cmp_ep(const void *a, const void *b)
{
    const endpoint *x = a, *y = b;
    if (x->key != y->key) return (x->key > y->key) - (x->key < y->key);
    return (x->line > y->line) - (x->line < y->line);
}

int bs_check_closed(const bs_scene *s, char *err, size_t errlen)
{
    /* Each sector's walls, oriented so that the sector is on their right
     * (front: start -> end, back: end -> start), must form closed loops:
     * at every vertex as many leave as arrive. */
    size_t n = 0;
    endpoint *e = malloc(sizeof *e * (size_t)s->nlines * 4 + 1);
    if (!e) return bs_fail(err, errlen, "%s: out of memory", s->name);
    for (uint32_t i = 0; i < s->nlines; i++) {
        const bs_line *l = &s->lines[i];
        for (int side = 0; side < 2; side++) {
            uint32_t sec = l->sector[side];
            if (sec == SCN_NONE) continue;
            uint32_t from = side ? l->v2 : l->v1, to = side ? l->v1 : l->v2;
            e[n++] = (endpoint){((uint64_t)sec << 32) | from, +1, i};
            e[n++] = (endpoint){((uint64_t)sec << 32) | to, -1, i};
        }
    }
    qsort(e, n, sizeof *e, cmp_ep);
    int rc = 0;
    for (size_t i = 0; i < n && rc == 0;) {
        size_t j = i;
        int out = 0, in = 0;
        while (j < n && e[j].key == e[i].key) {
            if (e[j].delta > 0)
                out++;
            else
                in++;
            j++;
        }
        if (out != in) {
            uint32_t sec = (uint32_t)(e[i].key >> 32), v = (uint32_t)e[i].key;
            char lab[64], b1[32], b2[32];
            sector_label(s, sec, lab, sizeof lab);
            rc = bs_fail(err, errlen,
                         "%s:%d: %s is not closed: at (%s, %s) %d of its walls arrive and %d leave "
                         "(the walls bounding a sector must form closed loops, each with the sector "
                         "on its front (right) side or as its back sector)",
                         s->name, s->lines[e[i].line].src_line, lab, bs_fxstr(s->vx[v], b1), bs_fxstr(s->vy[v], b2), in,
                         out);
        }
        i = j;
    }
    free(e);
    if (rc) return rc;

    /* Orientation: with the sector on the right of every edge, its outer loops run
     * clockwise, so the signed area summed over its edges is negative. */
    bs_i128 *area = calloc(s->nsectors + 1, sizeof *area);
    uint32_t *first = malloc(sizeof *first * (s->nsectors + 1));
    if (!area || !first) {
        free(area);
        free(first);
        return bs_fail(err, errlen, "%s: out of memory", s->name);
    }
    for (uint32_t i = 0; i < s->nsectors; i++) first[i] = SCN_NONE;
    for (uint32_t i = 0; i < s->nlines; i++) {
        const bs_line *l = &s->lines[i];
        for (int side = 0; side < 2; side++) {
            uint32_t sec = l->sector[side];
            if (sec == SCN_NONE) continue;
            uint32_t a = side ? l->v2 : l->v1, b = side ? l->v1 : l->v2;
            area[sec] += (bs_i128)s->vx[a] * s->vy[b] - (bs_i128)s->vx[b] * s->vy[a];
            if (first[sec] == SCN_NONE) first[sec] = i;
        }
    }
    for (uint32_t i = 0; i < s->nsectors && rc == 0; i++) {
        if (first[i] == SCN_NONE || area[i] < 0) continue;
        char lab[64];
        sector_label(s, i, lab, sizeof lab);
        if (area[i] == 0)
            rc = bs_fail(err, errlen, "%s:%d: %s encloses no area", s->name, s->lines[first[i]].src_line, lab);
        else
            rc = bs_fail(err, errlen,
                         "%s:%d: the walls of %s face away from it (the front side is on the right "
                         "going from start to end: list its outer walls clockwise)",
                         s->name, s->lines[first[i]].src_line, lab);
    }
    free(area);
    free(first);
    return rc;
}

uint32_t bs_player_sector(const bs_scene *s)
{
    if (!s->has_player) return SCN_NONE;
    return bs_point_sector(s, s->player_x, s->player_y);
}

uint32_t bs_point_sector(const bs_scene *s, int32_t x, int32_t y)
{
    /* Winding number of the point around each sector's boundary (edges
     * oriented with the sector on their right); the first non-zero one wins. */
    if (s->nsectors == 0) return SCN_NONE;
    int32_t *wn = calloc(s->nsectors, sizeof *wn);
    if (!wn) return SCN_NONE;
    const int64_t px = x, py = y;
    for (uint32_t i = 0; i < s->nlines; i++) {
        const bs_line *l = &s->lines[i];
        for (int side = 0; side < 2; side++) {
            uint32_t sec = l->sector[side];
            if (sec == SCN_NONE) continue;
            uint32_t a = side ? l->v2 : l->v1, b = side ? l->v1 : l->v2;
            int64_t ax = s->vx[a], ay = s->vy[a], bx = s->vx[b], by = s->vy[b];
            bs_i128 c = (bs_i128)(bx - ax) * (py - ay) - (bs_i128)(px - ax) * (by - ay);
            if (ay <= py) {
                if (by > py && c > 0) wn[sec]++;
            } else {
                if (by <= py && c < 0) wn[sec]--;
            }
        }
    }
    uint32_t found = SCN_NONE;
    for (uint32_t i = 0; i < s->nsectors; i++)
        if (wn[i] != 0) {
            found = i;
            break;
        }
    free(wn);
    return found;
}
