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

int main(void)
{
    Suite* s = suite_create("sampled");
    TCase* tc = tcase_create("compare with samples");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_compare_closed_form);
    tcase_add_test(tc, test_compare_holes_and_nan);
    tcase_add_test(tc, test_compare_bad_input);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
