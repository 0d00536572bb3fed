/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: the guarantee over all the checks of one body (contact.h, sdfccd_guard_body): each
 * pair through sdfccd_guard_step_rigid, the earliest rollback by scc_guard_earlier (core/guard.h);
 * its broad phase, the box a body can occupy over the step (sdfccd_swept_aabb, scc_swept_aabb); and
 * the guarantee for a world (sdfccd_guard_world): the bodies, their parts and the SDFs in plain arrays. */
#include "capi_internal.h"
#include "../../core/guard.h"

#include <stdio.h>
#include <string.h>

/* The answer of a check that found nothing before t1 (the safe pose is the end pose when given). */
static sdfccd_GuardResult clear_result(double t1, const sdfccd_Pose* end)
{
    sdfccd_GuardResult g;
    memset(&g, 0, sizeof g);
    g.state = SDFCCD_GUARD_CLEAR;
    g.toi = t1;
    g.fraction = 1.0;
    g.min_gap_start = INFINITY;
    if (end) g.safe_pose = *end;
    return g;
}

sdfccd_Status sdfccd_guard_body(sdfccd_Workspace* ws, const sdfccd_GuardPair* pairs, int32_t count, double t0, double t1,
                                const sdfccd_GuardParams* params, sdfccd_GuardBodyResult* out)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out, "sdfccd_guard_body: out")) || (st = sdfccd__check_ptr(params, "sdfccd_guard_body: params"))) return st;
    if (count < 0 || (count > 0 && !pairs))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_guard_body: count must be >= 0 with pairs not NULL (got %d, %p)", (int)count,
                             (const void*)pairs);
    sdfccd_GuardBodyResult r;
    memset(&r, 0, sizeof r);
    r.index = -1;
    r.first = clear_result(t1, NULL);
    for (int32_t i = 0; i < count; ++i) {
        const sdfccd_GuardPair* p = &pairs[i];
        sdfccd_GuardResult g;
        const sdfccd_Status s = sdfccd_guard_step_rigid(ws, p->sdf, p->sdf_motion, p->mesh, &p->executed, t0, t1, params, &g);
        if (s != SDFCCD_OK) {
            if (!r.failed++) r.error = s;
            continue;
        }
        r.sdf_evaluations += g.sdf_evaluations;
        r.certified += g.certified != 0;
        if (scc_guard_earlier(g.state == SDFCCD_GUARD_ROLLED_BACK, g.toi, r.first.toi)) {
            r.first = g;
            r.index = i;
        }
    }
    *out = r;
    return SDFCCD_OK;
}

static int finite_pose(const sdfccd_Pose* p)
{
    const double v[7] = { p->position.x, p->position.y, p->position.z, p->orientation.w, p->orientation.x, p->orientation.y, p->orientation.z };
    for (int i = 0; i < 7; ++i)
        if (!isfinite(v[i])) return 0;
    return v[3] != 0.0 || v[4] != 0.0 || v[5] != 0.0 || v[6] != 0.0;
}

sdfccd_Status sdfccd_swept_aabb(const sdfccd_Aabb* start_box, const sdfccd_Aabb* end_box, const sdfccd_Pose* start, const sdfccd_Pose* end,
                                double reach, sdfccd_Aabb* out_box)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(start_box, "sdfccd_swept_aabb: start_box")) || (st = sdfccd__check_ptr(end_box, "sdfccd_swept_aabb: end_box")) ||
        (st = sdfccd__check_ptr(start, "sdfccd_swept_aabb: start")) || (st = sdfccd__check_ptr(end, "sdfccd_swept_aabb: end")) ||
        (st = sdfccd__check_ptr(out_box, "sdfccd_swept_aabb: out_box")))
        return st;
    const sdfccd_Vec3 c[4] = { start_box->lo, start_box->hi, end_box->lo, end_box->hi };
    for (int i = 0; i < 4; ++i)
        if (isnan(c[i].x) || isnan(c[i].y) || isnan(c[i].z))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_swept_aabb: a box coordinate is NaN");
    if (!finite_pose(start) || !finite_pose(end))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_swept_aabb: a pose is not finite or has a zero orientation");
    const scc_quat q0 = { start->orientation.w, start->orientation.x, start->orientation.y, start->orientation.z };
    const scc_quat q1 = { end->orientation.w, end->orientation.x, end->orientation.y, end->orientation.z };
    double angle = 0.0; /* of the shortest arc from q0 to q1 (the same orientation: none) */
    if (memcmp(&q0, &q1, sizeof q0) != 0) {
        const scc_quat d = scc_quat_mul(q1, scc_quat_conj(q0));
        angle = 2.0 * atan2(sqrt(d.x * d.x + d.y * d.y + d.z * d.z), fabs(d.w));
    }
    if (angle > 0.0 && !(reach >= 0.0 && isfinite(reach)))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_swept_aabb: reach = %g (must be finite and >= 0)", reach);
    const scc_aabb a = { sdfccd__v(start_box->lo), sdfccd__v(start_box->hi) }, b = { sdfccd__v(end_box->lo), sdfccd__v(end_box->hi) };
    scc_aabb r;
    scc_swept_aabb(&a, &b, sdfccd__v(start->position), sdfccd__v(end->position), reach, angle, &r);
    out_box->lo.x = r.lo.x; out_box->lo.y = r.lo.y; out_box->lo.z = r.lo.z;
    out_box->hi.x = r.hi.x; out_box->hi.y = r.hi.y; out_box->hi.z = r.hi.z;
    return SDFCCD_OK;
}

/* ---- the guarantee for a world (sdfccd_guard_world) ----
 * The paper's rule (Section 4): the simulation never advances past a time of impact. After an
 * engine's step every dynamic body's executed motion is checked against the SDFs it can reach, part
 * by part, and a body that reached one goes back to its earliest time of impact. */

static int same_pose(const sdfccd_Pose* a, const sdfccd_Pose* b)
{
    return a->position.x == b->position.x && a->position.y == b->position.y && a->position.z == b->position.z &&
           a->orientation.w == b->orientation.w && a->orientation.x == b->orientation.x && a->orientation.y == b->orientation.y &&
           a->orientation.z == b->orientation.z;
}

static int is_identity(const sdfccd_Pose* p)
{
    return p->position.x == 0.0 && p->position.y == 0.0 && p->position.z == 0.0 && p->orientation.w == 1.0 && p->orientation.x == 0.0 &&
           p->orientation.y == 0.0 && p->orientation.z == 0.0;
}

static scc_xform to_xform(const sdfccd_Pose* p)
{
    const scc_quat q = { p->orientation.w, p->orientation.x, p->orientation.y, p->orientation.z };
    scc_xform r = { scc_quat_normalize(q), sdfccd__v(p->position) };
    return r;
}

static sdfccd_Pose from_xform(scc_xform t)
{
    sdfccd_Pose r;
    r.position = sdfccd__pv(t.p);
    r.orientation = (sdfccd_Quat){ t.q.w, t.q.x, t.q.y, t.q.z };
    return r;
}

static scc_xform compose(scc_xform a, scc_xform b)
{
    scc_xform r = { scc_quat_mul(a.q, b.q), scc_xform_apply(a, b.p) };
    return r;
}

static scc_xform inverse(scc_xform a)
{
    const scc_quat c = scc_quat_conj(a.q);
    scc_xform r = { c, scc_scale(scc_quat_rotate(c, a.p), -1.0) };
    return r;
}

/* The pose of body pose `body` followed by `offset` (a part's pose); the same pose, untouched, for
 * an identity offset. */
static sdfccd_Pose times_offset(const sdfccd_Pose* body, const sdfccd_Pose* offset)
{
    return is_identity(offset) ? *body : from_xform(compose(to_xform(body), to_xform(offset)));
}

/* The box a body or SDF can occupy over the step (validated inputs: cannot fail). */
static scc_aabb swept_box(const sdfccd_Aabb* b0, const sdfccd_Aabb* b1, const sdfccd_Pose* p0, const sdfccd_Pose* p1, double reach)
{
    sdfccd_Aabb out;
    sdfccd_swept_aabb(b0, b1, p0, p1, reach, &out);
    return sdfccd__box(out);
}

static int boxes_overlap(const scc_aabb* a, const scc_aabb* b)
{
    return !(a->lo.x > b->hi.x || a->hi.x < b->lo.x) && !(a->lo.y > b->hi.y || a->hi.y < b->lo.y) && !(a->lo.z > b->hi.z || a->hi.z < b->lo.z);
}

static int bad_box(const sdfccd_Aabb* b)
{
    return isnan(b->lo.x) || isnan(b->lo.y) || isnan(b->lo.z) || isnan(b->hi.x) || isnan(b->hi.y) || isnan(b->hi.z);
}

/* A pose checked as sdfccd_rigid_motion_from_poses does; the message (formatted only on failure)
 * names it "sdfccd_guard_world: what[i].field". */
static sdfccd_Status check_pose(const sdfccd_Pose* p, const char* what, int32_t i, const char* field)
{
    scc_xform x;
    if (sdfccd__unit_pose(p, "sdfccd_guard_world", &x) == SDFCCD_OK) return SDFCCD_OK;
    char w[96];
    snprintf(w, sizeof w, "sdfccd_guard_world: %s[%d].%s", what, (int)i, field);
    return sdfccd__unit_pose(p, w, &x);
}

/* The checks an SDF or body shares: poses, boxes, reach, friction, state. */
static sdfccd_Status check_moving(const char* what, int32_t i, const sdfccd_Pose* start, const sdfccd_Pose* end, const sdfccd_Aabb* b0,
                                  const sdfccd_Aabb* b1, double reach, double friction, const sdfccd_BodyState* state)
{
    static const char fn[] = "sdfccd_guard_world";
    scc_body_state s;
    sdfccd_Status st;
    if ((st = check_pose(start, what, i, "start")) || (st = check_pose(end, what, i, "end"))) return st;
    if (bad_box(b0) || bad_box(b1)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: %s[%d] has a NaN box coordinate", fn, what, (int)i);
    if (!(isfinite(reach) && reach >= 0.0) || !(isfinite(friction) && friction >= 0.0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: %s[%d]: reach (%g) and friction (%g) must be finite and >= 0", fn, what, (int)i,
                             reach, friction);
    if (!state || sdfccd__body_state(state, fn, "state", &s) == SDFCCD_OK) return SDFCCD_OK;
    char w[32];
    snprintf(w, sizeof w, "%s[%d].state", what, (int)i);
    return sdfccd__body_state(state, fn, w, &s);
}

/* The SDF's motion over the step, from its two poses (about its origin). */
static sdfccd_Status sdf_motion(const sdfccd_GuardSdf* s, int32_t i, double t0, double t1, sdfccd_RigidMotion* out)
{
    const sdfccd_Vec3 origin = { 0, 0, 0 };
    if (sdfccd_rigid_motion_from_poses(&s->start, &s->end, origin, t0, t1, out) == SDFCCD_OK) return SDFCCD_OK;
    return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_guard_world: sdfs[%d]: its two poses give no motion over [%g, %g]", (int)i, t0, t1);
}

/* Whether a handle is live, without keeping the reference: a world has more handles than the
 * per-thread list of references a call may hold, and each check takes its own. */
static int live_sdf(sdfccd_SdfId id)
{
    const int mark = sdfccd__hold_mark();
    const int ok = sdfccd__sdf_acquire(id) != NULL;
    sdfccd__hold_release_to(mark);
    return ok;
}

static int live_mesh(sdfccd_MeshId id)
{
    const int mark = sdfccd__hold_mark();
    const int ok = sdfccd__mesh_acquire(id) != NULL;
    sdfccd__hold_release_to(mark);
    return ok;
}

static sdfccd_Status check_world(sdfccd_Workspace* ws, const sdfccd_GuardSdf* sdfs, int32_t sdf_count, const sdfccd_GuardRigidBody* bodies,
                                 int32_t body_count, double t0, double t1, const sdfccd_GuardParams* params, sdfccd_GuardWorldResult* results)
{
    static const char fn[] = "sdfccd_guard_world";
    sdfccd_Status st;
    scc_params p;
    double tol;
    if ((st = sdfccd__check_ptr(ws, "sdfccd_guard_world: ws")) || (st = sdfccd__convert_guard_params(params, fn, &p, &tol)) ||
        (st = sdfccd__check_interval(t0, t1, fn)))
        return st;
    if (!(t1 > t0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: t1 (%g) must be > t0 (%g)", fn, t1, t0);
    if (sdf_count < 0 || body_count < 0 || (sdf_count > 0 && !sdfs) || (body_count > 0 && (!bodies || !results)))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: counts (%d, %d) must be >= 0, with sdfs, bodies and results not NULL when > 0", fn,
                             (int)sdf_count, (int)body_count);
    for (int32_t i = 0; i < sdf_count; ++i) {
        const sdfccd_GuardSdf* s = &sdfs[i];
        sdfccd_RigidMotion m;
        if ((st = check_moving("sdfs", i, &s->start, &s->end, &s->start_box, &s->end_box, s->reach, s->friction, s->has_state ? &s->state : NULL)) ||
            (st = sdf_motion(s, i, t0, t1, &m)))
            return st;
        if (s->body < -1 || s->body >= body_count)
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: sdfs[%d].body = %d (must be -1 or a body index < %d)", fn, (int)i, (int)s->body,
                                 (int)body_count);
        if (!live_sdf(s->sdf)) return SDFCCD_INVALID_HANDLE;
    }
    for (int32_t i = 0; i < body_count; ++i) {
        const sdfccd_GuardRigidBody* b = &bodies[i];
        if ((st = check_moving("bodies", i, &b->start, &b->end, &b->start_box, &b->end_box, b->reach, b->friction, &b->state))) return st;
        if (b->part_count < 0 || (b->part_count > 0 && !b->parts))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: bodies[%d].part_count = %d (must be >= 0, with parts not NULL when > 0)", fn, (int)i,
                                 (int)b->part_count);
        for (int32_t k = 0; k < b->part_count; ++k) {
            scc_xform x;
            if (sdfccd__unit_pose(&b->parts[k].offset, fn, &x)) {
                char w[48];
                snprintf(w, sizeof w, "bodies[%d].parts", (int)i);
                return check_pose(&b->parts[k].offset, w, k, "offset");
            }
            if (!live_mesh(b->parts[k].mesh)) return SDFCCD_INVALID_HANDLE;
        }
    }
    return SDFCCD_OK;
}

/* Where a body rolled back by part `part_offset`'s safe pose goes: that pose times the inverse
 * offset, carried with a moving SDF from the time of impact to its end pose. */
static sdfccd_Pose rolled_back_pose(const sdfccd_GuardResult* g, const sdfccd_Pose* part_offset, const sdfccd_GuardSdf* s,
                                    const sdfccd_RigidMotion* sm, double t0)
{
    sdfccd_Pose pose = is_identity(part_offset) ? g->safe_pose : from_xform(compose(to_xform(&g->safe_pose), inverse(to_xform(part_offset))));
    if (same_pose(&s->start, &s->end)) return pose;
    const double tau = g->toi - t0;
    const scc_xform s0 = to_xform(&s->start);
    const scc_xform at_toi = { scc_quat_mul(scc_quat_from_rotvec(scc_scale(sdfccd__v(sm->angular_velocity), tau)), s0.q),
                               scc_madd(s0.p, sdfccd__v(sm->linear_velocity), tau) };
    return from_xform(compose(compose(to_xform(&s->end), inverse(at_toi)), to_xform(&pose)));
}

/* The body's state at pose `to` (it was `state` at `from`): centre carried, world inverse inertia turned. */
static sdfccd_BodyState state_at(const sdfccd_BodyState* state, const sdfccd_Pose* from, const sdfccd_Pose* to)
{
    const scc_xform a = to_xform(from), b = to_xform(to);
    sdfccd_BodyState r = *state;
    r.center = sdfccd__pv(scc_xform_apply(b, scc_xform_apply_inv(a, sdfccd__v(state->center))));
    const scc_mat3 d = scc_mat3_from_quat(scc_quat_mul(b.q, scc_quat_conj(a.q)));
    scc_mat3 in, dt;
    for (int k = 0; k < 9; ++k) {
        in.m[k / 3][k % 3] = state->inverse_inertia[k];
        dt.m[k % 3][k / 3] = d.m[k / 3][k % 3];
    }
    const scc_mat3 di = scc_mat3_mul(&d, &in), out = scc_mat3_mul(&di, &dt);
    for (int k = 0; k < 9; ++k) r.inverse_inertia[k] = out.m[k / 3][k % 3];
    return r;
}

static sdfccd_Status guard_world(sdfccd_Workspace* ws, const sdfccd_GuardSdf* sdfs, int32_t sdf_count, const sdfccd_GuardRigidBody* bodies,
                                 int32_t body_count, double t0, double t1, const sdfccd_GuardParams* params, sdfccd_GuardPlaceFn place,
                                 void* place_user, sdfccd_GuardWorldResult* results)
{
    sdfccd_Status st = check_world(ws, sdfs, sdf_count, bodies, body_count, t0, t1, params, results);
    if (st) return st;
    for (int32_t i = 0; i < body_count; ++i) {
        sdfccd_GuardWorldResult* r = &results[i];
        memset(r, 0, sizeof *r);
        r->sdf = r->part = -1;
        r->pose = bodies[i].end;
        r->state = bodies[i].state;
        r->guard = clear_result(t1, &bodies[i].end);
    }
    const double pad = params->tolerance;
    for (int32_t i = 0; i < body_count; ++i) {
        const sdfccd_GuardRigidBody* b = &bodies[i];
        sdfccd_GuardWorldResult* r = &results[i];
        if (b->part_count == 0) continue;
        scc_aabb box = swept_box(&b->start_box, &b->end_box, &b->start, &b->end, b->reach);
        box.lo = scc_sub(box.lo, scc_v3(pad, pad, pad));
        box.hi = scc_add(box.hi, scc_v3(pad, pad, pad));
        const int still = same_pose(&b->start, &b->end);
        const sdfccd_Vec3 centre = sdfccd__pv(scc_xform_apply_inv(to_xform(&b->end), sdfccd__v(b->state.center))); /* body frame */
        for (int32_t j = 0; j < sdf_count; ++j) {
            const sdfccd_GuardSdf* s = &sdfs[j];
            if (s->body == i) continue;
            const scc_aabb sbox = swept_box(&s->start_box, &s->end_box, &s->start, &s->end, s->reach);
            if (!boxes_overlap(&box, &sbox)) continue;
            if (still && same_pose(&s->start, &s->end)) continue; /* neither moved: nothing went deeper */
            sdfccd_RigidMotion sm;
            sdf_motion(s, j, t0, t1, &sm);
            for (int32_t k = 0; k < b->part_count; ++k) {
                const sdfccd_GuardPart* part = &b->parts[k];
                if (part->shape_key != 0 && part->shape_key == s->shape_key) continue; /* the SDF's own surface */
                r->queries++;
                const sdfccd_Pose p0 = times_offset(&b->start, &part->offset), p1 = times_offset(&b->end, &part->offset);
                const sdfccd_Vec3 c = is_identity(&part->offset)
                                          ? centre
                                          : sdfccd__pv(scc_xform_apply_inv(to_xform(&part->offset), sdfccd__v(centre)));
                sdfccd_RigidMotion executed;
                sdfccd_GuardResult g;
                if (sdfccd_rigid_motion_from_poses(&p0, &p1, c, t0, t1, &executed) != SDFCCD_OK ||
                    sdfccd_guard_step_rigid(ws, s->sdf, &sm, part->mesh, &executed, t0, t1, params, &g) != SDFCCD_OK) {
                    r->failures++;
                    continue;
                }
                r->sdf_evaluations += g.sdf_evaluations;
                if (scc_guard_earlier(g.state == SDFCCD_GUARD_ROLLED_BACK, g.toi, r->guard.toi)) {
                    r->guard = g;
                    r->sdf = j;
                    r->part = k;
                }
            }
        }
        if (r->sdf < 0) continue;
        const sdfccd_GuardSdf* s = &sdfs[r->sdf];
        sdfccd_RigidMotion sm;
        sdf_motion(s, r->sdf, t0, t1, &sm);
        r->rolled_back = 1;
        r->pose = rolled_back_pose(&r->guard, &b->parts[r->part].offset, s, &sm, t0);
        r->state = state_at(&b->state, &b->end, &r->pose);
        double mu = b->friction * s->friction;
        if (place) place(place_user, i, r->sdf, &r->pose, &r->state, &mu);
        const sdfccd_BodyState* ss = s->body >= 0 ? &results[s->body].state : s->has_state ? &s->state : NULL;
        sdfccd_BodyState after = r->state;
        if (sdfccd_guard_response(&r->guard, 1, ss, mu, &after) == SDFCCD_OK) r->state = after;
    }
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_guard_world(sdfccd_Workspace* ws, const sdfccd_GuardSdf* sdfs, int32_t sdf_count, const sdfccd_GuardRigidBody* bodies,
                                 int32_t body_count, double t0, double t1, const sdfccd_GuardParams* params, sdfccd_GuardPlaceFn place,
                                 void* place_user, sdfccd_GuardWorldResult* results)
{
    SDFCCD__HELD_CALL(guard_world(ws, sdfs, sdf_count, bodies, body_count, t0, t1, params, place, place_user, results));
}
