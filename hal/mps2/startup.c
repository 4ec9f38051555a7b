/* startup.c - vector table, reset handler and fault handlers of the Cortex-M3
 * firmware (hal/mps2).
 *
 * Reset: copy .data from its load address in ROM, zero .bss, paint the stack
 * (so mps2_stack_unused() can tell the high-water mark), trap divide-by-zero,
 * enable the MemManage, BusFault and UsageFault handlers, call main(), and end
 * the program with main's return value as the semihosting exit status.
 *
 * Faults: every fault handler reports the fault over the UART (and the
 * semihosting console) - which fault, the stacked pc, lr and xPSR, and the
 * fault status registers - and exits with status FW_EXIT_FAULT (3). A BKPT
 * that reaches the HardFault handler means semihosting is not enabled: that
 * is said on the UART, and the core halts (there is no way to exit without it).
 */
#include <stdint.h>

#include "log.h"
#include "mps2.h"
#include "semihost.h"
#include "tick.h"
#include "uart.h"

#define FW_EXIT_FAULT 3u
#define STACK_PAINT 0xA5A5A5A5u

extern uint32_t __data_load[], __data_start[], __data_end[], __bss_start[], __bss_end[];
int main(void);

void reset_handler(void);
void default_handler(void);
void fault_handler(void);

__attribute__((noreturn, used)) void fault_report(const uint32_t *frame, uint32_t ipsr);

/* ---- vector table (placed at 0x00000000 by mps2.ld) --------------------- */
typedef void (*vector)(void);

__attribute__((section(".vectors"), used)) const vector mps2_vectors[16 + 32] = {
    (vector)(uintptr_t)__stack_top,
    reset_handler,
    fault_handler, /* NMI */
    fault_handler, /* HardFault */
    fault_handler, /* MemManage */
    fault_handler, /* BusFault */
    fault_handler, /* UsageFault */
    0,
    0,
    0,
    0,
    default_handler, /* SVCall */
    default_handler, /* DebugMonitor */
    0,
    default_handler, /* PendSV */
    systick_irq,     /* SysTick */
    /* external interrupts of the AN385 image */
    [16 + MPS2_IRQ_UART0_RX] = uart0_rx_irq,
    [16 + MPS2_IRQ_UART0_TX] = default_handler,
    [16 + 2 ... 16 + 31] = default_handler,
};

/* ---- reset -------------------------------------------------------------- */
void reset_handler(void)
{
    for (uint32_t *s = __data_load, *d = __data_start; d < __data_end;) *d++ = *s++;
    for (volatile uint32_t *d = __bss_start; d < __bss_end;) *d++ = 0;
    uint32_t sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (volatile uint32_t *p = __stack_limit; (uintptr_t)p < sp - 64u;) *p++ = STACK_PAINT;

    SCB_VTOR = (uint32_t)(uintptr_t)mps2_vectors;
    SCB_CCR |= SCB_CCR_DIV_0_TRP;
    SCB_SHCSR |= SCB_SHCSR_MEMFAULTENA | SCB_SHCSR_BUSFAULTENA | SCB_SHCSR_USGFAULTENA;
    __asm__ volatile("dsb\n isb" ::: "memory");

    int rc = main();
    uart_flush();
    sh_exit((uint32_t)rc);
}

uint32_t mps2_stack_unused(void)
{
    const uint32_t *p = __stack_limit;
    while (p < __stack_top && *p == STACK_PAINT) p++;
    return (uint32_t)((uintptr_t)p - (uintptr_t)__stack_limit);
}

/* ---- faults ------------------------------------------------------------- */
/* Pass the exception frame (on whichever stack was in use) and IPSR to C. */
__attribute__((naked)) void fault_handler(void)
{
    __asm__ volatile("tst lr, #4\n"
                     "ite eq\n"
                     "mrseq r0, msp\n"
                     "mrsne r0, psp\n"
                     "mrs r1, ipsr\n"
                     "b fault_report\n");
}

static const char *fault_name(uint32_t exc)
{
    switch (exc) {
    case 2: return "NMI";
    case 3: return "HardFault";
    case 4: return "MemManage fault";
    case 5: return "BusFault";
    case 6: return "UsageFault";
    default: return "unexpected exception";
    }
}

void fault_report(const uint32_t *frame, uint32_t ipsr)
{
    static int nested;
    uint32_t exc = ipsr & 0x1FFu, hfsr = SCB_HFSR;
    log_set_sinks(LOG_TO_UART);
    uart_init(); /* the fault may come before main set the UART up */
    if (nested++) {
        uart_puts("\nFAULT: a second fault while reporting one; halting\n");
        for (;;) __asm__ volatile("wfi");
    }
    if (exc == 3 && (hfsr & SCB_HFSR_DEBUGEVT)) {
        uart_puts("\nFAULT: BKPT without a debugger: semihosting is not enabled "
                  "(run QEMU with -semihosting-config enable=on,target=native); halting\n");
        for (;;) __asm__ volatile("wfi");
    }
    log_set_sinks(LOG_TO_UART | LOG_TO_SEMIHOST);
    uart_putc(0); /* ends any frame-link message cut short, so the text stands on its own */
    log_printf("\nFAULT: %s: pc=0x%08x lr=0x%08x xpsr=0x%08x sp=0x%08x\n", fault_name(exc), (unsigned)frame[6],
               (unsigned)frame[5], (unsigned)frame[7], (unsigned)(uintptr_t)frame);
    log_printf("FAULT: cfsr=0x%08x hfsr=0x%08x mmfar=0x%08x bfar=0x%08x\n", (unsigned)SCB_CFSR, (unsigned)hfsr,
               (unsigned)SCB_MMFAR, (unsigned)SCB_BFAR);
    uart_flush();
    sh_exit(FW_EXIT_FAULT);
}

void default_handler(void)
{
    uint32_t ipsr;
    __asm__ volatile("mrs %0, ipsr" : "=r"(ipsr));
    log_printf("\nFAULT: unexpected exception %u\n", (unsigned)(ipsr & 0x1FFu));
    uart_flush();
    sh_exit(FW_EXIT_FAULT);
}
