/* uart.h - UART0 of the MPS2 AN385 (CMSDK APB UART at 0x40004000), the frame
 * link's wire (prefix uart_).
 *
 * Transmit: polled. Each byte waits until the one-byte TX buffer is free (the
 * TX-full flag clears), so the driver never overruns the transmitter; under
 * QEMU the flag stays set while the character backend cannot take the byte, so
 * a slow reader slows the firmware down instead of losing data (except on a
 * pty with no reader: QEMU drops those bytes - see hal/mps2/README.md).
 * Receive: interrupt-driven into a 256-byte ring, so acks and keyframe requests
 * from the receiver are kept while the firmware renders. A full ring holds the
 * sender back (the byte stays in the data register, the RX interrupt off, until
 * uart_getc makes room) rather than losing bytes: the display board (hal/board)
 * receives whole frames through it while it decodes. uart_rx_overruns() counts
 * bytes the hardware lost. The link protocol's ack window is
 * the flow control above this (hal/mps2/stream.c).
 */
#ifndef MPS2_UART_H
#define MPS2_UART_H

#include <stddef.h>
#include <stdint.h>

#define UART_BAUD 115200u /* what BAUDDIV is set for; QEMU sends as fast as its backend takes bytes */

void uart_init(void);
void uart_putc(uint8_t c);
void uart_write(const void *p, size_t n);
void uart_puts(const char *s);   /* text, '\n' sent as "\r\n" */
void uart_flush(void);           /* wait until the last byte has left the TX buffer */
int uart_getc(void);             /* next received byte, or -1 if none is waiting */
int uart_rx_ready(void);         /* 1 if a received byte is waiting */
uint32_t uart_rx_overruns(void); /* received bytes the hardware dropped (overrun) */

/* The RX interrupt handler (vector table, startup.c). */
void uart0_rx_irq(void);

#endif
