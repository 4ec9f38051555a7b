/* name_table.c - names to numbers by open addressing (name_table.h). */
#include "name_table.h"

#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"

int nt_init(name_table *t, uint32_t n)
{
    uint32_t slots = 16;
    while (slots < 2 * (uint64_t)n && slots < (1u << 30)) slots *= 2;
    t->e = malloc(sizeof *t->e * slots);
    t->mask = slots - 1;
    if (!t->e) return -1;
    for (uint32_t i = 0; i < slots; i++) t->e[i].value = NT_NONE;
    return 0;
}

void nt_free(name_table *t)
{
    free(t->e);
    t->e = NULL;
}

/* the slot of name (at most 8 characters), or the empty slot where it would go */
static nt_entry *slot_of(const name_table *t, const char *name)
{
    for (uint32_t i = bs_name_hash(name) & t->mask;; i = (i + 1) & t->mask) {
        nt_entry *e = &t->e[i];
        if (e->value == NT_NONE || strcmp(e->name, name) == 0) return e;
    }
}

void nt_put(name_table *t, const char *name, uint32_t value, int replace)
{
    char cut[9];
    size_t n = strlen(name);
    if (n > 8) n = 8;
    memcpy(cut, name, n);
    cut[n] = 0;
    nt_entry *e = slot_of(t, cut);
    if (e->value != NT_NONE && !replace) return;
    memcpy(e->name, cut, n + 1);
    e->value = value;
}

uint32_t nt_get(const name_table *t, const char *name)
{
    if (strlen(name) > 8) return NT_NONE; /* no entry has a longer name */
    return slot_of(t, name)->value;
}
