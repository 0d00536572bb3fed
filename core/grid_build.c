/* SPDX-License-Identifier: MIT
 * sdfccd core: building a cubic Lagrange grid by sampling a function at the nodes, in
 * Discregrid's dense layout (GenerateSDF: every node sampled, identity cell map), optionally
 * reduced to a narrow band (cells whose 32 node values all lie at least band + |h| from the
 * surface are culled, the referenced nodes are kept and renumbered). Shared notes
 * sdf-format-and-assets.md sections 2, 4, 6 and 7.
 */
#include "grid.h"

#include <string.h>

typedef struct node_ctx {
    const scc_grid_build_def* def;
    const scc_grid* g;
    double* nodes;        /* indexed by node id, or by scc_grid_dense_block_index when `blocks` */
    int blocks;
    const uint32_t* list; /* node ids to sample, or NULL for 0 .. count-1 */
    double cap;           /* passed to the sample function */
    uint64_t count;
    uint64_t chunk;
} node_ctx;

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
        c->nodes[c->blocks ? scc_grid_dense_block_index(c->def->res, l) : l] = v;
    }
}

static int sample_nodes(const scc_grid_build_def* def, node_ctx* nc, int stage)
{
    const uint32_t tasks = (uint32_t)((nc->count + nc->chunk - 1) / nc->chunk);
    if (def->parallel_for) return def->parallel_for(def->parallel_user, stage, tasks, node_task, nc);
    for (uint32_t t = 0; t < tasks; ++t) node_task(nc, t);
    return 0;
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
    scc_grid_field* fd = &g->fields[0];
    const int banded = def->band > 0.0 && isfinite(def->band);
    /* Dense grids sample straight into the vertex-block layout; bands use file numbering. */
    const uint64_t nodes_len = banded ? n_nodes : 7 * (uint64_t)(def->res[0] + 1) * (def->res[1] + 1) * (def->res[2] + 1);
    double* nodes = scc_alloc(a, (size_t)nodes_len * sizeof(double));
    if (!nodes) { scc_grid_destroy(g); return SCC_GRID_BUILD_OUT_OF_MEMORY; }
    if (!banded) memset(nodes, 0, (size_t)nodes_len * sizeof(double)); /* slots of edges past the grid stay 0 */

    const double keep_below = banded ? def->band + scc_len(g->h) : 0.0;
    const double hmax = fmax(g->h.x, fmax(g->h.y, g->h.z));
    int cancelled;
    if (banded && def->sample_lipschitz > 0.0 && isfinite(def->sample_lipschitz)) {
        /* Narrow band with a known Lipschitz constant L: sample the cell corners first. An edge
         * node lies within 2h/3 of a corner of every cell that uses it, so when all 8 corners of
         * a cell have |v| >= keep_below + L * hmax, none of its 32 nodes can keep it and its edge
         * nodes need no sample (unless a kept cell shares them). Unsampled nodes are never
         * referenced by a kept cell. */
        const uint64_t nv = (uint64_t)(def->res[0] + 1) * (def->res[1] + 1) * (def->res[2] + 1);
        for (uint64_t l = nv; l < n_nodes; ++l) nodes[l] = NAN;
        /* Corner values are only needed exactly below keep_below + L (|h| + hmax): corners of
         * kept cells lie within |h| of a node below keep_below, and the skip test below only
         * compares with keep_below + L hmax. */
        node_ctx nc = { def, g, nodes, 0, NULL, keep_below + def->sample_lipschitz * (scc_len(g->h) + hmax) * 1.000001, nv, 1024 };
        cancelled = sample_nodes(def, &nc, SCC_GRID_STAGE_CORNERS);
        uint32_t* list = NULL;
        uint64_t listed = 0;
        if (!cancelled) {
            uint8_t* need = scc_alloc(a, (size_t)(n_nodes - nv));
            if (!need) { scc_free(a, nodes, (size_t)nodes_len * sizeof(double)); scc_grid_destroy(g); return SCC_GRID_BUILD_OUT_OF_MEMORY; }
            memset(need, 0, (size_t)(n_nodes - nv));
            const double skip_at = keep_below + def->sample_lipschitz * hmax;
            uint32_t ids[32];
            for (uint32_t k = 0; k < def->res[2]; ++k)
                for (uint32_t j = 0; j < def->res[1]; ++j)
                    for (uint32_t i = 0; i < def->res[0]; ++i) {
                        scc_grid_dense_cell_nodes(def->res, i, j, k, ids);
                        double cmin = INFINITY;
                        for (int s = 0; s < 8; ++s) cmin = fmin(cmin, fabs(nodes[ids[s]]));
                        if (!(cmin < skip_at)) continue; /* NaN corner values fall through to sampling */
                        for (int s = 8; s < 32; ++s) need[ids[s] - nv] = 1;
                    }
            for (uint64_t l = 0; l < n_nodes - nv; ++l) listed += need[l];
            list = listed ? scc_alloc(a, (size_t)listed * sizeof(uint32_t)) : NULL;
            if (listed && !list) {
                scc_free(a, need, (size_t)(n_nodes - nv));
                scc_free(a, nodes, (size_t)nodes_len * sizeof(double));
                scc_grid_destroy(g);
                return SCC_GRID_BUILD_OUT_OF_MEMORY;
            }
            uint64_t at = 0;
            for (uint64_t l = 0; l < n_nodes - nv; ++l)
                if (need[l]) list[at++] = (uint32_t)(nv + l);
            scc_free(a, need, (size_t)(n_nodes - nv));
            node_ctx ec = { def, g, nodes, 0, list, INFINITY, listed, 1024 };
            cancelled = sample_nodes(def, &ec, SCC_GRID_STAGE_EDGES);
            scc_free(a, list, (size_t)listed * sizeof(uint32_t));
        }
        if (!cancelled)
            for (uint64_t l = 0; l < nv; ++l)
                if (!(fabs(nodes[l]) <= SCC_GRID_MAX_COORDINATE)) { scc_free(a, nodes, (size_t)nodes_len * sizeof(double)); scc_grid_destroy(g); return SCC_GRID_BUILD_BAD_VALUE; }
    } else {
        node_ctx nc = { def, g, nodes, !banded, NULL, INFINITY, n_nodes, 1024 };
        cancelled = sample_nodes(def, &nc, SCC_GRID_STAGE_NODES);
    }
    if (cancelled) { scc_free(a, nodes, (size_t)nodes_len * sizeof(double)); scc_grid_destroy(g); return SCC_GRID_BUILD_CANCELLED; }
    if (!banded)
        for (uint64_t l = 0; l < nodes_len; ++l)
            if (!(fabs(nodes[l]) <= SCC_GRID_MAX_COORDINATE)) { scc_free(a, nodes, (size_t)nodes_len * sizeof(double)); scc_grid_destroy(g); return SCC_GRID_BUILD_BAD_VALUE; }

    fd->map = scc_alloc(a, (size_t)n_cells * sizeof(uint32_t));
    if (!fd->map) { scc_free(a, nodes, (size_t)nodes_len * sizeof(double)); scc_grid_destroy(g); return SCC_GRID_BUILD_OUT_OF_MEMORY; }

    if (!banded) {
        /* Dense: Discregrid's numbering, identity map; the cell table is implied (NULL) and the
         * values are in the vertex-block layout. */
        g->blocks = nodes;
        g->block_count = nodes_len;
        fd->nodes = NULL;
        fd->node_count = n_nodes;
        fd->cells = NULL;
        fd->cell_count = n_cells;
        for (uint64_t l = 0; l < n_cells; ++l) fd->map[l] = (uint32_t)l;
    } else {
        /* Narrow band: keep a cell when any of its nodes is nearer than band + |h| to the
         * surface. Culled cells then satisfy |phi| >= band everywhere (every point of a cell
         * lies within |h| of one of its corners and the samples are exact distances). */
        uint32_t* renumber = scc_alloc(a, (size_t)n_nodes * sizeof(uint32_t));
        if (!renumber) { scc_free(a, nodes, (size_t)nodes_len * sizeof(double)); scc_grid_destroy(g); return SCC_GRID_BUILD_OUT_OF_MEMORY; }
        memset(renumber, 0xFF, (size_t)n_nodes * sizeof(uint32_t));
        uint64_t kept = 0, l = 0;
        uint32_t ids[32];
        for (uint32_t k = 0; k < def->res[2]; ++k)
            for (uint32_t j = 0; j < def->res[1]; ++j)
                for (uint32_t i = 0; i < def->res[0]; ++i, ++l) {
                    scc_grid_dense_cell_nodes(def->res, i, j, k, ids);
                    int keep = 0;
                    for (int s = 0; s < 32 && !keep; ++s) keep = fabs(nodes[ids[s]]) < keep_below;
                    if (!keep) { fd->map[l] = SCC_GRID_NO_CELL; continue; }
                    int bad = 0;
                    for (int s = 0; s < 32; ++s) bad |= !(fabs(nodes[ids[s]]) <= SCC_GRID_MAX_COORDINATE);
                    if (bad) { /* a sample returned NaN/inf (a skipped node cannot be here) */
                        scc_free(a, renumber, (size_t)n_nodes * sizeof(uint32_t));
                        scc_free(a, nodes, (size_t)nodes_len * sizeof(double));
                        scc_grid_destroy(g);
                        return SCC_GRID_BUILD_BAD_VALUE;
                    }
                    fd->map[l] = (uint32_t)kept++;
                    for (int s = 0; s < 32; ++s) renumber[ids[s]] = 0; /* mark used */
                }
        if (kept == 0) {
            scc_free(a, renumber, (size_t)n_nodes * sizeof(uint32_t));
            scc_free(a, nodes, (size_t)nodes_len * sizeof(double));
            scc_grid_destroy(g);
            return SCC_GRID_BUILD_EMPTY_BAND;
        }
        uint64_t used = 0;
        for (uint64_t n = 0; n < n_nodes; ++n) used += renumber[n] == 0;
        scc_free(a, renumber, (size_t)n_nodes * sizeof(uint32_t));
        /* Block-sparse storage: every vertex of a kept cell owns a block of 7 values (its own and
         * the nodes of the edges starting there), so kept cells need no 128-byte id table. */
        const uint64_t nv1 = (uint64_t)(def->res[0] + 1) * (def->res[1] + 1) * (def->res[2] + 1);
        uint32_t* vb = scc_alloc(a, (size_t)nv1 * sizeof(uint32_t));
        if (!vb) { scc_free(a, nodes, (size_t)nodes_len * sizeof(double)); scc_grid_destroy(g); return SCC_GRID_BUILD_OUT_OF_MEMORY; }
        memset(vb, 0xFF, (size_t)nv1 * sizeof(uint32_t));
        uint64_t nblocks = 0;
        l = 0;
        for (uint32_t k = 0; k < def->res[2]; ++k)
            for (uint32_t j = 0; j < def->res[1]; ++j)
                for (uint32_t i = 0; i < def->res[0]; ++i, ++l) {
                    if (fd->map[l] == SCC_GRID_NO_CELL) continue;
                    for (int c = 0; c < 8; ++c) {
                        const uint64_t vtx = (i + (c & 1)) + (def->res[0] + 1) * ((uint64_t)(j + ((c >> 1) & 1)) + (def->res[1] + 1) * (uint64_t)(k + (c >> 2)));
                        if (vb[vtx] == 0xFFFFFFFFu) vb[vtx] = 0; /* mark */
                    }
                }
        for (uint64_t vtx = 0; vtx < nv1; ++vtx)
            if (vb[vtx] == 0) vb[vtx] = (uint32_t)nblocks++;
        double* blocks = scc_alloc(a, (size_t)nblocks * 7 * sizeof(double));
        if (!blocks) {
            scc_free(a, vb, (size_t)nv1 * sizeof(uint32_t));
            scc_free(a, nodes, (size_t)nodes_len * sizeof(double));
            scc_grid_destroy(g);
            return SCC_GRID_BUILD_OUT_OF_MEMORY;
        }
        for (uint64_t q = 0; q < nblocks * 7; ++q) blocks[q] = SCC_GRID_NO_VALUE; /* slots no kept cell uses */
        l = 0;
        for (uint32_t k = 0; k < def->res[2]; ++k)
            for (uint32_t j = 0; j < def->res[1]; ++j)
                for (uint32_t i = 0; i < def->res[0]; ++i, ++l) {
                    if (fd->map[l] == SCC_GRID_NO_CELL) continue;
                    scc_grid_dense_cell_nodes(def->res, i, j, k, ids);
                    for (int s = 0; s < 32; ++s) {
                        const uint64_t bi = scc_grid_dense_block_index(def->res, ids[s]);
                        blocks[7 * (uint64_t)vb[bi / 7] + bi % 7] = nodes[ids[s]];
                    }
                }
        scc_free(a, nodes, (size_t)nodes_len * sizeof(double));
        g->blocks = blocks;
        g->block_count = nblocks * 7;
        g->vertex_block = vb;
        fd->nodes = NULL;
        fd->cells = NULL;
        fd->node_count = used;
        fd->cell_count = kept;
    }

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
