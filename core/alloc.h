/* SPDX-License-Identifier: MIT
 * sdfccd core: the allocator every allocating core routine takes as a parameter.
 * Core owns no allocator and no global state; the C ABI layer passes its hooks down. */
#ifndef SCC_ALLOC_H
#define SCC_ALLOC_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef struct scc_allocator {
    /* Returns NULL on failure. Memory is aligned for any scalar type (like malloc). */
    void* (*alloc)(size_t size, void* user);
    /* `size` is the size passed to alloc. Freeing NULL is a no-op. */
    void (*free)(void* mem, size_t size, void* user);
    void* user;
} scc_allocator;

static inline void* scc_alloc(const scc_allocator* a, size_t size) { return size ? a->alloc(size, a->user) : NULL; }
static inline void scc_free(const scc_allocator* a, void* p, size_t size) { if (p) a->free(p, size, a->user); }

/* The one growable array of the project: makes the array *data (capacity *cap elements of `elem`
 * bytes, allocated with `a`, NULL when *cap is 0) hold at least `need` elements, doubling from
 * `first_cap` (> 0), keeping its contents. Returns 0 (array unchanged) on size overflow or
 * allocation failure. */
static inline int scc_array_reserve(const scc_allocator* a, void** data, size_t* cap, size_t elem, size_t need, size_t first_cap)
{
    if (need <= *cap) return 1;
    size_t ncap = *cap ? *cap : first_cap;
    while (ncap < need) {
        if (ncap > SIZE_MAX / 2 / elem) return 0;
        ncap *= 2;
    }
    if (ncap > SIZE_MAX / elem) return 0;
    void* nd = scc_alloc(a, ncap * elem);
    if (!nd) return 0;
    if (*data) {
        memcpy(nd, *data, *cap * elem);
        scc_free(a, *data, *cap * elem);
    }
    *data = nd;
    *cap = ncap;
    return 1;
}

#endif
