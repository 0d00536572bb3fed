/* SPDX-License-Identifier: MIT
 * Test support for the suites that use internals (INTERNALS in tests/CMakeLists.txt, which also
 * compiles test_internal.c into them). For single-threaded tests that look inside objects
 * (capi_internal.h): the object behind a live handle. The reference acquire takes is dropped at
 * once; the test's handle keeps the object alive until the test destroys it. And independent
 * references computed on core types. */
#ifndef SDFCCD_TEST_INTERNAL_H
#define SDFCCD_TEST_INTERNAL_H

#include <check.h>
#include "grid_internal.h"

static inline const scc_mesh* test_mesh_of(sdfccd_MeshId id)
{
    const int mark = sdfccd__hold_mark();
    sdfccd__mesh* m = sdfccd__mesh_acquire(id);
    sdfccd__hold_release_to(mark);
    ck_assert_ptr_nonnull(m);
    return &m->mesh;
}

static inline scc_grid* test_grid_of(sdfccd_SdfId id)
{
    scc_grid* g = NULL;
    const int mark = sdfccd__hold_mark();
    const sdfccd_Status st = sdfccd__grid_acquire(id, "test", &g);
    sdfccd__hold_release_to(mark);
    ck_assert_int_eq(st, SDFCCD_OK);
    return g;
}

/* Generalised winding number of a closed mesh at p (solid angles, Van Oosterom and Strackee):
 * about 1 inside, 0 outside. An independent reference for signs. */
double test_winding_number(const scc_mesh* m, scc_vec3 p);

#endif
