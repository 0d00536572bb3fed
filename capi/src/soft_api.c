/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: the per-vertex linear motion part of contact.h. Validates the arguments and runs
 * the core's point path and distance certificates (core/soft.c). */
#include "capi_internal.h"
#include "../../core/soft.h"

#include <math.h>

static sdfccd_Status check_lipschitz(double lipschitz, const char* fn)
{
    if (isfinite(lipschitz) && lipschitz > 0) return SDFCCD_OK;
    return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: lipschitz = %g is not finite and > 0", fn, lipschitz);
}

static scc_cert to_cert(const sdfccd_DistanceCert* c)
{
    scc_cert r;
    for (int k = 0; k < 3; ++k) r.anchor[k] = sdfccd__v(c->anchor[k]);
    r.bound = c->bound;
    return r;
}

sdfccd_DistanceCert sdfccd_empty_distance_cert(void)
{
    sdfccd_DistanceCert c = { { { 0, 0, 0 }, { 0, 0, 0 }, { 0, 0, 0 } }, -INFINITY };
    return c;
}

sdfccd_Status sdfccd_distance_cert_bound(const sdfccd_DistanceCert* cert, const sdfccd_Vec3* start, const sdfccd_Vec3* end,
                                         int32_t count, double lipschitz, double* out_bound)
{
    static const char fn[] = "sdfccd_distance_cert_bound";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(cert, "sdfccd_distance_cert_bound: cert")) ||
        (st = sdfccd__check_ptr(start, "sdfccd_distance_cert_bound: start")) ||
        (st = sdfccd__check_ptr(end, "sdfccd_distance_cert_bound: end")) ||
        (st = sdfccd__check_ptr(out_bound, "sdfccd_distance_cert_bound: out_bound")) || (st = check_lipschitz(lipschitz, fn)))
        return st;
    if (count < 1 || count > 3) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: count = %d is not 1, 2 or 3", fn, (int)count);
    scc_vec3 s[3], e[3];
    for (int k = 0; k < count; ++k) {
        if ((st = sdfccd__check_vec(start[k], "sdfccd_distance_cert_bound: a start corner")) ||
            (st = sdfccd__check_vec(end[k], "sdfccd_distance_cert_bound: an end corner")))
            return st;
        s[k] = sdfccd__v(start[k]);
        e[k] = sdfccd__v(end[k]);
    }
    const scc_cert c = to_cert(cert);
    *out_bound = scc_cert_bound(&c, s, e, count, lipschitz);
    return SDFCCD_OK;
}

static sdfccd_Status point_first_hit_held(sdfccd_SdfId sdf, sdfccd_Vec3 start, sdfccd_Vec3 end, double level, double lipschitz,
                                          sdfccd_PointHit* out, int64_t* io_evals)
{
    static const char fn[] = "sdfccd_point_first_hit";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out, "sdfccd_point_first_hit: out")) || (st = sdfccd__check_vec(start, "sdfccd_point_first_hit: start")) ||
        (st = sdfccd__check_vec(end, "sdfccd_point_first_hit: end")) || (st = sdfccd__check_finite(level, "sdfccd_point_first_hit: level")) ||
        (st = check_lipschitz(lipschitz, fn)))
        return st;
    sdfccd__sdf* s = sdfccd__sdf_acquire(sdf);
    if (!s) return SDFCCD_INVALID_HANDLE;
    int64_t evals = 0;
    double f = 0, phi = 0, phi_a;
    scc_vec3 g = scc_v3(0, 0, 0);
    const int hit = scc_point_first_hit(s->sdf, sdfccd__v(start), sdfccd__v(end), level, lipschitz, &f, &phi, &g, &phi_a, &evals);
    out->hit = hit;
    out->fraction = hit ? f : 0;
    out->distance = hit ? phi : 0;
    out->gradient = hit ? sdfccd__pv(g) : sdfccd__pv(scc_v3(0, 0, 0));
    out->start_distance = phi_a;
    if (io_evals) *io_evals += evals;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_point_first_hit(sdfccd_SdfId sdf, sdfccd_Vec3 start, sdfccd_Vec3 end, double level, double lipschitz,
                                     sdfccd_PointHit* out, int64_t* io_sdf_evaluations)
{
    SDFCCD__HELD_CALL(point_first_hit_held(sdf, start, end, level, lipschitz, out, io_sdf_evaluations));
}

static sdfccd_Status triangle_clear_held(sdfccd_SdfId sdf, sdfccd_DistanceCert* cert, const sdfccd_Vec3* start, const sdfccd_Vec3* end,
                                         double level, double lipschitz, int32_t* out_clear, int64_t* io_evals)
{
    static const char fn[] = "sdfccd_triangle_clear";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(cert, "sdfccd_triangle_clear: cert")) || (st = sdfccd__check_ptr(start, "sdfccd_triangle_clear: start")) ||
        (st = sdfccd__check_ptr(end, "sdfccd_triangle_clear: end")) || (st = sdfccd__check_ptr(out_clear, "sdfccd_triangle_clear: out_clear")) ||
        (st = sdfccd__check_finite(level, "sdfccd_triangle_clear: level")) || (st = check_lipschitz(lipschitz, fn)))
        return st;
    scc_vec3 s[3], e[3];
    for (int k = 0; k < 3; ++k) {
        if ((st = sdfccd__check_vec(start[k], "sdfccd_triangle_clear: a start corner")) ||
            (st = sdfccd__check_vec(end[k], "sdfccd_triangle_clear: an end corner")))
            return st;
        s[k] = sdfccd__v(start[k]);
        e[k] = sdfccd__v(end[k]);
    }
    sdfccd__sdf* h = sdfccd__sdf_acquire(sdf);
    if (!h) return SDFCCD_INVALID_HANDLE;
    int64_t evals = 0;
    scc_cert c = to_cert(cert);
    *out_clear = scc_face_clear(h->sdf, &c, s, e, level, lipschitz, &evals);
    for (int k = 0; k < 3; ++k) cert->anchor[k] = sdfccd__pv(c.anchor[k]);
    cert->bound = c.bound;
    if (io_evals) *io_evals += evals;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_triangle_clear(sdfccd_SdfId sdf, sdfccd_DistanceCert* cert, const sdfccd_Vec3 start[3], const sdfccd_Vec3 end[3],
                                    double level, double lipschitz, int32_t* out_clear, int64_t* io_sdf_evaluations)
{
    SDFCCD__HELD_CALL(triangle_clear_held(sdf, cert, start, end, level, lipschitz, out_clear, io_sdf_evaluations));
}

static sdfccd_Status guard_point_held(sdfccd_SdfId sdf, const sdfccd_DistanceCert* cert, sdfccd_Vec3 start, sdfccd_Vec3 end, double tol,
                                     double lipschitz, sdfccd_PointGuard* out, int64_t* io_evals)
{
    static const char fn[] = "sdfccd_guard_point";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(cert, "sdfccd_guard_point: cert")) || (st = sdfccd__check_ptr(out, "sdfccd_guard_point: out")) ||
        (st = sdfccd__check_vec(start, "sdfccd_guard_point: start")) || (st = sdfccd__check_vec(end, "sdfccd_guard_point: end")) ||
        (st = check_lipschitz(lipschitz, fn)))
        return st;
    if (!(isfinite(tol) && tol > 0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: tolerance = %g is not finite and > 0", fn, tol);
    sdfccd__sdf* s = sdfccd__sdf_acquire(sdf);
    if (!s) return SDFCCD_INVALID_HANDLE;
    int64_t evals = 0;
    int clear = 0;
    double level = -tol, f = 0;
    scc_vec3 g = scc_v3(0, 0, 0);
    const scc_cert c = to_cert(cert);
    const int hit = scc_guard_point(s->sdf, &c, sdfccd__v(start), sdfccd__v(end), tol, lipschitz, &clear, &level, &f, &g, &evals);
    out->clear = clear;
    out->level = level;
    out->hit = hit;
    out->fraction = hit ? f : 0;
    out->gradient = hit ? sdfccd__pv(g) : sdfccd__pv(scc_v3(0, 0, 0));
    if (io_evals) *io_evals += evals;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_guard_point(sdfccd_SdfId sdf, const sdfccd_DistanceCert* cert, sdfccd_Vec3 start, sdfccd_Vec3 end, double tolerance,
                                 double lipschitz, sdfccd_PointGuard* out, int64_t* io_sdf_evaluations)
{
    SDFCCD__HELD_CALL(guard_point_held(sdf, cert, start, end, tolerance, lipschitz, out, io_sdf_evaluations));
}

static sdfccd_Status segment_first_hit_held(sdfccd_SdfId sdf, const sdfccd_Vec3* start, const sdfccd_Vec3* end, double level, double spacing,
                                           double lipschitz, sdfccd_PointHit* out, int64_t* io_evals)
{
    static const char fn[] = "sdfccd_segment_first_hit";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(start, "sdfccd_segment_first_hit: start")) || (st = sdfccd__check_ptr(end, "sdfccd_segment_first_hit: end")) ||
        (st = sdfccd__check_ptr(out, "sdfccd_segment_first_hit: out")) || (st = sdfccd__check_finite(level, "sdfccd_segment_first_hit: level")) ||
        (st = check_lipschitz(lipschitz, fn)))
        return st;
    for (int k = 0; k < 2; ++k)
        if ((st = sdfccd__check_vec(start[k], "sdfccd_segment_first_hit: a start end")) || (st = sdfccd__check_vec(end[k], "sdfccd_segment_first_hit: an end end")))
            return st;
    if (!(isfinite(spacing) && spacing > 0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: spacing = %g is not finite and > 0", fn, spacing);
    const scc_vec3 s0 = sdfccd__v(start[0]), s1 = sdfccd__v(start[1]), e0 = sdfccd__v(end[0]), e1 = sdfccd__v(end[1]);
    const double longest = fmax(scc_dist(s1, s0), scc_dist(e1, e0));
    if (!(longest / spacing <= 1e6)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: %g points (at most 1e6)", fn, longest / spacing);
    sdfccd__sdf* s = sdfccd__sdf_acquire(sdf);
    if (!s) return SDFCCD_INVALID_HANDLE;
    int64_t evals = 0;
    double f = 0;
    scc_vec3 g = scc_v3(0, 0, 0);
    const int hit = scc_segment_first_hit(s->sdf, s0, s1, e0, e1, level, spacing, lipschitz, &f, &g, &evals);
    out->hit = hit;
    out->fraction = hit ? f : 0;
    out->distance = 0;
    out->gradient = hit ? sdfccd__pv(g) : sdfccd__pv(scc_v3(0, 0, 0));
    out->start_distance = 0;
    if (io_evals) *io_evals += evals;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_segment_first_hit(sdfccd_SdfId sdf, const sdfccd_Vec3 start[2], const sdfccd_Vec3 end[2], double level, double spacing,
                                       double lipschitz, sdfccd_PointHit* out, int64_t* io_sdf_evaluations)
{
    SDFCCD__HELD_CALL(segment_first_hit_held(sdf, start, end, level, spacing, lipschitz, out, io_sdf_evaluations));
}

/* The soft guard's face rule (the bridge's guard, per face; Section 4 with per-vertex linear motion):
 * composed of the public certificate and triangle query, so the engine bridge only moves nodes. */
static sdfccd_Status guard_face_held(sdfccd_SdfId sdf, sdfccd_DistanceCert* cert, const sdfccd_Vec3* s, const sdfccd_Vec3* e, double level,
                                     double tol, double lipschitz, const sdfccd_QueryParams* params, double duration, int32_t last_pass,
                                     sdfccd_FaceGuard* out, int64_t* io_evals)
{
    static const char fn[] = "sdfccd_guard_face";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(params, "sdfccd_guard_face: params")) || (st = sdfccd__check_ptr(out, "sdfccd_guard_face: out")))
        return st;
    if (!(isfinite(tol) && tol > 0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: tolerance = %g is not finite and > 0", fn, tol);
    if (!(isfinite(duration) && duration > 0))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: duration = %g is not finite and > 0", fn, duration);
    int32_t clear = 0;
    int64_t evals = 0;
    if ((st = sdfccd_triangle_clear(sdf, cert, s, e, level, lipschitz, &clear, &evals))) return st;
    sdfccd_FaceGuard r = { 0, 0.0, 0, { 0, 0, 1 }, 0 };
    sdfccd_Contact c[8];
    sdfccd_QueryResult res;
    sdfccd_QueryParams qp = *params;
    qp.margin = level;
    if (!clear) {
        ++r.queries;
        if ((st = sdfccd_query_triangle_linear(sdf, NULL, s, e, 0.0, duration, &qp, c, 8, &res))) return st;
        evals += res.sdf_evaluations;
        if (res.state == SDFCCD_STATE_PENETRATING && res.contact_count > 0) {
            /* Started below the level: no deeper than its deepest start point (a level of start depth
             * minus the tolerance would let it sink that much every step). */
            double deepest = level;
            for (int j = 0; j < res.contact_count; ++j) deepest = fmin(deepest, c[j].distance);
            qp.margin = deepest - 0.1 * tol;
            ++r.queries;
            if ((st = sdfccd_query_triangle_linear(sdf, NULL, e, e, 0.0, duration, &qp, c, 8, &res))) return st;
            evals += res.sdf_evaluations;
            r.hit = res.hit ? 1 : 0;
        } else if (res.hit) {
            r.hit = r.stop = 1;
            r.normal = c[0].normal;
            r.fraction = last_pass ? 0.0 : res.fraction;
            if (r.fraction > 0) { /* back to where the face first came within half the tolerance */
                qp.margin = level + 0.5 * tol;
                ++r.queries;
                if ((st = sdfccd_query_triangle_linear(sdf, NULL, s, e, 0.0, duration, &qp, c, 8, &res))) return st;
                evals += res.sdf_evaluations;
                if (res.hit) r.fraction = fmin(r.fraction, res.state == SDFCCD_STATE_PENETRATING ? 0.0 : res.fraction);
            }
        }
    }
    *out = r;
    if (io_evals) *io_evals += evals;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_guard_face(sdfccd_SdfId sdf, sdfccd_DistanceCert* cert, const sdfccd_Vec3 start[3], const sdfccd_Vec3 end[3], double level,
                                double tolerance, double lipschitz, const sdfccd_QueryParams* params, double duration, int32_t last_pass, sdfccd_FaceGuard* out,
                                int64_t* io_sdf_evaluations)
{
    SDFCCD__HELD_CALL(guard_face_held(sdf, cert, start, end, level, tolerance, lipschitz, params, duration, last_pass, out, io_sdf_evaluations));
}
