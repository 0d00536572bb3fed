/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: the guarantee over all the checks of one body (contact.h, sdfccd_guard_body): each
 * pair through sdfccd_guard_step_rigid, the earliest rollback by scc_guard_earlier (core/guard.h);
 * and its broad phase, the box a body can occupy over the step (sdfccd_swept_aabb, scc_swept_aabb). */
#include "capi_internal.h"
#include "../../core/guard.h"

#include <string.h>

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
    r.first.state = SDFCCD_GUARD_CLEAR;
    r.first.toi = t1;
    r.first.fraction = 1.0;
    r.first.min_gap_start = INFINITY;
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
