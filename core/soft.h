/* SPDX-License-Identifier: MIT
 * sdfccd core: per-vertex linear motion against an SDF (soft.c): a point's path to a level, and
 * distance certificates that let nodes and faces far from the surface skip the CCD. */
#ifndef SCC_SOFT_H
#define SCC_SOFT_H

#include <stdint.h>

#include "scc_math.h"
#include "sdf.h"

/* A lower bound of phi near anchors: corners within d of anchor[] (a point: anchor[0]) have
 * phi >= bound - L d for an L-Lipschitz field. bound = -INFINITY certifies nothing. */
typedef struct scc_cert {
    scc_vec3 anchor[3];
    double bound;
} scc_cert;

/* The certificate's bound over n (1..3) corners moving linearly from x0[] to x1[]: a corner's
 * distance to its anchor is largest at an end of its path. */
double scc_cert_bound(const scc_cert* cert, const scc_vec3* x0, const scc_vec3* x1, int n, double L);

/* The first fraction f in [0, 1] of the segment a -> b where phi <= level + 1e-6, by conservative
 * advancement. Returns 1 with *out_f, *out_phi and *out_grad there, 0 when the segment stays above.
 * *out_phi_a (may be NULL) gets phi(a). After 200 steps the point reached counts as the hit (early,
 * never late). Adds the SDF evaluations to *io_evals. */
int scc_point_first_hit(const scc_sdf* sdf, scc_vec3 a, scc_vec3 b, double level, double L, double* out_f, double* out_phi,
                        scc_vec3* out_grad, double* out_phi_a, int64_t* io_evals);

/* A lower bound of phi over the triangle p0 p1 p2 that is >= need: phi at the centroid minus L times
 * the farthest corner, split into four at the edge midpoints up to `depth` times where that is below
 * need. Returns 0 when some piece stays below need, else 1 with the bound in *out_bound. */
int scc_triangle_lower_bound(const scc_sdf* sdf, scc_vec3 p0, scc_vec3 p1, scc_vec3 p2, double need, double L, int depth,
                             double* out_bound, int64_t* io_evals);

/* Is the triangle moving linearly from s[] to e[] certified above need? First by *cert, else by a
 * new bound at s[] (scc_triangle_lower_bound, depth 3, need raised by L times the largest corner
 * motion), which then replaces *cert. Returns 1 when certified, 0 otherwise (*cert unchanged). */
/* The first fraction where points of a segment moving linearly (s0 s1 -> e0 e1) reach `level`:
 * n - 1 inner points every h <= spacing along it (n = 1 + ceil(longest length / spacing)), each path
 * held to level + L h / 2, so no point between two of them goes below level earlier. Returns 1 with
 * *out_f and *out_grad (phi's gradient there), 0 when none reaches it. */
int scc_segment_first_hit(const scc_sdf* sdf, scc_vec3 s0, scc_vec3 s1, scc_vec3 e0, scc_vec3 e1, double level, double spacing, double L,
                          double* out_f, scc_vec3* out_grad, int64_t* io_evals);

int scc_face_clear(const scc_sdf* sdf, scc_cert* cert, const scc_vec3 s[3], const scc_vec3 e[3], double need, double L,
                   int64_t* io_evals);

/* The guard of one node moving linearly from s to e (L-Lipschitz phi): its path may not go below
 * level = -tol, or, when it starts deeper than tol, below its start depth minus 0.1 tol. Returns 1
 * when the path crosses its level, with *out_f the first reach of level + tol / 2 when that comes
 * earlier than the first reach of the level (so the next step does not start at the level), else
 * of the level, and *out_grad phi's gradient at the first reach of the level. *out_clear = 1 when
 * *cert alone keeps the path above -tol (no evaluation; *out_level = -tol). */
int scc_guard_point(const scc_sdf* sdf, const scc_cert* cert, scc_vec3 s, scc_vec3 e, double tol, double L, int* out_clear,
                    double* out_level, double* out_f, scc_vec3* out_grad, int64_t* io_evals);

#endif
