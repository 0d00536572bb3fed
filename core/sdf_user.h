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

/* phi alone: one call of the user's function. */
static inline double scc_sdf_user_value(const scc_sdf_user* u, scc_vec3 p)
{
    const struct sdfccd_Vec3 q = { p.x, p.y, p.z };
    return ((scc_user_eval_fn*)u->fn)(q, NULL, u->user);
}

#endif
