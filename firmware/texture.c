/* texture.c - textured spans: walls, floors and ceilings, the sky, under
 * Doom's light (docs/textures.md gives the rules; docs/ranges.md the ranges).
 *
 * Screen positions are in half pixels from the view centre, so that a pixel
 * centre is a whole number: column x is sx = 2x + 1 - 320, row y is
 * sy = 2 (100 + look) - 2y - 1 (positive above the horizon). The ray through a
 * pixel centre is F + (sx / 320) R + (sy / 320) up, F and R the view's forward
 * and right unit vectors.
 *
 * Depths are 16.16 map units, at most TEX_ZMAX (65535 units): a surface
 * farther than that is drawn with the texel of that depth. */
#include "texture.h"

#if CFG_TEXTURES

#define TEX_ZMAX 0xFFFFFFFFu
#define TEX_SUBDIV (1 << TEX_SUBDIV_BITS)
#define LIGHT_TABLE_MASK (~((1 << (5 - TEX_LIGHT_BITS)) - 1))

/* sky angle of each screen column: atan((160 - (x + 0.5)) / 160), a full turn
 * being 2^32 (tools/gen_tables.c). */
extern const uint32_t tex_sky_angle[VIEW_W];
#if TEX_RECIP_BITS
/* tex_recip[j] = 2^(k + 32) / (2m + 1) rounded, m = 2^k + j (as view.h's table) */
extern const uint32_t tex_recip[1 << TEX_RECIP_BITS];
#endif

/* floor(num / den) for den > 0, at most TEX_ZMAX. */
static inline uint32_t depth_div(uint64_t num, uint32_t den)
{
    if (num >= (uint64_t)den << 32) return TEX_ZMAX;
#if TEX_RECIP_BITS
    /* den = m 2^(b - k), 1/den ~ r / 2^(31 + b); num is cut to 32 bits first
     * (its top bits are all the quotient's relative precision needs). */
    int b = 31 - __builtin_clz(den);
    uint32_t m = b >= TEX_RECIP_BITS ? den >> (b - TEX_RECIP_BITS) : den << (TEX_RECIP_BITS - b);
    uint64_t r = tex_recip[m - (1u << TEX_RECIP_BITS)];
    int sn = num >> 32 ? 32 - __builtin_clz((uint32_t)(num >> 32)) : 0;
    uint64_t q = ((num >> sn) * r) >> (31 + b - sn); /* num >= den 2^32 was refused: 31 + b > sn */
    return q > TEX_ZMAX ? TEX_ZMAX : (uint32_t)q;
#elif FX_DIV32
    uint32_t r;
    return fx_udiv64_32(num, den, &r);
#else
    return (uint32_t)(num / den);
#endif
}

/* The brightest light table of a light level (Doom: lightnum = level / 16). */
static int8_t light_start(uint8_t light, int adj)
{
    int n = (light >> 4) + adj;
    n = n < 0 ? 0 : (n > 15 ? 15 : n);
    return (int8_t)((15 - n) * 4);
}

static const uint8_t *light_table(const tex_paint *p, int dim)
{
    int t = p->start - dim;
    t = t < 0 ? 0 : (t > SCN_LIGHT_MAPS - 1 ? SCN_LIGHT_MAPS - 1 : t);
    return p->lights + ((uint32_t)(t & LIGHT_TABLE_MASK) << 8);
}

static void set_texture(tex_paint *p, const scene *sc, uint32_t tex)
{
    const scn_texture *t = &sc->textures[tex];
    p->texels = sc->texels + t->first;
    p->hbits = t->hbits;
    p->wmask = (1u << t->wbits) - 1u;
    p->hmask = (1u << t->hbits) - 1u;
    p->lights = sc->lights;
}

tex_paint tex_wall(const scene *sc, const view_xform *v, const scn_side *sd, uint32_t tex, const scn_vertex *a,
                   int32_t top, uint8_t light, uint8_t colour)
{
    if (tex == SCN_TEX_NONE) return tex_flat(colour);
    tex_paint p;
    p.kind = TEX_WALL;
    p.colour = colour;
    set_texture(&p, sc, tex);
    p.start = light_start(light, sd->light_adj);
    p.look = VIEW_LOOK(v);
    int64_t ux = sd->ux, uy = sd->uy;
    /* |U| <= 1 in 2.30 and |sin|, |cos| <= 1: each dot product fits 2.30 */
    int32_t uf = (int32_t)((ux * v->cos + uy * v->sin) >> 30); /* U . F */
    int32_t ur = (int32_t)((ux * v->sin - uy * v->cos) >> 30); /* U . R */
    /* The ray meets the line at depth z = d / (N . ray), N = (uy, -ux) the
     * side's front normal, d the eye's distance in front: N . ray = U . R -
     * (sx / 320) U . F. The texture column there is u(eye) + z U . ray. */
    p.a = ur;
    p.b = -uf / 320;
    p.c = uf;
    p.d = ur / 320;
    int64_t dx = v->cx - a->x, dy = v->cy - a->y; /* |dx|, |dy| < 2^32: the cross product < 2^62.5 */
    int64_t d = (uy * dx - ux * dy) >> 30;
    if (d < 1) d = 1; /* the walk draws only walls the eye is in front of; rounding may say 0 */
    p.dist = d * 16384;
    p.u0 = (uint32_t)((ux * v->cx + uy * v->cy) >> 30) + (uint32_t)sd->u0;
    p.v0 = (uint32_t)top + (uint32_t)sd->row_off - (uint32_t)v->cz;
    p.dh = 0;
    p.w0 = 0;
    return p;
}

/* Light table 0 of an opacity map: its texels as they are (every byte value, so
 * a damaged map reads inside it). */
#define ID4(n) (n), (n) + 1, (n) + 2, (n) + 3
#define ID16(n) ID4(n), ID4((n) + 4), ID4((n) + 8), ID4((n) + 12)
#define ID64(n) ID16(n), ID16((n) + 16), ID16((n) + 32), ID16((n) + 48)
static const uint8_t identity[256] = {ID64(0), ID64(64), ID64(128), ID64(192)};

tex_paint tex_mid(const scene *sc, const view_xform *v, uint32_t side, int32_t top, int holes)
{
    const scn_line *l = &sc->lines[side >> 1];
    const scn_side *sd = &sc->sides[side];
    uint32_t tex = sd->tex[SCN_PART_MIDDLE];
    uint8_t colour = l->color[side & 1][SCN_PART_MIDDLE];
    tex_paint p = tex_wall(sc, v, sd, tex, &sc->verts[l->v1], top, sc->sectors[l->sector[side & 1]].light, colour);
    if (!holes || p.kind != TEX_WALL) return p;
    set_texture(&p, sc, sc->textures[tex].mask);
    p.lights = identity;
    p.start = 0; /* every depth takes table 0 */
    return p;
}

int tex_mid_opaque(const scene *sc, const view_xform *v, uint32_t side, int32_t top, int y, int a, int b, uint32_t *op)
{
    if (sc->textures[sc->sides[side].tex[SCN_PART_MIDDLE]].mask == SCN_TEX_NONE) return 0;
    tex_paint p = tex_mid(sc, v, side, top, 1);
    uint8_t row[VIEW_W];
    tex_span(&p, y, a, b, row);
    for (int x = a; x < b; x++)
        if (row[x]) op[x >> 5] |= 1u << (x & 31);
    return 1;
}

tex_paint tex_plane(const scene *sc, const view_xform *v, uint32_t tex, int32_t h, uint8_t light, uint8_t colour)
{
    if (tex == SCN_TEX_NONE) return tex_flat(colour);
    tex_paint p;
    p.kind = TEX_PLANE;
    p.colour = colour;
    set_texture(&p, sc, tex);
    p.start = light_start(light, 0);
    p.look = VIEW_LOOK(v);
    p.a = v->cos;
    p.b = v->sin;
    p.c = v->sin / 320;
    p.d = v->cos / 320;
    p.dh = (int64_t)h - v->cz;
    p.v0 = (uint32_t)v->cx;
    p.w0 = 0u - (uint32_t)v->cy;
    p.dist = 0;
    p.u0 = 0;
    return p;
}

tex_paint tex_sky(const scene *sc, const view_xform *v, uint8_t colour)
{
    if (!sc->look || sc->look->sky_tex == SCN_TEX_NONE) return tex_flat(colour);
    tex_paint p;
    p.kind = TEX_SKY;
    p.colour = colour;
    set_texture(&p, sc, sc->look->sky_tex);
    p.start = 0;
    p.look = VIEW_LOOK(v);
    p.u0 = v->angle;
    p.a = p.b = p.c = p.d = 0;
    p.dist = p.dh = 0;
    p.v0 = p.w0 = 0;
    return p;
}

/* A texture's addressing in locals: the span loops store through a uint8_t
 * pointer, which may alias anything, so fields read from the paint inside the
 * loop would be read again after every pixel. */
typedef struct {
    const uint8_t *texels;
    uint32_t cmask;  /* column bits, already shifted into place: wmask << hbits */
    uint32_t rmask;  /* hmask */
    unsigned cshift; /* 16 - hbits: a 16.16 column to its place in the index */
} tex_addr;

static inline tex_addr addr_of(const tex_paint *p)
{
    tex_addr a = {p->texels, p->wmask << p->hbits, p->hmask, 16u - p->hbits};
    return a;
}

static inline uint8_t texel(tex_addr a, uint32_t u, uint32_t v)
{
    return a.texels[((u >> a.cshift) & a.cmask) | ((v >> 16) & a.rmask)];
}

/* n texels along a straight line through the texture, each through its
 * light table: the inner loop of every wall piece and plane span. */
static inline __attribute__((always_inline)) void run_of(uint8_t *out, int n, const uint8_t *light, tex_addr a,
                                                         uint32_t u, uint32_t v, uint32_t du, uint32_t dv)
{
#pragma GCC unroll 4
    for (int i = 0; i < n; i++) {
        out[i] = light[texel(a, u, v)];
        u += du;
        v += dv;
    }
}

/* run_of with the shifts and masks of the common shapes as constants: flats
 * (64 x 64) and textures 128 rows high (most of Doom's walls). */
static void texel_run(uint8_t *out, int n, const uint8_t *light, tex_addr a, uint32_t u, uint32_t v, uint32_t du,
                      uint32_t dv)
{
    if (a.rmask == 63u && a.cmask == 63u << 6) {
        run_of(out, n, light, (tex_addr){a.texels, 63u << 6, 63u, 10u}, u, v, du, dv);
    } else if (a.rmask == 127u) {
        run_of(out, n, light, (tex_addr){a.texels, a.cmask, 127u, 9u}, u, v, du, dv);
    } else {
        run_of(out, n, light, a, u, v, du, dv);
    }
}

/* ---- walls ---- */

typedef struct {
    uint32_t u, v; /* 16.16 texture column and row */
    const uint8_t *light;
} wall_sample;

/* Doom's scale light: 160 / z in steps of 1/16, at most 47, halved. */
static inline const uint8_t *wall_light(const tex_paint *p, uint32_t z)
{
    uint32_t scale = z ? 167772160u / z : 47u; /* 2560 * 65536 / z */
    return light_table(p, (int)(scale > 47u ? 47u : scale) / 2);
}

/* The exact texture column, row and light where a pixel's ray meets the
 * wall: den and slope are the paint's a + sx b and c + sx d for the pixel's
 * column (2.30, stepped along the span), vk its row's sy 2^22 / 320. */
static inline __attribute__((always_inline)) uint32_t wall_depth(const tex_paint *p, int64_t den)
{
    int64_t d14 = den >> 16; /* 2.14, < 2^15 */
    return d14 > 0 ? depth_div((uint64_t)p->dist, (uint32_t)d14) : TEX_ZMAX;
}

static inline __attribute__((always_inline)) wall_sample wall_at_depth(const tex_paint *p, uint32_t z, int64_t slope,
                                                                       int32_t vk)
{
    wall_sample s;
    s.u = p->u0 + (uint32_t)(((int64_t)z * (slope >> 16)) >> 14); /* < 2^47 before the shift */
    s.v = p->v0 - (uint32_t)(((int64_t)z * vk) >> 22);            /* < 2^56 */
    s.light = wall_light(p, z);
    return s;
}

static inline __attribute__((always_inline)) wall_sample wall_at(const tex_paint *p, int64_t den, int64_t slope,
                                                                 int32_t vk)
{
    return wall_at_depth(p, wall_depth(p, den), slope, vk);
}

/* A row of a wall. The exact samples are taken at columns that are multiples
 * of TEX_SUBDIV, whatever the span, so a pixel's texel does not depend on how
 * its row was cut into spans: every render mode and pool size draws the same
 * texels. Past a wall's vanishing point (a sample the ray of which misses the
 * line) the span's own end is sampled instead. */
static inline __attribute__((always_inline)) void wall_span_as(const tex_paint *p, int y, int x0, int x1, uint8_t *row,
                                                               tex_addr a)
{
    int32_t sy = 2 * (VIEW_CY + p->look) - 2 * y - 1;
    int32_t vk = sy * 13107; /* sy 2^22 / 320, |sy| < 600 */
    int k = x0 & ~(TEX_SUBDIV - 1);
    int32_t sx = 2 * k + 1 - VIEW_W;
    int64_t den = (int64_t)p->a + (int64_t)sx * p->b, slope = (int64_t)p->c + (int64_t)sx * p->d;
    const int64_t dden = (int64_t)p->b * (2 * TEX_SUBDIV), dslope = (int64_t)p->d * (2 * TEX_SUBDIV);
    wall_sample s = wall_at(p, den, slope, vk);
    for (int x = x0; x < x1; k += TEX_SUBDIV) {
        den += dden;
        slope += dslope;
        int32_t du, dv;
        int end = k + TEX_SUBDIV < x1 ? k + TEX_SUBDIV : x1;
        wall_sample e;
        if ((den >> 16) > 0) {
            e = wall_at(p, den, slope, vk);
            du = (int32_t)(e.u - s.u) >> TEX_SUBDIV_BITS;
            dv = (int32_t)(e.v - s.v) >> TEX_SUBDIV_BITS;
        } else { /* beyond the vanishing point (rounding aside, only past the span's end):
                  * the rest of the span interpolated to its end */
            int32_t ex = 2 * x1 + 1 - VIEW_W;
            e = wall_at(p, (int64_t)p->a + (int64_t)ex * p->b, (int64_t)p->c + (int64_t)ex * p->d, vk);
            du = (int32_t)(e.u - s.u) / (x1 - k);
            dv = (int32_t)(e.v - s.v) / (x1 - k);
            end = x1;
        }
        uint32_t skip = (uint32_t)(x - k);
        run_of(row + x, end - x, s.light, a, s.u + skip * (uint32_t)du, s.v + skip * (uint32_t)dv, (uint32_t)du,
               (uint32_t)dv);
        x = end;
        s = e;
    }
}

/* wall_span_as with the texture's shape as constants for the common shapes
 * (most of Doom's wall textures are 128 rows high), the texel loop inlined. */
static void wall_span(const tex_paint *p, int y, int x0, int x1, uint8_t *row)
{
    tex_addr a = addr_of(p);
    if (a.rmask == 127u)
        wall_span_as(p, y, x0, x1, row, (tex_addr){a.texels, a.cmask, 127u, 9u});
    else
        wall_span_as(p, y, x0, x1, row, a);
}

/* Rows [y0, y1) of column x down a wall: the exact sample of the column's
 * centre ray (wall_at's depth, texture column and light), then the texture row
 * stepped down the column, Doom's wall column: one coordinate stepped, the
 * texture column and the light fixed. */
static inline __attribute__((always_inline)) void wall_column_as(const tex_paint *p, int x, int y0, int y1,
                                                                 uint8_t *dst, uint32_t pitch, uint32_t hmask)
{
    int32_t sx = 2 * x + 1 - VIEW_W;
    int64_t den = (int64_t)p->a + (int64_t)sx * p->b, slope = (int64_t)p->c + (int64_t)sx * p->d;
    int32_t sy = 2 * (VIEW_CY + p->look) - 2 * y0 - 1;
    uint32_t z = wall_depth(p, den);
    wall_sample s = wall_at_depth(p, z, slope, sy * 13107);
    uint32_t dv = (uint32_t)(((int64_t)z * (2 * 13107)) >> 22); /* a row down: sy falls by 2 */
    const uint8_t *col = p->texels + (((s.u >> 16) & p->wmask) << p->hbits), *light = s.light;
    uint32_t v = s.v;
    int n = y1 - y0;
    for (; n >= 2; n -= 2) { /* two rows a turn: the loop's own count and branch shared */
        uint8_t a = light[col[(v >> 16) & hmask]], b = light[col[((v + dv) >> 16) & hmask]];
        dst[0] = a;
        dst[pitch] = b;
        dst += 2 * pitch;
        v += 2 * dv;
    }
    if (n) *dst = light[col[(v >> 16) & hmask]];
}

void tex_column(const tex_paint *p, int x, int y0, int y1, uint8_t *dst, uint32_t pitch)
{
    if (p->hmask == 127u)
        wall_column_as(p, x, y0, y1, dst, pitch, 127u);
    else
        wall_column_as(p, x, y0, y1, dst, pitch, p->hmask);
}

/* ---- floors and ceilings: one depth a row (Doom's trick) ---- */

static void plane_span(const tex_paint *p, int y, int x0, int x1, uint8_t *row)
{
    int32_t sy = 2 * (VIEW_CY + p->look) - 2 * y - 1;
    uint32_t z = TEX_ZMAX;
    if (sy != 0 && (sy > 0) == (p->dh > 0)) /* the plane is on this side of the horizon */
        z = depth_div((uint64_t)(p->dh < 0 ? -p->dh : p->dh) * 320u, (uint32_t)(sy < 0 ? -sy : sy));
    /* P = eye + z (F + sx / 320 R): |cos + sx sin / 320| < 2^30.5, z < 2^32. Taken at
     * column 0 and stepped from there, so that a pixel's texel does not depend on
     * where its span starts. */
    const int64_t sx = 1 - VIEW_W;
    uint32_t du = (uint32_t)(((int64_t)z * (2 * p->c)) >> 30), dw = (uint32_t)(((int64_t)z * (2 * p->d)) >> 30);
    uint32_t u = p->v0 + (uint32_t)(((int64_t)z * (p->a + sx * p->c)) >> 30) + (uint32_t)x0 * du;
    uint32_t w = p->w0 - (uint32_t)(((int64_t)z * (p->b - sx * p->d)) >> 30) + (uint32_t)x0 * dw;
    uint32_t bucket = z >> 20; /* Doom's z light: 16 units a step, at most 127 */
    const uint8_t *light = light_table(p, (int)(160u / ((bucket > 127u ? 127u : bucket) + 1u)) / 2);
    texel_run(row + x0, x1 - x0, light, addr_of(p), u, w, du, dw);
}

/* ---- the sky: by view angle, at full light ---- */

static void sky_span(const tex_paint *p, int y, int x0, int x1, uint8_t *row)
{
    const uint8_t *light = p->lights;
    const uint8_t *column0 = p->texels + ((uint32_t)(y - p->look) & p->hmask);
    uint32_t angle = p->u0, wmask = p->wmask;
    unsigned hbits = p->hbits;
    for (int x = x0; x < x1; x++) {
        uint32_t col = ((angle + tex_sky_angle[x]) >> 22) & wmask;
        row[x] = light[column0[col << hbits]];
    }
}

tex_paint tex_sprite(const scene *sc, const spr_view *sv, int look, uint8_t colour)
{
    const scn_sprite *img = &sc->sprites[sv->image];
    tex_paint p;
    p.kind = TEX_SPRITE;
    p.colour = colour;
    p.texels = sc->texels + img->first;
    p.lights = sc->lights + ((uint32_t)(sv->table & LIGHT_TABLE_MASK) << 8);
    p.wmask = img->width;
    p.hmask = img->height;
    p.hbits = sv->mirror;
    p.a = sv->zc;
    p.b = sv->xl;
    p.c = sv->yt;
    p.look = look;
    return p;
}

static void sprite_span(const tex_paint *p, int y, int x0, int x1, uint8_t *row)
{
    spr_view sv = {0, p->hbits, 0, p->a, p->b, p->c};
    int32_t w = (int32_t)p->wmask;
    int v = spr_row(&sv, p->look, y, (int)p->hmask);
    if (v < 0) v = 0; /* the caller's pixels are opaque, so inside the image */
    spr_cols c;
    spr_cols_at(&c, &sv, x0);
    for (int x = x0; x < x1; x++, spr_cols_next(&c)) {
        int32_t u = c.u < 0 ? 0 : (c.u >= w ? w - 1 : c.u);
        if (p->hbits) u = w - 1 - u;
        row[x] = p->lights[p->texels[(uint32_t)u * p->hmask + (uint32_t)v]];
    }
}

void tex_span(const tex_paint *p, int y, int x0, int x1, uint8_t *row)
{
    if (p->kind == TEX_WALL)
        wall_span(p, y, x0, x1, row);
    else if (p->kind == TEX_PLANE)
        plane_span(p, y, x0, x1, row);
    else if (p->kind == TEX_SKY)
        sky_span(p, y, x0, x1, row);
    else if (p->kind == TEX_SPRITE)
        sprite_span(p, y, x0, x1, row);
    else
        for (int x = x0; x < x1; x++) row[x] = p->colour;
}

#endif
