/* painter.c - render mode "painter": the Listing 62.1 pipeline. Walk the BSP tree
 * back to front (data recursion, bsp_walk.c), turn each leaf into its floor,
 * ceiling and front-facing wall polygons (surfaces.c), and fill each one as it
 * comes; nearer polygons overdraw farther ones. Kept as the baseline the
 * zero-overdraw span renderer is measured against. */
#include "bsp_walk.h"
#include "render.h"
#include "surfaces.h"

#define PAINTER_BACKGROUND 0

typedef struct {
    const scene *sc;
    const view_xform *v;
    const rast_target *t;
    render_stats *st;
    surf_sink sink;
} painter;

static void fill_polygon(void *ctx, const screen_pt *pts, int n, uint8_t colour, uint32_t id)
{
    const painter *p = ctx;
    rast_convex(p->t, pts, n, colour, id);
}

static int draw_leaf(void *ctx, uint32_t leaf, unsigned clip_mask)
{
    painter *p = ctx;
    surf_leaf(p->sc, p->v, leaf, clip_mask, &p->sink, 0, p->st);
    return 0;
}

void painter_render(const scene *sc, const view_xform *v, const rast_target *t, render_stats *st)
{
    painter p = {sc, v, t, st, {fill_polygon, 0}};
    walk_stats ws;
    p.sink.ctx = &p;
    render_clear(t, PAINTER_BACKGROUND);
    walk_tree(sc, v, WALK_BACK_TO_FRONT, draw_leaf, &p, 0, &ws);
    st->nodes = ws.nodes;
    st->boxes_culled = ws.boxes_culled;
}
