/* SPDX-License-Identifier: MIT
 * The C ABI's contract: every bad input returns its status with a message and writes nothing;
 * the user allocator sees every byte and the count returns to zero; version and configuration
 * queries; handles are generation-checked. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

#define DT (1.0 / 60.0)

static const sdfccd_Vec3 k_tri[3] = { { 0, 0, 0.3 }, { 0.1, 0, 0.3 }, { 0, 0.1, 0.3 } };

START_TEST(test_version_and_config)
{
    ck_assert_int_eq(sdfccd_version(), SDFCCD_VERSION_ID);
    ck_assert_str_eq(sdfccd_version_string(), "0.1.0");
    ck_assert_int_eq(sdfccd_is_double_precision(), 1);
    ck_assert_ptr_nonnull(strstr(sdfccd_configuration_string(), "scalar=double"));
    ck_assert_str_eq(sdfccd_status_string(SDFCCD_DEGENERATE), "SDFCCD_DEGENERATE");
    ck_assert_str_eq(sdfccd_status_string((sdfccd_Status)999), "SDFCCD_UNKNOWN_STATUS");
}
END_TEST

/* Every bad input to the triangle query returns its status, sets a message, and leaves the
 * result untouched. */
START_TEST(test_query_bad_inputs)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(0.2, &s), SDFCCD_OK);
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity.z = -10;
    sdfccd_QueryResult r;
    memset(&r, 0xAB, sizeof r);
    sdfccd_QueryResult untouched = r;
    sdfccd_Contact c[4];
#define EXPECT(call, status)                                                    \
    do {                                                                        \
        ck_assert_int_eq((call), (status));                                     \
        ck_assert_msg(sdfccd_last_error()[0] != '\0', "no message for " #call); \
        ck_assert_msg(!memcmp(&r, &untouched, sizeof r), "result written by " #call); \
    } while (0)
    sdfccd_Vec3 nan_tri[3] = { { NAN, 0, 0 }, { 0.1, 0, 0 }, { 0, 0.1, 0 } };
    EXPECT(sdfccd_query_triangle(s, NULL, nan_tri, &m, 0, DT, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_Vec3 inf_tri[3] = { { 0, 0, 0 }, { INFINITY, 0, 0 }, { 0, 0.1, 0 } };
    EXPECT(sdfccd_query_triangle(s, NULL, inf_tri, &m, 0, DT, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_Vec3 line[3] = { { 0, 0, 0 }, { 0.1, 0, 0 }, { 0.2, 0, 0 } };
    EXPECT(sdfccd_query_triangle(s, NULL, line, &m, 0, DT, &p, c, 4, &r), SDFCCD_DEGENERATE);
    sdfccd_Vec3 point[3] = { { 1, 1, 1 }, { 1, 1, 1 }, { 1, 1, 1 } };
    EXPECT(sdfccd_query_triangle(s, NULL, point, &m, 0, DT, &p, c, 4, &r), SDFCCD_DEGENERATE);
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, DT, 0, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT); /* t1 < t0 */
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, NAN, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_RigidMotion bad = m;
    bad.angular_velocity.y = NAN;
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &bad, 0, DT, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    bad = m;
    bad.pose.orientation = (sdfccd_Quat){ 0, 0, 0, 0 };
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &bad, 0, DT, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_query_triangle(s, &bad, k_tri, &m, 0, DT, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT); /* bad SDF motion */
    EXPECT(sdfccd_query_triangle(s, NULL, NULL, &m, 0, DT, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, NULL, 0, DT, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, NULL, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &p, NULL, 4, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &p, c, -1, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &p, c, 4, NULL), SDFCCD_INVALID_ARGUMENT);
    sdfccd_QueryParams raw;
    memset(&raw, 0, sizeof raw);
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &raw, c, 4, &r), SDFCCD_INVALID_ARGUMENT); /* not from the default */
    sdfccd_QueryParams bp = p;
    bp.time_tolerance = 0.0;
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &bp, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    bp = p;
    bp.max_iterations = 0;
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &bp, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    bp = p;
    bp.method = (sdfccd_Method)42;
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &bp, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    bp = p;
    bp.margin = NAN;
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &bp, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    bp = p;
    bp.fwgss_gap_tolerance = -0.5;
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &bp, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    bp.fwgss_gap_tolerance = NAN;
    EXPECT(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &bp, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_SdfId unknown = { 999, 3 };
    EXPECT(sdfccd_query_triangle(unknown, NULL, k_tri, &m, 0, DT, &p, c, 4, &r), SDFCCD_INVALID_HANDLE);
    sdfccd_Vec3 end[3] = { { 0, 0, NAN }, { 0.1, 0, 0 }, { 0, 0.1, 0 } };
    EXPECT(sdfccd_query_triangle_linear(s, NULL, k_tri, end, 0, DT, &p, c, 4, &r), SDFCCD_INVALID_ARGUMENT);
    EXPECT(sdfccd_query_triangle_linear(s, NULL, line, k_tri, 0, DT, &p, c, 4, &r), SDFCCD_DEGENERATE);
    /* A valid call still works, and a zero-length interval is allowed. */
    ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0, DT, &p, c, 4, &r), SDFCCD_OK);
    ck_assert(r.hit);
    ck_assert_int_eq(sdfccd_query_triangle(s, NULL, k_tri, &m, 0.5, 0.5, &p, c, 4, &r), SDFCCD_OK);
    ck_assert(!r.hit);
    ck_assert_double_eq(r.fraction, 0.0);
    sdfccd_destroy_sdf(s);
#undef EXPECT
}
END_TEST

START_TEST(test_mesh_bad_inputs)
{
    const double v[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 2, 0, 0 } };
    const uint32_t good[3] = { 0, 1, 2 }, degenerate[6] = { 0, 1, 2, 0, 1, 3 }, out_of_range[3] = { 0, 1, 7 };
    sdfccd_MeshDef d = sdfccd_default_mesh_def();
    sdfccd_MeshId mesh = { 0, 0 };
    ck_assert_int_eq(sdfccd_create_mesh(&d, &mesh), SDFCCD_INVALID_ARGUMENT); /* no arrays */
    d.vertices = &v[0][0];
    d.vertex_count = 4;
    d.indices = good;
    d.triangle_count = 0;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &mesh), SDFCCD_DEGENERATE); /* empty */
    d.triangle_count = 1;
    d.indices = out_of_range;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &mesh), SDFCCD_INVALID_ARGUMENT);
    d.indices = degenerate;
    d.triangle_count = 2;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &mesh), SDFCCD_DEGENERATE);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "triangle 1"));
    d.drop_degenerate = 1;
    ck_assert_int_eq(sdfccd_create_mesh(&d, &mesh), SDFCCD_OK);
    sdfccd_MeshInfo info;
    ck_assert_int_eq(sdfccd_mesh_get_info(mesh, &info), SDFCCD_OK);
    ck_assert_int_eq(info.triangle_count, 1);
    ck_assert_int_eq(info.dropped_triangles, 1);
    double nanv[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, NAN, 0 }, { 2, 0, 0 } };
    sdfccd_MeshDef dn = d;
    dn.vertices = &nanv[0][0];
    sdfccd_MeshId other;
    ck_assert_int_eq(sdfccd_create_mesh(&dn, &other), SDFCCD_INVALID_ARGUMENT);
    sdfccd_MeshDef raw;
    memset(&raw, 0, sizeof raw);
    ck_assert_int_eq(sdfccd_create_mesh(&raw, &other), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_mesh(NULL, &other), SDFCCD_INVALID_ARGUMENT);
    /* Mesh queries: handles, NULL motion, non-finite per-vertex positions. */
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(0.5, &s), SDFCCD_OK);
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    sdfccd_QueryResult r;
    sdfccd_MeshId stale = mesh;
    ck_assert_int_eq(sdfccd_query_mesh(s, NULL, mesh, NULL, 0, DT, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    sdfccd_MeshId as_mesh = { s.index1, s.generation }; /* an SDF handle is not a mesh */
    ck_assert_int_eq(sdfccd_query_mesh(s, NULL, as_mesh, &m, 0, DT, &p, NULL, 0, &r), SDFCCD_INVALID_HANDLE);
    sdfccd_Vec3 start[4] = { { 0, 0, 0 } }, endp[4] = { { 0, 0, 0 } };
    start[1].y = NAN;
    ck_assert_int_eq(sdfccd_query_mesh_linear(s, NULL, mesh, start, endp, 0, DT, &p, NULL, 0, &r), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_query_mesh(s, NULL, stale, &m, 0, DT, &p, NULL, 0, &r), SDFCCD_INVALID_HANDLE);
    ck_assert_int_eq(sdfccd_destroy_mesh(stale), SDFCCD_INVALID_HANDLE);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* The two calls on a batch of points (sdfccd_sdf_eval_batch, sdfccd_mesh_signed_distance) check
 * count, the arrays and every point before writing anything, with the messages they had before
 * the checks were shared. */
START_TEST(test_point_batch_bad_inputs)
{
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(0.5, &s), SDFCCD_OK);
    sdfccd_MeshId mesh = test_load_mesh("bullet3/cube.obj"); /* the cube [-0.5, 0.5]^3 */
    sdfccd_Vec3 p[3] = { { 0.1, 0.1, 0.1 }, { 2, 0, 0 }, { 0, 0, 3 } };
    double out[3] = { 7, 7, 7 };
    ck_assert_int_eq(sdfccd_sdf_eval_batch(s, NULL, 0, NULL, NULL), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_mesh_signed_distance(mesh, NULL, 0, 1, NULL, NULL), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_sdf_eval_batch(s, p, -2, out, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_sdf_eval_batch: count = -2 < 0");
    ck_assert_int_eq(sdfccd_mesh_signed_distance(mesh, p, -2, 1, out, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_mesh_signed_distance: count = -2 < 0");
    ck_assert_int_eq(sdfccd_sdf_eval_batch(s, NULL, 3, out, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_sdf_eval_batch: points is NULL");
    ck_assert_int_eq(sdfccd_mesh_signed_distance(mesh, NULL, 3, 1, out, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_mesh_signed_distance: points is NULL");
    ck_assert_int_eq(sdfccd_sdf_eval_batch(s, p, 3, NULL, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_sdf_eval_batch: out_values is NULL");
    ck_assert_int_eq(sdfccd_mesh_signed_distance(mesh, p, 3, 1, NULL, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_mesh_signed_distance: out_distances is NULL");
    p[2].z = INFINITY;
    ck_assert_int_eq(sdfccd_sdf_eval_batch(s, p, 3, out, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_sdf_eval_batch: a point is not finite (0, 0, inf)");
    ck_assert_int_eq(sdfccd_mesh_signed_distance(mesh, p, 3, 1, out, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_str_eq(sdfccd_last_error(), "sdfccd_mesh_signed_distance: a point is not finite (0, 0, inf)");
    ck_assert(out[0] == 7 && out[1] == 7 && out[2] == 7); /* nothing written */
    ck_assert_int_eq(sdfccd_mesh_signed_distance(mesh, p, 2, 1, out, NULL), SDFCCD_OK); /* the finite ones */
    ck_assert_double_near(out[1], 1.5, 1e-12); /* (2, 0, 0) is 1.5 outside the face x = 0.5 */
    sdfccd_destroy_mesh(mesh);
    sdfccd_destroy_sdf(s);
}
END_TEST

/* Contacts beyond the capacity are counted but not written. */
START_TEST(test_capacity)
{
    sdfccd_SdfId box;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 1, 1, 0.5 }, &box), SDFCCD_OK);
    sdfccd_Vec3 flat[3] = { { -0.3, -0.2, 0.6 }, { 0.4, -0.25, 0.6 }, { 0.0, 0.35, 0.6 } };
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity.z = -10;
    sdfccd_QueryParams p = sdfccd_default_query_params();
    sdfccd_Contact c[2];
    memset(c, 0, sizeof c);
    sdfccd_QueryResult r;
    ck_assert_int_eq(sdfccd_query_triangle(box, NULL, flat, &m, 0, DT, &p, c, 1, &r), SDFCCD_OK);
    ck_assert_int_eq(r.contact_count, 1);
    ck_assert_int_ge(r.contacts_found, 3);
    ck_assert_double_eq(c[1].toi, 0.0); /* untouched */
    ck_assert_int_eq(sdfccd_query_triangle(box, NULL, flat, &m, 0, DT, &p, NULL, 0, &r), SDFCCD_OK);
    ck_assert_int_eq(r.contact_count, 0);
    ck_assert(r.hit);
    sdfccd_destroy_sdf(box);
}
END_TEST

/* ---- a user allocator that counts ---- */
typedef struct counter { long long allocs, frees; long long live; int fail_after; } counter;
static void* count_alloc(size_t size, void* user)
{
    counter* c = user;
    if (c->fail_after >= 0 && c->allocs >= c->fail_after) return NULL;
    c->allocs++;
    c->live += (long long)size;
    return malloc(size);
}
static void count_free(void* p, size_t size, void* user)
{
    counter* c = user;
    c->frees++;
    c->live -= (long long)size;
    free(p);
}

START_TEST(test_allocator)
{
    counter cnt = { 0, 0, 0, -1 };
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    ck_assert_int_eq(sdfccd_set_allocator(count_alloc, NULL, &cnt), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_set_allocator(count_alloc, count_free, &cnt), SDFCCD_OK);
    sdfccd_SdfId a, b, u;
    ck_assert_int_eq(sdfccd_create_sphere(1, &a), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 1, 1, 1 }, &b), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_UNION, a, b, &u), SDFCCD_OK);
    ck_assert_int_gt(cnt.allocs, 0);
    ck_assert_int_eq(cnt.live, sdfccd_byte_count());
    /* Changing the allocator while memory is live is refused. */
    ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_BAD_STATE);
    /* The certified method allocates through the hooks too, and frees it all. */
    sdfccd_QueryParams p = sdfccd_default_query_params();
    p.method = SDFCCD_METHOD_CERTIFIED;
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity.z = -90;
    sdfccd_QueryResult r;
    long long before = cnt.allocs;
    ck_assert_int_eq(sdfccd_query_triangle(u, NULL, (sdfccd_Vec3[3]){ { 0, 0, 1.5 }, { 0.1, 0, 1.6 }, { 0, 0.1, 1.6 } }, &m, 0, DT, &p, NULL, 0, &r),
                     SDFCCD_OK);
    ck_assert(r.hit);
    ck_assert_int_gt(cnt.allocs, before);
    sdfccd_destroy_sdf(a);
    sdfccd_destroy_sdf(b);
    sdfccd_destroy_sdf(u);
    ck_assert_int_eq(cnt.live, 0);
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    ck_assert_int_eq(cnt.allocs, cnt.frees);
    /* Out of memory: a failing allocator gives a status, not a crash, and leaks nothing. */
    cnt.fail_after = cnt.allocs + 1;
    sdfccd_SdfId s;
    ck_assert_int_eq(sdfccd_create_sphere(1, &s), SDFCCD_OUT_OF_MEMORY);
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_OK);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("api");
    TCase* tc = tcase_create("contract");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_version_and_config);
    tcase_add_test(tc, test_query_bad_inputs);
    tcase_add_test(tc, test_mesh_bad_inputs);
    tcase_add_test(tc, test_point_batch_bad_inputs);
    tcase_add_test(tc, test_capacity);
    tcase_add_test(tc, test_allocator);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
