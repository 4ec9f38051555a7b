/* models.c - model geometry (docs/objects.md): each part, a box or an upright
 * prism, becomes a ring of bottom vertices, the same ring lifted by its height,
 * and its faces (sides, top, bottom), counter-clockwise seen from outside.
 * Boxes are exact in 16.16; prism corners use double cos/sin and are rounded
 * once, so the reference renderer can reproduce every vertex bit for bit from
 * the formulas written in docs/objects.md. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bspc_int.h"
#include "geom.h"

#define MODEL_RAW_MAX ((int64_t)SCN_MODEL_MAX * 65536)

uint8_t bs_shade(uint8_t c, int delta)
{
    int shade = (c & 15) + delta;
    if (shade < 0) shade = 0;
    if (shade > 15) shade = 15;
    return (uint8_t)((c & 0xF0) | shade);
}

/* nearest integer, ties away from zero, as the text format rounds */
static int64_t round_away(double v)
{
    return (int64_t)(v < 0 ? -floor(-v + 0.5) : floor(v + 0.5));
}

int bs_model_begin(bs_scene *s, const char *name, int src_line, char *err, size_t errlen)
{
    if (bs_grow(&s->models, &s->mcap, s->nmodels + 1, sizeof *s->models)) return bs_fail(err, errlen, "out of memory");
    bs_model *m = &s->models[s->nmodels++];
    memset(m, 0, sizeof *m);
    m->first_vert = s->nmverts;
    m->first_face = s->nfaces;
    m->src_line = src_line;
    snprintf(m->name, sizeof m->name, "%s", name ? name : "");
    return 0;
}

/* Can two upright prisms share interior points? Their z ranges must overlap and
 * no edge normal of either ring may separate the rings; touching (equal extents)
 * is allowed. Coordinates are below 2^27 raw, so every product fits in 64 bits. */
static int rings_overlap(const bs_mvert *a, int na, const bs_mvert *b, int nb)
{
    for (int pass = 0; pass < 2; pass++) {
        const bs_mvert *p = pass ? b : a;
        int np = pass ? nb : na;
        for (int k = 0; k < np; k++) {
            const bs_mvert *u = &p[k], *v = &p[(k + 1) % np];
            int64_t nx = (int64_t)v->y - u->y, ny = -((int64_t)v->x - u->x);
            int64_t amin = INT64_MAX, amax = INT64_MIN, bmin = INT64_MAX, bmax = INT64_MIN;
            for (int i = 0; i < na; i++) {
                int64_t d = nx * a[i].x + ny * a[i].y;
                if (d < amin) amin = d;
                if (d > amax) amax = d;
            }
            for (int i = 0; i < nb; i++) {
                int64_t d = nx * b[i].x + ny * b[i].y;
                if (d < bmin) bmin = d;
                if (d > bmax) bmax = d;
            }
            if (amax <= bmin || bmax <= amin) return 0;
        }
    }
    return 1;
}

static int push_face(bs_scene *s, const uint32_t *idx, int n, uint8_t colour, uint8_t part)
{
    if (bs_grow(&s->faces, &s->fcap, s->nfaces + 1, sizeof *s->faces) ||
        bs_grow(&s->findex, &s->ficap, s->nfindex + (uint32_t)n, sizeof *s->findex))
        return -1;
    bs_face *f = &s->faces[s->nfaces++];
    f->first_index = s->nfindex;
    f->num_index = (uint16_t)n;
    f->colour = colour;
    f->part = part;
    memcpy(s->findex + s->nfindex, idx, sizeof *idx * (size_t)n);
    s->nfindex += (uint32_t)n;
    return 0;
}

int bs_model_add_part(bs_scene *s, const bs_mpart *p, char *err, size_t errlen)
{
    bs_model *m = &s->models[s->nmodels - 1];
    const int n = p->sides;
    if (m->num_verts + 2u * (uint32_t)n > SCN_MAX_MODEL_VERTS)
        return bs_fail(err, errlen, "model has %u vertices with this part, more than %d", m->num_verts + 2 * n,
                       SCN_MAX_MODEL_VERTS);
    if (m->num_faces + (uint32_t)n + 2u > SCN_MAX_MODEL_FACES)
        return bs_fail(err, errlen, "model has %u faces with this part, more than %d", m->num_faces + n + 2,
                       SCN_MAX_MODEL_FACES);
    if (m->nparts >= BS_MAX_PARTS) return bs_fail(err, errlen, "more than %d parts in one model", BS_MAX_PARTS);

    bs_mvert ring[2 * SCN_MAX_FACE_VERTS];
    int64_t zb = p->at[2], zt = (int64_t)p->at[2] + p->h;
    for (int k = 0; k < n; k++) {
        int64_t x, y;
        if (p->box) {
            /* corners (-,-) (+,-) (+,+) (-,+): a half of an odd raw size rounds
             * away from the centre, so the box stays symmetric */
            int64_t hw = ((int64_t)p->w + 1) / 2, hd = ((int64_t)p->d + 1) / 2;
            x = p->at[0] + ((k == 1 || k == 2) ? hw : -hw);
            y = p->at[1] + ((k >= 2) ? hd : -hd);
        } else {
            double a = 2 * M_PI * k / n;
            x = p->at[0] + round_away((double)p->r * cos(a));
            y = p->at[1] + round_away((double)p->r * sin(a));
        }
        char b1[32], b2[32], b3[32];
        for (int lift = 0; lift < 2; lift++) {
            int64_t z = lift ? zt : zb;
            if (x > MODEL_RAW_MAX || x < -MODEL_RAW_MAX || y > MODEL_RAW_MAX || y < -MODEL_RAW_MAX ||
                z > MODEL_RAW_MAX || z < -MODEL_RAW_MAX)
                return bs_fail(err, errlen, "part: vertex (%s, %s, %s) outside the model's range (|coordinate| <= %d)",
                               x > INT32_MAX || x < INT32_MIN ? "?" : bs_fxstr((int32_t)x, b1),
                               y > INT32_MAX || y < INT32_MIN ? "?" : bs_fxstr((int32_t)y, b2),
                               z > INT32_MAX || z < INT32_MIN ? "?" : bs_fxstr((int32_t)z, b3), SCN_MODEL_MAX);
        }
        ring[k] = (bs_mvert){(int32_t)x, (int32_t)y, (int32_t)zb};
        ring[n + k] = (bs_mvert){(int32_t)x, (int32_t)y, (int32_t)zt};
    }
    /* a part so small that rounding made its outline not strictly convex has
     * faces without a direction */
    for (int k = 0; k < n; k++) {
        const bs_mvert *a = &ring[k], *b = &ring[(k + 1) % n], *c = &ring[(k + 2) % n];
        int64_t cr = ((int64_t)b->x - a->x) * ((int64_t)c->y - b->y) - ((int64_t)b->y - a->y) * ((int64_t)c->x - b->x);
        if (cr <= 0) return bs_fail(err, errlen, "part: too small (its corners coincide after rounding to 16.16)");
    }
    /* earlier parts of this model: their bottom rings are the first half of each part's vertices */
    for (uint32_t q = 0; q < m->nparts; q++) {
        const bs_mvert *o = &s->mverts[m->first_vert + m->part_vert[q]];
        int no = m->part_sides[q];
        int64_t ozb = o[0].z, ozt = o[no].z;
        if (ozt <= zb || zt <= ozb) continue;
        if (rings_overlap(ring, n, o, no))
            return bs_fail(err, errlen,
                           "part overlaps part %u of the model (the parts of a model may "
                           "touch but not overlap)",
                           q + 1);
    }

    uint32_t base = m->num_verts;
    if (bs_grow(&s->mverts, &s->mvcap, s->nmverts + 2u * (uint32_t)n, sizeof *s->mverts))
        return bs_fail(err, errlen, "out of memory");
    memcpy(s->mverts + s->nmverts, ring, sizeof *ring * 2 * (size_t)n);
    s->nmverts += 2u * (uint32_t)n;
    m->part_vert[m->nparts] = (uint8_t)base;
    m->part_sides[m->nparts] = (uint8_t)n;

    uint8_t part = (uint8_t)m->nparts;
    uint32_t idx[SCN_MAX_FACE_VERTS];
    for (int k = 0; k < n; k++) {
        int j = (k + 1) % n;
        idx[0] = base + (uint32_t)k;
        idx[1] = base + (uint32_t)j;
        idx[2] = base + (uint32_t)(n + j);
        idx[3] = base + (uint32_t)(n + k);
        /* Doom's fake contrast: a face whose normal points along x (its edge
         * runs north-south) darker, along y lighter */
        int contrast = (ring[k].y == ring[j].y) ? 1 : (ring[k].x == ring[j].x) ? -1 : 0;
        if (push_face(s, idx, 4, bs_scene_shade(s, p->side, contrast), part))
            return bs_fail(err, errlen, "out of memory");
    }
    for (int k = 0; k < n; k++) idx[k] = base + (uint32_t)(n + k);
    if (push_face(s, idx, n, p->top, part)) return bs_fail(err, errlen, "out of memory");
    idx[0] = base;
    for (int k = 1; k < n; k++) idx[k] = base + (uint32_t)(n - k);
    if (push_face(s, idx, n, p->bottom, part)) return bs_fail(err, errlen, "out of memory");
    m->num_verts += 2u * (uint32_t)n;
    m->num_faces += (uint32_t)n + 2u;
    m->nparts++;
    return 0;
}

int bs_model_end(bs_scene *s, char *err, size_t errlen)
{
    bs_model *m = &s->models[s->nmodels - 1];
    if (m->num_faces == 0) return bs_fail(err, errlen, "model '%s' has no parts", m->name);
    uint64_t r2 = 0;
    m->zmin = INT32_MAX;
    m->zmax = INT32_MIN;
    for (uint32_t i = 0; i < m->num_verts; i++) {
        const bs_mvert *v = &s->mverts[m->first_vert + i];
        uint64_t d = (uint64_t)((int64_t)v->x * v->x) + (uint64_t)((int64_t)v->y * v->y);
        if (d > r2) r2 = d;
        if (v->z < m->zmin) m->zmin = v->z;
        if (v->z > m->zmax) m->zmax = v->z;
    }
    /* the smallest whole raw radius that holds every vertex: ceil(sqrt(r2)) */
    uint64_t r = bs_isqrt(r2);
    if (r * r < r2) r++;
    m->radius = (int32_t)r;
    return 0;
}
