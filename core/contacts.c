/* SPDX-License-Identifier: MIT
 * sdfccd core: the contact set an engine needs for one mesh against one SDF over a step [t0, t1]
 * (ours, on the paper's queries; Section 4's rule: the solver never advances past a time of
 * impact). The one generator of the library (sdfccd_generate_contacts*, the Bullet bridge):
 *  1. A discrete query (DCD, Section 3.2, with adaptive subdivision, Section 4.5) at the start pose
 *     with the margin widened by the step's travel: phi is Lipschitz, so it sees every feature that
 *     can come within the margin during the step. When its broad phase culls every triangle the
 *     step provably has no contact and nothing else runs.
 *  2. The face search (faces.c) at the start pose over the same reach, for SDFs with features
 *     smaller than the mesh's faces (feature_size > 0, subdivision on).
 *  3. Unless a feature of 1 or 2 is already within the margin (the step STARTS in contact: the CCD
 *     would only report contact at t0), the CCD over the step (Sections 4.3-4.6): its whole contact
 *     set at the first time of impact, each point held by the surface point and normal it touches
 *     there, plus the vertices of those triangles within vertex_distance of the margin then. No hit
 *     (and no face point): no contact.
 *  4. Whenever the step has contact: the features of 1 and those of a discrete query at the end
 *     pose, each held by its own closest surface point at t0 (the speculative-contact rule: a point
 *     with gap d > 0 lets the solver close at most d), with the vertices of their triangles.
 *  5. The reduction (reduce.c: deepest, then the contact area, points about to touch weighted over
 *     far ones) to the caller's room, then cover points (cover.c) where the reduction leaves the
 *     body free to turn into the surface.
 * Every point is expressed at t0 and carries its triangle and a feature id that stays the same from
 * step to step. With the DCD method (the discrete baseline), 3 is the end pose's query and 1 follows
 * it. With t1 == t0 (closest points) only 3 runs, at that pose. */
#include "contacts.h"
#include "faces.h"
#include "reduce.h"

#include <stdlib.h>
#include <string.h>

/* Scales of the mesh's radius R (the largest distance of a vertex from its centre of rotation). */
#define SAME_PLACE_SHARE 1e-3          /* points closer than this x R are one place (at least 1e-6 m) */
#define SAME_PLACE_MIN 1e-6
#define DEPTH_SCALE_SHARE 0.1          /* the reduction's depth weight: 0.1 R, at most 0.3 m */
#define DEPTH_SCALE_MAX 0.3
#define DISCRETE_SUBDIVISION_SHARE 0.1 /* discrete queries do not split regions below (0.1 R)^2: the vertices count already */
#define FACE_REGION_SHARE 0.4          /* the face search's regions: 0.4 x the SDF's feature size */

typedef struct cand_buf {
    scc_contact_point* a;
    size_t n, cap;
    const scc_allocator* alloc;
} cand_buf;

static int reserve(cand_buf* b, size_t need)
{
    void* data = b->a;
    if (!scc_array_reserve(b->alloc, &data, &b->cap, sizeof *b->a, need, 64)) return 0;
    b->a = data;
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

/* What the steps of one call share. */
typedef struct gen {
    const scc_sdf* sdf;
    const scc_mesh_motion* mm; /* the step */
    scc_workspace* ws;
    cand_buf b;
    scc_contact_set* sum;
} gen;

/* A candidate: the material point x0 (at t0) of triangle t at weights bary, held by surface point q
 * with unit normal n (found at `toi`). */
static int add(gen* g, uint32_t t, const double bary[3], scc_vec3 x0, scc_vec3 q, scc_vec3 n, double toi)
{
    if (!reserve(&g->b, g->b.n + 1)) return 0;
    scc_contact_point* c = &g->b.a[g->b.n++];
    memset(c, 0, sizeof *c);
    c->point = x0;
    c->surface = q;
    c->normal = n;
    c->gap = scc_dot(n, scc_sub(x0, q));
    c->toi = toi;
    for (int k = 0; k < 3; ++k) c->bary[k] = bary[k];
    scc_classify_feature(g->mm->mesh, t, bary, c);
    return 1;
}

/* The material point of triangle t at weights bary at time `at` of the step's motion. */
static scc_vec3 point_at(const scc_mesh_motion* mm, uint32_t t, const double bary[3], double at)
{
    scc_tri_motion m;
    scc_mesh_triangle_motion(mm, t, &m);
    return scc_tri_point_at(&m, bary, at, NULL);
}

/* The material point held by its own closest surface point at t0 (none when phi there is above
 * `accept`). */
static int add_from_start(gen* g, uint32_t t, const double bary[3], double accept)
{
    const scc_vec3 x0 = point_at(g->mm, t, bary, g->mm->t0);
    scc_vec3 grad;
    const double phi = scc_sdf_eval(g->sdf, x0, &grad);
    g->sum->own_evals++;
    if (!isfinite(phi) || !(phi <= accept)) return 1;
    const scc_vec3 n = scc_normalize_or(grad, scc_v3(0, 0, 0));
    if (!(scc_len2(n) > 0.0)) return 1;
    return add(g, t, bary, x0, scc_sub(x0, scc_scale(n, phi)), n, g->mm->t0);
}

/* A vertex of a touching triangle: its index, the time it is looked at and the triangle. */
typedef struct vertex_ref {
    uint32_t vertex, triangle;
    double time;
} vertex_ref;

static int vertex_ref_cmp(const void* pa, const void* pb)
{
    const vertex_ref* a = pa;
    const vertex_ref* b = pb;
    if (a->vertex != b->vertex) return a->vertex < b->vertex ? -1 : 1;
    if (a->time != b->time) return a->time < b->time ? -1 : 1;
    return a->triangle < b->triangle ? -1 : a->triangle > b->triangle;
}

/* The vertices of the contacts' triangles, each once (its earliest time, then its lowest triangle),
 * in vertex order: the order of the candidates, and so of the reduction's ties, does not depend on
 * the order the queries found the contacts in. Writes their count; NULL on allocation failure. */
static const vertex_ref* contact_vertices(gen* g, const scc_contact* cs, int count, size_t* out_n)
{
    const scc_mesh* mesh = g->mm->mesh;
    vertex_ref* v = scc_ws_get(g->ws, SCC_WS_VERTEX_LIST, 3 * (size_t)(count > 0 ? count : 1) * sizeof *v);
    if (!v) return NULL;
    size_t n = 0;
    for (int i = 0; i < count; ++i) {
        if (cs[i].triangle >= mesh->triangle_count) continue;
        for (int k = 0; k < 3; ++k) v[n++] = (vertex_ref){ mesh->indices[3 * (size_t)cs[i].triangle + (size_t)k], cs[i].triangle, cs[i].toi };
    }
    qsort(v, n, sizeof *v, vertex_ref_cmp);
    size_t u = 0;
    for (size_t i = 0; i < n; ++i)
        if (u == 0 || v[i].vertex != v[u - 1].vertex) v[u++] = v[i];
    *out_n = u;
    return v;
}

static int corner_of(const scc_mesh* mesh, const vertex_ref* r)
{
    const uint32_t* f = &mesh->indices[3 * (size_t)r->triangle];
    return f[0] == r->vertex ? 0 : f[1] == r->vertex ? 1 : 2;
}

static const double unit_bary[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };

/* The contacts of a discrete query at pose `pose` (a motion at rest at that time), each held from
 * t0, and the vertices of their triangles whose phi at that pose is at most `accept`. At the start
 * pose (`at_start`) a vertex is evaluated once: the test and its closest point from one value. */
static int add_pose(gen* g, const scc_contact* cs, int count, const scc_mesh_motion* pose, int at_start, double accept)
{
    const scc_mesh* mesh = g->mm->mesh;
    for (int i = 0; i < count; ++i)
        if (cs[i].triangle < mesh->triangle_count && !add_from_start(g, cs[i].triangle, cs[i].bary, INFINITY)) return 0;
    size_t n = 0;
    const vertex_ref* v = contact_vertices(g, cs, count, &n);
    if (!v) return 0;
    for (size_t i = 0; i < n; ++i) {
        const int k = corner_of(mesh, &v[i]);
        if (at_start) {
            if (!add_from_start(g, v[i].triangle, unit_bary[k], accept)) return 0;
            continue;
        }
        const double phi = scc_sdf_eval(g->sdf, point_at(pose, v[i].triangle, unit_bary[k], pose->t0), NULL);
        g->sum->own_evals++;
        if (phi <= accept && !add_from_start(g, v[i].triangle, unit_bary[k], INFINITY)) return 0;
    }
    return 1;
}

/* The CCD's contacts, each held by the surface point and normal it touches at its time of impact,
 * and the vertices of their triangles within `accept` of the surface at that time (a face landing
 * flat gives its corners). */
static int add_ccd(gen* g, const scc_contact* cs, int count, double accept)
{
    const scc_mesh_motion* mm = g->mm;
    for (int i = 0; i < count; ++i) {
        const scc_contact* k = &cs[i];
        const scc_vec3 n = scc_normalize_or(k->normal, scc_v3(0, 0, 0));
        if (k->triangle >= mm->mesh->triangle_count || !(scc_len2(n) > 0.0)) continue;
        const scc_vec3 x0 = point_at(mm, k->triangle, k->bary, mm->t0);
        if (!add(g, k->triangle, k->bary, x0, scc_sub(k->point, scc_scale(n, k->distance)), n, k->toi)) return 0;
    }
    size_t nv = 0;
    const vertex_ref* v = contact_vertices(g, cs, count, &nv);
    if (!v) return 0;
    for (size_t i = 0; i < nv; ++i) {
        const int k = corner_of(mm->mesh, &v[i]);
        scc_tri_motion m;
        scc_mesh_triangle_motion(mm, v[i].triangle, &m);
        const scc_vec3 x = scc_tri_point_at(&m, unit_bary[k], v[i].time, NULL);
        scc_vec3 grad;
        const double phi = scc_sdf_eval(g->sdf, x, &grad);
        g->sum->own_evals++;
        if (!(phi <= accept)) continue;
        const scc_vec3 n = scc_normalize_or(grad, scc_v3(0, 0, 0));
        if (!(scc_len2(n) > 0.0)) continue;
        const scc_vec3 x0 = scc_tri_point_at(&m, unit_bary[k], mm->t0, NULL);
        if (!add(g, v[i].triangle, unit_bary[k], x0, scc_sub(x, scc_scale(n, phi)), n, v[i].time)) return 0;
    }
    return 1;
}

/* One mesh query with the contacts left in the workspace's contact slot. */
static int query(gen* g, const scc_mesh_motion* mm, const scc_params* p, scc_query_summary* s)
{
    if (!scc_query_mesh_ws(g->sdf, mm, p, g->ws, NULL, 0, s)) return 0;
    g->sum->evals += s->evals;
    return 1;
}

static const scc_contact* slot_contacts(const gen* g) { return (const scc_contact*)g->ws->slot[SCC_WS_CONTACTS].p; }

/* The start-pose query's contacts copied out of the contact slot (the next query reuses it); NULL on
 * allocation failure. */
static const scc_contact* keep_start(gen* g, const scc_query_summary* r0)
{
    scc_contact* copy = scc_ws_get(g->ws, SCC_WS_START, ((size_t)r0->contacts_found + 1) * sizeof *copy);
    if (copy) memcpy(copy, slot_contacts(g), (size_t)r0->contacts_found * sizeof *copy);
    return copy;
}

/* A rigid motion at rest at its pose at time t. */
static scc_rigid at_rest(const scc_rigid* r, double t)
{
    scc_rigid o = *r;
    scc_rigid_pose_at(r, t, &o.q0, &o.p0);
    o.v = o.w = scc_v3(0, 0, 0);
    o.t0 = t;
    return o;
}

/* The step's motion at rest at time t (its start or end pose), into *out (rests: storage). */
static void pose_at(const scc_mesh_motion* mm, double t, scc_rigid rests[2], scc_mesh_motion* out)
{
    *out = *mm;
    out->t0 = out->t1 = t;
    if (mm->body) {
        rests[0] = at_rest(mm->body, t);
        out->body = &rests[0];
    } else {
        out->start = out->end = t == mm->t0 ? mm->start : mm->end;
    }
    if (mm->sdf) {
        rests[1] = at_rest(mm->sdf, t);
        out->sdf = &rests[1];
    }
}

static int is_zero(scc_vec3 v) { return v.x == 0.0 && v.y == 0.0 && v.z == 0.0; }

static int same_rigid_pose(const scc_rigid* a, const scc_rigid* b)
{
    if (!a || !b) return a == b;
    return a->q0.w == b->q0.w && a->q0.x == b->q0.x && a->q0.y == b->q0.y && a->q0.z == b->q0.z && a->p0.x == b->p0.x &&
           a->p0.y == b->p0.y && a->p0.z == b->p0.z;
}

/* 1 when two poses of pose_at() are the same (a step at rest: its end pose is its start). */
static int same_pose(const scc_mesh_motion* a, const scc_mesh_motion* b)
{
    return (a->body ? same_rigid_pose(a->body, b->body) : a->start == b->start) && same_rigid_pose(a->sdf, b->sdf);
}

/* The mesh's radius: the largest distance of a vertex from its centre of rotation (rigid: from the
 * mesh's cached radius about its origin, exact when the centre is the origin, else that radius plus
 * the centre's offset, a bound), or half the diagonal of the start positions' box (linear). */
static double mesh_radius(const scc_mesh_motion* mm)
{
    double r2 = 0.0;
    if (mm->body && mm->mesh->radius > 0.0) return mm->mesh->radius + scc_len(mm->body->c_local);
    if (mm->body) {
        for (uint32_t i = 0; i < mm->mesh->vertex_count; ++i) r2 = fmax(r2, scc_len2(scc_sub(mm->mesh->vertices[i], mm->body->c_local)));
        return sqrt(r2);
    }
    scc_aabb box = { { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    for (uint32_t i = 0; i < mm->mesh->vertex_count; ++i) {
        box.lo = scc_vmin(box.lo, mm->start[i]);
        box.hi = scc_vmax(box.hi, mm->start[i]);
    }
    return mm->mesh->vertex_count ? 0.5 * scc_len(scc_sub(box.hi, box.lo)) : 0.0;
}

/* The farthest any point of the mesh can travel relative to the SDF in the step. */
static double step_travel(const scc_mesh_motion* mm, double radius)
{
    const double dt = mm->t1 - mm->t0;
    if (!(dt > 0.0)) return 0.0;
    if (!mm->body) return scc_mesh_speed_bound(mm) * dt;
    const scc_rigid* b = mm->body;
    const scc_rigid* s = mm->sdf;
    double speed = scc_len(s ? scc_sub(b->v, s->v) : b->v) + scc_len(b->w) * radius;
    if (s) speed += scc_len(s->w) * (radius + scc_dist(scc_rigid_center_at(b, mm->t0), scc_rigid_center_at(s, mm->t0)));
    return speed * dt;
}

static void cand_item(const void* set, size_t i, scc_reduce_item* out)
{
    const scc_contact_point* c = (const scc_contact_point*)set + i;
    out->p = c->surface;
    out->n = c->normal;
    out->gap = c->gap;
    out->id = c->id;
}

/* The candidates (1-4 of the file's comment). Returns 0 on allocation failure. */
static int candidates(gen* g, const scc_contact_params* cp, double radius)
{
    const scc_mesh_motion* mm = g->mm;
    const scc_params* p = &cp->query;
    scc_contact_set* sum = g->sum;
    const double dt = mm->t1 - mm->t0, margin = p->margin;
    const int continuous = p->method != SCC_METHOD_DCD;
    const double travel = step_travel(mm, radius), start_margin = margin + travel;
    const double vertex_accept = margin + fmax(cp->vertex_distance, p->contact_slop);
    scc_params dp = *p;
    dp.method = SCC_METHOD_DCD;
    const double sub = DISCRETE_SUBDIVISION_SHARE * radius;
    if (continuous && sub > 0.0) dp.sub_min_area = fmax(dp.sub_min_area, sub * sub);
    scc_rigid rest0[2], rest1[2];
    scc_mesh_motion start, end;
    pose_at(mm, mm->t0, rest0, &start);
    pose_at(mm, mm->t1, rest1, &end);

    /* 1. the start pose within the step's reach; its contacts kept while the CCD runs */
    scc_query_summary r0;
    memset(&r0, 0, sizeof r0);
    int start_ran = 0, touching = 0;
    const scc_contact* kept = NULL;
    if (dt > 0.0 && continuous) {
        start_ran = 1;
        dp.margin = start_margin;
        sum->discrete_queries++;
        if (!query(g, &start, &dp, &r0)) return 0;
        if (r0.triangles_tested == 0 && r0.state == SCC_NO_HIT) return 1; /* culled: no contact this step */
        for (int i = 0; r0.hit && i < r0.contacts_found; ++i) touching |= slot_contacts(g)[i].distance <= margin;
    }
    if (start_ran && r0.hit && !(kept = keep_start(g, &r0))) return 0;

    /* 2. the face search: at the start pose over the step's reach (the DCD baseline: at the end
     *    pose within the margin); its points count like the start pose's */
    size_t face_found = 0;
    if (dt > 0.0 && p->subdivision && cp->feature_size > 0.0) {
        const scc_mesh_motion* pose = continuous ? &start : &end;
        const double accept = continuous ? start_margin : margin;
        if (!reserve(&g->b, g->b.n + 16)) return 0;
        for (;;) {
            size_t found = 0;
            if (!scc_search_faces(g->sdf, pose, pose->t0, FACE_REGION_SHARE * cp->feature_size, accept, p, g->ws, g->b.a + g->b.n,
                                  g->b.cap - g->b.n, &found, &sum->face_regions, &sum->evals))
                return 0;
            if (found <= g->b.cap - g->b.n) {
                face_found = found;
                break;
            }
            if (!reserve(&g->b, g->b.n + found)) return 0; /* all or nothing: room for every point, and again */
        }
        for (size_t i = g->b.n; i < g->b.n + face_found; ++i) { /* at t0 (the baseline's end-pose points moved back) */
            scc_contact_point* c = &g->b.a[i];
            if (!continuous) c->point = point_at(mm, c->triangle, c->bary, mm->t0);
            c->gap = scc_dot(c->normal, scc_sub(c->point, c->surface));
            touching |= continuous && c->gap <= margin;
        }
        g->b.n += face_found;
    }

    /* 3. the CCD over the step, unless it starts in contact */
    if (touching) {
        sum->started_in_contact = 1;
        sum->toi = mm->t0;
    } else {
        scc_query_summary s;
        if (!query(g, mm, p, &s)) return 0;
        sum->ccd_ran = 1;
        sum->ccd_state = s.state;
        if (!s.hit) /* clear: only the face search can have found what the CCD missed; the start pose's features then count too */
            return face_found > 0 && kept ? add_pose(g, kept, r0.contacts_found, &start, 1, start_margin) : 1;
        sum->toi = s.toi;
        if (!add_ccd(g, slot_contacts(g), s.contacts_found, vertex_accept)) return 0;
        if (dt > 0.0 && !start_ran && (s.toi > mm->t0 || travel > margin)) { /* the DCD baseline */
            dp.margin = start_margin;
            sum->discrete_queries++;
            if (!query(g, &start, &dp, &r0)) return 0;
            if (r0.hit && !(kept = keep_start(g, &r0))) return 0;
        }
    }

    /* 4. the start pose's features and the end pose's, each held from t0; no end-pose query when
     *    the step's travel is within end_skip_travel (its features are the start pose's, moved by at
     *    most that) */
    if (dt > 0.0) {
        const int end_query = !(continuous && cp->end_skip_travel > 0.0 && travel <= cp->end_skip_travel);
        if (kept && !add_pose(g, kept, r0.contacts_found, &start, 1, touching ? fmax(start_margin, vertex_accept) : start_margin)) return 0;
        scc_query_summary r1;
        dp.margin = margin;
        if (!end_query) return 1;
        sum->discrete_queries++;
        if (!query(g, &end, &dp, &r1)) return 0;
        if (r1.hit && !add_pose(g, slot_contacts(g), r1.contacts_found, &end, same_pose(&end, &start), margin)) return 0;
    }
    return 1;
}

int scc_generate_contacts(const scc_sdf* sdf, const scc_mesh_motion* mm_in, const scc_contact_params* cp, scc_workspace* ws,
                          scc_contact_point* out, int capacity, scc_contact_set* sum)
{
    memset(sum, 0, sizeof *sum);
    sum->ccd_state = SCC_NO_HIT;
    sum->toi = mm_in->t1;
    /* A static SDF given as a motion: the body in the SDF's frame, so the field is evaluated
     * without moving it (the points are in that frame anyway). */
    scc_mesh_motion mm = *mm_in;
    mm.tri_margin = NULL;
    mm.node_clear = NULL;
    scc_rigid body;
    if (mm.sdf && mm.body && is_zero(mm.sdf->v) && is_zero(mm.sdf->w)) {
        const scc_quat qi = scc_quat_conj(mm.sdf->q0);
        body = *mm.body;
        body.q0 = scc_quat_mul(qi, mm.body->q0);
        body.p0 = scc_quat_rotate(qi, scc_sub(mm.body->p0, mm.sdf->p0));
        body.v = scc_quat_rotate(qi, mm.body->v);
        body.w = scc_quat_rotate(qi, mm.body->w);
        mm.body = &body;
        mm.sdf = NULL;
    }
    const double radius = mesh_radius(&mm);
    gen g = { sdf, &mm, ws, { ws->slot[SCC_WS_CANDIDATES].p, 0, ws->slot[SCC_WS_CANDIDATES].bytes / sizeof(scc_contact_point), ws->alloc },
              sum };
    const int ok = candidates(&g, cp, radius);
    scc_ws_adopt(ws, SCC_WS_CANDIDATES, g.b.a, g.b.cap * sizeof *g.b.a);
    sum->evals += sum->own_evals;
    if (!ok) return 0;

    /* 5. the reduction to the caller's room, then cover points */
    const scc_contact_point* c = g.b.a;
    const size_t n = g.b.n;
    sum->candidates = n;
    if (capacity <= 0 || n == 0) return 1;
    const double same = cp->same_place > 0.0 ? cp->same_place : fmax(SAME_PLACE_MIN, SAME_PLACE_SHARE * radius);
    const size_t k = cp->reduced > 0 && cp->reduced < capacity ? (size_t)cp->reduced : (size_t)capacity;
    int32_t* idx = scc_ws_get(ws, SCC_WS_REDUCE, (size_t)capacity * sizeof *idx);
    double* scratch = idx ? scc_ws_get(ws, SCC_WS_REDUCE_SCRATCH, n * sizeof *scratch) : NULL;
    if (!scratch) return 0;
    sum->reduced = scc_reduce_kept(c, n, cand_item, same, fmin(DEPTH_SCALE_MAX, DEPTH_SCALE_SHARE * radius), &cp->keep, k, idx, scratch);
    sum->written = sum->reduced;
    if (cp->cover_depth > 0.0 && sum->reduced > 0 && sum->reduced < (size_t)capacity) {
        /* the body's turn (relative to the SDF) about axes in the contact plane over the step */
        scc_vec3 w = mm.body ? mm.body->w : scc_v3(0, 0, 0), nrm = c[idx[0]].normal;
        if (mm.sdf) {
            w = scc_sub(w, mm.sdf->w);
            nrm = scc_world_vector(mm.sdf, mm.t0, nrm);
        }
        const double tilt = (mm.t1 - mm.t0) * scc_len(scc_sub(w, scc_scale(nrm, scc_dot(nrm, w))));
        sum->written += scc_cover(c, n, cand_item, idx, sum->reduced, tilt, cp->cover_depth, same, (size_t)capacity - sum->reduced,
                                  idx + sum->reduced);
    }
    for (size_t i = 0; i < sum->written; ++i) out[i] = c[idx[i]];
    return 1;
}
