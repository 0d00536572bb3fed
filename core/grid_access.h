/* SPDX-License-Identifier: MIT
 * sdfccd core, private to the grid (grid.c, grid_bounds.c): cell addressing and the gathering
 * and interpolation of one cell's 32 values, whatever the storage of the field (node table,
 * dense vertex blocks or narrow-band vertex blocks; see scc_grid in grid.h).
 */
#ifndef SCC_GRID_ACCESS_H
#define SCC_GRID_ACCESS_H

#include "grid.h"

/* The 8 vertex blocks of full-grid cell ijk of a field 0 kept in vertex blocks (see
 * scc_grid_dense_block_index), corner order di + 2 dj + 4 dk. */
static inline void cell_blocks_of(const scc_grid* g, const uint32_t ijk[3], const double* b[8])
{
    const uint64_t sy = (uint64_t)g->res[0] + 1, sz = sy * ((uint64_t)g->res[1] + 1);
    const uint64_t base = ijk[0] + sy * ijk[1] + sz * ijk[2];
    const uint64_t vid[8] = { base, base + 1, base + sy, base + sy + 1, base + sz, base + sz + 1, base + sz + sy, base + sz + sy + 1 };
    if (g->vertex_block)
        for (int q = 0; q < 8; ++q) b[q] = g->blocks + 7 * (uint64_t)g->vertex_block[vid[q]];
    else
        for (int q = 0; q < 8; ++q) b[q] = g->blocks + 7 * vid[q];
}

/* The 32 values of stored cell c (full-grid position ijk) of a field, in slot order. */
static inline void gather_cell(const scc_grid* g, const scc_grid_field* fd, uint32_t c, const uint32_t ijk[3], double v[32])
{
    if (fd == &g->fields[0] && g->blocks) {
        const double* b[8];
        cell_blocks_of(g, ijk, b);
        /* corners: slot di + 2 dj + 4 dk = block index q */
        for (int q = 0; q < 8; ++q) v[q] = b[q][0];
        /* x edges (slot 8 + 4 dj + 2 dk + s) start at corner c = 2 dj + 4 dk */
        v[8] = b[0][1]; v[9] = b[0][2]; v[10] = b[4][1]; v[11] = b[4][2];
        v[12] = b[2][1]; v[13] = b[2][2]; v[14] = b[6][1]; v[15] = b[6][2];
        /* y edges (slot 16 + 4 dk + 2 di + s) start at corner c = di + 4 dk */
        v[16] = b[0][3]; v[17] = b[0][4]; v[18] = b[1][3]; v[19] = b[1][4];
        v[20] = b[4][3]; v[21] = b[4][4]; v[22] = b[5][3]; v[23] = b[5][4];
        /* z edges (slot 24 + 4 di + 2 dj + s) start at corner c = di + 2 dj */
        v[24] = b[0][5]; v[25] = b[0][6]; v[26] = b[2][5]; v[27] = b[2][6];
        v[28] = b[1][5]; v[29] = b[1][6]; v[30] = b[3][5]; v[31] = b[3][6];
        return;
    }
    uint32_t scratch[32];
    const uint32_t* ids = fd->cells ? fd->cells + (size_t)c * 32 : scc_grid_cell_ids(g, (uint32_t)(fd - g->fields), c, scratch);
    for (int a = 0; a < 32; ++a) v[a] = fd->nodes[ids[a]];
}

static inline void cell_ijk(const scc_grid* g, uint64_t l, uint32_t ijk[3])
{
    ijk[0] = (uint32_t)(l % g->res[0]);
    ijk[1] = (uint32_t)((l / g->res[0]) % g->res[1]);
    ijk[2] = (uint32_t)(l / ((uint64_t)g->res[0] * g->res[1]));
}

static inline scc_aabb cell_box(const scc_grid* g, const uint32_t ijk[3])
{
    scc_aabb b;
    b.lo = scc_v3(g->lo.x + (double)ijk[0] * g->h.x, g->lo.y + (double)ijk[1] * g->h.y, g->lo.z + (double)ijk[2] * g->h.z);
    b.hi = scc_add(b.lo, g->h);
    return b;
}

/* Locates the cell of p (p inside the domain) the way Discregrid and Bullet do. */
static inline uint64_t locate(const scc_grid* g, scc_vec3 p, uint32_t ijk[3])
{
    const double r[3] = { (p.x - g->lo.x) * g->inv_h.x, (p.y - g->lo.y) * g->inv_h.y, (p.z - g->lo.z) * g->inv_h.z };
    for (int d = 0; d < 3; ++d) {
        double v = r[d] > 0.0 ? r[d] : 0.0;
        uint32_t m = v >= (double)g->res[d] ? g->res[d] - 1 : (uint32_t)v;
        ijk[d] = m;
    }
    return ijk[0] + (uint64_t)g->res[0] * (ijk[1] + (uint64_t)g->res[1] * ijk[2]);
}

/* Local coordinates of p in the cell at ijk, xi_d = c0_d p_d - c1_d, with the per-cell
 * coefficients of axis_coef (the same numbers the per-query formula of Discregrid and Bullet
 * gives: 2/(hi - lo) and (hi + lo)/(hi - lo) of the cell box). */
static inline scc_vec3 cell_local(const scc_grid* g, const uint32_t ijk[3], scc_vec3 p, double c0[3])
{
    const double* tx = g->axis_coef + 2 * (size_t)ijk[0];
    const double* ty = g->axis_coef + 2 * ((size_t)g->res[0] + ijk[1]);
    const double* tz = g->axis_coef + 2 * ((size_t)g->res[0] + g->res[1] + ijk[2]);
    c0[0] = tx[0]; c0[1] = ty[0]; c0[2] = tz[0];
    return scc_v3(tx[0] * p.x - tx[1], ty[0] * p.y - ty[1], tz[0] * p.z - tz[1]);
}

/* Interpolates stored cell c (whose full-grid position is ijk) at p. Returns 0 when a node is
 * not sampled (checked only when `check`: field 0's cells with a bound >= 0 have every value). */
static inline int interpolate_cell_checked(const scc_grid* g, const scc_grid_field* fd, uint32_t c, const uint32_t ijk[3], scc_vec3 p,
                                           double* out_value, scc_vec3* out_grad, int check)
{
    double c0[3];
    const scc_vec3 xi = cell_local(g, ijk, p, c0);
    double gr[3];
    if (!check && fd == &g->fields[0] && g->blocks) {
        /* straight from the vertex blocks (the same numbers as gather_cell gives, the edge
         * pairs read as pairs) */
        const double* b[8];
        cell_blocks_of(g, ijk, b);
        const double* const ex[4] = { b[0] + 1, b[4] + 1, b[2] + 1, b[6] + 1 };
        const double* const ey[4] = { b[0] + 3, b[1] + 3, b[4] + 3, b[5] + 3 };
        const double* const ez[4] = { b[0] + 5, b[2] + 5, b[1] + 5, b[3] + 5 };
        scc_cell_eval_at(b, ex, ey, ez, xi, out_value, out_grad ? gr : NULL);
    } else {
        /* gather the 32 values first: independent loads let the memory accesses overlap */
        double v[32];
        gather_cell(g, fd, c, ijk, v);
        if (check) {
            int missing = 0;
            for (int a = 0; a < 32; ++a) missing |= v[a] == SCC_GRID_NO_VALUE;
            if (missing) return 0;
        }
        scc_cell_eval_inline(v, xi, out_value, out_grad ? gr : NULL);
    }
    if (out_grad) *out_grad = scc_v3(gr[0] * c0[0], gr[1] * c0[1], gr[2] * c0[2]);
    return 1;
}

static inline int interpolate_cell(const scc_grid* g, const scc_grid_field* fd, uint32_t c, const uint32_t ijk[3], scc_vec3 p,
                                   double* out_value, scc_vec3* out_grad)
{
    return interpolate_cell_checked(g, fd, c, ijk, p, out_value, out_grad, 1);
}

static inline scc_vec3 clamp_box(scc_vec3 p, const scc_aabb* b)
{
    return scc_v3(scc_clamp(p.x, b->lo.x, b->hi.x), scc_clamp(p.y, b->lo.y, b->hi.y), scc_clamp(p.z, b->lo.z, b->hi.z));
}

#endif
