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
