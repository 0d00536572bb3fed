/* SPDX-License-Identifier: MIT
 * sdfccd C ABI internals for grid SDFs: the handle wrapper and the thread pool. */
#ifndef SDFCCD_GRID_INTERNAL_H
#define SDFCCD_GRID_INTERNAL_H

#include "capi_internal.h"
#include "sdfccd/grid.h"
#include "../../core/grid.h"

/* Wraps a finished core grid in a new SDF handle (takes ownership; destroys it on failure). */
sdfccd_Status sdfccd__grid_register(scc_grid* g, sdfccd_SdfId* out_sdf);
/* The grid behind a handle, acquired (sdfccd__sdf_acquire: call it inside SDFCCD__HELD_CALL):
 * INVALID_HANDLE, or INVALID_ARGUMENT when the SDF is not a grid. */
sdfccd_Status sdfccd__grid_acquire(sdfccd_SdfId id, const char* fn, scc_grid** out_grid);
/* Size of the .cdf file of a grid. */
int64_t sdfccd__grid_file_bytes(const scc_grid* g);

/* Runs a parallel_for on `threads` threads (0 = online cores) and reports progress. */
typedef struct sdfccd__pool {
    int threads;
    sdfccd_ProgressFcn* progress;
    void* progress_user;
    double stage_base[4], stage_weight[4]; /* progress mapping per stage (SCC_GRID_STAGE_*) */
    double last_reported;
    int cancelled;       /* the progress callback asked to stop */
} sdfccd__pool;
void sdfccd__pool_init(sdfccd__pool* p, int threads, sdfccd_ProgressFcn* progress, void* user);
int sdfccd__pool_parallel_for(void* user, int stage, uint32_t count, scc_task_fn* task, void* ctx);

#endif
