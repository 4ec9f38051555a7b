/* format.c - a tiny printf into a buffer (see format.h), shared by the bare-metal
 * targets' logs and messages. */
#include "format.h"

#include <stdint.h>

typedef struct {
    char *buf;
    int size, len;
} out_buf;

static void put(out_buf *o, char c)
{
    if (o->len + 1 < o->size) o->buf[o->len++] = c;
}

static void put_num(out_buf *o, uint32_t v, unsigned base, int neg, int width, char pad)
{
    char tmp[12];
    int n = 0;
    do {
        unsigned d = v % base;
        tmp[n++] = (char)(d < 10 ? '0' + d : 'a' + d - 10);
        v /= base;
    } while (v);
    if (neg) {
        if (pad == '0')
            put(o, '-');
        else
            tmp[n++] = '-';
        width--;
    }
    for (int i = n; i < width; i++) put(o, pad);
    while (n) put(o, tmp[--n]);
}

int fmt_format(char *buf, int size, const char *fmt, va_list ap)
{
    out_buf o = {buf, size, 0};
    for (; *fmt; fmt++) {
        if (*fmt != '%') {
            put(&o, *fmt);
            continue;
        }
        fmt++;
        char pad = ' ';
        int width = 0;
        if (*fmt == '0') {
            pad = '0';
            fmt++;
        }
        while (*fmt >= '0' && *fmt <= '9') width = width * 10 + (*fmt++ - '0');
        switch (*fmt) {
        case 's': {
            const char *s = va_arg(ap, const char *);
            if (!s) s = "(null)";
            int n = 0;
            while (s[n]) n++;
            for (int i = n; i < width; i++) put(&o, ' ');
            while (*s) put(&o, *s++);
            break;
        }
        case 'c': put(&o, (char)va_arg(ap, int)); break;
        case 'd': {
            int v = va_arg(ap, int);
            put_num(&o, v < 0 ? 0u - (uint32_t)v : (uint32_t)v, 10, v < 0, width, pad);
            break;
        }
        case 'u': put_num(&o, va_arg(ap, unsigned), 10, 0, width, pad); break;
        case 'x': put_num(&o, va_arg(ap, unsigned), 16, 0, width, pad); break;
        case '%': put(&o, '%'); break;
        case '\0': fmt--; break;
        default:
            put(&o, '%');
            put(&o, *fmt);
            break;
        }
    }
    if (size > 0) buf[o.len] = '\0';
    return o.len;
}
