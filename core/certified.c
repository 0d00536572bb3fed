/* SPDX-License-Identifier: MIT
 * sdfccd core: certified time of impact by Lipschitz branch and bound (ours; DESIGN.md
 * "Certified TOI"; the paper has no such method and uses brute force ground truth, Section 5.2).
 *
 * A region is a sub-triangle (three barycentric corners) times a time span [ta, tb]. Its
 * centroid c is sampled at ta. Any point of the region lies within
 *   rho = max_i |corner_i(ta) - c(ta)| + S (tb - ta)
 * of c(ta), where S bounds the speed of every point of the triangle, so for an L-Lipschitz
 * field phi >= phi(c) - L rho over the region. Regions whose bound exceeds the margin are
 * pruned; the rest are split (space into four, or time into two, whichever term of rho is
 * larger) and processed earliest-first. A sample with phi <= margin is a witness: the first
 * TOI is at most its time (unresolved regions are also sampled at their corners, at ta and tb, for witnesses). The
 * popped region's ta is a proven lower bound (everything earlier was pruned), so the loop
 * brackets the first TOI in [lo, hi] and stops when hi - lo <= tolerance; a witness at the
 * popped region's own ta closes the bracket exactly. No false negatives
 * as long as L is a true Lipschitz bound (1 for the analytic fields). When phi is convex (the
 * distance of a convex shape) the first-order bound phi(x) >= phi(c) + grad(c).(x - c) prunes
 * tangential contacts far sooner than the Lipschitz ball. */
#include "ccd.h"
#include "min_heap.h"
#include "sdf_analytic.h"

typedef struct region {
    double ta, tb;
    double u[3], v[3]; /* barycentric corners: weights (u, v, 1 - u - v) */
} region;

SCC_MIN_HEAP(region_heap, region, ta)

/* Whether phi is convex on `box`: the field's own answer or, for CSG (ours, issue 20), where one
 * operand decides phi on the whole box (the operands evaluated at its centre, their Lipschitz bounds
 * over its half-diagonal), that operand's answer: a cube minus a ball is the cube's convex distance
 * away from the carved ball, which lets the first-order bound prune sliding contacts there. */
static int convex_on(const scc_sdf* sdf, const scc_aabb* box, int64_t* evals)
{
    if (scc_sdf_convex_in(sdf, box)) return 1;
    if (sdf->kind != SCC_SDF_CSG) return 0;
    const scc_sdf_csg* s = (const scc_sdf_csg*)sdf;
    const scc_vec3 c = scc_scale(scc_add(box->lo, box->hi), 0.5);
    const double h = 0.5 * scc_dist(box->lo, box->hi);
    double a = scc_sdf_eval(s->a, c, NULL), b = scc_sdf_eval(s->b, c, NULL);
    *evals += 2;
    const double ra = scc_sdf_lipschitz(s->a, box) * h, rb = scc_sdf_lipschitz(s->b, box) * h;
    if (s->op == SCC_CSG_DIFFERENCE) b = -b; /* max(a, -b) */
    if (s->op == SCC_CSG_UNION) { /* min(a, b) */
        if (a + ra < b - rb) return scc_sdf_convex_in(s->a, box);
        if (b + rb < a - ra) return scc_sdf_convex_in(s->b, box);
        return 0;
    }
    if (a - ra > b + rb) return scc_sdf_convex_in(s->a, box);
    if (s->op == SCC_CSG_INTERSECTION && b - rb > a + ra) return scc_sdf_convex_in(s->b, box);
    return 0;
}

static scc_vec3 corner(const scc_tri_state* st, double u, double v)
{
    return scc_add(scc_add(scc_scale(st->x[0], u), scc_scale(st->x[1], v)), scc_scale(st->x[2], 1.0 - u - v));
}

/* The region store of a check of FWGSS (scc_fwgss_verify) starts in a buffer on the stack (ours): a
 * check that never holds more regions than it does allocates nothing, so a mesh or guard query
 * through a warm workspace allocates nothing when its checks stay within it (test_guard). The heap
 * grows by allocating the new array, copying, then freeing the old one, so a request that fits is
 * given the same buffer again (the copy is onto itself); larger ones go to the caller's allocator. */
#define STACK_REGIONS 1024 /* 64 KB */
typedef struct stack_store {
    region buf[STACK_REGIONS];
    const scc_allocator* next;
} stack_store;

static void* stack_alloc(size_t size, void* user)
{
    stack_store* st = user;
    return size <= sizeof st->buf ? st->buf : scc_alloc(st->next, size);
}

static void stack_free(void* mem, size_t size, void* user)
{
    stack_store* st = user;
    if (mem != (void*)st->buf) scc_free(st->next, mem, size);
}

/* The search. `seed_t` (INFINITY: none) is a known contact (weights seed_b) that is the initial upper
 * bound: while no earlier witness turns up, the search stops once the bracket is `seed_tol` wide;
 * after one, at the certified time tolerance. At most `max_evals` evaluations. */
static int certified_search(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                            const scc_allocator* alloc, double seed_t, const double seed_b[3], double seed_tol, int64_t max_evals,
                            scc_tri_hit* out)
{
    /* The region store never holds more than cert_max_bytes (0: no limit); when it is full the
     * search stops like at the other caps: NOT_CONVERGED, the earliest witness so far, and the
     * popped region's start as the proven lower bound. */
    region_heap h = { NULL, 0, 0, alloc, 0, 0 };
    if (p->cert_max_bytes > 0) h.max_bytes = (uint64_t)p->cert_max_bytes > SIZE_MAX ? SIZE_MAX : (size_t)p->cert_max_bytes;
    region root = { ta, tb, { 1, 0, 0 }, { 0, 1, 0 } };
    int capped = 0, ok = 1;
    if (!region_heap_push(&h, root)) {
        if (!h.full) return 0;
        capped = 1;
    }
    const double speed = scc_tri_speed_bound(m);
    const double accel = scc_tri_accel_bound(m);
    double hi = seed_t, lo = ta;
    double hit_b[3] = { 1, 0, 0 };
    if (isfinite(seed_t))
        for (int j = 0; j < 3; ++j) hit_b[j] = seed_b[j];
    int64_t processed = 0, evals = 0;
    while (h.n) {
        region r = region_heap_pop(&h);
        lo = r.ta;
        if (r.ta >= hi) { lo = hi; break; }
        if (hi - lo <= (hi == seed_t ? seed_tol : p->cert_time_tol)) break;
        if (processed >= p->cert_max_regions || evals >= max_evals) { capped = 1; break; }
        ++processed;
        scc_tri_state st;
        scc_tri_state_at(m, r.ta, &st);
        double cu = (r.u[0] + r.u[1] + r.u[2]) / 3.0, cv = (r.v[0] + r.v[1] + r.v[2]) / 3.0;
        scc_vec3 c = corner(&st, cu, cv);
        scc_vec3 gc;
        double phi = scc_sdf_eval(sdf, c, &gc);
        ++evals;
        if (phi <= p->margin && r.ta < hi) {
            hi = r.ta;
            hit_b[0] = cu; hit_b[1] = cv; hit_b[2] = 1.0 - cu - cv;
            lo = hi;
            break; /* sampled at the region's earliest time: nothing earlier is unresolved */
        }
        double rs = 0.0;
        for (int i = 0; i < 3; ++i) rs = fmax(rs, scc_dist(corner(&st, r.u[i], r.v[i]), c));
        double rt = speed * (r.tb - r.ta);
        double rho = rs + rt;
        scc_aabb box = { scc_sub(c, scc_v3(rho, rho, rho)), scc_add(c, scc_v3(rho, rho, rho)) };
        double L = scc_sdf_lipschitz(sdf, &box);
        if (phi - L * rho > p->margin) continue; /* pruned: no contact anywhere in the region */
        /* Which part of the bound's slack to refine: the Lipschitz ball's spatial and temporal
         * radii, or, for a convex phi, the spatial and temporal parts of the first-order bound. */
        double slack_space = rs, slack_time = rt;
        if (convex_on(sdf, &box, &evals)) {
            /* First-order bound of a convex phi: phi(x) >= phi(c) + g.(x - c). Over the region,
             * x(b, ta + s) - c = sum_i b_i (x_i(ta) - c + s v_i(ta)) + e with |e| <= A s^2 / 2, and
             * the bilinear part is smallest at a corner and at s = 0 or s = tb - ta. Tangential
             * sliding therefore costs nothing, unlike in the Lipschitz ball. */
            double dt = r.tb - r.ta, lin = INFINITY, lin_space = INFINITY, lin_time = INFINITY;
            for (int i = 0; i < 3; ++i) {
                scc_vec3 xi = corner(&st, r.u[i], r.v[i]);
                scc_vec3 vi = scc_add(scc_add(scc_scale(st.v[0], r.u[i]), scc_scale(st.v[1], r.v[i])), scc_scale(st.v[2], 1.0 - r.u[i] - r.v[i]));
                double at0 = scc_dot(gc, scc_sub(xi, c)), drift = dt * scc_dot(gc, vi);
                lin = fmin(lin, fmin(at0, at0 + drift));
                lin_space = fmin(lin_space, at0);
                lin_time = fmin(lin_time, drift);
            }
            double curve = scc_len(gc) * 0.5 * accel * dt * dt;
            if (phi + lin - curve > p->margin) continue;
            if (phi + lin - curve > phi - L * rho) {
                slack_space = -fmin(lin_space, 0.0);
                slack_time = -fmin(lin_time, 0.0) + curve;
            }
        }
        /* Unresolved: look for witnesses at the corners at ta (a contact there is exact: nothing
         * earlier is unresolved) and at the centroid and corners at tb (an upper bound). Corners
         * matter: at a vertex-first contact the centroid alone stays borderline at every scale. */
        int done = 0;
        for (int i = 0; i < 3 && !done; ++i) {
            ++evals;
            if (scc_sdf_eval(sdf, corner(&st, r.u[i], r.v[i]), NULL) <= p->margin) {
                hi = lo = r.ta;
                hit_b[0] = r.u[i]; hit_b[1] = r.v[i]; hit_b[2] = 1.0 - r.u[i] - r.v[i];
                done = 1;
            }
        }
        if (done) break;
        if (r.tb < hi) {
            scc_tri_state se;
            scc_tri_state_at(m, r.tb, &se);
            double su[4] = { cu, r.u[0], r.u[1], r.u[2] }, sv[4] = { cv, r.v[0], r.v[1], r.v[2] };
            for (int i = 0; i < 4; ++i) {
                ++evals;
                if (scc_sdf_eval(sdf, corner(&se, su[i], sv[i]), NULL) <= p->margin) {
                    hi = r.tb;
                    hit_b[0] = su[i]; hit_b[1] = sv[i]; hit_b[2] = 1.0 - su[i] - sv[i];
                    break;
                }
            }
        }
        if (slack_time >= slack_space) {
            double tm = 0.5 * (r.ta + r.tb);
            region a = r, b = r;
            a.tb = tm;
            b.ta = tm;
            if (!region_heap_push(&h, a) || (b.ta < hi && !region_heap_push(&h, b))) {
                if (h.full) capped = 1;
                else ok = 0;
                break;
            }
        } else {
            double mu[3], mv[3];
            for (int i = 0; i < 3; ++i) {
                int j = (i + 1) % 3;
                mu[i] = 0.5 * (r.u[i] + r.u[j]);
                mv[i] = 0.5 * (r.v[i] + r.v[j]);
            }
            region k[4] = {
                { r.ta, r.tb, { r.u[0], mu[0], mu[2] }, { r.v[0], mv[0], mv[2] } },
                { r.ta, r.tb, { mu[0], r.u[1], mu[1] }, { mv[0], r.v[1], mv[1] } },
                { r.ta, r.tb, { mu[2], mu[1], r.u[2] }, { mv[2], mv[1], r.v[2] } },
                { r.ta, r.tb, { mu[0], mu[1], mu[2] }, { mv[0], mv[1], mv[2] } },
            };
            for (int i = 0; i < 4 && ok; ++i) ok = region_heap_push(&h, k[i]);
            if (!ok) {
                if (h.full) ok = capped = 1;
                break;
            }
        }
    }
    if (!h.n && ok && !capped) lo = isfinite(hi) ? hi : tb;
    scc_free(alloc, h.a, h.cap * sizeof *h.a);
    if (!ok) return 0;

    out->iterations = processed;
    out->hit = isfinite(hi);
    if (out->hit) {
        out->toi = hi;
        out->toi_lower = fmin(lo, hi);
        for (int j = 0; j < 3; ++j) out->bary[j] = hit_b[j];
        out->point = scc_tri_point_at(m, hit_b, hi, NULL);
        out->distance = scc_sdf_eval(sdf, out->point, &out->normal);
        ++evals;
        out->state = capped ? SCC_NOT_CONVERGED : (hi <= ta ? SCC_PENETRATING : SCC_HIT);
    } else {
        out->toi = tb;
        out->toi_lower = capped ? lo : tb;
        out->bary[0] = 1; out->bary[1] = 0; out->bary[2] = 0;
        out->point = scc_v3(0, 0, 0);
        out->normal = scc_v3(0, 0, 1);
        out->distance = INFINITY;
        out->state = capped ? SCC_NOT_CONVERGED : SCC_NO_HIT;
    }
    out->evals = evals;
    return 1;
}

int scc_certified(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                  const scc_allocator* alloc, scc_tri_hit* out)
{
    const double none[3] = { 1, 0, 0 };
    return certified_search(sdf, m, ta, tb, p, alloc, INFINITY, none, 0.0, p->max_evals, out);
}

/* Whether FWGSS's answer on this field is checked by the certified search (ours, issue 20): fields
 * whose gradient may jump (box and cylinder edges, CSG seams, cone tips, grid cells, unknown user
 * fields), where the descents' local steps can stop at a later contact. Smooth fields are not. */
int scc_fwgss_verified(const scc_sdf* sdf, const scc_params* p)
{
    if (p->fwgss_kink_guard <= 0 || !p->fwgss_verify || sdf->smooth) return 0; /* smooth: scc_sdf.smooth */
    switch (sdf->kind) {
    case SCC_SDF_SPHERE: case SCC_SDF_TORUS: case SCC_SDF_CAPSULE: case SCC_SDF_ROUNDED_BOX: case SCC_SDF_HALF_SPACE: return 0;
    case SCC_SDF_GRID: return 0; /* the Lipschitz bounds of a grid's cells make it far too slow (median 10^5 evaluations) */
    default: return 1;
    }
}

int scc_fwgss_verify(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                     const scc_allocator* alloc, scc_tri_hit* io)
{
    if (!scc_fwgss_verified(sdf, p) || (io->hit && !(io->toi > ta))) return 1;
    /* No hit with no descent run: FWGSS's conservative no-contact proof (fwgss_clear_proof) held */
    if (!io->hit && io->state == SCC_NO_HIT && io->iterations == 0) return 1;
    int64_t budget = p->max_evals - io->evals;
    /* at most SCC_VERIFY_FACTOR times FWGSS's own evaluations plus SCC_VERIFY_BASE_EVALS: a triangle
     * resting at the contact level (a guard's per-triangle levels) keeps every region borderline, and
     * the check would otherwise spend 10^5 evaluations there (test_guard) */
    const int64_t cap = SCC_VERIFY_FACTOR * io->evals + SCC_VERIFY_BASE_EVALS;
    if (budget > cap) budget = cap;
    if (budget > SCC_VERIFY_MAX_EVALS) budget = SCC_VERIFY_MAX_EVALS;
    if (budget <= 0) return 1;
    scc_tri_hit c;
    const double seed_t = io->hit ? io->toi : INFINITY;
    stack_store store;
    store.next = alloc;
    const scc_allocator hooks = { stack_alloc, stack_free, &store };
    if (!certified_search(sdf, m, ta, io->hit ? io->toi : tb, p, &hooks, seed_t, io->bary, fmax(p->time_tol, SCC_VERIFY_TOL), budget, &c)) return 0;
    io->evals += c.evals;
    io->iterations += c.iterations;
    if (c.hit && c.toi < seed_t) {
        /* an earlier contact: the certified witness replaces FWGSS's */
        const int64_t evals = io->evals, iterations = io->iterations;
        *io = c;
        io->evals = evals;
        io->iterations = iterations;
        io->toi_lower = io->toi;
        if (io->state == SCC_NOT_CONVERGED) io->state = io->toi <= ta ? SCC_PENETRATING : SCC_HIT;
    } else if (c.state != SCC_NOT_CONVERGED && io->hit && io->state == SCC_NOT_CONVERGED) {
        io->state = SCC_HIT; /* proven: no contact more than SCC_VERIFY_TOL before the witness */
    }
    return 1;
}
