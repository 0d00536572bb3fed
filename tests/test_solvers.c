/* SPDX-License-Identifier: MIT
 * Golden-section search (Algorithm 1) on functions with known minima, and DCD (Section 3.2)
 * against known deepest points. Uses the core's internal headers. */
#include <math.h>
#include <stdint.h>
#include <string.h>
#include "test_util.h"
#include "ccd.h"
#include "gss.h"
#include "sdf_analytic.h"

/* No constant offset: with one, f differences below the offset's ulp hide the minimum (sqrt(eps) limit). */
static double quad(double x, void* c) { double m = *(double*)c; return (x - m) * (x - m); }
static double vee(double x, void* c) { (void)c; return fabs(x - 0.7); }
static double rising(double x, void* c) { (void)c; return x; }
static double cosine(double x, void* c) { (void)c; return cos(x); }

START_TEST(test_gss_known_minima)
{
    double m = 0.3;
    scc_gss_result r = scc_gss_minimize(0.0, 1.0, 1e-9, 200, quad, &m);
    ck_assert_double_near(r.l, 0.3, 1e-8);
    ck_assert_double_near(r.f, 0.0, 1e-15);
    ck_assert(r.converged);
    /* One new evaluation per iteration: about log(1e9) / log(phi) = 43 of them, plus 5. */
    ck_assert_int_le(r.evals, 50);
    r = scc_gss_minimize(0.0, 1.0, 1e-9, 200, vee, NULL);
    ck_assert_double_near(r.l, 0.7, 1e-8);
    r = scc_gss_minimize(2.0, 5.0, 1e-10, 200, cosine, NULL);
    /* cos(pi + d) = -1 + d^2 / 2: values cannot separate d below sqrt(eps) ~ 1.5e-8. */
    ck_assert_double_near(r.l, M_PI, 5e-8);
    /* Monotone: the minimum is at the interval start (Algorithm 1 returns l0). */
    r = scc_gss_minimize(-1.0, 1.0, 1e-9, 200, rising, NULL);
    ck_assert_double_near(r.l, -1.0, 1e-8);
    /* Reversed interval and zero width. */
    m = 0.25;
    r = scc_gss_minimize(1.0, 0.0, 1e-9, 200, quad, &m);
    ck_assert_double_near(r.l, 0.25, 1e-8);
    r = scc_gss_minimize(0.4, 0.4, 1e-9, 200, quad, &m);
    ck_assert_double_eq(r.l, 0.4);
    ck_assert_int_eq(r.evals, 1);
    /* Absolute tolerance near zero (a relative one never stops there): minimum at 1e-12. */
    m = 1e-12;
    r = scc_gss_minimize(0.0, 1e-6, 1e-15, 200, quad, &m);
    ck_assert_double_near(r.l, 1e-12, 2e-15);
    /* The cap is reported. */
    m = 0.3;
    r = scc_gss_minimize(0.0, 1.0, 1e-12, 5, quad, &m);
    ck_assert(!r.converged);
    ck_assert_int_eq(r.evals, 4 + 5 + 1);
}
END_TEST

/* Brent's minimiser (the FWGSS option fwgss_brent_spatial): same minima, far fewer evaluations on
 * a smooth function, still converges on a kink and at an interval end, and reports its cap. */
START_TEST(test_brent_known_minima)
{
    double m = 0.3;
    scc_gss_result r = scc_brent_minimize(0.0, 1.0, 1e-9, 200, quad, &m);
    ck_assert_double_near(r.l, 0.3, 1e-8);
    ck_assert(r.converged);
    ck_assert_int_le(r.evals, 10); /* a parabola: exact after one parabolic step, then the stopping steps */
    r = scc_brent_minimize(0.0, 1.0, 1e-9, 200, vee, NULL);
    ck_assert_double_near(r.l, 0.7, 1e-8);
    ck_assert(r.converged);
    r = scc_brent_minimize(2.0, 5.0, 1e-10, 200, cosine, NULL);
    ck_assert_double_near(r.l, M_PI, 5e-8);
    r = scc_brent_minimize(-1.0, 1.0, 1e-9, 200, rising, NULL);
    ck_assert_double_near(r.l, -1.0, 1e-8);
    r = scc_brent_minimize(0.0, 1.0, 1e-12, 3, vee, NULL);
    ck_assert(!r.converged);
    ck_assert_int_eq(r.evals, 4);
}
END_TEST

/* |x - c| + h: 1-Lipschitz, minimum h at c. */
static double vee_at(double x, void* c) { const double* k = c; return fabs(x - k[0]) + k[1]; }

/* The gap-stopped search (FWGSS's temporal searches with fwgss_gap_tolerance): with slope = 2 x the
 * Lipschitz bound it ends as soon as the bracket is narrower than half the smallest value over the
 * bound, so the function stays above half that value on the final bracket: far from zero it
 * stops early, near zero or below it it is the plain search, bit for bit. */
START_TEST(test_gss_gap_stop)
{
    double k[2] = { 0.3, 0.1 }; /* minimum 0.1 at 0.3 */
    scc_gss_result plain = scc_gss_minimize(0.0, 1.0, 1e-9, 200, vee_at, k);
    scc_gss_result gap = scc_gss_minimize_gap(0.0, 1.0, 1e-9, 2.0, 200, vee_at, k);
    ck_assert(gap.converged);
    /* the bracket may stop at width <= 0.1 / 2 = 0.05: about log(0.05) / log(0.618) = 7 iterations, plus 5 */
    ck_assert_int_le(gap.evals, 13);
    ck_assert_int_lt(gap.evals, plain.evals);
    ck_assert_double_near(gap.l, 0.3, 0.05);
    ck_assert_double_ge(gap.f, 0.1); /* a sampled value: never below the true minimum */
    /* The guarantee: anywhere within the stopping width of the returned point the function is
     * above half the smallest sample (here: the minimum 0.1 is above 0.05). */
    ck_assert_double_ge(vee_at(0.3, k), 0.5 * gap.f);
    /* A function that reaches zero: no early stop, the same result as the plain search. */
    k[1] = -0.01;
    plain = scc_gss_minimize(0.0, 1.0, 1e-9, 200, vee_at, k);
    gap = scc_gss_minimize_gap(0.0, 1.0, 1e-9, 2.0, 200, vee_at, k);
    ck_assert_int_eq(gap.evals, plain.evals);
    ck_assert_double_eq(gap.l, plain.l);
    ck_assert_double_eq(gap.f, plain.f);
    /* slope 0 is the plain search */
    k[1] = 0.1;
    plain = scc_gss_minimize(0.0, 1.0, 1e-9, 200, vee_at, k);
    gap = scc_gss_minimize_gap(0.0, 1.0, 1e-9, 0.0, 200, vee_at, k);
    ck_assert_int_eq(gap.evals, plain.evals);
    ck_assert_double_eq(gap.l, plain.l);
}
END_TEST

/* The same search with f(a), f(b) handed in (FWGSS passes the values it already has): the same
 * samples and result, one evaluation fewer per known end. */
static int g_calls;
static double quad_counted(double x, void* c) { ++g_calls; return quad(x, c); }

START_TEST(test_gss_known_ends)
{
    double m = 0.3;
    g_calls = 0;
    scc_gss_result plain = scc_gss_minimize_gap(0.0, 1.0, 1e-9, 0.0, 200, quad_counted, &m);
    const int plain_calls = g_calls;
    g_calls = 0;
    scc_gss_result known = scc_gss_minimize_from(0.0, 1.0, quad(0.0, &m), quad(1.0, &m), 1e-9, 0.0, 200, quad_counted, &m);
    ck_assert_int_eq(g_calls, plain_calls - 2);
    ck_assert_int_eq(known.evals, plain.evals - 2);
    ck_assert_double_eq(known.l, plain.l);
    ck_assert_double_eq(known.f, plain.f);
    g_calls = 0;
    known = scc_gss_minimize_from(0.0, 1.0, NAN, quad(1.0, &m), 1e-9, 0.0, 200, quad_counted, &m);
    ck_assert_int_eq(g_calls, plain_calls - 1);
    ck_assert_double_eq(known.l, plain.l);
}
END_TEST

/* f and its slope for the search with derivatives. */
static double quad_d(double x, double* df, void* c) { double m = *(double*)c; *df = 2.0 * (x - m); ++g_calls; return (x - m) * (x - m); }
static double quartic_d(double x, double* df, void* c) { (void)c; double u = x - 0.62; *df = 4.0 * u * u * u + 2.0 * u; ++g_calls; return u * u * u * u + u * u; }
static double vee_d(double x, double* df, void* c) { (void)c; *df = x < 0.7 ? -1.0 : 1.0; ++g_calls; return fabs(x - 0.7); }
/* Two dips: f falls to -1 at 0.25, rises to 1 at 0.75 and falls again, to f(1) = 2.4e-16 > f(0) = 0. */
static double twodip_d(double x, double* df, void* c) { (void)c; *df = -2.0 * M_PI * cos(2.0 * M_PI * x); ++g_calls; return -sin(2.0 * M_PI * x); }

/* The spatial search with derivatives (FWGSS's fwgss_derivative_spatial): the minimiser to the
 * tolerance in a handful of evaluations on smooth functions, bisection-bounded on a kink, the whole
 * step when f still descends at l = 1, no step for a non-descent start, and a refusal (for golden
 * section) when f' changes sign more than once. Every returned point is an evaluated one. */
START_TEST(test_deriv_minimize)
{
    double m = 0.3, f1 = 0.0;
    scc_gss_result r;
    g_calls = 0;
    ck_assert(scc_deriv_minimize(m * m, -2.0 * m, 1e-9, 64, quad_d, &m, &r, &f1));
    ck_assert_double_near(r.l, 0.3, 1e-9);
    ck_assert_int_le(r.evals, 4); /* the secant on a linear slope is exact */
    ck_assert_int_eq(r.evals, g_calls);
    ck_assert(r.converged);
    g_calls = 0;
    ck_assert(scc_deriv_minimize(pow(0.62, 4) + 0.62 * 0.62, -4.0 * pow(0.62, 3) - 2.0 * 0.62, 1e-9, 64, quartic_d, NULL, &r, &f1));
    ck_assert_double_near(r.l, 0.62, 1e-8);
    ck_assert_int_le(r.evals, 16); /* 14 here; golden section needs about 45 */
    ck_assert_double_near(r.f, quartic_d(r.l, &f1, NULL), 0.0);
    /* a kink: the slope jumps from -1 to 1; the bisection safeguard still closes the bracket */
    g_calls = 0;
    ck_assert(scc_deriv_minimize(0.7, -1.0, 1e-9, 200, vee_d, NULL, &r, &f1));
    ck_assert_double_near(r.l, 0.7, 1e-8);
    ck_assert_int_le(r.evals, 2 * 35);
    /* still descending at the end: the whole step in one evaluation */
    m = 1.5;
    ck_assert(scc_deriv_minimize(m * m, -2.0 * m, 1e-9, 64, quad_d, &m, &r, &f1));
    ck_assert_double_eq(r.l, 1.0);
    ck_assert_int_eq(r.evals, 1);
    /* not a descent direction: no step, no evaluation */
    m = -0.5;
    ck_assert(scc_deriv_minimize(m * m, -2.0 * m, 1e-9, 64, quad_d, &m, &r, &f1));
    ck_assert_double_eq(r.l, 0.0);
    ck_assert_int_eq(r.evals, 0);
    /* two dips: refused, with f(1) handed back for the golden-section search that follows */
    double d0;
    const double f0 = twodip_d(0.0, &d0, NULL);
    ck_assert(d0 < 0.0);
    r.l = -1.0;
    ck_assert(!scc_deriv_minimize(f0, d0, 1e-9, 64, twodip_d, NULL, &r, &f1));
    ck_assert_double_eq(r.l, -1.0);
    ck_assert_double_eq(f1, twodip_d(1.0, &d0, NULL));
}
END_TEST

static scc_params default_params(void)
{
    scc_params p = { 0 };
    p.method = SCC_METHOD_DCD;
    p.time_tol = 1e-7;
    p.dist_tol = 1e-9;
    p.max_iter = 64;
    p.max_ls_iter = 100;
    p.max_evals = INT64_MAX;
    return p;
}

START_TEST(test_dcd_deepest_vertex)
{
    scc_sdf_half_space plane;
    scc_sdf_half_space_init(&plane, scc_v3(0, 0, 1), 0.0);
    scc_vec3 tri[3] = { { 0, 0, 0.1 }, { 1, 0, -0.2 }, { 0, 1, 0.05 } };
    scc_params p = default_params();
    scc_dcd_result r = scc_dcd(&plane.base, tri, &p);
    ck_assert_double_near(r.phi, -0.2, 1e-12);
    ck_assert_double_near(r.bary[1], 1.0, 1e-12);
    ck_assert_double_near(r.normal.z, 1.0, 1e-15);
}
END_TEST

/* A flat triangle over a sphere: the deepest point is the projection of the centre. */
START_TEST(test_dcd_face_interior)
{
    scc_sdf_sphere s;
    scc_sdf_sphere_init(&s, 1.0);
    scc_vec3 tri[3] = { { -1, -1, 0.9 }, { 1.5, -0.5, 0.9 }, { -0.5, 1.5, 0.9 } };
    scc_params p = default_params();
    scc_dcd_result r = scc_dcd(&s.base, tri, &p);
    ck_assert_double_near(r.phi, -0.1, 1e-9);
    ck_assert_double_near(r.point.x, 0.0, 1e-5);
    ck_assert_double_near(r.point.y, 0.0, 1e-5);
    ck_assert(r.converged);
}
END_TEST

/* A long edge dips into a sphere: the deepest point is the edge point nearest the centre. */
START_TEST(test_dcd_edge_interior)
{
    scc_sdf_sphere s;
    scc_sdf_sphere_init(&s, 1.0);
    scc_vec3 tri[3] = { { -2, 0, 0.8 }, { 2, 0, 0.8 }, { 0, 0.5, 2.5 } };
    scc_params p = default_params();
    scc_dcd_result r = scc_dcd(&s.base, tri, &p);
    ck_assert_double_near(r.phi, -0.2, 1e-9);
    ck_assert_double_near(r.point.x, 0.0, 1e-5);
    ck_assert_double_near(r.point.z, 0.8, 1e-5);
    ck_assert_double_near(r.bary[2], 0.0, 1e-6);
}
END_TEST

/* A triangle over a box edge: the deepest point is on the triangle edge above the box edge. */
START_TEST(test_dcd_box_separated)
{
    scc_sdf_box b;
    scc_sdf_box_init(&b, scc_v3(1, 1, 1), 0.0);
    scc_vec3 tri[3] = { { 3, 0, 0 }, { 4, 1, 0 }, { 4, -1, 0 } };
    scc_params p = default_params();
    scc_dcd_result r = scc_dcd(&b.base, tri, &p);
    ck_assert_double_near(r.phi, 2.0, 1e-12); /* separated: the nearest point is vertex 0 */
    ck_assert_double_near(r.bary[0], 1.0, 1e-12);
}
END_TEST

/* The spike grid's convexity claim (scc_sdf.convex_in, which the certified bound relies on): on every
 * random box it accepts, phi lies above its tangent plane at the box's centre and below its chords
 * (sampled); it accepts boxes about single cones and the ground and rejects boxes across the seams
 * between them. Accepting every small box fails the first check (seams between cones). */
START_TEST(test_spike_grid_convex_in)
{
    scc_sdf_spike_grid sg;
    scc_sdf_spike_grid_init(&sg, 0.1, 0.05, 0.1, 20, 20);
    const scc_sdf* f = &sg.base;
    ck_assert_ptr_nonnull(f->convex_in);
    test_rng rng = { 77 };
    int accepted = 0, rejected = 0;
    for (int n = 0; n < 4000; ++n) {
        scc_vec3 c = scc_v3(test_rng_uniform(&rng, -1.2, 1.2), test_rng_uniform(&rng, -1.2, 1.2), test_rng_uniform(&rng, -0.03, 0.15));
        double h = pow(10.0, test_rng_uniform(&rng, -5.0, -1.5));
        scc_aabb box = { scc_sub(c, scc_v3(h, h, h)), scc_add(c, scc_v3(h, h, h)) };
        if (!scc_sdf_convex_in(f, &box)) {
            ++rejected;
            continue;
        }
        ++accepted;
        scc_vec3 g;
        double pc = scc_sdf_eval(f, c, &g);
        for (int k = 0; k < 16; ++k) {
            scc_vec3 x = scc_add(c, scc_v3(test_rng_uniform(&rng, -h, h), test_rng_uniform(&rng, -h, h), test_rng_uniform(&rng, -h, h)));
            scc_vec3 y = scc_add(c, scc_v3(test_rng_uniform(&rng, -h, h), test_rng_uniform(&rng, -h, h), test_rng_uniform(&rng, -h, h)));
            double px = scc_sdf_eval(f, x, NULL), py = scc_sdf_eval(f, y, NULL), pm = scc_sdf_eval(f, scc_scale(scc_add(x, y), 0.5), NULL);
            ck_assert_msg(px >= pc + scc_dot(g, scc_sub(x, c)) - 1e-12, "below the tangent plane: box at (%g, %g, %g), half size %g", c.x, c.y, c.z, h);
            ck_assert_msg(pm <= 0.5 * (px + py) + 1e-12, "above a chord: box at (%g, %g, %g), half size %g", c.x, c.y, c.z, h);
        }
    }
    ck_assert_msg(accepted >= 1000 && rejected >= 200, "accepted %d, rejected %d of 4000 boxes", accepted, rejected);
}
END_TEST

/* The range-checked length as it was before its common-case test on the sum of squares (scc_math.h):
 * the reference the fast path must match bit for bit. */
static double hypot3_reference(double x, double y, double z)
{
    double ax = fabs(x), ay = fabs(y), az = fabs(z);
    double m = ax > ay ? ax : ay;
    m = m > az ? m : az;
    if (m <= 1e150 && m >= 1e-150) {
        double s = x * x + y * y + z * z;
        if (s >= 1e-300) return sqrt(s);
    }
    if (!(m > 0.0) || isinf(m)) return m;
    x /= m; y /= m; z /= m;
    return m * sqrt(x * x + y * y + z * z);
}

static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0 || (isnan(a) && isnan(b)); }

/* scc_hypot3 and scc_hypot2 equal the reference bit for bit, most of all next to the range limits
 * (largest coordinate near 1e-150 and 1e150, sums of squares near 1e-300), where a fast path with
 * looser bounds would take sqrt of the sum where the reference scales. */
START_TEST(test_hypot_fast_path_identical)
{
    uint64_t state = 12345;
    const double bands[6] = { 1e-150, 7.1e-151, 2e-150, 3.2e149, 1e150, 1.0 };
    int checked = 0;
    for (int i = 0; i < 200000; ++i) {
        double c[3];
        for (int k = 0; k < 3; ++k) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            const double u = (double)(state >> 11) * 0x1.0p-53; /* [0, 1) */
            const double band = bands[(state >> 7) % 6];
            c[k] = (k == 2 && (i & 1) ? 0.0 : band * (0.5 + 1.5 * u)) * ((state >> 3) & 1 ? -1.0 : 1.0);
        }
        const double ref = hypot3_reference(c[0], c[1], c[2]);
        ck_assert_msg(same_bits(scc_hypot3(c[0], c[1], c[2]), ref), "hypot3(%a, %a, %a)", c[0], c[1], c[2]);
        if (c[2] == 0.0) ck_assert_msg(same_bits(scc_hypot2(c[0], c[1]), ref), "hypot2(%a, %a)", c[0], c[1]);
        ++checked;
    }
    const double odd[6] = { 0.0, -0.0, INFINITY, -INFINITY, NAN, 0x1p-1070 };
    for (int a = 0; a < 6; ++a)
        for (int b = 0; b < 6; ++b) {
            ck_assert(same_bits(scc_hypot3(odd[a], odd[b], 1e-160), hypot3_reference(odd[a], odd[b], 1e-160)));
            ck_assert(same_bits(scc_hypot2(odd[a], odd[b]), hypot3_reference(odd[a], odd[b], 0.0)));
        }
    ck_assert_int_eq(checked, 200000);
}
END_TEST

/* FWGSS takes a rigid triangle's speed bound as the largest of its vertices' bounds (fwgss.c,
 * tri_speed_bound), which holds bit for bit because the bound is nondecreasing in a vertex's distance
 * from the centre, rounding included: checked on random rigid motions, with and without a moving SDF. */
START_TEST(test_rigid_speed_bound_is_vertex_max)
{
    test_rng rng = { 2026 };
    for (int n = 0; n < 2000; ++n) {
        scc_rigid body = { scc_v3(test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2)),
                           scc_quat_normalize((scc_quat){ test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1),
                                                          test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1) }),
                           scc_v3(test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1)),
                           scc_v3(test_rng_uniform(&rng, -5, 5), test_rng_uniform(&rng, -5, 5), test_rng_uniform(&rng, -5, 5)),
                           scc_v3(test_rng_uniform(&rng, -30, 30), test_rng_uniform(&rng, -30, 30), test_rng_uniform(&rng, -30, 30)), 0.0 };
        scc_rigid field = body;
        field.v = scc_v3(test_rng_uniform(&rng, -3, 3), 0.5, -1.0);
        field.w = scc_v3(0.2, test_rng_uniform(&rng, -9, 9), 1.0);
        scc_tri_motion m;
        memset(&m, 0, sizeof m);
        m.kind = SCC_TRI_RIGID;
        m.body = &body;
        m.sdf = n % 2 ? &field : NULL;
        m.t0 = 0.0;
        m.t1 = test_rng_uniform(&rng, 1e-4, 0.1);
        /* vertices at nearly equal distances from the centre half of the time: ties and near-ties */
        const double scale = n % 4 < 2 ? 1e-9 : 1.0;
        for (int i = 0; i < 3; ++i)
            m.local[i] = scc_add(body.c_local, scc_v3(0.3 + scale * test_rng_uniform(&rng, -1, 1), scale * test_rng_uniform(&rng, -1, 1),
                                                     scale * test_rng_uniform(&rng, -1, 1)));
        double vmax = 0.0;
        for (int i = 0; i < 3; ++i) vmax = scc_fmax(vmax, scc_vertex_speed_bound(&m, i));
        const double tri = scc_tri_speed_bound(&m);
        ck_assert_msg(memcmp(&tri, &vmax, sizeof tri) == 0, "case %d: triangle %.17g, vertices' largest %.17g", n, tri, vmax);
    }
}
END_TEST

int main(void)
{
    Suite* s = suite_create("solvers");
    TCase* g = tcase_create("gss");
    tcase_add_test(g, test_gss_known_minima);
    tcase_add_test(g, test_brent_known_minima);
    tcase_add_test(g, test_gss_gap_stop);
    tcase_add_test(g, test_gss_known_ends);
    tcase_add_test(g, test_deriv_minimize);
    suite_add_tcase(s, g);
    TCase* d = tcase_create("dcd");
    tcase_add_test(d, test_dcd_deepest_vertex);
    tcase_add_test(d, test_dcd_face_interior);
    tcase_add_test(d, test_dcd_edge_interior);
    tcase_add_test(d, test_dcd_box_separated);
    tcase_add_test(d, test_spike_grid_convex_in);
    tcase_add_test(d, test_hypot_fast_path_identical);
    tcase_add_test(d, test_rigid_speed_bound_is_vertex_max);
    suite_add_tcase(s, d);
    return test_run_suite(s);
}
