/* SPDX-License-Identifier: MIT
 * sdfccd core: a bounding-volume hierarchy (axis-aligned boxes) over the triangles of a
 * mesh for exact nearest-point queries, and the point-triangle closest point with its
 * nearest feature. */
#ifndef SCC_TRI_BVH_H
#define SCC_TRI_BVH_H

#include <stdint.h>
#include "alloc.h"
#include "mesh.h"

/* Nearest feature of a triangle (a, b, c) = vertices 0, 1, 2. */
typedef enum scc_tri_feature {
    SCC_TRI_V0 = 0, SCC_TRI_V1, SCC_TRI_V2,
    SCC_TRI_E01, SCC_TRI_E12, SCC_TRI_E20,
    SCC_TRI_FACE
} scc_tri_feature;

/* Closest point of triangle (a, b, c) to p (Voronoi-region walk). Returns the squared
 * distance, writes the point and the feature it lies on. Degenerate triangles give a point of
 * one of their edges. */
double scc_closest_point_triangle(scc_vec3 p, scc_vec3 a, scc_vec3 b, scc_vec3 c, scc_vec3* out_point, scc_tri_feature* out_feature);

typedef struct scc_tri_bvh_node {
    scc_aabb box;
    uint32_t first;   /* leaf: first slot in tris; inner: index of the left child (right = first + 1) */
    uint32_t count;   /* leaf: number of triangles (> 0); inner: 0 */
} scc_tri_bvh_node;

typedef struct scc_tri_bvh {
    scc_tri_bvh_node* nodes;
    uint32_t node_count, node_capacity;
    scc_vec3* tris;      /* 3 vertices per slot, in leaf order */
    scc_aabb* tri_boxes; /* box of each slot's triangle (a cheap lower bound before the exact test) */
    uint32_t* tri_index; /* mesh triangle of each slot */
    uint32_t tri_count;
    scc_allocator allocator;
} scc_tri_bvh;

/* Builds the hierarchy (median split on the longest axis of the centroid box, leaves of up
 * to 8 triangles). Returns 1 on success, 0 when out of memory. */
int scc_tri_bvh_build(scc_tri_bvh* bvh, const scc_allocator* a, const scc_mesh* mesh);
void scc_tri_bvh_destroy(scc_tri_bvh* bvh);

typedef struct scc_tri_nearest {
    double dist2;             /* squared distance */
    scc_vec3 point;           /* closest point on the mesh */
    uint32_t triangle;        /* mesh triangle index */
    uint32_t slot;            /* the triangle's slot in the hierarchy (a hint for the next query) */
    scc_tri_feature feature;  /* feature of that triangle */
} scc_tri_nearest;

/* Exact nearest triangle to p. Returns 1 and fills *out, or 0 when the mesh is empty. */
int scc_tri_bvh_nearest(const scc_tri_bvh* bvh, scc_vec3 p, scc_tri_nearest* out);
/* The same, starting from the distance to the triangle in slot `hint` (e.g. the answer for a
 * nearby point; UINT32_MAX for none), which prunes most of the tree at once. Exact either way. */
int scc_tri_bvh_nearest_hint(const scc_tri_bvh* bvh, scc_vec3 p, uint32_t hint, scc_tri_nearest* out);
/* The same, but only triangles nearer than sqrt(max_dist2) are looked for: returns 0 (and
 * leaves *out unspecified) when there is none, which is fast for points far from the mesh. */
int scc_tri_bvh_nearest_within(const scc_tri_bvh* bvh, scc_vec3 p, uint32_t hint, double max_dist2, scc_tri_nearest* out);

#endif
