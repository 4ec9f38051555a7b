/* main.c - the PC kernel's main loop (hal/pcvga).
 *
 * From the multiboot entry (boot.S): keep the loader's command line and memory
 * size, set up COM1, interrupts and the PIT, validate the built-in scene, take
 * its work area from the free memory above the kernel, put the VGA in mode 13h
 * (unchained for flip), then for each frame of the scripted camera path (or of
 * a fixed view) step the engine and report on COM1 one line: the CRC-32 of the
 * frame the VGA shows (read back from VGA memory), the camera it was rendered
 * from, the frame's write counters and its modelled bus cycles (hal.h). Then,
 * with --wait, wait for a byte on
 * COM1 (a test takes the screen meanwhile), and exit through isa-debug-exit.
 *
 * Exit statuses: exit.h (QEMU exits with 2 * status + 1).
 *
 * The build (mk/pcvga.mk) generates the scene file: the compiled scene blob,
 * its name and the camera path's name.
 */
#include <stdint.h>

#include "args.h"
#include "campath.h"
#include "com1.h"
#include "crc32.h"
#include "engine.h"
#include "fixed_view.h"
#include "exit.h"
#include "hal.h"
#include "hal_pcvga.h"
#include "log.h"
#include "scene_refusal.h"
#include "trap.h"

#define MULTIBOOT_MAGIC 0x2BADB002u
#define MB_HAVE_MEMORY (1u << 0)
#define MB_HAVE_CMDLINE (1u << 2)
#define UPPER_MEMORY_BASE 0x100000u

/* ---- from the generated scene file (mk/pcvga.mk) ------------------------ */
extern const uint8_t fw_scene[];
extern const uint32_t fw_scene_len;
extern const char fw_scene_name[];
extern const char fw_campath_name[];

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
static void report_frame(const engine *e, uint32_t f)
{
    static _Alignas(4) uint8_t shown[HAL_PAGE_BYTES];
    pcvga_read_shown(shown);
    const camera *v = &e->cam.view;
    log_printf("frame %u crc %08x x %d y %d z %d angle %d look %d t_ms %u", (unsigned)f,
               (unsigned)crc_update(0, shown, HAL_PAGE_BYTES), (int)v->x, (int)v->y, (int)v->z, (int)v->angle_deg,
               (int)v->look, (unsigned)e->t_ms);
    for (int ev = 0; ev < HAL_EV_COUNT; ev++)
        log_printf(" %s %u", hal_event_name((hal_event)ev), (unsigned)hal_perf_event((hal_event)ev));
    log_printf(" bus_cycles %u\n", (unsigned)hal_perf_tsc());
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

void pcvga_start(uint32_t magic, const uint32_t *info)
{
    static boot_info boot;
    static engine e;
    static fw_args args;
    static char err[128];

    com1_init();
    if (magic != MULTIBOOT_MAGIC) {
        log_printf("pcvga: not started by a multiboot loader (eax 0x%08x)\n", (unsigned)magic);
        pcvga_exit(PCVGA_EXIT_BOOT);
    }
    keep_boot_info(&boot, info);
    trap_init();
    if (args_parse(&args, boot.cmdline, ARGS_WAIT, err, sizeof err) != 0) {
        log_printf("pcvga: %s\n", err);
        pcvga_exit(PCVGA_EXIT_ARGS);
    }
    const campath *path = campath_find(args.path ? args.path : fw_campath_name);
    if (!path) {
        log_printf("pcvga: no camera path named '%s' (default, map01)\n", args.path ? args.path : fw_campath_name);
        pcvga_exit(PCVGA_EXIT_ARGS);
    }
    if (args.fault) __asm__ volatile("ud2");
    int fixed_view = fixed_view_wanted(&args);

    scene_error se;
    scene_status st = eng_init(&e, fw_scene, fw_scene_len, &se);
    if (st != SCENE_OK) {
        static char why[240]; /* with the prefix, within a log line (256) */
        scene_refusal_format(why, sizeof why, fw_scene_name, st, &se);
        log_printf("pcvga: %s\n", why);
        pcvga_exit(PCVGA_EXIT_SCENE);
    }
    uint8_t *work = (uint8_t *)(((uintptr_t)__end + 7u) & ~(uintptr_t)7u);
    uint32_t avail = boot.mem_top > (uintptr_t)work ? boot.mem_top - (uint32_t)(uintptr_t)work : 0;
    uint32_t need = eng_work_bytes(&e);
    if (eng_set_work(&e, work, need <= avail ? need : avail) != 0) {
        log_printf("pcvga: the scene %s needs %u bytes of work memory; %u are free above the kernel "
                   "(give QEMU more with -m)\n", fw_scene_name, (unsigned)need, (unsigned)avail);
        pcvga_exit(PCVGA_EXIT_WORK);
    }
    if (args.mode >= 0) e.mode = (render_mode)args.mode;
    e.flat = (uint8_t)args.flat;
    if (args.present >= 0) e.present = (hal_present_mode)args.present;
    if (fixed_view) fixed_view_apply(&e, &args);
    pcvga_use_present(e.present);

    uint32_t frames = args.frames >= 0 ? (uint32_t)args.frames : campath_frames(path);
    pcvga_set_path(fixed_view ? 0 : path);
    log_printf("pcvga: PC, VGA %s; scene %s (%u bytes, work %u of %u bytes free); %s %u frames; mode %s, present %s\n",
               e.present == HAL_PRESENT_FLIP ? "320x200 unchained, 2 pages" : "mode 13h", fw_scene_name,
               (unsigned)fw_scene_len, (unsigned)need, (unsigned)avail, fixed_view ? "fixed view," : path->name,
               (unsigned)frames, render_mode_name(e.mode), hal_present_name(e.present));

    uint32_t t0 = hal_ticks_ms();
    for (uint32_t f = 0; f < frames; f++) {
        uint32_t input = hal_input();
        hal_perf_reset();
        if (fixed_view) {
            eng_render(&e, 0);
            hal_frame_done();
        } else {
            eng_step(&e, input, campath_dt_ms(f));
        }
        report_frame(&e, f);
    }
    log_printf("pcvga: done, %u frames in %u ms (PIT)\n", (unsigned)frames, (unsigned)(hal_ticks_ms() - t0));
    if (args.linger_ms > 0) wait_ms((uint32_t)args.linger_ms);
    if (args.wait) wait_for_byte();
    pcvga_exit(PCVGA_EXIT_OK);
}
