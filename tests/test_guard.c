/* SPDX-License-Identifier: MIT
 * The no-tunnelling guarantee (contact.h, issue 19 item 2): sdfccd_guard_rigid and
 * sdfccd_rigid_motion_from_poses, public ABI only. Every time of impact is compared with a closed
 * form (and the certified method where the motion allows), and every safe pose is checked by brute
 * force: phi at the vertices and on a barycentric grid of every triangle. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

/* GUARD_VERBOSE=1 prints the measured figures (TOI against the exact one, depth at the safe pose). */
#define REPORT(...) do { if (getenv("GUARD_VERBOSE")) { printf(__VA_ARGS__); fflush(stdout); } } while (0)

enum { DIVS_MAX = 16 };
static const double DT = 1.0 / 60.0;
static const double TOL = 5e-4; /* the default guard tolerance */

/* A box mesh [-h, h] with each face split into a grid (n[k] cells along axis k), kept for brute force. */
typedef struct box_mesh {
    sdfccd_MeshId id;
    double* v;
    uint32_t* f;
    uint32_t nv, nt;
} box_mesh;

/* A mesh handle with a copy of its arrays (for brute force). */
static box_mesh mesh_data(sdfccd_MeshId id)
{
    box_mesh b;
    b.id = id;
    sdfccd_MeshInfo info;
    ck_assert_int_eq(sdfccd_mesh_get_info(b.id, &info), SDFCCD_OK);
    b.nv = info.vertex_count;
    b.nt = info.triangle_count;
    b.v = malloc(3 * (size_t)b.nv * sizeof *b.v);
    b.f = malloc(3 * (size_t)b.nt * sizeof *b.f);
    ck_assert_int_eq(sdfccd_mesh_get_data(b.id, b.v, b.f), SDFCCD_OK);
    return b;
}

static box_mesh make_box(double hx, double hy, double hz, int nx, int ny, int nz)
{
    return mesh_data(test_box_mesh((sdfccd_Vec3){ hx, hy, hz }, nx, ny, nz));
}

static void free_box(box_mesh* b)
{
    ck_assert_int_eq(sdfccd_destroy_mesh(b->id), SDFCCD_OK);
    free(b->v);
    free(b->f);
}

/* A box SDF of half extents `half` centred at `c`. */
static sdfccd_SdfId box_at(sdfccd_Vec3 half, sdfccd_Vec3 c)
{
    sdfccd_SdfId box, moved;
    ck_assert_int_eq(sdfccd_create_box(half, &box), SDFCCD_OK);
    sdfccd_Pose pose = sdfccd_pose_identity();
    pose.position = c;
    ck_assert_int_eq(sdfccd_create_transformed(box, pose, 1.0, &moved), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(box), SDFCCD_OK);
    return moved;
}

static sdfccd_Vec3 v3(double x, double y, double z) { return (sdfccd_Vec3){ x, y, z }; }

static sdfccd_Vec3 rotate(sdfccd_Quat q, sdfccd_Vec3 v)
{
    /* v + 2w (u x v) + 2 u x (u x v) */
    double tx = 2 * (q.y * v.z - q.z * v.y), ty = 2 * (q.z * v.x - q.x * v.z), tz = 2 * (q.x * v.y - q.y * v.x);
    return v3(v.x + q.w * tx + (q.y * tz - q.z * ty), v.y + q.w * ty + (q.z * tx - q.x * tz), v.z + q.w * tz + (q.x * ty - q.y * tx));
}

static sdfccd_Quat axis_angle(sdfccd_Vec3 axis, double angle)
{
    double l = sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z), s = sin(0.5 * angle) / l;
    return (sdfccd_Quat){ cos(0.5 * angle), axis.x * s, axis.y * s, axis.z * s };
}

static sdfccd_Quat qmul(sdfccd_Quat a, sdfccd_Quat b)
{
    return (sdfccd_Quat){ a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w };
}

/* Brute force: the smallest phi over the mesh at `pose`, at the vertices and on a barycentric grid
 * of K steps per edge of every triangle (12 unless said; SDF static; world point = pose applied to the
 * local one). */
static double min_phi_grid(sdfccd_SdfId sdf, const box_mesh* b, sdfccd_Pose pose, int K)
{
    double best = INFINITY;
    for (uint32_t t = 0; t < b->nt; ++t) {
        const double* a = b->v + 3 * b->f[3 * t];
        const double* c = b->v + 3 * b->f[3 * t + 1];
        const double* d = b->v + 3 * b->f[3 * t + 2];
        for (int i = 0; i <= K; ++i)
            for (int j = 0; i + j <= K; ++j) {
                double u = (double)i / K, w = (double)j / K, s = 1.0 - u - w;
                sdfccd_Vec3 local = v3(s * a[0] + u * c[0] + w * d[0], s * a[1] + u * c[1] + w * d[1], s * a[2] + u * c[2] + w * d[2]);
                sdfccd_Vec3 r = rotate(pose.orientation, local);
                sdfccd_Vec3 x = v3(r.x + pose.position.x, r.y + pose.position.y, r.z + pose.position.z);
                double phi;
                ck_assert_int_eq(sdfccd_sdf_eval(sdf, x, &phi, NULL), SDFCCD_OK);
                best = fmin(best, phi);
            }
    }
    return best;
}

static double min_phi_at(sdfccd_SdfId sdf, const box_mesh* b, sdfccd_Pose pose) { return min_phi_grid(sdf, b, pose, 12); }

/* The smallest phi over the mesh's vertices at `pose` (one batch evaluation). */
static double min_phi_vertices(sdfccd_SdfId sdf, const box_mesh* b, sdfccd_Pose pose, sdfccd_Vec3* scratch, double* values)
{
    for (uint32_t i = 0; i < b->nv; ++i) {
        sdfccd_Vec3 r = rotate(pose.orientation, v3(b->v[3 * i], b->v[3 * i + 1], b->v[3 * i + 2]));
        scratch[i] = v3(r.x + pose.position.x, r.y + pose.position.y, r.z + pose.position.z);
    }
    ck_assert_int_eq(sdfccd_sdf_eval_batch(sdf, scratch, (int32_t)b->nv, values, NULL), SDFCCD_OK);
    double best = INFINITY;
    for (uint32_t i = 0; i < b->nv; ++i) best = fmin(best, values[i]);
    return best;
}

/* The pose of Eq. 14 at time t (t0 = 0, centre at the local origin). */
static sdfccd_Pose pose_at(const sdfccd_RigidMotion* m, double t)
{
    sdfccd_Vec3 w = m->angular_velocity;
    double a = sqrt(w.x * w.x + w.y * w.y + w.z * w.z) * t;
    sdfccd_Pose p;
    p.orientation = a > 0 ? qmul(axis_angle(w, a), m->pose.orientation) : m->pose.orientation;
    p.position = v3(m->pose.position.x + m->linear_velocity.x * t, m->pose.position.y + m->linear_velocity.y * t,
                    m->pose.position.z + m->linear_velocity.z * t);
    return p;
}

static void assert_pose_near(sdfccd_Pose a, sdfccd_Pose b, double tol)
{
    ck_assert_double_near(a.position.x, b.position.x, tol);
    ck_assert_double_near(a.position.y, b.position.y, tol);
    ck_assert_double_near(a.position.z, b.position.z, tol);
    double sign = a.orientation.w * b.orientation.w + a.orientation.x * b.orientation.x + a.orientation.y * b.orientation.y +
                  a.orientation.z * b.orientation.z < 0 ? -1.0 : 1.0;
    ck_assert_double_near(a.orientation.w, sign * b.orientation.w, tol);
    ck_assert_double_near(a.orientation.x, sign * b.orientation.x, tol);
    ck_assert_double_near(a.orientation.y, sign * b.orientation.y, tol);
    ck_assert_double_near(a.orientation.z, sign * b.orientation.z, tol);
}

static sdfccd_GuardResult guard(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                const sdfccd_RigidMotion* m, const sdfccd_GuardParams* gp)
{
    sdfccd_GuardResult r;
    ck_assert_msg(sdfccd_guard_rigid(ws, sdf, sdf_motion, mesh, m, 0.0, DT, gp, &r) == SDFCCD_OK, "%s", sdfccd_last_error());
    return r;
}

/* A rod (half extents R, A, A along x, y, z) spinning about z from rest across a 1 cm wall whose
 * face is the plane y = H (x in [0.1, 1]): the corner (R, A) reaches the level y = H + TOL first,
 * at angle asin((H + TOL) / sqrt(R^2 + A^2)) - atan2(A, R). Start and end poses are clear of the wall. */
static const double ROD_R = 0.2, ROD_A = 0.01, WALL_H = 0.1;

static void spin_through_wall(double total_angle, sdfccd_Method method)
{
    box_mesh rod = make_box(ROD_R, ROD_A, ROD_A, 10, 1, 1);
    sdfccd_SdfId wall = box_at(v3(0.45, 0.005, 1), v3(0.55, WALL_H + 0.005, 0));
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    gp.query.method = method;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.angular_velocity = v3(0, 0, total_angle / DT);
    sdfccd_Pose end = pose_at(&m, DT);
    ck_assert(min_phi_at(wall, &rod, m.pose) > 0.05);
    ck_assert(min_phi_at(wall, &rod, end) > 0.0); /* the end pose is beyond (or beside) the wall */
    double theta = asin((WALL_H + TOL) / hypot(ROD_R, ROD_A)) - atan2(ROD_A, ROD_R);
    double t_exact = theta / (total_angle / DT);

    sdfccd_GuardResult r = guard(ws, wall, NULL, rod.id, &m, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    ck_assert_int_eq(r.deep_triangles, 0);
    ck_assert_int_eq(r.queries, 1);
    /* never past the TOI, and at most a few time tolerances (1e-7 s) before it */
    REPORT("%s: toi - exact %.3g s, evals %lld\n", __func__, r.toi - t_exact, (long long)r.sdf_evaluations);
    ck_assert_msg(r.toi <= t_exact && r.toi >= t_exact - 3e-7, "toi %.12g, exact %.12g", r.toi, t_exact);
    ck_assert_double_near(r.fraction, r.toi / DT, 1e-15);
    assert_pose_near(r.safe_pose, pose_at(&m, r.toi), 1e-12);
    double depth = min_phi_at(wall, &rod, r.safe_pose);
    REPORT("%s: min phi at the safe pose %.9g\n", __func__, depth);
    ck_assert_msg(depth >= -TOL && depth <= -0.8 * TOL, "min phi at the safe pose %.9g", depth);
    ck_assert_double_near(r.normal.y, -1.0, 1e-9); /* out of the wall's face */
    ck_assert_double_near(r.point.y, WALL_H + TOL, 0.1 * TOL);
    ck_assert(r.min_gap_start > 0.05);

    if (method != SDFCCD_METHOD_CERTIFIED) {
        /* the certified method brackets the same TOI: the guard is never later */
        sdfccd_QueryParams cp = sdfccd_default_query_params();
        cp.method = SDFCCD_METHOD_CERTIFIED;
        cp.margin = -TOL;
        sdfccd_QueryResult q;
        ck_assert_int_eq(sdfccd_query_mesh_ws(ws, wall, NULL, rod.id, &m, 0.0, DT, &cp, NULL, 0, &q), SDFCCD_OK);
        ck_assert_int_eq(q.state, SDFCCD_STATE_HIT);
        ck_assert(q.toi_lower <= t_exact + 1e-12 && q.toi >= t_exact - 1e-12);
        ck_assert(r.toi <= q.toi && r.toi >= q.toi_lower - 3e-7);
    }
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(wall), SDFCCD_OK);
    free_box(&rod);
}

START_TEST(test_spun_through_thin_wall)
{
    spin_through_wall(1.5, SDFCCD_METHOD_FWGSS); /* 90 rad/s for one 60 Hz step */
}
END_TEST

START_TEST(test_spun_more_than_a_turn)
{
    spin_through_wall(2 * M_PI + 1.5, SDFCCD_METHOD_FWGSS); /* > 2 pi in one step: the CCD splits it */
}
END_TEST

START_TEST(test_spun_certified)
{
    spin_through_wall(1.5, SDFCCD_METHOD_CERTIFIED);
}
END_TEST

/* A 4 mm plate, 10 cm wide, tilted 45 degrees, at 500 m/s across a 1 cm wall (x in [0, 0.01]):
 * start and end poses both outside the wall. Its leading edge reaches x = TOL at
 * (TOL - x_lead) / 500 with x_lead = -0.1 + (0.05 + 0.002) / sqrt(2). */
START_TEST(test_fast_tilted_plate)
{
    box_mesh plate = make_box(0.05, 0.002, 0.05, 4, 1, 4);
    sdfccd_SdfId wall = box_at(v3(0.005, 1, 1), v3(0.005, 0, 0));
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = v3(-0.1, 0, 0);
    m.pose.orientation = axis_angle(v3(0, 0, 1), M_PI / 4);
    m.linear_velocity = v3(500, 0, 0);
    ck_assert(min_phi_at(wall, &plate, m.pose) > 0.06);
    ck_assert(min_phi_at(wall, &plate, pose_at(&m, DT)) > 8.0);
    double t_exact = (TOL - (-0.1 + 0.052 / sqrt(2.0))) / 500.0;
    sdfccd_GuardResult r = guard(ws, wall, NULL, plate.id, &m, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    REPORT("%s: toi - exact %.3g s, evals %lld\n", __func__, r.toi - t_exact, (long long)r.sdf_evaluations);
    ck_assert_msg(r.toi <= t_exact && r.toi >= t_exact - 3e-7, "toi %.12g, exact %.12g", r.toi, t_exact);
    double depth = min_phi_at(wall, &plate, r.safe_pose);
    REPORT("%s: min phi at the safe pose %.9g\n", __func__, depth);
    ck_assert_msg(depth >= -TOL && depth <= -0.8 * TOL, "min phi at the safe pose %.9g", depth);
    ck_assert_double_near(r.normal.x, -1.0, 1e-9);
    /* with the plate spinning about its normal as well, still caught before the wall */
    m.angular_velocity = v3(0, 200, 0);
    r = guard(ws, wall, NULL, plate.id, &m, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    depth = min_phi_at(wall, &plate, r.safe_pose);
    REPORT("%s: min phi at the safe pose %.9g\n", __func__, depth);
    ck_assert_msg(depth >= -TOL && depth <= -0.8 * TOL, "min phi at the safe pose %.9g", depth);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(wall), SDFCCD_OK);
    free_box(&plate);
}
END_TEST

/* A body moving and spinning away from the wall: CLEAR, and the safe pose is the end pose. */
START_TEST(test_moving_away_is_clear)
{
    box_mesh rod = make_box(ROD_R, ROD_A, ROD_A, 10, 1, 1);
    sdfccd_SdfId wall = box_at(v3(1, 0.005, 1), v3(0, WALL_H + 0.005, 0));
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    /* from two poses, as an engine that only has them would do */
    sdfccd_Pose start = sdfccd_pose_identity(), end;
    start.position = v3(0, 0.09 - ROD_A, 0); /* 1 cm below the wall */
    end.position = v3(0.3, -0.5, 0.1);
    end.orientation = axis_angle(v3(0.2, 0.1, 1), 2.0);
    sdfccd_RigidMotion m;
    ck_assert_int_eq(sdfccd_rigid_motion_from_poses(&start, &end, v3(0, 0, 0), 0.0, DT, &m), SDFCCD_OK);
    sdfccd_GuardResult r = guard(ws, wall, NULL, rod.id, &m, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_CLEAR);
    ck_assert(r.toi == DT);
    ck_assert(r.fraction == 1.0);
    assert_pose_near(r.safe_pose, end, 1e-12);
    ck_assert(r.normal.x == 0 && r.normal.y == 0 && r.normal.z == 0);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(wall), SDFCCD_OK);
    free_box(&rod);
}
END_TEST

/* A 10 cm cube whose bottom starts 2 mm inside a ground (top face y = 0) and, in the third case,
 * a 1 cm wall (x in [0.1, 0.11], above the ground) made one SDF with it. */
typedef struct inside_scene {
    box_mesh cube;
    sdfccd_SdfId ground, wall, both;
    sdfccd_Workspace* ws;
    sdfccd_GuardParams gp;
    sdfccd_RigidMotion m;
} inside_scene;

static void inside_setup(inside_scene* s)
{
    s->cube = make_box(0.05, 0.05, 0.05, 4, 4, 4);
    s->ground = box_at(v3(1, 0.05, 1), v3(0, -0.05, 0));
    s->wall = box_at(v3(0.005, 0.25, 1), v3(0.105, 0.25, 0));
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, s->ground, s->wall, &s->both), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_workspace(&s->ws), SDFCCD_OK);
    s->gp = sdfccd_default_guard_params();
    s->m = sdfccd_default_rigid_motion();
    s->m.pose.position = v3(0, 0.05 - 0.002, 0);
    ck_assert_double_near(min_phi_at(s->ground, &s->cube, s->m.pose), -0.002, 1e-12);
}

static void inside_teardown(inside_scene* s)
{
    sdfccd_destroy_workspace(s->ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(s->both), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(s->wall), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(s->ground), SDFCCD_OK);
    free_box(&s->cube);
}

START_TEST(test_inside_at_start_left_to_contacts)
{
    inside_scene s;
    inside_setup(&s);
    /* resting 2 mm deep and sliding 1 mm: not frozen, the pose advances */
    s.m.linear_velocity = v3(0.06, 0, 0);
    sdfccd_GuardResult r = guard(s.ws, s.ground, NULL, s.cube.id, &s.m, &s.gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_INSIDE_AT_START);
    ck_assert(r.toi == DT);
    assert_pose_near(r.safe_pose, pose_at(&s.m, DT), 1e-12);
    ck_assert_int_gt(r.deep_triangles, 0);
    ck_assert_int_eq(r.queries, 2);
    ck_assert_double_near(r.min_gap_start, -0.002, 1e-9);
    /* at rest (a body the contacts hold): the same */
    s.m.linear_velocity = v3(0, 0, 0);
    r = guard(s.ws, s.ground, NULL, s.cube.id, &s.m, &s.gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_INSIDE_AT_START);
    ck_assert(r.toi == DT);
    inside_teardown(&s);
}
END_TEST

START_TEST(test_inside_at_start_sinking_further)
{
    inside_scene s;
    inside_setup(&s);
    /* sinking 1 mm more in the step: stopped once it is TOL deeper than it started */
    s.m.linear_velocity = v3(0, -0.06, 0);
    double t_exact = TOL / 0.06;
    sdfccd_GuardResult r = guard(s.ws, s.ground, NULL, s.cube.id, &s.m, &s.gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    REPORT("%s: toi - exact %.3g s, evals %lld\n", __func__, r.toi - t_exact, (long long)r.sdf_evaluations);
    ck_assert_msg(r.toi <= t_exact && r.toi >= t_exact - 3e-7, "toi %.12g, exact %.12g", r.toi, t_exact);
    double depth = min_phi_at(s.ground, &s.cube, r.safe_pose);
    ck_assert_msg(depth >= -0.002 - TOL && depth <= -0.002 - 0.8 * TOL, "min phi at the safe pose %.9g", depth);
    ck_assert_double_near(r.normal.y, 1.0, 1e-9);
    inside_teardown(&s);
}
END_TEST

START_TEST(test_inside_at_start_rest_guarded)
{
    inside_scene s;
    inside_setup(&s);
    /* 2 mm in the ground and thrown at 30 m/s into the wall: the cube's side above the ground is
     * guarded at the level -TOL, reached at (0.05 + TOL) / 30 */
    s.m.linear_velocity = v3(30, 0, 0);
    ck_assert(min_phi_at(s.wall, &s.cube, pose_at(&s.m, DT)) > 0.2); /* beyond the wall at the end */
    double t_exact = (0.05 + TOL) / 30.0;
    sdfccd_GuardResult r = guard(s.ws, s.both, NULL, s.cube.id, &s.m, &s.gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    ck_assert_int_gt(r.deep_triangles, 0);
    REPORT("%s: toi - exact %.3g s, evals %lld\n", __func__, r.toi - t_exact, (long long)r.sdf_evaluations);
    ck_assert_msg(r.toi <= t_exact && r.toi >= t_exact - 3e-7, "toi %.12g, exact %.12g", r.toi, t_exact);
    double depth = min_phi_at(s.wall, &s.cube, r.safe_pose);
    ck_assert_msg(depth >= -TOL && depth <= -0.8 * TOL, "min phi in the wall at the safe pose %.9g", depth);
    ck_assert_double_near(r.normal.x, -1.0, 1e-9);
    inside_teardown(&s);
}
END_TEST

/* The wall moves at 20 m/s onto a resting rod (top face y = ROD_A): it is TOL into the rod at
 * (WALL_H - ROD_A + TOL) / 20, and has passed it by the end of the step. */
START_TEST(test_moving_sdf)
{
    box_mesh rod = make_box(ROD_R, ROD_A, ROD_A, 10, 1, 1);
    sdfccd_SdfId wall = box_at(v3(1, 0.005, 1), v3(0, WALL_H + 0.005, 0));
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    sdfccd_RigidMotion body = sdfccd_default_rigid_motion(), sm = sdfccd_default_rigid_motion();
    sm.linear_velocity = v3(0, -20, 0);
    double t_exact = (WALL_H - ROD_A + TOL) / 20.0;
    sdfccd_GuardResult r = guard(ws, wall, &sm, rod.id, &body, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    REPORT("%s: toi - exact %.3g s, evals %lld\n", __func__, r.toi - t_exact, (long long)r.sdf_evaluations);
    ck_assert_msg(r.toi <= t_exact && r.toi >= t_exact - 3e-7, "toi %.12g, exact %.12g", r.toi, t_exact);
    ck_assert_double_near(r.normal.y, -1.0, 1e-9);
    ck_assert_double_near(r.point.y, ROD_A, 1e-9 + 20 * 3e-7);
    assert_pose_near(r.safe_pose, sdfccd_pose_identity(), 0.0);
    /* moving together: clear */
    body.linear_velocity = sm.linear_velocity;
    r = guard(ws, wall, &sm, rod.id, &body, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_CLEAR);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(wall), SDFCCD_OK);
    free_box(&rod);
}
END_TEST

/* A cloth (5 x 5 vertices, 10 cm, tilted 45 deg about z) moving linearly at 500 m/s across the 1 cm
 * wall x in [0, 0.01]: sdfccd_guard_linear stops it where its leading edge x = -0.1 + 0.05 / sqrt(2)
 * reaches x = TOL, and the safe positions are the vertices there. */
START_TEST(test_guard_linear_cloth)
{
    enum { NV = 25, NT = 32 };
    double v[3 * NV];
    uint32_t f[3 * NT];
    sdfccd_Vec3 start[NV], end[NV], safe[NV];
    const double c45 = sqrt(0.5);
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) {
            int k = 5 * i + j;
            double u = -0.05 + 0.025 * i, w = -0.05 + 0.025 * j;
            v[3 * k] = u * c45 - 0.1;
            v[3 * k + 1] = u * c45;
            v[3 * k + 2] = w;
            start[k] = (sdfccd_Vec3){ v[3 * k], v[3 * k + 1], v[3 * k + 2] };
            end[k] = (sdfccd_Vec3){ v[3 * k] + 500 * DT, v[3 * k + 1], v[3 * k + 2] };
        }
    int t = 0;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            uint32_t a = (uint32_t)(5 * i + j);
            uint32_t q[6] = { a, a + 5, a + 6, a, a + 6, a + 1 };
            memcpy(f + 6 * t++, q, sizeof q);
        }
    sdfccd_MeshDef d = sdfccd_default_mesh_def();
    d.vertices = v;
    d.vertex_count = NV;
    d.indices = f;
    d.triangle_count = NT;
    sdfccd_MeshId cloth;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &cloth), SDFCCD_OK);
    sdfccd_SdfId wall = box_at(v3(0.005, 1, 1), v3(0.005, 0, 0));
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    sdfccd_GuardResult r;
    ck_assert_msg(sdfccd_guard_linear(ws, wall, NULL, cloth, start, end, 0.0, DT, &gp, &r, safe) == SDFCCD_OK, "%s", sdfccd_last_error());
    double t_exact = (TOL - (-0.1 + 0.05 * c45)) / 500.0;
    REPORT("%s: toi - exact %.3g s\n", __func__, r.toi - t_exact);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    ck_assert_msg(r.toi <= t_exact && r.toi >= t_exact - 3e-7, "toi %.12g, exact %.12g", r.toi, t_exact);
    ck_assert_double_near(r.normal.x, -1.0, 1e-9);
    /* the safe positions, and no point of the cloth there deeper than TOL (vertices and a grid on each triangle) */
    double depth = INFINITY;
    for (int k = 0; k < NV; ++k) ck_assert_double_near(safe[k].x, start[k].x + 500 * r.toi, 1e-12);
    for (int k = 0; k < NT; ++k)
        for (int i = 0; i <= 12; ++i)
            for (int j = 0; i + j <= 12; ++j) {
                sdfccd_Vec3 a = safe[f[3 * k]], b = safe[f[3 * k + 1]], c = safe[f[3 * k + 2]];
                double u = i / 12.0, w = j / 12.0, s0 = 1 - u - w, phi;
                sdfccd_Vec3 x = v3(s0 * a.x + u * b.x + w * c.x, s0 * a.y + u * b.y + w * c.y, s0 * a.z + u * b.z + w * c.z);
                ck_assert_int_eq(sdfccd_sdf_eval(wall, x, &phi, NULL), SDFCCD_OK);
                depth = fmin(depth, phi);
            }
    ck_assert_msg(depth >= -TOL && depth <= -0.8 * TOL, "min phi at the safe positions %.9g", depth);
    /* moving away: clear, the end positions */
    for (int k = 0; k < NV; ++k) { end[k] = start[k]; end[k].x -= 0.3; }
    ck_assert_int_eq(sdfccd_guard_linear(ws, wall, NULL, cloth, start, end, 0.0, DT, &gp, &r, safe), SDFCCD_OK);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_CLEAR);
    for (int k = 0; k < NV; ++k) ck_assert(safe[k].x == end[k].x && safe[k].y == end[k].y && safe[k].z == end[k].z);
    /* bad input */
    ck_assert_int_eq(sdfccd_guard_linear(ws, wall, NULL, cloth, NULL, end, 0.0, DT, &gp, &r, safe), SDFCCD_INVALID_ARGUMENT);
    end[3].y = NAN;
    ck_assert_int_eq(sdfccd_guard_linear(ws, wall, NULL, cloth, start, end, 0.0, DT, &gp, &r, safe), SDFCCD_INVALID_ARGUMENT);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(wall), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cloth), SDFCCD_OK);
}
END_TEST

/* The thin-body battery at the core (issue 19): the data set's 4 mm shuriken shot at 100-500 m/s
 * with random orientation, incidence up to 80 degrees and spin up to 200 rad/s, into a 1 cm box wall
 * and a 1.5 cm spherical shell (CSG difference), seeded. Every shot crosses the wall within the step.
 * Checked against brute force: the guard rolls back; on [t0, toi] (200 times) no vertex is deeper
 * than TOL; at the safe pose no point (vertices and a grid of 4 steps per edge) is deeper than TOL,
 * and the deepest is deeper than 0.8 TOL (the pose is not early). */
START_TEST(test_shuriken_battery)
{
    box_mesh sh = mesh_data(test_load_mesh("../samples/report/dataset/shuriken.obj"));
    ck_assert_int_eq(sh.nt, 888);
    sdfccd_SdfId box, wall, outer, inner, shell;
    ck_assert_int_eq(sdfccd_create_box(v3(0.005, 1, 1), &box), SDFCCD_OK);
    sdfccd_Pose at = sdfccd_pose_identity();
    at.position.x = 0.005;
    ck_assert_int_eq(sdfccd_create_transformed(box, at, 1.0, &wall), SDFCCD_OK); /* x in [0, 0.01] */
    ck_assert_int_eq(sdfccd_create_sphere(0.3, &outer), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_sphere(0.285, &inner), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_DIFFERENCE, outer, inner, &shell), SDFCCD_OK);
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    sdfccd_Vec3* scratch = malloc(sh.nv * sizeof *scratch);
    double* values = malloc(sh.nv * sizeof *values);
    test_rng rng = { 1919 };
    enum { SHOTS = 12, SAMPLES = 200 };
    double worst_before = INFINITY, worst_safe = INFINITY, shallowest_safe = -INFINITY;
    for (int k = 0; k < SHOTS; ++k) {
        const int into_shell = k % 2;
        sdfccd_SdfId target = into_shell ? shell : wall;
        double speed = test_rng_uniform(&rng, 100, 500), incidence = test_rng_uniform(&rng, 0, 80) * M_PI / 180;
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        m.pose.orientation = axis_angle(test_rng_unit_vector(&rng), test_rng_uniform(&rng, 0, 2 * M_PI));
        sdfccd_Vec3 axis = test_rng_unit_vector(&rng);
        double spin = test_rng_uniform(&rng, 0, 200);
        m.angular_velocity = v3(axis.x * spin, axis.y * spin, axis.z * spin);
        /* centre 6 cm before the surface (the shuriken's radius is 5 cm), moving at `incidence` to its normal */
        sdfccd_Vec3 dir = v3(cos(incidence), sin(incidence), 0);
        m.pose.position = into_shell ? v3(-0.36, -0.36 * tan(incidence) * 0.1, 0) : v3(-0.06, 0, 0);
        m.linear_velocity = v3(dir.x * speed, dir.y * speed, 0);
        ck_assert(min_phi_vertices(target, &sh, m.pose, scratch, values) > 0.0);
        sdfccd_GuardResult r = guard(ws, target, NULL, sh.id, &m, &gp);
        ck_assert_msg(r.state == SDFCCD_GUARD_ROLLED_BACK, "shot %d: state %d", k, (int)r.state);
        double before = INFINITY;
        for (int i = 0; i <= SAMPLES; ++i) before = fmin(before, min_phi_vertices(target, &sh, pose_at(&m, r.toi * i / SAMPLES), scratch, values));
        double safe = min_phi_grid(target, &sh, r.safe_pose, 4);
        REPORT("shot %2d (%s, %3.0f m/s, %2.0f deg, %3.0f rad/s): toi %.4g s, deepest vertex before %.3g, at the safe pose %.4g, "
               "%lld evaluations\n", k, into_shell ? "shell" : "wall ", speed, incidence * 180 / M_PI, spin, r.toi, before, safe,
               (long long)r.sdf_evaluations);
        ck_assert_msg(before >= -TOL, "shot %d: a vertex %.9g deep before the safe pose", k, before);
        ck_assert_msg(safe >= -TOL && safe <= -0.8 * TOL, "shot %d: min phi at the safe pose %.9g", k, safe);
        worst_before = fmin(worst_before, before);
        worst_safe = fmin(worst_safe, safe);
        shallowest_safe = fmax(shallowest_safe, safe);
    }
    REPORT("battery: deepest vertex before the safe poses %.4g, depth at the safe poses in [%.4g, %.4g]\n", worst_before, worst_safe,
           shallowest_safe);
    free(scratch);
    free(values);
    sdfccd_destroy_workspace(ws);
    const sdfccd_SdfId all[5] = { shell, inner, outer, wall, box };
    for (int i = 0; i < 5; ++i) ck_assert_int_eq(sdfccd_destroy_sdf(all[i]), SDFCCD_OK);
    free_box(&sh);
}
END_TEST

START_TEST(test_motion_from_poses)
{
    test_rng rng = { 19 };
    for (int i = 0; i < 50; ++i) {
        sdfccd_Pose a, b;
        a.position = test_rng_unit_vector(&rng);
        b.position = test_rng_unit_vector(&rng);
        a.orientation = axis_angle(test_rng_unit_vector(&rng), test_rng_uniform(&rng, -6, 6));
        b.orientation = axis_angle(test_rng_unit_vector(&rng), test_rng_uniform(&rng, -6, 6));
        sdfccd_Vec3 c = v3(0.1, -0.2, 0.05);
        sdfccd_RigidMotion m;
        ck_assert_int_eq(sdfccd_rigid_motion_from_poses(&a, &b, c, 1.0, 1.0 + DT, &m), SDFCCD_OK);
        /* shortest arc: at most pi */
        sdfccd_Vec3 w = m.angular_velocity;
        ck_assert(sqrt(w.x * w.x + w.y * w.y + w.z * w.z) * DT <= M_PI + 1e-12);
        /* Eq. 14 at t1 gives b: the centre moved linearly, the frame turned about it */
        double ang = sqrt(w.x * w.x + w.y * w.y + w.z * w.z) * DT;
        sdfccd_Quat q1 = ang > 0 ? qmul(axis_angle(w, ang), a.orientation) : a.orientation;
        sdfccd_Vec3 ca = rotate(a.orientation, c), c1 = rotate(q1, c);
        sdfccd_Pose e;
        e.orientation = q1;
        e.position = v3(a.position.x + ca.x + m.linear_velocity.x * DT - c1.x, a.position.y + ca.y + m.linear_velocity.y * DT - c1.y,
                        a.position.z + ca.z + m.linear_velocity.z * DT - c1.z);
        assert_pose_near(e, b, 1e-12);
    }
    /* three quarters of a turn one way is a quarter turn the other way */
    sdfccd_Pose a = sdfccd_pose_identity(), b = sdfccd_pose_identity();
    b.orientation = axis_angle(v3(0, 0, 1), 1.5 * M_PI);
    sdfccd_RigidMotion m;
    ck_assert_int_eq(sdfccd_rigid_motion_from_poses(&a, &b, v3(0, 0, 0), 0.0, 2.0, &m), SDFCCD_OK);
    ck_assert_double_near(m.angular_velocity.z, -0.25 * M_PI, 1e-14);
    ck_assert_double_near(m.angular_velocity.x, 0.0, 1e-14);
}
END_TEST

START_TEST(test_bad_input)
{
    box_mesh rod = make_box(ROD_R, ROD_A, ROD_A, 2, 1, 1);
    sdfccd_SdfId wall = box_at(v3(1, 0.005, 1), v3(0, WALL_H + 0.005, 0));
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params(), bad;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    sdfccd_GuardResult r, untouched;
    memset(&untouched, 0x5a, sizeof untouched);
    r = untouched;
#define EXPECT(call, status)                                                              \
    do {                                                                                  \
        ck_assert_int_eq((call), (status));                                               \
        ck_assert_msg(strlen(sdfccd_last_error()) > 0, "no message");                     \
        ck_assert(memcmp(&r, &untouched, sizeof r) == 0);                                 \
    } while (0)
    EXPECT(sdfccd_guard_rigid(NULL, wall, NULL, rod.id, &m, 0, DT, &gp, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_guard_rigid(ws, wall, NULL, rod.id, NULL, 0, DT, &gp, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_guard_rigid(ws, wall, NULL, rod.id, &m, 0, DT, NULL, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_rigid(ws, wall, NULL, rod.id, &m, 0, DT, &gp, NULL), SDFCCD_INVALID_ARGUMENT);
    memset(&bad, 0, sizeof bad);
    bad.tolerance = 1e-3;
    bad.query = sdfccd_default_query_params();
    EXPECT(sdfccd_guard_rigid(ws, wall, NULL, rod.id, &m, 0, DT, &bad, &r), SDFCCD_INVALID_ARGUMENT); /* no default */
    const double tols[] = { 0.0, -1e-3, NAN, INFINITY };
    for (int i = 0; i < 4; ++i) {
        bad = gp;
        bad.tolerance = tols[i];
        EXPECT(sdfccd_guard_rigid(ws, wall, NULL, rod.id, &m, 0, DT, &bad, &r), SDFCCD_INVALID_ARGUMENT);
    }
    bad = gp;
    bad.query.method = SDFCCD_METHOD_DCD;
    EXPECT(sdfccd_guard_rigid(ws, wall, NULL, rod.id, &m, 0, DT, &bad, &r), SDFCCD_INVALID_ARGUMENT);
    bad = gp;
    bad.query.time_tolerance = -1;
    EXPECT(sdfccd_guard_rigid(ws, wall, NULL, rod.id, &m, 0, DT, &bad, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_guard_rigid(ws, wall, NULL, rod.id, &m, DT, 0, &gp, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_guard_rigid(ws, wall, NULL, rod.id, &m, 0, NAN, &gp, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_RigidMotion nan_m = m;
    nan_m.linear_velocity.y = NAN;
    EXPECT(sdfccd_guard_rigid(ws, wall, NULL, rod.id, &nan_m, 0, DT, &gp, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_guard_rigid(ws, wall, &nan_m, rod.id, &m, 0, DT, &gp, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_MeshId null_mesh = { 0, 0 };
    sdfccd_SdfId null_sdf = { 0, 0 };
    EXPECT(sdfccd_guard_rigid(ws, wall, NULL, null_mesh, &m, 0, DT, &gp, &r), SDFCCD_INVALID_HANDLE);
    EXPECT(sdfccd_guard_rigid(ws, null_sdf, NULL, rod.id, &m, 0, DT, &gp, &r), SDFCCD_INVALID_HANDLE);

    sdfccd_Pose a = sdfccd_pose_identity(), b = sdfccd_pose_identity();
    sdfccd_RigidMotion out, out_untouched;
    memset(&out_untouched, 0x5a, sizeof out_untouched);
    out = out_untouched;
#define EXPECT_POSES(call)                                                                \
    do {                                                                                  \
        ck_assert_int_eq((call), SDFCCD_INVALID_ARGUMENT);                                \
        ck_assert_msg(strlen(sdfccd_last_error()) > 0, "no message");                     \
        ck_assert(memcmp(&out, &out_untouched, sizeof out) == 0);                         \
    } while (0)
    EXPECT_POSES(sdfccd_rigid_motion_from_poses(NULL, &b, v3(0, 0, 0), 0, DT, &out));
    EXPECT_POSES(sdfccd_rigid_motion_from_poses(&a, NULL, v3(0, 0, 0), 0, DT, &out));
    ck_assert_int_eq(sdfccd_rigid_motion_from_poses(&a, &b, v3(0, 0, 0), 0, DT, NULL), SDFCCD_INVALID_ARGUMENT);
    EXPECT_POSES(sdfccd_rigid_motion_from_poses(&a, &b, v3(0, 0, 0), DT, DT, &out));
    EXPECT_POSES(sdfccd_rigid_motion_from_poses(&a, &b, v3(0, 0, 0), DT, 0, &out));
    EXPECT_POSES(sdfccd_rigid_motion_from_poses(&a, &b, v3(NAN, 0, 0), 0, DT, &out));
    b.orientation.w = 1.01; /* not a unit quaternion */
    EXPECT_POSES(sdfccd_rigid_motion_from_poses(&a, &b, v3(0, 0, 0), 0, DT, &out));
    b.orientation.w = 1.0 + 1e-6; /* rounding: accepted */
    ck_assert_int_eq(sdfccd_rigid_motion_from_poses(&a, &b, v3(0, 0, 0), 0, DT, &out), SDFCCD_OK);
    b.position.x = INFINITY;
    out = out_untouched;
    EXPECT_POSES(sdfccd_rigid_motion_from_poses(&a, &b, v3(0, 0, 0), 0, DT, &out));
#undef EXPECT
#undef EXPECT_POSES
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(wall), SDFCCD_OK);
    free_box(&rod);
}
END_TEST


/* After a first call of each kind (clear, rolled back, inside at start), guard calls through a
 * workspace allocate nothing. */
START_TEST(test_no_allocation_after_warm_up)
{
    long allocs = 0;
    ck_assert_int_eq(sdfccd_set_allocator(test_counting_alloc, test_counting_free, &allocs), SDFCCD_OK);
    {
        inside_scene s;
        inside_setup(&s);
        sdfccd_RigidMotion ms[3] = { s.m, s.m, s.m };
        ms[0].linear_velocity = v3(0.06, 0, 0);  /* inside at start */
        ms[1].linear_velocity = v3(30, 0, 0);    /* rolled back */
        ms[2].pose.position.y = 0.06;            /* clear */
        for (int k = 0; k < 3; ++k) (void)guard(s.ws, s.both, NULL, s.cube.id, &ms[k], &s.gp);
        long before = allocs;
        int states[3] = { 0, 0, 0 };
        for (int i = 0; i < 10; ++i)
            for (int k = 0; k < 3; ++k) states[guard(s.ws, s.both, NULL, s.cube.id, &ms[k], &s.gp).state]++;
        ck_assert_int_eq(allocs - before, 0);
        ck_assert_int_eq(states[SDFCCD_GUARD_CLEAR], 10);
        ck_assert_int_eq(states[SDFCCD_GUARD_ROLLED_BACK], 10);
        ck_assert_int_eq(states[SDFCCD_GUARD_INSIDE_AT_START], 10);
        inside_teardown(&s);
    }
    ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_OK);
}
END_TEST

/* ---- sdfccd_guard_step_rigid: the engine's step (certificate, safe time, discrete check) ---- */

static sdfccd_GuardResult guard_step(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                     const sdfccd_RigidMotion* m, const sdfccd_GuardParams* gp)
{
    sdfccd_GuardResult r;
    ck_assert_msg(sdfccd_guard_step_rigid(ws, sdf, sdf_motion, mesh, m, 0.0, DT, gp, &r) == SDFCCD_OK, "%s", sdfccd_last_error());
    return r;
}

/* The rod spun through the thin wall by an applied spin: put back before its TOI (closed form, as in
 * spin_through_wall), where its first point was half the tolerance higher: no point of the safe pose
 * deeper than TOL / 2 (brute force), and not more than a few time tolerances before that time. */
START_TEST(test_step_spun_through_wall)
{
    box_mesh rod = make_box(ROD_R, ROD_A, ROD_A, 10, 1, 1);
    sdfccd_SdfId wall = box_at(v3(0.45, 0.005, 1), v3(0.55, WALL_H + 0.005, 0));
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.angular_velocity = v3(0, 0, 1.5 / DT);
    const double R = hypot(ROD_R, ROD_A);
    const double t_full = (asin((WALL_H + TOL) / R) - atan2(ROD_A, ROD_R)) / (1.5 / DT);
    const double t_half = (asin((WALL_H + 0.5 * TOL) / R) - atan2(ROD_A, ROD_R)) / (1.5 / DT);
    sdfccd_GuardResult r = guard_step(ws, wall, NULL, rod.id, &m, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    ck_assert_int_eq(r.pinned, 0);
    ck_assert_int_eq(r.certified, 0);
    REPORT("%s: toi - half-level time %.3g s, evals %lld\n", __func__, r.toi - t_half, (long long)r.sdf_evaluations);
    ck_assert_msg(r.toi < t_full && r.toi <= t_half && r.toi >= t_half - 3e-7, "toi %.12g, half-level time %.12g", r.toi, t_half);
    assert_pose_near(r.safe_pose, pose_at(&m, r.toi), 1e-12);
    double depth = min_phi_at(wall, &rod, r.safe_pose);
    ck_assert_msg(depth >= -0.5 * TOL && depth <= -0.4 * TOL, "min phi at the safe pose %.9g", depth);
    ck_assert_double_near(r.normal.y, -1.0, 1e-9);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(wall), SDFCCD_OK);
    free_box(&rod);
}
END_TEST

/* Moving away: CLEAR at the end pose; not moving at all: CLEAR at no cost (certified); sliding 1 cm
 * above a ground: CLEAR by the certificate alone, and by the CCD's check (whose pre-check is cheaper). */
START_TEST(test_step_clear_and_certified)
{
    box_mesh rod = make_box(ROD_R, ROD_A, ROD_A, 10, 1, 1);
    sdfccd_SdfId wall = box_at(v3(1, 0.005, 1), v3(0, WALL_H + 0.005, 0));
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    sdfccd_Pose start = sdfccd_pose_identity(), end;
    start.position = v3(0, 0.09 - ROD_A, 0);
    end.position = v3(0.3, -0.5, 0.1);
    end.orientation = axis_angle(v3(0.2, 0.1, 1), 2.0);
    sdfccd_RigidMotion m;
    ck_assert_int_eq(sdfccd_rigid_motion_from_poses(&start, &end, v3(0, 0, 0), 0.0, DT, &m), SDFCCD_OK);
    sdfccd_GuardResult r = guard_step(ws, wall, NULL, rod.id, &m, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_CLEAR);
    ck_assert(r.toi == DT && r.pinned == 0);
    assert_pose_near(r.safe_pose, end, 1e-12);
    /* no motion, even touching the wall */
    sdfccd_RigidMotion still = sdfccd_default_rigid_motion();
    still.pose.position = v3(0, WALL_H - ROD_A, 0);
    r = guard_step(ws, wall, NULL, rod.id, &still, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_CLEAR);
    ck_assert_int_eq(r.certified, 1);
    ck_assert_int_eq(r.sdf_evaluations, 0);
    /* sliding along the wall 1 cm below it, turning slowly */
    sdfccd_RigidMotion slide = sdfccd_default_rigid_motion();
    slide.pose.position = v3(0, WALL_H - ROD_A - 0.01, 0);
    slide.linear_velocity = v3(0.6, 0, 0.3);
    slide.angular_velocity = v3(0, 0.5, 0);
    r = guard_step(ws, wall, NULL, rod.id, &slide, &gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_CLEAR);
    ck_assert_int_eq(r.certified, 1);
    sdfccd_GuardResult full = guard(ws, wall, NULL, rod.id, &slide, &gp);
    ck_assert_int_eq(full.state, SDFCCD_GUARD_CLEAR);
    REPORT("%s: sliding: certificate %lld evaluations, CCD check %lld\n", __func__, (long long)r.sdf_evaluations,
           (long long)full.sdf_evaluations);
    /* The CCD's mesh query now clears this slide's triangles by the certified search's short proof
     * before FWGSS (mesh_query.c, precheck): 251 evaluations where FWGSS and its checks spent 4,181,
     * so it undercuts the certificate's 305. */
    ck_assert_int_lt(full.sdf_evaluations, r.sdf_evaluations);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(wall), SDFCCD_OK);
    free_box(&rod);
}
END_TEST

/* Resting 0.3 mm deep on the ground (deeper than TOL / 2, not TOL) and sliding 6 cm into a wall 5 cm
 * away, rising 0.1 mm: put back where it meets the wall (half the tolerance into it), not frozen at
 * its start although every pose after t0 is deeper than TOL / 2 on the ground. At the safe pose no
 * point is deeper than it started (brute force against ground and wall). */
START_TEST(test_step_inside_slides_into_wall)
{
    inside_scene s;
    inside_setup(&s);
    s.m.pose.position = v3(0, 0.05 - 0.0003, 0);
    s.m.linear_velocity = v3(0.06 / DT, 0.0001 / DT, 0);
    const double start = min_phi_at(s.both, &s.cube, s.m.pose);
    sdfccd_GuardResult r = guard_step(s.ws, s.both, NULL, s.cube.id, &s.m, &s.gp);
    REPORT("%s: state %d toi/DT %.6g pinned %d\n", __func__, (int)r.state, r.toi / DT, (int)r.pinned);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    ck_assert_int_eq(r.pinned, 0);
    ck_assert_msg(r.toi >= (0.05 / 0.06) * DT && r.toi <= (0.05 + 0.5 * TOL) / 0.06 * DT, "toi/DT %.9g", r.toi / DT);
    assert_pose_near(r.safe_pose, pose_at(&s.m, r.toi), 1e-12);
    const double depth = min_phi_at(s.both, &s.cube, r.safe_pose);
    ck_assert_msg(depth >= start - 1e-9, "min phi at the safe pose %.9g, at the start %.9g", depth, start);
    ck_assert_msg(min_phi_at(s.wall, &s.cube, r.safe_pose) >= -0.5 * TOL, "into the wall at the safe pose");
    inside_teardown(&s);
}
END_TEST

/* Already inside: left to the contacts (INSIDE_AT_START, end pose). Starting 0.3 mm deep (between
 * TOL / 2 and TOL) and sinking 1 mm: no later time passes the discrete check, pinned at t0. */
START_TEST(test_step_inside_and_pinned)
{
    inside_scene s;
    inside_setup(&s);
    s.m.linear_velocity = v3(0.06, 0, 0);
    sdfccd_GuardResult r = guard_step(s.ws, s.ground, NULL, s.cube.id, &s.m, &s.gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_INSIDE_AT_START);
    ck_assert(r.toi == DT && r.pinned == 0);
    assert_pose_near(r.safe_pose, pose_at(&s.m, DT), 1e-12);
    s.m.pose.position = v3(0, 0.05 - 0.0003, 0);
    s.m.linear_velocity = v3(0, -0.06, 0);
    r = guard_step(s.ws, s.ground, NULL, s.cube.id, &s.m, &s.gp);
    ck_assert_int_eq(r.state, SDFCCD_GUARD_ROLLED_BACK);
    ck_assert_int_eq(r.pinned, 1);
    ck_assert(r.toi == 0.0 && r.fraction == 0.0);
    assert_pose_near(r.safe_pose, s.m.pose, 1e-12);
    ck_assert_double_near(r.normal.y, 1.0, 1e-9);
    inside_teardown(&s);
}
END_TEST

/* The certificate against brute force: random motions of a tumbling box near a sphere; whenever the
 * step says CLEAR, no point (vertices and a barycentric grid, 21 times in the step) went deeper than
 * TOL; whenever it rolls back, the safe pose has no point deeper than TOL. Both outcomes and both
 * kinds of CLEAR (certified and not) must occur. */
START_TEST(test_step_certificate_brute_force)
{
    box_mesh cube = make_box(0.05, 0.02, 0.03, 3, 2, 2);
    sdfccd_SdfId ball;
    ck_assert_int_eq(sdfccd_create_sphere(0.5, &ball), SDFCCD_OK);
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    uint64_t seed = 12345;
    int certified = 0, clear_ccd = 0, rolled = 0;
    for (int k = 0; k < 100; ++k) {
        double u[9];
        for (int i = 0; i < 9; ++i) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            u[i] = (double)(seed >> 11) / 9007199254740992.0;
        }
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        const double h = 0.5 + 0.066 + 0.01 * (u[0] - 0.3); /* the centre 6 to 7 cm above the surface */
        m.pose.position = v3(0, h, 0);
        m.pose.orientation = axis_angle(v3(u[1] - 0.5, u[2] - 0.5, u[3] - 0.5 + 1e-3), 6 * u[4]);
        m.linear_velocity = v3(3 * (u[5] - 0.5), -3 * u[6], 3 * (u[7] - 0.5));
        m.angular_velocity = v3(0, 0, 60 * (u[8] - 0.5));
        if (!(min_phi_grid(ball, &cube, m.pose, 6) > 0.0)) continue; /* starts clear of the surface */
        sdfccd_GuardResult r = guard_step(ws, ball, NULL, cube.id, &m, &gp);
        if (r.state == SDFCCD_GUARD_CLEAR) {
            double lo = INFINITY;
            for (int i = 0; i <= 20; ++i) lo = fmin(lo, min_phi_grid(ball, &cube, pose_at(&m, DT * i / 20.0), 3));
            ck_assert_msg(lo > -TOL, "motion %d: CLEAR (certified %d) but a point reached %.9g", k, r.certified, lo);
            if (r.certified) ++certified;
            else ++clear_ccd;
        } else if (r.state == SDFCCD_GUARD_ROLLED_BACK) {
            ++rolled;
            double depth = min_phi_at(ball, &cube, r.safe_pose);
            ck_assert_msg(depth > -TOL, "motion %d: safe pose %.9g deep", k, depth);
        }
    }
    REPORT("%s: certified %d, clear by the CCD %d, rolled back %d\n", __func__, certified, clear_ccd, rolled);
    ck_assert_int_gt(certified, 10);
    ck_assert_int_gt(clear_ccd, 0);
    ck_assert_int_gt(rolled, 10);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(ball), SDFCCD_OK);
    free_box(&cube);
}
END_TEST

/* ---- sdfccd_guard_response: hand-computed impulses ---- */

static sdfccd_BodyState unit_body(void)
{
    sdfccd_BodyState b;
    memset(&b, 0, sizeof b);
    b.inverse_mass = 1.0;
    b.inverse_inertia[0] = b.inverse_inertia[4] = b.inverse_inertia[8] = 1.0;
    return b;
}

START_TEST(test_response)
{
    sdfccd_GuardResult r;
    memset(&r, 0, sizeof r);
    r.state = SDFCCD_GUARD_ROLLED_BACK;
    r.point = v3(1, 0, 0);
    r.normal = v3(0, 1, 0);
    /* unit mass and inertia at the origin, spinning about -z: the point (1, 0, 0) moves at (0, -2, 0).
     * k = 1 + n.((r x n) x r) = 2, j = 1: v = (0, 1, 0), w = (0, 0, -1), the point at rest. */
    sdfccd_BodyState b = unit_body();
    b.angular_velocity = v3(0, 0, -2);
    ck_assert_int_eq(sdfccd_guard_response(&r, 1, NULL, 0.0, &b), SDFCCD_OK);
    ck_assert_double_near(b.linear_velocity.y, 1.0, 1e-15);
    ck_assert_double_near(b.angular_velocity.z, -1.0, 1e-15);
    ck_assert(b.linear_velocity.x == 0 && b.linear_velocity.z == 0 && b.angular_velocity.x == 0 && b.angular_velocity.y == 0);
    /* sliding along x as well, friction 0.5: the tangential impulse is min(0.5 j, |u| / kt) = 0.5 */
    b = unit_body();
    b.angular_velocity = v3(0, 0, -2);
    b.linear_velocity = v3(1, 0, 0);
    ck_assert_int_eq(sdfccd_guard_response(&r, 1, NULL, 0.5, &b), SDFCCD_OK);
    ck_assert_double_near(b.linear_velocity.x, 0.5, 1e-15);
    ck_assert_double_near(b.linear_velocity.y, 1.0, 1e-15);
    ck_assert_double_near(b.angular_velocity.z, -1.0, 1e-15);
    /* falling at its centre: first the centre's velocity into the surface goes */
    b = unit_body();
    b.linear_velocity = v3(0.2, -3, 0);
    ck_assert_int_eq(sdfccd_guard_response(&r, 1, NULL, 0.0, &b), SDFCCD_OK);
    ck_assert(b.linear_velocity.x == 0.2 && b.linear_velocity.y == 0.0);
    /* the first rollback keeps the velocity */
    b = unit_body();
    b.linear_velocity = v3(0.2, -3, 0);
    ck_assert_int_eq(sdfccd_guard_response(&r, 0, NULL, 0.0, &b), SDFCCD_OK);
    ck_assert(b.linear_velocity.y == -3.0);
    /* pinned on a moving, turning SDF body: the body takes its motion (at its centre (0, 0, 0)) */
    sdfccd_BodyState sdf = unit_body();
    sdf.center = v3(0, -1, 0);
    sdf.linear_velocity = v3(1, 0, 0);
    sdf.angular_velocity = v3(0, 0, 2); /* at (0, 0, 0): (1, 0, 0) + (0, 0, 2) x (0, 1, 0) = (-1, 0, 0) */
    r.pinned = 1;
    b = unit_body();
    b.linear_velocity = v3(5, 5, 5);
    ck_assert_int_eq(sdfccd_guard_response(&r, 0, &sdf, 0.3, &b), SDFCCD_OK);
    ck_assert_double_near(b.linear_velocity.x, -1.0, 1e-15);
    ck_assert(b.linear_velocity.y == 0 && b.linear_velocity.z == 0 && b.angular_velocity.z == 2.0);
    /* not rolled back: unchanged; bad input refused */
    r.state = SDFCCD_GUARD_CLEAR;
    b = unit_body();
    b.linear_velocity = v3(0, -1, 0);
    ck_assert_int_eq(sdfccd_guard_response(&r, 1, NULL, 0.0, &b), SDFCCD_OK);
    ck_assert(b.linear_velocity.y == -1.0);
    ck_assert_int_eq(sdfccd_guard_response(&r, 1, NULL, -1.0, &b), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_response(NULL, 1, NULL, 0.0, &b), SDFCCD_INVALID_ARGUMENT);
    b.inverse_mass = NAN;
    ck_assert_int_eq(sdfccd_guard_response(&r, 1, NULL, 0.0, &b), SDFCCD_INVALID_ARGUMENT);
}
END_TEST

/* sdfccd_guard_body on known inputs: a box (bottom at z = 1) falling at 2 m/s for 1 s, checked
 * against a far sphere, a ground at z = 0 and two grounds at z = 0.4. The earliest rollback is the
 * first z = 0.4 ground's, where the bottom first reached -TOL/2 (closed form t = 0.300125 s), equal
 * to that pair's own sdfccd_guard_step_rigid; evaluations and certificates are the pairs' sums. A
 * pair that fails is skipped and counted; moving up, or no pair, is CLEAR at t1. */
START_TEST(test_guard_body_earliest)
{
    const sdfccd_MeshId box = test_box_mesh(v3(0.1, 0.1, 0.1), 2, 2, 2);
    sdfccd_SdfId ball, ground, raised, dead;
    ck_assert_int_eq(sdfccd_create_sphere(0.5, &ball), SDFCCD_OK);
    sdfccd_Pose far = sdfccd_pose_identity();
    far.position = v3(10, 0, 0);
    sdfccd_SdfId far_ball;
    ck_assert_int_eq(sdfccd_create_transformed(ball, far, 1.0, &far_ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_half_space(v3(0, 0, 1), 0.0, &ground), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_half_space(v3(0, 0, 1), 0.4, &raised), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_half_space(v3(0, 0, 1), 0.2, &dead), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(dead), SDFCCD_OK);
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    const sdfccd_GuardParams gp = sdfccd_default_guard_params();
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = v3(0, 0, 1.1);
    m.linear_velocity = v3(0, 0, -2);
    sdfccd_GuardPair pairs[4] = { { far_ball, NULL, box, m }, { ground, NULL, box, m }, { raised, NULL, box, m }, { raised, NULL, box, m } };
    sdfccd_GuardBodyResult r;
    ck_assert_int_eq(sdfccd_guard_body(ws, pairs, 4, 0, 1, &gp, &r), SDFCCD_OK);
    ck_assert_int_eq(r.index, 2);
    ck_assert_int_eq(r.failed, 0);
    ck_assert_int_eq(r.error, SDFCCD_OK);
    ck_assert_int_eq(r.first.state, SDFCCD_GUARD_ROLLED_BACK);
    ck_assert_msg(r.first.toi <= 0.300125 && r.first.toi > 0.300125 - 1e-6, "toi %.12g", r.first.toi);
    int64_t evals = 0;
    int32_t certified = 0;
    for (int i = 0; i < 4; ++i) {
        sdfccd_GuardResult g;
        ck_assert_int_eq(sdfccd_guard_step_rigid(ws, pairs[i].sdf, NULL, box, &m, 0, 1, &gp, &g), SDFCCD_OK);
        evals += g.sdf_evaluations;
        certified += g.certified;
        if (i == 2) {
            ck_assert(g.toi == r.first.toi && g.triangle == r.first.triangle && g.sdf_evaluations == r.first.sdf_evaluations);
            ck_assert(memcmp(&g.safe_pose, &r.first.safe_pose, sizeof g.safe_pose) == 0);
        }
        if (i == 1) ck_assert(g.state == SDFCCD_GUARD_ROLLED_BACK && g.toi > r.first.toi + 0.19);
    }
    ck_assert_int_eq(certified, 1); /* the far ball */
    ck_assert(r.sdf_evaluations == evals);
    ck_assert_int_eq(r.certified, certified);
    /* A dead handle between two checks: skipped and counted; the later ground still decides. */
    sdfccd_GuardPair with_dead[3] = { { ground, NULL, box, m }, { dead, NULL, box, m }, { raised, NULL, box, m } };
    ck_assert_int_eq(sdfccd_guard_body(ws, with_dead, 3, 0, 1, &gp, &r), SDFCCD_OK);
    ck_assert_int_eq(r.index, 2);
    ck_assert_int_eq(r.failed, 1);
    ck_assert_int_eq(r.error, SDFCCD_INVALID_HANDLE);
    /* Moving up, and no pair: CLEAR at t1, no index. */
    for (int i = 0; i < 4; ++i) pairs[i].executed.linear_velocity = v3(0, 0, 2);
    ck_assert_int_eq(sdfccd_guard_body(ws, pairs, 4, 0, 1, &gp, &r), SDFCCD_OK);
    ck_assert(r.index == -1 && r.first.state == SDFCCD_GUARD_CLEAR && r.first.toi == 1.0 && r.failed == 0);
    ck_assert_int_eq(sdfccd_guard_body(ws, NULL, 0, 0, 1, &gp, &r), SDFCCD_OK);
    ck_assert(r.index == -1 && r.first.toi == 1.0 && r.sdf_evaluations == 0);
    /* Bad calls: nothing written. */
    r.index = 77;
    ck_assert_int_eq(sdfccd_guard_body(ws, pairs, -1, 0, 1, &gp, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_body(ws, NULL, 2, 0, 1, &gp, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_body(ws, pairs, 4, 0, 1, NULL, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_guard_body(ws, pairs, 4, 0, 1, &gp, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(r.index, 77);
    sdfccd_destroy_workspace(ws);
    sdfccd_destroy_sdf(far_ball);
    sdfccd_destroy_sdf(ball);
    sdfccd_destroy_sdf(ground);
    sdfccd_destroy_sdf(raised);
    sdfccd_destroy_mesh(box);
}
END_TEST

/* sdfccd_swept_aabb against a brute-force reference: points of a body at 400 times of a motion built
 * here (origin linear, a turn by a known angle <= pi about a known axis at a constant rate) must lie in
 * the box; the end boxes are the exact boxes of the points at the two poses. */
static sdfccd_Aabb points_box(const sdfccd_Vec3* x, int n, sdfccd_Vec3 origin, sdfccd_Quat q)
{
    sdfccd_Aabb b = { v3(INFINITY, INFINITY, INFINITY), v3(-INFINITY, -INFINITY, -INFINITY) };
    for (int i = 0; i < n; ++i) {
        const sdfccd_Vec3 r = rotate(q, x[i]);
        const double p[3] = { origin.x + r.x, origin.y + r.y, origin.z + r.z };
        b.lo = v3(fmin(b.lo.x, p[0]), fmin(b.lo.y, p[1]), fmin(b.lo.z, p[2]));
        b.hi = v3(fmax(b.hi.x, p[0]), fmax(b.hi.y, p[1]), fmax(b.hi.z, p[2]));
    }
    return b;
}

/* The largest distance (m) by which a point of the sampled motion leaves `box` (0: all inside). */
static double swept_escape(const sdfccd_Vec3* x, int n, sdfccd_Pose a, sdfccd_Vec3 axis, double angle, sdfccd_Vec3 end, const sdfccd_Aabb* box)
{
    double worst = 0;
    for (int k = 0; k <= 400; ++k) {
        const double s = k / 400.0;
        const sdfccd_Vec3 o = v3(a.position.x + s * (end.x - a.position.x), a.position.y + s * (end.y - a.position.y),
                                 a.position.z + s * (end.z - a.position.z));
        const sdfccd_Aabb at = points_box(x, n, o, qmul(axis_angle(axis, s * angle), a.orientation));
        worst = fmax(worst, fmax(fmax(box->lo.x - at.lo.x, box->lo.y - at.lo.y), box->lo.z - at.lo.z));
        worst = fmax(worst, fmax(fmax(at.hi.x - box->hi.x, at.hi.y - box->hi.y), at.hi.z - box->hi.z));
    }
    return worst;
}

START_TEST(test_swept_aabb)
{
    /* Translation only: the union of the two boxes, exactly (reach unused). */
    sdfccd_Aabb a = { v3(0, 0, 0), v3(1, 1, 1) }, b = { v3(2, 0, 0), v3(3, 1, 1) }, out;
    sdfccd_Pose p0 = sdfccd_pose_identity(), p1 = sdfccd_pose_identity();
    p0.position = v3(0.5, 0.5, 0.5);
    p1.position = v3(2.5, 0.5, 0.5);
    ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, &p1, -1.0, &out), SDFCCD_OK);
    ck_assert(out.lo.x == 0 && out.lo.y == 0 && out.lo.z == 0 && out.hi.x == 3 && out.hi.y == 1 && out.hi.z == 1);
    /* A 2 m rod along x turning half a revolution about z: both end boxes are flat in y, but at the
     * quarter turn the rod lies along y. The box is the reach box [-1, 1]^3 (its bow, pi^2 / 8 m, is
     * wider). */
    const sdfccd_Vec3 rod[2] = { v3(-1, 0, 0), v3(1, 0, 0) };
    p0 = sdfccd_pose_identity();
    p1 = sdfccd_pose_identity();
    p1.orientation = axis_angle(v3(0, 0, 1), M_PI);
    a = points_box(rod, 2, p0.position, p0.orientation);
    b = points_box(rod, 2, p1.position, p1.orientation);
    ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, &p1, 1.0, &out), SDFCCD_OK);
    ck_assert_double_eq_tol(out.lo.y, -1.0, 1e-12);
    ck_assert_double_eq_tol(out.hi.y, 1.0, 1e-12);
    ck_assert_double_eq_tol(out.lo.z, -1.0, 1e-12);
    ck_assert(swept_escape(rod, 2, p0, v3(0, 0, 1), M_PI, p1.position, &out) <= 1e-12);
    /* A small turn: a point at (1, 0, 0) from -0.1 to +0.1 rad about z passes x = 1 while both ends
     * have x = cos(0.1); with reach 1.2 the box reaches x = cos(0.1) + 1.2 * 0.2^2 / 8 >= 1. */
    const sdfccd_Vec3 tip[1] = { v3(1, 0, 0) };
    p0.orientation = axis_angle(v3(0, 0, 1), -0.1);
    p1.orientation = axis_angle(v3(0, 0, 1), 0.1);
    a = points_box(tip, 1, p0.position, p0.orientation);
    b = points_box(tip, 1, p1.position, p1.orientation);
    ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, &p1, 1.2, &out), SDFCCD_OK);
    ck_assert_double_eq_tol(out.hi.x, cos(0.1) + 1.2 * 0.2 * 0.2 / 8.0, 1e-12);
    ck_assert(swept_escape(tip, 1, p0, v3(0, 0, 1), 0.2, p1.position, &out) <= 1e-12);
    /* Seeded sweep: 200 bodies of 12 points within reach 0.5 of the origin, random translations and
     * turns of up to pi. Every sampled point is inside; the box never exceeds the reach box. */
    test_rng rng = { 1919 };
    for (int i = 0; i < 200; ++i) {
        sdfccd_Vec3 x[12];
        for (int j = 0; j < 12; ++j) {
            const sdfccd_Vec3 u = test_rng_unit_vector(&rng);
            const double r = 0.5 * test_rng_uniform(&rng, 0.2, 1.0);
            x[j] = v3(r * u.x, r * u.y, r * u.z);
        }
        const sdfccd_Vec3 axis = test_rng_unit_vector(&rng), t = test_rng_unit_vector(&rng);
        const double angle = test_rng_uniform(&rng, 0.0, 1.0) * test_rng_uniform(&rng, 0.0, M_PI);
        const double travel = test_rng_uniform(&rng, 0.0, 2.0);
        p0.position = test_rng_unit_vector(&rng);
        p0.orientation = axis_angle(test_rng_unit_vector(&rng), test_rng_uniform(&rng, -3, 3));
        p1.position = v3(p0.position.x + travel * t.x, p0.position.y + travel * t.y, p0.position.z + travel * t.z);
        p1.orientation = qmul(axis_angle(axis, angle), p0.orientation);
        a = points_box(x, 12, p0.position, p0.orientation);
        b = points_box(x, 12, p1.position, p1.orientation);
        ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, &p1, 0.5, &out), SDFCCD_OK);
        ck_assert_msg(swept_escape(x, 12, p0, axis, angle, p1.position, &out) <= 1e-12, "body %d, turn %g", i, angle);
        ck_assert(out.lo.x >= fmin(p0.position.x, p1.position.x) - 0.5 - 1e-12 && out.hi.z <= fmax(p0.position.z, p1.position.z) + 0.5 + 1e-12);
    }
    /* Bad input: nothing written. */
    const sdfccd_Aabb keep = out, nan_box = { v3(NAN, 0, 0), v3(1, 1, 1) };
    ck_assert_int_eq(sdfccd_swept_aabb(NULL, &b, &p0, &p1, 0.5, &out), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, NULL, 0.5, &out), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, &p1, 0.5, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_swept_aabb(&nan_box, &b, &p0, &p1, 0.5, &out), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, &p1, NAN, &out), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, &p1, -0.5, &out), SDFCCD_INVALID_ARGUMENT);
    p1.orientation.w = p1.orientation.x = p1.orientation.y = p1.orientation.z = 0;
    ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, &p1, 0.5, &out), SDFCCD_INVALID_ARGUMENT);
    p1.orientation = p0.orientation;
    p1.position.y = INFINITY;
    ck_assert_int_eq(sdfccd_swept_aabb(&a, &b, &p0, &p1, 0.5, &out), SDFCCD_INVALID_ARGUMENT);
    ck_assert(memcmp(&keep, &out, sizeof out) == 0);
    ck_assert(strstr(sdfccd_last_error(), "sdfccd_swept_aabb") != NULL);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("guard");
    TCase* tc = tcase_create("guard");
    test_add_memory_fixture(tc);
    tcase_set_timeout(tc, 600);
    /* first: sdfccd_set_allocator needs no library memory live (without fork the suites share a process) */
    tcase_add_test(tc, test_no_allocation_after_warm_up);
    tcase_add_test(tc, test_spun_through_thin_wall);
    tcase_add_test(tc, test_spun_more_than_a_turn);
    tcase_add_test(tc, test_spun_certified);
    tcase_add_test(tc, test_fast_tilted_plate);
    tcase_add_test(tc, test_moving_away_is_clear);
    tcase_add_test(tc, test_inside_at_start_left_to_contacts);
    tcase_add_test(tc, test_inside_at_start_sinking_further);
    tcase_add_test(tc, test_inside_at_start_rest_guarded);
    tcase_add_test(tc, test_moving_sdf);
    tcase_add_test(tc, test_guard_linear_cloth);
    tcase_add_test(tc, test_shuriken_battery);
    tcase_add_test(tc, test_motion_from_poses);
    tcase_add_test(tc, test_swept_aabb);
    tcase_add_test(tc, test_bad_input);
    tcase_add_test(tc, test_step_spun_through_wall);
    tcase_add_test(tc, test_step_clear_and_certified);
    tcase_add_test(tc, test_step_inside_and_pinned);
    tcase_add_test(tc, test_step_inside_slides_into_wall);
    tcase_add_test(tc, test_step_certificate_brute_force);
    tcase_add_test(tc, test_response);
    tcase_add_test(tc, test_guard_body_earliest);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
