/* SPDX-License-Identifier: MIT
 * Safe destroy while a call is in flight (issue 11, "concurrent destroy"): every public entry
 * point that takes an SDF or mesh handle holds a reference on the object while it runs, so a
 * destroy from another thread (or from a user callback inside the call) frees the object only
 * when the call returns.
 *
 * Two kinds of tests:
 * - deterministic: a callback SDF (or a grid build's progress callback) destroys the handle the
 *   call is working on, halfway through the call. Without the reference the call reads freed
 *   memory on its next step, which ASan and valgrind report every time;
 * - a race: threads run every entry point in a loop while the main thread destroys the handles
 *   (ASan: use after free; TSan, scripts/tsan.sh: data races). Every call must return OK or
 *   SDFCCD_INVALID_HANDLE, and all memory must come back. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "test_util.h"

/* ---------------- a callback SDF that destroys a handle when first evaluated ---------------- */

typedef struct victim {
    sdfccd_SdfId sdf;     /* destroyed on the first evaluation (or progress report) when armed */
    sdfccd_MeshId mesh;   /* the same, for mesh victims */
    int armed_sdf, armed_mesh;
    int destroyed;
} victim;

static double destroying_sphere(sdfccd_Vec3 p, sdfccd_Vec3* out_grad, void* user)
{
    victim* v = user;
    if (v->armed_sdf) {
        v->armed_sdf = 0;
        ck_assert_int_eq(sdfccd_destroy_sdf(v->sdf), SDFCCD_OK);
        v->destroyed++;
    }
    if (v->armed_mesh) {
        v->armed_mesh = 0;
        ck_assert_int_eq(sdfccd_destroy_mesh(v->mesh), SDFCCD_OK);
        v->destroyed++;
    }
    const double r = sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    if (out_grad) {
        out_grad->x = r > 0 ? p.x / r : 0;
        out_grad->y = r > 0 ? p.y / r : 0;
        out_grad->z = r > 0 ? p.z / r : 1;
    }
    return r - 0.3;
}

static int32_t destroying_progress(double fraction, void* user)
{
    (void)fraction;
    destroying_sphere((sdfccd_Vec3){ 1, 0, 0 }, NULL, user);
    return 0;
}

/* union(callback sphere, box) under a new handle; the children's own handles are destroyed, so
 * destroying the union frees all three objects unless a call holds them. */
static sdfccd_SdfId make_union(victim* v)
{
    sdfccd_CallbackSdfDef d = sdfccd_default_callback_sdf_def();
    d.eval = destroying_sphere;
    d.user = v;
    d.bounds.lo = (sdfccd_Vec3){ -0.3, -0.3, -0.3 };
    d.bounds.hi = (sdfccd_Vec3){ 0.3, 0.3, 0.3 };
    sdfccd_SdfId cb, box, u;
    ck_assert_int_eq(sdfccd_create_callback_sdf(&d, &cb), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.1, 0.1, 0.4 }, &box), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, cb, box, &u), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(cb), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(box), SDFCCD_OK);
    return u;
}

static const sdfccd_Vec3 k_tri[3] = { { -0.05, -0.05, 0 }, { 0.1, -0.05, 0 }, { -0.05, 0.1, 0 } };
static const sdfccd_Vec3 k_tri_end[3] = { { -0.05, -0.05, -1 }, { 0.1, -0.05, -1 }, { -0.05, 0.1, -1 } };

static sdfccd_RigidMotion falling(void)
{
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position.z = 0.8;
    m.linear_velocity.z = -1.0;
    return m;
}

enum {
    CALL_EVAL, CALL_EVAL_BATCH, CALL_QUERY_TRIANGLE, CALL_QUERY_TRIANGLE_LINEAR, CALL_QUERY_MESH, CALL_QUERY_MESH_WS,
    CALL_QUERY_MESH_LINEAR, CALL_GUARD, CALL_GENERATE_CONTACTS, CALL_GRID_FROM_SDF, CALL_GRID_FROM_SDF_PROGRESS, CALL_EXTRACT, CALL_COUNT
};
static const char* const k_call_names[CALL_COUNT] = {
    "sdf_eval", "sdf_eval_batch", "query_triangle", "query_triangle_linear", "query_mesh", "query_mesh_ws",
    "query_mesh_linear", "guard_rigid", "generate_contacts", "create_grid_from_sdf", "create_grid_from_sdf (progress)",
    "extract_isosurface",
};

/* Runs entry point `call` on `u` (and `mesh`); returns its status. Objects it creates are destroyed. */
static sdfccd_Status run_sdf_call(int call, sdfccd_SdfId u, sdfccd_MeshId mesh, victim* v)
{
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_RigidMotion m = falling();
    sdfccd_Contact c[4];
    sdfccd_QueryResult r;
    sdfccd_Status st = SDFCCD_OK;
    switch (call) {
    case CALL_EVAL: {
        double val;
        sdfccd_Vec3 g;
        st = sdfccd_sdf_eval(u, (sdfccd_Vec3){ 0.5, 0.1, 0.2 }, &val, &g);
        break;
    }
    case CALL_EVAL_BATCH: {
        sdfccd_Vec3 pts[64];
        double val[64];
        for (int i = 0; i < 64; ++i) pts[i] = (sdfccd_Vec3){ 0.01 * i, 0.2, -0.1 };
        st = sdfccd_sdf_eval_batch(u, pts, 64, val, NULL);
        break;
    }
    case CALL_QUERY_TRIANGLE: st = sdfccd_query_triangle(u, NULL, k_tri, &m, 0, 1, &p, c, 4, &r); break;
    case CALL_QUERY_TRIANGLE_LINEAR: {
        sdfccd_Vec3 s[3], e[3];
        for (int i = 0; i < 3; ++i) {
            s[i] = k_tri[i];
            s[i].z += 0.8;
            e[i] = k_tri_end[i];
        }
        st = sdfccd_query_triangle_linear(u, NULL, s, e, 0, 1, &p, c, 4, &r);
        break;
    }
    case CALL_QUERY_MESH: st = sdfccd_query_mesh(u, NULL, mesh, &m, 0, 1, &p, c, 4, &r); break;
    case CALL_QUERY_MESH_WS: {
        sdfccd_Workspace* ws = NULL;
        ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
        st = sdfccd_query_mesh_ws(ws, u, NULL, mesh, &m, 0, 1, &p, c, 4, &r);
        sdfccd_destroy_workspace(ws);
        break;
    }
    case CALL_QUERY_MESH_LINEAR: {
        sdfccd_MeshInfo info;
        ck_assert_int_eq(sdfccd_mesh_get_info(mesh, &info), SDFCCD_OK);
        const uint32_t n = info.vertex_count;
        double* vd = malloc(sizeof(double) * 3 * n);
        sdfccd_Vec3* s = malloc(sizeof(sdfccd_Vec3) * n);
        sdfccd_Vec3* e = malloc(sizeof(sdfccd_Vec3) * n);
        ck_assert_int_eq(sdfccd_mesh_get_data(mesh, vd, NULL), SDFCCD_OK);
        for (uint32_t i = 0; i < n; ++i) {
            s[i] = (sdfccd_Vec3){ vd[3 * i], vd[3 * i + 1], vd[3 * i + 2] + 0.8 };
            e[i] = (sdfccd_Vec3){ vd[3 * i], vd[3 * i + 1], vd[3 * i + 2] - 0.2 };
        }
        st = sdfccd_query_mesh_linear(u, NULL, mesh, s, e, 0, 1, &p, c, 4, &r);
        free(vd);
        free(s);
        free(e);
        break;
    }
    case CALL_GUARD:
    case CALL_GENERATE_CONTACTS: {
        sdfccd_Workspace* ws = NULL;
        ck_assert_int_eq(sdfccd_create_workspace(&ws), SDFCCD_OK);
        if (call == CALL_GUARD) {
            sdfccd_GuardParams gp = sdfccd_default_guard_params();
            sdfccd_GuardResult gr;
            st = sdfccd_guard_rigid(ws, u, NULL, mesh, &m, 0, 1, &gp, &gr);
        } else {
            sdfccd_ContactParams cp = sdfccd_default_contact_params();
            sdfccd_ContactPoint pts[4];
            sdfccd_ContactSet set;
            st = sdfccd_generate_contacts(ws, u, NULL, mesh, &m, 0, 1, &cp, pts, 4, &set);
        }
        sdfccd_destroy_workspace(ws);
        break;
    }
    case CALL_GRID_FROM_SDF:
    case CALL_GRID_FROM_SDF_PROGRESS: {
        sdfccd_GridDef d = sdfccd_default_grid_def();
        d.resolution[0] = d.resolution[1] = d.resolution[2] = 6;
        d.threads = 1;
        if (call == CALL_GRID_FROM_SDF_PROGRESS) {
            d.progress = destroying_progress;
            d.progress_user = v;
        }
        sdfccd_SdfId g;
        st = sdfccd_create_grid_from_sdf(u, &d, &g);
        if (st == SDFCCD_OK) ck_assert_int_eq(sdfccd_destroy_sdf(g), SDFCCD_OK);
        break;
    }
    case CALL_EXTRACT: {
        sdfccd_MeshId out;
        sdfccd_Aabb box = { { -0.5, -0.5, -0.5 }, { 0.5, 0.5, 0.5 } };
        st = sdfccd_extract_isosurface(u, box, 8, &out);
        if (st == SDFCCD_OK) ck_assert_int_eq(sdfccd_destroy_mesh(out), SDFCCD_OK);
        break;
    }
    default: ck_abort();
    }
    return st;
}

/* The SDF handle is destroyed by the call's own callback: the call still completes with OK
 * (it holds the objects), the handle is dead afterwards, and everything is freed. */
START_TEST(test_destroy_sdf_inside_call)
{
    sdfccd_MeshId mesh = test_load_mesh("bullet3/cube.obj");
    sdfccd_MeshInfo mi;
    ck_assert_int_eq(sdfccd_mesh_get_info(mesh, &mi), SDFCCD_OK);
    const int64_t base = sdfccd_byte_count();
    for (int call = 0; call < CALL_COUNT; ++call) {
        victim v;
        memset(&v, 0, sizeof v);
        v.sdf = make_union(&v);
        v.armed_sdf = 1;
        const sdfccd_Status st = run_sdf_call(call, v.sdf, mesh, &v);
        ck_assert_msg(st == SDFCCD_OK, "%s: %s (%s)", k_call_names[call], sdfccd_status_string(st), sdfccd_last_error());
        ck_assert_msg(v.destroyed == 1, "%s: the callback did not run", k_call_names[call]);
        double val;
        ck_assert_int_eq(sdfccd_sdf_eval(v.sdf, (sdfccd_Vec3){ 0, 0, 0 }, &val, NULL), SDFCCD_INVALID_HANDLE);
        ck_assert_msg(sdfccd_byte_count() == base, "%s: %lld bytes not freed", k_call_names[call],
                      (long long)(sdfccd_byte_count() - base));
    }
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}
END_TEST

/* The same for the mesh handle: destroyed by the SDF callback during mesh queries, and by the
 * progress callback of a grid build from that mesh. */
START_TEST(test_destroy_mesh_inside_call)
{
    const int64_t base = sdfccd_byte_count();
    const int calls[] = { CALL_QUERY_MESH, CALL_QUERY_MESH_WS, CALL_QUERY_MESH_LINEAR, CALL_GUARD, CALL_GENERATE_CONTACTS };
    for (size_t k = 0; k < sizeof calls / sizeof calls[0]; ++k) {
        victim v;
        memset(&v, 0, sizeof v);
        sdfccd_SdfId u = make_union(&v);
        v.mesh = test_load_mesh("bullet3/cube.obj");
        v.armed_mesh = 1;
        const sdfccd_Status st = run_sdf_call(calls[k], u, v.mesh, &v);
        ck_assert_msg(st == SDFCCD_OK, "%s: %s (%s)", k_call_names[calls[k]], sdfccd_status_string(st), sdfccd_last_error());
        ck_assert_int_eq(v.destroyed, 1);
        sdfccd_MeshInfo info;
        ck_assert_int_eq(sdfccd_mesh_get_info(v.mesh, &info), SDFCCD_INVALID_HANDLE);
        ck_assert_int_eq(sdfccd_destroy_sdf(u), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_byte_count(), base);
    }
    victim v;
    memset(&v, 0, sizeof v);
    v.mesh = test_load_mesh("bullet3/cube.obj");
    v.armed_mesh = 1;
    sdfccd_GridDef d = sdfccd_default_grid_def();
    d.resolution[0] = d.resolution[1] = d.resolution[2] = 6;
    d.threads = 1;
    d.progress = destroying_progress;
    d.progress_user = &v;
    sdfccd_SdfId g;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(v.mesh, &d, &g), SDFCCD_OK);
    ck_assert_int_eq(v.destroyed, 1);
    ck_assert_int_eq(sdfccd_destroy_sdf(g), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_byte_count(), base);
}
END_TEST

/* ---------------- the race over every entry point ---------------- */

enum { RACE_THREADS = 3, RACE_ITERATIONS = 60 };

typedef struct race {
    sdfccd_SdfId sdf, grid;
    sdfccd_MeshId mesh;
    atomic_int ok, invalid, other;
    atomic_int started;
    char other_message[256];
} race;

typedef struct racer_arg { race* r; int index; } racer_arg;

static void tally(race* r, sdfccd_Status st, const char* what)
{
    if (st == SDFCCD_OK) r->ok++;
    else if (st == SDFCCD_INVALID_HANDLE) r->invalid++;
    else {
        r->other++;
        snprintf(r->other_message, sizeof r->other_message, "%s: %s (%s)", what, sdfccd_status_string(st), sdfccd_last_error());
    }
}

static void* race_everything(void* arg)
{
    racer_arg* a = arg;
    race* r = a->r;
    char path[512];
    snprintf(path, sizeof path, "%s/destroy_race_%d.cdf", SDFCCD_TEST_TMP_DIR, a->index);
    enum { N = 200 };
    sdfccd_Vec3 pts[N];
    double val[N];
    sdfccd_Vec3 closest[N];
    double* vd = malloc(sizeof(double) * 3 * 4096);
    uint32_t* id = malloc(sizeof(uint32_t) * 3 * 8192);
    for (int i = 0; i < N; ++i) pts[i] = (sdfccd_Vec3){ 0.004 * i - 0.4, 0.1, 0.05 };
    sdfccd_Workspace* ws = NULL; /* the guard and contact sets need one; it holds no handle */
    tally(r, sdfccd_create_workspace(&ws), "create_workspace");
    /* RACE_ITERATIONS rounds at least, then on until a destroy is seen: the main thread destroys
     * once every racer has finished a round, so this ends (under valgrind, which runs one thread
     * at a time, a fixed count could finish before the destroy). */
    for (int it = 0; it < RACE_ITERATIONS || (r->invalid == 0 && it < 1000000); ++it) {
        if (it == 1) r->started++; /* a whole round done: some calls were OK before any destroy */
        sdfccd_SdfInfo si;
        tally(r, sdfccd_sdf_get_info(r->sdf, &si), "sdf_get_info");
        tally(r, sdfccd_sdf_eval_batch(r->sdf, pts, N, val, NULL), "sdf_eval_batch");
        sdfccd_SdfId d;
        sdfccd_Status st = sdfccd_create_csg(SDFCCD_CSG_DIFFERENCE, r->sdf, r->grid, &d);
        tally(r, st, "create_csg");
        if (st == SDFCCD_OK) sdfccd_destroy_sdf(d);
        st = sdfccd_create_transformed(r->sdf, sdfccd_pose_identity(), 2.0, &d);
        tally(r, st, "create_transformed");
        if (st == SDFCCD_OK) sdfccd_destroy_sdf(d);
        sdfccd_GridInfo gi;
        tally(r, sdfccd_grid_get_info(r->grid, &gi), "grid_get_info");
        int32_t has;
        tally(r, sdfccd_grid_interpolate(r->grid, 0, (sdfccd_Vec3){ 0.1, 0.2, 0.05 }, val, NULL, &has), "grid_interpolate");
        sdfccd_Aabb box = { { -0.2, -0.2, -0.2 }, { 0.2, 0.2, 0.2 } };
        tally(r, sdfccd_grid_lipschitz_bound(r->grid, box, val), "grid_lipschitz_bound");
        tally(r, sdfccd_save_grid(r->grid, path), "save_grid");
        sdfccd_MeshId em;
        st = sdfccd_extract_isosurface(r->grid, box, 6, &em);
        tally(r, st, "extract_isosurface");
        if (st == SDFCCD_OK) sdfccd_destroy_mesh(em);
        sdfccd_MeshInfo mi;
        st = sdfccd_mesh_get_info(r->mesh, &mi);
        tally(r, st, "mesh_get_info");
        if (st == SDFCCD_OK && mi.vertex_count <= 4096 && mi.triangle_count <= 8192)
            tally(r, sdfccd_mesh_get_data(r->mesh, vd, id), "mesh_get_data");
        sdfccd_MeshTopology topo;
        tally(r, sdfccd_mesh_get_topology(r->mesh, &topo), "mesh_get_topology");
        tally(r, sdfccd_mesh_signed_distance(r->mesh, pts, N, 0, val, closest), "mesh_signed_distance");
        sdfccd_GridDef gd = sdfccd_default_grid_def();
        gd.resolution[0] = gd.resolution[1] = gd.resolution[2] = 4;
        gd.threads = 1;
        st = sdfccd_create_grid_from_mesh(r->mesh, &gd, &d);
        tally(r, st, "create_grid_from_mesh");
        if (st == SDFCCD_OK) sdfccd_destroy_sdf(d);
        st = sdfccd_create_grid_from_sdf(r->sdf, &gd, &d);
        tally(r, st, "create_grid_from_sdf");
        if (st == SDFCCD_OK) sdfccd_destroy_sdf(d);
        sdfccd_QueryParams p = sdfccd_default_query_params();
        sdfccd_RigidMotion m = falling();
        sdfccd_Contact c[4];
        sdfccd_QueryResult res;
        tally(r, sdfccd_query_mesh(r->grid, NULL, r->mesh, &m, 0, 1, &p, c, 4, &res), "query_mesh");
        sdfccd_GuardParams gp = sdfccd_default_guard_params();
        sdfccd_GuardResult gr;
        tally(r, sdfccd_guard_rigid(ws, r->sdf, NULL, r->mesh, &m, 0, 1, &gp, &gr), "guard_rigid");
        sdfccd_ContactParams cp = sdfccd_default_contact_params();
        sdfccd_ContactPoint cpts[4];
        sdfccd_ContactSet set;
        tally(r, sdfccd_generate_contacts(ws, r->grid, NULL, r->mesh, &m, 0, 1, &cp, cpts, 4, &set), "generate_contacts");
    }
    sdfccd_destroy_workspace(ws);
    free(vd);
    free(id);
    remove(path);
    return NULL;
}

START_TEST(test_destroy_while_calling)
{
    const int64_t base = sdfccd_byte_count();
    int invalid_total = 0;
    for (int round = 0; round < 4; ++round) {
        race r;
        memset(&r, 0, sizeof r);
        sdfccd_SdfId a, b;
        ck_assert_int_eq(sdfccd_create_sphere(0.3, &a), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_create_torus(0.3, 0.08, &b), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, a, b, &r.sdf), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_destroy_sdf(a), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_destroy_sdf(b), SDFCCD_OK);
        sdfccd_GridDef gd = sdfccd_default_grid_def();
        gd.resolution[0] = gd.resolution[1] = gd.resolution[2] = 8;
        gd.padding = 0.1;
        ck_assert_int_eq(sdfccd_create_grid_from_sdf(r.sdf, &gd, &r.grid), SDFCCD_OK);
        r.mesh = test_load_mesh("bullet3/cube.obj");
        pthread_t t[RACE_THREADS];
        racer_arg args[RACE_THREADS];
        for (int i = 0; i < RACE_THREADS; ++i) {
            args[i] = (racer_arg){ &r, i };
            ck_assert_int_eq(pthread_create(&t[i], NULL, race_everything, &args[i]), 0);
        }
        while (r.started < RACE_THREADS) {
            struct timespec ts = { 0, 100000L };
            nanosleep(&ts, NULL);
        }
        /* destroy the three handles under the running calls, at a different moment each round */
        struct timespec ts = { 0, 1000000L * (round + 1) };
        nanosleep(&ts, NULL);
        ck_assert_int_eq(sdfccd_destroy_mesh(r.mesh), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_destroy_sdf(r.grid), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_destroy_sdf(r.sdf), SDFCCD_OK);
        for (int i = 0; i < RACE_THREADS; ++i) pthread_join(t[i], NULL);
        ck_assert_msg(r.other == 0, "%d calls returned another status; last: %s", (int)r.other, r.other_message);
        ck_assert_int_gt(r.ok, 0);
        invalid_total += r.invalid;
        ck_assert_int_eq(sdfccd_byte_count(), base);
    }
    ck_assert_int_gt(invalid_total, 0); /* the destroys were seen by calls still running */
}
END_TEST

int main(void)
{
    Suite* s = suite_create("destroy");
    TCase* tc = tcase_create("in_flight");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_destroy_sdf_inside_call);
    tcase_add_test(tc, test_destroy_mesh_inside_call);
    tcase_add_test(tc, test_destroy_while_calling);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
