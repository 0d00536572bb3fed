/* SPDX-License-Identifier: MIT
 * sdfccd core: exact signed distance to a closed triangle mesh: the nearest triangle from a
 * BVH and the sign from angle-weighted pseudonormals (Baerentzen and Aanaes, "Signed distance
 * computation using the angle weighted pseudonormal", IEEE TVCG 2005), plus the topology check
 * that tells whether the sign can be trusted. */
#ifndef SCC_MESH_DISTANCE_H
#define SCC_MESH_DISTANCE_H

#include "sdf.h"
#include "tri_bvh.h"

/* Topology of a mesh as the sign computation needs it. */
typedef struct scc_mesh_topology {
    uint32_t boundary_edges;     /* edges used by one triangle */
    uint32_t nonmanifold_edges;  /* edges used by more than two triangles */
    uint32_t inconsistent_edges; /* edges whose two triangles traverse it in the same direction */
    double volume;               /* signed volume (divergence theorem); > 0 for outward normals */
    int closed;                  /* 1 when every edge has exactly two consistently oriented triangles */
} scc_mesh_topology;

typedef struct scc_mesh_sdf {
    scc_sdf base;            /* first member; kind SCC_SDF_CALLBACK (exact, 1-Lipschitz) */
    const scc_mesh* mesh;    /* borrowed: must outlive this object */
    scc_tri_bvh bvh;
    scc_vec3* face_normal;   /* per triangle, unit */
    scc_vec3* edge_normal;   /* 3 per triangle (edges 01, 12, 20): normalised sum of the adjacent face normals */
    scc_vec3* vertex_normal; /* per vertex: normalised angle-weighted sum of incident face normals */
    scc_mesh_topology topology;
    scc_allocator allocator;
} scc_mesh_sdf;

/* Builds the BVH, the pseudonormals and the topology report. The sign is only meaningful when
 * topology.closed is set; the caller decides what to do otherwise. 1 on success, 0 on OOM. */
int scc_mesh_sdf_init(scc_mesh_sdf* m, const scc_allocator* a, const scc_mesh* mesh);
void scc_mesh_sdf_destroy(scc_mesh_sdf* m);

/* Signed distance of p (< 0 inside). *out_nearest (may be NULL) receives the nearest triangle,
 * its closest point and feature, and *out_normal (may be NULL) that feature's pseudonormal. An
 * empty mesh gives INFINITY, a zeroed nearest and the normal (0, 0, 1). */
double scc_mesh_sdf_query(const scc_mesh_sdf* m, scc_vec3 p, scc_tri_nearest* out_nearest, scc_vec3* out_normal);
/* The same with a caller-kept hint (start with UINT32_MAX; updated to the answer's BVH slot):
 * queries at nearby points in sequence run much faster. The result does not depend on it. */
double scc_mesh_sdf_query_hint(const scc_mesh_sdf* m, scc_vec3 p, uint32_t* hint, scc_tri_nearest* out_nearest,
                               scc_vec3* out_normal);
/* Signed distance when |distance| < cap; otherwise returns cap (sign not computed) without
 * searching further than cap. */
double scc_mesh_sdf_distance_capped(const scc_mesh_sdf* m, scc_vec3 p, uint32_t* hint, double cap);

/* Only the topology report (no BVH). 1 on success, 0 on OOM. */
int scc_mesh_topology_check(const scc_allocator* a, const scc_mesh* mesh, scc_mesh_topology* out);

#endif
