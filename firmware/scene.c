/* scene.c - compiled-scene validation and point location. Every offset, count and
 * index is checked here, in 64-bit arithmetic so no sum can wrap; the tree walk
 * that proves the node graph is a tree is bounded by the node count. */
#include "scene.h"
#include "build_config.h"
#include "crc32.h"
#include "fixed.h"

static const uint32_t record_bytes[SCN_SEC_COUNT] = {
    sizeof(scn_vertex),  sizeof(scn_sector),
    sizeof(scn_line),    sizeof(scn_seg),
    sizeof(scn_node),    sizeof(scn_leaf),
    sizeof(scn_vertex),  3,
    sizeof(scn_model),   sizeof(scn_mvert),
    sizeof(scn_face),    sizeof(uint32_t),
    sizeof(scn_object),  sizeof(scn_needs),
    sizeof(scn_look),    256,
    sizeof(scn_texture), 1,
    sizeof(scn_side),    sizeof(scn_plane),
    sizeof(scn_sprite),  sizeof(uint32_t),
    sizeof(scn_sprset),  sizeof(scn_anim),
};

const char *scene_status_text(scene_status st)
{
    static const char *const text[SCENE_ERR_COUNT] = {
        "ok",
        "truncated",
        "not 4-byte aligned in memory",
        "wrong magic (not a compiled scene)",
        "unsupported version",
        "inconsistent header",
        "bad CRC-32",
        "section outside the blob",
        "index out of range",
        "value outside the proven-safe range",
        "node graph is not a tree or is too deep",
        "needs record does not match the scene",
        "needs more than this build provides",
    };
    return ((unsigned)st < SCENE_ERR_COUNT) ? text[st] : "unknown error";
}

const char *scene_section_name(int section)
{
    static const char *const names[SCN_SEC_COUNT] = {
        "vertices",     "sectors",      "lines",          "segs",   "nodes",        "leaves",  "leaf polygon vertices",
        "palette",      "models",       "model vertices", "faces",  "face indices", "objects", "needs",
        "look",         "light tables", "textures",       "texels", "sides",        "planes",  "sprites",
        "sprite masks", "sprite sets",  "animations",
    };
    return (section >= 0 && section < SCN_SEC_COUNT) ? names[section] : "header";
}

static scene_status fail(scene_error *err, scene_status st, int section, uint32_t index)
{
    if (err) {
        err->status = st;
        err->section = section;
        err->index = index;
    }
    return st;
}

static scene_status refuse(scene_error *err, uint32_t item, uint32_t need, uint32_t have)
{
    if (err) {
        err->need = need;
        err->have = have;
    }
    return fail(err, SCENE_ERR_BUILD, SCN_SEC_NEEDS, item);
}

const char *scene_item_name(uint32_t item)
{
    static const char *const names[SCENE_ITEM_COUNT] = {
        "objects",
        "doors",
        "two-sided walls",
        "height changes",
        "sky steps",
        "look up/down",
        "y-clipping",
        "textures",
        "animation",
        "edges per frame",
        "surfaces per frame",
        "tree depth",
        "leaf polygon vertices",
        "model vertices",
        "face vertices",
    };
    return item < SCENE_ITEM_COUNT ? names[item] : "?";
}

static int coord_ok(int32_t v, int32_t limit_units)
{
    int64_t lim = (int64_t)limit_units << 16;
    return v >= -lim && v <= lim;
}

/* The look's sections: none at all (a flat-shaded scene: every section after
 * the look is empty), or one look record with all 32 light tables, a side per
 * line side and a plane per sector. */
static scene_status check_look_sections(scene *s, const uint8_t *base, const scn_header *h, scene_error *err)
{
    const scn_section *sec = h->sec;
    uint32_t look = sec[SCN_SEC_LOOK].count;
    if (look > 1) return fail(err, SCENE_ERR_SECTION, SCN_SEC_LOOK, 0);
    if (look == 0) {
        for (int i = SCN_SEC_LIGHTS; i < SCN_SEC_COUNT; i++)
            if (sec[i].count != 0) return fail(err, SCENE_ERR_SECTION, i, 0);
        s->look = 0;
    } else {
        if (sec[SCN_SEC_LIGHTS].count != SCN_LIGHT_MAPS) return fail(err, SCENE_ERR_SECTION, SCN_SEC_LIGHTS, 0);
        if (sec[SCN_SEC_TEXTURES].count < 1) return fail(err, SCENE_ERR_SECTION, SCN_SEC_TEXTURES, 0);
        if ((uint64_t)sec[SCN_SEC_SIDES].count != 2u * (uint64_t)s->nlines)
            return fail(err, SCENE_ERR_SECTION, SCN_SEC_SIDES, 0);
        if (sec[SCN_SEC_PLANES].count != s->nsectors) return fail(err, SCENE_ERR_SECTION, SCN_SEC_PLANES, 0);
        s->look = (const scn_look *)(base + sec[SCN_SEC_LOOK].offset);
    }
    s->lights = base + sec[SCN_SEC_LIGHTS].offset;
    s->textures = (const scn_texture *)(base + sec[SCN_SEC_TEXTURES].offset);
    s->texels = base + sec[SCN_SEC_TEXELS].offset;
    s->sides = (const scn_side *)(base + sec[SCN_SEC_SIDES].offset);
    s->planes = (const scn_plane *)(base + sec[SCN_SEC_PLANES].offset);
    s->sprites = (const scn_sprite *)(base + sec[SCN_SEC_SPRITES].offset);
    s->sprmask = (const uint32_t *)(base + sec[SCN_SEC_SPRMASK].offset);
    s->sprsets = (const scn_sprset *)(base + sec[SCN_SEC_SPRSETS].offset);
    s->nsprites = sec[SCN_SEC_SPRITES].count;
    s->nsprmask = sec[SCN_SEC_SPRMASK].count;
    s->nsprsets = sec[SCN_SEC_SPRSETS].count;
    s->anims = (const scn_anim *)(base + sec[SCN_SEC_ANIMS].offset);
    s->nanims = sec[SCN_SEC_ANIMS].count;
    s->nlights = sec[SCN_SEC_LIGHTS].count;
    s->ntextures = sec[SCN_SEC_TEXTURES].count;
    s->ntexels = sec[SCN_SEC_TEXELS].count;
    return SCENE_OK;
}

static scene_status check_sections(scene *s, const uint8_t *base, const scn_header *h, scene_error *err)
{
    for (int i = 0; i < SCN_SEC_COUNT; i++) {
        uint64_t off = h->sec[i].offset;
        uint64_t end = off + (uint64_t)h->sec[i].count * record_bytes[i];
        if ((off & 3u) || off < h->header_bytes || end > h->total_bytes) return fail(err, SCENE_ERR_SECTION, i, 0);
    }
    if (h->sec[SCN_SEC_PALETTE].count != 256) return fail(err, SCENE_ERR_SECTION, SCN_SEC_PALETTE, 0);
    if (h->sec[SCN_SEC_NEEDS].count != 1) return fail(err, SCENE_ERR_SECTION, SCN_SEC_NEEDS, 0);
    s->needs = (const scn_needs *)(base + h->sec[SCN_SEC_NEEDS].offset);
    s->verts = (const scn_vertex *)(base + h->sec[SCN_SEC_VERTICES].offset);
    s->sectors = (const scn_sector *)(base + h->sec[SCN_SEC_SECTORS].offset);
    s->lines = (const scn_line *)(base + h->sec[SCN_SEC_LINES].offset);
    s->segs = (const scn_seg *)(base + h->sec[SCN_SEC_SEGS].offset);
    s->nodes = (const scn_node *)(base + h->sec[SCN_SEC_NODES].offset);
    s->leaves = (const scn_leaf *)(base + h->sec[SCN_SEC_LEAVES].offset);
    s->pverts = (const scn_vertex *)(base + h->sec[SCN_SEC_PVERTS].offset);
    s->palette = base + h->sec[SCN_SEC_PALETTE].offset;
    s->nverts = h->sec[SCN_SEC_VERTICES].count;
    s->nsectors = h->sec[SCN_SEC_SECTORS].count;
    s->nlines = h->sec[SCN_SEC_LINES].count;
    s->nsegs = h->sec[SCN_SEC_SEGS].count;
    s->nnodes = h->sec[SCN_SEC_NODES].count;
    s->nleaves = h->sec[SCN_SEC_LEAVES].count;
    s->npverts = h->sec[SCN_SEC_PVERTS].count;
    s->models = (const scn_model *)(base + h->sec[SCN_SEC_MODELS].offset);
    s->mverts = (const scn_mvert *)(base + h->sec[SCN_SEC_MVERTS].offset);
    s->faces = (const scn_face *)(base + h->sec[SCN_SEC_FACES].offset);
    s->findex = (const uint32_t *)(base + h->sec[SCN_SEC_FINDEX].offset);
    s->objects = (const scn_object *)(base + h->sec[SCN_SEC_OBJECTS].offset);
    s->nmodels = h->sec[SCN_SEC_MODELS].count;
    s->nmverts = h->sec[SCN_SEC_MVERTS].count;
    s->nfaces = h->sec[SCN_SEC_FACES].count;
    s->nfindex = h->sec[SCN_SEC_FINDEX].count;
    s->nobjects = h->sec[SCN_SEC_OBJECTS].count;
    return check_look_sections(s, base, h, err);
}

static scene_status check_geometry(const scene *s, scene_error *err)
{
    for (uint32_t i = 0; i < s->nverts; i++)
        if (!coord_ok(s->verts[i].x, SCN_COORD_MAX) || !coord_ok(s->verts[i].y, SCN_COORD_MAX))
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_VERTICES, i);
    for (uint32_t i = 0; i < s->npverts; i++)
        if (!coord_ok(s->pverts[i].x, SCN_COORD_MAX) || !coord_ok(s->pverts[i].y, SCN_COORD_MAX))
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_PVERTS, i);
    for (uint32_t i = 0; i < s->nsectors; i++) {
        const scn_sector *sec = &s->sectors[i];
        if (!coord_ok(sec->floor_h, SCN_HEIGHT_MAX) || !coord_ok(sec->ceil_h, SCN_HEIGHT_MAX))
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_SECTORS, i);
        /* a door's ceiling moves between ceil_h and open_h; every other ceiling stays put */
        int door_ok = (sec->flags & SCN_SECTOR_DOOR)
                          ? sec->open_h >= sec->ceil_h && coord_ok(sec->open_h, SCN_HEIGHT_MAX)
                          : sec->open_h == sec->ceil_h;
        if (!door_ok) return fail(err, SCENE_ERR_RANGE, SCN_SEC_SECTORS, i);
    }
    for (uint32_t i = 0; i < s->nlines; i++) {
        const scn_line *l = &s->lines[i];
        if (l->v1 >= s->nverts || l->v2 >= s->nverts || l->sector[0] >= s->nsectors ||
            (l->sector[1] != SCN_NONE && l->sector[1] >= s->nsectors))
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_LINES, i);
    }
    for (uint32_t i = 0; i < s->nsegs; i++) {
        const scn_seg *g = &s->segs[i];
        if (g->v1 >= s->nverts || g->v2 >= s->nverts || g->line >= s->nlines || g->side > 1 ||
            s->lines[g->line].sector[g->side] == SCN_NONE)
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_SEGS, i);
    }
    for (uint32_t i = 0; i < s->nleaves; i++) {
        const scn_leaf *f = &s->leaves[i];
        if ((uint64_t)f->first_seg + f->num_segs > s->nsegs || (uint64_t)f->first_pvert + f->num_pverts > s->npverts ||
            f->num_pverts > SCN_MAX_LEAF_VERTS || (f->sector != SCN_NONE && f->sector >= s->nsectors))
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_LEAVES, i);
    }
    for (uint32_t i = 0; i < s->nnodes; i++) {
        const scn_node *n = &s->nodes[i];
        if (!coord_ok(n->x, SCN_COORD_MAX) || !coord_ok(n->y, SCN_COORD_MAX) || (n->dx == 0 && n->dy == 0) ||
            n->dx == INT32_MIN || n->dy == INT32_MIN)
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_NODES, i);
        for (int c = 0; c < 2; c++) {
            uint32_t ch = n->child[c];
            if ((ch & SCN_LEAF_BIT) ? (ch & ~SCN_LEAF_BIT) >= s->nleaves : ch >= s->nnodes)
                return fail(err, SCENE_ERR_INDEX, SCN_SEC_NODES, i);
            for (int k = 0; k < 4; k++)
                if (!coord_ok(n->bbox[c][k], SCN_COORD_MAX)) return fail(err, SCENE_ERR_RANGE, SCN_SEC_NODES, i);
        }
    }
    return SCENE_OK;
}

/* Limits of docs/objects.md beyond scene_format.h: they keep an object's path
 * arithmetic (position = function of t) inside 64 bits. */
#define OBJ_PERIOD_MAX_MS 3600000u
#define OBJ_SPIN_MAX 3600

/* Is r the smallest whole raw radius that holds a vertex at squared distance
 * d2: (r - 1)^2 < d2 <= r^2? d2 < 2^53 and r < 2^27, so every square fits. */
static int radius_matches(int32_t r, uint64_t d2)
{
    if (r < 0 || r > ((int32_t)SCN_MODEL_MAX << 16) * 2) return 0;
    uint64_t ur = (uint64_t)r;
    return ur * ur >= d2 && (ur == 0 || (ur - 1) * (ur - 1) < d2);
}

/* Models, their vertices, faces and face indices, then the objects that place
 * them: every range inside its section, every face vertex inside its model, the
 * stored bounds equal to those of the vertices, every path inside the box. */
static scene_status check_objects(const scene *s, scene_error *err)
{
    for (uint32_t i = 0; i < s->nmverts; i++) {
        const scn_mvert *v = &s->mverts[i];
        if (!coord_ok(v->x, SCN_MODEL_MAX) || !coord_ok(v->y, SCN_MODEL_MAX) || !coord_ok(v->z, SCN_MODEL_MAX))
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_MVERTS, i);
    }
    for (uint32_t i = 0; i < s->nfaces; i++) {
        const scn_face *f = &s->faces[i];
        if (f->num_index < 3 || f->num_index > SCN_MAX_FACE_VERTS ||
            (uint64_t)f->first_index + f->num_index > s->nfindex)
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_FACES, i);
    }
    for (uint32_t i = 0; i < s->nmodels; i++) {
        const scn_model *m = &s->models[i];
        if (m->num_verts < 3 || m->num_verts > SCN_MAX_MODEL_VERTS || m->num_faces < 1 ||
            m->num_faces > SCN_MAX_MODEL_FACES || (uint64_t)m->first_vert + m->num_verts > s->nmverts ||
            (uint64_t)m->first_face + m->num_faces > s->nfaces)
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_MODELS, i);
        for (uint32_t k = 0; k < m->num_faces; k++) {
            const scn_face *f = &s->faces[m->first_face + k];
            for (uint32_t j = 0; j < f->num_index; j++)
                if (s->findex[f->first_index + j] >= m->num_verts) return fail(err, SCENE_ERR_INDEX, SCN_SEC_MODELS, i);
        }
        uint64_t d2 = 0;
        int32_t zmin = INT32_MAX, zmax = INT32_MIN;
        for (uint32_t k = 0; k < m->num_verts; k++) {
            const scn_mvert *v = &s->mverts[m->first_vert + k];
            uint64_t d = (uint64_t)((int64_t)v->x * v->x) + (uint64_t)((int64_t)v->y * v->y);
            if (d > d2) d2 = d;
            if (v->z < zmin) zmin = v->z;
            if (v->z > zmax) zmax = v->z;
        }
        if (!radius_matches(m->radius, d2) || m->zmin != zmin || m->zmax != zmax)
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_MODELS, i);
    }
    if (s->nobjects > SCN_MAX_OBJECTS) return fail(err, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, SCN_MAX_OBJECTS);
    const int64_t box = (int64_t)SCN_COORD_MAX << 16;
    for (uint32_t i = 0; i < s->nobjects; i++) {
        const scn_object *o = &s->objects[i];
        if (o->model >= s->nmodels) return fail(err, SCENE_ERR_INDEX, SCN_SEC_OBJECTS, i);
        if (o->path > SCN_PATH_LINE) return fail(err, SCENE_ERR_INDEX, SCN_SEC_OBJECTS, i);
        /* the extent of the whole path, which for no path is the origin */
        int64_t lo[2] = {o->x, o->y}, hi[2] = {o->x, o->y};
        int ok = coord_ok(o->z, SCN_HEIGHT_MAX) && o->spin >= -(OBJ_SPIN_MAX << 16) && o->spin <= (OBJ_SPIN_MAX << 16);
        if (o->path == SCN_PATH_NONE) {
            ok = ok && o->pa == 0 && o->pb == 0 && o->period_ms == 0;
        } else {
            ok = ok && o->period_ms > 0 && o->period_ms <= OBJ_PERIOD_MAX_MS;
            if (o->path == SCN_PATH_CIRCLE) {
                ok = ok && o->pa > 0 && o->pb == 0;
                for (int k = 0; k < 2; k++) {
                    lo[k] -= o->pa;
                    hi[k] += o->pa;
                }
            } else {
                int64_t d[2] = {o->pa, o->pb};
                ok = ok && (o->pa != 0 || o->pb != 0);
                for (int k = 0; k < 2; k++) {
                    if (d[k] < 0)
                        lo[k] += d[k];
                    else
                        hi[k] += d[k];
                }
            }
        }
        for (int k = 0; k < 2; k++) ok = ok && lo[k] >= -box && hi[k] <= box;
        if (!ok) return fail(err, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, i);
    }
    return SCENE_OK;
}

static int tex_ok(const scene *s, uint32_t t)
{
    return t == SCN_TEX_NONE || t < s->ntextures;
}

/* Every sequence of frames inside the textures (an index), then within the
 * format's limits, sorted and apart from the one before (docs/textures.md,
 * "Animation"): a texture is a frame of one sequence at most, so the
 * translation by time (firmware/anim.h) is one answer. */
static scene_status check_anims(const scene *s, scene_error *err)
{
    uint64_t end = 0; /* past the last frame of the sequence before */
    for (uint32_t i = 0; i < s->nanims; i++) {
        const scn_anim *a = &s->anims[i];
        if ((uint64_t)a->first + a->count > s->ntextures) return fail(err, SCENE_ERR_INDEX, SCN_SEC_ANIMS, i);
        if (a->count < 2 || a->count > SCN_ANIM_MAX_FRAMES || a->phase >= a->count || a->tics < 1 ||
            a->tics > SCN_ANIM_MAX_TICS || a->reserved != 0 || a->first < end)
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_ANIMS, i);
        end = (uint64_t)a->first + a->count;
    }
    return SCENE_OK;
}

/* Every texture inside the texels, every texture index in range, every side's
 * mapping a unit vector's size, every reserved field 0 (docs/textures.md). */
static scene_status check_look(const scene *s, scene_error *err)
{
    if (!s->look) return SCENE_OK;
    if (!tex_ok(s, s->look->sky_tex) || s->look->flags != 0) return fail(err, SCENE_ERR_INDEX, SCN_SEC_LOOK, 0);
    for (uint32_t i = 0; i < s->ntextures; i++) {
        const scn_texture *t = &s->textures[i];
        if (t->wbits > SCN_TEX_MAX_BITS || t->hbits > SCN_TEX_MAX_BITS || t->reserved != 0 || t->height == 0 ||
            t->height > (1u << t->hbits))
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_TEXTURES, i);
        if (!tex_ok(s, t->mask) || (t->mask != SCN_TEX_NONE &&
                                    (s->textures[t->mask].wbits != t->wbits || s->textures[t->mask].hbits != t->hbits)))
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_TEXTURES, i);
        if ((uint64_t)t->first + ((uint64_t)1 << (t->wbits + t->hbits)) > s->ntexels)
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_TEXTURES, i);
    }
    const int32_t one = 1 << 30;
    for (uint32_t i = 0; i < 2u * s->nlines; i++) {
        const scn_side *d = &s->sides[i];
        if (!tex_ok(s, d->tex[0]) || !tex_ok(s, d->tex[1]) || !tex_ok(s, d->tex[2]))
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_SIDES, i);
        if ((d->flags & ~(SCN_SIDE_UNPEG_TOP | SCN_SIDE_UNPEG_BOTTOM | SCN_SIDE_SCROLL)) || d->light_adj < -1 ||
            d->light_adj > 1 || d->ux < -one || d->ux > one || d->uy < -one || d->uy > one)
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_SIDES, i);
    }
    for (uint32_t i = 0; i < s->nsectors; i++)
        if (!tex_ok(s, s->planes[i].floor_tex) || !tex_ok(s, s->planes[i].ceil_tex))
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_PLANES, i);
    return check_anims(s, err);
}

/* Every sprite image inside the texels and masks and within its size limits,
 * every sprite set's images in range, and every sprite object's model holding
 * its images in every rotation (docs/objects.md, "Sprites"). */
static scene_status check_sprites(const scene *s, scene_error *err)
{
    const int32_t off_max = SCN_MODEL_MAX;
    for (uint32_t i = 0; i < s->nsprites; i++) {
        const scn_sprite *p = &s->sprites[i];
        if (p->width < 1 || p->width > SCN_SPRITE_MAX || p->height < 1 || p->height > SCN_SPRITE_MAX ||
            p->left < -off_max || p->left > off_max || p->top < -off_max || p->top > off_max)
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_SPRITES, i);
        uint64_t words = (uint64_t)p->width * (((uint32_t)p->height + 31u) >> 5);
        if ((uint64_t)p->first + (uint64_t)p->width * p->height > s->ntexels || (uint64_t)p->mask + words > s->nsprmask)
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_SPRITES, i);
    }
    for (uint32_t i = 0; i < s->nsprsets; i++) {
        const scn_sprset *q = &s->sprsets[i];
        for (int r = 0; r < SCN_SPRITE_ROTS; r++)
            if (q->image[r] >= s->nsprites) return fail(err, SCENE_ERR_INDEX, SCN_SEC_SPRSETS, i);
        if ((q->flags & ~SCN_SPRSET_BRIGHT) || q->reserved != 0) return fail(err, SCENE_ERR_RANGE, SCN_SEC_SPRSETS, i);
    }
    for (uint32_t i = 0; i < s->nobjects; i++) {
        const scn_object *o = &s->objects[i];
        /* a see-through middle texture: a side's of a textured scene that has one, on a one-face model */
        if (o->side != SCN_NONE &&
            (o->side >= 2u * s->nlines || !s->look || s->sides[o->side].tex[SCN_PART_MIDDLE] == SCN_TEX_NONE ||
             o->sprset != SCN_NONE || s->models[o->model].num_faces != 1))
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_OBJECTS, i);
        if (o->sprset == SCN_NONE) continue;
        if (o->sprset >= s->nsprsets) return fail(err, SCENE_ERR_INDEX, SCN_SEC_OBJECTS, i);
        const scn_model *m = &s->models[o->model];
        for (int r = 0; r < SCN_SPRITE_ROTS; r++) {
            const scn_sprite *p = &s->sprites[s->sprsets[o->sprset].image[r]];
            int32_t reach = p->left > p->width - p->left ? p->left : p->width - p->left;
            if ((int64_t)reach << 16 > m->radius || (int64_t)p->top * 65536 > m->zmax || m->zmin > 0)
                return fail(err, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, i);
        }
    }
    return SCENE_OK;
}

/* Walk the whole graph from the root with a stack of SCN_MAX_DEPTH + 1 entries,
 * counting visits: a tree visits each node at most once, so more visits than
 * nodes means a shared child or a cycle. Bounded by nnodes + 1 pops. */
static scene_status check_tree(const scene *s, scene_error *err)
{
    uint32_t stack[SCN_MAX_DEPTH + 1];
    uint8_t depth[SCN_MAX_DEPTH + 1];
    uint32_t sp = 0, visits = 0, deepest = 0;
    uint32_t root = s->hdr->root;
    if (root & SCN_LEAF_BIT) {
        if ((root & ~SCN_LEAF_BIT) >= s->nleaves) return fail(err, SCENE_ERR_INDEX, -1, SCENE_FIELD_ROOT);
        return (s->nnodes == 0) ? SCENE_OK : fail(err, SCENE_ERR_TREE, -1, SCENE_FIELD_ROOT);
    }
    if (root >= s->nnodes) return fail(err, SCENE_ERR_INDEX, -1, SCENE_FIELD_ROOT);
    stack[sp] = root;
    depth[sp++] = 1;
    while (sp > 0) {
        sp--;
        uint32_t n = stack[sp];
        uint32_t d = depth[sp];
        if (++visits > s->nnodes) return fail(err, SCENE_ERR_TREE, SCN_SEC_NODES, n);
        if (d > deepest) deepest = d;
        for (int c = 0; c < 2; c++) {
            uint32_t ch = s->nodes[n].child[c];
            if (ch & SCN_LEAF_BIT) continue;
            if (d >= SCN_MAX_DEPTH || sp > SCN_MAX_DEPTH) return fail(err, SCENE_ERR_TREE, SCN_SEC_NODES, n);
            stack[sp] = ch;
            depth[sp++] = (uint8_t)(d + 1);
        }
    }
    if (deepest > s->hdr->max_depth) return fail(err, SCENE_ERR_TREE, -1, SCENE_FIELD_MAX_DEPTH);
    return SCENE_OK;
}

scene_status scene_parse(scene *s, const void *blob, uint32_t len, scene_error *err)
{
    const uint8_t *base = (const uint8_t *)blob;
    if (err) {
        err->status = SCENE_OK;
        err->section = -1;
        err->index = err->need = err->have = 0;
    }
    if (!blob || len < sizeof(scn_header)) return fail(err, SCENE_ERR_SHORT, -1, 0);
    if (((uintptr_t)blob & 3u) != 0) return fail(err, SCENE_ERR_ALIGN, -1, 0);
    const scn_header *h = (const scn_header *)blob;
    if (h->magic != SCN_MAGIC) return fail(err, SCENE_ERR_MAGIC, -1, SCENE_FIELD_MAGIC);
    if (h->version != SCN_VERSION) return fail(err, SCENE_ERR_VERSION, -1, SCENE_FIELD_VERSION);
    if (h->header_bytes != sizeof(scn_header)) return fail(err, SCENE_ERR_HEADER, -1, SCENE_FIELD_HEADER_BYTES);
    /* total_bytes below the header would make the CRC's length below wrap */
    if ((h->total_bytes & 3u) || h->total_bytes < sizeof(scn_header))
        return fail(err, SCENE_ERR_HEADER, -1, SCENE_FIELD_TOTAL_BYTES);
    if (h->total_bytes > len) return fail(err, SCENE_ERR_SHORT, -1, SCENE_FIELD_TOTAL_BYTES);
    if (crc_update(0, base + 16, h->total_bytes - 16) != h->crc32) return fail(err, SCENE_ERR_CRC, -1, SCENE_FIELD_CRC);
    if (h->flags != 0) return fail(err, SCENE_ERR_HEADER, -1, SCENE_FIELD_FLAGS);
    if (h->max_depth > SCN_MAX_DEPTH) return fail(err, SCENE_ERR_TREE, -1, SCENE_FIELD_MAX_DEPTH);
    if (h->player_sector != SCN_NONE && h->player_sector >= h->sec[SCN_SEC_SECTORS].count)
        return fail(err, SCENE_ERR_INDEX, -1, SCENE_FIELD_PLAYER_SECTOR);
    if (!coord_ok(h->player_x, SCN_COORD_MAX) || !coord_ok(h->player_y, SCN_COORD_MAX))
        return fail(err, SCENE_ERR_RANGE, -1, SCENE_FIELD_PLAYER_START);
    s->hdr = h;
    s->root = h->root;
    scene_status st = check_sections(s, base, h, err);
    if (st == SCENE_OK) st = check_geometry(s, err);
    if (st == SCENE_OK) st = check_objects(s, err);
    if (st == SCENE_OK) st = check_look(s, err);
    if (st == SCENE_OK) st = check_sprites(s, err);
    if (st == SCENE_OK) st = check_tree(s, err);
    return st;
}

int scene_node_side(const scn_node *n, int32_t x, int32_t y)
{
    /* The offset from the partition's point reaches 2^33 raw and the direction
     * (not normalised) 2^31: dropping 3 fraction bits of the offset keeps each
     * product below 2^61 and classifies to 1/8192 unit. */
    int64_t ex = fx_asr64((int64_t)x - n->x, 3), ey = fx_asr64((int64_t)y - n->y, 3);
    int64_t cross = (int64_t)n->dx * ey - (int64_t)n->dy * ex;
    return cross > 0; /* left of the direction is the back */
}

uint32_t scene_leaf_at(const scene *s, int32_t x, int32_t y)
{
    uint32_t n = s->root;
    uint32_t guard = s->nnodes + 1; /* validated tree: never reached */
    while (!(n & SCN_LEAF_BIT) && guard--) n = s->nodes[n].child[scene_node_side(&s->nodes[n], x, y)];
    return n & ~SCN_LEAF_BIT;
}

uint32_t scene_sector_at(const scene *s, int32_t x, int32_t y)
{
    if (s->nleaves == 0) return SCN_NONE;
    return s->leaves[scene_leaf_at(s, x, y)].sector;
}

/* ---- the needs record ------------------------------------------------------ */

uint32_t scene_derived_features(const scene *s)
{
    uint32_t f = s->nmodels ? SCN_NEED_OBJECTS : 0;
    if (s->look) f |= SCN_NEED_TEXTURES;
    if (s->nanims) f |= SCN_NEED_ANIM;
    for (uint32_t i = 0; s->look && i < 2u * s->nlines; i++)
        if (s->sides[i].flags & SCN_SIDE_SCROLL) f |= SCN_NEED_ANIM;
    for (uint32_t i = 0; i < s->nsectors; i++) {
        const scn_sector *a = &s->sectors[i], *b = &s->sectors[0];
        if (a->flags & SCN_SECTOR_DOOR) f |= SCN_NEED_DOORS;
        if (a->open_h != a->ceil_h) f |= SCN_NEED_HEIGHTS; /* doors move apart from each other */
        if (a->floor_h != b->floor_h || a->ceil_h != b->ceil_h || a->open_h != b->open_h) f |= SCN_NEED_HEIGHTS;
    }
    for (uint32_t i = 0; i < s->nlines; i++) {
        const scn_line *l = &s->lines[i];
        if (l->sector[1] == SCN_NONE) continue;
        f |= SCN_NEED_TWO_SIDED;
        if (s->sectors[l->sector[0]].flags & s->sectors[l->sector[1]].flags & SCN_SECTOR_SKY) f |= SCN_NEED_SKY;
    }
    return f;
}

void scene_static_bounds(const scene *s, scn_needs *n)
{
    n->leaf_verts = n->model_verts = n->face_verts = n->object_faces = n->object_edges = 0;
    for (uint32_t i = 0; i < s->nleaves; i++)
        if (s->leaves[i].num_pverts > n->leaf_verts) n->leaf_verts = s->leaves[i].num_pverts;
    for (uint32_t i = 0; i < s->nmodels; i++)
        if (s->models[i].num_verts > n->model_verts) n->model_verts = s->models[i].num_verts;
    for (uint32_t i = 0; i < s->nfaces; i++)
        if (s->faces[i].num_index > n->face_verts) n->face_verts = s->faces[i].num_index;
    for (uint32_t i = 0; i < s->nobjects; i++) { /* validated: at most 4096 x 64 faces of 16 + 5 */
        const scn_model *m = &s->models[s->objects[i].model];
        n->object_faces += m->num_faces;
        n->object_edges += scene_model_edges(s, m);
    }
}

uint32_t scene_model_edges(const scene *s, const scn_model *m)
{
    uint32_t e = 0; /* validated: at most 64 faces of 16 + 5 */
    for (uint32_t f = 0; f < m->num_faces; f++) e += s->faces[m->first_face + f].num_index + 5u;
    return e;
}

void scene_all_polygons(const scene *s, uint64_t *edges, uint64_t *surfaces)
{
    *edges = (uint64_t)s->nsegs * 2u * (4u + 5u);
    for (uint32_t i = 0; i < s->nleaves; i++) *edges += 2u * ((uint64_t)s->leaves[i].num_pverts + 5u);
    *surfaces = 2u * ((uint64_t)s->nleaves + s->nsegs);
}

/* The record must say what the data shows (features and plain bounds), and its
 * per-frame bounds may not exceed every polygon at once. Those bounds are the
 * analysis's and are trusted for sizes only: the renderer never writes past
 * its pools whatever they say (render_stats.overflow). */
static scene_status check_needs(const scene *s, scene_error *err)
{
    const scn_needs *n = s->needs;
    scn_needs plain;
    scene_static_bounds(s, &plain);
    uint32_t derived = scene_derived_features(s), analysed = SCN_NEED_LOOK | SCN_NEED_YCLIP;
    uint64_t all_edges, all_surfs;
    scene_all_polygons(s, &all_edges, &all_surfs);
    if ((n->features & ~SCN_NEED_ALL) || (n->features & ~analysed) != derived || n->edges > all_edges ||
        n->surfaces > all_surfs || n->leaf_verts != plain.leaf_verts || n->model_verts != plain.model_verts ||
        n->face_verts != plain.face_verts || n->object_faces != plain.object_faces ||
        n->object_edges != plain.object_edges)
        return fail(err, SCENE_ERR_NEEDS, SCN_SEC_NEEDS, 0);
    return SCENE_OK;
}

/* Does this build (build_config.h) provide all the scene needs? */
static scene_status check_build(const scene *s, scene_error *err)
{
    const scn_needs *n = s->needs;
    /* textures are optional: a build without them draws the scene's flat colours */
    uint32_t missing = n->features & ~((uint32_t)CFG_FEATURES | SCN_NEED_TEXTURES);
    for (uint32_t bit = 0; missing; bit++)
        if (missing & (1u << bit)) return refuse(err, bit, 1, 0);
    if (s->hdr->max_depth > CFG_MAX_DEPTH) return refuse(err, SCENE_ITEM_DEPTH, s->hdr->max_depth, CFG_MAX_DEPTH);
    if (n->edges > CFG_MAX_EDGES) return refuse(err, SCENE_ITEM_EDGES, n->edges, CFG_MAX_EDGES);
    if (n->surfaces > CFG_MAX_SURFACES) return refuse(err, SCENE_ITEM_SURFACES, n->surfaces, CFG_MAX_SURFACES);
    if (n->leaf_verts > CFG_LEAF_VERTS) return refuse(err, SCENE_ITEM_LEAF_VERTS, n->leaf_verts, CFG_LEAF_VERTS);
    if (n->model_verts > CFG_MODEL_VERTS) return refuse(err, SCENE_ITEM_MODEL_VERTS, n->model_verts, CFG_MODEL_VERTS);
    if (n->face_verts > CFG_FACE_VERTS) return refuse(err, SCENE_ITEM_FACE_VERTS, n->face_verts, CFG_FACE_VERTS);
    return SCENE_OK;
}

scene_status scene_load(scene *s, const void *blob, uint32_t len, scene_error *err)
{
    scene_status st = scene_parse(s, blob, len, err);
    if (st == SCENE_OK) st = check_needs(s, err);
    if (st == SCENE_OK) st = check_build(s, err);
    return st;
}
