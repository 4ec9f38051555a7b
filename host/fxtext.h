/* fxtext.h - decimal text <-> 16.16 fixed point for host programs, exactly:
 * parsing rounds to the nearest 1/65536 (ties away from zero) without floating
 * point, and formatting prints the exact decimal value of a 16.16 number. */
#ifndef HOST_FXTEXT_H
#define HOST_FXTEXT_H

#include <stdint.h>

/* Parse "[-+]digits[.digits]" (whole string). Returns 0, or -1 if malformed or
 * outside the 16.16 range. */
int fxtext_parse(const char *s, int32_t *out);

/* Exact decimal of raw/65536 (at most 16 fraction digits, trailing zeros dropped). */
void fxtext_format(int32_t raw, char *buf, int buflen);

#endif
