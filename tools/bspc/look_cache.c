/* look_cache.c - textures kept between the maps of one WAD (look_cache.h). */
#include "look_cache.h"

#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"

struct bspc_look_cache {
    char wad[1100]; /* the resolved WAD path the entries come from */
    lc_entry *e;
    uint32_t n, cap;
};

bspc_look_cache *bspc_look_cache_new(void)
{
    return calloc(1, sizeof(bspc_look_cache));
}

static void clear(bspc_look_cache *c)
{
    for (uint32_t i = 0; i < c->n; i++) free(c->e[i].texels);
    c->n = 0;
}

void bspc_look_cache_free(bspc_look_cache *c)
{
    if (!c) return;
    clear(c);
    free(c->e);
    free(c);
}

const lc_entry *lc_find(bspc_look_cache *c, const char *wad, int kind, const char *name)
{
    if (strcmp(c->wad, wad) != 0) {
        clear(c);
        snprintf(c->wad, sizeof c->wad, "%s", wad);
        return NULL;
    }
    uint32_t h = bs_name_hash(name);
    for (uint32_t i = 0; i < c->n; i++)
        if (c->e[i].hash == h && c->e[i].kind == kind && strcmp(c->e[i].name, name) == 0) return &c->e[i];
    return NULL;
}

int lc_put(bspc_look_cache *c, int kind, const char *name, int known, const scn_texture *rec, const uint8_t *texels)
{
    if (strlen(name) > 8 || bs_grow(&c->e, &c->cap, c->n + 1, sizeof *c->e)) return -1;
    lc_entry *e = &c->e[c->n];
    memset(e, 0, sizeof *e);
    memcpy(e->name, name, strlen(name) + 1);
    e->kind = kind;
    e->hash = bs_name_hash(name);
    e->known = known;
    if (known) {
        size_t n = ((size_t)1 << rec->wbits) << rec->hbits;
        e->rec = *rec;
        e->texels = malloc(n);
        if (!e->texels) return -1;
        memcpy(e->texels, texels, n);
    }
    c->n++;
    return 0;
}
