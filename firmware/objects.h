/* objects.h - moving objects and doors: the world's run-time state (prefix obj_).
 * docs/objects.md is the contract; the compiled scene holds the models, the
 * objects' placements and paths, and which sectors are doors. The engine keeps
 * the state below in RAM and updates it each frame; the renderer only reads it. */
#ifndef OBJECTS_H
#define OBJECTS_H

#include <stdint.h>
#include "fixed.h"
#include "scene.h"

typedef struct {
    uint32_t model; /* index into the scene's models */
    fx_t x, y, z;   /* the model's origin, 16.16 map units, inside the world box */
    fx_t yaw_deg;   /* degrees, 16.16, 0 = the model's +x along east, counter-clockwise */
} obj_state;

typedef struct {
    obj_state *objs;   /* n objects, drawn with ids RAST_ID(RAST_KIND_OBJECT, i) */
    uint32_t n;
    fx_t *ceil;        /* current ceiling of every sector (nsectors entries), or NULL: as compiled */
} world_state;

/* Bytes of RAM the state of a scene needs (objects and ceilings). */
uint32_t obj_state_bytes(const scene *s);

/* Point w at mem (obj_state_bytes(s) bytes, 4-byte aligned) and set every object
 * and ceiling as compiled (time 0, doors closed). Returns 0, or -1 if mem is too small. */
int obj_init(world_state *w, const scene *s, void *mem, uint32_t bytes);

/* Objects along their paths at time t_ms; doors open when (px, py) is within 64
 * units of one of their walls and close 3 s after it left, moving 128 units per
 * second (dt_ms since the last call drives them). */
void obj_update(world_state *w, const scene *s, uint32_t t_ms, uint32_t dt_ms, fx_t px, fx_t py);

/* The ceiling of sector i now (the compiled one when w or w->ceil is NULL). */
static inline fx_t obj_ceil(const world_state *w, const scene *s, uint32_t i)
{
    return (w && w->ceil) ? w->ceil[i] : s->sectors[i].ceil_h;
}

#endif
