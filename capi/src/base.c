/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: allocator hooks and byte count, error messages, version queries and the
 * generation-checked handle registry shared by SDFs and meshes. */
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

const char* sdfccd_status_string(sdfccd_Status status)
{
    static const char* const names[SDFCCD_STATUS_COUNT] = {
        "SDFCCD_OK", "SDFCCD_INVALID_ARGUMENT", "SDFCCD_INVALID_HANDLE", "SDFCCD_DEGENERATE",
        "SDFCCD_OUT_OF_MEMORY", "SDFCCD_IO_ERROR", "SDFCCD_FORMAT_ERROR", "SDFCCD_UNSUPPORTED",
        "SDFCCD_BAD_STATE",
    };
    if ((int)status < 0 || status >= SDFCCD_STATUS_COUNT) return "SDFCCD_UNKNOWN_STATUS";
    return names[status];
}

/* ---------------- version ---------------- */

int32_t sdfccd_version(void) { return SDFCCD_VERSION_ID; }
const char* sdfccd_version_string(void) { return "0.1.0"; }
int sdfccd_is_double_precision(void) { return 1; }

#ifndef SDFCCD_HAVE_ASSIMP
#define SDFCCD_HAVE_ASSIMP 0
#endif
#define SDFCCD_STR2(x) #x
#define SDFCCD_STR(x) SDFCCD_STR2(x)
const char* sdfccd_configuration_string(void)
{
    return "sdfccd 0.1.0; scalar=double; assimp=" SDFCCD_STR(SDFCCD_HAVE_ASSIMP)
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

enum { KIND_FREE = 0, KIND_SDF = 1, KIND_MESH = 2 };

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

/* Registry storage is not counted in sdfccd_byte_count (it is released when the table empties). */
static void registry_maybe_shrink(void)
{
    for (uint32_t i = 0; i < s_slot_count; ++i)
        if (s_slots[i].kind != KIND_FREE) return;
    /* Keep the generations growing across a reset so stale ids never match again. */
}

static int registry_add(void* obj, uint32_t kind, uint32_t* out_index1, uint32_t* out_generation)
{
    pthread_mutex_lock(&s_lock);
    uint32_t i;
    if (s_free_head != UINT32_MAX) {
        i = s_free_head;
        s_free_head = s_slots[i].next_free;
    } else {
        if (s_slot_count == s_slot_capacity) {
            uint32_t cap = s_slot_capacity ? 2 * s_slot_capacity : 64;
            slot* n = realloc(s_slots, (size_t)cap * sizeof *n);
            if (!n) { pthread_mutex_unlock(&s_lock); return 0; }
            s_slots = n;
            s_slot_capacity = cap;
        }
        i = s_slot_count++;
        s_slots[i].generation = 0;
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

static void* registry_get(uint32_t index1, uint32_t generation, uint32_t kind)
{
    void* obj = NULL;
    pthread_mutex_lock(&s_lock);
    if (index1 >= 1 && index1 <= s_slot_count) {
        slot* s = &s_slots[index1 - 1];
        if (s->kind == kind && s->generation == generation) obj = s->obj;
    }
    pthread_mutex_unlock(&s_lock);
    return obj;
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
            s->kind = KIND_FREE;
            s->next_free = s_free_head;
            s_free_head = index1 - 1;
            registry_maybe_shrink();
        }
    }
    pthread_mutex_unlock(&s_lock);
    return obj;
}

/* ---------------- SDF objects ---------------- */

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

void sdfccd__sdf_release(sdfccd__sdf* s)
{
    if (!s) return;
    /* References only change under the registry lock so concurrent destroys stay consistent. */
    pthread_mutex_lock(&s_lock);
    uint32_t left = --s->refs;
    pthread_mutex_unlock(&s_lock);
    if (left) return;
    if (s->release_extra) s->release_extra(s);
    for (int i = 0; i < 2; ++i) sdfccd__sdf_release(s->children[i]);
    sdfccd__free(s->storage, s->storage_size);
    sdfccd__free(s, sizeof *s);
}

void sdfccd__sdf_retain(sdfccd__sdf* s)
{
    pthread_mutex_lock(&s_lock);
    s->refs++;
    pthread_mutex_unlock(&s_lock);
}

sdfccd_Status sdfccd__sdf_register(sdfccd__sdf* s, sdfccd_SdfId* out_id)
{
    sdfccd_SdfId id = { 0, 0 };
    if (!registry_add(s, KIND_SDF, &id.index1, &id.generation)) {
        sdfccd__sdf_release(s);
        return sdfccd__oom("an SDF handle");
    }
    *out_id = id;
    return SDFCCD_OK;
}

sdfccd__sdf* sdfccd__sdf_lookup(sdfccd_SdfId id)
{
    sdfccd__sdf* s = registry_get(id.index1, id.generation, KIND_SDF);
    if (!s) sdfccd__error(SDFCCD_INVALID_HANDLE, "SDF handle {%u, %u} is not a live SDF", id.index1, id.generation);
    return s;
}

sdfccd_Status sdfccd_destroy_sdf(sdfccd_SdfId id)
{
    sdfccd__sdf* s = registry_remove(id.index1, id.generation, KIND_SDF);
    if (!s) return sdfccd__error(SDFCCD_INVALID_HANDLE, "sdfccd_destroy_sdf: handle {%u, %u} is not a live SDF", id.index1, id.generation);
    sdfccd__sdf_release(s);
    return SDFCCD_OK;
}

/* ---------------- mesh objects ---------------- */

sdfccd_Status sdfccd__mesh_create(const double* vertices, uint32_t vertex_count, const uint32_t* indices,
                                  uint32_t triangle_count, int drop_degenerate, const char* what,
                               sdfccd_MeshId* out_mesh)
{
    if (!vertices || !indices) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: vertices or indices is NULL", what);
    if (vertex_count == 0 || triangle_count == 0)
        return sdfccd__error(SDFCCD_DEGENERATE, "%s: the mesh is empty (%u vertices, %u triangles)", what, vertex_count, triangle_count);
    if (vertex_count > (1u << 30) || triangle_count > (1u << 30))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: too many vertices or triangles", what);
    for (uint32_t i = 0; i < 3 * vertex_count; ++i)
        if (!isfinite(vertices[i]))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: vertex %u has a non-finite coordinate", what, i / 3);
    uint32_t kept = 0;
    for (uint32_t t = 0; t < triangle_count; ++t) {
        const uint32_t* f = indices + 3 * t;
        if (f[0] >= vertex_count || f[1] >= vertex_count || f[2] >= vertex_count)
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: triangle %u has a vertex index out of range (%u vertices)", what, t, vertex_count);
        scc_vec3 a = { vertices[3 * f[0]], vertices[3 * f[0] + 1], vertices[3 * f[0] + 2] };
        scc_vec3 b = { vertices[3 * f[1]], vertices[3 * f[1] + 1], vertices[3 * f[1] + 2] };
        scc_vec3 c = { vertices[3 * f[2]], vertices[3 * f[2] + 1], vertices[3 * f[2] + 2] };
        double scale = fmax(scc_len2(scc_sub(b, a)), scc_len2(scc_sub(c, a)));
        int degenerate = !(scc_triangle_area2(a, b, c) > 1e-12 * scale) || scale == 0.0;
        if (degenerate && !drop_degenerate)
            return sdfccd__error(SDFCCD_DEGENERATE, "%s: triangle %u (vertices %u %u %u) has zero area", what, t, f[0], f[1], f[2]);
        kept += !degenerate;
    }
    if (kept == 0) return sdfccd__error(SDFCCD_DEGENERATE, "%s: every triangle has zero area", what);

    size_t vbytes = (size_t)vertex_count * sizeof(scc_vec3);
    size_t ibytes = (size_t)kept * 3 * sizeof(uint32_t);
    sdfccd__mesh* m = sdfccd__calloc(sizeof *m);
    void* block = sdfccd__alloc(vbytes + ibytes);
    if (!m || !block) {
        sdfccd__free(m, sizeof *m);
        sdfccd__free(block, vbytes + ibytes);
        return sdfccd__oom("a mesh");
    }
    scc_vec3* v = block;
    uint32_t* idx = (uint32_t*)((char*)block + vbytes);
    scc_aabb box = { { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    for (uint32_t i = 0; i < vertex_count; ++i) {
        v[i] = scc_v3(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
        box.lo = scc_vmin(box.lo, v[i]);
        box.hi = scc_vmax(box.hi, v[i]);
    }
    uint32_t k = 0;
    for (uint32_t t = 0; t < triangle_count; ++t) {
        const uint32_t* f = indices + 3 * t;
        double scale = fmax(scc_len2(scc_sub(v[f[1]], v[f[0]])), scc_len2(scc_sub(v[f[2]], v[f[0]])));
        if (!(scc_triangle_area2(v[f[0]], v[f[1]], v[f[2]]) > 1e-12 * scale) || scale == 0.0) continue;
        idx[3 * k] = f[0]; idx[3 * k + 1] = f[1]; idx[3 * k + 2] = f[2];
        ++k;
    }
    m->block = block;
    m->block_size = vbytes + ibytes;
    m->mesh.vertices = v;
    m->mesh.indices = idx;
    m->mesh.vertex_count = vertex_count;
    m->mesh.triangle_count = kept;
    m->mesh.bounds = box;
    m->dropped_triangles = triangle_count - kept;
    m->refs = 1;
    m->bsh = scc_bsh_build(&m->mesh, sdfccd__allocator()); /* broad phase of the mesh query */
    if (!m->bsh) {
        sdfccd__free(block, m->block_size);
        sdfccd__free(m, sizeof *m);
        return sdfccd__oom("a mesh's bounding-sphere hierarchy");
    }
    m->mesh.bsh = m->bsh;
    sdfccd_MeshId id = { 0, 0 };
    if (!registry_add(m, KIND_MESH, &id.index1, &id.generation)) {
        scc_bsh_destroy(m->bsh, sdfccd__allocator());
        sdfccd__free(block, m->block_size);
        sdfccd__free(m, sizeof *m);
        return sdfccd__oom("a mesh handle");
    }
    *out_mesh = id;
    return SDFCCD_OK;
}

sdfccd__mesh* sdfccd__mesh_lookup(sdfccd_MeshId id)
{
    sdfccd__mesh* m = registry_get(id.index1, id.generation, KIND_MESH);
    if (!m) sdfccd__error(SDFCCD_INVALID_HANDLE, "mesh handle {%u, %u} is not a live mesh", id.index1, id.generation);
    return m;
}

sdfccd_Status sdfccd_destroy_mesh(sdfccd_MeshId id)
{
    sdfccd__mesh* m = registry_remove(id.index1, id.generation, KIND_MESH);
    if (!m) return sdfccd__error(SDFCCD_INVALID_HANDLE, "sdfccd_destroy_mesh: handle {%u, %u} is not a live mesh", id.index1, id.generation);
    scc_bsh_destroy(m->bsh, sdfccd__allocator());
    sdfccd__free(m->block, m->block_size);
    sdfccd__free(m, sizeof *m);
    return SDFCCD_OK;
}

sdfccd_MeshDef sdfccd_default_mesh_def(void)
{
    sdfccd_MeshDef d;
    memset(&d, 0, sizeof d);
    d.internal_value = 0x5DFCCD01;
    return d;
}

sdfccd_Status sdfccd_create_mesh(const sdfccd_MeshDef* def, sdfccd_MeshId* out_mesh)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(def, "sdfccd_create_mesh: def")) || (st = sdfccd__check_ptr(out_mesh, "sdfccd_create_mesh: out_mesh")))
        return st;
    if (def->internal_value != 0x5DFCCD01)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_mesh: def was not initialised with sdfccd_default_mesh_def()");
    return sdfccd__mesh_create(def->vertices, def->vertex_count, def->indices, def->triangle_count,
                               def->drop_degenerate, "sdfccd_create_mesh", out_mesh);
}

sdfccd_Status sdfccd_mesh_get_info(sdfccd_MeshId id, sdfccd_MeshInfo* out_info)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_info, "sdfccd_mesh_get_info: out_info"))) return st;
    sdfccd__mesh* m = sdfccd__mesh_lookup(id);
    if (!m) return SDFCCD_INVALID_HANDLE;
    out_info->vertex_count = m->mesh.vertex_count;
    out_info->triangle_count = m->mesh.triangle_count;
    out_info->dropped_triangles = m->dropped_triangles;
    out_info->bounds = sdfccd__pbox(m->mesh.bounds);
    out_info->memory_bytes = (int64_t)(m->block_size + sizeof *m + (m->bsh ? m->bsh->bytes : 0));
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_mesh_get_data(sdfccd_MeshId id, double* out_vertices, uint32_t* out_indices)
{
    sdfccd__mesh* m = sdfccd__mesh_lookup(id);
    if (!m) return SDFCCD_INVALID_HANDLE;
    if (out_vertices)
        for (uint32_t i = 0; i < m->mesh.vertex_count; ++i) {
            out_vertices[3 * i] = m->mesh.vertices[i].x;
            out_vertices[3 * i + 1] = m->mesh.vertices[i].y;
            out_vertices[3 * i + 2] = m->mesh.vertices[i].z;
        }
    if (out_indices) memcpy(out_indices, m->mesh.indices, (size_t)m->mesh.triangle_count * 3 * sizeof(uint32_t));
    return SDFCCD_OK;
}

sdfccd_Pose sdfccd_pose_identity(void)
{
    sdfccd_Pose p = { { 0, 0, 0 }, { 1, 0, 0, 0 } };
    return p;
}
