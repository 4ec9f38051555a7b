/* view.c - camera set-up and perspective projection. */
#include "view.h"
#include "scene_format.h"

void view_setup(view_xform *v, const camera *cam)
{
    const int64_t lim = (int64_t)SCN_COORD_MAX << 16;
    const int64_t hlim = (int64_t)SCN_HEIGHT_MAX << 16;
    v->cx = cam->x < -lim ? -lim : (cam->x > lim ? lim : cam->x);
    v->cy = cam->y < -lim ? -lim : (cam->y > lim ? lim : cam->y);
    v->cz = cam->z < -hlim ? -hlim : (cam->z > hlim ? hlim : cam->z);
    fx_ang_t a = fx_ang_from_deg(cam->angle_deg);
    v->angle = a;
    v->sin = fx_sin(a);
    v->cos = fx_cos(a);
    v->look = !CFG_LOOK                    ? 0
              : cam->look < -VIEW_LOOK_MAX ? -VIEW_LOOK_MAX
                                           : (cam->look > VIEW_LOOK_MAX ? VIEW_LOOK_MAX : cam->look);
}

static int32_t clamp32(int64_t v, int32_t hi)
{
    return v < 0 ? 0 : (v > hi ? hi : (int32_t)v);
}

int32_t view_project_x(view_pt p)
{
    int32_t z = p.z < VIEW_ZNEAR ? VIEW_ZNEAR : p.z;
    return view_subpixel(clamp32(((int64_t)VIEW_CX << 16) + view_persp(p.x, z), VIEW_W_FX));
}

screen_pt view_project(const view_xform *v, view_pt p)
{
    int32_t z = p.z < VIEW_ZNEAR ? VIEW_ZNEAR : p.z;
    screen_pt s;
    s.x = view_project_x(p);
    s.y = view_subpixel(clamp32(((int64_t)(VIEW_CY + VIEW_LOOK(v)) << 16) - view_persp(p.y, z), VIEW_H_FX));
    return s;
}
