/* SPDX-License-Identifier: MIT
 * For single-threaded tests that look inside objects (capi_internal.h): the object behind a live
 * handle. The reference acquire takes is dropped at once; the test's handle keeps the object
 * alive until the test destroys it. */
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

#endif
