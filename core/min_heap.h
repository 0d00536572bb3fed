/* SPDX-License-Identifier: MIT
 * sdfccd core: a binary min-heap generated for one element type, growing through an
 * scc_allocator. Used by the earliest-first searches (certified TOI, broad phase).
 *
 *   SCC_MIN_HEAP(name, type, key_field)
 * defines `name` (a struct with a, n, cap, alloc, max_bytes, full), `static int name##_push(name*,
 * type)` (0 when the allocator fails, or when growing would pass max_bytes: then `full` is set)
 * and `static type name##_pop(name*)` (the smallest key; the heap must not be empty). Release the
 * storage with scc_free(alloc, h.a, h.cap * sizeof *h.a).
 *
 * max_bytes (0: no limit) bounds what the heap holds at any moment, including the moment of
 * growing, when the old and the new array are both allocated: cap + new cap <= max_bytes / size.
 * The storage doubles while that allows, then takes what is left, then the heap is full. */
#ifndef SCC_MIN_HEAP_H
#define SCC_MIN_HEAP_H

#include <stddef.h>
#include "alloc.h"

#define SCC_MIN_HEAP(name, type, key)                                                   \
    typedef struct name {                                                               \
        type* a;                                                                        \
        size_t n, cap;                                                                  \
        const scc_allocator* alloc;                                                     \
        size_t max_bytes;                                                               \
        int full;                                                                       \
    } name;                                                                             \
    static int name##_push(name* h, type elem)                                          \
    {                                                                                   \
        if (h->n == h->cap) {                                                           \
            size_t cap = h->cap ? 2 * h->cap : 64;                                      \
            if (h->max_bytes) {                                                         \
                size_t most = h->max_bytes / sizeof *h->a;                              \
                size_t room = most > h->cap ? most - h->cap : 0;                        \
                if (cap > room) cap = room;                                             \
                if (cap <= h->n) { h->full = 1; return 0; }                             \
            }                                                                           \
            type* na = (type*)scc_alloc(h->alloc, cap * sizeof *na);                    \
            if (!na) return 0;                                                          \
            for (size_t k = 0; k < h->n; ++k) na[k] = h->a[k];                          \
            scc_free(h->alloc, h->a, h->cap * sizeof *h->a);                            \
            h->a = na;                                                                  \
            h->cap = cap;                                                               \
        }                                                                               \
        size_t i = h->n++;                                                              \
        while (i > 0) {                                                                 \
            size_t parent = (i - 1) / 2;                                                \
            if (h->a[parent].key <= elem.key) break;                                    \
            h->a[i] = h->a[parent];                                                     \
            i = parent;                                                                 \
        }                                                                               \
        h->a[i] = elem;                                                                 \
        return 1;                                                                       \
    }                                                                                   \
    static type name##_pop(name* h)                                                     \
    {                                                                                   \
        type top = h->a[0];                                                             \
        type last = h->a[--h->n];                                                       \
        size_t i = 0;                                                                   \
        for (;;) {                                                                      \
            size_t l = 2 * i + 1, r = l + 1, m = i;                                     \
            double km = last.key;                                                       \
            if (l < h->n && h->a[l].key < km) { m = l; km = h->a[l].key; }              \
            if (r < h->n && h->a[r].key < km) m = r;                                    \
            if (m == i) break;                                                          \
            h->a[i] = h->a[m];                                                          \
            i = m;                                                                      \
        }                                                                               \
        if (h->n) h->a[i] = last;                                                       \
        return top;                                                                     \
    }

#endif
