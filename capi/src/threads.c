/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: the thread loop shared by the batch calls (sdfccd_query_batch and
 * sdfccd_generate_contacts_batch). The calling thread and threads - 1 POSIX threads take the next
 * item from a shared atomic counter until none is left; nothing waits but the final join. */
#include "capi_internal.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>

typedef struct run_state {
    sdfccd__RunItem run;
    void* ctx;
    int32_t count;
    atomic_int next, slot, first_failure;
} run_state;

static void* run_worker(void* arg)
{
    run_state* s = arg;
    int32_t slot = atomic_fetch_add(&s->slot, 1);
    for (int i; (i = atomic_fetch_add(&s->next, 1)) < s->count;) {
        if (s->run(s->ctx, i, slot) == SDFCCD_OK) continue;
        int seen = atomic_load(&s->first_failure);
        while (i < seen && !atomic_compare_exchange_weak(&s->first_failure, &seen, i)) {
        }
    }
    return NULL;
}

sdfccd_Status sdfccd__run_threads(const char* fn, const char* noun, sdfccd__RunItem run, void* ctx, int32_t count, int32_t threads)
{
    if (count <= 0) return SDFCCD_OK;
    if (threads > count) threads = count;
    if (threads > SDFCCD__MAX_THREADS) threads = SDFCCD__MAX_THREADS;
    run_state s;
    s.run = run;
    s.ctx = ctx;
    s.count = count;
    atomic_init(&s.next, 0);
    atomic_init(&s.slot, 0);
    atomic_init(&s.first_failure, count);
    pthread_t tid[SDFCCD__MAX_THREADS];
    int started = 0;
    for (int k = 1; k < threads; ++k) {
        if (pthread_create(&tid[started], NULL, run_worker, &s) != 0) break; /* fewer threads: still correct */
        ++started;
    }
    run_worker(&s);
    for (int k = 0; k < started; ++k) pthread_join(tid[k], NULL);
    /* The first failure again on this thread (items are deterministic, so it fails the same way),
     * so that its message is this thread's last error. */
    int32_t first = atomic_load(&s.first_failure);
    if (first >= count) return SDFCCD_OK;
    sdfccd_Status st = run(ctx, first, 0);
    char msg[512];
    snprintf(msg, sizeof msg, "%s", sdfccd_last_error());
    return sdfccd__error(st, "%s: %s %d: %s", fn, noun, (int)first, msg);
}
