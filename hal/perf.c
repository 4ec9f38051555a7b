/* perf.c - the performance counters (prefix hal_perf_): running totals per
 * hal_event, two programmable counters and a time-stamp-style cycle counter
 * driven by the bus cost model. Shared by every target; freestanding C11,
 * integer only, no libc.
 *
 * All state lives in one static struct, fully determined by the calls a
 * caller can make: hal_perf_reset() zeroes every total, both programmable
 * counters and the cycle count; it keeps the bus model (set it with
 * hal_perf_set_bus) and the events the two counters have selected.
 * Out-of-range counters or events read as 0 and are otherwise ignored.
 */
#include "hal.h"
#include "perf_internal.h"

#define HAL_PERF_COUNTERS 2
#define HAL_BUS_DEFAULT_VRAM 8u
#define HAL_BUS_DEFAULT_SYSMEM 1u

static struct {
    uint64_t total[HAL_EV_COUNT];          /* running totals since reset */
    hal_event sel[HAL_PERF_COUNTERS];      /* event each counter counts */
    uint64_t base[HAL_PERF_COUNTERS];      /* total[sel] when selected or reset */
    uint64_t tsc;                          /* modelled bus cycles since reset */
    hal_bus_model bus;
} perf = {
    .sel = { HAL_EV_WRITES, HAL_EV_VRAM_WRITES },
    .bus = { HAL_BUS_DEFAULT_VRAM, HAL_BUS_DEFAULT_SYSMEM },
};

static const char *const event_names[HAL_EV_COUNT] = {
    [HAL_EV_WRITES] = "writes",
    [HAL_EV_BYTES] = "bytes",
    [HAL_EV_WRITES8] = "writes8",
    [HAL_EV_WRITES16] = "writes16",
    [HAL_EV_WRITES32] = "writes32",
    [HAL_EV_VRAM_WRITES] = "vram_writes",
    [HAL_EV_SYSMEM_WRITES] = "sysmem_writes",
    [HAL_EV_PIXELS] = "pixels",
    [HAL_EV_COPY_WRITES] = "copy_writes",
};

static int event_ok(hal_event e)
{
    return (unsigned)e < (unsigned)HAL_EV_COUNT;
}

const char *hal_event_name(hal_event e)
{
    return event_ok(e) ? event_names[e] : "unknown";
}

void hal_perf_reset(void)
{
    for (int i = 0; i < HAL_EV_COUNT; i++)
        perf.total[i] = 0;
    for (int c = 0; c < HAL_PERF_COUNTERS; c++)
        perf.base[c] = 0;
    perf.tsc = 0;
}

void hal_perf_set_bus(hal_bus_model m)
{
    perf.bus = m;
}

hal_bus_model hal_perf_bus(void)
{
    return perf.bus;
}

uint64_t hal_perf_event(hal_event e)
{
    return event_ok(e) ? perf.total[e] : 0;
}

void hal_perf_select(int counter, hal_event e)
{
    if (counter < 0 || counter >= HAL_PERF_COUNTERS || !event_ok(e))
        return;
    perf.sel[counter] = e;
    perf.base[counter] = perf.total[e];
}

uint64_t hal_perf_read(int counter)
{
    if (counter < 0 || counter >= HAL_PERF_COUNTERS)
        return 0;
    return perf.total[perf.sel[counter]] - perf.base[counter];
}

uint64_t hal_perf_tsc(void)
{
    return perf.tsc;
}

/* n transactions landing in VRAM or system memory, and their modelled cycles. */
static inline __attribute__((always_inline)) void count_destination(int dest, uint64_t n)
{
    if (dest == HAL_DEST_VRAM) {
        perf.total[HAL_EV_VRAM_WRITES] += n;
        perf.tsc += n * perf.bus.vram_cycles;
    } else {
        perf.total[HAL_EV_SYSMEM_WRITES] += n;
        perf.tsc += n * perf.bus.sysmem_cycles;
    }
}

void hal_perf_add_writes(unsigned width_bytes, int dest, uint32_t count, int is_copy)
{
    hal_event by_width;
    switch (width_bytes) {
    case 1: by_width = HAL_EV_WRITES8; break;
    case 2: by_width = HAL_EV_WRITES16; break;
    case 4: by_width = HAL_EV_WRITES32; break;
    default: return;
    }
    uint64_t n = count;
    perf.total[HAL_EV_WRITES] += n;
    perf.total[HAL_EV_BYTES] += n * width_bytes;
    perf.total[by_width] += n;
    count_destination(dest, n);
    if (is_copy)
        perf.total[HAL_EV_COPY_WRITES] += n;
}

void hal_perf_add_span(int dest, uint32_t n8, uint32_t n16, uint32_t n32, uint32_t pixels, uint32_t bytes)
{
    uint64_t n = (uint64_t)n8 + n16 + n32;
    perf.total[HAL_EV_WRITES] += n;
    perf.total[HAL_EV_BYTES] += bytes;
    perf.total[HAL_EV_WRITES8] += n8;
    perf.total[HAL_EV_WRITES16] += n16;
    perf.total[HAL_EV_WRITES32] += n32;
    perf.total[HAL_EV_PIXELS] += pixels;
    count_destination(dest, n);
}

void hal_perf_add_pixels(uint32_t count)
{
    perf.total[HAL_EV_PIXELS] += count;
}
