/* render.c - build/render: the headless renderer CLI. Scene + camera + mode +
 * present mode in; PNG, raw frame, surface-id buffer and one JSON object of
 * counters out. Runs the firmware on the null target. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "crc32.h"
#include "engine.h"
#include "fxtext.h"
#include "hal.h"
#include "hal_null.h"
#include "png.h"
#include "scene_file.h"

static const char usage[] =
    "usage: render SCENE [--at X,Y[,Z]] [--angle DEG] [options]\n"
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
    "  --mode MODE        spans (zero overdraw, the default) or painter (back to\n"
    "                     front, Listing 62.1)\n"
    "  --present P        flip | copy8 | copy16 | copy32 (default flip)\n"
    "  --split S          BSP split strategy when compiling a source: fewest |\n"
    "                     balanced | mixed (default mixed)\n"
    "  -o FILE.png        write the frame as a PNG (palette indices kept exactly)\n"
    "  --raw FILE         write the 64,000 frame bytes\n"
    "  --ids FILE         write the surface-id buffer: 320x200 little-endian uint32,\n"
    "                     kind << 24 | index (0 none, 1 wall, 2 floor, 3 ceiling, 4 object)\n"
    "  --repeat N         render the same frame N times (default 1); counters are\n"
    "                     those of the last frame\n"
    "  -h, --help         this text\n";

typedef struct {
    const char *scene, *png, *raw, *ids;
    camera cam;
    int have_at, have_z, have_angle;
    render_mode mode;
    hal_present_mode present;
    bspc_options bspc;
    long repeat;
} options;

static int die(const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "render: ");
    fprintf(stderr, fmt, a, b);
    fputc('\n', stderr);
    return 2;
}

static int parse_at(options *o, char *arg)
{
    char *parts[4];
    int n = 0;
    for (char *tok = strtok(arg, ","); tok && n < 4; tok = strtok(NULL, ",")) parts[n++] = tok;
    if (n < 2 || n > 3) return -1;
    if (fxtext_parse(parts[0], &o->cam.x) || fxtext_parse(parts[1], &o->cam.y)) return -1;
    if (n == 3) {
        if (fxtext_parse(parts[2], &o->cam.z)) return -1;
        o->have_z = 1;
    }
    o->have_at = 1;
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
        } else if (a[0] != '-' || !strcmp(a, "-")) {
            if (o->scene) return die("more than one scene given: '%s'%s", a, "");
            o->scene = a;
            takes = 0;
        } else if (!val) {
            return die("option %s needs a value%s", a, "");
        } else if (!strcmp(a, "--at")) {
            char buf[256];
            snprintf(buf, sizeof buf, "%s", val);
            if (parse_at(o, buf)) return die("--at '%s': expected X,Y or X,Y,Z in map units (|v| < 32768)%s", val, "");
        } else if (!strcmp(a, "--angle")) {
            if (fxtext_parse(val, &o->cam.angle_deg)) return die("--angle '%s': expected degrees%s", val, "");
            o->have_angle = 1;
        } else if (!strcmp(a, "--look")) {
            char *end;
            long v = strtol(val, &end, 10);
            if (*end || v < -VIEW_LOOK_MAX || v > VIEW_LOOK_MAX) return die("--look '%s': expected whole pixels -100..100%s", val, "");
            o->cam.look = (int32_t)v;
        } else if (!strcmp(a, "--mode")) {
            int m = render_mode_parse(val);
            if (m < 0) return die("--mode '%s': unknown mode (have: spans, painter)%s", val, "");
            o->mode = (render_mode)m;
        } else if (!strcmp(a, "--present")) {
            int m = hal_present_parse(val);
            if (m < 0) return die("--present '%s': unknown present mode (have: flip, copy8, copy16, copy32)%s", val, "");
            o->present = (hal_present_mode)m;
        } else if (!strcmp(a, "--split")) {
            if (!strcmp(val, "fewest")) o->bspc.split = BSPC_SPLIT_FEWEST;
            else if (!strcmp(val, "balanced")) o->bspc.split = BSPC_SPLIT_BALANCED;
            else if (!strcmp(val, "mixed")) o->bspc.split = BSPC_SPLIT_MIXED;
            else return die("--split '%s': expected fewest, balanced or mixed%s", val, "");
        } else if (!strcmp(a, "-o")) {
            o->png = val;
        } else if (!strcmp(a, "--raw")) {
            o->raw = val;
        } else if (!strcmp(a, "--ids")) {
            o->ids = val;
        } else if (!strcmp(a, "--repeat")) {
            char *end;
            o->repeat = strtol(val, &end, 10);
            if (*end || o->repeat < 1 || o->repeat > 1000000) return die("--repeat '%s': expected 1..1000000%s", val, "");
        } else {
            return die("unknown option '%s' (see --help)%s", a, "");
        }
        i += takes;
    }
    if (!o->scene) return die("no scene given (see --help)%s%s", "", "");
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

static void print_json(const options *o, const engine *e, uint32_t crc)
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
    printf("\"mode\": \"%s\", \"present\": \"%s\", ", render_mode_name(e->mode), hal_present_name(e->present));
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
           "\"polygons\": %u, \"occluded\": %u, \"edges\": %u, \"spans\": %u, \"work_bytes\": %u, \"frames\": %ld}\n",
           st->nodes, st->boxes_culled, st->leaves, st->segs, st->culled, st->polygons, st->occluded, st->edges,
           st->spans, e->work.bytes, o->repeat);
}

int main(int argc, char **argv)
{
    options o;
    memset(&o, 0, sizeof o);
    o.mode = RENDER_SPANS;
    o.present = HAL_PRESENT_FLIP;
    o.bspc = bspc_defaults();
    o.repeat = 1;
    int rc = parse_args(&o, argc, argv);
    if (rc) return rc;

    char err[512];
    uint8_t *blob;
    size_t len;
    if (scene_file_load(o.scene, &o.bspc, &blob, &len, err, sizeof err) != 0) {
        fprintf(stderr, "render: %s\n", err);
        return 1;
    }
    static engine e;
    scene_error se;
    hal_null_reset();
    if (len > UINT32_MAX || eng_init(&e, blob, (uint32_t)len, &se) != SCENE_OK) {
        scene_file_describe_error(o.scene, se.status, se.section, se.index, err, sizeof err);
        fprintf(stderr, "render: %s\n", err);
        free(blob);
        return 1;
    }
    uint32_t need = eng_work_bytes(&e);
    void *work = need ? malloc(need) : NULL;
    if (!work || eng_set_work(&e, work, need) != 0) {
        fprintf(stderr, "render: %s: the scene needs %u bytes of work memory, which could not be had\n", o.scene, need);
        free(work);
        free(blob);
        return 1;
    }
    e.mode = o.mode;
    e.present = o.present;
    if (o.have_at) {
        e.cam.view.x = o.cam.x;
        e.cam.view.y = o.cam.y;
    }
    if (o.have_angle) e.cam.view.angle_deg = o.cam.angle_deg;
    e.cam.view.look = o.cam.look;
    if (o.have_z) {
        e.cam.view.z = o.cam.z;
    } else {
        e.cam.view.z = CAM_EYE_HEIGHT;
        cam_follow_floor(&e.cam, &e.sc);
    }

    uint32_t *ids = o.ids ? calloc(HAL_PAGE_BYTES, sizeof *ids) : NULL;
    for (long i = 0; i < o.repeat; i++) {
        hal_perf_reset();
        eng_render(&e, ids);
    }
    const uint8_t *frame = hal_shown_page();
    uint32_t crc = crc_update(0, frame, HAL_PAGE_BYTES);

    int failed = 0;
    if (o.png && png_write_indexed(o.png, frame, HAL_WIDTH, HAL_HEIGHT, hal_get_palette()) != 0)
        failed = fprintf(stderr, "render: %s: cannot write PNG: %s\n", o.png, strerror(errno));
    if (o.raw && write_file(o.raw, frame, HAL_PAGE_BYTES) != 0)
        failed = fprintf(stderr, "render: %s: cannot write frame: %s\n", o.raw, strerror(errno));
    if (ids) {
        uint8_t *bytes = malloc((size_t)HAL_PAGE_BYTES * 4);
        for (int i = 0; bytes && i < HAL_PAGE_BYTES; i++)
            for (int k = 0; k < 4; k++) bytes[i * 4 + k] = (uint8_t)(ids[i] >> (8 * k));
        if (!bytes || write_file(o.ids, bytes, (size_t)HAL_PAGE_BYTES * 4) != 0)
            failed = fprintf(stderr, "render: %s: cannot write id buffer: %s\n", o.ids, strerror(errno));
        free(bytes);
    }
    print_json(&o, &e, crc);
    free(ids);
    free(work);
    free(blob);
    return failed ? 1 : 0;
}
