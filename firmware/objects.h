/* objects.h - moving objects and doors: the world's run-time state (prefix obj_).
 * docs/objects.md is the contract; the compiled scene holds the models, the
 * objects' placements and paths, and which sectors are doors. The engine keeps
 * the state below in RAM and updates it each frame; the renderer only reads it. */
#ifndef OBJECTS_H
#define OBJECTS_H

#include <stdint.h>
#include "build_config.h"
#include "fixed.h"
#include "scene.h"

#define OBJ_DOOR_REACH 64      /* units: a door opens for a player this near one of its walls */
#define OBJ_DOOR_SPEED 128     /* units per second, up and down */
#define OBJ_DOOR_WAIT_MS 3000u /* open this long after the player left, then close */
#define OBJ_TIC_HZ 35u         /* Doom's tics a second: the level time of animated textures */

typedef struct {
    uint32_t model; /* index into the scene's models */
    fx_t x, y, z;   /* the model's origin, 16.16 map units, inside the world box */
    fx_t yaw_deg;   /* degrees, 16.16, 0 = the model's +x along east, counter-clockwise */
} obj_state;

/* A door's motion, kept as times so that the ceiling depends on the sum of the
 * frame times only, not on how they were split into frames. 8 bytes: a scene
 * keeps one per door sector. */
typedef struct {
    uint32_t travel_ms; /* time spent rising from closed, 0 .. the door's full travel (< 2^18) */
    uint16_t wait_ms;   /* time it will still stay fully open, 0 .. OBJ_DOOR_WAIT_MS */
    uint8_t opening;    /* 1 rising or open, 0 closing or closed */
    uint8_t unused;
} obj_door;

_Static_assert(OBJ_DOOR_WAIT_MS <= 0xFFFFu, "obj_door.wait_ms");

typedef struct {
    obj_state *objs; /* n objects, drawn with ids RAST_ID(RAST_KIND_OBJECT, i) */
    uint32_t n;
    fx_t *ceil;      /* current ceiling of every sector (nsectors entries), or NULL: as compiled */
    obj_door *doors; /* motion of each door sector, in sector order (ndoors entries),
                        * or NULL: obj_update leaves the ceilings alone */
    uint32_t *near;  /* obj_update's scratch: one bit per sector, "triggered now" */
    uint32_t ndoors;
    const scn_object *own; /* the scene's objects when objs are theirs (for their sprite sets), else NULL */
    uint32_t tic;          /* level time in tics, obj_tic of obj_update's time (firmware/anim.h) */
} world_state;

/* The level time in tics at t_ms: floor(t_ms * 35 / 1000), below 2^28. */
static inline uint32_t obj_tic(uint32_t t_ms)
{
    return (uint32_t)((uint64_t)t_ms * OBJ_TIC_HZ / 1000u);
}

/* The sprite set object i is drawn as (docs/objects.md, "Sprites"), or SCN_NONE:
 * as its model. Only the scene's own objects have sprites. */
static inline uint32_t obj_sprset(const world_state *w, uint32_t i)
{
    return CFG_TEXTURES && w->own ? w->own[i].sprset : SCN_NONE;
}

/* The line side whose see-through middle texture object i shows (docs/textures.md), or SCN_NONE. */
static inline uint32_t obj_mid_side(const world_state *w, uint32_t i)
{
    return CFG_TEXTURES && w->own ? w->own[i].side : SCN_NONE;
}

/* Bytes of RAM the state of a scene needs (objects, every sector's ceiling, the
 * door sectors' motion, a bit per sector); a multiple of 8. */
uint32_t obj_state_bytes(const scene *s);

/* Point w at mem (obj_state_bytes(s) bytes, 4-byte aligned) and set every object
 * and ceiling as compiled (time 0, doors closed). Returns 0, or -1 if mem is too small. */
int obj_init(world_state *w, const scene *s, void *mem, uint32_t bytes);

/* The world at time t_ms: the level time (w->tic = obj_tic(t_ms), which animated
 * textures follow), objects along their paths at t_ms; doors open when (px, py)
 * is within 64 units of one of their walls and close 3 s after it left, moving
 * 128 units per second (dt_ms since the last call drives them).
 *
 * Paths (docs/objects.md), exact functions of t_ms, with s = t_ms mod period:
 *   circle: origin = centre + R (cos th, sin th), th = 360 s / period degrees,
 *           yaw = yaw0 + th + 90 (facing along the motion);
 *   line:   origin = start + f (dx, dy), f = 2 s / period rising to 1, then back;
 *   spin:   yaw += spin t_ms / 1000 (every path); yaw kept in [0, 360).
 * w->objs[i] follows the scene's object i for i < min(w->n, s->nobjects); objects
 * beyond the scene's (placed by hand) are left alone.
 *
 * Doors: the player is a point; "within 64 units" is decided exactly on a grid
 * of 1/16 unit. A door triggered (player near or in its sector) rises; once fully
 * open it waits 3 s counting from the last frame it was triggered, then falls;
 * triggered while falling, it rises again. */
void obj_update(world_state *w, const scene *s, uint32_t t_ms, uint32_t dt_ms, fx_t px, fx_t py);

/* The ceiling of sector i now (the compiled one when w or w->ceil is NULL). */
static inline fx_t obj_ceil(const world_state *w, const scene *s, uint32_t i)
{
    return (CFG_DOORS && w && w->ceil) ? w->ceil[i] : s->sectors[i].ceil_h;
}

#endif
