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
