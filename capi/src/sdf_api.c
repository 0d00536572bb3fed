/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: creating, combining, evaluating and describing SDF handles. */
#include "capi_internal.h"
#include "../../core/grid.h"
#include "../../core/sdf_analytic.h"

#include <stdio.h>
#include <string.h>


static sdfccd_Status positive(double v, const char* what)
{
    if (!isfinite(v) || !(v > 0.0)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s must be finite and > 0 (got %g)", what, v);
    return SDFCCD_OK;
}

/* Allocates storage of `size` for a new shape; NULL with an OOM message. */
static sdfccd__sdf* new_shape(size_t size, const char* what)
{
    sdfccd__sdf* s = sdfccd__sdf_new(size);
    if (!s) sdfccd__oom(what);
    return s;
}

sdfccd_Status sdfccd_create_sphere(double radius, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_sdf, "sdfccd_create_sphere: out_sdf")) || (st = positive(radius, "sdfccd_create_sphere: radius"))) return st;
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_sphere), "a sphere");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_sdf_sphere_init(s->storage, radius);
    return sdfccd__sdf_register(s, out_sdf);
}

static sdfccd_Status make_box(sdfccd_Vec3 half, double radius, const char* fn, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    char what[96];
    if ((st = sdfccd__check_ptr(out_sdf, fn))) return st;
    snprintf(what, sizeof what, "%s: half.x", fn);
    if ((st = positive(half.x, what))) return st;
    snprintf(what, sizeof what, "%s: half.y", fn);
    if ((st = positive(half.y, what))) return st;
    snprintf(what, sizeof what, "%s: half.z", fn);
    if ((st = positive(half.z, what))) return st;
    double m = fmin(half.x, fmin(half.y, half.z));
    if (!isfinite(radius) || radius < 0.0 || radius > m)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: radius must be in [0, %g] (got %g)", fn, m, radius);
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_box), "a box");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_sdf_box_init(s->storage, sdfccd__v(half), radius);
    return sdfccd__sdf_register(s, out_sdf);
}

sdfccd_Status sdfccd_create_box(sdfccd_Vec3 half, sdfccd_SdfId* out_sdf)
{
    return make_box(half, 0.0, "sdfccd_create_box", out_sdf);
}

sdfccd_Status sdfccd_create_rounded_box(sdfccd_Vec3 half, double radius, sdfccd_SdfId* out_sdf)
{
    return make_box(half, radius, "sdfccd_create_rounded_box", out_sdf);
}

sdfccd_Status sdfccd_create_torus(double major, double minor, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_sdf, "sdfccd_create_torus: out_sdf")) || (st = positive(major, "sdfccd_create_torus: major")) ||
        (st = positive(minor, "sdfccd_create_torus: minor")))
        return st;
    if (!(minor < major)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_torus: minor (%g) must be < major (%g)", minor, major);
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_torus), "a torus");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_sdf_torus_init(s->storage, major, minor);
    return sdfccd__sdf_register(s, out_sdf);
}

sdfccd_Status sdfccd_create_capsule(double half_height, double radius, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_sdf, "sdfccd_create_capsule: out_sdf")) || (st = positive(radius, "sdfccd_create_capsule: radius")))
        return st;
    if (!isfinite(half_height) || half_height < 0.0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_capsule: half_height must be finite and >= 0 (got %g)", half_height);
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_capsule), "a capsule");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_sdf_capsule_init(s->storage, half_height, radius);
    return sdfccd__sdf_register(s, out_sdf);
}

sdfccd_Status sdfccd_create_cylinder(double half_height, double radius, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_sdf, "sdfccd_create_cylinder: out_sdf")) || (st = positive(radius, "sdfccd_create_cylinder: radius")) ||
        (st = positive(half_height, "sdfccd_create_cylinder: half_height")))
        return st;
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_cylinder), "a cylinder");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_sdf_cylinder_init(s->storage, half_height, radius);
    return sdfccd__sdf_register(s, out_sdf);
}

sdfccd_Status sdfccd_create_half_space(sdfccd_Vec3 normal, double offset, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_sdf, "sdfccd_create_half_space: out_sdf")) || (st = sdfccd__check_vec(normal, "sdfccd_create_half_space: normal")) ||
        (st = sdfccd__check_finite(offset, "sdfccd_create_half_space: offset")))
        return st;
    double l = sqrt(normal.x * normal.x + normal.y * normal.y + normal.z * normal.z);
    if (!(l > 1e-12)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_half_space: normal has zero length");
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_half_space), "a half-space");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_sdf_half_space_init(s->storage, scc_scale(sdfccd__v(normal), 1.0 / l), offset / l);
    return sdfccd__sdf_register(s, out_sdf);
}

sdfccd_Status sdfccd_create_spike_grid(const sdfccd_SpikeGridDef* def, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    if ((st = SDFCCD__CHECK_DEF_ARGS("sdfccd_create_spike_grid", def, out_sdf, "out_sdf", "sdfccd_default_spike_grid_def"))) return st;
    if ((st = positive(def->spacing, "spike grid spacing")) || (st = positive(def->base_radius, "spike grid base_radius")) ||
        (st = positive(def->height, "spike grid height")))
        return st;
    if (def->base_radius > 0.5 * def->spacing)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_spike_grid: base_radius (%g) must be <= spacing / 2 (%g)", def->base_radius, 0.5 * def->spacing);
    if (def->count_x < 1 || def->count_y < 1 || def->count_x > 100000 || def->count_y > 100000)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_spike_grid: counts must be in [1, 100000] (got %d x %d)", def->count_x, def->count_y);
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_spike_grid), "a spike grid");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_sdf_spike_grid_init(s->storage, def->spacing, def->base_radius, def->height, def->count_x, def->count_y);
    return sdfccd__sdf_register(s, out_sdf);
}

static sdfccd_Status create_csg_held(sdfccd_CsgOp op, sdfccd_SdfId a, sdfccd_SdfId b, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_sdf, "sdfccd_create_csg: out_sdf"))) return st;
    if (op != SDFCCD_CSG_UNION && op != SDFCCD_CSG_INTERSECTION && op != SDFCCD_CSG_DIFFERENCE)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_csg: unknown operation %d", (int)op);
    sdfccd__sdf* sa = sdfccd__sdf_acquire(a);
    if (!sa) return SDFCCD_INVALID_HANDLE;
    sdfccd__sdf* sb = sdfccd__sdf_acquire(b);
    if (!sb) return SDFCCD_INVALID_HANDLE;
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_csg), "a CSG combination");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_csg_op cop = op == SDFCCD_CSG_UNION ? SCC_CSG_UNION : op == SDFCCD_CSG_INTERSECTION ? SCC_CSG_INTERSECTION : SCC_CSG_DIFFERENCE;
    scc_sdf_csg_init(s->storage, cop, sa->sdf, sb->sdf);
    sdfccd__sdf_retain(sa);
    sdfccd__sdf_retain(sb);
    s->children[0] = sa;
    s->children[1] = sb;
    return sdfccd__sdf_register(s, out_sdf);
}

sdfccd_Status sdfccd_create_csg(sdfccd_CsgOp op, sdfccd_SdfId a, sdfccd_SdfId b, sdfccd_SdfId* out_sdf)
{
    SDFCCD__HELD_CALL(create_csg_held(op, a, b, out_sdf));
}

/* Validates a pose and returns it as a core transform with a normalised rotation. */
sdfccd_Status sdfccd__check_pose(sdfccd_Pose pose, const char* what, scc_xform* out)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_vec(pose.position, what))) return st;
    sdfccd_Quat q = pose.orientation;
    if (!isfinite(q.w) || !isfinite(q.x) || !isfinite(q.y) || !isfinite(q.z))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: orientation is not finite", what);
    scc_quat cq = { q.w, q.x, q.y, q.z };
    if (!(scc_quat_norm(cq) > 1e-12)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: orientation is a zero quaternion", what);
    out->q = scc_quat_normalize(cq);
    out->p = sdfccd__v(pose.position);
    return SDFCCD_OK;
}

static sdfccd_Status create_transformed_held(sdfccd_SdfId child, sdfccd_Pose pose, double scale, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    scc_xform xf;
    if ((st = sdfccd__check_ptr(out_sdf, "sdfccd_create_transformed: out_sdf")) || (st = positive(scale, "sdfccd_create_transformed: scale")) ||
        (st = sdfccd__check_pose(pose, "sdfccd_create_transformed: pose", &xf)))
        return st;
    /* Beyond these, x / scale or scale * phi overflows for ordinary points (a scale of 1e-200 made
     * every evaluation NaN). */
    if (scale < 1e-100 || scale > 1e100)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_transformed: scale must be in [1e-100, 1e100] (got %g)", scale);
    if (fmax(fabs(pose.position.x), fmax(fabs(pose.position.y), fabs(pose.position.z))) > 1e150)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_transformed: pose position has a coordinate above 1e150");
    sdfccd__sdf* c = sdfccd__sdf_acquire(child);
    if (!c) return SDFCCD_INVALID_HANDLE;
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_transform), "a transformed SDF");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_sdf_transform_init(s->storage, c->sdf, xf, scale);
    sdfccd__sdf_retain(c);
    s->children[0] = c;
    return sdfccd__sdf_register(s, out_sdf);
}

sdfccd_Status sdfccd_create_transformed(sdfccd_SdfId child, sdfccd_Pose pose, double scale, sdfccd_SdfId* out_sdf)
{
    SDFCCD__HELD_CALL(create_transformed_held(child, pose, scale, out_sdf));
}

/* ---- user callbacks: scc_sdf_user (core/sdf.h), whose eval calls the user's function ---- */
sdfccd_Status sdfccd_create_callback_sdf(const sdfccd_CallbackSdfDef* def, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    if ((st = SDFCCD__CHECK_DEF_ARGS("sdfccd_create_callback_sdf", def, out_sdf, "out_sdf", "sdfccd_default_callback_sdf_def"))) return st;
    if (!def->eval && !def->eval_xyz)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_callback_sdf: def->eval and def->eval_xyz are NULL (set one)");
    if (def->eval && def->eval_xyz)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_callback_sdf: def->eval and def->eval_xyz are both set (set one)");
    if ((st = positive(def->lipschitz, "sdfccd_create_callback_sdf: lipschitz"))) return st;
    if (isnan(def->bounds.lo.x) || isnan(def->bounds.lo.y) || isnan(def->bounds.lo.z) || isnan(def->bounds.hi.x) ||
        isnan(def->bounds.hi.y) || isnan(def->bounds.hi.z))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_callback_sdf: bounds contain NaN");
    if (def->smooth != 0 && def->smooth != 1)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_callback_sdf: smooth must be 0 or 1 (got %d)", (int)def->smooth);
    sdfccd__sdf* s = new_shape(sizeof(scc_sdf_user), "a callback SDF");
    if (!s) return SDFCCD_OUT_OF_MEMORY;
    scc_sdf_user* c = s->storage;
    c->base.eval = scc_sdf_user_eval;
    c->base.lipschitz_in = NULL;
    c->base.domain.lo = scc_v3(-INFINITY, -INFINITY, -INFINITY);
    c->base.domain.hi = scc_v3(INFINITY, INFINITY, INFINITY);
    c->base.bounds = sdfccd__box(def->bounds);
    c->base.lipschitz = def->lipschitz;
    c->base.convex = 0;
    c->base.convex_in = NULL;
    c->base.smooth = def->smooth;
    c->base.kind = SCC_SDF_CALLBACK;
    c->fn = (scc_generic_fn*)def->eval;
    c->fn_xyz = (scc_generic_fn*)def->eval_xyz;
    c->user = def->user;
    return sdfccd__sdf_register(s, out_sdf);
}

static sdfccd_Status sdf_eval_held(sdfccd_SdfId sdf, sdfccd_Vec3 p, double* out_value, sdfccd_Vec3* out_grad)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_value, "sdfccd_sdf_eval: out_value")) || (st = sdfccd__check_vec(p, "sdfccd_sdf_eval: p"))) return st;
    sdfccd__sdf* s = sdfccd__sdf_acquire(sdf);
    if (!s) return SDFCCD_INVALID_HANDLE;
    scc_vec3 g;
    *out_value = scc_sdf_eval(s->sdf, sdfccd__v(p), out_grad ? &g : NULL);
    if (out_grad) *out_grad = sdfccd__pv(g);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_sdf_eval(sdfccd_SdfId sdf, sdfccd_Vec3 p, double* out_value, sdfccd_Vec3* out_grad)
{
    SDFCCD__HELD_CALL(sdf_eval_held(sdf, p, out_value, out_grad));
}

static sdfccd_Status sdf_eval_batch_held(sdfccd_SdfId sdf, const sdfccd_Vec3* points, int32_t count, double* out_values,
                                     sdfccd_Vec3* out_grads)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_points("sdfccd_sdf_eval_batch", points, count, out_values, "out_values"))) return st;
    sdfccd__sdf* s = sdfccd__sdf_acquire(sdf);
    if (!s) return SDFCCD_INVALID_HANDLE;
    if (s->sdf->kind == SCC_SDF_GRID) { /* grids: the batch evaluator (core/grid.c), 64 points at a time */
        scc_vec3 p[64], g[64];
        for (int32_t i = 0; i < count; i += 64) {
            const int32_t n = count - i < 64 ? count - i : 64;
            for (int32_t k = 0; k < n; ++k) p[k] = sdfccd__v(points[i + k]);
            scc_grid_eval_batch((const scc_grid*)s->sdf, p, (size_t)n, out_values + i, out_grads ? g : NULL);
            for (int32_t k = 0; out_grads && k < n; ++k) out_grads[i + k] = sdfccd__pv(g[k]);
        }
        return SDFCCD_OK;
    }
    for (int32_t i = 0; i < count; ++i) {
        scc_vec3 g;
        out_values[i] = scc_sdf_eval(s->sdf, sdfccd__v(points[i]), out_grads ? &g : NULL);
        if (out_grads) out_grads[i] = sdfccd__pv(g);
    }
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_sdf_eval_batch(sdfccd_SdfId sdf, const sdfccd_Vec3* points, int32_t count, double* out_values,
                                     sdfccd_Vec3* out_grads)
{
    SDFCCD__HELD_CALL(sdf_eval_batch_held(sdf, points, count, out_values, out_grads));
}

static sdfccd_Status sdf_get_info_held(sdfccd_SdfId sdf, sdfccd_SdfInfo* out_info)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_info, "sdfccd_sdf_get_info: out_info"))) return st;
    sdfccd__sdf* s = sdfccd__sdf_acquire(sdf);
    if (!s) return SDFCCD_INVALID_HANDLE;
    out_info->kind = (sdfccd_SdfKind)s->sdf->kind;
    out_info->domain = sdfccd__pbox(s->sdf->domain);
    out_info->bounds = sdfccd__pbox(s->sdf->bounds);
    out_info->lipschitz = s->sdf->lipschitz;
    out_info->memory_bytes = s->memory_bytes + (int64_t)sizeof *s;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_sdf_get_info(sdfccd_SdfId sdf, sdfccd_SdfInfo* out_info)
{
    SDFCCD__HELD_CALL(sdf_get_info_held(sdf, out_info));
}
