/* SPDX-License-Identifier: MIT
 * The bending bound that the certified search (and so FWGSS's check) uses on analytic fields
 * (scc_sdf_bend_bound, certified.c): phi(x) >= phi(c) + g.(x - c) - K |x - c|^2 / 2 within rad of c,
 * g the gradient scc_sdf_eval gives at c. Checked against sampling, independently of the certified
 * search that uses it: on CSG fields of spheres and boxes (a cube minus a ball, a cube intersected
 * with a ball, the shuriken's breastplate shape, a union, a ball minus a box) at random centres near
 * their surfaces and radii of 0.1 mm to 5 cm, phi at 64 points of each ball (on its boundary and
 * inside) must never fall below the bound; and the bound must apply (finite K) often, and bend
 * (K > 0) on the carved sphere. */
#include <math.h>
#include <stdio.h>
#include "test_internal.h"
#include "test_util.h"
#include "ccd.h"
#include "sdf_analytic.h"

static scc_vec3 unit(test_rng* rng)
{
    const sdfccd_Vec3 u = test_rng_unit_vector(rng);
    return scc_v3(u.x, u.y, u.z);
}

static void check_field(const char* name, const scc_sdf* sdf, double extent, unsigned seed, int* bent_total)
{
    test_rng rng = { seed };
    int applied = 0, bent = 0, samples = 0;
    double worst = INFINITY;
    for (int trial = 0; trial < 600; ++trial) {
        /* a centre near the surface (Newton steps from a random point), a little off it */
        scc_vec3 c = scc_v3(test_rng_uniform(&rng, -extent, extent), test_rng_uniform(&rng, -extent, extent), test_rng_uniform(&rng, -extent, extent));
        for (int it = 0; it < 20; ++it) {
            scc_vec3 g;
            const double f = scc_sdf_eval(sdf, c, &g);
            const double gl = scc_len2(g);
            if (!(gl > 0.25)) break;
            c = scc_sub(c, scc_scale(g, f / gl));
        }
        const double rad = exp(test_rng_uniform(&rng, log(1e-4), log(0.05)));
        c = scc_add(c, scc_scale(unit(&rng), test_rng_uniform(&rng, 0.0, 2.0) * rad));
        const double K = scc_sdf_bend_bound(sdf, c, rad);
        if (!(K < INFINITY)) continue;
        ++applied;
        bent += K > 0.0;
        scc_vec3 gc;
        const double fc = scc_sdf_eval(sdf, c, &gc);
        for (int k = 0; k < 64; ++k) {
            const scc_vec3 d = scc_scale(unit(&rng), rad * (k % 2 ? 1.0 : test_rng_uniform(&rng, 0.0, 1.0)));
            const scc_vec3 x = scc_add(c, d);
            const double bound = fc + scc_dot(gc, d) - 0.5 * K * scc_len2(d);
            const double gap = scc_sdf_eval(sdf, x, NULL) - bound;
            worst = fmin(worst, gap);
            ++samples;
            ck_assert_msg(gap >= -1e-12, "%s: phi %.17g below the bending bound %.17g at distance %.3g from c (K %.6g, rad %.3g)", name,
                          scc_sdf_eval(sdf, x, NULL), bound, scc_len(d), K, rad);
        }
    }
    printf("%s: the bound applied to %d of 600 balls (%d bending), never above phi at %d samples (closest %.3g m)\n", name, applied, bent,
           samples, worst);
    fflush(stdout);
    ck_assert_int_gt(applied, 300);
    *bent_total += bent;
}

START_TEST(test_csg_bend)
{
    scc_sdf_box cube, plate_box;
    scc_sdf_sphere ball, big, outer, inner;
    scc_sdf_box_init(&cube, scc_v3(0.1, 0.1, 0.1), 0.0);
    scc_sdf_sphere_init(&ball, 0.125);
    scc_sdf_sphere_init(&big, 0.13);
    scc_sdf_sphere_init(&outer, 0.6);
    scc_sdf_sphere_init(&inner, 0.58);
    scc_sdf_box_init(&plate_box, scc_v3(0.15, 0.3, 0.35), 0.0);
    scc_sdf_csg diff, inter, shell, breast, uni, carved;
    scc_sdf_csg_init(&diff, SCC_CSG_DIFFERENCE, &cube.base, &ball.base);
    scc_sdf_csg_init(&inter, SCC_CSG_INTERSECTION, &cube.base, &big.base);
    scc_sdf_csg_init(&shell, SCC_CSG_DIFFERENCE, &outer.base, &inner.base);
    scc_sdf_csg_init(&breast, SCC_CSG_INTERSECTION, &shell.base, &plate_box.base);
    scc_sdf_csg_init(&uni, SCC_CSG_UNION, &cube.base, &big.base);
    scc_sdf_csg_init(&carved, SCC_CSG_DIFFERENCE, &big.base, &cube.base);
    int bent_diff = 0, bent_other = 0;
    check_field("cube minus ball", &diff.base, 0.15, 20261127u, &bent_diff);
    check_field("cube intersect ball", &inter.base, 0.15, 20261128u, &bent_other);
    check_field("shell intersect box", &breast.base, 0.65, 20261129u, &bent_other);
    check_field("cube union ball", &uni.base, 0.15, 20261130u, &bent_other);
    check_field("ball minus cube", &carved.base, 0.15, 20261131u, &bent_other);
    ck_assert_int_gt(bent_diff, 50); /* the carved sphere bends: K > 0 there */
}
END_TEST

int main(void)
{
    Suite* s = suite_create("bend");
    TCase* tc = tcase_create("bound");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_csg_bend);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
