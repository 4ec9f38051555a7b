/* board_args.c - the display board's command line (see board_args.h). */
#include "board_args.h"

/* err = a b c, cut to fit */
static void say(char *err, uint32_t size, const char *a, const char *b, const char *c)
{
    const char *parts[3] = {a, b, c};
    uint32_t n = 0;
    for (int i = 0; i < 3; i++)
        for (const char *p = parts[i]; *p && n + 1 < size; p++) err[n++] = *p;
    if (size) err[n] = '\0';
}

static int is_space(char c)
{
    return c == ' ' || c == '\t';
}

/* The next word of *s into w (at most cap - 1 characters); 0 at the end. */
static int next_word(const char **s, char *w, uint32_t cap)
{
    const char *p = *s;
    while (is_space(*p)) p++;
    if (!*p) return 0;
    uint32_t n = 0;
    while (*p && !is_space(*p)) {
        if (n + 1 < cap) w[n++] = *p;
        p++;
    }
    w[n] = '\0';
    *s = p;
    return 1;
}

static int streq(const char *a, const char *b)
{
    while (*a && *a == *b) a++, b++;
    return *a == *b;
}

/* A decimal count 1..1,000,000,000, or -1. */
static int32_t count_of(const char *w)
{
    uint32_t v = 0;
    if (!*w) return -1;
    for (; *w; w++) {
        if (*w < '0' || *w > '9' || v > 100000000u) return -1;
        v = v * 10u + (uint32_t)(*w - '0');
    }
    return v >= 1u && v <= 1000000000u ? (int32_t)v : -1;
}

int board_args_parse(board_args *a, const char *cmdline, char *err, uint32_t err_size)
{
    char w[32];
    a->frames = 0;
    a->log_frames = 0;
    const char *s = cmdline;
    next_word(&s, w, sizeof w); /* the program (QEMU: the -kernel file) */
    while (next_word(&s, w, sizeof w)) {
        if (streq(w, "--frames")) {
            char v[32];
            int32_t n = next_word(&s, v, sizeof v) ? count_of(v) : -1;
            if (n < 0) {
                say(err, err_size, "--frames wants a number of frames (1 or more)", "", "");
                return -1;
            }
            a->frames = (uint32_t)n;
        } else if (streq(w, "--log-frames")) {
            a->log_frames = 1;
        } else {
            say(err, err_size, "unknown option '", w, "' (the board takes --frames N and --log-frames)");
            return -1;
        }
    }
    return 0;
}
