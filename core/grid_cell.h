/* SPDX-License-Identifier: MIT
 * sdfccd core: the grid's element, the 32-node cubic Lagrange (serendipity) cell (slot numbering
 * in grid_cell.c; shared notes sdf-format-and-assets.md section 3). Local coordinates xi are in
 * [-1,1]^3. Pure functions.
 */
#ifndef SCC_GRID_CELL_H
#define SCC_GRID_CELL_H

#include "scc_math.h"

/* Local coordinates (in [-1,1]^3) of the node in slot `slot` (0..31). */
scc_vec3 scc_cell_node_local(int slot);
/* Shape functions N[32] at local point xi; when dN is not NULL also dN/dxi (dN[a][d]). */
void scc_cell_shape(scc_vec3 xi, double N[32], double dN[32][3]);
/* sum_a v[a] N_a(xi) and, when out_grad is not NULL, its derivatives with respect to xi, in a
 * factored form (about 4x fewer operations than going through scc_cell_shape). */
void scc_cell_eval(const double v[32], scc_vec3 xi, double* out_value, double out_grad[3]);

/* The tensor cubic Bernstein form of the shape functions on [-1,1]^3: out[s][a] is coefficient
 * s = i + 4j + 16k (i, j, k in 0..3 along x, y, z) of shape function a, so the interpolant of node
 * values v has the Bernstein coefficients b[s] = sum_a out[s][a] v[a]. */
void scc_cell_bernstein(double out[64][32]);
/* Values of a cubic at {-1,-1/3,1/3,1} -> its Bernstein coefficients on [-1,1] (row = coefficient). */
extern const double scc_cell_to_bernstein[4][4];

/* ---- the factored kernel, inline for the grid's evaluation (scc_cell_eval calls it) ----
 * The two nodes of a cell edge are a pair (t = 0, 1: at -1/3 and +1/3 along it) that every
 * step of an edge family treats alike, so they go through two-lane vectors where the compiler
 * has them (GCC and Clang vector extensions; plain C otherwise). Each lane does the scalar
 * formula's operations in the scalar formula's order, so both builds give the same bits. */

#if (defined(__GNUC__) || defined(__clang__)) && !defined(SCC_CELL_PLAIN_C) /* SCC_CELL_PLAIN_C: test the fallback */
#define SCC_CELL_INLINE static inline __attribute__((always_inline))
typedef double scc_d2 __attribute__((vector_size(16)));
static inline scc_d2 scc_d2_load(const double* p) { scc_d2 r; __builtin_memcpy(&r, p, sizeof r); return r; }
static inline scc_d2 scc_d2_add(scc_d2 a, scc_d2 b) { return a + b; }
static inline scc_d2 scc_d2_sub(scc_d2 a, scc_d2 b) { return a - b; }
static inline scc_d2 scc_d2_mul(scc_d2 a, scc_d2 b) { return a * b; }
static inline scc_d2 scc_d2_muls(scc_d2 a, double s) { return a * s; }
static inline scc_d2 scc_d2_pair(double a, double b) { scc_d2 r = { a, b }; return r; }
static inline double scc_d2_lane(scc_d2 a, int i) { return a[i]; }
#else
#define SCC_CELL_INLINE static inline
typedef struct { double v[2]; } scc_d2;
static inline scc_d2 scc_d2_load(const double* p) { scc_d2 r = { { p[0], p[1] } }; return r; }
static inline scc_d2 scc_d2_add(scc_d2 a, scc_d2 b) { scc_d2 r = { { a.v[0] + b.v[0], a.v[1] + b.v[1] } }; return r; }
static inline scc_d2 scc_d2_sub(scc_d2 a, scc_d2 b) { scc_d2 r = { { a.v[0] - b.v[0], a.v[1] - b.v[1] } }; return r; }
static inline scc_d2 scc_d2_mul(scc_d2 a, scc_d2 b) { scc_d2 r = { { a.v[0] * b.v[0], a.v[1] * b.v[1] } }; return r; }
static inline scc_d2 scc_d2_muls(scc_d2 a, double s) { scc_d2 r = { { a.v[0] * s, a.v[1] * s } }; return r; }
static inline scc_d2 scc_d2_pair(double a, double b) { scc_d2 r = { { a, b } }; return r; }
static inline double scc_d2_lane(scc_d2 a, int i) { return a.v[i]; }
#endif

/* One edge family of the factored element: e[2 dp + dr] points at the pair of edge-node values
 * (t = 0, 1) of the edge at (dp, dr) on the outer and inner axes p, r; Lp, Lr their linear
 * factors. Adds the family's value to *phi and its derivatives to g[d], g[p], g[r]. */
SCC_CELL_INLINE void scc_cell_edge_family(const double* const e[4], double xd, const double Lp[2], const double Lr[2], double* phi, double* g, int d,
                                        int p, int r)
{
    const double w = 1.0 - xd * xd;
    const double m0 = 1.0 - 3.0 * xd, m1 = 1.0 + 3.0 * xd;
    const double l00 = Lp[0] * Lr[0], l01 = Lp[0] * Lr[1], l10 = Lp[1] * Lr[0], l11 = Lp[1] * Lr[1];
    const scc_d2 e00 = scc_d2_load(e[0]), e01 = scc_d2_load(e[1]), e10 = scc_d2_load(e[2]), e11 = scc_d2_load(e[3]);
    /* B_t = e00_t l00 + e01_t l01 + e10_t l10 + e11_t l11, both t at once */
    const scc_d2 B = scc_d2_add(scc_d2_add(scc_d2_add(scc_d2_muls(e00, l00), scc_d2_muls(e01, l01)), scc_d2_muls(e10, l10)), scc_d2_muls(e11, l11));
    const scc_d2 M = scc_d2_pair(m0, m1);
    const scc_d2 mB = scc_d2_mul(M, B);
    const double B0 = scc_d2_lane(B, 0), B1 = scc_d2_lane(B, 1);
    const double m = scc_d2_lane(mB, 0) + scc_d2_lane(mB, 1);
    *phi += (9.0 / 64.0) * w * m;
    if (g) {
        /* d/dx_p of Lp[dp] is -1, +1; d/dx_r of Lr[dr] likewise */
        const scc_d2 Bp = scc_d2_add(scc_d2_muls(scc_d2_sub(e10, e00), Lr[0]), scc_d2_muls(scc_d2_sub(e11, e01), Lr[1]));
        const scc_d2 Br = scc_d2_add(scc_d2_muls(scc_d2_sub(e01, e00), Lp[0]), scc_d2_muls(scc_d2_sub(e11, e10), Lp[1]));
        const scc_d2 mBp = scc_d2_mul(M, Bp), mBr = scc_d2_mul(M, Br);
        g[d] += (9.0 / 64.0) * (-2.0 * xd * m + w * 3.0 * (B1 - B0));
        g[p] += (9.0 / 64.0) * w * (scc_d2_lane(mBp, 0) + scc_d2_lane(mBp, 1));
        g[r] += (9.0 / 64.0) * w * (scc_d2_lane(mBr, 0) + scc_d2_lane(mBr, 1));
    }
}

/* The cell's interpolant and its xi-derivatives from its values: c[q] points at corner q's value
 * (slot q), ex/ey/ez[2 dp + dr] at the pair of edge nodes of each family (x: outer y, inner z;
 * y: outer z, inner x; z: outer x, inner y), wherever the storage keeps them. */
SCC_CELL_INLINE void scc_cell_eval_at(const double* const c[8], const double* const ex[4], const double* const ey[4], const double* const ez[4],
                                    scc_vec3 xi, double* out_value, double out_grad[3])
{
    /* The same interpolant as sum_a v[a] N_a, factored: the corner part is
     * (9 r^2 - 19)/64 times the trilinear form S of the corner values, and each edge family is
     * (9/64)(1 - x_d^2) times a cubic factor in x_d times a bilinear form in the other two. */
    const double x[3] = { xi.x, xi.y, xi.z };
    double L[3][2];
    for (int d = 0; d < 3; ++d) { L[d][0] = 1.0 - x[d]; L[d][1] = 1.0 + x[d]; }
    /* trilinear form of the corner values (slot di + 2 dj + 4 dk) and its derivatives, the
     * corners paired along y: lanes (dj = 0, dj = 1) */
    const scc_d2 v02 = scc_d2_pair(*c[0], *c[2]), v13 = scc_d2_pair(*c[1], *c[3]);
    const scc_d2 v46 = scc_d2_pair(*c[4], *c[6]), v57 = scc_d2_pair(*c[5], *c[7]);
    /* (a00, a10) and (a01, a11): a_jk = v(0,j,k) (1 - x) + v(1,j,k) (1 + x) */
    const scc_d2 A0 = scc_d2_add(scc_d2_muls(v02, L[0][0]), scc_d2_muls(v13, L[0][1]));
    const scc_d2 A1 = scc_d2_add(scc_d2_muls(v46, L[0][0]), scc_d2_muls(v57, L[0][1]));
    const double a00 = scc_d2_lane(A0, 0), a10 = scc_d2_lane(A0, 1), a01 = scc_d2_lane(A1, 0), a11 = scc_d2_lane(A1, 1);
    const scc_d2 Yz0 = scc_d2_muls(scc_d2_pair(L[1][0], L[1][1]), L[2][0]), Yz1 = scc_d2_muls(scc_d2_pair(L[1][0], L[1][1]), L[2][1]);
    const scc_d2 P0 = scc_d2_mul(A0, Yz0), P1 = scc_d2_mul(A1, Yz1);
    const double S = scc_d2_lane(P0, 0) + scc_d2_lane(P0, 1) + scc_d2_lane(P1, 0) + scc_d2_lane(P1, 1);
    double Sx = 0.0, Sy = 0.0, Sz = 0.0;
    if (out_grad) {
        const scc_d2 Q0 = scc_d2_mul(scc_d2_sub(v13, v02), Yz0), Q1 = scc_d2_mul(scc_d2_sub(v57, v46), Yz1);
        Sx = scc_d2_lane(Q0, 0) + scc_d2_lane(Q0, 1) + scc_d2_lane(Q1, 0) + scc_d2_lane(Q1, 1);
        Sy = (a10 - a00) * L[2][0] + (a11 - a01) * L[2][1];
        const scc_d2 Z = scc_d2_mul(scc_d2_sub(A1, A0), scc_d2_pair(L[1][0], L[1][1]));
        Sz = scc_d2_lane(Z, 0) + scc_d2_lane(Z, 1);
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
    scc_cell_edge_family(ex, x[0], L[1], L[2], &phi, out_grad ? g : NULL, 0, 1, 2);
    scc_cell_edge_family(ey, x[1], L[2], L[0], &phi, out_grad ? g : NULL, 1, 2, 0);
    scc_cell_edge_family(ez, x[2], L[0], L[1], &phi, out_grad ? g : NULL, 2, 0, 1);
    *out_value = phi;
    if (out_grad) { out_grad[0] = g[0]; out_grad[1] = g[1]; out_grad[2] = g[2]; }
}

/* The same for the 32 values in slot order. */
static inline void scc_cell_eval_inline(const double v[32], scc_vec3 xi, double* out_value, double out_grad[3])
{
    const double* const c[8] = { v, v + 1, v + 2, v + 3, v + 4, v + 5, v + 6, v + 7 };
    const double* const ex[4] = { v + 8, v + 10, v + 12, v + 14 };
    const double* const ey[4] = { v + 16, v + 18, v + 20, v + 22 };
    const double* const ez[4] = { v + 24, v + 26, v + 28, v + 30 };
    scc_cell_eval_at(c, ex, ey, ez, xi, out_value, out_grad);
}

#endif
