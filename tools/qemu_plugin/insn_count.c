/* insn_count.c - a QEMU TCG plugin that counts guest instructions per frame.
 *
 * Built as build/insn_count.so (mk/mps2.mk: make insn-plugin) and loaded with
 *   qemu-system-arm ... -plugin build/insn_count.so,begin=0xADDR,end=0xADDR,out=FILE
 * begin/end: the addresses of the firmware's two marker functions
 *   (hal/mps2/main.c: fw_mark_frame_begin and fw_mark_frame_end; the Thumb bit
 *   may be set or not), which the firmware calls right before and right after
 *   eng_step() - so "render" below is input + camera + render + present + the
 *   frame-done hook, and "total" adds streaming the frame over the UART.
 * out: where the per-frame counts go at exit (default: QEMU's log, stderr).
 * profile=FILE (optional): also where the instructions inside the frames were:
 *   every block gets a callback that counts its runs while a frame is open
 *   (between a begin and the next end mark), and at exit FILE gets one line
 *   "0xADDR runs" per guest instruction address run inside frames, summed over
 *   all frames (tools/bench_profile.py turns addresses into stages). A block's
 *   callback comes before its instructions, so the block holding the begin mark
 *   is left out and the one holding the end mark counted whole: a few
 *   instructions of the marker functions per frame.
 *
 * Every translated block adds its instruction count to one 64-bit counter with
 * an inline TCG add (no call per block). When a marker instruction runs, a
 * callback reads the counter and subtracts the instructions of its block that
 * come at or after it (the inline add counts the whole block up front), so a
 * snapshot is the exact number of guest instructions retired before the marker.
 * Instructions of interrupt handlers (the SysTick tick) are counted where they
 * happen, as a real core would spend them.
 *
 * Output, one line per frame marked with begin (plain text, # comments):
 *   frame render_insns total_insns
 * where total_insns runs from this frame's begin to the next one's (to the exit
 * for the last frame), and a last comment line with all instructions executed.
 *
 * Plain C, no glib: see qemu_plugin_api.h for why the API is declared here.
 */
#define _POSIX_C_SOURCE 200809L /* strdup */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "qemu_plugin_api.h"

QEMU_PLUGIN_EXPORT int qemu_plugin_version = QEMU_PLUGIN_VERSION;

static uint64_t insns;        /* instructions of every block entered so far */
static uint64_t mark_addr[2]; /* begin, end (Thumb bit cleared) */
static int have_mark[2];
static char *out_path;

typedef struct {
    uint64_t begin, end; /* counter snapshots; end == 0: no end mark seen */
} frame_rec;
static frame_rec *frames;
static size_t nframes, capframes;

/* profile= : each translated block's instruction addresses and its runs in frames */
typedef struct prof_tb {
    struct prof_tb *next;
    uint64_t runs;
    size_t n;
    uint32_t pc[];
} prof_tb;
static char *prof_path;
static prof_tb *prof_list;
static int in_frame;

static void on_mark(unsigned int vcpu, void *udata)
{
    (void)vcpu;
    uintptr_t u = (uintptr_t)udata;
    int which = (int)(u & 1);
    uint64_t now = insns - (uint64_t)(u >> 1); /* minus the rest of this block */
    if (which == 0) {
        if (nframes == capframes) {
            size_t cap = capframes ? capframes * 2 : 1024;
            frame_rec *f = realloc(frames, cap * sizeof *f);
            if (!f) return;
            frames = f;
            capframes = cap;
        }
        frames[nframes].begin = now;
        frames[nframes].end = 0;
        nframes++;
        in_frame = 1;
    } else if (nframes > 0 && frames[nframes - 1].end == 0) {
        frames[nframes - 1].end = now;
        in_frame = 0;
    }
}

static void on_tb_exec(unsigned int vcpu, void *udata)
{
    (void)vcpu;
    if (in_frame) ((prof_tb *)udata)->runs++;
}

/* A record of the block's instruction addresses, whose runs on_tb_exec counts. */
static void profile_tb(struct qemu_plugin_tb *tb, size_t n)
{
    prof_tb *p = malloc(sizeof *p + n * sizeof p->pc[0]);
    if (!p) return;
    p->runs = 0;
    p->n = n;
    for (size_t i = 0; i < n; i++) p->pc[i] = (uint32_t)qemu_plugin_insn_vaddr(qemu_plugin_tb_get_insn(tb, i));
    p->next = prof_list;
    prof_list = p;
    qemu_plugin_register_vcpu_tb_exec_cb(tb, on_tb_exec, QEMU_PLUGIN_CB_NO_REGS, p);
}

static void write_profile(void)
{
    FILE *f = fopen(prof_path, "w");
    if (!f) {
        char msg[512];
        snprintf(msg, sizeof msg, "insn_count: %s: cannot write: %s\n", prof_path, strerror(errno));
        qemu_plugin_outs(msg);
    } else {
        fprintf(f, "# insn_count profile: guest instruction address, runs inside frames (%zu frames)\n", nframes);
        for (prof_tb *p = prof_list; p; p = p->next)
            for (size_t i = 0; p->runs && i < p->n; i++)
                fprintf(f, "%#x %llu\n", (unsigned)p->pc[i], (unsigned long long)p->runs);
        fclose(f);
    }
    while (prof_list) {
        prof_tb *p = prof_list;
        prof_list = p->next;
        free(p);
    }
    free(prof_path);
}

static void on_tb_trans(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    size_t n = qemu_plugin_tb_n_insns(tb);
    qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &insns, n);
    if (prof_path) profile_tb(tb, n);
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        uint64_t pc = qemu_plugin_insn_vaddr(insn) & ~(uint64_t)1;
        for (int w = 0; w < 2; w++) {
            if (have_mark[w] && pc == mark_addr[w]) {
                uintptr_t u = ((uintptr_t)(n - i) << 1) | (uintptr_t)w;
                qemu_plugin_register_vcpu_insn_exec_cb(insn, on_mark, QEMU_PLUGIN_CB_NO_REGS, (void *)u);
            }
        }
    }
}

static void report_at_exit(qemu_plugin_id_t id, void *udata)
{
    (void)id;
    (void)udata;
    FILE *f = NULL;
    if (out_path) {
        f = fopen(out_path, "w");
        if (!f) {
            char msg[512];
            snprintf(msg, sizeof msg, "insn_count: %s: cannot write: %s\n", out_path, strerror(errno));
            qemu_plugin_outs(msg);
        }
    }
    /* Build the report in memory, so it can go to QEMU's log too. */
    size_t cap = 256 + nframes * 64, len = 0;
    char *buf = malloc(cap);
    if (!buf) return;
    len += (size_t)snprintf(buf + len, cap - len,
                            "# insn_count: guest instructions per frame (QEMU TCG plugin)\n"
                            "# frame render_insns total_insns\n");
    for (size_t i = 0; i < nframes; i++) {
        uint64_t next = i + 1 < nframes ? frames[i + 1].begin : insns;
        uint64_t render = frames[i].end ? frames[i].end - frames[i].begin : 0;
        len += (size_t)snprintf(buf + len, cap - len, "%zu %llu %llu\n", i, (unsigned long long)render,
                                (unsigned long long)(next - frames[i].begin));
    }
    len += (size_t)snprintf(buf + len, cap - len, "# frames %zu, instructions executed %llu\n", nframes,
                            (unsigned long long)insns);
    if (f) {
        fwrite(buf, 1, len, f);
        fclose(f);
    } else {
        qemu_plugin_outs(buf);
    }
    free(buf);
    free(frames);
    free(out_path);
    if (prof_path) write_profile();
}

static int parse_addr(const char *s, uint64_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 0);
    if (errno || end == s || *end) return -1;
    *out = v & ~1ull;
    return 0;
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv)
{
    (void)info;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (!strncmp(a, "begin=", 6)) {
            if (parse_addr(a + 6, &mark_addr[0])) goto bad;
            have_mark[0] = 1;
        } else if (!strncmp(a, "end=", 4)) {
            if (parse_addr(a + 4, &mark_addr[1])) goto bad;
            have_mark[1] = 1;
        } else if (!strncmp(a, "out=", 4)) {
            free(out_path);
            out_path = strdup(a + 4);
        } else if (!strncmp(a, "profile=", 8)) {
            free(prof_path);
            prof_path = strdup(a + 8);
        } else {
            goto bad;
        }
        continue;
    bad:
        fprintf(stderr, "insn_count: bad argument '%s' (expected begin=ADDR, end=ADDR, out=FILE, profile=FILE)\n", a);
        return -1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_tb_trans);
    qemu_plugin_register_atexit_cb(id, report_at_exit, NULL);
    return 0;
}
