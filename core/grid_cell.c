/* SPDX-License-Identifier: MIT
 * sdfccd core: the grid's element, the 32-node cubic Lagrange (serendipity) cell of Discregrid
 * (Koschier et al., "An hp-adaptive discretization algorithm for signed distance field
 * generation", 2017) as Discregrid's CubicLagrangeDiscreteGrid and Bullet's btMiniSDF use it:
 * node positions, shape functions, the factored evaluation, and the tensor Bernstein form of the
 * shape functions that the grid's gradient bounds (grid_bounds.c) are built on. Written from the
 * description in the shared notes (sdf-format-and-assets.md section 3), not from either codebase.
 */
#include "grid_cell.h"

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

/* out[s][a]: the Bernstein coefficient s = i + 4j + 16k (degree 3 per axis on [-1,1]^3) of
 * shape function a. Built by sampling at the tensor points {-1,-1/3,1/3,1}^3 and converting the
 * samples per axis. */
void scc_cell_bernstein(double out[64][32])
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
                for (int a = 0; a < 32; ++a) out[i + 4 * j + 16 * k][a] = N[a];
            }
    for (int a = 0; a < 32; ++a) {
        double f[64], g[64];
        for (int s = 0; s < 64; ++s) f[s] = out[s][a];
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
        for (int s = 0; s < 64; ++s) out[s][a] = f[s];
    }
}
