/* render.c - build/render: the headless renderer CLI. Scene + camera + mode +
 * present mode in; PNG, raw frame, surface-id buffer and one JSON object of
 * counters out. Runs the firmware on the null target. */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "crc32.h"
#include "engine.h"
#include "fxtext.h"
#include "hal.h"
#include "hal_null.h"
#include "fl_engine_info.h"
#include "link_send.h"
#include "objects.h"
#include "png.h"
#include "port.h"
#include "scene_start.h"

static const char usage[] = "usage: render SCENE [--at X,Y[,Z]] [--angle DEG] [options]\n"
                            "\n"
                            "Render one frame of SCENE headless and print its counters as one JSON object.\n"
                            "SCENE is a compiled scene (.bsc), a text scene, or FILE.wad:MAP (compiled on the\n"
                            "fly; a WAD named without a folder is looked for in $DOOMWADDIR and\n"
                            "/usr/share/games/doom).\n"
                            "\n"
                            "  --at X,Y[,Z]       eye position in map units (decimals allowed; rounded to\n"
                            "                     16.16). Default: the scene's player start. Z defaults to\n"
                            "                     the floor under the eye + 41.\n"
                            "  --angle DEG        view angle in degrees, 0 = east, counter-clockwise\n"
                            "                     (default: the player start's angle)\n"
                            "  --look PX          vertical shear in pixels, -100..100 (default 0)\n"
                            "  --mode MODE        direct (zero overdraw), spans (zero overdraw, sorted\n"
                            "                     edge lists), painter (back to front, Listing 62.1)\n"
                            "                     or columns (the default: Doom's, walls down columns,\n"
                            "                     floors from visplanes; objects by direct's code)\n"
                            "  --present P        flip | copy8 | copy16 | copy32 (default flip)\n"
                            "  --split S          BSP split strategy when compiling a source: fewest |\n"
                            "                     balanced | mixed (default mixed)\n"
                            "  -o FILE.png        write the frame as a PNG (palette indices kept exactly)\n"
                            "  --raw FILE         write the 64,000 frame bytes\n"
                            "  --ids FILE         write the surface-id buffer: 320x200 little-endian uint32,\n"
                            "                     kind << 24 | index (0 none, 1 wall, 2 floor, 3 ceiling, 4 object)\n"
                            "  --flat             draw a textured scene (a WAD map) in flat colours\n"
                            "  --repeat N         render the same frame N times (default 1); counters are\n"
                            "                     those of the last frame\n"
                            "  --link PORT        also send the frame over the frame link (docs/frame-link.md)\n"
                            "                     to a display board: PORT as build/display takes it, a tty or\n"
                            "                     pty (set raw at --baud) or socket://HOST:PORT. The JSON gains\n"
                            "                     \"link\": the link's bytes, frames, keyframes, deltas, acks\n"
                            "  --baud B           serial speed for a tty PORT (default 115200)\n"
                            "  -h, --help         this text\n"
                            "\n"
                            "Moving objects and doors (docs/objects.md), animated textures (docs/textures.md):\n"
                            "  --time MS          objects along their paths at MS milliseconds, and doors as\n"
                            "                     they would be after MS ms with the player standing at the\n"
                            "                     camera from time 0; animated textures and flats and\n"
                            "                     scrolling walls at level tic floor(MS * 35 / 1000)\n"
                            "                     (default: time 0, doors as compiled)\n"
                            "  --objects FILE     replace the scene's objects by FILE's: one per line,\n"
                            "                     'object MODEL X Y Z YAW' (map units, degrees; no paths;\n"
                            "                     '#' starts a comment). MODEL is a model number, or a\n"
                            "                     model name when SCENE is a text scene (names are read\n"
                            "                     from its 'model' lines: a compiled scene or a WAD map\n"
                            "                     has no names; a WAD's models are numbered in order of\n"
                            "                     first use by its things)\n"
                            "  --no-objects       draw no objects\n"
                            "  --door SECTOR=H    set door SECTOR's ceiling to H, between its closed and\n"
                            "                     open heights (repeatable; after --time)\n"
                            "The JSON gains \"objects\" (each object as drawn: model, x, y, z, yaw, the exact\n"
                            "16.16 values), \"ceilings\" (sectors whose ceiling is not the compiled one) and the\n"
                            "renderer's \"objects_visible\" and \"object_faces\".\n";

typedef struct {
    const char *arg; /* as given, for messages */
    uint32_t sector;
    fx_t h;
} door_opt;

typedef struct {
    const char *scene, *png, *raw, *ids;
    camera cam;
    int have_at, have_z, have_angle;
    render_mode mode;
    hal_present_mode present;
    bspc_options bspc;
    long repeat;
    uint32_t time_ms;
    int have_time, no_objects, flat;
    const char *objects; /* --objects FILE */
    const char *link;    /* --link PORT */
    long baud;
    door_opt *doors; /* room for every argument */
    int ndoors;
} options;

static int die(const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "render: ");
    fprintf(stderr, fmt, a, b);
    fputc('\n', stderr);
    return 2;
}

/* One coordinate of --at: a decimal number (syntax), strictly inside the
 * world's +-32768 (range). 0, or -1 (syntax) or -2 (range). */
static int parse_coord(const char *t, fx_t *out)
{
    int64_t v;
    if (fxtext_parse64(t, &v)) return -1;
    if (v <= -((int64_t)32768 << 16) || v >= (int64_t)32768 << 16) return -2;
    *out = (fx_t)v;
    return 0;
}

/* --at X,Y[,Z]: exactly two or three numbers, none of them empty. 0, or -1
 * (syntax) or -2 (range). */
static int parse_at(options *o, const char *arg)
{
    fx_t v[3];
    int n = 0;
    for (const char *p = arg;; n++) {
        size_t len = strcspn(p, ",");
        char tok[64];
        if (n == 3 || len == 0 || len >= sizeof tok) return -1;
        memcpy(tok, p, len);
        tok[len] = 0;
        int rc = parse_coord(tok, &v[n]);
        if (rc) return rc;
        if (!p[len]) break;
        p += len + 1;
    }
    if (++n < 2) return -1;
    o->cam.x = v[0];
    o->cam.y = v[1];
    if (n == 3) {
        o->cam.z = v[2];
        o->have_z = 1;
    }
    o->have_at = 1;
    return 0;
}

/* Options that take a value (every other option stands alone). */
static int takes_value(const char *a)
{
    static const char *const with_value[] = {"--at",    "--angle", "--look",    "--mode", "--present",
                                             "--split", "-o",      "--raw",     "--ids",  "--time",
                                             "--link",  "--baud",  "--objects", "--door", "--repeat"};
    for (size_t i = 0; i < sizeof with_value / sizeof *with_value; i++)
        if (!strcmp(a, with_value[i])) return 1;
    return 0;
}

static int parse_args(options *o, int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *val = (i + 1 < argc) ? argv[i + 1] : NULL;
        int takes = 1;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, stdout);
            exit(0);
        } else if (!strcmp(a, "--flat")) {
            o->flat = 1;
            takes = 0;
        } else if (!strcmp(a, "--no-objects")) {
            o->no_objects = 1;
            takes = 0;
        } else if (a[0] != '-' || !strcmp(a, "-")) {
            if (o->scene) return die("more than one scene given: '%s'%s", a, "");
            o->scene = a;
            takes = 0;
        } else if (!takes_value(a)) {
            return die("unknown option '%s' (see --help)%s", a, "");
        } else if (!val) {
            return die("option %s needs a value%s", a, "");
        } else if (!strcmp(a, "--at")) {
            int at = parse_at(o, val);
            if (at == -1)
                return die("--at '%s': expected X,Y or X,Y,Z: two or three decimal numbers such as 128,-64.5%s", val,
                           "");
            if (at == -2)
                return die("--at '%s': outside the map: each coordinate must be above -32768 and below 32768%s", val,
                           "");
        } else if (!strcmp(a, "--angle")) {
            if (fxtext_parse(val, &o->cam.angle_deg)) return die("--angle '%s': expected degrees%s", val, "");
            o->have_angle = 1;
        } else if (!strcmp(a, "--look")) {
            char *end;
            errno = 0;
            long v = strtol(val, &end, 10);
            if (*end || end == val || errno)
                return die("--look '%s': expected a whole number of pixels such as -20%s", val, "");
            if (v < -VIEW_LOOK_MAX || v > VIEW_LOOK_MAX)
                return die("--look '%s': expected whole pixels -100..100%s", val, "");
            o->cam.look = (int32_t)v;
        } else if (!strcmp(a, "--mode")) {
            int m = render_mode_parse(val);
            if (m < 0) return die("--mode '%s': unknown mode (have: direct, spans, painter, columns)%s", val, "");
            o->mode = (render_mode)m;
        } else if (!strcmp(a, "--present")) {
            int m = hal_present_parse(val);
            if (m < 0)
                return die("--present '%s': unknown present mode (have: flip, copy8, copy16, copy32)%s", val, "");
            o->present = (hal_present_mode)m;
        } else if (!strcmp(a, "--split")) {
            if (!strcmp(val, "fewest"))
                o->bspc.split = BSPC_SPLIT_FEWEST;
            else if (!strcmp(val, "balanced"))
                o->bspc.split = BSPC_SPLIT_BALANCED;
            else if (!strcmp(val, "mixed"))
                o->bspc.split = BSPC_SPLIT_MIXED;
            else
                return die("--split '%s': expected fewest, balanced or mixed%s", val, "");
        } else if (!strcmp(a, "-o")) {
            o->png = val;
        } else if (!strcmp(a, "--raw")) {
            o->raw = val;
        } else if (!strcmp(a, "--ids")) {
            o->ids = val;
        } else if (!strcmp(a, "--time")) {
            char *end;
            errno = 0;
            unsigned long long v = strtoull(val, &end, 10);
            if (*end || !*val || val[0] == '-' || errno || v > UINT32_MAX)
                return die("--time '%s': expected whole milliseconds 0..4294967295%s", val, "");
            o->time_ms = (uint32_t)v;
            o->have_time = 1;
        } else if (!strcmp(a, "--link")) {
            o->link = val;
        } else if (!strcmp(a, "--baud")) {
            char *end;
            o->baud = strtol(val, &end, 10);
            if (*end || o->baud <= 0) return die("--baud '%s': expected a speed in bits per second%s", val, "");
        } else if (!strcmp(a, "--objects")) {
            o->objects = val;
        } else if (!strcmp(a, "--door")) {
            const char *eq = strchr(val, '=');
            char *end;
            errno = 0;
            unsigned long v = strtoul(val, &end, 10);
            door_opt *d = &o->doors[o->ndoors];
            if (!eq || end != eq || end == val || val[0] == '-' || errno || v >= SCN_NONE ||
                fxtext_parse(eq + 1, &d->h))
                return die("--door '%s': expected SECTOR=H (a sector number and a height)%s", val, "");
            d->arg = val;
            d->sector = (uint32_t)v;
            o->ndoors++;
        } else if (!strcmp(a, "--repeat")) {
            char *end;
            o->repeat = strtol(val, &end, 10);
            if (*end || o->repeat < 1 || o->repeat > 1000000)
                return die("--repeat '%s': expected 1..1000000%s", val, "");
        } else {
            return die("option %s is not handled%s", a, ""); /* takes_value and this chain disagree */
        }
        i += takes;
    }
    if (!o->scene) return die("no scene given (see --help)%s%s", "", "");
    if (o->objects && o->no_objects) return die("--objects and --no-objects exclude each other%s%s", "", "");
    return 0;
}

#define OBJECTS_LINE_MAX 1022 /* characters of an --objects line, its end not counted */

static void file_error(const char *path, int lineno, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void file_error(const char *path, int lineno, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "render: %s:%d: ", path, lineno);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* An --objects line's words, up to 7 kept (the count goes on, so a line with too
 * many is refused): returns the count. The line is cut at '#' and tokenised in place. */
static int object_words(char *line, char *tok[7])
{
    char *hash = strchr(line, '#');
    if (hash) *hash = 0;
    char *save;
    int nt = 0;
    for (char *t = strtok_r(line, " \t\r\n", &save); t; t = strtok_r(NULL, " \t\r\n", &save))
        if (nt < 7)
            tok[nt++] = t;
        else
            nt++;
    return nt;
}

/* MODEL: a text scene's model name, else a model number below the scene's count. */
static int object_model(const char *path, int lineno, const char *m, const scene *s, const bspc_name *names, int nnames,
                        uint32_t *model)
{
    int named = -1;
    for (int i = 0; i < nnames; i++)
        if (!strcmp(names[i].name, m)) named = i;
    if (named >= 0) {
        *model = (uint32_t)named;
        return 0;
    }
    char *end;
    errno = 0;
    unsigned long v = strtoul(m, &end, 10);
    if (*end || m[0] < '0' || m[0] > '9' || errno || v >= s->nmodels) {
        if (s->nmodels == 0)
            file_error(path, lineno, "model '%s': the scene has no models", m);
        else if (nnames > 0)
            file_error(path, lineno, "model '%s': no model of that name or number (numbers 0..%u)", m,
                       (unsigned)s->nmodels - 1);
        else
            file_error(path, lineno,
                       "model '%s': expected a model number 0..%u (only a text scene's "
                       "models have names)",
                       m, (unsigned)s->nmodels - 1);
        return -1;
    }
    *model = (uint32_t)v;
    return 0;
}

/* X Y Z YAW (xyz[0..3]): numbers, X and Y inside the world box and Z inside the
 * height range, as the loader demands of compiled objects. */
static int object_place(const char *path, int lineno, char *const xyz[4], obj_state *o)
{
    static const char *const what[4] = {"X", "Y", "Z", "YAW"};
    const int64_t coord_max = (int64_t)SCN_COORD_MAX << 16, height_max = (int64_t)SCN_HEIGHT_MAX << 16;
    const int64_t limit[4] = {coord_max, coord_max, height_max, INT32_MAX};
    int64_t v[4];
    int k = 0;
    for (; k < 4; k++) {
        if (fxtext_parse64(xyz[k], &v[k])) {
            file_error(path, lineno, "%s '%s' is not a number", what[k], xyz[k]);
            return -1;
        }
        if (v[k] < -limit[k] || v[k] > limit[k]) break;
    }
    if (k < 2) {
        file_error(path, lineno, "X, Y outside the world box (|coordinate| <= %d)", SCN_COORD_MAX);
        return -1;
    } else if (k == 2) {
        file_error(path, lineno, "Z outside the height range (|Z| <= %d)", SCN_HEIGHT_MAX);
        return -1;
    } else if (k == 3) {
        file_error(path, lineno, "YAW '%s' outside the 16.16 range", xyz[3]);
        return -1;
    }
    o->x = (fx_t)v[0];
    o->y = (fx_t)v[1];
    o->z = (fx_t)v[2];
    o->yaw_deg = (fx_t)v[3];
    return 0;
}

/* One line of getline's (got bytes): 1 and *o for an object, 0 for a blank or
 * comment line, -1 after a message. n objects came before it. */
static int object_line(const char *path, int lineno, char *line, ssize_t got, long n, const scene *s,
                       const bspc_name *names, int nnames, obj_state *o)
{
    if (strlen(line) != (size_t)got) {
        file_error(path, lineno, "holds a NUL byte (not a text file?)");
        return -1;
    }
    if (got > OBJECTS_LINE_MAX + (line[got - 1] == '\n')) {
        file_error(path, lineno, "line longer than %u characters", OBJECTS_LINE_MAX);
        return -1;
    }
    char *tok[7];
    int nt = object_words(line, tok);
    if (nt == 0) return 0;
    if (strcmp(tok[0], "object") || nt != 6) {
        file_error(path, lineno, "expected 'object MODEL X Y Z YAW'");
        return -1;
    }
    if (n >= SCN_MAX_OBJECTS) {
        file_error(path, lineno, "more than %u objects", (unsigned)SCN_MAX_OBJECTS);
        return -1;
    }
    memset(o, 0, sizeof *o);
    if (object_model(path, lineno, tok[1], s, names, nnames, &o->model) || object_place(path, lineno, tok + 2, o))
        return -1;
    return 1;
}

/* --objects FILE: 'object MODEL X Y Z YAW' lines into a malloc'd array. Returns the
 * count, or -1 after a message naming the file and line. */
static long read_objects(const char *path, const char *spec, const scene *s, obj_state **out)
{
    *out = NULL;
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "render: %s: cannot read objects: %s\n", path, strerror(errno));
        return -1;
    }
    bspc_name *names;
    int nnames = bspc_model_names(spec, &names);
    obj_state *objs = NULL;
    long n = 0, rc = -1;
    char *line = NULL;
    size_t cap = 0;
    ssize_t got;
    int lineno = 0;
    if (nnames < 0) {
        fprintf(stderr, "render: out of memory\n");
        goto done;
    }
    while ((got = getline(&line, &cap, f)) >= 0) {
        obj_state o;
        int r = object_line(path, ++lineno, line, got, n, s, names, nnames, &o);
        if (r < 0) goto done;
        if (r == 0) continue;
        obj_state *grown = realloc(objs, sizeof *objs * (size_t)(n + 1));
        if (!grown) {
            fprintf(stderr, "render: out of memory\n");
            goto done;
        }
        objs = grown;
        objs[n++] = o;
    }
    if (ferror(f)) {
        fprintf(stderr, "render: %s: cannot read objects: %s\n", path, strerror(errno));
        goto done;
    }
    rc = n;
    *out = objs;
    objs = NULL;
done:
    free(objs);
    free(names);
    free(line);
    fclose(f);
    return rc;
}

/* The door options, after --time: each must name a door and a ceiling between its closed
 * and open heights, so the renderer sees only states a door can be in. */
/* Options that ask for more than the scene (its declaration) or this build
 * (build_config.h) provides. */
static int refuse_beyond_scene(const options *o, const scene *s)
{
    const char *why = 0;
    if (o->cam.look && !(s->needs->features & SCN_NEED_LOOK))
        why = "--look: the scene keeps its horizon level (it says 'look off')";
    else if (o->objects && !CFG_OBJECTS)
        why = "--objects: this build leaves out objects (it was built for a scene without them)";
    else if (o->ndoors && !CFG_DOORS)
        why = "--door: this build leaves out doors (it was built for a scene without them)";
    if (why) fprintf(stderr, "render: %s: %s\n", o->scene, why);
    return why != 0;
}

/* 1 when (x, y) lies in no sector: the first wall a ray to the east meets
 * has no sector on the side facing the point, or the ray meets no wall at
 * all. The same answer as the compiler's winding number for closed sectors. */
static int in_void(const scene *s, fx_t x, fx_t y)
{
    __int128 best_hx = -1; /* the nearest crossing so far, best_hx / best_dy past x; none yet */
    int64_t best_dy = 1;
    uint32_t sector = SCN_NONE;
    for (uint32_t i = 0; i < s->nlines; i++) {
        const scn_line *l = &s->lines[i];
        const scn_vertex *a = &s->verts[l->v1], *b = &s->verts[l->v2];
        if ((a->y > y) == (b->y > y)) continue; /* half-open: a vertex on the ray counts once */
        /* where the wall crosses the ray's line, as hx / dy past x (dy != 0) */
        int64_t dy = (int64_t)b->y - a->y;
        __int128 hx = (__int128)((int64_t)a->x - x) * dy + (__int128)((int64_t)b->x - a->x) * ((int64_t)y - a->y);
        if (dy < 0) {
            dy = -dy;
            hx = -hx;
        }
        if (hx < 0) continue;
        /* hx / dy against the best so far without dividing: 16.16 coordinates
         * differ by less than 2^33, so |hx| < 2^67 and dy < 2^33, products < 2^100 */
        if (best_hx >= 0 && hx * best_dy >= best_hx * dy) continue;
        best_hx = hx;
        best_dy = dy;
        /* the front side is on the right going v1 -> v2: a wall going up (north)
         * has its front to the east, away from the point */
        sector = l->sector[b->y > a->y ? 1 : 0];
    }
    return sector == SCN_NONE;
}

static int apply_doors(const options *o, const scene *s, world_state *w)
{
    for (int i = 0; i < o->ndoors; i++) {
        const door_opt *d = &o->doors[i];
        if (d->sector >= s->nsectors || !(s->sectors[d->sector].flags & SCN_SECTOR_DOOR)) {
            fprintf(stderr, "render: --door '%s': sector %u is not a door of %s\n", d->arg, (unsigned)d->sector,
                    o->scene);
            return -1;
        }
        const scn_sector *sec = &s->sectors[d->sector];
        if (d->h < sec->ceil_h || d->h > sec->open_h) {
            char lo[48], hi[48];
            fxtext_format(sec->ceil_h, lo, sizeof lo);
            fxtext_format(sec->open_h, hi, sizeof hi);
            fprintf(stderr, "render: --door '%s': the door moves between %s (closed) and %s (open)\n", d->arg, lo, hi);
            return -1;
        }
        w->ceil[d->sector] = d->h;
    }
    return 0;
}

/* An output file can be written where it is named: an existing file (not a
 * folder) we may write, or a new one in a folder we may write. 0, or -1 with
 * errno set. */
static int out_writable(const char *path)
{
    struct stat st;
    if (stat(path, &st) == 0) {
        if (S_ISDIR(st.st_mode)) {
            errno = EISDIR;
            return -1;
        }
        return access(path, W_OK);
    }
    if (errno != ENOENT) return -1;
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!slash) return access(".", W_OK);
    if ((size_t)(slash - path) >= sizeof dir) {
        errno = ENAMETOOLONG;
        return -1;
    }
    snprintf(dir, sizeof dir, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    return access(dir, W_OK);
}

/* The output files before any work: a frame is not rendered for nowhere. */
static int check_outputs(const options *o)
{
    const char *const paths[3] = {o->png, o->raw, o->ids};
    static const char *const opts[3] = {"-o", "--raw", "--ids"};
    for (int i = 0; i < 3; i++)
        if (paths[i] && out_writable(paths[i]) != 0) {
            fprintf(stderr, "render: %s %s: cannot write there: %s\n", opts[i], paths[i], strerror(errno));
            return -1;
        }
    return 0;
}

static int write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    size_t w = fwrite(data, 1, n, f);
    return (fclose(f) == 0 && w == n) ? 0 : -1;
}

static void print_fx(const char *key, int32_t v, const char *sep)
{
    char buf[48];
    fxtext_format(v, buf, sizeof buf);
    printf("\"%s\": %s%s", key, buf, sep);
}

static void print_json(const options *o, const engine *e, uint32_t crc, const link_sender *sender)
{
    const camera *c = &e->cam.view;
    uint64_t pixels = hal_perf_event(HAL_EV_PIXELS);
    printf("{\"scene\": \"");
    for (const char *p = o->scene; *p; p++) {
        if (*p == '"' || *p == '\\') putchar('\\');
        if ((unsigned char)*p >= 0x20) putchar(*p);
    }
    printf("\", \"camera\": {");
    print_fx("x", c->x, ", ");
    print_fx("y", c->y, ", ");
    print_fx("z", c->z, ", ");
    print_fx("angle", c->angle_deg, ", ");
    printf("\"look\": %d}, ", (int)c->look);
    printf("\"mode\": \"%s\", \"present\": \"%s\", \"textured\": %d, ", render_mode_name(e->mode),
           hal_present_name(e->present), eng_textured(e));
    printf("\"crc32\": \"%08x\", \"pixels_written\": %llu, \"overdraw\": %llu.%03llu, ", (unsigned)crc,
           (unsigned long long)pixels, (unsigned long long)(pixels / HAL_PAGE_BYTES),
           (unsigned long long)((pixels % HAL_PAGE_BYTES) * 1000 / HAL_PAGE_BYTES));
    for (int ev = 0; ev < HAL_EV_COUNT; ev++)
        printf("\"%s\": %llu, ", hal_event_name((hal_event)ev), (unsigned long long)hal_perf_event((hal_event)ev));
    hal_bus_model bus = hal_perf_bus();
    printf("\"bus_cycles\": %llu, \"bus_model\": {\"vram_cycles\": %u, \"sysmem_cycles\": %u}, ",
           (unsigned long long)hal_perf_tsc(), bus.vram_cycles, bus.sysmem_cycles);
    const render_stats *st = &e->stats;
    printf("\"nodes\": %u, \"boxes_culled\": %u, \"leaves\": %u, \"segs\": %u, \"culled\": %u, "
           "\"polygons\": %u, \"occluded\": %u, \"edges\": %u, \"spans\": %u, \"work_bytes\": %u, \"frames\": %ld, ",
           st->nodes, st->boxes_culled, st->leaves, st->segs, st->culled, st->polygons, st->occluded, st->edges,
           st->spans, e->work.bytes, o->repeat);
    printf("\"object_pass\": %u, \"overflow\": %u, \"flushes\": %u, \"yclip_skipped\": %u, \"planes_skipped\": %u, "
           "\"fallback\": %u, \"features\": %u, \"build_features\": %u, ",
           st->object_pass, st->overflow, st->flushes, st->yclip_skipped, st->planes_skipped, st->fallback,
           e->sc.needs->features, (unsigned)CFG_FEATURES);
    printf("\"objects_visible\": %u, \"object_faces\": %u, \"objects\": [", st->objects_visible, st->object_faces);
    const world_state *w = &e->world;
    for (uint32_t i = 0; i < w->n; i++) {
        const obj_state *ob = &w->objs[i];
        printf("%s{\"model\": %u, ", i ? ", " : "", (unsigned)ob->model);
        print_fx("x", ob->x, ", ");
        print_fx("y", ob->y, ", ");
        print_fx("z", ob->z, ", ");
        print_fx("yaw", ob->yaw_deg, "}");
    }
    printf("], \"ceilings\": {");
    int first = 1;
    for (uint32_t i = 0; i < e->sc.nsectors; i++) {
        fx_t h = obj_ceil(w, &e->sc, i);
        if (h == e->sc.sectors[i].ceil_h) continue;
        char key[16];
        snprintf(key, sizeof key, "%u", (unsigned)i);
        printf("%s", first ? "" : ", ");
        print_fx(key, h, "");
        first = 0;
    }
    printf("}");
    if (sender) {
        printf(", \"link\": ");
        link_print_json(sender, stdout);
    }
    printf("}\n");
}

/* --link: hello, palette and the frame as a keyframe, then its ack awaited
 * (at most the ack timeout). 0, or -1 after a message naming the port. */
static int send_link(link_sender *l, const engine *e, const uint8_t *frame, const char *scene_name, const uint8_t *blob,
                     size_t blob_len)
{
    fl_frame_info info = fl_engine_info(e);
    if (link_hello(l, scene_name, blob, blob_len) == 0 && link_frame(l, 0, frame, hal_get_palette(), &info) == 0 &&
        link_finish(l) == 0)
        return 0;
    fprintf(stderr, "render: --link %s\n", link_error(l));
    return -1;
}

/* The scene, with --objects' objects in place of its own when given: 0, or 1
 * after a message (then nothing is left open). */
static int open_scene(const options *o, scene_start *st, engine *e, obj_state **file_objs, long *nfile)
{
    char err[512];
    *file_objs = NULL;
    *nfile = 0;
    hal_null_reset();
    if (scene_start_open(st, e, o->scene, &o->bspc, NULL, 0, err, sizeof err) != 0) {
        fprintf(stderr, "render: %s\n", err);
        return 1;
    }
    if (refuse_beyond_scene(o, &e->sc)) {
        scene_start_close(st);
        return 1;
    }
    if (o->objects && (*nfile = read_objects(o->objects, o->scene, &e->sc, file_objs)) < 0) {
        scene_start_close(st);
        return 1;
    }
    world_state mine = {*file_objs, (uint32_t)*nfile, 0, 0};
    if (scene_start_work(st, e, o->objects ? &mine : NULL, err, sizeof err) != 0) {
        fprintf(stderr, "render: %s\n", err);
        free(*file_objs);
        scene_start_close(st);
        return 1;
    }
    return 0;
}

/* The drawing options and the camera: --at, --angle, --look, and the eye
 * height (the floor under the eye + CAM_EYE_HEIGHT unless --at gave Z). */
static void set_view(const options *o, engine *e)
{
    e->mode = o->mode;
    e->present = o->present;
    e->flat = (uint8_t)o->flat;
    if (o->have_at) {
        e->cam.view.x = o->cam.x;
        e->cam.view.y = o->cam.y;
    }
    if (o->have_angle) e->cam.view.angle_deg = o->cam.angle_deg;
    e->cam.view.look = o->cam.look;
    if (o->have_z) {
        e->cam.view.z = o->cam.z;
    } else {
        e->cam.view.z = CAM_EYE_HEIGHT;
        cam_follow_floor(&e->cam, &e->sc);
    }
}

/* The world at --time with --door's ceilings and the objects asked for: 0, or
 * -1 after a message. */
static int set_world(const options *o, engine *e, obj_state *file_objs, long nfile)
{
    /* Paths are exact functions of t and a door's motion depends only on the total time,
     * so one update from time 0 stands for every frame in between, the player at the camera. */
    if (o->have_time) {
        e->t_ms = o->time_ms;
        obj_update(&e->world, &e->sc, o->time_ms, o->time_ms, e->cam.view.x, e->cam.view.y);
    }
    if (apply_doors(o, &e->sc, &e->world) != 0) return -1;
    if (in_void(&e->sc, e->cam.view.x, e->cam.view.y))
        fprintf(stderr, "render: warning: the camera is outside every sector of %s: the frame shows the void\n",
                o->scene);
    if (o->objects) {
        e->world.objs = file_objs;
        e->world.own = NULL; /* the file's objects are models */
        e->world.n = (uint32_t)nfile;
    } else if (o->no_objects) {
        e->world.n = 0;
    }
    return 0;
}

/* The id buffer as 4 little-endian bytes per pixel. */
static int write_ids(const char *path, const uint32_t *ids)
{
    uint8_t *bytes = malloc((size_t)HAL_PAGE_BYTES * 4);
    for (int i = 0; bytes && i < HAL_PAGE_BYTES; i++)
        for (int k = 0; k < 4; k++) bytes[i * 4 + k] = (uint8_t)(ids[i] >> (8 * k));
    int rc = (!bytes || write_file(path, bytes, (size_t)HAL_PAGE_BYTES * 4) != 0) ? -1 : 0;
    int why = errno; /* for the caller's message */
    free(bytes);
    errno = why;
    return rc;
}

/* The frame to every place asked (--png, --raw, --ids, --link): 1 if any failed,
 * after a message. */
static int write_outputs(const options *o, const engine *e, const uint8_t *frame, const uint32_t *ids,
                         link_sender *sender, const scene_start *st)
{
    int failed = 0;
    if (o->png && png_write_indexed(o->png, frame, HAL_WIDTH, HAL_HEIGHT, hal_get_palette()) != 0)
        failed = fprintf(stderr, "render: %s: cannot write PNG: %s\n", o->png, strerror(errno));
    if (o->raw && write_file(o->raw, frame, HAL_PAGE_BYTES) != 0)
        failed = fprintf(stderr, "render: %s: cannot write frame: %s\n", o->raw, strerror(errno));
    if (ids && write_ids(o->ids, ids) != 0)
        failed = fprintf(stderr, "render: %s: cannot write id buffer: %s\n", o->ids, strerror(errno));
    if (o->link && send_link(sender, e, frame, o->scene, st->data, st->len) != 0) failed = 1;
    return failed != 0;
}

int main(int argc, char **argv)
{
    options o;
    memset(&o, 0, sizeof o);
    o.mode = render_mode_default();
    o.present = HAL_PRESENT_FLIP;
    o.bspc = bspc_defaults();
    o.repeat = 1;
    o.baud = PORT_DEFAULT_BAUD;
    door_opt doors[argc > 0 ? argc : 1];
    o.doors = doors;
    int rc = parse_args(&o, argc, argv);
    if (rc) return rc;

    if (check_outputs(&o) != 0) return 1;
    /* the port first: a PORT that does not open is a bad option, found before any work */
    static link_sender sender;
    char err[512];
    if (o.link && link_open(&sender, o.link, o.baud, err, sizeof err) != 0) {
        fprintf(stderr, "render: --link %s\n", err);
        return 2;
    }
    static engine e;
    scene_start st;
    obj_state *file_objs;
    long nfile;
    if (open_scene(&o, &st, &e, &file_objs, &nfile)) return 1;
    set_view(&o, &e);
    if (set_world(&o, &e, file_objs, nfile) != 0) {
        free(file_objs);
        scene_start_close(&st);
        return 1;
    }

    uint32_t *ids = o.ids ? calloc(HAL_PAGE_BYTES, sizeof *ids) : NULL;
    for (long i = 0; i < o.repeat; i++) {
        hal_perf_reset();
        eng_render(&e, ids);
    }
    const uint8_t *frame = hal_shown_page();
    uint32_t crc = crc_update(0, frame, HAL_PAGE_BYTES);
    int failed = write_outputs(&o, &e, frame, ids, &sender, &st);
    /* the counters only of a frame that went everywhere it was asked to go */
    if (!failed) print_json(&o, &e, crc, o.link ? &sender : NULL);
    if (o.link) link_close(&sender);
    free(ids);
    free(file_objs);
    scene_start_close(&st);
    return failed ? 1 : 0;
}
