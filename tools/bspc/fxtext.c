/* fxtext.c - exact decimal conversion of 16.16 values. */
#include "fxtext.h"

#include <stdio.h>
#include <string.h>

__extension__ typedef unsigned __int128 fxtext_u128;

int fxtext_parse64(const char *s, int64_t *out)
{
    int neg = 0, digits = 0, frac_digits = 0;
    int64_t whole = 0;
    if (*s == '-' || *s == '+') neg = *s++ == '-';
    for (; *s >= '0' && *s <= '9'; s++, digits++) {
        whole = whole * 10 + (*s - '0');
        if (whole > ((int64_t)1 << 31)) return -1;
    }
    /* the fraction as num / den with up to 30 digits: enough to round exactly */
    fxtext_u128 num = 0, den = 1;
    if (*s == '.') {
        for (s++; *s >= '0' && *s <= '9'; s++, frac_digits++) {
            if (frac_digits < 30) {
                num = num * 10u + (unsigned)(*s - '0');
                den *= 10u;
            }
        }
    }
    if (*s != '\0' || digits + frac_digits == 0) return -1;
    fxtext_u128 scaled = num * 65536u;
    int64_t q = (int64_t)(scaled / den);
    if ((scaled % den) * 2u >= den) q++; /* ties away from zero */
    int64_t v = whole * 65536 + q;
    if (v >= ((int64_t)1 << 47)) return -1;
    *out = neg ? -v : v;
    return 0;
}

int fxtext_parse(const char *s, int32_t *out)
{
    int64_t v;
    if (fxtext_parse64(s, &v) != 0 || v > INT32_MAX || v < INT32_MIN) return -1;
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
