/* SPDX-License-Identifier: MIT
 * sdfccd core: the contact set an engine needs for one mesh against one SDF over a step (ours, on
 * the paper's queries). Candidates come from two places:
 *  - the start pose within the step's reach: a discrete query (DCD, Section 3.2, with adaptive
 *    subdivision, Section 4.5) at t0 with the margin widened by the farthest any point can travel
 *    in the step, plus the vertices of those triangles within that reach; each is held by its own
 *    closest surface point at t0 (the speculative rule: a point with gap d > 0 may close at most d);
 *  - unless a start point already touches (then the CCD would only report contact at t0), the CCD's
 *    contact set at the first time of impact (Sections 4.3-4.6) plus the vertices of its triangles
 *    within vertex_distance of the margin then; each is held by the surface point and normal it
 *    touches at the TOI, its gap measured at t0 along that normal.
 * When the start-pose query finds nothing within reach, the step provably has no contact and the
 * CCD is not run. The set is reduced to the caller's capacity (reduce.c). Every point carries its
 * triangle and a feature id (vertex, edge or face) that stays the same from step to step. */
#include "contacts.h"
#include "reduce.h"

#include <string.h>

typedef struct cand_buf {
    scc_contact_point* a;
    size_t n, cap;
    const scc_allocator* alloc;
} cand_buf;

static int push(cand_buf* b, const scc_contact_point* c)
{
    void* data = b->a;
    if (!scc_array_reserve(b->alloc, &data, &b->cap, sizeof *b->a, b->n + 1, 64)) return 0;
    b->a = data;
    b->a[b->n++] = *c;
    return 1;
}

void scc_classify_feature(const scc_mesh* mesh, uint32_t t, const double b[3], scc_contact_point* c)
{
    const double eps = 1e-6;
    int zeros = 0, zero = 0, one = 0;
    for (int k = 0; k < 3; ++k) {
        if (b[k] <= eps) { ++zeros; zero = k; }
        if (b[k] >= 1.0 - eps) one = k;
    }
    c->triangle = t;
    if (zeros >= 2) {
        c->kind = SCC_FEATURE_VERTEX;
        c->feature = mesh->indices[3 * (size_t)t + (size_t)one];
        c->id = c->feature;
    } else if (zeros == 1) {
        c->kind = SCC_FEATURE_EDGE;
        c->feature = (uint32_t)zero;
        c->id = (UINT64_C(1) << 62) + 3 * (uint64_t)t + (uint64_t)zero;
    } else {
        c->kind = SCC_FEATURE_FACE;
        c->feature = 0;
        c->id = (UINT64_C(2) << 62) + (uint64_t)t;
    }
}

/* A candidate: material point x0 (at t0) held by surface point q with normal n (unit). */
static int add(cand_buf* b, const scc_mesh* mesh, uint32_t t, const double bary[3], scc_vec3 x0, scc_vec3 q, scc_vec3 n, double toi)
{
    scc_contact_point c;
    memset(&c, 0, sizeof c);
    c.point = x0;
    c.normal = n;
    c.gap = scc_dot(n, scc_sub(x0, q));
    c.surface = scc_sub(x0, scc_scale(n, c.gap));
    c.toi = toi;
    for (int k = 0; k < 3; ++k) c.bary[k] = bary[k];
    scc_classify_feature(mesh, t, bary, &c);
    return push(b, &c);
}

/* The vertices of triangle t at time `at` whose phi is at most `accept` and that no earlier triangle
 * gave (marks[v] == epoch): each held by its own closest surface point at `at`. */
static int add_vertices(const scc_sdf* sdf, const scc_mesh_motion* mm, uint32_t t, double at, double accept, uint32_t* marks,
                        uint32_t epoch, cand_buf* b, int64_t* evals)
{
    scc_tri_motion m;
    scc_mesh_triangle_motion(mm, t, &m);
    for (int k = 0; k < 3; ++k) {
        uint32_t v = mm->mesh->indices[3 * (size_t)t + (size_t)k];
        if (marks[v] == epoch) continue;
        marks[v] = epoch;
        const double bary[3] = { k == 0, k == 1, k == 2 };
        scc_vec3 x = scc_tri_point_at(&m, bary, at, NULL), g;
        double phi = scc_sdf_eval(sdf, x, &g);
        ++*evals;
        if (!(phi <= accept)) continue;
        scc_vec3 n = scc_normalize_or(g, scc_v3(0, 0, 0));
        if (!(scc_len2(n) > 0.0)) continue;
        scc_vec3 x0 = at == mm->t0 ? x : scc_tri_point_at(&m, bary, mm->t0, NULL);
        if (!add(b, mm->mesh, t, bary, x0, scc_sub(x, scc_scale(n, phi)), n, at)) return 0;
    }
    return 1;
}

/* Per-vertex marks for this call, told apart from earlier calls' by a new epoch. */
static uint32_t* marks_for(scc_workspace* ws, uint32_t nv, uint32_t* io_epoch)
{
    size_t need = (size_t)(nv ? nv : 1) * sizeof(uint32_t);
    int fresh = ws->slot[SCC_WS_MARKS].bytes < need;
    uint32_t* marks = scc_ws_get(ws, SCC_WS_MARKS, need);
    if (!marks) return NULL;
    if (fresh || ++ws->mark_epoch == 0) {
        memset(marks, 0, ws->slot[SCC_WS_MARKS].bytes);
        ws->mark_epoch = 1;
    }
    *io_epoch = ws->mark_epoch;
    return marks;
}

static void cand_item(const void* set, size_t i, scc_reduce_item* out)
{
    const scc_contact_point* c = (const scc_contact_point*)set + i;
    out->p = c->surface;
    out->n = c->normal;
    out->gap = c->gap;
    out->id = c->id;
}

int scc_generate_contacts(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_contact_params* cp, scc_workspace* ws,
                          scc_contact_point* out, int capacity, scc_contact_set* sum)
{
    const scc_params* p = &cp->query;
    const scc_mesh* mesh = mm->mesh;
    memset(sum, 0, sizeof *sum);
    sum->ccd_state = SCC_NO_HIT;
    sum->toi = mm->t1;
    cand_buf b = { ws->slot[SCC_WS_CANDIDATES].p, 0, ws->slot[SCC_WS_CANDIDATES].bytes / sizeof(scc_contact_point), ws->alloc };
    int ok = 1;
    uint32_t epoch = 0;
    uint32_t* marks = marks_for(ws, mesh->vertex_count, &epoch);
    if (!marks) return 0;

    /* 1. the start pose, within the step's reach */
    const double reach = scc_mesh_speed_bound(mm) * (mm->t1 - mm->t0);
    const double accept = p->margin + reach;
    scc_mesh_motion start = *mm;
    start.t1 = mm->t0;
    start.tri_margin = NULL;
    scc_params sp = *p;
    sp.method = SCC_METHOD_DCD;
    sp.margin = accept;
    scc_query_summary s;
    if (!scc_query_mesh_ws(sdf, &start, &sp, ws, NULL, 0, &s)) ok = 0;
    sum->evals += ok ? s.evals : 0;
    /* the mesh query's contacts stay in their slot until the next query: copy what is needed now */
    for (int i = 0; ok && i < s.contacts_found; ++i) {
        const scc_contact* c = (const scc_contact*)ws->slot[SCC_WS_CONTACTS].p + i;
        scc_vec3 n = scc_normalize_or(c->normal, scc_v3(0, 0, 0));
        if (!(scc_len2(n) > 0.0)) continue;
        ok = add(&b, mesh, c->triangle, c->bary, c->point, scc_sub(c->point, scc_scale(n, c->distance)), n, mm->t0);
    }
    const size_t from_query = b.n;
    for (size_t i = 0; ok && i < from_query; ++i)
        ok = add_vertices(sdf, &start, b.a[i].triangle, mm->t0, accept, marks, epoch, &b, &sum->evals);
    for (size_t i = 0; i < b.n; ++i) sum->started_in_contact |= b.a[i].gap <= p->margin;

    /* 2. the CCD's contact set at the first time of impact */
    if (ok && b.n > 0 && !sum->started_in_contact && p->method != SCC_METHOD_DCD && mm->t1 > mm->t0) {
        scc_mesh_motion run = *mm;
        run.tri_margin = NULL;
        if (!scc_query_mesh_ws(sdf, &run, p, ws, NULL, 0, &s)) ok = 0;
        if (ok) {
            sum->evals += s.evals;
            sum->ccd_ran = 1;
            sum->ccd_state = s.state;
            if (s.hit) sum->toi = s.toi;
            const size_t first_ccd = b.n;
            for (int i = 0; ok && s.hit && i < s.contacts_found; ++i) {
                const scc_contact* c = (const scc_contact*)ws->slot[SCC_WS_CONTACTS].p + i;
                scc_vec3 n = scc_normalize_or(c->normal, scc_v3(0, 0, 0));
                if (!(scc_len2(n) > 0.0)) continue;
                scc_tri_motion m;
                scc_mesh_triangle_motion(&run, c->triangle, &m);
                scc_vec3 x0 = scc_tri_point_at(&m, c->bary, mm->t0, NULL);
                ok = add(&b, mesh, c->triangle, c->bary, x0, scc_sub(c->point, scc_scale(n, c->distance)), n, c->toi);
            }
            const size_t last_ccd = b.n;
            uint32_t* m2 = ok ? marks_for(ws, mesh->vertex_count, &epoch) : NULL;
            if (ok && !m2) ok = 0;
            for (size_t i = first_ccd; ok && i < last_ccd; ++i)
                ok = add_vertices(sdf, &run, b.a[i].triangle, b.a[i].toi, p->margin + cp->vertex_distance, m2, epoch, &b, &sum->evals);
        }
    } else if (sum->started_in_contact) {
        sum->toi = mm->t0;
    }
    scc_ws_adopt(ws, SCC_WS_CANDIDATES, b.a, b.cap * sizeof *b.a);
    if (!ok) return 0;

    /* 3. the reduction to the caller's room */
    sum->candidates = b.n;
    if (capacity > 0 && b.n > 0) {
        int32_t* idx = scc_ws_get(ws, SCC_WS_REDUCE, (size_t)capacity * sizeof *idx);
        double* scratch = idx ? scc_ws_get(ws, SCC_WS_REDUCE_SCRATCH, b.n * sizeof *scratch) : NULL;
        if (!scratch) return 0;
        sum->written = scc_reduce(b.a, b.n, cand_item, cp->same_place, -1, (size_t)capacity, idx, scratch);
        for (size_t i = 0; i < sum->written; ++i) out[i] = b.a[idx[i]];
    }
    return 1;
}
