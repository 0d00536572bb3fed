/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: an SDF stretched along its axes (sdf.h, sdfccd_create_stretched; core/sdf_stretch.c). */
#include "capi_internal.h"
#include "../../core/sdf_stretch.h"

static sdfccd_Status create_stretched_held(sdfccd_SdfId child, sdfccd_Vec3 scale, sdfccd_SdfId* out_sdf)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_sdf, "sdfccd_create_stretched: out_sdf"))) return st;
    const double k[3] = { scale.x, scale.y, scale.z };
    for (int i = 0; i < 3; ++i) /* (NaN fails both comparisons) */
        if (!(k[i] >= 1e-100 && k[i] <= 1e100))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_create_stretched: scale must be in [1e-100, 1e100] per axis (got %g, %g, %g)",
                                 k[0], k[1], k[2]);
    sdfccd__sdf* c = sdfccd__sdf_acquire(child);
    if (!c) return SDFCCD_INVALID_HANDLE;
    sdfccd__sdf* s = sdfccd__sdf_new(sizeof(scc_sdf_stretch));
    if (!s) return sdfccd__oom("a stretched SDF");
    scc_sdf_stretch_init(s->storage, c->sdf, sdfccd__v(scale));
    sdfccd__sdf_retain(c);
    s->children[0] = c;
    return sdfccd__sdf_register(s, out_sdf);
}

sdfccd_Status sdfccd_create_stretched(sdfccd_SdfId child, sdfccd_Vec3 scale, sdfccd_SdfId* out_sdf)
{
    SDFCCD__HELD_CALL(create_stretched_held(child, scale, out_sdf));
}
