/* sprite.c - which image of a thing, where, and its opaque pixels (sprite.h). */
#include "sprite.h"

/* Doom's rotation of a thing seen along d (eye to thing, map units): the
 * octant of the angle from the thing's yaw, shifted by half an octant and
 * turned so that 0 is the thing seen from the front (docs/objects.md). */
static int rotation(int64_t dx, int64_t dy, fx_t yaw_deg)
{
    if (dx == 0 && dy == 0) return 0;
    /* turn d by 22.5 degrees less the yaw; 2^25 raw bounds |d| (< 2^33) shifted by 8 */
    fx_ang_t a = fx_ang_from_deg(22 * 65536 + 32768) - fx_ang_from_deg(yaw_deg);
    int64_t c = fx_cos(a), sn = fx_sin(a);
    dx = fx_asr64(dx, 8);
    dy = fx_asr64(dy, 8);
    int64_t x = dx * c - dy * sn, y = dx * sn + dy * c;
    int s = 0;
    if (y < 0 || (y == 0 && x < 0)) x = -x, y = -y, s = 4; /* [180, 360) */
    if (x <= 0) {                                          /* [90, 180): turn back a quarter */
        int64_t t = x;
        x = y;
        y = -t;
        s += 2;
    }
    if (y >= x) s += 1; /* [45, 90) */
    return (s + 4) & 7;
}

static int light_table_of(const scene *s, const obj_state *o, const scn_sprset *set, int32_t zc)
{
    if (set->flags & SCN_SPRSET_BRIGHT) return 0;
    uint32_t sec = scene_sector_at(s, o->x, o->y);
    int level = sec == SCN_NONE ? 0 : s->sectors[sec].light;
    int start = (15 - (level >> 4)) * 4;
    int64_t scale = ((int64_t)2560 << VIEW_SHIFT) / zc; /* Doom's scale light: 160 / z in 1/16 */
    int t = start - (int)(scale > 47 ? 47 : scale) / 2;
    return t < 0 ? 0 : (t > SCN_LIGHT_MAPS - 1 ? SCN_LIGHT_MAPS - 1 : t);
}

int spr_view_of(const scene *s, const obj_state *o, uint32_t sprset, const view_xform *v, spr_view *sv, view_pt quad[4])
{
    int64_t dx = (int64_t)o->x - v->cx, dy = (int64_t)o->y - v->cy;
    int32_t zc = (int32_t)fx_asr64(dx * v->cos + dy * v->sin, 46 - VIEW_SHIFT);
    int32_t xc = (int32_t)fx_asr64(dx * v->sin - dy * v->cos, 46 - VIEW_SHIFT);
    if (zc < SPR_MIN_DEPTH) return 0;
    const scn_sprset *set = &s->sprsets[sprset];
    int r = rotation(dx, dy, o->yaw_deg);
    const scn_sprite *p = &s->sprites[set->image[r]];
    /* heights as objd_transform takes them, so the bottom on a floor lies in its plane */
    int64_t top = (int64_t)o->z + (int64_t)p->top * 65536, bottom = top - (int64_t)p->height * 65536;
    if (bottom < o->z) bottom = o->z;
    if (bottom >= top) return 0;
    sv->image = set->image[r];
    sv->mirror = (uint8_t)((set->mirror >> r) & 1u);
    sv->table = (uint8_t)light_table_of(s, o, set, zc);
    sv->zc = zc;
    sv->xl = xc - p->left * VIEW_ONE;
    sv->yt = (int32_t)fx_asr64(top - v->cz, 16 - VIEW_SHIFT);
    int32_t xr = sv->xl + p->width * VIEW_ONE, yb = (int32_t)fx_asr64(bottom - v->cz, 16 - VIEW_SHIFT);
    quad[0] = (view_pt){sv->xl, sv->yt, zc};
    quad[1] = (view_pt){xr, sv->yt, zc};
    quad[2] = (view_pt){xr, yb, zc};
    quad[3] = (view_pt){sv->xl, yb, zc};
    return 1;
}

void spr_opaque(const scene *s, const spr_view *sv, int look, int y, int a, int b, uint32_t *bits)
{
    const scn_sprite *p = &s->sprites[sv->image];
    int v = spr_row(sv, look, y, p->height);
    if (v < 0 || a >= b) return;
    uint32_t stride = ((uint32_t)p->height + 31u) >> 5, bit = (uint32_t)v & 31u;
    const uint32_t *col0 = s->sprmask + p->mask + (v >> 5);
    int32_t w = p->width;
    spr_cols c;
    spr_cols_at(&c, sv, a);
    int x = a;
    for (; x < b && c.u < 0; x++) spr_cols_next(&c); /* left of the image (rounding at its edge) */
    /* column u's word, walked either way: mirrored, column 0 is the image's last */
    const uint32_t *col = sv->mirror ? col0 + (uint32_t)(w - 1) * stride : col0;
    int32_t step = sv->mirror ? -(int32_t)stride : (int32_t)stride;
    for (; x < b && c.u < w; x++, spr_cols_next(&c))
        if ((col[c.u * step] >> bit) & 1u) bits[x >> 5] |= 1u << (x & 31);
}
