/* camera.c - eye placement and free movement. Speeds are per second and scaled by
 * the frame time, so the walk feels the same at any frame rate. */
#include "camera.h"
#include "hal.h"

#define WALK_SPEED 256     /* units per second */
#define TURN_SPEED 120     /* degrees per second */
#define FLY_SPEED 128      /* units per second */
#define LOOK_SPEED 120     /* pixels per second */

void cam_follow_floor(cam_state *c, const scene *s)
{
    uint32_t sec = scene_sector_at(s, c->view.x, c->view.y);
    if (sec == SCN_NONE) return;
    int64_t z = (int64_t)s->sectors[sec].floor_h + CAM_EYE_HEIGHT + c->fly;
    c->view.z = fx_sat32(z);
}

void cam_start(cam_state *c, const scene *s)
{
    c->view.x = s->hdr->player_x;
    c->view.y = s->hdr->player_y;
    c->view.angle_deg = s->hdr->player_angle;
    c->view.look = 0;
    c->view.z = CAM_EYE_HEIGHT;
    c->fly = 0;
    cam_follow_floor(c, s);
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

void cam_move(cam_state *c, const scene *s, uint32_t input, uint32_t dt_ms)
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
    if (fwd || side) {
        fx_ang_t a = fx_ang_from_deg(c->view.angle_deg);
        int64_t sn = fx_sin(a), cs = fx_cos(a);
        /* forward (cos, sin), right (sin, -cos); |step| < 2^24, trig 2^30: < 2^55 */
        c->view.x = clamp_coord(c->view.x + fx_asr64(fwd * cs + side * sn, FX_TRIG_SHIFT));
        c->view.y = clamp_coord(c->view.y + fx_asr64(fwd * sn - side * cs, FX_TRIG_SHIFT));
    }
    if (input & HAL_KEY_FLY_UP) c->fly = fx_sat32((int64_t)c->fly + per_frame(FLY_SPEED, dt_ms));
    if (input & HAL_KEY_FLY_DOWN) c->fly = fx_sat32((int64_t)c->fly - per_frame(FLY_SPEED, dt_ms));
    int32_t look_step = (int32_t)(LOOK_SPEED * dt_ms / 1000u);
    if (look_step < 1) look_step = 1;
    if (input & HAL_KEY_LOOK_UP) c->view.look += look_step;
    if (input & HAL_KEY_LOOK_DOWN) c->view.look -= look_step;
    if (c->view.look > VIEW_LOOK_MAX) c->view.look = VIEW_LOOK_MAX;
    if (c->view.look < -VIEW_LOOK_MAX) c->view.look = -VIEW_LOOK_MAX;
    cam_follow_floor(c, s);
}
