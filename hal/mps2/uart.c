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
/* the received byte, DATA[7:0], read as a byte: no masking needed */
#define UART_DATA_BYTE (*(volatile uint8_t *)(uintptr_t)UART0_BASE)

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

#define NVIC_ISPR0 MPS2_REG(0xE000E200u) /* write 1s: set pending */

#define RX_RING UART_RX_RING
#define RX_HALF (RX_RING / 2u)
#define RX_MARKS 32u /* UART_RX_SPANS: delimiter positions kept; more in the ring are found by a scan */
#if RX_RING < 16u || (RX_RING & (RX_RING - 1u))
#error "UART_RX_RING must be a power of two, at least 16"
#endif

/* The receive ring. The interrupt writes head (and with UART_RX_SPANS marks,
 * mark[], wake_at and wake); the main loop writes tail and limit; held is set
 * by the one and cleared by the other, each while the receive interrupt cannot
 * run (see rx_resume). One struct, so that the handler reaches every field
 * from one base address. */
static struct {
    volatile uint32_t head;    /* bytes put in the ring, ever */
    volatile uint32_t limit;   /* tail + RX_RING: head when the ring is full */
    volatile uint32_t tail;    /* bytes taken out of it, ever */
    volatile uint32_t held;    /* the ring was full: a byte waits in the data register */
    volatile uint32_t dropped; /* bytes the UART lost (overrun) */
#if UART_RX_SPANS
    volatile uint32_t marks;          /* delimiters (UART_RX_MATCH) received, ever */
    volatile uint32_t wake_at;        /* the byte (a head) that wakes the main loop */
    volatile uint32_t wake;           /* set by the handler: uart_rx_wait returns */
    volatile uint32_t mark[RX_MARKS]; /* mark[k % RX_MARKS]: head just after delimiter k */
#endif
    volatile uint8_t ring[RX_RING];
} rx;

#if UART_RX_SPANS
/* The main loop's side: delimiters taken, and where the span handed out ends. */
static uint32_t marks_taken, span_end;
static uint8_t span_marked; /* the span handed out ends with a delimiter */
#endif

void uart_init(void)
{
    UART_CTRL = 0;
    UART_BAUDDIV = MPS2_SYSCLK_HZ / UART_BAUD;        /* 217; the UART needs >= 16 */
    UART_STATE = STATE_TX_OVERRUN | STATE_RX_OVERRUN; /* write 1 to clear */
    UART_INTSTATUS = 0xFu;
    uint8_t *p = (uint8_t *)&rx;
    for (uint32_t i = 0; i < sizeof rx; i++) p[i] = 0;
    rx.limit = RX_RING;
#if UART_RX_SPANS
    marks_taken = span_end = 0;
    span_marked = 0;
#endif
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

/* A receive overrun: the UART lost a byte (never under QEMU, whose UART takes
 * no byte while one waits in the data register). */
__attribute__((noinline)) static void rx_overrun(void)
{
    rx.dropped++;
    UART_STATE = STATE_RX_OVERRUN;
}

/* The receive interrupt: the byte in the data register into the ring, with no
 * call and nothing else done per byte than a test for a full ring (and with
 * UART_RX_SPANS two more: a delimiter, whose position is noted; a reason to
 * wake the main loop). What DMA does on a real part (hal/board/README.md).
 * The CMSDK UART holds one byte, and it is acknowledged before the byte is
 * read, so one that lands after the read raises the interrupt again: one byte
 * per interrupt. */
void uart0_rx_irq(void)
{
    /* Acknowledged after the read instead, the next byte could sit in the data
     * register with no interrupt pending, and the UART deliver nothing more. */
    UART_INTSTATUS = INT_RX | INT_RX_OVERRUN;
    uint32_t state = UART_STATE;
    if (state & STATE_RX_OVERRUN) rx_overrun();
    if (!(state & STATE_RX_FULL)) return;
    uint32_t head = rx.head;
    if (head == rx.limit) {
        /* full: the byte stays in the data register and the interrupt off, so
         * the sender is held back (QEMU takes no more from its backend; a real
         * part would drop RTS) until uart_rx_done or uart_getc makes room */
        UART_CTRL &= ~CTRL_RX_INT_EN;
        rx.held = 1;
        return;
    }
    uint8_t c = UART_DATA_BYTE;
    rx.ring[head % RX_RING] = c;
    rx.head = head + 1u;
#if UART_RX_SPANS
    if (c == UART_RX_MATCH) {
        /* a message ends: note where (a character match), wake the main loop,
         * and again at the next message's first byte */
        uint32_t k = rx.marks;
        rx.mark[k % RX_MARKS] = head + 1u;
        rx.marks = k + 1u;
        rx.wake_at = head + 1u;
        rx.wake = 1;
    } else if (head == rx.wake_at) {
        /* a message's first byte, or the last of a half ring: wake the main
         * loop, and again when the next half of the ring is filled */
        rx.wake_at = (head + 1u) | (RX_HALF - 1u);
        rx.wake = 1;
    }
#endif
}

/* The ring was full and has room again: the byte waiting in the data register
 * raised its interrupt long ago, so pend the handler by hand to take it. The
 * receive interrupt is off while held is set, so nothing races this. */
static void rx_resume(void)
{
    rx.held = 0;
    UART_CTRL |= CTRL_RX_INT_EN;
    NVIC_ISPR0 = 1u << MPS2_IRQ_UART0_RX;
}

int uart_getc(void)
{
    uint32_t tail = rx.tail;
    if (tail == rx.head) return -1;
    uint8_t c = rx.ring[tail % RX_RING];
#if UART_RX_SPANS
    if (c == UART_RX_MATCH) marks_taken++;
#endif
    rx.tail = tail + 1;
    rx.limit = tail + 1 + RX_RING;
    if (rx.held) rx_resume();
    return c;
}

int uart_rx_ready(void)
{
    return rx.tail != rx.head;
}

#if UART_RX_SPANS
void uart_rx_wait(void)
{
    /* with interrupts masked across the test, a byte that comes just before the
     * WFI still wakes it (a pending interrupt ends WFI even while masked) */
    __asm__ volatile("cpsid i" ::: "memory");
    while (!rx.wake) __asm__ volatile("wfi\n\tcpsie i\n\tisb\n\tcpsid i" ::: "memory");
    rx.wake = 0;
    __asm__ volatile("cpsie i" ::: "memory");
}

uint32_t uart_rx_span(const uint8_t **p, int *ends_message)
{
    uint32_t tail = rx.tail;
    uint32_t marks = rx.marks; /* before head: every delimiter counted lies below it */
    uint32_t head = rx.head;
    uint32_t end = head;
    span_marked = 0;
    if (marks != marks_taken) {
        uint32_t m = rx.mark[marks_taken % RX_MARKS];
        if (rx.marks - marks_taken <= RX_MARKS) {
            end = m; /* still the position of delimiter marks_taken: not written over */
            span_marked = 1;
        } else {
            /* more delimiters came than the list keeps: look for the next one */
            for (uint32_t i = tail; i != head; i++)
                if (rx.ring[i % RX_RING] == UART_RX_MATCH) {
                    end = i + 1u;
                    span_marked = 1;
                    break;
                }
        }
    }
    uint32_t off = tail % RX_RING;
    if (end - tail > RX_RING - off) { /* contiguous: up to the ring's end */
        end = tail + (RX_RING - off);
        span_marked = 0;
    }
    span_end = end;
    *p = (const uint8_t *)&rx.ring[off];
    *ends_message = span_marked;
    return end - tail;
}

void uart_rx_done(uint32_t n)
{
    uint32_t tail = rx.tail + n;
    rx.tail = tail;
    rx.limit = tail + RX_RING;
    if (span_marked && tail == span_end) {
        marks_taken++;
        span_marked = 0;
    }
    if (rx.held) rx_resume();
}
#endif

uint32_t uart_rx_overruns(void)
{
    return rx.dropped;
}
