/* flbench_m3.c - the frame-link encoder on the Cortex-M3 (QEMU mps2-an385), for
 * instruction counts: a bare-metal image with frames built in (frames.c, made by
 * tools/bin2c from a raw file of 64,000-byte frames) that sends each frame as
 * the firmware would (fl_enc_frame: a keyframe, then deltas against the frame
 * before, keyframes every 64; COBS, header and message CRC included; no pixel
 * CRC, info.no_crc set), with the two marker functions the instruction-counting
 * plugin watches (tools/qemu_plugin/insn_count.c) around each call, then the
 * same around crc_update of each frame (what a sender pays to fill info.crc),
 * and exits through semihosting. The plugin's output has one line per marked
 * region: frames 0..N-1 are the encoder, N..2N-1 the CRC. At the end the image
 * prints the stream's length and CRC-32 on the semihosting console, which must
 * equal `fltool digest` on the host for the same frames. Run by
 * tools/bench_link.py (make bench-link) and tests/test_framelink.py. */
#include <stdint.h>

#include "crc32.h"
#include "framelink.h"

extern const uint8_t fl_frames[];
extern const uint32_t fl_frames_len;
extern uint32_t __bss_start[], __bss_end[], __stack_top[];

volatile uint32_t fl_mark, fl_mark_done, fl_sink;

__attribute__((noinline, noipa, used)) void fl_mark_begin(uint32_t k)
{
    fl_mark = k;
}

__attribute__((noinline, noipa, used)) void fl_mark_end(uint32_t k)
{
    fl_mark_done = k + 1u;
}

static uint32_t sh_call(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static fl_encoder enc;
static _Alignas(4) uint8_t scratch[8192];
static uint32_t sent_bytes, sent_crc;

/* In the measured pass the bytes are only counted (a UART's cost is not the
 * encoder's); a second pass, unmeasured, digests the same stream. */
static void put_count(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)ctx;
    (void)p;
    sent_bytes += n;
}

static void put(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)ctx;
    sent_crc = crc_update(sent_crc, p, n);
}

static void put_hex(char *p, uint32_t v)
{
    for (int i = 7; i >= 0; i--, v >>= 4) p[i] = "0123456789abcdef"[v & 15u];
}

__attribute__((noreturn)) void reset_handler(void)
{
    for (uint32_t *p = __bss_start; p < __bss_end; p++) *p = 0;
    uint32_t n = fl_frames_len / FL_FRAME_BYTES;
    fl_enc_init(&enc, put_count, 0, scratch, sizeof scratch);
    static fl_frame_info info; /* zero camera */
    info.no_crc = 1;
    for (uint32_t k = 0; k < n; k++) {
        const uint8_t *px = fl_frames + k * FL_FRAME_BYTES;
        fl_mark_begin(k);
        fl_enc_frame(&enc, k, px, k ? px - FL_FRAME_BYTES : 0, k - 1, &info);
        fl_mark_end(k);
    }
    uint32_t counted = sent_bytes;
    sent_bytes = 0;
    fl_enc_init(&enc, put, 0, scratch, sizeof scratch);
    for (uint32_t k = 0; k < n; k++) {
        const uint8_t *px = fl_frames + k * FL_FRAME_BYTES;
        fl_enc_frame(&enc, k, px, k ? px - FL_FRAME_BYTES : 0, k - 1, &info);
    }
    sent_bytes = enc.bytes == counted ? counted : 0; /* both passes sent as much */
    for (uint32_t k = 0; k < n; k++) {
        fl_mark_begin(n + k);
        fl_sink ^= crc_update(0, fl_frames + k * FL_FRAME_BYTES, FL_FRAME_BYTES);
        fl_mark_end(n + k);
    }
    /* what the host's `fltool digest` prints for the same frames */
    char line[] = "stream bytes ........ crc ........\n";
    put_hex(line + 13, sent_bytes);
    put_hex(line + 26, sent_crc);
    sh_call(0x04, line); /* SYS_WRITE0 */
    uint32_t block[2] = {0x20026u, 0};
    sh_call(0x20, block); /* SYS_EXIT_EXTENDED, status 0 */
    sh_call(0x18, (const void *)0x20026u);
    for (;;) {
    }
}

__attribute__((noreturn)) static void hang(void)
{
    uint32_t block[2] = {0x20026u, 3};
    sh_call(0x20, block);
    for (;;) {
    }
}

typedef void (*vector)(void);
__attribute__((section(".vectors"), used)) const vector fl_vectors[16] = {
    (vector)(uintptr_t)__stack_top, reset_handler, hang, hang, hang, hang, hang, 0, 0, 0, 0, hang, hang, 0, hang, hang,
};
