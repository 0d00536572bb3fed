/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: contact.h. Validates the arguments, converts to the core's SDF-frame problem
 * (core/guard.c) and maps the results back to the world. */
#include "capi_internal.h"
#include "../../core/ccd.h"
#include "../../core/guard.h"
#include "../../core/reduce.h"
#include "../../core/contacts.h"
#include "../../core/faces.h"

#include <stdio.h>

/* Finite pose with a unit orientation (within 1e-4, then normalised) and a bounded position. */
sdfccd_Status sdfccd__unit_pose(const sdfccd_Pose* pose, const char* what, scc_xform* out)
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
        (st = sdfccd__unit_pose(start, "sdfccd_rigid_motion_from_poses: start", &a)) ||
        (st = sdfccd__unit_pose(end, "sdfccd_rigid_motion_from_poses: end", &b)) ||
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

sdfccd_Status sdfccd__convert_guard_params(const sdfccd_GuardParams* in, const char* fn, scc_params* out, double* out_tol)
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

/* What every step call shares: the workspace, the interval, the SDF (and its motion) and the mesh. */
typedef struct step_setup {
    scc_rigid sm;
    const scc_rigid* smp;
    sdfccd__sdf* sdf;
    sdfccd__mesh* mesh;
} step_setup;

static sdfccd_Status setup_step(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh, double t0,
                                double t1, const char* fn, step_setup* q)
{
    sdfccd_Status st;
    char what[96];
    snprintf(what, sizeof what, "%s: ws", fn);
    if ((st = sdfccd__check_ptr(ws, what)) || (st = sdfccd__check_interval(t0, t1, fn))) return st;
    q->smp = NULL;
    if (sdf_motion) {
        snprintf(what, sizeof what, "%s: sdf_motion", fn);
        if ((st = sdfccd__convert_motion(sdf_motion, t0, t1, what, &q->sm))) return st;
        q->smp = &q->sm;
    }
    if (!(q->sdf = sdfccd__sdf_acquire(sdf)) || !(q->mesh = sdfccd__mesh_acquire(mesh))) return SDFCCD_INVALID_HANDLE;
    return sdfccd__check_mesh_bounds(q->mesh, fn);
}

/* The rigid motion of a step call, checked with the SDF's. */
static sdfccd_Status setup_rigid(const sdfccd_RigidMotion* motion, double t0, double t1, const step_setup* q, const char* fn, scc_rigid* out)
{
    sdfccd_Status st;
    char what[96];
    snprintf(what, sizeof what, "%s: motion", fn);
    if ((st = sdfccd__check_ptr(motion, what)) || (st = sdfccd__convert_motion(motion, t0, t1, what, out))) return st;
    return sdfccd__check_total_rotation(out, q->smp, t1 - t0, fn);
}

/* The per-vertex linear motion of a step call, copied into the workspace. */
static sdfccd_Status setup_linear(const sdfccd_Vec3* start, const sdfccd_Vec3* end, sdfccd_Workspace* ws, const step_setup* q, const char* fn,
                                  scc_vec3** out)
{
    sdfccd_Status st;
    char what[96];
    snprintf(what, sizeof what, "%s: start", fn);
    if ((st = sdfccd__check_ptr(start, what))) return st;
    snprintf(what, sizeof what, "%s: end", fn);
    if ((st = sdfccd__check_ptr(end, what))) return st;
    return sdfccd__linear_vertices(q->mesh, start, end, &ws->ws, fn, out);
}

static sdfccd_Status run_guard(sdfccd_Workspace* ws, const step_setup* q, const scc_mesh_motion* mm, const sdfccd_GuardParams* params,
                               sdfccd_GuardResult* out, const char* fn, int step)
{
    scc_params p;
    double tol = 0.0;
    sdfccd_Status st;
    if ((st = sdfccd__convert_guard_params(params, fn, &p, &tol))) return st;
    scc_guard_out g;
    if (!(step ? scc_guard_step : scc_guard)(q->sdf->sdf, mm, &p, tol, &ws->ws, &g))
        return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory", fn);
    const double t0 = mm->t0, t1 = mm->t1;
    sdfccd_GuardResult r;
    memset(&r, 0, sizeof r);
    r.state = g.state == SCC_GUARD_ROLLED_BACK ? SDFCCD_GUARD_ROLLED_BACK
            : g.state == SCC_GUARD_INSIDE_AT_START ? SDFCCD_GUARD_INSIDE_AT_START : SDFCCD_GUARD_CLEAR;
    r.toi = g.toi;
    r.fraction = t1 > t0 ? (g.toi - t0) / (t1 - t0) : 0.0;
    r.safe_pose = sdfccd_pose_identity();
    if (mm->body) {
        scc_quat qq;
        scc_vec3 pos;
        scc_rigid_pose_at(mm->body, g.toi, &qq, &pos);
        r.safe_pose = public_pose(qq, pos);
    }
    if (g.state == SCC_GUARD_ROLLED_BACK) {
        r.point = sdfccd__pv(scc_world_point(q->smp, g.toi, g.point));
        r.normal = sdfccd__pv(scc_normalize_or(scc_world_vector(q->smp, g.toi, g.normal), scc_v3(0, 0, 1)));
        r.triangle = g.triangle;
    }
    r.min_gap_start = g.min_gap_start;
    r.deep_triangles = (int32_t)g.deep_triangles;
    r.query_state = sdfccd__public_state(g.query_state);
    r.queries = g.queries;
    r.sdf_evaluations = g.evals;
    r.pinned = step ? g.pinned : 0;
    r.certified = step ? g.certified : 0;
    *out = r;
    return SDFCCD_OK;
}

static sdfccd_Status guard_rigid(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                 const sdfccd_RigidMotion* executed, double t0, double t1, const sdfccd_GuardParams* params,
                                 sdfccd_GuardResult* out, int step)
{
    const char* fn = step ? "sdfccd_guard_step_rigid" : "sdfccd_guard_rigid";
    sdfccd_Status st;
    step_setup q;
    scc_rigid body;
    char what[64];
    snprintf(what, sizeof what, "%s: out", fn);
    if ((st = sdfccd__check_ptr(out, what)) || (st = setup_step(ws, sdf, sdf_motion, mesh, t0, t1, fn, &q)) ||
        (st = setup_rigid(executed, t0, t1, &q, fn, &body)))
        return st;
    scc_mesh_motion mm = { &q.mesh->mesh, &body, NULL, NULL, q.smp, t0, t1, NULL, NULL };
    return run_guard(ws, &q, &mm, params, out, fn, step);
}

static sdfccd_Status guard_linear(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                  const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0, double t1, const sdfccd_GuardParams* params,
                                  sdfccd_GuardResult* out, sdfccd_Vec3* out_positions)
{
    static const char fn[] = "sdfccd_guard_linear";
    sdfccd_Status st;
    step_setup q;
    scc_vec3* v;
    if ((st = sdfccd__check_ptr(out, "sdfccd_guard_linear: out")) || (st = setup_step(ws, sdf, sdf_motion, mesh, t0, t1, fn, &q)) ||
        (st = setup_linear(start, end, ws, &q, fn, &v)))
        return st;
    const uint32_t nv = q.mesh->mesh.vertex_count;
    scc_mesh_motion mm = { &q.mesh->mesh, NULL, v, v + nv, q.smp, t0, t1, NULL, NULL };
    if ((st = run_guard(ws, &q, &mm, params, out, fn, 0))) return st;
    if (out_positions) {
        const double s = out->fraction;
        for (uint32_t i = 0; i < nv; ++i) out_positions[i] = sdfccd__pv(scc_lerp(v[i], v[nv + i], s));
    }
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_guard_rigid(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                 const sdfccd_RigidMotion* executed, double t0, double t1, const sdfccd_GuardParams* params,
                                 sdfccd_GuardResult* out)
{
    SDFCCD__HELD_CALL(guard_rigid(ws, sdf, sdf_motion, mesh, executed, t0, t1, params, out, 0));
}

sdfccd_Status sdfccd_guard_linear(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                  const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0, double t1, const sdfccd_GuardParams* params,
                                  sdfccd_GuardResult* out, sdfccd_Vec3* out_positions)
{
    SDFCCD__HELD_CALL(guard_linear(ws, sdf, sdf_motion, mesh, start, end, t0, t1, params, out, out_positions));
}

/* ---- contact generation ---- */

/* The checks of a sdfccd_KeepPrevious (`what` names it in the message). */
static sdfccd_Status check_keep(const sdfccd_KeepPrevious* k, const char* fn, const char* what)
{
    if (k->count < 0 || (k->count > 0 && !k->ids))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: %s.count (%d) < 0, or > 0 with ids NULL", fn, what, k->count);
    if (!isfinite(k->depth) || k->depth < 0.0 || !(k->share >= 0.0 && k->share <= 1.0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: %s.depth (%g) must be finite and >= 0, share (%g) in [0, 1]", fn, what, k->depth,
                             k->share);
    return SDFCCD_OK;
}

static scc_reduce_keep core_keep(const sdfccd_KeepPrevious* k)
{
    scc_reduce_keep r = { k->ids, (size_t)k->count, k->depth, k->share };
    return r;
}

static sdfccd_Status convert_contact_params(const sdfccd_ContactParams* in, const char* fn, scc_contact_params* out)
{
    sdfccd_Status st;
    if (!in) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params is NULL", fn);
    if ((st = sdfccd__check_def(in->internal_value, fn, "params were", "sdfccd_default_contact_params"))) return st;
    const double d[5] = { in->vertex_distance, in->same_place_distance, in->feature_size, in->cover_depth, in->end_skip_travel };
    for (int i = 0; i < 5; ++i)
        if (!isfinite(d[i]) || d[i] < 0.0)
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT,
                                 "%s: params->vertex_distance, same_place_distance, feature_size, cover_depth and end_skip_travel must "
                                 "be finite and >= 0 (got %g, %g, %g, %g, %g)", fn, d[0], d[1], d[2], d[3], d[4]);
    if (in->reduced_count < 0) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->reduced_count (%d) < 0", fn, in->reduced_count);
    if ((st = check_keep(&in->previous, fn, "params->previous"))) return st;
    if ((st = sdfccd__convert_params(&in->query, fn, &out->query))) return st;
    out->vertex_distance = in->vertex_distance;
    out->same_place = in->same_place_distance;
    out->feature_size = in->feature_size;
    out->reduced = in->reduced_count;
    out->cover_depth = in->cover_depth;
    out->end_skip_travel = in->end_skip_travel;
    out->keep = core_keep(&in->previous);
    return SDFCCD_OK;
}

/* A contact point of the core (SDF frame at time t of smp) in the world frame. */
static void public_point(const scc_contact_point* c, const scc_rigid* smp, double t, sdfccd_ContactPoint* o)
{
    o->point = sdfccd__pv(scc_world_point(smp, t, c->point));
    o->surface_point = sdfccd__pv(scc_world_point(smp, t, c->surface));
    o->normal = sdfccd__pv(scc_normalize_or(scc_world_vector(smp, t, c->normal), scc_v3(0, 0, 1)));
    o->gap = c->gap;
    o->toi = c->toi;
    for (int k = 0; k < 3; ++k) o->barycentric[k] = c->bary[k];
    o->triangle = c->triangle;
    o->feature_kind = c->kind == SCC_FEATURE_VERTEX ? SDFCCD_FEATURE_VERTEX : c->kind == SCC_FEATURE_EDGE ? SDFCCD_FEATURE_EDGE : SDFCCD_FEATURE_FACE;
    o->feature = c->feature;
    o->id = c->id;
}

static sdfccd_Status run_contacts(sdfccd_Workspace* ws, const step_setup* q, const scc_mesh_motion* mm, const sdfccd_ContactParams* params,
                                  sdfccd_ContactPoint* out_points, int32_t capacity, sdfccd_ContactSet* out_set, const char* fn)
{
    sdfccd_Status st;
    scc_contact_params cp;
    if ((st = convert_contact_params(params, fn, &cp))) return st;
    if (capacity < 0 || (capacity > 0 && !out_points))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: out_points is NULL or capacity (%d) < 0", fn, capacity);
    scc_contact_point* c = NULL;
    if (capacity > 0 && !(c = scc_ws_get(&ws->ws, SCC_WS_STAGING, (size_t)capacity * sizeof *c)))
        return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory", fn);
    scc_contact_set s;
    if (!scc_generate_contacts(q->sdf->sdf, mm, &cp, &ws->ws, c, capacity, &s)) return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory", fn);
    for (size_t i = 0; i < s.written; ++i) public_point(&c[i], q->smp, mm->t0, &out_points[i]);
    sdfccd_ContactSet r;
    memset(&r, 0, sizeof r);
    r.count = (int32_t)s.written;
    r.candidates = s.candidates > INT32_MAX ? INT32_MAX : (int32_t)s.candidates;
    r.started_in_contact = s.started_in_contact;
    r.ccd_ran = s.ccd_ran;
    r.ccd_state = sdfccd__public_state(s.ccd_state);
    r.toi = s.toi;
    r.sdf_evaluations = s.evals;
    r.reduced = (int32_t)s.reduced;
    r.discrete_queries = s.discrete_queries;
    r.own_evaluations = s.own_evals;
    r.face_regions = s.face_regions;
    *out_set = r;
    return SDFCCD_OK;
}

static sdfccd_Status generate_contacts(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                       const sdfccd_RigidMotion* motion, double t0, double t1, const sdfccd_ContactParams* params,
                                       sdfccd_ContactPoint* out_points, int32_t capacity, sdfccd_ContactSet* out_set)
{
    static const char fn[] = "sdfccd_generate_contacts";
    sdfccd_Status st;
    step_setup q;
    scc_rigid body;
    if ((st = sdfccd__check_ptr(out_set, "sdfccd_generate_contacts: out_set")) || (st = setup_step(ws, sdf, sdf_motion, mesh, t0, t1, fn, &q)) ||
        (st = setup_rigid(motion, t0, t1, &q, fn, &body)))
        return st;
    scc_mesh_motion mm = { &q.mesh->mesh, &body, NULL, NULL, q.smp, t0, t1, NULL, NULL };
    return run_contacts(ws, &q, &mm, params, out_points, capacity, out_set, fn);
}

static sdfccd_Status generate_contacts_linear(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                              const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0, double t1,
                                              const sdfccd_ContactParams* params, sdfccd_ContactPoint* out_points, int32_t capacity,
                                              sdfccd_ContactSet* out_set)
{
    static const char fn[] = "sdfccd_generate_contacts_linear";
    sdfccd_Status st;
    step_setup q;
    scc_vec3* v;
    if ((st = sdfccd__check_ptr(out_set, "sdfccd_generate_contacts_linear: out_set")) ||
        (st = setup_step(ws, sdf, sdf_motion, mesh, t0, t1, fn, &q)) || (st = setup_linear(start, end, ws, &q, fn, &v)))
        return st;
    const uint32_t nv = q.mesh->mesh.vertex_count;
    scc_mesh_motion mm = { &q.mesh->mesh, NULL, v, v + nv, q.smp, t0, t1, NULL, NULL };
    return run_contacts(ws, &q, &mm, params, out_points, capacity, out_set, fn);
}

sdfccd_Status sdfccd_generate_contacts(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                       const sdfccd_RigidMotion* motion, double t0, double t1, const sdfccd_ContactParams* params,
                                       sdfccd_ContactPoint* out_points, int32_t capacity, sdfccd_ContactSet* out_set)
{
    SDFCCD__HELD_CALL(generate_contacts(ws, sdf, sdf_motion, mesh, motion, t0, t1, params, out_points, capacity, out_set));
}

sdfccd_Status sdfccd_generate_contacts_linear(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                              const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0, double t1,
                                              const sdfccd_ContactParams* params, sdfccd_ContactPoint* out_points, int32_t capacity,
                                              sdfccd_ContactSet* out_set)
{
    SDFCCD__HELD_CALL(generate_contacts_linear(ws, sdf, sdf_motion, mesh, start, end, t0, t1, params, out_points, capacity, out_set));
}

/* ---- contact sets of many pairs on threads ---- */

typedef struct contact_batch {
    sdfccd_ContactPair* pairs;
    sdfccd_Workspace* const* ws; /* one per thread slot */
} contact_batch;

static sdfccd_Status run_pair(void* ctx, int32_t i, int32_t slot)
{
    contact_batch* b = ctx;
    sdfccd_ContactPair* q = &b->pairs[i];
    return q->status = sdfccd_generate_contacts(b->ws[slot], q->sdf, q->sdf_motion, q->mesh, q->motion, q->t0, q->t1, q->params,
                                                q->out_points, q->capacity, q->out_set);
}

sdfccd_Status sdfccd_generate_contacts_batch(sdfccd_Workspace* const* workspaces, int32_t thread_count, sdfccd_ContactPair* pairs,
                                             int32_t count)
{
    static const char fn[] = "sdfccd_generate_contacts_batch";
    if (count < 0 || (count > 0 && !pairs) || !workspaces)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: pairs or workspaces is NULL or count (%d) < 0", fn, (int)count);
    if (thread_count < 1 || thread_count > SDFCCD__MAX_THREADS)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: thread_count must be in [1, %d] (got %d)", fn, SDFCCD__MAX_THREADS,
                             (int)thread_count);
    for (int32_t k = 0; k < thread_count; ++k)
        if (!workspaces[k]) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: workspaces[%d] is NULL", fn, (int)k);
    contact_batch b = { pairs, workspaces };
    return sdfccd__run_threads(fn, "pair", run_pair, &b, count, thread_count);
}

/* ---- the face search ---- */

static sdfccd_Status search_faces(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_Pose* sdf_pose, sdfccd_MeshId mesh, const sdfccd_Pose* pose,
                                  double region_size, double accept, const sdfccd_QueryParams* params, sdfccd_ContactPoint* out_points,
                                  int32_t capacity, sdfccd_FaceSearch* out)
{
    static const char fn[] = "sdfccd_search_faces";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out, "sdfccd_search_faces: out")) || (st = sdfccd__check_ptr(pose, "sdfccd_search_faces: pose")) ||
        (st = sdfccd__check_ptr(params, "sdfccd_search_faces: params")))
        return st;
    if (!isfinite(region_size) || !(region_size > 0.0) || !isfinite(accept))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: region_size must be finite and > 0 and accept finite (got %g, %g)", fn, region_size,
                             accept);
    if (capacity < 0 || (capacity > 0 && !out_points))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: out_points is NULL or capacity (%d) < 0", fn, capacity);
    scc_params p;
    if ((st = sdfccd__convert_params(params, fn, &p))) return st;
    sdfccd_RigidMotion bm = sdfccd_default_rigid_motion(), sm = sdfccd_default_rigid_motion();
    bm.pose = *pose;
    if (sdf_pose) sm.pose = *sdf_pose;
    step_setup q;
    scc_rigid body;
    if ((st = setup_step(ws, sdf, sdf_pose ? &sm : NULL, mesh, 0.0, 0.0, fn, &q)) || (st = setup_rigid(&bm, 0.0, 0.0, &q, fn, &body))) return st;
    scc_mesh_motion mm = { &q.mesh->mesh, &body, NULL, NULL, q.smp, 0.0, 0.0, NULL, NULL };
    scc_contact_point* c = NULL;
    if (capacity > 0 && !(c = scc_ws_get(&ws->ws, SCC_WS_STAGING, (size_t)capacity * sizeof *c)))
        return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory", fn);
    size_t found = 0;
    int64_t regions = 0, evals = 0;
    if (!scc_search_faces(q.sdf->sdf, &mm, 0.0, region_size, accept, &p, &ws->ws, c, (size_t)capacity, &found, &regions, &evals))
        return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory", fn);
    const int fits = found <= (size_t)capacity;
    for (size_t i = 0; fits && i < found; ++i) public_point(&c[i], q.smp, 0.0, &out_points[i]);
    out->count = fits ? (int32_t)found : 0;
    out->found = found > INT32_MAX ? INT32_MAX : (int32_t)found;
    out->regions = regions;
    out->sdf_evaluations = evals;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_search_faces(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_Pose* sdf_pose, sdfccd_MeshId mesh, const sdfccd_Pose* pose,
                                  double region_size, double accept, const sdfccd_QueryParams* params, sdfccd_ContactPoint* out_points,
                                  int32_t capacity, sdfccd_FaceSearch* out)
{
    SDFCCD__HELD_CALL(search_faces(ws, sdf, sdf_pose, mesh, pose, region_size, accept, params, out_points, capacity, out));
}

/* ---- contact points: reduction ---- */

static void public_item(const void* set, size_t i, scc_reduce_item* out)
{
    const sdfccd_ContactPoint* c = (const sdfccd_ContactPoint*)set + i;
    out->p = sdfccd__v(c->surface_point);
    out->n = sdfccd__v(c->normal);
    out->gap = c->gap;
    out->id = c->id;
}

static sdfccd_Status reduce_contacts(const sdfccd_ContactPoint* points, int32_t count, double same_place_distance, double depth_scale,
                                     const sdfccd_KeepPrevious* previous, int32_t* out_indices, int32_t capacity, int32_t* out_count,
                                     const char* fn)
{
    sdfccd_Status st;
    if (previous && (st = check_keep(previous, fn, "previous"))) return st;
    if (!out_count) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: out_count is NULL", fn);
    if (count < 0 || capacity < 0) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: count (%d) and capacity (%d) must be >= 0", fn, count, capacity);
    if ((count > 0 && !points) || (capacity > 0 && !out_indices))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: points or out_indices is NULL", fn);
    if (!isfinite(same_place_distance) || same_place_distance < 0.0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: same_place_distance must be finite and >= 0 (got %g)", fn, same_place_distance);
    if (!isfinite(depth_scale) || depth_scale < 0.0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: depth_scale must be finite and >= 0 (got %g)", fn, depth_scale);
    for (int32_t i = 0; i < count; ++i) {
        const sdfccd_ContactPoint* c = &points[i];
        if (!scc_vfinite(sdfccd__v(c->surface_point)) || !scc_vfinite(sdfccd__v(c->normal)) || !isfinite(c->gap))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: point %d has a non-finite surface point, normal or gap", fn, i);
    }
    const scc_reduce_keep keep = previous ? core_keep(previous) : (scc_reduce_keep){ NULL, 0, 0.0, 0.0 };
    *out_count = (int32_t)scc_reduce_kept(points, (size_t)count, public_item, same_place_distance, depth_scale, &keep, (size_t)capacity,
                                          out_indices, NULL);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_reduce_contacts(const sdfccd_ContactPoint* points, int32_t count, double same_place_distance, int32_t* out_indices,
                                     int32_t capacity, int32_t* out_count)
{
    return reduce_contacts(points, count, same_place_distance, 0.0, NULL, out_indices, capacity, out_count, "sdfccd_reduce_contacts");
}

sdfccd_Status sdfccd_reduce_contacts_weighted(const sdfccd_ContactPoint* points, int32_t count, double same_place_distance,
                                              double depth_scale, int32_t* out_indices, int32_t capacity, int32_t* out_count)
{
    return reduce_contacts(points, count, same_place_distance, depth_scale, NULL, out_indices, capacity, out_count,
                           "sdfccd_reduce_contacts_weighted");
}

sdfccd_Status sdfccd_reduce_contacts_kept(const sdfccd_ContactPoint* points, int32_t count, double same_place_distance, double depth_scale,
                                          const sdfccd_KeepPrevious* previous, int32_t* out_indices, int32_t capacity, int32_t* out_count)
{
    return reduce_contacts(points, count, same_place_distance, depth_scale, previous, out_indices, capacity, out_count,
                           "sdfccd_reduce_contacts_kept");
}

sdfccd_Status sdfccd_cover_contacts(const sdfccd_ContactPoint* points, int32_t count, const int32_t* chosen, int32_t chosen_count,
                                    double tilt, double depth, double same_place_distance, int32_t* out_indices, int32_t capacity,
                                    int32_t* out_count)
{
    static const char fn[] = "sdfccd_cover_contacts";
    if (!out_count) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: out_count is NULL", fn);
    if (count < 0 || chosen_count < 0 || capacity < 0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: count (%d), chosen_count (%d) and capacity (%d) must be >= 0", fn, count,
                             chosen_count, capacity);
    if ((count > 0 && !points) || (chosen_count > 0 && !chosen) || (capacity > 0 && !out_indices))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: points, chosen or out_indices is NULL", fn);
    if (!(isfinite(tilt) && tilt >= 0.0) || !(isfinite(depth) && depth >= 0.0) ||
        !(isfinite(same_place_distance) && same_place_distance >= 0.0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: tilt, depth and same_place_distance must be finite and >= 0", fn);
    for (int32_t j = 0; j < chosen_count; ++j)
        if (chosen[j] < 0 || chosen[j] >= count)
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: chosen[%d] = %d is outside [0, %d)", fn, j, chosen[j], count);
    for (int32_t i = 0; i < count; ++i) {
        const sdfccd_ContactPoint* c = &points[i];
        if (!scc_vfinite(sdfccd__v(c->surface_point)) || !scc_vfinite(sdfccd__v(c->normal)) || !isfinite(c->gap))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: point %d has a non-finite surface point, normal or gap", fn, i);
    }
    *out_count = (int32_t)scc_cover(points, (size_t)count, public_item, chosen, (size_t)chosen_count, tilt, depth,
                                    same_place_distance, (size_t)capacity, out_indices);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_match_contacts(const sdfccd_Vec3* previous, int32_t previous_count, const sdfccd_Vec3* points, int32_t count,
                                    double distance, int32_t* out_match)
{
    static const char fn[] = "sdfccd_match_contacts";
    sdfccd_Status st;
    if ((st = sdfccd__check_points(fn, points, count, out_match, "out_match"))) return st;
    if (previous_count < 0) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: previous_count = %d < 0", fn, (int)previous_count);
    if (previous_count > 0 && !previous) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: previous is NULL", fn);
    for (int32_t j = 0; j < previous_count; ++j)
        if ((st = sdfccd__check_vec(previous[j], "sdfccd_match_contacts: a previous point"))) return st;
    if (!isfinite(distance) || !(distance >= 0.0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: distance = %g is not finite and >= 0", fn, distance);
    if (count == 0) return SDFCCD_OK;
    unsigned char stack_used[4096];
    unsigned char* used = previous_count <= (int32_t)sizeof stack_used ? stack_used : (unsigned char*)sdfccd__alloc((size_t)previous_count);
    if (!used) return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: no memory for %d previous points", fn, (int)previous_count);
    /* (sdfccd_Vec3 and scc_vec3 are both three doubles x, y, z) */
    scc_match_points((const scc_vec3*)previous, (size_t)previous_count, (const scc_vec3*)points, (size_t)count, distance * distance,
                     out_match, used);
    if (used != stack_used) sdfccd__free(used, (size_t)previous_count);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_guard_step_rigid(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                      const sdfccd_RigidMotion* executed, double t0, double t1, const sdfccd_GuardParams* params,
                                      sdfccd_GuardResult* out)
{
    SDFCCD__HELD_CALL(guard_rigid(ws, sdf, sdf_motion, mesh, executed, t0, t1, params, out, 1));
}

/* Whether a body state passes sdfccd__body_state's checks (no message, no formatting). */
static int body_state_ok(const sdfccd_BodyState* in)
{
    if (!in || !scc_vfinite(sdfccd__v(in->center)) || !scc_vfinite(sdfccd__v(in->linear_velocity)) ||
        !scc_vfinite(sdfccd__v(in->angular_velocity)) || !isfinite(in->inverse_mass) || !(in->inverse_mass >= 0.0))
        return 0;
    for (int i = 0; i < 9; ++i)
        if (!isfinite(in->inverse_inertia[i])) return 0;
    return 1;
}

sdfccd_Status sdfccd__body_state(const sdfccd_BodyState* in, const char* fn, const char* what, scc_body_state* out)
{
    if (!body_state_ok(in)) { /* the message names the field */
        sdfccd_Status st;
        char w[96];
        snprintf(w, sizeof w, "%s: %s", fn, what);
        if ((st = sdfccd__check_ptr(in, w)) || (st = sdfccd__check_vec(in->center, w)) || (st = sdfccd__check_vec(in->linear_velocity, w)) ||
            (st = sdfccd__check_vec(in->angular_velocity, w)))
            return st;
        if (!isfinite(in->inverse_mass) || !(in->inverse_mass >= 0.0))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: inverse_mass must be finite and >= 0", w);
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: inverse_inertia is not finite", w);
    }
    for (int i = 0; i < 9; ++i) out->inv_inertia[i] = in->inverse_inertia[i];
    out->center = sdfccd__v(in->center);
    out->v = sdfccd__v(in->linear_velocity);
    out->w = sdfccd__v(in->angular_velocity);
    out->inv_mass = in->inverse_mass;
    return SDFCCD_OK;
}

static sdfccd_Status guard_response(const sdfccd_GuardResult* result, int32_t repeated, const sdfccd_BodyState* sdf_body, double friction,
                                    sdfccd_BodyState* body)
{
    sdfccd_Status st;
    scc_body_state b, s;
    if ((st = sdfccd__check_ptr(result, "sdfccd_guard_response: result")) || (st = sdfccd__body_state(body, "sdfccd_guard_response", "body", &b)) ||
        (sdf_body && (st = sdfccd__body_state(sdf_body, "sdfccd_guard_response", "sdf_body", &s))))
        return st;
    if (!isfinite(friction) || !(friction >= 0.0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_guard_response: friction must be finite and >= 0 (got %g)", friction);
    if (result->state != SDFCCD_GUARD_ROLLED_BACK) return SDFCCD_OK;
    if ((st = sdfccd__check_vec(result->point, "sdfccd_guard_response: result->point")) ||
        (st = sdfccd__check_vec(result->normal, "sdfccd_guard_response: result->normal")))
        return st;
    scc_guard_response(sdfccd__v(result->point), scc_normalize_or(sdfccd__v(result->normal), scc_v3(0, 0, 0)), result->pinned != 0,
                       repeated != 0, sdf_body ? &s : NULL, friction, &b);
    body->linear_velocity = sdfccd__pv(b.v);
    body->angular_velocity = sdfccd__pv(b.w);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_guard_response(const sdfccd_GuardResult* result, int32_t repeated, const sdfccd_BodyState* sdf_body, double friction,
                                    sdfccd_BodyState* body)
{
    SDFCCD__HELD_CALL(guard_response(result, repeated, sdf_body, friction, body));
}

/* Whether every loaded contact's material point moves slower than rest_speed relative to the SDF. */
static int held_at_rest(const sdfccd_HeldContact* contacts, int32_t count, double rest_speed, const scc_body_state* b)
{
    for (int32_t i = 0; i < count; ++i) {
        const sdfccd_HeldContact* c = &contacts[i];
        const scc_vec3 p = sdfccd__v(c->point);
        const scc_vec3 v = scc_sub(scc_add(b->v, scc_cross(b->w, scc_sub(p, b->center))), sdfccd__v(c->surface_velocity));
        if (c->normal_impulse > 0.0 && !(scc_len(v) < rest_speed)) return 0;
    }
    return 1;
}

static sdfccd_Status friction_hold(const sdfccd_HeldContact* contacts, int32_t count, double rest_speed, sdfccd_BodyState* body,
                                   sdfccd_Vec3* impulses)
{
    static const char fn[] = "sdfccd_friction_hold";
    enum { CHUNK = SCC_HOLD_MAX };
    sdfccd_Status st;
    scc_body_state b;
    if ((st = sdfccd__body_state(body, fn, "body", &b))) return st;
    if (count < 0) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: count must be >= 0 (got %d)", fn, (int)count);
    if (count > 0 && !contacts) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: contacts is NULL", fn);
    if (!isfinite(rest_speed) || !(rest_speed >= 0.0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: rest_speed must be finite and >= 0 (got %g)", fn, rest_speed);
    for (int32_t i = 0; i < count; ++i) {
        const sdfccd_HeldContact* c = &contacts[i];
        if (!isfinite(c->point.x + c->point.y + c->point.z + c->normal.x + c->normal.y + c->normal.z + c->surface_velocity.x +
                      c->surface_velocity.y + c->surface_velocity.z + c->friction_impulse.x + c->friction_impulse.y +
                      c->friction_impulse.z + c->normal_impulse + c->friction))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: contact %d has a non-finite value", fn, (int)i);
        if (!(c->normal_impulse >= 0.0) || !(c->friction >= 0.0))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: contact %d has a negative normal impulse or friction", fn, (int)i);
        if (!(scc_len(sdfccd__v(c->normal)) > 0.0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: contact %d has a zero normal", fn, (int)i);
    }
    /* The core works on fixed chunks (no allocation): a body's points in one chunk hold together; a
     * larger set is held chunk by chunk, each chunk seeing the velocities the earlier ones left. */
    scc_held_contact c[CHUNK];
    scc_vec3 held[CHUNK];
    const int at_rest = held_at_rest(contacts, count, rest_speed, &b);
    if (impulses)
        for (int32_t i = 0; i < count; ++i) impulses[i] = sdfccd__pv(scc_v3(0, 0, 0));
    for (int32_t lo = 0; at_rest && lo < count; lo += CHUNK) {
        const int32_t n = count - lo < CHUNK ? count - lo : CHUNK;
        for (int32_t i = 0; i < n; ++i) {
            const sdfccd_HeldContact* in = &contacts[lo + i];
            c[i].point = sdfccd__v(in->point);
            c[i].normal = scc_normalize_or(sdfccd__v(in->normal), scc_v3(0, 0, 1));
            c[i].surface_velocity = sdfccd__v(in->surface_velocity);
            c[i].applied = sdfccd__v(in->friction_impulse);
            c[i].normal_impulse = in->normal_impulse;
            c[i].mu = in->friction;
        }
        scc_friction_hold(c, (size_t)n, held, &b);
        if (impulses)
            for (int32_t i = 0; i < n; ++i) impulses[lo + i] = sdfccd__pv(held[i]);
    }
    body->linear_velocity = sdfccd__pv(b.v);
    body->angular_velocity = sdfccd__pv(b.w);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_friction_hold(const sdfccd_HeldContact* contacts, int32_t count, double rest_speed, sdfccd_BodyState* body,
                                   sdfccd_Vec3* impulses)
{
    SDFCCD__HELD_CALL(friction_hold(contacts, count, rest_speed, body, impulses));
}
