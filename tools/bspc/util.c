/* util.c - messages, growable arrays, clocks and the source-scene container
 * shared by the BSP compiler's files. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bspc_int.h"
#include "fxtext.h"

int bs_fail(char *err, size_t errlen, const char *fmt, ...)
{
    if (err && errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return -1;
}

uint32_t bs_name_hash(const char *s)
{
    uint32_t h = 2166136261u;
    while (*s) h = (h ^ (uint8_t)*s++) * 16777619u;
    return h;
}

void bs_warn(const bspc_options *opt, const char *fmt, ...)
{
    if (!opt || !opt->verbose) return;
    va_list ap;
    va_start(ap, fmt);
    fputs("bspc: warning: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

void bs_note(const bspc_options *opt, const char *fmt, ...)
{
    if (!opt || !opt->verbose) return;
    va_list ap;
    va_start(ap, fmt);
    fputs("bspc: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

int bs_grow(void *pp, uint32_t *cap, uint32_t need, size_t sz)
{
    void **p = (void **)pp;
    if (need <= *cap && *p) return 0;
    uint64_t nc = *cap ? *cap : 16;
    while (nc < need) nc *= 2;
    if (nc > UINT32_MAX / 2 || nc * sz > (uint64_t)SIZE_MAX / 2) return -1;
    void *q = realloc(*p, (size_t)nc * sz);
    if (!q) return -1;
    *p = q;
    *cap = (uint32_t)nc;
    return 0;
}

const char *bs_fxstr(int32_t v, char buf[32])
{
    fxtext_format(v, buf, 32);
    return buf;
}

double bs_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1000.0 + (double)ts.tv_nsec / 1e6;
}

void bs_scene_free(bs_scene *s)
{
    free(s->vx);
    free(s->vy);
    free(s->sectors);
    free(s->lines);
    free(s->models);
    free(s->mverts);
    free(s->faces);
    free(s->findex);
    free(s->objects);
    free(s->look.lights);
    free(s->look.tex);
    free(s->look.texels);
    free(s->look.sides);
    free(s->look.planes);
    free(s->look.sprites);
    free(s->look.sprmask);
    free(s->look.sprsets);
    free(s->look.anims);
    memset(s, 0, sizeof *s);
}

uint32_t bs_scene_add_vertex(bs_scene *s, int32_t x, int32_t y)
{
    uint32_t cap = s->vcap;
    if (bs_grow(&s->vx, &cap, s->nverts + 1, sizeof(int32_t))) return SCN_NONE;
    cap = s->vcap;
    if (bs_grow(&s->vy, &cap, s->nverts + 1, sizeof(int32_t))) return SCN_NONE;
    s->vcap = cap;
    s->vx[s->nverts] = x;
    s->vy[s->nverts] = y;
    return s->nverts++;
}
