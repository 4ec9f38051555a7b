/* name_table.h - lump and texture names (up to 8 characters) to numbers by
 * open addressing (prefix nt_): a map's textures make thousands of lookups in a
 * WAD directory of thousands of names, which a linear search pays for. */
#ifndef BSPC_NAME_TABLE_H
#define BSPC_NAME_TABLE_H

#include <stdint.h>

#define NT_NONE UINT32_MAX

typedef struct {
    char name[9];
    uint32_t value; /* NT_NONE: an empty slot */
} nt_entry;

typedef struct {
    nt_entry *e;
    uint32_t mask; /* slots - 1; the slots are at least twice the names */
} name_table;

/* Room for n names; 0, or -1 when out of memory. */
int nt_init(name_table *t, uint32_t n);
void nt_free(name_table *t);
/* Enter name (longer than 8 characters: cut) with value: a name already there
 * keeps its value unless replace, so the first or the last one wins. */
void nt_put(name_table *t, const char *name, uint32_t value, int replace);
/* The value of name, or NT_NONE. */
uint32_t nt_get(const name_table *t, const char *name);

#endif
