/* SPDX-License-Identifier: MIT */
/** @file mesh.h  Triangle meshes: the moving geometry of a query.
 *
 * A mesh stores vertices in its own local frame (metres) and counter-clockwise triangles
 * (outward normals for closed meshes). The library copies the caller's arrays.
 */
#ifndef SDFCCD_MESH_H
#define SDFCCD_MESH_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Handle to a mesh. Generation-checked; a null handle has index1 == 0. */
typedef struct sdfccd_MeshId { uint32_t index1; uint32_t generation; } sdfccd_MeshId;

/** Describes a mesh to create. Must be initialised with sdfccd_default_mesh_def(). */
typedef struct sdfccd_MeshDef {
    const double* vertices;   /**< 3 * vertex_count coordinates, x y z per vertex, local frame. */
    uint32_t vertex_count;
    const uint32_t* indices;  /**< 3 * triangle_count vertex indices, counter-clockwise. */
    uint32_t triangle_count;
    /** 0 (default): a zero-area triangle is an error (::SDFCCD_DEGENERATE, the message names it).
     * 1: zero-area triangles are dropped and counted in sdfccd_MeshInfo::dropped_triangles. */
    int32_t drop_degenerate;
    int32_t internal_value; /**< Set by sdfccd_default_mesh_def(); do not change. */
} sdfccd_MeshDef;

/** Defaults: no data (must be set), drop_degenerate 0. */
SDFCCD_API sdfccd_MeshDef sdfccd_default_mesh_def(void);

/** Copies the arrays into a new mesh. Errors: NULL or non-finite data, an index out of range,
 * no triangles (::SDFCCD_DEGENERATE), a zero-area triangle unless dropped. */
SDFCCD_API sdfccd_Status sdfccd_create_mesh(const sdfccd_MeshDef* def, sdfccd_MeshId* out_mesh);

SDFCCD_API sdfccd_Status sdfccd_destroy_mesh(sdfccd_MeshId mesh);

typedef struct sdfccd_MeshInfo {
    uint32_t vertex_count;
    uint32_t triangle_count;
    uint32_t dropped_triangles; /**< Degenerate triangles dropped at creation or import. */
    sdfccd_Aabb bounds;         /**< Local-frame bounding box. */
    int64_t memory_bytes;
} sdfccd_MeshInfo;
SDFCCD_API sdfccd_Status sdfccd_mesh_get_info(sdfccd_MeshId mesh, sdfccd_MeshInfo* out_info);

/** Copies the mesh's data out: `out_vertices` (3 * vertex_count doubles) and `out_indices`
 * (3 * triangle_count); either may be NULL to skip it. Sizes come from sdfccd_mesh_get_info(). */
SDFCCD_API sdfccd_Status sdfccd_mesh_get_data(sdfccd_MeshId mesh, double* out_vertices, uint32_t* out_indices);

#ifdef __cplusplus
}
#endif
#endif
