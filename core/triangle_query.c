/* SPDX-License-Identifier: MIT
 * sdfccd core: the per-triangle query. Splits the interval so no segment rotates more than
 * the limit (Section 4.6: the solvers assume less than half a turn), runs the chosen method
 * segment by segment until the first hit, then adds adaptive-subdivision contacts at the TOI
 * (Section 4.5). DCD tests the end pose only, as a discrete method does. */
#include "ccd.h"

static double gap_at_t0(const scc_sdf* sdf, const scc_tri_motion* m, const double b[3], int64_t* evals)
{
    ++*evals;
    return scc_sdf_eval(sdf, scc_tri_point_at(m, b, m->t0, NULL), NULL);
}

/* The answer h of the search over [.., tb] as contacts (the primary, then the subdivision points at
 * its TOI) and the summary. */
static void finish(const scc_sdf* sdf, const scc_tri_motion* m, const scc_params* p, uint32_t triangle_index, scc_tri_hit h,
                   int64_t evals, int64_t iterations, scc_contact* out, int capacity, scc_query_summary* sum);

int scc_query_triangle(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                       scc_workspace* ws, uint32_t triangle_index, scc_contact* out, int capacity,
                       scc_query_summary* sum)
{
    return scc_query_triangle_deferred(sdf, m, ta, tb, p, ws, triangle_index, out, capacity, sum, NULL, NULL);
}

int scc_query_triangle_deferred(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                                scc_workspace* ws, uint32_t triangle_index, scc_contact* out, int capacity,
                                scc_query_summary* sum, scc_tri_hit* raw, int* deferred)
{
    scc_tri_hit h;
    if (deferred) *deferred = 0;
    int64_t evals = 0, iterations = 0;
    int not_converged = 0;
    if (p->method == SCC_METHOD_DCD) {
        scc_tri_state st;
        scc_tri_state_at(m, tb, &st);
        scc_dcd_result d = scc_dcd_traced(sdf, st.x, m->trace, tb, p); /* vertex values shared in a mesh query */
        evals += d.evals;
        iterations += d.iterations;
        h.hit = d.phi <= p->margin;
        h.state = h.hit ? SCC_HIT : (d.converged ? SCC_NO_HIT : SCC_NOT_CONVERGED);
        h.toi = h.toi_lower = tb;
        for (int j = 0; j < 3; ++j) h.bary[j] = d.bary[j];
        h.point = d.point;
        h.normal = d.normal;
        h.distance = d.phi;
    } else {
        double angle = scc_tri_rotation_angle(m, ta, tb);
        int segments = 1;
        if (p->max_rotation > 0.0 && angle > p->max_rotation) {
            double n = ceil(angle / p->max_rotation);
            segments = n > 1e6 ? 1000000 : (int)n;
        }
        h.hit = 0;
        h.state = SCC_NO_HIT;
        double unresolved = tb; /* certified: the earliest time a stopped search left unproven */
        /* One evaluation budget for all segments: each solver gets what the earlier ones left. */
        scc_params sp = *p;
        for (int k = 0; k < segments; ++k) {
            double sa = ta + (tb - ta) * k / segments;
            if (evals >= p->max_evals) {
                not_converged = 1;
                unresolved = scc_fmin(unresolved, sa);
                break;
            }
            sp.max_evals = p->max_evals - evals;
            double sb = k + 1 == segments ? tb : ta + (tb - ta) * (k + 1) / segments;
            scc_tri_hit seg;
            if (p->method == SCC_METHOD_FWGSS) {
                scc_fwgss(sdf, m, sa, sb, &sp, &seg);
                if (raw && segments == 1 && scc_fwgss_verified(sdf, p)) { /* the check is the caller's (scc_triangle_finish_deferred) */
                    *raw = seg;
                    *deferred = 1;
                    sum->state = seg.state;
                    sum->hit = seg.hit;
                    sum->toi = seg.toi;
                    sum->toi_lower = seg.toi_lower;
                    sum->contacts_found = sum->contacts_written = 0;
                    sum->iterations = seg.iterations;
                    sum->evals = seg.evals;
                    sum->triangles_tested = 1;
                    return 1;
                }
                if (!scc_fwgss_verify(sdf, m, sa, sb, &sp, ws, &seg)) return 0;
            }
            else if (p->method == SCC_METHOD_FW) scc_fw(sdf, m, sa, sb, &sp, &seg);
            else if (!scc_certified(sdf, m, sa, sb, &sp, ws, &seg)) return 0;
            evals += seg.evals;
            iterations += seg.iterations;
            if (seg.hit) {
                h = seg;
                if (k > 0 && h.state == SCC_PENETRATING) h.state = SCC_HIT; /* touching at a segment start */
                if (not_converged && h.state == SCC_HIT) h.state = SCC_NOT_CONVERGED;
                break;
            }
            if (seg.state == SCC_NOT_CONVERGED) {
                not_converged = 1;
                unresolved = scc_fmin(unresolved, seg.toi_lower);
            }
            h = seg;
        }
        if (!h.hit) {
            h.state = not_converged ? SCC_NOT_CONVERGED : SCC_NO_HIT;
            h.toi = h.toi_lower = tb;
        }
        /* A certified search stopped by a cap proves nothing after its lower bound, nor does a
         * segment never searched: the bracket's lower end must not claim more. */
        if (p->method == SCC_METHOD_CERTIFIED) h.toi_lower = scc_fmin(h.toi_lower, unresolved);
    }
    finish(sdf, m, p, triangle_index, h, evals, iterations, out, capacity, sum);
    return 1;
}

int scc_triangle_finish_deferred(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                                 scc_workspace* ws, uint32_t triangle_index, scc_tri_hit raw, scc_contact* out,
                                 int capacity, scc_query_summary* sum)
{
    /* what scc_query_triangle does after its one segment's FWGSS: the check, then the answer */
    const int64_t fw_evals = raw.evals, fw_iterations = raw.iterations;
    int force = 0;
    if (raw.hit && raw.toi > tb) { /* a contact after tb: what is owed is a proof of none up to tb */
        raw.hit = 0;
        raw.state = SCC_NO_HIT;
        raw.toi = raw.toi_lower = tb;
        force = 1;
    }
    if (!scc_fwgss_check(sdf, m, ta, tb, p, ws, force, &raw)) return 0;
    scc_tri_hit h = raw;
    if (!h.hit) {
        h.state = raw.state == SCC_NOT_CONVERGED ? SCC_NOT_CONVERGED : SCC_NO_HIT;
        h.toi = h.toi_lower = tb;
    }
    finish(sdf, m, p, triangle_index, h, raw.evals, raw.iterations, out, capacity, sum);
    sum->evals -= fw_evals; /* the caller counted the search's evaluations already */
    sum->iterations -= fw_iterations;
    return 1;
}

static void finish(const scc_sdf* sdf, const scc_tri_motion* m, const scc_params* p, uint32_t triangle_index, scc_tri_hit h,
                   int64_t evals, int64_t iterations, scc_contact* out, int capacity, scc_query_summary* sum)
{
    int n = 0;
    if (h.hit) {
        scc_contact primary;
        primary.point = h.point;
        primary.normal = h.normal;
        primary.distance = h.distance;
        primary.toi = h.toi;
        for (int j = 0; j < 3; ++j) primary.bary[j] = h.bary[j];
        primary.triangle = triangle_index;
        primary.kind = SCC_CONTACT_PRIMARY;
        /* A contact at t0 (a discrete query at its pose) already has its gap there. */
        const int at_t0 = h.toi == m->t0;
        primary.gap_t0 = at_t0 ? h.distance : gap_at_t0(sdf, m, h.bary, &evals);
        if (n < capacity) out[n] = primary;
        ++n;
        if (p->subdivision) {
            scc_contact extra[SCC_MAX_SUBDIVISION_CONTACTS];
            scc_tri_state st;
            scc_tri_state_at(m, h.toi, &st);
            int k = scc_subdivide(sdf, st.x, h.bary, p, extra, SCC_MAX_SUBDIVISION_CONTACTS, &evals);
            for (int i = 0; i < k; ++i) {
                extra[i].toi = h.toi;
                extra[i].triangle = triangle_index;
                extra[i].gap_t0 = at_t0 ? extra[i].distance : gap_at_t0(sdf, m, extra[i].bary, &evals);
                if (n < capacity) out[n] = extra[i];
                ++n;
            }
        }
    }
    sum->state = h.state;
    sum->hit = h.hit;
    sum->toi = h.toi;
    sum->toi_lower = h.toi_lower;
    sum->contacts_found = n;
    sum->contacts_written = n < capacity ? n : (capacity > 0 ? capacity : 0);
    sum->iterations = iterations;
    sum->evals = evals;
    sum->triangles_tested = 1;
}
