/* SPDX-License-Identifier: MIT
 * A soft body's step against an SDF (soft.h, issue 19 item 5): contact planes of nodes and faces,
 * holding nodes on them with Coulomb friction, and the guard, on known inputs with closed-form
 * answers (half-spaces and spheres), in an identity and in a rotated, shifted SDF frame. Public ABI only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

static sdfccd_Vec3 v3(double x, double y, double z) { return (sdfccd_Vec3){ x, y, z }; }

static sdfccd_Frame identity_frame(void)
{
    sdfccd_Frame f = { { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } }, { 0, 0, 0 } };
    return f;
}

/* 90 degrees about x, then shifted: local z is world -y; local (0, 0, 0) is world (1, 2, 3). */
static sdfccd_Frame turned_frame(void)
{
    sdfccd_Frame f = { { { 1, 0, 0 }, { 0, 0, -1 }, { 0, 1, 0 } }, { 1, 2, 3 } };
    return f;
}

static sdfccd_Vec3 to_world(const sdfccd_Frame* f, sdfccd_Vec3 p)
{
    const double(*r)[3] = f->rotation;
    return v3(r[0][0] * p.x + r[0][1] * p.y + r[0][2] * p.z + f->origin.x, r[1][0] * p.x + r[1][1] * p.y + r[1][2] * p.z + f->origin.y,
              r[2][0] * p.x + r[2][1] * p.y + r[2][2] * p.z + f->origin.z);
}

static sdfccd_SdfId half_space_z(void)
{
    sdfccd_SdfId s;
    ck_assert(sdfccd_create_half_space(v3(0, 0, 1), 0, &s) == SDFCCD_OK);
    return s;
}

static sdfccd_SdfId sphere(double r)
{
    sdfccd_SdfId s;
    ck_assert(sdfccd_create_sphere(r, &s) == SDFCCD_OK);
    return s;
}

static sdfccd_SoftContactParams contact_params(double soft_margin)
{
    sdfccd_SoftContactParams p = { sdfccd_default_query_params(), soft_margin, 0.0, 0.01 };
    return p;
}

/* Nodes against the plane z >= 0 (local), soft margin 1 cm: node 0 falls through and gets the plane
 * z = 1 cm (closed form), node 1 passes 0.5 m above and gets none, node 2 falls through but is
 * pinned. In a turned, shifted frame the world plane is the local one carried over. */
START_TEST(test_contacts_node_half_space)
{
    const sdfccd_SdfId plane = half_space_z();
    for (int turned = 0; turned < 2; ++turned) {
        const sdfccd_Frame F = turned ? turned_frame() : identity_frame();
        const sdfccd_Vec3 start[3] = { to_world(&F, v3(0.2, 0, 0.1)), to_world(&F, v3(0, 0, 0.5)), to_world(&F, v3(1, 0, 0.1)) };
        const sdfccd_Vec3 end[3] = { to_world(&F, v3(0.2, 0, -0.05)), to_world(&F, v3(0.3, 0, 0.5)), to_world(&F, v3(1, 0, -0.05)) };
        const uint8_t pinned[3] = { 0, 0, 1 };
        const sdfccd_SoftBody body = { 3, start, end, pinned, 0, NULL, 0, NULL, 0 };
        const sdfccd_SoftContactParams p = contact_params(0.01);
        sdfccd_DistanceCert certs[3] = { sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert() };
        sdfccd_SoftPlane planes[6];
        int32_t count = -1;
        sdfccd_SoftStats stats = { 0, 0, 0 };
        ck_assert_msg(sdfccd_soft_contacts(plane, &F, &body, &p, certs, NULL, planes, 6, &count, &stats) == SDFCCD_OK, "%s",
                      sdfccd_last_error());
        ck_assert_int_eq(count, 1);
        ck_assert_int_eq(planes[0].node, 0);
        ck_assert_int_eq(planes[0].face, 0);
        ck_assert_double_eq_tol(planes[0].local_normal.z, 1.0, 1e-12);
        ck_assert_double_eq_tol(planes[0].local_offset, -0.01, 2e-6);
        const sdfccd_Vec3 up = to_world(&F, v3(0, 0, 1)), o = to_world(&F, v3(0, 0, 0));
        ck_assert_double_eq_tol(planes[0].normal.x, up.x - o.x, 1e-12);
        ck_assert_double_eq_tol(planes[0].normal.y, up.y - o.y, 1e-12);
        ck_assert_double_eq_tol(planes[0].normal.z, up.z - o.z, 1e-12);
        /* The world plane holds the world point 1 cm above the surface, and says how far the start is. */
        const sdfccd_Vec3 on = to_world(&F, v3(0.2, 0, 0.01));
        ck_assert_double_eq_tol(planes[0].normal.x * on.x + planes[0].normal.y * on.y + planes[0].normal.z * on.z + planes[0].offset, 0, 2e-6);
        ck_assert_double_eq_tol(planes[0].start_distance, 0.09, 2e-6);
        /* The node above keeps a certificate: the next step's same motion costs no evaluation. */
        ck_assert_double_eq_tol(certs[1].bound, 0.5, 1e-12);
        const int64_t evals = stats.sdf_evaluations;
        ck_assert(evals > 0);
        sdfccd_SoftBody only_above = body;
        only_above.node_count = 2;
        ck_assert(sdfccd_soft_contacts(plane, &F, &only_above, &p, certs, NULL, planes, 6, &count, &stats) == SDFCCD_OK);
        ck_assert_int_eq(count, 1); /* node 0 again (its certificate is its start distance, 0.1, below the margin reach) */
    }
    ck_assert(sdfccd_destroy_sdf(plane) == SDFCCD_OK);
}
END_TEST

/* A 2 m flat face falls onto a 10 cm ball centred under it: its corners stay 0.9 m or more from the
 * ball, so no node's own path meets it, but the face point over the ball's top does. Each node gets
 * a face plane: the horizontal plane at the ball's top plus 0.3 of the soft margin (the face is flat,
 * so the shift by the node's offset from the face point is horizontal). */
START_TEST(test_contacts_face_on_ball)
{
    const sdfccd_SdfId ball = sphere(0.1);
    const sdfccd_Frame F = identity_frame();
    const double z0 = 0.2, z1 = 0.05, margin = 0.01;
    const sdfccd_Vec3 start[3] = { v3(-1, -1, z0), v3(1.2, -0.8, z0), v3(-0.2, 1.3, z0) };
    const sdfccd_Vec3 end[3] = { v3(-1, -1, z1), v3(1.2, -0.8, z1), v3(-0.2, 1.3, z1) };
    const int32_t faces[3] = { 0, 1, 2 };
    const sdfccd_SoftBody body = { 3, start, end, NULL, 1, faces, 0, NULL, 0 };
    const sdfccd_SoftContactParams p = contact_params(margin);
    sdfccd_DistanceCert nc[3] = { sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert() };
    sdfccd_DistanceCert fc[1] = { sdfccd_empty_distance_cert() };
    sdfccd_SoftPlane planes[6];
    int32_t count = 0;
    sdfccd_SoftStats stats = { 0, 0, 0 };
    ck_assert_msg(sdfccd_soft_contacts(ball, &F, &body, &p, nc, fc, planes, 6, &count, &stats) == SDFCCD_OK, "%s", sdfccd_last_error());
    ck_assert_int_eq(count, 3);
    ck_assert_int_eq(stats.face_queries, 1);
    for (int k = 0; k < 3; ++k) {
        ck_assert_int_eq(planes[k].node, k);
        ck_assert_int_eq(planes[k].face, 1);
        ck_assert_double_eq_tol(planes[k].normal.z, 1.0, 1e-3);
        ck_assert_double_eq_tol(-planes[k].offset / planes[k].normal.z, 0.1 + 0.3 * margin, 1e-4);
    }
    /* Moving sideways, 1 m above the ball, the face is certified: no query, no plane. */
    const sdfccd_Vec3 hs[3] = { v3(-1, -1, 1.2), v3(1.2, -0.8, 1.2), v3(-0.2, 1.3, 1.2) };
    const sdfccd_Vec3 he[3] = { v3(-0.9, -1, 1.2), v3(1.3, -0.8, 1.2), v3(-0.1, 1.3, 1.2) };
    const sdfccd_SoftBody high = { 3, hs, he, NULL, 1, faces, 0, NULL, 0 };
    fc[0] = sdfccd_empty_distance_cert();
    ck_assert(sdfccd_soft_contacts(ball, &F, &high, &p, nc, fc, planes, 6, &count, &stats) == SDFCCD_OK);
    ck_assert_int_eq(count, 0);
    ck_assert_int_eq(stats.face_queries, 1);
    ck_assert(fc[0].bound >= 0.3 * margin + 0.1); /* the level plus the Lipschitz bound times the motion */
    ck_assert(sdfccd_destroy_sdf(ball) == SDFCCD_OK);
}
END_TEST

/* Holding on the plane z >= 0 (local), closed form: a node 2 cm below goes onto it (push 2 cm);
 * a node above is free; a node without mass stays. Friction: a 1 cm sideways step stops while it
 * is within friction x push (1.0 x 2 cm); at friction 0.25 (limit 5 mm) it stays in a middle pass
 * and is shortened by 5 mm in the last one, whose velocity is scale x the executed step with no
 * outward part beyond the node's own. */
START_TEST(test_hold_closed_form)
{
    for (int turned = 0; turned < 2; ++turned) {
        const sdfccd_Frame F = turned ? turned_frame() : identity_frame();
        const sdfccd_SoftPlane pl = { 0, 0, v3(0, 0, 1), 0, v3(0, 0, 1), 0.0, 0 };
        sdfccd_SoftPlane planes[3] = { pl, pl, pl };
        planes[1].node = 1;
        planes[2].node = 2;
        /* Node 0 starts 3 cm deep: its executed step (3 cm out) is faster outward than the node's own velocity. */
        const sdfccd_Vec3 start[3] = { to_world(&F, v3(0, 0, -0.03)), to_world(&F, v3(0, 0, 0.5)), to_world(&F, v3(0, 0, 0.01)) };
        const double masses[3] = { 1, 1, 0 };
        for (int fr = 0; fr < 2; ++fr) {
            const double friction = fr ? 0.25 : 1.0;
            for (int last = 0; last < 2; ++last) {
                sdfccd_Vec3 x[3] = { to_world(&F, v3(0.01, 0, -0.02)), to_world(&F, v3(0, 0.3, 0.4)), to_world(&F, v3(0, 0, -0.02)) };
                sdfccd_Vec3 v[3] = { v3(0, 0, 0), v3(7, 7, 7), v3(0, 0, 0) };
                double push[3] = { 0, 0, 0 };
                int32_t held = -1;
                ck_assert_msg(sdfccd_soft_hold(&F, &F, start, x, v, masses, 3, planes, 3, friction, push, 50.0, last, 0, &held) == SDFCCD_OK,
                              "%s", sdfccd_last_error());
                const sdfccd_Vec3 o = to_world(&F, v3(0, 0, 0));
                const sdfccd_Vec3 up = to_world(&F, v3(0, 0, 1)), ex = to_world(&F, v3(1, 0, 0));
                const sdfccd_Vec3 d = v3(x[0].x - o.x, x[0].y - o.y, x[0].z - o.z);
                const double z = d.x * (up.x - o.x) + d.y * (up.y - o.y) + d.z * (up.z - o.z);
                const double side = d.x * (ex.x - o.x) + d.y * (ex.y - o.y) + d.z * (ex.z - o.z);
                ck_assert_double_eq_tol(z, 0.0, 1e-15);
                ck_assert_double_eq_tol(push[0], 0.02, 1e-15);
                ck_assert_double_eq_tol(side, fr == 0 ? 0.0 : (last ? 0.005 : 0.01), 1e-15);
                /* Free and massless nodes: untouched. */
                const sdfccd_Vec3 x1 = to_world(&F, v3(0, 0.3, 0.4)), x2 = to_world(&F, v3(0, 0, -0.02));
                ck_assert(x[1].x == x1.x && x[1].y == x1.y && x[1].z == x1.z && push[1] == 0);
                ck_assert(x[2].x == x2.x && x[2].y == x2.y && x[2].z == x2.z && push[2] == 0);
                ck_assert(v[1].x == 7 && v[2].z == 0);
                ck_assert_int_eq(held, last ? 1 : 0);
                if (last) { /* v = 50 (x - start): sideways 50 x side, and no outward part (the node's own was 0, not 1.5) */
                    const double vz = v[0].x * (up.x - o.x) + v[0].y * (up.y - o.y) + v[0].z * (up.z - o.z);
                    const double vs = v[0].x * (ex.x - o.x) + v[0].y * (ex.y - o.y) + v[0].z * (ex.z - o.z);
                    ck_assert_double_eq_tol(vz, 0.0, 1e-12);
                    ck_assert_double_eq_tol(vs, 50 * side, 1e-12);
                }
            }
        }
    }
}
END_TEST

/* Single precision: what the hold writes is what a float engine holds. */
START_TEST(test_hold_single_precision)
{
    const sdfccd_Frame F = turned_frame();
    const sdfccd_SoftPlane pl = { 0, 0, v3(0, 0, 1), 0, v3(0, 0, 1), -0.1, 0 };
    const sdfccd_Vec3 start = to_world(&F, v3(0.1, 0.2, 0.15));
    sdfccd_Vec3 x = to_world(&F, v3(0.1, 0.2, 0.05)), v = v3(0, 0, 0);
    const double m = 1;
    double push = 0;
    ck_assert(sdfccd_soft_hold(&F, &F, &start, &x, &v, &m, 1, &pl, 1, 0.5, &push, 100.0, 1, 1, NULL) == SDFCCD_OK);
    ck_assert(x.x == (double)(float)x.x && x.y == (double)(float)x.y && x.z == (double)(float)x.z);
    ck_assert(v.x == (double)(float)v.x && v.y == (double)(float)v.y && v.z == (double)(float)v.z);
    ck_assert_double_eq_tol(push, 0.05, 1e-12);
    ck_assert_double_eq_tol(x.y, 2 - 0.1, 1e-7); /* local z = 0.1 is world y = 2 - 0.1 */
}
END_TEST

/* The guard against the plane z >= 0 (tolerance 0.5 mm), closed form: a node falling through goes back
 * to where it first reached -tolerance / 2 and stops into +z; a node above is left alone; a node
 * starting 1 cm deep may not end deeper than 1 cm + a tenth of the tolerance. */
START_TEST(test_guard_node_half_space)
{
    const sdfccd_SdfId plane = half_space_z();
    const double tol = 5e-4;
    for (int turned = 0; turned < 2; ++turned) {
        const sdfccd_Frame F = turned ? turned_frame() : identity_frame();
        const sdfccd_Vec3 start[3] = { to_world(&F, v3(0, 0, 0.1)), to_world(&F, v3(1, 0, 0.1)), to_world(&F, v3(2, 0, -0.01)) };
        const sdfccd_Vec3 end[3] = { to_world(&F, v3(0.1, 0, -0.1)), to_world(&F, v3(1, 0, 0.05)), to_world(&F, v3(2, 0, -0.02)) };
        const sdfccd_SoftBody body = { 3, start, end, NULL, 0, NULL, 0, NULL, 0 };
        sdfccd_DistanceCert certs[3] = { sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert() };
        sdfccd_SoftGuardNode out[3];
        int32_t moved = -1;
        sdfccd_SoftStats stats = { 0, 0, 0 };
        const sdfccd_QueryParams qp = sdfccd_default_query_params();
        ck_assert_msg(sdfccd_soft_guard(plane, &F, &F, &body, tol, 0.01, 100.0, &qp, certs, NULL, out, &moved, &stats) == SDFCCD_OK, "%s",
                      sdfccd_last_error());
        ck_assert_int_eq(moved, 2);
        const sdfccd_Vec3 back = to_world(&F, v3(0.1 * (0.1 + 0.5 * tol) / 0.2, 0, -0.5 * tol)), up = to_world(&F, v3(0, 0, 1)),
                          o = to_world(&F, v3(0, 0, 0));
        ck_assert_int_eq(out[0].moved, 1);
        ck_assert_int_eq(out[0].stop, 1);
        ck_assert_double_eq_tol(out[0].position.x, back.x, 1e-6);
        ck_assert_double_eq_tol(out[0].position.y, back.y, 1e-6);
        ck_assert_double_eq_tol(out[0].position.z, back.z, 1e-6);
        ck_assert_double_eq_tol(out[0].normal.x, up.x - o.x, 1e-12);
        ck_assert_double_eq_tol(out[0].normal.y, up.y - o.y, 1e-12);
        ck_assert_double_eq_tol(out[0].normal.z, up.z - o.z, 1e-12);
        /* Its velocity: 100 x (back - start), less its part into +z: (5.0125, 0, 0) in the SDF's frame. */
        const sdfccd_Vec3 ex = to_world(&F, v3(1, 0, 0));
        const double vx = 100 * 0.1 * (0.1 + 0.5 * tol) / 0.2;
        ck_assert_double_eq_tol(out[0].velocity.x, vx * (ex.x - o.x), 1e-4);
        ck_assert_double_eq_tol(out[0].velocity.y, vx * (ex.y - o.y), 1e-4);
        ck_assert_double_eq_tol(out[0].velocity.z, vx * (ex.z - o.z), 1e-4);
        ck_assert(out[1].velocity.x == 0 && out[1].velocity.y == 0 && out[1].velocity.z == 0);
        ck_assert_int_eq(out[1].moved, 0);
        ck_assert_int_eq(out[2].moved, 1);
        const sdfccd_Vec3 d = v3(out[2].position.x - o.x, out[2].position.y - o.y, out[2].position.z - o.z);
        const double z2 = d.x * (up.x - o.x) + d.y * (up.y - o.y) + d.z * (up.z - o.z);
        ck_assert(z2 >= -0.01 - 0.1 * tol - 1e-9);
        ck_assert(z2 < -0.01 + 1e-9); /* and not lifted above its start */
    }
    ck_assert(sdfccd_destroy_sdf(plane) == SDFCCD_OK);
}
END_TEST

/* A node's contact terms with a rigid body, closed forms: against a static body the impulse matrix
 * is I / (ima dt); against a body with inverse mass 0.5 and inverse inertia 2 I at arm r = (0, 0, 1),
 * ima I + imb I - [r]x Iw^-1 [r]x = diag(3.5, 3.5, 1.5) (ima 1). Static friction holds while the node's
 * sideways motion relative to the body's point under it stays within friction times its normal
 * motion: a node carried sideways with a moving body keeps it; one sliding over a static body does not. */
START_TEST(test_node_contact_closed_form)
{
    const double dt = 0.01;
    sdfccd_SoftRigid fixed = { v3(1, 2, 3), v3(0, 0, 0), v3(0, 0, 0), 0, { { 0 } } };
    sdfccd_SoftNodeContact c;
    ck_assert(sdfccd_soft_node_contact(v3(1.1, 2, 4.1), v3(1.1, 2, 4), 2.0, &fixed, v3(0, 0, 1), 0.5, dt, 0, &c) == SDFCCD_OK);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) ck_assert_double_eq_tol(c.impulse[i][j], i == j ? 1 / (2.0 * dt) : 0.0, 1e-9);
    ck_assert_double_eq_tol(c.arm.x, 0.1, 1e-12);
    ck_assert_double_eq_tol(c.arm.z, 1.0, 1e-12);
    ck_assert_double_eq_tol(c.mass_dt, 2.0 * dt, 1e-15);
    ck_assert(c.friction_keep == 0.0); /* straight down */
    ck_assert(sdfccd_soft_node_contact(v3(0.9, 2, 4.1), v3(1.1, 2, 4), 2.0, &fixed, v3(0, 0, 1), 0.5, dt, 0, &c) == SDFCCD_OK);
    ck_assert_double_eq_tol(c.friction_keep, 0.5, 1e-15); /* 0.2 sideways against 0.5 x 0.1 */

    sdfccd_SoftRigid moving = { v3(0, 0, 0), v3(20, 0, 0), v3(0, 0, 0), 0.5, { { 2, 0, 0 }, { 0, 2, 0 }, { 0, 0, 2 } } };
    ck_assert(sdfccd_soft_node_contact(v3(-0.2, 0, 1.1), v3(0, 0, 1), 1.0, &moving, v3(0, 0, 1), 0.5, dt, 0, &c) == SDFCCD_OK);
    const double diag[3] = { 1 / 3.5, 1 / 3.5, 1 / 1.5 };
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) ck_assert_double_eq_tol(c.impulse[i][j], i == j ? diag[i] / dt : 0.0, 1e-9);
    ck_assert(c.friction_keep == 0.0); /* carried: 0.2 m sideways with the body's 20 m/s x 0.01 s */
    moving.angular_velocity = v3(0, -20, 0); /* w x r = (-20, 0, 0): the point under the node stands still */
    ck_assert(sdfccd_soft_node_contact(v3(-0.2, 0, 1.1), v3(0, 0, 1), 1.0, &moving, v3(0, 0, 1), 0.5, dt, 0, &c) == SDFCCD_OK);
    ck_assert_double_eq_tol(c.friction_keep, 0.5, 1e-15);

    /* Single precision: floats, near the double terms. */
    sdfccd_SoftNodeContact f;
    ck_assert(sdfccd_soft_node_contact(v3(-0.2, 0, 1.1), v3(0.03, 0.01, 1), 1.0, &moving, v3(0, 0, 1), 0.5, dt, 0, &c) == SDFCCD_OK);
    ck_assert(sdfccd_soft_node_contact(v3(-0.2, 0, 1.1), v3(0.03, 0.01, 1), 1.0, &moving, v3(0, 0, 1), 0.5, dt, 1, &f) == SDFCCD_OK);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            ck_assert(f.impulse[i][j] == (double)(float)f.impulse[i][j]);
            ck_assert_double_eq_tol(f.impulse[i][j], c.impulse[i][j], 1e-5 * (1 + fabs(c.impulse[i][j])));
        }

    ck_assert_int_eq(sdfccd_soft_node_contact(v3(0, 0, 0), v3(0, 0, 0), 1.0, NULL, v3(0, 0, 1), 0.5, dt, 0, &c), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_node_contact(v3(0, 0, 0), v3(0, 0, 0), 1.0, &fixed, v3(0, 0, 1), 0.5, 0.0, 0, &c), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_node_contact(v3(0, 0, 0), v3(0, 0, 0), 0.0, &fixed, v3(0, 0, 1), 0.5, dt, 0, &c), SDFCCD_INVALID_ARGUMENT);
}
END_TEST

/* Single precision: the guard's velocity is what a float engine computes (floats, near the double one),
 * and never into the surface by more than float rounding. */
START_TEST(test_guard_velocity_single)
{
    const sdfccd_SdfId plane = half_space_z();
    const sdfccd_Frame F = turned_frame();
    const sdfccd_Vec3 start = to_world(&F, v3(0.3, 0.1, 0.1)), end = to_world(&F, v3(0.4, 0.2, -0.1));
    sdfccd_SoftGuardNode out[2];
    for (int single = 0; single < 2; ++single) {
        const sdfccd_SoftBody body = { 1, &start, &end, NULL, 0, NULL, 0, NULL, single };
        sdfccd_DistanceCert cert = sdfccd_empty_distance_cert();
        sdfccd_SoftStats stats = { 0, 0, 0 };
        const sdfccd_QueryParams qp = sdfccd_default_query_params();
        ck_assert(sdfccd_soft_guard(plane, &F, &F, &body, 5e-4, 0.01, 99.0, &qp, &cert, NULL, &out[single], NULL, &stats) == SDFCCD_OK);
        ck_assert_int_eq(out[single].moved, 1);
    }
    const sdfccd_Vec3 v = out[1].velocity, n = out[1].normal;
    ck_assert(v.x == (double)(float)v.x && v.y == (double)(float)v.y && v.z == (double)(float)v.z);
    ck_assert_double_eq_tol(v.x, out[0].velocity.x, 1e-5);
    ck_assert_double_eq_tol(v.y, out[0].velocity.y, 1e-5);
    ck_assert_double_eq_tol(v.z, out[0].velocity.z, 1e-5);
    ck_assert(v.x * n.x + v.y * n.y + v.z * n.z > -1e-6);
    ck_assert(sdfccd_destroy_sdf(plane) == SDFCCD_OK);
}
END_TEST

/* A face (corners 0.9 m or more from a 10 cm ball) falling through it: no node's path goes near,
 * yet the guard puts the three nodes back above the ball's top (-tolerance), stopped into +z. A rope
 * link over the ball (ends beside it) likewise; with faces, the links are not checked. */
START_TEST(test_guard_face_and_link_through_ball)
{
    const sdfccd_SdfId ball = sphere(0.1);
    const double tol = 5e-4;
    const sdfccd_Frame F = identity_frame();
    const sdfccd_QueryParams qp = sdfccd_default_query_params();
    const sdfccd_Vec3 start[3] = { v3(-1, -1, 0.3), v3(1.2, -0.8, 0.3), v3(-0.2, 1.3, 0.3) };
    const sdfccd_Vec3 end[3] = { v3(-1, -1, -0.3), v3(1.2, -0.8, -0.3), v3(-0.2, 1.3, -0.3) };
    const int32_t faces[3] = { 0, 1, 2 }, links[2] = { 0, 1 };
    for (int rope = 0; rope < 2; ++rope) {
        /* The rope's link from (-1, -1) to (1.2, -0.8) passes beside the ball: move it over the centre. */
        sdfccd_Vec3 s[3], e[3];
        memcpy(s, start, sizeof s);
        memcpy(e, end, sizeof e);
        if (rope) s[0].y = e[0].y = 0.1, s[1].y = e[1].y = -0.1;
        const sdfccd_SoftBody body = { 3, s, e, NULL, rope ? 0 : 1, faces, 1, links, 0 };
        sdfccd_DistanceCert nc[3] = { sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert() };
        sdfccd_DistanceCert fc[2] = { sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert() };
        sdfccd_SoftGuardNode out[3];
        int32_t moved = 0;
        sdfccd_SoftStats stats = { 0, 0, 0 };
        ck_assert_msg(sdfccd_soft_guard(ball, &F, &F, &body, tol, 0.01, 100.0, &qp, nc, fc, out, &moved, &stats) == SDFCCD_OK, "%s",
                      sdfccd_last_error());
        ck_assert_int_eq(moved, rope ? 2 : 3);
        for (int k = 0; k < (rope ? 2 : 3); ++k) {
            ck_assert_int_eq(out[k].moved, 1);
            ck_assert_int_eq(out[k].stop, 1);
            ck_assert(out[k].position.z >= 0.1 - 2 * tol && out[k].position.z <= 0.1);
            ck_assert(out[k].position.z == out[0].position.z); /* a flat motion goes back by one fraction */
            ck_assert_double_eq_tol(out[k].normal.z, 1.0, 1e-2);
        }
        if (rope) ck_assert_int_eq(out[2].moved, 0);
        /* Checked along the corrected motion, no point of it goes below -tolerance. */
        for (int i = 0; i <= 40; ++i)
            for (int j = 0; i + j <= 40; ++j) {
                const double u = i / 40.0, w = j / 40.0;
                if (rope && w > 0) continue;
                for (int it = 0; it <= 20; ++it) {
                    const double t = it / 20.0;
                    double px = 0, py = 0, pz = 0;
                    for (int k = 0; k < 3; ++k) {
                        const double b = k == 0 ? u : (k == 1 ? 1 - u - w : w);
                        const sdfccd_Vec3 to = out[k].moved ? out[k].position : e[k];
                        px += b * (s[k].x + (to.x - s[k].x) * t);
                        py += b * (s[k].y + (to.y - s[k].y) * t);
                        pz += b * (s[k].z + (to.z - s[k].z) * t);
                    }
                    double phi;
                    ck_assert(sdfccd_sdf_eval(ball, v3(px, py, pz), &phi, NULL) == SDFCCD_OK);
                    ck_assert_msg(phi >= -tol, "phi %g at (%g %g %g) t %g", phi, px, py, pz, t);
                }
            }
    }
    /* With faces, links are left to them: a link crossing the ball beside a far face moves nothing. */
    const sdfccd_Vec3 s5[5] = { v3(5, 0, 0.3), v3(6, 0, 0.3), v3(5, 1, 0.3), v3(-1, 0, 0.3), v3(1, 0, 0.3) };
    const sdfccd_Vec3 e5[5] = { v3(5, 0, -0.3), v3(6, 0, -0.3), v3(5, 1, -0.3), v3(-1, 0, -0.3), v3(1, 0, -0.3) };
    const int32_t far_face[3] = { 0, 1, 2 }, cross_link[2] = { 3, 4 };
    const sdfccd_SoftBody mixed = { 5, s5, e5, NULL, 1, far_face, 1, cross_link, 0 };
    sdfccd_DistanceCert nc5[5], fc5[2] = { sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert() };
    for (int k = 0; k < 5; ++k) nc5[k] = sdfccd_empty_distance_cert();
    sdfccd_SoftGuardNode out5[5];
    int32_t moved5 = -1;
    sdfccd_SoftStats st5 = { 0, 0, 0 };
    ck_assert(sdfccd_soft_guard(ball, &F, &F, &mixed, tol, 0.01, 100.0, &qp, nc5, fc5, out5, &moved5, &st5) == SDFCCD_OK);
    ck_assert_int_eq(moved5, 0);
    ck_assert(sdfccd_destroy_sdf(ball) == SDFCCD_OK);
}
END_TEST

START_TEST(test_soft_step_bad_input)
{
    const sdfccd_SdfId plane = half_space_z();
    const sdfccd_Frame F = identity_frame();
    const sdfccd_Vec3 s[2] = { v3(0, 0, 1), v3(1, 0, 1) }, e[2] = { v3(0, 0, -1), v3(1, 0, -1) };
    const int32_t bad_face[3] = { 0, 1, 2 };
    const sdfccd_SoftBody body = { 2, s, e, NULL, 0, NULL, 0, NULL, 0 }, bad = { 2, s, e, NULL, 1, bad_face, 0, NULL, 0 };
    const sdfccd_SoftContactParams p = contact_params(0.01);
    sdfccd_SoftContactParams neg = p;
    neg.soft_margin = -1;
    sdfccd_DistanceCert c[2] = { sdfccd_empty_distance_cert(), sdfccd_empty_distance_cert() };
    sdfccd_SoftPlane planes[4];
    int32_t count = 77;
    sdfccd_SoftStats st = { 0, 0, 0 };
    ck_assert_int_eq(sdfccd_soft_contacts(plane, &F, NULL, &p, c, c, planes, 4, &count, &st), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_contacts(plane, &F, &bad, &p, c, c, planes, 4, &count, &st), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_contacts(plane, &F, &body, &p, c, c, planes, 3, &count, &st), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_contacts(plane, &F, &body, &neg, c, c, planes, 4, &count, &st), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_contacts(plane, NULL, &body, &p, c, c, planes, 4, &count, &st), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(count, 77);
    const sdfccd_QueryParams qp = sdfccd_default_query_params();
    sdfccd_SoftGuardNode out[2];
    ck_assert_int_eq(sdfccd_soft_guard(plane, &F, &F, &body, 0.0, 0.01, 100.0, &qp, c, c, out, NULL, &st), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_guard(plane, &F, &F, &body, 5e-4, NAN, 100.0, &qp, c, c, out, NULL, &st), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_guard(plane, &F, &F, &body, 5e-4, 0.01, NAN, &qp, c, c, out, NULL, &st), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_guard(plane, &F, &F, &bad, 5e-4, 0.01, 100.0, &qp, c, c, out, NULL, &st), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_guard(plane, &F, &F, &body, 5e-4, 0.01, 100.0, NULL, c, c, out, NULL, &st), SDFCCD_INVALID_ARGUMENT);
    const sdfccd_SoftPlane far = { 5, 0, v3(0, 0, 1), 0, v3(0, 0, 1), 0, 0 };
    sdfccd_Vec3 x[2] = { s[0], s[1] }, v[2] = { s[0], s[1] };
    const double m[2] = { 1, 1 };
    double push = 0;
    ck_assert_int_eq(sdfccd_soft_hold(&F, &F, s, x, v, m, 2, &far, 1, 0.5, &push, 1, 1, 0, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_soft_hold(&F, NULL, s, x, v, m, 2, &far, 1, 0.5, &push, 1, 1, 0, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strlen(sdfccd_last_error()) > 0);
    ck_assert(sdfccd_destroy_sdf(plane) == SDFCCD_OK);
    ck_assert_int_eq(sdfccd_soft_contacts(plane, &F, &body, &p, c, c, planes, 4, &count, &st), SDFCCD_INVALID_HANDLE);
    ck_assert_int_eq(sdfccd_soft_guard(plane, &F, &F, &body, 5e-4, 0.01, 100.0, &qp, c, c, out, NULL, &st), SDFCCD_INVALID_HANDLE);
    ck_assert_int_eq(count, 77);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("soft_step");
    TCase* tc = tcase_create("a soft body's step");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_contacts_node_half_space);
    tcase_add_test(tc, test_contacts_face_on_ball);
    tcase_add_test(tc, test_hold_closed_form);
    tcase_add_test(tc, test_hold_single_precision);
    tcase_add_test(tc, test_guard_node_half_space);
    tcase_add_test(tc, test_guard_velocity_single);
    tcase_add_test(tc, test_node_contact_closed_form);
    tcase_add_test(tc, test_guard_face_and_link_through_ball);
    tcase_add_test(tc, test_soft_step_bad_input);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
