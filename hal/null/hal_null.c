/* hal_null.c - the headless target: VRAM pages, system-memory buffer and palette
 * in RAM (hal/ram_target.c), scripted input, a deterministic 35 Hz clock, and a
 * frame-done hook that only counts. Freestanding C11, integer only, no libc.
 * See hal_null.h for the input and time rules.
 */
#include <stddef.h>
#include "hal.h"
#include "ram_target.h"
#include "hal_null.h"

#define HAL_NULL_TIC_HZ 35u


static struct {
    uint32_t input;
    uint32_t frames;
    uint32_t ticks;     /* ms */
    uint32_t tick_frac; /* carried remainder, in 1/35 ms */
    int manual_ticks;   /* 1 once the host set the clock */
} st;

#define HAL_KEY_EDGES ((uint32_t)HAL_KEY_NEXT_MODE | (uint32_t)HAL_KEY_NEXT_PRESENT | (uint32_t)HAL_KEY_PRINT_COUNTERS)

uint32_t hal_input(void)
{
    uint32_t keys = st.input;
    st.input &= ~HAL_KEY_EDGES;
    return keys;
}

uint32_t hal_ticks_ms(void)
{
    return st.ticks;
}

void hal_frame_done(void)
{
    st.frames++;
    if (!st.manual_ticks) {
        st.tick_frac += 1000u;
        st.ticks += st.tick_frac / HAL_NULL_TIC_HZ;
        st.tick_frac %= HAL_NULL_TIC_HZ;
    }
}

void hal_null_set_input(uint32_t keys)
{
    st.input = keys;
}

void hal_null_set_ticks(uint32_t ms)
{
    st.ticks = ms;
    st.tick_frac = 0;
    st.manual_ticks = 1;
}

uint32_t hal_null_frames(void)
{
    return st.frames;
}

void hal_null_reset(void)
{
    hal_ram_target_reset();
    st.input = 0;
    st.frames = 0;
    st.ticks = 0;
    st.tick_frac = 0;
    st.manual_ticks = 0;
}
