/* SPDX-License-Identifier: MIT
 * sdfccd_create_stretched (sdf.h): a field stretched per axis against closed forms (a stretched
 * sphere's value and gradient, the exact distance to a stretched box as an upper bound with the
 * same sign), a uniform stretch against sdfccd_create_transformed, a CCD query's time of impact
 * against the stretched surface, and bad input. Public ABI only. */
#include <math.h>
#include <string.h>
#include "test_util.h"

static sdfccd_Vec3 v3(double x, double y, double z) { return (sdfccd_Vec3){ x, y, z }; }

static sdfccd_SdfId stretched(sdfccd_SdfId child, sdfccd_Vec3 s)
{
    sdfccd_SdfId out;
    ck_assert_msg(sdfccd_create_stretched(child, s, &out) == SDFCCD_OK, "%s", sdfccd_last_error());
    return out;
}

/* The unit sphere stretched by s: phi = min(s) (|x / s| - 1), grad = min(s) (q / |q|) / s with
 * q = x / s, at random points; the child is destroyed first (the stretched field keeps it). */
START_TEST(test_sphere_closed_form)
{
    sdfccd_SdfId ball;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &ball), SDFCCD_OK);
    const sdfccd_Vec3 s = v3(1.5, 2.0, 3.0);
    sdfccd_SdfId e = stretched(ball, s);
    ck_assert_int_eq(sdfccd_destroy_sdf(ball), SDFCCD_OK);
    test_rng rng = { 19 };
    for (int i = 0; i < 1000; ++i) {
        const sdfccd_Vec3 p = v3(test_rng_uniform(&rng, -5, 5), test_rng_uniform(&rng, -5, 5), test_rng_uniform(&rng, -5, 5));
        const sdfccd_Vec3 q = v3(p.x / s.x, p.y / s.y, p.z / s.z);
        const double l = sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
        double v;
        sdfccd_Vec3 g;
        ck_assert_int_eq(sdfccd_sdf_eval(e, p, &v, &g), SDFCCD_OK);
        ck_assert_double_near(v, 1.5 * (l - 1.0), 1e-13);
        ck_assert_double_near(g.x, 1.5 * q.x / l / s.x, 1e-13);
        ck_assert_double_near(g.y, 1.5 * q.y / l / s.y, 1e-13);
        ck_assert_double_near(g.z, 1.5 * q.z / l / s.z, 1e-13);
    }
    /* The stretched bounds (the ellipsoid's box), the child's Lipschitz bound. */
    sdfccd_SdfInfo info;
    ck_assert_int_eq(sdfccd_sdf_get_info(e, &info), SDFCCD_OK);
    ck_assert_double_near(info.bounds.lo.x, -1.5, 0);
    ck_assert_double_near(info.bounds.hi.y, 2.0, 0);
    ck_assert_double_near(info.bounds.hi.z, 3.0, 0);
    ck_assert_double_near(info.lipschitz, 1.0, 0);
    ck_assert_int_eq(info.kind, SDFCCD_SDF_TRANSFORM);
    ck_assert_int_eq(sdfccd_destroy_sdf(e), SDFCCD_OK);
}
END_TEST

/* Exact signed distance to the box [-h, h] (per axis). */
static double box_distance(sdfccd_Vec3 p, sdfccd_Vec3 h)
{
    const double d[3] = { fabs(p.x) - h.x, fabs(p.y) - h.y, fabs(p.z) - h.z };
    double out = 0, in = fmax(d[0], fmax(d[1], d[2]));
    for (int k = 0; k < 3; ++k) out += d[k] > 0 ? d[k] * d[k] : 0;
    return in > 0 ? sqrt(out) : in;
}

/* A cube of half 0.5 stretched by (1, 2, 4) is the box of half (0.5, 1, 2): the field has the exact
 * distance's sign and never exceeds it in magnitude, and equals it where the smallest factor decides
 * (outside the x faces, along x). */
START_TEST(test_box_lower_bound)
{
    sdfccd_SdfId cube;
    ck_assert_int_eq(sdfccd_create_box(v3(0.5, 0.5, 0.5), &cube), SDFCCD_OK);
    const sdfccd_SdfId e = stretched(cube, v3(1, 2, 4));
    const sdfccd_Vec3 h = v3(0.5, 1, 2);
    test_rng rng = { 7 };
    int inside = 0;
    for (int i = 0; i < 2000; ++i) {
        const sdfccd_Vec3 p = v3(test_rng_uniform(&rng, -3, 3), test_rng_uniform(&rng, -3, 3), test_rng_uniform(&rng, -4, 4));
        double v;
        ck_assert_int_eq(sdfccd_sdf_eval(e, p, &v, NULL), SDFCCD_OK);
        const double exact = box_distance(p, h);
        ck_assert_msg((v < 0) == (exact < 0), "sign at (%g %g %g): %g vs %g", p.x, p.y, p.z, v, exact);
        ck_assert_msg(fabs(v) <= fabs(exact) + 1e-12, "|phi| %g above the distance %g", v, exact);
        inside += v < 0;
    }
    ck_assert_int_gt(inside, 50);
    for (double x = 0.6; x < 3; x += 0.3) {
        double v;
        ck_assert_int_eq(sdfccd_sdf_eval(e, v3(x, 0.3, -1.2), &v, NULL), SDFCCD_OK);
        ck_assert_double_near(v, x - 0.5, 1e-15);
    }
    sdfccd_destroy_sdf(e);
    sdfccd_destroy_sdf(cube);
}
END_TEST

/* A uniform stretch is the uniformly scaled field: sdfccd_create_transformed's values to rounding. */
START_TEST(test_uniform_is_transformed)
{
    sdfccd_SdfId torus, scaled;
    ck_assert_int_eq(sdfccd_create_torus(1.0, 0.25, &torus), SDFCCD_OK);
    const sdfccd_SdfId e = stretched(torus, v3(4, 4, 4));
    ck_assert_int_eq(sdfccd_create_transformed(torus, sdfccd_pose_identity(), 4.0, &scaled), SDFCCD_OK);
    test_rng rng = { 3 };
    for (int i = 0; i < 500; ++i) {
        const sdfccd_Vec3 p = v3(test_rng_uniform(&rng, -6, 6), test_rng_uniform(&rng, -6, 6), test_rng_uniform(&rng, -2, 2));
        double a, b;
        sdfccd_Vec3 ga, gb;
        ck_assert_int_eq(sdfccd_sdf_eval(e, p, &a, &ga), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_sdf_eval(scaled, p, &b, &gb), SDFCCD_OK);
        ck_assert_double_near(a, b, 1e-14);
        ck_assert_double_near(ga.x, gb.x, 1e-14);
        ck_assert_double_near(ga.z, gb.z, 1e-14);
    }
    sdfccd_destroy_sdf(e);
    sdfccd_destroy_sdf(scaled);
    sdfccd_destroy_sdf(torus);
}
END_TEST

/* A box falling onto the unit sphere stretched to an ellipsoid 3 m tall: its flat bottom, starting
 * 1 m above the pole at 2 m/s, touches it at t = 0.5 s (the FWGSS query, every method's answer). */
START_TEST(test_query_toi)
{
    sdfccd_SdfId ball;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &ball), SDFCCD_OK);
    const sdfccd_SdfId e = stretched(ball, v3(1, 1.5, 3));
    const sdfccd_MeshId box = test_box_mesh(v3(0.2, 0.2, 0.2), 2, 2, 2);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = v3(0, 0, 4.2);
    m.linear_velocity = v3(0, 0, -2);
    sdfccd_QueryParams p = sdfccd_default_query_params();
    p.margin = 0;
    const sdfccd_Method methods[] = { SDFCCD_METHOD_FWGSS, SDFCCD_METHOD_CERTIFIED };
    for (int k = 0; k < 2; ++k) {
        p.method = methods[k];
        sdfccd_QueryResult r;
        ck_assert_int_eq(sdfccd_query_mesh(e, NULL, box, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_OK);
        ck_assert_int_eq(r.hit, 1);
        ck_assert_double_near(r.toi, 0.5, 1e-4);
    }
    sdfccd_destroy_mesh(box);
    sdfccd_destroy_sdf(e);
    sdfccd_destroy_sdf(ball);
}
END_TEST

/* Bad input: a status and a message, the output untouched. */
START_TEST(test_bad_input)
{
    sdfccd_SdfId ball, out = { 77, 77 };
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &ball), SDFCCD_OK);
    const sdfccd_Vec3 bad[] = { v3(0, 1, 1), v3(1, -1, 1), v3(1, 1, NAN), v3(INFINITY, 1, 1), v3(1, 1e-101, 1), v3(1, 1, 1e101) };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        ck_assert_int_eq(sdfccd_create_stretched(ball, bad[i], &out), SDFCCD_INVALID_ARGUMENT);
        ck_assert(strstr(sdfccd_last_error(), "sdfccd_create_stretched") != NULL);
        ck_assert(out.index1 == 77 && out.generation == 77);
    }
    ck_assert_int_eq(sdfccd_create_stretched(ball, v3(1, 2, 3), NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_destroy_sdf(ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_stretched(ball, v3(1, 2, 3), &out), SDFCCD_INVALID_HANDLE);
    ck_assert(out.index1 == 77);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("stretch");
    TCase* tc = tcase_create("stretched SDF");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_sphere_closed_form);
    tcase_add_test(tc, test_box_lower_bound);
    tcase_add_test(tc, test_uniform_is_transformed);
    tcase_add_test(tc, test_query_toi);
    tcase_add_test(tc, test_bad_input);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
