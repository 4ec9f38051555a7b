/* log.c - a tiny printf to the UART and the semihosting console (see log.h). */
#include "log.h"

#include "format.h"

#include <stdint.h>

#include "semihost.h"
#include "uart.h"

static unsigned sinks = LOG_TO_UART | LOG_TO_SEMIHOST;

void log_set_sinks(unsigned s)
{
    sinks = s;
}

void log_vprintf(const char *fmt, va_list ap)
{
    static char line[256];
    fmt_format(line, sizeof line, fmt, ap);
    if (sinks & LOG_TO_UART) uart_puts(line);
    if (sinks & LOG_TO_SEMIHOST) sh_write0(line);
}

void log_printf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    log_vprintf(fmt, ap);
    va_end(ap);
}
