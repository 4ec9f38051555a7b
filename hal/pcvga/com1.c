/* com1.c - COM1 by polling (see com1.h). */
#include "com1.h"

#include "io.h"

#define COM1 0x3F8
#define REG_DATA 0 /* THR / RBR; divisor low with DLAB */
#define REG_IER 1  /* interrupt enable; divisor high with DLAB */
#define REG_FCR 2
#define REG_LCR 3
#define REG_MCR 4
#define REG_LSR 5
#define LSR_DATA_READY 0x01u
#define LSR_THR_EMPTY 0x20u
#define LCR_8N1 0x03u
#define LCR_DLAB 0x80u
#define BAUD_DIVISOR 1u /* 115,200 = 1,843,200 / 16 / 1 */

void com1_init(void)
{
    io_out8(COM1 + REG_IER, 0x00); /* polled: no interrupts */
    io_out8(COM1 + REG_LCR, LCR_DLAB);
    io_out8(COM1 + REG_DATA, BAUD_DIVISOR & 0xFFu);
    io_out8(COM1 + REG_IER, BAUD_DIVISOR >> 8);
    io_out8(COM1 + REG_LCR, LCR_8N1);
    io_out8(COM1 + REG_FCR, 0xC7); /* FIFOs on and cleared */
    io_out8(COM1 + REG_MCR, 0x03); /* DTR, RTS */
}

void com1_putc(char c)
{
    while (!(io_in8(COM1 + REG_LSR) & LSR_THR_EMPTY)) {
    }
    io_out8(COM1 + REG_DATA, (uint8_t)c);
}

void com1_puts(const char *s)
{
    for (; *s; s++) {
        if (*s == '\n') com1_putc('\r');
        com1_putc(*s);
    }
}

int com1_getc(void)
{
    if (!(io_in8(COM1 + REG_LSR) & LSR_DATA_READY)) return -1;
    return io_in8(COM1 + REG_DATA);
}
