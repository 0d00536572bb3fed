/* SPDX-License-Identifier: MIT
 * Contact sets (contact.h, issue 19 item 1): sdfccd_reduce_contacts on known candidate sets, the way
 * Box2D tests its manifold functions (single, coincident, collinear, a face, a thousand points,
 * ids that persist, order that does not matter, a buffer smaller than the set), the mesh query's
 * contacts reduced instead of truncated, and contact generation for a step. Public ABI only. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

#define REPORT(...) do { if (getenv("CONTACTS_VERBOSE")) { printf(__VA_ARGS__); fflush(stdout); } } while (0)

static const double SAME = 1e-4; /* same_place_distance of the reductions below */

static sdfccd_ContactPoint cp(double x, double y, double z, double gap, uint64_t id)
{
    sdfccd_ContactPoint c;
    memset(&c, 0, sizeof c);
    c.surface_point = (sdfccd_Vec3){ x, y, z };
    c.point = (sdfccd_Vec3){ x, y, z + gap };
    c.normal = (sdfccd_Vec3){ 0, 0, 1 };
    c.gap = gap;
    c.id = id;
    c.feature_kind = SDFCCD_FEATURE_VERTEX;
    c.feature = (uint32_t)id;
    return c;
}

/* A reduction's result checked: never two at one place, never one twice, within the room. */
static int32_t checked(const sdfccd_ContactPoint* c, int32_t n, int32_t cap, const int32_t* idx, int32_t count)
{
    ck_assert(count >= 0 && count <= cap && count <= n);
    for (int32_t i = 0; i < count; ++i) {
        ck_assert(idx[i] >= 0 && idx[i] < n);
        for (int32_t j = 0; j < i; ++j) {
            sdfccd_Vec3 a = c[idx[i]].surface_point, b = c[idx[j]].surface_point;
            ck_assert(hypot(hypot(a.x - b.x, a.y - b.y), a.z - b.z) > SAME);
        }
    }
    return count;
}

/* sdfccd_reduce_contacts_weighted (scale 0: sdfccd_reduce_contacts), checked. */
static int32_t reduce_w(const sdfccd_ContactPoint* c, int32_t n, double scale, int32_t cap, int32_t* idx)
{
    int32_t count = -1;
    if (scale > 0.0)
        ck_assert_msg(sdfccd_reduce_contacts_weighted(c, n, SAME, scale, idx, cap, &count) == SDFCCD_OK, "%s", sdfccd_last_error());
    else
        ck_assert_msg(sdfccd_reduce_contacts(c, n, SAME, idx, cap, &count) == SDFCCD_OK, "%s", sdfccd_last_error());
    return checked(c, n, cap, idx, count);
}

static int32_t reduce(const sdfccd_ContactPoint* c, int32_t n, int32_t cap, int32_t* idx) { return reduce_w(c, n, 0.0, cap, idx); }

static int contains(const int32_t* idx, int32_t count, int32_t want)
{
    for (int32_t i = 0; i < count; ++i)
        if (idx[i] == want) return 1;
    return 0;
}

/* Area of the convex hull of the chosen points (xy plane), by gift wrapping: the reference. */
static double hull_area(const sdfccd_ContactPoint* c, const int32_t* idx, int32_t count)
{
    if (count < 3) return 0.0;
    int32_t start = 0;
    for (int32_t i = 1; i < count; ++i) {
        sdfccd_Vec3 p = c[idx[i]].surface_point, s = c[idx[start]].surface_point;
        if (p.x < s.x || (p.x == s.x && p.y < s.y)) start = i;
    }
    double area = 0.0;
    int32_t cur = start;
    for (int guard = 0; guard <= count; ++guard) {
        int32_t nxt = (cur + 1) % count;
        for (int32_t i = 0; i < count; ++i) {
            sdfccd_Vec3 a = c[idx[cur]].surface_point, b = c[idx[nxt]].surface_point, q = c[idx[i]].surface_point;
            double cr = (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
            if (cr < 0) nxt = i;
        }
        sdfccd_Vec3 a = c[idx[cur]].surface_point, b = c[idx[nxt]].surface_point;
        area += 0.5 * (a.x * b.y - b.x * a.y);
        cur = nxt;
        if (cur == start) break;
    }
    return fabs(area);
}

START_TEST(test_reduce_single_point)
{
    sdfccd_ContactPoint c = cp(0.1, 0.2, 0.0, -0.001, 7);
    int32_t idx[4];
    ck_assert_int_eq(reduce(&c, 1, 4, idx), 1);
    ck_assert_int_eq(idx[0], 0);
    ck_assert_int_eq(reduce(&c, 1, 0, idx), 0);
    ck_assert_int_eq(reduce(NULL, 0, 4, idx), 0);
}
END_TEST

START_TEST(test_reduce_coincident)
{
    /* ten contacts at one place (a vertex shared by ten triangles): one point, the deepest */
    sdfccd_ContactPoint c[10];
    for (int i = 0; i < 10; ++i) c[i] = cp(0.3, -0.2, 0.0, -0.001 * ((i * 7) % 10), (uint64_t)i);
    int32_t idx[4];
    ck_assert_int_eq(reduce(c, 10, 4, idx), 1);
    ck_assert_int_eq(idx[0], 7); /* (7 * 7) % 10 = 9: the deepest */
}
END_TEST

START_TEST(test_reduce_collinear)
{
    /* a cylinder lying on a floor: eleven points on a line, the middle one deepest */
    sdfccd_ContactPoint c[11];
    for (int i = 0; i < 11; ++i) c[i] = cp(0.1 * i, 0.05 * i, 0.0, i == 5 ? -0.002 : 0.0, (uint64_t)(100 + i));
    int32_t idx[4];
    int32_t n = reduce(c, 11, 3, idx);
    ck_assert_int_eq(n, 3);
    ck_assert_int_eq(idx[0], 5);                        /* deepest first */
    ck_assert(contains(idx, n, 0) && contains(idx, n, 10)); /* then both ends */
    n = reduce(c, 11, 4, idx);
    ck_assert_int_eq(n, 4);
    ck_assert(idx[0] == 5 && contains(idx, n, 0) && contains(idx, n, 10));
}
END_TEST

START_TEST(test_reduce_face_corners)
{
    /* a face landing flat: a 5 x 5 grid at one gap, the corners last in the array; four points are
     * the corners (the reduction, not the first four) */
    sdfccd_ContactPoint c[25];
    int k = 0, corners[4], nc = 0;
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j)
            if ((i == 0 || i == 4) && (j == 0 || j == 4)) continue;
            else c[k] = cp(0.01 * i, 0.01 * j, 0.0, 0.0005, (uint64_t)k), ++k;
    for (int i = 0; i <= 4; i += 4)
        for (int j = 0; j <= 4; j += 4) corners[nc++] = k, c[k] = cp(0.01 * i, 0.01 * j, 0.0, 0.0005, (uint64_t)k), ++k;
    int32_t idx[8];
    int32_t n = reduce(c, 25, 4, idx);
    ck_assert_int_eq(n, 4);
    for (int i = 0; i < 4; ++i) ck_assert(contains(idx, n, corners[i]));
    ck_assert_double_near(hull_area(c, idx, n), 0.04 * 0.04, 1e-15);
    /* with room for more, the corners and then points spread inside */
    n = reduce(c, 25, 8, idx);
    ck_assert_int_eq(n, 8);
    for (int i = 0; i < 4; ++i) ck_assert(contains(idx, n, corners[i]));
    ck_assert(contains(idx, n, 10)); /* the centre (2, 2) is the point farthest from the corners */
}
END_TEST

/* n points in the unit square, gaps in [-1e-3, 1e-3], ids 1000 + i */
static void random_set(test_rng* r, sdfccd_ContactPoint* c, int n)
{
    for (int i = 0; i < n; ++i)
        c[i] = cp(test_rng_uniform(r, 0, 1), test_rng_uniform(r, 0, 1), 0.0, test_rng_uniform(r, -1e-3, 1e-3), (uint64_t)(1000 + i));
}

START_TEST(test_reduce_thousand_points)
{
    enum { N = 1000 };
    static sdfccd_ContactPoint c[N], shuffled[N], moved[N];
    test_rng rng = { 42 };
    random_set(&rng, c, N);
    int deepest = 0;
    for (int i = 1; i < N; ++i)
        if (c[i].gap < c[deepest].gap) deepest = i;
    int32_t idx[16], idx2[16];
    const int caps[3] = { 4, 8, 16 };
    for (int t = 0; t < 3; ++t) {
        int32_t n = reduce(c, N, caps[t], idx);
        ck_assert_int_eq(n, caps[t]);
        ck_assert_int_eq(idx[0], deepest);
        double area = hull_area(c, idx, n);
        REPORT("thousand points, %d kept: hull area %.4f of the unit square\n", caps[t], area);
        /* the deepest point may lie anywhere, the rest go to the corners: at least half the square
         * with 4 points, nearly all of it with 8 and 16 */
        ck_assert(area >= (caps[t] == 4 ? 0.5 : 0.9));
        /* the input's order does not matter (distinct ids) */
        for (int i = 0; i < N; ++i) shuffled[i] = c[(i * 617 + 13) % N];
        int32_t n2 = reduce(shuffled, N, caps[t], idx2);
        ck_assert_int_eq(n2, n);
        for (int i = 0; i < n; ++i) ck_assert(shuffled[idx2[i]].id == c[idx[i]].id);
        /* ids persist: the same set a step later, every point moved by less than 1e-7 m */
        for (int i = 0; i < N; ++i) {
            moved[i] = c[i];
            moved[i].surface_point.x += test_rng_uniform(&rng, -1e-8, 1e-8);
            moved[i].surface_point.y += test_rng_uniform(&rng, -1e-8, 1e-8);
            moved[i].gap += test_rng_uniform(&rng, -1e-12, 1e-12);
        }
        n2 = reduce(moved, N, caps[t], idx2);
        ck_assert_int_eq(n2, n);
        for (int i = 0; i < n; ++i) ck_assert(moved[idx2[i]].id == c[idx[i]].id);
    }
}
END_TEST

START_TEST(test_reduce_same_place)
{
    /* pairs of points closer than same_place_distance (one above the other): never both */
    sdfccd_ContactPoint c[8];
    for (int i = 0; i < 4; ++i) {
        c[2 * i] = cp((i & 1) * 0.1, (i >> 1) * 0.1, 0.0, -0.001, (uint64_t)(2 * i));
        c[2 * i + 1] = cp((i & 1) * 0.1, (i >> 1) * 0.1, 0.5 * SAME, -0.002, (uint64_t)(2 * i + 1));
    }
    int32_t idx[8];
    int32_t n = reduce(c, 8, 8, idx);
    ck_assert_int_eq(n, 4);
    /* the deeper of each pair: the same spread, and ties go to the smaller gap */
    for (int i = 0; i < n; ++i) ck_assert_int_eq(idx[i] % 2, 1);
}
END_TEST

START_TEST(test_reduce_bad_input)
{
    sdfccd_ContactPoint c[2] = { cp(0, 0, 0, 0, 1), cp(1, 0, 0, 0, 2) };
    int32_t idx[2], count = -7;
    ck_assert_int_eq(sdfccd_reduce_contacts(c, 2, SAME, idx, 2, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts(NULL, 2, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts(c, 2, SAME, NULL, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts(c, -1, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts(c, 2, SAME, idx, -1, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts(c, 2, -1.0, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts(c, 2, NAN, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    c[1].gap = NAN;
    ck_assert_int_eq(sdfccd_reduce_contacts(c, 2, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strlen(sdfccd_last_error()) > 0);
    ck_assert_int_eq(count, -7); /* not written on error */
}
END_TEST

/* ---- the depth-weighted reduction (sdfccd_reduce_contacts_weighted) ---- */

START_TEST(test_reduce_weighted_crossover)
{
    /* the deepest point at the origin, a point about to touch at y = 0.3 and a far one (gap 0.5, a
     * corner that may reach the surface late in the step) at x = D: the far one is second exactly
     * when 0.95 D exp(-(0.5 - g0) / s) > 0.3 (the weight, and the deeper point within 95 % of the
     * best score winning) */
    const double g0 = -0.001, s = 0.1, w = exp(-(0.5 - g0) / s);
    const double d_cross = 0.3 / (0.95 * w);
    for (int side = -1; side <= 1; side += 2) {
        sdfccd_ContactPoint c[3] = { cp(0.0, 0.0, 0.0, g0, 1), cp(0.0, 0.3, 0.0, g0 + 1e-4, 2),
                                     cp(d_cross * (1.0 + 1e-3 * side), 0.0, 0.0, 0.5, 3) };
        int32_t idx[2];
        ck_assert_int_eq(reduce_w(c, 3, s, 2, idx), 2);
        ck_assert_int_eq(idx[0], 0);
        ck_assert_int_eq(idx[1], side > 0 ? 2 : 1);
        /* unweighted (scale 0: sdfccd_reduce_contacts), the far point always wins */
        ck_assert_int_eq(reduce_w(c, 3, 0.0, 2, idx), 2);
        ck_assert_int_eq(idx[1], 2);
    }
}
END_TEST

START_TEST(test_reduce_weighted_small_sets)
{
    int32_t idx[4];
    /* single point, and nothing */
    sdfccd_ContactPoint one = cp(0.1, 0.2, 0.0, 0.3, 7);
    ck_assert_int_eq(reduce_w(&one, 1, 0.01, 4, idx), 1);
    ck_assert_int_eq(idx[0], 0);
    ck_assert_int_eq(reduce_w(NULL, 0, 0.01, 4, idx), 0);
    /* coincident: ten at one place, one point, the deepest */
    sdfccd_ContactPoint c[11];
    for (int i = 0; i < 10; ++i) c[i] = cp(0.3, -0.2, 0.0, -0.001 * ((i * 7) % 10), (uint64_t)i);
    ck_assert_int_eq(reduce_w(c, 10, 0.01, 4, idx), 1);
    ck_assert_int_eq(idx[0], 7);
    /* collinear, the deepest in the middle and one end far from the surface (gap 0.05 m): the
     * near end (0.56 m x exp(-0.2)), then the point next to the far end (0.45 m x exp(-0.2)) beats
     * the far end (0.56 m x exp(-5.2)); unweighted, both ends */
    for (int i = 0; i < 11; ++i) c[i] = cp(0.1 * i, 0.05 * i, 0.0, i == 5 ? -0.002 : i == 10 ? 0.05 : 0.0, (uint64_t)(100 + i));
    int32_t n = reduce_w(c, 11, 0.01, 3, idx);
    ck_assert_int_eq(n, 3);
    ck_assert(idx[0] == 5 && idx[1] == 0 && idx[2] == 9);
    n = reduce_w(c, 11, 0.0, 3, idx);
    ck_assert_int_eq(n, 3);
    ck_assert(idx[0] == 5 && contains(idx, n, 0) && contains(idx, n, 10));
}
END_TEST

START_TEST(test_reduce_weighted_thousand_points)
{
    enum { N = 1000 };
    static sdfccd_ContactPoint c[N], shuffled[N];
    test_rng rng = { 7 };
    random_set(&rng, c, N);
    for (int i = 0; i < N; ++i) c[i].gap *= 100.0; /* gaps in [-0.1, 0.1] m */
    const double s = 0.02;
    int deepest = 0;
    for (int i = 1; i < N; ++i)
        if (c[i].gap < c[deepest].gap) deepest = i;
    /* the reference for the second point, by brute force: the deepest of the points whose weighted
     * distance is at least 95 % of the largest */
    static double sc[N];
    double best = -1.0;
    for (int i = 0; i < N; ++i) {
        double dx = c[i].surface_point.x - c[deepest].surface_point.x, dy = c[i].surface_point.y - c[deepest].surface_point.y;
        sc[i] = i == deepest ? -1.0 : hypot(dx, dy) * exp(-(c[i].gap - c[deepest].gap) / s);
        best = fmax(best, sc[i]);
    }
    int second = -1;
    for (int i = 0; i < N; ++i)
        if (sc[i] >= 0.95 * best && (second < 0 || c[i].gap < c[second].gap)) second = i;
    int32_t idx[16], idx2[16], plain[16];
    for (int cap = 1; cap <= 16; cap *= 2) {
        /* a buffer smaller than the set: the reduction, never the first points */
        int32_t n = reduce_w(c, N, s, cap, idx);
        ck_assert_int_eq(n, cap);
        ck_assert_int_eq(idx[0], deepest);
        if (cap > 1) ck_assert_int_eq(idx[1], second);
        /* deeper points win: the kept points are on average deeper than the unweighted choice */
        int32_t np = reduce(c, N, cap, plain);
        double gw = 0.0, gp = 0.0;
        for (int i = 1; i < n; ++i) gw += c[idx[i]].gap;
        for (int i = 1; i < np; ++i) gp += c[plain[i]].gap;
        if (cap >= 4) ck_assert(gw < gp);
        /* the order of the input does not matter (distinct ids) */
        for (int i = 0; i < N; ++i) shuffled[i] = c[(i * 617 + 13) % N];
        ck_assert_int_eq(reduce_w(shuffled, N, s, cap, idx2), n);
        for (int i = 0; i < n; ++i) ck_assert(shuffled[idx2[i]].id == c[idx[i]].id);
        /* ids persist: the set a step later, moved by less than 1e-8 m */
        for (int i = 0; i < N; ++i) {
            shuffled[i] = c[i];
            shuffled[i].surface_point.x += test_rng_uniform(&rng, -1e-9, 1e-9);
            shuffled[i].gap += test_rng_uniform(&rng, -1e-12, 1e-12);
        }
        ck_assert_int_eq(reduce_w(shuffled, N, s, cap, idx2), n);
        for (int i = 0; i < n; ++i) ck_assert(shuffled[idx2[i]].id == c[idx[i]].id);
    }
    /* scale 0 is sdfccd_reduce_contacts() */
    int32_t count = -1;
    ck_assert_int_eq(sdfccd_reduce_contacts_weighted(c, N, SAME, 0.0, idx, 16, &count), SDFCCD_OK);
    ck_assert_int_eq(count, reduce(c, N, 16, plain));
    for (int i = 0; i < 16; ++i) ck_assert_int_eq(idx[i], plain[i]);
}
END_TEST

START_TEST(test_reduce_weighted_rounding)
{
    /* a face resting flat, its 25 corner and grid points' gaps computed by a float engine: equal up
     * to 3e-8 m of rounding that changes from step to step. The points chosen (first the corner
     * farthest from the centre, then the opposite one) must not change with the rounding: the same
     * ids over 20 steps (the order of the last two, of equal area, may follow the rounding) */
    enum { N = 25 };
    sdfccd_ContactPoint c[N];
    test_rng rng = { 11 };
    int32_t first[4] = { -1, -1, -1, -1 }, idx[4];
    for (int step = 0; step < 20; ++step) {
        for (int i = 0; i < N; ++i)
            c[i] = cp(0.01 * (i % 5), 0.01 * (i / 5), 0.0, 0.0005 + test_rng_uniform(&rng, -3e-8, 3e-8), (uint64_t)(500 + i));
        ck_assert_int_eq(reduce_w(c, N, 0.01, 4, idx), 4);
        ck_assert_int_eq(idx[0], 0); /* the first corner in index order: all four are equally far */
        ck_assert_int_eq(idx[1], 24);
        for (int i = 0; i < 4; ++i) {
            if (step == 0) first[i] = idx[i];
            ck_assert(contains(first, 4, idx[i]));
        }
        ck_assert(contains(idx, 4, 4) && contains(idx, 4, 20));
    }
}
END_TEST

START_TEST(test_reduce_weighted_contact_plane)
{
    /* three equally deep points of a curved surface, the first (the deepest by index) with normal +z:
     * on its contact plane the centre is (-0.00667, 0) and the farthest is the one at x = -0.12
     * (0.1133 against 0.1067), though in space the one at height 0.5 is farther (0.35) */
    sdfccd_ContactPoint c[3] = { cp(0.0, 0.0, 0.0, -0.001, 1), cp(0.1, 0.0, 0.5, -0.001, 2), cp(-0.12, 0.0, 0.0, -0.001, 3) };
    c[1].normal = (sdfccd_Vec3){ 0.6, 0.0, 0.8 };
    int32_t idx[1];
    ck_assert_int_eq(reduce_w(c, 3, 0.01, 1, idx), 1);
    ck_assert_int_eq(idx[0], 2);
}
END_TEST

START_TEST(test_reduce_weighted_bad_input)
{
    sdfccd_ContactPoint c[2] = { cp(0, 0, 0, 0, 1), cp(1, 0, 0, 0, 2) };
    int32_t idx[2], count = -7;
    ck_assert_int_eq(sdfccd_reduce_contacts_weighted(c, 2, SAME, -0.1, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts_weighted(c, 2, SAME, NAN, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts_weighted(c, 2, SAME, INFINITY, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts_weighted(c, 2, -1.0, 0.1, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts_weighted(c, 2, SAME, 0.1, idx, 2, NULL), SDFCCD_INVALID_ARGUMENT);
    c[0].normal.x = NAN;
    ck_assert_int_eq(sdfccd_reduce_contacts_weighted(c, 2, SAME, 0.1, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strstr(sdfccd_last_error(), "sdfccd_reduce_contacts_weighted") != NULL);
    ck_assert_int_eq(count, -7);
}
END_TEST

/* ---- the previous step's points (sdfccd_reduce_contacts_kept, sdfccd_KeepPrevious) ---- */

static const double KEEP_SCALE = 0.1; /* the weighted reduction's depth scale below */

/* sdfccd_reduce_contacts_kept with the ids `prev` (count n_prev; NULL: none), checked as reduce_w. */
static int32_t reduce_k(const sdfccd_ContactPoint* c, int32_t n, const uint64_t* prev, int32_t n_prev, double depth, double share,
                        int32_t cap, int32_t* idx)
{
    sdfccd_KeepPrevious k = { prev, n_prev, depth, share };
    int32_t count = -1;
    ck_assert_msg(sdfccd_reduce_contacts_kept(c, n, SAME, KEEP_SCALE, prev ? &k : NULL, idx, cap, &count) == SDFCCD_OK, "%s",
                  sdfccd_last_error());
    return checked(c, n, cap, idx, count);
}

/* The ids of the chosen points. */
static void chosen_ids(const sdfccd_ContactPoint* c, const int32_t* idx, int32_t n, uint64_t* ids)
{
    for (int32_t i = 0; i < n; ++i) ids[i] = c[idx[i]].id;
}

/* A resting set one step and the next, as a wedged body gives it: the two deepest points, A (0, 0)
 * and B (1, 0), trade the first place by 2 micrometres of rounding (-1e-6 and +1e-6 m, then the other
 * way); C (1, 1) and D (0, 1) 1 mm above. */
static void wedge_set(sdfccd_ContactPoint* c, int step)
{
    const double s = step == 1 ? 1.0 : -1.0;
    c[0] = cp(0.0, 0.0, 0.0, -1e-6 * s, 460);
    c[1] = cp(1.0, 0.0, 0.0, 1e-6 * s, 2);
    c[2] = cp(1.0, 1.0, 0.0, 1e-3, 543);
    c[3] = cp(0.0, 1.0, 0.0, 1e-3, 176);
}

/* Three points of a set, the third of two candidates that trade it by 1e-5 m of depth: A (0, 0) the
 * deepest (-1 mm), C (1, 1) the farthest, then E (0, 1) at 0 and F (1, 0) at +1e-5 m, then -1e-5 m
 * (both add the same area, and the deeper one within 95 % of the best score is chosen). */
static void third_set(sdfccd_ContactPoint* c, int step)
{
    c[0] = cp(0.0, 0.0, 0.0, -1e-3, 460);
    c[1] = cp(1.0, 1.0, 0.0, 0.0, 543);
    c[2] = cp(0.0, 1.0, 0.0, 0.0, 176);
    c[3] = cp(1.0, 0.0, 0.0, step == 1 ? 1e-5 : -1e-5, 178);
}

START_TEST(test_reduce_kept_persist)
{
    sdfccd_ContactPoint c[4];
    int32_t idx[4], idx2[4];
    uint64_t ids1[4], ids2[4];
    /* without the previous points, the first point flips with the rounding (and the order with it) */
    wedge_set(c, 1);
    ck_assert_int_eq(reduce_k(c, 4, NULL, 0, 0, 0, 4, idx), 4);
    chosen_ids(c, idx, 4, ids1);
    wedge_set(c, 2);
    ck_assert_int_eq(reduce_k(c, 4, NULL, 0, 0, 0, 4, idx2), 4);
    chosen_ids(c, idx2, 4, ids2);
    ck_assert(ids1[0] == 460 && ids2[0] == 2);
    /* with them (depth 5e-4 m, share 0.8): the same points in the same order, step after step */
    for (int step = 2; step <= 5; ++step) {
        wedge_set(c, step % 2 ? 1 : 2);
        ck_assert_int_eq(reduce_k(c, 4, ids1, 4, 5e-4, 0.8, 4, idx2), 4);
        chosen_ids(c, idx2, 4, ids2);
        for (int i = 0; i < 4; ++i) ck_assert(ids2[i] == ids1[i]);
    }
    /* step 2's own choice, kept, is kept in turn: whichever came first stays */
    wedge_set(c, 2);
    ck_assert_int_eq(reduce_k(c, 4, NULL, 0, 0, 0, 4, idx), 4);
    chosen_ids(c, idx, 4, ids1);
    wedge_set(c, 1);
    ck_assert_int_eq(reduce_k(c, 4, ids1, 4, 5e-4, 0.8, 4, idx2), 4);
    chosen_ids(c, idx2, 4, ids2);
    for (int i = 0; i < 4; ++i) ck_assert(ids2[i] == ids1[i]);
    /* the identity of a later point: without them, E then F; with them, E both times */
    third_set(c, 1);
    ck_assert_int_eq(reduce_k(c, 4, NULL, 0, 0, 0, 3, idx), 3);
    chosen_ids(c, idx, 3, ids1);
    ck_assert(ids1[0] == 460 && ids1[1] == 543 && ids1[2] == 176);
    third_set(c, 2);
    ck_assert_int_eq(reduce_k(c, 4, NULL, 0, 0, 0, 3, idx), 3);
    ck_assert(c[idx[2]].id == 178);
    ck_assert_int_eq(reduce_k(c, 4, ids1, 3, 5e-4, 0.8, 3, idx), 3);
    chosen_ids(c, idx, 3, ids2);
    for (int i = 0; i < 3; ++i) ck_assert(ids2[i] == ids1[i]);
    /* a previous first point is the contact plane: two walls (normals 90 degrees apart), the other
     * one the deeper by 2 micrometres; on the kept wall's plane (normal +x) the two points are 0.3 m
     * apart, so both are chosen */
    sdfccd_ContactPoint w[2] = { cp(0.0, 0.0, 0.0, -1e-6, 1), cp(0.0, 0.3, 0.0, 1e-6, 2) };
    w[1].normal = (sdfccd_Vec3){ 1.0, 0.0, 0.0 };
    const uint64_t first_wall[1] = { 2 };
    ck_assert_int_eq(reduce_k(w, 2, first_wall, 1, 5e-4, 0.8, 2, idx), 2);
    ck_assert(idx[0] == 1 && idx[1] == 0);
}
END_TEST

START_TEST(test_reduce_kept_better_wins)
{
    sdfccd_ContactPoint c[5];
    int32_t idx[4];
    uint64_t ids1[4], ids[4];
    wedge_set(c, 1);
    ck_assert_int_eq(reduce_k(c, 4, NULL, 0, 0, 0, 4, idx), 4);
    chosen_ids(c, idx, 4, ids1);
    /* a new point deeper by more than the depth (0.6 mm against 0.5) is first; by less (0.4 mm), not */
    for (int deeper = 0; deeper <= 1; ++deeper) {
        wedge_set(c, 2);
        c[4] = cp(0.5, 0.5, 0.0, deeper ? -6e-4 : -4e-4, 999);
        ck_assert_int_eq(reduce_k(c, 5, ids1, 4, 5e-4, 0.8, 4, idx), 4);
        ck_assert(c[idx[0]].id == (deeper ? 999u : 460u));
    }
    /* depth 0: the deeper point is first again */
    wedge_set(c, 2);
    ck_assert_int_eq(reduce_k(c, 4, ids1, 4, 0.0, 0.8, 4, idx), 4);
    ck_assert(c[idx[0]].id == 2);
    /* a new point H (x, 1) adding more than 1 / 0.8 of the kept E's area (1.5 x at x = -0.5) wins; one
     * adding 1.2 x (x = -0.2; the plain reduction takes it) does not */
    third_set(c, 1);
    ck_assert_int_eq(reduce_k(c, 4, NULL, 0, 0, 0, 3, idx), 3);
    chosen_ids(c, idx, 3, ids1);
    for (int far = 0; far <= 1; ++far) {
        third_set(c, 2);
        c[4] = cp(far ? -0.5 : -0.2, 1.0, 0.0, 0.0, 777);
        ck_assert_int_eq(reduce_k(c, 5, NULL, 0, 0, 0, 3, idx), 3);
        ck_assert(c[idx[2]].id == 777);
        ck_assert_int_eq(reduce_k(c, 5, ids1, 3, 5e-4, 0.8, 3, idx), 3);
        chosen_ids(c, idx, 3, ids);
        ck_assert(ids[0] == 460 && ids[1] == 543);
        ck_assert(ids[2] == (far ? 777u : 176u));
    }
    /* share 1: only as good a point is kept (F scores a little more than E: its weight) */
    third_set(c, 2);
    ck_assert_int_eq(reduce_k(c, 4, ids1, 3, 5e-4, 1.0, 3, idx), 3);
    ck_assert(c[idx[2]].id == 178);
}
END_TEST

START_TEST(test_reduce_kept_deterministic)
{
    enum { N = 1000 };
    static sdfccd_ContactPoint c[N], shuffled[N];
    test_rng rng = { 23 };
    random_set(&rng, c, N);
    int32_t idx[16], idx2[16], plain[16];
    uint64_t prev[16], none[3] = { 5000001, 5000002, 5000003 };
    int plain_flipped = 0;
    for (int cap = 1; cap <= 16; cap *= 2) {
        /* no previous points, or none in the set: exactly the weighted reduction */
        int32_t count = -1;
        ck_assert_int_eq(sdfccd_reduce_contacts_weighted(c, N, SAME, KEEP_SCALE, plain, cap, &count), SDFCCD_OK);
        ck_assert_int_eq(reduce_k(c, N, NULL, 0, 5e-4, 0.8, cap, idx), count);
        for (int i = 0; i < count; ++i) ck_assert_int_eq(idx[i], plain[i]);
        ck_assert_int_eq(reduce_k(c, N, none, 3, 5e-4, 0.8, cap, idx), count);
        for (int i = 0; i < count; ++i) ck_assert_int_eq(idx[i], plain[i]);
        /* the set a step later, moved by up to 1e-4 m in gap and 1e-5 m in place: each choice is a
         * previous point (no new one is clearly better), in the same order; without them, the choice
         * follows the noise (checked below over the caps) */
        chosen_ids(c, plain, count, prev);
        for (int i = 0; i < N; ++i) {
            shuffled[i] = c[i];
            shuffled[i].surface_point.x += test_rng_uniform(&rng, -1e-5, 1e-5);
            shuffled[i].gap += test_rng_uniform(&rng, -1e-4, 1e-4);
        }
        int32_t n = reduce_k(shuffled, N, prev, count, 5e-4, 0.8, cap, idx);
        ck_assert_int_eq(n, count);
        for (int i = 0; i < n; ++i) ck_assert(shuffled[idx[i]].id == prev[i]);
        const int32_t np = reduce_k(shuffled, N, NULL, 0, 0, 0, cap, idx2);
        for (int i = 0; i < np && !plain_flipped; ++i) plain_flipped = np != n || shuffled[idx2[i]].id != prev[i];
        /* the order of the input does not matter (distinct ids) */
        for (int i = 0; i < N; ++i) c[i] = shuffled[(i * 617 + 13) % N];
        ck_assert_int_eq(reduce_k(c, N, prev, count, 5e-4, 0.8, cap, idx2), n);
        for (int i = 0; i < n; ++i) ck_assert(c[idx2[i]].id == prev[i]);
        /* and twice the same call, the same answer */
        ck_assert_int_eq(reduce_k(c, N, prev, count, 5e-4, 0.8, cap, idx), n);
        for (int i = 0; i < n; ++i) ck_assert_int_eq(idx[i], idx2[i]);
    }
    ck_assert(plain_flipped);
}
END_TEST

START_TEST(test_reduce_kept_bad_input)
{
    sdfccd_ContactPoint c[2] = { cp(0, 0, 0, 0, 1), cp(1, 0, 0, 0, 2) };
    const uint64_t ids[2] = { 1, 2 };
    int32_t idx[2], count = -7;
    const sdfccd_KeepPrevious bad[5] = { { ids, -1, 5e-4, 0.8 }, { NULL, 2, 5e-4, 0.8 }, { ids, 2, NAN, 0.8 }, { ids, 2, -1e-3, 0.8 },
                                         { ids, 2, 5e-4, 1.5 } };
    for (int i = 0; i < 5; ++i) {
        ck_assert_int_eq(sdfccd_reduce_contacts_kept(c, 2, SAME, 0.1, &bad[i], idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
        ck_assert(strstr(sdfccd_last_error(), "sdfccd_reduce_contacts_kept") != NULL);
    }
    const sdfccd_KeepPrevious nan_share = { ids, 2, 5e-4, NAN };
    ck_assert_int_eq(sdfccd_reduce_contacts_kept(c, 2, SAME, 0.1, &nan_share, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts_kept(c, 2, SAME, -0.1, NULL, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_reduce_contacts_kept(c, 2, SAME, 0.1, NULL, idx, 2, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(count, -7);
}
END_TEST

/* ---- cover points (sdfccd_cover_contacts) ---- */

static int32_t cover(const sdfccd_ContactPoint* c, int32_t n, const int32_t* chosen, int32_t m, double tilt, double depth, int32_t cap,
                     int32_t* idx)
{
    int32_t count = -1;
    ck_assert_msg(sdfccd_cover_contacts(c, n, chosen, m, tilt, depth, SAME, idx, cap, &count) == SDFCCD_OK, "%s", sdfccd_last_error());
    ck_assert(count >= 0 && count <= cap);
    return count;
}

/* No turn: only a point deeper than the held one by more than `depth` needs holding. */
START_TEST(test_cover_no_tilt)
{
    sdfccd_ContactPoint c[3] = { cp(0, 0, 0, 0.0, 1), cp(1, 0, 0, -0.005, 2), cp(0, 1, 0, 0.0002, 3) };
    const int32_t chosen[1] = { 0 };
    int32_t idx[3];
    ck_assert_int_eq(cover(c, 3, chosen, 1, 0.0, 0.0005, 3, idx), 1);
    ck_assert_int_eq(idx[0], 1);
    /* 5 mm short of its bound is within a depth of 6 mm: nothing */
    ck_assert_int_eq(cover(c, 3, chosen, 1, 0.0, 0.006, 3, idx), 0);
}
END_TEST

/* A turn of `tilt` about the held point lets a point at distance L sink by tilt L: held when that
 * exceeds its gap by more than depth (closed form: 0.2 - 0.1 > 0; 0.05 - 0.1 < 0). */
START_TEST(test_cover_tilt_closed_form)
{
    sdfccd_ContactPoint c[2] = { cp(0, 0, 0, 0.0, 1), cp(1, 0, 0, 0.1, 2) };
    const int32_t chosen[1] = { 0 };
    int32_t idx[2];
    ck_assert_int_eq(cover(c, 2, chosen, 1, 0.2, 0.0005, 2, idx), 1);
    ck_assert_int_eq(idx[0], 1);
    ck_assert_int_eq(cover(c, 2, chosen, 1, 0.05, 0.0005, 2, idx), 0);
}
END_TEST

/* The largest shortfall first; a point held then bounds its neighbours. */
START_TEST(test_cover_order_and_neighbours)
{
    sdfccd_ContactPoint c[3] = { cp(0, 0, 0, 0.0, 1), cp(2, 0, 0, 0.0, 2), cp(2.1, 0, 0, 0.0, 3) };
    const int32_t chosen[1] = { 0 };
    int32_t idx[3];
    /* shortfalls 0.2 and 0.21: point 2 first; then point 1 is bounded by it to 0.1 x 0.1 = 0.01 */
    ck_assert_int_eq(cover(c, 3, chosen, 1, 0.1, 0.0005, 3, idx), 2);
    ck_assert_int_eq(idx[0], 2);
    ck_assert_int_eq(idx[1], 1);
    ck_assert_int_eq(cover(c, 3, chosen, 1, 0.1, 0.02, 3, idx), 1); /* 0.01 <= 0.02: covered */
    ck_assert_int_eq(idx[0], 2);
    ck_assert_int_eq(cover(c, 3, chosen, 1, 0.1, 0.0005, 1, idx), 1); /* capacity */
    ck_assert_int_eq(idx[0], 2);
}
END_TEST

/* Equal shortfalls go to the smaller gap (0.1 x 1 - 0 = 0.1 x 2 - 0.1, exactly). */
START_TEST(test_cover_tie)
{
    sdfccd_ContactPoint c[3] = { cp(0, 0, 0, 0.0, 1), cp(-2, 0, 0, 0.1, 2), cp(1, 0, 0, 0.0, 3) };
    const int32_t chosen[1] = { 0 };
    int32_t idx[3];
    ck_assert_int_eq(cover(c, 3, chosen, 1, 0.1, 0.0005, 1, idx), 1);
    ck_assert_int_eq(idx[0], 2);
}
END_TEST

/* A point facing the other way (the far side of a thin wall) is not bounded by the held one; a point
 * at the held one's place is never picked. */
START_TEST(test_cover_normals_and_same_place)
{
    sdfccd_ContactPoint c[3] = { cp(0, 0, 0, 0.0, 1), cp(0.5, 0, 0, 0.0, 2), cp(0.5 * SAME, 0, 0, -1.0, 3) };
    c[1].normal = (sdfccd_Vec3){ 0, 0, -1 };
    const int32_t chosen[1] = { 0 };
    int32_t idx[3];
    ck_assert_int_eq(cover(c, 3, chosen, 1, 0.0, 0.0005, 3, idx), 1);
    ck_assert_int_eq(idx[0], 1);
    /* nothing chosen: nothing to cover */
    ck_assert_int_eq(cover(c, 3, NULL, 0, 0.0, 0.0005, 3, idx), 0);
}
END_TEST

/* Random sets against a brute-force reading of the rule: when fewer than capacity are picked, every
 * point left (not at a held point's place) ends no deeper than depth below its bound. */
START_TEST(test_cover_random_property)
{
    enum { N = 300, CAP = 12 };
    static sdfccd_ContactPoint c[N];
    unsigned seed = 12345u;
    for (int trial = 0; trial < 20; ++trial) {
        for (int i = 0; i < N; ++i) {
            seed = seed * 1664525u + 1013904223u;
            double x = (seed >> 8) / 16777216.0 - 0.5;
            seed = seed * 1664525u + 1013904223u;
            double y = (seed >> 8) / 16777216.0 - 0.5;
            seed = seed * 1664525u + 1013904223u;
            double g = 0.004 * ((seed >> 8) / 16777216.0) - 0.001;
            c[i] = cp(x, y, 0, g, (uint64_t)i);
        }
        int32_t red[4], n_red = reduce(c, N, 4, red), idx[CAP];
        const double tilt = 0.002 * trial, depth = 0.0005;
        int32_t m = cover(c, N, red, n_red, tilt, depth, CAP, idx);
        int32_t held[4 + CAP], nh = 0;
        for (int32_t j = 0; j < n_red; ++j) held[nh++] = red[j];
        for (int32_t j = 0; j < m; ++j) {
            ck_assert(!contains(red, n_red, idx[j]));
            ck_assert(!contains(idx, j, idx[j]));
            held[nh++] = idx[j];
        }
        if (m == CAP) continue;
        for (int i = 0; i < N; ++i) {
            if (contains(held, nh, i)) continue;
            double bound = INFINITY;
            int near = 0;
            for (int32_t h = 0; h < nh; ++h) {
                const sdfccd_Vec3 a = c[i].surface_point, b = c[held[h]].surface_point;
                const double d = hypot(hypot(a.x - b.x, a.y - b.y), a.z - b.z);
                near |= d <= SAME;
                bound = fmin(bound, c[held[h]].gap + tilt * d);
            }
            ck_assert_msg(near || bound - c[i].gap <= depth, "trial %d: point %d may sink %g below its bound", trial, i, bound - c[i].gap);
        }
    }
}
END_TEST

START_TEST(test_cover_bad_input)
{
    sdfccd_ContactPoint c[2] = { cp(0, 0, 0, 0, 1), cp(1, 0, 0, 0, 2) };
    int32_t chosen[1] = { 0 }, idx[2], count = -7;
    ck_assert_int_eq(sdfccd_cover_contacts(c, 2, chosen, 1, 0, 0, SAME, idx, 2, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_cover_contacts(NULL, 2, chosen, 1, 0, 0, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_cover_contacts(c, 2, NULL, 1, 0, 0, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_cover_contacts(c, 2, chosen, 1, 0, 0, SAME, NULL, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_cover_contacts(c, 2, chosen, -1, 0, 0, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_cover_contacts(c, 2, chosen, 1, -1, 0, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_cover_contacts(c, 2, chosen, 1, 0, NAN, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    chosen[0] = 2;
    ck_assert_int_eq(sdfccd_cover_contacts(c, 2, chosen, 1, 0, 0, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    chosen[0] = 0;
    c[1].gap = INFINITY;
    ck_assert_int_eq(sdfccd_cover_contacts(c, 2, chosen, 1, 0, 0, SAME, idx, 2, &count), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strlen(sdfccd_last_error()) > 0);
    ck_assert_int_eq(count, -7); /* not written on error */
}
END_TEST

/* A torus mesh (ring in the xy-plane, major R, minor r, nu x nv quads); a vertex ring at the bottom. */
static sdfccd_MeshId torus_mesh(double R, double r, int nu, int nv)
{
    double* v = malloc(3 * (size_t)nu * nv * sizeof *v);
    uint32_t* f = malloc(6 * (size_t)nu * nv * sizeof *f);
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            double u = 2 * M_PI * i / nu, w = 2 * M_PI * j / nv;
            double* p = v + 3 * (i * nv + j);
            p[0] = (R + r * cos(w)) * cos(u);
            p[1] = (R + r * cos(w)) * sin(u);
            p[2] = r * sin(w);
            uint32_t a = (uint32_t)(i * nv + j), b = (uint32_t)(((i + 1) % nu) * nv + j), c = (uint32_t)(i * nv + (j + 1) % nv),
                     d = (uint32_t)(((i + 1) % nu) * nv + (j + 1) % nv);
            uint32_t* t = f + 6 * (i * nv + j);
            t[0] = a; t[1] = b; t[2] = d;
            t[3] = a; t[4] = d; t[5] = c;
        }
    sdfccd_MeshDef d = sdfccd_default_mesh_def();
    d.vertices = v;
    d.vertex_count = (uint32_t)(nu * nv);
    d.indices = f;
    d.triangle_count = (uint32_t)(2 * nu * nv);
    sdfccd_MeshId id;
    ck_assert_msg(sdfccd_create_mesh(&d, &id) == SDFCCD_OK, "%s", sdfccd_last_error());
    free(v);
    free(f);
    return id;
}

/* Area of the convex hull (xy) of the query's contact points (world). */
static double contacts_hull_area(const sdfccd_Contact* k, int32_t n)
{
    sdfccd_ContactPoint* c = malloc((size_t)(n > 0 ? n : 1) * sizeof *c);
    int32_t* idx = malloc((size_t)(n > 0 ? n : 1) * sizeof *idx);
    for (int32_t i = 0; i < n; ++i) {
        c[i] = cp(k[i].point.x, k[i].point.y, 0.0, 0.0, (uint64_t)i);
        idx[i] = i;
    }
    double a = hull_area(c, idx, n);
    free(c);
    free(idx);
    return a;
}

static int cmp_double(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

/* The widest angle (degrees, about the z axis) between neighbouring contact points. */
static double widest_gap_deg(const sdfccd_Contact* k, int32_t n)
{
    double a[64];
    for (int32_t i = 0; i < n && i < 64; ++i) a[i] = atan2(k[i].point.y, k[i].point.x) * 180.0 / M_PI;
    qsort(a, (size_t)n, sizeof a[0], cmp_double);
    double widest = a[0] + 360.0 - a[n - 1];
    for (int32_t i = 1; i < n; ++i) widest = fmax(widest, a[i] - a[i - 1]);
    return widest;
}

/* A torus landing flat on a floor: far more contacts at the TOI than the caller's room. The
 * contacts written are the reduction (the earliest first, spread over the ring), not the first ones
 * found (which lay on one side of the ring); hit, TOI and the count found do not change. */
START_TEST(test_mesh_query_reduces_contacts)
{
    sdfccd_MeshId torus = torus_mesh(0.1, 0.03, 48, 16);
    sdfccd_SdfId floor;
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &floor), SDFCCD_OK);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.z = 0.03 + 0.01;
    m.linear_velocity.z = -1.0;
    sdfccd_QueryParams p = sdfccd_default_query_params();
    enum { ALL = 2048 };
    sdfccd_Contact* all = malloc(ALL * sizeof *all);
    sdfccd_Contact few[16];
    sdfccd_QueryResult ra, rf;
    ck_assert_int_eq(sdfccd_query_mesh(floor, NULL, torus, &m, 0.0, 1.0 / 60.0, &p, all, ALL, &ra), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_query_mesh(floor, NULL, torus, &m, 0.0, 1.0 / 60.0, &p, few, 16, &rf), SDFCCD_OK);
    ck_assert_int_eq(ra.state, SDFCCD_STATE_HIT);
    ck_assert_int_lt(ra.contacts_found, ALL);
    ck_assert_int_eq(ra.contact_count, ra.contacts_found);
    ck_assert_int_gt(ra.contacts_found, 64); /* the case this tests */
    ck_assert(rf.toi == ra.toi && rf.hit == ra.hit && rf.contacts_found == ra.contacts_found);
    ck_assert_int_eq(rf.contact_count, 16);
    /* first the deepest contact at the earliest time */
    int deepest = 0;
    for (int i = 1; i < ra.contact_count && all[i].toi == all[0].toi; ++i)
        if (all[i].distance < all[deepest].distance) deepest = i;
    ck_assert(memcmp(&few[0], &all[deepest], sizeof few[0]) == 0);
    for (int i = 1; i < 16; ++i) ck_assert(few[i].toi >= few[i - 1].toi);
    double full = contacts_hull_area(all, ra.contact_count), kept = contacts_hull_area(few, 16),
           prefix = contacts_hull_area(all, 16);
    REPORT("torus on a floor: %d contacts found; hull area of 16 kept %.5f, of all %.5f, of the first 16 %.5f; widest angle "
           "between kept points %.1f deg, between the first 16 %.1f deg\n",
           ra.contacts_found, kept, full, prefix, widest_gap_deg(few, 16), widest_gap_deg(all, 16));
    /* around the ring: no gap wider than two sixteenths of a turn */
    ck_assert(widest_gap_deg(few, 16) <= 45.0);
    /* 16 points spread over a ring of radius 0.1: a 16-gon covers 97 % of the circle */
    ck_assert(kept >= 0.9 * full);
    free(all);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(torus), SDFCCD_OK);
}
END_TEST

/* ---------------- contact generation ---------------- */

static const double DT = 1.0 / 60.0;
static const double H = 0.05; /* half extent of the test cube */


static sdfccd_SdfId make_floor(void)
{
    sdfccd_SdfId floor;
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &floor), SDFCCD_OK);
    return floor;
}

static sdfccd_ContactSet generate(sdfccd_Workspace* ws, sdfccd_SdfId sdf, sdfccd_MeshId mesh, const sdfccd_RigidMotion* m,
                                  sdfccd_ContactPoint* out, int32_t cap)
{
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    sdfccd_ContactSet set;
    ck_assert_msg(sdfccd_generate_contacts(ws, sdf, NULL, mesh, m, 0.0, DT, &p, out, cap, &set) == SDFCCD_OK, "%s", sdfccd_last_error());
    ck_assert(set.count >= 0 && set.count <= cap && set.count <= set.candidates);
    return set;
}

/* Every point is a bottom corner of the cube (|x| = |y| = H, z = z0 at t0), a vertex, with normal +z
 * and gap z0; the corners are all there. */
static void assert_bottom_corners(const sdfccd_ContactPoint* c, int32_t n, sdfccd_Vec3 centre, double z0)
{
    ck_assert_int_eq(n, 4);
    int seen = 0;
    for (int32_t i = 0; i < n; ++i) {
        ck_assert_double_near(fabs(c[i].point.x - centre.x), H, 1e-12);
        ck_assert_double_near(fabs(c[i].point.y - centre.y), H, 1e-12);
        ck_assert_double_near(c[i].point.z, z0, 1e-12);
        ck_assert_double_near(c[i].gap, z0, 1e-9);
        ck_assert_double_near(c[i].normal.z, 1.0, 1e-12);
        ck_assert_double_near(c[i].surface_point.z, 0.0, 1e-9);
        ck_assert_int_eq(c[i].feature_kind, SDFCCD_FEATURE_VERTEX);
        ck_assert(c[i].id == c[i].feature);
        seen |= 1 << ((c[i].point.x > centre.x) + 2 * (c[i].point.y > centre.y));
    }
    ck_assert_int_eq(seen, 15);
}

/* First in the suite: sdfccd_set_allocator needs no library memory live. */
START_TEST(test_generate_no_allocation_after_warm_up)
{
    long allocs = 0;
    ck_assert_int_eq(sdfccd_set_allocator(test_counting_alloc, test_counting_free, &allocs), SDFCCD_OK);
    {
        sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 4, 4, 4);
        sdfccd_SdfId floor = make_floor();
        sdfccd_Workspace* ws;
        ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
        sdfccd_RigidMotion m[3] = { sdfccd_default_rigid_motion(), sdfccd_default_rigid_motion(), sdfccd_default_rigid_motion() };
        m[0].pose.position.z = H;          /* resting */
        m[1].pose.position.z = H + 0.05;   /* falling onto the floor */
        m[1].linear_velocity.z = -10;
        m[2].pose.position.z = 1.0;        /* nothing within reach */
        sdfccd_ContactPoint c[8];
        for (int k = 0; k < 3; ++k) (void)generate(ws, floor, cube, &m[k], c, 8);
        long before = allocs;
        for (int i = 0; i < 10; ++i)
            for (int k = 0; k < 3; ++k) ck_assert_int_eq(generate(ws, floor, cube, &m[k], c, 8).count, k == 2 ? 0 : 8);
        ck_assert_int_eq(allocs - before, 0);
        /* the batch, one workspace per thread, each warmed up with every pair */
        sdfccd_Workspace* ws2[2] = { ws, NULL };
        ck_assert_int_eq(sdfccd_create_workspace(&ws2[1]), SDFCCD_OK);
        sdfccd_ContactParams bp = sdfccd_default_contact_params();
        sdfccd_ContactPoint bc[3][8];
        sdfccd_ContactSet bs[3];
        sdfccd_ContactPair pairs[3];
        for (int k = 0; k < 3; ++k) (void)generate(ws2[1], floor, cube, &m[k], c, 8); /* either thread may take any pair */
        for (int round = 0; round < 8; ++round) {
            if (round == 1) before = allocs;
            for (int k = 0; k < 3; ++k) pairs[k] = (sdfccd_ContactPair){ floor, NULL, cube, &m[k], 0.0, DT, &bp, bc[k], 8, &bs[k], SDFCCD_OK };
            ck_assert_int_eq(sdfccd_generate_contacts_batch(ws2, 2, pairs, 3), SDFCCD_OK);
        }
        ck_assert_int_eq(allocs - before, 0);
        sdfccd_destroy_workspace(ws2[1]);
        before = allocs;
        /* the face search: a slab on the floor, after a first call */
        sdfccd_MeshId slab = test_box_mesh((sdfccd_Vec3){ 0.2, 0.2, 0.05 }, 1, 1, 1);
        sdfccd_Pose pose = sdfccd_pose_identity();
        pose.position.z = 0.049;
        sdfccd_QueryParams qp = sdfccd_default_query_params();
        static sdfccd_ContactPoint fc[1024];
        sdfccd_FaceSearch fs;
        ck_assert_int_eq(sdfccd_search_faces(ws, floor, NULL, slab, &pose, 0.1, 0.0, &qp, fc, 1024, &fs), SDFCCD_OK);
        ck_assert_int_gt(fs.count, 0);
        before = allocs;
        for (int i = 0; i < 5; ++i) ck_assert_int_eq(sdfccd_search_faces(ws, floor, NULL, slab, &pose, 0.1, 0.0, &qp, fc, 1024, &fs), SDFCCD_OK);
        ck_assert_int_eq(allocs - before, 0);
        ck_assert_int_eq(sdfccd_destroy_mesh(slab), SDFCCD_OK);
        /* the reductions are pure functions: no allocation at all */
        int32_t idx[8], count = 0;
        for (int i = 0; i < 10; ++i) {
            ck_assert_int_eq(sdfccd_reduce_contacts_weighted(c, 8, SAME, 0.01, idx, 4, &count), SDFCCD_OK);
            ck_assert_int_eq(sdfccd_reduce_contacts(c, 8, SAME, idx, 4, &count), SDFCCD_OK);
        }
        ck_assert_int_eq(allocs - before, 0);
        sdfccd_destroy_workspace(ws);
        ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
    }
    ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_OK);
}
END_TEST

START_TEST(test_generate_resting_box)
{
    sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 4, 4, 4);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = (sdfccd_Vec3){ 0.3, -0.2, H };
    sdfccd_ContactPoint c[4];
    sdfccd_ContactSet set = generate(ws, floor, cube, &m, c, 4);
    ck_assert_int_eq(set.started_in_contact, 1);
    ck_assert_int_eq(set.ccd_ran, 0);
    ck_assert(set.toi == 0.0);
    ck_assert_int_gt(set.candidates, 4); /* the bottom face's 25 vertices and its triangles: reduced, not cut */
    assert_bottom_corners(c, set.count, m.pose.position, 0.0);
    for (int i = 0; i < 4; ++i) ck_assert(c[i].toi == 0.0);
    /* ids persist: a step later, slid by 1 cm, the same four features */
    uint64_t ids[4];
    for (int i = 0; i < 4; ++i) ids[i] = c[i].id;
    m.pose.position.x += 0.01;
    set = generate(ws, floor, cube, &m, c, 4);
    assert_bottom_corners(c, set.count, m.pose.position, 0.0);
    for (int i = 0; i < 4; ++i) ck_assert(c[i].id == ids[i]);
    /* a coarse cube (two triangles a face) without subdivision: one deepest point per triangle, so the
     * corners come from the triangles' vertices within reach */
    sdfccd_MeshId coarse = test_box_mesh((sdfccd_Vec3){ H, H, H }, 1, 1, 1);
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    p.query.subdivision = 0;
    ck_assert_int_eq(sdfccd_generate_contacts(ws, floor, NULL, coarse, &m, 0.0, DT, &p, c, 4, &set), SDFCCD_OK);
    assert_bottom_corners(c, set.count, m.pose.position, 0.0);
    ck_assert_int_eq(sdfccd_destroy_mesh(coarse), SDFCCD_OK);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
}
END_TEST

/* A box resting on the floor, tilted by +-1e-5 rad about y from step to step (the rounding of a
 * resting body): without the previous points the first point swaps sides; with them (the bridge
 * passes its last step's), the same four points in the same order. */
START_TEST(test_generate_kept_ids)
{
    sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 4, 4, 4);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_ContactPoint c[4];
    sdfccd_ContactSet set;
    uint64_t ids[2][4], kept[4];
    for (int with = 0; with <= 1; ++with)
        for (int step = 0; step < 4; ++step) {
            const double a = (step % 2 ? 1e-5 : -1e-5) / 2;
            sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
            m.pose.position = (sdfccd_Vec3){ 0.3, -0.2, H - 1e-6 };
            m.pose.orientation = (sdfccd_Quat){ 0.0, sin(a), 0.0, cos(a) };
            sdfccd_ContactParams p = sdfccd_default_contact_params();
            p.previous.ids = with && step > 0 ? kept : NULL;
            p.previous.count = with && step > 0 ? 4 : 0;
            ck_assert_msg(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0.0, DT, &p, c, 4, &set) == SDFCCD_OK, "%s",
                          sdfccd_last_error());
            ck_assert_int_eq(set.count, 4);
            for (int i = 0; i < 4; ++i) { /* the bottom corners (tilted by 5e-6 rad: within 1e-6 m) */
                ck_assert(fabs(fabs(c[i].point.x - m.pose.position.x) - H) < 1e-6 && fabs(fabs(c[i].point.y - m.pose.position.y) - H) < 1e-6);
                ck_assert(fabs(c[i].gap) < 2e-6);
            }
            for (int i = 0; i < 4; ++i) {
                if (step < 2) ids[step][i] = c[i].id;
                else ck_assert(c[i].id == ids[step % 2][i]); /* deterministic */
                kept[i] = c[i].id;
            }
        }
    /* without: the first point's side (x of the corner) follows the tilt; with: steps 1 and 0 agree */
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = (sdfccd_Vec3){ 0.3, -0.2, H - 1e-6 };
    double side[2];
    for (int step = 0; step < 2; ++step) {
        const double a = (step % 2 ? 1e-5 : -1e-5) / 2;
        m.pose.orientation = (sdfccd_Quat){ 0.0, sin(a), 0.0, cos(a) };
        ck_assert_int_eq(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0.0, DT, &p, c, 4, &set), SDFCCD_OK);
        side[step] = c[0].point.x - m.pose.position.x;
    }
    ck_assert(side[0] * side[1] < 0.0);
    for (int i = 0; i < 4; ++i) ck_assert(ids[0][i] == ids[1][i]);
    /* bad previous points are refused */
    p.previous.count = 2;
    p.previous.ids = NULL;
    ck_assert_int_eq(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0.0, DT, &p, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strstr(sdfccd_last_error(), "previous") != NULL);
    p.previous.ids = kept;
    p.previous.share = 2.0;
    ck_assert_int_eq(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0.0, DT, &p, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
}
END_TEST

START_TEST(test_generate_falling_box)
{
    /* 5 cm above the floor at 10 m/s: the CCD's TOI is 5 ms, each corner's gap at t0 is 5 cm */
    sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 4, 4, 4);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.z = H + 0.05;
    m.linear_velocity.z = -10;
    sdfccd_ContactPoint c[4];
    sdfccd_ContactSet set = generate(ws, floor, cube, &m, c, 4);
    ck_assert_int_eq(set.started_in_contact, 0);
    ck_assert_int_eq(set.ccd_ran, 1);
    ck_assert_int_eq(set.ccd_state, SDFCCD_STATE_HIT);
    ck_assert_double_near(set.toi, 0.005, 1e-7);
    assert_bottom_corners(c, set.count, m.pose.position, 0.05);
    /* nothing within the step's reach: no point, no CCD */
    m.pose.position.z = 1.0;
    set = generate(ws, floor, cube, &m, c, 4);
    ck_assert_int_eq(set.count, 0);
    ck_assert_int_eq(set.candidates, 0);
    ck_assert_int_eq(set.ccd_ran, 0);
    ck_assert(set.toi == DT);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
}
END_TEST

START_TEST(test_generate_fast_plate_thin_wall)
{
    /* a 4 mm plate tilted 45 deg at 500 m/s towards a 1 cm wall (x in [0, 0.01]): its leading edge is
     * 0.1 - 0.052 / sqrt(2) from the wall at t0 and reaches it at that over 500 */
    sdfccd_MeshId plate = test_box_mesh((sdfccd_Vec3){ 0.05, 0.002, 0.05 }, 4, 1, 4);
    sdfccd_SdfId box, wall;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.005, 1, 1 }, &box), SDFCCD_OK);
    sdfccd_Pose at = sdfccd_pose_identity();
    at.position.x = 0.005;
    ck_assert_int_eq(sdfccd_create_transformed(box, at, 1.0, &wall), SDFCCD_OK);
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.x = -0.1;
    m.pose.orientation = (sdfccd_Quat){ cos(M_PI / 8), 0, 0, sin(M_PI / 8) };
    m.linear_velocity.x = 500;
    sdfccd_ContactPoint c[4];
    sdfccd_ContactSet set = generate(ws, wall, plate, &m, c, 4);
    const double lead = 0.1 - 0.052 / sqrt(2.0);
    ck_assert_int_eq(set.ccd_ran, 1);
    ck_assert_int_eq(set.ccd_state, SDFCCD_STATE_HIT);
    ck_assert_double_near(set.toi, lead / 500.0, 1e-9);
    ck_assert_int_ge(set.count, 2); /* the leading edge: both its ends */
    ck_assert_double_near(c[0].gap, lead, 1e-9);
    for (int i = 0; i < set.count; ++i) {
        ck_assert_double_near(c[i].normal.x, -1.0, 1e-9);
        ck_assert(c[i].gap >= lead - 1e-9);
    }
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(wall), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(box), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(plate), SDFCCD_OK);
}
END_TEST

/* A 20 cm cloth (5 x 5 vertices) dropping linearly from z = 2 cm to z = -3 cm onto the floor. */
START_TEST(test_generate_linear_cloth)
{
    double v[75];
    uint32_t f[96];
    sdfccd_Vec3 start[25], end[25];
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) {
            int k = 5 * i + j;
            v[3 * k] = -0.1 + 0.05 * i;
            v[3 * k + 1] = -0.1 + 0.05 * j;
            v[3 * k + 2] = 0.0;
            start[k] = (sdfccd_Vec3){ v[3 * k], v[3 * k + 1], 0.02 };
            end[k] = (sdfccd_Vec3){ v[3 * k], v[3 * k + 1], -0.03 };
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
    d.vertex_count = 25;
    d.indices = f;
    d.triangle_count = 32;
    sdfccd_MeshId cloth;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &cloth), SDFCCD_OK);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    sdfccd_ContactPoint c[4];
    sdfccd_ContactSet set;
    ck_assert_int_eq(sdfccd_generate_contacts_linear(ws, floor, NULL, cloth, start, end, 0.0, DT, &p, c, 4, &set), SDFCCD_OK);
    ck_assert_int_eq(set.ccd_state, SDFCCD_STATE_HIT);
    ck_assert_double_near(set.toi, 0.4 * DT, 1e-7);
    ck_assert_int_eq(set.count, 4);
    uint32_t corners = 0;
    for (int i = 0; i < 4; ++i) {
        ck_assert_double_near(c[i].gap, 0.02, 1e-9);
        ck_assert_double_near(c[i].normal.z, 1.0, 1e-12);
        ck_assert_int_eq(c[i].feature_kind, SDFCCD_FEATURE_VERTEX);
        ck_assert(c[i].id == 0 || c[i].id == 4 || c[i].id == 20 || c[i].id == 24);
        corners |= 1u << (c[i].id % 5 == 0 ? c[i].id / 20 : 2 + c[i].id / 20);
    }
    ck_assert_int_eq(corners, 15);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cloth), SDFCCD_OK);
}
END_TEST

/* ---- the face search (sdfccd_search_faces) ---- */

static double dot3(sdfccd_Vec3 a, sdfccd_Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/* A 2 m x 2 m slab 0.1 m thick (12 triangles; its bottom face at z = bottom), searched with regions
 * of 0.1 m; returns the points (at most cap). */
static sdfccd_FaceSearch search(sdfccd_Workspace* ws, sdfccd_SdfId sdf, sdfccd_MeshId slab, double bottom, double size, double accept,
                                sdfccd_ContactPoint* out, int32_t cap)
{
    sdfccd_Pose pose = sdfccd_pose_identity();
    pose.position.z = bottom + 0.05;
    sdfccd_QueryParams qp = sdfccd_default_query_params();
    sdfccd_FaceSearch fs;
    ck_assert_msg(sdfccd_search_faces(ws, sdf, NULL, slab, &pose, size, accept, &qp, out, cap, &fs) == SDFCCD_OK, "%s", sdfccd_last_error());
    ck_assert(fs.count == 0 || fs.count == fs.found);
    ck_assert(fs.found <= cap ? fs.count == fs.found : fs.count == 0);
    return fs;
}

/* A sphere of radius 5 cm, the slab and a workspace (the face search tests' set-up). */
static void faces_setup(sdfccd_SdfId* ball, sdfccd_MeshId* slab, sdfccd_Workspace** ws)
{
    ck_assert_int_eq(sdfccd_create_sphere(0.05, ball), SDFCCD_OK);
    *slab = test_box_mesh((sdfccd_Vec3){ 1, 1, 0.05 }, 1, 1, 1);
    ck_assert_int_eq(sdfccd_create_workspace(ws), SDFCCD_OK);
}

START_TEST(test_faces_sphere_cap)
{
    /* the slab's bottom face 1 cm into a sphere of radius 5 cm (far smaller than the face): the
     * deepest point is above the centre, phi -0.01, held at the top of the sphere with normal +z;
     * every point lies on the bottom face, inside the cap (radius 3 cm) */
    sdfccd_SdfId ball;
    sdfccd_MeshId slab;
    sdfccd_Workspace* ws;
    faces_setup(&ball, &slab, &ws);
    static sdfccd_ContactPoint c[256];
    sdfccd_FaceSearch fs = search(ws, ball, slab, 0.04, 0.1, 0.0, c, 256);
    ck_assert_int_gt(fs.count, 0);
    int deepest = 0;
    for (int32_t i = 0; i < fs.count; ++i) {
        ck_assert_double_near(c[i].point.z, 0.04, 1e-12);
        ck_assert(hypot(c[i].point.x, c[i].point.y) <= 0.03 + 1e-9);
        ck_assert(c[i].gap <= 1e-9);
        ck_assert(c[i].feature_kind != SDFCCD_FEATURE_VERTEX); /* inside a face or on its diagonal */
        if (c[i].gap < c[deepest].gap) deepest = i;
    }
    ck_assert_double_near(c[deepest].gap, -0.01, 1e-6);
    ck_assert_double_near(c[deepest].surface_point.z, 0.05, 1e-6);
    ck_assert_double_near(c[deepest].normal.z, 1.0, 1e-6);
    REPORT("sphere cap: %d points, %lld regions, %lld evaluations\n", fs.count, (long long)fs.regions, (long long)fs.sdf_evaluations);
    /* all or nothing: one point less room gives none, and the same search again the same points */
    static sdfccd_ContactPoint c2[256];
    sdfccd_FaceSearch f2 = search(ws, ball, slab, 0.04, 0.1, 0.0, c2, fs.found - 1);
    ck_assert_int_eq(f2.count, 0);
    ck_assert_int_eq(f2.found, fs.found);
    f2 = search(ws, ball, slab, 0.04, 0.1, 0.0, c2, fs.found);
    ck_assert_int_eq(f2.count, fs.count);
    for (int32_t i = 0; i < fs.count; ++i) ck_assert(c2[i].id == c[i].id && c2[i].gap == c[i].gap);
    /* faces with no edge longer than the region size are left to the mesh queries */
    ck_assert_int_eq(search(ws, ball, slab, 0.04, 3.0, 0.0, c, 256).regions, 0);
    /* far above: every face (all 12 have an edge over 0.1 m) dropped at its first region */
    f2 = search(ws, ball, slab, 5.0, 0.1, 0.0, c, 256);
    ck_assert_int_eq(f2.found, 0);
    ck_assert_int_eq(f2.regions, 12);
    sdfccd_destroy_workspace(ws);
    sdfccd_destroy_mesh(slab);
    sdfccd_destroy_sdf(ball);
}
END_TEST

START_TEST(test_faces_ridge)
{
    /* a box turned 45 degrees about x: a ridge along x (|x| <= 0.5) at z = 0.1 sqrt 2. The slab's bottom
     * face lies 1 cm below the ridge; inside the box the field's normal points out of its sides (45
     * degrees from +z), so each point is pushed up along the face's normal to the ridge's surface:
     * normal +z, surface z = ridge - |y| (the box's side), gap = point z - surface z = |y| - 0.01
     * (not the field's (|y| - 0.01) / sqrt 2 along its 45-degree normal) */
    sdfccd_SdfId bar, ridge;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.5, 0.1, 0.1 }, &bar), SDFCCD_OK);
    sdfccd_Pose turn = sdfccd_pose_identity();
    turn.orientation = (sdfccd_Quat){ cos(M_PI / 8), sin(M_PI / 8), 0, 0 };
    ck_assert_int_eq(sdfccd_create_transformed(bar, turn, 1.0, &ridge), SDFCCD_OK);
    const double top = 0.1 * sqrt(2.0);
    sdfccd_MeshId slab = test_box_mesh((sdfccd_Vec3){ 1, 1, 0.05 }, 1, 1, 1);
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    static sdfccd_ContactPoint c[512];
    sdfccd_FaceSearch fs = search(ws, ridge, slab, top - 0.01, 0.1, 0.0, c, 512);
    ck_assert_int_gt(fs.count, 0);
    double deepest = 0.0;
    for (int32_t i = 0; i < fs.count; ++i) {
        REPORT("ridge point %d: (%.5f %.5f %.5f) gap %.6f n (%.3f %.3f %.3f)\n", i, c[i].point.x, c[i].point.y, c[i].point.z, c[i].gap,
               c[i].normal.x, c[i].normal.y, c[i].normal.z);
        ck_assert_double_near(c[i].point.z, top - 0.01, 1e-12);
        ck_assert(c[i].gap <= 1e-9);
        ck_assert_double_near(c[i].gap, dot3(c[i].normal, c[i].point) - dot3(c[i].normal, c[i].surface_point), 1e-12);
        if (c[i].gap > -1e-9) continue; /* on the surface (the ridge's end face): held where it is */
        ck_assert_double_near(c[i].normal.z, 1.0, 1e-12);
        ck_assert_double_near(c[i].surface_point.z, top - fabs(c[i].point.y), 2e-6);
        ck_assert_double_near(c[i].gap, c[i].point.z - c[i].surface_point.z, 1e-12);
        deepest = fmin(deepest, c[i].gap);
    }
    ck_assert(deepest < -0.005); /* a point inside was found and pushed up */
    REPORT("ridge: %d points, deepest %.6f\n", fs.count, deepest);
    sdfccd_destroy_workspace(ws);
    sdfccd_destroy_mesh(slab);
    sdfccd_destroy_sdf(ridge);
    sdfccd_destroy_sdf(bar);
}
END_TEST

START_TEST(test_faces_bad_input)
{
    sdfccd_SdfId ball;
    sdfccd_MeshId slab;
    sdfccd_Workspace* ws;
    faces_setup(&ball, &slab, &ws);
    sdfccd_Pose pose = sdfccd_pose_identity();
    sdfccd_QueryParams qp = sdfccd_default_query_params();
    sdfccd_ContactPoint c[4];
    sdfccd_FaceSearch fs = { -7, -7, -7, -7 };
    ck_assert_int_eq(sdfccd_search_faces(NULL, ball, NULL, slab, &pose, 0.1, 0.0, &qp, c, 4, &fs), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_search_faces(ws, ball, NULL, slab, NULL, 0.1, 0.0, &qp, c, 4, &fs), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_search_faces(ws, ball, NULL, slab, &pose, 0.0, 0.0, &qp, c, 4, &fs), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_search_faces(ws, ball, NULL, slab, &pose, NAN, 0.0, &qp, c, 4, &fs), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_search_faces(ws, ball, NULL, slab, &pose, 0.1, INFINITY, &qp, c, 4, &fs), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_search_faces(ws, ball, NULL, slab, &pose, 0.1, 0.0, NULL, c, 4, &fs), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_search_faces(ws, ball, NULL, slab, &pose, 0.1, 0.0, &qp, NULL, 4, &fs), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_search_faces(ws, ball, NULL, slab, &pose, 0.1, 0.0, &qp, c, -1, &fs), SDFCCD_INVALID_ARGUMENT);
    pose.position.x = NAN;
    ck_assert_int_eq(sdfccd_search_faces(ws, ball, NULL, slab, &pose, 0.1, 0.0, &qp, c, 4, &fs), SDFCCD_INVALID_ARGUMENT);
    pose.position.x = 0;
    ck_assert_int_eq(sdfccd_search_faces(ws, (sdfccd_SdfId){ 0, 0 }, NULL, slab, &pose, 0.1, 0.0, &qp, c, 4, &fs), SDFCCD_INVALID_HANDLE);
    ck_assert(strstr(sdfccd_last_error(), "sdfccd_search_faces") != NULL || strlen(sdfccd_last_error()) > 0);
    ck_assert_int_eq(fs.count, -7); /* not written on error */
    sdfccd_destroy_workspace(ws);
    sdfccd_destroy_mesh(slab);
    sdfccd_destroy_sdf(ball);
}
END_TEST

/* ---- the one generator's rules (the Bullet bridge's sequence) on sets known in closed form ---- */

static sdfccd_ContactSet generate_p(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sm, sdfccd_MeshId mesh,
                                    const sdfccd_RigidMotion* m, const sdfccd_ContactParams* p, sdfccd_ContactPoint* out, int32_t cap)
{
    sdfccd_ContactSet set;
    ck_assert_msg(sdfccd_generate_contacts(ws, sdf, sm, mesh, m, 0.0, DT, p, out, cap, &set) == SDFCCD_OK, "%s", sdfccd_last_error());
    ck_assert(set.count >= 0 && set.count <= cap && set.reduced <= set.count && set.count <= set.candidates);
    ck_assert(set.own_evaluations >= 0 && set.own_evaluations <= set.sdf_evaluations);
    return set;
}

/* A coarse cube (2 triangles a face, each face with its own 4 vertices, no subdivision) 5 mm above
 * the floor at rest, margin 1 cm: the start-pose query holds the 10 triangles with a point at the
 * bottom (bottom and sides, each at gap 5 mm), so the step starts in contact and the CCD is skipped;
 * the end-pose query (the same pose) holds them again. Each gives 10 points and, of their faces' 20
 * vertices, the 12 at the bottom (the others are 10.5 cm away): 2 x 22 = 44 candidates and
 * 2 x (10 + 20) = 60 closest-point evaluations of our own (the step is at rest, so both poses are
 * the start: a vertex's test and its closest point come from one evaluation; 84 when evaluated twice). */
START_TEST(test_generate_rules_resting_closed_form)
{
    sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 1, 1, 1);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    p.query.subdivision = 0;
    p.query.margin = 0.01;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = (sdfccd_Vec3){ 0.2, 0.1, H + 0.005 };
    sdfccd_ContactPoint c[64], few[4];
    memset(c, 0, sizeof c); /* padding too: compared byte for byte */
    memset(few, 0, sizeof few);
    sdfccd_ContactSet set = generate_p(ws, floor, NULL, cube, &m, &p, c, 64);
    ck_assert_int_eq(set.started_in_contact, 1);
    ck_assert_int_eq(set.ccd_ran, 0);
    ck_assert_int_eq(set.discrete_queries, 2);
    ck_assert_int_eq(set.candidates, 44);
    ck_assert_int_eq(set.own_evaluations, 60);
    for (int i = 0; i < set.count; ++i) {
        ck_assert_double_near(c[i].gap, 0.005, 1e-9);
        ck_assert_double_near(c[i].point.z, 0.005, 1e-9);
        ck_assert_double_near(c[i].surface_point.z, 0.0, 1e-9);
        ck_assert(c[i].toi == 0.0);
    }
    /* buffer smaller than the set: the reduction, the same choice in the same order, never a prefix of the candidates */
    for (int32_t cap = 1; cap <= 4; ++cap) {
        sdfccd_ContactSet s2 = generate_p(ws, floor, NULL, cube, &m, &p, few, cap);
        ck_assert_int_eq(s2.count, cap);
        ck_assert_int_eq(s2.candidates, 44);
        for (int32_t i = 0; i < cap; ++i) ck_assert(memcmp(&few[i], &c[i], sizeof few[i]) == 0);
    }
    assert_bottom_corners(few, 4, m.pose.position, 0.005);
    /* end_skip_travel: the step's travel (0) is within it, so no end-pose query: the start pose's 22
     * candidates and (10 + 20) evaluations, and the same 4 points (the end pose's were the same) */
    sdfccd_ContactParams ps = p;
    ps.end_skip_travel = 0.0005;
    sdfccd_ContactSet s4 = generate_p(ws, floor, NULL, cube, &m, &ps, few, 4);
    ck_assert_int_eq(s4.discrete_queries, 1);
    ck_assert_int_eq(s4.candidates, 22);
    ck_assert_int_eq(s4.own_evaluations, 30);
    ck_assert_int_eq(s4.count, 4);
    for (int32_t i = 0; i < 4; ++i) ck_assert(memcmp(&few[i], &c[i], sizeof few[i]) == 0);
    /* the same with the floor given as a motion at rest (moved and turned): the same points moved */
    sdfccd_RigidMotion sm = sdfccd_default_rigid_motion();
    sm.pose.position = (sdfccd_Vec3){ 1, 2, 3 };
    sm.pose.orientation = (sdfccd_Quat){ cos(0.3), sin(0.3), 0, 0 }; /* 0.6 rad about x */
    sdfccd_RigidMotion mw = m; /* the cube carried along with the floor's frame */
    const double cs = cos(0.6), sn = sin(0.6);
    sdfccd_Vec3 q = m.pose.position;
    mw.pose.position = (sdfccd_Vec3){ 1 + q.x, 2 + cs * q.y - sn * q.z, 3 + sn * q.y + cs * q.z };
    mw.pose.orientation = sm.pose.orientation;
    sdfccd_ContactSet s3 = generate_p(ws, floor, &sm, cube, &mw, &p, few, 4);
    ck_assert_int_eq(s3.candidates, 44);
    ck_assert_int_eq(s3.count, 4);
    for (int i = 0; i < 4; ++i) {
        sdfccd_Vec3 a = c[i].point, b = few[i].point;
        ck_assert_double_near(b.x, 1 + a.x, 1e-9);
        ck_assert_double_near(b.y, 2 + cs * a.y - sn * a.z, 1e-9);
        ck_assert_double_near(b.z, 3 + sn * a.y + cs * a.z, 1e-9);
        ck_assert_double_near(few[i].gap, 0.005, 1e-9);
        ck_assert(few[i].id == c[i].id);
    }
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
}
END_TEST

/* The coarse cube 5 cm above the floor at 10 m/s (margin 0, no subdivision; reach 10/60 m): every
 * triangle is within reach at t0 and none touches, so the CCD runs: its first time of impact is 5 ms
 * (5 cm / 10 m/s), with the bottom and side triangles (10 points) and, of their 20 vertices, the 12
 * at the bottom; then the start pose's 12 triangles and 24 vertices (all within 5 cm + reach), and
 * the end pose's 12 triangles and 24 vertices (all below the floor): 22 + 36 + 36 = 94 candidates;
 * own evaluations 20 (the vertices at the TOI) + (12 + 24) at the start pose (a vertex's test and
 * its closest point from one evaluation) + (12 + 24 + 24) at the end pose = 116. */
START_TEST(test_generate_rules_falling_closed_form)
{
    sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 1, 1, 1);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    p.query.subdivision = 0;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.z = H + 0.05;
    m.linear_velocity.z = -10;
    sdfccd_ContactPoint c[4];
    sdfccd_ContactSet set = generate_p(ws, floor, NULL, cube, &m, &p, c, 4);
    ck_assert_int_eq(set.started_in_contact, 0);
    ck_assert_int_eq(set.ccd_ran, 1);
    ck_assert_int_eq(set.ccd_state, SDFCCD_STATE_HIT);
    ck_assert_double_near(set.toi, 0.005, 1e-7);
    ck_assert_int_eq(set.discrete_queries, 2);
    ck_assert_int_eq(set.candidates, 94);
    ck_assert_int_eq(set.own_evaluations, 116);
    assert_bottom_corners(c, set.count, m.pose.position, 0.05);
    /* a travel of 10/60 m is beyond end_skip_travel: the end pose is still queried, the same set */
    p.end_skip_travel = 0.0005;
    sdfccd_ContactSet s2 = generate_p(ws, floor, NULL, cube, &m, &p, c, 4);
    ck_assert_int_eq(s2.discrete_queries, 2);
    ck_assert_int_eq(s2.candidates, 94);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
}
END_TEST

/* The cull: out of reach, the start-pose query's broad phase proves the step clear and nothing else
 * runs: the call costs exactly that one discrete query (the same evaluations as sdfccd_query_mesh
 * with DCD at t0 and the margin widened by the reach). */
START_TEST(test_generate_rules_cull)
{
    sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 4, 4, 4);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    p.query.margin = 0.01;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.z = 0.5;
    m.linear_velocity.z = -6; /* reach 0.1 m */
    sdfccd_ContactPoint c[4];
    sdfccd_ContactSet set = generate_p(ws, floor, NULL, cube, &m, &p, c, 4);
    ck_assert_int_eq(set.count, 0);
    ck_assert_int_eq(set.candidates, 0);
    ck_assert_int_eq(set.ccd_ran, 0);
    ck_assert_int_eq(set.discrete_queries, 1);
    ck_assert_int_eq(set.own_evaluations, 0);
    ck_assert(set.toi == DT);
    sdfccd_QueryParams dcd = p.query;
    dcd.method = SDFCCD_METHOD_DCD;
    dcd.margin = 0.01 + 6 * DT;
    dcd.subdivision_min_area = fmax(dcd.subdivision_min_area, pow(0.1 * H * sqrt(3.0), 2));
    sdfccd_RigidMotion at = m;
    at.linear_velocity.z = 0;
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_mesh(floor, NULL, cube, &at, 0.0, 0.0, &dcd, NULL, 0, &r), SDFCCD_OK);
    ck_assert_int_eq(r.triangles_tested, 0);
    ck_assert_int_eq(set.sdf_evaluations, r.sdf_evaluations);
    /* spinning about z at 6 rad/s, 1.5 cm up: within the reach the spin gives (margin + 6 R dt,
     * R = H sqrt 3) but never closer than 1.5 cm: the CCD runs and misses */
    m.pose.position.z = H + 0.015;
    m.linear_velocity.z = 0;
    m.angular_velocity.z = 6;
    set = generate_p(ws, floor, NULL, cube, &m, &p, c, 4);
    ck_assert_int_eq(set.ccd_ran, 1);
    ck_assert_int_eq(set.ccd_state, SDFCCD_STATE_NO_HIT);
    ck_assert_int_eq(set.candidates, 0);
    ck_assert_int_eq(set.own_evaluations, 0); /* no hit: the start pose's points are not even held */
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
}
END_TEST

/* Cover points: a fine cube at rest gives none (no turn); spinning about x at 30 rad/s on the floor
 * it gets points beyond the reduction's 4, none of them one of the 4, the same as
 * sdfccd_cover_contacts would pick from the 4 (checked: every cover point is deeper than the
 * reduction lets it stay by more than the depth). */
START_TEST(test_generate_rules_cover)
{
    sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 4, 4, 4);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    p.query.margin = 0.01;
    p.reduced_count = 4;
    p.cover_depth = 0.0005;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.z = H;
    sdfccd_ContactPoint c[16];
    sdfccd_ContactSet set = generate_p(ws, floor, NULL, cube, &m, &p, c, 16);
    ck_assert_int_eq(set.reduced, 4);
    ck_assert_int_eq(set.count, 4);
    m.angular_velocity.x = 30;
    set = generate_p(ws, floor, NULL, cube, &m, &p, c, 16);
    ck_assert_int_eq(set.reduced, 4);
    ck_assert_int_gt(set.count, 4);
    for (int i = 4; i < set.count; ++i)
        for (int j = 0; j < i; ++j) ck_assert(c[i].id != c[j].id || c[i].toi != c[j].toi || c[i].gap != c[j].gap);
    /* p.cover_depth 0: the reduction only, to the whole capacity */
    p.cover_depth = 0;
    p.reduced_count = 0;
    set = generate_p(ws, floor, NULL, cube, &m, &p, c, 16);
    ck_assert_int_eq(set.reduced, set.count);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
}
END_TEST

/* The face search runs only with a feature size (and subdivision): a coarse 40 cm plate resting on
 * the floor gets its regions' points too. */
START_TEST(test_generate_rules_face_search)
{
    sdfccd_MeshId plate = test_box_mesh((sdfccd_Vec3){ 0.2, 0.2, 0.01 }, 1, 1, 1);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    p.query.margin = 0.01;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.z = 0.01;
    sdfccd_ContactPoint c[4];
    sdfccd_ContactSet off = generate_p(ws, floor, NULL, plate, &m, &p, c, 4);
    ck_assert_int_eq(off.face_regions, 0);
    p.feature_size = 0.1;
    sdfccd_ContactSet on = generate_p(ws, floor, NULL, plate, &m, &p, c, 4);
    ck_assert_int_gt(on.face_regions, 0);
    ck_assert_int_gt(on.candidates, off.candidates);
    p.query.subdivision = 0; /* part of the subdivision: off with it */
    ck_assert_int_eq(generate_p(ws, floor, NULL, plate, &m, &p, c, 4).face_regions, 0);
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(plate), SDFCCD_OK);
}
END_TEST

/* The batch: every pair exactly as its own call, whatever the thread count; a bad pair reports its
 * status and message, the others still run. */
START_TEST(test_generate_batch)
{
    sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 4, 4, 4);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws[3];
    for (int k = 0; k < 3; ++k) ck_assert_int_eq(sdfccd_create_workspace(&ws[k]), SDFCCD_OK);
    sdfccd_ContactParams p = sdfccd_default_contact_params();
    p.query.margin = 0.01;
    enum { N = 12 };
    sdfccd_RigidMotion m[N];
    sdfccd_ContactPoint one[N][8], many[N][8];
    memset(one, 0, sizeof one); /* padding too: compared byte for byte */
    sdfccd_ContactSet s1[N], sn[N];
    sdfccd_ContactPair pairs[N];
    for (int i = 0; i < N; ++i) {
        m[i] = sdfccd_default_rigid_motion();
        m[i].pose.position = (sdfccd_Vec3){ 0.3 * i, 0, H + 0.01 * (i % 4) };
        m[i].linear_velocity.z = -(double)(i % 3);
        m[i].angular_velocity.y = 2.0 * (i % 5);
        s1[i] = generate_p(ws[0], floor, NULL, cube, &m[i], &p, one[i], 8);
    }
    for (int threads = 1; threads <= 3; ++threads) {
        memset(many, 0, sizeof many);
        for (int i = 0; i < N; ++i)
            pairs[i] = (sdfccd_ContactPair){ floor, NULL, cube, &m[i], 0.0, DT, &p, many[i], 8, &sn[i], SDFCCD_INVALID_ARGUMENT };
        ck_assert_int_eq(sdfccd_generate_contacts_batch(ws, threads, pairs, N), SDFCCD_OK);
        for (int i = 0; i < N; ++i) {
            ck_assert_int_eq(pairs[i].status, SDFCCD_OK);
            ck_assert(memcmp(&sn[i], &s1[i], sizeof sn[i]) == 0);
            ck_assert(memcmp(many[i], one[i], (size_t)s1[i].count * sizeof one[i][0]) == 0);
        }
    }
    sdfccd_ContactParams bad = p;
    bad.reduced_count = -1;
    pairs[5].params = &bad;
    ck_assert_int_eq(sdfccd_generate_contacts_batch(ws, 2, pairs, N), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strstr(sdfccd_last_error(), "pair 5") != NULL);
    ck_assert_int_eq(pairs[5].status, SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(pairs[6].status, SDFCCD_OK);
    ck_assert_int_eq(sdfccd_generate_contacts_batch(NULL, 1, pairs, N), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_generate_contacts_batch(ws, 0, pairs, N), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_generate_contacts_batch(ws, 257, pairs, N), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_generate_contacts_batch(ws, 1, NULL, 3), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_generate_contacts_batch(ws, 1, pairs, -1), SDFCCD_INVALID_ARGUMENT);
    sdfccd_Workspace* holes[2] = { ws[0], NULL };
    ck_assert_int_eq(sdfccd_generate_contacts_batch(holes, 2, pairs, N), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_generate_contacts_batch(ws, 1, NULL, 0), SDFCCD_OK);
    for (int k = 0; k < 3; ++k) sdfccd_destroy_workspace(ws[k]);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
}
END_TEST

START_TEST(test_generate_bad_input)
{
    sdfccd_MeshId cube = test_box_mesh((sdfccd_Vec3){ H, H, H }, 1, 1, 1);
    sdfccd_SdfId floor = make_floor();
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    sdfccd_ContactParams p = sdfccd_default_contact_params(), bad;
    sdfccd_ContactPoint c[4];
    sdfccd_ContactSet set, untouched;
    memset(&untouched, 0x5a, sizeof untouched);
    set = untouched;
#define EXPECT(call, status)                                          \
    do {                                                              \
        ck_assert_int_eq((call), (status));                           \
        ck_assert_msg(strlen(sdfccd_last_error()) > 0, "no message"); \
        ck_assert(memcmp(&set, &untouched, sizeof set) == 0);         \
    } while (0)
    EXPECT(sdfccd_generate_contacts(NULL, floor, NULL, cube, &m, 0, DT, &p, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &p, c, 4, NULL), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, NULL, 0, DT, &p, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, NULL, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &p, NULL, 4, &set), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &p, c, -1, &set), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, DT, 0, &p, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    memset(&bad, 0, sizeof bad);
    bad.query = sdfccd_default_query_params();
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &bad, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    bad = p;
    bad.vertex_distance = -1;
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &bad, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    bad = p;
    bad.same_place_distance = NAN;
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &bad, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    bad = p;
    bad.feature_size = NAN;
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &bad, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    bad = p;
    bad.cover_depth = -1;
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &bad, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    bad = p;
    bad.reduced_count = -1;
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &bad, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    bad = p;
    bad.query.margin = INFINITY;
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &m, 0, DT, &bad, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    sdfccd_RigidMotion nan_m = m;
    nan_m.angular_velocity.x = NAN;
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, cube, &nan_m, 0, DT, &p, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_generate_contacts(ws, floor, &nan_m, cube, &m, 0, DT, &p, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    sdfccd_MeshId null_mesh = { 0, 0 };
    EXPECT(sdfccd_generate_contacts(ws, floor, NULL, null_mesh, &m, 0, DT, &p, c, 4, &set), SDFCCD_INVALID_HANDLE);
    sdfccd_Vec3 pts[8];
    memset(pts, 0, sizeof pts);
    EXPECT(sdfccd_generate_contacts_linear(ws, floor, NULL, cube, NULL, pts, 0, DT, &p, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_generate_contacts_linear(ws, floor, NULL, cube, pts, NULL, 0, DT, &p, c, 4, &set), SDFCCD_INVALID_ARGUMENT);
#undef EXPECT
    sdfccd_destroy_workspace(ws);
    ck_assert_int_eq(sdfccd_destroy_sdf(floor), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
}
END_TEST

/* ---- sdfccd_friction_hold: the static friction a one-direction solver leaves out ---- */

static const double REST = 2.0; /* rest_speed (m/s) above every slip below but the one of test_hold_rest_speed */

static sdfccd_BodyState hold_body(double inv_mass, double inv_inertia, sdfccd_Vec3 v, sdfccd_Vec3 w)
{
    sdfccd_BodyState b;
    memset(&b, 0, sizeof b);
    b.inverse_mass = inv_mass;
    b.inverse_inertia[0] = b.inverse_inertia[4] = b.inverse_inertia[8] = inv_inertia;
    b.linear_velocity = v;
    b.angular_velocity = w;
    return b;
}

static sdfccd_HeldContact held_contact(double x, double y, double z, double normal_impulse, double friction)
{
    sdfccd_HeldContact c;
    memset(&c, 0, sizeof c);
    c.point = (sdfccd_Vec3){ x, y, z };
    c.normal = (sdfccd_Vec3){ 0, 0, 1 };
    c.normal_impulse = normal_impulse;
    c.friction = friction;
    return c;
}

/* The tangential (x, y) velocity of the body's material point at p. */
static double tangential_speed(const sdfccd_BodyState* b, sdfccd_Vec3 p, sdfccd_Vec3 surface)
{
    const sdfccd_Vec3 r = { p.x - b->center.x, p.y - b->center.y, p.z - b->center.z }, w = b->angular_velocity;
    const double vx = b->linear_velocity.x + w.y * r.z - w.z * r.y - surface.x, vy = b->linear_velocity.y + w.z * r.x - w.x * r.z - surface.y;
    return hypot(vx, vy);
}

/* The normal (z) velocity of the body's material point at p. */
static double normal_speed(const sdfccd_BodyState* b, sdfccd_Vec3 p)
{
    const sdfccd_Vec3 w = b->angular_velocity;
    return b->linear_velocity.z + w.x * (p.y - b->center.y) - w.y * (p.x - b->center.x);
}

START_TEST(test_hold_sticks_closed_form)
{
    /* A sliding point mass (no rotation) inside its cone: the impulse that stops it, -v/inv_mass in
     * the plane, and nothing along the normal. */
    sdfccd_BodyState b = hold_body(0.5, 0.0, (sdfccd_Vec3){ 0.3, -0.4, -0.2 }, (sdfccd_Vec3){ 0, 0, 0 });
    sdfccd_HeldContact c = held_contact(0.1, 0.2, 0.0, 10.0, 0.5); /* cap 5 > |0.5 m/s| / 0.5 = 1 */
    sdfccd_Vec3 j;
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, &j), SDFCCD_OK);
    ck_assert(fabs(b.linear_velocity.x) < 1e-15 && fabs(b.linear_velocity.y) < 1e-15);
    ck_assert(b.linear_velocity.z == -0.2);
    ck_assert(fabs(j.x + 0.6) < 1e-15 && fabs(j.y - 0.8) < 1e-15 && j.z == 0.0);
    /* A moving surface (a conveyor at 1 m/s in y) carries a sticking body along. */
    b = hold_body(1.0, 0.0, (sdfccd_Vec3){ 0, 0, 0 }, (sdfccd_Vec3){ 0, 0, 0 });
    c.surface_velocity = (sdfccd_Vec3){ 0, 1, 0 };
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, NULL), SDFCCD_OK);
    ck_assert(fabs(b.linear_velocity.x) < 1e-15 && fabs(b.linear_velocity.y - 1.0) < 1e-15);
    /* No load, no hold: the velocities stay bit for bit. */
    b = hold_body(1.0, 0.0, (sdfccd_Vec3){ 0.3, -0.4, 0 }, (sdfccd_Vec3){ 0, 0, 0 });
    c = held_contact(0, 0, 0, 0.0, 0.5);
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, &j), SDFCCD_OK);
    ck_assert(b.linear_velocity.x == 0.3 && b.linear_velocity.y == -0.4 && j.x == 0.0 && j.y == 0.0);
}
END_TEST

START_TEST(test_hold_cone_closed_form)
{
    /* Outside the cone the point keeps sliding: |impulse| = mu N opposite the slip. v = (0.3, -0.4),
     * cap 0.25 with inverse mass 1: v loses 0.25 along (0.6, -0.8). */
    sdfccd_BodyState b = hold_body(1.0, 0.0, (sdfccd_Vec3){ 0.3, -0.4, 0 }, (sdfccd_Vec3){ 0, 0, 0 });
    sdfccd_HeldContact c = held_contact(0, 0, 0, 0.5, 0.5);
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, NULL), SDFCCD_OK);
    ck_assert(fabs(b.linear_velocity.x - 0.15) < 1e-15 && fabs(b.linear_velocity.y + 0.2) < 1e-15);
    /* The solver's own friction counts against the cone. It pushed 0.2 along -x (its one direction)
     * and left the body sliding at 1 m/s in y: stopping that needs (-0.2, -1) in total, |.| = 1.0198
     * > cap 0.5, so the total is cut to 0.5 (-0.2, -1)/1.0198 and the hold adds that minus (-0.2, 0). */
    b = hold_body(1.0, 0.0, (sdfccd_Vec3){ 0, 1, 0 }, (sdfccd_Vec3){ 0, 0, 0 });
    c = held_contact(0, 0, 0, 1.0, 0.5);
    c.friction_impulse = (sdfccd_Vec3){ -0.2, 0, 0.7 }; /* its part along the normal is ignored */
    sdfccd_Vec3 j;
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, &j), SDFCCD_OK);
    const double len = sqrt(0.04 + 1.0), tx = -0.2 * 0.5 / len, ty = -1.0 * 0.5 / len;
    ck_assert(fabs(j.x - (tx + 0.2)) < 1e-12 && fabs(j.y - ty) < 1e-12);
    ck_assert(fabs(b.linear_velocity.x - (tx + 0.2)) < 1e-12 && fabs(b.linear_velocity.y - (1.0 + ty)) < 1e-12);
    ck_assert(hypot(-0.2 + j.x, j.y) <= 0.5 + 1e-12);
    /* A solver that already used the whole cone along the slip leaves nothing to add. */
    b = hold_body(1.0, 0.0, (sdfccd_Vec3){ 0, 1, 0 }, (sdfccd_Vec3){ 0, 0, 0 });
    c.friction_impulse = (sdfccd_Vec3){ 0, -0.5, 0 };
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, &j), SDFCCD_OK);
    ck_assert(fabs(j.x) < 1e-15 && fabs(j.y) < 1e-15 && b.linear_velocity.y == 1.0);
}
END_TEST

START_TEST(test_hold_box_on_four_corners)
{
    /* A unit cube (1 kg, inverse inertia 6) on its four bottom corners, creeping and turning about
     * the normal as Bullet's one friction row per corner leaves it: with the corners inside their
     * cones (2.5 N s each, mu 0.5) every corner stops sliding, within 1e-9 of its start slip. */
    sdfccd_BodyState b = hold_body(1.0, 6.0, (sdfccd_Vec3){ 0.004, -0.003, 0 }, (sdfccd_Vec3){ 0.001, 0.002, 0.02 });
    b.center = (sdfccd_Vec3){ 0, 0, 0.5 };
    sdfccd_HeldContact c[4] = { held_contact(-0.5, -0.5, 0, 2.5, 0.5), held_contact(0.5, -0.5, 0, 2.5, 0.5),
                                held_contact(0.5, 0.5, 0, 2.5, 0.5), held_contact(-0.5, 0.5, 0, 2.5, 0.5) };
    double before = 0, after = 0, vn0[4];
    for (int i = 0; i < 4; ++i) {
        before = fmax(before, tangential_speed(&b, c[i].point, c[i].surface_velocity));
        vn0[i] = normal_speed(&b, c[i].point);
    }
    sdfccd_Vec3 j[4];
    ck_assert_int_eq(sdfccd_friction_hold(c, 4, REST, &b, j), SDFCCD_OK);
    for (int i = 0; i < 4; ++i) {
        after = fmax(after, tangential_speed(&b, c[i].point, c[i].surface_velocity));
        /* Within the cone of the solver's and any added normal impulse (>= 0); the hold's turn sinks no
         * corner faster than after the solve (the ones that rose may not approach at all). */
        ck_assert(j[i].z >= 0.0 && hypot(j[i].x, j[i].y) <= 0.5 * (2.5 + j[i].z) + 1e-12);
        ck_assert(normal_speed(&b, c[i].point) >= fmin(vn0[i], 0.0) - 1e-12);
    }
    REPORT("hold: box corners slip %.3g -> %.3g m/s\n", before, after);
    ck_assert(before > 0.01 && after <= 1e-9 * before);
    /* Deterministic: the same input, the same bits. */
    sdfccd_BodyState b2 = hold_body(1.0, 6.0, (sdfccd_Vec3){ 0.004, -0.003, 0 }, (sdfccd_Vec3){ 0.001, 0.002, 0.02 });
    b2.center = b.center;
    ck_assert_int_eq(sdfccd_friction_hold(c, 4, REST, &b2, NULL), SDFCCD_OK);
    ck_assert(memcmp(&b, &b2, sizeof b) == 0);
}
END_TEST

START_TEST(test_hold_rest_speed)
{
    /* A point sliding at 0.5 m/s is held below a 0.6 m/s rest speed, and left to the solver at
     * 0.5 m/s (not slower than it): velocities bit for bit, impulses zero. A point without load does
     * not count. */
    sdfccd_HeldContact c[2] = { held_contact(0, 0, 0, 10.0, 0.5), held_contact(0, 0, 0, 0.0, 0.5) };
    c[1].surface_velocity = (sdfccd_Vec3){ 5, 0, 0 };
    sdfccd_BodyState b = hold_body(1.0, 0.0, (sdfccd_Vec3){ 0.3, -0.4, 0 }, (sdfccd_Vec3){ 0, 0, 0 });
    sdfccd_Vec3 j[2] = { { 9, 9, 9 }, { 9, 9, 9 } };
    ck_assert_int_eq(sdfccd_friction_hold(c, 2, 0.6, &b, j), SDFCCD_OK);
    ck_assert(fabs(b.linear_velocity.x) < 1e-15 && fabs(b.linear_velocity.y) < 1e-15 && fabs(j[0].x + 0.3) < 1e-15);
    b = hold_body(1.0, 0.0, (sdfccd_Vec3){ 0.3, -0.4, 0 }, (sdfccd_Vec3){ 0, 0, 0 });
    ck_assert_int_eq(sdfccd_friction_hold(c, 2, 0.5, &b, j), SDFCCD_OK);
    ck_assert(b.linear_velocity.x == 0.3 && b.linear_velocity.y == -0.4);
    ck_assert(j[0].x == 0.0 && j[0].y == 0.0 && j[1].x == 0.0 && j[1].y == 0.0);
}
END_TEST

START_TEST(test_hold_bad_input)
{
    sdfccd_BodyState b = hold_body(1.0, 1.0, (sdfccd_Vec3){ 1, 2, 3 }, (sdfccd_Vec3){ 4, 5, 6 });
    const sdfccd_BodyState keep = b;
    sdfccd_HeldContact c = held_contact(0, 0, 0, 1.0, 0.5);
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, NULL, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_friction_hold(NULL, 1, REST, &b, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_friction_hold(&c, -1, REST, &b, NULL), SDFCCD_INVALID_ARGUMENT);
    c.normal = (sdfccd_Vec3){ 0, 0, 0 };
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strstr(sdfccd_last_error(), "sdfccd_friction_hold") != NULL);
    c = held_contact(0, 0, 0, -1.0, 0.5);
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, NULL), SDFCCD_INVALID_ARGUMENT);
    c = held_contact(0, 0, 0, 1.0, -0.5);
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, NULL), SDFCCD_INVALID_ARGUMENT);
    c = held_contact(0, 0, 0, 1.0, 0.5);
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, -1.0, &b, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, NAN, &b, NULL), SDFCCD_INVALID_ARGUMENT);
    c = held_contact(0, 0, NAN, 1.0, 0.5);
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, NULL), SDFCCD_INVALID_ARGUMENT);
    c = held_contact(0, 0, 0, 1.0, 0.5);
    b.inverse_mass = -1;
    ck_assert_int_eq(sdfccd_friction_hold(&c, 1, REST, &b, NULL), SDFCCD_INVALID_ARGUMENT);
    b.inverse_mass = 1;
    ck_assert(memcmp(&b, &keep, sizeof b) == 0);
    ck_assert_int_eq(sdfccd_friction_hold(NULL, 0, REST, &b, NULL), SDFCCD_OK); /* nothing to hold */
    ck_assert(memcmp(&b, &keep, sizeof b) == 0);
}
END_TEST

/* ---- warm starting by place (sdfccd_match_contacts) ---- */

static double dist2(sdfccd_Vec3 a, sdfccd_Vec3 b)
{
    return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z);
}

/* Known sets: the nearest previous point within the distance, each previous point at most once, in
 * the order of the new points; the distance is strict; equal distances go to the lower index. */
START_TEST(test_match_known)
{
    const sdfccd_Vec3 prev[3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
    /* 0.9 -> 1; 0.05 -> 0; far away -> none; 1.05 is near 1, which 0.9 took -> none */
    const sdfccd_Vec3 pts[4] = { { 0.9, 0, 0 }, { 0.05, 0, 0 }, { 5, 5, 5 }, { 1.05, 0, 0 } };
    int32_t m[4] = { 9, 9, 9, 9 };
    ck_assert_int_eq(sdfccd_match_contacts(prev, 3, pts, 4, 0.2, m), SDFCCD_OK);
    ck_assert_int_eq(m[0], 1);
    ck_assert_int_eq(m[1], 0);
    ck_assert_int_eq(m[2], -1);
    ck_assert_int_eq(m[3], -1);
    /* the nearest, not the first within the distance */
    const sdfccd_Vec3 prev2[2] = { { 0.15, 0, 0 }, { 0.05, 0, 0 } }, origin[1] = { { 0, 0, 0 } };
    ck_assert_int_eq(sdfccd_match_contacts(prev2, 2, origin, 1, 0.2, m), SDFCCD_OK);
    ck_assert_int_eq(m[0], 1);
    /* strictly closer than the distance: 0.5 away with distance 0.5 (exact in binary) is no match */
    const sdfccd_Vec3 half[1] = { { 0.5, 0, 0 } };
    ck_assert_int_eq(sdfccd_match_contacts(half, 1, origin, 1, 0.5, m), SDFCCD_OK);
    ck_assert_int_eq(m[0], -1);
    ck_assert_int_eq(sdfccd_match_contacts(half, 1, origin, 1, 0.5000001, m), SDFCCD_OK);
    ck_assert_int_eq(m[0], 0);
    /* greedy in the new points' order: the first takes the previous point although the second is nearer */
    const sdfccd_Vec3 two[2] = { { 0.1, 0, 0 }, { 0.01, 0, 0 } };
    ck_assert_int_eq(sdfccd_match_contacts(origin, 1, two, 2, 0.2, m), SDFCCD_OK);
    ck_assert_int_eq(m[0], 0);
    ck_assert_int_eq(m[1], -1);
    /* equally near previous points (0.25 each way, exact): the lower index */
    const sdfccd_Vec3 tie[2] = { { 0.25, 0, 0 }, { -0.25, 0, 0 } };
    ck_assert_int_eq(sdfccd_match_contacts(tie, 2, origin, 1, 1.0, m), SDFCCD_OK);
    ck_assert_int_eq(m[0], 0);
    /* no previous set, or distance 0: nothing matches */
    ck_assert_int_eq(sdfccd_match_contacts(NULL, 0, pts, 4, 0.2, m), SDFCCD_OK);
    for (int i = 0; i < 4; ++i) ck_assert_int_eq(m[i], -1);
    ck_assert_int_eq(sdfccd_match_contacts(prev, 3, prev, 3, 0.0, m), SDFCCD_OK);
    for (int i = 0; i < 3; ++i) ck_assert_int_eq(m[i], -1);
    /* a resting set (the same points, another order) matches itself */
    const sdfccd_Vec3 again[3] = { prev[2], prev[0], prev[1] };
    ck_assert_int_eq(sdfccd_match_contacts(prev, 3, again, 3, 0.02, m), SDFCCD_OK);
    ck_assert_int_eq(m[0], 2);
    ck_assert_int_eq(m[1], 0);
    ck_assert_int_eq(m[2], 1);
}
END_TEST

/* Seeded random sets (up to 5000 previous points: the allocated scratch too) against the rule
 * checked point by point by brute force: a match is within the distance, no previous point is
 * matched twice, and no previous point free at point i's turn is nearer than its match (or, for
 * an unmatched point, within the distance at all); equal distances go to the lower index. */
START_TEST(test_match_random_property)
{
    enum { NMAX = 40, MMAX = 5000 };
    static sdfccd_Vec3 prev[MMAX], pts[NMAX];
    static int32_t m[NMAX];
    static int taken[MMAX];
    unsigned seed = 777u;
    for (int trial = 0; trial < 60; ++trial) {
        const int n = 1 + trial % NMAX, mc = trial == 59 ? MMAX : 1 + (trial * 7) % 30;
        const double grid = trial % 3 == 0 ? 0.125 : 0.0; /* on a coarse grid: exact ties */
        for (int j = 0; j < mc + n; ++j) {
            double c[3];
            for (int k = 0; k < 3; ++k) {
                seed = seed * 1664525u + 1013904223u;
                c[k] = (seed >> 8) / 16777216.0;
                if (grid > 0) c[k] = grid * floor(c[k] / grid);
            }
            sdfccd_Vec3 v = { c[0], c[1], c[2] };
            if (j < mc) prev[j] = v;
            else pts[j - mc] = v;
        }
        const double d = 0.1 + 0.05 * (trial % 5);
        ck_assert_int_eq(sdfccd_match_contacts(prev, mc, pts, n, d, m), SDFCCD_OK);
        memset(taken, 0, sizeof taken);
        for (int i = 0; i < n; ++i) {
            if (m[i] >= 0) {
                ck_assert_int_lt(m[i], mc);
                ck_assert(!taken[m[i]]);
                ck_assert(dist2(prev[m[i]], pts[i]) < d * d);
            }
            const double mine = m[i] >= 0 ? dist2(prev[m[i]], pts[i]) : d * d;
            for (int j = 0; j < mc; ++j) {
                if (taken[j] || j == m[i]) continue;
                const double o = dist2(prev[j], pts[i]);
                ck_assert_msg(!(o < mine) && !(o == mine && m[i] >= 0 && j < m[i]),
                              "trial %d point %d: previous %d (d2 %g) beats %d (d2 %g)", trial, i, j, o, (int)m[i], mine);
            }
            if (m[i] >= 0) taken[m[i]] = 1;
        }
    }
}
END_TEST

START_TEST(test_match_bad_input)
{
    const sdfccd_Vec3 p[2] = { { 0, 0, 0 }, { 1, 0, 0 } };
    sdfccd_Vec3 nan_p[1] = { { 0, NAN, 0 } };
    int32_t m[2] = { 7, 7 };
    ck_assert_int_eq(sdfccd_match_contacts(p, 2, p, 2, 0.1, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_match_contacts(NULL, 2, p, 2, 0.1, m), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_match_contacts(p, 2, NULL, 2, 0.1, m), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_match_contacts(p, -1, p, 2, 0.1, m), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_match_contacts(p, 2, p, -1, 0.1, m), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_match_contacts(p, 2, p, 2, -0.1, m), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_match_contacts(p, 2, p, 2, NAN, m), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_match_contacts(p, 2, p, 2, INFINITY, m), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_match_contacts(nan_p, 1, p, 2, 0.1, m), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_match_contacts(p, 2, nan_p, 1, 0.1, m), SDFCCD_INVALID_ARGUMENT);
    ck_assert(strlen(sdfccd_last_error()) > 0);
    ck_assert_int_eq(m[0], 7); /* not written on error */
    ck_assert_int_eq(m[1], 7);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("contacts");
    TCase* tg = tcase_create("generate");
    test_add_memory_fixture(tg);
    tcase_add_test(tg, test_generate_no_allocation_after_warm_up); /* first: it installs an allocator */
    tcase_add_test(tg, test_generate_resting_box);
    tcase_add_test(tg, test_generate_kept_ids);
    tcase_add_test(tg, test_generate_falling_box);
    tcase_add_test(tg, test_generate_fast_plate_thin_wall);
    tcase_add_test(tg, test_generate_linear_cloth);
    tcase_add_test(tg, test_generate_rules_resting_closed_form);
    tcase_add_test(tg, test_generate_rules_falling_closed_form);
    tcase_add_test(tg, test_generate_rules_cull);
    tcase_add_test(tg, test_generate_rules_cover);
    tcase_add_test(tg, test_generate_rules_face_search);
    tcase_add_test(tg, test_generate_batch);
    tcase_add_test(tg, test_generate_bad_input);
    tcase_add_test(tg, test_faces_sphere_cap);
    tcase_add_test(tg, test_faces_ridge);
    tcase_add_test(tg, test_faces_bad_input);
    suite_add_tcase(s, tg);
    TCase* tc = tcase_create("reduce");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_reduce_single_point);
    tcase_add_test(tc, test_reduce_coincident);
    tcase_add_test(tc, test_reduce_collinear);
    tcase_add_test(tc, test_reduce_face_corners);
    tcase_add_test(tc, test_reduce_thousand_points);
    tcase_add_test(tc, test_reduce_same_place);
    tcase_add_test(tc, test_reduce_bad_input);
    tcase_add_test(tc, test_reduce_weighted_crossover);
    tcase_add_test(tc, test_reduce_weighted_small_sets);
    tcase_add_test(tc, test_reduce_weighted_thousand_points);
    tcase_add_test(tc, test_reduce_weighted_rounding);
    tcase_add_test(tc, test_reduce_weighted_contact_plane);
    tcase_add_test(tc, test_reduce_weighted_bad_input);
    tcase_add_test(tc, test_reduce_kept_persist);
    tcase_add_test(tc, test_reduce_kept_better_wins);
    tcase_add_test(tc, test_reduce_kept_deterministic);
    tcase_add_test(tc, test_reduce_kept_bad_input);
    tcase_add_test(tc, test_cover_no_tilt);
    tcase_add_test(tc, test_cover_tilt_closed_form);
    tcase_add_test(tc, test_cover_order_and_neighbours);
    tcase_add_test(tc, test_cover_tie);
    tcase_add_test(tc, test_cover_normals_and_same_place);
    tcase_add_test(tc, test_cover_random_property);
    tcase_add_test(tc, test_cover_bad_input);
    tcase_add_test(tc, test_match_known);
    tcase_add_test(tc, test_match_random_property);
    tcase_add_test(tc, test_match_bad_input);
    suite_add_tcase(s, tc);
    TCase* tq = tcase_create("mesh query");
    test_add_memory_fixture(tq);
    tcase_add_test(tq, test_mesh_query_reduces_contacts);
    suite_add_tcase(s, tq);
    TCase* th = tcase_create("friction hold");
    test_add_memory_fixture(th);
    tcase_add_test(th, test_hold_sticks_closed_form);
    tcase_add_test(th, test_hold_cone_closed_form);
    tcase_add_test(th, test_hold_box_on_four_corners);
    tcase_add_test(th, test_hold_rest_speed);
    tcase_add_test(th, test_hold_bad_input);
    suite_add_tcase(s, th);
    return test_run_suite(s);
}
