/* SPDX-License-Identifier: MIT
 * The lower bound on phi over a moving sub-triangle that the certified check of FWGSS uses on
 * grids (scc_grid_region_bound, certified.c: per-cell first-order Taylor forms with Bernstein
 * bounds on each cell's Hessian), against brute force: phi sampled on a barycentric grid of the
 * sub-triangle at evenly spaced times must never fall below the bound. Regions are drawn near
 * the surface of bullet3's concave box (32^3 grid) and of the data set's spike grid (sharp tips and
 * valleys, where cells' gradients jump), 0.2 mm to 3 cm across, over 0.1 us to 0.1 ms, moving at up to
 * 15 m/s and spinning at up to 300 rad/s; with the whole-cell Hessian bounds and with the local ones. The bound must also be
 * useful: the margin between it and the sampled minimum is reported, and most small regions near
 * the surface must be bounded within a tenth of their size. */
#include <math.h>
#include <stdio.h>
#include "test_internal.h"
#include "test_util.h"
#include "ccd.h"

static double phi_at(const scc_sdf* sdf, const scc_tri_motion* m, double u, double v, double t)
{
    const double b[3] = { u, v, 1.0 - u - v };
    return scc_sdf_eval(sdf, scc_tri_point_at(m, b, t, NULL), NULL);
}

static void check_grid_id(sdfccd_SdfId id, const char* path, unsigned seed);

static void check_grid(const char* path, unsigned seed)
{
    sdfccd_SdfId id;
    ck_assert_int_eq(sdfccd_load_grid(path, &id), SDFCCD_OK);
    check_grid_id(id, path, seed);
}

static void check_grid_id(sdfccd_SdfId id, const char* path, unsigned seed)
{
    const scc_grid* g = test_grid_of(id);
    const scc_sdf* sdf = &g->base;
    test_rng rng = { seed };
    int applied = 0, tight = 0, small = 0, applied_grad = 0, outside = 0;
    double worst_gap = INFINITY;
    for (int trial = 0; trial < 400; ++trial) {
        /* a point near the surface (a few Newton steps from a random point of the domain) */
        scc_vec3 x = scc_v3(test_rng_uniform(&rng, g->lo.x, g->hi.x), test_rng_uniform(&rng, g->lo.y, g->hi.y), test_rng_uniform(&rng, g->lo.z, g->hi.z));
        for (int it = 0; it < 20; ++it) {
            scc_vec3 gr;
            const double f = scc_sdf_eval(sdf, x, &gr);
            const double gl = scc_len2(gr);
            if (!(gl > 0.25)) break;
            x = scc_sub(x, scc_scale(gr, f / gl));
        }
        if (!(fabs(scc_sdf_eval(sdf, x, NULL)) < 1e-6)) continue;
        /* a triangle of 2-6 cm centred within 1 mm of it, moving and spinning */
        scc_rigid body;
        body.p0 = scc_add(x, scc_v3(test_rng_uniform(&rng, -1e-3, 1e-3), test_rng_uniform(&rng, -1e-3, 1e-3), test_rng_uniform(&rng, -1e-3, 1e-3)));
        const sdfccd_Vec3 ax = test_rng_unit_vector(&rng);
        const double ang = test_rng_uniform(&rng, 0.0, M_PI);
        body.q0 = (scc_quat){ cos(ang / 2), ax.x * sin(ang / 2), ax.y * sin(ang / 2), ax.z * sin(ang / 2) };
        body.c_local = scc_v3(0, 0, 0);
        const sdfccd_Vec3 dv = test_rng_unit_vector(&rng), dw = test_rng_unit_vector(&rng);
        const double speed = test_rng_uniform(&rng, 0.0, 15.0), spin = test_rng_uniform(&rng, 0.0, 300.0);
        body.v = scc_v3(dv.x * speed, dv.y * speed, dv.z * speed);
        body.w = scc_v3(dw.x * spin, dw.y * spin, dw.z * spin);
        body.t0 = 0.0;
        scc_tri_motion m;
        memset(&m, 0, sizeof m);
        m.kind = SCC_TRI_RIGID;
        m.body = &body;
        m.t0 = 0.0;
        m.t1 = 1.0 / 60.0;
        const double size = test_rng_uniform(&rng, 0.02, 0.06);
        scc_vec3 mean = scc_v3(0, 0, 0);
        for (int i = 0; i < 3; ++i) {
            const sdfccd_Vec3 u = test_rng_unit_vector(&rng);
            m.local[i] = scc_v3(u.x * size, u.y * size, u.z * size);
            mean = scc_add(mean, scc_scale(m.local[i], 1.0 / 3.0));
        }
        for (int i = 0; i < 3; ++i) m.local[i] = scc_sub(m.local[i], mean);
        /* a sub-triangle 1/2^k of it around its centroid (0.2 mm to 3 cm), over 0.1 us to 0.1 ms */
        const int level = (int)test_rng_uniform(&rng, 1.0, 9.0);
        const double w = ldexp(1.0, -level);
        double u[3], v[3];
        for (int i = 0; i < 3; ++i) {
            u[i] = (1.0 - w) / 3.0 + w * (i == 0);
            v[i] = (1.0 - w) / 3.0 + w * (i == 1);
        }
        const double dt = pow(10.0, test_rng_uniform(&rng, -7.0, -4.0)), ta = test_rng_uniform(&rng, 0.0, 1e-3), tb = ta + dt;
        /* brute force: 21 x 21 weights at 11 times */
        double lowest = INFINITY;
        for (int k = 0; k <= 10; ++k)
            for (int i = 0; i <= 20; ++i)
                for (int j = 0; i + j <= 20; ++j) {
                    const double a = i / 20.0, b = j / 20.0;
                    const double pu = u[2] + a * (u[0] - u[2]) + b * (u[1] - u[2]), pv = v[2] + a * (v[0] - v[2]) + b * (v[1] - v[2]);
                    lowest = fmin(lowest, phi_at(sdf, &m, pu, pv, ta + dt * k / 10.0));
                }
        for (int local = 0; local < 3; ++local) {
            double bound;
            if (!scc_grid_region_bound(sdf, &m, u, v, ta, tb, local, &bound)) continue;
            if (local == 2) applied_grad++;
            else applied++;
            if (local == 2) {
                /* regions reaching outside the domain: phi there is sqrt(d^2 + phi_q^2) */
                scc_tri_state st;
                scc_tri_state_at(&m, ta, &st);
                for (int i = 0; i < 3; ++i) {
                    const scc_vec3 p = st.x[i];
                    outside += p.x < g->lo.x || p.y < g->lo.y || p.z < g->lo.z || p.x > g->hi.x || p.y > g->hi.y || p.z > g->hi.z;
                }
            }
            ck_assert_msg(bound <= lowest + 1e-12, "%s trial %d (local %d): bound %.9g above the sampled minimum %.9g", path, trial, local, bound,
                          lowest);
            worst_gap = fmin(worst_gap, lowest - bound);
            /* usefulness: regions under 5 mm within their extent of the surface */
            double extent = 0.0;
            scc_tri_state st;
            scc_tri_state_at(&m, ta, &st);
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) {
                    const double bi[3] = { u[i], v[i], 1.0 - u[i] - v[i] }, bj[3] = { u[j], v[j], 1.0 - u[j] - v[j] };
                    extent = fmax(extent, scc_dist(scc_tri_point_at(&m, bi, ta, NULL), scc_tri_point_at(&m, bj, ta, NULL)));
                }
            extent += scc_tri_speed_bound(&m) * dt;
            if (local == 1 && extent < 5e-3 && fabs(lowest) < extent) {
                small++;
                tight += lowest - bound <= 0.1 * extent;
            }
        }
    }
    printf("%s: the bound applied to %d regions, the gradient-interval bound to %d (%d corners outside the domain), never above the sampled "
           "minimum (closest %.3g m); %d of %d small regions near the surface bounded within a tenth of their extent\n",
           path, applied, applied_grad, outside, worst_gap, tight, small);
    fflush(stdout);
    ck_assert_int_gt(applied, 200);
    ck_assert_int_gt(applied_grad, 200);
    ck_assert_int_gt(small, 40);
    ck_assert_msg(tight * 10 >= small * 8, "%s: only %d of %d small regions bounded within a tenth of their extent", path, tight, small);
    sdfccd_destroy_sdf(id);
}

START_TEST(test_concave_box_grid) { check_grid(SDFCCD_DATA_DIR "/sdf/concave_box_r32.cdf", 20261126u); }
END_TEST

/* The 32^3 grid of a torus fitted to its box: the surface touches the domain's faces, so regions
 * near it reach outside the domain, where the bounds take phi = sqrt(d^2 + phi_q^2). */
START_TEST(test_torus_grid)
{
    sdfccd_SdfId torus, grid;
    ck_assert_int_eq(sdfccd_create_torus(0.1, 0.05, &torus), SDFCCD_OK);
    sdfccd_GridDef gd = sdfccd_default_grid_def();
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(torus, &gd, &grid), SDFCCD_OK);
    check_grid_id(grid, "torus 32^3", 20261127u);
    sdfccd_destroy_sdf(torus);
}
END_TEST

START_TEST(test_spike_grid) { check_grid(SDFCCD_DATA_DIR "/../samples/report/dataset_kinds/spikes.cdf", 20261127u); }
END_TEST

int main(void)
{
    Suite* s = suite_create("grid_taylor");
    TCase* tc = tcase_create("bound");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_concave_box_grid);
    tcase_add_test(tc, test_spike_grid);
    tcase_add_test(tc, test_torus_grid);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
