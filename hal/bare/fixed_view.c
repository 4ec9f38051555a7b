/* fixed_view.c - a fixed view from the run-time options (see fixed_view.h). */
#include "fixed_view.h"

int fixed_view_wanted(const fw_args *a)
{
    return a->have_at || a->have_angle || a->look != 0 || a->no_objects;
}

void fixed_view_apply(engine *e, const fw_args *a)
{
    if (a->have_at) {
        e->cam.view.x = a->x;
        e->cam.view.y = a->y;
    }
    if (a->have_angle) e->cam.view.angle_deg = a->angle_deg;
    if (a->no_objects) e->world.n = 0;
    e->cam.view.look = a->look;
    if (a->have_z) {
        e->cam.view.z = a->z;
    } else {
        e->cam.view.z = CAM_EYE_HEIGHT;
        cam_follow_floor(&e->cam, &e->sc);
    }
}
