/* format.h - a tiny printf into one buffer (prefix fmt_), for the bare-metal
 * targets (hal/mps2, hal/pcvga), which have no libc: %s %c %d %u %x, with an
 * optional 0 flag and width, and %%. */
#ifndef BARE_FORMAT_H
#define BARE_FORMAT_H

#include <stdarg.h>

/* Format into buf (always NUL-terminated when size > 0); returns the length written. */
int fmt_format(char *buf, int size, const char *fmt, va_list ap);

#endif
