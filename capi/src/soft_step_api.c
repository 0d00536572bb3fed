/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: a soft body's step against an SDF (soft.h): its contact planes, holding nodes on
 * them inside a position solve, and the guard after the solve. The paper's deformable case
 * (Section 4, each node moving linearly over the step; the cloth of Section 5 / Fig. 9), built on
 * the point paths and distance certificates of core/soft.c and the triangle query. */
#include "capi_internal.h"
#include "../../core/soft.h"
#include "sdfccd/soft.h"

#include <math.h>

/* Frame arithmetic, term for term as an engine bridge does it, so that its results do not depend on
 * which side computes them. */
static scc_vec3 to_local(const sdfccd_Frame* f, scc_vec3 p)
{
    const double(*r)[3] = f->rotation;
    const scc_vec3 d = scc_sub(p, sdfccd__v(f->origin));
    return scc_v3(r[0][0] * d.x + r[1][0] * d.y + r[2][0] * d.z, r[0][1] * d.x + r[1][1] * d.y + r[2][1] * d.z,
                  r[0][2] * d.x + r[1][2] * d.y + r[2][2] * d.z);
}
static scc_vec3 dir_to_world(const sdfccd_Frame* f, scc_vec3 v)
{
    const double(*r)[3] = f->rotation;
    return scc_v3(r[0][0] * v.x + r[0][1] * v.y + r[0][2] * v.z, r[1][0] * v.x + r[1][1] * v.y + r[1][2] * v.z,
                  r[2][0] * v.x + r[2][1] * v.y + r[2][2] * v.z);
}
static scc_vec3 to_world(const sdfccd_Frame* f, scc_vec3 p) { return scc_add(dir_to_world(f, p), sdfccd__v(f->origin)); }
static scc_vec3 dir_to_local(const sdfccd_Frame* f, scc_vec3 v) { return to_local(f, scc_add(v, sdfccd__v(f->origin))); }

static scc_vec3 unit_or_z(scc_vec3 v)
{
    const double l = scc_len(v);
    return l > 0 ? scc_scale(v, 1 / l) : scc_v3(0, 0, 1);
}

/* What the engine stores: float positions round each component. Through a volatile float: GCC 12's
 * SLP vectorizer at -O2 drops the double -> float -> double round trip of a vector's first two
 * components (measured). */
static double to_float(double x)
{
    volatile float f = (float)x;
    return f;
}
static scc_vec3 stored(scc_vec3 v, int32_t single) { return single ? scc_v3(to_float(v.x), to_float(v.y), to_float(v.z)) : v; }
/* x as the engine computes it: one double operation on floats, rounded once, is the float operation. */
static double eng(double x, int32_t single) { return single ? to_float(x) : x; }

/* The bridge's Lipschitz bound: the SDF's own, never below 1. */
static double lipschitz_of(sdfccd_SdfId sdf)
{
    sdfccd_SdfInfo info;
    if (sdfccd_sdf_get_info(sdf, &info) != SDFCCD_OK || !(info.lipschitz >= 1.0) || !isfinite(info.lipschitz)) return 1.0;
    return info.lipschitz;
}

static sdfccd_Status check_body(const sdfccd_SoftBody* b, const char* fn)
{
    if (!b) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: body is NULL", fn);
    if (b->node_count < 0 || b->face_count < 0 || b->link_count < 0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: a negative count (%d nodes, %d faces, %d links)", fn, (int)b->node_count,
                             (int)b->face_count, (int)b->link_count);
    if ((b->node_count > 0 && (!b->start || !b->end)) || (b->face_count > 0 && !b->faces) || (b->link_count > 0 && !b->links))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: a NULL array in body", fn);
    for (int64_t k = 0; k < 3 * (int64_t)b->face_count; ++k)
        if ((uint32_t)b->faces[k] >= (uint32_t)b->node_count)
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: face %d names node %d (of %d)", fn, (int)(k / 3), (int)b->faces[k], (int)b->node_count);
    for (int64_t k = 0; k < 2 * (int64_t)b->link_count; ++k)
        if ((uint32_t)b->links[k] >= (uint32_t)b->node_count)
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: link %d names node %d (of %d)", fn, (int)(k / 2), (int)b->links[k], (int)b->node_count);
    return SDFCCD_OK;
}

/* ---- contacts ---- */

/* Keeps, in slot 2 node + face, the plane the node's start position is closest to. */
static void offer(sdfccd_SoftPlane* slots, const sdfccd_Frame* f, scc_vec3 start, int32_t node, scc_vec3 nw, double offset, int32_t face)
{
    const double dist = scc_dot(nw, start) + offset;
    sdfccd_SoftPlane* pl = &slots[2 * (int64_t)node + face];
    if (!(dist < pl->start_distance)) return;
    pl->node = node;
    pl->face = face;
    pl->normal = sdfccd__pv(nw);
    pl->offset = offset;
    pl->local_normal = sdfccd__pv(dir_to_local(f, nw));
    pl->local_offset = offset + scc_dot(nw, sdfccd__v(f->origin));
    pl->start_distance = dist;
}

static sdfccd_Status soft_contacts_held(sdfccd_SdfId sdf, const sdfccd_Frame* F, const sdfccd_SoftBody* body,
                                        const sdfccd_SoftContactParams* prm, sdfccd_DistanceCert* node_certs, sdfccd_DistanceCert* face_certs,
                                        sdfccd_SoftPlane* out, int32_t capacity, int32_t* out_count, sdfccd_SoftStats* stats)
{
    static const char fn[] = "sdfccd_soft_contacts";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(F, "sdfccd_soft_contacts: frame")) || (st = sdfccd__check_ptr(prm, "sdfccd_soft_contacts: params")) ||
        (st = sdfccd__check_ptr(out_count, "sdfccd_soft_contacts: out_count")) ||
        (st = sdfccd__check_ptr(stats, "sdfccd_soft_contacts: io_stats")) || (st = check_body(body, fn)))
        return st;
    const int32_t nn = body->node_count;
    if (nn > 0 && (!node_certs || !out)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: node_certs or out_planes is NULL", fn);
    if (body->face_count > 0 && !face_certs) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: face_certs is NULL", fn);
    if ((int64_t)capacity < 2 * (int64_t)nn)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: capacity %d is below 2 x %d nodes", fn, (int)capacity, (int)nn);
    if (!(isfinite(prm->soft_margin) && prm->soft_margin >= 0) || !(isfinite(prm->contact_margin) && prm->contact_margin >= 0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: soft_margin %g or contact_margin %g is not finite and >= 0", fn,
                             prm->soft_margin, prm->contact_margin);
    sdfccd__sdf* h = sdfccd__sdf_acquire(sdf);
    if (!h) return SDFCCD_INVALID_HANDLE;
    const double L = lipschitz_of(sdf);
    const double soft_margin = prm->soft_margin, margin = soft_margin + prm->contact_margin;
    const int dcd = prm->query.method == SDFCCD_METHOD_DCD;
    int64_t evals = 0;
    for (int64_t k = 0; k < 2 * (int64_t)nn; ++k) out[k].start_distance = HUGE_VAL;

    /* Nodes: each one's path (DCD, the discrete baseline: its end alone). */
    for (int32_t i = 0; i < nn; ++i) {
        if (body->pinned && body->pinned[i]) continue;
        const scc_vec3 b = to_local(F, sdfccd__v(body->end[i])), a = dcd ? b : to_local(F, sdfccd__v(body->start[i]));
        scc_cert c = { { a, a, a }, node_certs[i].bound };
        for (int k = 0; k < 3; ++k) c.anchor[k] = sdfccd__v(node_certs[i].anchor[k]);
        if (scc_cert_bound(&c, &a, &b, 1, L) >= margin) continue;
        double f, phi, phi_a;
        scc_vec3 g;
        const int hit = scc_point_first_hit(h->sdf, a, b, margin, L, &f, &phi, &g, &phi_a, &evals);
        node_certs[i].bound = phi_a;
        node_certs[i].anchor[0] = sdfccd__pv(a);
        if (!hit) continue;
        const scc_vec3 p = scc_add(a, scc_scale(scc_sub(b, a), f)), nl = unit_or_z(g), nw = dir_to_world(F, nl);
        offer(out, F, sdfccd__v(body->start[i]), i, nw, -scc_dot(nw, to_world(F, scc_sub(p, scc_scale(nl, phi - soft_margin)))), 0);
    }

    /* Faces: a point comes 0.7 of the way into the soft margin (the nodes hold the rest; a face lying on
     * the surface at the margin then needs no query). Halfway, the planes of faces sagging over the
     * bunny's curved top came and went every few steps: the Fig. 9 cloth never rested (0.03-0.05 m/s
     * against 0.005-0.015 m/s at 0.2-0.4 of the margin). */
    const double dt = prm->duration, face_level = soft_margin > 0 ? 0.3 * soft_margin : margin;
    sdfccd_QueryParams qp = prm->query;
    qp.margin = face_level;
    sdfccd_Contact cs[8];
    for (int32_t fi = 0; fi < body->face_count; ++fi) {
        const int32_t* idx = body->faces + 3 * (int64_t)fi;
        scc_vec3 s[3], e[3];
        sdfccd_Vec3 ss[3], ee[3];
        for (int k = 0; k < 3; ++k) {
            s[k] = to_local(F, sdfccd__v(body->start[idx[k]]));
            e[k] = to_local(F, sdfccd__v(body->end[idx[k]]));
            ss[k] = sdfccd__pv(s[k]);
            ee[k] = sdfccd__pv(e[k]);
        }
        sdfccd_DistanceCert* fc = &face_certs[fi];
        scc_cert c;
        for (int k = 0; k < 3; ++k) c.anchor[k] = sdfccd__v(fc->anchor[k]);
        c.bound = fc->bound;
        const int clear = scc_face_clear(h->sdf, &c, s, e, face_level, L, &evals);
        for (int k = 0; k < 3; ++k) fc->anchor[k] = sdfccd__pv(c.anchor[k]);
        fc->bound = c.bound;
        if (clear) continue;
        sdfccd_QueryResult res;
        const sdfccd_Status qs = sdfccd_query_triangle_linear(sdf, NULL, ss, ee, 0.0, dt, &qp, cs, 8, &res);
        ++stats->face_queries;
        if (qs == SDFCCD_DEGENERATE) continue; /* a collapsed face: its nodes are checked on their own */
        if (qs != SDFCCD_OK) {
            ++stats->query_errors;
            continue;
        }
        evals += res.sdf_evaluations;
        if (!res.hit) continue;
        for (int j = 0; j < res.contact_count; ++j) {
            const sdfccd_Contact* ct = &cs[j];
            const double wmax = fmax(ct->barycentric[0], fmax(ct->barycentric[1], ct->barycentric[2]));
            if (wmax > 0.99) continue; /* at a node: that node's own path gives its contact */
            const double f = dt > 0 ? ct->toi / dt : 0;
            const scc_vec3 p = sdfccd__v(ct->point), nl = unit_or_z(sdfccd__v(ct->normal));
            /* Held at the level it was found at: a plane higher up would lift the face off that level,
             * the next step would find no contact, and the face would fall back (an oscillation). */
            const scc_vec3 surface = scc_sub(p, scc_scale(nl, ct->distance - face_level)), nw = dir_to_world(F, nl);
            for (int k = 0; k < 3; ++k) {
                if (ct->barycentric[k] < 0.01 || (body->pinned && body->pinned[idx[k]])) continue;
                const scc_vec3 xk = scc_add(s[k], scc_scale(scc_sub(e[k], s[k]), f));
                /* Shifted by the node's offset from the face point: while every node stays on its side,
                 * the face point stays on the surface's. */
                offer(out, F, sdfccd__v(body->start[idx[k]]), idx[k], nw,
                      -scc_dot(nw, to_world(F, scc_add(surface, scc_sub(xk, p)))), 1);
            }
        }
    }
    int32_t n = 0;
    for (int64_t k = 0; k < 2 * (int64_t)nn; ++k)
        if (out[k].start_distance < HUGE_VAL) out[n++] = out[k];
    *out_count = n;
    stats->sdf_evaluations += evals;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_soft_contacts(sdfccd_SdfId sdf, const sdfccd_Frame* frame, const sdfccd_SoftBody* body, const sdfccd_SoftContactParams* params,
                                   sdfccd_DistanceCert* node_certs, sdfccd_DistanceCert* face_certs, sdfccd_SoftPlane* out_planes,
                                   int32_t capacity, int32_t* out_count, sdfccd_SoftStats* io_stats)
{
    SDFCCD__HELD_CALL(soft_contacts_held(sdf, frame, body, params, node_certs, face_certs, out_planes, capacity, out_count, io_stats));
}

/* ---- holding nodes on their planes ---- */

sdfccd_Status sdfccd_soft_hold(const sdfccd_Frame* F0, const sdfccd_Frame* F, const sdfccd_Vec3* start, sdfccd_Vec3* positions,
                               sdfccd_Vec3* velocities, const double* inverse_masses, int32_t node_count, const sdfccd_SoftPlane* planes,
                               int32_t plane_count, double friction, double* pushes, double velocity_scale, int32_t last,
                               int32_t single_precision, int32_t* out_held)
{
    static const char fn[] = "sdfccd_soft_hold";
    if (!F0 || !F || (node_count > 0 && (!start || !positions || !velocities || !inverse_masses)) ||
        (plane_count > 0 && (!planes || !pushes)))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: a NULL pointer", fn);
    if (node_count < 0 || plane_count < 0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: node_count %d or plane_count %d < 0", fn, (int)node_count, (int)plane_count);
    for (int32_t k = 0; k < plane_count; ++k)
        if (planes[k].node < 0 || planes[k].node >= node_count)
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: plane %d names node %d (of %d)", fn, (int)k, (int)planes[k].node, (int)node_count);
    int32_t held = 0;
    for (int32_t k = 0; k < plane_count; ++k) {
        const int32_t i = planes[k].node;
        if (!(inverse_masses[i] > 0)) continue;
        const scc_vec3 n = sdfccd__v(planes[k].local_normal);
        scc_vec3 x = to_local(F, sdfccd__v(positions[i]));
        const double d = scc_dot(n, x) + planes[k].local_offset;
        if (d < 0) {
            x = scc_sub(x, scc_scale(n, d));
            pushes[k] -= d;
        }
        if (!(pushes[k] > 0)) continue;
        const scc_vec3 step = scc_sub(x, to_local(F0, sdfccd__v(start[i]))), side = scc_sub(step, scc_scale(n, scc_dot(step, n)));
        const double sl = scc_len(side), lim = friction * pushes[k];
        if (sl <= lim)
            x = scc_sub(x, side);
        else if (last)
            x = scc_sub(x, scc_scale(side, lim / sl));
        const scc_vec3 w = stored(to_world(F, x), single_precision);
        positions[i] = sdfccd__pv(w);
        if (!last) continue;
        const scc_vec3 nw = dir_to_world(F, n);
        scc_vec3 v = scc_scale(scc_sub(w, sdfccd__v(start[i])), velocity_scale);
        const double vn = scc_dot(sdfccd__v(velocities[i]), nw), out = scc_dot(v, nw) - (vn < 0.0 ? 0.0 : vn);
        if (out > 0) v = scc_sub(v, scc_scale(nw, out));
        velocities[i] = sdfccd__pv(stored(v, single_precision));
        ++held;
    }
    if (out_held) *out_held = held;
    return SDFCCD_OK;
}

/* ---- a node's contact with a rigid body ---- */

/* Bullet's soft-rigid contact terms (btSoftBody's collision handler), operation for operation in
 * its order (btVector3, btMatrix3x3: products summed left to right, the inverse by the cofactors of
 * the first row), each rounded as the engine rounds (R). */
#define R(x) eng((x), sp)
static double cofac(const double m[3][3], int r1, int c1, int r2, int c2, int32_t sp) { return R(R(m[r1][c1] * m[r2][c2]) - R(m[r1][c2] * m[r2][c1])); }
static void mat_mul(const double a[3][3], const double b[3][3], double out[3][3], int32_t sp)
{
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) out[i][j] = R(R(R(b[0][j] * a[i][0]) + R(b[1][j] * a[i][1])) + R(b[2][j] * a[i][2]));
}
static double dot_r(scc_vec3 a, scc_vec3 b, int32_t sp) { return R(R(R(a.x * b.x) + R(a.y * b.y)) + R(a.z * b.z)); }

sdfccd_Status sdfccd_soft_node_contact(sdfccd_Vec3 start, sdfccd_Vec3 end, double inverse_mass, const sdfccd_SoftRigid* body,
                                       sdfccd_Vec3 normal, double friction, double duration, int32_t sp, sdfccd_SoftNodeContact* out)
{
    static const char fn[] = "sdfccd_soft_node_contact";
    if (!body || !out) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: a NULL pointer", fn);
    if (!(duration > 0) || !isfinite(duration)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: duration %g not finite and > 0", fn, duration);
    const double ima = inverse_mass, imb = body->inverse_mass, dt = duration, fc = friction;
    if (!(R(ima + imb) > 0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: node and body both without inverse mass", fn);
    const scc_vec3 x = sdfccd__v(end), q = sdfccd__v(start), o = sdfccd__v(body->origin), w = sdfccd__v(body->angular_velocity);
    const scc_vec3 lv = sdfccd__v(body->linear_velocity), n = sdfccd__v(normal);
    const scc_vec3 r = scc_v3(R(x.x - o.x), R(x.y - o.y), R(x.z - o.z));
    /* The node's motion relative to the body's point under it; static friction when its sideways
     * part is below friction times its normal part. */
    const scc_vec3 wr = scc_v3(R(R(w.y * r.z) - R(w.z * r.y)), R(R(w.z * r.x) - R(w.x * r.z)), R(R(w.x * r.y) - R(w.y * r.x)));
    const scc_vec3 va = scc_v3(R(R(lv.x + wr.x) * dt), R(R(lv.y + wr.y) * dt), R(R(lv.z + wr.z) * dt));
    const scc_vec3 vr = scc_v3(R(R(x.x - q.x) - va.x), R(R(x.y - q.y) - va.y), R(R(x.z - q.z) - va.z));
    const double dn = dot_r(vr, n, sp);
    const scc_vec3 fv = scc_v3(R(vr.x - R(n.x * dn)), R(vr.y - R(n.y * dn)), R(vr.z - R(n.z * dn)));
    out->friction_keep = dot_r(fv, fv, sp) < R(R(R(dn * fc) * dn) * fc) ? 0.0 : R(1 - fc);
    /* The effective inverse mass at the node, ima I + imb I - [r]x Iw^-1 [r]x, inverted, per dt. */
    const double cr[3][3] = { { 0, -r.z, r.y }, { r.z, 0, -r.x }, { -r.y, r.x, 0 } };
    double t[3][3], k[3][3], m[3][3];
    mat_mul(cr, body->inverse_inertia, t, sp);
    mat_mul(t, cr, k, sp);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m[i][j] = R((i == j ? R(ima + imb) : 0.0) - k[i][j]);
    const double c0 = cofac(m, 1, 1, 2, 2, sp), c1 = cofac(m, 1, 2, 2, 0, sp), c2 = cofac(m, 1, 0, 2, 1, sp);
    const double s = R(1.0 / R(R(R(m[0][0] * c0) + R(m[0][1] * c1)) + R(m[0][2] * c2))), per_dt = R(1 / dt);
    const double inv[3][3] = { { c0, cofac(m, 0, 2, 2, 1, sp), cofac(m, 0, 1, 1, 2, sp) },
                               { c1, cofac(m, 0, 0, 2, 2, sp), cofac(m, 0, 2, 1, 0, sp) },
                               { c2, cofac(m, 0, 1, 2, 0, sp), cofac(m, 0, 0, 1, 1, sp) } };
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) out->impulse[i][j] = R(R(inv[i][j] * s) * per_dt);
    out->arm = sdfccd__pv(r);
    out->mass_dt = R(ima * dt);
    return SDFCCD_OK;
}
#undef R

/* ---- the guard ---- */

typedef struct guard_state {
    const sdfccd_SoftBody* body;
    const sdfccd_Frame* F;
    sdfccd_SoftGuardNode* out;
    scc_vec3* S;      /* start positions in the start frame */
    scc_vec3* E;      /* end positions (as the engine stores them) in the frame now */
    double* level;    /* per node: the level its paths are held to */
    char* touched;    /* moved in the last pass */
    char* touched_next;
} guard_state;


/* The node's executed motion becomes start -> `local` (SDF frame now); stop: then it loses its
 * velocity into the unit gradient direction of `grad`. */
static void set_end(guard_state* g, int32_t i, scc_vec3 local, int stop, scc_vec3 grad)
{
    sdfccd_SoftGuardNode* o = &g->out[i];
    o->position = sdfccd__pv(to_world(g->F, local));
    g->E[i] = to_local(g->F, stored(sdfccd__v(o->position), g->body->single_precision));
    o->moved = 1;
    o->stop = stop;
    o->normal = sdfccd__pv(stop ? dir_to_world(g->F, unit_or_z(grad)) : scc_v3(0, 0, 1));
    g->touched_next[i] = 1;
}

static int cert_clears(const sdfccd_DistanceCert* dc, const scc_vec3* s, const scc_vec3* e, int n, double L, double need)
{
    scc_cert c;
    for (int k = 0; k < 3; ++k) c.anchor[k] = sdfccd__v(dc->anchor[k]);
    c.bound = dc->bound;
    return scc_cert_bound(&c, s, e, n, L) >= need;
}

/* A moved node's velocity as the engine sets it: vscale * (position - start) stored, then (stop) less
 * its part into the stored normal, term for term in the engine's precision. */
static sdfccd_Vec3 moved_velocity(const sdfccd_SoftGuardNode* o, sdfccd_Vec3 start, double vscale, int32_t single)
{
    scc_vec3 v = stored(scc_scale(scc_sub(sdfccd__v(o->position), sdfccd__v(start)), vscale), single);
    const scc_vec3 n = stored(sdfccd__v(o->normal), single);
    const double vn = eng(eng(eng(v.x * n.x, single) + eng(v.y * n.y, single), single) + eng(v.z * n.z, single), single);
    if (o->stop && vn < 0)
        v = scc_v3(eng(v.x - eng(n.x * vn, single), single), eng(v.y - eng(n.y * vn, single), single), eng(v.z - eng(n.z * vn, single), single));
    return sdfccd__pv(v);
}

static sdfccd_Status soft_guard_held(sdfccd_SdfId sdf, const sdfccd_Frame* F0, const sdfccd_Frame* F, const sdfccd_SoftBody* body, double tol,
                                     double dt, double vscale, const sdfccd_QueryParams* query, sdfccd_DistanceCert* node_certs,
                                     sdfccd_DistanceCert* face_certs, sdfccd_SoftGuardNode* out, int32_t* out_moved, sdfccd_SoftStats* stats)
{
    static const char fn[] = "sdfccd_soft_guard";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(F0, "sdfccd_soft_guard: start_frame")) || (st = sdfccd__check_ptr(F, "sdfccd_soft_guard: frame")) ||
        (st = sdfccd__check_ptr(query, "sdfccd_soft_guard: query")) || (st = sdfccd__check_ptr(stats, "sdfccd_soft_guard: io_stats")) ||
        (st = check_body(body, fn)))
        return st;
    const int32_t nn = body->node_count, nf = body->face_count, nl = body->link_count;
    if (nn > 0 && (!node_certs || !out)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: node_certs or out_nodes is NULL", fn);
    if (nf + (int64_t)nl > 0 && !face_certs) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: face_certs is NULL", fn);
    if (!(isfinite(tol) && tol > 0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: tolerance = %g is not finite and > 0", fn, tol);
    if (!(isfinite(dt) && dt > 0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: duration = %g is not finite and > 0", fn, dt);
    if (!isfinite(vscale)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: velocity_scale = %g is not finite", fn, vscale);
    if (!sdfccd__sdf_acquire(sdf)) return SDFCCD_INVALID_HANDLE;
    const double L = lipschitz_of(sdf);
    const size_t bytes = (size_t)nn * (2 * sizeof(scc_vec3) + sizeof(double) + 2);
    void* mem = nn > 0 ? sdfccd__alloc(bytes) : NULL;
    if (nn > 0 && !mem) return sdfccd__oom(fn);
    guard_state g = { body, F, out, (scc_vec3*)mem, NULL, NULL, NULL, NULL };
    g.E = g.S + nn;
    g.level = (double*)(g.E + nn);
    g.touched = (char*)(g.level + nn);
    g.touched_next = g.touched + nn;
    int64_t evals = 0;
    for (int32_t i = 0; i < nn; ++i) {
        out[i].moved = out[i].stop = 0;
        out[i].position = body->end[i];
        out[i].normal = (sdfccd_Vec3){ 0, 0, 1 };
        out[i].velocity = (sdfccd_Vec3){ 0, 0, 0 };
        g.E[i] = to_local(F, sdfccd__v(body->end[i]));
        g.level[i] = -tol;
        g.touched[i] = g.touched_next[i] = 0;
    }
    /* Nodes: each one's level, and where it goes back to. */
    for (int32_t i = 0; i < nn; ++i) {
        const scc_vec3 s = g.S[i] = to_local(F0, sdfccd__v(body->start[i])), e = g.E[i];
        if (cert_clears(&node_certs[i], &s, &e, 1, L, -tol)) continue; /* what sdfccd_guard_point checks first */
        sdfccd_PointGuard pg;
        if (sdfccd_guard_point(sdf, &node_certs[i], sdfccd__pv(s), sdfccd__pv(e), tol, L, &pg, &evals) != SDFCCD_OK) continue;
        g.level[i] = pg.level;
        if (pg.hit) set_end(&g, i, scc_add(s, scc_scale(scc_sub(e, s), pg.fraction)), 1, sdfccd__v(pg.gradient));
    }
    /* Faces (links of a body without faces), repeated while a pass moves nodes (a moved node changes its
     * faces' motion). After `passes` passes a face still crossing goes back to its start, and so on for
     * the faces of the nodes that moves, until none crosses: every change puts nodes at their start. */
    const int passes = 4;
    for (int pass = 0; pass <= passes + nn; ++pass) {
        int changed = 0;
        /* Ropes: points along each link every h <= tol / 2, each path held to its level + L h / 2, so no
         * point between them goes below the level either. */
        for (int32_t li = 0; nf == 0 && li < nl; ++li) {
            const int32_t a = body->links[2 * (int64_t)li], b = body->links[2 * (int64_t)li + 1];
            if (pass > 0 && !g.touched[a] && !g.touched[b]) continue;
            const scc_vec3 s[3] = { g.S[a], g.S[b], g.S[b] }, e[3] = { g.E[a], g.E[b], g.E[b] };
            const double lev = fmin(g.level[a], g.level[b]);
            sdfccd_DistanceCert* fc = &face_certs[nf + li];
            if (cert_clears(fc, s, e, 3, L, lev)) continue;
            const sdfccd_Vec3 ss[3] = { sdfccd__pv(s[0]), sdfccd__pv(s[1]), sdfccd__pv(s[2]) },
                              ee[3] = { sdfccd__pv(e[0]), sdfccd__pv(e[1]), sdfccd__pv(e[2]) };
            int32_t clear = 0;
            if (sdfccd_triangle_clear(sdf, fc, ss, ee, lev, L, &clear, &evals) == SDFCCD_OK && clear) continue;
            sdfccd_PointHit hit;
            if (sdfccd_segment_first_hit(sdf, ss, ee, lev, 0.5 * tol, L, &hit, &evals) != SDFCCD_OK || !hit.hit) continue;
            const double f = pass >= passes ? 0.0 : hit.fraction;
            for (int k = 0; k < 2; ++k) set_end(&g, k ? b : a, scc_add(s[k], scc_scale(scc_sub(e[k], s[k]), f)), 1, sdfccd__v(hit.gradient));
            changed = 1;
        }
        for (int32_t fi = 0; fi < nf; ++fi) {
            const int32_t* idx = body->faces + 3 * (int64_t)fi;
            scc_vec3 s[3], e[3];
            double lev = 0;
            for (int k = 0; k < 3; ++k) {
                s[k] = g.S[idx[k]];
                e[k] = g.E[idx[k]];
                lev = fmin(lev, g.level[idx[k]]);
            }
            if (pass > 0 && !g.touched[idx[0]] && !g.touched[idx[1]] && !g.touched[idx[2]]) continue;
            if (cert_clears(&face_certs[fi], s, e, 3, L, lev)) continue; /* what sdfccd_guard_face checks first */
            const sdfccd_Vec3 ss[3] = { sdfccd__pv(s[0]), sdfccd__pv(s[1]), sdfccd__pv(s[2]) },
                              ee[3] = { sdfccd__pv(e[0]), sdfccd__pv(e[1]), sdfccd__pv(e[2]) };
            sdfccd_FaceGuard fg;
            const sdfccd_Status fs = sdfccd_guard_face(sdf, &face_certs[fi], ss, ee, lev, tol, L, query, dt, pass >= passes, &fg, &evals);
            if (fs != SDFCCD_OK) {
                if (fs != SDFCCD_DEGENERATE) ++stats->query_errors;
                continue;
            }
            stats->face_queries += fg.queries;
            if (!fg.hit) continue;
            for (int k = 0; k < 3; ++k) set_end(&g, idx[k], scc_add(s[k], scc_scale(scc_sub(e[k], s[k]), fg.fraction)), fg.stop, sdfccd__v(fg.normal));
            changed = 1;
        }
        if (!changed) break;
        char* t = g.touched; /* the next pass checks the faces of the nodes this one moved */
        g.touched = g.touched_next;
        g.touched_next = t;
        memset(g.touched_next, 0, (size_t)nn);
    }
    stats->sdf_evaluations += evals;
    int32_t moved = 0;
    for (int32_t i = 0; i < nn; ++i)
        if (out[i].moved) out[i].velocity = moved_velocity(&out[i], body->start[i], vscale, body->single_precision), ++moved;
    if (out_moved) *out_moved = moved;
    sdfccd__free(mem, bytes);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_soft_guard(sdfccd_SdfId sdf, const sdfccd_Frame* start_frame, const sdfccd_Frame* frame, const sdfccd_SoftBody* body,
                                double tolerance, double duration, double velocity_scale, const sdfccd_QueryParams* query, sdfccd_DistanceCert* node_certs,
                                sdfccd_DistanceCert* face_certs, sdfccd_SoftGuardNode* out_nodes, int32_t* out_moved, sdfccd_SoftStats* io_stats)
{
    SDFCCD__HELD_CALL(soft_guard_held(sdf, start_frame, frame, body, tolerance, duration, velocity_scale, query, node_certs, face_certs, out_nodes, out_moved,
                                      io_stats));
}
