/* hal_sdl.c - the host window target (SDL2), VRAM pages, system-memory buffer
 * and palette in RAM (hal/ram_target.c); the frame-done hook converts the shown page through the
 * palette into an ARGB texture and presents it; keyboard input, SDL ticks.
 * A host target: it may use libc, but no floating point (the build compiles
 * hal/ with -mgeneral-regs-only).
 *
 * Scaling (Chocolate Doom's way): the 320x200 frame is a nearest-sampled
 * streaming texture, drawn into a render-target texture `scale` times larger
 * with nearest sampling, which is then drawn with linear filtering into a
 * 320x240 logical area: 4:3 with sharp pixels, no uneven rows. Without
 * render-target support the frame goes straight to the 4:3 area (nearest).
 */
#define SDL_MAIN_HANDLED
#include <SDL.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal.h"
#include "ram_target.h"
#include "hal_sdl.h"

#define HAL_SDL_ASPECT_H 240 /* 320x200 shown as 320x240 */


#define HAL_SDL_FRAME_MS 14u

static struct {
    SDL_Window *win;
    SDL_Renderer *ren;
    SDL_Texture *frame;    /* 320x200 ARGB, streaming, nearest */
    SDL_Texture *upscaled; /* 320s x 200s render target, linear; NULL if unsupported */
    uint32_t t0;
    uint32_t last_shown; /* SDL ticks when the last frame was shown */
    uint32_t edges;      /* edge-triggered bits (and quit) pressed since the last hal_input */
    SDL_Scancode sc_a, sc_z, sc_q, sc_w, sc_comma, sc_period, sc_m, sc_p, sc_c, sc_v, sc_s;
    char err[256];
} sdl;

#define HAL_KEY_EDGES                                                                                                  \
    ((uint32_t)HAL_KEY_NEXT_MODE | (uint32_t)HAL_KEY_NEXT_PRESENT | (uint32_t)HAL_KEY_PRINT_COUNTERS |                 \
     (uint32_t)HAL_KEY_PRINT_VIEW | (uint32_t)HAL_KEY_SCREENSHOT)

/* ---- window -------------------------------------------------------------- */
const char *hal_sdl_error(void)
{
    return sdl.err;
}

static void fail(const char *what)
{
    snprintf(sdl.err, sizeof sdl.err, "%s: %s", what, SDL_GetError());
}

static void destroy(void)
{
    if (sdl.upscaled) SDL_DestroyTexture(sdl.upscaled);
    if (sdl.frame) SDL_DestroyTexture(sdl.frame);
    if (sdl.ren) SDL_DestroyRenderer(sdl.ren);
    if (sdl.win) SDL_DestroyWindow(sdl.win);
    sdl.upscaled = NULL;
    sdl.frame = NULL;
    sdl.ren = NULL;
    sdl.win = NULL;
}

/* Letter and punctuation keys follow the keyboard layout's labels. */
static SDL_Scancode key_sc(SDL_Keycode k, SDL_Scancode fallback)
{
    SDL_Scancode sc = SDL_GetScancodeFromKey(k);
    return sc == SDL_SCANCODE_UNKNOWN ? fallback : sc;
}

/* SDL 2.26 picks its windowless "offscreen" (or "dummy") driver by itself
 * when no display works; that is a failure unless the user asked for it. */
static int headless_fallback(const char *asked)
{
    const char *drv = SDL_GetCurrentVideoDriver();
    if (drv == NULL) return 1;
    if (strcmp(drv, "offscreen") != 0 && strcmp(drv, "dummy") != 0) return 0;
    return asked == NULL || strstr(asked, drv) == NULL;
}

int hal_sdl_init(int scale, const char *title)
{
    sdl.err[0] = '\0';
    if (sdl.win) return 0;
    if (scale <= 0) scale = HAL_SDL_DEFAULT_SCALE;
    if (scale > HAL_SDL_MAX_SCALE) scale = HAL_SDL_MAX_SCALE;
    if (title == NULL) title = "hal";

    const char *asked = SDL_GetHint(SDL_HINT_VIDEODRIVER); /* also reads the environment */
    const char *xdg = getenv("XDG_RUNTIME_DIR"), *wl = getenv("WAYLAND_DISPLAY");
    if (!asked && (!xdg || !*xdg) && (!wl || wl[0] != '/')) {
        /* No Wayland socket can be found, and libwayland would say so on
         * stderr when SDL tries it: leave Wayland out of SDL's own list. */
        SDL_SetHint(SDL_HINT_VIDEODRIVER, "x11,KMSDRM,offscreen,dummy");
    }
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        fail("SDL_Init(video) failed (no display?)");
        return -1;
    }
    if (headless_fallback(asked)) {
        snprintf(sdl.err, sizeof sdl.err,
                 "no display available: SDL fell back to its '%s' video driver "
                 "(set DISPLAY, or SDL_VIDEODRIVER=%s to run without a window)",
                 SDL_GetCurrentVideoDriver(), SDL_GetCurrentVideoDriver());
        SDL_Quit();
        return -1;
    }
    sdl.win = SDL_CreateWindow(title, SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, HAL_WIDTH * scale,
                               HAL_SDL_ASPECT_H * scale, SDL_WINDOW_RESIZABLE);
    if (!sdl.win) {
        fail("SDL_CreateWindow");
        goto out;
    }
    sdl.ren = SDL_CreateRenderer(sdl.win, -1, SDL_RENDERER_TARGETTEXTURE);
    if (!sdl.ren) sdl.ren = SDL_CreateRenderer(sdl.win, -1, 0);
    if (!sdl.ren) sdl.ren = SDL_CreateRenderer(sdl.win, -1, SDL_RENDERER_SOFTWARE);
    if (!sdl.ren) {
        fail("SDL_CreateRenderer");
        goto out;
    }
    if (SDL_RenderSetLogicalSize(sdl.ren, HAL_WIDTH, HAL_SDL_ASPECT_H) != 0) {
        fail("SDL_RenderSetLogicalSize");
        goto out;
    }
    SDL_SetHint(SDL_HINT_RENDER_SCALE_QUALITY, "nearest");
    sdl.frame = SDL_CreateTexture(sdl.ren, SDL_PIXELFORMAT_ARGB8888, SDL_TEXTUREACCESS_STREAMING, HAL_WIDTH,
                                  HAL_HEIGHT);
    if (!sdl.frame) {
        fail("SDL_CreateTexture");
        goto out;
    }
    if (SDL_RenderTargetSupported(sdl.ren)) {
        SDL_SetHint(SDL_HINT_RENDER_SCALE_QUALITY, "linear");
        sdl.upscaled = SDL_CreateTexture(sdl.ren, SDL_PIXELFORMAT_ARGB8888, SDL_TEXTUREACCESS_TARGET, HAL_WIDTH * scale,
                                         HAL_HEIGHT * scale);
        /* NULL: fall back to the direct nearest copy */
    }
    sdl.sc_a = key_sc(SDLK_a, SDL_SCANCODE_A);
    sdl.sc_z = key_sc(SDLK_z, SDL_SCANCODE_Z);
    sdl.sc_q = key_sc(SDLK_q, SDL_SCANCODE_Q);
    sdl.sc_w = key_sc(SDLK_w, SDL_SCANCODE_W);
    sdl.sc_comma = key_sc(SDLK_COMMA, SDL_SCANCODE_COMMA);
    sdl.sc_period = key_sc(SDLK_PERIOD, SDL_SCANCODE_PERIOD);
    sdl.sc_m = key_sc(SDLK_m, SDL_SCANCODE_M);
    sdl.sc_p = key_sc(SDLK_p, SDL_SCANCODE_P);
    sdl.sc_c = key_sc(SDLK_c, SDL_SCANCODE_C);
    sdl.sc_v = key_sc(SDLK_v, SDL_SCANCODE_V);
    sdl.sc_s = key_sc(SDLK_s, SDL_SCANCODE_S);
    sdl.edges = 0;
    sdl.t0 = SDL_GetTicks();
    return 0;
out:
    destroy();
    SDL_Quit();
    return -1;
}

void hal_sdl_quit(void)
{
    if (!sdl.win) return;
    destroy();
    SDL_Quit();
}

/* ---- input and time ----------------------------------------------------- */
static void pump(void)
{
    SDL_Event ev;
    while (SDL_PollEvent(&ev)) {
        if (ev.type == SDL_QUIT) {
            sdl.edges |= HAL_KEY_QUIT;
        } else if (ev.type == SDL_WINDOWEVENT && ev.window.event == SDL_WINDOWEVENT_CLOSE) {
            sdl.edges |= HAL_KEY_QUIT;
        } else if (ev.type == SDL_KEYDOWN && !ev.key.repeat) {
            SDL_Scancode sc = ev.key.keysym.scancode;
            if (sc == SDL_SCANCODE_ESCAPE)
                sdl.edges |= HAL_KEY_QUIT;
            else if (sc == sdl.sc_m)
                sdl.edges |= HAL_KEY_NEXT_MODE;
            else if (sc == sdl.sc_p)
                sdl.edges |= HAL_KEY_NEXT_PRESENT;
            else if (sc == sdl.sc_c)
                sdl.edges |= HAL_KEY_PRINT_COUNTERS;
            else if (sc == sdl.sc_v)
                sdl.edges |= HAL_KEY_PRINT_VIEW;
            else if (sc == sdl.sc_s || sc == SDL_SCANCODE_F12)
                sdl.edges |= HAL_KEY_SCREENSHOT;
        }
    }
}

uint32_t hal_input(void)
{
    if (!sdl.win) return 0;
    pump();
    const Uint8 *k = SDL_GetKeyboardState(NULL);
    uint32_t keys = 0;
    int alt = k[SDL_SCANCODE_LALT] || k[SDL_SCANCODE_RALT];
    if (k[SDL_SCANCODE_UP]) keys |= HAL_KEY_FORWARD;
    if (k[SDL_SCANCODE_DOWN]) keys |= HAL_KEY_BACK;
    if (k[SDL_SCANCODE_LEFT]) keys |= alt ? HAL_KEY_STRAFE_LEFT : HAL_KEY_TURN_LEFT;
    if (k[SDL_SCANCODE_RIGHT]) keys |= alt ? HAL_KEY_STRAFE_RIGHT : HAL_KEY_TURN_RIGHT;
    if (k[sdl.sc_comma]) keys |= HAL_KEY_STRAFE_LEFT;
    if (k[sdl.sc_period]) keys |= HAL_KEY_STRAFE_RIGHT;
    if (k[SDL_SCANCODE_PAGEUP] || k[sdl.sc_a]) keys |= HAL_KEY_FLY_UP;
    if (k[SDL_SCANCODE_PAGEDOWN] || k[sdl.sc_z]) keys |= HAL_KEY_FLY_DOWN;
    if (k[SDL_SCANCODE_HOME] || k[sdl.sc_q]) keys |= HAL_KEY_LOOK_UP;
    if (k[SDL_SCANCODE_END] || k[sdl.sc_w]) keys |= HAL_KEY_LOOK_DOWN;
    if (k[SDL_SCANCODE_LSHIFT] || k[SDL_SCANCODE_RSHIFT]) keys |= HAL_KEY_RUN;
    keys |= sdl.edges;
    sdl.edges &= ~HAL_KEY_EDGES; /* edges once; quit stays */
    return keys;
}

uint32_t hal_ticks_ms(void)
{
    if (!sdl.win) return 0;
    return SDL_GetTicks() - sdl.t0;
}

/* ---- show a frame ------------------------------------------------------- */
void hal_frame_done(void)
{
    if (!sdl.win) return;
    const uint8_t *palette = hal_target_palette();
    uint32_t lut[256];
    for (int i = 0; i < 256; i++)
        lut[i] = 0xff000000u | (uint32_t)palette[i * 3] << 16 | (uint32_t)palette[i * 3 + 1] << 8 | palette[i * 3 + 2];

    const uint8_t *src = hal_target_vram(hal_target_display_start());
    void *pixels;
    int pitch;
    if (SDL_LockTexture(sdl.frame, NULL, &pixels, &pitch) == 0) {
        for (int y = 0; y < HAL_HEIGHT; y++) {
            uint32_t *row = (uint32_t *)(void *)((uint8_t *)pixels + (size_t)y * (size_t)pitch);
            const uint8_t *s = src + y * HAL_WIDTH;
            for (int x = 0; x < HAL_WIDTH; x++) row[x] = lut[s[x]];
        }
        SDL_UnlockTexture(sdl.frame);
    }

    SDL_SetRenderDrawColor(sdl.ren, 0, 0, 0, 255);
    if (sdl.upscaled && SDL_SetRenderTarget(sdl.ren, sdl.upscaled) == 0) {
        SDL_RenderCopy(sdl.ren, sdl.frame, NULL, NULL);
        SDL_SetRenderTarget(sdl.ren, NULL);
        SDL_RenderClear(sdl.ren);
        SDL_RenderCopy(sdl.ren, sdl.upscaled, NULL, NULL);
    } else {
        SDL_RenderClear(sdl.ren);
        SDL_RenderCopy(sdl.ren, sdl.frame, NULL, NULL);
    }
    SDL_RenderPresent(sdl.ren);
    pump();
    /* No vsync is asked for (it is not available everywhere): cap the loop at
     * about 70 frames per second, VGA mode 13h's refresh rate, instead. */
    uint32_t since = SDL_GetTicks() - sdl.last_shown;
    if (since < HAL_SDL_FRAME_MS) SDL_Delay(HAL_SDL_FRAME_MS - since);
    sdl.last_shown = SDL_GetTicks();
}
