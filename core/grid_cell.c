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

void scc_cell_eval(const double v[32], scc_vec3 xi, double* out_value, double out_grad[3])
{
    scc_cell_eval_inline(v, xi, out_value, out_grad);
}

/* Values at the 4 points above -> cubic Bernstein coefficients on [-1,1] (the inverse of the
 * Bernstein basis sampled at those points). */
const double scc_cell_to_bernstein[4][4] = {
    { 1.0, 0.0, 0.0, 0.0 },
    { -5.0 / 6.0, 3.0, -1.5, 1.0 / 3.0 },
    { 1.0 / 3.0, -1.5, 3.0, -5.0 / 6.0 },
    { 0.0, 0.0, 0.0, 1.0 },
};

/* out[s][a]: the Bernstein coefficient s = i + 4j + 16k (degree 3 per axis on [-1,1]^3) of
 * shape function a. Built by sampling at the tensor points {-1,-1/3,1/3,1}^3 and converting the
 * samples per axis. */
void scc_cell_bernstein(double out[64][32])
{
    static const double pts[4] = { -1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0 };
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
                for (int m = 0; m < 4; ++m) acc += scc_cell_to_bernstein[idx][m] * f[base + m * stride];
                g[s] = acc;
            }
            memcpy(f, g, sizeof f);
        }
        for (int s = 0; s < 64; ++s) out[s][a] = f[s];
    }
}
