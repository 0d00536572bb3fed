/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: query parameters, rigid motions and the triangle and mesh queries. Validates
 * every input, converts to the core's SDF-frame problem, and maps results back to the world. */
#include "capi_internal.h"
#include "../../core/ccd.h"

#include <stdio.h>
#include <string.h>

sdfccd_Status sdfccd__convert_params(const sdfccd_QueryParams* in, const char* fn, scc_params* out)
{
    sdfccd_Status st;
    if (!in) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params is NULL", fn);
    if ((st = sdfccd__check_def(in->internal_value, fn, "params were", "sdfccd_default_query_params"))) return st;
    if ((int)in->method < 0 || in->method >= SDFCCD_METHOD_COUNT)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: unknown method %d", fn, (int)in->method);
#define POS(f) if (!isfinite(in->f) || !(in->f > 0.0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->" #f " must be finite and > 0 (got %g)", fn, in->f)
#define NONNEG(f) if (!isfinite(in->f) || in->f < 0.0) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->" #f " must be finite and >= 0 (got %g)", fn, in->f)
    POS(time_tolerance);
    POS(distance_tolerance);
    POS(max_rotation_per_segment);
    POS(certified_time_tolerance);
    NONNEG(subdivision_min_area);
    NONNEG(contact_slop);
    NONNEG(toi_window);
    NONNEG(fwgss_gap_tolerance);
#undef POS
#undef NONNEG
    if (!isfinite(in->margin)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->margin is not finite", fn);
    if (in->max_iterations < 1 || in->max_line_search_iterations < 1 || in->certified_max_regions < 1)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: iteration caps must be >= 1", fn);
    if (in->max_line_search_iterations > 4096)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->max_line_search_iterations must be <= 4096 (got %d)", fn,
                             in->max_line_search_iterations);
    if (in->max_sdf_evaluations < 1)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->max_sdf_evaluations must be >= 1 (got %lld)", fn,
                             (long long)in->max_sdf_evaluations);
    out->method = in->method == SDFCCD_METHOD_FWGSS ? SCC_METHOD_FWGSS
                : in->method == SDFCCD_METHOD_FW ? SCC_METHOD_FW
                : in->method == SDFCCD_METHOD_DCD ? SCC_METHOD_DCD : SCC_METHOD_CERTIFIED;
    out->margin = in->margin;
    out->time_tol = in->time_tolerance;
    out->dist_tol = in->distance_tolerance;
    out->max_iter = in->max_iterations;
    out->max_ls_iter = in->max_line_search_iterations;
    if (in->fwgss_restarts < 0 || in->fwgss_restarts > 2)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->fwgss_restarts must be 0, 1 or 2 (got %d)", fn, in->fwgss_restarts);
    out->fwgss_restarts = in->fwgss_restarts;
    if (in->fwgss_vertex_trace < 0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->fwgss_vertex_trace must be >= 0 (got %d)", fn, in->fwgss_vertex_trace);
    out->fwgss_vertex_trace = in->fwgss_vertex_trace;
    out->subdivision = in->subdivision != 0;
    out->sub_min_area = in->subdivision_min_area;
    if (in->subdivision_max_depth < 1 || in->subdivision_max_depth > 32)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->subdivision_max_depth must be in [1, 32] (got %d)", fn, in->subdivision_max_depth);
    out->sub_max_depth = in->subdivision_max_depth;
    out->contact_slop = in->contact_slop;
    out->toi_window = in->toi_window;
    out->max_rotation = in->max_rotation_per_segment;
    out->cert_time_tol = in->certified_time_tolerance;
    out->cert_max_regions = in->certified_max_regions;
    if (in->certified_max_bytes < 1)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->certified_max_bytes must be >= 1 (got %lld)", fn,
                             (long long)in->certified_max_bytes);
    out->cert_max_bytes = in->certified_max_bytes;
    out->broad_phase = in->broad_phase != 0;
    out->max_evals = in->max_sdf_evaluations;
    out->fwgss_secant = in->fwgss_secant_entry != 0;
    out->fwgss_speed_tol = in->fwgss_speed_tolerance != 0;
    out->fwgss_brent_spatial = in->fwgss_brent_spatial != 0;
    out->fwgss_gap_tol = in->fwgss_gap_tolerance;
    out->fwgss_deriv_spatial = in->fwgss_derivative_spatial != 0;
    out->fwgss_restart_at_witness = in->fwgss_restart_at_witness != 0;
    if (in->fwgss_clear_proof < 0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->fwgss_clear_proof must be >= 0 (got %d)", fn, in->fwgss_clear_proof);
    out->fwgss_clear_budget = in->fwgss_clear_proof;
    if (in->fwgss_kink_guard < 0 || in->fwgss_kink_guard > 2)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->fwgss_kink_guard must be 0, 1 or 2 (got %d)", fn, in->fwgss_kink_guard);
    out->fwgss_kink_guard = in->fwgss_kink_guard;
    if (in->fwgss_verify != 0 && in->fwgss_verify != 1)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: params->fwgss_verify must be 0 or 1 (got %d)", fn, in->fwgss_verify);
    out->fwgss_verify = in->fwgss_verify;
    return SDFCCD_OK;
}

/* Finite and within SDFCCD_MAX_QUERY_MAGNITUDE in every coordinate. */
static sdfccd_Status check_magnitude(sdfccd_Vec3 v, const char* what)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_vec(v, what))) return st;
    double m = scc_fmax(fabs(v.x), scc_fmax(fabs(v.y), fabs(v.z)));
    if (m > SDFCCD_MAX_QUERY_MAGNITUDE)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s has a coordinate of magnitude %g, above SDFCCD_MAX_QUERY_MAGNITUDE (%g)",
                             what, m, SDFCCD_MAX_QUERY_MAGNITUDE);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd__convert_motion(const sdfccd_RigidMotion* in, double t0, double t1, const char* what, scc_rigid* out)
{
    sdfccd_Status st;
    scc_xform xf;
    if ((st = sdfccd__check_pose(in->pose, what, &xf))) return st;
    if ((st = check_magnitude(in->pose.position, what)) || (st = check_magnitude(in->local_center, what)) ||
        (st = check_magnitude(in->linear_velocity, what)) || (st = check_magnitude(in->angular_velocity, what)))
        return st;
    /* Lengths of vectors within the magnitude limit do not overflow; t1 - t0 is finite (sdfccd__check_interval). */
    double dt = t1 - t0;
    double shift = scc_len(sdfccd__v(in->linear_velocity)) * dt;
    if (!(shift <= SDFCCD_MAX_QUERY_MAGNITUDE))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the displacement |v| (t1 - t0) = %g is above SDFCCD_MAX_QUERY_MAGNITUDE (%g)",
                             what, shift, SDFCCD_MAX_QUERY_MAGNITUDE);
    double angle = scc_len(sdfccd__v(in->angular_velocity)) * dt;
    if (!(angle <= SDFCCD_MAX_ROTATION_ANGLE))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the rotation |w| (t1 - t0) = %g rad is above SDFCCD_MAX_ROTATION_ANGLE (%g rad), "
                             "beyond which the motion model is not accurate", what, angle, SDFCCD_MAX_ROTATION_ANGLE);
    out->p0 = xf.p;
    out->q0 = xf.q;
    out->c_local = sdfccd__v(in->local_center);
    out->v = sdfccd__v(in->linear_velocity);
    out->w = sdfccd__v(in->angular_velocity);
    out->t0 = t0;
    return SDFCCD_OK;
}

/* The body's and the SDF's rotations add up: their sum must stay within SDFCCD_MAX_ROTATION_ANGLE. */
sdfccd_Status sdfccd__check_total_rotation(const scc_rigid* body, const scc_rigid* sdf, double dt, const char* fn)
{
    double angle = (scc_len(body->w) + (sdf ? scc_len(sdf->w) : 0.0)) * dt;
    if (!(angle <= SDFCCD_MAX_ROTATION_ANGLE))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the relative rotation over the interval (%g rad) is above "
                             "SDFCCD_MAX_ROTATION_ANGLE (%g rad), beyond which the motion model is not accurate",
                          fn, angle, SDFCCD_MAX_ROTATION_ANGLE);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd__check_mesh_bounds(const sdfccd__mesh* m, const char* fn)
{
    double b = scc_fmax(scc_maxc(scc_vabs(m->mesh.bounds.lo)), scc_maxc(scc_vabs(m->mesh.bounds.hi)));
    if (!(b <= SDFCCD_MAX_QUERY_MAGNITUDE))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the mesh has a vertex coordinate of magnitude %g, above SDFCCD_MAX_QUERY_MAGNITUDE (%g)",
                             fn, b, SDFCCD_MAX_QUERY_MAGNITUDE);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd__check_interval(double t0, double t1, const char* fn)
{
    if (!isfinite(t0) || !isfinite(t1)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: t0 and t1 must be finite (got %g, %g)", fn, t0, t1);
    if (t1 < t0) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: t1 (%g) < t0 (%g)", fn, t1, t0);
    if (!isfinite(t1 - t0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: t1 - t0 overflows (t0 = %g, t1 = %g)", fn, t0, t1);
    return SDFCCD_OK;
}

/* "fn: suffix" into out (size n, truncated like snprintf): the argument name in error messages.
 * Without snprintf's formatting cost (about 700 instructions), and built only when a check fails. */
static void what_name(char* out, size_t n, const char* fn, const char* suffix)
{
    size_t k = 0;
    for (const char* c = fn; *c && k + 1 < n; ++c) out[k++] = *c;
    for (const char* c = ": "; *c && k + 1 < n; ++c) out[k++] = *c;
    for (const char* c = suffix; *c && k + 1 < n; ++c) out[k++] = *c;
    out[k] = '\0';
}

/* sdfccd__check_ptr of the argument `arg` of fn, its name "fn: arg" built only when it is NULL. */
static sdfccd_Status check_arg(const void* ptr, const char* fn, const char* arg)
{
    if (ptr) return SDFCCD_OK;
    char what[96];
    what_name(what, sizeof what, fn, arg);
    return sdfccd__check_ptr(ptr, what);
}

/* The argument `arg` of fn, a motion, checked (not NULL) and converted (sdfccd__convert_motion). Its
 * name "fn: arg" for the error message is built only when the conversion fails, which then runs again
 * with it (about 480 instructions a query saved; same statuses and messages). */
static sdfccd_Status convert_arg(const sdfccd_RigidMotion* in, double t0, double t1, const char* fn, const char* arg, scc_rigid* out)
{
    sdfccd_Status st;
    if ((st = check_arg(in, fn, arg)) || sdfccd__convert_motion(in, t0, t1, fn, out) == SDFCCD_OK) return st;
    char what[96];
    what_name(what, sizeof what, fn, arg);
    return sdfccd__convert_motion(in, t0, t1, what, out);
}

/* Common prologue: out_result, params, interval, SDF handle (acquired) and SDF motion. */
typedef struct query_setup {
    scc_params p;
    sdfccd__sdf* sdf;
    scc_rigid sdf_motion;
    const scc_rigid* sdf_motion_ptr;
} query_setup;

static sdfccd_Status setup(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, double t0, double t1,
                           const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
                           sdfccd_QueryResult* out_result, const char* fn, query_setup* q)
{
    sdfccd_Status st;
    if ((st = check_arg(out_result, fn, "out_result"))) return st;
    if (capacity < 0 || (capacity > 0 && !out_contacts))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: out_contacts is NULL or capacity (%d) < 0", fn, capacity);
    if ((st = sdfccd__convert_params(params, fn, &q->p)) || (st = sdfccd__check_interval(t0, t1, fn))) return st;
    q->sdf_motion_ptr = NULL;
    if (sdf_motion) {
        if ((st = convert_arg(sdf_motion, t0, t1, fn, "sdf_motion", &q->sdf_motion))) return st;
        q->sdf_motion_ptr = &q->sdf_motion;
    }
    q->sdf = sdfccd__sdf_acquire(sdf); /* held until the public call returns (SDFCCD__HELD_CALL) */
    if (!q->sdf) return SDFCCD_INVALID_HANDLE;
    return SDFCCD_OK;
}

sdfccd_ResultState sdfccd__public_state(int s)
{
    switch (s) {
    case SCC_HIT: return SDFCCD_STATE_HIT;
    case SCC_PENETRATING: return SDFCCD_STATE_PENETRATING;
    case SCC_NOT_CONVERGED: return SDFCCD_STATE_NOT_CONVERGED;
    default: return SDFCCD_STATE_NO_HIT;
    }
}

/* Maps core results (SDF frame) to the public result (world frame). */
static void write_result(const query_setup* q, double t0, double t1, const scc_query_summary* s, const scc_contact* c,
                         sdfccd_Contact* out, int32_t capacity, sdfccd_QueryResult* r)
{
    r->state = sdfccd__public_state(s->state);
    r->hit = s->hit;
    r->toi = s->toi;
    r->toi_lower = s->toi_lower;
    r->fraction = t1 > t0 ? (s->toi - t0) / (t1 - t0) : 0.0;
    r->contacts_found = s->contacts_found;
    r->contact_count = s->contacts_written < capacity ? s->contacts_written : capacity; /* triangle queries stage more */
    r->iterations = s->iterations;
    r->sdf_evaluations = s->evals;
    r->triangles_tested = s->triangles_tested;
    for (int32_t i = 0; i < r->contact_count; ++i) {
        sdfccd_Contact* o = &out[i];
        o->point = sdfccd__pv(scc_world_point(q->sdf_motion_ptr, c[i].toi, c[i].point));
        o->normal = sdfccd__pv(scc_normalize_or(scc_world_vector(q->sdf_motion_ptr, c[i].toi, c[i].normal), scc_v3(0, 0, 1)));
        o->distance = c[i].distance;
        o->gap_t0 = c[i].gap_t0;
        o->toi = c[i].toi;
        for (int j = 0; j < 3; ++j) o->barycentric[j] = c[i].bary[j];
        o->triangle = c[i].triangle;
        o->kind = c[i].kind == SCC_CONTACT_PRIMARY ? SDFCCD_CONTACT_PRIMARY : SDFCCD_CONTACT_SUBDIVISION;
    }
}

/* The triangle query with the certified searches' scratch in `workspace`, or in a temporary
 * workspace freed before returning (NULL). */
static sdfccd_Status run_triangle(const query_setup* q, const scc_tri_motion* m, double t0, double t1, sdfccd_Workspace* workspace,
                                  sdfccd_Contact* out_contacts, int32_t capacity, sdfccd_QueryResult* out_result, const char* fn)
{
    scc_contact c[1 + SCC_MAX_SUBDIVISION_CONTACTS];
    scc_query_summary s;
    scc_workspace tmp;
    scc_ws_init(&tmp, sdfccd__allocator());
    const int ok = scc_query_triangle(q->sdf->sdf, m, t0, t1, &q->p, workspace ? &workspace->ws : &tmp, 0, c, 1 + SCC_MAX_SUBDIVISION_CONTACTS, &s);
    scc_ws_release(&tmp);
    if (!ok) return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory in the certified search", fn);
    write_result(q, t0, t1, &s, c, out_contacts, capacity, out_result);
    return SDFCCD_OK;
}

static sdfccd_Status query_triangle(sdfccd_Workspace* workspace, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, const sdfccd_Vec3 triangle[3],
                                    const sdfccd_RigidMotion* motion, double t0, double t1, const sdfccd_QueryParams* params,
                                    sdfccd_Contact* out_contacts, int32_t capacity, sdfccd_QueryResult* out_result)
{
    static const char fn[] = "sdfccd_query_triangle";
    query_setup q;
    sdfccd_Status st;
    if ((st = setup(sdf, sdf_motion, t0, t1, params, out_contacts, capacity, out_result, fn, &q))) return st;
    if ((st = sdfccd__check_ptr(triangle, "sdfccd_query_triangle: triangle")) || (st = sdfccd__check_ptr(motion, "sdfccd_query_triangle: motion")))
        return st;
    scc_rigid body;
    scc_tri_motion m;
    memset(&m, 0, sizeof m);
    for (int i = 0; i < 3; ++i) {
        if ((st = check_magnitude(triangle[i], "sdfccd_query_triangle: triangle vertex"))) return st;
        m.local[i] = sdfccd__v(triangle[i]);
    }
    if (scc_triangle_is_degenerate(m.local[0], m.local[1], m.local[2])) return sdfccd__error(SDFCCD_DEGENERATE, "%s: the triangle has zero area", fn);
    if ((st = sdfccd__convert_motion(motion, t0, t1, "sdfccd_query_triangle: motion", &body))) return st;
    if ((st = sdfccd__check_total_rotation(&body, q.sdf_motion_ptr, t1 - t0, fn))) return st;
    m.kind = SCC_TRI_RIGID;
    m.body = &body;
    m.sdf = q.sdf_motion_ptr;
    m.t0 = t0;
    m.t1 = t1;
    return run_triangle(&q, &m, t0, t1, workspace, out_contacts, capacity, out_result, fn);
}

static sdfccd_Status query_triangle_linear(sdfccd_Workspace* workspace, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, const sdfccd_Vec3 start[3],
                                           const sdfccd_Vec3 end[3], double t0, double t1, const sdfccd_QueryParams* params,
                                           sdfccd_Contact* out_contacts, int32_t capacity, sdfccd_QueryResult* out_result)
{
    static const char fn[] = "sdfccd_query_triangle_linear";
    query_setup q;
    sdfccd_Status st;
    if ((st = setup(sdf, sdf_motion, t0, t1, params, out_contacts, capacity, out_result, fn, &q))) return st;
    if ((st = sdfccd__check_ptr(start, "sdfccd_query_triangle_linear: start")) || (st = sdfccd__check_ptr(end, "sdfccd_query_triangle_linear: end")))
        return st;
    scc_tri_motion m;
    memset(&m, 0, sizeof m);
    for (int i = 0; i < 3; ++i) {
        if ((st = check_magnitude(start[i], "sdfccd_query_triangle_linear: start vertex")) ||
            (st = check_magnitude(end[i], "sdfccd_query_triangle_linear: end vertex")))
            return st;
        m.start[i] = sdfccd__v(start[i]);
        m.end[i] = sdfccd__v(end[i]);
    }
    if (scc_triangle_is_degenerate(m.start[0], m.start[1], m.start[2])) return sdfccd__error(SDFCCD_DEGENERATE, "%s: the triangle has zero area at t0", fn);
    m.kind = SCC_TRI_LINEAR;
    m.sdf = q.sdf_motion_ptr;
    m.t0 = t0;
    m.t1 = t1;
    return run_triangle(&q, &m, t0, t1, workspace, out_contacts, capacity, out_result, fn);
}

sdfccd_Status sdfccd_query_triangle(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, const sdfccd_Vec3 triangle[3],
                                    const sdfccd_RigidMotion* motion, double t0, double t1, const sdfccd_QueryParams* params,
                                    sdfccd_Contact* out_contacts, int32_t capacity, sdfccd_QueryResult* out_result)
{
    SDFCCD__HELD_CALL(query_triangle(NULL, sdf, sdf_motion, triangle, motion, t0, t1, params, out_contacts, capacity, out_result));
}

sdfccd_Status sdfccd_query_triangle_ws(sdfccd_Workspace* workspace, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
                                       const sdfccd_Vec3 triangle[3], const sdfccd_RigidMotion* motion, double t0, double t1,
                                       const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
                                       sdfccd_QueryResult* out_result)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(workspace, "sdfccd_query_triangle_ws: workspace"))) return st;
    SDFCCD__HELD_CALL(query_triangle(workspace, sdf, sdf_motion, triangle, motion, t0, t1, params, out_contacts, capacity, out_result));
}

sdfccd_Status sdfccd_query_triangle_linear(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, const sdfccd_Vec3 start[3],
                                           const sdfccd_Vec3 end[3], double t0, double t1, const sdfccd_QueryParams* params,
                                           sdfccd_Contact* out_contacts, int32_t capacity, sdfccd_QueryResult* out_result)
{
    SDFCCD__HELD_CALL(query_triangle_linear(NULL, sdf, sdf_motion, start, end, t0, t1, params, out_contacts, capacity, out_result));
}

sdfccd_Status sdfccd_query_triangle_linear_ws(sdfccd_Workspace* workspace, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
                                              const sdfccd_Vec3 start[3], const sdfccd_Vec3 end[3], double t0, double t1,
                                              const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
                                              sdfccd_QueryResult* out_result)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(workspace, "sdfccd_query_triangle_linear_ws: workspace"))) return st;
    SDFCCD__HELD_CALL(query_triangle_linear(workspace, sdf, sdf_motion, start, end, t0, t1, params, out_contacts, capacity, out_result));
}

sdfccd_Status sdfccd_create_workspace(sdfccd_Workspace** out_workspace)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_workspace, "sdfccd_create_workspace: out_workspace"))) return st;
    *out_workspace = NULL;
    sdfccd_Workspace* w = sdfccd__alloc(sizeof *w);
    if (!w) return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "sdfccd_create_workspace: out of memory");
    scc_ws_init(&w->ws, sdfccd__allocator());
    *out_workspace = w;
    return SDFCCD_OK;
}

void sdfccd_destroy_workspace(sdfccd_Workspace* workspace)
{
    if (!workspace) return;
    scc_ws_release(&workspace->ws);
    sdfccd__free(workspace, sizeof *workspace);
}

int64_t sdfccd_workspace_bytes(const sdfccd_Workspace* workspace)
{
    return workspace ? (int64_t)(sizeof *workspace + scc_ws_bytes(&workspace->ws)) : 0;
}

/* The mesh query in `ws` (a caller's, or a temporary one freed before returning). */
static sdfccd_Status run_mesh(const query_setup* q, const scc_mesh_motion* mm, scc_workspace* ws, sdfccd_Contact* out_contacts,
                              int32_t capacity, sdfccd_QueryResult* out_result, const char* fn)
{
    scc_contact* c = NULL;
    if (capacity > 0 && !(c = scc_ws_get(ws, SCC_WS_STAGING, (size_t)capacity * sizeof *c)))
        return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory", fn);
    scc_query_summary s;
    int ok = scc_query_mesh_ws(q->sdf->sdf, mm, &q->p, ws, c, capacity, &s);
    if (ok) write_result(q, mm->t0, mm->t1, &s, c, out_contacts, capacity, out_result);
    return ok ? SDFCCD_OK : sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory", fn);
}

static sdfccd_Status query_mesh(sdfccd_Workspace* workspace, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                const sdfccd_RigidMotion* motion, double t0, double t1, const sdfccd_QueryParams* params,
                                sdfccd_Contact* out_contacts, int32_t capacity, sdfccd_QueryResult* out_result, const char* fn)
{
    query_setup q;
    sdfccd_Status st;
    if ((st = setup(sdf, sdf_motion, t0, t1, params, out_contacts, capacity, out_result, fn, &q))) return st;
    scc_rigid body;
    if ((st = convert_arg(motion, t0, t1, fn, "motion", &body))) return st;
    if ((st = sdfccd__check_total_rotation(&body, q.sdf_motion_ptr, t1 - t0, fn))) return st;
    sdfccd__mesh* m = sdfccd__mesh_acquire(mesh);
    if (!m) return SDFCCD_INVALID_HANDLE;
    if ((st = sdfccd__check_mesh_bounds(m, fn))) return st;
    scc_mesh_motion mm = { &m->mesh, &body, NULL, NULL, q.sdf_motion_ptr, t0, t1, NULL, NULL };
    if (workspace) return run_mesh(&q, &mm, &workspace->ws, out_contacts, capacity, out_result, fn);
    scc_workspace tmp;
    scc_ws_init(&tmp, sdfccd__allocator());
    st = run_mesh(&q, &mm, &tmp, out_contacts, capacity, out_result, fn);
    scc_ws_release(&tmp);
    return st;
}

sdfccd_Status sdfccd_query_mesh(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                const sdfccd_RigidMotion* motion, double t0, double t1, const sdfccd_QueryParams* params,
                                sdfccd_Contact* out_contacts, int32_t capacity, sdfccd_QueryResult* out_result)
{
    SDFCCD__HELD_CALL(query_mesh(NULL, sdf, sdf_motion, mesh, motion, t0, t1, params, out_contacts, capacity, out_result, "sdfccd_query_mesh"));
}

sdfccd_Status sdfccd_query_mesh_ws(sdfccd_Workspace* workspace, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                   const sdfccd_RigidMotion* motion, double t0, double t1, const sdfccd_QueryParams* params,
                                   sdfccd_Contact* out_contacts, int32_t capacity, sdfccd_QueryResult* out_result)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(workspace, "sdfccd_query_mesh_ws: workspace"))) return st;
    SDFCCD__HELD_CALL(query_mesh(workspace, sdf, sdf_motion, mesh, motion, t0, t1, params, out_contacts, capacity, out_result, "sdfccd_query_mesh_ws"));
}

sdfccd_Status sdfccd__linear_vertices(const sdfccd__mesh* m, const sdfccd_Vec3* start, const sdfccd_Vec3* end, scc_workspace* ws,
                                      const char* fn, scc_vec3** out)
{
    uint32_t nv = m->mesh.vertex_count;
    for (uint32_t i = 0; i < nv; ++i) {
        const double c[6] = { start[i].x, start[i].y, start[i].z, end[i].x, end[i].y, end[i].z };
        for (int k = 0; k < 6; ++k)
            if (!(fabs(c[k]) <= SDFCCD_MAX_QUERY_MAGNITUDE))
                return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: vertex %u has a non-finite coordinate or one above SDFCCD_MAX_QUERY_MAGNITUDE", fn, i);
    }
    scc_vec3* v = scc_ws_get(ws, SCC_WS_VERTICES, 2 * (size_t)nv * sizeof(scc_vec3));
    if (!v) return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s: out of memory", fn);
    for (uint32_t i = 0; i < nv; ++i) {
        v[i] = sdfccd__v(start[i]);
        v[nv + i] = sdfccd__v(end[i]);
    }
    *out = v;
    return SDFCCD_OK;
}

static sdfccd_Status query_mesh_linear(sdfccd_Workspace* workspace, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
                                       sdfccd_MeshId mesh, const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0, double t1,
                                       const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
                                       sdfccd_QueryResult* out_result, const char* fn)
{
    query_setup q;
    sdfccd_Status st;
    if ((st = setup(sdf, sdf_motion, t0, t1, params, out_contacts, capacity, out_result, fn, &q))) return st;
    if ((st = check_arg(start, fn, "start")) || (st = check_arg(end, fn, "end"))) return st;
    sdfccd__mesh* m = sdfccd__mesh_acquire(mesh);
    if (!m) return SDFCCD_INVALID_HANDLE;
    uint32_t nv = m->mesh.vertex_count;
    scc_workspace tmp;
    scc_ws_init(&tmp, sdfccd__allocator());
    scc_workspace* ws = workspace ? &workspace->ws : &tmp;
    scc_vec3* v;
    if ((st = sdfccd__linear_vertices(m, start, end, ws, fn, &v))) {
        scc_ws_release(&tmp);
        return st;
    }
    scc_mesh_motion mm = { &m->mesh, NULL, v, v + nv, q.sdf_motion_ptr, t0, t1, NULL, NULL };
    st = run_mesh(&q, &mm, ws, out_contacts, capacity, out_result, fn);
    scc_ws_release(&tmp);
    return st;
}

sdfccd_Status sdfccd_query_mesh_linear(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh,
                                       const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0, double t1,
                                       const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
                                       sdfccd_QueryResult* out_result)
{
    SDFCCD__HELD_CALL(query_mesh_linear(NULL, sdf, sdf_motion, mesh, start, end, t0, t1, params, out_contacts, capacity, out_result,
                                "sdfccd_query_mesh_linear"));
}

sdfccd_Status sdfccd_query_mesh_linear_ws(sdfccd_Workspace* workspace, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
                                          sdfccd_MeshId mesh, const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0, double t1,
                                          const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
                                          sdfccd_QueryResult* out_result)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(workspace, "sdfccd_query_mesh_linear_ws: workspace"))) return st;
    SDFCCD__HELD_CALL(query_mesh_linear(workspace, sdf, sdf_motion, mesh, start, end, t0, t1, params, out_contacts, capacity, out_result,
                                "sdfccd_query_mesh_linear_ws"));
}
