/* SPDX-License-Identifier: MIT
 * sdfccd core: building a cubic Lagrange grid by sampling a function at the nodes, in
 * Discregrid's dense layout (GenerateSDF: every node sampled, identity cell map), or as a narrow
 * band (cells whose 32 node values all lie at least band + |h| from the surface are culled) that
 * samples and stores only the nodes near candidate cells and never allocates the dense node
 * array. Shared notes sdf-format-and-assets.md sections 2, 4, 6 and 7.
 */
#include "grid.h"

#include <string.h>

typedef struct node_ctx {
    const scc_grid_build_def* def;
    const scc_grid* g;
    double* nodes;        /* indexed by node id, by scc_grid_dense_block_index when `blocks`, or
                             (band edges) by band_slot() when `vertex_block` */
    int blocks;
    const uint32_t* vertex_block; /* band edge stage: candidate block of each vertex */
    const uint32_t* list; /* node ids to sample, or NULL for 0 .. count-1 */
    double cap;           /* passed to the sample function */
    uint64_t count;
    uint64_t chunk;
} node_ctx;

/* Band build: a candidate vertex owns 7 doubles (its own value, then the two nodes of each of its
 * x, y and z edges, as in scc_grid_dense_block_index); `b` is a dense block index (7 vertex + slot). */
static inline uint64_t band_slot(const uint32_t* vertex_block, uint64_t b) { return 7 * (uint64_t)vertex_block[b / 7] + b % 7; }

static void node_task(void* vctx, uint32_t task)
{
    node_ctx* c = vctx;
    const uint64_t begin = (uint64_t)task * c->chunk;
    uint64_t end = begin + c->chunk;
    if (end > c->count) end = c->count;
    uint32_t state = UINT32_MAX;
    for (uint64_t i = begin; i < end; ++i) {
        const uint64_t l = c->list ? c->list[i] : i;
        const double v = c->def->sample(c->def->sample_user, scc_grid_dense_node_position(c->g, l), &state, c->cap);
        if (c->vertex_block) c->nodes[band_slot(c->vertex_block, scc_grid_dense_block_index(c->def->res, l))] = v;
        else c->nodes[c->blocks ? scc_grid_dense_block_index(c->def->res, l) : l] = v;
    }
}

static int sample_nodes(const scc_grid_build_def* def, node_ctx* nc, int stage)
{
    const uint32_t tasks = (uint32_t)((nc->count + nc->chunk - 1) / nc->chunk);
    if (def->parallel_for) return def->parallel_for(def->parallel_user, stage, tasks, node_task, nc);
    for (uint32_t t = 0; t < tasks; ++t) node_task(nc, t);
    return 0;
}

/* Dense: every node sampled straight into the vertex-block layout, identity cell map; the cell
 * table is implied (NULL). */
static scc_grid_build_status build_dense(const scc_allocator* a, const scc_grid_build_def* def, scc_grid* g)
{
    scc_grid_field* fd = &g->fields[0];
    const uint64_t n_nodes = scc_grid_dense_node_count(def->res);
    const uint64_t n_cells = (uint64_t)def->res[0] * def->res[1] * def->res[2];
    const uint64_t nodes_len = 7 * (uint64_t)(def->res[0] + 1) * (def->res[1] + 1) * (def->res[2] + 1);
    double* nodes = scc_alloc(a, (size_t)nodes_len * sizeof(double));
    if (!nodes) return SCC_GRID_BUILD_OUT_OF_MEMORY;
    memset(nodes, 0, (size_t)nodes_len * sizeof(double)); /* slots of edges past the grid stay 0 */
    g->blocks = nodes; /* owned by the grid from here on */
    g->block_count = nodes_len;
    node_ctx nc = { def, g, nodes, 1, NULL, NULL, INFINITY, n_nodes, 1024 };
    if (sample_nodes(def, &nc, SCC_GRID_STAGE_NODES)) return SCC_GRID_BUILD_CANCELLED;
    for (uint64_t l = 0; l < nodes_len; ++l)
        if (!(fabs(nodes[l]) <= SCC_GRID_MAX_COORDINATE)) return SCC_GRID_BUILD_BAD_VALUE;
    fd->map = scc_alloc(a, (size_t)n_cells * sizeof(uint32_t));
    if (!fd->map) return SCC_GRID_BUILD_OUT_OF_MEMORY;
    fd->nodes = NULL;
    fd->node_count = n_nodes;
    fd->cells = NULL;
    fd->cell_count = n_cells;
    for (uint64_t l = 0; l < n_cells; ++l) fd->map[l] = (uint32_t)l;
    return SCC_GRID_BUILD_OK;
}

/* The dense block index (7 vertex + slot) of each of the 32 nodes of cell (i, j, k), in the slot
 * order of scc_grid_dense_cell_nodes: out[s] == scc_grid_dense_block_index(res, ids[s]). */
static void cell_blocks(const uint32_t res[3], uint32_t i, uint32_t j, uint32_t k, uint64_t out[32])
{
    const uint64_t nx1 = (uint64_t)res[0] + 1, ny1 = (uint64_t)res[1] + 1;
#define SCC_VTX(a, b, c) (7 * ((uint64_t)(a) + nx1 * ((uint64_t)(b) + ny1 * (uint64_t)(c))))
    for (int dk = 0; dk < 2; ++dk)
        for (int dj = 0; dj < 2; ++dj)
            for (int di = 0; di < 2; ++di) out[di + 2 * dj + 4 * dk] = SCC_VTX(i + di, j + dj, k + dk);
    for (int dj = 0; dj < 2; ++dj)
        for (int dk = 0; dk < 2; ++dk)
            for (int s = 0; s < 2; ++s) out[8 + 4 * dj + 2 * dk + s] = SCC_VTX(i, j + dj, k + dk) + 1 + s;
    for (int dk = 0; dk < 2; ++dk)
        for (int di = 0; di < 2; ++di)
            for (int s = 0; s < 2; ++s) out[16 + 4 * dk + 2 * di + s] = SCC_VTX(i + di, j, k + dk) + 3 + s;
    for (int di = 0; di < 2; ++di)
        for (int dj = 0; dj < 2; ++dj)
            for (int s = 0; s < 2; ++s) out[24 + 4 * di + 2 * dj + s] = SCC_VTX(i + di, j + dj, k) + 5 + s;
#undef SCC_VTX
}

/* The edge nodes marked (value INFINITY) in the candidate blocks, in ascending node id (the order
 * a dense scan visits them, so the sample function sees the same sequence as before): written to
 * `list` when not NULL; returns how many. x edges come first (i fastest), then y edges (j fastest,
 * then k, then i), then z edges (k fastest, then i, then j), two nodes each. */
static uint64_t list_marked_edges(const uint32_t res[3], const uint32_t* vb, const double* cblocks, uint32_t* list)
{
    const uint64_t nx = res[0], ny = res[1], nz = res[2], nv = (nx + 1) * (ny + 1) * (nz + 1);
    const uint64_t ex = nx * (ny + 1) * (nz + 1), ey = (nx + 1) * ny * (nz + 1);
    uint64_t n = 0;
#define SCC_MARKED(vtx, slot, l)                                                                       \
    do {                                                                                               \
        const uint64_t v_ = (vtx);                                                                     \
        if (vb[v_] != UINT32_MAX)                                                                      \
            for (int s = 0; s < 2; ++s)                                                                \
                if (cblocks[7 * (uint64_t)vb[v_] + (slot) + s] == INFINITY) {                          \
                    if (list) list[n] = (uint32_t)((l) + s);                                           \
                    ++n;                                                                               \
                }                                                                                      \
    } while (0)
    for (uint64_t k = 0; k <= nz; ++k)
        for (uint64_t j = 0; j <= ny; ++j)
            for (uint64_t i = 0; i < nx; ++i) SCC_MARKED(i + (nx + 1) * (j + (ny + 1) * k), 1, nv + 2 * (i + nx * (j + (ny + 1) * k)));
    for (uint64_t i = 0; i <= nx; ++i)
        for (uint64_t k = 0; k <= nz; ++k)
            for (uint64_t j = 0; j < ny; ++j)
                SCC_MARKED(i + (nx + 1) * (j + (ny + 1) * k), 3, nv + 2 * ex + 2 * (j + ny * (k + (nz + 1) * i)));
    for (uint64_t j = 0; j <= ny; ++j)
        for (uint64_t i = 0; i <= nx; ++i)
            for (uint64_t k = 0; k < nz; ++k)
                SCC_MARKED(i + (nx + 1) * (j + (ny + 1) * k), 5, nv + 2 * (ex + ey) + 2 * (k + nz * (i + (nx + 1) * j)));
#undef SCC_MARKED
    return n;
}

/* Scratch of a band build, freed by band_free whatever happens. */
typedef struct band_scratch {
    const scc_allocator* a;
    double* corners;   /* nv: the value of every grid vertex */
    uint32_t* vb;      /* nv: candidate block of each vertex (UINT32_MAX: none); becomes the grid's
                          vertex_block */
    double* cblocks;   /* 7 per candidate vertex */
    uint8_t* used;     /* per candidate block: bit s set when slot s is a node of a kept cell */
    uint32_t* list;
    uint64_t nv, ncand, listed;
    uint64_t live, max_bytes, *needed; /* bytes held for nodes; the build's limit (0: none) */
} band_scratch;

/* Counts `bytes` more in b->live; 0 (and the total in *needed) when that passes the limit. */
static int band_reserve(band_scratch* b, uint64_t bytes)
{
    if (b->max_bytes && b->live + bytes > b->max_bytes) {
        if (b->needed) *b->needed = b->live + bytes;
        return 0;
    }
    b->live += bytes;
    return 1;
}

static void band_free(band_scratch* b)
{
    scc_free(b->a, b->corners, (size_t)b->nv * sizeof(double));
    scc_free(b->a, b->vb, (size_t)b->nv * sizeof(uint32_t));
    scc_free(b->a, b->cblocks, (size_t)b->ncand * 7 * sizeof(double));
    scc_free(b->a, b->used, (size_t)b->ncand);
    scc_free(b->a, b->list, (size_t)b->listed * sizeof(uint32_t));
}

/* Visits the candidate cells (a corner below skip_at; every cell when skip_at is infinite) and
 * marks their 8 corner vertices in b->vb (0), or (edges) their 24 edge nodes in b->cblocks
 * (INFINITY). */
static void mark_candidates(band_scratch* b, const uint32_t res[3], double skip_at, int edges)
{
    uint64_t cb[32];
    for (uint32_t k = 0; k < res[2]; ++k)
        for (uint32_t j = 0; j < res[1]; ++j)
            for (uint32_t i = 0; i < res[0]; ++i) {
                cell_blocks(res, i, j, k, cb);
                if (isfinite(skip_at)) {
                    double cmin = INFINITY;
                    for (int s = 0; s < 8; ++s) cmin = fmin(cmin, fabs(b->corners[cb[s] / 7]));
                    if (!(cmin < skip_at)) continue; /* NaN corner values fall through to sampling */
                }
                if (edges)
                    for (int s = 8; s < 32; ++s) b->cblocks[band_slot(b->vb, cb[s])] = INFINITY;
                else
                    for (int s = 0; s < 8; ++s) b->vb[cb[s] / 7] = 0;
            }
}

/* Narrow band without the dense node array. Sample the nv cell corners; a cell is a candidate
 * when a corner lies below skip_at (with a Lipschitz bound L an edge node lies within 2h/3 of a
 * corner of every cell using it, so when all 8 corners have |v| >= keep_below + L hmax none of
 * its 32 nodes can keep it; without L every cell is a candidate). Only the vertices of candidate
 * cells get a block of 7 values, and only the edge nodes of candidate cells are sampled (in
 * ascending node id, as the dense scan did). A cell is kept when one of its 32 nodes is nearer
 * than keep_below; unsampled nodes are NaN, which keeps nothing and makes a kept cell a
 * BAD_VALUE, exactly as with the dense array this replaces. The kept vertices' blocks are then
 * copied, in vertex order, into the grid's block array. Peak memory: 12 bytes per vertex, 56 per
 * candidate vertex (plus 4 per listed edge node), then 4 per vertex and per cell, 57 per candidate
 * and 56 per kept vertex, against 8 bytes per node (about 56 per vertex) for the dense array; each
 * step is checked against def->max_bytes before its allocation. */
static scc_grid_build_status build_band(const scc_allocator* a, const scc_grid_build_def* def, scc_grid* g)
{
    scc_grid_field* fd = &g->fields[0];
    const uint32_t* res = def->res;
    const uint64_t n_cells = (uint64_t)res[0] * res[1] * res[2];
    const int lipschitz = def->sample_lipschitz > 0.0 && isfinite(def->sample_lipschitz);
    const double keep_below = def->band + scc_len(g->h);
    const double hmax = fmax(g->h.x, fmax(g->h.y, g->h.z));
    band_scratch b;
    memset(&b, 0, sizeof b);
    b.a = a;
    b.nv = (uint64_t)(res[0] + 1) * (res[1] + 1) * (res[2] + 1);
    b.max_bytes = def->max_bytes;
    b.needed = def->needed_bytes;
    scc_grid_build_status st = SCC_GRID_BUILD_OUT_OF_MEMORY;

    if (!band_reserve(&b, 12 * b.nv)) return SCC_GRID_BUILD_OVER_LIMIT;
    b.corners = scc_alloc(a, (size_t)b.nv * sizeof(double));
    b.vb = scc_alloc(a, (size_t)b.nv * sizeof(uint32_t));
    if (!b.corners || !b.vb) goto done;
    /* Corner values are only needed exactly below keep_below + L (|h| + hmax): corners of kept
     * cells lie within |h| of a node below keep_below, and the candidate test only compares
     * with keep_below + L hmax. */
    const double cap = lipschitz ? keep_below + def->sample_lipschitz * (scc_len(g->h) + hmax) * 1.000001 : INFINITY;
    node_ctx nc = { def, g, b.corners, 0, NULL, NULL, cap, b.nv, 1024 };
    if (sample_nodes(def, &nc, SCC_GRID_STAGE_CORNERS)) { st = SCC_GRID_BUILD_CANCELLED; goto done; }

    /* candidate cells -> candidate vertices (all 8 corners; every edge of a cell starts at one) */
    const double skip_at = lipschitz ? keep_below + def->sample_lipschitz * hmax : INFINITY;
    memset(b.vb, 0xFF, (size_t)b.nv * sizeof(uint32_t));
    mark_candidates(&b, res, skip_at, 0);
    for (uint64_t v = 0; v < b.nv; ++v)
        if (b.vb[v] == 0) b.vb[v] = (uint32_t)b.ncand++;
    if (!band_reserve(&b, 56 * b.ncand)) { st = SCC_GRID_BUILD_OVER_LIMIT; goto done; }
    b.cblocks = scc_alloc(a, (size_t)b.ncand * 7 * sizeof(double));
    if (b.ncand && !b.cblocks) goto done;
    for (uint64_t q = 0; q < b.ncand * 7; ++q) b.cblocks[q] = NAN; /* not sampled */
    for (uint64_t v = 0; v < b.nv; ++v)
        if (b.vb[v] != UINT32_MAX) b.cblocks[7 * (uint64_t)b.vb[v]] = b.corners[v];
    /* mark the edge nodes of candidate cells, list them in node order, sample them */
    mark_candidates(&b, res, skip_at, 1);
    int bad_corner = 0;
    for (uint64_t v = 0; v < b.nv; ++v) bad_corner |= !(fabs(b.corners[v]) <= SCC_GRID_MAX_COORDINATE);
    scc_free(a, b.corners, (size_t)b.nv * sizeof(double));
    b.corners = NULL;
    b.live -= 8 * b.nv;
    b.listed = list_marked_edges(res, b.vb, b.cblocks, NULL);
    if (!band_reserve(&b, 4 * b.listed)) { b.listed = 0; st = SCC_GRID_BUILD_OVER_LIMIT; goto done; }
    b.list = b.listed ? scc_alloc(a, (size_t)b.listed * sizeof(uint32_t)) : NULL;
    if (b.listed && !b.list) goto done;
    list_marked_edges(res, b.vb, b.cblocks, b.list);
    node_ctx ec = { def, g, b.cblocks, 0, b.vb, b.list, INFINITY, b.listed, 1024 };
    if (sample_nodes(def, &ec, SCC_GRID_STAGE_EDGES)) { st = SCC_GRID_BUILD_CANCELLED; goto done; }
    scc_free(a, b.list, (size_t)b.listed * sizeof(uint32_t));
    b.list = NULL;
    b.live -= 4 * b.listed;
    if (lipschitz && bad_corner) { st = SCC_GRID_BUILD_BAD_VALUE; goto done; }

    /* Keep a cell when any of its nodes is nearer than band + |h| to the surface. Culled cells
     * then satisfy |phi| >= band everywhere (every point of a cell lies within |h| of one of its
     * corners and the samples are exact distances). A cell with a vertex outside the candidates
     * has no sampled node below keep_below (its corners are at least skip_at) and is culled. */
    if (!band_reserve(&b, 4 * n_cells + b.ncand)) { st = SCC_GRID_BUILD_OVER_LIMIT; goto done; }
    uint64_t cb[32];
    fd->map = scc_alloc(a, (size_t)n_cells * sizeof(uint32_t));
    b.used = b.ncand ? scc_alloc(a, (size_t)b.ncand) : NULL;
    if (!fd->map || (b.ncand && !b.used)) goto done;
    if (b.ncand) memset(b.used, 0, (size_t)b.ncand);
    uint64_t kept = 0, l = 0;
    for (uint32_t k = 0; k < res[2]; ++k)
        for (uint32_t j = 0; j < res[1]; ++j)
            for (uint32_t i = 0; i < res[0]; ++i, ++l) {
                cell_blocks(res, i, j, k, cb);
                int candidate = 1;
                for (int s = 0; s < 8; ++s) candidate &= b.vb[cb[s] / 7] != UINT32_MAX;
                int keep = 0, bad = 0;
                if (candidate) {
                    for (int s = 0; s < 32; ++s) {
                        const double v = b.cblocks[band_slot(b.vb, cb[s])];
                        keep |= fabs(v) < keep_below;
                        bad |= !(fabs(v) <= SCC_GRID_MAX_COORDINATE);
                    }
                } else {
                    /* some vertex has no block: none of its edge nodes was sampled (every cell
                     * using such an edge has the vertex as a corner), so the cell holds NaN */
                    for (int s = 8; s < 32; ++s) {
                        const uint32_t vb = b.vb[cb[s] / 7];
                        keep |= vb != UINT32_MAX && fabs(b.cblocks[band_slot(b.vb, cb[s])]) < keep_below;
                    }
                    bad = 1;
                }
                if (!keep) { fd->map[l] = SCC_GRID_NO_CELL; continue; }
                if (bad) { st = SCC_GRID_BUILD_BAD_VALUE; goto done; } /* a sample returned NaN/inf (a skipped node cannot be here) */
                fd->map[l] = (uint32_t)kept++;
                for (int s = 0; s < 32; ++s) b.used[b.vb[cb[s] / 7]] |= (uint8_t)(1u << (cb[s] % 7));
            }
    if (kept == 0) { st = SCC_GRID_BUILD_EMPTY_BAND; goto done; }

    /* Block-sparse storage: every vertex of a kept cell owns a block of 7 values (its own and
     * the nodes of the edges starting there), so kept cells need no 128-byte id table. Slots no
     * kept cell uses hold SCC_GRID_NO_VALUE. The candidate numbering becomes the kept one in
     * place (kept vertices are candidates, and both number in vertex order). */
    uint64_t nblocks = 0, used_nodes = 0;
    for (uint64_t c = 0; c < b.ncand; ++c) nblocks += b.used[c] & 1; /* slot 0: a corner of a kept cell */
    if (!band_reserve(&b, 56 * nblocks)) { st = SCC_GRID_BUILD_OVER_LIMIT; goto done; }
    double* blocks = scc_alloc(a, (size_t)nblocks * 7 * sizeof(double));
    if (!blocks) goto done;
    for (uint64_t v = 0, f = 0; v < b.nv; ++v) {
        const uint32_t c = b.vb[v];
        if (c == UINT32_MAX || !(b.used[c] & 1)) { b.vb[v] = UINT32_MAX; continue; }
        for (int s = 0; s < 7; ++s) {
            const int on = (b.used[c] >> s) & 1;
            blocks[7 * f + s] = on ? b.cblocks[7 * (uint64_t)c + s] : SCC_GRID_NO_VALUE;
            used_nodes += (uint64_t)on;
        }
        b.vb[v] = (uint32_t)f++;
    }
    g->blocks = blocks;
    g->block_count = nblocks * 7;
    g->vertex_block = b.vb;
    b.vb = NULL;
    fd->nodes = NULL;
    fd->cells = NULL;
    fd->node_count = used_nodes;
    fd->cell_count = kept;
    st = SCC_GRID_BUILD_OK;
done:
    band_free(&b);
    return st;
}

scc_grid_build_status scc_grid_build(const scc_allocator* a, const scc_grid_build_def* def, scc_grid** out_grid)
{
    *out_grid = NULL;
    const uint64_t n_nodes = scc_grid_dense_node_count(def->res);
    const uint64_t n_cells = (uint64_t)def->res[0] * def->res[1] * def->res[2];
    if (n_nodes >= 0xFFFFFFFFull || n_cells > 0x7FFFFFFEull) return SCC_GRID_BUILD_TOO_LARGE;
    if ((size_t)n_nodes != n_nodes || (size_t)(n_cells * 128) / 128 != n_cells) return SCC_GRID_BUILD_TOO_LARGE;

    scc_grid* g = scc_grid_create(a, def->lo, def->hi, def->res, 1);
    if (!g) return SCC_GRID_BUILD_OUT_OF_MEMORY;
    const int banded = def->band > 0.0 && isfinite(def->band);
    const scc_grid_build_status st = banded ? build_band(a, def, g) : build_dense(a, def, g);
    if (st != SCC_GRID_BUILD_OK) { scc_grid_destroy(g); return st; }

    /* Every point of a culled cell is within |h| of a corner whose |value| >= band + |h|, so
     * |phi| >= band + |h| (1 - L) there for an L-Lipschitz source (band itself for distances). */
    double band_lb = 0.0;
    if (banded && def->sample_lipschitz > 0.0 && isfinite(def->sample_lipschitz))
        band_lb = fmax(0.0, def->band + scc_len(g->h) * (1.0 - def->sample_lipschitz));
    switch (scc_grid_finalize(g, band_lb, def->parallel_for, def->parallel_user)) {
    case SCC_GRID_OK: break;
    case SCC_GRID_CANCELLED: scc_grid_destroy(g); return SCC_GRID_BUILD_CANCELLED;
    case SCC_GRID_EMPTY: scc_grid_destroy(g); return SCC_GRID_BUILD_EMPTY_BAND;
    case SCC_GRID_TOO_LARGE: scc_grid_destroy(g); return SCC_GRID_BUILD_TOO_LARGE;
    case SCC_GRID_STEEP: scc_grid_destroy(g); return SCC_GRID_BUILD_BAD_VALUE;
    default: scc_grid_destroy(g); return SCC_GRID_BUILD_OUT_OF_MEMORY;
    }
    *out_grid = g;
    return SCC_GRID_BUILD_OK;
}
