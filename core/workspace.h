/* SPDX-License-Identifier: MIT
 * sdfccd core: a reusable workspace for the mesh query (issue 9). The mesh query's scratch
 * storage (contact buffer, broad-phase heap, segment table, tested-triangle bits, refit nodes,
 * output staging, the certified searches' region buffer and caches) lives in slots that only grow,
 * so a caller who keeps one workspace per thread
 * allocates nothing after the first query of a given size. A query given no workspace uses a
 * temporary one and frees it at the end (the allocations of a one-off call). */
#ifndef SCC_WORKSPACE_H
#define SCC_WORKSPACE_H

#include <stddef.h>
#include <stdint.h>
#include "alloc.h"

enum {
    SCC_WS_CONTACTS,  /* mesh query: contacts of the triangles within the TOI window; after a query it
                         holds all sum->contacts_found of them, earliest first */
    SCC_WS_HEAP,      /* broad phase: earliest-candidate heap */
    SCC_WS_SEGMENTS,  /* broad phase: time segments */
    SCC_WS_TESTED,    /* broad phase: one byte per triangle, all zero between traversals (bsh.c) */
    SCC_WS_STACK,     /* broad phase (DCD): descent stack */
    SCC_WS_MOVING,    /* broad phase: nodes refitted for linear motion */
    SCC_WS_STAGING,   /* the ABI: contacts before conversion to the world frame */
    SCC_WS_VERTICES,  /* the ABI: linear-motion vertex copies */
    SCC_WS_TRACES,    /* mesh query: one FWGSS vertex trace record per mesh vertex (motion.h) */
    SCC_WS_GUARD,     /* guard: per-triangle contact levels (guard.c) */
    SCC_WS_REDUCE,    /* mesh query and contact sets: indices of the contacts kept (reduce.c) */
    SCC_WS_REDUCE_SCRATCH, /* the reduction's per-contact distances (reduce.c) */
    SCC_WS_CANDIDATES, /* contact sets: the candidates of a step (contacts.c) */
    SCC_WS_MARKS,     /* contact sets: one mark per mesh vertex (tagged by mark_epoch) */
    SCC_WS_CERTIFIED, /* guard: one flag per BSH node proven clear (bsh.c, scc_bsh_certify) */
    SCC_WS_FACES,     /* the face search's region stack (faces.c) */
    SCC_WS_POSED,     /* mesh query (DCD): vertices at the tested pose, tagged by trace_epoch (mesh_query.c) */
    SCC_WS_START,     /* contact sets: the start-pose query's contacts, kept while the CCD runs (contacts.c) */
    SCC_WS_VERTEX_LIST, /* contact sets: the vertices of the touching triangles, sorted (contacts.c) */
    SCC_WS_DEFERRED,  /* mesh query: FWGSS answers whose check waits for the earliest contact (mesh_query.c) */
    SCC_WS_BELOW,     /* broad phase: the triangles a traversal marked, with the motions of those bounded below their leaves (bsh.c) */
    SCC_WS_CHECK,     /* certified searches: the region store's first regions and the sample cache, one fixed size (certified.c) */
    SCC_WS_CELLS,     /* certified searches on grids: the cell cache, one fixed size (certified.c) */
    SCC_WS_SLOTS
};

typedef struct scc_ws_slot { void* p; size_t bytes; } scc_ws_slot;

typedef struct scc_workspace {
    const scc_allocator* alloc;
    scc_ws_slot slot[SCC_WS_SLOTS];
    uint32_t trace_epoch;  /* mesh queries so far (tags the SCC_WS_TRACES records in use) */
    uint32_t trace_count;  /* the records' count the SCC_WS_TRACES page marks are laid out for (mesh_query.c) */
    uint32_t mark_epoch;   /* vertex marks handed out so far (tags SCC_WS_MARKS) */
} scc_workspace;

static inline void scc_ws_init(scc_workspace* ws, const scc_allocator* alloc)
{
    ws->alloc = alloc;
    ws->trace_epoch = 0;
    ws->trace_count = 0;
    ws->mark_epoch = 0;
    for (int i = 0; i < SCC_WS_SLOTS; ++i) {
        ws->slot[i].p = NULL;
        ws->slot[i].bytes = 0;
    }
}

/* At least `bytes` of storage in `slot` (contents not kept when it grows); NULL on failure. */
static inline void* scc_ws_get(scc_workspace* ws, int slot, size_t bytes)
{
    scc_ws_slot* s = &ws->slot[slot];
    if (bytes <= s->bytes) return s->p;
    size_t grown = s->bytes * 2 > bytes ? s->bytes * 2 : bytes;
    void* p = scc_alloc(ws->alloc, grown);
    if (!p) return NULL;
    scc_free(ws->alloc, s->p, s->bytes);
    s->p = p;
    s->bytes = grown;
    return p;
}

/* Hands a growable array (pointer and byte size, allocated with ws->alloc) back to a slot. */
static inline void scc_ws_adopt(scc_workspace* ws, int slot, void* p, size_t bytes)
{
    ws->slot[slot].p = p;
    ws->slot[slot].bytes = bytes;
}

static inline size_t scc_ws_bytes(const scc_workspace* ws)
{
    size_t n = 0;
    for (int i = 0; i < SCC_WS_SLOTS; ++i) n += ws->slot[i].bytes;
    return n;
}

static inline void scc_ws_release(scc_workspace* ws)
{
    for (int i = 0; i < SCC_WS_SLOTS; ++i) {
        scc_free(ws->alloc, ws->slot[i].p, ws->slot[i].bytes);
        ws->slot[i].p = NULL;
        ws->slot[i].bytes = 0;
    }
}

#endif
