/* mids.c - see-through middle textures of a WAD map (docs/textures.md): each
 * side of a two-sided line that has a middle texture becomes an object whose
 * model is one upright quad, the side's opening cut to one copy of the
 * texture (Doom draws a single copy, its row 0 pegged as below), facing the
 * side's viewer. The renderer draws it with the texture's holes. */
#include "bspc_int.h"

#include <string.h>

/* The quad's reach from its origin, the line's middle: a model's coordinates
 * stay within SCN_MODEL_MAX units. */
#define MID_REACH ((int64_t)SCN_MODEL_MAX << 16)

/* Height of row 0 of side k of line l's middle texture (Doom: the lower ceiling,
 * or lower-unpegged the higher floor plus the texture's height), without the
 * side's row offset. */
static int64_t mid_top(const bs_scene *s, const bs_line *l, const scn_side *sd, uint32_t tex_h)
{
    const bs_sector *a = &s->sectors[l->sector[0]], *b = &s->sectors[l->sector[1]];
    if (sd->flags & SCN_SIDE_UNPEG_BOTTOM)
        return (int64_t)(a->floor_h > b->floor_h ? a->floor_h : b->floor_h) + ((int64_t)tex_h << 16);
    return a->ceil_h < b->ceil_h ? a->ceil_h : b->ceil_h;
}

static int add_quad_model(bs_scene *s, const bs_mvert v[4], uint8_t colour, char *err, size_t errlen)
{
    if (bs_model_begin(s, NULL, 0, err, errlen)) return -1;
    bs_model *m = &s->models[s->nmodels - 1];
    if (bs_grow(&s->mverts, &s->mvcap, s->nmverts + 4, sizeof *s->mverts) ||
        bs_grow(&s->faces, &s->fcap, s->nfaces + 1, sizeof *s->faces) ||
        bs_grow(&s->findex, &s->ficap, s->nfindex + 4, sizeof *s->findex))
        return bs_fail(err, errlen, "out of memory");
    memcpy(s->mverts + s->nmverts, v, 4 * sizeof *v);
    s->nmverts += 4;
    m->num_verts = 4;
    bs_face *f = &s->faces[s->nfaces++];
    f->first_index = s->nfindex;
    f->num_index = 4;
    f->colour = colour;
    f->part = 0;
    for (uint32_t k = 0; k < 4; k++) s->findex[s->nfindex++] = k;
    m->num_faces = 1;
    m->nparts = 1;
    return bs_model_end(s, err, errlen);
}

/* Side k of line i, if it shows a see-through middle texture: its object. */
static int add_mid(bs_scene *s, uint32_t i, int k, const char *display, const bspc_options *opt, char *err,
                   size_t errlen)
{
    const bs_line *l = &s->lines[i];
    const bs_look *lk = &s->look;
    const scn_side *sd = &lk->sides[2 * i + (uint32_t)k];
    uint32_t tex = sd->tex[SCN_PART_MIDDLE];
    if (tex == SCN_TEX_NONE || lk->tex[tex].mask == SCN_TEX_NONE) return 0; /* no holes: the opening is drawn */
    const bs_sector *a = &s->sectors[l->sector[0]], *b = &s->sectors[l->sector[1]];
    int64_t lo = a->floor_h > b->floor_h ? a->floor_h : b->floor_h, hi = a->ceil_h < b->ceil_h ? a->ceil_h : b->ceil_h;
    int64_t top = mid_top(s, l, sd, lk->tex[tex].height), row0 = top + sd->row_off;
    int64_t zt = row0 < hi ? row0 : hi, zb = row0 - ((int64_t)lk->tex[tex].height << 16);
    if (zb < lo) zb = lo;
    if (zb >= zt) return 0; /* no opening, or the copy lies outside it */
    /* along the side as its viewer sees it: left end first */
    uint32_t va = k ? l->v2 : l->v1, vb = k ? l->v1 : l->v2;
    int64_t ax = s->vx[va], ay = s->vy[va], bx = s->vx[vb], by = s->vy[vb];
    int64_t mx = (ax + bx) / 2, my = (ay + by) / 2;
    if (ax - mx > MID_REACH || mx - ax > MID_REACH || ay - my > MID_REACH || my - ay > MID_REACH ||
        zt - top > MID_REACH || top - zb > MID_REACH || top > ((int64_t)SCN_HEIGHT_MAX << 16) ||
        top < -((int64_t)SCN_HEIGHT_MAX << 16)) {
        bs_note(opt,
                "%s: line %u side %d: middle texture spans more than %d units from its middle, or is pegged "
                "beyond a height of %d: not drawn",
                display, i, k, SCN_MODEL_MAX, SCN_HEIGHT_MAX);
        return 0;
    }
    if (s->nobjects >= SCN_MAX_OBJECTS)
        return bs_fail(err, errlen, "%s: more than %d objects with the see-through middle textures", display,
                       SCN_MAX_OBJECTS);
    int32_t z0 = (int32_t)(zb - top), z1 = (int32_t)(zt - top);
    bs_mvert v[4] = {{(int32_t)(ax - mx), (int32_t)(ay - my), z0},
                     {(int32_t)(bx - mx), (int32_t)(by - my), z0},
                     {(int32_t)(bx - mx), (int32_t)(by - my), z1},
                     {(int32_t)(ax - mx), (int32_t)(ay - my), z1}};
    if (add_quad_model(s, v, l->color[k][SCN_PART_MIDDLE], err, errlen)) return -1;
    if (bs_grow(&s->objects, &s->ocap, s->nobjects + 1, sizeof *s->objects))
        return bs_fail(err, errlen, "%s: out of memory", display);
    bs_object *o = &s->objects[s->nobjects++];
    memset(o, 0, sizeof *o);
    o->model = s->nmodels - 1;
    o->x = (int32_t)mx;
    o->y = (int32_t)my;
    o->z = (int32_t)top;
    o->has_z = 1;
    o->path = SCN_PATH_NONE;
    o->src_line = (int)i;
    o->side1 = 2 * i + (uint32_t)k + 1;
    return 0;
}

/* Only a scene that keeps its look (bs_look_close's rule) shows textures. */
static int textured(const bs_scene *s, const bs_wadlook *look, const bspc_options *opt)
{
    return look && s->look.sides && s->look.doom_palette && s->look.ntex > 0 && !(opt && opt->flat);
}

int bs_mid_masks(bs_scene *s, bs_wadlook *look, const bspc_options *opt, char *err, size_t errlen)
{
    if (!textured(s, look, opt)) return 0;
    for (uint32_t i = 0; i < s->nlines; i++) {
        if (s->lines[i].sector[1] == SCN_NONE) continue;
        for (uint32_t k = 0; k < 2; k++) {
            uint32_t tex = s->look.sides[2 * i + k].tex[SCN_PART_MIDDLE];
            if (tex != SCN_TEX_NONE && bs_look_mask(look, (uint16_t)tex, err, errlen)) return -1;
        }
    }
    return 0;
}

int bs_mid_objects(bs_scene *s, bs_wadlook *look, const char *display, const bspc_options *opt, char *err,
                   size_t errlen)
{
    if (!textured(s, look, opt)) return 0;
    uint32_t before = s->nobjects;
    for (uint32_t i = 0; i < s->nlines; i++) {
        if (s->lines[i].sector[1] == SCN_NONE) continue;
        for (int k = 0; k < 2; k++)
            if (add_mid(s, i, k, display, opt, err, errlen)) return -1;
    }
    if (s->nobjects > before)
        bs_note(opt, "%s: %u see-through middle texture(s) as objects", display, s->nobjects - before);
    return 0;
}
