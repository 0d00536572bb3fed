/* SPDX-License-Identifier: MIT
 * sdfccd_query_batch (issue 9): a mixed batch of triangle and mesh queries (rigid and linear)
 * gives results bitwise identical to the single queries run one by one, with 1, 2 and 3
 * threads; a failing query reports its status without disturbing the others. Public ABI only. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

#define N 48
#define CAP 16

static sdfccd_MeshId box_mesh(double h)
{
    double v[24];
    for (int i = 0; i < 8; ++i) {
        v[3 * i] = (i & 1) ? h : -h;
        v[3 * i + 1] = (i & 2) ? h : -h;
        v[3 * i + 2] = (i & 4) ? h : -h;
    }
    uint32_t f[36] = { 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5 };
    sdfccd_MeshDef d = sdfccd_default_mesh_def();
    d.vertices = v;
    d.vertex_count = 8;
    d.indices = f;
    d.triangle_count = 12;
    sdfccd_MeshId id;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &id), SDFCCD_OK);
    return id;
}

typedef struct inputs {
    sdfccd_RigidMotion motion[N];
    sdfccd_Vec3 tri[N][3], tri_end[N][3];
    sdfccd_Vec3 start[N][8], end[N][8];
} inputs;

static void set_coord(sdfccd_Vec3* v, int c, double x)
{
    if (c == 0) v->x = x;
    else if (c == 1) v->y = x;
    else v->z = x;
}

static void make_inputs(inputs* in)
{
    test_rng r = { 7 };
    for (int i = 0; i < N; ++i) {
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        sdfccd_Vec3 u = test_rng_unit_vector(&r);
        m.pose.position = (sdfccd_Vec3){ 0.3 * u.x, 0.3 * u.y, 0.3 * u.z };
        double s = 60.0 * test_rng_uniform(&r, 1.0, 2.0);
        sdfccd_Vec3 aim = test_rng_unit_vector(&r);
        m.linear_velocity = (sdfccd_Vec3){ (0.08 * aim.x - m.pose.position.x) * s, (0.08 * aim.y - m.pose.position.y) * s,
                                           (0.08 * aim.z - m.pose.position.z) * s };
        sdfccd_Vec3 w = test_rng_unit_vector(&r);
        double wm = test_rng_uniform(&r, 0.0, 60.0);
        m.angular_velocity = (sdfccd_Vec3){ w.x * wm, w.y * wm, w.z * wm };
        in->motion[i] = m;
        for (int k = 0; k < 3; ++k) {
            sdfccd_Vec3 a = test_rng_unit_vector(&r);
            in->tri[i][k] = (sdfccd_Vec3){ 0.04 * a.x, 0.04 * a.y, 0.04 * a.z };
            in->tri_end[i][k] = (sdfccd_Vec3){ 0.04 * a.x + 0.1 * aim.x, 0.04 * a.y + 0.1 * aim.y, 0.04 * a.z + 0.1 * aim.z };
            in->tri[i][k].x += m.pose.position.x;
            in->tri[i][k].y += m.pose.position.y;
            in->tri[i][k].z += m.pose.position.z;
        }
        for (int v = 0; v < 8; ++v)
            for (int c = 0; c < 3; ++c) {
                double x = ((v >> c) & 1) ? 0.03 : -0.03;
                double p0 = c == 0 ? m.pose.position.x : (c == 1 ? m.pose.position.y : m.pose.position.z);
                double a = c == 0 ? aim.x : (c == 1 ? aim.y : aim.z);
                set_coord(&in->start[i][v], c, p0 + x);
                set_coord(&in->end[i][v], c, 0.08 * a + 1.2 * x);
            }
    }
}

typedef struct outputs {
    sdfccd_QueryResult r[N];
    sdfccd_Contact c[N][CAP];
    sdfccd_Status st[N];
} outputs;

static void fill(sdfccd_BatchQuery* q, const inputs* in, outputs* out, sdfccd_SdfId sdf, sdfccd_MeshId mesh, const sdfccd_QueryParams* p)
{
    memset(out, 0, sizeof *out);
    for (int i = 0; i < N; ++i) {
        memset(&q[i], 0, sizeof q[i]);
        q[i].kind = (sdfccd_BatchKind)(i % 4);
        q[i].sdf = sdf;
        q[i].mesh = mesh;
        q[i].triangle = in->tri[i];
        q[i].triangle_end = in->tri_end[i];
        q[i].start = in->start[i];
        q[i].end = in->end[i];
        q[i].motion = &in->motion[i];
        q[i].t0 = 0.0;
        q[i].t1 = 1.0 / 60.0;
        q[i].params = p;
        q[i].out_contacts = out->c[i];
        q[i].capacity = CAP;
        q[i].out_result = &out->r[i];
    }
}

START_TEST(test_batch_matches_single_queries)
{
    sdfccd_SdfId torus;
    ck_assert_int_eq(sdfccd_create_torus(0.1, 0.05, &torus), SDFCCD_OK);
    sdfccd_MeshId mesh = box_mesh(0.03);
    sdfccd_QueryParams p = sdfccd_default_query_params();
    static inputs in;
    static outputs ref, got;
    make_inputs(&in);
    sdfccd_BatchQuery q[N];
    /* the reference: each query by itself, through the single-query functions */
    fill(q, &in, &ref, torus, mesh, &p);
    int hits = 0;
    for (int i = 0; i < N; ++i) {
        sdfccd_BatchQuery* b = &q[i];
        switch (b->kind) {
        case SDFCCD_BATCH_TRIANGLE:
            ref.st[i] = sdfccd_query_triangle(torus, NULL, b->triangle, b->motion, b->t0, b->t1, &p, ref.c[i], CAP, &ref.r[i]);
            break;
        case SDFCCD_BATCH_TRIANGLE_LINEAR:
            ref.st[i] = sdfccd_query_triangle_linear(torus, NULL, b->triangle, b->triangle_end, b->t0, b->t1, &p, ref.c[i], CAP, &ref.r[i]);
            break;
        case SDFCCD_BATCH_MESH:
            ref.st[i] = sdfccd_query_mesh(torus, NULL, mesh, b->motion, b->t0, b->t1, &p, ref.c[i], CAP, &ref.r[i]);
            break;
        default:
            ref.st[i] = sdfccd_query_mesh_linear(torus, NULL, mesh, b->start, b->end, b->t0, b->t1, &p, ref.c[i], CAP, &ref.r[i]);
        }
        ck_assert_int_eq(ref.st[i], SDFCCD_OK);
        hits += ref.r[i].hit;
    }
    ck_assert_int_gt(hits, N / 4);
    for (int threads = 1; threads <= 3; ++threads) {
        fill(q, &in, &got, torus, mesh, &p);
        ck_assert_int_eq(sdfccd_query_batch(q, N, threads), SDFCCD_OK);
        for (int i = 0; i < N; ++i) {
            ck_assert_int_eq(q[i].status, SDFCCD_OK);
            ck_assert_msg(memcmp(&got.r[i], &ref.r[i], sizeof ref.r[i]) == 0, "query %d (kind %d) differs with %d threads", i, (int)q[i].kind, threads);
            ck_assert(memcmp(got.c[i], ref.c[i], (size_t)ref.r[i].contact_count * sizeof ref.c[i][0]) == 0);
        }
    }
    printf("batch: %d queries (%d hits) identical to the single queries with 1, 2 and 3 threads\n", N, hits);

    /* one bad query: its status and message; the others are still answered */
    fill(q, &in, &got, torus, mesh, &p);
    q[5].t1 = -1.0;
    ck_assert_int_eq(sdfccd_query_batch(q, N, 2), SDFCCD_INVALID_ARGUMENT);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "query 5"));
    ck_assert_int_eq(q[5].status, SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(q[6].status, SDFCCD_OK);
    ck_assert(memcmp(&got.r[6], &ref.r[6], sizeof ref.r[6]) == 0);
    ck_assert_int_eq(sdfccd_query_batch(q, N, 0), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_query_batch(NULL, 3, 1), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_query_batch(NULL, 0, 1), SDFCCD_OK);
    sdfccd_destroy_mesh(mesh);
    sdfccd_destroy_sdf(torus);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("batch");
    TCase* tc = tcase_create("determinism");
    test_add_memory_fixture(tc);
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_batch_matches_single_queries);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
