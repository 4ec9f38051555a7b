/* uart.c - CMSDK APB UART driver for UART0 (see uart.h). Registers as in Arm's
 * Cortex-M System Design Kit TRM and QEMU's hw/char/cmsdk-apb-uart.c. */
#include "uart.h"

#include "mps2.h"

#define UART0_BASE 0x40004000u
#define UART_DATA MPS2_REG(UART0_BASE + 0x000u)
#define UART_STATE MPS2_REG(UART0_BASE + 0x004u)
#define UART_CTRL MPS2_REG(UART0_BASE + 0x008u)
#define UART_INTSTATUS MPS2_REG(UART0_BASE + 0x00Cu) /* write 1s to clear */
#define UART_BAUDDIV MPS2_REG(UART0_BASE + 0x010u)

#define STATE_TX_FULL (1u << 0)
#define STATE_RX_FULL (1u << 1)
#define STATE_TX_OVERRUN (1u << 2)
#define STATE_RX_OVERRUN (1u << 3)
#define CTRL_TX_EN (1u << 0)
#define CTRL_RX_EN (1u << 1)
#define CTRL_RX_INT_EN (1u << 3)
#define CTRL_RX_OVR_INT_EN (1u << 5)
#define INT_RX (1u << 1)
#define INT_RX_OVERRUN (1u << 3)

#define RX_RING 256u /* power of two */

static volatile uint8_t rx_ring[RX_RING];
static volatile uint32_t rx_head, rx_tail; /* head: written by the IRQ; tail: by uart_getc */
static volatile uint32_t rx_dropped;
static volatile uint8_t rx_held; /* a byte waits in the data register: the ring was full */

void uart_init(void)
{
    UART_CTRL = 0;
    UART_BAUDDIV = MPS2_SYSCLK_HZ / UART_BAUD;        /* 217; the UART needs >= 16 */
    UART_STATE = STATE_TX_OVERRUN | STATE_RX_OVERRUN; /* write 1 to clear */
    UART_INTSTATUS = 0xFu;
    rx_head = rx_tail = 0;
    rx_dropped = 0;
    rx_held = 0;
    UART_CTRL = CTRL_TX_EN | CTRL_RX_EN | CTRL_RX_INT_EN | CTRL_RX_OVR_INT_EN;
    NVIC_ISER0 = 1u << MPS2_IRQ_UART0_RX;
}

void uart_putc(uint8_t c)
{
    while (UART_STATE & STATE_TX_FULL) {
    }
    UART_DATA = c;
}

void uart_write(const void *p, size_t n)
{
    const uint8_t *b = p;
    for (size_t i = 0; i < n; i++) uart_putc(b[i]);
}

void uart_puts(const char *s)
{
    for (; *s; s++) {
        if (*s == '\n') uart_putc('\r');
        uart_putc((uint8_t)*s);
    }
}

void uart_flush(void)
{
    while (UART_STATE & STATE_TX_FULL) {
    }
}

/* Move received bytes from the data register into the ring while it has room.
 * Returns 1 if a byte is left in the register because the ring is full. */
static int rx_drain(void)
{
    while (UART_STATE & STATE_RX_FULL) {
        uint32_t head = rx_head;
        if (head - rx_tail >= RX_RING) return 1;
        rx_ring[head % RX_RING] = (uint8_t)UART_DATA;
        rx_head = head + 1;
    }
    return 0;
}

/* The ring was full: a byte waits in the data register with the RX interrupt
 * off, so the sender is held back instead of losing bytes (QEMU takes no more
 * from its backend while the register is full). Called with room in the ring. */
static void rx_resume(void)
{
    __asm__ volatile("cpsid i" ::: "memory");
    if (!rx_drain()) {
        rx_held = 0;
        UART_CTRL |= CTRL_RX_INT_EN;
        /* a byte that came between the drain and the enable raised no interrupt */
        if (rx_drain()) {
            UART_CTRL &= ~CTRL_RX_INT_EN;
            rx_held = 1;
        }
    }
    __asm__ volatile("cpsie i" ::: "memory");
}

int uart_getc(void)
{
    uint32_t tail = rx_tail;
    if (tail == rx_head) return -1;
    uint8_t c = rx_ring[tail % RX_RING];
    rx_tail = tail + 1;
    if (rx_held) rx_resume();
    return c;
}

int uart_rx_ready(void)
{
    return rx_tail != rx_head;
}

uint32_t uart_rx_overruns(void)
{
    return rx_dropped;
}

void uart0_rx_irq(void)
{
    /* Acknowledge before draining: a byte that lands after the drain then raises
     * the interrupt again. Acknowledged after, it would sit in the data register
     * with no interrupt pending, and the UART delivers nothing more. */
    UART_INTSTATUS = INT_RX | INT_RX_OVERRUN;
    if (UART_STATE & STATE_RX_OVERRUN) {
        rx_dropped++;
        UART_STATE = STATE_RX_OVERRUN;
    }
    if (rx_drain()) {
        UART_CTRL &= ~CTRL_RX_INT_EN;
        rx_held = 1;
    }
}
