/* SPDX-License-Identifier: MIT
 * sdfccd core: the allocator every allocating core routine takes as a parameter.
 * Core owns no allocator and no global state; the C ABI layer passes its hooks down. */
#ifndef SCC_ALLOC_H
#define SCC_ALLOC_H

#include <stddef.h>

typedef struct scc_allocator {
    /* Returns NULL on failure. Memory is aligned for any scalar type (like malloc). */
    void* (*alloc)(size_t size, void* user);
    /* `size` is the size passed to alloc. Freeing NULL is a no-op. */
    void (*free)(void* mem, size_t size, void* user);
    void* user;
} scc_allocator;

static inline void* scc_alloc(const scc_allocator* a, size_t size) { return size ? a->alloc(size, a->user) : NULL; }
static inline void scc_free(const scc_allocator* a, void* p, size_t size) { if (p) a->free(p, size, a->user); }

#endif
