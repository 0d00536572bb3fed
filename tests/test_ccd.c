/* SPDX-License-Identifier: MIT
 * CCD against closed-form times of impact (FWGSS and FW), and the paper's failure scenes as
 * small kinematic tests: Fig. 2 (tunnelling twice through a torus), Fig. 12 (a pyramid spinning
 * 360 degrees in one step onto a box) and Fig. 11 (a triangle falling flat on a box face). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "test_util.h"

#define DT (1.0 / 60.0)

static sdfccd_QueryParams params_for(sdfccd_Method m)
{
    sdfccd_QueryParams p = sdfccd_default_query_params();
    p.method = m;
    return p;
}

static sdfccd_RigidMotion translating(sdfccd_Vec3 v)
{
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity = v;
    return m;
}

/* Runs one triangle query and checks the TOI and, when given, the contact point and normal. */
static void expect_toi(sdfccd_SdfId sdf, const sdfccd_Vec3 tri[3], const sdfccd_RigidMotion* m, sdfccd_Method method,
                       double toi, double toi_tol, const sdfccd_Vec3* point, const sdfccd_Vec3* normal)
{
    sdfccd_QueryParams p = params_for(method);
    p.subdivision = 0;
    sdfccd_Contact c[4];
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_triangle(sdf, NULL, tri, m, 0.0, DT, &p, c, 4, &r), SDFCCD_OK);
    ck_assert_msg(r.hit, "method %d: no hit (state %d), expected toi %.9g", method, r.state, toi);
    ck_assert_msg(fabs(r.toi - toi) <= toi_tol, "method %d: toi %.12g, expected %.12g (tol %g)", method, r.toi, toi, toi_tol);
    ck_assert_int_ge(r.contact_count, 1);
    if (point) {
        ck_assert_double_near(c[0].point.x, point->x, 1e-4);
        ck_assert_double_near(c[0].point.y, point->y, 1e-4);
        ck_assert_double_near(c[0].point.z, point->z, 1e-4);
    }
    if (normal) {
        ck_assert_double_near(c[0].normal.x, normal->x, 1e-3);
        ck_assert_double_near(c[0].normal.y, normal->y, 1e-3);
        ck_assert_double_near(c[0].normal.z, normal->z, 1e-3);
    }
    ck_assert_msg(fabs(c[0].distance) <= 1e-4, "contact distance %g", c[0].distance);
}

/* Vertex-first onto the plane z = 0 at 6 m/s: toi = 0.05 / 6. */
START_TEST(test_halfspace_vertex_first)
{
    sdfccd_SdfId plane;
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &plane), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { 0.0, 0.0, 0.05 }, { 0.1, 0.02, 0.08 }, { -0.03, 0.09, 0.1 } };
    sdfccd_RigidMotion m = translating((sdfccd_Vec3){ 0.5, 0.0, -6.0 });
    sdfccd_Vec3 n = { 0, 0, 1 };
    double toi = 0.05 / 6.0;
    sdfccd_Vec3 pt = { 0.5 * toi, 0.0, 0.0 };
    expect_toi(plane, tri, &m, SDFCCD_METHOD_FWGSS, toi, 1e-6, &pt, &n);
    expect_toi(plane, tri, &m, SDFCCD_METHOD_FW, toi, 2e-4, NULL, NULL);
    expect_toi(plane, tri, &m, SDFCCD_METHOD_CERTIFIED, toi, 1e-6, NULL, NULL);
    sdfccd_destroy_sdf(plane);
}
END_TEST

/* A vertex pointing at the centre of a sphere: toi = (h - R) / speed. */
START_TEST(test_sphere_vertex_first)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(0.2, &s), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { 0.0, 0.0, 0.4 }, { 0.08, 0.0, 0.5 }, { -0.04, 0.07, 0.5 } };
    sdfccd_RigidMotion m = translating((sdfccd_Vec3){ 0.0, 0.0, -20.0 });
    double toi = (0.4 - 0.2) / 20.0;
    sdfccd_Vec3 pt = { 0, 0, 0.2 }, n = { 0, 0, 1 };
    expect_toi(s, tri, &m, SDFCCD_METHOD_FWGSS, toi, 1e-6, &pt, &n);
    expect_toi(s, tri, &m, SDFCCD_METHOD_CERTIFIED, toi, 1e-6, NULL, NULL);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* Edge-first onto a box's top face (z = 0.25): the lowest edge is horizontal. */
START_TEST(test_box_face_edge_first)
{
    sdfccd_SdfId box;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.5, 0.5, 0.25 }, &box), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { -0.05, 0.0, 0.30 }, { 0.05, 0.0, 0.30 }, { 0.0, 0.06, 0.38 } };
    sdfccd_RigidMotion m = translating((sdfccd_Vec3){ 0.0, 1.0, -9.0 });
    double toi = 0.05 / 9.0;
    sdfccd_Vec3 n = { 0, 0, 1 };
    expect_toi(box, tri, &m, SDFCCD_METHOD_FWGSS, toi, 1e-6, NULL, &n);
    expect_toi(box, tri, &m, SDFCCD_METHOD_CERTIFIED, toi, 1e-6, NULL, NULL);
    sdfccd_destroy_sdf(box);
}
END_TEST

/* Vertex-first onto a box face, sliding sideways while falling. */
START_TEST(test_box_face_vertex_first)
{
    sdfccd_SdfId box;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.5, 0.5, 0.25 }, &box), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { 0.1, -0.1, 0.27 }, { 0.2, -0.05, 0.33 }, { 0.12, 0.02, 0.31 } };
    sdfccd_RigidMotion m = translating((sdfccd_Vec3){ -3.0, 2.0, -4.0 });
    double toi = 0.02 / 4.0;
    sdfccd_Vec3 pt = { 0.1 - 3.0 * toi, -0.1 + 2.0 * toi, 0.25 }, n = { 0, 0, 1 };
    expect_toi(box, tri, &m, SDFCCD_METHOD_FWGSS, toi, 1e-6, &pt, &n);
    sdfccd_destroy_sdf(box);
}
END_TEST

/* Rotation about the y axis through the centre (0, 0, 0.5): the vertex at +x (r = 1) dips
 * with z = 0.5 - sin(w t), first touching z = 0 at t = asin(0.5) / w. */
START_TEST(test_rotation_onto_plane)
{
    sdfccd_SdfId plane;
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &plane), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { 1.0, 0.0, 0.0 }, { -0.1, 0.05, 0.0 }, { -0.1, -0.05, 0.0 } };
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = (sdfccd_Vec3){ 0.0, 0.0, 0.5 };
    m.angular_velocity = (sdfccd_Vec3){ 0.0, 60.0, 0.0 };
    double toi = asin(0.5) / 60.0;
    sdfccd_Vec3 pt = { cos(60.0 * toi), 0.0, 0.0 }, n = { 0, 0, 1 };
    expect_toi(plane, tri, &m, SDFCCD_METHOD_FWGSS, toi, 1e-6, &pt, &n);
    expect_toi(plane, tri, &m, SDFCCD_METHOD_CERTIFIED, toi, 1e-6, NULL, NULL);
    /* The same with a translation added: the centre also falls at 3 m/s. */
    m.linear_velocity = (sdfccd_Vec3){ 0.0, 0.0, -3.0 };
    /* Solve 0.5 - 3 t - sin(60 t) = 0 by bisection for the reference. */
    double lo = 0.0, hi = asin(0.5) / 60.0;
    for (int i = 0; i < 200; ++i) {
        double mid = 0.5 * (lo + hi);
        if (0.5 - 3.0 * mid - sin(60.0 * mid) > 0.0) lo = mid; else hi = mid;
    }
    expect_toi(plane, tri, &m, SDFCCD_METHOD_FWGSS, hi, 1e-6, NULL, &n);
    sdfccd_destroy_sdf(plane);
}
END_TEST

/* A moving SDF: a plane rising at 5 m/s towards a static triangle 0.05 m above it. */
START_TEST(test_moving_sdf)
{
    sdfccd_SdfId plane;
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &plane), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { 0.0, 0.0, 0.05 }, { 0.1, 0.0, 0.1 }, { 0.0, 0.1, 0.1 } };
    sdfccd_RigidMotion still = sdfccd_default_rigid_motion();
    sdfccd_RigidMotion rising = translating((sdfccd_Vec3){ 0.0, 0.0, 5.0 });
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_Contact c[8];
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_triangle(plane, &rising, tri, &still, 0.0, DT, &p, c, 8, &r), SDFCCD_OK);
    ck_assert(r.hit);
    ck_assert_double_near(r.toi, 0.01, 1e-6);
    ck_assert_double_near(c[0].point.z, 0.05, 1e-5);
    ck_assert_double_near(c[0].normal.z, 1.0, 1e-9);
    sdfccd_destroy_sdf(plane);
}
END_TEST

/* Per-vertex linear motion (cloth): vertices fall at different speeds onto z = 0. */
START_TEST(test_linear_vertices)
{
    sdfccd_SdfId plane;
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &plane), SDFCCD_OK);
    sdfccd_Vec3 s[3] = { { 0, 0, 0.1 }, { 0.1, 0, 0.1 }, { 0, 0.1, 0.1 } };
    sdfccd_Vec3 e[3] = { { 0, 0, 0.05 }, { 0.1, 0, -0.1 }, { 0, 0.1, 0.0 } }; /* vertex 1 crosses at t = DT / 2 */
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_Contact c[8];
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_triangle_linear(plane, NULL, s, e, 0.0, DT, &p, c, 8, &r), SDFCCD_OK);
    ck_assert(r.hit);
    ck_assert_double_near(r.toi, DT / 2, 1e-6);
    ck_assert_double_near(c[0].point.x, 0.1, 1e-4);
    sdfccd_destroy_sdf(plane);
}
END_TEST

/* Fig. 2: a small triangle crosses both sides of a torus tube in one step. The first crossing
 * (leading vertex reaching x = -(R + r)) must be found; DCD at the end pose sees nothing. */
START_TEST(test_torus_tunnel_twice)
{
    const double R = 0.1, r = 0.05;
    sdfccd_SdfId torus;
    ck_assert_int_eq(sdfccd_create_torus(R, r, &torus), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { -0.30, 0.0, 0.0 }, { -0.32, 0.01, 0.0 }, { -0.32, -0.01, 0.005 } };
    double speed = 0.6 / DT; /* ends at x = +0.30, past the far side */
    sdfccd_RigidMotion m = translating((sdfccd_Vec3){ speed, 0.0, 0.0 });
    double toi = (0.30 - (R + r)) / speed;
    sdfccd_Vec3 pt = { -(R + r), 0, 0 }, n = { -1, 0, 0 };
    expect_toi(torus, tri, &m, SDFCCD_METHOD_FWGSS, toi, 1e-6, &pt, &n);
    expect_toi(torus, tri, &m, SDFCCD_METHOD_CERTIFIED, toi, 1e-6, NULL, NULL);
    sdfccd_QueryParams p = params_for(SDFCCD_METHOD_DCD);
    sdfccd_QueryResult res;
    ck_assert_int_eq(sdfccd_query_triangle(torus, NULL, tri, &m, 0.0, DT, &p, NULL, 0, &res), SDFCCD_OK);
    ck_assert_msg(!res.hit, "DCD at the end pose should miss the tunnelling triangle");
    sdfccd_destroy_sdf(torus);
}
END_TEST

/* FWGSS on a 32^3 grid of the smooth torus, triangles flying at the tube from all sides: every
 * answer agrees with the certified search on the grid (FWGSS alone is late on a grazing contact
 * with the tube's top or bottom in one of these, which its certified check corrects), and the
 * check stays affordable: outside the grid's tight domain scc_grid_lipschitz_in bounds |grad phi|
 * by max(1, L), where hypot(1, L) made the check split ~2x more (1,550 evaluations per query). */
/* The torus (R 0.1 m, r 0.05 m) and its 32^3 grid fitted to its box. */
static void torus_grid32(sdfccd_SdfId* torus, sdfccd_SdfId* grid)
{
    ck_assert_int_eq(sdfccd_create_torus(0.1, 0.05, torus), SDFCCD_OK);
    sdfccd_GridDef gd = sdfccd_default_grid_def();
    gd.resolution[0] = gd.resolution[1] = gd.resolution[2] = 32;
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(*torus, &gd, grid), SDFCCD_OK);
}

/* FWGSS (with its check) and the certified search on one triangle of the grid: the same hit, and
 * FWGSS's TOI within 1 us of the certified bracket; returns FWGSS's result. */
static sdfccd_QueryResult fwgss_agrees(sdfccd_SdfId grid, const sdfccd_Vec3 tri[3], const sdfccd_RigidMotion* m, int i)
{
    const sdfccd_QueryParams pf = params_for(SDFCCD_METHOD_FWGSS), pc = params_for(SDFCCD_METHOD_CERTIFIED);
    sdfccd_QueryResult rf, rc;
    ck_assert_int_eq(sdfccd_query_triangle(grid, NULL, tri, m, 0.0, DT, &pf, NULL, 0, &rf), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_query_triangle(grid, NULL, tri, m, 0.0, DT, &pc, NULL, 0, &rc), SDFCCD_OK);
    ck_assert_int_eq(rf.hit, rc.hit);
    if (rc.hit)
        ck_assert_msg(rf.toi <= rc.toi + 1e-6 && rf.toi >= rc.toi_lower - 1e-6, "case %d: FWGSS toi %.9g, certified [%.9g, %.9g]", i, rf.toi,
                      rc.toi_lower, rc.toi);
    return rf;
}

START_TEST(test_torus_grid_check_cheap)
{
    sdfccd_SdfId torus, grid;
    torus_grid32(&torus, &grid);
    const int n = 24;
    long long evals = 0;
    int hits = 0;
    for (int i = 0; i < n; ++i) {
        /* start 0.3 m out on a spiral of directions, aimed at a point of the tube's centre circle */
        const double zc = 1.0 - (2.0 * i + 1.0) / n, rc = sqrt(1.0 - zc * zc), ph = 2.39996 * i, th = 1.1 * i;
        const sdfccd_Vec3 s = { 0.3 * rc * cos(ph), 0.3 * rc * sin(ph), 0.3 * zc }, aim = { 0.1 * cos(th), 0.1 * sin(th), 0.0 };
        const sdfccd_Vec3 tri[3] = { s, { s.x + 0.02, s.y, s.z + 0.005 }, { s.x, s.y + 0.015, s.z - 0.01 } };
        sdfccd_RigidMotion m = translating((sdfccd_Vec3){ (aim.x - s.x) / DT, (aim.y - s.y) / DT, (aim.z - s.z) / DT });
        const sdfccd_QueryResult rf = fwgss_agrees(grid, tri, &m, i);
        evals += (long long)rf.sdf_evaluations;
        hits += rf.hit;
    }
    ck_assert_int_eq(hits, n);
    if (getenv("SDFCCD_TEST_VERBOSE")) fprintf(stderr, "aimed: %.1f evaluations per query\n", (double)evals / n);
    ck_assert_msg(evals <= 1000LL * n, "%.1f evaluations per query on the smooth torus grid", (double)evals / n);
    sdfccd_destroy_sdf(grid);
    sdfccd_destroy_sdf(torus);
}
END_TEST

/* Triangles falling onto the top of the 32^3 torus grid's tube, whose contact lies on the grid's
 * domain boundary (the domain is fitted to the torus's box): the check of FWGSS must still agree
 * with the certified search, and its regions leaving the domain must be bounded by the first-order
 * form outside it (phi = sqrt(d^2 + phi_q^2), certified.c) and across cells by the blocks' gradient
 * intervals rather than by the Lipschitz ball, which cannot slide along the top face (12,946
 * evaluations per query with the ball there; 2,947 now). */
START_TEST(test_torus_grid_top_check_cheap)
{
    sdfccd_SdfId torus, grid;
    torus_grid32(&torus, &grid);
    const int n = 24;
    long long evals = 0;
    for (int i = 0; i < n; ++i) {
        /* 15 cm above the tube's top circle, tilted, aimed 5 cm below the top (the tube's centre
         * circle: the path reaches its cells, so the check runs) while sliding sideways */
        const double ph = 2.39996 * i, rr = 0.1 + 0.004 * ((i % 5) - 2), tilt = 0.003 * ((i % 3) - 1);
        const sdfccd_Vec3 s = { rr * cos(ph), rr * sin(ph), 0.2 };
        const sdfccd_Vec3 tri[3] = { { s.x - 0.01, s.y - 0.006, s.z + tilt }, { s.x + 0.01, s.y - 0.004, s.z }, { s.x, s.y + 0.011, s.z - tilt } };
        sdfccd_RigidMotion m = translating((sdfccd_Vec3){ 0.02 * cos(1.7 * i) / DT, 0.02 * sin(1.7 * i) / DT, -0.2 / DT });
        const sdfccd_QueryResult rf = fwgss_agrees(grid, tri, &m, i);
        ck_assert(rf.hit);
        evals += (long long)rf.sdf_evaluations;
    }
    if (getenv("SDFCCD_TEST_VERBOSE")) fprintf(stderr, "top: %.1f evaluations per query\n", (double)evals / n);
    ck_assert_msg(evals <= 5000LL * n, "%.1f evaluations per query on the torus grid's top", (double)evals / n);
    sdfccd_destroy_sdf(grid);
    sdfccd_destroy_sdf(torus);
}
END_TEST

/* Fig. 12: a square pyramid spinning 360 degrees about x in one step above a box. Its first
 * contact with the box top (z = 0) is the first vertex to reach z = 0 (a polytope meets a plane
 * at a vertex first). The end pose equals the start pose, so DCD never sees the contact. */
START_TEST(test_pyramid_spin_360)
{
    sdfccd_SdfId box;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 2.0, 2.0, 0.5 }, &box), SDFCCD_OK);
    sdfccd_SdfId top;
    sdfccd_Pose down = sdfccd_pose_identity();
    down.position.z = -0.5;
    ck_assert_int_eq(sdfccd_create_transformed(box, down, 1.0, &top), SDFCCD_OK);
    const double v[5][3] = { { -0.1, -0.1, -0.05 }, { 0.1, -0.1, -0.05 }, { 0.1, 0.1, -0.05 }, { -0.1, 0.1, -0.05 }, { 0.0, 0.0, 0.25 } };
    const uint32_t idx[18] = { 0, 2, 1, 0, 3, 2, 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4 };
    sdfccd_MeshDef def = sdfccd_default_mesh_def();
    def.vertices = &v[0][0];
    def.vertex_count = 5;
    def.indices = idx;
    def.triangle_count = 6;
    sdfccd_MeshId mesh;
    ck_assert_int_eq(sdfccd_create_mesh(&def, &mesh), SDFCCD_OK);
    const double h = 0.2, w = 2.0 * M_PI / DT;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.z = h;
    m.angular_velocity.x = w;
    /* Reference: z_i(t) = h + y_i sin(wt) + z_i cos(wt); earliest root over the vertices. */
    double ref = INFINITY;
    for (int i = 0; i < 5; ++i) {
        double prev = h + v[i][2];
        const int n = 200000;
        for (int k = 1; k <= n; ++k) {
            double t = DT * k / n, z = h + v[i][1] * sin(w * t) + v[i][2] * cos(w * t);
            if (z <= 0.0 && prev > 0.0) {
                double lo = DT * (k - 1) / n, hi = t;
                for (int it = 0; it < 100; ++it) {
                    double mid = 0.5 * (lo + hi);
                    if (h + v[i][1] * sin(w * mid) + v[i][2] * cos(w * mid) > 0.0) lo = mid; else hi = mid;
                }
                if (hi < ref) ref = hi;
                break;
            }
            prev = z;
        }
    }
    ck_assert(isfinite(ref));
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_Contact c[16];
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_mesh(top, NULL, mesh, &m, 0.0, DT, &p, c, 16, &r), SDFCCD_OK);
    ck_assert_msg(r.hit, "FWGSS missed the spinning pyramid (state %d)", r.state);
    ck_assert_msg(fabs(r.toi - ref) <= 1e-6, "toi %.12g, expected %.12g", r.toi, ref);
    ck_assert_double_near(c[0].normal.z, 1.0, 1e-6);
    p.method = SDFCCD_METHOD_DCD;
    ck_assert_int_eq(sdfccd_query_mesh(top, NULL, mesh, &m, 0.0, DT, &p, c, 16, &r), SDFCCD_OK);
    ck_assert_msg(!r.hit, "DCD should not see the contact: the end pose equals the start pose");
    sdfccd_destroy_mesh(mesh);
    sdfccd_destroy_sdf(top);
    sdfccd_destroy_sdf(box);
}
END_TEST

/* Fig. 11: a large triangle falls flat onto a box face. With subdivision the query returns at
 * least three non-collinear contacts at the TOI; without it, one. */
START_TEST(test_flat_triangle_subdivision)
{
    sdfccd_SdfId box;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 1.0, 1.0, 0.5 }, &box), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { -0.3, -0.2, 0.6 }, { 0.4, -0.25, 0.6 }, { 0.0, 0.35, 0.6 } };
    sdfccd_RigidMotion m = translating((sdfccd_Vec3){ 0.0, 0.0, -10.0 });
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_Contact c[16];
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_triangle(box, NULL, tri, &m, 0.0, DT, &p, c, 16, &r), SDFCCD_OK);
    ck_assert(r.hit);
    ck_assert_double_near(r.toi, 0.01, 1e-6);
    ck_assert_int_ge(r.contact_count, 3);
    int noncollinear = 0;
    for (int i = 0; i < r.contact_count; ++i)
        for (int j = i + 1; j < r.contact_count; ++j)
            for (int k = j + 1; k < r.contact_count; ++k) {
                sdfccd_Vec3 a = c[i].point, b = c[j].point, d = c[k].point;
                double ux = b.x - a.x, uy = b.y - a.y, vx = d.x - a.x, vy = d.y - a.y;
                if (fabs(ux * vy - uy * vx) > 1e-4) noncollinear = 1;
            }
    ck_assert_msg(noncollinear, "subdivision contacts are collinear");
    for (int i = 0; i < r.contact_count; ++i) {
        ck_assert_double_near(c[i].point.z, 0.5, 1e-4);
        ck_assert_double_near(c[i].normal.z, 1.0, 1e-9);
    }
    p.subdivision = 0;
    ck_assert_int_eq(sdfccd_query_triangle(box, NULL, tri, &m, 0.0, DT, &p, c, 16, &r), SDFCCD_OK);
    ck_assert(r.hit);
    ck_assert_int_eq(r.contact_count, 1);
    sdfccd_destroy_sdf(box);
}
END_TEST

/* Moving away, or passing by: no hit. Penetrating at t0: PENETRATING with toi = t0. */
START_TEST(test_no_hit_and_penetrating)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(0.2, &s), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { 0.0, 0.0, 0.3 }, { 0.1, 0.0, 0.35 }, { 0.0, 0.1, 0.35 } };
    sdfccd_RigidMotion away = translating((sdfccd_Vec3){ 0.0, 0.0, 5.0 });
    sdfccd_QueryResult r;
    for (int method = 0; method < SDFCCD_METHOD_COUNT; ++method) {
        sdfccd_QueryParams p = params_for((sdfccd_Method)method);
        ck_assert_int_eq(sdfccd_query_triangle(s, NULL, tri, &away, 0.0, DT, &p, NULL, 0, &r), SDFCCD_OK);
        ck_assert_msg(!r.hit, "method %d reported a hit for a triangle moving away", method);
        ck_assert_int_eq(r.state, SDFCCD_STATE_NO_HIT);
        ck_assert_double_eq(r.toi, DT);
    }
    sdfccd_Vec3 inside[3] = { { 0.0, 0.0, 0.1 }, { 0.1, 0.0, 0.35 }, { 0.0, 0.1, 0.35 } };
    for (int method = 0; method < SDFCCD_METHOD_COUNT; ++method) {
        if (method == SDFCCD_METHOD_DCD) continue;
        sdfccd_QueryParams p = params_for((sdfccd_Method)method);
        ck_assert_int_eq(sdfccd_query_triangle(s, NULL, inside, &away, 0.0, DT, &p, NULL, 0, &r), SDFCCD_OK);
        ck_assert_msg(r.hit && r.state == SDFCCD_STATE_PENETRATING, "method %d: state %d", method, r.state);
        ck_assert_double_eq(r.toi, 0.0);
    }
    sdfccd_destroy_sdf(s);
}
END_TEST

/* Mesh query: the earliest triangle wins and every triangle within the window reports. */
START_TEST(test_mesh_query_earliest)
{
    sdfccd_SdfId plane;
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &plane), SDFCCD_OK);
    /* Two separate triangles: the second is lower and must decide the TOI. */
    const double v[6][3] = { { 0, 0, 0.2 }, { 0.1, 0, 0.25 }, { 0, 0.1, 0.25 }, { 1, 0, 0.1 }, { 1.1, 0, 0.15 }, { 1, 0.1, 0.15 } };
    const uint32_t idx[6] = { 0, 1, 2, 3, 4, 5 };
    sdfccd_MeshDef def = sdfccd_default_mesh_def();
    def.vertices = &v[0][0];
    def.vertex_count = 6;
    def.indices = idx;
    def.triangle_count = 2;
    sdfccd_MeshId mesh;
    ck_assert_int_eq(sdfccd_create_mesh(&def, &mesh), SDFCCD_OK);
    sdfccd_RigidMotion m = translating((sdfccd_Vec3){ 0, 0, -20.0 });
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_Contact c[8];
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_mesh(plane, NULL, mesh, &m, 0.0, DT, &p, c, 8, &r), SDFCCD_OK);
    ck_assert(r.hit);
    ck_assert_double_near(r.toi, 0.1 / 20.0, 1e-6);
    ck_assert_int_eq(c[0].triangle, 1);
    for (int i = 0; i < r.contact_count; ++i) ck_assert_int_eq(c[i].triangle, 1);
    /* With the broad phase the earliest candidate goes first and its hit culls the other
     * triangle; the plain loop tests both. Same answer either way. */
    ck_assert_int_eq(r.triangles_tested, 1);
    p.broad_phase = 0;
    ck_assert_int_eq(sdfccd_query_mesh(plane, NULL, mesh, &m, 0.0, DT, &p, c, 8, &r), SDFCCD_OK);
    ck_assert_int_eq(r.triangles_tested, 2);
    ck_assert_double_near(r.toi, 0.1 / 20.0, 1e-6);
    ck_assert_int_eq(c[0].triangle, 1);
    sdfccd_destroy_mesh(mesh);
    sdfccd_destroy_sdf(plane);
}
END_TEST

/* The vertex traces advance together in time (fwgss.c trace_vertices): a vertex that stays clear
 * (here sweeping fast over the plane, so its conservative steps are short) stops its trace where
 * another vertex touches, whichever vertex is listed first. Traced one after the other, the
 * triangle listed with the sweeping vertex first cost its whole trace (130 evaluations instead of
 * 110 with the touching vertex first). */
START_TEST(test_vertex_traces_in_time)
{
    sdfccd_SdfId plane;
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &plane), SDFCCD_OK);
    /* a touches at 0.005 / 0.6 s; b and c stay above the plane (b ends the step 1 mm above it) */
    const sdfccd_Vec3 a = { 0.0, 0.0, 0.005 }, b = { 0.1, 0.0, 0.011 }, c = { 0.0, 0.1, 0.02 };
    const sdfccd_Vec3 orders[3][3] = { { a, b, c }, { b, c, a }, { c, a, b } };
    sdfccd_RigidMotion m = translating((sdfccd_Vec3){ 0.0, 0.0, -0.6 });
    m.angular_velocity = (sdfccd_Vec3){ 0.0, 0.0, 100.0 }; /* about a vertical axis through a */
    sdfccd_QueryParams p = params_for(SDFCCD_METHOD_FWGSS);
    p.subdivision = 0;
    int64_t evals[3];
    for (int k = 0; k < 3; ++k) {
        sdfccd_QueryResult r;
        ck_assert_int_eq(sdfccd_query_triangle(plane, NULL, orders[k], &m, 0.0, DT, &p, NULL, 0, &r), SDFCCD_OK);
        ck_assert(r.hit);
        ck_assert_double_near(r.toi, 0.005 / 0.6, 1e-9);
        evals[k] = r.sdf_evaluations;
    }
    for (int k = 1; k < 3; ++k)
        ck_assert_msg(evals[k] <= evals[0], "order %d: %lld evaluations, touching vertex first: %lld", k, (long long)evals[k], (long long)evals[0]);
    sdfccd_destroy_sdf(plane);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("ccd");
    TCase* tc = tcase_create("closed_form");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_halfspace_vertex_first);
    tcase_add_test(tc, test_sphere_vertex_first);
    tcase_add_test(tc, test_box_face_edge_first);
    tcase_add_test(tc, test_box_face_vertex_first);
    tcase_add_test(tc, test_rotation_onto_plane);
    tcase_add_test(tc, test_moving_sdf);
    tcase_add_test(tc, test_linear_vertices);
    tcase_add_test(tc, test_no_hit_and_penetrating);
    tcase_add_test(tc, test_mesh_query_earliest);
    tcase_add_test(tc, test_vertex_traces_in_time);
    suite_add_tcase(s, tc);
    TCase* fail = tcase_create("failure_scenes");
    test_add_memory_fixture(fail);
    tcase_add_test(fail, test_torus_tunnel_twice);
    tcase_add_test(fail, test_torus_grid_check_cheap);
    tcase_add_test(fail, test_torus_grid_top_check_cheap);
    tcase_add_test(fail, test_pyramid_spin_360);
    tcase_add_test(fail, test_flat_triangle_subdivision);
    suite_add_tcase(s, fail);
    return test_run_suite(s);
}
