/* scene_refusal.c - the refusal of a built-in scene in words (see scene_refusal.h). */
#include "scene_refusal.h"

#include <stdarg.h>

#include "format.h"

static int print(char *buf, int size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = fmt_format(buf, size, fmt, ap);
    va_end(ap);
    return n;
}

int scene_refusal_format(char *buf, int size, const char *scene_name, scene_status st, const scene_error *se)
{
    if (st == SCENE_ERR_BUILD && se->index < SCENE_ITEM_EDGES)
        return print(buf, size, "the built-in scene %s needs %s, which this build leaves out; refusing to run",
                     scene_name, scene_item_name(se->index));
    if (st == SCENE_ERR_BUILD)
        return print(buf, size, "the built-in scene %s needs %s %u; this build provides %u; refusing to run",
                     scene_name, scene_item_name(se->index), (unsigned)se->need, (unsigned)se->have);
    if (se->section >= 0)
        return print(buf, size, "the built-in scene %s is invalid: %s (%s record %u); refusing to run", scene_name,
                     scene_status_text(st), scene_section_name(se->section), (unsigned)se->index);
    return print(buf, size, "the built-in scene %s is invalid: %s; refusing to run", scene_name, scene_status_text(st));
}
