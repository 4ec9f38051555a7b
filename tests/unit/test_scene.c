/* test_scene.c - the compiled-scene loader never trusts its input: every header
 * field, offset, count and index is checked, and damaged blobs (with the CRC
 * recomputed, so the damage reaches the structural checks) are refused or, if
 * accepted, render without touching memory outside the blob (ASan watches).
 * The models, objects and doors of docs/objects.md: every index, count and
 * range field of a valid record, damaged on its own (CRC recomputed), is refused
 * with the status, section and index docs/objects.md gives. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bspc.h"
#include "crc32.h"
#include "engine.h"
#include "hal_null.h"
#include "scene.h"
#include "scene_fixture.h"

static uint8_t *blob;
static size_t blob_len;
static uint8_t *oblob; /* with models, objects and a door */
static size_t oblob_len;

static const char OBJECTS_SCENE[] = "sector room floor=0 ceil=128\n"
                                    "sector door1 floor=0 ceil=0 door=112\n"
                                    "wall 0 0 0 256 room\n"
                                    "wall 0 256 256 256 room\n"
                                    "wall 256 256 256 0 room\n"
                                    "wall 256 0 128 0 room\n"
                                    "wall 128 0 96 0 room door1\n"
                                    "wall 96 0 0 0 room\n"
                                    "wall 128 0 128 -16 door1\n"
                                    "wall 128 -16 96 -16 door1\n"
                                    "wall 96 -16 96 0 door1\n"
                                    "player 64 128 0\n"
                                    "model crate\n"
                                    "part box w=32 d=32 h=32 color=brown:8\n"
                                    "end\n"
                                    "model ship\n"
                                    "part box w=48 d=16 h=8 color=grey:9\n"
                                    "part prism sides=5 r=12 h=4 at=36,0,2 color=red:8\n"
                                    "end\n"
                                    "object crate 200 200 yaw=30\n"
                                    "object ship 128 128 z=40 path=circle:64:8000\n"
                                    "object ship 40 200 z=20 path=line:150:-100:5000 spin=90\n";

static int compile_text(const char *text, uint8_t **out, size_t *len)
{
    char err[256];
    return fixture_compile_text(text, NULL, out, len, NULL, err, sizeof err);
}

static int setup(void **state)
{
    (void)state;
    char err[256];
    bspc_options opt = bspc_defaults();
    if (bspc_compile("tests/scenes/default.scene", &opt, &blob, &blob_len, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    return compile_text(OBJECTS_SCENE, &oblob, &oblob_len);
}

static int teardown(void **state)
{
    (void)state;
    free(blob);
    free(oblob);
    return 0;
}

static void fix_crc(uint8_t *b, size_t len)
{
    uint32_t crc = crc_update(0, b + 16, len - 16);
    memcpy(b + 12, &crc, 4);
}

static scene_status load_copy(const uint8_t *src, size_t len, scene_error *err)
{
    uint32_t *aligned = malloc(len + 4);
    memcpy(aligned, src, len);
    scene s;
    scene_status st = scene_load(&s, aligned, (uint32_t)len, err);
    if (st == SCENE_OK) {
        /* accepted: it must render within bounds */
        static engine e;
        hal_null_reset();
        assert_int_equal(eng_init(&e, aligned, (uint32_t)len, NULL), SCENE_OK);
        uint32_t need = eng_work_bytes(&e);
        void *work = malloc(need ? need : 1);
        assert_int_equal(eng_set_work(&e, work, need), 0);
        for (int m = 0; m < RENDER_MODE_COUNT; m++) {
            e.mode = (render_mode)m;
            eng_render(&e, NULL);
        }
        free(work);
    }
    free(aligned);
    return st;
}

static void test_good_blob_loads(void **state)
{
    (void)state;
    scene_error err;
    assert_int_equal(load_copy(blob, blob_len, &err), SCENE_OK);
}

static void test_header_damage(void **state)
{
    (void)state;
    uint8_t *b = malloc(blob_len);
    scene_error err;
    /* truncated anywhere */
    for (size_t n = 0; n < blob_len; n += 1 + n / 8) assert_int_equal(load_copy(blob, n, &err) != SCENE_OK, 1);
    /* each header byte flipped (the CRC fixed where it does not cover the byte) */
    for (size_t i = 0; i < sizeof(scn_header); i++) {
        if (i >= 12 && i < 16) continue;
        memcpy(b, blob, blob_len);
        b[i] ^= 0x5A;
        fix_crc(b, blob_len);
        scene_status st = load_copy(b, blob_len, &err);
        /* magic, version, sizes and the reserved flags must match exactly; the
         * player start, the root and the depth may change to other valid values
         * (load_copy has then rendered a frame from them under ASan) */
        if (i < 20) assert_int_not_equal(st, SCENE_OK);
    }
    /* total_bytes below the header (0, 4, 8, 12 pass the multiple-of-4 test): refused
     * before the CRC, whose length total_bytes - 16 would wrap */
    for (uint32_t total = 0; total < sizeof(scn_header); total += 4) {
        memcpy(b, blob, blob_len);
        memcpy(b + 8, &total, 4);
        assert_int_equal(load_copy(b, blob_len, &err), SCENE_ERR_HEADER);
    }
    /* a bad CRC */
    memcpy(b, blob, blob_len);
    b[blob_len - 1] ^= 1;
    assert_int_equal(load_copy(b, blob_len, &err), SCENE_ERR_CRC);
    /* misaligned in memory */
    uint8_t *odd = malloc(blob_len + 1);
    memcpy(odd + 1, blob, blob_len);
    scene s;
    assert_int_equal(scene_load(&s, odd + 1, (uint32_t)blob_len, &err), SCENE_ERR_ALIGN);
    free(odd);
    free(b);
}

/* Every 32-bit word of the body replaced by hostile values, CRC recomputed:
 * the loader refuses or the renderer survives it. */
static void test_body_damage(void **state)
{
    (void)state;
    static const uint32_t hostile[] = {0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu, 0, 1, 0x80000001u, 0x10000};
    uint8_t *b = malloc(blob_len);
    uint32_t refused = 0, total = 0;
    for (size_t off = 16; off + 4 <= blob_len; off += 4)
        for (size_t k = 0; k < sizeof hostile / sizeof hostile[0]; k++) {
            memcpy(b, blob, blob_len);
            memcpy(b + off, &hostile[k], 4);
            fix_crc(b, blob_len);
            scene_error err;
            refused += load_copy(b, blob_len, &err) != SCENE_OK;
            total++;
        }
    assert_true(refused > 0 && refused <= total);
    free(b);
}

static void test_tree_must_be_a_tree(void **state)
{
    (void)state;
    uint8_t *b = malloc(blob_len);
    memcpy(b, blob, blob_len);
    scn_header *h = (scn_header *)(void *)b;
    if (h->sec[SCN_SEC_NODES].count >= 2) {
        scn_node *nodes = (scn_node *)(void *)(b + h->sec[SCN_SEC_NODES].offset);
        /* point the root's children at the root itself: a cycle */
        nodes[h->root].child[0] = h->root;
        fix_crc(b, blob_len);
        scene_error err;
        assert_int_equal(load_copy(b, blob_len, &err), SCENE_ERR_TREE);
    }
    free(b);
}

/* Nodes on the longest path from node n down to a leaf, walked here on the blob's
 * own records (a tree the loader has accepted). */
static uint32_t depth_below(const scn_node *nodes, uint32_t n)
{
    uint32_t deepest = 0;
    for (int c = 0; c < 2; c++) {
        uint32_t ch = nodes[n].child[c];
        if (ch & SCN_LEAF_BIT) continue;
        uint32_t d = depth_below(nodes, ch);
        if (d > deepest) deepest = d;
    }
    return deepest + 1;
}

/* The header's max_depth sizes the walkers' stacks: the loader measures the tree
 * and refuses a header that claims less than the longest root-to-leaf path, and
 * takes one that claims exactly it. */
static void test_depth_must_cover_the_tree(void **state)
{
    (void)state;
    uint8_t *b = malloc(blob_len);
    memcpy(b, blob, blob_len);
    scn_header *h = (scn_header *)(void *)b;
    const scn_node *nodes = (const scn_node *)(const void *)(b + h->sec[SCN_SEC_NODES].offset);
    assert_false(h->root & SCN_LEAF_BIT);
    uint32_t depth = depth_below(nodes, h->root);
    assert_true(depth >= 3); /* default.scene: a tree deep enough that every level counts */
    assert_int_equal(h->max_depth, depth);
    scene_error err;
    for (uint32_t claim = 1; claim < depth; claim++) {
        h->max_depth = claim;
        fix_crc(b, blob_len);
        assert_int_equal(load_copy(b, blob_len, &err), SCENE_ERR_TREE);
        assert_int_equal(err.section, -1);
        assert_int_equal(err.index, SCENE_FIELD_MAX_DEPTH);
    }
    h->max_depth = depth;
    fix_crc(b, blob_len);
    assert_int_equal(load_copy(b, blob_len, &err), SCENE_OK);
    free(b);
}

/* A partition's direction: each component must be negatable (the side tests
 * negate them), so INT32_MIN is refused, and both 0 is no line at all; the
 * refusal names the node. Any other value loads (and renders, load_copy). */
static void test_node_direction_range(void **state)
{
    (void)state;
    uint8_t *b = malloc(blob_len);
    const scn_header *h = (const scn_header *)(const void *)blob;
    uint32_t nn = h->sec[SCN_SEC_NODES].count;
    assert_true(nn >= 2);
    static const int32_t bad[][2] = {{INT32_MIN, 1}, {1, INT32_MIN}, {INT32_MIN, 0}, {0, INT32_MIN}, {0, 0}};
    for (uint32_t i = 0; i < nn; i += nn - 1) { /* the first node and the last */
        for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
            memcpy(b, blob, blob_len);
            scn_node *nodes = (scn_node *)(void *)(b + h->sec[SCN_SEC_NODES].offset);
            nodes[i].dx = bad[k][0];
            nodes[i].dy = bad[k][1];
            fix_crc(b, blob_len);
            scene_error err;
            assert_int_equal(load_copy(b, blob_len, &err), SCENE_ERR_RANGE);
            assert_int_equal(err.section, SCN_SEC_NODES);
            assert_int_equal(err.index, i);
        }
        memcpy(b, blob, blob_len);
        scn_node *nodes = (scn_node *)(void *)(b + h->sec[SCN_SEC_NODES].offset);
        nodes[i].dx = INT32_MIN + 1; /* the most negative that negates */
        fix_crc(b, blob_len);
        scene_error err;
        assert_int_equal(load_copy(b, blob_len, &err), SCENE_OK);
    }
    free(b);
}

/* The features a scene needs follow from what it holds: textures exactly when it
 * has a look (a flat scene needs none), objects exactly when it has models,
 * animation exactly when a look has a sequence of frames or a scrolling side. */
static void test_derived_features(void **state)
{
    (void)state;
    uint32_t *aligned = malloc(blob_len + 4);
    memcpy(aligned, blob, blob_len);
    scene s;
    scene_error err;
    assert_int_equal(scene_load(&s, aligned, (uint32_t)blob_len, &err), SCENE_OK);
    assert_null(s.look);
    uint32_t flat = scene_derived_features(&s);
    assert_int_equal(flat & SCN_NEED_TEXTURES, 0);
    assert_int_equal(flat & SCN_NEED_OBJECTS, s.nmodels ? SCN_NEED_OBJECTS : 0);
    scn_look look;
    memset(&look, 0, sizeof look);
    scn_side *sides = calloc(2u * s.nlines, sizeof *sides); /* a look has a side per line side */
    assert_non_null(sides);
    scene t = s;
    t.look = &look;
    t.sides = sides;
    assert_int_equal(scene_derived_features(&t), flat | SCN_NEED_TEXTURES);
    sides[2u * s.nlines - 1].flags = SCN_SIDE_SCROLL;
    assert_int_equal(scene_derived_features(&t), flat | SCN_NEED_TEXTURES | SCN_NEED_ANIM);
    sides[2u * s.nlines - 1].flags = 0;
    scn_anim anim = {0, 2, 0, 8, 0};
    t.anims = &anim;
    t.nanims = 1;
    assert_int_equal(scene_derived_features(&t), flat | SCN_NEED_TEXTURES | SCN_NEED_ANIM);
    free(sides);
    free(aligned);
}

/* ---- models, objects, doors ---- */

typedef struct {
    scn_header *h;
    scn_sector *sec;
    scn_model *m;
    scn_mvert *mv;
    scn_face *f;
    uint32_t *fi;
    scn_object *o;
} oview;

static oview oview_of(uint8_t *b)
{
    oview v;
    v.h = (scn_header *)(void *)b;
    v.sec = (scn_sector *)(void *)(b + v.h->sec[SCN_SEC_SECTORS].offset);
    v.m = (scn_model *)(void *)(b + v.h->sec[SCN_SEC_MODELS].offset);
    v.mv = (scn_mvert *)(void *)(b + v.h->sec[SCN_SEC_MVERTS].offset);
    v.f = (scn_face *)(void *)(b + v.h->sec[SCN_SEC_FACES].offset);
    v.fi = (uint32_t *)(void *)(b + v.h->sec[SCN_SEC_FINDEX].offset);
    v.o = (scn_object *)(void *)(b + v.h->sec[SCN_SEC_OBJECTS].offset);
    return v;
}

static void test_objects_blob_loads(void **state)
{
    (void)state;
    scene_error err;
    assert_int_equal(load_copy(oblob, oblob_len, &err), SCENE_OK);
    oview v = oview_of(oblob);
    assert_int_equal(v.h->sec[SCN_SEC_MODELS].count, 2);
    assert_int_equal(v.h->sec[SCN_SEC_OBJECTS].count, 3);
    assert_true(v.sec[1].flags & SCN_SECTOR_DOOR);
}

enum { F_SEC, F_MODEL, F_MVERT, F_FACE, F_FINDEX, F_OBJECT };

typedef struct {
    const char *what;
    int rec;      /* F_* */
    uint32_t idx; /* which record */
    size_t field; /* byte offset in the record */
    int size;     /* 1, 2 or 4 bytes */
    int64_t value;
    int relative; /* value is added to the field */
    scene_status want;
    int section;
    uint32_t want_idx;
} damage;

/* indices of OBJECTS_SCENE: sector 0 room, 1 door; model 0 crate (8 verts,
 * 6 faces), 1 ship (8 + 10 verts, 6 + 7 faces); object 0 none, 1 circle, 2 line */
#define FLD(type, member) offsetof(type, member), (int)sizeof(((type *)0)->member)
static const damage damages[] = {
    {"door opens below its ceiling", F_SEC, 1, FLD(scn_sector, open_h), -1, 0, SCENE_ERR_RANGE, SCN_SEC_SECTORS, 1},
    {"door opens above the limit", F_SEC, 1, FLD(scn_sector, open_h), (int64_t)16384 << 16, 0, SCENE_ERR_RANGE,
     SCN_SEC_SECTORS, 1},
    {"non-door with an open ceiling", F_SEC, 0, FLD(scn_sector, open_h), 1, 1, SCENE_ERR_RANGE, SCN_SEC_SECTORS, 0},
    {"door flag on a plain sector", F_SEC, 0, FLD(scn_sector, flags), SCN_SECTOR_DOOR, 0, SCENE_OK, -1, 0},
    {"door flag off", F_SEC, 1, FLD(scn_sector, flags), 0, 0, SCENE_ERR_RANGE, SCN_SEC_SECTORS, 1},
    {"model vertex x beyond 1024", F_MVERT, 3, FLD(scn_mvert, x), ((int64_t)1024 << 16) + 1, 0, SCENE_ERR_RANGE,
     SCN_SEC_MVERTS, 3},
    {"model vertex y below -1024", F_MVERT, 9, FLD(scn_mvert, y), -((int64_t)1024 << 16) - 1, 0, SCENE_ERR_RANGE,
     SCN_SEC_MVERTS, 9},
    {"model vertex z beyond 1024", F_MVERT, 17, FLD(scn_mvert, z), (int64_t)INT32_MAX, 0, SCENE_ERR_RANGE,
     SCN_SEC_MVERTS, 17},
    {"model vertex moved", F_MVERT, 0, FLD(scn_mvert, x), -1, 1, SCENE_ERR_RANGE, SCN_SEC_MODELS, 0},
    {"model vertex lowered", F_MVERT, 8, FLD(scn_mvert, z), -1, 1, SCENE_ERR_RANGE, SCN_SEC_MODELS, 1},
    {"face of 2 vertices", F_FACE, 2, FLD(scn_face, num_index), 2, 0, SCENE_ERR_INDEX, SCN_SEC_FACES, 2},
    {"face of 17 vertices", F_FACE, 2, FLD(scn_face, num_index), 17, 0, SCENE_ERR_INDEX, SCN_SEC_FACES, 2},
    {"face past the indices", F_FACE, 12, FLD(scn_face, first_index), 1000, 0, SCENE_ERR_INDEX, SCN_SEC_FACES, 12},
    {"face index wraps", F_FACE, 1, FLD(scn_face, first_index), 0xFFFFFFFF, 0, SCENE_ERR_INDEX, SCN_SEC_FACES, 1},
    {"face vertex outside its model", F_FINDEX, 5, 0, 4, 8, 0, SCENE_ERR_INDEX, SCN_SEC_MODELS, 0},
    {"face vertex far outside", F_FINDEX, 30, 0, 4, 0xFFFFFFFF, 0, SCENE_ERR_INDEX, SCN_SEC_MODELS, 1},
    {"model vertices past the section", F_MODEL, 1, FLD(scn_model, first_vert), 1, 1, SCENE_ERR_INDEX, SCN_SEC_MODELS,
     1},
    {"model vertex range wraps", F_MODEL, 1, FLD(scn_model, first_vert), 0xFFFFFFF0, 0, SCENE_ERR_INDEX, SCN_SEC_MODELS,
     1},
    {"model of 65 vertices", F_MODEL, 0, FLD(scn_model, num_verts), 65, 0, SCENE_ERR_INDEX, SCN_SEC_MODELS, 0},
    {"model of 2 vertices", F_MODEL, 0, FLD(scn_model, num_verts), 2, 0, SCENE_ERR_INDEX, SCN_SEC_MODELS, 0},
    {"model of no faces", F_MODEL, 0, FLD(scn_model, num_faces), 0, 0, SCENE_ERR_INDEX, SCN_SEC_MODELS, 0},
    {"model of 65 faces", F_MODEL, 0, FLD(scn_model, num_faces), 65, 0, SCENE_ERR_INDEX, SCN_SEC_MODELS, 0},
    {"model faces past the section", F_MODEL, 1, FLD(scn_model, first_face), 1, 1, SCENE_ERR_INDEX, SCN_SEC_MODELS, 1},
    {"model with fewer vertices than its faces use", F_MODEL, 1, FLD(scn_model, num_verts), 17, 0, SCENE_ERR_INDEX,
     SCN_SEC_MODELS, 1},
    {"radius one too big", F_MODEL, 0, FLD(scn_model, radius), 1, 1, SCENE_ERR_RANGE, SCN_SEC_MODELS, 0},
    {"radius one too small", F_MODEL, 1, FLD(scn_model, radius), -1, 1, SCENE_ERR_RANGE, SCN_SEC_MODELS, 1},
    {"negative radius", F_MODEL, 1, FLD(scn_model, radius), -5, 0, SCENE_ERR_RANGE, SCN_SEC_MODELS, 1},
    {"zmin wrong", F_MODEL, 0, FLD(scn_model, zmin), 1, 1, SCENE_ERR_RANGE, SCN_SEC_MODELS, 0},
    {"zmax wrong", F_MODEL, 1, FLD(scn_model, zmax), -1, 1, SCENE_ERR_RANGE, SCN_SEC_MODELS, 1},
    {"object of a missing model", F_OBJECT, 1, FLD(scn_object, model), 2, 0, SCENE_ERR_INDEX, SCN_SEC_OBJECTS, 1},
    {"object model none", F_OBJECT, 0, FLD(scn_object, model), 0xFFFFFFFF, 0, SCENE_ERR_INDEX, SCN_SEC_OBJECTS, 0},
    {"unknown path", F_OBJECT, 2, FLD(scn_object, path), 3, 0, SCENE_ERR_INDEX, SCN_SEC_OBJECTS, 2},
    {"object x outside the box", F_OBJECT, 0, FLD(scn_object, x), ((int64_t)32767 << 16) + 1, 0, SCENE_ERR_RANGE,
     SCN_SEC_OBJECTS, 0},
    {"object y outside the box", F_OBJECT, 0, FLD(scn_object, y), INT32_MIN, 0, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, 0},
    {"object z above the limit", F_OBJECT, 0, FLD(scn_object, z), (int64_t)16384 << 16, 0, SCENE_ERR_RANGE,
     SCN_SEC_OBJECTS, 0},
    {"circle leaves the box", F_OBJECT, 1, FLD(scn_object, x), (int64_t)32767 << 16, 0, SCENE_ERR_RANGE,
     SCN_SEC_OBJECTS, 1},
    {"line leaves the box", F_OBJECT, 2, FLD(scn_object, y), -((int64_t)32700 << 16), 0, SCENE_ERR_RANGE,
     SCN_SEC_OBJECTS, 2},
    {"line along y only", F_OBJECT, 2, FLD(scn_object, pa), 0, 0, SCENE_OK, -1, 0},
    {"circle of radius 0", F_OBJECT, 1, FLD(scn_object, pa), 0, 0, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, 1},
    {"circle with a pb", F_OBJECT, 1, FLD(scn_object, pb), 1, 0, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, 1},
    {"path of period 0", F_OBJECT, 1, FLD(scn_object, period_ms), 0, 0, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, 1},
    {"path of period over an hour", F_OBJECT, 2, FLD(scn_object, period_ms), 3600001, 0, SCENE_ERR_RANGE,
     SCN_SEC_OBJECTS, 2},
    {"no path but a period", F_OBJECT, 0, FLD(scn_object, period_ms), 100, 0, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, 0},
    {"no path but a radius", F_OBJECT, 0, FLD(scn_object, pa), 1, 0, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, 0},
    {"spin too fast", F_OBJECT, 2, FLD(scn_object, spin), ((int64_t)3600 << 16) + 1, 0, SCENE_ERR_RANGE,
     SCN_SEC_OBJECTS, 2},
    {"spin too fast backwards", F_OBJECT, 0, FLD(scn_object, spin), INT32_MIN, 0, SCENE_ERR_RANGE, SCN_SEC_OBJECTS, 0},
    {"yaw anything", F_OBJECT, 0, FLD(scn_object, yaw), INT32_MIN, 0, SCENE_OK, -1, 0},
    {"colour anything", F_FACE, 4, FLD(scn_face, colour), 255, 0, SCENE_OK, -1, 0},
};

/* An object's whole path must stay in the coordinate box [-SCN_COORD_MAX,
 * SCN_COORD_MAX] units, both ends closed: a still object exactly on either edge
 * loads, one raw unit beyond is refused naming it; a circling one is measured
 * by its circle's reach. */
static void test_object_box_edges(void **state)
{
    (void)state;
    const int64_t box = (int64_t)SCN_COORD_MAX << 16;
    uint8_t *b = malloc(oblob_len);
    for (int axis = 0; axis < 2; axis++)
        for (int side = -1; side <= 1; side += 2)
            for (int64_t beyond = 0; beyond <= 1; beyond++) {
                for (uint32_t i = 0; i < 2; i++) { /* 0: the crate, still; 1: the ship, circling */
                    memcpy(b, oblob, oblob_len);
                    oview v = oview_of(b);
                    int64_t reach = v.o[i].path == SCN_PATH_CIRCLE ? v.o[i].pa : 0;
                    assert_int_equal(v.o[i].path, i == 0 ? SCN_PATH_NONE : SCN_PATH_CIRCLE);
                    fx_t at = (fx_t)(side * (box - reach + beyond));
                    if (axis == 0)
                        v.o[i].x = at;
                    else
                        v.o[i].y = at;
                    fix_crc(b, oblob_len);
                    scene_error err;
                    scene_status st = load_copy(b, oblob_len, &err);
                    if (beyond) {
                        assert_int_equal(st, SCENE_ERR_RANGE);
                        assert_int_equal(err.section, SCN_SEC_OBJECTS);
                        assert_int_equal(err.index, i);
                    } else {
                        assert_int_equal(st, SCENE_OK);
                    }
                }
            }
    free(b);
}

static void test_object_damage(void **state)
{
    (void)state;
    uint8_t *b = malloc(oblob_len);
    for (size_t i = 0; i < sizeof damages / sizeof damages[0]; i++) {
        const damage *d = &damages[i];
        memcpy(b, oblob, oblob_len);
        oview v = oview_of(b);
        uint8_t *rec = d->rec == F_SEC      ? (uint8_t *)&v.sec[d->idx]
                       : d->rec == F_MODEL  ? (uint8_t *)&v.m[d->idx]
                       : d->rec == F_MVERT  ? (uint8_t *)&v.mv[d->idx]
                       : d->rec == F_FACE   ? (uint8_t *)&v.f[d->idx]
                       : d->rec == F_FINDEX ? (uint8_t *)&v.fi[d->idx]
                                            : (uint8_t *)&v.o[d->idx];
        uint8_t *p = rec + d->field;
        if (d->size == 4) {
            uint32_t x;
            memcpy(&x, p, 4);
            x = d->relative ? x + (uint32_t)d->value : (uint32_t)d->value;
            memcpy(p, &x, 4);
        } else if (d->size == 2) {
            uint16_t x;
            memcpy(&x, p, 2);
            x = (uint16_t)(d->relative ? x + d->value : d->value);
            memcpy(p, &x, 2);
        } else {
            *p = (uint8_t)(d->relative ? *p + d->value : d->value);
        }
        fix_crc(b, oblob_len);
        scene_error err;
        scene_status st = load_copy(b, oblob_len, &err);
        if (st != d->want || (st != SCENE_OK && (err.section != d->section || err.index != d->want_idx)))
            fprintf(stderr, "%s: status %d section %d index %u\n", d->what, st, err.section, err.index);
        assert_int_equal(st, d->want);
        if (st != SCENE_OK) {
            assert_int_equal(err.section, d->section);
            assert_int_equal(err.index, d->want_idx);
        }
    }
    free(b);
}

/* Hostile words over the new sections (and the sectors), CRC recomputed: refused,
 * or rendered within bounds. */
static void test_object_body_damage(void **state)
{
    (void)state;
    static const uint32_t hostile[] = {0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu, 0, 1, 0x10000, 0x4000000};
    uint8_t *b = malloc(oblob_len);
    const scn_header *h = (const scn_header *)(const void *)oblob;
    uint32_t refused = 0;
    static const int secs[] = {SCN_SEC_SECTORS, SCN_SEC_MODELS, SCN_SEC_MVERTS,
                               SCN_SEC_FACES,   SCN_SEC_FINDEX, SCN_SEC_OBJECTS};
    static const uint32_t recsz[] = {sizeof(scn_sector), sizeof(scn_model), sizeof(scn_mvert), sizeof(scn_face), 4,
                                     sizeof(scn_object)};
    for (size_t k = 0; k < sizeof secs / sizeof secs[0]; k++) {
        size_t from = h->sec[secs[k]].offset, to = from + (size_t)h->sec[secs[k]].count * recsz[k];
        for (size_t off = from; off + 4 <= to; off += 4)
            for (size_t j = 0; j < sizeof hostile / sizeof hostile[0]; j++) {
                memcpy(b, oblob, oblob_len);
                memcpy(b + off, &hostile[j], 4);
                fix_crc(b, oblob_len);
                scene_error err;
                refused += load_copy(b, oblob_len, &err) != SCENE_OK;
            }
    }
    assert_true(refused > 0);
    free(b);
}

/* 4096 objects load; a 4097th, appended to the blob, is refused. */
static void test_object_count_limit(void **state)
{
    (void)state;
    size_t cap = 200 + 40 * SCN_MAX_OBJECTS, n = 0;
    char *text = malloc(cap);
    n += (size_t)snprintf(text + n, cap - n,
                          "sector a floor=0 ceil=64\nwall 0 0 0 64 a\nwall 0 64 64 64 a\n"
                          "wall 64 64 64 0 a\nwall 64 0 0 0 a\nplayer 32 32 0\n"
                          "model m\npart box w=1 d=1 h=1\nend\n");
    for (int i = 0; i < SCN_MAX_OBJECTS; i++)
        n += (size_t)snprintf(text + n, cap - n, "object m %d %d\n", 1 + i % 62, 1 + i / 62 % 62);
    uint8_t *b = NULL;
    size_t len = 0;
    assert_int_equal(compile_text(text, &b, &len), 0);
    scene_error err;
    assert_int_equal(load_copy(b, len, &err), SCENE_OK);
    uint8_t *big = malloc(len + sizeof(scn_object));
    memcpy(big, b, len);
    scn_header *h = (scn_header *)(void *)big;
    /* the objects end where the needs record (the last section) starts: a copy of
     * the last object goes in between */
    size_t oend = h->sec[SCN_SEC_OBJECTS].offset + h->sec[SCN_SEC_OBJECTS].count * sizeof(scn_object);
    assert_int_equal(h->sec[SCN_SEC_NEEDS].offset, oend);
    assert_int_equal(oend + sizeof(scn_needs), len);
    memcpy(big + oend + sizeof(scn_object), b + oend, sizeof(scn_needs));
    memcpy(big + oend, b + oend - sizeof(scn_object), sizeof(scn_object));
    h->sec[SCN_SEC_OBJECTS].count++;
    h->sec[SCN_SEC_NEEDS].offset += sizeof(scn_object);
    h->total_bytes += sizeof(scn_object);
    fix_crc(big, len + sizeof(scn_object));
    assert_int_equal(load_copy(big, len + sizeof(scn_object), &err), SCENE_ERR_RANGE);
    assert_int_equal(err.section, SCN_SEC_OBJECTS);
    assert_int_equal(err.index, SCN_MAX_OBJECTS);
    /* bspc refuses the 4097th */
    n += (size_t)snprintf(text + n, cap - n, "object m 5 5\n");
    uint8_t *b2 = NULL;
    assert_int_not_equal(compile_text(text, &b2, &len), 0);
    free(big);
    free(b);
    free(text);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_blob_loads),
        cmocka_unit_test(test_header_damage),
        cmocka_unit_test(test_body_damage),
        cmocka_unit_test(test_tree_must_be_a_tree),
        cmocka_unit_test(test_depth_must_cover_the_tree),
        cmocka_unit_test(test_node_direction_range),
        cmocka_unit_test(test_derived_features),
        cmocka_unit_test(test_object_box_edges),
        cmocka_unit_test(test_objects_blob_loads),
        cmocka_unit_test(test_object_damage),
        cmocka_unit_test(test_object_body_damage),
        cmocka_unit_test(test_object_count_limit),
    };
    return cmocka_run_group_tests_name("scene", tests, setup, teardown);
}
