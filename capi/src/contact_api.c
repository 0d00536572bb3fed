/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: contact.h. Validates the arguments, converts to the core's SDF-frame problem
 * (core/guard.c) and maps the results back to the world. */
#include "capi_internal.h"
#include "../../core/ccd.h"
#include "../../core/guard.h"

#include <stdio.h>

/* Finite pose with a unit orientation (within 1e-4, then normalised) and a bounded position. */
static sdfccd_Status unit_pose(const sdfccd_Pose* pose, const char* what, scc_xform* out)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(pose, what)) || (st = sdfccd__check_pose(*pose, what, out))) return st;
    sdfccd_Quat q = pose->orientation;
    double n = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (!(fabs(n - 1.0) <= 1e-4))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: orientation is not a unit quaternion (norm %.17g)", what, n);
    if (!(scc_maxc(scc_vabs(out->p)) <= SDFCCD_MAX_QUERY_MAGNITUDE))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: position has a coordinate above SDFCCD_MAX_QUERY_MAGNITUDE", what);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_rigid_motion_from_poses(const sdfccd_Pose* start, const sdfccd_Pose* end, sdfccd_Vec3 local_center, double t0,
                                             double t1, sdfccd_RigidMotion* out_motion)
{
    static const char fn[] = "sdfccd_rigid_motion_from_poses";
    sdfccd_Status st;
    scc_xform a, b;
    if ((st = sdfccd__check_ptr(out_motion, "sdfccd_rigid_motion_from_poses: out_motion")) ||
        (st = unit_pose(start, "sdfccd_rigid_motion_from_poses: start", &a)) ||
        (st = unit_pose(end, "sdfccd_rigid_motion_from_poses: end", &b)) ||
        (st = sdfccd__check_vec(local_center, "sdfccd_rigid_motion_from_poses: local_center")))
        return st;
    if (!(scc_maxc(scc_vabs(sdfccd__v(local_center))) <= SDFCCD_MAX_QUERY_MAGNITUDE))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: local_center has a coordinate above SDFCCD_MAX_QUERY_MAGNITUDE", fn);
    if (!isfinite(t0) || !isfinite(t1) || !(t1 > t0) || !isfinite(t1 - t0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: t0 and t1 must be finite with t1 > t0 (got %g, %g)", fn, t0, t1);
    const double dt = t1 - t0;
    scc_vec3 c = sdfccd__v(local_center);
    scc_vec3 v = scc_scale(scc_sub(scc_xform_apply(b, c), scc_xform_apply(a, c)), 1.0 / dt);
    /* The rotation from start to end, on the hemisphere of the shorter arc (angle <= pi). */
    scc_quat d = scc_quat_mul(b.q, scc_quat_conj(a.q));
    if (d.w < 0.0) d = (scc_quat){ -d.w, -d.x, -d.y, -d.z };
    scc_vec3 axis = scc_v3(d.x, d.y, d.z);
    double s = scc_len(axis);
    double angle = 2.0 * atan2(s, d.w);
    scc_vec3 w = s > 1e-300 ? scc_scale(axis, angle / (s * dt)) : scc_v3(0, 0, 0);
    if (!scc_vfinite(v) || !(scc_maxc(scc_vabs(v)) <= SDFCCD_MAX_QUERY_MAGNITUDE))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the velocity (displacement / (t1 - t0)) is not finite or above "
                             "SDFCCD_MAX_QUERY_MAGNITUDE", fn);
    if (!scc_vfinite(w))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the angular velocity (angle / (t1 - t0)) is not finite", fn);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = sdfccd__pv(a.p);
    m.pose.orientation = (sdfccd_Quat){ a.q.w, a.q.x, a.q.y, a.q.z };
    m.local_center = local_center;
    m.linear_velocity = sdfccd__pv(v);
    m.angular_velocity = sdfccd__pv(w);
    *out_motion = m;
    return SDFCCD_OK;
}

/* Guard params (checked) as the core's query params and tolerance. */
static sdfccd_Status convert_guard_params(const sdfccd_GuardParams* in, const char* fn, scc_params* out, double* out_tol)
{
    sdfccd_Status st;
    if (!in) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params is NULL", fn);
    if ((st = sdfccd__check_def(in->internal_value, fn, "params were", "sdfccd_default_guard_params"))) return st;
    if (!isfinite(in->tolerance) || !(in->tolerance > 0.0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->tolerance must be finite and > 0 (got %g)", fn, in->tolerance);
    if ((st = sdfccd__convert_params(&in->query, fn, out))) return st;
    if (out->method == SCC_METHOD_DCD)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the DCD method tests the end pose only and cannot guard a motion", fn);
    *out_tol = in->tolerance;
    return SDFCCD_OK;
}

static sdfccd_Pose public_pose(scc_quat q, scc_vec3 p)
{
    sdfccd_Pose r;
    r.position = sdfccd__pv(p);
    r.orientation = (sdfccd_Quat){ q.w, q.x, q.y, q.z };
    return r;
}

static sdfccd_Status guard_rigid(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                 const sdfccd_RigidMotion* executed, double t0, double t1, const sdfccd_GuardParams* params,
                                 sdfccd_GuardResult* out)
{
    static const char fn[] = "sdfccd_guard_rigid";
    sdfccd_Status st;
    scc_params p;
    double tol = 0.0;
    if ((st = sdfccd__check_ptr(ws, "sdfccd_guard_rigid: ws")) || (st = sdfccd__check_ptr(out, "sdfccd_guard_rigid: out")) ||
        (st = sdfccd__check_ptr(executed, "sdfccd_guard_rigid: executed")) || (st = convert_guard_params(params, fn, &p, &tol)) ||
        (st = sdfccd__check_interval(t0, t1, fn)))
        return st;
    scc_rigid sm, body;
    const scc_rigid* smp = NULL;
    if (sdf_motion) {
        if ((st = sdfccd__convert_motion(sdf_motion, t0, t1, "sdfccd_guard_rigid: sdf_motion", &sm))) return st;
        smp = &sm;
    }
    if ((st = sdfccd__convert_motion(executed, t0, t1, "sdfccd_guard_rigid: executed", &body)) ||
        (st = sdfccd__check_total_rotation(&body, smp, t1 - t0, fn)))
        return st;
    sdfccd__sdf* s = sdfccd__sdf_acquire(sdf);
    if (!s) return SDFCCD_INVALID_HANDLE;
    sdfccd__mesh* m = sdfccd__mesh_acquire(mesh);
    if (!m) return SDFCCD_INVALID_HANDLE;
    if ((st = sdfccd__check_mesh_bounds(m, fn))) return st;
    scc_mesh_motion mm = { &m->mesh, &body, NULL, NULL, smp, t0, t1, NULL };
    scc_guard_out g;
    if (!scc_guard(s->sdf, &mm, &p, tol, &ws->ws, &g)) return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory", fn);
    sdfccd_GuardResult r;
    memset(&r, 0, sizeof r);
    r.state = g.state == SCC_GUARD_ROLLED_BACK ? SDFCCD_GUARD_ROLLED_BACK
            : g.state == SCC_GUARD_INSIDE_AT_START ? SDFCCD_GUARD_INSIDE_AT_START : SDFCCD_GUARD_CLEAR;
    r.toi = g.toi;
    r.fraction = t1 > t0 ? (g.toi - t0) / (t1 - t0) : 0.0;
    scc_quat q;
    scc_vec3 pos;
    scc_rigid_pose_at(&body, g.toi, &q, &pos);
    r.safe_pose = public_pose(q, pos);
    if (g.state == SCC_GUARD_ROLLED_BACK) {
        r.point = sdfccd__pv(scc_world_point(smp, g.toi, g.point));
        r.normal = sdfccd__pv(scc_normalize_or(scc_world_vector(smp, g.toi, g.normal), scc_v3(0, 0, 1)));
        r.triangle = g.triangle;
    }
    r.min_gap_start = g.min_gap_start;
    r.deep_triangles = (int32_t)g.deep_triangles;
    r.query_state = sdfccd__public_state(g.query_state);
    r.queries = g.queries;
    r.sdf_evaluations = g.evals;
    *out = r;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_guard_rigid(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                 const sdfccd_RigidMotion* executed, double t0, double t1, const sdfccd_GuardParams* params,
                                 sdfccd_GuardResult* out)
{
    SDFCCD__HELD_CALL(guard_rigid(ws, sdf, sdf_motion, mesh, executed, t0, t1, params, out));
}
