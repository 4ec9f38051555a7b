/* blob_write.c - serialises the built tree as the compiled-scene blob of
 * firmware/scene_format.h: little-endian whatever the host, header first,
 * sections in enum order, each 4-byte aligned, CRC-32 over bytes [16, total). */
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"
#include "crc32.h"

_Static_assert(sizeof(scn_header) == 44 + 8 * SCN_SEC_COUNT, "scn_header layout");
_Static_assert(sizeof(scn_vertex) == 8, "scn_vertex layout");
_Static_assert(sizeof(scn_sector) == 16, "scn_sector layout");
_Static_assert(sizeof(scn_model) == 28, "scn_model layout");
_Static_assert(sizeof(scn_mvert) == 12, "scn_mvert layout");
_Static_assert(sizeof(scn_face) == 8, "scn_face layout");
_Static_assert(sizeof(scn_object) == 48, "scn_object layout");
_Static_assert(sizeof(scn_sprite) == 16, "scn_sprite layout");
_Static_assert(sizeof(scn_sprset) == 20, "scn_sprset layout");
_Static_assert(sizeof(scn_line) == 24, "scn_line layout");
_Static_assert(sizeof(scn_seg) == 16, "scn_seg layout");
_Static_assert(sizeof(scn_node) == 56, "scn_node layout");
_Static_assert(sizeof(scn_leaf) == 20, "scn_leaf layout");
_Static_assert(sizeof(scn_look) == 8, "scn_look layout");
_Static_assert(sizeof(scn_texture) == 12, "scn_texture layout");
_Static_assert(sizeof(scn_side) == 24, "scn_side layout");
_Static_assert(sizeof(scn_plane) == 4, "scn_plane layout");
_Static_assert(sizeof(scn_anim) == 12, "scn_anim layout");

typedef struct {
    uint8_t *p;
    size_t at;
} wr;

static void w8(wr *w, uint8_t v)
{
    w->p[w->at++] = v;
}
static void w16(wr *w, uint16_t v)
{
    w8(w, (uint8_t)v);
    w8(w, (uint8_t)(v >> 8));
}
static void w32(wr *w, uint32_t v)
{
    w16(w, (uint16_t)v);
    w16(w, (uint16_t)(v >> 16));
}
static void wi32(wr *w, int32_t v)
{
    w32(w, (uint32_t)v);
}

static void bbox_add(int32_t b[4], int32_t x, int32_t y)
{
    if (y > b[0]) b[0] = y; /* top */
    if (y < b[1]) b[1] = y; /* bottom */
    if (x < b[2]) b[2] = x; /* left */
    if (x > b[3]) b[3] = x; /* right */
}

static void bbox_union(int32_t b[4], const int32_t c[4])
{
    if (c[0] > b[0]) b[0] = c[0];
    if (c[1] < b[1]) b[1] = c[1];
    if (c[2] < b[2]) b[2] = c[2];
    if (c[3] > b[3]) b[3] = c[3];
}

static const int32_t empty_box[4] = {INT32_MIN, INT32_MAX, INT32_MAX, INT32_MIN};

/* bbox of a child: leaf polygon and segs, or the union of a node's children */
static void child_box(const bs_tree *t, uint32_t child, int32_t (*nodebox)[4], int32_t out[4])
{
    memcpy(out, empty_box, sizeof empty_box);
    if (child & SCN_LEAF_BIT) {
        const bs_leaf *L = &t->leaves[child & ~SCN_LEAF_BIT];
        for (uint32_t k = 0; k < L->poly.n; k++) bbox_add(out, L->poly.v[k].x, L->poly.v[k].y);
        for (uint32_t k = 0; k < L->nsegs; k++) {
            const bs_seg *g = &t->segs[L->segs[k]];
            bbox_add(out, g->x1, g->y1);
            bbox_add(out, g->x2, g->y2);
        }
    } else {
        memcpy(out, nodebox[child], sizeof(int32_t) * 4);
    }
}

/* ---- pass: node boxes ---- */

/* Each node's two child boxes, children before parents (nodes are numbered
 * parent first); an empty child (no geometry below) gets an all-zero box. */
static int blob_child_boxes(const bs_tree *t, int32_t (*childbox)[2][4])
{
    int32_t(*nodebox)[4] = malloc(sizeof *nodebox * (t->nnodes + 1));
    if (!nodebox) return -1;
    for (uint32_t i = t->nnodes; i-- > 0;) {
        memcpy(nodebox[i], empty_box, sizeof empty_box);
        for (int c = 0; c < 2; c++) {
            child_box(t, t->nodes[i].child[c], nodebox, childbox[i][c]);
            if (childbox[i][c][0] < childbox[i][c][1]) /* empty: no geometry below */
                memset(childbox[i][c], 0, sizeof childbox[i][c]);
            else
                bbox_union(nodebox[i], childbox[i][c]);
        }
    }
    free(nodebox);
    return 0;
}

/* ---- layout ---- */

/* Every section's record count and 4-aligned offset; returns the blob's size
 * (which may not fit in 32 bits: the caller refuses that). */
static uint64_t blob_layout(const bs_scene *s, const bs_tree *t, uint32_t counts[SCN_SEC_COUNT],
                            uint32_t off[SCN_SEC_COUNT])
{
    uint32_t npv = 0;
    for (uint32_t i = 0; i < t->nleaves; i++) npv += t->leaves[i].poly.n;
    const bs_look *lk = &s->look;
    int look = lk->present;
    const uint32_t c[SCN_SEC_COUNT] = {t->nverts,
                                       s->nsectors,
                                       s->nlines,
                                       t->nsegs,
                                       t->nnodes,
                                       t->nleaves,
                                       npv,
                                       256,
                                       s->nmodels,
                                       s->nmverts,
                                       s->nfaces,
                                       s->nfindex,
                                       s->nobjects,
                                       1,
                                       look ? 1u : 0u,
                                       look ? SCN_LIGHT_MAPS : 0u,
                                       look ? lk->ntex : 0u,
                                       look ? lk->ntexels : 0u,
                                       look ? 2u * s->nlines : 0u,
                                       look ? s->nsectors : 0u,
                                       look ? lk->nsprites : 0u,
                                       look ? lk->nsprmask : 0u,
                                       look ? lk->nsprsets : 0u,
                                       look ? lk->nanims : 0u};
    static const uint32_t recsz[SCN_SEC_COUNT] = {8, 12 + 4, 24, 16, 56, 20, 8,  3, 28, 12, 8, 4, 48, sizeof(scn_needs),
                                                  8, 256,    12, 1,  24, 4,  16, 4, 20, 12};
    uint64_t at = sizeof(scn_header);
    for (int k = 0; k < SCN_SEC_COUNT; k++) {
        at = (at + 3) & ~(uint64_t)3;
        counts[k] = c[k];
        off[k] = (uint32_t)at;
        at += (uint64_t)c[k] * recsz[k];
    }
    return (at + 3) & ~(uint64_t)3;
}

/* ---- section writers ---- */

/* What the section writers read: the scene, its tree and the node boxes. */
typedef struct {
    const bs_scene *s;
    const bs_tree *t;
    int32_t (*childbox)[2][4];
} blob_src;

static void put_header(wr *w, const blob_src *b, uint32_t size, const uint32_t counts[SCN_SEC_COUNT],
                       const uint32_t off[SCN_SEC_COUNT])
{
    w32(w, SCN_MAGIC);
    w16(w, SCN_VERSION);
    w16(w, (uint16_t)sizeof(scn_header));
    w32(w, size);
    w32(w, 0); /* crc, at the end */
    w32(w, 0); /* flags */
    wi32(w, b->s->player_x);
    wi32(w, b->s->player_y);
    wi32(w, b->s->player_angle);
    w32(w, b->s->player_sector);
    w32(w, b->t->root);
    w32(w, b->t->max_depth);
    for (int k = 0; k < SCN_SEC_COUNT; k++) {
        w32(w, off[k]);
        w32(w, counts[k]);
    }
}

static void put_vertices(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->t->nverts; i++) {
        wi32(w, b->t->vx[i]);
        wi32(w, b->t->vy[i]);
    }
}

static void put_sectors(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->nsectors; i++) {
        const bs_sector *c = &b->s->sectors[i];
        wi32(w, c->floor_h);
        wi32(w, c->ceil_h);
        w8(w, c->floor_color);
        w8(w, c->ceil_color);
        w8(w, c->light);
        w8(w, c->flags);
        wi32(w, (c->flags & SCN_SECTOR_DOOR) ? c->open_h : c->ceil_h);
    }
}

static void put_lines(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->nlines; i++) {
        const bs_line *l = &b->s->lines[i];
        w32(w, b->t->line_v[2 * i]);
        w32(w, b->t->line_v[2 * i + 1]);
        w32(w, l->sector[0]);
        w32(w, l->sector[1]);
        for (int sd = 0; sd < 2; sd++)
            for (int part = 0; part < 3; part++) w8(w, l->color[sd][part]);
        w16(w, 0);
    }
}

/* segs grouped by leaf, in leaf order: put_leaves numbers them the same way */
static void put_segs(wr *w, const blob_src *b)
{
    const bs_tree *t = b->t;
    for (uint32_t i = 0; i < t->nleaves; i++) {
        const bs_leaf *L = &t->leaves[i];
        for (uint32_t k = 0; k < L->nsegs; k++) {
            const bs_seg *g = &t->segs[L->segs[k]];
            w32(w, g->v1);
            w32(w, g->v2);
            w32(w, g->line);
            w32(w, g->side);
        }
    }
}

static void put_nodes(wr *w, const blob_src *b)
{
    const bs_tree *t = b->t;
    for (uint32_t i = 0; i < t->nnodes; i++) {
        const bs_node *N = &t->nodes[i];
        const bs_pline *P = &t->plines[N->pline];
        wi32(w, P->x);
        wi32(w, P->y);
        wi32(w, N->rev ? -P->dx : P->dx);
        wi32(w, N->rev ? -P->dy : P->dy);
        for (int c = 0; c < 2; c++)
            for (int k = 0; k < 4; k++) wi32(w, b->childbox[i][c][k]);
        w32(w, N->child[0]);
        w32(w, N->child[1]);
    }
}

static void put_leaves(wr *w, const blob_src *b)
{
    uint32_t fs = 0, fp = 0;
    for (uint32_t i = 0; i < b->t->nleaves; i++) {
        const bs_leaf *L = &b->t->leaves[i];
        w32(w, fs);
        w32(w, L->nsegs);
        w32(w, L->sector);
        w32(w, fp);
        w32(w, L->poly.n);
        fs += L->nsegs;
        fp += L->poly.n;
    }
}

static void put_pverts(wr *w, const blob_src *b)
{
    const bs_tree *t = b->t;
    for (uint32_t i = 0; i < t->nleaves; i++)
        for (uint32_t k = 0; k < t->leaves[i].poly.n; k++) {
            wi32(w, t->leaves[i].poly.v[k].x);
            wi32(w, t->leaves[i].poly.v[k].y);
        }
}

/* the WAD's PLAYPAL when it has one, else the built-in palette */
static void put_palette(wr *w, const blob_src *b)
{
    if (b->s->look.doom_palette)
        memcpy(w->p + w->at, b->s->look.palette, 768);
    else
        bs_palette(w->p + w->at);
}

static void put_models(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->nmodels; i++) {
        const bs_model *m = &b->s->models[i];
        w32(w, m->first_vert);
        w32(w, m->num_verts);
        w32(w, m->first_face);
        w32(w, m->num_faces);
        wi32(w, m->radius);
        wi32(w, m->zmin);
        wi32(w, m->zmax);
    }
}

static void put_mverts(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->nmverts; i++) {
        wi32(w, b->s->mverts[i].x);
        wi32(w, b->s->mverts[i].y);
        wi32(w, b->s->mverts[i].z);
    }
}

static void put_faces(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->nfaces; i++) {
        const bs_face *f = &b->s->faces[i];
        w32(w, f->first_index);
        w16(w, f->num_index);
        w8(w, f->colour);
        w8(w, f->part);
    }
}

static void put_findex(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->nfindex; i++) w32(w, b->s->findex[i]);
}

static void put_objects(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->nobjects; i++) {
        const bs_object *o = &b->s->objects[i];
        w32(w, o->model);
        wi32(w, o->x);
        wi32(w, o->y);
        wi32(w, o->z);
        wi32(w, o->yaw);
        w32(w, o->path);
        wi32(w, o->pa);
        wi32(w, o->pb);
        w32(w, o->period_ms);
        wi32(w, o->spin);
        w32(w, o->sprset1 ? o->sprset1 - 1 : SCN_NONE);
        w32(w, o->side1 ? o->side1 - 1 : SCN_NONE);
    }
}

static void put_look(wr *w, const blob_src *b)
{
    w32(w, b->s->look.sky_tex);
    w32(w, 0);
}

static void put_lights(wr *w, const blob_src *b)
{
    memcpy(w->p + w->at, b->s->look.lights, 256 * SCN_LIGHT_MAPS);
}

static void put_textures(wr *w, const blob_src *b)
{
    const bs_look *lk = &b->s->look;
    for (uint32_t i = 0; i < lk->ntex; i++) {
        w32(w, lk->tex[i].first);
        w8(w, lk->tex[i].wbits);
        w8(w, lk->tex[i].hbits);
        w8(w, lk->tex[i].colour);
        w8(w, 0);
        w16(w, lk->tex[i].height);
        w16(w, lk->tex[i].mask);
    }
}

static void put_texels(wr *w, const blob_src *b)
{
    memcpy(w->p + w->at, b->s->look.texels, b->s->look.ntexels);
}

static void put_sides(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < 2 * b->s->nlines; i++) {
        const scn_side *d = &b->s->look.sides[i];
        wi32(w, d->ux);
        wi32(w, d->uy);
        wi32(w, d->u0);
        wi32(w, d->row_off);
        for (int k = 0; k < 3; k++) w16(w, d->tex[k]);
        w8(w, d->flags);
        w8(w, (uint8_t)d->light_adj);
    }
}

static void put_planes(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->nsectors; i++) {
        w16(w, b->s->look.planes[i].floor_tex);
        w16(w, b->s->look.planes[i].ceil_tex);
    }
}

static void put_sprites(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->look.nsprites; i++) {
        const scn_sprite *p = &b->s->look.sprites[i];
        w32(w, p->first);
        w32(w, p->mask);
        w16(w, p->width);
        w16(w, p->height);
        w16(w, (uint16_t)p->left);
        w16(w, (uint16_t)p->top);
    }
}

static void put_sprmask(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->look.nsprmask; i++) w32(w, b->s->look.sprmask[i]);
}

static void put_sprsets(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->look.nsprsets; i++) {
        const scn_sprset *p = &b->s->look.sprsets[i];
        for (int r = 0; r < SCN_SPRITE_ROTS; r++) w16(w, p->image[r]);
        w8(w, p->mirror);
        w8(w, p->flags);
        w16(w, 0);
    }
}

static void put_anims(wr *w, const blob_src *b)
{
    for (uint32_t i = 0; i < b->s->look.nanims; i++) {
        const scn_anim *a = &b->s->look.anims[i];
        w32(w, a->first);
        w16(w, a->count);
        w16(w, a->phase);
        w16(w, a->tics);
        w16(w, 0);
    }
}

/* One writer per section, in enum order. The needs record (SCN_SEC_NEEDS) has
 * none: it stays zero here, and bspc.c fills it in from the analysis of this
 * very blob and recomputes the CRC. */
static void (*const put_section[SCN_SEC_COUNT])(wr *, const blob_src *) = {
    [SCN_SEC_VERTICES] = put_vertices, [SCN_SEC_SECTORS] = put_sectors, [SCN_SEC_LINES] = put_lines,
    [SCN_SEC_SEGS] = put_segs,         [SCN_SEC_NODES] = put_nodes,     [SCN_SEC_LEAVES] = put_leaves,
    [SCN_SEC_PVERTS] = put_pverts,     [SCN_SEC_PALETTE] = put_palette, [SCN_SEC_MODELS] = put_models,
    [SCN_SEC_MVERTS] = put_mverts,     [SCN_SEC_FACES] = put_faces,     [SCN_SEC_FINDEX] = put_findex,
    [SCN_SEC_OBJECTS] = put_objects,   [SCN_SEC_LOOK] = put_look,       [SCN_SEC_LIGHTS] = put_lights,
    [SCN_SEC_TEXTURES] = put_textures, [SCN_SEC_TEXELS] = put_texels,   [SCN_SEC_SIDES] = put_sides,
    [SCN_SEC_PLANES] = put_planes,     [SCN_SEC_SPRITES] = put_sprites, [SCN_SEC_SPRMASK] = put_sprmask,
    [SCN_SEC_SPRSETS] = put_sprsets,   [SCN_SEC_ANIMS] = put_anims,
};

int bs_write_blob(const bs_scene *s, const bs_tree *t, uint8_t **blob, size_t *len, char *err, size_t errlen)
{
    int32_t(*childbox)[2][4] = malloc(sizeof *childbox * (t->nnodes + 1));
    if (!childbox || blob_child_boxes(t, childbox)) {
        free(childbox);
        return bs_fail(err, errlen, "%s: out of memory", s->name);
    }
    uint32_t counts[SCN_SEC_COUNT], off[SCN_SEC_COUNT];
    uint64_t size = blob_layout(s, t, counts, off);
    uint8_t *p = size > UINT32_MAX ? NULL : calloc((size_t)size, 1);
    if (!p) {
        free(childbox);
        if (size > UINT32_MAX) return bs_fail(err, errlen, "%s: compiled scene larger than 4 GiB", s->name);
        return bs_fail(err, errlen, "%s: out of memory", s->name);
    }
    blob_src b = {s, t, childbox};
    wr w = {p, 0};
    put_header(&w, &b, (uint32_t)size, counts, off);
    /* a section without records is not written: the look's sections have
     * none when the scene has no look (their sources are then empty) */
    for (int k = 0; k < SCN_SEC_COUNT; k++)
        if (put_section[k] && counts[k]) {
            w.at = off[k];
            put_section[k](&w, &b);
        }
    uint32_t crc = crc_update(0, p + 16, (size_t)size - 16);
    w.at = 12;
    w32(&w, crc);
    free(childbox);
    *blob = p;
    *len = (size_t)size;
    return 0;
}
