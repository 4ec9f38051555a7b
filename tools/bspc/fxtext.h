/* fxtext.h - decimal text <-> 16.16 fixed point for the host tools, exactly:
 * parsing rounds to the nearest 1/65536 (ties away from zero) without floating
 * point, and formatting prints the exact decimal value of a 16.16 number. */
#ifndef HOST_FXTEXT_H
#define HOST_FXTEXT_H

#include <stdint.h>

/* Parse "[-+]digits[.digits]" or "[-+].digits" (the whole string) to 16.16 raw
 * units in 64 bits, so callers can name an out-of-range value in their message.
 * Returns 0, or -1 if malformed or |v| >= 2^31 units. */
int fxtext_parse64(const char *s, int64_t *out);

/* The same, into an int32_t: -1 also if outside the 16.16 range. */
int fxtext_parse(const char *s, int32_t *out);

/* Exact decimal of raw/65536 (at most 16 fraction digits, trailing zeros dropped). */
void fxtext_format(int32_t raw, char *buf, int buflen);

#endif
