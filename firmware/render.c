/* render.c - mode dispatch and the parts every mode shares. */
#include "render.h"

#include "spans.h"

static const char *const mode_names[RENDER_MODE_COUNT] = {"spans", "painter"};

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
        if (str_eq(name, mode_names[m])) return m;
    return -1;
}

void render_clear(const rast_target *t, uint8_t colour)
{
    for (int y = 0; y < VIEW_H; y++) rast_span(t, y, 0, VIEW_W, colour, RAST_ID(RAST_KIND_NONE, 0));
}

uint32_t render_work_bytes(const scene *s, const world_state *w)
{
    uint32_t spans = span_work_bytes(s, w), painter = painter_work_bytes(s, w);
    return spans == 0 ? 0 : (spans > painter ? spans : painter);
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
    switch (mode) {
    case RENDER_PAINTER:
        painter_render(s, w, &v, t, work, st);
        break;
    default:
        spans_render(s, w, &v, t, st, work ? work->mem : 0, work ? work->bytes : 0);
        break;
    }
}
