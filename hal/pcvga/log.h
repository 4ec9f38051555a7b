/* log.h - the PC kernel's messages (prefix log_): one line formatted by
 * hal/bare/format.h's tiny printf, sent on COM1. */
#ifndef PCVGA_LOG_H
#define PCVGA_LOG_H

void log_printf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
