/* SPDX-License-Identifier: MIT
 * Regression tests of the hardening issue (11): every finding of its table has a test here
 * that failed before the fix. Work bounded per query (evaluation budget, rotation limit),
 * no NaN behind SDFCCD_OK (magnitude checks, overflow-safe SDFs). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

/* A flat sheet of n x n quads (2 n^2 triangles) of side `size` in the plane z = height. */
static sdfccd_MeshId make_sheet(int n, double size, double height)
{
    int nv = (n + 1) * (n + 1);
    double* v = malloc(sizeof(double) * 3 * (size_t)nv);
    uint32_t* idx = malloc(sizeof(uint32_t) * 6 * (size_t)(n * n));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            double* p = v + 3 * (j * (n + 1) + i);
            p[0] = size * ((double)i / n - 0.5);
            p[1] = size * ((double)j / n - 0.5);
            p[2] = height;
        }
    uint32_t* f = idx;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            uint32_t a = (uint32_t)(j * (n + 1) + i), b = a + 1, c = a + (uint32_t)(n + 1), d = c + 1;
            *f++ = a; *f++ = b; *f++ = d;
            *f++ = a; *f++ = d; *f++ = c;
        }
    sdfccd_MeshDef d = sdfccd_default_mesh_def();
    d.vertices = v;
    d.vertex_count = (uint32_t)nv;
    d.indices = idx;
    d.triangle_count = (uint32_t)(2 * n * n);
    sdfccd_MeshId mesh;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &mesh), SDFCCD_OK);
    free(v);
    free(idx);
    return mesh;
}

static const sdfccd_Vec3 k_tri[3] = { { 2, 0, 0 }, { 2.5, 0, 0 }, { 2, 0.5, 0 } };

/* Finding "unbounded work": a triangle spinning at 1e90 rad/s took 14.8 s (FWGSS) and > 600 s
 * (CERTIFIED). Such a rotation is beyond what the motion model represents: rejected at once. */
START_TEST(test_huge_spin_rejected)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &s), SDFCCD_OK);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity.x = -1.0;
    m.angular_velocity.z = 1e90;
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_QueryResult r;
    for (int method = 0; method < SDFCCD_METHOD_COUNT; ++method) {
        p.method = (sdfccd_Method)method;
        ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
        ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "SDFCCD_MAX_ROTATION_ANGLE"));
        ck_assert_int_eq(sdfccd_query_triangle(s, &m, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    }
    /* Just below the limit the query is accepted (and bounded by the evaluation budget). */
    m.angular_velocity.z = 0.9 * SDFCCD_MAX_ROTATION_ANGLE;
    p.method = SDFCCD_METHOD_FWGSS;
    p.max_sdf_evaluations = 100000;
    ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_OK);
    ck_assert_int_eq(r.state, SDFCCD_STATE_NOT_CONVERGED);
    ck_assert_int_le(r.sdf_evaluations, 100000 + 2000);
    /* The body's and the SDF's rotations add up. */
    m.angular_velocity.z = 0.6 * SDFCCD_MAX_ROTATION_ANGLE;
    ck_assert_int_eq(sdfccd_query_triangle(s, &m, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* The budget is shared by the interval's segments: a rotation split into 1e6 segments (each of
 * which used to get the full per-call caps) stops at the budget with NOT_CONVERGED, for every
 * method; the same query with a large budget spends more, so the cap is what stopped it. */
START_TEST(test_budget_shared_by_segments)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &s), SDFCCD_OK);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity.x = -1.0;
    m.angular_velocity.z = 1e4;
    sdfccd_QueryParams p = sdfccd_default_query_params();
    p.max_rotation_per_segment = 1e-2; /* 1e6 segments */
    const int64_t budget = 50000;
    const sdfccd_Method methods[3] = { SDFCCD_METHOD_FWGSS, SDFCCD_METHOD_FW, SDFCCD_METHOD_CERTIFIED };
    for (int k = 0; k < 3; ++k) {
        sdfccd_QueryResult r;
        p.method = methods[k];
        p.max_sdf_evaluations = budget;
        ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_OK);
        ck_assert_int_eq(r.state, SDFCCD_STATE_NOT_CONVERGED);
        ck_assert_int_ge(r.sdf_evaluations, budget);
        ck_assert_int_le(r.sdf_evaluations, budget + 2000); /* at most one solver iteration over */
        ck_assert(r.toi == 1.0 && r.fraction == 1.0);
        p.max_sdf_evaluations = 4 * budget;
        ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_OK);
        ck_assert_int_gt(r.sdf_evaluations, budget + 2000);
    }
    p.max_sdf_evaluations = 0;
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    p = sdfccd_default_query_params();
    p.max_line_search_iterations = 5000;
    ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* The budget is shared by the triangles of a mesh query (with and without the broad phase);
 * a budget that runs out after a contact was witnessed keeps that witness (hit = 1). */
START_TEST(test_budget_shared_by_triangles)
{
    sdfccd_SdfId plane;
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &plane), SDFCCD_OK);
    sdfccd_MeshId sheet = make_sheet(16, 1.0, 0.5); /* 512 triangles */
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity.z = -1.0;
    m.angular_velocity.x = 0.3;
    for (int broad = 0; broad < 2; ++broad) {
        sdfccd_QueryParams p = sdfccd_default_query_params();
        p.broad_phase = broad;
        sdfccd_QueryResult full, capped;
        sdfccd_Contact c[8];
        ck_assert_int_eq(sdfccd_query_mesh(plane, NULL, sheet, &m, 0, 1, &p, c, 8, &full), SDFCCD_OK);
        ck_assert_int_eq(full.state, SDFCCD_STATE_HIT);
        ck_assert_int_gt(full.sdf_evaluations, 3000);
        p.max_sdf_evaluations = full.sdf_evaluations / 2;
        ck_assert_int_eq(sdfccd_query_mesh(plane, NULL, sheet, &m, 0, 1, &p, c, 8, &capped), SDFCCD_OK);
        ck_assert_int_eq(capped.state, SDFCCD_STATE_NOT_CONVERGED);
        ck_assert_int_le(capped.sdf_evaluations, p.max_sdf_evaluations + 2000);
        ck_assert_int_lt(capped.triangles_tested, full.triangles_tested + 1);
        ck_assert_int_eq(capped.hit, 1); /* the sheet is flat: its first triangles already touch */
        ck_assert(isfinite(capped.toi) && capped.toi >= 0.0 && capped.toi <= 1.0);
        ck_assert(capped.toi >= full.toi - 1e-6);
    }
    sdfccd_destroy_mesh(sheet);
    sdfccd_destroy_sdf(plane);
}
END_TEST

/* Finding "NaN behind OK": huge but finite inputs used to give NaN poses, segment starts and
 * fractions with SDFCCD_OK. They are now rejected where overflow starts. */
START_TEST(test_overflowing_query_inputs_rejected)
{
    sdfccd_SdfId a, b, u;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &a), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 1, 1, 1 }, &b), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, a, b, &u), SDFCCD_OK);
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_QueryResult r;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.angular_velocity.y = 1e154; /* |w| overflowed: NaN poses, and CSG let a NaN point touch */
    ck_assert_int_eq(sdfccd_query_triangle(u, NULL, k_tri, &m, 0, 1e-160, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    m = sdfccd_default_rigid_motion();
    m.linear_velocity.x = -1.0;
    /* t1 - t0 = inf: NaN segment starts and fraction, the real contact missed */
    ck_assert_int_eq(sdfccd_query_triangle(u, NULL, k_tri, &m, -1e308, 1e308, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_query_triangle(u, NULL, k_tri, &m, -1e200, 1e200, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_Vec3 far[3] = { { 1e160, 0, 0 }, { 1e160, 1, 0 }, { 1e160, 0, 1 } };
    ck_assert_int_eq(sdfccd_query_triangle(u, NULL, far, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    m.pose.position.z = -2e150;
    ck_assert_int_eq(sdfccd_query_triangle(u, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    /* Within the limits a far-away query is valid and its result finite. */
    m.pose.position.z = -1e149;
    ck_assert_int_eq(sdfccd_query_triangle(u, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_OK);
    ck_assert(r.state == SDFCCD_STATE_NO_HIT && r.fraction == 1.0);
    sdfccd_destroy_sdf(u);
    sdfccd_destroy_sdf(a);
    sdfccd_destroy_sdf(b);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("hardening");
    TCase* tc = tcase_create("findings");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_huge_spin_rejected);
    tcase_add_test(tc, test_budget_shared_by_segments);
    tcase_add_test(tc, test_budget_shared_by_triangles);
    tcase_add_test(tc, test_overflowing_query_inputs_rejected);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
