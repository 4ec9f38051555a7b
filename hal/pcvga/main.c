/* main.c - the PC kernel's entry and its hooks into the shared main loop
 * (hal/pcvga, hal/bare/bare_main.h).
 *
 * From the multiboot entry (boot.S): keep the loader's command line and memory
 * size, set up COM1, interrupts and the PIT, then run the shared loop: the work
 * area is the free memory above the kernel, the VGA goes to mode 13h
 * (unchained for flip), and after each frame of the scripted camera path (or
 * of a fixed view) COM1 gets one line: the CRC-32 of the frame the VGA shows
 * (read back from VGA memory), the camera it was rendered from, the frame's
 * write counters and its modelled bus cycles (hal.h). Then, with --wait, wait
 * for a byte on COM1 (a test takes the screen meanwhile), and exit through
 * isa-debug-exit.
 *
 * Exit statuses: exit.h (QEMU exits with 2 * status + 1).
 *
 * The build (mk/pcvga.mk) generates the scene file: the compiled scene blob,
 * its name and the camera path's name.
 */
#include <stdint.h>

#include "bare_main.h"
#include "com1.h"
#include "crc32.h"
#include "exit.h"
#include "hal.h"
#include "hal_pcvga.h"
#include "log.h"
#include "trap.h"

#define MULTIBOOT_MAGIC 0x2BADB002u
#define MB_HAVE_MEMORY (1u << 0)
#define MB_HAVE_CMDLINE (1u << 2)
#define UPPER_MEMORY_BASE 0x100000u

_Static_assert(PCVGA_EXIT_OK == BARE_EXIT_OK && PCVGA_EXIT_SCENE == BARE_EXIT_SCENE &&
                   PCVGA_EXIT_WORK == BARE_EXIT_WORK && PCVGA_EXIT_ARGS == BARE_EXIT_ARGS,
               "exit.h gives bare_main's statuses their own numbers");

extern uint8_t __end[]; /* pcvga.ld: the first free byte above the kernel */

__attribute__((noreturn)) void pcvga_start(uint32_t magic, const uint32_t *info);

/* The multiboot information lies in memory the work area will take: keep
 * what is needed of it first. */
typedef struct {
    char cmdline[256];
    uint32_t mem_top; /* end of the upper memory, or 0 if the loader did not say */
} boot_info;

static void keep_boot_info(boot_info *b, const uint32_t *info)
{
    b->cmdline[0] = '\0';
    b->mem_top = 0;
    if (info[0] & MB_HAVE_MEMORY) b->mem_top = UPPER_MEMORY_BASE + info[2] * 1024u;
    if (info[0] & MB_HAVE_CMDLINE) {
        const char *s = (const char *)(uintptr_t)info[4];
        uint32_t n = 0;
        while (s[n] && n + 1 < sizeof b->cmdline) {
            b->cmdline[n] = s[n];
            n++;
        }
        b->cmdline[n] = '\0';
    }
}

/* One line a frame: what the screen shows, from which camera, at what cost. */
static int report_frame(const bare_run *r, uint32_t f)
{
    const engine *e = &r->e;
    static _Alignas(4) uint8_t shown[HAL_PAGE_BYTES];
    pcvga_read_shown(shown);
    const camera *v = &e->cam.view;
    log_printf("frame %u crc %08x x %d y %d z %d angle %d look %d t_ms %u", (unsigned)f,
               (unsigned)crc_update(0, shown, HAL_PAGE_BYTES), (int)v->x, (int)v->y, (int)v->z, (int)v->angle_deg,
               (int)v->look, (unsigned)e->t_ms);
    for (int ev = 0; ev < HAL_EV_COUNT; ev++)
        log_printf(" %s %u", hal_event_name((hal_event)ev), (unsigned)hal_perf_event((hal_event)ev));
    log_printf(" bus_cycles %u\n", (unsigned)hal_perf_tsc());
    return 0;
}

static void wait_ms(uint32_t ms)
{
    for (uint32_t start = hal_ticks_ms(); hal_ticks_ms() - start < ms;) __asm__ volatile("hlt");
}

static void wait_for_byte(void)
{
    log_printf("pcvga: waiting for a byte on COM1 to exit\n");
    while (com1_getc() < 0) __asm__ volatile("hlt"); /* the PIT wakes it every ms */
}


static void pcvga_fault(void)
{
    __asm__ volatile("ud2");
}

/* The multiboot memory size, kept before the work area takes the information's place. */
static uint32_t mem_top;

static bare_work pcvga_work(uint32_t need)
{
    uint8_t *work = (uint8_t *)(((uintptr_t)__end + 7u) & ~(uintptr_t)7u);
    uint32_t avail = mem_top > (uintptr_t)work ? mem_top - (uint32_t)(uintptr_t)work : 0;
    return (bare_work){work, need <= avail ? need : avail, avail};
}

static void pcvga_work_refused(uint32_t need, uint32_t avail)
{
    log_printf("pcvga: the scene %s needs %u bytes of work memory; %u are free above the kernel "
               "(give QEMU more with -m)\n",
               fw_scene_name, (unsigned)need, (unsigned)avail);
}

static int pcvga_run_start(const bare_run *r)
{
    const engine *e = &r->e;
    pcvga_use_present(e->present);
    pcvga_set_path(r->fixed_view ? 0 : r->path);
    log_printf("pcvga: PC, VGA %s; scene %s (%u bytes, work %u of %u bytes free); %s %u frames; mode %s, present %s\n",
               e->present == HAL_PRESENT_FLIP ? "320x200 unchained, 2 pages" : "mode 13h", fw_scene_name,
               (unsigned)fw_scene_len, (unsigned)r->need, (unsigned)r->avail,
               r->fixed_view ? "fixed view," : r->path->name, (unsigned)r->frames, render_mode_name(e->mode),
               hal_present_name(e->present));
    return 0;
}

/* The frame's write counters and bus cycles start at its engine step. */
static void pcvga_frame_begin(uint32_t f)
{
    (void)f;
    hal_perf_reset();
}

static int pcvga_finish(const bare_run *r)
{
    log_printf("pcvga: done, %u frames in %u ms (PIT)\n", (unsigned)r->frames, (unsigned)(hal_ticks_ms() - r->t0));
    if (r->args.linger_ms > 0) wait_ms((uint32_t)r->args.linger_ms);
    if (r->args.wait) wait_for_byte();
    return PCVGA_EXIT_OK;
}

static const bare_target pcvga_target = {
    .name = "pcvga",
    .offered = ARGS_WAIT,
    .log = log_printf,
    .fault = pcvga_fault,
    .work = pcvga_work,
    .work_refused = pcvga_work_refused,
    .start = pcvga_run_start,
    .frame_begin = pcvga_frame_begin,
    .frame_out = report_frame,
    .finish = pcvga_finish,
};

void pcvga_start(uint32_t magic, const uint32_t *info)
{
    static boot_info boot;

    com1_init();
    if (magic != MULTIBOOT_MAGIC) {
        log_printf("pcvga: not started by a multiboot loader (eax 0x%08x)\n", (unsigned)magic);
        pcvga_exit(PCVGA_EXIT_BOOT);
    }
    keep_boot_info(&boot, info);
    trap_init();
    mem_top = boot.mem_top;
    pcvga_exit((uint8_t)bare_main(&pcvga_target, boot.cmdline));
}
