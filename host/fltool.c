/* fltool.c - build/fltool: the frame link on the host, for tests and benchmarks.
 *
 *   fltool walk SCENE [--frames N] [--dt MS] [--out DIR] [--flat]
 *       A deterministic fly-through: an autopilot walks the camera through the
 *       scene from the player start (the firmware's own camera and collision,
 *       eng_step at DT ms per frame, default 50 = 20 fps) along corridors. Writes
 *       DIR/frames.raw (N x 64,000 bytes) and DIR/frames.jsonl (one line per
 *       frame: number, crc32, the camera exactly as the firmware used it, raw and
 *       as exact decimals, mode, present) and DIR/palette.bin (768 bytes).
 *       --flat draws a textured scene in its flat colours (the cameras are
 *       the same: drawing does not steer the walk). --keys STEPS replaces the
 *       autopilot by a script (for tests of what happens over time, such as
 *       doors): STEPS is KEYS*N[,KEYS*N...], KEYS letters held for N frames,
 *       f forward, b back, l turn left, r turn right, '-' nothing; it sets the
 *       number of frames. Each line also has the time (t_ms) and the ceilings
 *       not at their compiled height, as build/render's JSON has them.
 *   fltool encode FRAMES.raw --out STREAM [--info FRAMES.jsonl] [--palette P.bin]
 *                 [--key-interval N] [--scratch BYTES] [--sizes] [--scene NAME [--scene-crc HEX]]
 *                 [--no-match-finder]
 *       Encodes the frames with the C encoder (hello, palette, then one frame
 *       message each: keyframe or delta against the previous frame) into a byte
 *       stream file; its hello names the scene NAME, blob CRC-32 HEX (default:
 *       none). --sizes prints one JSON line per frame (bytes on the wire,
 *       keyframe or not). Textured frames go with the COPY coding and its match
 *       finder, as build/emu and build/render send them; --no-match-finder
 *       codes them as the firmware does, without one.
 *   fltool decode STREAM [--chunk N] [--frames-out FILE]
 *       Feeds the stream to the C decoder (in chunks of N bytes, default 4096)
 *       and prints one JSON line per event and a final line with the counters.
 *       --frames-out appends every shown frame's 64,000 bytes to FILE.
 *   fltool bench FRAMES.raw [--key-interval N] [--repeat R]
 *       Encodes the frames R times (for callgrind: instructions per frame are
 *       the difference between two R's) without writing anything.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "crc32.h"
#include "engine.h"
#include "collide.h"
#include "framelink.h"
#include "fxtext.h"
#include "hal.h"
#include "hal_null.h"
#include "scene_start.h"

static int usage_to(FILE *f, int rc)
{
    fputs("usage: fltool walk SCENE [--frames N] [--dt MS] [--out DIR] [--flat] [--keys STEPS]\n"
          "       fltool encode FRAMES.raw --out STREAM [--info FRAMES.jsonl] [--palette P.bin]\n"
          "                     [--key-interval N] [--scratch BYTES] [--sizes] [--no-match-finder]\n"
          "       fltool decode STREAM [--chunk N] [--frames-out FILE]\n"
          "       fltool bench FRAMES.raw [--key-interval N] [--repeat R] [--crc]\n"
          "       fltool digest FRAMES.raw\n"
          "       fltool --help\n",
          f);
    return rc;
}

static int usage(void)
{
    return usage_to(stderr, 2);
}

static uint8_t *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 20, n = 0;
    uint8_t *buf = malloc(cap);
    for (;;) {
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (n < cap) break;
        cap *= 2;
        buf = realloc(buf, cap);
    }
    fclose(f);
    *len = n;
    return buf;
}

/* ---- walk ------------------------------------------------------------------ */

/* Cells of 64 units visited by the walk (the autopilot prefers new ground). */
#define CELL_SHIFT 22 /* 64 units in 16.16 */
#define CELLS 1024
static uint8_t *visits;
static uint8_t *cell(fx_t x, fx_t y)
{
    uint32_t cx = (uint32_t)((x >> CELL_SHIFT) + CELLS / 2) % CELLS,
             cy = (uint32_t)((y >> CELL_SHIFT) + CELLS / 2) % CELLS;
    return &visits[cy * CELLS + cx];
}

/* Clear distance (units, multiple of 16, at most maxd) from (x, y) along deg at
 * height z, and the novelty of the ground along it (*score: more for cells
 * visited less often). */
static int free_dist(const scene *s, fx_t x, fx_t y, fx_t z, int deg, int maxd, int *score)
{
    fx_ang_t a = fx_ang_from_deg((fx_t)(((deg % 360) + 360) % 360) * FX_ONE);
    int64_t c = fx_cos(a), sn = fx_sin(a);
    int d, sc = 0;
    for (d = 16; d <= maxd; d += 16) {
        fx_t px = (fx_t)(x + ((c * d * FX_ONE) >> FX_TRIG_SHIFT));
        fx_t py = (fx_t)(y + ((sn * d * FX_ONE) >> FX_TRIG_SHIFT));
        if (!col_line_of_sight(s, NULL, x, y, z, px, py, z)) break;
        sc += 64 / (1 + *cell(px, py));
    }
    if (score) *score = sc;
    return d - 16;
}

static int deg_of(fx_t a)
{
    return (int)(((a + FX_HALF) >> FX_SHIFT) % 360 + 360) % 360;
}

static int ang_diff(int a, int b) /* a - b in (-180, 180] */
{
    int d = ((a - b) % 360 + 360) % 360;
    return d > 180 ? d - 360 : d;
}

/* One script step "KEYS*N" at *p: the keys into *keys, N into *n; the end of the step, or NULL. */
static const char *key_step(const char *p, uint32_t *keys, long *n)
{
    *keys = 0;
    for (; *p && *p != '*'; p++) {
        switch (*p) {
        case 'f': *keys |= HAL_KEY_FORWARD; break;
        case 'b': *keys |= HAL_KEY_BACK; break;
        case 'l': *keys |= HAL_KEY_TURN_LEFT; break;
        case 'r': *keys |= HAL_KEY_TURN_RIGHT; break;
        case '-': break;
        default: return NULL;
        }
    }
    if (*p != '*') return NULL;
    char *end;
    *n = strtol(p + 1, &end, 10);
    if (end == p + 1 || *n < 1 || *n > 100000 || (*end && *end != ',')) return NULL;
    return end;
}

/* The keys the script holds at frame n; -1 if the script is malformed, 0 past its end. */
static long script_keys(const char *script, long n, long *total)
{
    uint32_t keys = 0, at = 0;
    long count, sum = 0, found = -1;
    for (const char *p = script; *p;) {
        if (!(p = key_step(p, &keys, &count))) return -1;
        if (found < 0 && n < sum + count) at = keys, found = 1;
        sum += count;
        if (*p == ',') p++;
    }
    if (total) *total = sum;
    return found < 0 ? 0 : (long)at;
}

static void print_ceilings(FILE *f, const engine *e)
{
    fprintf(f, "\"ceilings\": {");
    int first = 1;
    for (uint32_t i = 0; i < e->sc.nsectors; i++) {
        fx_t h = obj_ceil(&e->world, &e->sc, i);
        if (h == e->sc.sectors[i].ceil_h) continue;
        char key[16], buf[48];
        snprintf(key, sizeof key, "%u", (unsigned)i);
        fxtext_format(h, buf, sizeof buf);
        fprintf(f, "%s\"%s\": %s", first ? "" : ", ", key, buf);
        first = 0;
    }
    fprintf(f, "}");
}

static void print_fx(FILE *f, const char *key, int32_t v, const char *sep)
{
    char buf[48];
    fxtext_format(v, buf, sizeof buf);
    fprintf(f, "\"%s\": %s%s", key, buf, sep);
}

/* Create dir and any missing parents (mkdir -p). 0, or -1 with errno set (a
 * part that exists and is not a folder: ENOTDIR). */
static int make_dirs(const char *dir)
{
    char p[4096];
    size_t n = strlen(dir);
    if (n == 0 || n >= sizeof p) {
        errno = ENAMETOOLONG;
        return -1;
    }
    memcpy(p, dir, n + 1);
    for (size_t i = 1; i <= n; i++) {
        if (p[i] != '/' && p[i] != '\0') continue;
        char c = p[i];
        p[i] = '\0';
        struct stat st;
        if (stat(p, &st) != 0) {
            if (mkdir(p, 0777) != 0 && errno != EEXIST) return -1;
        } else if (!S_ISDIR(st.st_mode)) {
            errno = ENOTDIR;
            return -1;
        }
        p[i] = c;
    }
    return 0;
}

static int cmd_walk(int argc, char **argv)
{
    const char *spec = NULL, *out = ".", *script = NULL;
    long frames = 200, dt = 50;
    int flat = 0;
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--frames") && i + 1 < argc)
            frames = atol(argv[++i]);
        else if (!strcmp(argv[i], "--flat"))
            flat = 1;
        else if (!strcmp(argv[i], "--dt") && i + 1 < argc)
            dt = atol(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc)
            out = argv[++i];
        else if (!strcmp(argv[i], "--keys") && i + 1 < argc)
            script = argv[++i];
        else if (argv[i][0] != '-' && !spec)
            spec = argv[i];
        else
            return usage();
    }
    if (script && script_keys(script, 0, &frames) < 0) {
        fprintf(stderr, "fltool: --keys '%s': expected KEYS*N[,KEYS*N...], KEYS of f b l r -\n", script);
        return 2;
    }
    if (!spec || frames < 1 || dt < 1) return usage();
    char err[512];
    bspc_options opt = bspc_defaults();
    static engine e;
    scene_start st;
    hal_null_reset();
    if (scene_start_load(&st, &e, spec, &opt, NULL, 0, err, sizeof err) != 0) {
        fprintf(stderr, "fltool: %s\n", err);
        return 1;
    }
    e.flat = (uint8_t)flat;

    char path[4096];
    if (make_dirs(out) != 0) {
        fprintf(stderr, "fltool: cannot create the folder %s: %s\n", out, strerror(errno));
        return 1;
    }
    snprintf(path, sizeof path, "%s/frames.raw", out);
    FILE *fr = fopen(path, "wb");
    snprintf(path, sizeof path, "%s/frames.jsonl", out);
    FILE *fj = fopen(path, "w");
    snprintf(path, sizeof path, "%s/palette.bin", out);
    FILE *fp = fopen(path, "wb");
    if (!fr || !fj || !fp) {
        fprintf(stderr, "fltool: cannot write into %s\n", out);
        return 1;
    }
    fwrite(hal_get_palette(), 1, HAL_PALETTE_BYTES, fp);
    fclose(fp);

    /* The autopilot: head for a target direction; when the way ahead closes in,
     * pick the most open direction (not backwards if anything else is open);
     * now and then take a wider opening to the side. */
    visits = calloc(CELLS * CELLS, 1);
    int target = deg_of(e.cam.view.angle_deg), stuck = 0;
    fx_t lastx = e.cam.view.x, lasty = e.cam.view.y;
    for (long n = 0; n < frames; n++) {
        const camera *c = &e.cam.view;
        fx_t z = e.cam.feet + 32 * FX_ONE;
        int here = deg_of(c->angle_deg);
        if (*cell(c->x, c->y) < 255) (*cell(c->x, c->y))++;
        int ahead = free_dist(&e.sc, c->x, c->y, z, target, 512, NULL);
        if (ahead < 96 || stuck > 8 || (n % 30 == 29)) {
            int best = target, bestd = -1;
            static const int ks[] = {0, 1, -1, 2, -2, 3, -3, 4, -4, 5, -5, 6};
            for (unsigned k = 0; k < sizeof ks / sizeof ks[0]; k++) {
                int cand = ((target + ks[k] * 30) % 360 + 360) % 360, d;
                if (free_dist(&e.sc, c->x, c->y, z, cand, 1024, &d) < 64) d = 0;
                if (abs(ks[k]) >= 4) d /= 2;              /* turning back only if nothing else */
                if (ahead >= 96 && k == 0) d = d * 3 / 2; /* a re-look keeps the heading unless much better */
                if (stuck > 8 && k == 0) d = 0;
                if (d > bestd) bestd = d, best = cand;
            }
            target = best;
            stuck = 0;
        }
        int diff = ang_diff(target, here);
        uint32_t keys = 0;
        if (diff > 3) keys |= HAL_KEY_TURN_LEFT;
        if (diff < -3) keys |= HAL_KEY_TURN_RIGHT;
        if (abs(diff) < 60 && free_dist(&e.sc, c->x, c->y, z, here, 32, NULL) >= 16) keys |= HAL_KEY_FORWARD;
        if (script) keys = (uint32_t)script_keys(script, n, NULL);
        eng_step(&e, keys, (uint32_t)dt);
        if ((keys & HAL_KEY_FORWARD) && c->x == lastx && c->y == lasty)
            stuck++;
        else if (keys & HAL_KEY_FORWARD)
            stuck = stuck > 0 ? stuck - 1 : 0;
        lastx = c->x;
        lasty = c->y;

        const uint8_t *px = hal_shown_page();
        fwrite(px, 1, HAL_PAGE_BYTES, fr);
        fprintf(fj, "{\"frame\": %ld, \"crc32\": \"%08x\", \"camera\": {", n,
                (unsigned)crc_update(0, px, HAL_PAGE_BYTES));
        print_fx(fj, "x", c->x, ", ");
        print_fx(fj, "y", c->y, ", ");
        print_fx(fj, "z", c->z, ", ");
        print_fx(fj, "angle", c->angle_deg, ", ");
        fprintf(fj, "\"look\": %d}, \"raw\": [%d, %d, %d, %d, %d], \"mode\": %d, \"present\": %d, \"t_ms\": %u, ",
                (int)c->look, (int)c->x, (int)c->y, (int)c->z, (int)c->angle_deg, (int)c->look, (int)e.mode,
                (int)e.present, (unsigned)e.t_ms);
        print_ceilings(fj, &e);
        fprintf(fj, "}\n");
    }
    fclose(fr);
    fclose(fj);
    scene_start_close(&st);
    return 0;
}

/* ---- encode / decode / bench ------------------------------------------------ */

static void put_file(void *ctx, const uint8_t *p, uint32_t n)
{
    fwrite(p, 1, n, (FILE *)ctx);
}

static void put_count(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)p;
    *(uint64_t *)ctx += n;
}

/* The camera of frame k from a frames.jsonl line: "raw": [x, y, z, angle, look], "mode": m, "present": p. */
static void parse_info(const char *line, fl_frame_info *fi)
{
    const char *r = strstr(line, "\"raw\": [");
    if (r) {
        long v[5] = {0};
        sscanf(r + 8, "%ld, %ld, %ld, %ld, %ld", &v[0], &v[1], &v[2], &v[3], &v[4]);
        fi->x = (int32_t)v[0];
        fi->y = (int32_t)v[1];
        fi->z = (int32_t)v[2];
        fi->angle = (int32_t)v[3];
        fi->look = (int32_t)v[4];
    }
    const char *m = strstr(line, "\"mode\": ");
    if (m) fi->mode = (uint8_t)atoi(m + 8);
    const char *pr = strstr(line, "\"present\": ");
    if (pr) fi->present = (uint8_t)atoi(pr + 11);
    const char *t = strstr(line, "\"t_ms\": ");
    if (t) fi->time_ms = (uint32_t)strtoul(t + 8, NULL, 10);
}

/* the COPY coder's match finder (the firmware goes without: fltool digest) */
static int32_t match_hash[FL_CP_HASH];

static int cmd_encode(int argc, char **argv, int bench)
{
    const char *in = NULL, *out = NULL, *infof = NULL, *palf = NULL, *scene_name = NULL;
    unsigned long scene_crc = 0;
    long key_interval = 64, scratch_bytes = 16384, repeat = 1, limit = -1;
    int sizes = 0, with_crc = 0, no_crc = 0, match_finder = 1;
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--out") && i + 1 < argc)
            out = argv[++i];
        else if (!strcmp(argv[i], "--info") && i + 1 < argc)
            infof = argv[++i];
        else if (!strcmp(argv[i], "--palette") && i + 1 < argc)
            palf = argv[++i];
        else if (!strcmp(argv[i], "--key-interval") && i + 1 < argc)
            key_interval = atol(argv[++i]);
        else if (!strcmp(argv[i], "--scratch") && i + 1 < argc)
            scratch_bytes = atol(argv[++i]);
        else if (!strcmp(argv[i], "--repeat") && i + 1 < argc)
            repeat = atol(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc)
            limit = atol(argv[++i]);
        else if (!strcmp(argv[i], "--sizes"))
            sizes = 1;
        else if (!strcmp(argv[i], "--crc"))
            with_crc = 1;
        else if (!strcmp(argv[i], "--no-crc"))
            no_crc = 1;
        else if (!strcmp(argv[i], "--no-match-finder"))
            match_finder = 0;
        else if (!strcmp(argv[i], "--scene") && i + 1 < argc)
            scene_name = argv[++i];
        else if (!strcmp(argv[i], "--scene-crc") && i + 1 < argc)
            scene_crc = strtoul(argv[++i], NULL, 16);
        else if (argv[i][0] != '-' && !in)
            in = argv[i];
        else
            return usage();
    }
    if (!in || (!bench && !out) || key_interval < 0 || scratch_bytes < 0) return usage();
    size_t len;
    uint8_t *raw = read_file(in, &len);
    if (!raw) {
        fprintf(stderr, "fltool: %s: cannot read: %s\n", in, strerror(errno));
        return 1;
    }
    long nframes = (long)(len / FL_FRAME_BYTES);
    if (limit >= 0 && limit < nframes) nframes = limit;
    /* frames copied into word-aligned memory, as VRAM pages are */
    uint8_t *frames = aligned_alloc(64, (size_t)nframes * FL_FRAME_BYTES + 64);
    memcpy(frames, raw, (size_t)nframes * FL_FRAME_BYTES);
    free(raw);
    fl_frame_info *infos = calloc((size_t)nframes + 1, sizeof *infos);
    if (infof) {
        FILE *f = fopen(infof, "r");
        char line[4096];
        for (long k = 0; f && k < nframes && fgets(line, sizeof line, f); k++) parse_info(line, &infos[k]);
        if (f) fclose(f);
    }
    for (long k = 0; k < nframes; k++) {
        infos[k].crc = no_crc ? 0 : crc_update(0, frames + (size_t)k * FL_FRAME_BYTES, FL_FRAME_BYTES);
        infos[k].no_crc = (uint8_t)no_crc;
    }
    uint8_t pal[FL_PALETTE_BYTES];
    for (int i = 0; i < FL_PALETTE_BYTES; i++) pal[i] = (uint8_t)(i / 3);
    if (palf) {
        size_t pl;
        uint8_t *p = read_file(palf, &pl);
        if (p && pl >= FL_PALETTE_BYTES) memcpy(pal, p, FL_PALETTE_BYTES);
        free(p);
    }
    FILE *fo = NULL;
    uint64_t counted = 0;
    if (!bench) {
        fo = fopen(out, "wb");
        if (!fo) {
            fprintf(stderr, "fltool: %s: cannot write\n", out);
            return 1;
        }
    }
    static fl_encoder enc;
    uint8_t *scratch = malloc((size_t)scratch_bytes + 1);
    uint32_t crc_sink = 0;
    for (long rep = 0; rep < repeat; rep++) {
        if (bench)
            fl_enc_init(&enc, put_count, &counted, scratch, (uint32_t)scratch_bytes);
        else
            fl_enc_init(&enc, put_file, fo, scratch, (uint32_t)scratch_bytes);
        enc.key_interval = (uint32_t)key_interval;
        enc.match_hash = match_finder ? match_hash : NULL;
        fl_enc_scene(&enc, scene_name, (uint32_t)scene_crc);
        fl_enc_hello(&enc);
        fl_enc_palette(&enc, pal);
        for (long k = 0; k < nframes; k++) {
            const uint8_t *px = frames + (size_t)k * FL_FRAME_BYTES;
            uint32_t before = enc.bytes;
            if (with_crc) crc_sink ^= crc_update(0, px, FL_FRAME_BYTES);
            int t = fl_enc_frame(&enc, (uint32_t)k, px, k ? px - FL_FRAME_BYTES : NULL, (uint32_t)(k - 1), &infos[k]);
            if (sizes && rep == 0)
                printf("{\"frame\": %ld, \"type\": \"%s\", \"bytes\": %u}\n", k, t == FL_MSG_KEYFRAME ? "key" : "delta",
                       enc.bytes - before);
        }
    }
    if (bench)
        printf("{\"frames\": %ld, \"repeat\": %ld, \"bytes\": %llu, \"keyframes\": %u, \"raw_fallbacks\": %u, \"crc\": "
               "%u}\n",
               nframes, repeat, (unsigned long long)counted, enc.keyframes, enc.raw_fallbacks, crc_sink & 1u);
    if (fo) fclose(fo);
    free(scratch);
    free(frames);
    free(infos);
    return 0;
}

typedef struct {
    FILE *frames_out;
    const fl_decoder *d;
} dec_ctx;

static const char *reason_name(fl_reason r)
{
    static const char *names[] = {"none",   "framing", "short",   "long",    "crc",    "version",
                                  "length", "type",    "payload", "no_base", "decode", "frame_crc"};
    return (unsigned)r < sizeof names / sizeof names[0] ? names[r] : "?";
}

static void print_info(const fl_frame_info *i)
{
    printf("\"info\": {\"x\": %d, \"y\": %d, \"z\": %d, \"angle\": %d, \"look\": %d, \"mode\": %u, \"present\": %u, "
           "\"crc32\": \"%08x\", \"no_crc\": %u, \"time_ms\": %u}",
           (int)i->x, (int)i->y, (int)i->z, (int)i->angle, (int)i->look, i->mode, i->present, (unsigned)i->crc,
           i->no_crc, (unsigned)i->time_ms);
}

static void on_event(void *ctx, const fl_event *ev)
{
    dec_ctx *c = ctx;
    switch (ev->kind) {
    case FL_EV_HELLO:
        printf(
            "{\"event\": \"hello\", \"frame\": %u, \"version\": %u, \"width\": %u, \"height\": %u, \"gun_bits\": %u, "
            "\"key_interval\": %u, \"window\": %u, \"methods\": %u, \"scene\": \"",
            (unsigned)ev->frame_no, ev->hello.version, ev->hello.width, ev->hello.height, ev->hello.gun_bits,
            ev->hello.key_interval, ev->hello.window, ev->hello.methods);
        for (const char *q = ev->hello.scene_name; *q; q++) printf(*q == '"' || *q == '\\' ? "\\%c" : "%c", *q);
        printf("\", \"scene_crc32\": \"%08x\"}\n", (unsigned)ev->hello.scene_crc);
        break;
    case FL_EV_PALETTE:
        printf("{\"event\": \"palette\", \"frame\": %u, \"crc32\": \"%08x\"}\n", (unsigned)ev->frame_no,
               (unsigned)crc_update(0, ev->palette, FL_PALETTE_BYTES));
        break;
    case FL_EV_FRAME:
        printf("{\"event\": \"frame\", \"frame\": %u, \"keyframe\": %u, ", (unsigned)ev->frame_no, ev->keyframe);
        print_info(&ev->info);
        printf("}\n");
        if (c->frames_out) fwrite(c->d->frame, 1, FL_FRAME_BYTES, c->frames_out);
        break;
    case FL_EV_DROP:
        printf("{\"event\": \"drop\", \"frame\": %u, \"type\": %u, \"reason\": \"%s\"}\n", (unsigned)ev->frame_no,
               ev->type, reason_name(ev->reason));
        break;
    case FL_EV_BAD: printf("{\"event\": \"bad\", \"reason\": \"%s\"}\n", reason_name(ev->reason)); break;
    case FL_EV_KEYREQ: printf("{\"event\": \"keyreq\", \"frame\": %u}\n", (unsigned)ev->frame_no); break;
    case FL_EV_OTHER:
        printf("{\"event\": \"other\", \"frame\": %u, \"type\": %u}\n", (unsigned)ev->frame_no, ev->type);
        break;
    }
}

static void put_back(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)p;
    *(uint64_t *)ctx += n;
}

static int cmd_decode(int argc, char **argv)
{
    const char *in = NULL, *fout = NULL;
    long chunk = 4096;
    for (int i = 0; i < argc; i++) {
        if (!strcmp(argv[i], "--chunk") && i + 1 < argc)
            chunk = atol(argv[++i]);
        else if (!strcmp(argv[i], "--frames-out") && i + 1 < argc)
            fout = argv[++i];
        else if (argv[i][0] != '-' && !in)
            in = argv[i];
        else
            return usage();
    }
    if (!in || chunk < 1) return usage();
    size_t len;
    uint8_t *data = read_file(in, &len);
    if (!data) {
        fprintf(stderr, "fltool: %s: cannot read: %s\n", in, strerror(errno));
        return 1;
    }
    static fl_decoder dec;
    static uint8_t frame[FL_FRAME_BYTES];
    uint8_t *work = malloc(FL_DEC_WORK_BYTES);
    dec_ctx c = {fout ? fopen(fout, "wb") : NULL, &dec};
    uint64_t back = 0;
    fl_dec_init(&dec, frame, work, on_event, &c, put_back, &back);
    for (size_t off = 0; off < len; off += (size_t)chunk) {
        size_t n = len - off < (size_t)chunk ? len - off : (size_t)chunk;
        fl_dec_feed(&dec, data + off, (uint32_t)n);
    }
    const fl_counters *k = &dec.count;
    printf("{\"counters\": {\"bytes\": %u, \"msgs_ok\": %u, \"msgs_bad\": %u, \"resyncs\": %u, \"frames_shown\": %u, "
           "\"frames_dropped\": %u, \"frames_missed\": %u, \"keyreqs_sent\": %u, \"palreqs_sent\": %u, \"acks_sent\": "
           "%u, \"palettes\": %u, "
           "\"hellos\": %u}, \"back_bytes\": %llu}\n",
           k->bytes, k->msgs_ok, k->msgs_bad, k->resyncs, k->frames_shown, k->frames_dropped, k->frames_missed,
           k->keyreqs_sent, k->palreqs_sent, k->acks_sent, k->palettes, k->hellos, (unsigned long long)back);
    if (c.frames_out) fclose(c.frames_out);
    free(work);
    free(data);
    return 0;
}

/* The stream tools/flbench_m3 sends for the same frames (no hello or palette,
 * zero camera, no pixel CRC, keyframes every 64): its length and CRC-32. */
static uint32_t digest_bytes, digest_crc;
static void put_digest(void *ctx, const uint8_t *p, uint32_t n)
{
    (void)ctx;
    digest_bytes += n;
    digest_crc = crc_update(digest_crc, p, n);
}

static int cmd_digest(int argc, char **argv)
{
    if (argc != 1) return usage();
    size_t len;
    uint8_t *raw = read_file(argv[0], &len);
    if (!raw) {
        fprintf(stderr, "fltool: %s: cannot read: %s\n", argv[0], strerror(errno));
        return 1;
    }
    size_t n = len / FL_FRAME_BYTES;
    uint8_t *frames = aligned_alloc(64, n * FL_FRAME_BYTES + 64);
    memcpy(frames, raw, n * FL_FRAME_BYTES);
    static fl_encoder enc;
    static uint8_t scratch[8192];
    fl_enc_init(&enc, put_digest, NULL, scratch, sizeof scratch);
    fl_frame_info info;
    memset(&info, 0, sizeof info);
    info.no_crc = 1;
    for (size_t k = 0; k < n; k++) {
        const uint8_t *px = frames + k * FL_FRAME_BYTES;
        fl_enc_frame(&enc, (uint32_t)k, px, k ? px - FL_FRAME_BYTES : NULL, (uint32_t)k - 1, &info);
    }
    printf("stream bytes %08x crc %08x\n", (unsigned)digest_bytes, (unsigned)digest_crc);
    free(frames);
    free(raw);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) return usage();
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) return usage_to(stdout, 0);
    if (!strcmp(argv[1], "walk")) return cmd_walk(argc - 2, argv + 2);
    if (!strcmp(argv[1], "encode")) return cmd_encode(argc - 2, argv + 2, 0);
    if (!strcmp(argv[1], "bench")) return cmd_encode(argc - 2, argv + 2, 1);
    if (!strcmp(argv[1], "decode")) return cmd_decode(argc - 2, argv + 2);
    if (!strcmp(argv[1], "digest")) return cmd_digest(argc - 2, argv + 2);
    return usage();
}
