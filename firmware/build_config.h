/* build_config.h - what this build of the renderer provides (prefix CFG_).
 *
 * The full build provides every feature and sizes its buffers from each scene's
 * needs record at run time. A build for one scene (make firmware SCENE=...,
 * make scene-host SCENE=...) includes the header the compiler wrote for it
 * (bspc --config FILE, docs/needs.md), named by SCENE_CONFIG: features the
 * scene does not need are left out (their code is behind if (CFG_...), which
 * the compiler drops) and the fixed buffers are sized to the scene's bounds.
 * The loader refuses a scene that needs more than the build provides. */
#ifndef BUILD_CONFIG_H
#define BUILD_CONFIG_H

#include "scene_format.h"

#ifdef SCENE_CONFIG
#include SCENE_CONFIG
#endif

#ifndef CFG_FEATURES
#define CFG_FEATURES SCN_NEED_ALL
#endif
#ifndef CFG_MAX_EDGES /* world edges and surfaces per frame; the full build: any */
#define CFG_MAX_EDGES 0xFFFFFFFFu
#endif
#ifndef CFG_MAX_SURFACES
#define CFG_MAX_SURFACES 0xFFFFFFFFu
#endif
#ifndef CFG_MAX_DEPTH /* tree depth: the walk stacks hold CFG_MAX_DEPTH + 2 */
#define CFG_MAX_DEPTH SCN_MAX_DEPTH
#endif
#ifndef CFG_LEAF_VERTS
#define CFG_LEAF_VERTS SCN_MAX_LEAF_VERTS
#endif
#ifndef CFG_MODEL_VERTS
#define CFG_MODEL_VERTS SCN_MAX_MODEL_VERTS
#endif
#ifndef CFG_FACE_VERTS
#define CFG_FACE_VERTS SCN_MAX_FACE_VERTS
#endif

/* The render modes this build carries (render.h): a bit each. A firmware carries
 * only the modes it runs, so its work area is only what they need. */
#define CFG_MODE_SPANS 1u
#define CFG_MODE_PAINTER 2u
#define CFG_MODE_DIRECT 4u
#define CFG_MODE_COLUMNS 8u
#ifndef CFG_RENDER_MODES
#define CFG_RENDER_MODES (CFG_MODE_SPANS | CFG_MODE_PAINTER | CFG_MODE_DIRECT | CFG_MODE_COLUMNS)
#endif
#define CFG_MODE(bit) ((CFG_RENDER_MODES & (bit)) != 0)

/* Mode columns' visplanes (columns.c), 652 bytes each: any number from 4 works,
 * a full pool is drawn early. */
#ifndef CFG_COLS_PLANES
#define CFG_COLS_PLANES 64
#endif

/* Mode direct's pools for the faces of the objects met in a frame, and their
 * edges (direct.c): any size works, larger ones only save recomputing. */
#ifndef CFG_DIRECT_FACES
#define CFG_DIRECT_FACES 128
#endif
#ifndef CFG_DIRECT_EDGES
#define CFG_DIRECT_EDGES 512
#endif

#define CFG_HAS(bit) ((CFG_FEATURES & (bit)) != 0)
#define CFG_OBJECTS CFG_HAS(SCN_NEED_OBJECTS)
#define CFG_DOORS CFG_HAS(SCN_NEED_DOORS)
#define CFG_TWO_SIDED CFG_HAS(SCN_NEED_TWO_SIDED)
#define CFG_HEIGHTS CFG_HAS(SCN_NEED_HEIGHTS)
#define CFG_SKY CFG_HAS(SCN_NEED_SKY)
#define CFG_LOOK CFG_HAS(SCN_NEED_LOOK)
#define CFG_YCLIP CFG_HAS(SCN_NEED_YCLIP)
/* CFG_FLAT=1: a build that draws every scene in flat colours, textured ones
 * too (the loader accepts them and leaves their look unused). */
#ifndef CFG_FLAT
#define CFG_FLAT 0
#endif
#define CFG_TEXTURES (CFG_HAS(SCN_NEED_TEXTURES) && !CFG_FLAT)
/* Textures by time (firmware/anim.h): only a textured build draws them. */
#define CFG_ANIM (CFG_HAS(SCN_NEED_ANIM) && CFG_TEXTURES)

/* The most vertices of a polygon before clipping: a wall (4), a leaf floor, an
 * object's face. */
#define CFG_MAX3(a, b, c) ((a) > (b) ? ((a) > (c) ? (a) : (c)) : ((b) > (c) ? (b) : (c)))
#define CFG_POLY_VERTS CFG_MAX3(4, CFG_LEAF_VERTS, CFG_OBJECTS ? CFG_FACE_VERTS : 0)

_Static_assert(CFG_MAX_DEPTH >= 1 && CFG_MAX_DEPTH <= SCN_MAX_DEPTH, "CFG_MAX_DEPTH");
_Static_assert(CFG_LEAF_VERTS >= 3 && CFG_LEAF_VERTS <= SCN_MAX_LEAF_VERTS, "CFG_LEAF_VERTS");
_Static_assert(CFG_MODEL_VERTS >= 1 && CFG_MODEL_VERTS <= SCN_MAX_MODEL_VERTS, "CFG_MODEL_VERTS");
_Static_assert(CFG_FACE_VERTS >= 1 && CFG_FACE_VERTS <= SCN_MAX_FACE_VERTS, "CFG_FACE_VERTS");
_Static_assert((CFG_FEATURES & ~SCN_NEED_ALL) == 0, "CFG_FEATURES");
_Static_assert(CFG_DIRECT_FACES >= 1 && CFG_DIRECT_FACES <= 65535 && CFG_DIRECT_EDGES >= 1 && CFG_DIRECT_EDGES <= 65535,
               "CFG_DIRECT_FACES, CFG_DIRECT_EDGES");
_Static_assert((CFG_RENDER_MODES & 15u) != 0 && (CFG_RENDER_MODES & ~15u) == 0, "CFG_RENDER_MODES");
_Static_assert(CFG_COLS_PLANES >= 4 && CFG_COLS_PLANES <= 4096, "CFG_COLS_PLANES");

#endif
