/* SPDX-License-Identifier: MIT
 * sdfccd core: a user's field (sdf.h, sdf_user.h). */
#include "sdf_user.h"

double scc_sdf_user_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    return scc_sdf_user_value((const scc_sdf_user*)self, p, g);
}
