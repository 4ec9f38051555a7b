/* wad_maps.c - the maps a WAD holds (bspc --list, and the messages that name a
 * map the WAD does not have). A map is a marker lump (MAP01, E1M1, ...) that
 * THINGS follows, as Doom's P_SetupLevel finds it. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Appends name to the space-separated list in out; once it does not fit, the
 * list ends in "...". */
static void list_add(char *out, size_t outlen, const char *name)
{
    size_t used = strlen(out), need = strlen(name) + (used ? 1 : 0);
    if (used >= 3 && !strcmp(out + used - 3, "...")) return;
    if (used + need + 4 < outlen) {
        snprintf(out + used, outlen - used, "%s%s", used ? " " : "", name);
    } else if (used + 4 < outlen) {
        snprintf(out + used, outlen - used, "%s...", used ? " " : "");
    }
}

int bspc_list_maps(const char *wad, char *out, size_t outlen, char *err, size_t errlen)
{
    char path[1100];
    if (outlen) out[0] = 0;
    if (bspc_find_wad(wad, path, sizeof path))
        return bs_fail(err, errlen,
                       "%s: cannot find it (looked in the current folder, $DOOMWADDIR and "
                       "/usr/share/games/doom)",
                       wad);
    FILE *f = fopen(path, "rb");
    if (!f) return bs_fail(err, errlen, "%s: cannot open: %s", path, strerror(errno));
    uint8_t hdr[12];
    uint8_t *dir = NULL;
    int n = -1;
    long flen = -1;
    if (fseek(f, 0, SEEK_END) == 0) flen = ftell(f);
    if (flen < 12 || fseek(f, 0, SEEK_SET) || fread(hdr, 1, 12, f) != 12 ||
        (memcmp(hdr, "IWAD", 4) && memcmp(hdr, "PWAD", 4))) {
        bs_fail(err, errlen, "%s: not a WAD file (no IWAD or PWAD header)", path);
        goto out;
    }
    uint32_t nlumps = le32(hdr + 4), dirofs = le32(hdr + 8);
    if (dirofs > (unsigned long)flen || nlumps > ((unsigned long)flen - dirofs) / 16) {
        bs_fail(err, errlen, "%s: lump directory runs past the end of the file", path);
        goto out;
    }
    dir = malloc((size_t)nlumps * 16 + 1);
    if (!dir) {
        bs_fail(err, errlen, "%s: out of memory", path);
        goto out;
    }
    if (fseek(f, (long)dirofs, SEEK_SET) || fread(dir, 16, nlumps, f) != nlumps) {
        bs_fail(err, errlen, "%s: cannot read the lump directory", path);
        goto out;
    }
    n = 0;
    for (uint32_t i = 0; i + 1 < nlumps; i++) {
        if (memcmp(dir + 16 * (i + 1) + 8, "THINGS\0\0", 8) != 0) continue;
        char name[9];
        memcpy(name, dir + 16 * i + 8, 8);
        name[8] = 0;
        list_add(out, outlen, name);
        n++;
    }
out:
    free(dir);
    fclose(f);
    return n;
}
