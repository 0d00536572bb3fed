/* SPDX-License-Identifier: MIT
 * Regression tests of the hardening issue (11): every finding of its table has a test here
 * that failed before the fix. Work bounded per query (evaluation budget, rotation limit),
 * no NaN behind SDFCCD_OK (magnitude checks, overflow-safe SDFs). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <time.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include "test_util.h"

/* A flat sheet of nx x ny quads (2 nx ny triangles), `size` x `size`, in the plane z = height. */
static sdfccd_MeshId make_sheet_xy(int nx, int ny, double size, double height)
{
    int nv = (nx + 1) * (ny + 1);
    double* v = malloc(sizeof(double) * 3 * (size_t)nv);
    uint32_t* idx = malloc(sizeof(uint32_t) * 6 * (size_t)(nx * ny));
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) {
            double* p = v + 3 * (j * (nx + 1) + i);
            p[0] = size * ((double)i / nx - 0.5);
            p[1] = size * ((double)j / ny - 0.5);
            p[2] = height;
        }
    uint32_t* f = idx;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            uint32_t a = (uint32_t)(j * (nx + 1) + i), b = a + 1, c = a + (uint32_t)(nx + 1), d = c + 1;
            *f++ = a; *f++ = b; *f++ = d;
            *f++ = a; *f++ = d; *f++ = c;
        }
    sdfccd_MeshDef d = sdfccd_default_mesh_def();
    d.vertices = v;
    d.vertex_count = (uint32_t)nv;
    d.indices = idx;
    d.triangle_count = (uint32_t)(2 * nx * ny);
    sdfccd_MeshId mesh;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &mesh), SDFCCD_OK);
    free(v);
    free(idx);
    return mesh;
}

/* A flat sheet of n x n quads (2 n^2 triangles) of side `size` in the plane z = height. */
static sdfccd_MeshId make_sheet(int n, double size, double height)
{
    return make_sheet_xy(n, n, size, height);
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

/* SDF evaluations are the unit of cost the library reports: every call of a user's field is one counted
 * evaluation (nothing computed ahead and thrown away), for a query that hits, one that grazes past, and at
 * every evaluation budget. */
static double counted_sphere(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    ++*(int64_t*)user;
    const double l = sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    if (g) *g = l > 0.0 ? (sdfccd_Vec3){ p.x / l, p.y / l, p.z / l } : (sdfccd_Vec3){ 0.0, 0.0, 1.0 };
    return l - 1.0;
}

/* The same with the point as three coordinates (sdfccd_CallbackSdfDef::eval_xyz). */
static double counted_sphere_xyz(double x, double y, double z, sdfccd_Vec3* g, void* user)
{
    return counted_sphere((sdfccd_Vec3){ x, y, z }, g, user);
}

/* A user field declared smooth with the given bounds: the point as an sdfccd_Vec3 (eval) when eval is
 * set, else as three coordinates (eval_xyz). */
static sdfccd_SdfId smooth_callback(sdfccd_SdfEvalFcn* eval, sdfccd_SdfEvalXyzFcn* eval_xyz, void* user, sdfccd_Aabb bounds)
{
    sdfccd_CallbackSdfDef d = sdfccd_default_callback_sdf_def();
    if (eval) d.eval = eval;
    else d.eval_xyz = eval_xyz;
    d.user = user;
    d.bounds = bounds;
    d.smooth = 1;
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_callback_sdf(&d, &s), SDFCCD_OK);
    return s;
}

START_TEST(test_field_calls_are_counted)
{
    int64_t calls = 0;
    /* _i: 0 the point as an sdfccd_Vec3 (eval), 1 as three coordinates (eval_xyz) */
    const sdfccd_SdfId s = smooth_callback(_i == 0 ? counted_sphere : NULL, counted_sphere_xyz, &calls, (sdfccd_Aabb){ { -1, -1, -1 }, { 1, 1, 1 } });
    /* z = 1.0005 slides 0.5 mm over the top (the traces' steps shrink there); z = 0.5 hits */
    const double heights[2] = { 1.0005, 0.5 };
    for (int k = 0; k < 2; ++k) {
        const double z = heights[k];
        const sdfccd_Vec3 tri[3] = { { 2, 0, z }, { 2.5, 0, z }, { 2, 0.5, z } };
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        m.linear_velocity.x = -4.0;
        m.local_center = (sdfccd_Vec3){ 2.17, 0.17, z }; /* spin about the triangle's centroid */
        m.angular_velocity.z = 3.0;
        for (int method = 0; method < SDFCCD_METHOD_COUNT; ++method) {
            sdfccd_QueryParams p = sdfccd_default_query_params();
            p.method = (sdfccd_Method)method;
            sdfccd_QueryResult r;
            calls = 0;
            ck_assert_int_eq(sdfccd_query_triangle(s, NULL, tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_OK);
            if (method == SDFCCD_METHOD_FWGSS || method == SDFCCD_METHOD_CERTIFIED) ck_assert_int_eq(r.hit, k);
            ck_assert_int_gt(calls, 0);
            ck_assert_int_eq(calls, r.sdf_evaluations);
            for (int64_t budget = 1; budget <= 40; budget += 3) {
                calls = 0;
                p.max_sdf_evaluations = budget;
                ck_assert_int_eq(sdfccd_query_triangle(s, NULL, tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_OK);
                ck_assert_int_eq(calls, r.sdf_evaluations);
            }
        }
    }
    sdfccd_destroy_sdf(s);
}
END_TEST

/* A user's gradient with an infinite or NaN coordinate is never handed on: the solvers and the
 * contacts get (0, 0, 1) in its place (scc_sdf_user_value), whichever coordinate is bad, in either form
 * of the function (_i: 0 eval, 1 eval_xyz). The field is the half-space z <= 0, whose true gradient is
 * that fallback, so the query still hits at the time the plane is reached. */
static double bad_gradient_plane(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    if (g) *g = *(const sdfccd_Vec3*)user;
    return p.z;
}

static double bad_gradient_plane_xyz(double x, double y, double z, sdfccd_Vec3* g, void* user)
{
    return bad_gradient_plane((sdfccd_Vec3){ x, y, z }, g, user);
}

START_TEST(test_user_gradient_not_finite)
{
    const sdfccd_Vec3 bad[4] = { { INFINITY, 0, 1 }, { 0, NAN, 1 }, { 0, 0, -INFINITY }, { NAN, NAN, NAN } };
    for (int k = 0; k < 4; ++k) {
        sdfccd_Vec3 grad = bad[k];
        const sdfccd_SdfId s = smooth_callback(_i == 0 ? bad_gradient_plane : NULL, bad_gradient_plane_xyz, &grad,
                                               (sdfccd_Aabb){ { -10, -10, -10 }, { 10, 10, 0 } });
        const sdfccd_Vec3 tri[3] = { { 0, 0, 1 }, { 0.5, 0, 1 }, { 0, 0.5, 1 } };
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        m.linear_velocity.z = -4.0; /* reaches the plane at t = 0.25 */
        sdfccd_QueryParams p = sdfccd_default_query_params();
        sdfccd_Contact c[8];
        sdfccd_QueryResult r;
        ck_assert_int_eq(sdfccd_query_triangle(s, NULL, tri, &m, 0, 1, &p, c, 8, &r), SDFCCD_OK);
        ck_assert_int_eq(r.hit, 1);
        ck_assert(fabs(r.toi - 0.25) < 1e-6);
        ck_assert_int_gt(r.contact_count, 0);
        for (int i = 0; i < r.contact_count; ++i) {
            ck_assert_double_eq(c[i].normal.x, 0.0);
            ck_assert_double_eq(c[i].normal.y, 0.0);
            ck_assert_double_eq(c[i].normal.z, 1.0);
        }
        sdfccd_destroy_sdf(s);
    }
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
    const int32_t bad_guard[2] = { -1, 3 }; /* fwgss_kink_guard is 0, 1 or 2 */
    for (int k = 0; k < 2; ++k) {
        p = sdfccd_default_query_params();
        p.fwgss_kink_guard = bad_guard[k];
        ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
        ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "fwgss_kink_guard"));
        p = sdfccd_default_query_params();
        p.fwgss_verify = bad_guard[k] < 0 ? -1 : 2; /* fwgss_verify is 0 or 1 */
        ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
        ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "fwgss_verify"));
    }
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

/* The mesh queries name the bad argument in their message ("function: argument"), though the name is
 * built only when a check fails (ccd_api.c, convert_arg: a failed conversion runs again with it). */
START_TEST(test_query_argument_names)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &s), SDFCCD_OK);
    sdfccd_MeshId mesh = make_sheet(1, 0.5, 2.0);
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_QueryResult r;
    sdfccd_RigidMotion ok = sdfccd_default_rigid_motion(), bad = ok;
    bad.linear_velocity.y = NAN;
    ck_assert_int_eq(sdfccd_query_mesh(s, NULL, mesh, &ok, 0, 1, &p, NULL, 0, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_query_mesh: out_result is NULL");
    ck_assert_int_eq(sdfccd_query_mesh(s, NULL, mesh, NULL, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_query_mesh: motion is NULL");
    ck_assert_int_eq(sdfccd_query_mesh(s, NULL, mesh, &bad, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "sdfccd_query_mesh: motion is not finite"));
    ck_assert_int_eq(sdfccd_query_mesh(s, &bad, mesh, &ok, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "sdfccd_query_mesh: sdf_motion is not finite"));
    ck_assert_int_eq(sdfccd_query_mesh(s, &ok, mesh, &ok, 0, 1, &p, NULL, 0, &r), SDFCCD_OK); /* both valid */
    sdfccd_Vec3 v[4] = { { 0, 0, 2 }, { 1, 0, 2 }, { 0, 1, 2 }, { 1, 1, 2 } };
    ck_assert_int_eq(sdfccd_query_mesh_linear(s, NULL, mesh, NULL, v, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_query_mesh_linear: start is NULL");
    ck_assert_int_eq(sdfccd_query_mesh_linear(s, NULL, mesh, v, NULL, 0, 1, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_query_mesh_linear: end is NULL");
    sdfccd_destroy_mesh(mesh);
    sdfccd_destroy_sdf(s);
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

/* Finding "NaN behind OK": |p| >~ 1.3e154 overflowed sqrt(x^2 + y^2) on the torus and the
 * cylinder. Every analytic SDF now gives the exact, finite distance far away. */
START_TEST(test_analytic_far_points_finite)
{
    sdfccd_SdfId shapes[6];
    ck_assert_int_eq(sdfccd_create_torus(1.0, 0.25, &shapes[0]), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_cylinder(1.0, 0.5, &shapes[1]), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &shapes[2]), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 1, 2, 3 }, &shapes[3]), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_capsule(1.0, 0.5, &shapes[4]), SDFCCD_OK);
    sdfccd_SpikeGridDef sg = sdfccd_default_spike_grid_def();
    ck_assert_int_eq(sdfccd_create_spike_grid(&sg, &shapes[5]), SDFCCD_OK);
    const double mags[3] = { 1e154, 1e200, 1e300 };
    for (int k = 0; k < 6; ++k)
        for (int m = 0; m < 3; ++m) {
            /* along the diagonal (x, x, x): the distance is |p| sqrt(3) to within the shape's size */
            double x = mags[m];
            sdfccd_Vec3 p = { x, x, x * (k == 5 ? 1.0 : 1.0) }, g;
            double v;
            ck_assert_int_eq(sdfccd_sdf_eval(shapes[k], p, &v, &g), SDFCCD_OK);
            ck_assert_msg(isfinite(v) && isfinite(g.x) && isfinite(g.y) && isfinite(g.z), "shape %d at %g: %g", k, x, v);
            if (k < 5) ck_assert_double_near(v / (x * sqrt(3.0)), 1.0, 1e-12);
            else ck_assert_double_near(v / x, 1.0, 1e-12); /* the ground plane z = 0 is nearest */
            ck_assert_double_near(sqrt(g.x * g.x + g.y * g.y + g.z * g.z), 1.0, 1e-12);
        }
    /* and tiny offsets (squares underflowing) still give a unit gradient */
    sdfccd_Vec3 g;
    double v;
    ck_assert_int_eq(sdfccd_sdf_eval(shapes[2], (sdfccd_Vec3){ 1e-200, 0, 0 }, &v, &g), SDFCCD_OK);
    ck_assert_double_near(v, -1.0, 0.0);
    ck_assert_double_near(g.x, 1.0, 1e-15);
    for (int k = 0; k < 6; ++k) sdfccd_destroy_sdf(shapes[k]);
}
END_TEST

/* Finding "NaN behind OK": a transformed SDF with scale 1e-200 gave NaN at every point. Scales
 * are limited to [1e-100, 1e100]; at the limits evaluations are finite and exact. */
START_TEST(test_transform_scale_limits)
{
    sdfccd_SdfId s, t;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &s), SDFCCD_OK);
    sdfccd_Pose id = sdfccd_pose_identity();
    ck_assert_int_eq(sdfccd_create_transformed(s, id, 1e-200, &t), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_transformed(s, id, 1e200, &t), SDFCCD_INVALID_ARGUMENT);
    sdfccd_Pose far = id;
    far.position.x = 1e200;
    ck_assert_int_eq(sdfccd_create_transformed(s, far, 1.0, &t), SDFCCD_INVALID_ARGUMENT);
    const double scales[2] = { 1e-100, 1e100 };
    for (int k = 0; k < 2; ++k) {
        ck_assert_int_eq(sdfccd_create_transformed(s, id, scales[k], &t), SDFCCD_OK);
        const double pts[4] = { 1.0, 1e100, 1e200, 1e300 };
        for (int i = 0; i < 4; ++i) {
            double v;
            sdfccd_Vec3 g;
            ck_assert_int_eq(sdfccd_sdf_eval(t, (sdfccd_Vec3){ 0, pts[i], 0 }, &v, &g), SDFCCD_OK);
            ck_assert_msg(isfinite(v) && isfinite(g.y), "scale %g at %g: %g", scales[k], pts[i], v);
            ck_assert_double_near(g.y, 1.0, 1e-12);
            if (pts[i] / scales[k] > 1e300) { /* clamped in the child's frame: a finite underestimate */
                ck_assert(v > 0.0 && v <= pts[i]);
                continue;
            }
            ck_assert_double_near(v, pts[i] - scales[k], 1e-12 * fmax(pts[i], scales[k])); /* |p| - scale * radius */
        }
        sdfccd_destroy_sdf(t);
    }
    sdfccd_destroy_sdf(s);
}
END_TEST

static double nan_field(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    (void)user;
    if (g) *g = (sdfccd_Vec3){ 0, 0, 1 };
    return p.z > 0.05 ? p.z : NAN;
}

/* Finding "NaN behind OK": CSG's fmin/fmax dropped a NaN operand, so a NaN point "touched"
 * (hit = 1 with NaN contacts). A NaN operand now makes the combination NaN, which never touches,
 * and an OK result has only finite contacts. The plane z = 0 united with a field that is NaN for
 * z <= 0.05 and z above: the union is NaN wherever the plane would be touched and equals that
 * field elsewhere, so a triangle falling through z = 0 must give, for every method, exactly the
 * result of the NaN field alone (no hit, no contact), while the plane alone is hit at t = 0.5
 * (DCD: at the end pose). */
START_TEST(test_csg_nan_operand)
{
    sdfccd_SdfId plane, cb, csg[3];
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &plane), SDFCCD_OK);
    sdfccd_CallbackSdfDef d = sdfccd_default_callback_sdf_def();
    d.eval = nan_field;
    ck_assert_int_eq(sdfccd_create_callback_sdf(&d, &cb), SDFCCD_OK);
    const sdfccd_CsgOp ops[3] = { SDFCCD_CSG_UNION, SDFCCD_CSG_INTERSECTION, SDFCCD_CSG_DIFFERENCE };
    for (int k = 0; k < 3; ++k) {
        ck_assert_int_eq(sdfccd_create_csg(ops[k], plane, cb, &csg[k]), SDFCCD_OK);
        double v;
        sdfccd_Vec3 g;
        ck_assert_int_eq(sdfccd_sdf_eval(csg[k], (sdfccd_Vec3){ 0, 0, 0 }, &v, &g), SDFCCD_OK);
        ck_assert_msg(isnan(v) && isnan(g.z), "op %d: %g with a NaN operand", k, v);
        ck_assert_int_eq(sdfccd_sdf_eval(csg[k], (sdfccd_Vec3){ 0, 0, 1 }, &v, NULL), SDFCCD_OK);
        ck_assert_double_eq(v, 1.0); /* min(1, 1), max(1, 1), max(1, -1): finite operands combine as before */
    }
    sdfccd_SdfId u = csg[0];
    sdfccd_Vec3 tri[3] = { { 0, 0, 0.5 }, { 0.1, 0, 0.5 }, { 0, 0.1, 0.5 } };
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity.z = -1.0;
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_Contact c[8];
    sdfccd_QueryResult r, ref, pl;
    for (int method = 0; method < SDFCCD_METHOD_COUNT; ++method) {
        p.method = (sdfccd_Method)method;
        ck_assert_int_eq(sdfccd_query_triangle(plane, NULL, tri, &m, 0, 1, &p, c, 8, &pl), SDFCCD_OK);
        const double plane_toi = method == SDFCCD_METHOD_DCD ? 1.0 : 0.5; /* DCD looks at the end pose only */
        ck_assert_msg(pl.hit && fabs(pl.toi - plane_toi) <= 1e-6, "method %d: the plane alone hit %d at %.9g", method, pl.hit, pl.toi);
        ck_assert_int_eq(sdfccd_query_triangle(cb, NULL, tri, &m, 0, 1, &p, c, 8, &ref), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_query_triangle(u, NULL, tri, &m, 0, 1, &p, c, 8, &r), SDFCCD_OK);
        ck_assert_msg(!r.hit && r.contact_count == 0 && r.contacts_found == 0, "method %d: the NaN union touched (hit %d at %.9g, %d contacts)",
                      method, r.hit, r.toi, r.contacts_found);
        ck_assert_msg(r.hit == ref.hit && r.state == ref.state && r.toi == ref.toi && r.toi_lower == ref.toi_lower,
                      "method %d: union state %d toi %.9g lower %.9g, NaN field alone state %d toi %.9g lower %.9g", method, r.state, r.toi,
                      r.toi_lower, ref.state, ref.toi, ref.toi_lower);
        ck_assert(isfinite(r.toi) && isfinite(r.fraction));
    }
    for (int k = 0; k < 3; ++k) sdfccd_destroy_sdf(csg[k]);
    sdfccd_destroy_sdf(cb);
    sdfccd_destroy_sdf(plane);
}
END_TEST

static unsigned char* read_all(const char* path, size_t* out_size)
{
    FILE* f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char* b = malloc((size_t)n);
    ck_assert_int_eq(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *out_size = (size_t)n;
    return b;
}

/* Findings on .cdf files: a domain of +-1e308 loaded (every evaluation NaN); node values of
 * 1e154 loaded (infinite value, NaN gradient, infinite Lipschitz bound); a directory reported
 * out of memory (a 9.2e18-byte request); an empty node array called memcpy(NULL, src, 0). */
START_TEST(test_cdf_overflow_and_files)
{
    size_t n;
    unsigned char* b = read_all(SDFCCD_DATA_DIR "/sdf/upstream/box.cdf", &n);
    sdfccd_SdfId g;
    ck_assert_int_eq(sdfccd_load_grid_memory(b, n, &g), SDFCCD_OK);
    sdfccd_destroy_sdf(g);
    unsigned char* m = malloc(n);
    /* domain -1e308 .. 1e308 on every axis (cell size and its inverse follow) */
    memcpy(m, b, n);
    uint32_t res[3];
    memcpy(res, m + 48, 12);
    for (int i = 0; i < 3; ++i) {
        double lo = -1e308, hi = 1e308, h = hi / res[i] * 2.0, ih = 1.0 / h;
        memcpy(m + 8 * i, &lo, 8);
        memcpy(m + 24 + 8 * i, &hi, 8);
        memcpy(m + 60 + 8 * i, &h, 8);
        memcpy(m + 84 + 8 * i, &ih, 8);
    }
    ck_assert_int_eq(sdfccd_load_grid_memory(m, n, &g), SDFCCD_FORMAT_ERROR);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "domain"));
    /* node 0 of field 0 (after the 124-byte header, the array count and the node count) = 1e154 */
    memcpy(m, b, n);
    const double huge = 1e154;
    memcpy(m + 140, &huge, 8);
    ck_assert_int_eq(sdfccd_load_grid_memory(m, n, &g), SDFCCD_FORMAT_ERROR);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "node value"));
    /* a field with empty node and cell arrays */
    unsigned char e[124 + 8 + 8 + 8 + 8 + 8 + 8 + 4];
    memcpy(e, b, 124);
    const uint64_t one = 1, zero = 0, cells = 1;
    const uint32_t r1[3] = { 1, 1, 1 };
    memcpy(e + 48, r1, 12);
    for (int i = 0; i < 3; ++i) { /* one cell: h = extent */
        double lo, hi;
        memcpy(&lo, e + 8 * i, 8);
        memcpy(&hi, e + 24 + 8 * i, 8);
        double h = hi - lo, ih = 1.0 / h;
        memcpy(e + 60 + 8 * i, &h, 8);
        memcpy(e + 84 + 8 * i, &ih, 8);
    }
    memcpy(e + 108, &cells, 8);
    memcpy(e + 116, &one, 8);
    memcpy(e + 124, &one, 8);  /* node arrays: 1 */
    memcpy(e + 132, &zero, 8); /*   count 0 */
    memcpy(e + 140, &one, 8);  /* cell arrays: 1 */
    memcpy(e + 148, &zero, 8); /*   count 0 */
    memcpy(e + 156, &one, 8);  /* cell maps: 1 */
    memcpy(e + 164, &cells, 8);
    const uint32_t none = 0xFFFFFFFFu;
    memcpy(e + 172, &none, 4);
    ck_assert_int_eq(sdfccd_load_grid_memory(e, sizeof e, &g), SDFCCD_FORMAT_ERROR);
    /* a directory */
    ck_assert_int_eq(sdfccd_load_grid(SDFCCD_DATA_DIR, &g), SDFCCD_IO_ERROR);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "not a regular file"));
    free(m);
    free(b);
}
END_TEST

static void write_file(const char* path, const char* text)
{
    FILE* f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

/* Files: a directory is an I/O error, not an out-of-memory (.cdf) or a hang (mesh); callers can
 * refuse formats and cap the file size; assimp validates its data before its asserting steps
 * (an OFF file declaring 5 vertices but holding 4 aborted the process, found by fuzz_mesh). */
START_TEST(test_mesh_files)
{
    sdfccd_MeshId m;
    sdfccd_MeshLoadDef d = sdfccd_default_mesh_load_def();
    ck_assert_int_eq(sdfccd_load_mesh(SDFCCD_DATA_DIR, &d, &m), SDFCCD_IO_ERROR);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "not a regular file"));
    ck_assert_int_eq(sdfccd_load_mesh("/dev/zero", &d, &m), SDFCCD_IO_ERROR);
    const char* obj = SDFCCD_TEST_TMP_DIR "/hardening_tri.obj";
    write_file(obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    ck_assert_int_eq(sdfccd_load_mesh(obj, &d, &m), SDFCCD_OK);
    sdfccd_destroy_mesh(m);
    d.formats = "stl;OBJ";
    ck_assert_int_eq(sdfccd_load_mesh(obj, &d, &m), SDFCCD_OK);
    sdfccd_destroy_mesh(m);
    d.formats = "stl;off";
    ck_assert_int_eq(sdfccd_load_mesh(obj, &d, &m), SDFCCD_UNSUPPORTED);
    d.formats = "ob";
    ck_assert_int_eq(sdfccd_load_mesh(obj, &d, &m), SDFCCD_UNSUPPORTED);
    d.formats = NULL;
    d.max_file_bytes = 10;
    ck_assert_int_eq(sdfccd_load_mesh(obj, &d, &m), SDFCCD_UNSUPPORTED);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "max_file_bytes"));
    d.max_file_bytes = 0;
    ck_assert_int_eq(sdfccd_load_mesh(obj, &d, &m), SDFCCD_INVALID_ARGUMENT);
    remove(obj);
    if (strstr(sdfccd_configuration_string(), "assimp=1")) {
        const char* off = SDFCCD_TEST_TMP_DIR "/hardening_bad.off";
        write_file(off, "OFF\n5 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
        d = sdfccd_default_mesh_load_def();
        ck_assert_int_eq(sdfccd_load_mesh(off, &d, &m), SDFCCD_FORMAT_ERROR);
        remove(off);
    }
}
END_TEST

/* Finding "concurrent destroy": destroying an SDF (or a mesh) while other threads query it
 * jumped to freed memory. Queries now hold a reference while they run: every query returns OK
 * or INVALID_HANDLE (once the destroy is visible), never a crash, and all memory returns. Run
 * under ASan (use after free) and TSan (scripts/tsan.sh) this is the regression test. */
typedef struct racer {
    sdfccd_SdfId sdf;
    sdfccd_MeshId mesh;
    _Atomic int ok, invalid, other, started, total;
} racer;

static void* race_queries(void* arg)
{
    racer* r = arg;
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.z = 0.3;
    m.linear_velocity.z = -1.0;
    m.angular_velocity.x = 3.0;
    static const sdfccd_Vec3 tri[3] = { { 0, 0, 0 }, { 0.1, 0, 0 }, { 0, 0.1, 0 } };
    /* At least 400 calls, then on until the destroy is seen (the main thread destroys once every
     * racer has started, so this ends; under valgrind, which runs one thread at a time, a fixed
     * count could finish before the destroy). */
    for (int i = 0; i < 400 || (r->invalid == 0 && i < 10000000); ++i) {
        sdfccd_Contact c[8];
        sdfccd_QueryResult res;
        sdfccd_Status st = (i & 1) ? sdfccd_query_mesh(r->sdf, NULL, r->mesh, &m, 0, 1, &p, c, 8, &res)
                                   : sdfccd_query_triangle(r->sdf, NULL, tri, &m, 0, 1, &p, c, 8, &res);
        double v;
        sdfccd_Status se = sdfccd_sdf_eval(r->sdf, (sdfccd_Vec3){ 0, 0, 1 }, &v, NULL);
        if (st == SDFCCD_OK && (se == SDFCCD_OK || se == SDFCCD_INVALID_HANDLE)) r->ok++;
        else if (st == SDFCCD_INVALID_HANDLE) r->invalid++;
        else r->other++;
        r->total++;
        if (i == 0) r->started++;
    }
    return NULL;
}

START_TEST(test_destroy_while_querying)
{
    for (int round = 0; round < 6; ++round) {
        racer r;
        memset(&r, 0, sizeof r);
        sdfccd_SdfId a, b;
        ck_assert_int_eq(sdfccd_create_sphere(0.2, &a), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_create_torus(0.3, 0.05, &b), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, a, b, &r.sdf), SDFCCD_OK);
        sdfccd_destroy_sdf(a); /* the union keeps its children */
        sdfccd_destroy_sdf(b);
        r.mesh = make_sheet(4, 0.2, 0.0);
        pthread_t t[3];
        for (int i = 0; i < 3; ++i) ck_assert_int_eq(pthread_create(&t[i], NULL, race_queries, &r), 0);
        /* let every racer finish a first call, then destroy both handles under them */
        const struct timespec poll = { 0, 50000L };
        while (r.started < 3) nanosleep(&poll, NULL);
        struct timespec ts = { 0, 200000L * (round + 1) };
        nanosleep(&ts, NULL);
        ck_assert_int_eq(sdfccd_destroy_sdf(r.sdf), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_destroy_mesh(r.mesh), SDFCCD_OK);
        for (int i = 0; i < 3; ++i) pthread_join(t[i], NULL);
        ck_assert_int_eq(r.other, 0);
        ck_assert_int_eq(r.ok + r.invalid, r.total);
        ck_assert_int_ge(r.total, 3 * 400);
        ck_assert_int_gt(r.invalid, 0); /* the destroy was seen */
    }
}
END_TEST

/* The handle registry uses the user's allocator and is freed with the last handle (valgrind
 * reported 1,536 bytes still reachable in every test): byte_count counts it and returns to 0. */
START_TEST(test_registry_in_user_allocator)
{
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    sdfccd_SdfId s[100];
    for (int i = 0; i < 100; ++i) ck_assert_int_eq(sdfccd_create_sphere(1.0, &s[i]), SDFCCD_OK);
    sdfccd_SdfInfo info;
    ck_assert_int_eq(sdfccd_sdf_get_info(s[0], &info), SDFCCD_OK);
    ck_assert_int_gt(sdfccd_byte_count(), 100 * info.memory_bytes); /* the table (128 slots) is counted */
    for (int i = 0; i < 100; ++i) ck_assert_int_eq(sdfccd_destroy_sdf(s[i]), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    /* stale handles stay invalid after the table was freed and rebuilt */
    sdfccd_SdfId fresh;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &fresh), SDFCCD_OK);
    double v;
    for (int i = 0; i < 100; ++i) ck_assert_int_eq(sdfccd_sdf_eval(s[i], (sdfccd_Vec3){ 0, 0, 0 }, &v, NULL), SDFCCD_INVALID_HANDLE);
    ck_assert_int_eq(sdfccd_destroy_sdf(fresh), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_byte_count(), 0);
}
END_TEST

/* Finding "memory": a 849^3 grid made one 32.7 GB request and extraction at resolution 1024 asked
 * for 8.3 GB. Both now compare the size they need with a limit first. */
START_TEST(test_memory_limits)
{
    sdfccd_SdfId s, g;
    sdfccd_MeshId m;
    ck_assert_int_eq(sdfccd_create_sphere(0.5, &s), SDFCCD_OK);
    sdfccd_GridDef d = sdfccd_default_grid_def();
    d.resolution[0] = d.resolution[1] = d.resolution[2] = 849;
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(s, &d, &g), SDFCCD_OUT_OF_MEMORY);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "max_bytes"));
    d.resolution[0] = d.resolution[1] = d.resolution[2] = 8;
    d.max_bytes = 1000;
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(s, &d, &g), SDFCCD_OUT_OF_MEMORY);
    d.max_bytes = 0;
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(s, &d, &g), SDFCCD_INVALID_ARGUMENT);
    d.max_bytes = 1 << 20;
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(s, &d, &g), SDFCCD_OK);
    sdfccd_destroy_sdf(g);
    sdfccd_Aabb box = { { -1, -1, -1 }, { 1, 1, 1 } };
    ck_assert_int_eq(sdfccd_extract_isosurface(s, box, 1024, &m), SDFCCD_OUT_OF_MEMORY);
    ck_assert_int_eq(sdfccd_extract_isosurface(s, box, 16, &m), SDFCCD_OK);
    sdfccd_destroy_mesh(m);
    sdfccd_destroy_sdf(s);
}
END_TEST


/* Peak of the library's allocations, through the allocator hooks. */
typedef struct peak_counter { int64_t now, peak; } peak_counter;
static void* peak_alloc(size_t n, void* user)
{
    peak_counter* c = user;
    c->now += (int64_t)n;
    if (c->now > c->peak) c->peak = c->now;
    return malloc(n);
}
static void peak_free(void* p, size_t n, void* user)
{
    peak_counter* c = user;
    c->now -= (int64_t)n;
    free(p);
}

/* Finding "memory": CERTIFIED on a triangle sliding 1 nm above a non-convex surface (the torus's
 * top circle, which the Lipschitz bound cannot prune) held 96 MiB of regions before the
 * evaluation budget stopped it, and on a 1,656-triangle sheet it ran 23.7 s. The region store is
 * now capped by certified_max_bytes: the query stops there with NOT_CONVERGED and the earliest
 * witness, and nothing it allocates at once passes the cap. */
START_TEST(test_certified_memory_cap)
{
    peak_counter c = { 0, 0 };
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    ck_assert_int_eq(sdfccd_set_allocator(peak_alloc, peak_free, &c), SDFCCD_OK);
    sdfccd_SdfId torus;
    ck_assert_int_eq(sdfccd_create_torus(1.0, 0.25, &torus), SDFCCD_OK);
    const double z = 0.25 + 1e-9;
    const sdfccd_Vec3 tri[3] = { { 0.5, -0.3, z }, { 1.5, -0.3, z }, { 1.0, 0.4, z } };
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity.x = 0.5;
    sdfccd_QueryParams p = sdfccd_default_query_params();
    p.method = SDFCCD_METHOD_CERTIFIED;
    p.max_sdf_evaluations = 5000000; /* the budget of the 96 MiB finding: the memory cap must stop it first */
    ck_assert_int_eq(p.certified_max_bytes, SDFCCD_DEFAULT_CERTIFIED_MAX_BYTES);
    sdfccd_QueryResult r;
    sdfccd_Contact ct[8];

    /* The default cap, then smaller ones: the peak stays under each, and the cap (not the
     * evaluation budget) is what stopped the search. No contact: the triangle stays 1 nm above,
     * and the search never got past the start, so nothing later than t0 is claimed. */
    const int64_t caps[3] = { SDFCCD_DEFAULT_CERTIFIED_MAX_BYTES, 1 << 20, 100000 };
    for (int k = 0; k < 3; ++k) {
        p.certified_max_bytes = caps[k];
        const int64_t before = c.now;
        c.peak = c.now;
        ck_assert_int_eq(sdfccd_query_triangle(torus, NULL, tri, &m, 0, 1, &p, ct, 8, &r), SDFCCD_OK);
        const int64_t peak = c.peak - before;
        fprintf(stderr, "sliding 1 nm above the torus, cap %lld: peak %lld bytes, %lld evaluations, state %d\n", (long long)caps[k],
                (long long)peak, (long long)r.sdf_evaluations, (int)r.state);
        ck_assert_int_le(peak, caps[k]);
        ck_assert_int_gt(peak, caps[k] / 2); /* it did fill the store (the cap is what bounds it) */
        ck_assert_int_lt(r.sdf_evaluations, p.max_sdf_evaluations);
        ck_assert_int_eq(r.state, SDFCCD_STATE_NOT_CONVERGED);
        ck_assert_int_eq(r.hit, 0);
        ck_assert(r.toi == 1.0 && r.fraction == 1.0);
        ck_assert(r.toi_lower == 0.0);
    }
    /* A cap below one region: nothing is allocated, nothing is proven. */
    p.certified_max_bytes = 1;
    c.peak = c.now;
    int64_t before = c.now;
    ck_assert_int_eq(sdfccd_query_triangle(torus, NULL, tri, &m, 0, 1, &p, ct, 8, &r), SDFCCD_OK);
    ck_assert_int_eq(c.peak, before);
    ck_assert_int_eq(r.state, SDFCCD_STATE_NOT_CONVERGED);
    ck_assert(r.toi == 1.0 && r.toi_lower == 0.0 && r.hit == 0);
    p.certified_max_bytes = 0;
    ck_assert_int_eq(sdfccd_query_triangle(torus, NULL, tri, &m, 0, 1, &p, ct, 8, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "certified_max_bytes"));
    p.certified_max_bytes = SDFCCD_DEFAULT_CERTIFIED_MAX_BYTES;

    /* The same slide with a ball ahead (union with the torus): the capped search keeps its
     * witness. The true TOI is the ball's alone (the torus is never touched), which the convex
     * ball's own certified search brackets; the witness is a real contact at or after it. */
    sdfccd_SdfId sphere, ball, both;
    ck_assert_int_eq(sdfccd_create_sphere(0.3, &sphere), SDFCCD_OK);
    sdfccd_Pose pose = { { 1.8, 0.0, 0.5 }, { 1, 0, 0, 0 } };
    ck_assert_int_eq(sdfccd_create_transformed(sphere, pose, 1.0, &ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, torus, ball, &both), SDFCCD_OK);
    sdfccd_QueryResult alone;
    ck_assert_int_eq(sdfccd_query_triangle(ball, NULL, tri, &m, 0, 1, &p, NULL, 0, &alone), SDFCCD_OK);
    ck_assert_int_eq(alone.state, SDFCCD_STATE_HIT);
    p.certified_max_bytes = 1 << 20;
    c.peak = c.now;
    before = c.now;
    ck_assert_int_eq(sdfccd_query_triangle(both, NULL, tri, &m, 0, 1, &p, ct, 8, &r), SDFCCD_OK);
    ck_assert_int_le(c.peak - before, p.certified_max_bytes);
    ck_assert_int_eq(r.state, SDFCCD_STATE_NOT_CONVERGED);
    ck_assert_int_eq(r.hit, 1);
    ck_assert_int_ge(r.contact_count, 1);
    ck_assert(r.toi >= alone.toi_lower && r.toi <= 1.0);
    ck_assert(r.toi_lower <= alone.toi_lower);
    ck_assert(ct[0].distance <= p.margin && ct[0].toi == r.toi);
    double v;
    ck_assert_int_eq(sdfccd_sdf_eval(ball, ct[0].point, &v, NULL), SDFCCD_OK);
    ck_assert(v <= 1e-12);
    p.certified_max_bytes = SDFCCD_DEFAULT_CERTIFIED_MAX_BYTES;

    /* The 1,656-triangle sheet 1 nm above the torus, through a workspace warmed by the same query,
     * so that the second query's allocations are the certified searches alone: their peak stays
     * under the cap; no contact; the untested triangles prove nothing, so toi_lower is t0. */
    sdfccd_MeshId sheet = make_sheet_xy(36, 23, 3.0, z);
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    p.certified_max_bytes = 131072;
    ck_assert_int_eq(sdfccd_query_mesh_ws(ws, torus, NULL, sheet, &m, 0, 1, &p, ct, 8, &r), SDFCCD_OK);
    c.peak = c.now;
    before = c.now;
    sdfccd_QueryResult again;
    ck_assert_int_eq(sdfccd_query_mesh_ws(ws, torus, NULL, sheet, &m, 0, 1, &p, ct, 8, &again), SDFCCD_OK);
    fprintf(stderr, "1,656-triangle sheet 1 nm above the torus, cap %lld: peak %lld bytes, %lld evaluations, %lld triangles\n",
            (long long)p.certified_max_bytes, (long long)(c.peak - before), (long long)again.sdf_evaluations,
            (long long)again.triangles_tested);
    ck_assert_int_le(c.peak - before, p.certified_max_bytes);
    ck_assert_int_gt(c.peak - before, p.certified_max_bytes / 2);
    ck_assert_int_eq(again.state, SDFCCD_STATE_NOT_CONVERGED);
    ck_assert_int_eq(again.hit, 0);
    ck_assert(again.toi == 1.0 && again.toi_lower == 0.0);
    ck_assert_int_eq(again.sdf_evaluations, r.sdf_evaluations); /* deterministic */
    sdfccd_destroy_workspace(ws);

    /* A certified query that converges gives the same result bit for bit with any cap it does
     * not reach: the cap changes nothing until the store is full. */
    sdfccd_RigidMotion fall = sdfccd_default_rigid_motion();
    fall.pose.position.z = 0.3;
    fall.local_center = (sdfccd_Vec3){ 1.0, 0.0, z };
    fall.linear_velocity = (sdfccd_Vec3){ 0.3, 0.1, -0.6 };
    fall.angular_velocity = (sdfccd_Vec3){ 0.4, -1.1, 0.7 };
    sdfccd_QueryResult capped, free_run;
    p.certified_max_bytes = SDFCCD_DEFAULT_CERTIFIED_MAX_BYTES;
    ck_assert_int_eq(sdfccd_query_triangle(torus, NULL, tri, &fall, 0, 1, &p, NULL, 0, &capped), SDFCCD_OK);
    p.certified_max_bytes = INT64_MAX;
    ck_assert_int_eq(sdfccd_query_triangle(torus, NULL, tri, &fall, 0, 1, &p, NULL, 0, &free_run), SDFCCD_OK);
    ck_assert_int_eq(capped.state, SDFCCD_STATE_HIT);
    ck_assert(capped.toi == free_run.toi && capped.toi_lower == free_run.toi_lower);
    ck_assert_int_eq(capped.sdf_evaluations, free_run.sdf_evaluations);

    ck_assert_int_eq(sdfccd_destroy_mesh(sheet), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(both), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(sphere), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(torus), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_OK);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("hardening");
    TCase* tc = tcase_create("findings");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_huge_spin_rejected);
    tcase_add_test(tc, test_budget_shared_by_segments);
    tcase_add_loop_test(tc, test_field_calls_are_counted, 0, 2);
    tcase_add_loop_test(tc, test_user_gradient_not_finite, 0, 2);
    tcase_add_test(tc, test_budget_shared_by_triangles);
    tcase_add_test(tc, test_overflowing_query_inputs_rejected);
    tcase_add_test(tc, test_query_argument_names);
    tcase_add_test(tc, test_analytic_far_points_finite);
    tcase_add_test(tc, test_transform_scale_limits);
    tcase_add_test(tc, test_csg_nan_operand);
    tcase_add_test(tc, test_cdf_overflow_and_files);
    tcase_add_test(tc, test_mesh_files);
    tcase_add_test(tc, test_destroy_while_querying);
    tcase_add_test(tc, test_registry_in_user_allocator);
    tcase_add_test(tc, test_memory_limits);
    tcase_add_test(tc, test_certified_memory_cap);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
