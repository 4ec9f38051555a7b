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
 *
 * Spans are counted in 32-bit sums (a 32-bit core adds a 64-bit total in two
 * instructions and loads and stores both halves: 7.6% of a Cortex-M3 frame when
 * every span did), folded into the 64-bit totals when a frame is presented and
 * before anything reads, resets, reselects or reprices them, so every value read
 * is the one per-span 64-bit sums would give.
 */
#include "hal.h"
#include "perf_internal.h"

#define HAL_PERF_COUNTERS 2
#define HAL_BUS_DEFAULT_VRAM 8u
#define HAL_BUS_DEFAULT_SYSMEM 1u

static struct {
    uint64_t total[HAL_EV_COUNT];     /* running totals since reset */
    hal_event sel[HAL_PERF_COUNTERS]; /* event each counter counts */
    uint64_t base[HAL_PERF_COUNTERS]; /* total[sel] when selected or reset */
    uint64_t tsc;                     /* modelled bus cycles since reset */
    hal_bus_model bus;
    /* span counts not yet in total[] or tsc; each span adds at most 320 to pixels
     * and no more than that to any other sum (hal_fill_span clips len to the row;
     * transactions <= bytes <= pixels), and pixels is folded in once it passes
     * 2^31, so none can wrap */
    struct {
        uint32_t n8, n16, n32, pixels, bytes, vram, sysmem;
    } span;
} perf = {
    .sel = {HAL_EV_WRITES, HAL_EV_VRAM_WRITES},
    .bus = {HAL_BUS_DEFAULT_VRAM, HAL_BUS_DEFAULT_SYSMEM},
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

void hal_perf_fold(void)
{
    uint64_t vram = perf.span.vram, sysmem = perf.span.sysmem;
    perf.total[HAL_EV_WRITES] += vram + sysmem;
    perf.total[HAL_EV_BYTES] += perf.span.bytes;
    perf.total[HAL_EV_WRITES8] += perf.span.n8;
    perf.total[HAL_EV_WRITES16] += perf.span.n16;
    perf.total[HAL_EV_WRITES32] += perf.span.n32;
    perf.total[HAL_EV_PIXELS] += perf.span.pixels;
    perf.total[HAL_EV_VRAM_WRITES] += vram;
    perf.total[HAL_EV_SYSMEM_WRITES] += sysmem;
    perf.tsc += vram * perf.bus.vram_cycles + sysmem * perf.bus.sysmem_cycles;
    perf.span.n8 = perf.span.n16 = perf.span.n32 = perf.span.pixels = perf.span.bytes = 0;
    perf.span.vram = perf.span.sysmem = 0;
}

void hal_perf_reset(void)
{
    hal_perf_fold();
    for (int i = 0; i < HAL_EV_COUNT; i++) perf.total[i] = 0;
    for (int c = 0; c < HAL_PERF_COUNTERS; c++) perf.base[c] = 0;
    perf.tsc = 0;
}

void hal_perf_set_bus(hal_bus_model m)
{
    hal_perf_fold(); /* the spans so far at the old prices */
    perf.bus = m;
}

hal_bus_model hal_perf_bus(void)
{
    return perf.bus;
}

uint64_t hal_perf_event(hal_event e)
{
    hal_perf_fold();
    return event_ok(e) ? perf.total[e] : 0;
}

void hal_perf_select(int counter, hal_event e)
{
    if (counter < 0 || counter >= HAL_PERF_COUNTERS || !event_ok(e)) return;
    hal_perf_fold();
    perf.sel[counter] = e;
    perf.base[counter] = perf.total[e];
}

uint64_t hal_perf_read(int counter)
{
    if (counter < 0 || counter >= HAL_PERF_COUNTERS) return 0;
    hal_perf_fold();
    return perf.total[perf.sel[counter]] - perf.base[counter];
}

uint64_t hal_perf_tsc(void)
{
    hal_perf_fold();
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
    if (is_copy) perf.total[HAL_EV_COPY_WRITES] += n;
}

void hal_perf_add_span(int dest, uint32_t n8, uint32_t n16, uint32_t n32, uint32_t pixels, uint32_t bytes)
{
    uint32_t n = n8 + n16 + n32;
    perf.span.n8 += n8;
    perf.span.n16 += n16;
    perf.span.n32 += n32;
    perf.span.bytes += bytes;
    if (dest == HAL_DEST_VRAM)
        perf.span.vram += n;
    else
        perf.span.sysmem += n;
    perf.span.pixels += pixels;
    if (perf.span.pixels >= 0x80000000u) hal_perf_fold();
}

void hal_perf_add_pixels(uint32_t count)
{
    perf.total[HAL_EV_PIXELS] += count;
}
