/* tick.c - SysTick millisecond tick (see tick.h). */
#include "tick.h"

#include "mps2.h"

#define SYST_CSR MPS2_REG(0xE000E010u)
#define SYST_RVR MPS2_REG(0xE000E014u)
#define SYST_CVR MPS2_REG(0xE000E018u)
#define CSR_ENABLE (1u << 0)
#define CSR_TICKINT (1u << 1)
#define CSR_CLKSOURCE_CPU (1u << 2)

static volatile uint32_t ms;

void tick_init(void)
{
    SYST_CSR = 0;
    ms = 0;
    SYST_RVR = MPS2_SYSCLK_HZ / 1000u - 1u;
    SYST_CVR = 0;
    SYST_CSR = CSR_ENABLE | CSR_TICKINT | CSR_CLKSOURCE_CPU;
}

void tick_stop(void)
{
    SYST_CSR = 0;
}

uint32_t tick_ms(void)
{
    return ms;
}

void systick_irq(void)
{
    ms++;
}
