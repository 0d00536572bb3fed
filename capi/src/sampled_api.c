/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: an SDF compared with a field known by samples (sampled.h). */
#include "capi_internal.h"
#include "sdfccd/sampled.h"

#include <math.h>

sdfccd_Status sdfccd_sdf_compare_samples(sdfccd_SdfId sdf, sdfccd_SampleFcn* sample, void* user, sdfccd_Aabb box, int32_t n,
                                         double* out_max_difference, int32_t* out_compared)
{
    static const char fn[] = "sdfccd_sdf_compare_samples";
    sdfccd_Status st;
    if (!sample) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: sample is NULL", fn);
    if ((st = sdfccd__check_ptr(out_max_difference, "sdfccd_sdf_compare_samples: out_max_difference"))) return st;
    if (n < 1 || n > 256) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: n = %d is not in 1..256", fn, (int)n);
    const double lo[3] = { box.lo.x, box.lo.y, box.lo.z }, hi[3] = { box.hi.x, box.hi.y, box.hi.z };
    for (int k = 0; k < 3; ++k)
        if (!isfinite(lo[k]) || !isfinite(hi[k]) || !(hi[k] >= lo[k]))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the box is not finite with lo <= hi", fn);
    sdfccd_SdfInfo info;
    if ((st = sdfccd_sdf_get_info(sdf, &info)) != SDFCCD_OK) return st; /* a bad handle, even with no samples */
    double worst = 0;
    int32_t compared = 0;
    for (int32_t i = 0; i < n * n * n; ++i) {
        const int32_t c[3] = { i % n, i / n % n, i / (n * n) };
        double x[3];
        for (int k = 0; k < 3; ++k) x[k] = lo[k] + (hi[k] - lo[k]) * ((c[k] + 0.5) / n);
        const sdfccd_Vec3 p = { x[0], x[1], x[2] };
        double theirs = 0, ours = 0;
        if (!sample(p, &theirs, user)) continue;
        if ((st = sdfccd_sdf_eval(sdf, p, &ours, NULL)) != SDFCCD_OK) return st;
        const double d = isfinite(theirs) && isfinite(ours) ? fabs(ours - theirs) : INFINITY;
        if (d > worst) worst = d;
        ++compared;
    }
    *out_max_difference = worst;
    if (out_compared) *out_compared = compared;
    return SDFCCD_OK;
}

/* ---- an SDF from a sampled field ---- */
typedef struct sampled_sdf {
    scc_sdf base;
    sdfccd_SampleGradFcn* fn;
    void* user;
    double lo[3], hi[3]; /* the box shrunk by 1e-6 of its size per axis: where the samples are taken */
    scc_vec3 centre;
    double hole;
} sampled_sdf;

/* v / |v| as v * (1 / |v|); (0, 0, 1) for a zero or non-finite vector. */
static scc_vec3 unit_or_up(scc_vec3 v)
{
    const double l = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return l > 0.0 && isfinite(l) ? scc_scale(v, 1.0 / l) : scc_v3(0.0, 0.0, 1.0);
}

static double sampled_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* grad)
{
    const sampled_sdf* s = (const sampled_sdf*)self;
    double q[3] = { p.x, p.y, p.z };
    for (int k = 0; k < 3; ++k) { /* (comparisons as written: a NaN stays NaN) */
        if (q[k] < s->lo[k]) q[k] = s->lo[k];
        if (s->hi[k] < q[k]) q[k] = s->hi[k];
    }
    const scc_vec3 out = scc_v3(p.x - q[0], p.y - q[1], p.z - q[2]);
    const double outside = sqrt(out.x * out.x + out.y * out.y + out.z * out.z);
    double v = 0.0;
    sdfccd_Vec3 g = { 0.0, 0.0, 1.0 };
    const sdfccd_Vec3 at = { q[0], q[1], q[2] };
    scc_vec3 dir;
    if (s->fn(at, &v, &g, s->user)) {
        v += outside;
        dir = outside > 0.0 ? unit_or_up(scc_scale(out, 1.0 / outside)) : sdfccd__v(g);
        if (!scc_vfinite(dir)) dir = scc_v3(0.0, 0.0, 1.0); /* never hand NaN to a solver */
    } else {
        v = s->hole + outside; /* a cell without data (narrow-band grids): far from the surface by construction */
        dir = unit_or_up(scc_sub(p, s->centre));
    }
    if (grad) *grad = dir;
    return v;
}

sdfccd_Status sdfccd_create_sampled_sdf(sdfccd_SampleGradFcn* sample, void* user, sdfccd_Aabb box, double hole_value, sdfccd_SdfId* out_sdf)
{
    static const char fn[] = "sdfccd_create_sampled_sdf";
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_sdf, "sdfccd_create_sampled_sdf: out_sdf"))) return st;
    if (!sample) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: sample is NULL", fn);
    const double lo[3] = { box.lo.x, box.lo.y, box.lo.z }, hi[3] = { box.hi.x, box.hi.y, box.hi.z };
    for (int k = 0; k < 3; ++k)
        if (!isfinite(lo[k]) || !isfinite(hi[k]) || !(hi[k] >= lo[k]))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: the box is not finite with lo <= hi", fn);
    if (!isfinite(hole_value)) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: hole_value is not finite", fn);
    sdfccd__sdf* h = sdfccd__sdf_new(sizeof(sampled_sdf));
    if (!h) return sdfccd__oom("a sampled SDF");
    sampled_sdf* s = h->storage;
    s->base.eval = sampled_eval;
    s->base.lipschitz_in = NULL;
    s->base.domain.lo = scc_v3(-INFINITY, -INFINITY, -INFINITY);
    s->base.domain.hi = scc_v3(INFINITY, INFINITY, INFINITY);
    s->base.bounds = sdfccd__box(box);
    s->base.lipschitz = 1.0;
    s->base.convex = 0;
    s->base.convex_in = NULL;
    s->base.smooth = 0;
    s->base.kind = SCC_SDF_CALLBACK;
    s->fn = sample;
    s->user = user;
    for (int k = 0; k < 3; ++k) {
        const double eps = (hi[k] - lo[k]) * 1e-6;
        s->lo[k] = lo[k] + eps;
        s->hi[k] = hi[k] - eps;
    }
    s->centre = scc_v3((lo[0] + hi[0]) * 0.5, (lo[1] + hi[1]) * 0.5, (lo[2] + hi[2]) * 0.5);
    s->hole = hole_value;
    return sdfccd__sdf_register(h, out_sdf);
}
