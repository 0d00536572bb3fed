/* SPDX-License-Identifier: MIT
 * The threading contract of base.h: queries on the same SDF and mesh handles from several threads
 * at once give bit-identical results to a single-threaded run; error messages are per thread;
 * creating and destroying handles concurrently keeps the registry and the byte count consistent. */
#include <pthread.h>
#include <string.h>
#include "test_util.h"

#define DT (1.0 / 60.0)
#define QUERIES 300
#define THREADS 4

typedef struct job {
    sdfccd_SdfId sdf;
    sdfccd_MeshId mesh;
    sdfccd_QueryResult results[QUERIES];
    sdfccd_Contact contacts[QUERIES];
} job;

static void make_motion(int i, sdfccd_RigidMotion* m)
{
    test_rng rng = { 1000u + (uint64_t)i };
    *m = sdfccd_default_rigid_motion();
    sdfccd_Vec3 d = test_rng_unit_vector(&rng);
    m->pose.position = (sdfccd_Vec3){ 0.3 * d.x, 0.3 * d.y, 0.3 * d.z };
    m->linear_velocity = (sdfccd_Vec3){ -30 * d.x + test_rng_uniform(&rng, -3, 3), -30 * d.y, -30 * d.z };
    sdfccd_Vec3 w = test_rng_unit_vector(&rng);
    m->angular_velocity = (sdfccd_Vec3){ 40 * w.x, 40 * w.y, 40 * w.z };
}

static void* run_job(void* arg)
{
    job* j = arg;
    sdfccd_QueryParams p = sdfccd_default_query_params();
    for (int i = 0; i < QUERIES; ++i) {
        sdfccd_RigidMotion m;
        make_motion(i, &m);
        memset(&j->contacts[i], 0, sizeof j->contacts[i]);
        if (sdfccd_query_mesh(j->sdf, NULL, j->mesh, &m, 0.0, DT, &p, &j->contacts[i], 1, &j->results[i]) != SDFCCD_OK) return arg;
    }
    return NULL;
}

START_TEST(test_concurrent_queries)
{
    sdfccd_SdfId torus, ball, scene;
    ck_assert_int_eq(sdfccd_create_torus(0.1, 0.05, &torus), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_sphere(0.04, &ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, torus, ball, &scene), SDFCCD_OK);
    const double v[4][3] = { { 0.03, 0, 0 }, { -0.02, 0.03, 0 }, { -0.02, -0.03, 0 }, { 0, 0, 0.03 } };
    const uint32_t idx[12] = { 0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0 };
    sdfccd_MeshDef def = sdfccd_default_mesh_def();
    def.vertices = &v[0][0];
    def.vertex_count = 4;
    def.indices = idx;
    def.triangle_count = 4;
    sdfccd_MeshId mesh;
    ck_assert_int_eq(sdfccd_create_mesh(&def, &mesh), SDFCCD_OK);

    static job reference, jobs[THREADS];
    reference.sdf = scene;
    reference.mesh = mesh;
    ck_assert_ptr_null(run_job(&reference));
    int hits = 0;
    for (int i = 0; i < QUERIES; ++i) hits += reference.results[i].hit;
    ck_assert_int_gt(hits, QUERIES / 4); /* the comparison below is about real contacts */

    pthread_t th[THREADS];
    for (int k = 0; k < THREADS; ++k) {
        jobs[k].sdf = scene;
        jobs[k].mesh = mesh;
        ck_assert_int_eq(pthread_create(&th[k], NULL, run_job, &jobs[k]), 0);
    }
    for (int k = 0; k < THREADS; ++k) {
        void* ret;
        ck_assert_int_eq(pthread_join(th[k], &ret), 0);
        ck_assert_ptr_null(ret);
        for (int i = 0; i < QUERIES; ++i) {
            const sdfccd_QueryResult* a = &reference.results[i];
            const sdfccd_QueryResult* b = &jobs[k].results[i];
            ck_assert_int_eq(a->hit, b->hit);
            ck_assert_int_eq(a->state, b->state);
            ck_assert_msg(a->toi == b->toi, "thread %d query %d: toi %.17g vs %.17g", k, i, b->toi, a->toi);
            ck_assert_int_eq(a->sdf_evaluations, b->sdf_evaluations);
            ck_assert(!memcmp(&reference.contacts[i], &jobs[k].contacts[i], sizeof(sdfccd_Contact)));
        }
    }
    sdfccd_destroy_mesh(mesh);
    sdfccd_destroy_sdf(scene);
    sdfccd_destroy_sdf(ball);
    sdfccd_destroy_sdf(torus);
}
END_TEST

/* Each thread sees only its own last error; handles created and destroyed concurrently. */
static void* churn(void* arg)
{
    int id = (int)(intptr_t)arg;
    for (int i = 0; i < 2000; ++i) {
        sdfccd_SdfId s;
        if (sdfccd_create_sphere(1.0 + id, &s) != SDFCCD_OK) return (void*)1;
        double val;
        if (sdfccd_sdf_eval(s, (sdfccd_Vec3){ 3, 0, 0 }, &val, NULL) != SDFCCD_OK || val != 2.0 - id) return (void*)2;
        if (sdfccd_destroy_sdf(s) != SDFCCD_OK) return (void*)3;
        if (sdfccd_destroy_sdf(s) != SDFCCD_INVALID_HANDLE) return (void*)4; /* stale now */
        if (id == 0 && sdfccd_create_sphere(-1.0, &s) != SDFCCD_INVALID_ARGUMENT) return (void*)5;
        /* Thread 0's failures must not show in the other threads' messages, and vice versa. */
        const char* msg = sdfccd_last_error();
        if (id == 0 && !strstr(msg, "radius")) return (void*)6;
        if (id != 0 && !strstr(msg, "not a live SDF")) return (void*)7;
    }
    return NULL;
}

START_TEST(test_concurrent_handles_and_errors)
{
    pthread_t th[THREADS];
    for (int k = 0; k < THREADS; ++k) ck_assert_int_eq(pthread_create(&th[k], NULL, churn, (void*)(intptr_t)k), 0);
    for (int k = 0; k < THREADS; ++k) {
        void* ret;
        ck_assert_int_eq(pthread_join(th[k], &ret), 0);
        ck_assert_msg(ret == NULL, "thread %d failed at check %ld", k, (long)(intptr_t)ret);
    }
}
END_TEST

int main(void)
{
    Suite* s = suite_create("threads");
    TCase* tc = tcase_create("contract");
    tcase_set_timeout(tc, 300);
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_concurrent_queries);
    tcase_add_test(tc, test_concurrent_handles_and_errors);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
