/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: sdfccd_query_batch, many independent triangle or mesh queries on a caller-chosen
 * number of threads (issue 9). The calling thread and threads - 1 POSIX threads take the next
 * query from a shared atomic counter until none is left and then exit (no thread waits on
 * another except the final join, nothing spins). Mesh queries go through one workspace per
 * thread, so a batch allocates only per thread, not per query. Every query is computed exactly
 * as by itself (the solvers are deterministic and the workspace does not change results), so the
 * results do not depend on the thread count or on the order in which threads take queries. */
#include "capi_internal.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>

#define MAX_BATCH_THREADS 256

typedef struct batch {
    sdfccd_BatchQuery* q;
    int32_t count;
    atomic_int next;
} batch;

static sdfccd_Status run_one(sdfccd_BatchQuery* b, sdfccd_Workspace* ws)
{
    switch (b->kind) {
    case SDFCCD_BATCH_TRIANGLE:
        return sdfccd_query_triangle(b->sdf, b->sdf_motion, b->triangle, b->motion, b->t0, b->t1, b->params, b->out_contacts,
                                     b->capacity, b->out_result);
    case SDFCCD_BATCH_TRIANGLE_LINEAR:
        return sdfccd_query_triangle_linear(b->sdf, b->sdf_motion, b->triangle, b->triangle_end, b->t0, b->t1, b->params,
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

static void* worker(void* arg)
{
    batch* bt = arg;
    sdfccd_Workspace* ws = NULL;
    if (sdfccd_create_workspace(&ws) != SDFCCD_OK) ws = NULL; /* then each mesh query allocates its own */
    for (;;) {
        int i = atomic_fetch_add(&bt->next, 1);
        if (i >= bt->count) break;
        bt->q[i].status = run_one(&bt->q[i], ws);
    }
    sdfccd_destroy_workspace(ws);
    return NULL;
}

sdfccd_Status sdfccd_query_batch(sdfccd_BatchQuery* queries, int32_t count, int32_t threads)
{
    static const char fn[] = "sdfccd_query_batch";
    if (count < 0 || (count > 0 && !queries))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: queries is NULL or count (%d) < 0", fn, (int)count);
    if (threads < 1 || threads > MAX_BATCH_THREADS)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: threads must be in [1, %d] (got %d)", fn, MAX_BATCH_THREADS, (int)threads);
    if (count == 0) return SDFCCD_OK;
    if (threads > count) threads = count;
    batch bt;
    bt.q = queries;
    bt.count = count;
    atomic_init(&bt.next, 0);
    pthread_t tid[MAX_BATCH_THREADS];
    int started = 0;
    for (int k = 1; k < threads; ++k) {
        if (pthread_create(&tid[started], NULL, worker, &bt) != 0) break; /* fewer threads: still correct */
        ++started;
    }
    worker(&bt);
    for (int k = 0; k < started; ++k) pthread_join(tid[k], NULL);
    /* The first failure, re-run on this thread so that its message is this thread's last error
     * (queries are deterministic, so the re-run fails the same way). */
    for (int32_t i = 0; i < count; ++i)
        if (queries[i].status != SDFCCD_OK) {
            sdfccd_Status st = run_one(&queries[i], NULL);
            char msg[512];
            snprintf(msg, sizeof msg, "%s", sdfccd_last_error());
            return sdfccd__error(st, "%s: query %d: %s", fn, (int)i, msg);
        }
    return SDFCCD_OK;
}
