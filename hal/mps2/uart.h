/* uart.h - UART0 of the MPS2 AN385 (CMSDK APB UART at 0x40004000), the frame
 * link's wire (prefix uart_).
 *
 * Transmit: polled. Each byte waits until the one-byte TX buffer is free (the
 * TX-full flag clears), so the driver never overruns the transmitter; under
 * QEMU the flag stays set while the character backend cannot take the byte, so
 * a slow reader slows the firmware down instead of losing data (except on a
 * pty with no reader: QEMU drops those bytes - see hal/mps2/README.md).
 * Receive: interrupt-driven into a ring (UART_RX_RING bytes, 256 unless the
 * build says otherwise; the display board's is larger). The handler only stores
 * bytes. The main loop takes them one at a time (uart_getc: acks and keyframe
 * requests while the firmware renders), or, in a build with UART_RX_SPANS = 1
 * (the display board, hal/board), where the handler also notes where each
 * delimiter (UART_RX_MATCH, the frame link's 0x00) lands, it sleeps in
 * uart_rx_wait and takes contiguous spans of the ring in place (uart_rx_span /
 * uart_rx_done), each ending at a delimiter, the ring's end, or what has come,
 * and hands them straight to the decoder. uart_rx_wait returns when a
 * message's first byte or its delimiter has come or a half of the ring has
 * filled. A full ring holds the sender back (the byte stays in the data register, the RX
 * interrupt off, until uart_rx_done or uart_getc makes room) rather than
 * losing bytes. uart_rx_overruns() counts bytes the hardware lost. The link
 * protocol's ack window is the flow control above this (hal/mps2/stream.c).
 */
#ifndef MPS2_UART_H
#define MPS2_UART_H

#include <stddef.h>
#include <stdint.h>

#ifndef UART_RX_RING
#define UART_RX_RING 256u /* receive ring bytes, a power of two */
#endif
#ifndef UART_RX_SPANS
#define UART_RX_SPANS 0 /* 1: uart_rx_wait, uart_rx_span, uart_rx_done (about 150 bytes more RAM) */
#endif
#define UART_RX_MATCH 0x00u /* the byte whose positions the receiver notes: the frame link's delimiter */

#define UART_BAUD 115200u /* what BAUDDIV is set for; QEMU sends as fast as its backend takes bytes */

void uart_init(void);
void uart_putc(uint8_t c);
void uart_write(const void *p, size_t n);
void uart_puts(const char *s);   /* text, '\n' sent as "\r\n" */
void uart_flush(void);           /* wait until the last byte has left the TX buffer */
int uart_getc(void);             /* next received byte, or -1 if none is waiting */
int uart_rx_ready(void);         /* 1 if a received byte is waiting */
uint32_t uart_rx_overruns(void); /* received bytes the hardware dropped (overrun) */

/* UART_RX_SPANS builds only. Sleep (WFI) until the receiver has something for the main loop: a message's
 * first byte, a delimiter, or half a ring of bytes. Returns at once if that
 * happened since the last call. */
void uart_rx_wait(void);
/* The received bytes not taken yet that lie contiguously in the ring, from the
 * oldest, ending at the first delimiter among them (*ends_message = 1), or at
 * the ring's end or at the last byte received (*ends_message = 0). *p points
 * into the ring: the bytes stay put until uart_rx_done. Returns their count, 0
 * if none. */
uint32_t uart_rx_span(const uint8_t **p, int *ends_message);
/* The first n bytes of the span uart_rx_span gave are done with: the ring may
 * take new bytes in their place. */
void uart_rx_done(uint32_t n);

/* The RX interrupt handler (vector table, startup.c). */
void uart0_rx_irq(void);

#endif
