/* trap.c - the IDT, the PICs, the PIT tick and the exception report (see trap.h). */
#include "trap.h"

#include "exit.h"
#include "io.h"
#include "log.h"

#define PIC1 0x20
#define PIC2 0xA0
#define PIC_EOI 0x20
#define IRQ_BASE 32
#define VEC_TIMER IRQ_BASE
#define VEC_SPURIOUS (IRQ_BASE + 7)
#define PIT_CH0 0x40
#define PIT_CMD 0x43
#define PIT_DIVISOR 1193u /* 1,193,182 Hz / 1,193 = 1,000.15 Hz */
#define CODE_SELECTOR 0x08
#define GATE_INTERRUPT 0x8E /* present, ring 0, 32-bit interrupt gate */
#define NSTUBS 34           /* exceptions 0..31, the timer, the spurious IRQ 7 */

typedef struct __attribute__((packed)) {
    uint16_t offset_lo, selector;
    uint8_t zero, type;
    uint16_t offset_hi;
} idt_gate;

typedef struct __attribute__((packed)) {
    uint16_t limit;
    uint32_t base;
} idt_desc;

extern const uint32_t trap_stubs[NSTUBS];
void trap_dispatch(struct trap_frame *f);

static idt_gate idt[IRQ_BASE + 16];
static volatile uint32_t ticks;

static const char *const exception_names[32] = {
    /* Intel's mnemonics */
    "#DE divide error",
    "#DB debug",
    "NMI",
    "#BP breakpoint",
    "#OF overflow",
    "#BR bound range",
    "#UD invalid opcode",
    "#NM no coprocessor",
    "#DF",
    "coprocessor segment overrun",
    "#TS invalid TSS",
    "#NP segment not present",
    "#SS stack fault",
    "#GP general protection",
    "#PF page fault",
    "reserved",
    "#MF x87 error",
    "#AC alignment check",
    "#MC machine check",
    "#XM SIMD error",
    "#VE virtualisation",
    "#CP control protection",
};

static void set_gate(int vec, uint32_t handler)
{
    idt[vec].offset_lo = (uint16_t)handler;
    idt[vec].selector = CODE_SELECTOR;
    idt[vec].zero = 0;
    idt[vec].type = GATE_INTERRUPT;
    idt[vec].offset_hi = (uint16_t)(handler >> 16);
}

/* Both PICs to vectors 32..47, edge-triggered, cascaded on IRQ 2; only IRQ 0 unmasked. */
static void pic_init(void)
{
    io_out8(PIC1, 0x11);
    io_out8(PIC2, 0x11);
    io_out8(PIC1 + 1, IRQ_BASE);
    io_out8(PIC2 + 1, IRQ_BASE + 8);
    io_out8(PIC1 + 1, 0x04);
    io_out8(PIC2 + 1, 0x02);
    io_out8(PIC1 + 1, 0x01);
    io_out8(PIC2 + 1, 0x01);
    io_out8(PIC1 + 1, 0xFE);
    io_out8(PIC2 + 1, 0xFF);
}

static void pit_init(void)
{
    io_out8(PIT_CMD, 0x34); /* channel 0, low then high byte, mode 2 (rate generator) */
    io_out8(PIT_CH0, PIT_DIVISOR & 0xFFu);
    io_out8(PIT_CH0, PIT_DIVISOR >> 8);
}

void trap_init(void)
{
    for (int v = 0; v < 32; v++) set_gate(v, trap_stubs[v]);
    set_gate(VEC_TIMER, trap_stubs[32]);
    set_gate(VEC_SPURIOUS, trap_stubs[33]);
    idt_desc d = {sizeof idt - 1, (uint32_t)(uintptr_t)idt};
    __asm__ volatile("lidt %0" : : "m"(d));
    pic_init();
    pit_init();
    __asm__ volatile("sti");
}

uint32_t trap_ticks(void)
{
    return ticks;
}

static __attribute__((noreturn)) void report_exception(const struct trap_frame *f)
{
    uint32_t cr2 = 0;
    if (f->vector == 14) __asm__ volatile("mov %%cr2, %0" : "=r"(cr2));
    const char *name = f->vector < 32 && exception_names[f->vector] ? exception_names[f->vector] : "exception";
    log_printf("pcvga: fault: %s (vector %u) at eip 0x%08x, error code 0x%x, cr2 0x%08x, eflags 0x%08x\n", name,
               (unsigned)f->vector, (unsigned)f->eip, (unsigned)f->error, (unsigned)cr2, (unsigned)f->eflags);
    pcvga_exit(PCVGA_EXIT_FAULT);
}

void trap_dispatch(struct trap_frame *f)
{
    if (f->vector == VEC_TIMER) {
        ticks++;
        io_out8(PIC1, PIC_EOI);
    } else if (f->vector == VEC_SPURIOUS) {
        /* not a real interrupt: no EOI */
    } else {
        report_exception(f);
    }
}
