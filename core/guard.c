/* SPDX-License-Identifier: MIT
 * sdfccd core: the no-tunnelling guarantee. The paper's rule (Section 4): the simulation never
 * advances past a time of impact. After an engine has integrated a step, the motion the body
 * executed is checked with the mesh CCD (mesh_query.c, Sections 4.3-4.6) against the contact level
 * phi = -tolerance; the earliest time a point reaches it is where the body must stop.
 *
 * A triangle that already starts deeper than the tolerance (a resting body slightly inside) would
 * make every check report a contact at t0 and freeze the body. Such a triangle is instead held to
 * its own level, its start depth (the deepest point DCD finds at t0, Section 3.2) minus the
 * tolerance: it may not sink further by more than the tolerance, and every other triangle keeps the
 * level -tolerance. The CCD is local, so a triangle can still report a contact at t0 at its lowered
 * level; it is lowered again to what the query saw, and after GUARD_ROUNDS such rounds left out. */
#include "guard.h"

#include <string.h>

enum { GUARD_ROUNDS = 3, GUARD_MAX_QUERIES = 8 };

/* A bound on the speed of any point of the mesh, in the SDF frame, over [t0, t1]. */
static double speed_bound(const scc_mesh_motion* mm)
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

/* phi at triangle t's material point b at time t, minus `level` (SDF frame point in *out_x). */
static double above_level(const scc_sdf* sdf, const scc_tri_motion* m, const double b[3], double t, double level, scc_vec3* out_x,
                          int64_t* evals)
{
    *out_x = scc_tri_point_at(m, b, t, NULL);
    ++*evals;
    return scc_sdf_eval(sdf, *out_x, NULL) - level;
}

/* The safe time of a hit at `toi` by contact c: the witnessed material point must be above its level
 * there. The CCD's TOI lies up to a time tolerance after the crossing, so one tolerance earlier is
 * tried first, then bisection on [t0, toi] keeps the last time found above. */
static double safe_time(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_contact* c, double level, double time_tol,
                        int64_t* evals)
{
    scc_tri_motion m;
    scc_mesh_triangle_motion(mm, c->triangle, &m);
    scc_vec3 x;
    double t = fmax(mm->t0, c->toi - time_tol);
    if (above_level(sdf, &m, c->bary, t, level, &x, evals) > 0.0) return t;
    double lo = mm->t0, hi = t;
    if (!(above_level(sdf, &m, c->bary, lo, level, &x, evals) > 0.0)) return lo;
    for (int k = 0; k < 64 && hi - lo > 1e-3 * time_tol; ++k) {
        double mid = 0.5 * (lo + hi);
        if (above_level(sdf, &m, c->bary, mid, level, &x, evals) > 0.0) lo = mid;
        else hi = mid;
    }
    return lo;
}

int scc_guard(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, double tolerance, scc_workspace* ws,
              scc_guard_out* out)
{
    const double level = -tolerance;
    scc_params qp = *p;
    qp.margin = level;
    qp.subdivision = 0; /* the first point is enough */
    /* The TOI may lie a time tolerance late: at most a tenth of the tolerance in depth. */
    double speed = speed_bound(mm);
    if (speed > 0.0) qp.time_tol = fmin(qp.time_tol, 0.1 * tolerance / speed);

    memset(out, 0, sizeof *out);
    out->min_gap_start = INFINITY;
    scc_mesh_motion run = *mm;
    run.tri_margin = NULL;
    double* margins = NULL;
    scc_query_summary s;
    const uint32_t nt = mm->mesh->triangle_count;
    for (int round = 0;; ++round) {
        if (!scc_query_mesh_ws(sdf, &run, &qp, ws, NULL, 0, &s)) return 0;
        out->evals += s.evals;
        out->queries += 1;
        const scc_contact* c = ws->slot[SCC_WS_CONTACTS].p;
        for (int i = 0; i < s.contacts_found; ++i) out->min_gap_start = fmin(out->min_gap_start, c[i].gap_t0);
        if (!(s.hit && s.toi <= mm->t0) || round + 1 >= GUARD_MAX_QUERIES) break;
        /* Some triangles are at their level at t0: hold each to its start depth minus the tolerance. */
        if (!margins) {
            if (!(margins = scc_ws_get(ws, SCC_WS_GUARD, (size_t)nt * sizeof *margins))) return 0;
            for (uint32_t t = 0; t < nt; ++t) margins[t] = level;
            run.tri_margin = margins;
        }
        for (int i = 0; i < s.contacts_found; ++i) {
            if (c[i].toi > mm->t0) continue;
            uint32_t t = c[i].triangle;
            double depth = fmin(c[i].distance, c[i].gap_t0);
            if (margins[t] == level) {
                scc_tri_motion m;
                scc_tri_state st;
                scc_mesh_triangle_motion(&run, t, &m);
                scc_tri_state_at(&m, mm->t0, &st);
                scc_dcd_result d = scc_dcd(sdf, st.x, &qp);
                out->evals += d.evals;
                depth = fmin(depth, d.phi);
                out->deep_triangles += 1;
            }
            out->min_gap_start = fmin(out->min_gap_start, depth);
            margins[t] = round < GUARD_ROUNDS ? fmin(margins[t], depth - tolerance) : -INFINITY;
        }
    }
    out->query_state = s.state;
    out->toi = mm->t1;
    out->state = out->deep_triangles ? SCC_GUARD_INSIDE_AT_START : SCC_GUARD_CLEAR;
    if (!s.hit || (s.toi <= mm->t0 && out->deep_triangles)) return 1; /* the query cap: left to the contacts */
    /* The earliest contact (the buffer is sorted by time) sets the safe time. */
    const scc_contact* first = ws->slot[SCC_WS_CONTACTS].p;
    double lv = margins ? margins[first->triangle] : level;
    out->toi = safe_time(sdf, &run, first, lv, qp.time_tol, &out->evals);
    scc_tri_motion m;
    scc_mesh_triangle_motion(&run, first->triangle, &m);
    out->point = scc_tri_point_at(&m, first->bary, out->toi, NULL);
    out->evals += 1;
    scc_sdf_eval(sdf, out->point, &out->normal);
    out->normal = scc_normalize_or(out->normal, first->normal);
    out->triangle = first->triangle;
    out->state = SCC_GUARD_ROLLED_BACK;
    return 1;
}
