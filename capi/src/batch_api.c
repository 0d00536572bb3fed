/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: sdfccd_query_batch, many independent triangle or mesh queries on a caller-chosen
 * number of threads (issue 9), through the thread loop in threads.c. Mesh queries go through one
 * workspace per thread, so a batch allocates only per thread, not per query; so do triangle queries' certified searches (their scratch). Every query is computed
 * exactly as by itself (the solvers are deterministic and the workspace does not change results), so
 * the results do not depend on the thread count or on the order in which threads take queries. */
#include "capi_internal.h"

typedef struct batch {
    sdfccd_BatchQuery* q;
    sdfccd_Workspace* ws[SDFCCD__MAX_THREADS]; /* one per thread slot; NULL: each query allocates its own */
} batch;

static sdfccd_Status run_one(sdfccd_BatchQuery* b, sdfccd_Workspace* ws)
{
    switch (b->kind) {
    case SDFCCD_BATCH_TRIANGLE:
        return ws ? sdfccd_query_triangle_ws(ws, b->sdf, b->sdf_motion, b->triangle, b->motion, b->t0, b->t1, b->params, b->out_contacts,
                                             b->capacity, b->out_result)
                  : sdfccd_query_triangle(b->sdf, b->sdf_motion, b->triangle, b->motion, b->t0, b->t1, b->params, b->out_contacts, b->capacity,
                                          b->out_result);
    case SDFCCD_BATCH_TRIANGLE_LINEAR:
        return ws ? sdfccd_query_triangle_linear_ws(ws, b->sdf, b->sdf_motion, b->triangle, b->triangle_end, b->t0, b->t1, b->params,
                                                    b->out_contacts, b->capacity, b->out_result)
                  : sdfccd_query_triangle_linear(b->sdf, b->sdf_motion, b->triangle, b->triangle_end, b->t0, b->t1, b->params,
                                                 b->out_contacts, b->capacity, b->out_result);
    case SDFCCD_BATCH_MESH:
        return ws ? sdfccd_query_mesh_ws(ws, b->sdf, b->sdf_motion, b->mesh, b->motion, b->t0, b->t1, b->params, b->out_contacts,
                                         b->capacity, b->out_result)
                  : sdfccd_query_mesh(b->sdf, b->sdf_motion, b->mesh, b->motion, b->t0, b->t1, b->params, b->out_contacts,
                                      b->capacity, b->out_result);
    case SDFCCD_BATCH_MESH_LINEAR:
        return ws ? sdfccd_query_mesh_linear_ws(ws, b->sdf, b->sdf_motion, b->mesh, b->start, b->end, b->t0, b->t1, b->params,
                                                b->out_contacts, b->capacity, b->out_result)
                  : sdfccd_query_mesh_linear(b->sdf, b->sdf_motion, b->mesh, b->start, b->end, b->t0, b->t1, b->params,
                                             b->out_contacts, b->capacity, b->out_result);
    default:
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_query_batch: unknown query kind %d", (int)b->kind);
    }
}

static sdfccd_Status run_item(void* ctx, int32_t i, int32_t slot)
{
    batch* bt = ctx;
    return bt->q[i].status = run_one(&bt->q[i], bt->ws[slot]);
}

sdfccd_Status sdfccd_query_batch(sdfccd_BatchQuery* queries, int32_t count, int32_t threads)
{
    static const char fn[] = "sdfccd_query_batch";
    if (count < 0 || (count > 0 && !queries))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: queries is NULL or count (%d) < 0", fn, (int)count);
    if (threads < 1 || threads > SDFCCD__MAX_THREADS)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: threads must be in [1, %d] (got %d)", fn, SDFCCD__MAX_THREADS, (int)threads);
    if (count == 0) return SDFCCD_OK;
    if (threads > count) threads = count;
    batch bt;
    bt.q = queries;
    for (int k = 0; k < threads; ++k)
        if (sdfccd_create_workspace(&bt.ws[k]) != SDFCCD_OK) bt.ws[k] = NULL;
    sdfccd_Status st = sdfccd__run_threads(fn, "query", run_item, &bt, count, threads);
    for (int k = 0; k < threads; ++k) sdfccd_destroy_workspace(bt.ws[k]);
    return st;
}
