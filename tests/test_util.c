/* SPDX-License-Identifier: MIT */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef SDFCCD_DATA_DIR
#define SDFCCD_DATA_DIR "data"
#endif

uint64_t test_rng_next(test_rng* r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double test_rng_uniform(test_rng* r, double lo, double hi)
{
    return lo + (hi - lo) * ((double)(test_rng_next(r) >> 11) * (1.0 / 9007199254740992.0));
}

sdfccd_Vec3 test_rng_unit_vector(test_rng* r)
{
    for (;;) {
        sdfccd_Vec3 v = { test_rng_uniform(r, -1, 1), test_rng_uniform(r, -1, 1), test_rng_uniform(r, -1, 1) };
        double l = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
        if (l > 1e-3 && l <= 1.0) { v.x /= l; v.y /= l; v.z /= l; return v; }
    }
}

static int64_t s_bytes_at_setup;
void test_memory_setup(void) { s_bytes_at_setup = sdfccd_byte_count(); }
void test_memory_teardown(void)
{
    ck_assert_msg(sdfccd_byte_count() == s_bytes_at_setup, "leak: %lld bytes still allocated after the test (%lld before)",
                  (long long)sdfccd_byte_count(), (long long)s_bytes_at_setup);
}
void test_add_memory_fixture(TCase* tc) { tcase_add_checked_fixture(tc, test_memory_setup, test_memory_teardown); }

int test_run_suite(Suite* s)
{
    SRunner* sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}

sdfccd_MeshId test_load_mesh(const char* rel)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", SDFCCD_DATA_DIR, rel);
    sdfccd_MeshId m = { 0, 0 };
    sdfccd_Status st = sdfccd_load_mesh(path, NULL, &m);
    ck_assert_msg(st == SDFCCD_OK, "load %s: %s", path, sdfccd_last_error());
    return m;
}

double test_box_distance(sdfccd_Vec3 p, double h)
{
    const double q[3] = { fabs(p.x) - h, fabs(p.y) - h, fabs(p.z) - h };
    const double ox = fmax(q[0], 0.0), oy = fmax(q[1], 0.0), oz = fmax(q[2], 0.0);
    return sqrt(ox * ox + oy * oy + oz * oz) + fmin(fmax(q[0], fmax(q[1], q[2])), 0.0);
}

sdfccd_MeshId test_box_mesh(sdfccd_Vec3 half, int nx, int ny, int nz)
{
    const double h[3] = { half.x, half.y, half.z };
    const int n[3] = { nx, ny, nz };
    struct { double* v; uint32_t* f; uint32_t nv, nt; } b;
    size_t maxv = 0, maxt = 0;
    for (int k = 0; k < 3; ++k) {
        int u = (k + 1) % 3, w = (k + 2) % 3;
        maxv += 2 * (size_t)(n[u] + 1) * (n[w] + 1);
        maxt += 4 * (size_t)n[u] * n[w];
    }
    b.v = malloc(3 * maxv * sizeof *b.v);
    b.f = malloc(3 * maxt * sizeof *b.f);
    b.nv = b.nt = 0;
    for (int k = 0; k < 3; ++k)
        for (int s = -1; s <= 1; s += 2) {
            int u = (k + 1) % 3, w = (k + 2) % 3;
            uint32_t base = b.nv;
            for (int i = 0; i <= n[u]; ++i)
                for (int j = 0; j <= n[w]; ++j) {
                    double* p = b.v + 3 * b.nv++;
                    p[k] = s * h[k];
                    p[u] = -h[u] + 2.0 * h[u] * i / n[u];
                    p[w] = -h[w] + 2.0 * h[w] * j / n[w];
                }
            for (int i = 0; i < n[u]; ++i)
                for (int j = 0; j < n[w]; ++j) {
                    uint32_t a = base + (uint32_t)(i * (n[w] + 1) + j), c = a + (uint32_t)(n[w] + 1);
                    uint32_t q[4] = { a, c, c + 1, a + 1 };
                    if (s < 0) { uint32_t t = q[1]; q[1] = q[3]; q[3] = t; } /* outward winding */
                    uint32_t* f = b.f + 3 * b.nt;
                    f[0] = q[0]; f[1] = q[1]; f[2] = q[2];
                    f[3] = q[0]; f[4] = q[2]; f[5] = q[3];
                    b.nt += 2;
                }
        }
    sdfccd_MeshDef d = sdfccd_default_mesh_def();
    d.vertices = b.v;
    d.vertex_count = b.nv;
    d.indices = b.f;
    d.triangle_count = b.nt;
    sdfccd_MeshId id;
    ck_assert_msg(sdfccd_create_mesh(&d, &id) == SDFCCD_OK, "%s", sdfccd_last_error());
    free(b.v);
    free(b.f);
    return id;
}

void* test_counting_alloc(size_t size, void* user)
{
    ++*(long*)user;
    return malloc(size);
}

void test_counting_free(void* mem, size_t size, void* user)
{
    (void)size;
    (void)user;
    free(mem);
}

sdfccd_SdfId test_carved_box_grid(void)
{
    sdfccd_SdfId box, ball, carved, grid;
    ck_assert_int_eq(sdfccd_create_box((sdfccd_Vec3){ 0.1, 0.1, 0.1 }, &box), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_sphere(0.12, &ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_csg(SDFCCD_CSG_DIFFERENCE, box, ball, &carved), SDFCCD_OK);
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 16;
    def.padding = 0.05;
    def.threads = 1;
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(carved, &def, &grid), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(carved), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(ball), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(box), SDFCCD_OK);
    return grid;
}
