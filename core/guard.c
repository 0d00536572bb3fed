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
#include "bsh.h"

#include <string.h>

enum { GUARD_ROUNDS = 3, GUARD_MAX_QUERIES = 8 };

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
    double speed = scc_mesh_speed_bound(mm);
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
    memcpy(out->bary, first->bary, sizeof out->bary);
    out->level = lv;
    out->state = SCC_GUARD_ROLLED_BACK;
    return 1;
}

/* A point of the mesh at or below `level` at time t by the discrete query (its first contact in *c). */
static int deep_at(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, double t, double level, scc_workspace* ws,
                   scc_contact* c, int* found, int64_t* evals)
{
    scc_mesh_motion m = *mm;
    m.tri_margin = NULL;
    m.t1 = t; /* the rigid pose at t */
    scc_params dp = *p;
    dp.method = SCC_METHOD_DCD;
    dp.margin = level;
    dp.contact_slop = 0.0;
    dp.subdivision = 0; /* a yes/no question: the deepest point per triangle is enough */
    scc_query_summary s;
    if (!scc_query_mesh_ws(sdf, &m, &dp, ws, c, 1, &s)) return 0;
    *evals += s.evals;
    *found = s.hit && s.contacts_written > 0;
    return 1;
}

int scc_guard_step(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, double tolerance, scc_workspace* ws,
                   scc_guard_out* out)
{
    scc_mesh_motion run = *mm;
    run.node_clear = NULL;
    memset(out, 0, sizeof *out);
    out->min_gap_start = INFINITY;
    out->toi = mm->t1;
    out->state = SCC_GUARD_CLEAR;
    out->uncertified = -1;
    const int sdf_still = !mm->sdf || (scc_len2(mm->sdf->v) == 0.0 && scc_len2(mm->sdf->w) == 0.0);
    if (!mm->body) return 0;
    if (sdf_still && scc_len2(mm->body->v) == 0.0 && scc_len2(mm->body->w) == 0.0) {
        out->certified = 1;
        return 1;
    }
    /* A static SDF: the body's motion is taken into its frame once, so that no evaluation pays for
     * the SDF's pose and frame change (FW's rigid fast path applies). Points and normals are in that
     * frame either way; times do not change. */
    scc_rigid local_body;
    if (mm->sdf && sdf_still) {
        const scc_quat ci = scc_quat_conj(mm->sdf->q0); /* (the pose of a still SDF is (q0, p0) at every time) */
        local_body = *mm->body;
        local_body.p0 = scc_quat_rotate(ci, scc_sub(mm->body->p0, mm->sdf->p0));
        local_body.q0 = scc_quat_mul(ci, mm->body->q0);
        local_body.v = scc_quat_rotate(ci, mm->body->v);
        local_body.w = scc_quat_rotate(ci, mm->body->w);
        run.body = &local_body;
        run.sdf = NULL;
    }
    const scc_bsh* bsh = mm->mesh->bsh;
    uint8_t* flags = NULL;
    if (bsh && p->broad_phase) {
        flags = scc_ws_get(ws, SCC_WS_CERTIFIED, bsh->node_count);
        if (!flags) return 0;
        int64_t evals = 0;
        out->uncertified = scc_bsh_certify(bsh, &run, sdf, -0.5 * tolerance, p, flags, ws, &evals);
        if (out->uncertified == 0) {
            out->evals = evals;
            out->certified = 1;
            return 1;
        }
        if (out->uncertified > 0) run.node_clear = flags;
        out->evals = evals;
    }
    const int64_t cert_evals = out->evals;
    const int64_t uncertified = out->uncertified;
    if (!scc_guard(sdf, &run, p, tolerance, ws, out)) return 0;
    out->evals += cert_evals;
    out->uncertified = uncertified;
    if (out->state == SCC_GUARD_INSIDE_AT_START) return 1; /* left to the contacts */
    double check_level = -tolerance;
    if (out->state == SCC_GUARD_ROLLED_BACK && out->toi > mm->t0) {
        scc_contact first;
        memset(&first, 0, sizeof first);
        first.triangle = out->triangle;
        memcpy(first.bary, out->bary, sizeof first.bary);
        first.toi = out->toi;
        const double speed = scc_mesh_speed_bound(&run);
        const double time_tol = speed > 0.0 ? fmin(p->time_tol, 0.1 * tolerance / speed) : p->time_tol;
        /* The first time a point was at -tolerance/2: the check at half the tolerance over [t0, toi]
         * (the CCD), else the first point's own time at that level. */
        scc_mesh_motion h = run;
        h.t1 = first.toi;
        scc_guard_out half;
        if (!scc_guard(sdf, &h, p, 0.5 * tolerance, ws, &half)) return 0;
        out->evals += half.evals;
        out->queries += half.queries;
        if (half.state == SCC_GUARD_ROLLED_BACK) {
            out->toi = half.toi;
            out->triangle = half.triangle;
            memcpy(out->bary, half.bary, sizeof out->bary);
        } else {
            out->toi = safe_time(sdf, &run, &first, out->level + 0.5 * tolerance, time_tol, &out->evals);
        }
        scc_tri_motion m;
        scc_mesh_triangle_motion(&run, out->triangle, &m);
        out->point = scc_tri_point_at(&m, out->bary, out->toi, NULL);
        out->evals += 1;
        scc_sdf_eval(sdf, out->point, &out->normal);
        check_level = -0.5 * tolerance;
    }
    scc_contact c;
    int found = 0;
    if (!deep_at(sdf, &run, p, out->toi, check_level, ws, &c, &found, &out->evals)) return 0;
    if (found) {
        const int ccd_rolled_back = out->state == SCC_GUARD_ROLLED_BACK;
        out->bisections = 1;
        out->state = SCC_GUARD_ROLLED_BACK;
        out->point = c.point;
        out->normal = c.normal;
        out->triangle = c.triangle;
        const double end_depth = c.distance;
        double lo = mm->t0, hi = out->toi, level = -0.5 * tolerance;
        /* Already deeper than half the tolerance at t0 (a body the contacts hold slightly deep): it
         * may keep any pose no deeper than its start's deepest point (left to the contacts, as a
         * triangle that starts inside is in the CCD); only sinking further is rolled back. */
        if (!deep_at(sdf, &run, p, mm->t0, level, ws, &c, &found, &out->evals)) return 0;
        if (found) {
            level = c.distance;
            if (end_depth >= level) { /* not sinking: the CCD's time of impact (if any) stands */
                out->bisections = 0;
                if (!ccd_rolled_back) {
                    out->state = SCC_GUARD_INSIDE_AT_START;
                    out->toi = mm->t1;
                }
                out->pinned = out->state == SCC_GUARD_ROLLED_BACK && !(out->toi > mm->t0);
                if (out->state == SCC_GUARD_ROLLED_BACK) out->normal = scc_normalize_or(out->normal, scc_v3(0, 1, 0));
                return 1;
            }
            out->point = c.point;
            out->normal = c.normal;
            out->triangle = c.triangle;
        }
        for (int it = 0; it < 12 && hi > lo; ++it) {
            const double mid = 0.5 * (lo + hi);
            if (!deep_at(sdf, &run, p, mid, level, ws, &c, &found, &out->evals)) return 0;
            if (found) {
                hi = mid;
                out->point = c.point;
                out->normal = c.normal;
                out->triangle = c.triangle;
            } else {
                lo = mid;
            }
        }
        out->toi = lo;
    }
    if (out->state == SCC_GUARD_ROLLED_BACK) out->normal = scc_normalize_or(out->normal, scc_v3(0, 1, 0));
    out->pinned = out->state == SCC_GUARD_ROLLED_BACK && !(out->toi > mm->t0);
    return 1;
}

static scc_vec3 mat_mul(const double m[9], scc_vec3 a)
{
    return scc_v3(m[0] * a.x + m[1] * a.y + m[2] * a.z, m[3] * a.x + m[4] * a.y + m[5] * a.z, m[6] * a.x + m[7] * a.y + m[8] * a.z);
}

/* Velocity of the body's material point at world x. */
static scc_vec3 point_velocity(const scc_body_state* b, scc_vec3 x)
{
    return scc_add(b->v, scc_cross(b->w, scc_sub(x, b->center)));
}

/* Impulse j (world) at world point x. */
static void apply_impulse(scc_body_state* b, scc_vec3 j, scc_vec3 x)
{
    b->v = scc_madd(b->v, j, b->inv_mass);
    b->w = scc_add(b->w, mat_mul(b->inv_inertia, scc_cross(scc_sub(x, b->center), j)));
}

/* The inverse effective mass of the body at x along unit direction d. */
static double inv_effective_mass(const scc_body_state* b, scc_vec3 x, scc_vec3 d)
{
    scc_vec3 r = scc_sub(x, b->center);
    return b->inv_mass + scc_dot(d, scc_cross(mat_mul(b->inv_inertia, scc_cross(r, d)), r));
}

void scc_guard_response(scc_vec3 point, scc_vec3 normal, int pinned, int repeated, const scc_body_state* sdf_body, double mu,
                        scc_body_state* body)
{
    if (pinned) {
        body->v = sdf_body ? point_velocity(sdf_body, body->center) : scc_v3(0, 0, 0);
        body->w = sdf_body ? sdf_body->w : scc_v3(0, 0, 0);
        return;
    }
    if (!repeated) return;
    const scc_vec3 n = normal;
    const scc_vec3 vs = sdf_body ? point_velocity(sdf_body, point) : scc_v3(0, 0, 0);
    const double vc = scc_dot(scc_sub(body->v, vs), n);
    if (vc < 0.0) body->v = scc_madd(body->v, n, -vc);
    const double vn = scc_dot(scc_sub(point_velocity(body, point), vs), n);
    const double k = inv_effective_mass(body, point, n);
    if (!(vn < 0.0) || !(k > 0.0)) return;
    const double j = -vn / k;
    apply_impulse(body, scc_scale(n, j), point);
    scc_vec3 u = scc_sub(point_velocity(body, point), vs);
    u = scc_madd(u, n, -scc_dot(u, n));
    const double ul = scc_len(u);
    if (!(ul > 1e-12) || !(mu > 0.0)) return;
    const scc_vec3 t = scc_scale(u, 1.0 / ul);
    const double kt = inv_effective_mass(body, point, t);
    if (kt > 0.0) apply_impulse(body, scc_scale(t, -fmin(mu * j, ul / kt)), point);
}

void scc_friction_hold(const scc_held_contact* c, size_t count, scc_vec3* held, scc_body_state* body)
{
    /* held[i] is the point's added impulse, tangential and normal; a point may approach the surface no
     * faster than it did after the solve (and not at all if it did not), so the added turn of the body
     * never sinks another point. */
    double floor_vn[SCC_HOLD_MAX];
    for (size_t i = 0; i < count; ++i) {
        held[i] = scc_v3(0, 0, 0);
        floor_vn[i] = fmin(0.0, scc_dot(scc_sub(point_velocity(body, c[i].point), c[i].surface_velocity), c[i].normal));
    }
    for (int pass = 0; pass < SCC_HOLD_PASSES; ++pass)
        for (size_t i = 0; i < count; ++i) {
            const scc_vec3 n = c[i].normal;
            scc_vec3 u = scc_sub(point_velocity(body, c[i].point), c[i].surface_velocity);
            const double kn = inv_effective_mass(body, c[i].point, n);
            double jn = scc_dot(held[i], n); /* the added normal impulse, >= 0 */
            const double push = kn > 0.0 ? fmax(-jn, (floor_vn[i] - scc_dot(u, n)) / kn) : 0.0;
            if (push != 0.0) {
                apply_impulse(body, scc_scale(n, push), c[i].point);
                held[i] = scc_madd(held[i], n, push);
                jn += push;
                u = scc_sub(point_velocity(body, c[i].point), c[i].surface_velocity);
            }
            u = scc_madd(u, n, -scc_dot(u, n));
            const double ul = scc_len(u);
            if (!(ul > 0.0)) continue;
            const scc_vec3 t = scc_scale(u, 1.0 / ul);
            const double kt = inv_effective_mass(body, c[i].point, t);
            if (!(kt > 0.0)) continue;
            /* The friction the point needs to stop sliding, the solver's included, cut to the cone. */
            const scc_vec3 applied = scc_madd(c[i].applied, n, -scc_dot(c[i].applied, n));
            const scc_vec3 old_t = scc_madd(held[i], n, -jn);
            scc_vec3 total = scc_madd(scc_add(applied, old_t), t, -ul / kt);
            const double tl = scc_len(total), cap = c[i].mu * (c[i].normal_impulse + jn);
            if (tl > cap) total = scc_scale(total, cap / tl);
            const scc_vec3 next = scc_sub(total, applied);
            apply_impulse(body, scc_sub(next, old_t), c[i].point);
            held[i] = scc_madd(next, n, jn);
        }
}

void scc_swept_aabb(const scc_aabb* a, const scc_aabb* b, scc_vec3 o0, scc_vec3 o1, double reach, double angle, scc_aabb* out)
{
    scc_aabb r = { scc_vmin(a->lo, b->lo), scc_vmax(a->hi, b->hi) };
    if (angle > 0.0) {
        const scc_vec3 g = scc_v3(1, 1, 1), e = scc_scale(g, reach), bow = scc_scale(g, reach * angle * angle / 8.0);
        r.lo = scc_vmax(scc_sub(r.lo, bow), scc_sub(scc_vmin(o0, o1), e)); /* the tighter of the two bounds */
        r.hi = scc_vmin(scc_add(r.hi, bow), scc_add(scc_vmax(o0, o1), e));
    }
    *out = r;
}
