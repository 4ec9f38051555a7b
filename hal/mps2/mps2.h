/* mps2.h - the board: Arm's MPS2 with the AN385 FPGA image (a Cortex-M3), as
 * QEMU models it (qemu-system-arm -M mps2-an385; hw/arm/mps2.c; checked with
 * `info mtree` on QEMU 7.2). Memory map and the few core registers used here.
 *
 *   0x00000000 - 0x003FFFFF  SSRAM1, 4 MB    "ROM" (flash): vectors, code, constants, the
 *                                            scene (QEMU -kernel loads the ELF here; it
 *                                            is RAM in QEMU, treated as flash)
 *   0x20000000 - ...         SSRAM2/3        "RAM": the first MPS2_RAM_BYTES (default
 *                                            200,000) only: the stack, both VRAM pages,
 *                                            the palette, the display-start register,
 *                                            .data, .bss and the work area (mps2.ld)
 *   0x40004000  UART0 (CMSDK APB UART): the frame link
 *   0xE000E010  SysTick; 0xE000ED00 System Control Block
 *
 * QEMU maps nothing useful at the board's real VGA window (0x41000000: an
 * unimplemented-device stub), so the VRAM pages are plain RAM, exported by
 * the linker (mps2_vram0, ...) for a debugger or QEMU's monitor
 * (`xp /16xb ADDR` with the address from arm-none-eabi-nm).
 */
#ifndef MPS2_H
#define MPS2_H

#include <stdint.h>

/* System clock of the AN385 image in QEMU: 25 MHz (SYSCLK; the 1 MHz REFCLK is
 * the other SysTick source). */
#define MPS2_SYSCLK_HZ 25000000u

#define MPS2_REG(a) (*(volatile uint32_t *)(uintptr_t)(a))

/* System Control Block */
#define SCB_ICSR MPS2_REG(0xE000ED04u)
#define SCB_VTOR MPS2_REG(0xE000ED08u)
#define SCB_AIRCR MPS2_REG(0xE000ED0Cu)
#define SCB_CCR MPS2_REG(0xE000ED14u)
#define SCB_SHCSR MPS2_REG(0xE000ED24u)
#define SCB_CFSR MPS2_REG(0xE000ED28u)
#define SCB_HFSR MPS2_REG(0xE000ED2Cu)
#define SCB_MMFAR MPS2_REG(0xE000ED34u)
#define SCB_BFAR MPS2_REG(0xE000ED38u)
#define SCB_CCR_DIV_0_TRP (1u << 4)
#define SCB_SHCSR_MEMFAULTENA (1u << 16)
#define SCB_SHCSR_BUSFAULTENA (1u << 17)
#define SCB_SHCSR_USGFAULTENA (1u << 18)
#define SCB_HFSR_DEBUGEVT (1u << 31)

/* NVIC */
#define NVIC_ISER0 MPS2_REG(0xE000E100u)

/* Interrupt numbers of the AN385 image (QEMU's hw/arm/mps2.c) */
#define MPS2_IRQ_UART0_RX 0
#define MPS2_IRQ_UART0_TX 1

/* Linker-script symbols (mps2.ld) */
extern uint8_t mps2_vram0[], mps2_vram1[], mps2_palette[];
extern volatile uint32_t mps2_display_start;
extern uint8_t __work_start[], __work_end[];
extern uint32_t __stack_limit[], __stack_top[];

/* Stack bytes never touched since reset (startup.c paints the stack). */
uint32_t mps2_stack_unused(void);

#endif
