/* bspc_int.h - private types and helpers shared by the BSP compiler's files
 * (prefix bs_). Not installed, not used outside tools/bspc.
 *
 * Pipeline (bspc.c): a source scene (scene_text.c or wad.c) becomes a bs_scene;
 * scene_check.c validates it and finds the player's sector; bsp_build.c builds
 * the tree (split choice, exact seg splitting, leaf regions); leaf_poly.c owns
 * the convex-polygon clipping; tjunc.c removes T-junctions from segs and leaf
 * polygons; leaf_split.c cuts floor polygons too big for the renderer; blob_write.c writes firmware/scene_format.h.
 *
 * Numbers: every coordinate is 16.16 (one raw unit = 1/65536 map unit) held in
 * an int32_t. Side tests and intersections use exact integer arithmetic
 * (__int128 products); the only tolerance is BS_EPS, see geom.h.
 */
#ifndef BSPC_INT_H
#define BSPC_INT_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "bspc.h"
#include "scene_format.h"

__extension__ typedef __int128 bs_i128;
__extension__ typedef unsigned __int128 bs_u128;

#define BS_COORD_RAW_MAX ((int64_t)SCN_COORD_MAX * 65536)
#define BS_HEIGHT_RAW_MAX ((int64_t)SCN_HEIGHT_MAX * 65536)

/* ---- errors and warnings (util.c) ---- */

/* Format a one-line message into err; always returns -1. */
int bs_fail(char *err, size_t errlen, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Print "bspc: warning: ..." on stderr when opt->verbose; otherwise silent. */
void bs_warn(const bspc_options *opt, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Same, without the "warning:" prefix (progress notes). */
void bs_note(const bspc_options *opt, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Grow *p (element size sz) so that it holds at least need elements. 0 or -1. */
int bs_grow(void *pp, uint32_t *cap, uint32_t need, size_t sz);
/* FNV-1a of a NUL-terminated name: the hash of the compiler's name lookups. */
uint32_t bs_name_hash(const char *s);
/* A 16.16 value as exact decimal text (fxtext_format), for messages. */
const char *bs_fxstr(int32_t v, char buf[32]);
double bs_now_ms(void);

/* ---- the source scene ---- */

typedef struct {
    int32_t floor_h, ceil_h; /* 16.16; ceil_h is a door's closed ceiling */
    int32_t open_h;          /* 16.16: a door's open ceiling (SCN_SECTOR_DOOR); unused otherwise */
    uint8_t floor_color, ceil_color, light, flags;
    int src_line;  /* text: line of the declaration; WAD: 0 */
    char name[32]; /* text: optional name; WAD: "" */
} bs_sector;

typedef struct {
    uint32_t v1, v2;     /* scene vertex indices */
    uint32_t sector[2];  /* front, back (SCN_NONE) */
    uint8_t color[2][3]; /* [side][SCN_PART_*] */
    int src_line;        /* text: line number; WAD: linedef index in the lump */
} bs_line;

/* Models (docs/objects.md): the records of scn_model / scn_mvert / scn_face,
 * with findex numbers relative to the model's first vertex. */
typedef struct {
    int32_t x, y, z; /* 16.16 model space */
} bs_mvert;

typedef struct {
    uint32_t first_index; /* into bs_scene.findex */
    uint16_t num_index;
    uint8_t colour, part;
} bs_face;

/* Each part has at least 6 vertices (a 3-sided prism). */
#define BS_MAX_PARTS (SCN_MAX_MODEL_VERTS / 6)

typedef struct {
    uint32_t first_vert, num_verts, first_face, num_faces;
    uint32_t nparts;
    uint8_t part_vert[BS_MAX_PARTS];  /* a part's first vertex, relative to first_vert */
    uint8_t part_sides[BS_MAX_PARTS]; /* its ring's corner count */
    int32_t radius, zmin, zmax;       /* set by bs_model_end */
    int src_line;                     /* text: the model statement; WAD: 0 */
    char name[32];                    /* text: its name; WAD: "" */
} bs_model;

typedef struct {
    uint32_t model;
    int32_t x, y, z, yaw; /* 16.16; yaw in degrees, [0, 360) */
    int has_z;            /* 0: z is the floor under (x, y), found after the build */
    uint32_t path;        /* SCN_PATH_* */
    int32_t pa, pb;       /* 16.16 */
    uint32_t period_ms;
    int32_t spin;     /* degrees per second, 16.16 */
    int src_line;     /* text: line; WAD: thing index in the lump */
    uint32_t sprset1; /* 1 + its bs_look sprite set; 0: drawn as its model */
    uint32_t side1;   /* a see-through middle texture: 1 + its line side (line * 2 + side); 0: none */
} bs_object;

/* Limits beyond scene_format.h that keep the path arithmetic of docs/objects.md
 * inside 64 bits; the loader enforces the same. */
#define BS_PERIOD_MAX_MS 3600000u /* one hour */
#define BS_SPIN_MAX 3600          /* |degrees per second| */

/* A WAD map's look (docs/textures.md), filled by wad_look.c: the records of
 * the look sections, ready to write. */
typedef struct {
    int present;      /* write the look sections (not under --flat) */
    int doom_palette; /* palette[] is PLAYPAL's (even under --flat) */
    uint8_t palette[768];
    uint8_t *lights; /* SCN_LIGHT_MAPS tables of 256 */
    scn_texture *tex;
    uint32_t ntex, tcap;
    uint8_t *texels;
    uint32_t ntexels, txcap;
    uint32_t sky_tex;      /* SCN_TEX_NONE: no sky */
    scn_side *sides;       /* 2 per scene line, index line * 2 + side */
    scn_plane *planes;     /* one per sector */
    uint8_t shade[3][256]; /* model faces' fake contrast under PLAYPAL: [contrast + 1][colour] */
    /* the things' sprites (docs/objects.md, "Sprites"); their texels are in texels[] */
    scn_sprite *sprites;
    uint32_t nsprites, spcap;
    uint32_t *sprmask;
    uint32_t nsprmask, smcap;
    scn_sprset *sprsets;
    uint32_t nsprsets, sscap;
    /* animated textures and flats (anims.c): sequences of frames stored one after another */
    scn_anim *anims;
    uint32_t nanims, acap;
} bs_look;

typedef struct {
    char name[300];   /* for messages: "a.scene" or "x.wad:MAP01" */
    int is_text;      /* messages quote text line numbers */
    int32_t *vx, *vy; /* 16.16 */
    uint32_t nverts, vcap;
    bs_sector *sectors;
    uint32_t nsectors, scap;
    bs_line *lines;
    uint32_t nlines, lcap;
    int has_player;
    int no_look;                              /* text: 'look off': the camera keeps its horizon level */
    int32_t player_x, player_y, player_angle; /* 16.16; angle in degrees */
    int player_line;
    uint32_t player_sector; /* filled by bs_scene_check / bspc.c */
    bs_model *models;
    uint32_t nmodels, mcap;
    bs_mvert *mverts;
    uint32_t nmverts, mvcap;
    bs_face *faces;
    uint32_t nfaces, fcap;
    uint32_t *findex;
    uint32_t nfindex, ficap;
    bs_object *objects;
    uint32_t nobjects, ocap;
    uint32_t ndoors;
    bs_look look;
} bs_scene;

void bs_scene_free(bs_scene *s);
/* Append a vertex; returns its index or SCN_NONE on allocation failure. */
uint32_t bs_scene_add_vertex(bs_scene *s, int32_t x, int32_t y);

/* scene_text.c: parse the text format (docs/scene-format.md). */
int bs_read_text(const char *path, bs_scene *s, const bspc_options *opt, char *err, size_t errlen);
/* wad.c: read one Doom-format map. wadpath: a resolved file; map: "MAP01"/"E1M1";
 * display: the spec as the user wrote it, for messages. */
int bs_read_wad(const char *wadpath, const char *map, const char *display, bs_scene *s, const bspc_options *opt,
                char *err, size_t errlen);

/* wad_look.c: a WAD's palette, light tables, textures, flats and sprites
 * (docs/textures.md). wad.c reads the directory and the map; it opens the look
 * once (NULL and 0: the WAD has none, the scene stays flat as before), then
 * asks it for each sector, each line side and each thing, and closes it. */
typedef struct {
    uint32_t pos, size;
    char name[9];
} bs_wadlump;
typedef struct bs_wadlook bs_wadlook;
int bs_look_open(FILE *f, const char *wadpath, size_t flen, const bs_wadlump *dir, uint32_t ndir, const char *map,
                 bs_scene *s, uint32_t nsectors, uint32_t nlinedefs, const bspc_options *opt, bs_wadlook **out,
                 char *err, size_t errlen);
/* Sector i from its SECTORS record: plane textures and flat colours. */
int bs_look_sector(bs_wadlook *L, uint32_t i, const uint8_t rec[26], char *err, size_t errlen);
/* Side k of scene line li (vertices and sectors set) from its SIDEDEFS record
 * and the linedef's flags: textures, column mapping, pegging, flat colours. */
int bs_look_side(bs_wadlook *L, uint32_t li, int k, const uint8_t rec[30], unsigned line_flags, char *err,
                 size_t errlen);
/* A thing's box colour: the sprite's mean colour, or fallback (a default-palette
 * colour of things.txt) moved to the nearest PLAYPAL colour. */
uint8_t bs_look_thing_colour(bs_wadlook *L, const char prefix[4], uint8_t fallback);
/* Wall texture tex's holes (docs/textures.md): if a patch leaves any texel of
 * it uncovered, an opacity map (texels 1 and 0) is stored as a texture and
 * named by tex's mask. 0, or -1 with a message. */
int bs_look_mask(bs_wadlook *L, uint16_t tex, char *err, size_t errlen);
/* sprites.c: the sprite set of a thing type (docs/objects.md, "Sprites"):
 * its sprite, frame letter and SCN_SPRSET_* flags from things.txt. 0 and
 * *set1 = 1 + the set's index in s->look.sprsets, with the box around its
 * images (radius, height: whole units, at least 1); or 0 and *set1 = 0 when the
 * type stays a box (no look, --flat, or the WAD lacks the images: -v says
 * why); -1 with a message for damaged sprite data. A set asked for again is
 * the same set; each lump is stored once. */
int bs_look_thing_sprite(bs_wadlook *L, const char sprite[4], char frame, unsigned flags, uint32_t *set1,
                         int32_t *radius, int32_t *height, char *err, size_t errlen);
/* Keep only the sprite sets the scene's objects name, and the images those
 * use (after objects were left out), in their order. */
void bs_sprites_prune(bs_scene *s);
/* Done (also after a failure): the look is kept unless --flat (the Doom palette
 * and colours stay either way). */
void bs_look_close(bs_wadlook *L);
/* default-palette colour, one light step brighter (+1) or darker (-1), in the scene's palette */
uint8_t bs_scene_shade(const bs_scene *s, uint8_t c, int delta);

/* scene_check.c: ranges (both inputs); closed loops and orientation (strict, text
 * scenes); the player's sector by winding number (SCN_NONE if outside all). */
int bs_check_ranges(const bs_scene *s, char *err, size_t errlen);
int bs_check_closed(const bs_scene *s, char *err, size_t errlen);
uint32_t bs_player_sector(const bs_scene *s);
/* crossings.c: refuse two walls whose insides cross, naming both and the point. */
int bs_check_crossings(const bs_scene *s, char *err, size_t errlen);
/* The sector containing (x, y) by the same winding-number rule, or SCN_NONE. */
uint32_t bs_point_sector(const bs_scene *s, int32_t x, int32_t y);

/* models.c: model geometry (docs/objects.md). A model is begun, given parts, and
 * ended; each call returns 0, or -1 with a message (without file or line: the
 * caller prefixes them) in err. */
typedef struct {
    int sides;                 /* 4 for a box, N for a prism */
    int box;                   /* corners at (+-w/2, +-d/2) instead of on a circle */
    int32_t w, d, r, h;        /* 16.16, > 0 */
    int32_t at[3];             /* 16.16 */
    uint8_t top, bottom, side; /* colours; side before fake contrast */
} bs_mpart;
int bs_model_begin(bs_scene *s, const char *name, int src_line, char *err, size_t errlen);
int bs_model_add_part(bs_scene *s, const bs_mpart *p, char *err, size_t errlen);
int bs_model_end(bs_scene *s, char *err, size_t errlen);
/* A textured WAD map's see-through middle textures (mids.c): the opacity maps
 * of the middle textures of two-sided lines (before the things' sprites,
 * whose texels bs_sprites_prune compacts at the end), then the objects that
 * show them (after the things, whose objects keep THINGS order). */
int bs_mid_masks(bs_scene *s, bs_wadlook *look, const bspc_options *opt, char *err, size_t errlen);
int bs_mid_objects(bs_scene *s, bs_wadlook *look, const char *display, const bspc_options *opt, char *err,
                   size_t errlen);
/* Shade c one step lighter (+1) or darker (-1) within its ramp of 16. */
uint8_t bs_shade(uint8_t c, int delta);

/* palette.c: the default 256-colour palette: 16 ramps (hues) x 16 shades,
 * index = ramp * 16 + shade, shade 0 darkest. See docs/scene-format.md. */
enum {
    BS_RAMP_GREY,
    BS_RAMP_RED,
    BS_RAMP_ORANGE,
    BS_RAMP_YELLOW,
    BS_RAMP_LIME,
    BS_RAMP_GREEN,
    BS_RAMP_TEAL,
    BS_RAMP_CYAN,
    BS_RAMP_BLUE,
    BS_RAMP_VIOLET,
    BS_RAMP_MAGENTA,
    BS_RAMP_BROWN,
    BS_RAMP_SAND,
    BS_RAMP_MOSS,
    BS_RAMP_SLATE,
    BS_RAMP_PLUM,
    BS_RAMP_COUNT
};
void bs_palette(uint8_t pal[768]);
const char *bs_ramp_name(int ramp);
/* "NAME" or "NAME:SHADE" (shade 0..15, default 10) -> index; -1 if unknown. */
int bs_color_by_name(const char *s);
/* Doom texture / flat names (up to 8 chars, not NUL-terminated when 8 long). */
uint8_t bs_wall_color(const char tex[8], int light, int contrast);
uint8_t bs_flat_color(const char flat[8], int light, int ceiling);
uint8_t bs_sky_color(void);
uint8_t bs_neutral_color(int light);

/* ---- geometry (geom.c, geom.h) ---- */

typedef struct {
    int32_t x, y;     /* a point of the line, 16.16 */
    int32_t dx, dy;   /* direction as written to scn_node, 16.16 raw; not both 0 */
    int32_t rdx, rdy; /* the same direction divided by gcd(dx, dy): used by the arithmetic */
    int64_t thr;      /* |cross| <= thr means "on the line": isqrt(BS_EPS^2 (rdx^2+rdy^2)) */
    int small;        /* |rdx|, |rdy| < 2^29: cross products fit in 64 bits */
} bs_pline;

typedef struct {
    int32_t x, y;
    uint32_t eline; /* bs_pline index of the edge from this vertex to the next */
} bs_pv;

typedef struct {
    bs_pv *v;
    uint32_t n, cap;
} bs_poly;

/* ---- the tree under construction (bsp_build.c) ---- */

typedef struct {
    int32_t x1, y1, x2, y2; /* copies of the vertex coordinates */
    uint32_t v1, v2;        /* tree vertex indices */
    uint32_t line;          /* linedef (also its bs_pline index) */
    uint32_t side;          /* 0 front, 1 back: the seg runs v2->v1 of the line */
} bs_seg;

typedef struct {
    uint32_t pline; /* partition = plines[pline], reversed when rev */
    uint32_t rev;
    uint32_t child[2];
    int32_t bbox[2][4];
} bs_node;

typedef struct {
    uint32_t *segs;
    uint32_t nsegs, cap;
    uint32_t sector;
    uint32_t depth;  /* nodes on the path from the root */
    uint32_t parent; /* node index or SCN_NONE */
    bs_poly poly;
} bs_leaf;

typedef struct {
    /* vertices: scene vertices that lines use, in scene order, then split points */
    int32_t *vx, *vy;
    uint32_t nverts, vcap, norig;
    uint32_t *line_v; /* per line: tree indices of v1, v2 */
    uint32_t *vhash;  /* open addressing: vertex index + 1, 0 empty */
    uint32_t hcap;
    bs_pline *plines; /* one per line, the 4 world-box edges, then free partitions */
    uint32_t nplines, plcap;
    bs_seg *segs;
    uint32_t nsegs, segcap, nsides;
    bs_node *nodes;
    uint32_t nnodes, nodecap;
    bs_leaf *leaves;
    uint32_t nleaves, leafcap;
    uint32_t root;
    uint32_t max_depth;
    double mean_depth;
    uint32_t part_splits; /* seg splits made by partitions */
    uint32_t tj_splits;   /* seg splits made by T-junction removal */
    uint32_t tj_pverts;   /* vertices inserted into leaf polygons */
    int32_t world[4];     /* xmin, ymin, xmax, ymax of the world box (16.16) */
} bs_tree;

/* Wall pieces a compile may make. Walls that do not cross (crossings.c refuses
 * the others) need O(n log n) pieces for n wall sides (Paterson and Yao's bound
 * for autopartitions): nested rooms, where every partition cuts the rooms
 * around it, need the log factor (150 concentric squares, 1,196 sides: 7,104
 * pieces); the 68 Freedoom maps make at most 12% more pieces than sides. The
 * budget is sides x (log2 sides + 2) + 4,096. A damaged WAD whose walls cross
 * everywhere splits quadratically, and the T-junction passes then cost pieces x
 * points: such a compile is refused at the budget instead of running for
 * minutes toward a polygon the renderer could not take. */
uint64_t bs_seg_budget(const bs_tree *t);
int bs_seg_budget_check(const bs_tree *t, const char *name, uint32_t more, uint32_t line, char *err, size_t errlen);

/* Vertex table: index of (x, y), adding it if new; SCN_NONE on allocation failure. */
uint32_t bs_vertex(bs_tree *t, int32_t x, int32_t y);

int bs_build(const bs_scene *s, const bspc_options *opt, bs_tree *t, char *err, size_t errlen);

/* split_choice.c: partition choice for a set of segs */
typedef struct {
    uint32_t pl, rev; /* the line plines[pl], reversed when rev */
    /* pl == SCN_NONE: a line on no seg, to be made by the caller: x = c (axis 0,
     * pointing north) or y = c (axis 1, pointing east) */
    int axis;
    int32_t c;
} bs_part;
typedef struct bs_chooser bs_chooser;
bs_chooser *bs_chooser_new(const bs_tree *t, bspc_split strategy);
void bs_chooser_free(bs_chooser *C);
/* 0 and *out: a partition for the set; 1: the set is convex (a leaf); -1: out of memory */
int bs_choose(bs_chooser *C, const uint32_t *segs, uint32_t n, uint32_t depth, bs_part *out);
/* Does seg g, lying on the line of p, run the same way as p? */
int bs_same_dir(const bs_tree *t, const bs_seg *g, bs_part p);
void bs_tree_free(bs_tree *t);

/* leaf_poly.c */
void bs_poly_free(bs_poly *p);
int bs_poly_push(bs_poly *p, int32_t x, int32_t y, uint32_t eline);
/* Split p by the oriented line (pl, rev) into the part on its front (right) and
 * the part on its back; either may come out empty (n == 0). -1 on allocation failure. */
int bs_poly_split(const bs_tree *t, const bs_poly *p, uint32_t pl, uint32_t rev, bs_poly *front, bs_poly *back);
/* Keep only the front (right) part of p, in place. */
int bs_poly_clip_front(const bs_tree *t, bs_poly *p, uint32_t pl, uint32_t rev);
/* Drop repeated points and degenerate polygons (< 3 distinct points, zero area). */
void bs_poly_tidy(bs_poly *p);

/* tjunc.c */
int bs_tjunc_segs(bs_tree *t, const char *name, char *err, size_t errlen);
int bs_tjunc_polys(bs_tree *t, char *err, size_t errlen);

/* leaf_split.c: cut every leaf whose floor polygon has more than
 * SCN_MAX_LEAF_VERTS corners into convex pieces (new nodes on chords). */
int bs_split_big_leaves(bs_tree *t, const char *name, char *err, size_t errlen);

/* blob_write.c */
int bs_write_blob(const bs_scene *s, const bs_tree *t, uint8_t **blob, size_t *len, char *err, size_t errlen);

#endif
