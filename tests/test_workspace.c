/* SPDX-License-Identifier: MIT
 * Issue 9: no allocation per mesh query. Through a caller-kept workspace (sdfccd_query_mesh_ws,
 * sdfccd_query_mesh_linear_ws) a mesh query allocates nothing after the first one of its size,
 * counted with a counting allocator installed through sdfccd_set_allocator; results are the same
 * as without the workspace. Also on fields with kinks, where the certified check's scratch is the
 * workspace's, and triangle queries through one (sdfccd_query_triangle_ws). Public ABI only. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

typedef struct counter { long allocs, frees; long long bytes; } counter;
static void* count_alloc(size_t n, void* u)
{
    counter* c = u;
    c->allocs++;
    c->bytes += (long long)n;
    return malloc(n);
}
static void count_free(void* p, size_t n, void* u)
{
    counter* c = u;
    (void)n;
    c->frees++;
    free(p);
}

/* A closed UV sphere of radius r: (rings - 1) * segs * 2 triangles. */
static sdfccd_MeshId uv_sphere(double r, int rings, int segs)
{
    int nv = 2 + (rings - 1) * segs;
    double* v = malloc(3 * (size_t)nv * sizeof *v);
    uint32_t* f = malloc(6 * (size_t)rings * segs * sizeof *f);
    int k = 0;
    v[k++] = 0; v[k++] = 0; v[k++] = r;
    for (int i = 1; i < rings; ++i)
        for (int j = 0; j < segs; ++j) {
            double th = M_PI * i / rings, ph = 2 * M_PI * j / segs;
            v[k++] = r * sin(th) * cos(ph);
            v[k++] = r * sin(th) * sin(ph);
            v[k++] = r * cos(th);
        }
    v[k++] = 0; v[k++] = 0; v[k++] = -r;
    int nt = 0;
    for (int j = 0; j < segs; ++j) {
        uint32_t a = 1 + j, b = 1 + (j + 1) % segs;
        f[3 * nt] = 0; f[3 * nt + 1] = a; f[3 * nt + 2] = b; ++nt;
    }
    for (int i = 1; i < rings - 1; ++i)
        for (int j = 0; j < segs; ++j) {
            uint32_t a = 1 + (i - 1) * segs + j, b = 1 + (i - 1) * segs + (j + 1) % segs;
            uint32_t c = a + segs, d = b + segs;
            f[3 * nt] = a; f[3 * nt + 1] = c; f[3 * nt + 2] = b; ++nt;
            f[3 * nt] = b; f[3 * nt + 1] = c; f[3 * nt + 2] = d; ++nt;
        }
    for (int j = 0; j < segs; ++j) {
        uint32_t a = 1 + (rings - 2) * segs + j, b = 1 + (rings - 2) * segs + (j + 1) % segs;
        f[3 * nt] = a; f[3 * nt + 1] = (uint32_t)nv - 1; f[3 * nt + 2] = b; ++nt;
    }
    sdfccd_MeshDef d = sdfccd_default_mesh_def();
    d.vertices = v;
    d.vertex_count = (uint32_t)nv;
    d.indices = f;
    d.triangle_count = (uint32_t)nt;
    sdfccd_MeshId id;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &id), SDFCCD_OK);
    free(v);
    free(f);
    return id;
}

static sdfccd_RigidMotion motion_of(test_rng* r)
{
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    sdfccd_Vec3 u = test_rng_unit_vector(r);
    m.pose.position = (sdfccd_Vec3){ 0.3 * u.x, 0.3 * u.y, 0.3 * u.z };
    double s = 1.0 / (1.0 / 60.0) * test_rng_uniform(r, 1.0, 2.0);
    sdfccd_Vec3 aim = test_rng_unit_vector(r);
    m.linear_velocity = (sdfccd_Vec3){ (0.05 * aim.x - m.pose.position.x) * s, (0.05 * aim.y - m.pose.position.y) * s,
                                       (0.05 * aim.z - m.pose.position.z) * s };
    sdfccd_Vec3 w = test_rng_unit_vector(r);
    double wm = test_rng_uniform(r, 0.0, 60.0);
    m.angular_velocity = (sdfccd_Vec3){ w.x * wm, w.y * wm, w.z * wm };
    return m;
}

static void same_result(const sdfccd_QueryResult* a, const sdfccd_Contact* ca, const sdfccd_QueryResult* b, const sdfccd_Contact* cb)
{
    ck_assert_int_eq(a->state, b->state);
    ck_assert_int_eq(a->hit, b->hit);
    ck_assert(a->toi == b->toi);
    ck_assert_int_eq(a->contact_count, b->contact_count);
    ck_assert(a->sdf_evaluations == b->sdf_evaluations);
    ck_assert(memcmp(ca, cb, (size_t)a->contact_count * sizeof *ca) == 0);
}

START_TEST(test_no_allocation_after_first_query)
{
    counter cnt = { 0, 0, 0 };
    ck_assert_int_eq(sdfccd_set_allocator(count_alloc, count_free, &cnt), SDFCCD_OK);
    sdfccd_SdfId torus;
    ck_assert_int_eq(sdfccd_create_torus(0.1, 0.05, &torus), SDFCCD_OK);
    sdfccd_MeshId mesh = uv_sphere(0.05, 12, 16);
    sdfccd_MeshInfo info;
    ck_assert_int_eq(sdfccd_mesh_get_info(mesh, &info), SDFCCD_OK);
    sdfccd_Workspace* ws;
    ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_Contact ca[64], cb[64];
    sdfccd_QueryResult ra, rb;
    test_rng rng = { 99 };
    int hits = 0;
    long allocs_without = 0;
    /* the first query sizes the workspace; the first few queries may still grow it (a larger heap
     * or more contacts), so warm up on the same motions that are then measured */
    sdfccd_RigidMotion mo[24];
    for (int i = 0; i < 24; ++i) mo[i] = motion_of(&rng);
    for (int i = 0; i < 24; ++i)
        ck_assert_int_eq(sdfccd_query_mesh_ws(ws, torus, NULL, mesh, &mo[i], 0.0, 1.0 / 60.0, &p, ca, 64, &ra), SDFCCD_OK);
    for (int i = 0; i < 24; ++i) {
        long before = cnt.allocs;
        ck_assert_int_eq(sdfccd_query_mesh(torus, NULL, mesh, &mo[i], 0.0, 1.0 / 60.0, &p, cb, 64, &rb), SDFCCD_OK);
        allocs_without += cnt.allocs - before;
        before = cnt.allocs;
        ck_assert_int_eq(sdfccd_query_mesh_ws(ws, torus, NULL, mesh, &mo[i], 0.0, 1.0 / 60.0, &p, ca, 64, &ra), SDFCCD_OK);
        ck_assert_msg(cnt.allocs == before, "query %d through the workspace allocated %ld times", i, cnt.allocs - before);
        same_result(&ra, ca, &rb, cb);
        hits += ra.hit;
    }
    /* linear motion (per-vertex positions) through the same workspace */
    uint32_t nv = info.vertex_count;
    double* v = malloc(3 * (size_t)nv * sizeof *v);
    uint32_t* f = malloc(3 * (size_t)info.triangle_count * sizeof *f);
    ck_assert_int_eq(sdfccd_mesh_get_data(mesh, v, f), SDFCCD_OK);
    sdfccd_Vec3* s0 = malloc((size_t)nv * sizeof *s0);
    sdfccd_Vec3* s1 = malloc((size_t)nv * sizeof *s1);
    for (uint32_t i = 0; i < nv; ++i) {
        s0[i] = (sdfccd_Vec3){ v[3 * i] + 0.2, v[3 * i + 1], v[3 * i + 2] };
        s1[i] = (sdfccd_Vec3){ v[3 * i] + 0.1 + 0.3 * v[3 * i], v[3 * i + 1], v[3 * i + 2] };
    }
    ck_assert_int_eq(sdfccd_query_mesh_linear_ws(ws, torus, NULL, mesh, s0, s1, 0.0, 1.0 / 60.0, &p, ca, 64, &ra), SDFCCD_OK);
    long before = cnt.allocs;
    ck_assert_int_eq(sdfccd_query_mesh_linear_ws(ws, torus, NULL, mesh, s0, s1, 0.0, 1.0 / 60.0, &p, ca, 64, &ra), SDFCCD_OK);
    ck_assert_int_eq(cnt.allocs, before);
    ck_assert_int_eq(sdfccd_query_mesh_linear(torus, NULL, mesh, s0, s1, 0.0, 1.0 / 60.0, &p, cb, 64, &rb), SDFCCD_OK);
    same_result(&ra, ca, &rb, cb);
    ck_assert(ra.hit);
    printf("workspace: %d of 24 rigid queries hit; without a workspace %.1f allocations per query, with one 0 (workspace %lld bytes)\n", hits,
           allocs_without / 24.0, (long long)sdfccd_workspace_bytes(ws));
    ck_assert_int_gt(hits, 0);
    ck_assert_int_gt(allocs_without, 0); /* the counter sees the library's allocations */
    ck_assert_int_eq(sdfccd_query_mesh_ws(NULL, torus, NULL, mesh, &mo[0], 0.0, 1.0 / 60.0, &p, ca, 64, &ra), SDFCCD_INVALID_ARGUMENT);
    free(v);
    free(f);
    free(s0);
    free(s1);
    sdfccd_destroy_workspace(ws);
    sdfccd_destroy_mesh(mesh);
    sdfccd_destroy_sdf(torus);
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    ck_assert_int_eq(cnt.allocs, cnt.frees);
    ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_OK);
}
END_TEST

/* The same on fields with kinks, where FWGSS's answers are checked by the certified search, whose
 * scratch (the region store's first regions, the sample cache, a grid's cell cache) the workspace
 * holds: a box and a grid of a box minus a ball. The check runs (the evaluations differ from
 * fwgss_verify 0) and the workspace holds its scratch (it is larger than one that never checked). */
START_TEST(test_no_allocation_kinked)
{
    counter cnt = { 0, 0, 0 };
    ck_assert_int_eq(sdfccd_set_allocator(count_alloc, count_free, &cnt), SDFCCD_OK);
    sdfccd_SdfId box;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.1, 0.08, 0.06 }, &box), SDFCCD_OK);
    const sdfccd_SdfId grid = test_carved_box_grid();
    sdfccd_MeshId mesh = uv_sphere(0.03, 6, 8);
    const sdfccd_SdfId fields[2] = { box, grid };
    const char* names[2] = { "box", "grid" };
    for (int k = 0; k < 2; ++k) {
        sdfccd_Workspace *ws, *ws_off;
        ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_create_workspace(&ws_off), SDFCCD_OK);
        sdfccd_QueryParams p = sdfccd_default_query_params(), p_off = p;
        p_off.fwgss_verify = 0;
        sdfccd_Contact ca[64], cb[64];
        sdfccd_QueryResult ra, rb;
        test_rng rng = { 5 };
        sdfccd_RigidMotion mo[24];
        for (int i = 0; i < 24; ++i) mo[i] = motion_of(&rng);
        for (int i = 0; i < 24; ++i) {
            ck_assert_int_eq(sdfccd_query_mesh_ws(ws, fields[k], NULL, mesh, &mo[i], 0.0, 1.0 / 60.0, &p, ca, 64, &ra), SDFCCD_OK);
            ck_assert_int_eq(sdfccd_query_mesh_ws(ws_off, fields[k], NULL, mesh, &mo[i], 0.0, 1.0 / 60.0, &p_off, cb, 64, &rb), SDFCCD_OK);
        }
        int checked = 0, hits = 0;
        for (int i = 0; i < 24; ++i) {
            ck_assert_int_eq(sdfccd_query_mesh(fields[k], NULL, mesh, &mo[i], 0.0, 1.0 / 60.0, &p, cb, 64, &rb), SDFCCD_OK);
            long before = cnt.allocs;
            ck_assert_int_eq(sdfccd_query_mesh_ws(ws, fields[k], NULL, mesh, &mo[i], 0.0, 1.0 / 60.0, &p, ca, 64, &ra), SDFCCD_OK);
            ck_assert_msg(cnt.allocs == before, "%s: query %d through the workspace allocated %ld times", names[k], i, cnt.allocs - before);
            same_result(&ra, ca, &rb, cb);
            ck_assert_int_eq(sdfccd_query_mesh_ws(ws_off, fields[k], NULL, mesh, &mo[i], 0.0, 1.0 / 60.0, &p_off, cb, 64, &rb), SDFCCD_OK);
            checked += ra.sdf_evaluations != rb.sdf_evaluations;
            hits += ra.hit;
        }
        /* triangle queries through the workspace (sdfccd_query_triangle_ws): the same answers as
         * without it, and no allocation */
        const sdfccd_Vec3 tri[3] = { { 0.03, 0, 0 }, { -0.02, 0.03, 0 }, { -0.02, -0.03, 0 } };
        for (int i = 0; i < 24; ++i) {
            ck_assert_int_eq(sdfccd_query_triangle(fields[k], NULL, tri, &mo[i], 0.0, 1.0 / 60.0, &p, cb, 64, &rb), SDFCCD_OK);
            long before = cnt.allocs;
            ck_assert_int_eq(sdfccd_query_triangle_ws(ws, fields[k], NULL, tri, &mo[i], 0.0, 1.0 / 60.0, &p, ca, 64, &ra), SDFCCD_OK);
            ck_assert_msg(cnt.allocs == before, "%s: triangle query %d through the workspace allocated %ld times", names[k], i,
                          cnt.allocs - before);
            same_result(&ra, ca, &rb, cb);
        }
        ck_assert_int_eq(sdfccd_query_triangle_ws(NULL, fields[k], NULL, tri, &mo[0], 0.0, 1.0 / 60.0, &p, ca, 64, &ra), SDFCCD_INVALID_ARGUMENT);
        const int64_t bytes = sdfccd_workspace_bytes(ws), bytes_off = sdfccd_workspace_bytes(ws_off);
        printf("workspace, %s: %d of 24 queries hit, the check ran in %d; workspace %lld bytes (%lld without the check)\n", names[k], hits,
               checked, (long long)bytes, (long long)bytes_off);
        ck_assert_int_gt(hits, 0);
        ck_assert_int_gt(checked, 0);
        ck_assert_int_ge(bytes - bytes_off, 64 * 1024);
        sdfccd_destroy_workspace(ws);
        sdfccd_destroy_workspace(ws_off);
    }
    sdfccd_destroy_mesh(mesh);
    sdfccd_destroy_sdf(grid);
    sdfccd_destroy_sdf(box);
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    ck_assert_int_eq(cnt.allocs, cnt.frees);
    ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_OK);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("workspace");
    TCase* tc = tcase_create("allocation");
    tcase_add_test(tc, test_no_allocation_after_first_query);
    tcase_add_test(tc, test_no_allocation_kinked);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
