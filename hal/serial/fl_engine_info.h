/* fl_engine_info.h - what the frame link says about an engine's frame: its
 * camera, modes and time (fl_frame_info), for every sender (hal/mps2/stream_fl.c,
 * host/link_send.c's callers). Inline, so it is compiled with the includer's
 * build_config.h: the engine's layout depends on the build, and the frame
 * link's codec itself does not know the engine. */
#ifndef FL_ENGINE_INFO_H
#define FL_ENGINE_INFO_H

#include "engine.h"
#include "framelink.h"

static inline fl_frame_info fl_engine_info(const engine *e)
{
    fl_frame_info info = {
        .x = e->cam.view.x,
        .y = e->cam.view.y,
        .z = e->cam.view.z,
        .angle = e->cam.view.angle_deg,
        .look = e->cam.view.look,
        .mode = (uint8_t)e->mode,
        .present = (uint8_t)e->present,
        .time_ms = e->t_ms,
    };
    return info;
}

#endif
