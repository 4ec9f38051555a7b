/* fixed_view.h - the camera of a fixed view given by the run-time options
 * (--at, --angle, --look: args.h), placed as build/render places it (prefix
 * fixed_view_). Shared by the bare-metal targets' main loops. */
#ifndef BARE_FIXED_VIEW_H
#define BARE_FIXED_VIEW_H

#include "args.h"
#include "engine.h"

int fixed_view_wanted(const fw_args *a); /* nonzero: the options ask for a fixed view */
/* The eye at --at (default: the player start), Z as given or the floor under
 * the eye + 41, --angle (default: the start's), --look; no objects with
 * --no-objects. */
void fixed_view_apply(engine *e, const fw_args *a);

#endif
