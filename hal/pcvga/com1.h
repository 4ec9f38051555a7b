/* com1.h - the PC's first serial port (prefix com1_), a 16550 UART at I/O port
 * 0x3F8: 115,200 baud 8N1, by polling. The kernel's log goes out here; a byte
 * coming in is what --wait waits for. Under QEMU, -serial chooses where it
 * goes (stdio, a file, a socket). */
#ifndef PCVGA_COM1_H
#define PCVGA_COM1_H

void com1_init(void);
void com1_putc(char c);        /* waits while the transmitter is full */
void com1_puts(const char *s); /* "\n" goes out as "\r\n", for terminals */
int com1_getc(void);           /* a received byte, or -1 if none has arrived */

#endif
