/* SPDX-License-Identifier: MIT
 * sdfccd C ABI internals: the allocator, error messages and the handle registry.
 * Only files under capi/src (and tests that say so in their CMake) include this.
 *
 * Names: the public API is sdfccd_* / SDFCCD_*; what the ABI layer shares between its own files
 * is sdfccd__* (two underscores: internal, never in an installed header; hidden in the shared
 * library); the core is scc_* (core/). So every symbol of libsdfccd starts with sdfccd_ or scc_. */
#ifndef SDFCCD_CAPI_INTERNAL_H
#define SDFCCD_CAPI_INTERNAL_H

#include <math.h>
#include <stdarg.h>
#include <string.h>
#include "sdfccd/sdfccd.h"
#include "../../core/alloc.h"
#include "../../core/mesh.h"
#include "../../core/sdf.h"
#include "../../core/workspace.h"

/* ---- allocation (counted; routed to the user's hooks) ---- */
void* sdfccd__alloc(size_t size);          /* NULL on failure (no message set) */
void* sdfccd__calloc(size_t size);         /* zeroed */
void sdfccd__free(void* p, size_t size);
const scc_allocator* sdfccd__allocator(void); /* what to hand to core routines */

/* ---- errors: set the thread's message and return `status` ---- */
sdfccd_Status sdfccd__error(sdfccd_Status status, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
sdfccd_Status sdfccd__oom(const char* what);
/* Validation helpers: return SDFCCD_OK or an INVALID_ARGUMENT status with a message naming `what`. */
sdfccd_Status sdfccd__check_ptr(const void* p, const char* what);
sdfccd_Status sdfccd__check_finite(double v, const char* what);
sdfccd_Status sdfccd__check_vec(sdfccd_Vec3 v, const char* what);
sdfccd_Status sdfccd__check_pose(sdfccd_Pose pose, const char* what, scc_xform* out); /* validated, normalised */

/* ---- batches on threads (threads.c) ---- */
#define SDFCCD__MAX_THREADS 256
/* One item of a batch; `slot` in [0, threads) is the running thread's own (for its workspace). */
typedef sdfccd_Status (*sdfccd__RunItem)(void* ctx, int32_t item, int32_t slot);
/* Runs every item in [0, count) on up to `threads` threads. If any failed, the first one is run
 * again on this thread in slot 0 and its status returned with the message "fn: noun i: ...". */
sdfccd_Status sdfccd__run_threads(const char* fn, const char* noun, sdfccd__RunItem run, void* ctx, int32_t count, int32_t threads);

static inline scc_vec3 sdfccd__v(sdfccd_Vec3 v) { scc_vec3 r = { v.x, v.y, v.z }; return r; }
static inline sdfccd_Vec3 sdfccd__pv(scc_vec3 v) { sdfccd_Vec3 r = { v.x, v.y, v.z }; return r; }
static inline scc_aabb sdfccd__box(sdfccd_Aabb b) { scc_aabb r = { sdfccd__v(b.lo), sdfccd__v(b.hi) }; return r; }
static inline sdfccd_Aabb sdfccd__pbox(scc_aabb b) { sdfccd_Aabb r = { sdfccd__pv(b.lo), sdfccd__pv(b.hi) }; return r; }

/* ---- defs: every sdfccd_default_*() sets internal_value to this cookie; a def without it was
 * not initialised by its default function ---- */
#define SDFCCD__DEF_COOKIE 0x5DFCCD01
/* OK, or INVALID_ARGUMENT "FN: WHAT was not initialised with DEFAULT_FN()" when the cookie is missing. */
sdfccd_Status sdfccd__check_def(int32_t internal_value, const char* fn, const char* what, const char* default_fn);
/* How every sdfccd_default_*() starts its def `d`: every field zero, then the cookie. */
#define SDFCCD__DEF_BEGIN(d) (memset(&(d), 0, sizeof(d)), (d).internal_value = SDFCCD__DEF_COOKIE)
/* The opening checks of every create function that takes a def: FN's `def` and `out` (named
 * OUT_NAME in the message) are not NULL and def was initialised by DEFAULT_FN. */
#define SDFCCD__CHECK_DEF_ARGS(fn, def, out, out_name, default_fn) \
    sdfccd__check_def_args((fn), (def), (def) ? (def)->internal_value : 0, (out), (out_name), (default_fn))
static inline sdfccd_Status sdfccd__check_def_args(const char* fn, const void* def, int32_t internal_value, const void* out,
                                                   const char* out_name, const char* default_fn)
{
    if (!def) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: def is NULL", fn);
    if (!out) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: %s is NULL", fn, out_name);
    return sdfccd__check_def(internal_value, fn, "def was", default_fn);
}

/* The arguments of FN on a batch of points: count >= 0 and, when count > 0, `points` and `out`
 * (named OUT_NAME in the message) not NULL and every point finite. */
static inline sdfccd_Status sdfccd__check_points(const char* fn, const sdfccd_Vec3* points, int32_t count, const void* out,
                                                 const char* out_name)
{
    if (count < 0) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: count = %d < 0", fn, (int)count);
    if (count == 0) return SDFCCD_OK;
    if (!points) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: points is NULL", fn);
    if (!out) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: %s is NULL", fn, out_name);
    for (int32_t i = 0; i < count; ++i) {
        const sdfccd_Vec3 p = points[i];
        if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: a point is not finite (%g, %g, %g)", fn, p.x, p.y, p.z);
    }
    return SDFCCD_OK;
}

/* ---- the handle registry (base.c), shared by SDF and mesh objects ---- */
enum { SDFCCD__KIND_FREE = 0, SDFCCD__KIND_SDF = 1, SDFCCD__KIND_MESH = 2 };
/* Adds `obj` under a new generation-checked id; 0 when the table cannot grow. */
int sdfccd__registry_add(void* obj, uint32_t kind, uint32_t* out_index1, uint32_t* out_generation);

/* ---- SDF objects ----
 * A sdfccd__sdf owns one block `storage` (the concrete core SDF, which embeds scc_sdf first),
 * optional extra memory freed by `release_extra`, and references to up to two children. */
typedef struct sdfccd__sdf {
    const scc_sdf* sdf;              /* == storage for built-in kinds */
    void* storage;
    size_t storage_size;
    void (*release_extra)(struct sdfccd__sdf* self); /* may be NULL */
    void* extra;                     /* free for release_extra's use */
    struct sdfccd__sdf* children[2];
    int64_t memory_bytes;            /* storage + extra, reported by sdfccd_sdf_get_info */
    uint32_t refs;
} sdfccd__sdf;

/* Allocates a wrapper with `storage_size` zeroed bytes of storage; sdf = storage. NULL on OOM. */
sdfccd__sdf* sdfccd__sdf_new(size_t storage_size);
/* Drops one reference; frees storage, extra (via release_extra) and child references at zero. */
void sdfccd__sdf_release(sdfccd__sdf* s);
void sdfccd__sdf_retain(sdfccd__sdf* s); /* adds a reference (for combinations that use a child) */
/* Registers a new object (takes over its one reference). On failure the object is released. */
sdfccd_Status sdfccd__sdf_register(sdfccd__sdf* s, sdfccd_SdfId* out_id);

/* ---- mesh objects (mesh_api.c) ---- */
typedef struct sdfccd__mesh {
    scc_mesh mesh;                   /* arrays point into `block` */
    void* block;
    size_t block_size;
    uint32_t dropped_triangles;
    uint32_t refs;
    struct scc_bsh* bsh;             /* broad-phase sphere hierarchy (core/bsh.h), built at creation and
                                        owned; mesh.bsh points to it (memory counted by the allocator) */
} sdfccd__mesh;

/* Creates a mesh object from arrays (validated). `what` names the source in messages. */
sdfccd_Status sdfccd__mesh_create(const double* vertices, uint32_t vertex_count, const uint32_t* indices,
                                  uint32_t triangle_count, int drop_degenerate, const char* what,
                               sdfccd_MeshId* out_mesh);
/* Drops one reference; frees the mesh at zero. */
void sdfccd__mesh_release(sdfccd__mesh* m);

/* ---- references held by a call in flight (safe concurrent destroy) ----
 * The only way from a handle to its object: acquire looks up a live handle and takes a
 * reference recorded in a per-thread list. Every public call that takes a handle runs its body
 * through SDFCCD__HELD_CALL, which drops what the body acquired when it returns, so a destroy
 * racing the call frees the object only after the call ends (never a use after free). */
sdfccd__sdf* sdfccd__sdf_acquire(sdfccd_SdfId id);   /* NULL with an INVALID_HANDLE message */
sdfccd__mesh* sdfccd__mesh_acquire(sdfccd_MeshId id); /* NULL with an INVALID_HANDLE message */
int sdfccd__hold_mark(void);
void sdfccd__hold_release_to(int mark);
/* `return body;` with every reference the body acquired dropped after it ran. */
#define SDFCCD__HELD_CALL(body)                           \
    do {                                                  \
        const int mark_ = sdfccd__hold_mark();            \
        const sdfccd_Status st_ = (body);                 \
        sdfccd__hold_release_to(mark_);                   \
        return st_;                                       \
    } while (0)
/* DEGENERATE with a message when the topology cannot give correct signs, else OK. */
struct scc_mesh_topology;
sdfccd_Status sdfccd__mesh_topology_message(const struct scc_mesh_topology* t, const char* fn);

/* Validates public query params and converts them to the core's (the only place this is done;
 * internal tools that call the core directly use it too). Declared with an incomplete type so
 * this header does not pull in core/ccd.h. */
struct scc_params;
sdfccd_Status sdfccd__convert_params(const sdfccd_QueryParams* in, const char* fn, struct scc_params* out);

/* ---- the guard's argument checks (contact_api.c), shared with guard_api.c ---- */
struct scc_xform;
struct scc_body_state;
/* A finite pose with a unit orientation (within 1e-4, then normalised into *out) and a position
 * within SDFCCD_MAX_QUERY_MAGNITUDE; `what` names it in messages. */
sdfccd_Status sdfccd__unit_pose(const sdfccd_Pose* pose, const char* what, struct scc_xform* out);
/* Guard params (from sdfccd_default_guard_params(), a finite tolerance > 0, no DCD) as the core's
 * query params and tolerance. */
sdfccd_Status sdfccd__convert_guard_params(const sdfccd_GuardParams* in, const char* fn, struct scc_params* out, double* out_tol);
/* A body state (finite, inverse mass >= 0) in the core's form; "fn: what" names it in messages. */
sdfccd_Status sdfccd__body_state(const sdfccd_BodyState* in, const char* fn, const char* what, struct scc_body_state* out);

/* ---- query arguments (ccd_api.c), shared by every call that runs a query ---- */
struct scc_rigid;
/* A public rigid motion over [t0, t1] (validated: finite, within SDFCCD_MAX_QUERY_MAGNITUDE and
 * SDFCCD_MAX_ROTATION_ANGLE) as the core's; `what` names it in messages. */
sdfccd_Status sdfccd__convert_motion(const sdfccd_RigidMotion* in, double t0, double t1, const char* what, struct scc_rigid* out);
/* The body's and the SDF's rotations together within SDFCCD_MAX_ROTATION_ANGLE (`sdf` may be NULL). */
sdfccd_Status sdfccd__check_total_rotation(const struct scc_rigid* body, const struct scc_rigid* sdf, double dt, const char* fn);
/* Finite t0 <= t1 with a finite difference. */
sdfccd_Status sdfccd__check_interval(double t0, double t1, const char* fn);
/* The public result state of a core scc_state (core/ccd.h). */
sdfccd_ResultState sdfccd__public_state(int core_state);
/* The mesh's coordinates within SDFCCD_MAX_QUERY_MAGNITUDE. */
sdfccd_Status sdfccd__check_mesh_bounds(const sdfccd__mesh* m, const char* fn);

/* Per-vertex linear motion: `start` and `end` (vertex_count each, checked finite and within
 * SDFCCD_MAX_QUERY_MAGNITUDE) copied into the workspace's vertex slot: *out holds start then end. */
sdfccd_Status sdfccd__linear_vertices(const sdfccd__mesh* m, const sdfccd_Vec3* start, const sdfccd_Vec3* end, scc_workspace* ws,
                                      const char* fn, scc_vec3** out);

/* A caller-kept workspace: the mesh query's scratch storage, reused from call to call. */
struct sdfccd_Workspace {
    scc_workspace ws;
};


#endif
