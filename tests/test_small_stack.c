/* SPDX-License-Identifier: MIT
 * Queries on fields with kinks (a box, a box rounded by a sphere, a grid of a box minus a ball),
 * where FWGSS's answers are checked by the certified search, on a thread with a 64 KB stack (a job
 * system's fibre): through a workspace, and without one, the same answers as on the main thread.
 * The check's scratch (its region store, sample and cell caches) lives in the workspace, not on the
 * stack (certified.c). Public ABI only. */
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

#define QUERIES 24
#define CONTACTS 8
#ifndef SMALL_STACK
#define SMALL_STACK (64 * 1024)
#endif

typedef struct run {
    sdfccd_SdfId sdf;
    sdfccd_MeshId mesh;
    const sdfccd_RigidMotion* motions;
    sdfccd_QueryParams p;
    int use_workspace;
    sdfccd_Status status;
    sdfccd_QueryResult r[QUERIES];
    sdfccd_Contact c[QUERIES][CONTACTS];
} run;

static void* run_queries(void* arg)
{
    run* x = arg;
    sdfccd_Workspace* ws = NULL;
    x->status = x->use_workspace ? sdfccd_create_workspace(&ws) : SDFCCD_OK;
    for (int i = 0; i < QUERIES && x->status == SDFCCD_OK; ++i) {
        memset(x->c[i], 0, sizeof x->c[i]);
        x->status = ws ? sdfccd_query_mesh_ws(ws, x->sdf, NULL, x->mesh, &x->motions[i], 0.0, 1.0 / 60.0, &x->p, x->c[i], CONTACTS, &x->r[i])
                       : sdfccd_query_mesh(x->sdf, NULL, x->mesh, &x->motions[i], 0.0, 1.0 / 60.0, &x->p, x->c[i], CONTACTS, &x->r[i]);
    }
    sdfccd_destroy_workspace(ws);
    return NULL;
}

/* `x` run on a new thread with a stack of SMALL_STACK bytes (PTHREAD_STACK_MIN if larger) */
static void run_on_small_stack(run* x)
{
    pthread_attr_t a;
    ck_assert_int_eq(pthread_attr_init(&a), 0);
    size_t size = SMALL_STACK < PTHREAD_STACK_MIN ? PTHREAD_STACK_MIN : SMALL_STACK;
    ck_assert_int_eq(pthread_attr_setstacksize(&a, size), 0);
    pthread_t th;
    ck_assert_int_eq(pthread_create(&th, &a, run_queries, x), 0);
    ck_assert_int_eq(pthread_join(th, NULL), 0);
    pthread_attr_destroy(&a);
}

static void same_results(const run* a, const run* b, const char* what)
{
    for (int i = 0; i < QUERIES; ++i) {
        ck_assert_msg(a->r[i].state == b->r[i].state && a->r[i].hit == b->r[i].hit && a->r[i].toi == b->r[i].toi &&
                          a->r[i].toi_lower == b->r[i].toi_lower && a->r[i].sdf_evaluations == b->r[i].sdf_evaluations &&
                          a->r[i].contact_count == b->r[i].contact_count,
                      "%s: query %d differs from the main thread's", what, i);
        ck_assert(memcmp(a->c[i], b->c[i], (size_t)a->r[i].contact_count * sizeof a->c[i][0]) == 0);
    }
}

/* Motions from 0.3 m away aimed at the field's surface, fast enough to reach it within the step. */
static void make_motions(sdfccd_RigidMotion* mo, uint64_t seed)
{
    test_rng r = { seed };
    for (int i = 0; i < QUERIES; ++i) {
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        sdfccd_Vec3 u = test_rng_unit_vector(&r), aim = test_rng_unit_vector(&r), w = test_rng_unit_vector(&r);
        m.pose.position = (sdfccd_Vec3){ 0.3 * u.x, 0.3 * u.y, 0.3 * u.z };
        const double s = 60.0 * test_rng_uniform(&r, 1.0, 2.0), wm = test_rng_uniform(&r, 0.0, 30.0);
        m.linear_velocity = (sdfccd_Vec3){ (0.08 * aim.x - m.pose.position.x) * s, (0.08 * aim.y - m.pose.position.y) * s,
                                           (0.08 * aim.z - m.pose.position.z) * s };
        m.angular_velocity = (sdfccd_Vec3){ w.x * wm, w.y * wm, w.z * wm };
        mo[i] = m;
    }
}

/* The field's queries on the main thread, then on a small-stack thread through a workspace and
 * without one: identical. The check must have run (evaluations differ from fwgss_verify 0). */
static void check_field(sdfccd_SdfId sdf, const char* name)
{
    static run ref, off, on_ws, on_tmp;
    static sdfccd_RigidMotion mo[QUERIES];
    make_motions(mo, 7);
    sdfccd_MeshId mesh = test_box_mesh((sdfccd_Vec3){ 0.03, 0.02, 0.01 }, 2, 2, 1);
    memset(&ref, 0, sizeof ref);
    ref.sdf = sdf;
    ref.mesh = mesh;
    ref.motions = mo;
    ref.p = sdfccd_default_query_params();
    ref.use_workspace = 1;
    off = on_ws = on_tmp = ref;
    off.p.fwgss_verify = 0;
    on_tmp.use_workspace = 0;
    run_queries(&ref);
    run_queries(&off);
    ck_assert_int_eq(ref.status, SDFCCD_OK);
    ck_assert_int_eq(off.status, SDFCCD_OK);
    int hits = 0, checked = 0;
    for (int i = 0; i < QUERIES; ++i) {
        hits += ref.r[i].hit;
        checked += ref.r[i].sdf_evaluations != off.r[i].sdf_evaluations;
    }
    printf("%s: %d of %d queries hit, the check ran in %d\n", name, hits, QUERIES, checked);
    ck_assert_int_gt(hits, 0);
    ck_assert_int_gt(checked, 0);
    run_on_small_stack(&on_ws);
    ck_assert_int_eq(on_ws.status, SDFCCD_OK);
    same_results(&ref, &on_ws, name);
    run_on_small_stack(&on_tmp);
    ck_assert_int_eq(on_tmp.status, SDFCCD_OK);
    same_results(&ref, &on_tmp, name);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}

START_TEST(test_box_on_small_stack)
{
    sdfccd_SdfId box;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.1, 0.08, 0.06 }, &box), SDFCCD_OK);
    check_field(box, "box");
    ck_assert_int_eq(sdfccd_destroy_sdf(box), SDFCCD_OK);
}
END_TEST

START_TEST(test_csg_on_small_stack)
{
    sdfccd_SdfId box, ball, rounded;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.1, 0.1, 0.1 }, &box), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_sphere(0.13, &ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_INTERSECTION, box, ball, &rounded), SDFCCD_OK);
    check_field(rounded, "csg-intersection");
    ck_assert_int_eq(sdfccd_destroy_sdf(rounded), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(box), SDFCCD_OK);
}
END_TEST

START_TEST(test_grid_on_small_stack)
{
    const sdfccd_SdfId grid = test_carved_box_grid();
    check_field(grid, "grid of a box minus a ball");
    ck_assert_int_eq(sdfccd_destroy_sdf(grid), SDFCCD_OK);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("small_stack");
    TCase* tc = tcase_create("kinked");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_box_on_small_stack);
    tcase_add_test(tc, test_csg_on_small_stack);
    tcase_add_test(tc, test_grid_on_small_stack);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
