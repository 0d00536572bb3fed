/* SPDX-License-Identifier: MIT
 * sdfccd core: Frank-Wolfe with golden-section line searches, FWGSS (Pelletier-Guenette et al.
 * 2025, Algorithm 2, Sections 4.3-4.4). Each iteration solves a temporal line search (unsigned
 * distance backwards in time when the iterate is in contact, else signed distance in the
 * direction of Eq. 17) and then a spatial line search towards the support vertex at the new time.
 * Every evaluated point in contact is a witness that shrinks the time interval, so the earliest
 * witnessed time converges to the first time of impact from above. */
#include "fw_common.h"
#include "gss.h"

/* A temporal search's context: the solver and the point it follows (s->b, fixed during the search). */
typedef struct time_ctx {
    scc_fw_state* s;
    scc_fw_path path;
} time_ctx;

SCC_HOT_INLINE double phi_at_time(double t, void* c)
{
    time_ctx* k = c;
    scc_fw_state* s = k->s;
    scc_vec3 x = scc_fw_path_point(s, &k->path, t);
    double phi = scc_fw_sdf(s, x, NULL);
    s->evals++;
    scc_fw_witness(s, t, k->path.b, phi);
    return phi - s->margin;
}

static double unsigned_phi_at_time(double t, void* c) { return fabs(phi_at_time(t, c)); }

/* Algorithm 2 line 13 minimises |phi| over [ts, t_i] to find where the current point enters the
 * contact surface. When its path first grazes the surface and re-enters later (rotation, thin
 * features), |phi| has a second local minimum away from zero and the golden-section search can
 * settle there; the solver then cycles between the graze and the entry. phi is in contact at
 * t_i, so when it is not in contact at ts a sign change is bracketed: bisection then lands on a
 * true crossing. (Ours; the paper's conclusion also suggests bisection.) */
static scc_gss_result crossing_by_bisection(time_ctx* tc, double lo, double hi, const scc_params* p)
{
    scc_gss_result r;
    r.evals = 0;
    r.converged = 1;
    double flo = phi_at_time(lo, tc);
    if (flo <= 0.0) { /* in contact already at the interval start */
        r.l = lo;
        r.f = fabs(flo);
        return r;
    }
    int it = 0;
    while (hi - lo > p->time_tol && it++ < p->max_ls_iter) {
        double mid = 0.5 * (lo + hi);
        if (phi_at_time(mid, tc) > 0.0) lo = mid;
        else hi = mid;
    }
    r.converged = hi - lo <= p->time_tol;
    r.l = hi;
    r.f = fabs(phi_at_time(hi, tc));
    return r;
}

/* The same entry search by regula falsi with the Illinois modification (ours): phi is
 * smooth along a path away from the field's ridges, so the secant through the bracket's ends
 * converges superlinearly, and halving the retained end's value when one end repeats keeps it
 * from stalling on a convex stretch. Every few steps that did not halve the bracket, a
 * bisection step bounds the worst case by the bisection's. `fhi` (<= 0) is phi - margin at hi. */
static scc_gss_result crossing_by_secant(time_ctx* tc, double lo, double hi, double fhi, const scc_params* p)
{
    /* the parameters the loop reads, read once (a sample's stores through the solver's pointer could
     * alias them for the compiler) */
    const double time_tol = p->time_tol;
    const int max_ls_iter = p->max_ls_iter;
    scc_gss_result r;
    r.evals = 0;
    r.converged = 1;
    double flo = phi_at_time(lo, tc);
    if (flo <= 0.0) {
        r.l = lo;
        r.f = fabs(flo);
        return r;
    }
    int it = 0, side = 0, slow = 0;
    while (hi - lo > time_tol && it++ < max_ls_iter) {
        double width = hi - lo, t;
        if (slow >= 2) {
            t = 0.5 * (lo + hi);
            slow = 0;
        } else {
            t = hi - fhi * (hi - lo) / (fhi - flo);
            /* keep the sample strictly inside, at least a quarter tolerance from either end */
            double m = 0.25 * time_tol;
            if (!(t > lo + m)) t = lo + m;
            if (!(t < hi - m)) t = hi - m;
        }
        double f = phi_at_time(t, tc);
        if (f > 0.0) {
            lo = t;
            flo = f;
            if (side == -1) fhi *= 0.5;
            side = -1;
        } else {
            hi = t;
            fhi = f;
            if (side == 1) flo *= 0.5;
            side = 1;
        }
        slow = hi - lo > 0.5 * width ? slow + 1 : 0;
    }
    r.converged = hi - lo <= time_tol;
    r.l = hi;
    r.f = fabs(fhi);
    return r;
}

typedef struct space_ctx {
    scc_fw_state* s;
    scc_vec3 a, b;      /* segment from the iterate to the support vertex */
    double ba[3], bb[3];
    double t;
    scc_vec3 d;         /* b - a, once per segment (scc_lerp's difference) */
} space_ctx;

/* phi at parameter l of the segment (and its derivative along it when df is not NULL); a point in
 * contact is a witness. */
SCC_HOT_INLINE double eval_on_segment(space_ctx* k, double l, double* df)
{
    scc_vec3 g;
    double phi = scc_fw_sdf(k->s, scc_madd(k->a, k->d, l), df ? &g : NULL);
    k->s->evals++;
    if (df) *df = scc_dot(g, k->d);
    if (phi <= k->s->margin) {
        double b[3];
        for (int j = 0; j < 3; ++j) b[j] = (1.0 - l) * k->ba[j] + l * k->bb[j];
        scc_fw_witness(k->s, k->t, b, phi);
    }
    return phi;
}

/* Inlined into the searches' loops: callgrind over the data set's triangle queries, 231.8 -> 222.3
 * instructions per evaluation with the built-in torus and 288.2 -> 281.7 with a callback field (an
 * earlier measurement found a callback's queries 3 % slower inlined, when every sample still went
 * through scc_sdf_eval_builtin's tests; same-run timings here differ by less than their noise). */
SCC_HOT_INLINE double phi_on_segment(double l, void* c) { return eval_on_segment(c, l, NULL); }

/* phi on the segment and its slope, for the search with derivatives. */
SCC_HOT_INLINE double phi_slope_on_segment(double l, double* df, void* c) { return eval_on_segment(c, l, df); }

/* Inside the triangle: the end point (weights `bb`) where the in-plane steepest descent
 * direction -grad leaves the triangle. Returns 0 when there is no such direction. */
static int interior_direction(const scc_tri_state* st, scc_vec3 g, const double b[3], double bb[3])
{
    scc_vec3 e1 = scc_sub(st->x[1], st->x[0]), e2 = scc_sub(st->x[2], st->x[0]);
    double a11 = scc_dot(e1, e1), a12 = scc_dot(e1, e2), a22 = scc_dot(e2, e2);
    double r1 = -scc_dot(g, e1), r2 = -scc_dot(g, e2);
    double det = a11 * a22 - a12 * a12;
    if (!(det > 0.0)) return 0;
    double d1 = (a22 * r1 - a12 * r2) / det, d2 = (a11 * r2 - a12 * r1) / det;
    double db[3] = { -d1 - d2, d1, d2 };
    double lmax = INFINITY;
    for (int j = 0; j < 3; ++j)
        if (db[j] < 0.0) lmax = scc_fmin(lmax, -b[j] / db[j]);
    if (!isfinite(lmax)) return 0;
    double sum = 0.0;
    for (int j = 0; j < 3; ++j) sum += (bb[j] = scc_fmax(b[j] + lmax * db[j], 0.0));
    if (!(sum > 0.0)) return 0;
    for (int j = 0; j < 3; ++j) bb[j] /= sum;
    return 1;
}

/* Golden-section search of phi at time t on the segment from the iterate (point xn, weights
 * s->b, phi - margin = gap there, gradient gn) to the weights bb; moves s->b there and returns the
 * length of the step. The search's tolerance is the spatial tolerance or, far from the surface, a
 * fraction of the gap (ours): there the step only has to point the next temporal search the right
 * way, and the searches that place the contact run at contact, where the gap is 0. */
static double spatial_search(scc_fw_state* s, const scc_tri_state* st, scc_vec3 xn, double gap, scc_vec3 gn, const double bb[3], double t)
{
    const scc_params* p = s->p;
    scc_vec3 end = scc_add(scc_add(scc_scale(st->x[0], bb[0]), scc_scale(st->x[1], bb[1])), scc_scale(st->x[2], bb[2]));
    double len = scc_dist(end, xn);
    if (!(len > s->dist_tol)) return 0.0;
    space_ctx k = { s, xn, end, { s->b[0], s->b[1], s->b[2] }, { bb[0], bb[1], bb[2] }, t, scc_sub(end, xn) };
    const double fine = s->dist_tol, coarse = p->fwgss_gap_tol * gap;
    const double tol = scc_fmax(fine, coarse) / len;
    const double f0 = gap + p->margin; /* phi at the iterate, l = 0: not evaluated again */
    double f1 = NAN;
    scc_gss_result sp;
    /* At full precision (at or next to contact, where the spatial step places the contact) the
     * gradient is used (ours): secant steps on the slope along the segment need a handful of
     * evaluations where golden section needs log(tol) / log(0.618), about 25. Far from the surface
     * the wide golden-section samples stay: there they find the lower of several dips. Converging
     * superlinearly, it runs to a twentieth of the tolerance for about 2 evaluations more per
     * query (test_sweep, golden section / this / this at the full tolerance: mean |dTOI| 3.08e-8 /
     * 3.04e-8 / 3.09e-8 s, mean distance from the certified bracket 2.53e-9 / 2.17e-9 / 2.65e-9 s). */
    if (p->fwgss_deriv_spatial && !s->kinked && coarse <= fine &&
        scc_deriv_run(f0, scc_dot(gn, scc_sub(end, xn)), 0.05 * tol, p->max_ls_iter, phi_slope_on_segment, &k, &sp, &f1)) {
        /* done */
    } else if (p->fwgss_brent_spatial) {
        /* Brent's parabolic steps (ours) converge superlinearly where phi is smooth along the segment */
        sp = scc_brent_minimize(0.0, 1.0, tol, p->max_ls_iter, phi_on_segment, &k);
    } else {
        sp = scc_gss_run(0.0, 1.0, f0, f1, tol, 0.0, p->max_ls_iter, phi_on_segment, &k); /* Algorithm 1 */
    }
    for (int j = 0; j < 3; ++j) s->b[j] = scc_fmax((1.0 - sp.l) * s->b[j] + sp.l * bb[j], 0.0);
    return sp.l * len;
}

/* The spatial sub-problem at time tn from the weights s->b: one step, which moves s->b; returns
 * its length (*out_gap: phi - margin at the weights before the step). */
static double spatial_step(scc_fw_state* s, double tn, double* out_gap)
{
    /* Spatial sub-problem at the new time (lines 22-31). On the boundary of the triangle it
     * is a pairwise step: weight moves from the active vertex with the largest grad . vertex
     * (the "away" vertex) to the support vertex of Eq. 15; at a vertex this is the paper's
     * step towards the support vertex. Inside the triangle (ours) the step follows the
     * in-plane steepest descent up to the boundary: vertex-to-vertex directions zig-zag
     * towards an interior optimum (a spike apex under a face took more than 32 iterations and
     * stopped 62 us late), while the projected gradient points at it. */
    scc_vec3 xn, gn;
    double gap = scc_fw_eval(s, s->b, tn, &xn, &gn, NULL) - s->margin; /* no velocity needed here */
    if (out_gap) *out_gap = gap;
    scc_tri_state st;
    scc_fw_tri_points(s, tn, &st);
    double bb[3];
    int have_dir = 0, interior = 0;
    if (s->b[0] > 0.0 && s->b[1] > 0.0 && s->b[2] > 0.0) interior = have_dir = interior_direction(&st, gn, s->b, bb);
    if (!have_dir) {
        /* grad . vertex once for both: the support vertex and the away vertex */
        const double d[3] = { scc_dot(gn, st.x[0]), scc_dot(gn, st.x[1]), scc_dot(gn, st.x[2]) };
        int sv = scc_fw_support_of(d);
        int av = sv;
        double best = -INFINITY;
        for (int j = 0; j < 3; ++j)
            if (s->b[j] > 0.0 && d[j] > best) { best = d[j]; av = j; }
        if (av != sv) {
            for (int j = 0; j < 3; ++j) bb[j] = s->b[j];
            bb[sv] += s->b[av];
            bb[av] = 0.0;
            have_dir = 1;
        }
    }
    double step = have_dir ? spatial_search(s, &st, xn, gap, gn, bb, tn) : 0.0;
    if (interior && step <= s->dist_tol) {
        /* Stalled inside (ours): at a kink of the field (a box's edge or corner under the face)
         * the steepest descent of one side need not descend, and the iterate would stop short
         * of the minimum over the triangle (test_sweep: 19 us late on a box). Before concluding,
         * the paper's step towards the support vertex (Eq. 15) is searched too. */
        int sv = scc_fw_support(&st, gn);
        for (int j = 0; j < 3; ++j) bb[j] = j == sv;
        step = spatial_search(s, &st, scc_fw_point(s, s->b, tn, NULL), gap, gn, bb, tn);
    }
    return step;
}

/* One FWGSS descent from the weights in s->b and the time t (Algorithm 2 lines 4-33: t = ts).
 * Returns 1 if it converged. */
static int descend(scc_fw_state* s, double t, int64_t* io_iterations)
{
    const scc_params* p = s->p;
    int64_t it = 0;
    while (it < p->max_iter && s->evals < p->max_evals) {
        ++it;
        /* Temporal sub-problem (lines 5-21). */
        scc_vec3 x, g, v;
        double phi = scc_fw_eval(s, s->b, t, &x, &g, &v);
        scc_gss_result ls;
        time_ctx tc;
        tc.s = s;
        scc_fw_path_of_current(s, &tc.path); /* the point scc_fw_eval has just taken */
        if (phi <= p->margin && p->fwgss_secant && t > s->ts) {
            ls = crossing_by_secant(&tc, s->ts, t, phi - p->margin, p);
        } else if (phi <= p->margin) {
            ls = scc_gss_minimize(s->ts, t, p->time_tol, p->max_ls_iter, unsigned_phi_at_time, &tc);
            if (ls.f > s->dist_tol) ls = crossing_by_bisection(&tc, s->ts, scc_fmin(t, s->te), p);
        } else if (scc_dot(g, v) > 0.0) { /* d = -1: moving away, look back in time (phi at t is known) */
            ls = scc_gss_run(s->ts, t, NAN, phi - p->margin, p->time_tol, s->time_slope, p->max_ls_iter, phi_at_time, &tc);
        } else {
            ls = scc_gss_run(t, s->te, phi - p->margin, NAN, p->time_tol, s->time_slope, p->max_ls_iter, phi_at_time, &tc);
        }
        double tn = scc_fmin(ls.l, s->te);

        double step = spatial_step(s, tn, NULL);
        int small = fabs(tn - t) <= p->time_tol && step <= s->dist_tol; /* line 32 */
        t = tn;
        if (small) { *io_iterations += it; return 1; }
    }
    *io_iterations += it;
    return 0;
}

/* Gradient bound for a conservative step from point x with gap phi: the field's bound in the
 * box about the ball of radius phi (at least 1e-12). */
static double step_lipschitz(const scc_fw_state* s, scc_vec3 x, double phi)
{
    double L = s->sdf->lipschitz; /* scc_sdf_lipschitz without the box when the field has no local bound */
    if (s->sdf->lipschitz_in) {
        scc_aabb box = { scc_sub(x, scc_v3(phi, phi, phi)), scc_add(x, scc_v3(phi, phi, phi)) };
        L = s->sdf->lipschitz_in(s->sdf, &box);
    }
    return L > 1e-12 ? L : 1e-12;
}

/* The vertex path with weights b enters the margin between lo (phi - margin = flo > 0) and *io_t
 * (*io_phi <= margin), the last step of a conservative advancement; that step is short, so phi is
 * nearly linear on it and a few regula falsi steps move the witness to the crossing (otherwise it
 * can lie up to a time tolerance late, and a witness of a shared trace then bounds other
 * triangles' descents by a late time). */
static void refine_entry(scc_fw_state* s, const scc_fw_path* path, double lo, double flo, double* io_t, double* io_phi)
{
    const double margin = s->margin;
    double hi = *io_t, fhi = *io_phi - margin;
    for (int k = 0; k < 3 && hi - lo > 1e-3 * s->p->time_tol; ++k) {
        double t = hi - fhi * (hi - lo) / (fhi - flo);
        if (!(t > lo && t < hi)) t = 0.5 * (lo + hi);
        double phi = scc_fw_sdf(s, scc_fw_path_point(s, path, t), NULL);
        s->evals++;
        if (phi - margin > 0.0) {
            lo = t;
            flo = phi - margin;
        } else {
            hi = t;
            fhi = phi - margin;
            *io_t = t;
            *io_phi = phi;
        }
    }
}

/* One vertex path's conservative advancement (trace_vertices). */
typedef struct trace_lane {
    scc_vertex_trace* r; /* shared record, or NULL */
    scc_fw_path path;
    double t, start, t_prev, f_prev, clear_to, speed, ls;
    int k;               /* samples taken */
} trace_lane;

/* Sets up vertex i's trace: reuses its record's witness or skips its clear stretch. Returns 0 when
 * there is nothing to trace. */
static int trace_begin(scc_fw_state* s, int i, trace_lane* L)
{
    const double b[3] = { i == 0, i == 1, i == 2 };
    scc_vertex_trace* r = s->m->trace[i];
    double t = s->ts;
    double speed;
    if (r) {
        if (r->speed < 0.0) r->speed = scc_vertex_speed_bound(s->m, i);
        speed = r->speed;
        if (r->hit_t >= s->ts && r->hit_t <= s->te) {
            scc_fw_witness(s, r->hit_t, b, r->hit_phi);
            return 0;
        }
        if (r->from <= t && t < r->to) t = r->to;
    } else {
        speed = scc_vertex_speed_bound(s->m, i);
    }
    if (!(speed > 0.0)) return 0;
    L->r = r;
    scc_fw_path_init(s, b, &L->path);
    L->t = L->start = L->t_prev = L->clear_to = t;
    L->f_prev = INFINITY;
    L->speed = speed;
    /* L x S of the step's bound, once per trace when the field has one global bound (the same product) */
    L->ls = s->sdf->lipschitz_in ? NAN : step_lipschitz(s, s->g0, 0.0) * speed;
    L->k = 0;
    return 1;
}

/* Vertex trace L has ended: [start, clear_to) is clear, merged with the recorded stretch when they
 * touch, else the longer one is kept. */
static void trace_end(const trace_lane* L)
{
    scc_vertex_trace* r = L->r;
    const double start = L->start, clear_to = L->clear_to;
    if (!r || !(clear_to > start)) return;
    if (!(r->to > r->from) || start > r->to || clear_to < r->from) {
        if (!(r->to > r->from) || clear_to - start > r->to - r->from) { r->from = start; r->to = clear_to; }
    } else {
        r->from = scc_fmin(r->from, start);
        r->to = scc_fmax(r->to, clear_to);
    }
}

/* Conservative advancement of the three vertex paths (ours): with |grad phi| <= L and a vertex's
 * speed <= S, phi cannot reach the margin sooner than (phi - margin) / (L S), so stepping by that
 * never skips a crossing (steps are at least the time tolerance). A trace stops at its first
 * witness, at te (the earliest witness so far), or after `cap` samples. The three traces advance
 * together in time, in rounds: the trace furthest behind (the laggard) and any within its last
 * step of it take one sample each. So a trace does not run far past a contact another trace is
 * about to find (one after the other, the first trace ran to its own contact or to the end of the
 * interval), and the samples of one round, not depending on each other, overlap in the processor
 * (each trace alone is a chain: the next time needs phi at this one). With a shared record (a
 * mesh query's vertex, motion.h) the part of the path traced for an earlier triangle is not
 * traced again: its witness is reused, a clear stretch is skipped, and the new samples extend the
 * record. Every sample is counted and used. */
static void trace_vertices(scc_fw_state* s, int cap)
{
    trace_lane lanes[3];
    int live[3], n = 0;
    for (int i = 0; i < 3; ++i)
        if (trace_begin(s, i, &lanes[n])) live[n++] = i; /* live[j]: the vertex of lanes[j] */
    const int local_bound = s->sdf->lipschitz_in != NULL;
    const int64_t max_evals = s->p->max_evals;
    const double time_tol = s->p->time_tol;
    const double margin = s->margin;
    while (n > 0) {
        /* the traces that go on (te as it stands at the round's start); the others end */
        int m = 0;
        for (int j = 0; j < n; ++j) {
            if (lanes[j].k < cap && lanes[j].t < s->te && s->evals < max_evals) {
                if (m != j) { lanes[m] = lanes[j]; live[m] = live[j]; }
                ++m;
            } else {
                trace_end(&lanes[j]);
            }
        }
        n = m;
        if (n == 0) break;
        /* The traces within one step (the laggard's last) of the laggard's time go this round: a trace
         * far ahead waits, so that it does not sample past a contact the laggard is about to find. */
        double tmin = INFINITY, gate = INFINITY;
        for (int j = 0; j < n; ++j)
            if (lanes[j].t < tmin) { tmin = lanes[j].t; gate = lanes[j].t + (lanes[j].t - lanes[j].t_prev); }
        int sel[3], go = 0;
        for (int j = 0; j < n; ++j)
            if (lanes[j].t <= gate && s->evals + go < max_evals) sel[go++] = j;
        scc_vec3 x[3];
        double phi[3];
        for (int q = 0; q < go; ++q) x[q] = scc_fw_path_point_pure(s, &lanes[sel[q]].path, lanes[sel[q]].t);
        for (int q = 0; q < go; ++q) phi[q] = scc_fw_sdf(s, x[q], NULL);
        s->evals += go;
        for (int q = 0; q < go; ++q) {
            const int j = sel[q];
            trace_lane* L = &lanes[j];
            double t = L->t, f = phi[q];
            if (f <= margin) {
                const int first = L->k == 0;
                L->clear_to = L->t_prev;
                L->k = cap; /* ended: recorded at the next round */
                /* An entry after the earliest witness (found this round by a trace before this one)
                 * is not refined: it cannot move te. */
                if (!first && !(L->t_prev < s->te)) continue;
                const double b[3] = { live[j] == 0, live[j] == 1, live[j] == 2 };
                if (!first) refine_entry(s, &L->path, L->t_prev, L->f_prev, &t, &f);
                scc_fw_witness(s, t, b, f);
                if (L->r && t < L->r->hit_t) { L->r->hit_t = t; L->r->hit_phi = f; }
                continue;
            }
            L->k++;
            L->t_prev = t;
            L->f_prev = f - margin;
            const double step = (f - margin) / (local_bound ? step_lipschitz(s, x[q], f) * L->speed : L->ls);
            /* Near the surface the steps shrink geometrically; a step of the time tolerance can
             * then pass a crossing by at most that tolerance. */
            L->t = t + scc_fmax(step, time_tol);
            L->clear_to = L->t;
        }
    }
}

#define CLEAR_STACK 32
#define KINK_PROBE_STEPS 8 /* spatial steps of one probe of m(t) (refine_late) */
typedef struct clear_region { double u[3], v[3], t, rad; int depth; } clear_region;

/* Radius about its centroid of the sub-triangle with barycentric corners (u[i], v[i],
 * 1 - u[i] - v[i]) of the triangle x[0..2]. Pointer parameters, not arrays of 3: with arrays, GCC 12's
 * -Wstringop-overread misreads the size of s->r0 in a partly inlined caller (the TSan build). */
static double region_radius(const scc_vec3* x, const double* u, const double* v, scc_vec3 c)
{
    double rad = 0.0;
    for (int i = 0; i < 3; ++i) {
        scc_vec3 xi = scc_add(scc_add(scc_scale(x[0], u[i]), scc_scale(x[1], v[i])), scc_scale(x[2], 1.0 - u[i] - v[i]));
        double d = scc_dist(xi, c);
        if (d > rad) rad = d;
    }
    return rad * (1.0 + 1e-12);
}

/* A rigid motion keeps distances, so a region's radius is that of the offsets r0 (computed once
 * per region); otherwise it is recomputed at each time (rad < 0). */
static double region_radius_rigid(const scc_fw_state* s, const double u[3], const double v[3])
{
    if (!s->fast) return -1.0;
    double cu = (u[0] + u[1] + u[2]) / 3.0, cv = (v[0] + v[1] + v[2]) / 3.0;
    scc_vec3 c = scc_add(scc_add(scc_scale(s->r0[0], cu), scc_scale(s->r0[1], cv)), scc_scale(s->r0[2], 1.0 - cu - cv));
    return region_radius(s->r0, u, v, c);
}

/* A proof that no point of the triangle reaches the margin during [ta, tb] (ours; the padded
 * sphere tracing of the broad phase, bsh.h, continued below the leaf): a sub-triangle (three
 * barycentric corners) whose points lie within r of its centroid c(t) cannot touch before
 * t + ((phi(c) - margin) / L - r) / S, with L the field's Lipschitz bound and S the speed bound;
 * a sub-triangle that cannot advance by a useful step is split in four. Returns 1 when every
 * sub-triangle reached tb within `budget` evaluations (then there is provably no contact), 0
 * otherwise (nothing is concluded; a point found in contact is recorded as a witness). */
static int prove_clear(scc_fw_state* s, double ta, double tb, double speed, int budget)
{
    clear_region stack[CLEAR_STACK];
    int n = 0;
    /* a region's radius (rad) is NaN until its first sample needs it: a proof that stops (budget, a
     * witness) leaves regions on the stack whose radii were never used */
    stack[n++] = (clear_region){ { 1, 0, 0 }, { 0, 1, 0 }, ta, NAN, 0 };
    const double margin = s->margin;
    while (n > 0) {
        clear_region r = stack[--n];
        const double cu = (r.u[0] + r.u[1] + r.u[2]) / 3.0, cv = (r.v[0] + r.v[1] + r.v[2]) / 3.0;
        const double bc[3] = { cu, cv, 1.0 - cu - cv };
        for (;;) {
            if (r.t >= tb) break;
            if (budget-- <= 0 || s->evals >= s->p->max_evals) return 0;
            if (isnan(r.rad)) r.rad = region_radius_rigid(s, r.u, r.v);
            double rad = r.rad;
            scc_vec3 c;
            if (rad >= 0.0) {
                c = scc_fw_point(s, bc, r.t, NULL);
            } else {
                scc_tri_state st;
                scc_fw_tri_points(s, r.t, &st);
                c = scc_add(scc_add(scc_scale(st.x[0], bc[0]), scc_scale(st.x[1], bc[1])), scc_scale(st.x[2], bc[2]));
                rad = region_radius(st.x, r.u, r.v, c);
            }
            double phi = scc_fw_sdf(s, c, NULL);
            s->evals++;
            if (phi <= margin) {
                scc_fw_witness(s, r.t, bc, phi);
                return 0;
            }
            double R = phi - margin < phi ? phi - margin : phi; /* the bound is used inside the ball of radius phi */
            double clear = R / step_lipschitz(s, c, phi);
            if (clear > 2.0 * rad) {
                r.t += (clear - rad) / speed;
                continue;
            }
            if (n + 4 > CLEAR_STACK || r.depth >= 6) return 0;
            /* split at the edge midpoints; the children start at this time */
            double mu[3], mv[3];
            for (int i = 0; i < 3; ++i) {
                int j = (i + 1) % 3;
                mu[i] = 0.5 * (r.u[i] + r.u[j]);
                mv[i] = 0.5 * (r.v[i] + r.v[j]);
            }
            stack[n++] = (clear_region){ { r.u[0], mu[0], mu[2] }, { r.v[0], mv[0], mv[2] }, r.t, NAN, r.depth + 1 };
            stack[n++] = (clear_region){ { mu[0], r.u[1], mu[1] }, { mv[0], r.v[1], mv[1] }, r.t, NAN, r.depth + 1 };
            stack[n++] = (clear_region){ { mu[2], mu[1], r.u[2] }, { mv[2], mv[1], r.v[2] }, r.t, NAN, r.depth + 1 };
            stack[n++] = (clear_region){ { mu[0], mu[1], mu[2] }, { mv[0], mv[1], mv[2] }, r.t, NAN, r.depth + 1 };
            break;
        }
    }
    return 1;
}

/* Whether a witness earlier than `before` is recorded (hit_t is the interval's end while there is none). */
static int witnessed_before(const scc_fw_state* s, double before) { return s->hit && s->hit_t < before; }

/* Whether the triangle touches at time t (a witness there): spatial steps (at most `steps` per
 * start) from the weights b, then from each vertex; s->b is kept. */
static int contact_at_time(scc_fw_state* s, double t, const double b[3], int steps)
{
    const double keep[3] = { s->b[0], s->b[1], s->b[2] };
    const double before = s->hit ? s->hit_t : INFINITY;
    for (int k = 0; k < 4 && !witnessed_before(s, before); ++k) {
        for (int j = 0; j < 3; ++j) s->b[j] = k == 0 ? b[j] : (double)(j == k - 1);
        for (int i = 0; i < steps && s->evals < s->p->max_evals; ++i) {
            double gap;
            const double step = spatial_step(s, t, &gap);
            if (gap <= 0.0 || step <= s->dist_tol || witnessed_before(s, before)) break;
        }
    }
    for (int j = 0; j < 3; ++j) s->b[j] = keep[j];
    return witnessed_before(s, before);
}

/* Where the gradient jumps or bends sharply (ours, issue 20): the descents alternate a search in
 * time along one point's path and a search in space at one time. When the first contact slides
 * over the triangle as a sharp feature crosses it (a box's edge or corner under a face or an edge,
 * a knife edge, a spike tip), phi over (weights, time) has a valley oblique to both directions,
 * and the alternation creeps along it (steps of micrometres) and stops, often at the iteration
 * cap, at a later entry: 17 of 498 box cases of the per-kind data set were late, by up to 2 ms.
 * So the earliest witness t_w is checked as a root of m(t) = min over the triangle of phi(t):
 * is the triangle in contact at t_w - 1 us (the miss tolerance)? The spatial steps look from the
 * witness's weights and from each vertex. If it is, the probe moves back by factors of four until
 * the triangle is clear, and bisection closes [clear, contact] to the time tolerance. A witness
 * that passes the first probe costs one probe. */
static void refine_late(scc_fw_state* s)
{
    const scc_params* p = s->p;
    if (!s->hit || !(s->hit_t > s->ts)) return;
    double delta = 1e-6, lo = NAN, b[3];
    for (int k = 0; k < 12; ++k) {
        if (s->evals >= p->max_evals) return;
        const double t = scc_fmax(s->hit_t - delta, s->ts);
        for (int j = 0; j < 3; ++j) b[j] = s->hit_b[j];
        if (!contact_at_time(s, t, b, KINK_PROBE_STEPS)) {
            if (k == 0) return; /* the witness is within 1 us of m's root */
            lo = t;
            break;
        }
        if (t <= s->ts) return; /* in contact at the start */
        delta *= 4.0;
    }
    if (isnan(lo)) return;
    while (s->hit_t - lo > p->time_tol && s->evals < p->max_evals) {
        const double t = 0.5 * (lo + s->hit_t);
        for (int j = 0; j < 3; ++j) b[j] = s->hit_b[j];
        if (!contact_at_time(s, t, b, KINK_PROBE_STEPS)) lo = t;
    }
}

/* The check's fallback (ours; ccd.h): contact_at_time forward from t_lo by factors of four, then
 * refine_late back to where the triangle enters. */
void scc_fwgss_probe(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p, double t_lo, double t_hi,
                     const double b[3], double tol, int64_t max_evals, scc_tri_hit* out)
{
    scc_params q = *p;
    q.max_evals = max_evals;
    scc_fw_state s;
    scc_fw_begin(&s, sdf, m, &q, ta, tb);
    s.kinked = 1; /* golden-section spatial searches: the field's gradient may jump */
    const double speed = scc_tri_speed_bound(m);
    if (p->fwgss_speed_tol && speed > 0.0) s.dist_tol = speed * p->time_tol;
    /* nothing before t_lo is in contact (the certified search proved it); only a contact before t_hi is of use */
    s.ts = scc_fmax(t_lo, ta);
    s.te = scc_fmin(t_hi, tb);
    for (double d = 0.5 * tol; s.ts + d < s.te && s.evals < max_evals; d *= 4.0)
        if (contact_at_time(&s, s.ts + d, b, KINK_PROBE_STEPS)) {
            refine_late(&s);
            break;
        }
    scc_fw_finish(&s, 1, 0, out);
}

/* Whether phi bends sharply at the earliest witness: its gradient there and 1 mm away (along two
 * edges of the triangle and its normal) differ by more than 0.2 rad, a bend radius under 5 mm (a
 * box's edge or corner, a knife edge, a cone's tip; a grid of a smooth shape bends less). */
static int sharp_at_witness(scc_fw_state* s)
{
    scc_vec3 g0, g;
    const scc_vec3 x = scc_fw_point(s, s->hit_b, s->hit_t, NULL);
    scc_fw_sdf(s, x, &g0);
    s->evals++;
    scc_tri_state st;
    scc_fw_tri_points(s, s->hit_t, &st);
    const scc_vec3 e1 = scc_sub(st.x[1], st.x[0]), e2 = scc_sub(st.x[2], st.x[0]);
    const scc_vec3 dirs[3] = { e1, e2, scc_cross(e1, e2) };
    const double l0 = scc_len(g0);
    for (int i = 0; i < 3; ++i) {
        const double l = scc_len(dirs[i]);
        if (!(l > 0.0)) continue;
        scc_fw_sdf(s, scc_add(x, scc_scale(dirs[i], 1e-3 / l)), &g);
        s->evals++;
        const double lg = scc_len(g);
        if (!(l0 > 0.0 && lg > 0.0) || scc_dot(g0, g) < cos(0.2) * l0 * lg) return 1;
    }
    return 0;
}

/* Whether phi may have gradient jumps outside the surface: box edges and faces, CSG seams, cone
 * tips, grid cells, or unknown (transformed fields, user fields not declared smooth). The sphere,
 * torus, capsule, rounded box and half-space are smooth there (scc_sdf.smooth). */
static int field_has_kinks(const scc_sdf* sdf) { return !sdf->smooth; }

/* scc_tri_speed_bound(m), the same bits. For a rigid body the triangle's bound is |v| + |w| r (plus
 * the moving SDF's terms, also nondecreasing in r) at r the largest of the vertices' distances from
 * the centre, and rounding keeps a nondecreasing function so: it is the largest of the vertices'
 * bounds (scc_vertex_speed_bound), which a mesh query's vertex records hold for the vertex traces
 * (trace_begin), so they are computed once, not a second time for the triangle. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline)) /* kept out of scc_fwgss: inlined there, it moved the vertex traces' register allocation (more instructions per sample) */
#endif
static double tri_speed_bound(const scc_tri_motion* m)
{
    if (m->kind != SCC_TRI_RIGID || !m->trace[0] || !m->trace[1] || !m->trace[2]) return scc_tri_speed_bound(m);
    double speed = 0.0;
    for (int i = 0; i < 3; ++i) {
        scc_vertex_trace* r = m->trace[i];
        if (r->speed < 0.0) r->speed = scc_vertex_speed_bound(m, i);
        speed = scc_fmax(speed, r->speed);
    }
    return speed;
}

void scc_fwgss(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p, scc_tri_hit* out)
{
    scc_fw_state s;
    scc_fw_begin(&s, sdf, m, p, ta, tb);
    /* Analytic fields with kinks: the whole guard; grids: at level 2 likewise, at level 1 after a check. */
    const int grid_field = sdf->kind == SCC_SDF_GRID;
    s.kinked = p->fwgss_kink_guard > 0 && field_has_kinks(sdf) && (!grid_field || p->fwgss_kink_guard >= 2);
    /* On a convex field the certified check (scc_fwgss_verify) finds the earlier contacts the guard's
     * searches would: without them, box 615 instead of 787 evaluations per query, no miss either way.
     * Likewise on the spike grid, a union of convex pieces whose convexity per box the check uses
     * (scaling scene, report section 4, 1K / 10K / 100K: 20,502 / 15,077 / 18,708 -> 16,172 / 10,245 /
     * 11,688 evaluations; the TOI inside the certified bracket at 1K and 10K, was at 1K only). */
    if ((sdf->convex || sdf->kind == SCC_SDF_SPIKE_GRID) && scc_fwgss_verified(sdf, p)) s.kinked = 0;
    const int grid_check = p->fwgss_kink_guard == 1 && grid_field;
    double speed = tri_speed_bound(m);
    /* A spatial error of speed x time_tol moves the entry time by about time_tol. */
    if (p->fwgss_speed_tol && speed > 0.0) s.dist_tol = speed * p->time_tol;
    /* phi along a point's path changes at most L x speed per second: a temporal search whose
     * bracket is narrower than fwgss_gap_tol x (smallest gap) / (L x speed) cannot hide a contact
     * (scc_gss_minimize_gap), so far from the surface it stops there. */
    s.time_slope = p->fwgss_gap_tol > 0.0 ? scc_fmax(sdf->lipschitz, 1.0) * speed / p->fwgss_gap_tol : 0.0;
    /* The vertex paths first: in a mesh query their traces are shared with the neighbouring
     * triangles, and a contact found there rules the proof below out. */
    if (p->fwgss_vertex_trace > 0) trace_vertices(&s, p->fwgss_vertex_trace);
    /* Most triangles the broad phase hands over pass close to the field without touching it; a
     * short proof of that skips the descents. */
    if (!s.hit && p->fwgss_clear_budget > 0 && speed > 0.0 && prove_clear(&s, s.ts, s.te, speed, p->fwgss_clear_budget)) {
        scc_fw_finish(&s, 1, 0, out);
        return;
    }
    int order[3];
    scc_fw_start_order(&s, order);
    int converged = 1;
    int64_t it = 0;
    /* Section 4.4 picks the most promising vertex; the other vertices are tried next (ours),
     * sharing the shrinking interval, so a local minimum or a later entry of the first descent
     * is corrected and every later descent only searches before the earliest witness. A restart
     * begins at that witness's time (fwgss_restart_at_witness): a part of the triangle that
     * touched earlier is, for a body moving into the field, usually in contact there as well, so the
     * descent finds it by its spatial steps and searches back in time for its entry, without a
     * temporal search of the whole interval along the vertex's path first. */
    int starts = 1 + (p->fwgss_restarts < 2 ? p->fwgss_restarts : 2);
    for (int k = 0; k < starts; ++k) {
        s.b[0] = order[k] == 0; s.b[1] = order[k] == 1; s.b[2] = order[k] == 2;
        const double t_start = k > 0 && s.hit && p->fwgss_restart_at_witness ? s.te : s.ts;
        if (!descend(&s, t_start, &it)) converged = 0;
        if (s.hit && s.hit_t <= s.ts) break; /* in contact at the start: nothing is earlier */
    }
    /* Where the gradient jumps (ours, issue 20), a sharp feature (a knife edge, a spike tip, a grid
     * cell's kink) can touch an edge or the inside of the triangle while the gradient at every
     * vertex's descent leads elsewhere: the descents stop at a later local minimum (a cube minus a
     * ball: 11 of 64 cases late or missed with the three vertex starts and golden-section spatial
     * searches). Four more descents start from the edge midpoints and the centroid, at the earliest
     * witness like the restarts. A convex field (box, cylinder) has no such later minimum at a
     * given time: there only the spatial searches change. */
    /* A grid may sample a smooth shape, where this costs 3.4x for nothing (the triangle against the
     * 32^3 grid of the torus); at guard level 1 a grid query goes on only when phi bends sharply at
     * the earliest witness. */
    const int sharp = s.kinked || (grid_check && s.hit && !(s.hit_t <= s.ts) && sharp_at_witness(&s));
    if (sharp && !sdf->convex && p->fwgss_restarts > 0 && !(s.hit && s.hit_t <= s.ts)) {
        static const double extra[4][3] = { { 0.5, 0.5, 0.0 }, { 0.0, 0.5, 0.5 }, { 0.5, 0.0, 0.5 }, { 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0 } };
        for (int k = 0; k < 4; ++k) {
            for (int j = 0; j < 3; ++j) s.b[j] = extra[k][j];
            if (!descend(&s, s.hit && p->fwgss_restart_at_witness ? s.te : s.ts, &it)) converged = 0;
            if (s.hit && s.hit_t <= s.ts) break;
        }
    }
    if (sharp) refine_late(&s);
    scc_fw_finish(&s, converged, it, out);
}
