/* SPDX-License-Identifier: MIT
 * sdfccd core: a triangle mesh as the solvers see it (borrowed arrays, no ownership). */
#ifndef SCC_MESH_H
#define SCC_MESH_H

#include <stdint.h>
#include "scc_math.h"

struct scc_bsh;

typedef struct scc_mesh {
    const scc_vec3* vertices;   /* local frame */
    const uint32_t* indices;    /* 3 per triangle, counter-clockwise */
    uint32_t vertex_count;
    uint32_t triangle_count;
    scc_aabb bounds;            /* local-frame box of the vertices */
    double radius;              /* largest distance of a vertex from the local origin, cached at creation;
                                   0 on a mesh made without it (the contact generator then computes it) */
    /* Optional prebuilt bounding-sphere hierarchy (bsh.h) over these triangles; NULL: the mesh
     * query builds a temporary one when params->broad_phase is set. */
    const struct scc_bsh* bsh;
} scc_mesh;

static inline void scc_mesh_triangle(const scc_mesh* m, uint32_t t, scc_vec3 out[3])
{
    out[0] = m->vertices[m->indices[3 * t + 0]];
    out[1] = m->vertices[m->indices[3 * t + 1]];
    out[2] = m->vertices[m->indices[3 * t + 2]];
}

/* Twice the area of triangle (a, b, c). */
static inline double scc_triangle_area2(scc_vec3 a, scc_vec3 b, scc_vec3 c)
{
    return scc_len(scc_cross(scc_sub(b, a), scc_sub(c, a)));
}

/* The one zero-area test (mesh creation and the triangle queries): true when twice the area is at
 * most 1e-12 times the larger squared edge from a (so the test does not depend on the unit), when
 * a coincides with b and c, or when a coordinate is NaN. */
static inline int scc_triangle_is_degenerate(scc_vec3 a, scc_vec3 b, scc_vec3 c)
{
    const double scale = fmax(scc_len2(scc_sub(b, a)), scc_len2(scc_sub(c, a)));
    return scale == 0.0 || !(scc_triangle_area2(a, b, c) > 1e-12 * scale);
}

#endif
