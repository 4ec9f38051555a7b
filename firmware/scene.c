/* scene.c - compiled-scene validation and point location. Every offset, count and
 * index is checked here, in 64-bit arithmetic so no sum can wrap; the tree walk
 * that proves the node graph is a tree is bounded by the node count. */
#include "scene.h"
#include "crc32.h"
#include "fixed.h"

static const uint32_t record_bytes[SCN_SEC_COUNT] = {
    sizeof(scn_vertex), sizeof(scn_sector), sizeof(scn_line), sizeof(scn_seg),
    sizeof(scn_node), sizeof(scn_leaf), sizeof(scn_vertex), 3,
    sizeof(scn_model), sizeof(scn_mvert), sizeof(scn_face), sizeof(uint32_t), sizeof(scn_object),
};

const char *scene_status_text(scene_status st)
{
    static const char *const text[SCENE_ERR_COUNT] = {
        "ok", "truncated", "not 4-byte aligned in memory", "wrong magic (not a compiled scene)",
        "unsupported version", "inconsistent header", "bad CRC-32", "section outside the blob",
        "index out of range", "value outside the proven-safe range", "node graph is not a tree or is too deep",
    };
    return ((unsigned)st < SCENE_ERR_COUNT) ? text[st] : "unknown error";
}

const char *scene_section_name(int section)
{
    static const char *const names[SCN_SEC_COUNT] = {
        "vertices", "sectors", "lines", "segs", "nodes", "leaves", "leaf polygon vertices", "palette",
        "models", "model vertices", "faces", "face indices", "objects",
    };
    return (section >= 0 && section < SCN_SEC_COUNT) ? names[section] : "header";
}

static scene_status fail(scene_error *err, scene_status st, int section, uint32_t index)
{
    if (err) {
        err->status = st;
        err->section = section;
        err->index = index;
    }
    return st;
}

static int coord_ok(int32_t v, int32_t limit_units)
{
    int64_t lim = (int64_t)limit_units << 16;
    return v >= -lim && v <= lim;
}

static scene_status check_sections(scene *s, const uint8_t *base, const scn_header *h, scene_error *err)
{
    for (int i = 0; i < SCN_SEC_COUNT; i++) {
        uint64_t off = h->sec[i].offset;
        uint64_t end = off + (uint64_t)h->sec[i].count * record_bytes[i];
        if ((off & 3u) || off < h->header_bytes || end > h->total_bytes)
            return fail(err, SCENE_ERR_SECTION, i, 0);
    }
    if (h->sec[SCN_SEC_PALETTE].count != 256) return fail(err, SCENE_ERR_SECTION, SCN_SEC_PALETTE, 0);
    s->verts = (const scn_vertex *)(base + h->sec[SCN_SEC_VERTICES].offset);
    s->sectors = (const scn_sector *)(base + h->sec[SCN_SEC_SECTORS].offset);
    s->lines = (const scn_line *)(base + h->sec[SCN_SEC_LINES].offset);
    s->segs = (const scn_seg *)(base + h->sec[SCN_SEC_SEGS].offset);
    s->nodes = (const scn_node *)(base + h->sec[SCN_SEC_NODES].offset);
    s->leaves = (const scn_leaf *)(base + h->sec[SCN_SEC_LEAVES].offset);
    s->pverts = (const scn_vertex *)(base + h->sec[SCN_SEC_PVERTS].offset);
    s->palette = base + h->sec[SCN_SEC_PALETTE].offset;
    s->nverts = h->sec[SCN_SEC_VERTICES].count;
    s->nsectors = h->sec[SCN_SEC_SECTORS].count;
    s->nlines = h->sec[SCN_SEC_LINES].count;
    s->nsegs = h->sec[SCN_SEC_SEGS].count;
    s->nnodes = h->sec[SCN_SEC_NODES].count;
    s->nleaves = h->sec[SCN_SEC_LEAVES].count;
    s->npverts = h->sec[SCN_SEC_PVERTS].count;
    s->models = (const scn_model *)(base + h->sec[SCN_SEC_MODELS].offset);
    s->mverts = (const scn_mvert *)(base + h->sec[SCN_SEC_MVERTS].offset);
    s->faces = (const scn_face *)(base + h->sec[SCN_SEC_FACES].offset);
    s->findex = (const uint32_t *)(base + h->sec[SCN_SEC_FINDEX].offset);
    s->objects = (const scn_object *)(base + h->sec[SCN_SEC_OBJECTS].offset);
    s->nmodels = h->sec[SCN_SEC_MODELS].count;
    s->nmverts = h->sec[SCN_SEC_MVERTS].count;
    s->nfaces = h->sec[SCN_SEC_FACES].count;
    s->nfindex = h->sec[SCN_SEC_FINDEX].count;
    s->nobjects = h->sec[SCN_SEC_OBJECTS].count;
    return SCENE_OK;
}

static scene_status check_geometry(const scene *s, scene_error *err)
{
    for (uint32_t i = 0; i < s->nverts; i++)
        if (!coord_ok(s->verts[i].x, SCN_COORD_MAX) || !coord_ok(s->verts[i].y, SCN_COORD_MAX))
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_VERTICES, i);
    for (uint32_t i = 0; i < s->npverts; i++)
        if (!coord_ok(s->pverts[i].x, SCN_COORD_MAX) || !coord_ok(s->pverts[i].y, SCN_COORD_MAX))
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_PVERTS, i);
    for (uint32_t i = 0; i < s->nsectors; i++) {
        const scn_sector *sec = &s->sectors[i];
        if (!coord_ok(sec->floor_h, SCN_HEIGHT_MAX) || !coord_ok(sec->ceil_h, SCN_HEIGHT_MAX))
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_SECTORS, i);
    }
    for (uint32_t i = 0; i < s->nlines; i++) {
        const scn_line *l = &s->lines[i];
        if (l->v1 >= s->nverts || l->v2 >= s->nverts || l->sector[0] >= s->nsectors ||
            (l->sector[1] != SCN_NONE && l->sector[1] >= s->nsectors))
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_LINES, i);
    }
    for (uint32_t i = 0; i < s->nsegs; i++) {
        const scn_seg *g = &s->segs[i];
        if (g->v1 >= s->nverts || g->v2 >= s->nverts || g->line >= s->nlines || g->side > 1 ||
            s->lines[g->line].sector[g->side] == SCN_NONE)
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_SEGS, i);
    }
    for (uint32_t i = 0; i < s->nleaves; i++) {
        const scn_leaf *f = &s->leaves[i];
        if ((uint64_t)f->first_seg + f->num_segs > s->nsegs ||
            (uint64_t)f->first_pvert + f->num_pverts > s->npverts || f->num_pverts > SCN_MAX_LEAF_VERTS ||
            (f->sector != SCN_NONE && f->sector >= s->nsectors))
            return fail(err, SCENE_ERR_INDEX, SCN_SEC_LEAVES, i);
    }
    for (uint32_t i = 0; i < s->nnodes; i++) {
        const scn_node *n = &s->nodes[i];
        if (!coord_ok(n->x, SCN_COORD_MAX) || !coord_ok(n->y, SCN_COORD_MAX) ||
            (n->dx == 0 && n->dy == 0) || n->dx == INT32_MIN || n->dy == INT32_MIN)
            return fail(err, SCENE_ERR_RANGE, SCN_SEC_NODES, i);
        for (int c = 0; c < 2; c++) {
            uint32_t ch = n->child[c];
            if ((ch & SCN_LEAF_BIT) ? (ch & ~SCN_LEAF_BIT) >= s->nleaves : ch >= s->nnodes)
                return fail(err, SCENE_ERR_INDEX, SCN_SEC_NODES, i);
            for (int k = 0; k < 4; k++)
                if (!coord_ok(n->bbox[c][k], SCN_COORD_MAX))
                    return fail(err, SCENE_ERR_RANGE, SCN_SEC_NODES, i);
        }
    }
    return SCENE_OK;
}

/* Walk the whole graph from the root with a stack of SCN_MAX_DEPTH + 1 entries,
 * counting visits: a tree visits each node at most once, so more visits than
 * nodes means a shared child or a cycle. Bounded by nnodes + 1 pops. */
static scene_status check_tree(const scene *s, scene_error *err)
{
    uint32_t stack[SCN_MAX_DEPTH + 1];
    uint8_t depth[SCN_MAX_DEPTH + 1];
    uint32_t sp = 0, visits = 0, deepest = 0;
    uint32_t root = s->hdr->root;
    if (root & SCN_LEAF_BIT) {
        if ((root & ~SCN_LEAF_BIT) >= s->nleaves) return fail(err, SCENE_ERR_INDEX, -1, 0);
        return (s->nnodes == 0) ? SCENE_OK : fail(err, SCENE_ERR_TREE, -1, 0);
    }
    if (root >= s->nnodes) return fail(err, SCENE_ERR_INDEX, -1, 0);
    stack[sp] = root;
    depth[sp++] = 1;
    while (sp > 0) {
        sp--;
        uint32_t n = stack[sp];
        uint32_t d = depth[sp];
        if (++visits > s->nnodes) return fail(err, SCENE_ERR_TREE, SCN_SEC_NODES, n);
        if (d > deepest) deepest = d;
        for (int c = 0; c < 2; c++) {
            uint32_t ch = s->nodes[n].child[c];
            if (ch & SCN_LEAF_BIT) continue;
            if (d >= SCN_MAX_DEPTH || sp > SCN_MAX_DEPTH) return fail(err, SCENE_ERR_TREE, SCN_SEC_NODES, n);
            stack[sp] = ch;
            depth[sp++] = (uint8_t)(d + 1);
        }
    }
    if (deepest > s->hdr->max_depth) return fail(err, SCENE_ERR_TREE, -1, 0);
    return SCENE_OK;
}

scene_status scene_load(scene *s, const void *blob, uint32_t len, scene_error *err)
{
    const uint8_t *base = (const uint8_t *)blob;
    if (err) {
        err->status = SCENE_OK;
        err->section = -1;
        err->index = 0;
    }
    if (!blob || len < sizeof(scn_header)) return fail(err, SCENE_ERR_SHORT, -1, 0);
    if (((uintptr_t)blob & 3u) != 0) return fail(err, SCENE_ERR_ALIGN, -1, 0);
    const scn_header *h = (const scn_header *)blob;
    if (h->magic != SCN_MAGIC) return fail(err, SCENE_ERR_MAGIC, -1, 0);
    if (h->version != SCN_VERSION) return fail(err, SCENE_ERR_VERSION, -1, 0);
    if (h->header_bytes != sizeof(scn_header) || (h->total_bytes & 3u)) return fail(err, SCENE_ERR_HEADER, -1, 0);
    if (h->total_bytes > len) return fail(err, SCENE_ERR_SHORT, -1, 0);
    if (crc_update(0, base + 16, h->total_bytes - 16) != h->crc32) return fail(err, SCENE_ERR_CRC, -1, 0);
    if (h->flags != 0) return fail(err, SCENE_ERR_HEADER, -1, 0);
    if (h->max_depth > SCN_MAX_DEPTH) return fail(err, SCENE_ERR_TREE, -1, 0);
    if (h->player_sector != SCN_NONE && h->player_sector >= h->sec[SCN_SEC_SECTORS].count)
        return fail(err, SCENE_ERR_INDEX, -1, 0);
    if (!coord_ok(h->player_x, SCN_COORD_MAX) || !coord_ok(h->player_y, SCN_COORD_MAX))
        return fail(err, SCENE_ERR_RANGE, -1, 0);
    s->hdr = h;
    s->root = h->root;
    scene_status st = check_sections(s, base, h, err);
    if (st == SCENE_OK) st = check_geometry(s, err);
    if (st == SCENE_OK) st = check_tree(s, err);
    return st;
}

int scene_node_side(const scn_node *n, int32_t x, int32_t y)
{
    /* The offset from the partition's point reaches 2^33 raw and the direction
     * (not normalised) 2^31: dropping 3 fraction bits of the offset keeps each
     * product below 2^61 and classifies to 1/8192 unit. */
    int64_t ex = fx_asr64((int64_t)x - n->x, 3), ey = fx_asr64((int64_t)y - n->y, 3);
    int64_t cross = (int64_t)n->dx * ey - (int64_t)n->dy * ex;
    return cross > 0; /* left of the direction is the back */
}

uint32_t scene_leaf_at(const scene *s, int32_t x, int32_t y)
{
    uint32_t n = s->root;
    uint32_t guard = s->nnodes + 1; /* validated tree: never reached */
    while (!(n & SCN_LEAF_BIT) && guard--) n = s->nodes[n].child[scene_node_side(&s->nodes[n], x, y)];
    return n & ~SCN_LEAF_BIT;
}

uint32_t scene_sector_at(const scene *s, int32_t x, int32_t y)
{
    if (s->nleaves == 0) return SCN_NONE;
    return s->leaves[scene_leaf_at(s, x, y)].sector;
}
