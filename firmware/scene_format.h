/* scene_format.h - the compiled-scene blob (prefix scn_): the one contract between
 * the BSP compiler (tools/bspc) and the renderer (firmware/scene.c loads it).
 *
 * The blob is little-endian and position-independent: a fixed header, then
 * sections addressed by byte offsets from the start of the blob. Every record is
 * a multiple of 4 bytes and every section starts 4-byte aligned, so a loaded blob
 * (itself 4-byte aligned) can be read in place on a little-endian target.
 * The loader never trusts it: magic, version, sizes, CRC-32, every count, every
 * offset and every index are validated before the renderer touches it.
 *
 * Coordinates and heights are 16.16 (fx_t) map units: x east, y north, z up.
 *
 * Every field that refers to other records says so in brackets at the end of
 * its comment, and tests/test_scene_indices.py corrupts each such field of the
 * first and last record of its type from this list, so a new one is tested too:
 *   [index: SECS]           below the count of section SCN_SEC_SECS (or below a number)
 *   [index: SECS or NONE]   that, or the value NONE
 *   [child]                 a node index, or SCN_LEAF_BIT | a leaf index
 *   [range: SECS]           on "first, num": records [first, first + num) of SECS
 *   [range: SECS, EXPR]     on "first": [first, first + EXPR of the record's fields)
 *   [count of FIELD]        the num of a range annotated on FIELD
 */
#ifndef SCN_FORMAT_H
#define SCN_FORMAT_H

#include <stdint.h>

#define SCN_MAGIC 0x4E435342u /* bytes "BSCN" */
#define SCN_VERSION 6u
#define SCN_NONE 0xFFFFFFFFu     /* "no sector" / "no index" */
#define SCN_LEAF_BIT 0x80000000u /* child index refers to a leaf */

/* Proven-safe ranges (see docs/ranges.md); bspc rejects scenes outside them. */
#define SCN_COORD_MAX 32767   /* |x|, |y| of every vertex, whole units */
#define SCN_HEIGHT_MAX 16383  /* |floor|, |ceiling| heights, whole units */
#define SCN_MAX_DEPTH 255     /* deepest node path the walk stack supports */
#define SCN_MAX_LEAF_VERTS 64 /* most vertices of a leaf floor polygon (clip.h has room for 5 more) */
/* Objects (docs/objects.md) */
#define SCN_MODEL_MAX 1024     /* |x|, |y|, |z| of a model vertex, whole units */
#define SCN_MAX_MODEL_VERTS 64 /* vertices of one model */
#define SCN_MAX_MODEL_FACES 64 /* faces of one model */
#define SCN_MAX_FACE_VERTS 16  /* vertices of one face (clip.h has room for 5 more) */
#define SCN_MAX_OBJECTS 4096   /* objects of one scene */

enum scn_section_id {
    SCN_SEC_VERTICES, /* scn_vertex[]: original vertices first, then split points */
    SCN_SEC_SECTORS,  /* scn_sector[] */
    SCN_SEC_LINES,    /* scn_line[]: linedefs in source order (id buffer index = line*2+side) */
    SCN_SEC_SEGS,     /* scn_seg[]: wall pieces, grouped by leaf */
    SCN_SEC_NODES,    /* scn_node[] */
    SCN_SEC_LEAVES,   /* scn_leaf[] */
    SCN_SEC_PVERTS,   /* scn_vertex[]: leaf floor polygons, convex, counter-clockwise */
    SCN_SEC_PALETTE,  /* 768 bytes: 256 x (r, g, b), 8 bits per gun; count = 256 */
    SCN_SEC_MODELS,   /* scn_model[] (docs/objects.md) */
    SCN_SEC_MVERTS,   /* scn_mvert[]: model vertices, model by model */
    SCN_SEC_FACES,    /* scn_face[]: model faces, model by model */
    SCN_SEC_FINDEX, /* uint32_t[]: face vertex numbers, relative to the model's first vertex [index: the model's vertices] */
    SCN_SEC_OBJECTS, /* scn_object[]: placed objects */
    SCN_SEC_NEEDS,   /* scn_needs[1]: what the scene needs (docs/needs.md) */
    /* A textured scene's look (docs/textures.md); every count is 0 in a flat-shaded scene. */
    SCN_SEC_LOOK,     /* scn_look[1] */
    SCN_SEC_LIGHTS,   /* light tables: records of 256 bytes (palette index -> palette index), brightest first */
    SCN_SEC_TEXTURES, /* scn_texture[]: wall textures and flats the scene uses */
    SCN_SEC_TEXELS,   /* uint8_t[]: the textures' texels (count = bytes; the section is padded to 4) */
    SCN_SEC_SIDES,    /* scn_side[]: per line side, index line * 2 + side */
    SCN_SEC_PLANES,   /* scn_plane[]: per sector, its floor and ceiling textures */
    /* Sprites of WAD things (docs/objects.md, "Sprites"); counts 0 in a flat-shaded scene. */
    SCN_SEC_SPRITES, /* scn_sprite[]: sprite images (their texels are in SCN_SEC_TEXELS) */
    SCN_SEC_SPRMASK, /* uint32_t[]: the images' opacity bits */
    SCN_SEC_SPRSETS, /* scn_sprset[]: a thing's image for each of the 8 rotations */
    /* Textures by time (docs/textures.md, "Animation"); none without a look, none in a map without. */
    SCN_SEC_ANIMS, /* scn_anim[]: animated textures and flats, by first frame, not overlapping */
    SCN_SEC_COUNT
};

typedef struct {
    uint32_t offset; /* from the start of the blob, multiple of 4 */
    uint32_t count;  /* records */
} scn_section;

typedef struct {
    uint32_t magic;             /* SCN_MAGIC */
    uint16_t version;           /* SCN_VERSION */
    uint16_t header_bytes;      /* sizeof(scn_header) */
    uint32_t total_bytes;       /* whole blob */
    uint32_t crc32;             /* CRC-32 (IEEE, as zlib) of bytes [16, total_bytes) */
    uint32_t flags;             /* reserved, 0 */
    int32_t player_x, player_y; /* 16.16 */
    int32_t player_angle;       /* degrees, 16.16, 0 = east, counter-clockwise */
    uint32_t player_sector;     /* sector of the player start, or SCN_NONE [index: SECTORS or SCN_NONE] */
    uint32_t root;              /* node index, or SCN_LEAF_BIT | leaf index [child] */
    uint32_t max_depth;         /* longest root-to-leaf path, in nodes */
    scn_section sec[SCN_SEC_COUNT];
} scn_header;

typedef struct {
    int32_t x, y; /* 16.16 */
} scn_vertex;

#define SCN_SECTOR_SKY 1u  /* ceiling is sky */
#define SCN_SECTOR_DOOR 2u /* a door: the ceiling moves between ceil_h (closed) and open_h */

typedef struct {
    int32_t floor_h, ceil_h; /* 16.16; ceil_h is a door's closed ceiling */
    uint8_t floor_color, ceil_color, light, flags;
    int32_t open_h; /* 16.16: a door's open ceiling (>= ceil_h); ceil_h for other sectors */
} scn_sector;

enum { SCN_PART_UPPER, SCN_PART_MIDDLE, SCN_PART_LOWER };

typedef struct {
    uint32_t v1, v2;     /* vertex indices; the front side is on the right going v1 -> v2 [index: VERTICES] */
    uint32_t sector[2];  /* front, back (SCN_NONE: one-sided) [index: SECTORS or SCN_NONE] */
    uint8_t color[2][3]; /* [side][SCN_PART_*] */
    uint16_t flags;      /* reserved, 0 */
} scn_line;

typedef struct {
    uint32_t v1, v2; /* vertex indices; the seg faces right going v1 -> v2 [index: VERTICES] */
    uint32_t line;   /* linedef index [index: LINES] */
    uint32_t side;   /* 0 front, 1 back of the linedef [index: 2] */
} scn_seg;

/* The sides of a map box, in the order a node's child boxes keep them (and
 * every other box of map coordinates in the core): box[BOX_TOP] is ymax. */
enum { BOX_TOP, BOX_BOTTOM, BOX_LEFT, BOX_RIGHT, BOX_SIDES };

typedef struct {
    int32_t x, y, dx, dy;       /* partition line through (x,y) along (dx,dy), 16.16; front = right side */
    int32_t bbox[2][BOX_SIDES]; /* [child][BOX_*]: ymax, ymin, xmin, xmax, 16.16 */
    uint32_t child[2];          /* 0 front (right), 1 back; SCN_LEAF_BIT marks a leaf [child] */
} scn_node;

typedef struct {
    uint32_t first_seg, num_segs;     /* segs[first_seg .. first_seg + num_segs) [range: SEGS] */
    uint32_t sector;                  /* the leaf's sector (SCN_NONE if it has none) [index: SECTORS or SCN_NONE] */
    uint32_t first_pvert, num_pverts; /* floor polygon in pverts[] (0 pverts if degenerate) [range: PVERTS] */
} scn_leaf;

/* A model: convex parts made of faces over its vertices (model space: x forward,
 * y left, z up, 16.16, |v| <= SCN_MODEL_MAX units). */
typedef struct {
    uint32_t first_vert, num_verts; /* mverts[first_vert ..), at most SCN_MAX_MODEL_VERTS [range: MVERTS] */
    uint32_t first_face, num_faces; /* faces[first_face ..), at most SCN_MAX_MODEL_FACES [range: FACES] */
    int32_t radius;                 /* 16.16: largest horizontal distance of a vertex from the origin */
    int32_t zmin, zmax;             /* 16.16: lowest and highest vertex */
} scn_model;

typedef struct {
    int32_t x, y, z; /* 16.16 model space */
} scn_mvert;

typedef struct {
    /* findex[first_index .. + num_index): vertex numbers within the model */
    uint32_t first_index; /* [range: FINDEX, num_index] */
    uint16_t num_index;   /* 3 .. SCN_MAX_FACE_VERTS, counter-clockwise seen from outside [count of first_index] */
    uint8_t colour;
    uint8_t part; /* convex part of the model it belongs to */
} scn_face;

enum { SCN_PATH_NONE, SCN_PATH_CIRCLE, SCN_PATH_LINE };

typedef struct {
    uint32_t model;     /* [index: MODELS] */
    int32_t x, y, z;    /* 16.16: the origin at time 0 (circle: the circle's centre) */
    int32_t yaw;        /* degrees, 16.16 */
    uint32_t path;      /* SCN_PATH_* [index: 3] */
    int32_t pa, pb;     /* 16.16: circle radius, 0; line DX, DY */
    uint32_t period_ms; /* one turn or one round trip; > 0 when path != SCN_PATH_NONE */
    int32_t spin;       /* degrees per second, 16.16 */
    uint32_t sprset;    /* drawn as this sprite set, or SCN_NONE: as its model [index: SPRSETS or SCN_NONE] */
    uint32_t
        side; /* see-through middle texture: its side's, row 0 at z (docs/textures.md) [index: SIDES or SCN_NONE] */
} scn_object;

/* ---- Textures and light (docs/textures.md) ---- */

#define SCN_TEX_NONE 0xFFFFu /* no texture: the part or plane keeps its flat colour */
#define SCN_LIGHT_MAPS 32    /* light tables of a textured scene (Doom's COLORMAP 0..31) */
#define SCN_TEX_MAX_BITS 10  /* a texture is at most 1024 x 1024 texels */

typedef struct {
    uint32_t sky_tex; /* scn_texture index of the sky, or SCN_TEX_NONE [index: TEXTURES or SCN_TEX_NONE] */
    uint32_t flags;   /* reserved, 0 */
} scn_look;

/* A texture of 2^wbits columns of 2^hbits texels, column-major: texel (u, v)
 * (column u from the left, row v from the top) is
 * texels[first + ((u & (2^wbits - 1)) << hbits) + (v & (2^hbits - 1))], so
 * coordinates wrap. Wall textures keep Doom's rule: the columns up to the
 * largest power of two not above the width (the rest is never shown); a height
 * that is not a power of two is padded to the next one by repeating rows from
 * the top. A flat is 64 x 64 with u = map x, v = -map y (Doom's alignment). */
typedef struct {
    uint32_t first;       /* first texel in SCN_SEC_TEXELS [range: TEXELS, 1 << (wbits + hbits)] */
    uint8_t wbits, hbits; /* 0 .. SCN_TEX_MAX_BITS */
    uint8_t colour;       /* palette index nearest the texture's mean colour [index: PALETTE] */
    uint8_t reserved;     /* 0 */
    uint16_t height;      /* rows as the WAD gives them (<= 2^hbits): Doom's pegging counts these */
    uint16_t mask;        /* its holes: texels 1 opaque, 0 a hole; NONE: opaque [index: TEXTURES or SCN_TEX_NONE] */
} scn_texture;

#define SCN_SIDE_UNPEG_TOP 1u    /* Doom's linedef flag 8: upper texture hangs from the front ceiling */
#define SCN_SIDE_UNPEG_BOTTOM 2u /* Doom's linedef flag 16: lower from the front ceiling, middle from the floor */
#define SCN_SIDE_SCROLL 4u       /* Doom's line special 48: the texture column grows by 1 unit a tic */

/* How a line side's wall parts are textured. The texture column at map point
 * P (16.16) is u(P) = ((ux * P.x + uy * P.y) >> 30) + u0: (ux, uy) is the unit
 * vector along the side (from the line's v1 for side 0, from v2 for side 1),
 * u0 folds in where that runs from and the side's x offset. */
typedef struct {
    int32_t ux, uy;   /* 2.30 */
    int32_t u0;       /* 16.16 */
    int32_t row_off;  /* 16.16: the side's y offset (added to every part's texture row) */
    uint16_t tex[3];  /* [SCN_PART_*]: scn_texture index, or SCN_TEX_NONE [index: TEXTURES or SCN_TEX_NONE] */
    uint8_t flags;    /* SCN_SIDE_* */
    int8_t light_adj; /* Doom's fake contrast in light levels: -1 along x (east-west), +1 along y, else 0 */
} scn_side;

typedef struct {
    uint16_t floor_tex; /* scn_texture index, or SCN_TEX_NONE [index: TEXTURES or SCN_TEX_NONE] */
    uint16_t ceil_tex;  /* the same; SCN_TEX_NONE is a sky ceiling [index: TEXTURES or SCN_TEX_NONE] */
} scn_plane;

/* ---- Sprites (docs/objects.md, "Sprites") ---- */

#define SCN_SPRITE_MAX 512   /* width and height of a sprite image, texels */
#define SCN_SPRITE_ROTS 8    /* Doom's rotations: 0 seen from the front, then every 45 degrees */
#define SCN_SPRSET_BRIGHT 1u /* full-bright: drawn with light table 0 */

/* An image of a sprite: Doom's patch, decoded. Column u (0 left) row v (0 top)
 * is texels[first + u * height + v]; it is opaque where bit (v & 31) of
 * mask words[mask + u * ((height + 31) >> 5) + (v >> 5)] is set. */
typedef struct {
    uint32_t first;         /* [range: TEXELS, width * height] */
    uint32_t mask;          /* [range: SPRMASK, width * ((height + 31) >> 5)] */
    uint16_t width, height; /* 1 .. SCN_SPRITE_MAX */
    int16_t left, top;      /* Doom's offsets: the origin is left texels right of column 0, row 0 top above it */
} scn_sprite;

/* The images of one thing, by rotation (the angle from the eye to the thing,
 * less the thing's yaw: docs/objects.md). */
typedef struct {
    uint16_t image[8]; /* by rotation (SCN_SPRITE_ROTS) [index: SPRITES] */
    uint8_t mirror;    /* bit r: rotation r's image is drawn mirrored left to right */
    uint8_t flags;     /* SCN_SPRSET_* */
    uint16_t reserved; /* 0 */
} scn_sprset;

/* ---- Textures by time (docs/textures.md, "Animation") ---- */

#define SCN_ANIM_MAX_FRAMES 64 /* frames of one sequence (Doom's longest has 4) */
#define SCN_ANIM_MAX_TICS 3500 /* tics a frame shows (Doom's: 8; 35 tics a second) */

/* Doom's animated wall textures and flats: the frames of a sequence are the
 * textures [first, first + count), stored in the WAD's own order. At level time
 * T tics (floor(t_ms * 35 / 1000)) texture first + k shows texture
 * first + ((T / tics + phase + k) mod count): phase is the WAD's number of the
 * first frame (its texture or flat number) modulo count, as Doom's
 * P_UpdateSpecials counts it. Records are sorted by first and do not overlap. */
typedef struct {
    uint32_t first;    /* the first frame [range: TEXTURES, count] */
    uint16_t count;    /* 2 .. SCN_ANIM_MAX_FRAMES [count of first] */
    uint16_t phase;    /* 0 .. count - 1 */
    uint16_t tics;     /* 1 .. SCN_ANIM_MAX_TICS */
    uint16_t reserved; /* 0 */
} scn_anim;

/* What a scene needs of a renderer, written by the compiler's analysis
 * (tools/bspc/needs.c, docs/needs.md). A build compiled for one scene
 * (firmware/build_config.h) leaves out every feature whose bit is clear and
 * sizes its buffers to the bounds; its loader refuses a scene that needs more.
 * The bounds hold for every camera the renderer accepts (any position in the
 * coordinate box, any height, any angle and look) and every door state. */
/* Macros, not an enum: builds test them in #if (build_config.h's CFG_TEXTURES). */
#define SCN_NEED_OBJECTS (1u << 0)   /* models (objects are placed from them) */
#define SCN_NEED_DOORS (1u << 1)     /* a sector whose ceiling moves */
#define SCN_NEED_TWO_SIDED (1u << 2) /* a line with a sector on both sides */
#define SCN_NEED_HEIGHTS (1u << 3)   /* floors or ceilings at more than one height */
#define SCN_NEED_SKY (1u << 4)       /* two sky ceilings meet at a step (Doom's sky rule) */
#define SCN_NEED_LOOK (1u << 5)      /* the camera may look up and down */
#define SCN_NEED_YCLIP (1u << 6)     /* a polygon can cross the top or bottom screen edge */
#define SCN_NEED_TEXTURES (1u << 7)  /* textures, light tables and a sky (docs/textures.md) */
#define SCN_NEED_ANIM (1u << 8)      /* animated textures or flats, or scrolling walls (docs/textures.md) */
#define SCN_NEED_ALL ((1u << 9) - 1u)

typedef struct {
    uint32_t features;     /* SCN_NEED_* */
    uint32_t edges;        /* most world edges on the edge lists in one frame (mode spans) */
    uint32_t surfaces;     /* most world surfaces in one frame */
    uint32_t leaf_verts;   /* most vertices of a leaf floor polygon */
    uint32_t object_faces; /* faces of the scene's own objects */
    uint32_t object_edges; /* their edges after clipping, at most */
    uint32_t model_verts;  /* most vertices of one model */
    uint32_t face_verts;   /* most vertices of one model face */
} scn_needs;

#endif
