/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: allocator hooks and byte count, error messages, version queries, the
 * generation-checked handle registry shared by SDFs and meshes, and the one lifetime both kinds
 * of object share (references, acquire for calls in flight, destroy). Mesh creation is in
 * mesh_api.c, the SDF kinds in sdf_api.c. */
#include "capi_internal.h"
#include "../../core/bsh.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------- allocation ---------------- */

static void* default_alloc(size_t size, void* user) { (void)user; return malloc(size); }
static void default_free(void* mem, size_t size, void* user) { (void)size; (void)user; free(mem); }

static sdfccd_AllocFcn* s_alloc = default_alloc;
static sdfccd_FreeFcn* s_free = default_free;
static void* s_alloc_user = NULL;
static _Atomic int64_t s_bytes = 0;

static void* counted_alloc(size_t size, void* user)
{
    (void)user;
    if (size == 0) return NULL;
    void* p = s_alloc(size, s_alloc_user);
    if (p) atomic_fetch_add(&s_bytes, (int64_t)size);
    return p;
}

static void counted_free(void* p, size_t size, void* user)
{
    (void)user;
    if (!p) return;
    atomic_fetch_sub(&s_bytes, (int64_t)size);
    s_free(p, size, s_alloc_user);
}

static const scc_allocator s_core_allocator = { counted_alloc, counted_free, NULL };

void* sdfccd__alloc(size_t size) { return counted_alloc(size, NULL); }
void* sdfccd__calloc(size_t size)
{
    void* p = counted_alloc(size, NULL);
    if (p) memset(p, 0, size);
    return p;
}
void sdfccd__free(void* p, size_t size) { counted_free(p, size, NULL); }
const scc_allocator* sdfccd__allocator(void) { return &s_core_allocator; }

sdfccd_Status sdfccd_set_allocator(sdfccd_AllocFcn* alloc, sdfccd_FreeFcn* free_fcn, void* user)
{
    if ((alloc == NULL) != (free_fcn == NULL))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_set_allocator: alloc and free must both be set or both be NULL");
    if (atomic_load(&s_bytes) != 0)
        return sdfccd__error(SDFCCD_BAD_STATE, "sdfccd_set_allocator: %lld bytes are still allocated; destroy every handle first",
                             (long long)atomic_load(&s_bytes));
    s_alloc = alloc ? alloc : default_alloc;
    s_free = free_fcn ? free_fcn : default_free;
    s_alloc_user = alloc ? user : NULL;
    return SDFCCD_OK;
}

int64_t sdfccd_byte_count(void) { return atomic_load(&s_bytes); }

/* ---------------- errors ---------------- */

static _Thread_local char s_message[512];

sdfccd_Status sdfccd__error(sdfccd_Status status, const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s_message, sizeof s_message, fmt, ap);
    va_end(ap);
    return status;
}

sdfccd_Status sdfccd__oom(const char* what)
{
    return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "out of memory while creating %s", what);
}

sdfccd_Status sdfccd__check_ptr(const void* p, const char* what)
{
    return p ? SDFCCD_OK : sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s is NULL", what);
}

sdfccd_Status sdfccd__check_finite(double v, const char* what)
{
    return isfinite(v) ? SDFCCD_OK : sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s is not finite (%g)", what, v);
}

sdfccd_Status sdfccd__check_vec(sdfccd_Vec3 v, const char* what)
{
    if (isfinite(v.x) && isfinite(v.y) && isfinite(v.z)) return SDFCCD_OK;
    return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s is not finite (%g, %g, %g)", what, v.x, v.y, v.z);
}

const char* sdfccd_last_error(void) { return s_message; }

sdfccd_Status sdfccd__check_def(int32_t internal_value, const char* fn, const char* what, const char* default_fn)
{
    if (internal_value == SDFCCD__DEF_COOKIE) return SDFCCD_OK;
    return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: %s not initialised with %s()", fn, what, default_fn);
}

const char* sdfccd_status_string(sdfccd_Status status)
{
    static const char* const names[SDFCCD_STATUS_COUNT] = {
        "SDFCCD_OK", "SDFCCD_INVALID_ARGUMENT", "SDFCCD_INVALID_HANDLE", "SDFCCD_DEGENERATE",
        "SDFCCD_OUT_OF_MEMORY", "SDFCCD_IO_ERROR", "SDFCCD_FORMAT_ERROR", "SDFCCD_UNSUPPORTED",
        "SDFCCD_BAD_STATE", "SDFCCD_CANCELLED",
    };
    if ((int)status < 0 || status >= SDFCCD_STATUS_COUNT) return "SDFCCD_UNKNOWN_STATUS";
    return names[status];
}

/* ---------------- version ---------------- */

int32_t sdfccd_version(void) { return SDFCCD_VERSION_ID; }
const char* sdfccd_version_string(void) { return SDFCCD_VERSION_STRING; }
int sdfccd_is_double_precision(void) { return 1; }

#ifndef SDFCCD_HAVE_ASSIMP
#define SDFCCD_HAVE_ASSIMP 0
#endif
#define SDFCCD_STR2(x) #x
#define SDFCCD_STR(x) SDFCCD_STR2(x)
const char* sdfccd_configuration_string(void)
{
    return "sdfccd " SDFCCD_VERSION_STRING "; scalar=double; assimp=" SDFCCD_STR(SDFCCD_HAVE_ASSIMP)
#if defined(__clang__)
        "; compiler=clang " __clang_version__
#elif defined(__GNUC__)
        "; compiler=gcc " __VERSION__
#endif
#if defined(__SANITIZE_ADDRESS__)
        "; asan"
#endif
        ;
}

/* ---------------- handle registry ---------------- */

typedef struct slot {
    void* obj;
    uint32_t generation;
    uint32_t kind;
    uint32_t next_free; /* index into slots, UINT32_MAX = none */
} slot;

static pthread_mutex_t s_lock = PTHREAD_MUTEX_INITIALIZER;
static slot* s_slots = NULL;
static uint32_t s_slot_count = 0, s_slot_capacity = 0;
static uint32_t s_free_head = UINT32_MAX;
static uint32_t s_generation_floor = 0; /* new slots start above every generation handed out before */

/* The table comes from the user's allocator (counted in sdfccd_byte_count) and is freed when the
 * last handle goes, so byte_count returns to 0 and the allocator can be changed again. */
static void registry_maybe_shrink(void)
{
    uint32_t top = s_generation_floor;
    for (uint32_t i = 0; i < s_slot_count; ++i) {
        if (s_slots[i].kind != SDFCCD__KIND_FREE) return;
        if (s_slots[i].generation > top) top = s_slots[i].generation;
    }
    /* Keep the generations growing across a reset so stale ids never match again. */
    s_generation_floor = top;
    sdfccd__free(s_slots, (size_t)s_slot_capacity * sizeof *s_slots);
    s_slots = NULL;
    s_slot_count = s_slot_capacity = 0;
    s_free_head = UINT32_MAX;
}

int sdfccd__registry_add(void* obj, uint32_t kind, uint32_t* out_index1, uint32_t* out_generation)
{
    pthread_mutex_lock(&s_lock);
    uint32_t i;
    if (s_free_head != UINT32_MAX) {
        i = s_free_head;
        s_free_head = s_slots[i].next_free;
    } else {
        if (s_slot_count == s_slot_capacity) {
            uint32_t cap = s_slot_capacity ? 2 * s_slot_capacity : 64;
            slot* n = sdfccd__alloc((size_t)cap * sizeof *n);
            if (!n) { pthread_mutex_unlock(&s_lock); return 0; }
            if (s_slot_count) memcpy(n, s_slots, (size_t)s_slot_count * sizeof *n);
            sdfccd__free(s_slots, (size_t)s_slot_capacity * sizeof *s_slots);
            s_slots = n;
            s_slot_capacity = cap;
        }
        i = s_slot_count++;
        s_slots[i].generation = s_generation_floor;
    }
    s_slots[i].obj = obj;
    s_slots[i].kind = kind;
    s_slots[i].generation += 1;
    if (s_slots[i].generation == 0) s_slots[i].generation = 1;
    s_slots[i].next_free = UINT32_MAX;
    *out_index1 = i + 1;
    *out_generation = s_slots[i].generation;
    pthread_mutex_unlock(&s_lock);
    return 1;
}

/* Removes the entry and returns its object (NULL if the id is not live). */
static void* registry_remove(uint32_t index1, uint32_t generation, uint32_t kind)
{
    void* obj = NULL;
    pthread_mutex_lock(&s_lock);
    if (index1 >= 1 && index1 <= s_slot_count) {
        slot* s = &s_slots[index1 - 1];
        if (s->kind == kind && s->generation == generation) {
            obj = s->obj;
            s->obj = NULL;
            s->kind = SDFCCD__KIND_FREE;
            s->next_free = s_free_head;
            s_free_head = index1 - 1;
            registry_maybe_shrink();
        }
    }
    pthread_mutex_unlock(&s_lock);
    return obj;
}

/* ---------------- objects behind handles ----------------
 * SDF and mesh objects share one lifetime: a reference count changed only under the registry
 * lock, one reference held by the handle and one by every call in flight that uses the object
 * (and, for SDFs, one by every combination using it as a child). Whatever drops the last one
 * frees the object, so a destroy that races a call frees it when that call returns. */

static const char* kind_noun(uint32_t kind) { return kind == SDFCCD__KIND_SDF ? "SDF" : "mesh"; }

static uint32_t* object_refs(void* obj, uint32_t kind)
{
    return kind == SDFCCD__KIND_SDF ? &((sdfccd__sdf*)obj)->refs : &((sdfccd__mesh*)obj)->refs;
}

static void object_free(void* obj, uint32_t kind)
{
    if (kind == SDFCCD__KIND_SDF) {
        sdfccd__sdf* s = obj;
        if (s->release_extra) s->release_extra(s);
        for (int i = 0; i < 2; ++i) sdfccd__sdf_release(s->children[i]);
        sdfccd__free(s->storage, s->storage_size);
        sdfccd__free(s, sizeof *s);
    } else {
        sdfccd__mesh* m = obj;
        scc_bsh_destroy(m->bsh, sdfccd__allocator());
        sdfccd__free(m->block, m->block_size);
        sdfccd__free(m, sizeof *m);
    }
}

static void object_release(void* obj, uint32_t kind)
{
    if (!obj) return;
    pthread_mutex_lock(&s_lock);
    const uint32_t left = --*object_refs(obj, kind);
    pthread_mutex_unlock(&s_lock);
    if (!left) object_free(obj, kind);
}

void sdfccd__sdf_release(sdfccd__sdf* s) { object_release(s, SDFCCD__KIND_SDF); }
void sdfccd__mesh_release(sdfccd__mesh* m) { object_release(m, SDFCCD__KIND_MESH); }

void sdfccd__sdf_retain(sdfccd__sdf* s)
{
    pthread_mutex_lock(&s_lock);
    s->refs++;
    pthread_mutex_unlock(&s_lock);
}

sdfccd__sdf* sdfccd__sdf_new(size_t storage_size)
{
    sdfccd__sdf* s = sdfccd__calloc(sizeof *s);
    if (!s) return NULL;
    s->storage = sdfccd__calloc(storage_size);
    if (!s->storage) { sdfccd__free(s, sizeof *s); return NULL; }
    s->storage_size = storage_size;
    s->sdf = (const scc_sdf*)s->storage;
    s->memory_bytes = (int64_t)storage_size;
    s->refs = 1;
    return s;
}

sdfccd_Status sdfccd__sdf_register(sdfccd__sdf* s, sdfccd_SdfId* out_id)
{
    sdfccd_SdfId id = { 0, 0 };
    if (!sdfccd__registry_add(s, SDFCCD__KIND_SDF, &id.index1, &id.generation)) {
        sdfccd__sdf_release(s);
        return sdfccd__oom("an SDF handle");
    }
    *out_id = id;
    return SDFCCD_OK;
}

/* ---------------- references held by calls in flight ----------------
 * Every public call that takes a handle runs inside SDFCCD__HELD_CALL: acquire records the
 * reference it takes in a per-thread list, and the wrapper drops everything recorded since the
 * call began when it returns. There is no other way from a handle to its object. */
enum { HOLD_MAX = 32 };
typedef struct held { void* obj; uint32_t kind; } held;
static _Thread_local held s_held[HOLD_MAX];
static _Thread_local int s_held_n = 0;

int sdfccd__hold_mark(void) { return s_held_n; }

void sdfccd__hold_release_to(int mark)
{
    while (s_held_n > mark) {
        --s_held_n;
        object_release(s_held[s_held_n].obj, s_held[s_held_n].kind);
    }
}

/* Looks up a live handle and, under the registry lock, takes a reference held until release_to.
 * NULL with an INVALID_HANDLE message when the id is not live (or the list is full: calls nested
 * through user callbacks deeper than HOLD_MAX). */
static void* acquire(uint32_t index1, uint32_t generation, uint32_t kind)
{
    void* obj = NULL;
    int full = 0;
    pthread_mutex_lock(&s_lock);
    if (index1 >= 1 && index1 <= s_slot_count) {
        slot* s = &s_slots[index1 - 1];
        if (s->kind == kind && s->generation == generation) {
            if (s_held_n < HOLD_MAX) {
                obj = s->obj;
                ++*object_refs(obj, kind);
                s_held[s_held_n].obj = obj;
                s_held[s_held_n].kind = kind;
                ++s_held_n;
            } else {
                full = 1;
            }
        }
    }
    pthread_mutex_unlock(&s_lock);
    if (full)
        sdfccd__error(SDFCCD_INVALID_HANDLE, "%s handle {%u, %u}: more than %d handles in use by nested calls on this thread",
                      kind_noun(kind), index1, generation, HOLD_MAX);
    else if (!obj)
        sdfccd__error(SDFCCD_INVALID_HANDLE, "%s handle {%u, %u} is not a live %s", kind_noun(kind), index1, generation, kind_noun(kind));
    return obj;
}

sdfccd__sdf* sdfccd__sdf_acquire(sdfccd_SdfId id) { return acquire(id.index1, id.generation, SDFCCD__KIND_SDF); }
sdfccd__mesh* sdfccd__mesh_acquire(sdfccd_MeshId id) { return acquire(id.index1, id.generation, SDFCCD__KIND_MESH); }

/* Removes the handle and drops its reference (the object lives on while calls or combinations
 * still hold one). */
static sdfccd_Status destroy_handle(uint32_t index1, uint32_t generation, uint32_t kind, const char* fn)
{
    void* obj = registry_remove(index1, generation, kind);
    if (!obj)
        return sdfccd__error(SDFCCD_INVALID_HANDLE, "%s: handle {%u, %u} is not a live %s", fn, index1, generation, kind_noun(kind));
    object_release(obj, kind);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_destroy_sdf(sdfccd_SdfId id) { return destroy_handle(id.index1, id.generation, SDFCCD__KIND_SDF, "sdfccd_destroy_sdf"); }
sdfccd_Status sdfccd_destroy_mesh(sdfccd_MeshId id) { return destroy_handle(id.index1, id.generation, SDFCCD__KIND_MESH, "sdfccd_destroy_mesh"); }

sdfccd_Pose sdfccd_pose_identity(void)
{
    sdfccd_Pose p = { { 0, 0, 0 }, { 1, 0, 0, 0 } };
    return p;
}
