/* objects.c - objects along their paths and doors, as functions of time (see objects.h).
 *
 * Ranges: the loader keeps a path inside the box (|x|, |y| <= 32767 at every
 * point), its period within 1 .. 3,600,000 ms (< 2^22) and |spin| <= 3600
 * degrees per second, so the phase s < 2^22 and every product below fits 64
 * bits with room (noted at each). */
#include "objects.h"

#define DEG360 ((int64_t)360 << 16)
#define DEG90 ((int64_t)90 << 16)
#define GRID_SHIFT 12 /* door distances on a grid of 1/16 unit (16.16 >> 12) */
#define REACH_GRID ((int64_t)OBJ_DOOR_REACH << (16 - GRID_SHIFT))
/* 16.16 raw per millisecond of door travel, times 1000: 128 units/s = 8388.608 raw/ms */
#define DOOR_RAW_PER_S ((int64_t)OBJ_DOOR_SPEED << 16)

static uint32_t align8(uint64_t n)
{
    return (uint32_t)((n + 7u) & ~(uint64_t)7u);
}

static uint32_t door_count(const scene *s)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < s->nsectors; i++) n += (s->sectors[i].flags & SCN_SECTOR_DOOR) != 0;
    return n;
}

static uint32_t bit_words(uint32_t bits)
{
    return bits / 32u + (bits % 32u != 0);
}

/* Bytes of each part of the state, in the order obj_init lays them out. */
static uint32_t objs_bytes(const scene *s)
{
    return CFG_OBJECTS ? align8((uint64_t)s->nobjects * sizeof(obj_state)) : 0;
}

static uint32_t ceil_bytes(const scene *s)
{
    return CFG_DOORS ? align8((uint64_t)s->nsectors * sizeof(fx_t)) : 0;
}

static uint32_t doors_bytes(const scene *s)
{
    return CFG_DOORS ? align8((uint64_t)door_count(s) * sizeof(obj_door)) : 0;
}

static uint32_t near_bytes(const scene *s)
{
    return CFG_DOORS ? align8((uint64_t)bit_words(s->nsectors) * sizeof(uint32_t)) : 0;
}

uint32_t obj_state_bytes(const scene *s)
{
    /* at most 4096 objects and far fewer sectors than 2^26: no overflow. A build
     * without objects or without doors keeps no state for them. */
    return objs_bytes(s) + ceil_bytes(s) + doors_bytes(s) + near_bytes(s);
}

static int64_t floor_div(int64_t a, int64_t b)
{
    int64_t q = a / b;
    return (a % b < 0) ? q - 1 : q;
}

static fx_t wrap_deg(int64_t d)
{
    d %= DEG360;
    if (d < 0) d += DEG360;
    return (fx_t)d;
}

/* Object i of the scene at time t. */
static void place(obj_state *o, const scn_object *so, uint32_t t)
{
    int64_t x = so->x, y = so->y;
    /* spin * t / 1000 exactly, in two parts so no product passes 2^43: spin < 2^28 */
    int64_t yaw = so->yaw + (int64_t)so->spin * (t / 1000u) % DEG360 + floor_div((int64_t)so->spin * (t % 1000u), 1000);
    if (so->path != SCN_PATH_NONE && so->period_ms > 0) {
        uint64_t ph = t % so->period_ms; /* < 2^22 */
        if (so->path == SCN_PATH_CIRCLE) {
            fx_ang_t a = (fx_ang_t)((ph << 32) / so->period_ms); /* < 2^32: ph < period */
            /* R < 2^31 raw, cos and sin <= 2^30: products below 2^61 */
            x += fx_asr64((int64_t)so->pa * fx_cos(a), FX_TRIG_SHIFT);
            y += fx_asr64((int64_t)so->pa * fx_sin(a), FX_TRIG_SHIFT);
            yaw += (int64_t)(ph * (uint64_t)DEG360 / so->period_ms) + DEG90; /* ph * 2^24.5 < 2^47 */
        } else {
            /* f = 2 ph / period out, 2 - 2 ph / period back, as num / period: the
             * displacement (< 2^33 raw) times num (<= period < 2^22) stays below 2^55 */
            uint64_t num = 2u * ph <= so->period_ms ? 2u * ph : 2u * ((uint64_t)so->period_ms - ph);
            x += floor_div((int64_t)so->pa * (int64_t)num, so->period_ms);
            y += floor_div((int64_t)so->pb * (int64_t)num, so->period_ms);
        }
    }
    const int64_t lim = (int64_t)SCN_COORD_MAX << 16;
    o->model = so->model;
    o->x = (fx_t)(x < -lim ? -lim : (x > lim ? lim : x));
    o->y = (fx_t)(y < -lim ? -lim : (y > lim ? lim : y));
    o->z = so->z;
    o->yaw_deg = wrap_deg(yaw);
}

int obj_init(world_state *w, const scene *s, void *mem, uint32_t bytes)
{
    if (!mem || bytes < obj_state_bytes(s)) return -1;
    uint8_t *p = mem;
    *w = (world_state){0};
    if (CFG_OBJECTS) {
        w->objs = (obj_state *)(void *)p;
        p += objs_bytes(s);
        w->n = s->nobjects;
        w->own = s->objects;
        for (uint32_t i = 0; i < s->nobjects; i++) place(&w->objs[i], &s->objects[i], 0);
    }
    if (CFG_DOORS) {
        w->ceil = (fx_t *)(void *)p;
        p += ceil_bytes(s);
        w->doors = (obj_door *)(void *)p;
        p += doors_bytes(s);
        w->near = (uint32_t *)(void *)p;
        w->ndoors = door_count(s);
        for (uint32_t i = 0; i < s->nsectors; i++) w->ceil[i] = s->sectors[i].ceil_h;
        for (uint32_t k = 0; k < w->ndoors; k++) w->doors[k] = (obj_door){0, 0, 0, 0};
        for (uint32_t k = 0; k < bit_words(s->nsectors); k++) w->near[k] = 0;
    }
    return 0;
}

/* 1 if (px, py) is within OBJ_DOOR_REACH of segment ab, exactly on the 1/16 grid.
 * Grid coordinates are below 2^20, differences below 2^21, so l2 < 2^43 and the
 * squared reach times l2 < 2^63; a cross product beyond 2^32 already means "far". */
static int near_wall(const scene *s, const scn_line *ln, int64_t px, int64_t py)
{
    const scn_vertex *va = &s->verts[ln->v1], *vb = &s->verts[ln->v2];
    int64_t ax = fx_asr64(va->x, GRID_SHIFT), ay = fx_asr64(va->y, GRID_SHIFT);
    int64_t bx = fx_asr64(vb->x, GRID_SHIFT), by = fx_asr64(vb->y, GRID_SHIFT);
    int64_t r = REACH_GRID;
    if (px < (ax < bx ? ax : bx) - r || px > (ax > bx ? ax : bx) + r || py < (ay < by ? ay : by) - r ||
        py > (ay > by ? ay : by) + r)
        return 0;
    int64_t abx = bx - ax, aby = by - ay, apx = px - ax, apy = py - ay;
    int64_t t = abx * apx + aby * apy, l2 = abx * abx + aby * aby;
    if (t <= 0 || l2 == 0) return apx * apx + apy * apy <= r * r;
    if (t >= l2) {
        int64_t bpx = px - bx, bpy = py - by;
        return bpx * bpx + bpy * bpy <= r * r;
    }
    int64_t c = abx * apy - aby * apx;
    uint64_t uc = (uint64_t)(c < 0 ? -c : c);
    if (uc >= ((uint64_t)1 << 32)) return 0;
    return uc * uc <= (uint64_t)(r * r) * (uint64_t)l2;
}

/* Milliseconds a door takes from closed to open. */
static uint32_t door_travel_ms(const scn_sector *sec)
{
    int64_t range = (int64_t)sec->open_h - sec->ceil_h; /* < 2^32 */
    return (uint32_t)((range * 1000 + DOOR_RAW_PER_S - 1) / DOOR_RAW_PER_S);
}

static void door_step(obj_door *d, uint32_t full, int triggered, uint32_t dt)
{
    if (triggered) {
        d->opening = 1;
        d->wait_ms = OBJ_DOOR_WAIT_MS;
        d->travel_ms = (full - d->travel_ms > dt) ? d->travel_ms + dt : full;
        return;
    }
    while (dt > 0) {
        uint32_t step;
        if (d->opening && d->travel_ms < full) { /* still rising after a short visit */
            step = full - d->travel_ms < dt ? full - d->travel_ms : dt;
            d->travel_ms += step;
        } else if (d->opening && d->wait_ms > 0) {
            step = d->wait_ms < dt ? d->wait_ms : dt;
            d->wait_ms = (uint16_t)(d->wait_ms - step);
        } else if (d->travel_ms > 0) {
            d->opening = 0;
            step = d->travel_ms < dt ? d->travel_ms : dt;
            d->travel_ms -= step;
        } else {
            d->opening = 0;
            return;
        }
        dt -= step;
    }
}

void obj_update(world_state *w, const scene *s, uint32_t t_ms, uint32_t dt_ms, fx_t px, fx_t py)
{
    if (!w) return;
    w->tic = obj_tic(t_ms);
    uint32_t n = w->n < s->nobjects ? w->n : s->nobjects;
    if (CFG_OBJECTS && w->objs)
        for (uint32_t i = 0; i < n; i++) place(&w->objs[i], &s->objects[i], t_ms);
    if (!CFG_DOORS || !w->ceil || !w->doors || !w->near || w->ndoors == 0) return;
    /* which doors the player triggers: its sector, and every wall of a door within reach */
    uint32_t *near = w->near;
    for (uint32_t k = 0; k < bit_words(s->nsectors); k++) near[k] = 0;
    uint32_t under = scene_sector_at(s, px, py);
    int64_t gx = fx_asr64(px, GRID_SHIFT), gy = fx_asr64(py, GRID_SHIFT);
    if (under != SCN_NONE) near[under / 32u] |= 1u << (under % 32u);
    for (uint32_t i = 0; i < s->nlines; i++) {
        const scn_line *ln = &s->lines[i];
        for (int k = 0; k < 2; k++) {
            uint32_t sec = ln->sector[k];
            if (sec == SCN_NONE || !(s->sectors[sec].flags & SCN_SECTOR_DOOR) || (near[sec / 32u] >> (sec % 32u) & 1u))
                continue;
            if (near_wall(s, ln, gx, gy)) near[sec / 32u] |= 1u << (sec % 32u);
        }
    }
    obj_door *d = w->doors; /* the door sectors' motion, in sector order */
    for (uint32_t i = 0; i < s->nsectors; i++) {
        const scn_sector *sec = &s->sectors[i];
        if (!(sec->flags & SCN_SECTOR_DOOR)) continue;
        if (d == w->doors + w->ndoors) break; /* a state made for another scene */
        int triggered = (near[i / 32u] >> (i % 32u)) & 1u;
        uint32_t full = door_travel_ms(sec);
        if (d->travel_ms > full) d->travel_ms = full;
        door_step(d, full, triggered, dt_ms);
        /* travel <= full < 2^18 ms: travel * 2^23 < 2^41 */
        int64_t rise = (int64_t)d->travel_ms * DOOR_RAW_PER_S / 1000;
        int64_t range = (int64_t)sec->open_h - sec->ceil_h;
        w->ceil[i] = (fx_t)(sec->ceil_h + (rise < range ? rise : range));
        d++;
    }
}
