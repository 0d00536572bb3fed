/* SPDX-License-Identifier: MIT
 * Analytic SDFs against closed-form distances and central finite differences of their
 * gradients; CSG, transforms and uniform scale; the spike grid against a brute-force minimum
 * over all cones; bad parameters. */
#include <math.h>
#include <string.h>
#include "test_util.h"

static double eval(sdfccd_SdfId s, double x, double y, double z, sdfccd_Vec3* g)
{
    double v = NAN;
    ck_assert_int_eq(sdfccd_sdf_eval(s, (sdfccd_Vec3){ x, y, z }, &v, g), SDFCCD_OK);
    return v;
}

/* Gradient against central differences (h = 1e-6) at random points away from kinks, and unit length.
 * At these seeds no point of any field lies within h of a kink: all 400 are checked (measured 400 of
 * 400 for every field; the floor was 300, so a value that is no distance over a quarter of the
 * samples, skipped as a "kink", passed). */
static void check_gradient(sdfccd_SdfId s, test_rng* rng, double extent)
{
    int checked = 0;
    for (int i = 0; i < 400; ++i) {
        double x = test_rng_uniform(rng, -extent, extent), y = test_rng_uniform(rng, -extent, extent), z = test_rng_uniform(rng, -extent, extent);
        sdfccd_Vec3 g;
        eval(s, x, y, z, &g);
        const double h = 1e-6;
        double fd[3] = { (eval(s, x + h, y, z, NULL) - eval(s, x - h, y, z, NULL)) / (2 * h),
                         (eval(s, x, y + h, z, NULL) - eval(s, x, y - h, z, NULL)) / (2 * h),
                         (eval(s, x, y, z + h, NULL) - eval(s, x, y, z - h, NULL)) / (2 * h) };
        /* Skip points within h of a gradient discontinuity (medial axis, edges): the one-sided
         * differences disagree there. */
        double fdl = sqrt(fd[0] * fd[0] + fd[1] * fd[1] + fd[2] * fd[2]);
        if (fabs(fdl - 1.0) > 1e-4) continue;
        ck_assert_double_near(g.x, fd[0], 1e-5);
        ck_assert_double_near(g.y, fd[1], 1e-5);
        ck_assert_double_near(g.z, fd[2], 1e-5);
        ck_assert_double_near(sqrt(g.x * g.x + g.y * g.y + g.z * g.z), 1.0, 1e-12);
        ++checked;
    }
    ck_assert_msg(checked == 400, "only %d of 400 points checked (the others' finite-difference gradient is not unit)", checked);
}

/* sdfccd_sdf_eval_batch gives sdfccd_sdf_eval's values and gradients bit for bit (analytic and
 * CSG shapes at seeded random points), checks every point first, and rejects bad arguments. */
START_TEST(test_eval_batch_matches_eval)
{
    sdfccd_SdfId torus, box, diff;
    ck_assert_int_eq(sdfccd_create_torus(0.4, 0.1, &torus), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.3, 0.2, 0.1 }, &box), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_DIFFERENCE, torus, box, &diff), SDFCCD_OK);
    enum { N = 257 };
    sdfccd_Vec3 p[N], g[N];
    double v[N];
    test_rng r = { 42 };
    for (int i = 0; i < N; ++i) p[i] = (sdfccd_Vec3){ test_rng_uniform(&r, -1, 1), test_rng_uniform(&r, -1, 1), test_rng_uniform(&r, -1, 1) };
    const sdfccd_SdfId shapes[3] = { torus, box, diff };
    for (int k = 0; k < 3; ++k) {
        ck_assert_int_eq(sdfccd_sdf_eval_batch(shapes[k], p, N, v, g), SDFCCD_OK);
        for (int i = 0; i < N; ++i) {
            double v1;
            sdfccd_Vec3 g1;
            ck_assert_int_eq(sdfccd_sdf_eval(shapes[k], p[i], &v1, &g1), SDFCCD_OK);
            ck_assert(v1 == v[i] && g1.x == g[i].x && g1.y == g[i].y && g1.z == g[i].z);
        }
        ck_assert_int_eq(sdfccd_sdf_eval_batch(shapes[k], p, N, v, NULL), SDFCCD_OK);
    }
    ck_assert_int_eq(sdfccd_sdf_eval_batch(torus, p, 0, NULL, NULL), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_sdf_eval_batch(torus, p, -1, v, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_sdf_eval_batch(torus, NULL, 3, v, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_sdf_eval_batch(torus, p, 3, NULL, NULL), SDFCCD_INVALID_ARGUMENT);
    v[1] = 123.0;
    p[2].y = NAN;
    ck_assert_int_eq(sdfccd_sdf_eval_batch(torus, p, 3, v, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert(v[1] == 123.0); /* nothing written before the check failed */
    sdfccd_destroy_sdf(diff);
    sdfccd_destroy_sdf(box);
    ck_assert_int_eq(sdfccd_sdf_eval_batch(box, p, 1, v, NULL), SDFCCD_INVALID_HANDLE);
    sdfccd_destroy_sdf(torus);
}
END_TEST

START_TEST(test_sphere)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(0.5, &s), SDFCCD_OK);
    ck_assert_double_near(eval(s, 0, 0, 0, NULL), -0.5, 1e-15);
    ck_assert_double_near(eval(s, 1, 2, 2, NULL), 2.5, 1e-15);
    sdfccd_Vec3 g;
    eval(s, 0, 3, 4, &g);
    ck_assert_double_near(g.y, 0.6, 1e-15);
    ck_assert_double_near(g.z, 0.8, 1e-15);
    test_rng rng = { 1 };
    check_gradient(s, &rng, 1.0);
    sdfccd_SdfInfo info;
    ck_assert_int_eq(sdfccd_sdf_get_info(s, &info), SDFCCD_OK);
    ck_assert_int_eq(info.kind, SDFCCD_SDF_SPHERE);
    ck_assert_double_eq(info.bounds.hi.x, 0.5);
    ck_assert_double_eq(info.lipschitz, 1.0);
    sdfccd_destroy_sdf(s);
}
END_TEST

START_TEST(test_box)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 1, 2, 3 }, &s), SDFCCD_OK);
    ck_assert_double_near(eval(s, 0, 0, 0, NULL), -1.0, 1e-15);       /* nearest face x = +-1 */
    ck_assert_double_near(eval(s, 0, 0, 2.5, NULL), -0.5, 1e-15);
    ck_assert_double_near(eval(s, 4, 0, 0, NULL), 3.0, 1e-15);        /* face region */
    ck_assert_double_near(eval(s, 4, 6, 0, NULL), 5.0, 1e-15);        /* edge region: (3, 4) */
    ck_assert_double_near(eval(s, 2, 3, 4, NULL), sqrt(3.0), 1e-15);  /* corner region */
    sdfccd_Vec3 g;
    eval(s, 4, 6, 0, &g);
    ck_assert_double_near(g.x, 0.6, 1e-15);
    ck_assert_double_near(g.y, 0.8, 1e-15);
    eval(s, 0.1, 0.1, -2.9, &g);
    ck_assert_double_eq(g.z, -1.0);
    test_rng rng = { 2 };
    check_gradient(s, &rng, 4.0);
    sdfccd_destroy_sdf(s);
}
END_TEST

START_TEST(test_rounded_box)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_rounded_box((sdfccd_Vec3){ 1, 1, 1 }, 0.25, &s), SDFCCD_OK);
    ck_assert_double_near(eval(s, 2, 0, 0, NULL), 1.0, 1e-15);                 /* face unchanged */
    ck_assert_double_near(eval(s, 2, 2, 2, NULL), sqrt(3.0) * 1.25 - 0.25, 1e-14); /* corner sphere at 0.75 */
    ck_assert_double_near(eval(s, 0, 0, 0, NULL), -1.0, 1e-15);
    test_rng rng = { 3 };
    check_gradient(s, &rng, 2.0);
    sdfccd_destroy_sdf(s);
}
END_TEST

START_TEST(test_torus)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_torus(1.0, 0.25, &s), SDFCCD_OK);
    ck_assert_double_near(eval(s, 1, 0, 0, NULL), -0.25, 1e-15);
    ck_assert_double_near(eval(s, 0, 0, 0, NULL), 0.75, 1e-15);
    ck_assert_double_near(eval(s, 0, 2, 0, NULL), 0.75, 1e-15);
    ck_assert_double_near(eval(s, 0, 1, 1, NULL), 0.75, 1e-15);
    ck_assert_double_near(eval(s, 3, 4, 0, NULL), 3.75, 1e-14); /* rho = 5 */
    test_rng rng = { 4 };
    check_gradient(s, &rng, 1.5);
    sdfccd_destroy_sdf(s);
}
END_TEST

START_TEST(test_capsule_cylinder_halfspace)
{
    sdfccd_SdfId c, y, h;
    ck_assert_int_eq(sdfccd_create_capsule(1.0, 0.5, &c), SDFCCD_OK);
    ck_assert_double_near(eval(c, 2, 0, 0.5, NULL), 1.5, 1e-15);
    ck_assert_double_near(eval(c, 0, 0, 3, NULL), 1.5, 1e-15);
    ck_assert_double_near(eval(c, 0, 0, 0, NULL), -0.5, 1e-15);
    ck_assert_int_eq(sdfccd_create_cylinder(1.0, 0.5, &y), SDFCCD_OK);
    ck_assert_double_near(eval(y, 2, 0, 0.5, NULL), 1.5, 1e-15);
    ck_assert_double_near(eval(y, 0, 0, 3, NULL), 2.0, 1e-15);
    ck_assert_double_near(eval(y, 3.5, 0, 5, NULL), 5.0, 1e-15); /* rim: (3, 4) */
    ck_assert_double_near(eval(y, 0, 0, 0.8, NULL), -0.2, 1e-15);
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 2 }, 1.0, &h), SDFCCD_OK);
    ck_assert_double_near(eval(h, 5, 5, 1.5, NULL), 1.0, 1e-15); /* normal normalised: z <= 0.5 */
    test_rng rng = { 5 };
    check_gradient(c, &rng, 2.0);
    check_gradient(y, &rng, 2.0);
    check_gradient(h, &rng, 2.0);
    sdfccd_destroy_sdf(c);
    sdfccd_destroy_sdf(y);
    sdfccd_destroy_sdf(h);
}
END_TEST

/* The spike grid against a brute-force minimum over the ground and every cone (each cone's
 * distance from its meridian triangle, computed independently here by dense sampling). */
static double seg_dist(double px, double pz, double ax, double az, double bx, double bz)
{
    double dx = bx - ax, dz = bz - az, t = ((px - ax) * dx + (pz - az) * dz) / (dx * dx + dz * dz);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return hypot(px - ax - t * dx, pz - az - t * dz);
}
START_TEST(test_spike_grid)
{
    sdfccd_SpikeGridDef d = sdfccd_default_spike_grid_def();
    d.count_x = 4;
    d.count_y = 3;
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_spike_grid(&d, &s), SDFCCD_OK);
    test_rng rng = { 6 };
    for (int i = 0; i < 2000; ++i) {
        double x = test_rng_uniform(&rng, -0.4, 0.4), y = test_rng_uniform(&rng, -0.3, 0.3), z = test_rng_uniform(&rng, 0.001, 0.3);
        double best = z;
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 3; ++b) {
                double cx = (a - 1.5) * d.spacing, cy = (b - 1.0) * d.spacing, rho = hypot(x - cx, y - cy);
                double dist = fmin(seg_dist(rho, z, d.base_radius, 0, 0, d.height), seg_dist(rho, z, 0, 0, d.base_radius, 0));
                int inside = rho / d.base_radius + z / d.height <= 1.0;
                best = fmin(best, inside ? -dist : dist);
            }
        ck_assert_double_near(eval(s, x, y, z, NULL), best, 1e-12);
    }
    check_gradient(s, &rng, 0.3);
    ck_assert_int_eq(sdfccd_create_spike_grid(NULL, &s), SDFCCD_INVALID_ARGUMENT);
    sdfccd_SpikeGridDef bad = d;
    bad.base_radius = d.spacing;
    ck_assert_int_eq(sdfccd_create_spike_grid(&bad, &s), SDFCCD_INVALID_ARGUMENT);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* CSG: the paper's hoop (Fig. 8): a thick ring = cylinder minus a smaller cylinder; plus union
 * and intersection identities, and a transformed, scaled copy. */
START_TEST(test_csg_and_transform)
{
    sdfccd_SdfId outer, inner, hoop, a, b, u, in, moved;
    ck_assert_int_eq(sdfccd_create_cylinder(0.1, 1.5, &outer), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_cylinder(0.2, 1.0, &inner), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_DIFFERENCE, outer, inner, &hoop), SDFCCD_OK);
    /* max(a, -b) is a lower bound on the distance, exact where one operand is active alone:
     * at the hole's centre the true distance is 1 (the inner wall); the field says 0.2 (the
     * inner cylinder's caps), a valid lower bound. */
    ck_assert_double_near(eval(hoop, 0, 0, 0, NULL), 0.2, 1e-15);
    ck_assert_double_near(eval(hoop, 0.9, 0, 0, NULL), 0.1, 1e-15);   /* 0.1 m from the inner wall */
    ck_assert_double_near(eval(hoop, 1.25, 0, 0, NULL), -0.1, 1e-15); /* inside the ring material */
    ck_assert_double_near(eval(hoop, 3.0, 0, 0, NULL), 1.5, 1e-15);
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &a), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.5, 0.5, 0.5 }, &b), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, a, b, &u), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_INTERSECTION, a, b, &in), SDFCCD_OK);
    test_rng rng = { 7 };
    for (int i = 0; i < 500; ++i) {
        double x = test_rng_uniform(&rng, -2, 2), y = test_rng_uniform(&rng, -2, 2), z = test_rng_uniform(&rng, -2, 2);
        double va = eval(a, x, y, z, NULL), vb = eval(b, x, y, z, NULL);
        ck_assert_double_eq(eval(u, x, y, z, NULL), fmin(va, vb));
        ck_assert_double_eq(eval(in, x, y, z, NULL), fmax(va, vb));
    }
    /* Destroying the children keeps the combination alive. */
    sdfccd_destroy_sdf(a);
    sdfccd_destroy_sdf(b);
    ck_assert_double_near(eval(u, 3, 0, 0, NULL), 2.0, 1e-15);
    /* A torus turned 90 degrees about x, moved to (1, 2, 3) and scaled by 2. */
    sdfccd_SdfId t;
    ck_assert_int_eq(sdfccd_create_torus(1.0, 0.25, &t), SDFCCD_OK);
    sdfccd_Pose pose = { { 1, 2, 3 }, { cos(M_PI / 4), sin(M_PI / 4), 0, 0 } };
    ck_assert_int_eq(sdfccd_create_transformed(t, pose, 2.0, &moved), SDFCCD_OK);
    for (int i = 0; i < 500; ++i) {
        double x = test_rng_uniform(&rng, -3, 3), y = test_rng_uniform(&rng, -3, 3), z = test_rng_uniform(&rng, -3, 3);
        /* Inverse: subtract the position, rotate by -90 deg about x: (x, y, z) -> (x, z, -y), divide by 2. */
        double lx = (x - 1) / 2, ly = (z - 3) / 2, lz = -(y - 2) / 2;
        ck_assert_double_near(eval(moved, x, y, z, NULL), 2.0 * eval(t, lx, ly, lz, NULL), 1e-12);
    }
    check_gradient(moved, &rng, 3.0);
    sdfccd_SdfInfo info;
    ck_assert_int_eq(sdfccd_sdf_get_info(moved, &info), SDFCCD_OK);
    ck_assert_double_near(info.bounds.lo.z, 3.0 - 2.5, 1e-12); /* ring now in the xz plane, radius 2.5 */
    ck_assert_double_near(info.bounds.lo.y, 2.0 - 0.5, 1e-12);
    sdfccd_SdfId ids[] = { outer, inner, hoop, u, in, t, moved };
    for (unsigned i = 0; i < sizeof ids / sizeof ids[0]; ++i) ck_assert_int_eq(sdfccd_destroy_sdf(ids[i]), SDFCCD_OK);
}
END_TEST

/* A user callback SDF behaves as the built-in it mimics, and a NaN gradient is replaced. */
static double user_sphere(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    double r = *(const double*)user, l = sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    if (g) *g = (sdfccd_Vec3){ p.x / l, p.y / l, p.z / l }; /* NaN at the centre */
    return l - r;
}
START_TEST(test_callback)
{
    double r = 0.3;
    sdfccd_CallbackSdfDef def = sdfccd_default_callback_sdf_def();
    def.eval = user_sphere;
    def.user = &r;
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_callback_sdf(&def, &s), SDFCCD_OK);
    ck_assert_double_near(eval(s, 1, 0, 0, NULL), 0.7, 1e-15);
    sdfccd_Vec3 g;
    eval(s, 0, 0, 0, &g);
    ck_assert(isfinite(g.x) && isfinite(g.y) && isfinite(g.z));
    sdfccd_CallbackSdfDef bad = def;
    bad.eval = NULL;
    ck_assert_int_eq(sdfccd_create_callback_sdf(&bad, &s), SDFCCD_INVALID_ARGUMENT);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* A callback declared smooth (sdfccd_CallbackSdfDef.smooth) is queried as the built-in smooth field
 * it evaluates: the built-in torus wrapped in a callback gives FWGSS's answers and evaluation counts
 * of the built-in torus bit for bit when declared smooth (no kink guard, no certified check), and
 * more evaluations when not. */
static double wrapped_builtin(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    double v = NAN;
    sdfccd_sdf_eval(*(const sdfccd_SdfId*)user, p, &v, g);
    return v;
}
START_TEST(test_callback_smooth)
{
    sdfccd_SdfId torus, cb[2];
    ck_assert_int_eq(sdfccd_create_torus(0.1, 0.05, &torus), SDFCCD_OK);
    for (int k = 0; k < 2; ++k) {
        sdfccd_CallbackSdfDef def = sdfccd_default_callback_sdf_def();
        ck_assert_int_eq(def.smooth, 0);
        def.eval = wrapped_builtin;
        def.user = &torus;
        def.smooth = k;
        ck_assert_int_eq(sdfccd_create_callback_sdf(&def, &cb[k]), SDFCCD_OK);
        def.smooth = 2;
        sdfccd_SdfId bad;
        ck_assert_int_eq(sdfccd_create_callback_sdf(&def, &bad), SDFCCD_INVALID_ARGUMENT);
    }
    const sdfccd_Vec3 tri[3] = { { -0.05, -0.03, 0 }, { 0.05, -0.03, 0 }, { 0, 0.06, 0 } };
    const sdfccd_QueryParams p = sdfccd_default_query_params();
    test_rng rng = { 2026 };
    int hits = 0;
    long long evals[3] = { 0, 0, 0 };
    for (int i = 0; i < 24; ++i) {
        /* from 25-35 cm out, aimed within 8 cm of the ring, arriving in about half a step, spinning */
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        sdfccd_Vec3 dir = test_rng_unit_vector(&rng), aim = test_rng_unit_vector(&rng);
        double dist = test_rng_uniform(&rng, 0.25, 0.35), a = test_rng_uniform(&rng, 0.0, 2.0 * 3.14159265358979);
        sdfccd_Vec3 target = { 0.1 * cos(a) + 0.08 * aim.x, 0.1 * sin(a) + 0.08 * aim.y, 0.08 * aim.z };
        m.pose.position = (sdfccd_Vec3){ target.x + dist * dir.x, target.y + dist * dir.y, target.z + dist * dir.z };
        double speed = dist / (test_rng_uniform(&rng, 0.6, 1.2) / 60.0);
        m.linear_velocity = (sdfccd_Vec3){ -speed * dir.x, -speed * dir.y, -speed * dir.z };
        sdfccd_Vec3 w = test_rng_unit_vector(&rng);
        double wl = test_rng_uniform(&rng, 0.0, 100.0);
        m.angular_velocity = (sdfccd_Vec3){ wl * w.x, wl * w.y, wl * w.z };
        sdfccd_QueryResult r[3];
        sdfccd_Contact c[3][8];
        const sdfccd_SdfId f[3] = { torus, cb[1], cb[0] };
        for (int k = 0; k < 3; ++k) {
            ck_assert_int_eq(sdfccd_query_triangle(f[k], NULL, tri, &m, 0.0, 1.0 / 60.0, &p, c[k], 8, &r[k]), SDFCCD_OK);
            evals[k] += r[k].sdf_evaluations;
        }
        ck_assert_int_eq(r[1].hit, r[0].hit);
        ck_assert_int_eq(r[1].state, r[0].state);
        ck_assert(r[1].toi == r[0].toi);
        ck_assert_int_eq(r[1].sdf_evaluations, r[0].sdf_evaluations);
        if (r[0].hit) {
            ck_assert(memcmp(&c[1][0], &c[0][0], sizeof c[0][0]) == 0);
            ++hits;
        }
    }
    ck_assert_msg(hits >= 8, "only %d of 24 paths hit the torus", hits);
    ck_assert_msg(evals[2] > evals[0], "not declared smooth: %lld evaluations, the built-in %lld (the guard should run)", evals[2], evals[0]);
    for (int k = 0; k < 2; ++k) sdfccd_destroy_sdf(cb[k]);
    sdfccd_destroy_sdf(torus);
}
END_TEST

/* The built-in field behind `user` with the point as three coordinates (sdfccd_CallbackSdfDef::eval_xyz). */
static double wrapped_builtin_xyz(double x, double y, double z, sdfccd_Vec3* g, void* user)
{
    return wrapped_builtin((sdfccd_Vec3){ x, y, z }, g, user);
}

/* A callback given as eval_xyz is the same field as the one given as eval: the same values and
 * gradients (sdfccd_sdf_eval, sdfccd_sdf_eval_batch) and FWGSS's answers, evaluation counts and
 * contacts bit for bit, declared smooth or not; exactly one of the two forms must be set. */
START_TEST(test_callback_xyz)
{
    sdfccd_SdfId box, cb[2][2]; /* [form][smooth] */
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.1, 0.06, 0.03 }, &box), SDFCCD_OK);
    for (int form = 0; form < 2; ++form)
        for (int k = 0; k < 2; ++k) {
            sdfccd_CallbackSdfDef def = sdfccd_default_callback_sdf_def();
            ck_assert(def.eval_xyz == NULL);
            if (form == 0) def.eval = wrapped_builtin;
            else def.eval_xyz = wrapped_builtin_xyz;
            def.user = &box;
            def.smooth = k;
            ck_assert_int_eq(sdfccd_create_callback_sdf(&def, &cb[form][k]), SDFCCD_OK);
        }
    sdfccd_CallbackSdfDef bad = sdfccd_default_callback_sdf_def();
    sdfccd_SdfId none = { 0, 0 };
    ck_assert_int_eq(sdfccd_create_callback_sdf(&bad, &none), SDFCCD_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "eval_xyz"));
    bad.eval = wrapped_builtin;
    bad.eval_xyz = wrapped_builtin_xyz;
    bad.user = &box;
    ck_assert_int_eq(sdfccd_create_callback_sdf(&bad, &none), SDFCCD_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "both"));
    ck_assert_int_eq(none.index1, 0);

    test_rng rng = { 77 };
    sdfccd_Vec3 pts[64];
    for (int i = 0; i < 64; ++i) {
        const sdfccd_Vec3 u = test_rng_unit_vector(&rng);
        const double r = test_rng_uniform(&rng, 0.0, 0.2);
        pts[i] = (sdfccd_Vec3){ r * u.x, r * u.y, r * u.z };
    }
    double v[2][64];
    sdfccd_Vec3 g[2][64];
    for (int form = 0; form < 2; ++form) ck_assert_int_eq(sdfccd_sdf_eval_batch(cb[form][0], pts, 64, v[form], g[form]), SDFCCD_OK);
    ck_assert(memcmp(v[0], v[1], sizeof v[0]) == 0 && memcmp(g[0], g[1], sizeof g[0]) == 0);
    for (int i = 0; i < 64; ++i) {
        double w;
        sdfccd_Vec3 gw;
        ck_assert_int_eq(sdfccd_sdf_eval(cb[1][1], pts[i], &w, &gw), SDFCCD_OK);
        ck_assert(w == v[0][i] && memcmp(&gw, &g[0][i], sizeof gw) == 0);
    }

    const sdfccd_Vec3 tri[3] = { { -0.05, -0.03, 0 }, { 0.05, -0.03, 0 }, { 0, 0.06, 0 } };
    const sdfccd_QueryParams p = sdfccd_default_query_params();
    int hits = 0;
    for (int i = 0; i < 16; ++i) {
        /* from 20-30 cm out towards the box, arriving in about half a step, spinning */
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        const sdfccd_Vec3 dir = test_rng_unit_vector(&rng), aim = test_rng_unit_vector(&rng), w = test_rng_unit_vector(&rng);
        const double dist = test_rng_uniform(&rng, 0.2, 0.3), speed = dist / (test_rng_uniform(&rng, 0.6, 1.2) / 60.0);
        const sdfccd_Vec3 target = { 0.06 * aim.x, 0.06 * aim.y, 0.04 * aim.z };
        m.pose.position = (sdfccd_Vec3){ target.x + dist * dir.x, target.y + dist * dir.y, target.z + dist * dir.z };
        m.linear_velocity = (sdfccd_Vec3){ -speed * dir.x, -speed * dir.y, -speed * dir.z };
        const double wl = test_rng_uniform(&rng, 0.0, 100.0);
        m.angular_velocity = (sdfccd_Vec3){ wl * w.x, wl * w.y, wl * w.z };
        for (int k = 0; k < 2; ++k) {
            sdfccd_QueryResult r[2];
            sdfccd_Contact c[2][8];
            memset(c, 0, sizeof c);
            for (int form = 0; form < 2; ++form)
                ck_assert_int_eq(sdfccd_query_triangle(cb[form][k], NULL, tri, &m, 0.0, 1.0 / 60.0, &p, c[form], 8, &r[form]), SDFCCD_OK);
            ck_assert(memcmp(&r[0], &r[1], sizeof r[0]) == 0);
            ck_assert(memcmp(c[0], c[1], sizeof c[0]) == 0);
            hits += r[0].hit;
        }
    }
    ck_assert_msg(hits >= 8, "only %d of 32 queries hit the box", hits);
    for (int form = 0; form < 2; ++form)
        for (int k = 0; k < 2; ++k) sdfccd_destroy_sdf(cb[form][k]);
    sdfccd_destroy_sdf(box);
}
END_TEST

/* The plane z = 0 as a user's field: its gradient (0, 0, 1), or not finite where asked for. */
static double plane_field(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    if (g) *g = user ? (sdfccd_Vec3){ NAN, 0.0, INFINITY } : (sdfccd_Vec3){ 0.0, 0.0, 1.0 };
    return p.z;
}

/* A user's gradient that is not finite reaches no solver: it reads as (0, 0, 1), through
 * sdfccd_sdf_eval and inside a query, where the solvers call the user's function themselves. */
START_TEST(test_callback_nonfinite_gradient)
{
    static int nonfinite = 1;
    sdfccd_SdfId f[2];
    for (int k = 0; k < 2; ++k) {
        sdfccd_CallbackSdfDef def = sdfccd_default_callback_sdf_def();
        def.eval = plane_field;
        def.user = k ? &nonfinite : NULL;
        def.smooth = 1;
        ck_assert_int_eq(sdfccd_create_callback_sdf(&def, &f[k]), SDFCCD_OK);
    }
    double v;
    sdfccd_Vec3 g;
    ck_assert_int_eq(sdfccd_sdf_eval(f[1], (sdfccd_Vec3){ 0.1, 0.2, 0.3 }, &v, &g), SDFCCD_OK);
    ck_assert(v == 0.3 && g.x == 0.0 && g.y == 0.0 && g.z == 1.0);
    const sdfccd_Vec3 tri[3] = { { -0.05, -0.03, 0.2 }, { 0.05, -0.03, 0.25 }, { 0, 0.06, 0.3 } };
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity = (sdfccd_Vec3){ 0.1, 0.0, -30.0 };
    m.angular_velocity = (sdfccd_Vec3){ 20.0, -10.0, 5.0 };
    const sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_QueryResult r[2];
    sdfccd_Contact c[2][8];
    for (int k = 0; k < 2; ++k) ck_assert_int_eq(sdfccd_query_triangle(f[k], NULL, tri, &m, 0.0, 1.0 / 60.0, &p, c[k], 8, &r[k]), SDFCCD_OK);
    ck_assert(r[0].hit);
    ck_assert_int_eq(r[1].hit, r[0].hit);
    ck_assert(r[1].toi == r[0].toi);
    ck_assert_int_eq(r[1].sdf_evaluations, r[0].sdf_evaluations);
    ck_assert(memcmp(&c[1][0], &c[0][0], sizeof c[0][0]) == 0);
    for (int k = 0; k < 2; ++k) sdfccd_destroy_sdf(f[k]);
}
END_TEST

START_TEST(test_bad_parameters)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(0.0, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_sphere(NAN, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_sphere(INFINITY, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_sphere(1.0, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 1, -1, 1 }, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_rounded_box((sdfccd_Vec3){ 1, 1, 1 }, 2.0, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_torus(0.5, 1.0, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 0 }, 0.0, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_csg((sdfccd_CsgOp)7, s, s, &s), SDFCCD_INVALID_ARGUMENT);
    sdfccd_SdfId unknown = { 12345, 1 };
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, unknown, unknown, &s), SDFCCD_INVALID_HANDLE);
    ck_assert_int_eq(sdfccd_create_transformed(unknown, sdfccd_pose_identity(), 1.0, &s), SDFCCD_INVALID_HANDLE);
    ck_assert_str_ne(sdfccd_last_error(), "");
    sdfccd_Pose zero = { { 0, 0, 0 }, { 0, 0, 0, 0 } };
    sdfccd_SdfId ball;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_transformed(ball, zero, 1.0, &s), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_transformed(ball, sdfccd_pose_identity(), -1.0, &s), SDFCCD_INVALID_ARGUMENT);
    double v;
    ck_assert_int_eq(sdfccd_sdf_eval(ball, (sdfccd_Vec3){ NAN, 0, 0 }, &v, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_destroy_sdf(ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(ball), SDFCCD_INVALID_HANDLE); /* stale after destroy */
    ck_assert_int_eq(sdfccd_sdf_eval(ball, (sdfccd_Vec3){ 0, 0, 0 }, &v, NULL), SDFCCD_INVALID_HANDLE);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("sdf");
    TCase* tc = tcase_create("analytic");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_sphere);
    tcase_add_test(tc, test_box);
    tcase_add_test(tc, test_rounded_box);
    tcase_add_test(tc, test_torus);
    tcase_add_test(tc, test_capsule_cylinder_halfspace);
    tcase_add_test(tc, test_spike_grid);
    tcase_add_test(tc, test_csg_and_transform);
    tcase_add_test(tc, test_callback);
    tcase_add_test(tc, test_callback_smooth);
    tcase_add_test(tc, test_callback_xyz);
    tcase_add_test(tc, test_callback_nonfinite_gradient);
    tcase_add_test(tc, test_bad_parameters);
    tcase_add_test(tc, test_eval_batch_matches_eval);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
