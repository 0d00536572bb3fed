/* SPDX-License-Identifier: MIT */
/** @file mesh.h  Triangle meshes: the moving geometry of a query; loading them from files, their
 * topology and exact signed distance to them.
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

/** Describes a mesh to create. Must be initialised with sdfccd_default_mesh_def(). */
typedef struct sdfccd_MeshDef {
    const double* vertices;   /**< 3 * vertex_count coordinates, x y z per vertex, local frame. */
    uint32_t vertex_count;    /**< Number of vertices (>= 3). */
    const uint32_t* indices;  /**< 3 * triangle_count vertex indices, counter-clockwise. */
    uint32_t triangle_count;  /**< Number of triangles (>= 1). */
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

/** Releases the handle. The mesh's memory is freed once no call in flight (on any thread) uses it. */
SDFCCD_API sdfccd_Status sdfccd_destroy_mesh(sdfccd_MeshId mesh);

/** What sdfccd_mesh_get_info() reports. */
typedef struct sdfccd_MeshInfo {
    uint32_t vertex_count;      /**< Vertices stored. */
    uint32_t triangle_count;    /**< Triangles kept (without dropped ones). */
    uint32_t dropped_triangles; /**< Degenerate triangles dropped at creation or import. */
    sdfccd_Aabb bounds;         /**< Local-frame bounding box. */
    int64_t memory_bytes;       /**< Bytes the mesh holds (arrays and broad-phase hierarchy). */
} sdfccd_MeshInfo;
/** Describes a mesh. */
SDFCCD_API sdfccd_Status sdfccd_mesh_get_info(sdfccd_MeshId mesh, sdfccd_MeshInfo* out_info);

/** Copies the mesh's data out: `out_vertices` (3 * vertex_count doubles) and `out_indices`
 * (3 * triangle_count); either may be NULL to skip it. Sizes come from sdfccd_mesh_get_info(). */
SDFCCD_API sdfccd_Status sdfccd_mesh_get_data(sdfccd_MeshId mesh, double* out_vertices, uint32_t* out_indices);

/* ------------------------------------------------------------------------------------------ */
/** @name Loading meshes from files */

/** How sdfccd_load_mesh() reads a file. Initialise with sdfccd_default_mesh_load_def(). */
typedef struct sdfccd_MeshLoadDef {
    double scale;             /**< Uniform factor applied to every position (file units to metres). Default 1. */
    /** 1 (default): vertices at exactly equal positions are merged into one, across the file's
     * sub-meshes, so seams of normals or texture coordinates do not open the surface. */
    int32_t merge_vertices;
    /** 1 (default): zero-area triangles (also those created by merging) are dropped and counted in
     * sdfccd_MeshInfo::dropped_triangles. 0: they are an error (::SDFCCD_DEGENERATE). */
    int32_t drop_degenerate;
    int32_t internal_value;   /**< Set by sdfccd_default_mesh_load_def(); do not change. */
    /** Largest file accepted (bytes, >= 1); a larger file gives ::SDFCCD_UNSUPPORTED before it is
     * parsed. Default 256 MiB. */
    int64_t max_file_bytes;
    /** Formats the caller accepts: file extensions separated by ';' (case-insensitive, e.g. "obj;stl").
     * A file with another extension gives ::SDFCCD_UNSUPPORTED without being opened. NULL (default):
     * every format. Use it to keep hostile files away from assimp's readers: assimp 5.2.5's PLY reader
     * can spin forever on a malformed 216-byte file, and no option of this call can bound that. */
    const char* formats;
} sdfccd_MeshLoadDef;

/** Defaults: scale 1, merge_vertices 1, drop_degenerate 1, max_file_bytes 256 MiB, every format. */
SDFCCD_API sdfccd_MeshLoadDef sdfccd_default_mesh_load_def(void);

/** Loads a triangle mesh from any format assimp reads (OBJ, PLY, STL, OFF, glTF, ...). Polygons
 * are triangulated, node transforms of the file are applied, and every sub-mesh is appended to
 * one mesh. Points and lines are ignored. `def` may be NULL for the defaults.
 * `.obj` files are read by a built-in reader in double precision (Debian's assimp stores
 * positions as float, which would round coordinates written with more digits): `v` and `f`
 * records only, polygons fan-triangulated, `i/t/n` and negative indices accepted, numbers parsed
 * with strtod (the C locale's '.' decimal point). Other formats go through assimp (float
 * positions).
 * assimp runs with its data-structure validation (aiProcess_ValidateDataStructure), so a file whose
 * counts and indices disagree is refused instead of reaching assimp's asserts (an OFF file declaring
 * more vertices than it holds aborted the process inside assimp's triangulation).
 * Errors: ::SDFCCD_IO_ERROR when the file cannot be opened or is not a regular file (a directory,
 * a device, a pipe); ::SDFCCD_UNSUPPORTED for a format not in `formats` or a file above
 * `max_file_bytes`; ::SDFCCD_FORMAT_ERROR when it cannot
 * be parsed (a bad OBJ record with its line number, or assimp's message); ::SDFCCD_DEGENERATE when
 * it holds no triangle; ::SDFCCD_UNSUPPORTED for a non-OBJ file when the library was built without
 * assimp (SDFCCD_WITH_ASSIMP=OFF). */
SDFCCD_API sdfccd_Status sdfccd_load_mesh(const char* path, const sdfccd_MeshLoadDef* def, sdfccd_MeshId* out_mesh);

/* ------------------------------------------------------------------------------------------ */
/** @name Exact mesh distance */

/** Topology as the sign of a mesh distance needs it. */
typedef struct sdfccd_MeshTopology {
    uint32_t boundary_edges;     /**< Edges used by one triangle (holes). */
    uint32_t nonmanifold_edges;  /**< Edges used by more than two triangles. */
    uint32_t inconsistent_edges; /**< Edges whose two triangles run in the same direction (flipped triangles). */
    double volume;               /**< Signed volume (m^3); positive for outward (counter-clockwise) triangles. */
    int32_t closed;              /**< 1 when there are no boundary, non-manifold or inconsistent edges. */
} sdfccd_MeshTopology;

/** Reports the mesh's topology. Signs of distances (and grids) are exact only for closed meshes with
 * positive volume. */
SDFCCD_API sdfccd_Status sdfccd_mesh_get_topology(sdfccd_MeshId mesh, sdfccd_MeshTopology* out_topology);

/** Exact signed distance from `count` points (mesh local frame) to the mesh: the magnitude is the
 * exact minimum over triangles, the sign comes from angle-weighted pseudonormals (negative inside).
 * `out_closest` (may be NULL) receives the nearest surface points. Builds a BVH per call, so batch
 * the points. Errors: ::SDFCCD_DEGENERATE when the mesh is not closed or has negative volume
 * (signs would be wrong) unless `allow_open` is 1 (then signs near holes are unreliable). */
SDFCCD_API sdfccd_Status sdfccd_mesh_signed_distance(sdfccd_MeshId mesh, const sdfccd_Vec3* points, int32_t count,
                                                     int32_t allow_open, double* out_distances, sdfccd_Vec3* out_closest);

#ifdef __cplusplus
}
#endif
#endif
