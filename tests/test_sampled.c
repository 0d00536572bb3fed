/* SPDX-License-Identifier: MIT
 * sdfccd_sdf_compare_samples (sampled.h): an SDF against a sampled field on known inputs (closed
 * forms on spheres), points without samples, non-finite samples, and bad input. Public ABI only. */
#include <math.h>
#include <string.h>
#include "test_util.h"

/* The unit sphere centred at (shift, 0, 0), sampled where x >= `from` (no value elsewhere). */
typedef struct sampled_sphere {
    double shift, from;
    int calls;
} sampled_sphere;

static int32_t sphere_sample(sdfccd_Vec3 p, double* out, void* user)
{
    sampled_sphere* s = user;
    ++s->calls;
    if (p.x < s->from) return 0;
    *out = sqrt((p.x - s->shift) * (p.x - s->shift) + p.y * p.y + p.z * p.z) - 1.0;
    return 1;
}

static int32_t nan_sample(sdfccd_Vec3 p, double* out, void* user)
{
    (void)user;
    *out = p.x > 0.5 ? NAN : 0.0;
    return 1;
}

static sdfccd_SdfId unit_sphere(void)
{
    sdfccd_SdfId s;
    ck_assert_msg(sdfccd_create_sphere(1.0, &s) == SDFCCD_OK, "%s", sdfccd_last_error());
    return s;
}

static const sdfccd_Aabb kBox = { { -2, -2, -2 }, { 2, 2, 2 } }; /* points at -1.6, -0.8, 0, 0.8, 1.6 per axis (n = 5) */

/* The same sphere: every point agrees (to rounding); a sphere moved by 0.01 along x differs by at
 * most 0.01 (triangle inequality), exactly 0.01 on the x axis, e.g. at (1.6, 0, 0). */
START_TEST(test_compare_closed_form)
{
    sdfccd_SdfId s = unit_sphere();
    sampled_sphere same = { 0.0, -INFINITY, 0 }, moved = { 0.01, -INFINITY, 0 };
    double diff = -1;
    int32_t compared = -1;
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &same, kBox, 5, &diff, &compared), SDFCCD_OK);
    ck_assert_int_eq(compared, 125);
    ck_assert_int_eq(same.calls, 125);
    ck_assert_msg(diff <= 1e-15, "same sphere: %g", diff);
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &moved, kBox, 5, &diff, &compared), SDFCCD_OK);
    ck_assert_int_eq(compared, 125);
    ck_assert_msg(fabs(diff - 0.01) <= 1e-12, "moved sphere: %.17g, expected 0.01", diff);
    /* n = 1: the box's centre only, where the moved sphere's phi is 0.01 below the unit sphere's. */
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &moved, kBox, 1, &diff, &compared), SDFCCD_OK);
    ck_assert_int_eq(compared, 1);
    ck_assert_msg(fabs(diff - 0.01) <= 1e-15, "centre: %.17g", diff);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* Points without a sample are skipped: with samples only where x >= 0, 3 of 5 x layers (75 points)
 * are compared; with none, nothing is and the difference is 0. A NaN sample never agrees. */
START_TEST(test_compare_holes_and_nan)
{
    sdfccd_SdfId s = unit_sphere();
    sampled_sphere half = { 0.01, 0.0, 0 }, none = { 0.0, INFINITY, 0 };
    double diff = -1;
    int32_t compared = -1;
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &half, kBox, 5, &diff, &compared), SDFCCD_OK);
    ck_assert_int_eq(compared, 75);
    ck_assert_msg(fabs(diff - 0.01) <= 1e-12, "half: %.17g", diff);
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &none, kBox, 5, &diff, NULL), SDFCCD_OK);
    ck_assert(diff == 0.0);
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, nan_sample, NULL, kBox, 5, &diff, &compared), SDFCCD_OK);
    ck_assert_int_eq(compared, 125);
    ck_assert(isinf(diff) && diff > 0);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* Bad input: a status and a message, outputs untouched. */
START_TEST(test_compare_bad_input)
{
    sdfccd_SdfId s = unit_sphere();
    sampled_sphere same = { 0.0, -INFINITY, 0 }, none = { 0.0, INFINITY, 0 };
    double diff = 7;
    int32_t compared = 7;
    const sdfccd_Aabb inverted = { { 1, -2, -2 }, { -1, 2, 2 } }, unbounded = { { -INFINITY, -2, -2 }, { 2, 2, 2 } };
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, NULL, NULL, kBox, 5, &diff, &compared), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &same, kBox, 5, NULL, &compared), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &same, kBox, 0, &diff, &compared), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &same, kBox, 257, &diff, &compared), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &same, inverted, 5, &diff, &compared), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &same, unbounded, 5, &diff, &compared), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strlen(sdfccd_last_error()) > 0);
    ck_assert_int_eq(same.calls, 0);
    sdfccd_destroy_sdf(s);
    /* A destroyed handle is refused even when the field has no samples to compare. */
    ck_assert_int_eq(sdfccd_sdf_compare_samples(s, sphere_sample, &none, kBox, 5, &diff, &compared), SDFCCD_INVALID_HANDLE);
    ck_assert(diff == 7 && compared == 7);
}
END_TEST

/* The unit sphere at the origin with its gradient, sampled where x >= `from`; records the largest
 * |coordinate| it was asked at. */
typedef struct grad_sphere {
    double from, asked;
    int calls;
} grad_sphere;

static int32_t grad_sample(sdfccd_Vec3 p, double* out, sdfccd_Vec3* grad, void* user)
{
    grad_sphere* s = user;
    ++s->calls;
    s->asked = fmax(s->asked, fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))));
    if (p.x < s->from) return 0;
    const double l = sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    *out = l - 1.0;
    *grad = (sdfccd_Vec3){ p.x / l, p.y / l, p.z / l };
    return 1;
}

static double len3(sdfccd_Vec3 v) { return sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }

/* sdfccd_create_sampled_sdf on the sampled unit sphere in [-2, 2]^3: inside the box, the sphere's
 * value and gradient; outside, the value at the nearest point of the box shrunk by 4e-6 plus the
 * distance to it: exactly the sphere's distance along an axis (e.g. 4 at (5, 0, 0)), elsewhere
 * between it and it plus twice the distance to the box (triangle inequality), the gradient pointing
 * away from the box; the samples are
 * asked inside the shrunk box only. */
START_TEST(test_sampled_sdf_closed_form)
{
    grad_sphere g = { -INFINITY, 0, 0 };
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sampled_sdf(grad_sample, &g, kBox, 0.5, &s), SDFCCD_OK);
    test_rng rng = { 5 };
    for (int i = 0; i < 2000; ++i) {
        const sdfccd_Vec3 p = { test_rng_uniform(&rng, -6, 6), test_rng_uniform(&rng, -6, 6), test_rng_uniform(&rng, -6, 6) };
        double v;
        sdfccd_Vec3 n;
        ck_assert_int_eq(sdfccd_sdf_eval(s, p, &v, &n), SDFCCD_OK);
        const double exact = len3(p) - 1.0;
        ck_assert_double_near(len3(n), 1.0, 1e-12);
        if (fabs(p.x) < 2 - 1e-5 && fabs(p.y) < 2 - 1e-5 && fabs(p.z) < 2 - 1e-5) {
            ck_assert_double_near(v, exact, 1e-12);
            ck_assert_double_near(n.x, p.x / len3(p), 1e-12);
        } else {
            const double dx = fmax(fabs(p.x) - 2, 0), dy = fmax(fabs(p.y) - 2, 0), dz = fmax(fabs(p.z) - 2, 0);
            const double out = sqrt(dx * dx + dy * dy + dz * dz); /* distance to the box */
            ck_assert_msg(v >= exact - 1e-12 && v <= exact + 2 * out + 1e-5, "outside (%g %g %g): %g, sphere %g", p.x, p.y, p.z, v, exact);
            if (fabs(p.x) > 2) ck_assert(n.x * p.x > 0);
        }
    }
    ck_assert_msg(g.asked <= 2 - 4e-6 + 1e-15, "asked at %.17g", g.asked);
    double v;
    sdfccd_Vec3 n;
    ck_assert_int_eq(sdfccd_sdf_eval(s, (sdfccd_Vec3){ 5, 0, 0 }, &v, &n), SDFCCD_OK);
    ck_assert_double_near(v, 4.0, 1e-12);
    ck_assert_double_near(n.x, 1.0, 1e-15);
    ck_assert_int_eq(sdfccd_sdf_eval(s, (sdfccd_Vec3){ 0, 0, -7 }, &v, &n), SDFCCD_OK);
    ck_assert_double_near(v, 6.0, 1e-12);
    ck_assert_double_near(n.z, -1.0, 1e-15);
    sdfccd_SdfInfo info;
    ck_assert_int_eq(sdfccd_sdf_get_info(s, &info), SDFCCD_OK);
    ck_assert(info.bounds.lo.x == -2 && info.bounds.hi.z == 2 && info.lipschitz == 1 && info.kind == SDFCCD_SDF_CALLBACK);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* Holes: where the sample has no value (x < 0), the hole value plus the distance to the box, the
 * gradient away from the box centre; the value without a gradient. */
START_TEST(test_sampled_sdf_holes)
{
    grad_sphere g = { 0.0, 0, 0 };
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sampled_sdf(grad_sample, &g, kBox, 0.5, &s), SDFCCD_OK);
    double v;
    sdfccd_Vec3 n;
    ck_assert_int_eq(sdfccd_sdf_eval(s, (sdfccd_Vec3){ -1, 0, 0 }, &v, &n), SDFCCD_OK);
    ck_assert_double_near(v, 0.5, 0);
    ck_assert_double_near(n.x, -1.0, 1e-15);
    ck_assert_int_eq(sdfccd_sdf_eval(s, (sdfccd_Vec3){ -3, 0, 0 }, &v, &n), SDFCCD_OK);
    ck_assert_double_near(v, 0.5 + 1 + 4e-6, 1e-12);
    ck_assert_int_eq(sdfccd_sdf_eval(s, (sdfccd_Vec3){ 0.5, 0, 0 }, &v, &n), SDFCCD_OK);
    ck_assert_double_near(v, -0.5, 1e-15);
    ck_assert_int_eq(sdfccd_sdf_eval(s, (sdfccd_Vec3){ 0.5, 3, 0 }, &v, NULL), SDFCCD_OK); /* no gradient asked */
    ck_assert_double_near(v, sqrt(0.25 + (2 - 4e-6) * (2 - 4e-6)) - 1 + 1 + 4e-6, 1e-12);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* A box mesh falling from outside the sampled box onto the sphere: its bottom starts at z = 3 at
 * 2 m/s and touches the sphere's top at t = 1 s. */
START_TEST(test_sampled_sdf_query)
{
    grad_sphere g = { -INFINITY, 0, 0 };
    const sdfccd_Aabb box = { { -1.5, -1.5, -1.5 }, { 1.5, 1.5, 1.5 } };
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sampled_sdf(grad_sample, &g, box, 0.5, &s), SDFCCD_OK);
    const sdfccd_MeshId mesh = test_box_mesh((sdfccd_Vec3){ 0.2, 0.2, 0.2 }, 2, 2, 2);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = (sdfccd_Vec3){ 0, 0, 3.2 };
    m.linear_velocity = (sdfccd_Vec3){ 0, 0, -2 };
    sdfccd_QueryParams p = sdfccd_default_query_params();
    p.margin = 0;
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_mesh(s, NULL, mesh, &m, 0, 1.5, &p, NULL, 0, &r), SDFCCD_OK);
    ck_assert_int_eq(r.hit, 1);
    ck_assert_double_near(r.toi, 1.0, 1e-4);
    sdfccd_destroy_mesh(mesh);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* Bad input: a status and a message, the output untouched. */
START_TEST(test_sampled_sdf_bad_input)
{
    grad_sphere g = { -INFINITY, 0, 0 };
    sdfccd_SdfId s = { 9, 9 };
    const sdfccd_Aabb inverted = { { 1, -2, -2 }, { -1, 2, 2 } }, unbounded = { { -INFINITY, -2, -2 }, { 2, 2, 2 } };
    ck_assert_int_eq(sdfccd_create_sampled_sdf(NULL, &g, kBox, 0.5, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_sampled_sdf(grad_sample, &g, inverted, 0.5, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_sampled_sdf(grad_sample, &g, unbounded, 0.5, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_sampled_sdf(grad_sample, &g, kBox, NAN, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strstr(sdfccd_last_error(), "sdfccd_create_sampled_sdf") != NULL);
    ck_assert_int_eq(sdfccd_create_sampled_sdf(grad_sample, &g, kBox, 0.5, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert(s.index1 == 9 && s.generation == 9 && g.calls == 0);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("sampled");
    TCase* tc = tcase_create("compare with samples");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_compare_closed_form);
    tcase_add_test(tc, test_compare_holes_and_nan);
    tcase_add_test(tc, test_compare_bad_input);
    tcase_add_test(tc, test_sampled_sdf_closed_form);
    tcase_add_test(tc, test_sampled_sdf_holes);
    tcase_add_test(tc, test_sampled_sdf_query);
    tcase_add_test(tc, test_sampled_sdf_bad_input);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
