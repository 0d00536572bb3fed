/* SPDX-License-Identifier: MIT
 * sdfccd core: the 32-node cubic Lagrange (serendipity) cell of Discregrid (Koschier et al.,
 * "An hp-adaptive discretization algorithm for signed distance field generation", 2017) as
 * used by Discregrid's CubicLagrangeDiscreteGrid and Bullet's btMiniSDF; grid evaluation,
 * conservative values outside the domain and in culled cells, and per-cell gradient bounds
 * from the Bernstein form of the interpolant's derivative. Written from the description in
 * the shared notes (sdf-format-and-assets.md sections 2-5), not from either codebase.
 */
#include "grid.h"

#include <float.h>
#include <string.h>

/* ------------------------------------------------------------------------------------------
 * The element. Slot numbering (notes section 3):
 *   corners      0..7 : di + 2 dj + 4 dk            at (2di-1, 2dj-1, 2dk-1)
 *   x-edge nodes 8..15: 8 + 4 dj + 2 dk + s         at (-1/3 + 2s/3, 2dj-1, 2dk-1)
 *   y-edge nodes 16..23: 16 + 4 dk + 2 di + s       at (2di-1, -1/3 + 2s/3, 2dk-1)
 *   z-edge nodes 24..31: 24 + 4 di + 2 dj + s       at (2di-1, 2dj-1, -1/3 + 2s/3)
 * ---------------------------------------------------------------------------------------- */

/* sigma[a] = local coordinates of slot a; axis[a] = edge direction (-1 for corners). */
static const double k_sigma[32][3] = {
    { -1, -1, -1 }, { 1, -1, -1 }, { -1, 1, -1 }, { 1, 1, -1 },
    { -1, -1, 1 }, { 1, -1, 1 }, { -1, 1, 1 }, { 1, 1, 1 },
    /* x edges: 8 + 4dj + 2dk + s */
    { -1.0 / 3, -1, -1 }, { 1.0 / 3, -1, -1 }, { -1.0 / 3, -1, 1 }, { 1.0 / 3, -1, 1 },
    { -1.0 / 3, 1, -1 }, { 1.0 / 3, 1, -1 }, { -1.0 / 3, 1, 1 }, { 1.0 / 3, 1, 1 },
    /* y edges: 16 + 4dk + 2di + s */
    { -1, -1.0 / 3, -1 }, { -1, 1.0 / 3, -1 }, { 1, -1.0 / 3, -1 }, { 1, 1.0 / 3, -1 },
    { -1, -1.0 / 3, 1 }, { -1, 1.0 / 3, 1 }, { 1, -1.0 / 3, 1 }, { 1, 1.0 / 3, 1 },
    /* z edges: 24 + 4di + 2dj + s */
    { -1, -1, -1.0 / 3 }, { -1, -1, 1.0 / 3 }, { -1, 1, -1.0 / 3 }, { -1, 1, 1.0 / 3 },
    { 1, -1, -1.0 / 3 }, { 1, -1, 1.0 / 3 }, { 1, 1, -1.0 / 3 }, { 1, 1, 1.0 / 3 },
};

scc_vec3 scc_cell_node_local(int slot)
{
    if (slot < 0 || slot > 31) return scc_v3(0, 0, 0);
    return scc_v3(k_sigma[slot][0], k_sigma[slot][1], k_sigma[slot][2]);
}

void scc_cell_shape(scc_vec3 xi, double N[32], double dN[32][3])
{
    const double x[3] = { xi.x, xi.y, xi.z };
    /* Linear factors (1 + s x_d) for s = -1 (index 0) and s = +1 (index 1). */
    double lin[3][2];
    for (int d = 0; d < 3; ++d) { lin[d][0] = 1.0 - x[d]; lin[d][1] = 1.0 + x[d]; }
    const double r2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    const double q = 9.0 * r2 - 19.0;

    /* Corners: N = (1/64) (1+s1 x)(1+s2 y)(1+s3 z)(9 r^2 - 19). */
    for (int a = 0; a < 8; ++a) {
        const int i0 = a & 1, i1 = (a >> 1) & 1, i2 = (a >> 2) & 1;
        const double l0 = lin[0][i0], l1 = lin[1][i1], l2 = lin[2][i2];
        N[a] = (1.0 / 64.0) * l0 * l1 * l2 * q;
        if (dN) {
            const double s[3] = { i0 ? 1.0 : -1.0, i1 ? 1.0 : -1.0, i2 ? 1.0 : -1.0 };
            const double l[3] = { l0, l1, l2 };
            for (int e = 0; e < 3; ++e) {
                const double others = l[(e + 1) % 3] * l[(e + 2) % 3];
                dN[a][e] = (1.0 / 64.0) * others * (s[e] * q + 18.0 * x[e] * l[e]);
            }
        }
    }
    /* Edge nodes: along axis d at sd = +-1/3, the two other axes p (outer) and q (inner).
     * N = (9/64)(1 - x_d^2)(1 + 9 sd x_d)(1 + sp x_p)(1 + sq x_q). */
    for (int d = 0; d < 3; ++d) {
        const int p = d == 0 ? 1 : (d == 1 ? 2 : 0); /* outer axis of the slot nesting */
        const int r = d == 0 ? 2 : (d == 1 ? 0 : 1); /* inner axis */
        const double w = 1.0 - x[d] * x[d];
        for (int dp = 0; dp < 2; ++dp)
            for (int dr = 0; dr < 2; ++dr)
                for (int s = 0; s < 2; ++s) {
                    const int a = 8 + 8 * d + 4 * dp + 2 * dr + s;
                    const double c = s ? 3.0 : -3.0; /* 9 * sd */
                    const double m = 1.0 + c * x[d];
                    const double lp = lin[p][dp], lr = lin[r][dr];
                    N[a] = (9.0 / 64.0) * w * m * lp * lr;
                    if (dN) {
                        dN[a][d] = (9.0 / 64.0) * lp * lr * (c * w - 2.0 * x[d] * m);
                        dN[a][p] = (9.0 / 64.0) * w * m * (dp ? 1.0 : -1.0) * lr;
                        dN[a][r] = (9.0 / 64.0) * w * m * lp * (dr ? 1.0 : -1.0);
                    }
                }
    }
}

/* One edge family of the factored element: e[4 dp + 2 dr + t] are the values of the edge
 * nodes along axis d (at -1/3, +1/3 for t = 0, 1); Lp, Lr the linear factors of the outer and
 * inner axes. Adds the family's value to *phi and its derivatives to g[d], g[p], g[r]. */
static inline void edge_family(const double e[8], double xd, const double Lp[2], const double Lr[2], double* phi, double* g, int d, int p, int r)
{
    const double w = 1.0 - xd * xd;
    const double m0 = 1.0 - 3.0 * xd, m1 = 1.0 + 3.0 * xd;
    const double l00 = Lp[0] * Lr[0], l01 = Lp[0] * Lr[1], l10 = Lp[1] * Lr[0], l11 = Lp[1] * Lr[1];
    const double B0 = e[0] * l00 + e[2] * l01 + e[4] * l10 + e[6] * l11;
    const double B1 = e[1] * l00 + e[3] * l01 + e[5] * l10 + e[7] * l11;
    const double m = m0 * B0 + m1 * B1;
    *phi += (9.0 / 64.0) * w * m;
    if (g) {
        /* d/dx_p of Lp[dp] is -1, +1; d/dx_r of Lr[dr] likewise */
        const double Bp0 = (e[4] - e[0]) * Lr[0] + (e[6] - e[2]) * Lr[1], Bp1 = (e[5] - e[1]) * Lr[0] + (e[7] - e[3]) * Lr[1];
        const double Br0 = (e[2] - e[0]) * Lp[0] + (e[6] - e[4]) * Lp[1], Br1 = (e[3] - e[1]) * Lp[0] + (e[7] - e[5]) * Lp[1];
        g[d] += (9.0 / 64.0) * (-2.0 * xd * m + w * 3.0 * (B1 - B0));
        g[p] += (9.0 / 64.0) * w * (m0 * Bp0 + m1 * Bp1);
        g[r] += (9.0 / 64.0) * w * (m0 * Br0 + m1 * Br1);
    }
}

void scc_cell_eval(const double v[32], scc_vec3 xi, double* out_value, double out_grad[3])
{
    /* The same interpolant as sum_a v[a] N_a, factored: the corner part is
     * (9 r^2 - 19)/64 times the trilinear form S of the corner values, and each edge family is
     * (9/64)(1 - x_d^2) times a cubic factor in x_d times a bilinear form in the other two. */
    const double x[3] = { xi.x, xi.y, xi.z };
    double L[3][2];
    for (int d = 0; d < 3; ++d) { L[d][0] = 1.0 - x[d]; L[d][1] = 1.0 + x[d]; }
    /* trilinear form of the corner values (slot di + 2 dj + 4 dk) and its derivatives */
    const double a00 = v[0] * L[0][0] + v[1] * L[0][1], a10 = v[2] * L[0][0] + v[3] * L[0][1];
    const double a01 = v[4] * L[0][0] + v[5] * L[0][1], a11 = v[6] * L[0][0] + v[7] * L[0][1];
    const double y0z0 = L[1][0] * L[2][0], y1z0 = L[1][1] * L[2][0], y0z1 = L[1][0] * L[2][1], y1z1 = L[1][1] * L[2][1];
    const double S = a00 * y0z0 + a10 * y1z0 + a01 * y0z1 + a11 * y1z1;
    double Sx = 0.0, Sy = 0.0, Sz = 0.0;
    if (out_grad) {
        Sx = (v[1] - v[0]) * y0z0 + (v[3] - v[2]) * y1z0 + (v[5] - v[4]) * y0z1 + (v[7] - v[6]) * y1z1;
        Sy = (a10 - a00) * L[2][0] + (a11 - a01) * L[2][1];
        Sz = (a01 - a00) * L[1][0] + (a11 - a10) * L[1][1];
    }
    const double q = 9.0 * (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - 19.0;
    double phi = (1.0 / 64.0) * q * S;
    double g[3] = { 0.0, 0.0, 0.0 };
    if (out_grad) {
        g[0] = (1.0 / 64.0) * (q * Sx + 18.0 * x[0] * S);
        g[1] = (1.0 / 64.0) * (q * Sy + 18.0 * x[1] * S);
        g[2] = (1.0 / 64.0) * (q * Sz + 18.0 * x[2] * S);
    }
    /* edge families: x (outer y, inner z), y (outer z, inner x), z (outer x, inner y) */
    edge_family(v + 8, x[0], L[1], L[2], &phi, out_grad ? g : NULL, 0, 1, 2);
    edge_family(v + 16, x[1], L[2], L[0], &phi, out_grad ? g : NULL, 1, 2, 0);
    edge_family(v + 24, x[2], L[0], L[1], &phi, out_grad ? g : NULL, 2, 0, 1);
    *out_value = phi;
    if (out_grad) { out_grad[0] = g[0]; out_grad[1] = g[1]; out_grad[2] = g[2]; }
}

/* ------------------------------------------------------------------------------------------
 * Grid data
 * ---------------------------------------------------------------------------------------- */

static scc_grid* grid_alloc(const scc_allocator* a, uint32_t field_count)
{
    if (field_count == 0) return NULL;
    scc_grid* g = scc_alloc(a, sizeof *g);
    if (!g) return NULL;
    memset(g, 0, sizeof *g);
    g->fields = scc_alloc(a, (size_t)field_count * sizeof *g->fields);
    if (!g->fields) { scc_free(a, g, sizeof *g); return NULL; }
    memset(g->fields, 0, (size_t)field_count * sizeof *g->fields);
    g->field_count = field_count;
    g->allocator = *a;
    return g;
}

scc_grid* scc_grid_create_raw(const scc_allocator* a, scc_vec3 lo, scc_vec3 hi, const uint32_t res[3],
                              scc_vec3 h, scc_vec3 inv_h, uint32_t field_count)
{
    scc_grid* g = grid_alloc(a, field_count);
    if (!g) return NULL;
    g->lo = lo; g->hi = hi;
    g->res[0] = res[0]; g->res[1] = res[1]; g->res[2] = res[2];
    g->h = h; g->inv_h = inv_h;
    g->n_cells = (uint64_t)res[0] * res[1] * res[2];
    return g;
}

scc_grid* scc_grid_create(const scc_allocator* a, scc_vec3 lo, scc_vec3 hi, const uint32_t res[3], uint32_t field_count)
{
    scc_vec3 h = scc_v3((hi.x - lo.x) / (double)res[0], (hi.y - lo.y) / (double)res[1], (hi.z - lo.z) / (double)res[2]);
    scc_vec3 ih = scc_v3(1.0 / h.x, 1.0 / h.y, 1.0 / h.z);
    return scc_grid_create_raw(a, lo, hi, res, h, ih, field_count);
}

void scc_grid_destroy(scc_grid* g)
{
    if (!g) return;
    const scc_allocator* a = &g->allocator;
    scc_allocator al = *a;
    for (uint32_t f = 0; f < g->field_count; ++f) {
        scc_grid_field* fd = &g->fields[f];
        scc_free(&al, fd->nodes, (size_t)fd->node_count * sizeof(double));
        scc_free(&al, fd->cells, (size_t)fd->cell_count * 32 * sizeof(uint32_t));
        scc_free(&al, fd->map, (size_t)g->n_cells * sizeof(uint32_t));
    }
    if (g->field_count) {
        scc_free(&al, g->cell_lipschitz, (size_t)g->fields[0].cell_count * sizeof(float));
    }
    scc_free(&al, g->hole_source, (size_t)g->n_cells * sizeof(uint32_t));
    scc_free(&al, g->blocks, (size_t)g->block_count * sizeof(double));
    scc_free(&al, g->block_lipschitz, (size_t)((g->res[0] + 3) / 4) * ((g->res[1] + 3) / 4) * ((g->res[2] + 3) / 4) * sizeof(float));
    scc_free(&al, g->vertex_block, (size_t)(g->res[0] + 1) * (g->res[1] + 1) * (g->res[2] + 1) * sizeof(uint32_t));
    scc_free(&al, g->fields, (size_t)g->field_count * sizeof *g->fields);
    scc_free(&al, g, sizeof *g);
}

size_t scc_grid_memory(const scc_grid* g)
{
    size_t b = sizeof *g + (size_t)g->field_count * sizeof *g->fields;
    for (uint32_t f = 0; f < g->field_count; ++f) {
        const scc_grid_field* fd = &g->fields[f];
        b += (fd->nodes ? (size_t)fd->node_count * sizeof(double) : 0) + (fd->cells ? (size_t)fd->cell_count * 32 * sizeof(uint32_t) : 0)
           + (fd->map ? (size_t)g->n_cells * sizeof(uint32_t) : 0);
    }
    if (g->cell_lipschitz) b += (size_t)g->fields[0].cell_count * sizeof(float);
    if (g->hole_source) b += (size_t)g->n_cells * sizeof(uint32_t);
    b += (size_t)g->block_count * sizeof(double);
    if (g->block_lipschitz) b += (size_t)((g->res[0] + 3) / 4) * ((g->res[1] + 3) / 4) * ((g->res[2] + 3) / 4) * sizeof(float);
    if (g->vertex_block) b += (size_t)(g->res[0] + 1) * (g->res[1] + 1) * (g->res[2] + 1) * sizeof(uint32_t);
    return b;
}

/* ---- dense numbering (notes section 2 and 4) ---- */

uint64_t scc_grid_dense_node_count(const uint32_t res[3])
{
    const uint64_t nx = res[0], ny = res[1], nz = res[2];
    const uint64_t nv = (nx + 1) * (ny + 1) * (nz + 1);
    const uint64_t ex = nx * (ny + 1) * (nz + 1), ey = (nx + 1) * ny * (nz + 1), ez = (nx + 1) * (ny + 1) * nz;
    return nv + 2 * (ex + ey + ez);
}

scc_vec3 scc_grid_dense_node_position(const scc_grid* g, uint64_t l)
{
    const uint64_t nx = g->res[0], ny = g->res[1], nz = g->res[2];
    const uint64_t nv = (nx + 1) * (ny + 1) * (nz + 1);
    const uint64_t ex = nx * (ny + 1) * (nz + 1), ey = (nx + 1) * ny * (nz + 1);
    uint64_t i, j, k;
    int axis = -1;
    double s = 0.0;
    if (l < nv) {
        k = l / ((nx + 1) * (ny + 1));
        uint64_t r = l % ((nx + 1) * (ny + 1));
        j = r / (nx + 1); i = r % (nx + 1);
    } else if (l < nv + 2 * ex) {
        uint64_t e = (l - nv) / 2;
        s = (double)((l - nv) % 2);
        k = e / (nx * (ny + 1));
        uint64_t r = e % (nx * (ny + 1));
        j = r / nx; i = r % nx;
        axis = 0;
    } else if (l < nv + 2 * (ex + ey)) {
        uint64_t e = (l - nv - 2 * ex) / 2;
        s = (double)((l - nv - 2 * ex) % 2);
        /* y edges: j fastest, then k, then i */
        i = e / (ny * (nz + 1));
        uint64_t r = e % (ny * (nz + 1));
        k = r / ny; j = r % ny;
        axis = 1;
    } else {
        uint64_t e = (l - nv - 2 * (ex + ey)) / 2;
        s = (double)((l - nv - 2 * (ex + ey)) % 2);
        /* z edges: k fastest, then i, then j */
        j = e / (nz * (nx + 1));
        uint64_t r = e % (nz * (nx + 1));
        i = r / nz; k = r % nz;
        axis = 2;
    }
    scc_vec3 x = scc_v3(g->lo.x + g->h.x * (double)i, g->lo.y + g->h.y * (double)j, g->lo.z + g->h.z * (double)k);
    const double f = (1.0 + s) / 3.0;
    if (axis == 0) x.x += f * g->h.x;
    else if (axis == 1) x.y += f * g->h.y;
    else if (axis == 2) x.z += f * g->h.z;
    return x;
}

void scc_grid_dense_cell_nodes(const uint32_t res[3], uint32_t i, uint32_t j, uint32_t k, uint32_t out[32])
{
    const uint64_t nx = res[0], ny = res[1], nz = res[2];
    const uint64_t nv = (nx + 1) * (ny + 1) * (nz + 1);
    const uint64_t ex = nx * (ny + 1) * (nz + 1), ey = (nx + 1) * ny * (nz + 1);
    for (int dk = 0; dk < 2; ++dk)
        for (int dj = 0; dj < 2; ++dj)
            for (int di = 0; di < 2; ++di)
                out[di + 2 * dj + 4 * dk] = (uint32_t)((i + di) + (nx + 1) * ((j + dj) + (ny + 1) * (uint64_t)(k + dk)));
    for (int dj = 0; dj < 2; ++dj)
        for (int dk = 0; dk < 2; ++dk)
            for (int s = 0; s < 2; ++s)
                out[8 + 4 * dj + 2 * dk + s] = (uint32_t)(nv + 2 * (i + nx * ((j + dj) + (ny + 1) * (uint64_t)(k + dk))) + s);
    for (int dk = 0; dk < 2; ++dk)
        for (int di = 0; di < 2; ++di)
            for (int s = 0; s < 2; ++s)
                out[16 + 4 * dk + 2 * di + s] = (uint32_t)(nv + 2 * ex + 2 * (j + ny * ((k + dk) + (nz + 1) * (uint64_t)(i + di))) + s);
    for (int di = 0; di < 2; ++di)
        for (int dj = 0; dj < 2; ++dj)
            for (int s = 0; s < 2; ++s)
                out[24 + 4 * di + 2 * dj + s] = (uint32_t)(nv + 2 * (ex + ey) + 2 * (k + nz * ((i + di) + (nx + 1) * (uint64_t)(j + dj))) + s);
}

/* ------------------------------------------------------------------------------------------
 * Evaluation
 * ---------------------------------------------------------------------------------------- */

uint64_t scc_grid_dense_block_index(const uint32_t res[3], uint64_t l)
{
    /* Vertex-block layout: vertex (i,j,k) owns 7 consecutive values: its own, then the two
     * nodes of the x, y and z edges that start at it. */
    const uint64_t nx = res[0], ny = res[1], nz = res[2];
    const uint64_t nv = (nx + 1) * (ny + 1) * (nz + 1);
    const uint64_t ex = nx * (ny + 1) * (nz + 1), ey = (nx + 1) * ny * (nz + 1);
    uint64_t i, j, k, slot;
    if (l < nv) return 7 * l;
    if (l < nv + 2 * ex) {
        const uint64_t e = (l - nv) / 2;
        slot = 1 + (l - nv) % 2;
        k = e / (nx * (ny + 1)); j = (e % (nx * (ny + 1))) / nx; i = e % nx;
    } else if (l < nv + 2 * (ex + ey)) {
        const uint64_t e = (l - nv - 2 * ex) / 2;
        slot = 3 + (l - nv - 2 * ex) % 2;
        i = e / (ny * (nz + 1)); k = (e % (ny * (nz + 1))) / ny; j = e % ny;
    } else {
        const uint64_t e = (l - nv - 2 * (ex + ey)) / 2;
        slot = 5 + (l - nv - 2 * (ex + ey)) % 2;
        j = e / (nz * (nx + 1)); i = (e % (nz * (nx + 1))) / nz; k = e % nz;
    }
    return 7 * (i + (nx + 1) * (j + (ny + 1) * k)) + slot;
}

double scc_grid_node_value(const scc_grid* g, uint32_t field, uint64_t id)
{
    if (field == 0 && g->vertex_block) return NAN; /* band layout: node ids exist only in saved files */
    if (field == 0 && g->blocks) return g->blocks[scc_grid_dense_block_index(g->res, id)];
    return g->fields[field].nodes[id];
}

/* The 32 values of stored cell c (full-grid position ijk) of a field, in slot order. */
static inline void gather_cell(const scc_grid* g, const scc_grid_field* fd, uint32_t c, const uint32_t ijk[3], double v[32])
{
    if (fd == &g->fields[0] && g->blocks) {
        const uint64_t sy = (uint64_t)g->res[0] + 1, sz = sy * ((uint64_t)g->res[1] + 1);
        const uint64_t base = ijk[0] + sy * ijk[1] + sz * ijk[2];
        const uint64_t vid[8] = { base, base + 1, base + sy, base + sy + 1, base + sz, base + sz + 1, base + sz + sy, base + sz + sy + 1 };
        const double* b[8];
        for (int q = 0; q < 8; ++q) b[q] = g->blocks + 7 * (uint64_t)(g->vertex_block ? g->vertex_block[vid[q]] : vid[q]);
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

const uint32_t* scc_grid_cell_ids(const scc_grid* g, uint32_t field, uint32_t c, uint32_t scratch[32])
{
    const scc_grid_field* fd = &g->fields[field];
    if (fd->cells) return fd->cells + (size_t)c * 32;
    /* dense field 0 without a table: stored cell c is full-grid cell c */
    const uint32_t i = (uint32_t)(c % g->res[0]), j = (uint32_t)((c / g->res[0]) % g->res[1]), k = (uint32_t)(c / ((uint64_t)g->res[0] * g->res[1]));
    scc_grid_dense_cell_nodes(g->res, i, j, k, scratch);
    return scratch;
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

uint64_t scc_grid_cell_of(const scc_grid* g, scc_vec3 p)
{
    uint32_t ijk[3];
    return locate(g, p, ijk);
}

/* Interpolates stored cell c (whose full-grid position is ijk) at p. Returns 0 when a node is
 * not sampled. */
static int interpolate_cell(const scc_grid* g, const scc_grid_field* fd, uint32_t c, const uint32_t ijk[3], scc_vec3 p,
                            double* out_value, scc_vec3* out_grad)
{
    const scc_aabb b = cell_box(g, ijk);
    const double den[3] = { b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z };
    const double c0[3] = { 2.0 / den[0], 2.0 / den[1], 2.0 / den[2] };
    const double c1[3] = { (b.hi.x + b.lo.x) / den[0], (b.hi.y + b.lo.y) / den[1], (b.hi.z + b.lo.z) / den[2] };
    const scc_vec3 xi = scc_v3(c0[0] * p.x - c1[0], c0[1] * p.y - c1[1], c0[2] * p.z - c1[2]);
    /* Gather the 32 values first: independent loads let the memory accesses overlap. A dense
     * field 0 reads them from 8 vertex blocks (see scc_grid_dense_block_index). */
    double v[32];
    int missing = 0;
    gather_cell(g, fd, c, ijk, v);
    for (int a = 0; a < 32; ++a) missing |= v[a] == SCC_GRID_NO_VALUE;
    if (missing) return 0;
    double gr[3];
    scc_cell_eval(v, xi, out_value, out_grad ? gr : NULL);
    if (out_grad) *out_grad = scc_v3(gr[0] * c0[0], gr[1] * c0[1], gr[2] * c0[2]);
    return 1;
}

int scc_grid_interpolate(const scc_grid* g, uint32_t field, scc_vec3 p, double* out_value, scc_vec3* out_grad)
{
    if (field >= g->field_count) return 0;
    if (!(p.x >= g->lo.x && p.x <= g->hi.x && p.y >= g->lo.y && p.y <= g->hi.y && p.z >= g->lo.z && p.z <= g->hi.z)) return 0;
    const scc_grid_field* fd = &g->fields[field];
    uint32_t ijk[3];
    const uint64_t l = locate(g, p, ijk);
    const uint32_t c = fd->map[l];
    if (c == SCC_GRID_NO_CELL) return 0;
    return interpolate_cell(g, fd, c, ijk, p, out_value, out_grad);
}

static inline scc_vec3 clamp_box(scc_vec3 p, const scc_aabb* b)
{
    return scc_v3(scc_clamp(p.x, b->lo.x, b->hi.x), scc_clamp(p.y, b->lo.y, b->hi.y), scc_clamp(p.z, b->lo.z, b->hi.z));
}

static inline double hmin(const scc_grid* g) { return fmin(g->h.x, fmin(g->h.y, g->h.z)); }

/* Conservative value in a cell without values (full index l, position ijk). */
static double eval_hole(const scc_grid* g, uint64_t l, const uint32_t ijk[3], scc_vec3 p, scc_vec3* out_grad)
{
    const uint32_t code = g->hole_source[l];
    const double s = (code & 0x80000000u) ? -1.0 : 1.0;
    const uint64_t src = code & 0x7FFFFFFFu;
    uint32_t sijk[3];
    cell_ijk(g, src, sijk);
    uint32_t cheb = 0;
    for (int d = 0; d < 3; ++d) {
        uint32_t dd = ijk[d] > sijk[d] ? ijk[d] - sijk[d] : sijk[d] - ijk[d];
        if (dd > cheb) cheb = dd;
    }
    double lb = g->band;
    if (cheb >= 1) lb = fmax(lb, (double)(cheb - 1) * hmin(g));
    /* 1-Lipschitz bound from the nearest point q of the source cell: |phi(p)| >= |phi(q)| - |p - q|. */
    const scc_aabb sb = cell_box(g, sijk);
    const scc_vec3 q = clamp_box(p, &sb);
    const scc_vec3 dq = scc_sub(p, q);
    const double dist = scc_len(dq);
    double vq;
    if (interpolate_cell(g, &g->fields[0], g->fields[0].map[src], sijk, q, &vq, NULL)) lb = fmax(lb, fabs(vq) - dist);
    if (out_grad) {
        scc_vec3 dir;
        if (dist > 0.0) dir = scc_scale(dq, 1.0 / dist);
        else {
            const scc_aabb cb = cell_box(g, ijk);
            dir = scc_normalize_or(scc_sub(scc_scale(scc_add(cb.lo, cb.hi), 0.5), scc_scale(scc_add(sb.lo, sb.hi), 0.5)), scc_v3(0, 0, 1));
        }
        *out_grad = scc_scale(dir, s);
    }
    return s * lb;
}

/* Field 0 at p inside the (closed) domain box. */
static double eval_inside(const scc_grid* g, scc_vec3 p, scc_vec3* out_grad)
{
    const scc_grid_field* fd = &g->fields[0];
    uint32_t ijk[3];
    const uint64_t l = locate(g, p, ijk);
    const uint32_t c = fd->map[l];
    double v;
    if (c != SCC_GRID_NO_CELL && g->cell_lipschitz[c] >= 0.0f && interpolate_cell(g, fd, c, ijk, p, &v, out_grad)) return v;
    return eval_hole(g, l, ijk, p, out_grad);
}

double scc_grid_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* out_grad)
{
    const scc_grid* g = (const scc_grid*)self;
    if (!scc_vfinite(p)) {
        if (out_grad) *out_grad = scc_v3(0, 0, 1);
        return INFINITY;
    }
    const scc_aabb dom = { g->lo, g->hi };
    const scc_vec3 q = clamp_box(p, &dom);
    const scc_vec3 dq = scc_sub(p, q);
    const double d2 = scc_len2(dq);
    if (d2 == 0.0) return eval_inside(g, p, out_grad);
    if (!(d2 < INFINITY)) {
        /* astronomically far: the largest axis distance is a finite lower bound */
        const scc_vec3 ad = scc_vabs(dq);
        const int ax = ad.x >= ad.y && ad.x >= ad.z ? 0 : (ad.y >= ad.z ? 1 : 2);
        if (out_grad) *out_grad = scc_v3(ax == 0 ? (dq.x > 0 ? 1.0 : -1.0) : 0.0, ax == 1 ? (dq.y > 0 ? 1.0 : -1.0) : 0.0, ax == 2 ? (dq.z > 0 ? 1.0 : -1.0) : 0.0);
        return ax == 0 ? ad.x : (ax == 1 ? ad.y : ad.z);
    }

    /* Outside the domain: d = |p - q| to the nearest box point q, phi_q = phi(q).
     * phi_q >= 0: sqrt(d^2 + phi_q^2), a lower bound on the distance to a surface that lies
     *             inside the box (any path to it crosses the box at some b with
     *             |p - b| >= sqrt(d^2 + |q - b|^2) and phi(b) >= phi_q - |q - b|).
     * phi_q < 0:  when every boundary node is >= 0 (outside_positive: the surface lies inside,
     *             as for meshes in a fitted domain) this is an interpolation dip and phi_q is
     *             taken as 0; otherwise the box cuts the shape and phi_q - d, the 1-Lipschitz
     *             lower bound, keeps points beyond an inside boundary inside (discontinuous
     *             where the surface crosses the boundary).
     * The gradient is that of these expressions; the part of grad phi(q) along clamped axes
     * drops out. */
    const double d = sqrt(d2);
    scc_vec3 gq;
    double vq = eval_inside(g, q, out_grad ? &gq : NULL);
    if (g->outside_positive && vq < 0.0) vq = 0.0; /* interpolation dip on the boundary: the surface is inside */
    if (!out_grad) return vq >= 0.0 ? sqrt(d2 + vq * vq) : vq - d;
    if (p.x != q.x) gq.x = 0.0;
    if (p.y != q.y) gq.y = 0.0;
    if (p.z != q.z) gq.z = 0.0;
    if (vq >= 0.0) {
        const double v = sqrt(d2 + vq * vq);
        *out_grad = scc_scale(scc_madd(dq, gq, vq), 1.0 / v);
        return v;
    }
    *out_grad = scc_sub(gq, scc_scale(dq, 1.0 / d));
    return vq - d;
}

double scc_grid_lipschitz_in(const scc_sdf* self, const scc_aabb* box)
{
    const scc_grid* g = (const scc_grid*)self;
    const double global = fmax(g->lipschitz_max, g->hole_source ? 1.0 : 0.0);
    const double outside_global = sqrt(1.0 + global * global);
    if (!box || !scc_vfinite(box->lo) || !scc_vfinite(box->hi) || box->lo.x > box->hi.x || box->lo.y > box->hi.y || box->lo.z > box->hi.z)
        return outside_global;
    const int leaves = box->lo.x < g->lo.x || box->lo.y < g->lo.y || box->lo.z < g->lo.z ||
                       box->hi.x > g->hi.x || box->hi.y > g->hi.y || box->hi.z > g->hi.z;
    const scc_aabb dom = { g->lo, g->hi };
    uint32_t a[3], b[3];
    locate(g, clamp_box(box->lo, &dom), a);
    locate(g, clamp_box(box->hi, &dom), b);
    const uint64_t count = (uint64_t)(b[0] - a[0] + 1) * (b[1] - a[1] + 1) * (b[2] - a[2] + 1);
    double L = 0.0;
    if (count > 512 && g->block_lipschitz) {
        /* large boxes: the per-block maxima (4^3 cells) of the blocks the box touches */
        const uint32_t nbx = (g->res[0] + 3) / 4, nby = (g->res[1] + 3) / 4;
        for (uint32_t k = a[2] / 4; k <= b[2] / 4; ++k)
            for (uint32_t j = a[1] / 4; j <= b[1] / 4; ++j)
                for (uint32_t i = a[0] / 4; i <= b[0] / 4; ++i) {
                    const double bl = g->block_lipschitz[i + (uint64_t)nbx * (j + (uint64_t)nby * k)];
                    if (bl > L) L = bl;
                }
    } else if (count > 32768) L = global;
    else {
        const scc_grid_field* fd = &g->fields[0];
        for (uint32_t k = a[2]; k <= b[2]; ++k)
            for (uint32_t j = a[1]; j <= b[1]; ++j)
                for (uint32_t i = a[0]; i <= b[0]; ++i) {
                    const uint64_t l = i + (uint64_t)g->res[0] * (j + (uint64_t)g->res[1] * k);
                    const uint32_t c = fd->map[l];
                    const double cl = (c == SCC_GRID_NO_CELL || g->cell_lipschitz[c] < 0.0f) ? 1.0 : (double)g->cell_lipschitz[c];
                    if (cl > L) L = cl;
                }
    }
    return leaves ? sqrt(1.0 + L * L) : L;
}

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

typedef struct bern_tables { double val[64][32]; } bern_tables;

/* val[s][a]: the Bernstein coefficient s = i + 4j + 16k (degree 3 per axis on [-1,1]^3) of
 * shape function a. Built by sampling at the tensor points {-1,-1/3,1/3,1}^3 and converting the
 * samples per axis. */
static void bern_tables_init(bern_tables* t)
{
    static const double pts[4] = { -1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0 };
    /* Values at the 4 points above -> cubic Bernstein coefficients on [-1,1] (the inverse of
     * the Bernstein basis sampled at those points). */
    static const double conv[4][4] = {
        { 1.0, 0.0, 0.0, 0.0 },
        { -5.0 / 6.0, 3.0, -1.5, 1.0 / 3.0 },
        { 1.0 / 3.0, -1.5, 3.0, -5.0 / 6.0 },
        { 0.0, 0.0, 0.0, 1.0 },
    };
    double N[32];
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                scc_cell_shape(scc_v3(pts[i], pts[j], pts[k]), N, NULL);
                for (int a = 0; a < 32; ++a) t->val[i + 4 * j + 16 * k][a] = N[a];
            }
    for (int a = 0; a < 32; ++a) {
        double f[64], g[64];
        for (int s = 0; s < 64; ++s) f[s] = t->val[s][a];
        for (int axis = 0; axis < 3; ++axis) {
            const int stride = axis == 0 ? 1 : (axis == 1 ? 4 : 16);
            for (int s = 0; s < 64; ++s) {
                const int idx = (s / stride) % 4;
                const int base = s - idx * stride;
                double acc = 0.0;
                for (int m = 0; m < 4; ++m) acc += conv[idx][m] * f[base + m * stride];
                g[s] = acc;
            }
            memcpy(f, g, sizeof f);
        }
        for (int s = 0; s < 64; ++s) t->val[s][a] = f[s];
    }
}

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
        if (c == SCC_GRID_NO_CELL) continue;
        double v[32];
        uint32_t ijk[3];
        cell_ijk(g, l, ijk);
        gather_cell(g, fd, c, ijk, v);
        int hole = 0;
        for (int a = 0; a < 32; ++a) hole |= v[a] == SCC_GRID_NO_VALUE;
        if (hole) { g->cell_lipschitz[c] = -1.0f; continue; }
        /* Bernstein coefficients of phi on the cell (degree 3 per axis), then those of each
         * partial derivative by differences: d/dxi of a cubic Bernstein form on [-1,1] has the
         * degree-2 coefficients 1.5 (b[i+1] - b[i]) along that axis. */
        double b[64];
        for (int s = 0; s < 64; ++s) {
            const double* row = ctx->bt->val[s];
            double acc = 0.0;
            for (int k = 0; k < 32; ++k) acc += row[k] * v[k];
            b[s] = acc;
        }
        double sum2 = 0.0;
        for (int d = 0; d < 3; ++d) {
            const int stride = d == 0 ? 1 : (d == 1 ? 4 : 16);
            double bmax = 0.0;
            for (int s = 0; s < 64; ++s) {
                if ((s / stride) % 4 != 0) continue;
                /* degree-2 coefficients along d, elevated back to degree 3 (convex combinations,
                 * so the enclosure only gets tighter) */
                const double e0 = 1.5 * (b[s + stride] - b[s]), e1 = 1.5 * (b[s + 2 * stride] - b[s + stride]),
                             e2 = 1.5 * (b[s + 3 * stride] - b[s + 2 * stride]);
                const double q[4] = { e0, (e0 + 2.0 * e1) / 3.0, (2.0 * e1 + e2) / 3.0, e2 };
                for (int m = 0; m < 4; ++m)
                    if (fabs(q[m]) > bmax) bmax = fabs(q[m]);
            }
            sum2 += (c0[d] * bmax) * (c0[d] * bmax);
        }
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

scc_grid_status scc_grid_finalize(scc_grid* g, double band, scc_parallel_for_fn* parallel_for, void* parallel_user)
{
    const scc_allocator* a = &g->allocator;
    scc_grid_field* fd = &g->fields[0];
    if (g->n_cells > 0x7FFFFFFEu) return SCC_GRID_TOO_LARGE;
    g->band = band > 0.0 && isfinite(band) ? band : 0.0;

    /* Dense Discregrid layout of field 0 (identity map, tables equal to the formulas)? Then the
     * node ids are implied, the 128-byte-per-cell table is dropped, and the values move to the
     * vertex-block layout (the builder writes them there directly). */
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

    /* Per-cell gradient bounds. */
    g->cell_lipschitz = scc_alloc(a, (size_t)fd->cell_count * sizeof(float));
    bern_tables* bt = scc_alloc(a, sizeof *bt);
    if ((fd->cell_count && !g->cell_lipschitz) || !bt) { scc_free(a, bt, sizeof *bt); return SCC_GRID_OUT_OF_MEMORY; }
    bern_tables_init(bt);
    finalize_ctx ctx = { g, bt, 2048 };
    const uint32_t tasks = (uint32_t)((g->n_cells + ctx.chunk - 1) / ctx.chunk);
    const int cancelled = run_tasks(parallel_for, parallel_user, SCC_GRID_STAGE_CELLS, tasks, cell_bound_task, &ctx);
    if (cancelled) { scc_free(a, bt, sizeof *bt); return SCC_GRID_CANCELLED; }

    g->lipschitz_max = 0.0;
    g->valued_cells = 0;
    for (uint64_t l = 0; l < g->n_cells; ++l) {
        const uint32_t c = fd->map[l];
        if (c == SCC_GRID_NO_CELL || g->cell_lipschitz[c] < 0.0f) continue;
        g->valued_cells++;
        if (g->cell_lipschitz[c] > g->lipschitz_max) g->lipschitz_max = g->cell_lipschitz[c];
    }
    if (g->valued_cells == 0) { scc_free(a, bt, sizeof *bt); return SCC_GRID_EMPTY; }


    /* Hole sources: multi-source breadth-first search over the 26-neighbourhood from every
     * cell with values, so each hole cell learns a valued cell at the least Chebyshev
     * distance; then the side (sign) from that cell's value at the point nearest the hole's
     * centre. */
    if (g->valued_cells < g->n_cells) {
        g->hole_source = scc_alloc(a, (size_t)g->n_cells * sizeof(uint32_t));
        uint32_t* queue = scc_alloc(a, (size_t)g->n_cells * sizeof(uint32_t));
        if (!g->hole_source || !queue) {
            scc_free(a, queue, (size_t)g->n_cells * sizeof(uint32_t));
            scc_free(a, bt, sizeof *bt);
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
    }

    /* The scc_sdf interface. bounds must contain every point with phi <= 0: the domain when
     * phi >= 0 on the whole domain boundary (then the outside continuation is positive), else
     * unbounded (phi_q - d continues the inside). Non-negativity of each boundary face is
     * proved with the face's Bernstein coefficients (the face restriction of the cell's
     * tensor Bernstein form), which enclose the interpolant on the face. */
    /* Per-block maxima of the cell bounds (blocks of 4^3 cells; cells without values count 1)
     * for the Lipschitz bound of large boxes. */
    {
        const uint32_t nbx = (g->res[0] + 3) / 4, nby = (g->res[1] + 3) / 4, nbz = (g->res[2] + 3) / 4;
        g->block_lipschitz = scc_alloc(a, (size_t)nbx * nby * nbz * sizeof(float));
        if (!g->block_lipschitz) { scc_free(a, bt, sizeof *bt); return SCC_GRID_OUT_OF_MEMORY; }
        for (size_t q = 0; q < (size_t)nbx * nby * nbz; ++q) g->block_lipschitz[q] = 0.0f;
        for (uint64_t l = 0; l < g->n_cells; ++l) {
            uint32_t ijk[3];
            cell_ijk(g, l, ijk);
            const uint32_t c = fd->map[l];
            const float cl = (c == SCC_GRID_NO_CELL || g->cell_lipschitz[c] < 0.0f) ? 1.0f : g->cell_lipschitz[c];
            float* bl = &g->block_lipschitz[ijk[0] / 4 + (uint64_t)nbx * (ijk[1] / 4 + (uint64_t)nby * (ijk[2] / 4))];
            if (cl > *bl) *bl = cl;
        }
    }

    /* outside_positive: every node on the domain boundary is >= 0 (and no inside hole touches
     * it), i.e. the sampled surface lies inside the box. */
    g->outside_positive = 1;
    for (uint64_t l = 0; l < g->n_cells && g->outside_positive; ++l) {
        uint32_t ijk[3];
        int lo_face[3], hi_face[3];
        if (!boundary_cell(g, l, ijk, lo_face, hi_face)) continue;
        const uint32_t c = fd->map[l];
        if (c == SCC_GRID_NO_CELL || g->cell_lipschitz[c] < 0.0f) {
            if (g->hole_source[l] & 0x80000000u) g->outside_positive = 0;
            continue;
        }
        double v[32];
        gather_cell(g, fd, c, ijk, v);
        for (int slot = 0; slot < 32; ++slot)
            for (int d = 0; d < 3; ++d)
                if ((lo_face[d] && k_sigma[slot][d] == -1.0) || (hi_face[d] && k_sigma[slot][d] == 1.0))
                    if (v[slot] < 0.0) g->outside_positive = 0;
    }
    /* Otherwise try to prove phi >= 0 on the boundary from the faces' Bernstein coefficients. */
    int boundary_nonneg = 1;
    for (uint64_t l = 0; l < g->n_cells && boundary_nonneg && !g->outside_positive; ++l) {
        uint32_t ijk[3];
        int lo_face[3], hi_face[3];
        if (!boundary_cell(g, l, ijk, lo_face, hi_face)) continue;
        const uint32_t c = fd->map[l];
        if (c == SCC_GRID_NO_CELL || g->cell_lipschitz[c] < 0.0f) {
            if (g->hole_source[l] & 0x80000000u) boundary_nonneg = 0;
            continue;
        }
        double v[32];
        gather_cell(g, fd, c, ijk, v);
        for (int s = 0; s < 64 && boundary_nonneg; ++s) {
            const int idx[3] = { s % 4, (s / 4) % 4, s / 16 };
            int on_face = 0;
            for (int d = 0; d < 3; ++d) on_face |= (lo_face[d] && idx[d] == 0) || (hi_face[d] && idx[d] == 3);
            if (!on_face) continue;
            double acc = 0.0;
            for (int k = 0; k < 32; ++k) acc += bt->val[s][k] * v[k];
            if (acc < 0.0) boundary_nonneg = 0;
        }
    }
    scc_free(a, bt, sizeof *bt);
    g->base.eval = scc_grid_eval;
    g->base.lipschitz_in = scc_grid_lipschitz_in;
    g->base.domain.lo = g->lo;
    g->base.domain.hi = g->hi;
    if (boundary_nonneg || g->outside_positive) {
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
    return SCC_GRID_OK;
}

scc_aabb scc_grid_fit_domain(scc_aabb box)
{
    scc_vec3 d = scc_sub(box.hi, box.lo);
    double e = 1.0e-3 * sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    box.hi = scc_add(box.hi, scc_v3(e, e, e));
    d = scc_sub(box.hi, box.lo);
    e = 1.0e-3 * sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    box.lo = scc_sub(box.lo, scc_v3(e, e, e));
    return box;
}
