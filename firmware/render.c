/* render.c - mode dispatch and the parts every mode shares. */
#include "render.h"

#include "columns.h"
#include "direct.h"
#include "painter.h"
#include "spans.h"

static const char *const mode_names[RENDER_MODE_COUNT] = {"spans", "painter", "direct", "columns"};
static const unsigned mode_bits[RENDER_MODE_COUNT] = {CFG_MODE_SPANS, CFG_MODE_PAINTER, CFG_MODE_DIRECT,
                                                      CFG_MODE_COLUMNS};

static int built(int m)
{
    return (unsigned)m < RENDER_MODE_COUNT && (CFG_RENDER_MODES & mode_bits[m]);
}

const char *render_mode_name(render_mode m)
{
    return ((unsigned)m < RENDER_MODE_COUNT) ? mode_names[m] : "?";
}

static int str_eq(const char *a, const char *b)
{
    while (*a && *a == *b) a++, b++;
    return *a == *b;
}

int render_mode_parse(const char *name)
{
    for (int m = 0; m < RENDER_MODE_COUNT; m++)
        if (built(m) && str_eq(name, mode_names[m])) return m;
    return -1;
}

render_mode render_mode_default(void)
{
    if (built(RENDER_COLUMNS)) return RENDER_COLUMNS;
    return built(RENDER_DIRECT) ? RENDER_DIRECT : (built(RENDER_SPANS) ? RENDER_SPANS : RENDER_PAINTER);
}

render_mode render_mode_next(render_mode m)
{
    for (int k = 1; k <= RENDER_MODE_COUNT; k++) {
        int n = ((int)m + k) % RENDER_MODE_COUNT;
        if (built(n)) return (render_mode)n;
    }
    return m;
}

static uint32_t max_u32(uint32_t a, uint32_t b)
{
    return a > b ? a : b;
}

uint32_t render_work_bytes(const scene *s, const world_state *w)
{
    uint32_t need = 0, b;
    if (CFG_MODE(CFG_MODE_SPANS)) {
        if ((b = spans_work_bytes(s, w)) == 0) return 0; /* beyond 32 bits: refuse the scene */
        need = max_u32(need, b);
    }
    if (CFG_MODE(CFG_MODE_DIRECT)) {
        if ((b = direct_work_bytes(s, w)) == 0) return 0;
        need = max_u32(need, b);
    }
    if (CFG_MODE(CFG_MODE_COLUMNS)) {
        if ((b = cols_work_bytes(s, w)) == 0) return 0;
        need = max_u32(need, b);
    }
    if (CFG_MODE(CFG_MODE_PAINTER)) need = max_u32(need, painter_work_bytes(s, w)); /* 0: none needed */
    return need;
}

void render_frame(const scene *s, const world_state *w, const camera *cam, render_mode mode, const rast_target *t,
                  const render_work *work, render_stats *stats)
{
    render_stats local;
    render_stats *st = stats ? stats : &local;
    view_xform v;
    *st = (render_stats){0};
    camera c = *cam;
    if (!(s->needs->features & SCN_NEED_LOOK)) c.look = 0; /* the scene keeps its horizon level */
    view_setup(&v, &c);
    if (!built(mode)) mode = render_mode_default();
    switch (mode) {
    case RENDER_PAINTER:
        if (CFG_MODE(CFG_MODE_PAINTER)) painter_render(s, w, &v, t, st, work ? work->mem : 0, work ? work->bytes : 0);
        break;
    case RENDER_SPANS:
        if (CFG_MODE(CFG_MODE_SPANS)) spans_render(s, w, &v, t, st, work ? work->mem : 0, work ? work->bytes : 0);
        break;
    case RENDER_COLUMNS:
        if (CFG_MODE(CFG_MODE_COLUMNS)) cols_render(s, w, &v, t, st, work ? work->mem : 0, work ? work->bytes : 0);
        break;
    default:
        if (CFG_MODE(CFG_MODE_DIRECT)) direct_render(s, w, &v, t, st, work ? work->mem : 0, work ? work->bytes : 0);
        break;
    }
}
