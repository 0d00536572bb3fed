/* SPDX-License-Identifier: MIT
 * sdfccd core: a user's field (sdf.h, sdf_user.h). */
#include "sdf_user.h"

double scc_sdf_user_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    const scc_sdf_user* u = (const scc_sdf_user*)self;
    if (!g) return scc_sdf_user_value(u, p); /* most samples: no gradient, nothing to check */
    struct sdfccd_Vec3 q = { p.x, p.y, p.z }, gp = { 0.0, 0.0, 1.0 };
    const double v = ((scc_user_eval_fn*)u->fn)(q, &gp, u->user);
    *g = scc_v3(gp.x, gp.y, gp.z);
    if (!scc_vfinite(*g)) *g = scc_v3(0.0, 0.0, 1.0);
    return v;
}
