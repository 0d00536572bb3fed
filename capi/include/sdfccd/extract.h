/* SPDX-License-Identifier: MIT */
/** @file extract.h  Isosurface extraction: an SDF's zero level set as a triangle mesh.
 *
 * Uses: a triangulation of an SDF for engines whose other paths need triangles (the Bullet
 * bridge's processAllTriangles, ray tests), visualisation, and benchmarks that compare mesh-mesh
 * collision with mesh-SDF collision.
 */
#ifndef SDFCCD_EXTRACT_H
#define SDFCCD_EXTRACT_H

#include "mesh.h"
#include "sdf.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Memory limit of sdfccd_extract_isosurface (bytes): about 8 (resolution + 1)^3 bytes are needed,
 * checked before allocating (::SDFCCD_OUT_OF_MEMORY with the figure); 1 GiB allows resolution 511. */
#define SDFCCD_EXTRACT_MAX_BYTES 1073741824.0

/** Extracts the surface phi = 0 of `sdf` inside `box` (SDF local frame, metres) into a new mesh.
 *
 * `resolution` (1..1024) is the number of grid cells along the box's longest axis; cells are
 * nearly cubic. The method is marching tetrahedra on that grid with vertices placed on the true
 * surface by a root search along grid edges, so every vertex lies on phi = 0 to about 1e-9 of a
 * cell (or within 1e-3 of a cell where the surface passes through a grid node). The mesh is
 * closed and counter-clockwise seen from outside: where the solid reaches the box's faces it is
 * capped within one cell outside the box. Features thinner than a cell can be lost.
 * Cost: (resolution + 3)^3 SDF evaluations (roughly) plus a few per surface vertex.
 *
 * Errors: ::SDFCCD_INVALID_HANDLE for a bad SDF; ::SDFCCD_INVALID_ARGUMENT for a NULL out_mesh,
 * a non-finite or empty box, or a resolution out of range; ::SDFCCD_DEGENERATE when the box
 * contains no surface; ::SDFCCD_OUT_OF_MEMORY. On success the caller owns `*out_mesh`
 * (sdfccd_destroy_mesh). Near-degenerate slivers that the mesh validation rejects are dropped
 * and counted in sdfccd_MeshInfo::dropped_triangles (0 in the tests' scenes). */
SDFCCD_API sdfccd_Status sdfccd_extract_isosurface(sdfccd_SdfId sdf, sdfccd_Aabb box, int32_t resolution,
                                                   sdfccd_MeshId* out_mesh);

#ifdef __cplusplus
}
#endif
#endif
