/* log.c - messages on COM1 (see log.h). */
#include "log.h"

#include <stdarg.h>

#include "com1.h"
#include "format.h"

void log_printf(const char *fmt, ...)
{
    static char line[256];
    va_list ap;
    va_start(ap, fmt);
    fmt_format(line, sizeof line, fmt, ap);
    va_end(ap);
    com1_puts(line);
}
