/* semihost.h - Arm semihosting (prefix sh_): the few calls the firmware makes to
 * the host that runs it (QEMU with -semihosting-config enable=on,target=native).
 * Each is a BKPT 0xAB with the operation in r0 and its argument in r1. Without
 * semihosting enabled the BKPT escalates to a HardFault (startup.c then says so
 * on the UART and halts). */
#ifndef SEMIHOST_H
#define SEMIHOST_H

#include <stdint.h>

/* End the program with an exit status: SYS_EXIT_EXTENDED (0x20) with reason
 * ADP_Stopped_ApplicationExit and the status as subcode, which QEMU turns into
 * its own exit status (plain SYS_EXIT on AArch32 can only say 0 or 1). */
__attribute__((noreturn)) void sh_exit(uint32_t status);

/* Write a NUL-terminated string to the host's console (SYS_WRITE0). */
void sh_write0(const char *s);

/* The command line the host passes (SYS_GET_CMDLINE: QEMU's -append, or the
 * arg= items of -semihosting-config), NUL-terminated in buf. Returns 0, or -1
 * if there is none or it does not fit. */
int sh_get_cmdline(char *buf, uint32_t size);

#endif
