/* SPDX-License-Identifier: MIT
 * The guarantee for a world (contact.h, sdfccd_guard_world; issue 19), public ABI only, on known
 * inputs with closed-form answers: 10 cm boxes (test_box_mesh) moved or spun through a 1 cm wall
 * (a box SDF placed by its poses) in one step of 1/60 s. A rolled-back body must be where its first
 * point was half the tolerance below the wall's top (the guard's safe time, contact.h), which for a
 * translation is t = (travel to that level) / speed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

static const double DT = 1.0 / 60.0;
static const double TOL = 5e-4;  /* the default guard tolerance */
static const double WALL = 0.005; /* the wall's half thickness: its top is at z = WALL at its origin */
static const double H = 0.1;      /* the boxes' half size */
/* How early a TOI may be (contact.h): the guard's time tolerance, tightened so that no point moves
 * more than a tenth of the tolerance in it, at the 1 m per step (60 m/s) of these motions. */
static const double EARLY = 0.1 * 5e-4 / 60.0;

static sdfccd_Vec3 v3(double x, double y, double z) { return (sdfccd_Vec3){ x, y, z }; }

static sdfccd_Quat axis_angle(sdfccd_Vec3 axis, double angle)
{
    double l = sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z), s = sin(0.5 * angle) / l;
    return (sdfccd_Quat){ cos(0.5 * angle), axis.x * s, axis.y * s, axis.z * s };
}

static sdfccd_Pose at(double x, double y, double z)
{
    sdfccd_Pose p = sdfccd_pose_identity();
    p.position = v3(x, y, z);
    return p;
}

/* A box around a pose's position holding every point within `r` of it. */
static sdfccd_Aabb ball_box(sdfccd_Pose p, double r)
{
    return (sdfccd_Aabb){ v3(p.position.x - r, p.position.y - r, p.position.z - r), v3(p.position.x + r, p.position.y + r, p.position.z + r) };
}

/* The wall (a 4 m x 4 m x 1 cm box SDF) from pose `a` at t0 to pose `b` at t1, static (no body). */
static sdfccd_GuardSdf wall_sdf(sdfccd_SdfId wall, sdfccd_Pose a, sdfccd_Pose b)
{
    sdfccd_GuardSdf s;
    memset(&s, 0, sizeof s);
    s.sdf = wall;
    s.start = a;
    s.end = b;
    s.reach = sqrt(8.0 + WALL * WALL);
    s.start_box = ball_box(a, s.reach);
    s.end_box = ball_box(b, s.reach);
    s.friction = 0.5;
    s.body = -1;
    return s;
}

/* A dynamic body of unit mass and inertia moving from `a` to `b` (its centre of mass at its origin). */
static sdfccd_GuardRigidBody body_of(const sdfccd_GuardPart* parts, int32_t n, sdfccd_Pose a, sdfccd_Pose b, double reach)
{
    sdfccd_GuardRigidBody r;
    memset(&r, 0, sizeof r);
    r.start = a;
    r.end = b;
    r.reach = reach;
    r.start_box = ball_box(a, reach);
    r.end_box = ball_box(b, reach);
    r.parts = parts;
    r.part_count = n;
    r.friction = 0.5;
    r.state.center = b.position;
    r.state.linear_velocity = v3((b.position.x - a.position.x) / DT, (b.position.y - a.position.y) / DT, (b.position.z - a.position.z) / DT);
    r.state.inverse_mass = 1.0;
    r.state.inverse_inertia[0] = r.state.inverse_inertia[4] = r.state.inverse_inertia[8] = 1.0;
    return r;
}

static sdfccd_GuardPart part_of(sdfccd_MeshId mesh, sdfccd_Pose offset)
{
    sdfccd_GuardPart p;
    memset(&p, 0, sizeof p);
    p.mesh = mesh;
    p.offset = offset;
    return p;
}

typedef struct fixture {
    sdfccd_Workspace* ws;
    sdfccd_SdfId wall;
    sdfccd_MeshId box;
    sdfccd_GuardParams gp;
} fixture;

static fixture setup(void)
{
    fixture f;
    ck_assert_int_eq(sdfccd_create_workspace(&f.ws), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_box(v3(2, 2, WALL), &f.wall), SDFCCD_OK);
    f.box = test_box_mesh(v3(H, H, H), 2, 2, 2);
    f.gp = sdfccd_default_guard_params();
    return f;
}

static void teardown(fixture* f)
{
    sdfccd_destroy_workspace(f->ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(f->wall), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(f->box), SDFCCD_OK);
}

static sdfccd_GuardWorldResult run1(fixture* f, const sdfccd_GuardSdf* sdfs, int32_t n, const sdfccd_GuardRigidBody* body)
{
    sdfccd_GuardWorldResult r;
    ck_assert_msg(sdfccd_guard_world(f->ws, sdfs, n, body, 1, 0.0, DT, &f->gp, NULL, NULL, &r) == SDFCCD_OK, "%s", sdfccd_last_error());
    return r;
}

/* A world with more bodies than the references one call may hold at once (32 on a thread): 48 boxes
 * side by side moved through the wall are each rolled back, as one box alone is. */
START_TEST(test_many_bodies)
{
    fixture f = setup();
    enum { N = 48 };
    const sdfccd_GuardSdf wall = wall_sdf(f.wall, at(0, 0, 0), at(0, 0, 0));
    const sdfccd_GuardPart part = part_of(f.box, sdfccd_pose_identity());
    sdfccd_GuardRigidBody bodies[N];
    sdfccd_GuardWorldResult r[N];
    for (int i = 0; i < N; ++i) {
        const double x = -0.9 + 1.8 * i / (N - 1);
        bodies[i] = body_of(&part, 1, at(x, 0, 0.5), at(x, 0, -0.5), 0.2);
    }
    ck_assert_msg(sdfccd_guard_world(f.ws, &wall, 1, bodies, N, 0.0, DT, &f.gp, NULL, NULL, r) == SDFCCD_OK, "%s", sdfccd_last_error());
    for (int i = 0; i < N; ++i) ck_assert_msg(r[i].rolled_back == 1 && r[i].failures == 0, "body %d not rolled back", i);
    teardown(&f);
}
END_TEST

/* The time a box falling from centre z0 to z1 over the step brings its bottom to `top` - TOL/2. */
static double half_level_time(double z0, double z1, double top)
{
    return (z0 - (top - 0.5 * TOL + H)) / (z0 - z1) * DT;
}

/* Moved through the wall (centre 0.5 -> -0.5 m in one step, 60 m/s): put back at its safe time, the
 * bottom half the tolerance into the wall (closed form), at rest against the wall (it loses its
 * velocity into the surface); the result is the pair's own sdfccd_guard_step_rigid. */
START_TEST(test_moved_through_wall)
{
    fixture f = setup();
    const sdfccd_GuardSdf wall = wall_sdf(f.wall, at(0, 0, 0), at(0, 0, 0));
    const sdfccd_GuardPart part = part_of(f.box, sdfccd_pose_identity());
    const sdfccd_GuardRigidBody body = body_of(&part, 1, at(0, 0, 0.5), at(0, 0, -0.5), 0.2);
    const sdfccd_GuardWorldResult r = run1(&f, &wall, 1, &body);
    const double t = half_level_time(0.5, -0.5, WALL);
    ck_assert(r.rolled_back == 1 && r.sdf == 0 && r.part == 0 && r.queries == 1 && r.failures == 0);
    ck_assert_msg(r.guard.toi <= t && r.guard.toi >= t - EARLY, "toi %.12g, closed form %.12g", r.guard.toi, t);
    ck_assert_double_near(r.pose.position.z, 0.5 - r.guard.toi / DT, 1e-12);
    const double bottom = r.pose.position.z - H;
    ck_assert_msg(bottom >= WALL - 0.5 * TOL - 1e-12 && bottom <= WALL - 0.4 * TOL, "bottom %.9g", bottom);
    ck_assert_double_near(r.state.center.z, r.pose.position.z, 1e-12);
    ck_assert_double_near(r.state.linear_velocity.z, 0.0, 1e-9);
    /* The same check by hand. */
    sdfccd_RigidMotion m, sm;
    sdfccd_GuardResult g;
    ck_assert_int_eq(sdfccd_rigid_motion_from_poses(&body.start, &body.end, v3(0, 0, 0), 0, DT, &m), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_rigid_motion_from_poses(&wall.start, &wall.end, v3(0, 0, 0), 0, DT, &sm), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_guard_step_rigid(f.ws, f.wall, &sm, f.box, &m, 0, DT, &f.gp, &g), SDFCCD_OK);
    ck_assert(g.toi == r.guard.toi && g.sdf_evaluations == r.sdf_evaluations && memcmp(&g.safe_pose, &r.pose, sizeof g.safe_pose) == 0);
    teardown(&f);
}
END_TEST

/* Spun through the wall: a 1 m x 4 cm x 4 cm bar (its centre of mass 0.3 m above the wall's top)
 * turning by 1.2 rad about y in one step about its centre of mass. The body's origin is at the bar's
 * end (the part's offset puts the bar's centre at +0.5 m in x), so the motion's centre is the state's
 * centre, not the origin. The lowest corner, at distance R from the centre, first reaches the half
 * level when R sin(a + phi) = 0.3 + TOL/2: put back at that angle (closed form), the centre in place,
 * and the corner no longer approaches the wall. */
static sdfccd_Pose bar_pose(double angle)
{
    sdfccd_Pose p;
    p.orientation = axis_angle(v3(0, 1, 0), angle);
    p.position = v3(-0.5 * cos(angle), 0, 0.3 + WALL + 0.5 * sin(angle)); /* the centre minus R(angle) (0.5, 0, 0) */
    return p;
}

START_TEST(test_spun_through_wall)
{
    fixture f = setup();
    const sdfccd_MeshId bar = test_box_mesh(v3(0.5, 0.02, 0.02), 10, 1, 1);
    const sdfccd_GuardSdf wall = wall_sdf(f.wall, at(0, 0, 0), at(0, 0, 0));
    const sdfccd_GuardPart part = part_of(bar, at(0.5, 0, 0));
    sdfccd_GuardRigidBody body = body_of(&part, 1, bar_pose(0), bar_pose(1.2), 1.01);
    body.state.center = v3(0, 0, 0.3 + WALL);
    body.state.linear_velocity = v3(0, 0, 0);
    body.state.angular_velocity = v3(0, 1.2 / DT, 0);
    const sdfccd_GuardWorldResult r = run1(&f, &wall, 1, &body);
    const double R = hypot(0.5, 0.02), phi = atan2(0.02, 0.5);
    const double t = (asin((0.3 + 0.5 * TOL) / R) - phi) / (1.2 / DT);
    ck_assert(r.rolled_back == 1 && r.part == 0);
    ck_assert_msg(r.guard.toi <= t && r.guard.toi >= t - 3e-7, "toi %.12g, closed form %.12g", r.guard.toi, t);
    /* The safe pose: the bar turned by 1.2 toi / DT about y about its centre. */
    const sdfccd_Pose expect = bar_pose(1.2 * r.guard.toi / DT);
    ck_assert_double_near(r.pose.orientation.w, expect.orientation.w, 1e-12);
    ck_assert_double_near(r.pose.orientation.y, expect.orientation.y, 1e-12);
    ck_assert_double_near(r.pose.position.x, expect.position.x, 1e-12);
    ck_assert_double_near(r.pose.position.z, expect.position.z, 1e-12);
    ck_assert_double_near(r.state.center.x, 0.0, 1e-12);
    ck_assert_double_near(r.state.center.z, 0.3 + WALL, 1e-12);
    /* The corner's velocity into the wall is gone. */
    const sdfccd_Vec3 p = r.guard.point, c = r.state.center, w = r.state.angular_velocity;
    const double vz = r.state.linear_velocity.z + (w.x * (p.y - c.y) - w.y * (p.x - c.x));
    ck_assert_msg(vz >= -1e-9, "the corner still approaches at %.9g m/s", vz);
    ck_assert_double_near(r.guard.normal.z, 1.0, 1e-9);
    ck_assert_int_eq(sdfccd_destroy_mesh(bar), SDFCCD_OK);
    teardown(&f);
}
END_TEST

/* Moving away (up from just above the wall): not rolled back, its end pose and state untouched. */
START_TEST(test_moving_away_left_alone)
{
    fixture f = setup();
    const sdfccd_GuardSdf wall = wall_sdf(f.wall, at(0, 0, 0), at(0, 0, 0));
    const sdfccd_GuardPart part = part_of(f.box, sdfccd_pose_identity());
    const sdfccd_GuardRigidBody body = body_of(&part, 1, at(0, 0, WALL + H + 0.001), at(0, 0, 0.6), 0.2);
    const sdfccd_GuardWorldResult r = run1(&f, &wall, 1, &body);
    ck_assert(r.rolled_back == 0 && r.sdf == -1 && r.part == -1 && r.queries == 1 && r.failures == 0);
    ck_assert(memcmp(&r.pose, &body.end, sizeof r.pose) == 0 && memcmp(&r.state, &body.state, sizeof r.state) == 0);
    ck_assert(r.guard.state == SDFCCD_GUARD_CLEAR && r.guard.toi == DT);
    teardown(&f);
}
END_TEST

/* Two SDFs: the wall at z = 0 listed first and one at z = 0.2 listed second; the box falling through
 * both goes back to the second one's time (earlier, closed form), whatever the order. The hook is
 * called once, for that SDF, with the safe pose; the friction it returns is the response's. */
static int g_placed, g_placed_sdf;
static sdfccd_Pose g_placed_pose;
static void count_place(void* user, int32_t body, int32_t sdf, const sdfccd_Pose* pose, sdfccd_BodyState* state, double* friction)
{
    (void)user;
    (void)state;
    ck_assert_int_eq(body, 0);
    ++g_placed;
    g_placed_sdf = sdf;
    g_placed_pose = *pose;
    ck_assert_double_near(*friction, 0.25, 1e-15); /* 0.5 x 0.5 */
}

START_TEST(test_two_sdfs_earliest_wins)
{
    fixture f = setup();
    const sdfccd_GuardSdf walls[2] = { wall_sdf(f.wall, at(0, 0, 0), at(0, 0, 0)), wall_sdf(f.wall, at(0, 0, 0.2), at(0, 0, 0.2)) };
    const sdfccd_GuardPart part = part_of(f.box, sdfccd_pose_identity());
    const sdfccd_GuardRigidBody body = body_of(&part, 1, at(0, 0, 0.5), at(0, 0, -0.5), 0.2);
    g_placed = 0;
    sdfccd_GuardWorldResult r;
    ck_assert_int_eq(sdfccd_guard_world(f.ws, walls, 2, &body, 1, 0.0, DT, &f.gp, count_place, NULL, &r), SDFCCD_OK);
    const double t = half_level_time(0.5, -0.5, 0.2 + WALL);
    ck_assert(r.rolled_back == 1 && r.sdf == 1 && r.queries == 2);
    ck_assert_msg(r.guard.toi <= t && r.guard.toi >= t - EARLY, "toi %.12g, closed form %.12g", r.guard.toi, t);
    ck_assert(g_placed == 1 && g_placed_sdf == 1 && memcmp(&g_placed_pose, &r.pose, sizeof r.pose) == 0);
    const sdfccd_GuardSdf swapped[2] = { walls[1], walls[0] };
    sdfccd_GuardWorldResult s;
    ck_assert_int_eq(sdfccd_guard_world(f.ws, swapped, 2, &body, 1, 0.0, DT, &f.gp, NULL, NULL, &s), SDFCCD_OK);
    ck_assert(s.sdf == 0 && s.guard.toi == r.guard.toi);
    teardown(&f);
}
END_TEST

/* A two-part body (a compound): part 0 half a metre above the body's origin, part 1 at 1 m to the
 * side turned 0.4 rad about z (its bottom still flat). Falling through the wall, part 1 reaches it
 * first; the body goes back to where part 1's bottom is at the half level: the body's origin at the
 * same height as a single box's, its orientation the start's. */
START_TEST(test_second_part_hits)
{
    fixture f = setup();
    const sdfccd_GuardSdf wall = wall_sdf(f.wall, at(0, 0, 0), at(0, 0, 0));
    sdfccd_Pose side = at(-1, 0, 0);
    side.orientation = axis_angle(v3(0, 0, 1), 0.4);
    const sdfccd_GuardPart parts[2] = { part_of(f.box, at(1, 0, 0.5)), part_of(f.box, side) };
    const sdfccd_GuardRigidBody body = body_of(parts, 2, at(0, 0, 0.5), at(0, 0, -0.5), 1.3);
    const sdfccd_GuardWorldResult r = run1(&f, &wall, 1, &body);
    const double t = half_level_time(0.5, -0.5, WALL);
    ck_assert(r.rolled_back == 1 && r.part == 1 && r.queries == 2);
    ck_assert_msg(r.guard.toi <= t && r.guard.toi >= t - EARLY, "toi %.12g, closed form %.12g", r.guard.toi, t);
    ck_assert_double_near(r.pose.position.x, 0.0, 1e-12);
    ck_assert_double_near(r.pose.position.z, 0.5 - r.guard.toi / DT, 1e-12);
    ck_assert_double_near(fabs(r.pose.orientation.w), 1.0, 1e-12);
    /* The part's own safe pose is the body's times the offset. */
    ck_assert_double_near(r.guard.safe_pose.position.x, -1.0, 1e-12);
    ck_assert_double_near(r.guard.safe_pose.orientation.z, side.orientation.z, 1e-12);
    teardown(&f);
}
END_TEST

/* A kinematic wall rising 1 m in the step (with its body's velocity, 60 m/s) under a box at rest
 * 0.4 m above it: the box is rolled back at the closed-form time and carried with the wall to its end
 * pose, so it sits at the same place relative to the wall (bottom half the tolerance in) and moves
 * with it. */
START_TEST(test_moving_sdf_carries)
{
    fixture f = setup();
    sdfccd_GuardSdf wall = wall_sdf(f.wall, at(0, 0, 0), at(0, 0, 1));
    wall.has_state = 1;
    wall.state.center = wall.end.position;
    wall.state.linear_velocity = v3(0, 0, 1.0 / DT);
    const sdfccd_GuardPart part = part_of(f.box, sdfccd_pose_identity());
    const sdfccd_GuardRigidBody body = body_of(&part, 1, at(0, 0, 0.5), at(0, 0, 0.5), 0.2);
    const sdfccd_GuardWorldResult r = run1(&f, &wall, 1, &body);
    const double t = (0.5 - H - WALL + 0.5 * TOL) * DT; /* the wall's top rises 1 m per step */
    ck_assert(r.rolled_back == 1 && r.sdf == 0);
    ck_assert_msg(r.guard.toi <= t && r.guard.toi >= t - EARLY, "toi %.12g, closed form %.12g", r.guard.toi, t);
    ck_assert_double_near(r.pose.position.z, 0.5 + (1.0 - r.guard.toi / DT), 1e-12);
    const double bottom = r.pose.position.z - H - (1.0 + WALL);
    ck_assert_msg(bottom >= -0.5 * TOL - 1e-12 && bottom <= -0.4 * TOL, "bottom %.9g relative to the wall's top", bottom);
    ck_assert_double_near(r.state.linear_velocity.z, 1.0 / DT, 1e-9);
    teardown(&f);
}
END_TEST

/* No query where nothing can have gone deeper: a sleeping box (start = end) resting on a static
 * wall, a box far from it (boxes apart), a part that is the SDF's own surface (same shape key), and
 * a body with no parts: 0 queries, 0 evaluations. The sleeping box on a rising wall is checked. */
START_TEST(test_still_pair_costs_nothing)
{
    fixture f = setup();
    sdfccd_GuardSdf wall = wall_sdf(f.wall, at(0, 0, 0), at(0, 0, 0));
    wall.shape_key = 7;
    sdfccd_GuardPart parts[2] = { part_of(f.box, sdfccd_pose_identity()), part_of(f.box, sdfccd_pose_identity()) };
    parts[1].shape_key = 7;
    const sdfccd_Pose rest = at(0, 0, WALL + H - 0.2 * TOL);
    sdfccd_GuardRigidBody bodies[4] = { body_of(parts, 1, rest, rest, 0.2), body_of(parts, 1, at(5, 0, 1), at(5, 0, 0.9), 0.2),
                                        body_of(parts + 1, 1, at(0, 0, 0.5), at(0, 0, -0.5), 0.2),
                                        body_of(NULL, 0, at(0, 0, 0.5), at(0, 0, -0.5), 0.2) };
    sdfccd_GuardWorldResult r[4];
    ck_assert_int_eq(sdfccd_guard_world(f.ws, &wall, 1, bodies, 4, 0.0, DT, &f.gp, NULL, NULL, r), SDFCCD_OK);
    for (int i = 0; i < 4; ++i) ck_assert_msg(r[i].queries == 0 && r[i].sdf_evaluations == 0 && !r[i].rolled_back, "body %d", i);
    wall.end = at(0, 0, 0.01);
    wall.end_box = ball_box(wall.end, wall.reach);
    ck_assert_int_eq(sdfccd_guard_world(f.ws, &wall, 1, bodies, 1, 0.0, DT, &f.gp, NULL, NULL, r), SDFCCD_OK);
    ck_assert(r[0].queries == 1 && r[0].rolled_back == 1);
    teardown(&f);
}
END_TEST

/* An SDF carried by a dynamic body (a slab of the world rising at 2 m/s, its own mesh inside it) is
 * not checked against that body, and the response takes that body's state: a box falling on it
 * leaves with the slab's vertical velocity. */
START_TEST(test_sdf_of_a_body)
{
    fixture f = setup();
    const sdfccd_GuardPart part = part_of(f.box, sdfccd_pose_identity());
    const sdfccd_Pose lift = at(0, 0, 2 * DT);
    sdfccd_GuardSdf wall = wall_sdf(f.wall, at(0, 0, 0), lift);
    wall.body = 1;
    wall.has_state = 1; /* ignored: the body's state counts */
    sdfccd_GuardRigidBody bodies[2] = { body_of(&part, 1, at(0, 0, 0.5), at(0, 0, -0.5), 0.2), body_of(&part, 1, at(0, 0, 0), lift, 0.2) };
    sdfccd_GuardWorldResult r[2];
    ck_assert_int_eq(sdfccd_guard_world(f.ws, &wall, 1, bodies, 2, 0.0, DT, &f.gp, NULL, NULL, r), SDFCCD_OK);
    ck_assert(r[0].rolled_back == 1 && r[1].queries == 0 && r[1].rolled_back == 0);
    ck_assert_double_near(r[0].state.linear_velocity.z, 2.0, 1e-9);
    teardown(&f);
}
END_TEST

static void never_place(void* user, int32_t body, int32_t sdf, const sdfccd_Pose* pose, sdfccd_BodyState* state, double* friction)
{
    (void)user, (void)body, (void)sdf, (void)pose, (void)state, (void)friction;
    ck_abort_msg("the hook was called on bad input");
}

/* Bad input: a status and a message naming the function, nothing written, the hook not called. */
START_TEST(test_bad_input)
{
    fixture f = setup();
    sdfccd_GuardSdf wall = wall_sdf(f.wall, at(0, 0, 0), at(0, 0, 0));
    sdfccd_GuardPart part = part_of(f.box, sdfccd_pose_identity());
    sdfccd_GuardRigidBody body = body_of(&part, 1, at(0, 0, 0.5), at(0, 0, -0.5), 0.2);
    sdfccd_GuardWorldResult r, keep;
    memset(&r, 0x5a, sizeof r);
    keep = r;
    sdfccd_GuardParams zero;
    memset(&zero, 0, sizeof zero);
    sdfccd_GuardParams neg = f.gp;
    neg.tolerance = -1.0;
#define BAD(status, call)                                                                    \
    do {                                                                                     \
        ck_assert_int_eq((call), (status));                                                  \
        ck_assert(memcmp(&r, &keep, sizeof r) == 0);                                         \
        ck_assert_msg(strstr(sdfccd_last_error(), "sdfccd_guard_world") != NULL || (status) == SDFCCD_INVALID_HANDLE, \
                      "%s", sdfccd_last_error());                                            \
    } while (0)
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(NULL, &wall, 1, &body, 1, 0, DT, &f.gp, never_place, NULL, &r));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, 1, &body, 1, 0, DT, NULL, never_place, NULL, &r));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, 1, &body, 1, 0, DT, &zero, never_place, NULL, &r));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, 1, &body, 1, 0, DT, &neg, never_place, NULL, &r));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, -1, &body, 1, 0, DT, &f.gp, never_place, NULL, &r));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, 1, &body, -1, 0, DT, &f.gp, never_place, NULL, &r));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, NULL, 1, &body, 1, 0, DT, &f.gp, never_place, NULL, &r));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, 1, NULL, 1, 0, DT, &f.gp, never_place, NULL, &r));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, 1, &body, 1, 0, DT, &f.gp, never_place, NULL, NULL));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, 1, &body, 1, DT, DT, &f.gp, never_place, NULL, &r));
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, 1, &body, 1, 0, NAN, &f.gp, never_place, NULL, &r));
    /* One bad field at a time, each restored. */
#define BAD_FIELD_STATUS(status, field, value)                                                        \
    do {                                                                                                  \
        const __typeof__(field) saved_ = (field);                                                         \
        (field) = (value);                                                                                \
        BAD((status), sdfccd_guard_world(f.ws, &wall, 1, &body, 1, 0, DT, &f.gp, never_place, NULL, &r)); \
        (field) = saved_;                                                                                 \
    } while (0)
#define BAD_FIELD(field, value) BAD_FIELD_STATUS(SDFCCD_INVALID_ARGUMENT, field, value)
    BAD_FIELD(body.start.position.x, NAN);
    BAD_FIELD(body.end.orientation.w, NAN);
    BAD_FIELD(body.end.orientation.w, 2.0);
    BAD_FIELD(wall.start.position.z, INFINITY);
    BAD_FIELD(wall.end.orientation.x, NAN);
    BAD_FIELD(body.start_box.lo.y, NAN);
    BAD_FIELD(wall.end_box.hi.z, NAN);
    BAD_FIELD(body.reach, -1.0);
    BAD_FIELD(wall.friction, NAN);
    BAD_FIELD(body.friction, -0.1);
    BAD_FIELD(body.state.linear_velocity.x, NAN);
    BAD_FIELD(body.state.inverse_mass, -1.0);
    BAD_FIELD(body.part_count, -1);
    BAD_FIELD(wall.body, 1);
    BAD_FIELD(wall.body, -2);
    BAD_FIELD(part.offset.position.y, NAN);
    wall.has_state = 1;
    BAD_FIELD(wall.state.angular_velocity.z, NAN);
    wall.has_state = 0;
    body.parts = NULL;
    BAD(SDFCCD_INVALID_ARGUMENT, sdfccd_guard_world(f.ws, &wall, 1, &body, 1, 0, DT, &f.gp, never_place, NULL, &r));
    body.parts = &part;
    sdfccd_SdfId dead;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &dead), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(dead), SDFCCD_OK);
    BAD_FIELD_STATUS(SDFCCD_INVALID_HANDLE, wall.sdf, dead);
    sdfccd_MeshId dead_mesh = test_box_mesh(v3(H, H, H), 1, 1, 1);
    ck_assert_int_eq(sdfccd_destroy_mesh(dead_mesh), SDFCCD_OK);
    BAD_FIELD_STATUS(SDFCCD_INVALID_HANDLE, part.mesh, dead_mesh);
    /* Still good after all that: the same result as a clean run. */
    ck_assert_int_eq(sdfccd_guard_world(f.ws, &wall, 1, &body, 1, 0, DT, &f.gp, NULL, NULL, &r), SDFCCD_OK);
    ck_assert(r.rolled_back == 1);
    ck_assert_int_eq(sdfccd_guard_world(f.ws, NULL, 0, NULL, 0, 0, DT, &f.gp, never_place, NULL, NULL), SDFCCD_OK);
#undef BAD_FIELD
#undef BAD_FIELD_STATUS
#undef BAD
    teardown(&f);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("guard_world");
    TCase* tc = tcase_create("guard_world");
    test_add_memory_fixture(tc);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_moved_through_wall);
    tcase_add_test(tc, test_spun_through_wall);
    tcase_add_test(tc, test_moving_away_left_alone);
    tcase_add_test(tc, test_two_sdfs_earliest_wins);
    tcase_add_test(tc, test_second_part_hits);
    tcase_add_test(tc, test_moving_sdf_carries);
    tcase_add_test(tc, test_still_pair_costs_nothing);
    tcase_add_test(tc, test_sdf_of_a_body);
    tcase_add_test(tc, test_bad_input);
    tcase_add_test(tc, test_many_bodies);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
