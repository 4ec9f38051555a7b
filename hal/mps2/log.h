/* log.h - text messages from the firmware (prefix log_): one line formatted by
 * hal/bare/format.h's tiny printf, sent to
 * the host's console over semihosting and, as text, over the UART.
 *
 * On the UART, text is only ever sent outside a frame-link message (before the
 * stream starts, or when the firmware stops), so a receiver sees it as bytes
 * between frames. */
#ifndef MPS2_LOG_H
#define MPS2_LOG_H

#include <stdarg.h>

void log_printf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void log_vprintf(const char *fmt, va_list ap);

/* Where messages go: bit 0 UART, bit 1 semihosting console (default both).
 * The fault handler uses UART only while semihosting may be what faulted. */
#define LOG_TO_UART 1u
#define LOG_TO_SEMIHOST 2u
void log_set_sinks(unsigned sinks);

#endif
