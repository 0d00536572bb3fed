/* SPDX-License-Identifier: MIT */
/** @file grid.h  Grid SDFs built in-tree (from meshes or SDFs) and Discregrid `.cdf` files.
 *
 * A grid SDF samples a signed distance on Discregrid's cubic Lagrange grid: every cell is a
 * 32-node serendipity element (8 corners, 2 nodes on each edge), and the field is C0 across
 * cells. Grids are SDF handles (sdf.h) of kind ::SDFCCD_SDF_GRID, so every query of ccd.h runs
 * on them unchanged. Files are Discregrid's `.cdf` layout, which Bullet's
 * `btSdfCollisionShape::initializeSDF` also reads (field 0 is the SDF).
 *
 * Units and frames: metres, in the grid's (= the mesh's) local frame; phi < 0 inside.
 *
 * Evaluation (sdfccd_sdf_eval) never returns a sentinel:
 *  - inside the domain, in a cell with values: the cubic interpolant and its gradient, exactly as
 *    Discregrid and Bullet compute them (the gradient is not normalised);
 *  - in a cell culled by a narrow band (or touching a node a file marks as not sampled): a value
 *    with the correct side (sign) whose magnitude is a lower bound on the distance, and a unit
 *    gradient pointing away from the nearest cell with values. Not continuous across cells;
 *  - outside the domain box, at distance d from its nearest point q: sqrt(d^2 + phi(q)^2), a lower
 *    bound on the distance when the surface lies inside the box. The grid takes the surface to be
 *    inside when every node on the domain boundary is >= 0 (always so for closed meshes with the
 *    default domain); then phi(q) < 0 can only be an interpolation dip and counts as 0, and the
 *    SDF's `bounds` are the domain. Otherwise (the box cuts the shape, e.g. a ground plane) the
 *    value is phi(q) - d where phi(q) < 0, a 1-Lipschitz lower bound that keeps points beyond an
 *    inside boundary inside; the two rules meet discontinuously where the surface crosses the
 *    boundary, and `bounds` are infinite unless phi >= 0 on the boundary is proved face by face.
 * The bound on |grad phi| the certified method uses in a box (sdfccd_grid_lipschitz_bound) is the
 * largest per-cell bound of the cells the box touches: in cells with values a rigorous upper bound
 * on the interpolant's gradient (Bernstein enclosure of each partial derivative; about 1.3x the
 * sampled maximum on average), 1 in culled cells (sound for the true distance the conservative
 * value bounds from below), and sqrt(1 + L^2) where the box leaves the domain.
 */
#ifndef SDFCCD_GRID_H
#define SDFCCD_GRID_H

#include "mesh.h"
#include "sdf.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------------------------ */
/** @name Building grids */

/** Progress of a build: `fraction` in [0, 1], called from the calling thread only, at most about
 * 200 times per build. Return 0 to go on, nonzero to cancel the build: it then stops soon (the
 * tasks already running finish), frees everything and returns ::SDFCCD_CANCELLED. */
typedef int32_t sdfccd_ProgressFcn(double fraction, void* user);

/** How a grid is built. Initialise with sdfccd_default_grid_def(). */
typedef struct sdfccd_GridDef {
    int32_t resolution[3];  /**< Cells per axis (each >= 1). Default 32, 32, 32. */
    /** 1 (default): the domain is the source's bounding box enlarged as Discregrid does (max grown by
     * 1e-3 |diagonal|, then min lowered by 1e-3 |new diagonal|); `domain` is ignored.
     * 0: `domain` is used as given. */
    int32_t fit_domain;
    sdfccd_Aabb domain;     /**< Grid box (m, local frame) when fit_domain is 0; lo < hi on every axis. */
    /** With fit_domain 1: extra margin (m, >= 0) added on every side of the fitted box, so that
     * queries a little outside the surface still read grid values (outside the domain only the
     * conservative continuation is available). Default 0 (exactly Discregrid's domain). */
    double padding;
    /** Narrow band half-width (m). 0 (default): dense, exactly Discregrid's layout. > 0: cells whose
     * 32 node values all satisfy |phi| >= band + |cell diagonal| are culled; |phi| >= band holds in
     * every culled cell and evaluation there returns a conservative value. */
    double band;
    int32_t threads;        /**< Worker threads. 0 (default): one per online core. 1: the calling thread only. */
    int32_t invert;         /**< 1: store -phi (positive inside), for containers, like GenerateSDF -i. Default 0. */
    /** Mesh sources: 0 (default) refuses a mesh that is not closed or has negative volume
     * (::SDFCCD_DEGENERATE, the message gives the edge counts); 1 builds anyway (signs near holes
     * are unreliable). */
    int32_t allow_open_mesh;
    sdfccd_ProgressFcn* progress; /**< May be NULL. */
    void* progress_user;    /**< Passed to `progress`. */
    int32_t internal_value; /**< Set by sdfccd_default_grid_def(); do not change. */
    /** Memory limit of the build (bytes, >= 1); over it the build returns ::SDFCCD_OUT_OF_MEMORY
     * with the figure, before allocating (a 849^3 grid once asked for 32.7 GB in one request).
     * Dense: checked first against the node array and the per-cell tables (8 bytes per node, 8 per
     * cell). Narrow band: it never allocates the dense node array; checked first against what it
     * needs whatever the band (12 bytes per grid vertex, 8 per cell), then before each allocation
     * of its node storage (56 bytes per vertex of a cell near the surface, then per vertex of a
     * kept cell) against the total it holds at that moment. Not counted: the source's own
     * structures (a mesh's distance hierarchy) and the derived tables of the finished grid.
     * Default 4 GiB. */
    int64_t max_bytes;
} sdfccd_GridDef;

/** Defaults: 32^3 cells, fitted domain without padding, dense, all cores, not inverted, closed meshes only, no progress. */
SDFCCD_API sdfccd_GridDef sdfccd_default_grid_def(void);

/** Samples the exact signed distance of a mesh at every node (BVH + pseudonormals, exact to
 * round-off). With the defaults and the same resolution, node values equal Discregrid's GenerateSDF
 * output to about 1e-12 and the file layout is identical. The mesh is not retained. Errors: bad
 * handle or def, non-closed mesh (see allow_open_mesh), more than 2^32 nodes, out of memory. */
SDFCCD_API sdfccd_Status sdfccd_create_grid_from_mesh(sdfccd_MeshId mesh, const sdfccd_GridDef* def, sdfccd_SdfId* out_grid);

/** Samples any SDF handle at every node. With fit_domain 1 the SDF's `bounds` must be finite.
 * The source is not retained. */
SDFCCD_API sdfccd_Status sdfccd_create_grid_from_sdf(sdfccd_SdfId sdf, const sdfccd_GridDef* def, sdfccd_SdfId* out_grid);

/* ------------------------------------------------------------------------------------------ */
/** @name Files (.cdf) */

/** Loads a Discregrid `.cdf` (or `.cdm`) file. Field 0 becomes the SDF; every field is kept (and
 * saved again by sdfccd_save_grid()). Dense, sparse (culled cells, not-sampled nodes) and
 * multi-field files load. The file must be exactly consistent: counts matching the header and
 * the file size, node ids and cell-map entries in range, finite geometry, h * resolution equal to
 * the domain size; otherwise ::SDFCCD_FORMAT_ERROR names the first problem and its byte offset.
 * Missing or unreadable files give ::SDFCCD_IO_ERROR. Little-endian hosts only
 * (::SDFCCD_UNSUPPORTED elsewhere). */
SDFCCD_API sdfccd_Status sdfccd_load_grid(const char* path, sdfccd_SdfId* out_grid);
/** The same from `size` bytes in memory (copied). */
SDFCCD_API sdfccd_Status sdfccd_load_grid_memory(const void* data, size_t size, sdfccd_SdfId* out_grid);

/** Writes the grid as a `.cdf` file that Discregrid and Bullet load (all fields, as stored).
 * Errors: not a grid handle (::SDFCCD_INVALID_ARGUMENT), write failure (::SDFCCD_IO_ERROR; the
 * partial file is removed). */
SDFCCD_API sdfccd_Status sdfccd_save_grid(sdfccd_SdfId grid, const char* path);

/* ------------------------------------------------------------------------------------------ */
/** @name Inspection */

/** What sdfccd_grid_get_info() reports. */
typedef struct sdfccd_GridInfo {
    int32_t resolution[3];  /**< Cells per axis. */
    sdfccd_Aabb domain;     /**< Grid box (m). */
    sdfccd_Vec3 cell_size;  /**< h (m). */
    int32_t field_count;    /**< Fields in the grid (field 0 is the SDF). */
    int64_t cell_count;     /**< Cells of the full grid. */
    int64_t stored_cells;   /**< Cells of field 0 kept in memory (not culled). */
    int64_t valued_cells;   /**< Cells of field 0 with values (stored and without not-sampled nodes). */
    int64_t node_count;     /**< Nodes of field 0. */
    int64_t memory_bytes;   /**< Bytes this grid holds (all fields and derived data). */
    int64_t file_bytes;     /**< Size of the `.cdf` sdfccd_save_grid() writes. */
    double max_lipschitz;   /**< Largest per-cell bound on |grad phi| in cells with values. */
    double band;            /**< Known lower bound on |phi| in culled cells (the build's band; 0 when loaded). */
} sdfccd_GridInfo;

/** Describes a grid. ::SDFCCD_INVALID_ARGUMENT when `grid` is an SDF of another kind. */
SDFCCD_API sdfccd_Status sdfccd_grid_get_info(sdfccd_SdfId grid, sdfccd_GridInfo* out_info);

/** Discregrid's and Bullet's raw interpolation of `field` at `p`: `*out_has_value` is 0 outside the
 * domain, in a culled cell or next to a not-sampled node (then value and gradient are 0), else 1. */
SDFCCD_API sdfccd_Status sdfccd_grid_interpolate(sdfccd_SdfId grid, int32_t field, sdfccd_Vec3 p, double* out_value,
                                                 sdfccd_Vec3* out_grad, int32_t* out_has_value);

/** Upper bound on |grad phi| of the grid's SDF inside `box` (what the certified method uses). */
SDFCCD_API sdfccd_Status sdfccd_grid_lipschitz_bound(sdfccd_SdfId grid, sdfccd_Aabb box, double* out_bound);

#ifdef __cplusplus
}
#endif
#endif
