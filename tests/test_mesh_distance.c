/* SPDX-License-Identifier: MIT
 * Exact mesh distance: point-triangle closest point against an independent plane/segment
 * computation, the BVH against brute force, signed distances against closed forms (a cube and
 * bounds for an icosphere), signs against the generalised winding number on genus 0, 1 and 3
 * meshes, and the topology report for open, flipped and unwelded meshes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"
#include "test_internal.h"
#include "../core/mesh_distance.h"

/* Independent reference: distance to the plane when the projection falls inside (tested with
 * edge-normal signs), otherwise the least distance to the three segments. */
static double seg_dist2(scc_vec3 p, scc_vec3 a, scc_vec3 b)
{
    scc_vec3 e = scc_sub(b, a);
    double t = scc_clamp(scc_dot(scc_sub(p, a), e) / scc_len2(e), 0.0, 1.0);
    return scc_len2(scc_sub(p, scc_madd(a, e, t)));
}
static double ref_tri_dist2(scc_vec3 p, scc_vec3 a, scc_vec3 b, scc_vec3 c)
{
    scc_vec3 n = scc_cross(scc_sub(b, a), scc_sub(c, a));
    double nl = scc_len(n);
    n = scc_scale(n, 1.0 / nl);
    double h = scc_dot(scc_sub(p, a), n);
    scc_vec3 q = scc_madd(p, n, -h);
    int inside = scc_dot(scc_cross(scc_sub(b, a), scc_sub(q, a)), n) >= 0 && scc_dot(scc_cross(scc_sub(c, b), scc_sub(q, b)), n) >= 0 &&
                 scc_dot(scc_cross(scc_sub(a, c), scc_sub(q, c)), n) >= 0;
    if (inside) return h * h;
    return fmin(seg_dist2(p, a, b), fmin(seg_dist2(p, b, c), seg_dist2(p, c, a)));
}

START_TEST(test_point_triangle)
{
    test_rng rng = { 1 };
    for (int it = 0; it < 20000; ++it) {
        scc_vec3 v[3], p;
        for (int k = 0; k < 3; ++k) v[k] = scc_v3(test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1));
        if (scc_triangle_area2(v[0], v[1], v[2]) < 1e-3) continue;
        p = scc_v3(test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2));
        scc_vec3 q;
        scc_tri_feature f;
        double d2 = scc_closest_point_triangle(p, v[0], v[1], v[2], &q, &f);
        double r2 = ref_tri_dist2(p, v[0], v[1], v[2]);
        ck_assert_double_near(sqrt(d2), sqrt(r2), 1e-12);
        ck_assert_double_near(d2, scc_len2(scc_sub(p, q)), 1e-12);
        /* the feature is where the point lies */
        if (f <= SCC_TRI_V2) ck_assert_double_near(scc_len(scc_sub(q, v[f])), 0.0, 0.0);
        else if (f != SCC_TRI_FACE) {
            const int i0 = f == SCC_TRI_E01 ? 0 : (f == SCC_TRI_E12 ? 1 : 2), i1 = (i0 + 1) % 3;
            ck_assert_double_near(seg_dist2(q, v[i0], v[i1]), 0.0, 1e-24);
        }
    }
}
END_TEST

START_TEST(test_bvh_vs_brute_force)
{
    const char* meshes[] = { "bullet3/bunny.obj", "bullet3/torus_textured.obj", "bullet3/concave_box.obj", "bullet3/cylinder.obj", "bullet3/shape_sorter.obj" };
    test_rng rng = { 2 };
    for (size_t mi = 0; mi < sizeof meshes / sizeof meshes[0]; ++mi) {
        sdfccd_MeshId id = test_load_mesh(meshes[mi]);
        const scc_mesh* m = test_mesh_of(id);
        scc_tri_bvh bvh;
        ck_assert_int_eq(scc_tri_bvh_build(&bvh, sdfccd__allocator(), m), 1);
        const scc_vec3 c = scc_scale(scc_add(m->bounds.lo, m->bounds.hi), 0.5), e = scc_sub(m->bounds.hi, m->bounds.lo);
        for (int it = 0; it < 2000; ++it) {
            const double s = it < 1000 ? 0.6 : 2.0; /* near and far */
            scc_vec3 p = scc_v3(c.x + e.x * test_rng_uniform(&rng, -s, s), c.y + e.y * test_rng_uniform(&rng, -s, s), c.z + e.z * test_rng_uniform(&rng, -s, s));
            double best = INFINITY;
            for (uint32_t t = 0; t < m->triangle_count; ++t) {
                scc_vec3 v[3];
                scc_mesh_triangle(m, t, v);
                best = fmin(best, scc_closest_point_triangle(p, v[0], v[1], v[2], NULL, NULL));
            }
            scc_tri_nearest nr;
            ck_assert_int_eq(scc_tri_bvh_nearest(&bvh, p, &nr), 1);
            ck_assert_double_eq(nr.dist2, best);
            /* the capped search finds the same triangle below the cap and nothing above it */
            const double cap2 = 0.01 * scc_len2(e);
            const int found = scc_tri_bvh_nearest_within(&bvh, p, (uint32_t)(it % m->triangle_count), cap2, &nr);
            ck_assert_int_eq(found, best < cap2);
            if (found) ck_assert_double_eq(nr.dist2, best);
        }
        scc_tri_bvh_destroy(&bvh);
        /* capped signed distance: exact below the cap, the cap above it */
        scc_mesh_sdf ms;
        ck_assert_int_eq(scc_mesh_sdf_init(&ms, sdfccd__allocator(), m), 1);
        uint32_t hint = UINT32_MAX, hint2 = UINT32_MAX;
        for (int it = 0; it < 500; ++it) {
            scc_vec3 p = scc_v3(c.x + e.x * test_rng_uniform(&rng, -1, 1), c.y + e.y * test_rng_uniform(&rng, -1, 1), c.z + e.z * test_rng_uniform(&rng, -1, 1));
            const double dist = scc_mesh_sdf_query_hint(&ms, p, &hint, NULL, NULL);
            const double cap = 0.1 * scc_len(e);
            const double v = scc_mesh_sdf_distance_capped(&ms, p, &hint2, cap);
            if (fabs(dist) < cap) ck_assert_double_eq(v, dist);
            else ck_assert_double_eq(v, cap);
        }
        scc_mesh_sdf_destroy(&ms);
        ck_assert_int_eq(sdfccd_destroy_mesh(id), SDFCCD_OK);
    }
}
END_TEST

/* cube.obj (+-0.5) gives the exact box distance, inside and outside. */
START_TEST(test_cube_closed_form)
{
    sdfccd_MeshId id = test_load_mesh("bullet3/cube.obj");
    enum { N = 5000 };
    sdfccd_Vec3* p = malloc(N * sizeof *p);
    double* d = malloc(N * sizeof *d);
    test_rng rng = { 3 };
    for (int i = 0; i < N; ++i) p[i] = (sdfccd_Vec3){ test_rng_uniform(&rng, -1.5, 1.5), test_rng_uniform(&rng, -1.5, 1.5), test_rng_uniform(&rng, -1.5, 1.5) };
    ck_assert_int_eq(sdfccd_mesh_signed_distance(id, p, N, 0, d, NULL), SDFCCD_OK);
    for (int i = 0; i < N; ++i) ck_assert_double_near(d[i], test_box_distance(p[i], 0.5), 1e-12);
    free(p);
    free(d);
    ck_assert_int_eq(sdfccd_destroy_mesh(id), SDFCCD_OK);
}
END_TEST

/* An icosphere of radius 1 (4 subdivisions): the mesh lies between the inscribed radius r_in
 * and 1, so |p| - 1 <= d <= |p| - r_in outside and the mirror bounds inside. */
static sdfccd_MeshId make_icosphere(int levels, double* out_rin)
{
    const double t = (1.0 + sqrt(5.0)) / 2.0;
    double* v = malloc(sizeof(double) * 3 * 20000);
    uint32_t* f = malloc(sizeof(uint32_t) * 3 * 40000);
    const double v0[12][3] = { { -1, t, 0 }, { 1, t, 0 }, { -1, -t, 0 }, { 1, -t, 0 }, { 0, -1, t }, { 0, 1, t }, { 0, -1, -t }, { 0, 1, -t }, { t, 0, -1 }, { t, 0, 1 }, { -t, 0, -1 }, { -t, 0, 1 } };
    const uint32_t f0[20][3] = { { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 }, { 0, 7, 10 }, { 0, 10, 11 }, { 1, 5, 9 }, { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 },
                                 { 3, 9, 4 }, { 3, 4, 2 }, { 3, 2, 6 }, { 3, 6, 8 }, { 3, 8, 9 }, { 4, 9, 5 }, { 2, 4, 11 }, { 6, 2, 10 }, { 8, 6, 7 }, { 9, 8, 1 } };
    uint32_t nv = 12, nf = 20;
    for (int i = 0; i < 12; ++i) { double l = sqrt(v0[i][0] * v0[i][0] + v0[i][1] * v0[i][1] + v0[i][2] * v0[i][2]); for (int k = 0; k < 3; ++k) v[3 * i + k] = v0[i][k] / l; }
    memcpy(f, f0, sizeof f0);
    for (int lv = 0; lv < levels; ++lv) {
        uint32_t* nfa = malloc(sizeof(uint32_t) * 3 * 4 * nf);
        uint32_t nn = 0;
        for (uint32_t i = 0; i < nf; ++i) {
            uint32_t a = f[3 * i], b = f[3 * i + 1], c = f[3 * i + 2], m[3];
            uint32_t pairs[3][2] = { { a, b }, { b, c }, { c, a } };
            for (int k = 0; k < 3; ++k) {
                double x[3];
                for (int d = 0; d < 3; ++d) x[d] = 0.5 * (v[3 * pairs[k][0] + d] + v[3 * pairs[k][1] + d]);
                double l = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
                /* reuse an existing midpoint (exact position match) to keep the mesh welded */
                uint32_t found = UINT32_MAX;
                for (uint32_t q = 12; q < nv && found == UINT32_MAX; ++q)
                    if (v[3 * q] == x[0] / l && v[3 * q + 1] == x[1] / l && v[3 * q + 2] == x[2] / l) found = q;
                if (found == UINT32_MAX) { found = nv++; for (int d = 0; d < 3; ++d) v[3 * found + d] = x[d] / l; }
                m[k] = found;
            }
            uint32_t tris[4][3] = { { a, m[0], m[2] }, { b, m[1], m[0] }, { c, m[2], m[1] }, { m[0], m[1], m[2] } };
            memcpy(nfa + 3 * nn, tris, sizeof tris);
            nn += 4;
        }
        memcpy(f, nfa, sizeof(uint32_t) * 3 * nn);
        free(nfa);
        nf = nn;
    }
    double rin = INFINITY;
    for (uint32_t i = 0; i < nf; ++i) {
        scc_vec3 a = { v[3 * f[3 * i]], v[3 * f[3 * i] + 1], v[3 * f[3 * i] + 2] }, b = { v[3 * f[3 * i + 1]], v[3 * f[3 * i + 1] + 1], v[3 * f[3 * i + 1] + 2] },
                 c = { v[3 * f[3 * i + 2]], v[3 * f[3 * i + 2] + 1], v[3 * f[3 * i + 2] + 2] };
        scc_vec3 n = scc_normalize_or(scc_cross(scc_sub(b, a), scc_sub(c, a)), scc_v3(0, 0, 1));
        rin = fmin(rin, fabs(scc_dot(n, a)));
    }
    *out_rin = rin;
    sdfccd_MeshDef def = sdfccd_default_mesh_def();
    def.vertices = v;
    def.vertex_count = nv;
    def.indices = f;
    def.triangle_count = nf;
    sdfccd_MeshId id;
    ck_assert_int_eq(sdfccd_create_mesh(&def, &id), SDFCCD_OK);
    free(v);
    free(f);
    return id;
}

START_TEST(test_icosphere_bounds)
{
    double rin;
    sdfccd_MeshId id = make_icosphere(3, &rin);
    sdfccd_MeshTopology topo;
    ck_assert_int_eq(sdfccd_mesh_get_topology(id, &topo), SDFCCD_OK);
    ck_assert_int_eq(topo.closed, 1);
    ck_assert(topo.volume > 4.0);
    ck_assert(rin > 0.98 && rin < 1.0);
    enum { N = 4000 };
    sdfccd_Vec3* p = malloc(N * sizeof *p);
    double* d = malloc(N * sizeof *d);
    test_rng rng = { 4 };
    for (int i = 0; i < N; ++i) {
        sdfccd_Vec3 u = test_rng_unit_vector(&rng);
        double r = i % 2 ? test_rng_uniform(&rng, 1.0, 3.0) : test_rng_uniform(&rng, 0.0, rin);
        p[i] = (sdfccd_Vec3){ u.x * r, u.y * r, u.z * r };
    }
    ck_assert_int_eq(sdfccd_mesh_signed_distance(id, p, N, 0, d, NULL), SDFCCD_OK);
    for (int i = 0; i < N; ++i) {
        double r = scc_len(sdfccd__v(p[i]));
        if (r >= 1.0) { ck_assert(d[i] >= r - 1.0 - 1e-12); ck_assert(d[i] <= r - rin + 1e-12); }
        else { ck_assert(d[i] <= -(rin - r) + 1e-12); ck_assert(d[i] >= -(1.0 - r) - 1e-12); }
    }
    free(p);
    free(d);
    ck_assert_int_eq(sdfccd_destroy_mesh(id), SDFCCD_OK);
}
END_TEST

/* Signs agree with the winding number on genus 0 (bunny, concave tray, armadillo), 1 (torus) and
 * 3 (shape sorter) meshes, at points near and far. */
START_TEST(test_signs_vs_winding_number)
{
    const char* meshes[] = { "bullet3/bunny.obj", "bullet3/torus_textured.obj", "bullet3/shape_sorter.obj", "bullet3/concave_box.obj",
                             "libigl-tutorial-data/armadillo.obj" };
    test_rng rng = { 5 };
    for (size_t mi = 0; mi < sizeof meshes / sizeof meshes[0]; ++mi) {
        sdfccd_MeshId id = test_load_mesh(meshes[mi]);
        const scc_mesh* m = test_mesh_of(id);
        sdfccd_MeshTopology topo;
        ck_assert_int_eq(sdfccd_mesh_get_topology(id, &topo), SDFCCD_OK);
        ck_assert_msg(topo.closed && topo.volume > 0, "%s should be closed and outward", meshes[mi]);
        enum { N = 3000 };
        sdfccd_Vec3 p[N];
        double d[N];
        const int n = m->triangle_count > 10000 ? 300 : N; /* the winding number costs a pass over the triangles */
        const scc_vec3 c = scc_scale(scc_add(m->bounds.lo, m->bounds.hi), 0.5), e = scc_sub(m->bounds.hi, m->bounds.lo);
        for (int i = 0; i < n; ++i)
            p[i] = (sdfccd_Vec3){ c.x + e.x * test_rng_uniform(&rng, -0.7, 0.7), c.y + e.y * test_rng_uniform(&rng, -0.7, 0.7), c.z + e.z * test_rng_uniform(&rng, -0.7, 0.7) };
        ck_assert_int_eq(sdfccd_mesh_signed_distance(id, p, n, 0, d, NULL), SDFCCD_OK);
        int inside = 0;
        for (int i = 0; i < n; ++i) {
            if (fabs(d[i]) < 1e-9) continue;
            double w = test_winding_number(m, sdfccd__v(p[i]));
            ck_assert_msg((w > 0.5) == (d[i] < 0), "%s: point (%g %g %g) d %g winding %g", meshes[mi], p[i].x, p[i].y, p[i].z, d[i], w);
            inside += d[i] < 0;
        }
        ck_assert_int_gt(inside, n / 60);
        ck_assert_int_eq(sdfccd_destroy_mesh(id), SDFCCD_OK);
    }
}
END_TEST

/* Open, flipped, inverted and unwelded meshes are reported; distances and grids refuse them
 * unless allowed. */
START_TEST(test_topology_reports)
{
    /* a cube of 8 vertices and 12 outward triangles */
    const double v[] = { -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1 };
    uint32_t f[] = { 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3 };
    sdfccd_MeshDef def = sdfccd_default_mesh_def();
    def.vertices = v;
    def.vertex_count = 8;
    def.indices = f;
    def.triangle_count = 12;
    sdfccd_MeshId id;
    sdfccd_MeshTopology t;
    ck_assert_int_eq(sdfccd_create_mesh(&def, &id), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_mesh_get_topology(id, &t), SDFCCD_OK);
    ck_assert_int_eq(t.closed, 1);
    ck_assert_double_near(t.volume, 8.0, 1e-12);
    ck_assert_int_eq(sdfccd_destroy_mesh(id), SDFCCD_OK);

    /* open: drop the last triangle */
    def.triangle_count = 11;
    ck_assert_int_eq(sdfccd_create_mesh(&def, &id), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_mesh_get_topology(id, &t), SDFCCD_OK);
    ck_assert_int_eq(t.closed, 0);
    ck_assert_uint_eq(t.boundary_edges, 3);
    sdfccd_Vec3 p = { 0, 0, 0 };
    double d;
    ck_assert_int_eq(sdfccd_mesh_signed_distance(id, &p, 1, 0, &d, NULL), SDFCCD_DEGENERATE);
    ck_assert(strstr(sdfccd_last_error(), "boundary") != NULL);
    ck_assert_int_eq(sdfccd_mesh_signed_distance(id, &p, 1, 1, &d, NULL), SDFCCD_OK);
    sdfccd_GridDef gd = sdfccd_default_grid_def();
    gd.resolution[0] = gd.resolution[1] = gd.resolution[2] = 4;
    sdfccd_SdfId g;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(id, &gd, &g), SDFCCD_DEGENERATE);
    gd.allow_open_mesh = 1;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(id, &gd, &g), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(g), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(id), SDFCCD_OK);

    /* one flipped triangle */
    def.triangle_count = 12;
    f[1] = 1; f[2] = 2;
    ck_assert_int_eq(sdfccd_create_mesh(&def, &id), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_mesh_get_topology(id, &t), SDFCCD_OK);
    ck_assert_int_eq(t.closed, 0);
    ck_assert_uint_eq(t.inconsistent_edges, 3);
    ck_assert_int_eq(sdfccd_destroy_mesh(id), SDFCCD_OK);
    f[1] = 2; f[2] = 1;

    /* inside out: every triangle flipped */
    for (int i = 0; i < 12; ++i) { uint32_t s = f[3 * i + 1]; f[3 * i + 1] = f[3 * i + 2]; f[3 * i + 2] = s; }
    ck_assert_int_eq(sdfccd_create_mesh(&def, &id), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_mesh_get_topology(id, &t), SDFCCD_OK);
    ck_assert_int_eq(t.closed, 1);
    ck_assert(t.volume < 0);
    gd.allow_open_mesh = 0;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(id, &gd, &g), SDFCCD_DEGENERATE);
    ck_assert(strstr(sdfccd_last_error(), "inside out") != NULL);
    ck_assert_int_eq(sdfccd_destroy_mesh(id), SDFCCD_OK);

    /* unwelded: every triangle with its own three vertices */
    for (int i = 0; i < 12; ++i) { uint32_t s = f[3 * i + 1]; f[3 * i + 1] = f[3 * i + 2]; f[3 * i + 2] = s; }
    double sv[36 * 3];
    uint32_t sf[36];
    for (int i = 0; i < 36; ++i) { memcpy(sv + 3 * i, v + 3 * f[i], 3 * sizeof(double)); sf[i] = (uint32_t)i; }
    def.vertices = sv;
    def.vertex_count = 36;
    def.indices = sf;
    ck_assert_int_eq(sdfccd_create_mesh(&def, &id), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_mesh_get_topology(id, &t), SDFCCD_OK);
    ck_assert_int_eq(t.closed, 0);
    ck_assert_uint_eq(t.boundary_edges, 36);
    ck_assert_int_eq(sdfccd_destroy_mesh(id), SDFCCD_OK);

    /* bad arguments */
    ck_assert_int_eq(sdfccd_mesh_signed_distance((sdfccd_MeshId){ 0, 0 }, &p, 1, 0, &d, NULL), SDFCCD_INVALID_HANDLE);
    ck_assert_int_eq(sdfccd_mesh_get_topology((sdfccd_MeshId){ 0, 0 }, &t), SDFCCD_INVALID_HANDLE);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("mesh_distance");
    TCase* tc = tcase_create("distance");
    test_add_memory_fixture(tc);
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_point_triangle);
    tcase_add_test(tc, test_bvh_vs_brute_force);
    tcase_add_test(tc, test_cube_closed_form);
    tcase_add_test(tc, test_icosphere_bounds);
    tcase_add_test(tc, test_signs_vs_winding_number);
    tcase_add_test(tc, test_topology_reports);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
