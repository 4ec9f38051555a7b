/* camera.c - eye placement, walking with collision (collide.c) and the eye's
 * height. Speeds are per second and scaled by the frame time, so the walk feels
 * the same at any frame rate; the easing of the eye over steps is integer and
 * depends only on the inputs, so a replay gives the same frames. */
#include "camera.h"
#include "collide.h"
#include "hal.h"

#define WALK_SPEED 256          /* units per second */
#define TURN_SPEED 120          /* degrees per second */
#define FLY_SPEED 128           /* units per second */
#define LOOK_SPEED 120          /* pixels per second */
#define EASE_SNAP (FX_ONE / 16) /* nearer than this, the eye is put on its floor */
#define EASE_DT_MAX 1000u       /* longer frames ease as one second (keeps products small) */
#define CEIL_GAP (4 * FX_ONE)   /* the eased eye stays this far under the ceiling */

static void set_eye(cam_state *c)
{
    c->view.z = fx_sat32((int64_t)c->eye_floor + CAM_EYE_HEIGHT + c->fly);
}

void cam_follow_floor(cam_state *c, const scene *s)
{
    fx_t f;
    if (!col_floor_at(s, c->view.x, c->view.y, &f)) return;
    c->eye_floor = f;
    set_eye(c);
}

void cam_start(cam_state *c, const scene *s)
{
    c->view.x = s->hdr->player_x;
    c->view.y = s->hdr->player_y;
    c->view.angle_deg = s->hdr->player_angle;
    c->view.look = 0;
    c->view.z = CAM_EYE_HEIGHT;
    c->fly = 0;
    c->eye_floor = 0;
    c->noclip = 0;
    c->feet = 0;
    col_move(s, 0, 0, &c->view.x, &c->view.y, &c->feet, 0, 0); /* the floor stood on; no move */
    cam_follow_floor(c, s);
}

/* Ease the eye's floor toward the floor under the eye: the gap shrinks by
 * dt / (dt + CAM_EASE_MS) each step (exponential, time constant 60 ms), the eye
 * never lags more than a step (COL_STEP) below the floor, so it is at least 17
 * units above it, and never rises to within CEIL_GAP + 41 of the ceiling. */
static void ease_floor(cam_state *c, const scene *s, const world_state *w, uint32_t dt_ms)
{
    uint32_t sec = scene_sector_at(s, c->view.x, c->view.y);
    if (sec == SCN_NONE) return;
    int64_t target = s->sectors[sec].floor_h, ceil = obj_ceil(w, s, sec);
    int64_t e = c->eye_floor, diff = target - e; /* |diff| < 2^32 */
    int64_t dt = dt_ms > EASE_DT_MAX ? EASE_DT_MAX : dt_ms;
    if (diff > -EASE_SNAP && diff < EASE_SNAP)
        e = target;
    else
        e += diff * dt / (dt + CAM_EASE_MS); /* < 2^42 */
    if (e < target - COL_STEP) e = target - COL_STEP;
    int64_t top = ceil - CAM_EYE_HEIGHT - CEIL_GAP;
    if (top < target) top = target;
    if (e > top) e = top;
    c->eye_floor = (fx_t)e; /* between two heights of the scene: in range */
}

/* rate (units per second, whole) * dt_ms / 1000 as 16.16. */
static int64_t per_frame(int32_t rate, uint32_t dt_ms)
{
    return (int64_t)rate * 65536 * dt_ms / 1000;
}

static fx_t wrap_degrees(int64_t deg)
{
    const int64_t turn = (int64_t)360 << 16;
    deg %= turn;
    if (deg < 0) deg += turn;
    return (fx_t)deg;
}

static fx_t clamp_coord(int64_t v)
{
    const int64_t lim = (int64_t)SCN_COORD_MAX << 16;
    return (fx_t)(v < -lim ? -lim : (v > lim ? lim : v));
}

void cam_move(cam_state *c, const scene *s, const world_state *w, uint32_t input, uint32_t dt_ms)
{
    int32_t boost = (input & HAL_KEY_RUN) ? 2 : 1;
    int64_t step = per_frame(WALK_SPEED * boost, dt_ms);
    int64_t turn = per_frame(TURN_SPEED * boost, dt_ms);
    int64_t fwd = 0, side = 0;
    if (input & HAL_KEY_TURN_LEFT) c->view.angle_deg = wrap_degrees((int64_t)c->view.angle_deg + turn);
    if (input & HAL_KEY_TURN_RIGHT) c->view.angle_deg = wrap_degrees((int64_t)c->view.angle_deg - turn);
    if (input & HAL_KEY_FORWARD) fwd += step;
    if (input & HAL_KEY_BACK) fwd -= step;
    if (input & HAL_KEY_STRAFE_RIGHT) side += step;
    if (input & HAL_KEY_STRAFE_LEFT) side -= step;
    int64_t mx = 0, my = 0;
    if (fwd || side) {
        fx_ang_t a = fx_ang_from_deg(c->view.angle_deg);
        int64_t sn = fx_sin(a), cs = fx_cos(a);
        /* forward (cos, sin), right (sin, -cos). A long frame can make |step| up to
         * 2^41; clamped to 2^31 (half the world: col_move cuts it up anyway), each
         * product is below 2^61 and their sum below 2^62 */
        const int64_t lim = (int64_t)1 << 31;
        fwd = fwd > lim ? lim : (fwd < -lim ? -lim : fwd);
        side = side > lim ? lim : (side < -lim ? -lim : side);
        mx = fx_asr64(fwd * cs + side * sn, FX_TRIG_SHIFT);
        my = fx_asr64(fwd * sn - side * cs, FX_TRIG_SHIFT);
    }
    if (c->noclip) {
        c->view.x = clamp_coord(c->view.x + mx);
        c->view.y = clamp_coord(c->view.y + my);
        col_move(s, w, 0, &c->view.x, &c->view.y, &c->feet, 0, 0);
    } else {
        col_move(s, w, 0, &c->view.x, &c->view.y, &c->feet, mx, my);
    }
    if (input & HAL_KEY_FLY_UP) c->fly = fx_sat32((int64_t)c->fly + per_frame(FLY_SPEED, dt_ms));
    if (input & HAL_KEY_FLY_DOWN) c->fly = fx_sat32((int64_t)c->fly - per_frame(FLY_SPEED, dt_ms));
    if (c->fly < 0) c->fly = 0;
    if (c->fly > CAM_FLY_MAX) c->fly = CAM_FLY_MAX;
    int32_t look_step = (int32_t)(LOOK_SPEED * dt_ms / 1000u);
    if (look_step < 1) look_step = 1;
    if (input & HAL_KEY_LOOK_UP) c->view.look += look_step;
    if (input & HAL_KEY_LOOK_DOWN) c->view.look -= look_step;
    if (c->view.look > VIEW_LOOK_MAX) c->view.look = VIEW_LOOK_MAX;
    if (c->view.look < -VIEW_LOOK_MAX) c->view.look = -VIEW_LOOK_MAX;
    ease_floor(c, s, w, dt_ms);
    set_eye(c);
}
