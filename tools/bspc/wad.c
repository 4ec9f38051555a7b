/* wad.c - reader of Doom-format maps from a WAD file (IWAD or PWAD).
 *
 * A map is the marker lump (MAP01, E1M1, ...) followed by THINGS, LINEDEFS,
 * SIDEDEFS, VERTEXES, SEGS, SSECTORS, NODES, SECTORS, REJECT, BLOCKMAP in any
 * order; only THINGS, LINEDEFS, SIDEDEFS, VERTEXES and SECTORS are read (the
 * shipped nodes are ignored: this compiler builds its own). A BEHAVIOR lump
 * marks a Hexen-format map, which is refused. Every index is validated.
 */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bspc_int.h"

typedef struct {
    uint32_t pos, size;
    char name[9];
} lump;

static uint16_t rd16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }
static int16_t rds16(const uint8_t *p) { return (int16_t)rd16(p); }
static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static const char *map_lumps[] = {"THINGS",  "LINEDEFS", "SIDEDEFS", "VERTEXES", "SEGS",
                                  "SSECTORS", "NODES",   "SECTORS",  "REJECT",   "BLOCKMAP",
                                  "BEHAVIOR", "SCRIPTS", NULL};

static int is_map_lump(const char *n)
{
    for (int i = 0; map_lumps[i]; i++)
        if (strcmp(n, map_lumps[i]) == 0) return 1;
    return 0;
}

/* read n bytes at offset pos */
static int read_at(FILE *f, uint32_t pos, uint32_t n, uint8_t *buf)
{
    if (fseek(f, (long)pos, SEEK_SET) != 0) return -1;
    return fread(buf, 1, n, f) == n ? 0 : -1;
}

/* texture/flat name field: 8 bytes, NUL padded, upper case */
static void name8(char out[9], const uint8_t *p)
{
    int i;
    for (i = 0; i < 8 && p[i]; i++) out[i] = (char)toupper(p[i]);
    out[i] = 0;
}

int bs_read_wad(const char *wadpath, const char *map, const char *display, bs_scene *s,
                const bspc_options *opt, char *err, size_t errlen)
{
    snprintf(s->name, sizeof s->name, "%s", display);
    s->is_text = 0;
    s->player_sector = SCN_NONE;
    FILE *f = fopen(wadpath, "rb");
    if (!f) return bs_fail(err, errlen, "%s: cannot open %s: %s", display, wadpath, strerror(errno));
    int rc = -1;
    lump *dir = NULL;
    uint8_t *vused = NULL, *dirbuf = NULL;
    enum { L_THINGS, L_LINEDEFS, L_SIDEDEFS, L_VERTEXES, L_SECTORS, L_N };
    uint8_t *ld[L_N] = {0};
    uint8_t hdr[12];
    long flen = -1;
    if (fseek(f, 0, SEEK_END) == 0) flen = ftell(f);
    if (flen < 12 || read_at(f, 0, 12, hdr) ||
        (memcmp(hdr, "IWAD", 4) != 0 && memcmp(hdr, "PWAD", 4) != 0)) {
        bs_fail(err, errlen, "%s: %s is not a WAD file (no IWAD/PWAD magic)", display, wadpath);
        goto out;
    }
    size_t len = (size_t)flen;
    uint32_t nlumps = rd32(hdr + 4), dirofs = rd32(hdr + 8);
    if (dirofs > len || nlumps > (len - dirofs) / 16) {
        bs_fail(err, errlen, "%s: %s: lump directory (%u lumps at offset %u) runs past the end of "
                "the file (%zu bytes)", display, wadpath, nlumps, dirofs, len);
        goto out;
    }
    dir = calloc(nlumps + 1, sizeof *dir);
    dirbuf = malloc((size_t)nlumps * 16 + 1);
    if (!dir || !dirbuf) {
        bs_fail(err, errlen, "%s: out of memory", display);
        goto out;
    }
    if (read_at(f, dirofs, nlumps * 16, dirbuf)) {
        bs_fail(err, errlen, "%s: %s: cannot read the lump directory", display, wadpath);
        goto out;
    }
    for (uint32_t i = 0; i < nlumps; i++) {
        const uint8_t *e = dirbuf + 16 * i;
        dir[i].pos = rd32(e);
        dir[i].size = rd32(e + 4);
        name8(dir[i].name, e + 8);
    }
    char want[9];
    size_t ml = strlen(map);
    if (ml > 8) {
        bs_fail(err, errlen, "%s: map name '%s' is longer than 8 characters", display, map);
        goto out;
    }
    memset(want, 0, sizeof want);
    for (size_t i = 0; i < ml; i++) want[i] = (char)toupper((unsigned char)map[i]);
    uint32_t marker = nlumps;
    for (uint32_t i = nlumps; i-- > 0;) /* the last one wins, as in the engine */
        if (strcmp(dir[i].name, want) == 0) {
            marker = i;
            break;
        }
    if (marker == nlumps) {
        bs_fail(err, errlen, "%s: no map %s in %s", display, want, wadpath);
        goto out;
    }
    static const char *need[L_N] = {"THINGS", "LINEDEFS", "SIDEDEFS", "VERTEXES", "SECTORS"};
    static const uint32_t recsz[L_N] = {10, 14, 30, 4, 26};
    uint32_t cnt[L_N] = {0};
    for (uint32_t i = marker + 1; i < nlumps && is_map_lump(dir[i].name); i++) {
        if (strcmp(dir[i].name, "BEHAVIOR") == 0) {
            bs_fail(err, errlen, "%s: Hexen-format map (has a BEHAVIOR lump): only Doom-format maps "
                    "are supported", display);
            goto out;
        }
        for (int k = 0; k < L_N; k++) {
            if (strcmp(dir[i].name, need[k]) != 0 || ld[k]) continue;
            if (dir[i].pos > len || dir[i].size > len - dir[i].pos) {
                bs_fail(err, errlen, "%s: %s lump runs past the end of the file", display, need[k]);
                goto out;
            }
            if (dir[i].size % recsz[k] != 0) {
                bs_fail(err, errlen, "%s: %s lump size %u is not a multiple of %u bytes", display,
                        need[k], dir[i].size, recsz[k]);
                goto out;
            }
            ld[k] = malloc(dir[i].size + 1);
            if (!ld[k]) {
                bs_fail(err, errlen, "%s: out of memory", display);
                goto out;
            }
            if (read_at(f, dir[i].pos, dir[i].size, ld[k])) {
                bs_fail(err, errlen, "%s: cannot read the %s lump", display, need[k]);
                goto out;
            }
            cnt[k] = dir[i].size / recsz[k];
        }
    }
    for (int k = 0; k < L_N; k++)
        if (!ld[k]) {
            bs_fail(err, errlen, "%s: map has no %s lump", display, need[k]);
            goto out;
        }

    /* sectors */
    if (cnt[L_SECTORS] == 0) {
        bs_fail(err, errlen, "%s: map has no sectors", display);
        goto out;
    }
    s->sectors = calloc(cnt[L_SECTORS], sizeof *s->sectors);
    if (!s->sectors) {
        bs_fail(err, errlen, "%s: out of memory", display);
        goto out;
    }
    s->scap = s->nsectors = cnt[L_SECTORS];
    for (uint32_t i = 0; i < cnt[L_SECTORS]; i++) {
        const uint8_t *r = ld[L_SECTORS] + 26 * i;
        bs_sector *c = &s->sectors[i];
        int fh = rds16(r), ch = rds16(r + 2);
        if (fh > SCN_HEIGHT_MAX || fh < -SCN_HEIGHT_MAX || ch > SCN_HEIGHT_MAX ||
            ch < -SCN_HEIGHT_MAX) {
            bs_fail(err, errlen, "%s: sector %u: floor %d / ceiling %d out of range (|height| <= %d)",
                    display, i, fh, ch, SCN_HEIGHT_MAX);
            goto out;
        }
        c->floor_h = fh * 65536;
        c->ceil_h = ch * 65536;
        int light = rds16(r + 20);
        if (light < 0) light = 0;
        if (light > 255) light = 255;
        c->light = (uint8_t)light;
        char fflat[9], cflat[9];
        name8(fflat, r + 4);
        name8(cflat, r + 12);
        c->floor_color = bs_flat_color(fflat, light, 0);
        if (strncmp(cflat, "F_SKY", 5) == 0) {
            c->flags |= SCN_SECTOR_SKY;
            c->ceil_color = bs_sky_color();
        } else {
            c->ceil_color = bs_flat_color(cflat, light, 1);
        }
    }

    /* vertices: all of them, in lump order (unused ones are dropped by the build) */
    uint32_t nv = cnt[L_VERTEXES];
    s->vx = malloc(sizeof(int32_t) * (nv + 1));
    s->vy = malloc(sizeof(int32_t) * (nv + 1));
    vused = calloc(nv + 1, 1);
    if (!s->vx || !s->vy || !vused) {
        bs_fail(err, errlen, "%s: out of memory", display);
        goto out;
    }
    s->vcap = s->nverts = nv;
    for (uint32_t i = 0; i < nv; i++) {
        s->vx[i] = rds16(ld[L_VERTEXES] + 4 * i) * 65536;
        s->vy[i] = rds16(ld[L_VERTEXES] + 4 * i + 2) * 65536;
    }

    /* linedefs */
    uint32_t nl = cnt[L_LINEDEFS], nsd = cnt[L_SIDEDEFS];
    s->lines = calloc(nl + 1, sizeof *s->lines);
    if (!s->lines) {
        bs_fail(err, errlen, "%s: out of memory", display);
        goto out;
    }
    s->lcap = nl + 1;
    uint32_t skipped = 0;
    for (uint32_t i = 0; i < nl; i++) {
        const uint8_t *r = ld[L_LINEDEFS] + 14 * i;
        uint32_t v1 = rd16(r), v2 = rd16(r + 2);
        uint32_t sd[2] = {rd16(r + 10), rd16(r + 12)};
        if (v1 >= nv || v2 >= nv) {
            bs_fail(err, errlen, "%s: linedef %u: vertex %u out of range (have %u)", display, i,
                    v1 >= nv ? v1 : v2, nv);
            goto out;
        }
        if (sd[0] == 0xFFFF) {
            bs_fail(err, errlen, "%s: linedef %u: no front sidedef", display, i);
            goto out;
        }
        for (int k = 0; k < 2; k++)
            if (sd[k] != 0xFFFF && sd[k] >= nsd) {
                bs_fail(err, errlen, "%s: linedef %u: sidedef %u out of range (have %u)", display, i,
                        sd[k], nsd);
                goto out;
            }
        if (s->vx[v1] == s->vx[v2] && s->vy[v1] == s->vy[v2]) {
            bs_warn(opt, "%s: linedef %u: zero length, skipped", display, i);
            skipped++;
            continue;
        }
        bs_line *l = &s->lines[s->nlines];
        l->v1 = v1;
        l->v2 = v2;
        l->src_line = (int)i;
        l->sector[0] = l->sector[1] = SCN_NONE;
        int64_t dx = ((int64_t)s->vx[v2] - s->vx[v1]) / 65536, dy = ((int64_t)s->vy[v2] - s->vy[v1]) / 65536;
        /* fake contrast as in Doom: walls running east-west a shade lighter,
         * north-south a shade darker */
        int contrast = (dy == 0) ? 1 : (dx == 0) ? -1 : 0;
        for (int k = 0; k < 2; k++) {
            if (sd[k] == 0xFFFF) continue;
            const uint8_t *sr = ld[L_SIDEDEFS] + 30 * sd[k];
            uint32_t sec = rd16(sr + 28);
            if (sec >= s->nsectors) {
                bs_fail(err, errlen, "%s: linedef %u: sidedef %u: sector %u out of range (have %u)",
                        display, i, sd[k], sec, s->nsectors);
                goto out;
            }
            l->sector[k] = sec;
            int light = s->sectors[sec].light;
            char up[9], lo[9], mid[9];
            name8(up, sr + 4);
            name8(lo, sr + 12);
            name8(mid, sr + 20);
            int has_mid = mid[0] && strcmp(mid, "-") != 0;
            uint8_t cm = has_mid ? bs_wall_color(mid, light, contrast) : bs_neutral_color(light);
            l->color[k][SCN_PART_MIDDLE] = cm;
            l->color[k][SCN_PART_UPPER] =
                (up[0] && strcmp(up, "-") != 0) ? bs_wall_color(up, light, contrast) : cm;
            l->color[k][SCN_PART_LOWER] =
                (lo[0] && strcmp(lo, "-") != 0) ? bs_wall_color(lo, light, contrast) : cm;
        }
        vused[v1] = vused[v2] = 1;
        s->nlines++;
    }
    if (skipped) bs_note(opt, "%s: skipped %u zero-length linedef(s)", display, skipped);
    if (s->nlines == 0) {
        bs_fail(err, errlen, "%s: map has no linedefs", display);
        goto out;
    }
    for (uint32_t i = 0; i < nv; i++)
        if (vused[i] && s->vx[i] == -32768 * 65536) {
            bs_fail(err, errlen, "%s: vertex %u: x = -32768 out of range (|coordinate| <= %d)",
                    display, i, SCN_COORD_MAX);
            goto out;
        } else if (vused[i] && s->vy[i] == -32768 * 65536) {
            bs_fail(err, errlen, "%s: vertex %u: y = -32768 out of range (|coordinate| <= %d)",
                    display, i, SCN_COORD_MAX);
            goto out;
        }

    /* player 1 start */
    for (uint32_t i = 0; i < cnt[L_THINGS]; i++) {
        const uint8_t *r = ld[L_THINGS] + 10 * i;
        if (rd16(r + 6) != 1) continue;
        int x = rds16(r), y = rds16(r + 2), a = rds16(r + 4);
        s->player_x = x * 65536;
        s->player_y = y * 65536;
        a %= 360;
        if (a < 0) a += 360;
        s->player_angle = a * 65536;
        s->has_player = 1;
        s->player_line = (int)i;
        if (x == -32768 || y == -32768) {
            bs_fail(err, errlen, "%s: thing %u (player start): coordinate out of range", display, i);
            goto out;
        }
        break;
    }
    if (!s->has_player) {
        bs_fail(err, errlen, "%s: no player start (no thing of type 1)", display);
        goto out;
    }
    rc = 0;
out:
    for (int k = 0; k < L_N; k++) free(ld[k]);
    free(vused);
    free(dir);
    free(dirbuf);
    fclose(f);
    return rc;
}
