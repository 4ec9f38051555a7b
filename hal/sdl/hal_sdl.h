/* hal_sdl.h - the host window target (prefix hal_sdl_), SDL2. Provides the
 * hal.h target functions, input, time and the frame-done hook for a desktop
 * window. VRAM, the system-memory buffer and the palette are static arrays;
 * hal_frame_done() shows the page the display start selects, through the
 * palette, scaled to a 4:3 window (320x200 with VGA's non-square pixels).
 *
 * Keys (held unless marked edge, which are reported once per press):
 *   Up/Down            forward/back        Left/Right      turn
 *   Alt+Left/Right, ',' '.'  strafe         PgUp/PgDn, A/Z  fly up/down
 *   Home/End, Q/W      look up/down        Shift           run
 *   M next render mode (edge)   P next present mode (edge)
 *   C print counters (edge)     V print the camera (edge)
 *   S or F12 screenshot (edge)  Esc or closing the window: quit (stays set)
 */
#ifndef HAL_SDL_H
#define HAL_SDL_H

#define HAL_SDL_DEFAULT_SCALE 3
#define HAL_SDL_MAX_SCALE 8

/* Open the window: scale is the integer size factor (<= 0: default 3; larger
 * than 8 is clamped), title may be NULL. Returns 0, or -1 with the reason in
 * hal_sdl_error() (e.g. no display available); on failure nothing stays open
 * and the call may be repeated. Calling it while open does nothing, returns 0. */
int hal_sdl_init(int scale, const char *title);

/* Why the last hal_sdl_init failed ("" if it did not). */
const char *hal_sdl_error(void);

/* Close the window and shut SDL down; safe to call when not open. */
void hal_sdl_quit(void);

#endif
