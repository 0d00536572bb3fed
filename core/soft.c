/* SPDX-License-Identifier: MIT
 * sdfccd core: per-vertex linear motion (the paper's deformable case, Section 4, with each vertex
 * moving linearly over the step, as for the cloth of Section 5 / Fig. 9). A node's path is checked
 * by conservative advancement on the L-Lipschitz SDF (the bound of Section 3: a step of
 * (phi - level) / L cannot jump over the level). Distance certificates (ours) keep a lower bound of
 * phi from step to step, so a node or face that stays far from the surface costs no evaluation. */
#include "soft.h"

#include <math.h>

static double max2(double a, double b) { return a < b ? b : a; }

double scc_cert_bound(const scc_cert* cert, const scc_vec3* x0, const scc_vec3* x1, int n, double L)
{
    double d = 0;
    for (int k = 0; k < n; ++k) d = max2(d, max2(scc_dist(x0[k], cert->anchor[k]), scc_dist(x1[k], cert->anchor[k])));
    return cert->bound - L * d;
}

int scc_point_first_hit(const scc_sdf* sdf, scc_vec3 a, scc_vec3 b, double level, double L, double* out_f, double* out_phi,
                        scc_vec3* out_grad, double* out_phi_a, int64_t* io_evals)
{
    if (out_phi_a) *out_phi_a = -HUGE_VAL;
    const scc_vec3 d = scc_sub(b, a);
    const double length = scc_len(d);
    double t = 0;
    for (int it = 0; it < 200; ++it) {
        scc_vec3 g;
        const double phi = scc_sdf_eval(sdf, scc_add(a, scc_scale(d, t)), &g);
        ++*io_evals;
        if (it == 0 && out_phi_a) *out_phi_a = phi;
        const double gap = phi - level;
        if (gap <= 1e-6 || it == 199) {
            *out_f = t;
            *out_phi = phi;
            *out_grad = g;
            return 1;
        }
        if (length * L * (1 - t) < gap) return 0; /* the rest of the path cannot reach the level */
        t += gap / (L * length);
        if (t > 1) return 0;
    }
    return 0;
}

int scc_triangle_lower_bound(const scc_sdf* sdf, scc_vec3 p0, scc_vec3 p1, scc_vec3 p2, double need, double L, int depth,
                             double* out_bound, int64_t* io_evals)
{
    const scc_vec3 c = scc_scale(scc_add(scc_add(p0, p1), p2), 1.0 / 3);
    const double r = max2(scc_dist(p0, c), max2(scc_dist(p1, c), scc_dist(p2, c)));
    const double phi = scc_sdf_eval(sdf, c, NULL);
    ++*io_evals;
    if (phi - L * r >= need) {
        *out_bound = phi - L * r;
        return 1;
    }
    if (depth == 0 || phi < need) return 0; /* the centroid itself is below: no split helps */
    const scc_vec3 m01 = scc_scale(scc_add(p0, p1), 0.5), m12 = scc_scale(scc_add(p1, p2), 0.5), m20 = scc_scale(scc_add(p2, p0), 0.5);
    const scc_vec3 kids[4][3] = { { p0, m01, m20 }, { m01, p1, m12 }, { m20, m12, p2 }, { m01, m12, m20 } };
    double bound = HUGE_VAL;
    for (int k = 0; k < 4; ++k) {
        double b;
        if (!scc_triangle_lower_bound(sdf, kids[k][0], kids[k][1], kids[k][2], need, L, depth - 1, &b, io_evals)) return 0;
        bound = b < bound ? b : bound;
    }
    *out_bound = bound;
    return 1;
}

int scc_guard_point(const scc_sdf* sdf, const scc_cert* cert, scc_vec3 s, scc_vec3 e, double tol, double L, int* out_clear,
                    double* out_level, double* out_f, scc_vec3* out_grad, int64_t* io_evals)
{
    *out_level = -tol;
    *out_clear = scc_cert_bound(cert, &s, &e, 1, L) >= -tol;
    if (*out_clear) return 0;
    const double phi_s = scc_sdf_eval(sdf, s, NULL);
    ++*io_evals;
    if (phi_s < -tol) *out_level = phi_s - 0.1 * tol; /* no deeper than it started */
    double f, phi, fh, phih;
    scc_vec3 g, gh;
    if (!scc_point_first_hit(sdf, s, e, *out_level, L, &f, &phi, &g, NULL, io_evals)) return 0;
    if (scc_point_first_hit(sdf, s, e, *out_level + 0.5 * tol, L, &fh, &phih, &gh, NULL, io_evals) && fh < f) f = fh;
    *out_f = f;
    *out_grad = g;
    return 1;
}

int scc_segment_first_hit(const scc_sdf* sdf, scc_vec3 s0, scc_vec3 s1, scc_vec3 e0, scc_vec3 e1, double level, double spacing, double L,
                          double* out_f, scc_vec3* out_grad, int64_t* io_evals)
{
    const double longest = max2(scc_dist(s1, s0), scc_dist(e1, e0));
    const int n = 1 + (int)ceil(longest / spacing);
    double first = 2;
    for (int k = 1; k < n; ++k) {
        const double w = (double)k / n, h = longest / n;
        double f, phi;
        scc_vec3 g;
        if (scc_point_first_hit(sdf, scc_add(scc_scale(s0, 1 - w), scc_scale(s1, w)), scc_add(scc_scale(e0, 1 - w), scc_scale(e1, w)),
                                level + 0.5 * L * h, L, &f, &phi, &g, NULL, io_evals) &&
            f < first) {
            first = f;
            *out_grad = g;
        }
    }
    if (first > 1) return 0;
    *out_f = first;
    return 1;
}

int scc_face_clear(const scc_sdf* sdf, scc_cert* cert, const scc_vec3 s[3], const scc_vec3 e[3], double need, double L,
                   int64_t* io_evals)
{
    if (scc_cert_bound(cert, s, e, 3, L) >= need) return 1;
    double move = 0;
    for (int k = 0; k < 3; ++k) move = max2(move, scc_dist(e[k], s[k]));
    double b;
    if (!scc_triangle_lower_bound(sdf, s[0], s[1], s[2], need + L * move, L, 3, &b, io_evals)) return 0;
    for (int k = 0; k < 3; ++k) cert->anchor[k] = s[k];
    cert->bound = b;
    return 1;
}
