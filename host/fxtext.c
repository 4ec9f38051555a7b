/* fxtext.c - exact decimal conversion of 16.16 values. */
#include "fxtext.h"

#include <stdio.h>
#include <string.h>

int fxtext_parse(const char *s, int32_t *out)
{
    int neg = 0, digits = 0;
    int64_t whole = 0;
    if (*s == '-' || *s == '+') neg = *s++ == '-';
    for (; *s >= '0' && *s <= '9'; s++, digits++) {
        whole = whole * 10 + (*s - '0');
        if (whole > 40000) return -1;
    }
    /* fraction as numerator / 10^k with k <= 18, enough to round correctly */
    int64_t num = 0, den = 1;
    int frac_digits = 0;
    if (*s == '.') {
        for (s++; *s >= '0' && *s <= '9'; s++, frac_digits++) {
            if (den < 1000000000000000000LL / 10) {
                num = num * 10 + (*s - '0');
                den *= 10;
            }
        }
    }
    if (*s != '\0' || digits + frac_digits == 0) return -1;
    /* round(num * 65536 / den): num < den <= 10^18 / 10, so num * 65536 may exceed
     * 2^63; split the multiply to keep it exact. */
    int64_t q = (num / den) * 65536;
    int64_t r = num % den;
    unsigned __int128 t = (unsigned __int128)r * 65536u;
    q += (int64_t)(t / (unsigned __int128)den);
    unsigned __int128 rem = t % (unsigned __int128)den;
    if (rem * 2u >= (unsigned __int128)den) q++;
    int64_t v = whole * 65536 + q;
    if (neg) v = -v;
    if (v > INT32_MAX || v < INT32_MIN) return -1;
    *out = (int32_t)v;
    return 0;
}

void fxtext_format(int32_t raw, char *buf, int buflen)
{
    int64_t v = raw;
    const char *sign = "";
    if (v < 0) {
        sign = "-";
        v = -v;
    }
    int64_t whole = v >> 16;
    uint64_t frac = (uint64_t)(v & 0xFFFF) * 152587890625ull; /* 10^16 / 65536 */
    if (frac == 0) {
        snprintf(buf, (size_t)buflen, "%s%lld", sign, (long long)whole);
        return;
    }
    char digits[17];
    snprintf(digits, sizeof digits, "%016llu", (unsigned long long)frac);
    int n = 16;
    while (n > 0 && digits[n - 1] == '0') digits[--n] = '\0';
    snprintf(buf, (size_t)buflen, "%s%lld.%s", sign, (long long)whole, digits);
}
