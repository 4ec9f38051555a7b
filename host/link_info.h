/* link_info.h - what the frame link says about an engine's frame (camera,
 * modes). Inline, so it is compiled with the includer's build_config.h: a
 * program built for one scene (mk/scene.mk) shares link_send.o with build/. */
#ifndef LINK_INFO_H
#define LINK_INFO_H

#include "engine.h"
#include "framelink.h"

static inline fl_frame_info link_info_of(const engine *e)
{
    fl_frame_info info = {
        .x = e->cam.view.x,
        .y = e->cam.view.y,
        .z = e->cam.view.z,
        .angle = e->cam.view.angle_deg,
        .look = e->cam.view.look,
        .mode = (uint8_t)e->mode,
        .present = (uint8_t)e->present,
    };
    return info;
}

#endif
