/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: grid SDF handles, building grids from meshes and SDFs on a small pthread
 * pool, and grid inspection. The grid itself (cell, evaluation, builder) lives in core/grid*.c. */
#include "grid_internal.h"

#include <pthread.h>
#include <stdatomic.h>
#include <string.h>
#include <unistd.h>

#include "../../core/mesh_distance.h"


/* ---------------- handles ---------------- */

static void grid_release(sdfccd__sdf* s)
{
    scc_grid_destroy((scc_grid*)s->extra);
    s->extra = NULL;
}

sdfccd_Status sdfccd__grid_register(scc_grid* g, sdfccd_SdfId* out_sdf)
{
    sdfccd__sdf* s = sdfccd__sdf_new(sizeof(scc_grid*));
    if (!s) {
        scc_grid_destroy(g);
        return sdfccd__oom("a grid SDF handle");
    }
    *(scc_grid**)s->storage = g;
    s->sdf = &g->base;
    s->extra = g;
    s->release_extra = grid_release;
    s->memory_bytes = (int64_t)(s->storage_size + scc_grid_memory(g));
    return sdfccd__sdf_register(s, out_sdf);
}

sdfccd_Status sdfccd__grid_acquire(sdfccd_SdfId id, const char* fn, scc_grid** out_grid)
{
    *out_grid = NULL;
    sdfccd__sdf* s = sdfccd__sdf_acquire(id); /* held until the caller's SDFCCD__HELD_CALL returns */
    if (!s) return sdfccd__error(SDFCCD_INVALID_HANDLE, "%s: SDF handle {%u, %u} is not a live SDF", fn, id.index1, id.generation);
    if (s->release_extra != grid_release)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: SDF handle {%u, %u} is not a grid", fn, id.index1, id.generation);
    *out_grid = (scc_grid*)s->extra;
    return SDFCCD_OK;
}

/* ---------------- thread pool ---------------- */

typedef struct pool_run {
    scc_task_fn* task;
    void* ctx;
    uint32_t count;
    atomic_uint next;
    atomic_uint done;
    atomic_int stop;     /* set when the build is cancelled: no new tasks start */
} pool_run;

static void pool_work(pool_run* r)
{
    for (;;) {
        if (atomic_load(&r->stop)) return;
        const unsigned i = atomic_fetch_add(&r->next, 1u);
        if (i >= r->count) return;
        r->task(r->ctx, i);
        atomic_fetch_add(&r->done, 1u);
    }
}

static void* pool_thread(void* arg)
{
    pool_work(arg);
    return NULL;
}

void sdfccd__pool_init(sdfccd__pool* p, int threads, sdfccd_ProgressFcn* progress, void* user)
{
    memset(p, 0, sizeof *p);
    if (threads <= 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        threads = n > 0 ? (int)n : 1;
    }
    if (threads > 256) threads = 256;
    p->threads = threads;
    p->progress = progress;
    p->progress_user = user;
    /* progress ranges per stage: nodes (dense) 0-0.9, corners then edges (band) 0-0.3-0.9, cells 0.9-1 */
    p->stage_base[SCC_GRID_STAGE_NODES] = 0.0; p->stage_weight[SCC_GRID_STAGE_NODES] = 0.9;
    p->stage_base[SCC_GRID_STAGE_CELLS] = 0.9; p->stage_weight[SCC_GRID_STAGE_CELLS] = 0.1;
    p->stage_base[SCC_GRID_STAGE_CORNERS] = 0.0; p->stage_weight[SCC_GRID_STAGE_CORNERS] = 0.3;
    p->stage_base[SCC_GRID_STAGE_EDGES] = 0.3; p->stage_weight[SCC_GRID_STAGE_EDGES] = 0.6;
    p->last_reported = -1.0;
}

static void pool_report(sdfccd__pool* p, double f)
{
    if (!p->progress || p->cancelled || f < p->last_reported) return;
    if (f < 1.0 && f - p->last_reported < 0.005) return;
    p->last_reported = f;
    if (p->progress(f, p->progress_user) != 0) p->cancelled = 1;
}

int sdfccd__pool_parallel_for(void* user, int stage, uint32_t count, scc_task_fn* task, void* ctx)
{
    sdfccd__pool* p = user;
    const int st = stage >= 0 && stage < 4 ? stage : 0;
    pool_run r;
    r.task = task;
    r.ctx = ctx;
    r.count = count;
    atomic_init(&r.next, 0u);
    atomic_init(&r.done, 0u);
    atomic_init(&r.stop, p->cancelled);
    int extra = p->threads - 1;
    if ((uint32_t)extra > count) extra = (int)count;
    pthread_t tids[256];
    int started = 0;
    for (int i = 0; i < extra; ++i) {
        if (pthread_create(&tids[started], NULL, pool_thread, &r) != 0) break; /* run with fewer */
        ++started;
    }
    /* The calling thread works too and is the only one that reports progress. */
    while (!p->cancelled) {
        const unsigned i = atomic_fetch_add(&r.next, 1u);
        if (i >= r.count) break;
        task(ctx, i);
        const unsigned done = atomic_fetch_add(&r.done, 1u) + 1u;
        if (count) pool_report(p, p->stage_base[st] + p->stage_weight[st] * (double)done / (double)count);
        if (p->cancelled) atomic_store(&r.stop, 1);
    }
    for (int i = 0; i < started; ++i) pthread_join(tids[i], NULL);
    pool_report(p, st == SCC_GRID_STAGE_CELLS ? 1.0 : p->stage_base[st] + p->stage_weight[st]);
    return p->cancelled;
}

/* ---------------- defs ---------------- */

static sdfccd_Status check_grid_def(const sdfccd_GridDef* def, const char* fn)
{
    sdfccd_Status st;
    if (!def) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: def is NULL", fn);
    if ((st = sdfccd__check_def(def->internal_value, fn, "def was", "sdfccd_default_grid_def"))) return st;
    for (int i = 0; i < 3; ++i)
        if (def->resolution[i] < 1)
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: resolution[%d] = %d must be >= 1", fn, i, def->resolution[i]);
    const uint64_t n = (uint64_t)def->resolution[0] * (uint64_t)def->resolution[1] * (uint64_t)def->resolution[2];
    if (n > 0x7FFFFFFEull || scc_grid_dense_node_count((const uint32_t[3]){ (uint32_t)def->resolution[0], (uint32_t)def->resolution[1], (uint32_t)def->resolution[2] }) >= 0xFFFFFFFFull)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: resolution %d x %d x %d needs more than 2^32 nodes", fn,
                             def->resolution[0], def->resolution[1], def->resolution[2]);
    if (def->max_bytes < 1) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: max_bytes = %lld must be >= 1", fn, (long long)def->max_bytes);
    {
        /* Dense: 8 bytes per node and 8 per cell (map and cell bounds). Narrow band: what it holds
         * whatever the band (12 bytes per grid vertex, 8 per cell); the band-dependent part is
         * checked by the builder before each allocation (scc_grid_build_def::max_bytes). */
        const uint64_t nodes = scc_grid_dense_node_count((const uint32_t[3]){ (uint32_t)def->resolution[0], (uint32_t)def->resolution[1], (uint32_t)def->resolution[2] });
        const double vertices = ((double)def->resolution[0] + 1) * ((double)def->resolution[1] + 1) * ((double)def->resolution[2] + 1);
        const int band = def->band > 0.0 && isfinite(def->band);
        const double need = band ? 12.0 * vertices + 8.0 * (double)n : 8.0 * (double)nodes + 8.0 * (double)n;
        if (need > (double)def->max_bytes)
            return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: a %d x %d x %d %s grid needs about %.4g bytes (%s), above max_bytes (%lld)",
                                 fn, def->resolution[0], def->resolution[1], def->resolution[2], band ? "narrow-band" : "dense", need,
                                 band ? "vertex values and cell tables before the band is known" : "nodes and cell tables",
                                 (long long)def->max_bytes);
    }
    if (!def->fit_domain) {
        if ((st = sdfccd__check_vec(def->domain.lo, "domain.lo")) || (st = sdfccd__check_vec(def->domain.hi, "domain.hi"))) return st;
        if (!(def->domain.lo.x < def->domain.hi.x && def->domain.lo.y < def->domain.hi.y && def->domain.lo.z < def->domain.hi.z))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: domain.lo must be below domain.hi on every axis", fn);
    }
    if (!(def->padding >= 0.0) || !isfinite(def->padding))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: padding = %g must be finite and >= 0", fn, def->padding);
    if (!(def->band >= 0.0) || isnan(def->band))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: band = %g must be >= 0 (0 = dense)", fn, def->band);
    if (def->threads < 0) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: threads = %d must be >= 0", fn, def->threads);
    return SDFCCD_OK;
}

/* The grid box as built: coordinates within SCC_GRID_MAX_COORDINATE and cells at least
 * SCC_GRID_MIN_CELL wide, so no distance or gradient of the grid overflows. */
static sdfccd_Status check_domain(scc_aabb d, const sdfccd_GridDef* def, const char* fn)
{
    const double lo[3] = { d.lo.x, d.lo.y, d.lo.z }, hi[3] = { d.hi.x, d.hi.y, d.hi.z };
    for (int i = 0; i < 3; ++i) {
        if (!(fabs(lo[i]) <= SCC_GRID_MAX_COORDINATE && fabs(hi[i]) <= SCC_GRID_MAX_COORDINATE))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the domain [%g, %g] on axis %d exceeds +-%g", fn, lo[i], hi[i], i,
                                 SCC_GRID_MAX_COORDINATE);
        if (!((hi[i] - lo[i]) / def->resolution[i] >= SCC_GRID_MIN_CELL))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: cells narrower than %g on axis %d", fn, SCC_GRID_MIN_CELL, i);
    }
    return SDFCCD_OK;
}

static sdfccd_Status build_status(scc_grid_build_status st, const char* fn)
{
    switch (st) {
    case SCC_GRID_BUILD_OK: return SDFCCD_OK;
    case SCC_GRID_BUILD_OUT_OF_MEMORY: return sdfccd__oom("a grid");
    case SCC_GRID_BUILD_TOO_LARGE: return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the grid needs more than 2^32 nodes", fn);
    case SCC_GRID_BUILD_EMPTY_BAND: return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the band culled every cell (no surface inside the domain?)", fn);
    case SCC_GRID_BUILD_BAD_VALUE: return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the source returned a non-finite value or one above 1e100 in magnitude at a node", fn);
    case SCC_GRID_BUILD_CANCELLED: return sdfccd__error(SDFCCD_CANCELLED, "%s: cancelled by the progress callback", fn);
    case SCC_GRID_BUILD_OVER_LIMIT: break; /* reported by the caller, which knows the figure */
    }
    return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: unknown build failure", fn);
}

static scc_aabb padded(scc_aabb b, double pad)
{
    if (pad > 0.0) {
        b.lo = scc_sub(b.lo, scc_v3(pad, pad, pad));
        b.hi = scc_add(b.hi, scc_v3(pad, pad, pad));
    }
    return b;
}

static void fill_build_def(scc_grid_build_def* bd, const sdfccd_GridDef* def, scc_aabb domain, sdfccd__pool* pool)
{
    memset(bd, 0, sizeof *bd);
    bd->lo = domain.lo;
    bd->hi = domain.hi;
    for (int i = 0; i < 3; ++i) bd->res[i] = (uint32_t)def->resolution[i];
    bd->band = def->band > 0.0 ? def->band : 0.0;
    bd->parallel_for = sdfccd__pool_parallel_for;
    bd->parallel_user = pool;
    bd->max_bytes = (uint64_t)def->max_bytes;
}

/* The builder's status as the public one; OVER_LIMIT with the figure the builder reached. */
static sdfccd_Status finish_build(scc_grid_build_status st, uint64_t needed, const sdfccd_GridDef* def, const char* fn)
{
    if (st != SCC_GRID_BUILD_OVER_LIMIT) return build_status(st, fn);
    return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: the narrow band's node storage needs %llu bytes, above max_bytes (%lld)", fn,
                         (unsigned long long)needed, (long long)def->max_bytes);
}

/* ---------------- build from a mesh ---------------- */

typedef struct mesh_sample_ctx {
    const scc_mesh_sdf* ms;
    double sign;
} mesh_sample_ctx;

static double mesh_sample(void* user, scc_vec3 p, uint32_t* state, double cap)
{
    const mesh_sample_ctx* c = user;
    return c->sign * scc_mesh_sdf_distance_capped(c->ms, p, state, cap);
}

static sdfccd_Status create_grid_from_mesh_held(sdfccd_MeshId mesh, const sdfccd_GridDef* def, sdfccd_SdfId* out_grid)
{
    static const char* fn = "sdfccd_create_grid_from_mesh";
    sdfccd_Status st;
    if ((st = check_grid_def(def, fn)) || (st = sdfccd__check_ptr(out_grid, "sdfccd_create_grid_from_mesh: out_grid"))) return st;
    sdfccd__mesh* m = sdfccd__mesh_acquire(mesh);
    if (!m) return SDFCCD_INVALID_HANDLE;
    scc_mesh_sdf ms;
    if (!scc_mesh_sdf_init(&ms, sdfccd__allocator(), &m->mesh)) return sdfccd__oom("a mesh distance structure");
    if (!def->allow_open_mesh && (st = sdfccd__mesh_topology_message(&ms.topology, fn))) {
        scc_mesh_sdf_destroy(&ms);
        return st;
    }
    const scc_aabb domain = def->fit_domain ? padded(scc_grid_fit_domain(m->mesh.bounds), def->padding) : sdfccd__box(def->domain);
    if ((st = check_domain(domain, def, fn))) {
        scc_mesh_sdf_destroy(&ms);
        return st;
    }
    sdfccd__pool pool;
    sdfccd__pool_init(&pool, def->threads, def->progress, def->progress_user);
    scc_grid_build_def bd;
    fill_build_def(&bd, def, domain, &pool);
    mesh_sample_ctx ctx = { &ms, def->invert ? -1.0 : 1.0 };
    bd.sample = mesh_sample;
    bd.sample_user = &ctx;
    bd.sample_lipschitz = 1.0; /* exact distance */
    scc_grid* g = NULL;
    uint64_t needed = 0;
    bd.needed_bytes = &needed;
    const scc_grid_build_status bs = scc_grid_build(sdfccd__allocator(), &bd, &g);
    st = finish_build(bs, needed, def, fn);
    scc_mesh_sdf_destroy(&ms);
    if (st) return st;
    return sdfccd__grid_register(g, out_grid);
}

sdfccd_Status sdfccd_create_grid_from_mesh(sdfccd_MeshId mesh, const sdfccd_GridDef* def, sdfccd_SdfId* out_grid)
{
    SDFCCD__HELD_CALL(create_grid_from_mesh_held(mesh, def, out_grid));
}

/* ---------------- build from an SDF ---------------- */

typedef struct sdf_sample_ctx { const scc_sdf* sdf; double sign; } sdf_sample_ctx;

static double sdf_sample(void* user, scc_vec3 p, uint32_t* state, double cap)
{
    (void)state;
    (void)cap;
    const sdf_sample_ctx* c = user;
    return c->sign * scc_sdf_eval(c->sdf, p, NULL);
}

static sdfccd_Status create_grid_from_sdf_held(sdfccd_SdfId sdf, const sdfccd_GridDef* def, sdfccd_SdfId* out_grid)
{
    static const char* fn = "sdfccd_create_grid_from_sdf";
    sdfccd_Status st;
    if ((st = check_grid_def(def, fn)) || (st = sdfccd__check_ptr(out_grid, "sdfccd_create_grid_from_sdf: out_grid"))) return st;
    sdfccd__sdf* s = sdfccd__sdf_acquire(sdf);
    if (!s) return SDFCCD_INVALID_HANDLE;
    scc_aabb domain;
    if (def->fit_domain) {
        if (!scc_vfinite(s->sdf->bounds.lo) || !scc_vfinite(s->sdf->bounds.hi))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the SDF's bounds are infinite; set fit_domain = 0 and a domain", fn);
        domain = padded(scc_grid_fit_domain(s->sdf->bounds), def->padding);
    } else {
        domain = sdfccd__box(def->domain);
    }
    if ((st = check_domain(domain, def, fn))) return st;
    sdfccd__pool pool;
    sdfccd__pool_init(&pool, def->threads, def->progress, def->progress_user);
    scc_grid_build_def bd;
    fill_build_def(&bd, def, domain, &pool);
    sdf_sample_ctx ctx = { s->sdf, def->invert ? -1.0 : 1.0 };
    bd.sample = sdf_sample;
    bd.sample_user = &ctx;
    bd.sample_lipschitz = isfinite(s->sdf->lipschitz) && s->sdf->lipschitz > 0.0 ? s->sdf->lipschitz : 0.0;
    scc_grid* g = NULL;
    uint64_t needed = 0;
    bd.needed_bytes = &needed;
    const scc_grid_build_status bs = scc_grid_build(sdfccd__allocator(), &bd, &g);
    st = finish_build(bs, needed, def, fn);
    if (st) return st;
    return sdfccd__grid_register(g, out_grid);
}

sdfccd_Status sdfccd_create_grid_from_sdf(sdfccd_SdfId sdf, const sdfccd_GridDef* def, sdfccd_SdfId* out_grid)
{
    SDFCCD__HELD_CALL(create_grid_from_sdf_held(sdf, def, out_grid));
}

/* ---------------- inspection ---------------- */

int64_t sdfccd__grid_file_bytes(const scc_grid* g)
{
    int64_t b = 124 + 3 * 8;
    for (uint32_t f = 0; f < g->field_count; ++f)
        b += 8 + 8 * (int64_t)g->fields[f].node_count + 8 + 128 * (int64_t)g->fields[f].cell_count + 8 + 4 * (int64_t)g->n_cells;
    return b;
}

static sdfccd_Status grid_get_info_held(sdfccd_SdfId grid, sdfccd_GridInfo* out_info)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_info, "sdfccd_grid_get_info: out_info"))) return st;
    scc_grid* g;
    if ((st = sdfccd__grid_acquire(grid, "sdfccd_grid_get_info", &g))) return st;
    sdfccd_GridInfo* o = out_info;
    memset(o, 0, sizeof *o);
    for (int i = 0; i < 3; ++i) o->resolution[i] = (int32_t)g->res[i];
    o->domain.lo = sdfccd__pv(g->lo);
    o->domain.hi = sdfccd__pv(g->hi);
    o->cell_size = sdfccd__pv(g->h);
    o->field_count = (int32_t)g->field_count;
    o->cell_count = (int64_t)g->n_cells;
    o->stored_cells = (int64_t)g->fields[0].cell_count;
    o->valued_cells = (int64_t)g->valued_cells;
    o->node_count = (int64_t)g->fields[0].node_count;
    o->memory_bytes = (int64_t)(scc_grid_memory(g) + sizeof(sdfccd__sdf) + sizeof(scc_grid*));
    o->file_bytes = sdfccd__grid_file_bytes(g);
    o->max_lipschitz = g->lipschitz_max;
    o->band = g->band;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_grid_get_info(sdfccd_SdfId grid, sdfccd_GridInfo* out_info)
{
    SDFCCD__HELD_CALL(grid_get_info_held(grid, out_info));
}

static sdfccd_Status grid_interpolate_held(sdfccd_SdfId grid, int32_t field, sdfccd_Vec3 p, double* out_value,
                                      sdfccd_Vec3* out_grad, int32_t* out_has_value)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_value, "sdfccd_grid_interpolate: out_value")) ||
        (st = sdfccd__check_ptr(out_has_value, "sdfccd_grid_interpolate: out_has_value")) ||
        (st = sdfccd__check_vec(p, "sdfccd_grid_interpolate: p")))
        return st;
    scc_grid* g;
    if ((st = sdfccd__grid_acquire(grid, "sdfccd_grid_interpolate", &g))) return st;
    if (field < 0 || (uint32_t)field >= g->field_count)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_grid_interpolate: field %d is not in [0, %u)", field, g->field_count);
    double v = 0.0;
    scc_vec3 gr = scc_v3(0, 0, 0);
    const int ok = scc_grid_interpolate(g, (uint32_t)field, sdfccd__v(p), &v, &gr);
    *out_has_value = ok;
    *out_value = ok ? v : 0.0;
    if (out_grad) *out_grad = ok ? sdfccd__pv(gr) : sdfccd__pv(scc_v3(0, 0, 0));
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_grid_interpolate(sdfccd_SdfId grid, int32_t field, sdfccd_Vec3 p, double* out_value,
                                      sdfccd_Vec3* out_grad, int32_t* out_has_value)
{
    SDFCCD__HELD_CALL(grid_interpolate_held(grid, field, p, out_value, out_grad, out_has_value));
}

static sdfccd_Status grid_lipschitz_bound_held(sdfccd_SdfId grid, sdfccd_Aabb box, double* out_bound)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_bound, "sdfccd_grid_lipschitz_bound: out_bound"))) return st;
    scc_grid* g;
    if ((st = sdfccd__grid_acquire(grid, "sdfccd_grid_lipschitz_bound", &g))) return st;
    scc_aabb b = sdfccd__box(box);
    *out_bound = scc_grid_lipschitz_in(&g->base, &b);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_grid_lipschitz_bound(sdfccd_SdfId grid, sdfccd_Aabb box, double* out_bound)
{
    SDFCCD__HELD_CALL(grid_lipschitz_bound_held(grid, box, out_bound));
}
