/* SPDX-License-Identifier: MIT
 * The shared test support of the Check suites (one place for scaffolding several suites use):
 * a seeded RNG, the allocator-balance fixture, a runner that prints the suite's summary line,
 * loading the data folder's meshes and the closed-form distance to a box. */
#ifndef SDFCCD_TEST_UTIL_H
#define SDFCCD_TEST_UTIL_H

#include <check.h>
#include <stdint.h>
#include "sdfccd/sdfccd.h"

/* splitmix64-based generator; deterministic for a given seed. */
typedef struct test_rng { uint64_t s; } test_rng;
uint64_t test_rng_next(test_rng* r);
double test_rng_uniform(test_rng* r, double lo, double hi); /* [lo, hi) */
sdfccd_Vec3 test_rng_unit_vector(test_rng* r);

/* Checked fixture: asserts sdfccd_byte_count() returns to its start value after each test. */
void test_memory_setup(void);
void test_memory_teardown(void);
/* Adds the memory fixture to a TCase. */
void test_add_memory_fixture(TCase* tc);

/* Loads `rel` (a path under data/, e.g. "bullet3/cube.obj") with the default load def; fails the
 * test with the library's message when it cannot. */
sdfccd_MeshId test_load_mesh(const char* rel);

/* Exact signed distance from p to the axis-aligned cube [-h, h]^3 (negative inside). */
double test_box_distance(sdfccd_Vec3 p, double h);

/* A closed box mesh [-half, half] whose faces are split into grids of nx, ny, nz cells along x, y, z
 * (two triangles a cell, outward winding); fails the test when it cannot be created. */
sdfccd_MeshId test_box_mesh(sdfccd_Vec3 half, int nx, int ny, int nz);

/* A 16^3 grid (5 cm padding, one build thread) of the cube [-0.1, 0.1]^3 less the ball of radius 0.12
 * about its centre: eight corner pieces with concave creases, a field FWGSS's answers are checked on;
 * fails the test when it cannot be created. */
sdfccd_SdfId test_carved_box_grid(void);

/* An allocator for sdfccd_set_allocator that counts its allocations in the long `user` points to. */
void* test_counting_alloc(size_t size, void* user);
void test_counting_free(void* mem, size_t size, void* user);

/* Runs a suite (CK_NORMAL output) and returns the process exit code. */
int test_run_suite(Suite* s);

#define ck_assert_double_near(a, b, tol) \
    ck_assert_msg(fabs((double)(a) - (double)(b)) <= (tol), "%s = %.17g, expected %.17g (tol %g)", #a, (double)(a), (double)(b), (double)(tol))

#endif
