/* SPDX-License-Identifier: MIT
 * sdfccd core: a moving mesh against an SDF. Each triangle is queried on [t0, best + window]
 * where `best` is the earliest TOI found so far, so the interval shrinks as earlier hits are
 * found (Section 5.3). The result is the earliest TOI with the contacts of every triangle whose
 * TOI lies within the window of it (plus their subdivision contacts).
 *
 * With params->broad_phase the triangles come from the bounding-sphere hierarchy (bsh.h,
 * Section 4.6): earliest candidate first, and every hit lowers the end of the interval the
 * hierarchy still searches. Without it, every triangle is tested in index order. The broad
 * phase's SDF evaluations are included in the summary's `evals`; `triangles_tested` counts the
 * narrow-phase tests only. */
#include "bsh.h"
#include "ccd.h"
#include "reduce.h"

#include <string.h>

/* Evaluations of the certified clear proof tried on a triangle before FWGSS (test_triangle; chosen
 * on the scaling scene, CHANGELOG). */
#define SCC_PRECHECK_EVALS 24
/* Proofs that may fail before the first clears (then two more per triangle cleared): where they fail
 * the triangles are large against their clearance (1K scaling scene: 19 of 19 failed, 6.6 % more
 * evaluations when every triangle tried). */
#define SCC_PRECHECK_MISSES 5

typedef struct contact_buf {
    scc_contact* a;
    size_t n, cap;
    const scc_allocator* alloc;
} contact_buf;

static int buf_push(contact_buf* b, const scc_contact* c)
{
    void* data = b->a;
    if (!scc_array_reserve(b->alloc, &data, &b->cap, sizeof *b->a, b->n + 1, 32)) return 0;
    b->a = data;
    b->a[b->n++] = *c;
    return 1;
}

/* Drops contacts later than `limit`. */
static void buf_prune(contact_buf* b, double limit)
{
    size_t k = 0;
    for (size_t i = 0; i < b->n; ++i)
        if (b->a[i].toi <= limit) b->a[k++] = b->a[i];
    b->n = k;
}

void scc_mesh_triangle_motion(const scc_mesh_motion* mm, uint32_t t, scc_tri_motion* m)
{
    const uint32_t* f = mm->mesh->indices + 3 * t;
    m->sdf = mm->sdf;
    m->t0 = mm->t0;
    m->t1 = mm->t1;
    m->trace[0] = m->trace[1] = m->trace[2] = NULL;
    if (mm->body) {
        m->kind = SCC_TRI_RIGID;
        m->body = mm->body;
        for (int i = 0; i < 3; ++i) m->local[i] = mm->mesh->vertices[f[i]];
    } else {
        m->kind = SCC_TRI_LINEAR;
        m->body = NULL;
        for (int i = 0; i < 3; ++i) {
            m->start[i] = mm->start[f[i]];
            m->end[i] = mm->end[f[i]];
        }
    }
}

double scc_mesh_speed_bound(const scc_mesh_motion* mm)
{
    const double T = mm->t1 - mm->t0;
    const scc_mesh* mesh = mm->mesh;
    const scc_rigid* s = mm->sdf;
    scc_vec3 gs0 = s ? scc_rigid_center_at(s, mm->t0) : scc_v3(0, 0, 0);
    double speed = 0.0, reach = 0.0;
    if (mm->body) {
        const scc_rigid* b = mm->body;
        double r = 0.0;
        for (int k = 0; k < 8; ++k) {
            scc_vec3 corner = scc_v3(k & 1 ? mesh->bounds.hi.x : mesh->bounds.lo.x, k & 2 ? mesh->bounds.hi.y : mesh->bounds.lo.y,
                                     k & 4 ? mesh->bounds.hi.z : mesh->bounds.lo.z);
            r = fmax(r, scc_dist(corner, b->c_local));
        }
        speed = scc_len(b->v) + scc_len(b->w) * r;
        if (s) reach = scc_dist(scc_rigid_center_at(b, mm->t0), gs0) + r + (scc_len(b->v) + scc_len(s->v)) * T;
    } else {
        for (uint32_t i = 0; i < mesh->vertex_count; ++i) {
            double d = scc_dist(mm->end[i], mm->start[i]);
            speed = fmax(speed, T > 0.0 ? d / T : 0.0);
            if (s) reach = fmax(reach, scc_dist(mm->start[i], gs0) + d + scc_len(s->v) * T);
        }
    }
    if (s) speed += scc_len(s->v) + scc_len(s->w) * reach;
    return speed;
}

/* The records are made usable a page of SCC_TRACE_PAGE at a time, when a triangle first hands one out
 * (ours): a mark per page after the records says whether its records were set since the marks were
 * laid out, so a new workspace (scc_query_mesh makes one per call) clears the marks, a byte per page,
 * instead of every record of a large mesh of which a query tests a few triangles. */
#define SCC_TRACE_PAGE 16

static uint8_t* trace_pages(scc_vertex_trace* traces, const scc_mesh* mesh)
{
    return (uint8_t*)(traces + mesh->vertex_count);
}

scc_vertex_trace* scc_mesh_traces(scc_workspace* ws, const scc_mesh* mesh)
{
    /* Records of earlier queries are told apart by the epoch, so nothing is cleared per query. */
    const size_t pages = (mesh->vertex_count + SCC_TRACE_PAGE - 1) / SCC_TRACE_PAGE;
    const size_t need = (size_t)mesh->vertex_count * sizeof(scc_vertex_trace) + pages;
    const int fresh = ws->slot[SCC_WS_TRACES].bytes < need || ws->trace_count != mesh->vertex_count;
    scc_vertex_trace* traces = scc_ws_get(ws, SCC_WS_TRACES, need);
    if (!traces) return NULL;
    if (fresh || ++ws->trace_epoch == 0) {
        memset(trace_pages(traces, mesh), 0, pages);
        ws->trace_count = mesh->vertex_count;
        ws->trace_epoch = 1;
    }
    return traces;
}

void scc_triangle_traces(scc_vertex_trace* traces, const scc_mesh* mesh, uint32_t t, uint32_t epoch, scc_vertex_trace* out[3])
{
    const uint32_t* f = mesh->indices + 3 * t;
    uint8_t* pages = trace_pages(traces, mesh);
    for (int i = 0; i < 3; ++i) {
        const uint32_t page = f[i] / SCC_TRACE_PAGE;
        if (!pages[page]) { /* never set since the marks were laid out: no record of it is in use */
            const uint32_t first = page * SCC_TRACE_PAGE, n = mesh->vertex_count - first < SCC_TRACE_PAGE ? mesh->vertex_count - first : SCC_TRACE_PAGE;
            memset(traces + first, 0, n * sizeof *traces);
            pages[page] = 1;
        }
        scc_vertex_trace* r = &traces[f[i]];
        if (r->epoch != epoch) {
            r->epoch = epoch;
            r->speed = -1.0;
            r->from = r->to = 0.0;
            r->hit_t = r->hit_phi = INFINITY;
        }
        out[i] = r;
    }
}

/* A vertex at a discrete query's pose, computed once per query (the epoch tells). */
typedef struct posed_vertex {
    scc_vec3 x;
    uint32_t epoch;
} posed_vertex;

/* A triangle whose FWGSS answer waits for its check (scc_query_triangle_deferred). */
typedef struct deferred_tri {
    scc_tri_hit raw;
    double ta, tb, margin;
    uint32_t triangle;
} deferred_tri;

/* A triangle whose FWGSS waits until the earliest candidate time reaches the lower bound its pre-check
 * proved (test_triangle). */
typedef struct pending_tri {
    double lower, tb;   /* the bound, and the end of the interval its pre-check had */
    uint32_t triangle;
    int rounds;         /* pre-checks so far */
} pending_tri;
#define SCC_PENDING_MAX 32
#define SCC_PENDING_ROUNDS 3 /* pre-checks per triangle at most */

typedef struct mesh_ctx {
    scc_mesh_query_in in;        /* the query's inputs, handed to the broad phase as they are */
    contact_buf buf;
    double best, lower;
    scc_state best_state;
    int any_not_converged;
    scc_query_summary* sum;
    scc_mesh_probe_fn* probe;
    void* probe_user;
    int64_t broad_evals;
    const scc_bsh_stats* broad;  /* live broad-phase counters (NULL without the broad phase) */
    scc_vertex_trace* traces;    /* one per mesh vertex (FWGSS with the vertex trace), else NULL */
    int budget_exhausted;        /* the evaluation budget ran out before every triangle was tested */
    posed_vertex* posed;         /* DCD of a rigid mesh against a still SDF: vertices at the pose (else NULL) */
    scc_quat pose_q;             /* that pose (scc_rigid_pose_at at mm->t1) */
    scc_vec3 pose_p;
    int defer;                   /* FWGSS's checks wait until the earliest contact is known (scc_query_mesh_probed) */
    int precheck;                /* the certified clear proof runs before FWGSS (test_triangle) */
    int pre_cleared, pre_failed; /* its outcomes so far */
    deferred_tri* deferred;      /* the triangles searched so, in the order searched */
    size_t n_deferred, cap_deferred;
    double provisional;          /* the earliest of their FWGSS contacts (a witness: the TOI is no later) */
    pending_tri pending[SCC_PENDING_MAX]; /* triangles whose pre-check raised their lower bound, waiting for FWGSS */
    int n_pending;
} mesh_ctx;

/* Evaluations left of the query's budget (narrow phase so far plus the broad phase's marching). */
static int64_t budget_left(const mesh_ctx* c)
{
    return c->in.p->max_evals - c->sum->evals - (c->broad ? c->broad->evals : 0);
}

/* A triangle's answer on [ta, ..] into the query's: its contacts, the earliest TOI and its state,
 * the proven lower bound. Returns 0 on allocation failure. */
static int take_answer(mesh_ctx* c, scc_query_summary* s, const scc_contact* local, double ta, double window)
{
    /* Touching at a candidate time after t0 is a hit there, not a penetration at the query's start. */
    if (s->state == SCC_PENETRATING && ta > c->in.mm->t0) s->state = SCC_HIT;
    c->lower = scc_fmin(c->lower, s->toi_lower);
    if (!s->hit) {
        c->any_not_converged |= s->state == SCC_NOT_CONVERGED;
        return 1;
    }
    int n = s->contacts_found < 1 + SCC_MAX_SUBDIVISION_CONTACTS ? s->contacts_found : 1 + SCC_MAX_SUBDIVISION_CONTACTS;
    for (int i = 0; i < n; ++i)
        if (!buf_push(&c->buf, &local[i])) return 0;
    if (s->toi < c->best) {
        c->best = s->toi;
        c->best_state = s->state;
        buf_prune(&c->buf, c->best + window);
    }
    return 1;
}

/* The certified search's short clear proof before FWGSS (ours, issue 20 item 6): on a kinked
 * analytic field its first-order bounds clear a triangle that passes a convex piece without touching
 * it in tens of evaluations, where FWGSS's descents spend hundreds before their deferred check proves
 * the same. Where it does not close, *lower is the start of the interval it left unproven (ta when it
 * proved nothing). Returns 1 when the triangle is done (cleared on [ta, tb], or the budget ran out), 0
 * when FWGSS goes on, -1 on allocation failure; tp->max_evals loses what the proof spent. */
static int precheck(mesh_ctx* c, const scc_tri_motion* m, double ta, double tb, scc_params* tp, double* lower)
{
    *lower = ta;
    scc_tri_hit h;
    const int64_t budget = tp->max_evals < SCC_PRECHECK_EVALS ? tp->max_evals : SCC_PRECHECK_EVALS;
    if (!scc_certified_clear(c->in.sdf, m, ta, tb, tp, c->in.ws, budget, &h)) return -1;
    c->sum->evals += h.evals;
    tp->max_evals -= h.evals;
    if (!h.hit && h.state == SCC_NO_HIT) { /* the same answer as a search that found nothing on [ta, tb] */
        c->sum->triangles_tested += 1;
        c->lower = scc_fmin(c->lower, tb);
        c->pre_cleared += 1;
        return 1;
    }
    c->pre_failed += 1;
    if (h.state == SCC_NOT_CONVERGED && h.toi_lower > ta) *lower = h.toi_lower; /* proven: no contact before it */
    if (tp->max_evals <= 0) c->budget_exhausted = 1; /* its contacts stay unproven */
    return c->budget_exhausted;
}

/* Narrow phase of triangle t on [ta, min(t1, best + window)], where ta is t0 or the broad phase's
 * candidate time (a proven lower bound of the triangle's contacts). Returns 0 on allocation failure. */
static int test_triangle(mesh_ctx* c, uint32_t t, double ta, int rounds)
{
    const scc_mesh_motion* mm = c->in.mm;
    scc_params tp = *c->in.p;
    const scc_params* p = &tp;
    tp.max_evals = budget_left(c);
    if (tp.max_evals <= 0) {
        c->budget_exhausted = 1;
        return 1;
    }
    if (mm->tri_margin) {
        if (!(mm->tri_margin[t] > -INFINITY)) return 1; /* left out by the caller */
        tp.margin = mm->tri_margin[t];
    }
    scc_contact local[1 + SCC_MAX_SUBDIVISION_CONTACTS];
    double tb = scc_fmin(mm->t1, scc_fmin(c->best, c->provisional) + p->toi_window);
    scc_tri_motion m;
    scc_mesh_triangle_motion(mm, t, &m);
    if (c->traces) scc_triangle_traces(c->traces, mm->mesh, t, c->in.ws->trace_epoch, m.trace);
    if (c->posed && tb == mm->t1) {
        /* The discrete pose as a motion that stays there: the triangle gets the vertices computed for
         * the query (the numbers scc_tri_state_at gives, without the pose per triangle). */
        const uint32_t* f = mm->mesh->indices + 3 * t;
        m.kind = SCC_TRI_LINEAR;
        m.body = NULL;
        for (int i = 0; i < 3; ++i) {
            posed_vertex* v = &c->posed[f[i]];
            if (v->epoch != c->in.ws->trace_epoch) {
                v->x = scc_add(scc_quat_rotate(c->pose_q, mm->mesh->vertices[f[i]]), c->pose_p);
                v->epoch = c->in.ws->trace_epoch;
            }
            m.start[i] = m.end[i] = v->x;
        }
    }
    scc_query_summary s;
    if (c->probe) c->probe(c->probe_user, t, 1);
    if (!(ta < tb)) ta = mm->t0;
    /* while the proofs pay: at most SCC_PRECHECK_MISSES more failed than twice the cleared */
    double lower = ta;
    const int pre = rounds >= 0 && c->precheck && c->pre_failed < SCC_PRECHECK_MISSES + 2 * c->pre_cleared ? precheck(c, &m, ta, tb, &tp, &lower) : 0;
    if (pre != 0 || (lower > ta && rounds < SCC_PENDING_ROUNDS && c->n_pending < SCC_PENDING_MAX)) {
        /* done, or FWGSS waits until the candidates reach the raised lower bound (drain_pending): by
         * then an earlier contact may have been found and the triangle need not be searched at all */
        if (pre == 0) c->pending[c->n_pending++] = (pending_tri){ lower, tb, t, rounds + 1 };
        if (c->probe) c->probe(c->probe_user, t, 0);
        return pre >= 0;
    }
    int deferred = 0;
    scc_tri_hit raw;
    int ok = scc_query_triangle_deferred(c->in.sdf, &m, ta, tb, p, c->in.ws, t, local, 1 + SCC_MAX_SUBDIVISION_CONTACTS, &s,
                                         c->defer ? &raw : NULL, &deferred);
    if (c->probe) c->probe(c->probe_user, t, 0);
    if (!ok) return 0;
    c->sum->iterations += s.iterations;
    c->sum->evals += s.evals;
    c->sum->triangles_tested += 1;
    if (deferred) {
        void* data = c->deferred;
        if (!scc_array_reserve(c->in.ws->alloc, &data, &c->cap_deferred, sizeof *c->deferred, c->n_deferred + 1, 32)) return 0;
        c->deferred = data;
        c->deferred[c->n_deferred++] = (deferred_tri){ raw, ta, tb, tp.margin, t };
        if (raw.hit) c->provisional = scc_fmin(c->provisional, raw.toi);
        return 1;
    }
    return take_answer(c, &s, local, ta, p->toi_window);
}

/* The deferred checks (ours): in candidate order, each triangle's FWGSS answer is checked only up to
 * the earliest contact known by then plus the window (a contact found later than that is dropped
 * anyway, so its check proves the shorter interval clear instead). A triangle searched before the
 * earliest contact was found no longer pays for checking its own later one (the 100K scaling
 * scene: three such triangles, 1,272 of the check's 3,519 evaluations per query). */
static int finish_deferred(mesh_ctx* c)
{
    const scc_mesh_motion* mm = c->in.mm;
    scc_params tp = *c->in.p;
    scc_contact local[1 + SCC_MAX_SUBDIVISION_CONTACTS];
    for (size_t i = 0; i < c->n_deferred; ++i) {
        const deferred_tri* d = &c->deferred[i];
        const double limit = scc_fmin(c->best, c->provisional) + tp.toi_window;
        if (d->ta > limit) continue; /* its contacts start after the window (ta is a proven lower bound) */
        tp.margin = d->margin;
        tp.max_evals = budget_left(c);
        if (tp.max_evals <= 0) c->budget_exhausted = 1; /* the check cannot run: the answer stays unproven */
        scc_tri_motion m;
        scc_mesh_triangle_motion(mm, d->triangle, &m);
        if (c->traces) scc_triangle_traces(c->traces, mm->mesh, d->triangle, c->in.ws->trace_epoch, m.trace);
        scc_query_summary s;
        if (c->probe) c->probe(c->probe_user, d->triangle, 1);
        const int ok = scc_triangle_finish_deferred(c->in.sdf, &m, d->ta, scc_fmin(d->tb, limit), &tp, c->in.ws, d->triangle, d->raw, local,
                                                    1 + SCC_MAX_SUBDIVISION_CONTACTS, &s);
        if (c->probe) c->probe(c->probe_user, d->triangle, 0);
        if (!ok) return 0;
        c->sum->iterations += s.iterations;
        c->sum->evals += s.evals;
        if (!take_answer(c, &s, local, d->ta, tp.toi_window)) return 0;
    }
    return 1;
}

/* The waiting triangles whose lower bound is at most `upto`, earliest first: FWGSS from that bound, or
 * nothing when the earliest contact found plus the window lies before it (ours, issue 20 item 6). */
static int drain_pending(mesh_ctx* c, double upto)
{
    while (c->n_pending > 0 && !c->budget_exhausted) {
        int k = 0;
        for (int i = 1; i < c->n_pending; ++i)
            if (c->pending[i].lower < c->pending[k].lower) k = i;
        const pending_tri w = c->pending[k];
        if (w.lower > upto) break;
        c->pending[k] = c->pending[--c->n_pending];
        const double tb = scc_fmin(c->in.mm->t1, scc_fmin(c->best, c->provisional) + c->in.p->toi_window);
        if (w.lower >= tb) { /* its contacts start after the window */
            c->sum->triangles_tested += 1;
            c->lower = scc_fmin(c->lower, w.lower);
            continue;
        }
        /* the pre-check again where the interval has shrunk since, else FWGSS */
        if (!test_triangle(c, w.triangle, w.lower, tb < w.tb ? w.rounds : -1)) return 0;
    }
    return 1;
}

static int visit_candidate(void* user, uint32_t triangle, double t_candidate, double* io_t_end)
{
    mesh_ctx* c = user;
    const scc_mesh_motion* mm = c->in.mm;
    if (!drain_pending(c, t_candidate)) return 0;
    /* The candidate time is a proven lower bound of the triangle's contacts, so the narrow phase
     * searches from there. FW (the paper's Section 4.2 baseline) keeps the whole interval: it is a
     * local method whose step sizes scale with the interval. */
    double ta = c->in.p->method == SCC_METHOD_FW ? mm->t0 : scc_fmax(mm->t0, t_candidate);
    if (!test_triangle(c, triangle, ta, 0)) return 0;
    *io_t_end = scc_fmin(*io_t_end, scc_fmin(mm->t1, scc_fmin(c->best, c->provisional) + c->in.p->toi_window));
    if (c->budget_exhausted) *io_t_end = -INFINITY; /* stops the traversal */
    return 1;
}

/* Broad phase: the mesh's own hierarchy or a temporary one, refitted for linear motion. */
static int run_broad_phase(mesh_ctx* c)
{
    const scc_mesh_motion* mm = c->in.mm;
    const scc_allocator* alloc = c->in.ws->alloc;
    const scc_bsh* bsh = mm->mesh->bsh;
    scc_bsh* own = NULL;
    if (!bsh) {
        own = scc_bsh_build(mm->mesh, alloc);
        if (!own) return 0;
        bsh = own;
    }
    scc_bsh_moving_node* moving = NULL;
    int ok = 1;
    if (!mm->body) {
        moving = scc_ws_get(c->in.ws, SCC_WS_MOVING, (size_t)bsh->node_count * sizeof *moving);
        if (!moving) ok = 0;
        else scc_bsh_refit_linear(bsh, mm->mesh, mm->start, mm->end, moving);
    }
    if (ok) {
        scc_bsh_stats st = { 0, 0, 0 };
        c->broad = &st;
        ok = scc_bsh_traverse(bsh, moving, &c->in, mm->t1, visit_candidate, c, &st);
        if (budget_left(c) <= 0) c->budget_exhausted = 1;
        c->broad = NULL;
        c->sum->evals += st.evals;
        c->broad_evals += st.evals;
    }
    scc_bsh_destroy(own, alloc);
    return ok;
}

/* The reduction reads a contact as its surface point (the point less phi along the normal). */
static void contact_item(const void* set, size_t i, scc_reduce_item* out)
{
    const scc_contact* c = (const scc_contact*)set + i;
    out->p = scc_sub(c->point, scc_scale(c->normal, c->distance));
    out->n = c->normal;
    out->gap = c->distance;
    out->id = i;
}

/* More contacts than the caller's room: the deepest at the earliest time, then a reduction of the rest
 * (reduce.h; points within the distance tolerance count as one place), written earliest first. */
static int reduce_output(const contact_buf* buf, const scc_params* p, scc_workspace* ws, scc_contact* out, int capacity, int* out_written)
{
    *out_written = 0;
    if (capacity <= 0) return 1;
    int32_t* idx = scc_ws_get(ws, SCC_WS_REDUCE, (size_t)capacity * sizeof *idx);
    if (!idx) return 0;
    /* the seed: the deepest contact at the earliest time (the buffer is sorted by time) */
    long seed = 0;
    for (size_t i = 1; i < buf->n && buf->a[i].toi == buf->a[0].toi; ++i)
        if (buf->a[i].distance < buf->a[seed].distance) seed = (long)i;
    double* scratch = scc_ws_get(ws, SCC_WS_REDUCE_SCRATCH, buf->n * sizeof *scratch);
    if (!scratch) return 0;
    size_t n = scc_reduce(buf->a, buf->n, contact_item, p->dist_tol, seed, (size_t)capacity, idx, scratch);
    for (size_t i = 0; i < n; ++i) {
        scc_contact key = buf->a[idx[i]];
        size_t j = i;
        while (j > 0 && out[j - 1].toi > key.toi) { out[j] = out[j - 1]; --j; }
        out[j] = key;
    }
    *out_written = (int)n;
    return 1;
}

int scc_query_mesh(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, const scc_allocator* alloc,
                   scc_contact* out, int capacity, scc_query_summary* sum)
{
    scc_workspace ws;
    scc_ws_init(&ws, alloc);
    int ok = scc_query_mesh_probed(sdf, mm, p, &ws, out, capacity, sum, NULL, NULL, NULL);
    scc_ws_release(&ws);
    return ok;
}

int scc_query_mesh_ws(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, scc_workspace* ws, scc_contact* out,
                      int capacity, scc_query_summary* sum)
{
    return scc_query_mesh_probed(sdf, mm, p, ws, out, capacity, sum, NULL, NULL, NULL);
}

int scc_query_mesh_probed(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, scc_workspace* ws,
                          scc_contact* out, int capacity, scc_query_summary* sum, scc_mesh_probe_fn* probe, void* probe_user,
                          int64_t* out_broad_evals)
{
    const scc_allocator* alloc = ws->alloc;
    mesh_ctx c;
    c.in.sdf = sdf;
    c.in.mm = mm;
    c.in.p = p;
    c.in.ws = ws;
    /* the contact buffer grows in its workspace slot and is handed back at the end */
    c.buf.a = ws->slot[SCC_WS_CONTACTS].p;
    c.buf.n = 0;
    c.buf.cap = ws->slot[SCC_WS_CONTACTS].bytes / sizeof(scc_contact);
    c.buf.alloc = alloc;
    if (c.buf.cap * sizeof(scc_contact) != ws->slot[SCC_WS_CONTACTS].bytes) {
        scc_free(alloc, c.buf.a, ws->slot[SCC_WS_CONTACTS].bytes);
        c.buf.a = NULL;
        c.buf.cap = 0;
    }
    c.best = c.lower = INFINITY;
    c.best_state = SCC_NO_HIT;
    c.any_not_converged = 0;
    c.sum = sum;
    c.probe = probe;
    c.probe_user = probe_user;
    c.broad_evals = 0;
    c.broad = NULL;
    c.budget_exhausted = 0;
    c.traces = NULL;
    /* Deferred checks: a mesh (one triangle has nothing to wait for) under FWGSS on a checked field */
    c.defer = p->method == SCC_METHOD_FWGSS && mm->mesh->triangle_count > 1 && scc_fwgss_verified(sdf, p);
    c.precheck = c.defer && sdf->kind != SCC_SDF_GRID;
    c.pre_cleared = c.pre_failed = 0;
    c.deferred = ws->slot[SCC_WS_DEFERRED].p;
    c.n_deferred = 0;
    c.cap_deferred = ws->slot[SCC_WS_DEFERRED].bytes / sizeof(deferred_tri);
    if (c.cap_deferred * sizeof(deferred_tri) != ws->slot[SCC_WS_DEFERRED].bytes) {
        scc_free(alloc, c.deferred, ws->slot[SCC_WS_DEFERRED].bytes);
        c.deferred = NULL;
        c.cap_deferred = 0;
    }
    c.provisional = INFINITY;
    c.n_pending = 0;
    sum->iterations = sum->evals = sum->triangles_tested = 0;
    int ok = 1;
    /* FWGSS's vertex traces; DCD keeps each vertex's value at the tested pose there (scc_dcd_traced) */
    const int traced = (p->method == SCC_METHOD_FWGSS && p->fwgss_vertex_trace > 0) || p->method == SCC_METHOD_DCD;
    if (traced && mm->mesh->vertex_count > 0 && !mm->tri_margin && !(c.traces = scc_mesh_traces(ws, mm->mesh))) ok = 0;
    c.posed = NULL;
    if (ok && c.traces && p->method == SCC_METHOD_DCD && mm->body && !mm->sdf && mm->t0 == mm->t1) {
        const size_t need = (size_t)mm->mesh->vertex_count * sizeof *c.posed;
        const int fresh = ws->slot[SCC_WS_POSED].bytes < need;
        if (!(c.posed = scc_ws_get(ws, SCC_WS_POSED, need))) ok = 0;
        else if (fresh || ws->trace_epoch == 1) memset(c.posed, 0, ws->slot[SCC_WS_POSED].bytes); /* epochs start again */
        scc_rigid_pose_at(mm->body, mm->t1, &c.pose_q, &c.pose_p);
    }
    if (!ok) {
    } else if (p->broad_phase && mm->mesh->triangle_count > 0) {
        ok = run_broad_phase(&c);
    } else {
        for (uint32_t t = 0; t < mm->mesh->triangle_count && ok && !c.budget_exhausted; ++t) ok = test_triangle(&c, t, mm->t0, 0);
    }
    if (ok) ok = drain_pending(&c, INFINITY);
    if (ok) ok = finish_deferred(&c);
    scc_ws_adopt(ws, SCC_WS_DEFERRED, c.deferred, c.cap_deferred * sizeof *c.deferred);
    if (out_broad_evals) *out_broad_evals = c.broad_evals;
    contact_buf buf = c.buf;
    double best = c.best, lower = c.lower;
    scc_state best_state = c.best_state;
    int any_not_converged = c.any_not_converged || c.budget_exhausted;
    scc_ws_adopt(ws, SCC_WS_CONTACTS, buf.a, buf.cap * sizeof *buf.a);
    if (!ok) return 0;
    /* Earliest first; insertion sort is fine for the handful of contacts at one TOI. */
    for (size_t i = 1; i < buf.n; ++i) {
        scc_contact key = buf.a[i];
        size_t j = i;
        while (j > 0 && buf.a[j - 1].toi > key.toi) { buf.a[j] = buf.a[j - 1]; --j; }
        buf.a[j] = key;
    }
    sum->hit = isfinite(best);
    sum->toi = sum->hit ? best : mm->t1;
    if (c.budget_exhausted) lower = scc_fmin(lower, mm->t0); /* triangles left untested prove nothing */
    sum->toi_lower = scc_fmin(lower, sum->toi); /* certified: no triangle touches before this */
    sum->state = sum->hit ? (c.budget_exhausted ? SCC_NOT_CONVERGED : best_state)
                          : (any_not_converged ? SCC_NOT_CONVERGED : SCC_NO_HIT);
    sum->contacts_found = (int)buf.n;
    if (buf.n <= (size_t)(capacity > 0 ? capacity : 0)) {
        for (size_t i = 0; i < buf.n; ++i) out[i] = buf.a[i];
        sum->contacts_written = (int)buf.n;
        return 1;
    }
    return reduce_output(&buf, p, ws, out, capacity, &sum->contacts_written);
}
