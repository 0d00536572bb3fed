/* SPDX-License-Identifier: MIT
 * sdfccd core: calling a user's field (scc_sdf_user, sdf.h) with the public API's function type.
 * Included by core sources only: the public headers define sdfccd_Vec3 themselves. */
#ifndef SCC_SDF_USER_H
#define SCC_SDF_USER_H

#include "sdf.h"

/* The public API's point type (sdfccd/types.h), declared with the same tag and members: types
 * compatible across translation units (C11 6.2.7), so the user's sdfccd_SdfEvalFcn is called through
 * a pointer of its own type. */
struct sdfccd_Vec3 {
    double x;
    double y;
    double z;
};
typedef double scc_user_eval_fn(struct sdfccd_Vec3 p, struct sdfccd_Vec3* out_grad, void* user);
typedef double scc_user_eval_xyz_fn(double x, double y, double z, struct sdfccd_Vec3* out_grad, void* user);

/* One call of the user's function, in whichever of the two forms it has. */
static inline double scc_sdf_user_call(const scc_sdf_user* u, scc_vec3 p, struct sdfccd_Vec3* g)
{
    if (u->fn_xyz) return ((scc_user_eval_xyz_fn*)u->fn_xyz)(p.x, p.y, p.z, g, u->user);
    const struct sdfccd_Vec3 q = { p.x, p.y, p.z };
    return ((scc_user_eval_fn*)u->fn)(q, g, u->user);
}

/* phi, and its gradient when g is not NULL: (0, 0, 1) where the function leaves it unset or writes a
 * non-finite one (never NaN to a solver). One call of the user's function. */
static inline double scc_sdf_user_value(const scc_sdf_user* u, scc_vec3 p, scc_vec3* g)
{
    if (!g) return scc_sdf_user_call(u, p, NULL); /* most samples: nothing to check */
    struct sdfccd_Vec3 gp = { 0.0, 0.0, 1.0 };
    const double v = scc_sdf_user_call(u, p, &gp);
    *g = scc_v3(gp.x, gp.y, gp.z);
    /* finite: x - x is 0 for a finite x and NaN for an infinite or NaN one (scc_vfinite in one test) */
    if (!((gp.x - gp.x) + (gp.y - gp.y) + (gp.z - gp.z) == 0.0)) *g = scc_v3(0.0, 0.0, 1.0);
    return v;
}

#endif
