/* scene.h - a validated, read-in-place view of a compiled scene (prefix scene_).
 * scene_load() checks everything in firmware/scene_format.h before any other
 * part of the renderer may look at the blob; nothing after it re-checks. */
#ifndef SCENE_H
#define SCENE_H

#include <stdint.h>
#include "scene_format.h"

typedef struct {
    const scn_header *hdr;
    const scn_vertex *verts;
    const scn_sector *sectors;
    const scn_line *lines;
    const scn_seg *segs;
    const scn_node *nodes;
    const scn_leaf *leaves;
    const scn_vertex *pverts;
    const uint8_t *palette; /* 768 bytes */
    const scn_model *models;
    const scn_mvert *mverts;
    const scn_face *faces;
    const uint32_t *findex;
    const scn_object *objects;
    const scn_needs *needs;
    /* A textured scene's look (docs/textures.md); look is NULL and the counts
     * 0 in a flat-shaded scene. The loader guarantees: nlights ==
     * SCN_LIGHT_MAPS, sides[] has 2 * nlines records and planes[] nsectors,
     * every texture index in them and in look is SCN_TEX_NONE or below
     * ntextures, and every texture's texels lie inside texels[]. */
    const scn_look *look;
    const uint8_t *lights; /* nlights tables of 256 bytes */
    const scn_texture *textures;
    const uint8_t *texels;
    const scn_side *sides;
    const scn_plane *planes;
    /* WAD things' sprites (docs/objects.md, "Sprites"): none without a look.
     * The loader guarantees every image lies inside texels[] and sprmask[],
     * every set's images exist, and each sprite object's model holds them. */
    const scn_sprite *sprites;
    const uint32_t *sprmask;
    const scn_sprset *sprsets;
    uint32_t nsprites, nsprmask, nsprsets;
    /* Textures by time (docs/textures.md, "Animation"): none without a look.
     * The loader guarantees every sequence lies inside textures[], has 2 ..
     * SCN_ANIM_MAX_FRAMES frames, a phase below them and 1 .. SCN_ANIM_MAX_TICS
     * tics a frame, and that the sequences are sorted and do not overlap. */
    const scn_anim *anims;
    uint32_t nanims;
    uint32_t nlights, ntextures, ntexels;
    uint32_t nverts, nsectors, nlines, nsegs, nnodes, nleaves, npverts;
    uint32_t nmodels, nmverts, nfaces, nfindex, nobjects;
    uint32_t root;
} scene;

typedef enum {
    SCENE_OK = 0,
    SCENE_ERR_SHORT, /* fewer bytes than the header or than total_bytes says */
    SCENE_ERR_ALIGN, /* blob not 4-byte aligned in memory */
    SCENE_ERR_MAGIC,
    SCENE_ERR_VERSION,
    SCENE_ERR_HEADER, /* header_bytes or total_bytes inconsistent */
    SCENE_ERR_CRC,
    SCENE_ERR_SECTION, /* a section is misaligned or lies outside the blob */
    SCENE_ERR_INDEX,   /* a record refers to something that does not exist */
    SCENE_ERR_RANGE,   /* a coordinate or height outside the proven-safe range */
    SCENE_ERR_TREE,    /* the node graph is not a tree, or is deeper than supported */
    SCENE_ERR_NEEDS,   /* the needs record does not match the scene */
    SCENE_ERR_BUILD,   /* the scene needs more than this build provides (need, have) */
    SCENE_ERR_COUNT
} scene_status;

typedef struct {
    scene_status status;
    int section;    /* SCN_SEC_* of the offending record, or -1 */
    uint32_t index; /* its index; section -1: the SCENE_FIELD_*; SCENE_ERR_BUILD: the SCENE_ITEM_* that does not fit */
    uint32_t need, have; /* SCENE_ERR_BUILD: what the scene needs, what the build provides */
} scene_error;

/* A refusal of the header itself (section -1): which field, as scene_error.index. */
enum {
    SCENE_FIELD_NONE,
    SCENE_FIELD_MAGIC,
    SCENE_FIELD_VERSION,
    SCENE_FIELD_HEADER_BYTES,
    SCENE_FIELD_TOTAL_BYTES,
    SCENE_FIELD_CRC,
    SCENE_FIELD_FLAGS,
    SCENE_FIELD_MAX_DEPTH,
    SCENE_FIELD_PLAYER_SECTOR,
    SCENE_FIELD_PLAYER_START,
    SCENE_FIELD_ROOT
};

/* What a build provides, item by item (SCENE_ERR_BUILD's index): the features
 * SCN_NEED_* by bit number, then the sizes. */
enum {
    SCENE_ITEM_EDGES = 9,
    SCENE_ITEM_SURFACES,
    SCENE_ITEM_DEPTH,
    SCENE_ITEM_LEAF_VERTS,
    SCENE_ITEM_MODEL_VERTS,
    SCENE_ITEM_FACE_VERTS,
    SCENE_ITEM_COUNT
};

/* Validate blob[0..len) and fill s: scene_parse, then the needs record checked
 * against the scene and against what this build provides (build_config.h).
 * Returns SCENE_OK, or a status with details in err (err may be NULL). s is
 * only usable after SCENE_OK. */
scene_status scene_load(scene *s, const void *blob, uint32_t len, scene_error *err);
/* Everything but the needs record's contents (for the compiler, which fills it). */
scene_status scene_parse(scene *s, const void *blob, uint32_t len, scene_error *err);

/* The features the scene's data shows (SCN_NEED_* but LOOK and YCLIP, which are
 * a declaration and an analysis), and the needs fields that are plain maxima
 * and sums of its records (leaf, model and face vertices, own objects). */
uint32_t scene_derived_features(const scene *s);
void scene_static_bounds(const scene *s, scn_needs *n);
/* Edges of model m's faces after clipping, at most (each face n + 5: one more
 * vertex per clipping plane). */
uint32_t scene_model_edges(const scene *s, const scn_model *m);
/* Every world polygon at once, the bound without the analysis: edges after
 * clipping (floors and ceilings n + 5, two wall parts of 4 + 5 per seg) and
 * surfaces. A needs record may never claim more. */
void scene_all_polygons(const scene *s, uint64_t *edges, uint64_t *surfaces);
/* "objects", "edges", ...: a SCENE_ITEM_* or feature bit number, for messages. */
const char *scene_item_name(uint32_t item);

/* Human-readable names, for messages: status ("bad CRC") and section ("segs"). */
const char *scene_status_text(scene_status st);
const char *scene_section_name(int section);

/* The leaf containing map point (x, y) (16.16); points on a partition go to its front. */
uint32_t scene_leaf_at(const scene *s, int32_t x, int32_t y);
/* The sector containing (x, y), or SCN_NONE. */
uint32_t scene_sector_at(const scene *s, int32_t x, int32_t y);

/* Which side of a node's partition a point is on: 0 front (right), 1 back. */
int scene_node_side(const scn_node *n, int32_t x, int32_t y);

#endif
