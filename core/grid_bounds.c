/* SPDX-License-Identifier: MIT
 * sdfccd core: the grid's bounds, computed once by scc_grid_finalize after the fields are set
 * (loaded from a file or built): per-cell bounds on |grad phi| from the Bernstein form of the
 * element (grid_cell.c), per-block maxima of those bounds, the nearest valued cell and the side
 * of every cell without values (hole sources), and whether phi >= 0 on the domain boundary
 * (which decides the SDF's `bounds` and the continuation outside the domain).
 */
#include "grid.h"
#include "grid_access.h"

#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

/* ------------------------------------------------------------------------------------------
 * Finalisation: per-cell gradient bounds and hole sources.
 *
 * Gradient bound: phi on a cell is a polynomial of degree <= 3 in each local coordinate, so it
 * has a tensor cubic Bernstein form on [-1,1]^3 (64 coefficients, a fixed 64x32 map from the
 * node values). Each partial derivative then has a Bernstein form with coefficients from
 * differences, and Bernstein coefficients enclose the range of their polynomial (convex hull
 * property), so max |coefficient| bounds |dphi/dxi_d| on the whole cell; grad phi scales that
 * by 2/h_d.
 * ---------------------------------------------------------------------------------------- */

typedef struct bern_tables {
    double val[64][32];
    double by_node[32][64]; /* val transposed: the conversion runs over independent coefficients */
} bern_tables;

typedef struct finalize_ctx {
    scc_grid* g;
    const bern_tables* bt;
    uint64_t chunk;
} finalize_ctx;

static float round_up_float(double v)
{
    float f = (float)v;
    if ((double)f < v) f = nextafterf(f, INFINITY);
    return f;
}

static float round_down_float(double v)
{
    float f = (float)v;
    if ((double)f > v) f = nextafterf(f, -INFINITY);
    return f;
}

/* Widens block q's gradient intervals (block_grad) by a cell's: lo[d], hi[d] per component. */
static void widen_block_grad(scc_grid* g, uint64_t l, const double lo[3], const double hi[3])
{
    uint32_t ijk[3];
    cell_ijk(g, l, ijk);
    const uint32_t nbx = scc_grid_grad_blocks(g, 0), nby = scc_grid_grad_blocks(g, 1), B = SCC_GRID_GRAD_BLOCK;
    float* bg = g->block_grad + 6 * (ijk[0] / B + (uint64_t)nbx * (ijk[1] / B + (uint64_t)nby * (ijk[2] / B)));
    for (int d = 0; d < 3; ++d) {
        const float a = round_down_float(lo[d]), b = round_up_float(hi[d]);
        if (a < bg[d]) bg[d] = a;
        if (b > bg[3 + d]) bg[3 + d] = b;
    }
}

static void cell_bound_task(void* vctx, uint32_t task)
{
    finalize_ctx* ctx = vctx;
    scc_grid* g = ctx->g;
    const scc_grid_field* fd = &g->fields[0];
    const uint64_t begin = (uint64_t)task * ctx->chunk;
    uint64_t end = begin + ctx->chunk;
    if (end > g->n_cells) end = g->n_cells;
    const double c0[3] = { 2.0 / g->h.x, 2.0 / g->h.y, 2.0 / g->h.z };
    for (uint64_t l = begin; l < end; ++l) {
        const uint32_t c = fd->map[l];
        if (c == SCC_GRID_NO_CELL) {
            const double inf[3] = { INFINITY, INFINITY, INFINITY }, minf[3] = { -INFINITY, -INFINITY, -INFINITY };
            widen_block_grad(g, l, minf, inf);
            continue;
        }
        double v[32];
        uint32_t ijk[3];
        cell_ijk(g, l, ijk);
        gather_cell(g, fd, c, ijk, v);
        int hole = 0;
        for (int a = 0; a < 32; ++a) hole |= v[a] == SCC_GRID_NO_VALUE;
        if (hole) {
            const double inf[3] = { INFINITY, INFINITY, INFINITY }, minf[3] = { -INFINITY, -INFINITY, -INFINITY };
            g->cell_lipschitz[c] = -1.0f;
            widen_block_grad(g, l, minf, inf);
            continue;
        }
        /* Bernstein coefficients of phi on the cell (degree 3 per axis), then those of each
         * partial derivative by differences: d/dxi of a cubic Bernstein form on [-1,1] has the
         * degree-2 coefficients 1.5 (b[i+1] - b[i]) along that axis. */
        double b[64] = { 0.0 };
        for (int k = 0; k < 32; ++k) {
            const double* row = ctx->bt->by_node[k];
            for (int s = 0; s < 64; ++s) b[s] += row[s] * v[k];
        }
        double sum2 = 0.0, glo[3], ghi[3];
        for (int d = 0; d < 3; ++d) {
            const int stride = d == 0 ? 1 : (d == 1 ? 4 : 16);
            double bmax = 0.0, emin = INFINITY, emax = -INFINITY;
            for (int s = 0; s < 64; ++s) {
                if ((s / stride) % 4 != 0) continue;
                /* degree-2 coefficients along d, elevated back to degree 3 (convex combinations,
                 * so the enclosure only gets tighter) */
                const double e0 = 1.5 * (b[s + stride] - b[s]), e1 = 1.5 * (b[s + 2 * stride] - b[s + stride]),
                             e2 = 1.5 * (b[s + 3 * stride] - b[s + 2 * stride]);
                const double q[4] = { e0, (e0 + 2.0 * e1) / 3.0, (2.0 * e1 + e2) / 3.0, e2 };
                for (int m = 0; m < 4; ++m)
                    if (fabs(q[m]) > bmax) bmax = fabs(q[m]);
                emin = fmin(emin, fmin(e0, fmin(e1, e2)));
                emax = fmax(emax, fmax(e0, fmax(e1, e2)));
            }
            sum2 += (c0[d] * bmax) * (c0[d] * bmax);
            /* the component's range (the degree-2 coefficients enclose it), widened for rounding */
            const double pad = 1e-9 * c0[d] * bmax + 1e-300;
            glo[d] = c0[d] * emin - pad;
            ghi[d] = c0[d] * emax + pad;
        }
        widen_block_grad(g, l, glo, ghi);
        /* Small relative margin for rounding in the sums above. */
        g->cell_lipschitz[c] = round_up_float(sqrt(sum2) * (1.0 + 1e-9) + 1e-300);
    }
}

static int run_tasks(scc_parallel_for_fn* pf, void* user, int stage, uint32_t count, scc_task_fn* task, void* ctx)
{
    if (pf) return pf(user, stage, count, task, ctx);
    for (uint32_t i = 0; i < count; ++i) task(ctx, i);
    return 0;
}

/* Cell l's grid coordinates and which domain faces it touches; 0 when it touches none. */
static int boundary_cell(const scc_grid* g, uint64_t l, uint32_t ijk[3], int lo_face[3], int hi_face[3])
{
    int any = 0;
    cell_ijk(g, l, ijk);
    for (int d = 0; d < 3; ++d) {
        lo_face[d] = ijk[d] == 0;
        hi_face[d] = ijk[d] == g->res[d] - 1;
        any |= lo_face[d] | hi_face[d];
    }
    return any;
}

/* Job 0: the per-cell coefficients of the map to local coordinates (axis_coef in grid.h), from
 * the cell box exactly as cell_box and the per-query formula compute it. */
static scc_grid_status axis_tables(scc_grid* g)
{
    const size_t n = 2 * ((size_t)g->res[0] + g->res[1] + g->res[2]);
    if (!g->axis_coef) g->axis_coef = scc_alloc(&g->allocator, n * sizeof(double));
    if (!g->axis_coef) return SCC_GRID_OUT_OF_MEMORY;
    const double lo[3] = { g->lo.x, g->lo.y, g->lo.z }, h[3] = { g->h.x, g->h.y, g->h.z };
    double* t = g->axis_coef;
    for (int d = 0; d < 3; ++d)
        for (uint32_t m = 0; m < g->res[d]; ++m, t += 2) {
            const double a = lo[d] + (double)m * h[d], b = a + h[d], den = b - a;
            t[0] = 2.0 / den;
            t[1] = (b + a) / den;
        }
    return SCC_GRID_OK;
}

/* Large value arrays are read at random cells (a cell's 8 vertex blocks lie on 4 rows, up to 4
 * pages apart): where the system has transparent huge pages, ask for them on the whole 2 MB pages
 * inside a fresh copy (before it is touched), so a query costs no TLB misses (dense grids of 4 MB
 * or more; the copy briefly doubles the blocks at load). Advisory only: a
 * refusal changes nothing. */
static void advise_huge_pages(void* p, size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const uintptr_t huge = (uintptr_t)2 << 20;
    const uintptr_t lo = ((uintptr_t)p + huge - 1) & ~(huge - 1), hi = ((uintptr_t)p + bytes) & ~(huge - 1);
    if (hi > lo) (void)madvise((void*)lo, hi - lo, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}

static scc_grid_status blocks_on_huge_pages(scc_grid* g)
{
    const size_t bytes = (size_t)g->block_count * sizeof(double);
    if (!g->blocks || g->vertex_block || bytes < ((size_t)4 << 20)) return SCC_GRID_OK;
    double* copy = scc_alloc(&g->allocator, bytes);
    if (!copy) return SCC_GRID_OK; /* keep the blocks where they are */
    advise_huge_pages(copy, bytes);
    memcpy(copy, g->blocks, bytes);
    scc_free(&g->allocator, g->blocks, bytes);
    g->blocks = copy;
    return SCC_GRID_OK;
}

/* Job 1, layout: a field 0 loaded in Discregrid's dense layout (identity map, tables equal to the
 * formulas) has implied node ids, so its 128-byte-per-cell table is dropped and the values move
 * to the vertex-block layout (the builder writes them there directly). */
static scc_grid_status adopt_dense_layout(scc_grid* g)
{
    const scc_allocator* a = &g->allocator;
    scc_grid_field* fd = &g->fields[0];
    if (fd->cells && !g->blocks) {
        int dense = fd->cell_count == g->n_cells && fd->node_count == scc_grid_dense_node_count(g->res);
        for (uint64_t l = 0; l < g->n_cells && dense; ++l) {
            uint32_t ijk[3], ids[32];
            cell_ijk(g, l, ijk);
            scc_grid_dense_cell_nodes(g->res, ijk[0], ijk[1], ijk[2], ids);
            dense = fd->map[l] == l && memcmp(ids, fd->cells + l * 32, sizeof ids) == 0;
        }
        if (dense) {
            const uint64_t nb = 7 * (uint64_t)(g->res[0] + 1) * (g->res[1] + 1) * (g->res[2] + 1);
            double* blocks = scc_alloc(a, (size_t)nb * sizeof(double));
            if (!blocks) return SCC_GRID_OUT_OF_MEMORY;
            memset(blocks, 0, (size_t)nb * sizeof(double));
            for (uint64_t l = 0; l < fd->node_count; ++l) blocks[scc_grid_dense_block_index(g->res, l)] = fd->nodes[l];
            scc_free(a, fd->cells, (size_t)fd->cell_count * 32 * sizeof(uint32_t));
            scc_free(a, fd->nodes, (size_t)fd->node_count * sizeof(double));
            fd->cells = NULL;
            fd->nodes = NULL;
            g->blocks = blocks;
            g->block_count = nb;
        }
    }
    g->dense_layout = g->blocks != NULL && g->vertex_block == NULL;
    return SCC_GRID_OK;
}

/* Job 2: the per-cell gradient bounds (cell_lipschitz), in parallel tasks of 2048 cells. */
static scc_grid_status compute_cell_bounds(scc_grid* g, const bern_tables* bt, scc_parallel_for_fn* parallel_for, void* parallel_user)
{
    g->cell_lipschitz = scc_alloc(&g->allocator, (size_t)g->fields[0].cell_count * sizeof(float));
    if (g->fields[0].cell_count && !g->cell_lipschitz) return SCC_GRID_OUT_OF_MEMORY;
    const uint64_t nblocks = scc_grid_grad_block_count(g);
    g->block_grad = scc_alloc(&g->allocator, (size_t)nblocks * 6 * sizeof(float));
    if (!g->block_grad) return SCC_GRID_OUT_OF_MEMORY;
    for (uint64_t q = 0; q < nblocks; ++q)
        for (int d = 0; d < 3; ++d) {
            g->block_grad[6 * q + d] = INFINITY;
            g->block_grad[6 * q + 3 + d] = -INFINITY;
        }
    /* tasks of whole layers of blocks (block_grad is written without locks) */
    finalize_ctx ctx = { g, bt, (uint64_t)g->res[0] * g->res[1] * SCC_GRID_GRAD_BLOCK * (SCC_GRID_GRAD_BLOCK == 1 ? 4 : 2) };
    const uint32_t tasks = (uint32_t)((g->n_cells + ctx.chunk - 1) / ctx.chunk);
    const int cancelled = run_tasks(parallel_for, parallel_user, SCC_GRID_STAGE_CELLS, tasks, cell_bound_task, &ctx);
    return cancelled ? SCC_GRID_CANCELLED : SCC_GRID_OK;
}

/* Job 3: how many cells have values and the largest of their bounds. */
static scc_grid_status count_valued_cells(scc_grid* g)
{
    const scc_grid_field* fd = &g->fields[0];
    g->lipschitz_max = 0.0;
    g->valued_cells = 0;
    for (uint64_t l = 0; l < g->n_cells; ++l) {
        const uint32_t c = fd->map[l];
        if (c == SCC_GRID_NO_CELL || g->cell_lipschitz[c] < 0.0f) continue;
        g->valued_cells++;
        if (g->cell_lipschitz[c] > g->lipschitz_max) g->lipschitz_max = g->cell_lipschitz[c];
    }
    if (!isfinite(g->lipschitz_max)) return SCC_GRID_STEEP; /* per-cell bounds are floats: > 3.4e38 is inf */
    return g->valued_cells == 0 ? SCC_GRID_EMPTY : SCC_GRID_OK;
}

/* Job 4, hole sources: multi-source breadth-first search over the 26-neighbourhood from every
 * cell with values, so each hole cell learns a valued cell at the least Chebyshev distance;
 * then the side (sign) from that cell's value at the point nearest the hole's centre. */
static scc_grid_status find_hole_sources(scc_grid* g)
{
    const scc_allocator* a = &g->allocator;
    const scc_grid_field* fd = &g->fields[0];
    if (g->valued_cells == g->n_cells) return SCC_GRID_OK;
    g->hole_source = scc_alloc(a, (size_t)g->n_cells * sizeof(uint32_t));
    uint32_t* queue = scc_alloc(a, (size_t)g->n_cells * sizeof(uint32_t));
    if (!g->hole_source || !queue) {
        scc_free(a, queue, (size_t)g->n_cells * sizeof(uint32_t));
        return SCC_GRID_OUT_OF_MEMORY;
    }
    uint64_t head = 0, tail = 0;
    for (uint64_t l = 0; l < g->n_cells; ++l) {
        const uint32_t c = fd->map[l];
        if (c != SCC_GRID_NO_CELL && g->cell_lipschitz[c] >= 0.0f) { g->hole_source[l] = (uint32_t)l; queue[tail++] = (uint32_t)l; }
        else g->hole_source[l] = 0xFFFFFFFFu;
    }
    while (head < tail) {
        const uint32_t l = queue[head++];
        uint32_t ijk[3];
        cell_ijk(g, l, ijk);
        for (int dk = -1; dk <= 1; ++dk)
            for (int dj = -1; dj <= 1; ++dj)
                for (int di = -1; di <= 1; ++di) {
                    const int64_t ni = (int64_t)ijk[0] + di, nj = (int64_t)ijk[1] + dj, nk = (int64_t)ijk[2] + dk;
                    if (ni < 0 || nj < 0 || nk < 0 || ni >= g->res[0] || nj >= g->res[1] || nk >= g->res[2]) continue;
                    const uint64_t n = (uint64_t)ni + g->res[0] * ((uint64_t)nj + (uint64_t)g->res[1] * (uint64_t)nk);
                    if (g->hole_source[n] != 0xFFFFFFFFu) continue;
                    g->hole_source[n] = g->hole_source[l];
                    queue[tail++] = (uint32_t)n;
                }
    }
    scc_free(a, queue, (size_t)g->n_cells * sizeof(uint32_t));
    for (uint64_t l = 0; l < g->n_cells; ++l) {
        const uint32_t c = fd->map[l];
        if (c != SCC_GRID_NO_CELL && g->cell_lipschitz[c] >= 0.0f) continue;
        const uint32_t src = g->hole_source[l];
        uint32_t ijk[3], sijk[3];
        cell_ijk(g, l, ijk);
        cell_ijk(g, src, sijk);
        const scc_aabb cb = cell_box(g, ijk), sb = cell_box(g, sijk);
        const scc_vec3 q = clamp_box(scc_scale(scc_add(cb.lo, cb.hi), 0.5), &sb);
        double v = 0.0;
        interpolate_cell(g, fd, fd->map[src], sijk, q, &v, NULL);
        if (v < 0.0) g->hole_source[l] = src | 0x80000000u;
    }
    return SCC_GRID_OK;
}

/* Job 5: per-block maxima of the cell bounds (blocks of 4^3 cells; cells without values count
 * 1) for the Lipschitz bound of large boxes. */
static scc_grid_status compute_block_bounds(scc_grid* g)
{
    const scc_grid_field* fd = &g->fields[0];
    const uint32_t nbx = (g->res[0] + 3) / 4, nby = (g->res[1] + 3) / 4, nbz = (g->res[2] + 3) / 4;
    g->block_lipschitz = scc_alloc(&g->allocator, (size_t)nbx * nby * nbz * sizeof(float));
    if (!g->block_lipschitz) return SCC_GRID_OUT_OF_MEMORY;
    for (size_t q = 0; q < (size_t)nbx * nby * nbz; ++q) g->block_lipschitz[q] = 0.0f;
    for (uint64_t l = 0; l < g->n_cells; ++l) {
        uint32_t ijk[3];
        cell_ijk(g, l, ijk);
        const uint32_t c = fd->map[l];
        const float cl = (c == SCC_GRID_NO_CELL || g->cell_lipschitz[c] < 0.0f) ? 1.0f : g->cell_lipschitz[c];
        float* bl = &g->block_lipschitz[ijk[0] / 4 + (uint64_t)nbx * (ijk[1] / 4 + (uint64_t)nby * (ijk[2] / 4))];
        if (cl > *bl) *bl = cl;
    }
    return SCC_GRID_OK;
}

/* Job 6: is phi >= 0 on the whole domain boundary? Each boundary cell's 32 values go to a
 * per-cell test of its boundary faces; a cell without values fails when an inside hole reaches
 * it, and is skipped otherwise. */
typedef int boundary_face_test(const double v[32], const int lo_face[3], const int hi_face[3], const bern_tables* bt);

static int boundary_cells_pass(const scc_grid* g, boundary_face_test* test, const bern_tables* bt)
{
    const scc_grid_field* fd = &g->fields[0];
    for (uint64_t l = 0; l < g->n_cells; ++l) {
        uint32_t ijk[3];
        int lo_face[3], hi_face[3];
        if (!boundary_cell(g, l, ijk, lo_face, hi_face)) continue;
        const uint32_t c = fd->map[l];
        if (c == SCC_GRID_NO_CELL || g->cell_lipschitz[c] < 0.0f) {
            if (g->hole_source[l] & 0x80000000u) return 0;
            continue;
        }
        double v[32];
        gather_cell(g, fd, c, ijk, v);
        if (!test(v, lo_face, hi_face, bt)) return 0;
    }
    return 1;
}

/* Job 6a, per cell: every node on the cell's boundary faces is >= 0, i.e. the sampled surface
 * lies inside the box (sets outside_positive). */
static int nodes_nonnegative(const double v[32], const int lo_face[3], const int hi_face[3], const bern_tables* bt)
{
    (void)bt;
    for (int slot = 0; slot < 32; ++slot) {
        const scc_vec3 xi = scc_cell_node_local(slot);
        const double x[3] = { xi.x, xi.y, xi.z };
        for (int d = 0; d < 3; ++d)
            if ((lo_face[d] && x[d] == -1.0) || (hi_face[d] && x[d] == 1.0))
                if (v[slot] < 0.0) return 0;
    }
    return 1;
}

/* Job 6b, per cell: phi >= 0 on the cell's boundary faces, proved with each face's Bernstein
 * coefficients (the face restriction of the cell's tensor Bernstein form), which enclose the
 * interpolant on the face. */
static int bernstein_nonnegative(const double v[32], const int lo_face[3], const int hi_face[3], const bern_tables* bt)
{
    for (int s = 0; s < 64; ++s) {
        const int idx[3] = { s % 4, (s / 4) % 4, s / 16 };
        int on_face = 0;
        for (int d = 0; d < 3; ++d) on_face |= (lo_face[d] && idx[d] == 0) || (hi_face[d] && idx[d] == 3);
        if (!on_face) continue;
        double acc = 0.0;
        for (int k = 0; k < 32; ++k) acc += bt->val[s][k] * v[k];
        if (acc < 0.0) return 0;
    }
    return 1;
}

/* The scc_sdf interface. bounds must contain every point with phi <= 0: the domain when phi >= 0
 * on the whole domain boundary (then the outside continuation is positive), else unbounded
 * (phi_q - d continues the inside). */
static void fill_sdf_interface(scc_grid* g, int boundary_nonneg)
{
#if SCC_GRID_AVX
    g->base.eval = scc_grid_avx() ? scc_grid_eval_avx : scc_grid_eval;
#else
    g->base.eval = scc_grid_eval;
#endif
    g->base.lipschitz_in = scc_grid_lipschitz_in;
    g->base.domain.lo = g->lo;
    g->base.domain.hi = g->hi;
    if (boundary_nonneg) {
        g->base.bounds.lo = g->lo;
        g->base.bounds.hi = g->hi;
    } else {
        g->base.bounds.lo = scc_v3(-INFINITY, -INFINITY, -INFINITY);
        g->base.bounds.hi = scc_v3(INFINITY, INFINITY, INFINITY);
    }
    g->base.lipschitz = sqrt(1.0 + fmax(g->lipschitz_max, 1.0) * fmax(g->lipschitz_max, 1.0));
    g->base.kind = SCC_SDF_GRID;
    /* An interpolated grid is not known to be convex anywhere: the certified TOI must use the
     * Lipschitz bounds only. */
    g->base.convex = 0;
    g->base.convex_in = NULL;
}

scc_grid_status scc_grid_finalize(scc_grid* g, double band, scc_parallel_for_fn* parallel_for, void* parallel_user)
{
    const scc_allocator* a = &g->allocator;
    if (g->n_cells > 0x7FFFFFFEu) return SCC_GRID_TOO_LARGE;
    g->band = band > 0.0 && isfinite(band) ? band : 0.0;
    scc_grid_status st = axis_tables(g);
    if (st == SCC_GRID_OK) st = adopt_dense_layout(g);
    if (st == SCC_GRID_OK) st = blocks_on_huge_pages(g);
    if (st != SCC_GRID_OK) return st;
    bern_tables* bt = scc_alloc(a, sizeof *bt);
    if (!bt) return SCC_GRID_OUT_OF_MEMORY;
    scc_cell_bernstein(bt->val);
    for (int k = 0; k < 32; ++k)
        for (int q = 0; q < 64; ++q) bt->by_node[k][q] = bt->val[q][k];
    st = compute_cell_bounds(g, bt, parallel_for, parallel_user);
    if (st == SCC_GRID_OK) st = count_valued_cells(g);
    if (st == SCC_GRID_OK && g->dense_layout && g->valued_cells == g->n_cells) {
        g->direct = 1;
        for (uint64_t l = 0; l < g->n_cells && g->direct; ++l) g->direct = g->fields[0].map[l] == l;
    }
    if (st == SCC_GRID_OK) st = find_hole_sources(g);
    if (st == SCC_GRID_OK) st = compute_block_bounds(g);
    if (st == SCC_GRID_OK) {
        g->outside_positive = boundary_cells_pass(g, nodes_nonnegative, bt);
        fill_sdf_interface(g, g->outside_positive || boundary_cells_pass(g, bernstein_nonnegative, bt));
    }
    /* kept for the certified check's per-cell Taylor bounds (certified.c), which would otherwise
     * rebuild each cell's Bernstein form from 32 interpolations per query */
    if (st == SCC_GRID_OK && !g->bernstein) {
        g->bernstein = scc_alloc(a, sizeof bt->by_node);
        if (!g->bernstein) st = SCC_GRID_OUT_OF_MEMORY;
        else memcpy(g->bernstein, bt->by_node, sizeof bt->by_node);
    }
    scc_free(a, bt, sizeof *bt);
    return st;
}
