/* SPDX-License-Identifier: MIT
 * Per-vertex linear motion (contact.h, issue 21; core/soft.c): a point's path to a level against
 * closed-form times of impact on a half-space and a sphere, distance certificates for faces checked
 * against a brute-force minimum of phi over the face, faces whose interior crosses the surface
 * while their corners stay far, and bad input. Public ABI only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

static sdfccd_Vec3 v3(double x, double y, double z) { return (sdfccd_Vec3){ x, y, z }; }

static sdfccd_SdfId sphere(double r)
{
    sdfccd_SdfId s;
    ck_assert_msg(sdfccd_create_sphere(r, &s) == SDFCCD_OK, "%s", sdfccd_last_error());
    return s;
}

/* Brute-force minimum of phi over the triangle moving linearly from s[] to e[] (a grid of
 * barycentric points at a grid of times): the independent reference for a certified bound. */
static double min_phi_swept(sdfccd_SdfId sdf, const sdfccd_Vec3 s[3], const sdfccd_Vec3 e[3])
{
    double m = HUGE_VAL;
    const int n = 60, nt = 20;
    for (int it = 0; it <= nt; ++it) {
        const double t = (double)it / nt;
        sdfccd_Vec3 c[3];
        for (int k = 0; k < 3; ++k)
            c[k] = v3(s[k].x + (e[k].x - s[k].x) * t, s[k].y + (e[k].y - s[k].y) * t, s[k].z + (e[k].z - s[k].z) * t);
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) {
                const double u = (double)i / n, v = (double)j / n, w = 1 - u - v;
                const sdfccd_Vec3 p = v3(u * c[0].x + v * c[1].x + w * c[2].x, u * c[0].y + v * c[1].y + w * c[2].y,
                                         u * c[0].z + v * c[1].z + w * c[2].z);
                double phi;
                ck_assert(sdfccd_sdf_eval(sdf, p, &phi, NULL) == SDFCCD_OK);
                if (phi < m) m = phi;
            }
    }
    return m;
}

/* A point falling straight onto a half-space z >= 0: the level is reached where z = level, at
 * fraction (z0 - level) / (z0 - z1), in one step (phi is exactly linear along the path). */
START_TEST(test_point_half_space_closed_form)
{
    sdfccd_SdfId plane;
    ck_assert(sdfccd_create_half_space(v3(0, 0, 1), 0, &plane) == SDFCCD_OK);
    const double z0 = 2.0, z1 = -1.0, level = 0.25;
    sdfccd_PointHit h;
    int64_t evals = 0;
    ck_assert_msg(sdfccd_point_first_hit(plane, v3(0.3, -0.2, z0), v3(0.3, -0.2, z1), level, 1.0, &h, &evals) == SDFCCD_OK, "%s",
                  sdfccd_last_error());
    ck_assert_int_eq(h.hit, 1);
    ck_assert_double_eq_tol(h.fraction, (z0 - level) / (z0 - z1), 1e-12);
    ck_assert_double_eq_tol(h.distance, level, 1e-9);
    ck_assert_double_eq_tol(h.start_distance, z0, 1e-12);
    ck_assert_double_eq_tol(h.gradient.z, 1.0, 1e-12);
    ck_assert_int_eq(evals, 2); /* the start, then the hit: a linear phi is reached in one step */
    /* A slanted path that stays above the level (0.25 above it at its end): no hit, and it stops
     * once the rest of the path cannot reach the level, far before the 200-step cap. */
    evals = 0;
    ck_assert(sdfccd_point_first_hit(plane, v3(0, 0, 2), v3(5, 0, 0.5), level, 1.0, &h, &evals) == SDFCCD_OK);
    ck_assert_int_eq(h.hit, 0);
    ck_assert_int_le(evals, 10);
    /* A start below the level hits at fraction 0. */
    ck_assert(sdfccd_point_first_hit(plane, v3(0, 0, 0.1), v3(0, 0, 3), level, 1.0, &h, NULL) == SDFCCD_OK);
    ck_assert_int_eq(h.hit, 1);
    ck_assert_double_eq(h.fraction, 0.0);
    ck_assert(sdfccd_destroy_sdf(plane) == SDFCCD_OK);
}
END_TEST

/* A point passing a sphere off its centre: the first time |p(t)| = R + level, from the quadratic,
 * reached within the 1e-6 tolerance and never after it (conservative advancement is never late). */
START_TEST(test_point_sphere_closed_form)
{
    const double R = 1.0, level = 0.1;
    sdfccd_SdfId s = sphere(R);
    const sdfccd_Vec3 a = v3(0.5, 0.2, 3.0), b = v3(0.5, 0.2, -3.0);
    /* |a + t (b - a)|^2 = (R + level)^2 with x, y fixed: z = sqrt((R+level)^2 - 0.29), first root. */
    const double z = sqrt((R + level) * (R + level) - 0.29), t_star = (a.z - z) / (a.z - b.z);
    for (int li = 0; li < 2; ++li) {
        const double L = li ? 2.5 : 1.0; /* a looser Lipschitz bound takes more steps, same answer */
        sdfccd_PointHit h;
        int64_t evals = 0;
        ck_assert(sdfccd_point_first_hit(s, a, b, level, L, &h, &evals) == SDFCCD_OK);
        ck_assert_int_eq(h.hit, 1);
        ck_assert_msg(h.fraction <= t_star + 1e-12, "late: %.17g > %.17g", h.fraction, t_star);
        ck_assert_msg(h.distance <= level + 1e-6 && h.distance >= level - 1e-9, "phi at the hit %.17g", h.distance);
        ck_assert_double_eq_tol(h.fraction, t_star, 1e-6 / 6.0 * 2);
        ck_assert_double_eq_tol(h.start_distance, sqrt(0.29 + 9.0) - R, 1e-12);
        ck_assert_int_lt(evals, 200);
    }
    /* A path that passes beside the sphere at distance 0.2 from it never reaches level 0.1. */
    sdfccd_PointHit h;
    ck_assert(sdfccd_point_first_hit(s, v3(1.2, 0, 3), v3(1.2, 0, -3), level, 1.0, &h, NULL) == SDFCCD_OK);
    ck_assert_int_eq(h.hit, 0);
    ck_assert(sdfccd_destroy_sdf(s) == SDFCCD_OK);
}
END_TEST

/* The certificate's bound over moving corners: bound - L times the farthest corner from its anchor
 * at either end of its path (closed form). */
START_TEST(test_cert_bound_closed_form)
{
    sdfccd_DistanceCert c = sdfccd_empty_distance_cert();
    const sdfccd_Vec3 s[3] = { v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0) }, e[3] = { v3(0, 0, 0.5), v3(1, 0, 0), v3(0, 1, -2) };
    double b = 0;
    ck_assert(sdfccd_distance_cert_bound(&c, s, e, 3, 1.0, &b) == SDFCCD_OK);
    ck_assert(b == -INFINITY);
    for (int k = 0; k < 3; ++k) c.anchor[k] = s[k];
    c.bound = 5.0;
    ck_assert(sdfccd_distance_cert_bound(&c, s, e, 3, 1.5, &b) == SDFCCD_OK);
    ck_assert_double_eq_tol(b, 5.0 - 1.5 * 2.0, 1e-15); /* corner 2 moves 2 from its anchor */
    ck_assert(sdfccd_distance_cert_bound(&c, s, e, 1, 1.5, &b) == SDFCCD_OK);
    ck_assert_double_eq_tol(b, 5.0 - 1.5 * 0.5, 1e-15); /* a point: anchor[0] only */
}
END_TEST

/* A small face far from the sphere is certified by one evaluation, with a bound that holds
 * (brute force); the certificate then clears the next small motion with no evaluation at all. */
START_TEST(test_face_far_certified)
{
    sdfccd_SdfId s = sphere(1.0);
    const sdfccd_Vec3 st[3] = { v3(10, 0, 0), v3(10.3, 0, 0), v3(10, 0.3, 0) }, en[3] = { v3(9.9, 0, 0), v3(10.2, 0, 0), v3(9.9, 0.3, 0) };
    sdfccd_DistanceCert c = sdfccd_empty_distance_cert();
    int32_t clear = -1;
    int64_t evals = 0;
    ck_assert(sdfccd_triangle_clear(s, &c, st, en, 0.0, 1.0, &clear, &evals) == SDFCCD_OK);
    ck_assert_int_eq(clear, 1);
    ck_assert_int_eq(evals, 1);
    ck_assert_msg(c.bound <= min_phi_swept(s, st, st), "bound %.17g above the face's minimum", c.bound);
    ck_assert(c.bound > 8.0);
    for (int k = 0; k < 3; ++k) ck_assert(c.anchor[k].x == st[k].x && c.anchor[k].y == st[k].y);
    /* The next step, 0.1 further: the old certificate suffices. */
    const sdfccd_Vec3 further[3] = { v3(9.8, 0, 0), v3(10.1, 0, 0), v3(9.8, 0.3, 0) };
    const double old = c.bound;
    ck_assert(sdfccd_triangle_clear(s, &c, en, further, 0.0, 1.0, &clear, &evals) == SDFCCD_OK);
    ck_assert_int_eq(clear, 1);
    ck_assert_int_eq(evals, 1);
    ck_assert(c.bound == old);
    ck_assert(sdfccd_destroy_sdf(s) == SDFCCD_OK);
}
END_TEST

/* A large face near the sphere that clears it: the centroid alone cannot certify it (its radius
 * times L exceeds the distance), splitting does, within the 85 evaluations of depth 3, and the bound
 * is below the brute-force minimum over the whole motion. */
START_TEST(test_face_near_certified_by_splitting)
{
    sdfccd_SdfId s = sphere(1.0);
    const sdfccd_Vec3 st[3] = { v3(-2, -2, 1.6), v3(2, -2, 1.6), v3(0, 2, 1.6) }, en[3] = { v3(-2, -2, 1.55), v3(2, -2, 1.55), v3(0, 2, 1.55) };
    sdfccd_DistanceCert c = sdfccd_empty_distance_cert();
    int32_t clear = -1;
    int64_t evals = 0;
    ck_assert(sdfccd_triangle_clear(s, &c, st, en, 0.1, 1.0, &clear, &evals) == SDFCCD_OK);
    ck_assert_int_eq(clear, 1);
    ck_assert_int_gt(evals, 1);
    ck_assert_int_le(evals, 85);
    const double truth = min_phi_swept(s, st, en);
    ck_assert_msg(c.bound - 0.05 <= truth && c.bound - 0.05 >= 0.1, "bound %.17g, true minimum %.17g", c.bound, truth);
    ck_assert(sdfccd_destroy_sdf(s) == SDFCCD_OK);
}
END_TEST

/* Faces whose corners all stay far outside the sphere while their interior crosses it are never
 * certified clear: a face over the sphere's centre, and one whose edge cuts through it (its centroid
 * well outside). The certificate is left as it was. */
START_TEST(test_face_interior_crossing_not_certified)
{
    sdfccd_SdfId s = sphere(1.0);
    const sdfccd_Vec3 over[3] = { v3(4, 0, 3), v3(-2, 3.5, 3), v3(-2, -3.5, 3) }, down[3] = { v3(4, 0, 0.5), v3(-2, 3.5, 0.5),
                                                                                             v3(-2, -3.5, 0.5) };
    const sdfccd_Vec3 edge[3] = { v3(-3, 0.2, 0), v3(3, 0.2, 0), v3(0, 6, 0) };
    const sdfccd_Vec3* cases[2][2] = { { over, down }, { edge, edge } };
    for (int i = 0; i < 2; ++i) {
        const sdfccd_Vec3* st = cases[i][0];
        const sdfccd_Vec3* en = cases[i][1];
        for (int k = 0; k < 3; ++k) { /* every corner stays outside at both ends */
            double p0, p1;
            ck_assert(sdfccd_sdf_eval(s, st[k], &p0, NULL) == SDFCCD_OK && sdfccd_sdf_eval(s, en[k], &p1, NULL) == SDFCCD_OK);
            ck_assert(p0 > 1.5 && p1 > 1.5);
        }
        ck_assert(min_phi_swept(s, st, en) < 0);
        sdfccd_DistanceCert c = sdfccd_empty_distance_cert();
        int32_t clear = -1;
        int64_t evals = 0;
        ck_assert(sdfccd_triangle_clear(s, &c, st, en, 0.0, 1.0, &clear, &evals) == SDFCCD_OK);
        ck_assert_msg(clear == 0, "case %d certified clear with bound %g", i, c.bound);
        ck_assert(c.bound == -INFINITY);
        ck_assert_int_le(evals, 85);
    }
    ck_assert(sdfccd_destroy_sdf(s) == SDFCCD_OK);
}
END_TEST

/* The guard of one node against a half-space z >= 0 (tolerance 0.01), every answer in closed form:
 * a node falling through goes back to where it came within half the tolerance of -tolerance; a node
 * starting 5 cm deep may not end deeper than it started (minus a tenth of the tolerance) and goes
 * back to its start, or stays where it went when it rises; a certificate clears a resting node
 * with no evaluation. */
START_TEST(test_guard_point_half_space)
{
    sdfccd_SdfId plane;
    ck_assert(sdfccd_create_half_space(v3(0, 0, 1), 0, &plane) == SDFCCD_OK);
    const double tol = 0.01;
    const sdfccd_DistanceCert none = sdfccd_empty_distance_cert();
    sdfccd_PointGuard g;
    int64_t evals = 0;
    ck_assert_msg(sdfccd_guard_point(plane, &none, v3(0.2, 0.1, 0.5), v3(0.2, 0.1, -0.5), tol, 1.0, &g, &evals) == SDFCCD_OK, "%s",
                  sdfccd_last_error());
    ck_assert_int_eq(g.clear, 0);
    ck_assert_double_eq(g.level, -tol);
    ck_assert_int_eq(g.hit, 1);
    ck_assert_double_eq_tol(g.fraction, (0.5 + 0.5 * tol) / 1.0, 1e-9); /* z = -tol / 2, not z = -tol */
    ck_assert_double_eq_tol(g.gradient.z, 1.0, 1e-12);
    ck_assert_int_eq(evals, 5); /* the start's depth, then two paths of two evaluations */
    /* Starting 5 cm deep, sinking to 20 cm: held at -0.051, back to the start. */
    ck_assert(sdfccd_guard_point(plane, &none, v3(0, 0, -0.05), v3(0, 0, -0.2), tol, 1.0, &g, NULL) == SDFCCD_OK);
    ck_assert_double_eq_tol(g.level, -0.05 - 0.1 * tol, 1e-15);
    ck_assert_int_eq(g.hit, 1);
    ck_assert_double_eq(g.fraction, 0.0);
    /* Starting as deep but rising: no hit at its level. */
    ck_assert(sdfccd_guard_point(plane, &none, v3(0, 0, -0.05), v3(0, 0, 0.3), tol, 1.0, &g, NULL) == SDFCCD_OK);
    ck_assert_double_eq_tol(g.level, -0.05 - 0.1 * tol, 1e-15);
    ck_assert_int_eq(g.hit, 0);
    /* A resting node: a certificate phi >= 1 at z = 1 clears a 20 cm motion (1 - 0.2 >= -tol) with no
     * evaluation; without it the node costs evaluations and is not hit. */
    sdfccd_DistanceCert c = sdfccd_empty_distance_cert();
    c.anchor[0] = v3(0, 0, 1);
    c.bound = 1.0;
    evals = 0;
    ck_assert(sdfccd_guard_point(plane, &c, v3(0, 0, 1), v3(0, 0, 0.8), tol, 1.0, &g, &evals) == SDFCCD_OK);
    ck_assert_int_eq(g.clear, 1);
    ck_assert_int_eq(g.hit, 0);
    ck_assert_int_eq(evals, 0);
    ck_assert(sdfccd_guard_point(plane, &none, v3(0, 0, 1), v3(0, 0, 0.8), tol, 1.0, &g, &evals) == SDFCCD_OK);
    ck_assert_int_eq(g.clear, 0);
    ck_assert_int_eq(g.hit, 0);
    ck_assert_int_gt(evals, 0);
    /* Bad input: nothing written. */
    memset(&g, 0x5a, sizeof g);
    const sdfccd_PointGuard before = g;
    ck_assert_int_eq(sdfccd_guard_point(plane, &none, v3(0, 0, 1), v3(0, 0, 0.8), 0.0, 1.0, &g, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_point(plane, &none, v3(0, 0, NAN), v3(0, 0, 0.8), tol, 1.0, &g, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_point(plane, NULL, v3(0, 0, 1), v3(0, 0, 0.8), tol, 1.0, &g, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert(memcmp(&g, &before, sizeof g) == 0);
    ck_assert(sdfccd_destroy_sdf(plane) == SDFCCD_OK);
}
END_TEST

/* A 4 m link lying flat 2 m above a unit sphere's centre sinks to 0.5 m: its ends stay 1 m clear
 * while its middle crosses. The first hit comes no later than the middle point's first reach of the
 * level (closed form: z = 1 + level) and no earlier than its reach of level + L spacing. */
START_TEST(test_segment_sphere_closed_form)
{
    sdfccd_SdfId s = sphere(1.0);
    const double level = 0.05, spacing = 0.1, z0 = 2.0, z1 = 0.5;
    const sdfccd_Vec3 st[2] = { v3(-2, 0, z0), v3(2, 0, z0) }, en[2] = { v3(-2, 0, z1), v3(2, 0, z1) };
    sdfccd_PointHit h;
    int64_t evals = 0;
    ck_assert_msg(sdfccd_segment_first_hit(s, st, en, level, spacing, 1.0, &h, &evals) == SDFCCD_OK, "%s", sdfccd_last_error());
    ck_assert_int_eq(h.hit, 1);
    const double late = (z0 - (1 + level)) / (z0 - z1), early = (z0 - (1 + level + spacing)) / (z0 - z1);
    ck_assert_msg(h.fraction <= late && h.fraction >= early, "fraction %.17g outside [%.17g, %.17g]", h.fraction, early, late);
    ck_assert(h.gradient.z > 0.99);
    ck_assert_int_gt(evals, 40); /* 41 points along the link */
    /* Passing 0.2 beside the sphere never reaches level 0.05. */
    const sdfccd_Vec3 st2[2] = { v3(-2, 1.2, z0), v3(2, 1.2, z0) }, en2[2] = { v3(-2, 1.2, -z0), v3(2, 1.2, -z0) };
    ck_assert(sdfccd_segment_first_hit(s, st2, en2, level, spacing, 1.0, &h, NULL) == SDFCCD_OK);
    ck_assert_int_eq(h.hit, 0);
    /* Bad input: nothing written. */
    memset(&h, 0x5a, sizeof h);
    const sdfccd_PointHit before = h;
    ck_assert_int_eq(sdfccd_segment_first_hit(s, st, en, level, 0.0, 1.0, &h, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_segment_first_hit(s, st, en, level, 1e-9, 1.0, &h, NULL), SDFCCD_INVALID_ARGUMENT); /* 4e9 points */
    ck_assert_int_eq(sdfccd_segment_first_hit(s, NULL, en, level, spacing, 1.0, &h, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert(memcmp(&h, &before, sizeof h) == 0);
    ck_assert(sdfccd_destroy_sdf(s) == SDFCCD_OK);
}
END_TEST

START_TEST(test_soft_bad_input)
{
    sdfccd_SdfId s = sphere(1.0);
    const sdfccd_Vec3 t[3] = { v3(3, 0, 0), v3(4, 0, 0), v3(3, 1, 0) };
    sdfccd_Vec3 bad[3] = { v3(3, 0, 0), v3(NAN, 0, 0), v3(3, 1, 0) };
    sdfccd_PointHit h;
    memset(&h, 0x5a, sizeof h);
    const sdfccd_PointHit before = h;
    int64_t evals = 0;
    ck_assert_int_eq(sdfccd_point_first_hit(s, t[0], t[1], 0.0, 1.0, NULL, &evals), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strlen(sdfccd_last_error()) > 0);
    ck_assert_int_eq(sdfccd_point_first_hit(s, bad[1], t[1], 0.0, 1.0, &h, &evals), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_point_first_hit(s, t[0], t[1], INFINITY, 1.0, &h, &evals), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_point_first_hit(s, t[0], t[1], 0.0, 0.0, &h, &evals), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_point_first_hit(s, t[0], t[1], 0.0, NAN, &h, &evals), SDFCCD_INVALID_ARGUMENT);
    ck_assert(memcmp(&h, &before, sizeof h) == 0);
    ck_assert_int_eq(evals, 0);

    sdfccd_DistanceCert c = sdfccd_empty_distance_cert();
    int32_t clear = 7;
    double b = 7;
    ck_assert_int_eq(sdfccd_triangle_clear(s, &c, bad, t, 0.0, 1.0, &clear, &evals), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_triangle_clear(s, &c, t, t, 0.0, -1.0, &clear, &evals), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_triangle_clear(s, NULL, t, t, 0.0, 1.0, &clear, &evals), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_triangle_clear(s, &c, t, t, 0.0, 1.0, NULL, &evals), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(clear, 7);
    ck_assert_int_eq(sdfccd_distance_cert_bound(&c, t, t, 4, 1.0, &b), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_distance_cert_bound(&c, t, t, 0, 1.0, &b), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_distance_cert_bound(&c, t, bad, 2, 1.0, &b), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_distance_cert_bound(&c, t, t, 3, INFINITY, &b), SDFCCD_INVALID_ARGUMENT);
    ck_assert(b == 7);
    ck_assert(c.bound == -INFINITY);
    /* A destroyed SDF: INVALID_HANDLE, nothing written. */
    ck_assert(sdfccd_destroy_sdf(s) == SDFCCD_OK);
    ck_assert_int_eq(sdfccd_point_first_hit(s, t[0], t[1], 0.0, 1.0, &h, &evals), SDFCCD_INVALID_HANDLE);
    ck_assert_int_eq(sdfccd_triangle_clear(s, &c, t, t, 0.0, 1.0, &clear, &evals), SDFCCD_INVALID_HANDLE);
    ck_assert(strlen(sdfccd_last_error()) > 0);
    ck_assert(memcmp(&h, &before, sizeof h) == 0);
    ck_assert_int_eq(clear, 7);
    ck_assert_int_eq(evals, 0);
}
END_TEST

/* The guard's face rule (sdfccd_guard_face) on closed forms. A flat triangle falling through the
 * half-space z >= 0 from z = 0.5 to -0.5 goes back to where it came within half the tolerance of
 * -tolerance (z = -tol / 2: fraction 0.505), to its start on the last pass; one starting 5 cm deep
 * may not end deeper than it started (back to its start, no stop) but may rise; a triangle whose
 * corners stay 2.6 m clear of a unit sphere while its interior sinks onto it is stopped at z = 0.995
 * (its corners alone, sdfccd_guard_point, are not); a certified face costs no query. */
START_TEST(test_guard_face_closed_form)
{
    sdfccd_SdfId plane;
    ck_assert(sdfccd_create_half_space(v3(0, 0, 1), 0, &plane) == SDFCCD_OK);
    const double tol = 0.01;
    const sdfccd_QueryParams qp = sdfccd_default_query_params();
    sdfccd_DistanceCert c = sdfccd_empty_distance_cert();
    const sdfccd_Vec3 s[3] = { v3(0, 0, 0.5), v3(0.3, 0, 0.5), v3(0, 0.3, 0.5) }, e[3] = { v3(0, 0, -0.5), v3(0.3, 0, -0.5), v3(0, 0.3, -0.5) };
    sdfccd_FaceGuard g;
    int64_t evals = 0;
    ck_assert_msg(sdfccd_guard_face(plane, &c, s, e, -tol, tol, 1.0, &qp, 0.01, 0, &g, &evals) == SDFCCD_OK, "%s", sdfccd_last_error());
    ck_assert_int_eq(g.hit, 1);
    ck_assert_int_eq(g.stop, 1);
    ck_assert_msg(fabs(g.fraction - 0.505) <= 1e-6, "fraction %.17g, not 0.505", g.fraction);
    ck_assert_double_eq_tol(g.normal.z, 1.0, 1e-9);
    ck_assert_int_eq(g.queries, 2);
    ck_assert_int_gt(evals, 0);
    c = sdfccd_empty_distance_cert();
    ck_assert(sdfccd_guard_face(plane, &c, s, e, -tol, tol, 1.0, &qp, 0.01, 1, &g, NULL) == SDFCCD_OK);
    ck_assert_int_eq(g.hit, 1);
    ck_assert_double_eq(g.fraction, 0.0);
    /* 5 cm deep, sinking to 20 cm: back to the start; rising to 3 cm: kept. */
    const sdfccd_Vec3 d[3] = { v3(0, 0, -0.05), v3(0.3, 0, -0.05), v3(0, 0.3, -0.05) };
    const sdfccd_Vec3 sink[3] = { v3(0, 0, -0.2), v3(0.3, 0, -0.2), v3(0, 0.3, -0.2) }, rise[3] = { v3(0, 0, -0.03), v3(0.3, 0, -0.03), v3(0, 0.3, -0.03) };
    c = sdfccd_empty_distance_cert();
    ck_assert(sdfccd_guard_face(plane, &c, d, sink, -tol, tol, 1.0, &qp, 0.01, 0, &g, NULL) == SDFCCD_OK);
    ck_assert_int_eq(g.hit, 1);
    ck_assert_int_eq(g.stop, 0);
    ck_assert_double_eq(g.fraction, 0.0);
    ck_assert(sdfccd_guard_face(plane, &c, d, rise, -tol, tol, 1.0, &qp, 0.01, 0, &g, NULL) == SDFCCD_OK);
    ck_assert_int_eq(g.hit, 0);
    /* Resting 1 m up: the certificate made on the first call clears the second with no evaluation. */
    const sdfccd_Vec3 up[3] = { v3(0, 0, 1), v3(0.3, 0, 1), v3(0, 0.3, 1) };
    c = sdfccd_empty_distance_cert();
    ck_assert(sdfccd_guard_face(plane, &c, up, up, -tol, tol, 1.0, &qp, 0.01, 0, &g, NULL) == SDFCCD_OK);
    ck_assert_int_eq(g.hit, 0);
    ck_assert_int_eq(g.queries, 0);
    evals = 0;
    ck_assert(sdfccd_guard_face(plane, &c, up, up, -tol, tol, 1.0, &qp, 0.01, 0, &g, &evals) == SDFCCD_OK);
    ck_assert_int_eq(g.queries, 0);
    ck_assert_int_eq(evals, 0);
    ck_assert(sdfccd_destroy_sdf(plane) == SDFCCD_OK);

    sdfccd_SdfId ball = sphere(1.0);
    const sdfccd_Vec3 bs[3] = { v3(-3, -2, 2.0), v3(3, -2, 2.0), v3(0, 3, 2.0) }, be[3] = { v3(-3, -2, 0.5), v3(3, -2, 0.5), v3(0, 3, 0.5) };
    c = sdfccd_empty_distance_cert();
    ck_assert(sdfccd_guard_face(ball, &c, bs, be, -tol, tol, 1.0, &qp, 0.01, 0, &g, NULL) == SDFCCD_OK);
    ck_assert_int_eq(g.hit, 1);
    ck_assert_msg(fabs(g.fraction - (2.0 - 0.995) / 1.5) <= 1e-6, "fraction %.17g, not %.17g", g.fraction, (2.0 - 0.995) / 1.5);
    ck_assert(g.normal.z > 0.999);
    for (int k = 0; k < 3; ++k) {
        sdfccd_PointGuard pg;
        const sdfccd_DistanceCert none = sdfccd_empty_distance_cert();
        ck_assert(sdfccd_guard_point(ball, &none, bs[k], be[k], tol, 1.0, &pg, NULL) == SDFCCD_OK);
        ck_assert_int_eq(pg.hit, 0);
    }
    /* Bad input: nothing written. */
    memset(&g, 0x5a, sizeof g);
    const sdfccd_FaceGuard before = g;
    sdfccd_Vec3 bad[3] = { bs[0], v3(NAN, 0, 0), bs[2] };
    ck_assert_int_eq(sdfccd_guard_face(ball, &c, bs, be, -tol, 0.0, 1.0, &qp, 0.01, 0, &g, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_face(ball, &c, bs, be, -tol, tol, 1.0, &qp, 0.0, 0, &g, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_face(ball, &c, bad, be, -tol, tol, 1.0, &qp, 0.01, 0, &g, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_face(ball, &c, bs, be, NAN, tol, 1.0, &qp, 0.01, 0, &g, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_face(ball, &c, bs, be, -tol, tol, 1.0, NULL, 0.01, 0, &g, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_face(ball, &c, bs, be, -tol, tol, 1.0, &qp, 0.01, 0, NULL, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert(sdfccd_destroy_sdf(ball) == SDFCCD_OK);
    ck_assert_int_eq(sdfccd_guard_face(ball, &c, bs, be, -tol, tol, 1.0, &qp, 0.01, 0, &g, NULL), SDFCCD_INVALID_HANDLE);
    ck_assert(strlen(sdfccd_last_error()) > 0);
    ck_assert(memcmp(&g, &before, sizeof g) == 0);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("soft");
    TCase* tc = tcase_create("per-vertex linear motion");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_point_half_space_closed_form);
    tcase_add_test(tc, test_point_sphere_closed_form);
    tcase_add_test(tc, test_cert_bound_closed_form);
    tcase_add_test(tc, test_face_far_certified);
    tcase_add_test(tc, test_face_near_certified_by_splitting);
    tcase_add_test(tc, test_face_interior_crossing_not_certified);
    tcase_add_test(tc, test_guard_point_half_space);
    tcase_add_test(tc, test_segment_sphere_closed_form);
    tcase_add_test(tc, test_soft_bad_input);
    tcase_add_test(tc, test_guard_face_closed_form);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
