/* needs_text.c - the needs analysis (needs.c) as words for a person and as a
 * C header for a build compiled for one scene (firmware/build_config.h). */
#include "needs.h"

/* Why a feature is needed or not, by SCN_NEED_* bit number (its name is
 * scene_item_name's, as in the loader's messages). */
static const struct {
    const char *yes, *no;
} feature_text[] = {
    {"the scene has models", "no models"},
    {"a sector's ceiling moves", "every ceiling stays put"},
    {"a line has a sector on both sides", "every line is one-sided"},
    {"floors or ceilings differ", "one floor height, one ceiling height"},
    {"two sky ceilings meet across a line", "no two sky ceilings meet"},
    {"the scene allows it", "the scene says 'look off'"},
    {"a polygon seen from just beside it crosses the screen's top or bottom", "nothing to draw"},
    {"the scene has wall textures, flats and light tables", "flat-shaded"},
    {"an animated texture or flat, or a scrolling wall", "every texture stands still"},
};
_Static_assert(SCN_NEED_ALL == (1u << (sizeof feature_text / sizeof feature_text[0])) - 1u, "one text per feature");
#define NFEATURES (sizeof feature_text / sizeof feature_text[0])

void needs_print(FILE *f, const char *name, const scene *s, const needs_report *r)
{
    const scn_needs *n = &r->needs;
    fprintf(f, "%s: what the scene needs (docs/needs.md)\n", name);
    for (unsigned i = 0; i < NFEATURES; i++) {
        int on = (n->features & (1u << i)) != 0;
        fprintf(f, "  %-16s %-4s %s\n", scene_item_name(i), on ? "yes" : "no",
                on ? feature_text[i].yes : feature_text[i].no);
    }
    fprintf(f, "  per frame, for any camera and door state (every polygon at once: %u edges, %u surfaces):\n",
            r->all_edges, r->all_surfaces);
    fprintf(f, "    edges     %8u = walls %u (most facing an eye anywhere in one leaf's region", n->edges,
            r->wall_edges);
    if (r->worst_leaf != SCN_NONE) fprintf(f, ", leaf %u", r->worst_leaf);
    fprintf(f, ") + floors and ceilings %u (most facing an eye at any height)\n", r->plane_edges);
    fprintf(f, "    surfaces  %8u = walls %u + floors and ceilings %u\n", n->surfaces, r->wall_surfaces,
            r->plane_surfaces);
    fprintf(f, "    tree depth %7u (walk stacks of %u)\n", s->hdr->max_depth, s->hdr->max_depth + 2);
    fprintf(f, "    leaf polygon vertices %u, model vertices %u, face vertices %u\n", n->leaf_verts, n->model_verts,
            n->face_verts);
    fprintf(f, "    own objects: %u, %u faces, %u edges at most\n", s->nobjects, n->object_faces, n->object_edges);
}

static uint32_t at_least(uint32_t v, uint32_t lo)
{
    return v < lo ? lo : v;
}

void needs_write_config(FILE *f, const char *name, const scene *s, const scn_needs *n)
{
    fprintf(f,
            "/* A build for one scene (firmware/build_config.h), written by bspc --config\n"
            " * from the needs of %s (docs/needs.md). */\n",
            name);
    fprintf(f, "#define CFG_FEATURES 0x%02xu /*", n->features);
    for (unsigned i = 0; i < NFEATURES; i++)
        if (n->features & (1u << i)) fprintf(f, " %s;", scene_item_name(i));
    fprintf(f, " */\n");
    fprintf(f, "#define CFG_MAX_EDGES %uu\n", n->edges);
    fprintf(f, "#define CFG_MAX_SURFACES %uu\n", n->surfaces);
    fprintf(f, "#define CFG_MAX_DEPTH %u\n", at_least(s->hdr->max_depth, 1));
    fprintf(f, "#define CFG_LEAF_VERTS %u\n", at_least(n->leaf_verts, 3));
    fprintf(f, "#define CFG_MODEL_VERTS %u\n", at_least(n->model_verts, 1));
    fprintf(f, "#define CFG_FACE_VERTS %u\n", at_least(n->face_verts, 3));
}
