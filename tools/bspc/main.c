/* main.c - build/bspc, the BSP compiler's command line:
 *   bspc INPUT [-o OUT] [--split fewest|balanced|mixed] [--flat] [--stats] [--needs] [--config FILE.h] [-v]
 *   bspc WAD --all [-o DIR] [-j N] [--split S] [--flat] [--stats] [-v]
 *   bspc --list WAD
 * INPUT is a text scene (docs/scene-format.md) or file.wad:MAP01 / file.wad:E1M1. */
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bspc.h"
#include "scene.h"
#include "scene_file.h"

#define MAX_JOBS 64 /* -j: maps compiled at once */

static void usage(FILE *f)
{
    fputs("usage: bspc INPUT [-o OUT] [--split fewest|balanced|mixed] [--flat] [--stats]\n"
          "            [--needs] [--config FILE.h] [-v]\n"
          "       bspc WAD --all [-o DIR] [-j N] [--split S] [--flat] [--stats] [-v]\n"
          "       bspc --list WAD\n"
          "\n"
          "Compiles a scene into a BSP blob (firmware/scene_format.h).\n"
          "  INPUT            a text scene (docs/scene-format.md), or a Doom-format map as\n"
          "                   file.wad:MAP01 or file.wad:E1M1 (a WAD named without a folder is\n"
          "                   also looked for in $DOOMWADDIR and /usr/share/games/doom)\n"
          "  -o OUT           output file (default: INPUT's base name with .bsc, in the\n"
          "                   current folder; file.wad:MAP01 gives file-MAP01.bsc)\n"
          "  --split S        partition choice: fewest (fewest splits), balanced (best\n"
          "                   balance) or mixed (weighted, the default)\n"
          "  --flat           leave a WAD map's textures and light tables out: flat\n"
          "                   colours only (still from the WAD's palette; docs/textures.md)\n"
          "  --stats          print one JSON object of build figures on stdout\n"
          "  --needs          print what the scene needs: features, and the most work one\n"
          "                   frame can take for any camera (docs/needs.md)\n"
          "  --config FILE.h  write the C header of a build for this scene alone\n"
          "                   (firmware/build_config.h); INPUT may then also be a compiled\n"
          "                   scene (.bsc), whose needs record is used as it is\n"
          "  -v               progress and warnings on stderr\n"
          "  --all            compile every map of the WAD given as INPUT, each to\n"
          "                   DIR/file-MAP.bsc (-o DIR, default the current folder);\n"
          "                   --stats prints one JSON object per map, a line each. A map\n"
          "                   refused is reported and the others still compiled (exit 1)\n"
          "  -j N             with --all: compile N maps at once (default 1); the files\n"
          "                   and --stats are the same for any N (-v's warnings may come\n"
          "                   in another order)\n"
          "  --list WAD       print the names of the maps in WAD on one line\n"
          "  --help           this text\n",
          f);
}

static void default_out(const char *in, char *out, size_t n)
{
    const char *base = strrchr(in, '/');
    base = base ? base + 1 : in;
    char tmp[1024];
    snprintf(tmp, sizeof tmp, "%s", base);
    char *colon = strrchr(tmp, ':');
    const char *map = NULL;
    if (colon) {
        *colon = 0;
        map = colon + 1;
    }
    char *dot = strrchr(tmp, '.');
    if (dot && dot != tmp) *dot = 0;
    if (map && *map)
        snprintf(out, n, "%s-%s.bsc", tmp, map);
    else
        snprintf(out, n, "%s.bsc", tmp);
}

static int write_config(const char *path, const char *name, const scene *sc)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "bspc: %s: cannot write: %s\n", path, strerror(errno));
        return 1;
    }
    needs_write_config(f, name, sc, sc->needs);
    if (fclose(f)) {
        fprintf(stderr, "bspc: %s: write failed\n", path);
        remove(path);
        return 1;
    }
    return 0;
}

/* --list WAD: its maps, one line. */
static int list_maps(const char *wad)
{
    char maps[16384], err[512];
    int n = bspc_list_maps(wad, maps, sizeof maps, err, sizeof err);
    if (n < 0) {
        fprintf(stderr, "bspc: %s\n", err);
        return 1;
    }
    printf("%s\n", maps);
    return 0;
}

/* --config for a scene compiled before: its own needs record, once it loads. It is
 * read and judged as build/render does, so both refuse it with the same words. */
static int config_from_compiled(const char *in, const char *config)
{
    uint8_t *blob;
    size_t n;
    char err[512];
    bspc_options opt = bspc_defaults();
    if (scene_file_load(in, &opt, &blob, &n, err, sizeof err) != 0) {
        fprintf(stderr, "bspc: %s\n", err);
        return 1;
    }
    scene sc;
    scene_error se;
    if (scene_load(&sc, blob, (uint32_t)n, &se) != SCENE_OK) { /* scene_file_load reads at most 256 MiB */
        scene_file_describe_error(in, blob, n, &se, err, sizeof err);
        fprintf(stderr, "bspc: %s\n", err);
        free(blob);
        return 1;
    }
    int rc = write_config(config, in, &sc);
    free(blob);
    return rc;
}

static void print_stats(const char *map, const bspc_stats *st)
{
    printf("{");
    if (map) printf("\"map\": \"%s\", ", map);
    printf("\"input_walls\": %u, \"segs\": %u, \"splits\": %u, \"leaves\": %u, \"nodes\": %u, "
           "\"vertices\": %u, \"max_depth\": %u, \"mean_depth\": %.3f, \"build_ms\": %.3f, "
           "\"models\": %u, \"objects\": %u, \"features\": %u, \"max_edges\": %u, \"max_surfaces\": %u, "
           "\"all_edges\": %u, \"all_surfaces\": %u, \"sprites\": %u, \"sprite_sets\": %u, "
           "\"sprite_texels\": %llu, \"sprite_mask_bytes\": %llu, \"sprite_bytes\": %llu}\n",
           st->input_walls, st->segs, st->splits, st->leaves, st->nodes, st->vertices, st->max_depth, st->mean_depth,
           st->build_ms, st->models, st->objects, st->needs.needs.features, st->needs.needs.edges,
           st->needs.needs.surfaces, st->needs.all_edges, st->needs.all_surfaces, st->sprites, st->sprite_sets,
           (unsigned long long)st->sprite_texels, (unsigned long long)st->sprite_mask_bytes,
           (unsigned long long)st->sprite_bytes);
}

/* Write blob[0..len) to path whole, or remove what was written and say why. */
static int write_blob(const char *path, const uint8_t *blob, size_t len, char *err, size_t errlen)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
        return 1;
    }
    size_t wrote = fwrite(blob, 1, len, f);
    if (fclose(f) || wrote != len) {
        snprintf(err, errlen, "%s: write failed", path);
        remove(path);
        return 1;
    }
    return 0;
}

/* One map of a --all run, and what became of it. */
typedef struct {
    const char *map;
    char out[2400];
    int failed; /* refused, or not written: msg says why */
    char msg[512];
    size_t len;
    bspc_stats st;
} map_job;

/* The maps of a --all run, taken in turn by its workers. */
typedef struct {
    const char *wad;
    bspc_options opt;
    map_job *jobs;
    int n, next;
    pthread_mutex_t lock;
} batch;

static void compile_job(map_job *j, const char *wad, const bspc_options *opt)
{
    char spec[1200];
    snprintf(spec, sizeof spec, "%s:%s", wad, j->map);
    uint8_t *blob = NULL;
    j->failed = bspc_compile(spec, opt, &blob, &j->len, &j->st, j->msg, sizeof j->msg) != 0;
    if (!j->failed) j->failed = write_blob(j->out, blob, j->len, j->msg, sizeof j->msg);
    free(blob);
}

/* A worker: maps until none is left, with textures kept from one to the next. */
static void *batch_worker(void *arg)
{
    batch *b = arg;
    bspc_options opt = b->opt;
    opt.look_cache = bspc_look_cache_new(); /* without one, each map composes its textures */
    for (;;) {
        pthread_mutex_lock(&b->lock);
        int i = b->next < b->n ? b->next++ : -1;
        pthread_mutex_unlock(&b->lock);
        if (i < 0) break;
        compile_job(&b->jobs[i], b->wad, &opt);
    }
    bspc_look_cache_free(opt.look_cache);
    return NULL;
}

/* --all: every map of the WAD, each into dir, by jobs workers at once; what
 * they print comes in the maps' order. 0 when all compiled. */
static int compile_all(const char *wad, const char *dir, const bspc_options *opt, int jobs, int want_stats)
{
    char maps[16384], err[512];
    struct stat st_dir;
    int found = stat(dir, &st_dir) == 0;
    if (!found || !S_ISDIR(st_dir.st_mode)) {
        fprintf(stderr, "bspc: %s: %s\n", dir, found ? "not a folder" : strerror(errno));
        return 1;
    }
    int n = bspc_list_maps(wad, maps, sizeof maps, err, sizeof err);
    if (n < 0) {
        fprintf(stderr, "bspc: %s\n", err);
        return 1;
    }
    if (n == 0) {
        fprintf(stderr, "bspc: %s: no maps in it\n", wad);
        return 1;
    }
    batch b = {wad, *opt, calloc((size_t)n, sizeof(map_job)), n, 0, PTHREAD_MUTEX_INITIALIZER};
    if (!b.jobs) {
        fprintf(stderr, "bspc: out of memory\n");
        return 1;
    }
    int k = 0;
    char *save = NULL;
    for (char *map = strtok_r(maps, " ", &save); map && k < n; map = strtok_r(NULL, " ", &save), k++) {
        char spec[1200], base[1100];
        snprintf(spec, sizeof spec, "%s:%s", wad, map);
        default_out(spec, base, sizeof base);
        b.jobs[k].map = map;
        snprintf(b.jobs[k].out, sizeof b.jobs[k].out, "%s/%s", dir, base);
    }
    b.n = k;
    if (jobs > b.n) jobs = b.n;
    pthread_t th[MAX_JOBS];
    int started = 0;
    while (started < jobs - 1 && pthread_create(&th[started], NULL, batch_worker, &b) == 0) started++;
    batch_worker(&b); /* this thread works too (alone, when no thread could start) */
    for (int t = 0; t < started; t++) pthread_join(th[t], NULL);
    int done = 0;
    for (int i = 0; i < b.n; i++) {
        const map_job *j = &b.jobs[i];
        if (j->failed) {
            fprintf(stderr, "bspc: %s\n", j->msg);
            continue;
        }
        done++;
        if (opt->verbose) fprintf(stderr, "bspc: wrote %s (%zu bytes, %d of %d)\n", j->out, j->len, i + 1, b.n);
        if (want_stats) print_stats(j->map, &j->st);
    }
    fprintf(stderr, "bspc: %s: %d of %d maps compiled into %s%s\n", wad, done, b.n, dir,
            done < b.n ? " (the others refused, above)" : "");
    free(b.jobs);
    return done < b.n ? 1 : 0;
}

int main(int argc, char **argv)
{
    const char *in = NULL, *outp = NULL;
    int want_stats = 0, want_needs = 0, all = 0, jobs = 1;
    const char *config = NULL;
    bspc_options opt = bspc_defaults();
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "-v") == 0 || strcmp(a, "--verbose") == 0) {
            opt.verbose = 1;
        } else if (strcmp(a, "--flat") == 0) {
            opt.flat = 1;
        } else if (strcmp(a, "--stats") == 0) {
            want_stats = 1;
        } else if (strcmp(a, "--needs") == 0) {
            want_needs = 1;
        } else if (strcmp(a, "--all") == 0) {
            all = 1;
        } else if (strcmp(a, "-j") == 0) {
            char *end = NULL;
            long v = ++i < argc ? strtol(argv[i], &end, 10) : 0;
            if (!end || *end || end == argv[i] || v < 1 || v > MAX_JOBS) {
                fprintf(stderr, "bspc: -j needs a number of maps to compile at once, 1 to %d\n", MAX_JOBS);
                return 2;
            }
            jobs = (int)v;
        } else if (strcmp(a, "--config") == 0) {
            if (++i >= argc) {
                fprintf(stderr, "bspc: --config needs a file name\n");
                return 2;
            }
            config = argv[i];
        } else if (strcmp(a, "--list") == 0) {
            if (++i >= argc) {
                fprintf(stderr, "bspc: --list needs a WAD file name\n");
                return 2;
            }
            return list_maps(argv[i]);
        } else if (strcmp(a, "-o") == 0) {
            if (++i >= argc) {
                fprintf(stderr, "bspc: -o needs a file name\n");
                return 2;
            }
            outp = argv[i];
        } else if (strcmp(a, "--split") == 0 || strncmp(a, "--split=", 8) == 0) {
            const char *v = a[7] == '=' ? a + 8 : (++i < argc ? argv[i] : NULL);
            if (!v) {
                fprintf(stderr, "bspc: --split needs fewest, balanced or mixed\n");
                return 2;
            }
            if (strcmp(v, "fewest") == 0)
                opt.split = BSPC_SPLIT_FEWEST;
            else if (strcmp(v, "balanced") == 0)
                opt.split = BSPC_SPLIT_BALANCED;
            else if (strcmp(v, "mixed") == 0)
                opt.split = BSPC_SPLIT_MIXED;
            else {
                fprintf(stderr, "bspc: --split %s: expected fewest, balanced or mixed\n", v);
                return 2;
            }
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "bspc: unknown option %s (see bspc --help)\n", a);
            return 2;
        } else if (!in) {
            in = a;
        } else {
            fprintf(stderr, "bspc: more than one input (%s and %s)\n", in, a);
            return 2;
        }
    }
    if (!in) {
        usage(stderr);
        return 2;
    }
    if (jobs > 1 && !all) {
        fprintf(stderr, "bspc: -j is for --all (one scene compiles on one thread)\n");
        return 2;
    }
    if (all) {
        if (want_needs || config) {
            fprintf(stderr, "bspc: --all compiles every map; --needs and --config take one (WAD:MAP)\n");
            return 2;
        }
        if (bspc_spec(in, NULL) != BSPC_SPEC_WAD) {
            fprintf(stderr, "bspc: --all: %s is not a WAD file name (file.wad)\n", in);
            return 2;
        }
        return compile_all(in, outp ? outp : ".", &opt, jobs, want_stats);
    }
    if (config && scene_file_probe(in)) return config_from_compiled(in, config);
    char outbuf[1100];
    if (!outp) {
        default_out(in, outbuf, sizeof outbuf);
        outp = outbuf;
    }

    uint8_t *blob = NULL;
    size_t len = 0;
    bspc_stats st;
    char err[512];
    if (bspc_compile(in, &opt, &blob, &len, &st, err, sizeof err)) {
        fprintf(stderr, "bspc: %s\n", err);
        return 1;
    }
    if (want_needs || config) {
        scene sc;
        scene_error se;
        if (scene_load(&sc, blob, (uint32_t)len, &se) != SCENE_OK) { /* cannot happen: bspc wrote it */
            fprintf(stderr, "bspc: %s: the compiled scene does not load: %s\n", in, scene_status_text(se.status));
            free(blob);
            return 1;
        }
        if (want_needs) needs_print(stdout, in, &sc, &st.needs);
        if (config && write_config(config, in, &sc)) {
            free(blob);
            return 1;
        }
    }
    int rc = write_blob(outp, blob, len, err, sizeof err);
    free(blob);
    if (rc) {
        fprintf(stderr, "bspc: %s\n", err);
        return 1;
    }
    if (opt.verbose) fprintf(stderr, "bspc: wrote %s (%zu bytes)\n", outp, len);
    if (want_stats) print_stats(NULL, &st);
    return 0;
}
