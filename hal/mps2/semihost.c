/* semihost.c - Arm semihosting calls (see semihost.h). */
#include "semihost.h"

#define SYS_WRITE0 0x04u
#define SYS_GET_CMDLINE 0x15u
#define SYS_EXIT 0x18u
#define SYS_EXIT_EXTENDED 0x20u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u

static uint32_t sh_call(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void sh_exit(uint32_t status)
{
    uint32_t block[2] = {ADP_STOPPED_APPLICATION_EXIT, status};
    sh_call(SYS_EXIT_EXTENDED, block);
    /* A host without SYS_EXIT_EXTENDED: plain SYS_EXIT still tells success
     * from failure (the reason is the argument itself on AArch32). */
    sh_call(SYS_EXIT, (const void *)(uintptr_t)(status == 0 ? ADP_STOPPED_APPLICATION_EXIT : 0x20023u));
    for (;;) __asm__ volatile("wfi");
}

void sh_write0(const char *s)
{
    sh_call(SYS_WRITE0, s);
}

int sh_get_cmdline(char *buf, uint32_t size)
{
    uint32_t block[2] = {(uint32_t)(uintptr_t)buf, size};
    if (size == 0) return -1;
    buf[0] = '\0';
    if (sh_call(SYS_GET_CMDLINE, block) != 0) return -1;
    buf[size - 1] = '\0';
    return 0;
}
