/* args.c - the bare-metal firmwares' run-time options (see args.h). */
#include "args.h"

#include <stdarg.h>

#include "hal.h"
#include "format.h"
#include "render.h"

#define FRAC_DIGITS_MAX 30 /* as many as the host tools use for rounding */

int args_parse_fx(const char *s, int32_t *out)
{
    int neg = 0, digits = 0, nfrac = 0;
    uint32_t whole = 0;
    uint8_t frac[FRAC_DIGITS_MAX];
    if (*s == '-' || *s == '+') neg = *s++ == '-';
    for (; *s >= '0' && *s <= '9'; s++, digits++) {
        whole = whole * 10u + (uint32_t)(*s - '0');
        if (whole > 32768u) return -1;
    }
    if (*s == '.') {
        for (s++; *s >= '0' && *s <= '9'; s++) {
            if (nfrac < FRAC_DIGITS_MAX) frac[nfrac++] = (uint8_t)(*s - '0');
            digits++;
        }
    }
    if (*s != '\0' || digits == 0) return -1;
    /* Multiply the decimal fraction by 65536 digit by digit, from the last:
     * the carry out of the first digit is floor(frac * 65536); the digits left
     * behind are the remainder, which rounds up if it is at least one half. */
    uint32_t carry = 0;
    for (int i = nfrac - 1; i >= 0; i--) {
        uint32_t v = frac[i] * 65536u + carry;
        frac[i] = (uint8_t)(v % 10u);
        carry = v / 10u;
    }
    if (nfrac > 0 && frac[0] >= 5) carry++;
    uint32_t v = (whole << 16) + carry;
    if (v > 0x7FFFFFFFu + (uint32_t)neg) return -1;
    *out = neg ? (int32_t)(0u - v) : (int32_t)v;
    return 0;
}

static int parse_int(const char *s, int32_t *out)
{
    int neg = 0;
    int64_t v = 0;
    if (*s == '-' || *s == '+') neg = *s++ == '-';
    if (!*s) return -1;
    for (; *s; s++) {
        if (*s < '0' || *s > '9') return -1;
        v = v * 10 + (*s - '0');
        if (v > 0x7FFFFFFF) return -1;
    }
    *out = (int32_t)(neg ? -v : v);
    return 0;
}

static int same(const char *a, const char *b)
{
    while (*a && *a == *b) a++, b++;
    return *a == *b;
}

static int fail(char *err, int size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fmt_format(err, size, fmt, ap);
    va_end(ap);
    return -1;
}

/* The ARGS_* feature an option belongs to (0: every target has it). */
static unsigned option_feature(const char *o)
{
    if (same(o, "--no-stream") || same(o, "--acks")) return ARGS_STREAM;
    if (same(o, "--no-tick")) return ARGS_NO_TICK;
    if (same(o, "--wait")) return ARGS_WAIT;
    return 0;
}

/* Split "a,b[,c]" in place; returns the number of parts (at most max). */
static int split_commas(char *s, char **parts, int max)
{
    int n = 0;
    parts[n++] = s;
    for (; *s; s++) {
        if (*s == ',') {
            if (n == max) return max + 1;
            *s = '\0';
            parts[n++] = s + 1;
        }
    }
    return n;
}

int args_parse(fw_args *a, char *line, unsigned offered, char *err, int errsize)
{
    char *words[32];
    int n = 0;
    for (char *p = line; *p;) {
        while (*p == ' ' || *p == '\t') *p++ = '\0';
        if (!*p) break;
        if (n == 32) return fail(err, errsize, "too many words on the command line");
        words[n++] = p;
        while (*p && *p != ' ' && *p != '\t') p++;
    }
    a->frames = -1;
    a->linger_ms = 0;
    a->path = 0;
    a->have_at = a->have_z = a->have_angle = 0;
    a->x = a->y = a->z = a->angle_deg = 0;
    a->look = 0;
    a->mode = a->present = -1;
    a->no_stream = a->no_tick = a->fault = a->wait = a->no_objects = a->flat = 0;
    a->acks = ARGS_ACKS_AUTO;
    for (int i = 1; i < n; i++) { /* words[0]: the program */
        const char *o = words[i];
        char *val = i + 1 < n ? words[i + 1] : 0;
        unsigned needs = option_feature(o);
        if (needs && !(offered & needs)) return fail(err, errsize, "option '%s' is not available on this target", o);
        if (same(o, "--no-stream") || same(o, "--no-tick") || same(o, "--fault") || same(o, "--wait") ||
            same(o, "--no-objects") || same(o, "--flat")) {
            *(same(o, "--no-stream")    ? &a->no_stream
              : same(o, "--no-tick")    ? &a->no_tick
              : same(o, "--wait")       ? &a->wait
              : same(o, "--no-objects") ? &a->no_objects
              : same(o, "--flat")       ? &a->flat
                                        : &a->fault) = 1;
            continue;
        }
        if (!val) return fail(err, errsize, "%s: missing value", o);
        i++;
        if (same(o, "--frames")) {
            if (parse_int(val, &a->frames) || a->frames < 0)
                return fail(err, errsize, "--frames '%s': expected a count", val);
        } else if (same(o, "--linger")) {
            if (parse_int(val, &a->linger_ms) || a->linger_ms < 0 || a->linger_ms > 60000)
                return fail(err, errsize, "--linger '%s': expected milliseconds, 0..60000", val);
        } else if (same(o, "--path")) {
            a->path = val;
        } else if (same(o, "--at")) {
            char *p[3];
            int k = split_commas(val, p, 3);
            if (k < 2 || k > 3 || args_parse_fx(p[0], &a->x) || args_parse_fx(p[1], &a->y) ||
                (k == 3 && args_parse_fx(p[2], &a->z)))
                return fail(err, errsize, "--at: expected X,Y or X,Y,Z in map units (|v| < 32768)");
            a->have_at = 1;
            a->have_z = k == 3;
        } else if (same(o, "--angle")) {
            if (args_parse_fx(val, &a->angle_deg)) return fail(err, errsize, "--angle '%s': expected degrees", val);
            a->have_angle = 1;
        } else if (same(o, "--look")) {
            if (parse_int(val, &a->look)) return fail(err, errsize, "--look '%s': expected pixels", val);
        } else if (same(o, "--mode")) {
            if ((a->mode = render_mode_parse(val)) < 0)
                return fail(err, errsize, "--mode '%s': direct, spans, painter or columns", val);
        } else if (same(o, "--present")) {
            if ((a->present = hal_present_parse(val)) < 0)
                return fail(err, errsize, "--present '%s': flip, copy8, copy16 or copy32", val);
        } else if (same(o, "--acks")) {
            if (same(val, "auto"))
                a->acks = ARGS_ACKS_AUTO;
            else if (same(val, "on"))
                a->acks = ARGS_ACKS_ON;
            else if (same(val, "off"))
                a->acks = ARGS_ACKS_OFF;
            else
                return fail(err, errsize, "--acks '%s': auto, on or off", val);
        } else {
            return fail(err, errsize, "unknown option '%s'", o);
        }
    }
    return 0;
}
