/* SPDX-License-Identifier: MIT
 * Allocation failure, every N (issue 11): a user allocator that fails the N-th allocation is
 * installed and a scenario (grid builds, mesh loads and imports, .cdf load/save, SDF
 * combinations, every query method, isosurface extraction) runs until its first failing call;
 * that call must return SDFCCD_OUT_OF_MEMORY with a message, and once everything created is
 * destroyed sdfccd_byte_count() must be 0 and the allocator must have seen every byte back.
 * N runs from 1 until a run completes without any failure. Before the fix a failure inside the
 * triangle BVH build freed with size 0, so the byte count never returned to 0.
 * A call during which the injected failure happened must itself fail with SDFCCD_OUT_OF_MEMORY:
 * SDFCCD_OK there is a swallowed out-of-memory (a result silently lost), since the library
 * documents no fallback for a failed allocation. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

typedef struct failing { long long allocs, frees, live, fail_at, failed; } failing;

static void* f_alloc(size_t size, void* user)
{
    failing* f = user;
    if (++f->allocs == f->fail_at) { f->failed = 1; return NULL; }
    f->live += (long long)size;
    return malloc(size);
}

static void f_free(void* p, size_t size, void* user)
{
    failing* f = user;
    f->frees++;
    f->live -= (long long)size;
    free(p);
}

/* The injecting allocator of the current run, and the first call that returned SDFCCD_OK although
 * the injected failure happened during it (NULL while none has). */
static failing* g_alloc;
static const char* g_swallowed;

/* Handles a scenario created, destroyed in reverse order by cleanup(). */
typedef struct made { sdfccd_SdfId sdf[16]; int ns; sdfccd_MeshId mesh[8]; int nm; sdfccd_Workspace* ws; } made;

static void cleanup(made* m)
{
    for (int i = m->nm - 1; i >= 0; --i) ck_assert_int_eq(sdfccd_destroy_mesh(m->mesh[i]), SDFCCD_OK);
    for (int i = m->ns - 1; i >= 0; --i) ck_assert_int_eq(sdfccd_destroy_sdf(m->sdf[i]), SDFCCD_OK);
    if (m->ws) sdfccd_destroy_workspace(m->ws);
    memset(m, 0, sizeof *m);
}

/* Stops the scenario at the first failing call: returns its status. A call that returns OK after
 * the injected failure happened during it is recorded as swallowing it. */
#define TRY(call)                                                                        \
    do {                                                                                 \
        long long failed_before_ = g_alloc ? g_alloc->failed : 0;                        \
        sdfccd_Status st_ = (call);                                                      \
        if (st_ == SDFCCD_OK && g_alloc && g_alloc->failed && !failed_before_ && !g_swallowed) \
            g_swallowed = #call;                                                         \
        if (st_ != SDFCCD_OK) return st_;                                                \
    } while (0)
#define SDF(call, slot) TRY(call); m->ns++
#define MESH(call, slot) TRY(call); m->nm++

static sdfccd_Status queries(sdfccd_SdfId sdf, sdfccd_MeshId mesh, made* m)
{
    static const sdfccd_Vec3 tri[3] = { { 0, 0, 0.6 }, { 0.1, 0, 0.6 }, { 0, 0.1, 0.6 } };
    static const sdfccd_Vec3 end[3] = { { 0, 0, -0.6 }, { 0.1, 0, -0.6 }, { 0, 0.1, -0.6 } };
    sdfccd_RigidMotion mo = sdfccd_default_rigid_motion();
    mo.linear_velocity.z = -1.2;
    mo.angular_velocity.x = 2.0;
    sdfccd_Contact c[16];
    sdfccd_QueryResult r;
    sdfccd_MeshInfo info;
    TRY(sdfccd_mesh_get_info(mesh, &info));
    sdfccd_Vec3 start_v[64], end_v[64];
    if (info.vertex_count > 64) return SDFCCD_INVALID_ARGUMENT;
    double v[3 * 64];
    TRY(sdfccd_mesh_get_data(mesh, v, NULL));
    for (uint32_t i = 0; i < info.vertex_count; ++i) {
        start_v[i] = (sdfccd_Vec3){ v[3 * i], v[3 * i + 1], v[3 * i + 2] + 0.6 };
        end_v[i] = (sdfccd_Vec3){ v[3 * i], v[3 * i + 1], v[3 * i + 2] - 0.6 };
    }
    for (int method = 0; method < SDFCCD_METHOD_COUNT; ++method) {
        sdfccd_QueryParams p = sdfccd_default_query_params();
        p.method = (sdfccd_Method)method;
        p.certified_max_regions = 5000;
        TRY(sdfccd_query_triangle(sdf, NULL, tri, &mo, 0, 1, &p, c, 16, &r));
        TRY(sdfccd_query_triangle_linear(sdf, &mo, tri, end, 0, 1, &p, c, 16, &r));
        for (int bp = 0; bp < 2; ++bp) {
            p.broad_phase = bp;
            TRY(sdfccd_query_mesh(sdf, NULL, mesh, &mo, 0, 1, &p, c, 16, &r));
            TRY(sdfccd_query_mesh_linear(sdf, NULL, mesh, start_v, end_v, 0, 1, &p, c, 16, &r));
        }
    }
    if (!m->ws) TRY(sdfccd_create_workspace(&m->ws));
    sdfccd_QueryParams p = sdfccd_default_query_params();
    TRY(sdfccd_query_mesh_ws(m->ws, sdf, NULL, mesh, &mo, 0, 1, &p, c, 16, &r));
    TRY(sdfccd_query_triangle_ws(m->ws, sdf, NULL, tri, &mo, 0, 1, &p, c, 16, &r)); /* the check's scratch in the workspace */
    sdfccd_GuardParams gp = sdfccd_default_guard_params(); /* the guard (contact.h) */
    sdfccd_GuardResult gr;
    TRY(sdfccd_guard_rigid(m->ws, sdf, NULL, mesh, &mo, 0, 1, &gp, &gr));
    TRY(sdfccd_guard_linear(m->ws, sdf, NULL, mesh, start_v, end_v, 0, 1, &gp, &gr, NULL));
    sdfccd_ContactParams cpar = sdfccd_default_contact_params(); /* contact sets (contact.h) */
    sdfccd_ContactPoint pts[4];
    sdfccd_ContactSet set;
    TRY(sdfccd_generate_contacts(m->ws, sdf, NULL, mesh, &mo, 0, 1, &cpar, pts, 4, &set));
    TRY(sdfccd_generate_contacts_linear(m->ws, sdf, NULL, mesh, start_v, end_v, 0, 1, &cpar, pts, 4, &set));
    return SDFCCD_OK;
}

/* Analytic shapes, CSG, transforms, mesh creation and import, queries, extraction. */
static sdfccd_Status scenario_shapes(made* m)
{
    SDF(sdfccd_create_sphere(0.3, &m->sdf[m->ns]), 0);
    SDF(sdfccd_create_box((sdfccd_Vec3){ 0.2, 0.2, 0.1 }, &m->sdf[m->ns]), 0);
    SDF(sdfccd_create_csg(SDFCCD_CSG_DIFFERENCE, m->sdf[1], m->sdf[0], &m->sdf[m->ns]), 0);
    sdfccd_Pose pose = sdfccd_pose_identity();
    pose.position.x = 0.05;
    SDF(sdfccd_create_transformed(m->sdf[2], pose, 1.5, &m->sdf[m->ns]), 0);
    sdfccd_MeshLoadDef d = sdfccd_default_mesh_load_def();
    d.scale = 0.3;
    MESH(sdfccd_load_mesh(SDFCCD_DATA_DIR "/meshes/pyramid.obj", &d, &m->mesh[m->nm]), 0);
    TRY(queries(m->sdf[3], m->mesh[0], m));
    sdfccd_Aabb box = { { -0.5, -0.5, -0.5 }, { 0.5, 0.5, 0.5 } };
    MESH(sdfccd_extract_isosurface(m->sdf[0], box, 8, &m->mesh[m->nm]), 0);
    sdfccd_MeshTopology topo;
    TRY(sdfccd_mesh_get_topology(m->mesh[1], &topo));
    sdfccd_Vec3 pts[2] = { { 0, 0, 0 }, { 1, 1, 1 } };
    double dist[2];
    TRY(sdfccd_mesh_signed_distance(m->mesh[1], pts, 2, 1, dist, NULL));
    return SDFCCD_OK;
}

/* Grid builds (dense and narrow band, from a mesh and from an SDF), save, load from file and
 * memory, and queries on a grid. */
static sdfccd_Status scenario_grids(made* m)
{
    sdfccd_MeshLoadDef d = sdfccd_default_mesh_load_def();
    d.scale = 0.3;
    MESH(sdfccd_load_mesh(SDFCCD_DATA_DIR "/meshes/pyramid.obj", &d, &m->mesh[m->nm]), 0);
    sdfccd_GridDef g = sdfccd_default_grid_def();
    g.resolution[0] = g.resolution[1] = g.resolution[2] = 6;
    g.threads = 1;
    g.padding = 0.05;
    SDF(sdfccd_create_grid_from_mesh(m->mesh[0], &g, &m->sdf[m->ns]), 0);
    g.band = 0.02;
    SDF(sdfccd_create_grid_from_mesh(m->mesh[0], &g, &m->sdf[m->ns]), 0);
    SDF(sdfccd_create_torus(0.3, 0.1, &m->sdf[m->ns]), 0);
    g.band = 0.0;
    SDF(sdfccd_create_grid_from_sdf(m->sdf[2], &g, &m->sdf[m->ns]), 0);
    const char* path = SDFCCD_TEST_TMP_DIR "/alloc_sweep.cdf";
    TRY(sdfccd_save_grid(m->sdf[1], path));
    SDF(sdfccd_load_grid(path, &m->sdf[m->ns]), 0);
    FILE* f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    unsigned char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    ck_assert(n > 0 && n < sizeof buf);
    SDF(sdfccd_load_grid_memory(buf, n, &m->sdf[m->ns]), 0);
    TRY(queries(m->sdf[0], m->mesh[0], m));
    TRY(queries(m->sdf[4], m->mesh[0], m));
    return SDFCCD_OK;
}

static void sweep(sdfccd_Status (*scenario)(made*), const char* name)
{
    long long n;
    int completed = 0;
    for (n = 1; n < 100000 && !completed; ++n) {
        ck_assert_int_eq(sdfccd_byte_count(), 0);
        failing f = { 0, 0, 0, n, 0 };
        ck_assert_int_eq(sdfccd_set_allocator(f_alloc, f_free, &f), SDFCCD_OK);
        made m;
        memset(&m, 0, sizeof m);
        g_alloc = &f;
        g_swallowed = NULL;
        sdfccd_Status st = scenario(&m);
        g_alloc = NULL;
        if (!f.failed) {
            ck_assert_msg(st == SDFCCD_OK, "%s: no allocation failed but status %s (%s)", name, sdfccd_status_string(st), sdfccd_last_error());
            completed = 1;
        } else {
            ck_assert_msg(!g_swallowed, "%s: allocation %lld failed inside %s, which returned SDFCCD_OK (a swallowed out-of-memory)", name, n,
                          g_swallowed);
            ck_assert_msg(st == SDFCCD_OUT_OF_MEMORY, "%s: allocation %lld failed and the status is %s (%s)", name, n, sdfccd_status_string(st),
                          sdfccd_last_error());
            ck_assert_msg(sdfccd_last_error()[0] != '\0', "%s: no message", name);
        }
        cleanup(&m);
        ck_assert_msg(sdfccd_byte_count() == 0, "%s: failing allocation %lld: %lld bytes still counted after cleanup", name, n,
                      (long long)sdfccd_byte_count());
        ck_assert_msg(f.live == 0 && f.allocs - f.failed == f.frees, "%s: failing allocation %lld: the allocator has %lld bytes live", name, n,
                      f.live);
        ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_OK);
    }
    ck_assert_msg(completed, "%s did not complete", name);
    printf("%s: %lld allocation points failed one at a time, all clean\n", name, n - 2);
}

START_TEST(test_sweep_shapes) { sweep(scenario_shapes, "shapes, meshes, queries, extraction"); }
END_TEST

START_TEST(test_sweep_grids) { sweep(scenario_grids, "grid builds, .cdf save/load, grid queries"); }
END_TEST

int main(void)
{
    Suite* s = suite_create("alloc_sweep");
    TCase* tc = tcase_create("every_n");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_sweep_shapes);
    tcase_add_test(tc, test_sweep_grids);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
