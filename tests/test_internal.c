/* SPDX-License-Identifier: MIT
 * Test support for the suites that use internals (see test_internal.h). */
#include "test_internal.h"

#include <math.h>

double test_winding_number(const scc_mesh* m, scc_vec3 p)
{
    double w = 0;
    for (uint32_t t = 0; t < m->triangle_count; ++t) {
        scc_vec3 v[3];
        scc_mesh_triangle(m, t, v);
        const scc_vec3 a = scc_sub(v[0], p), b = scc_sub(v[1], p), c = scc_sub(v[2], p);
        const double la = scc_len(a), lb = scc_len(b), lc = scc_len(c);
        const double num = scc_dot(a, scc_cross(b, c));
        const double den = la * lb * lc + scc_dot(a, b) * lc + scc_dot(b, c) * la + scc_dot(c, a) * lb;
        w += 2.0 * atan2(num, den);
    }
    return w / (4.0 * SCC_PI);
}
