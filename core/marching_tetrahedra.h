/* SPDX-License-Identifier: MIT
 * sdfccd core: isosurface extraction from any SDF on a box (a closed triangle mesh of phi = iso).
 *
 * Method: the box is sampled on a regular grid of nearly cubic cells; every cell is split into
 * six tetrahedra around its main diagonal (the Kuhn/Freudenthal split, which neighbouring cells
 * share face by face), and each tetrahedron is polygonised ("marching tetrahedra", the
 * ambiguity-free variant of marching cubes). A vertex on a grid edge is found by a safeguarded
 * regula-falsi search on phi along that edge, so it lies on the true surface up to the search
 * tolerance, not just on the linear interpolant.
 *
 * Guarantees:
 *  - The mesh is closed and consistently oriented (counter-clockwise seen from outside, normals
 *    pointing to phi > iso): the grid is padded with one layer of virtual "outside" nodes, so where
 *    the solid reaches the box's faces it is capped within one cell outside the box.
 *  - Vertices are shared between triangles (an indexed mesh without duplicates per grid edge).
 *  - Vertices never sit exactly on a grid node (the edge parameter is kept in [1e-3, 1 - 1e-3]),
 *    so no triangle collapses to zero area when the surface passes through a node.
 * Features thinner than a cell can be missed (as with any sampling method).
 */
#ifndef SCC_MARCHING_TETRAHEDRA_H
#define SCC_MARCHING_TETRAHEDRA_H

#include <stdint.h>
#include "alloc.h"
#include "sdf.h"

typedef struct scc_isosurface {
    scc_vec3* vertices;       /* vertex_count positions, SDF frame */
    uint32_t* indices;        /* 3 * triangle_count, counter-clockwise from outside */
    uint32_t vertex_count;
    uint32_t triangle_count;
    size_t vertex_capacity;   /* allocation sizes (elements), for scc_isosurface_free */
    size_t index_capacity;
} scc_isosurface;

typedef enum scc_mt_status {
    SCC_MT_OK = 0,
    SCC_MT_BAD_INPUT,       /* empty or non-finite box, resolution out of [1, SCC_MT_MAX_RESOLUTION] */
    SCC_MT_OUT_OF_MEMORY,
    SCC_MT_TOO_LARGE        /* more than 2^32 - 1 vertices or triangles */
} scc_mt_status;

#define SCC_MT_MAX_RESOLUTION 1024

/* Extracts {phi = iso} inside `box`. `resolution` is the number of cells along the box's longest
 * axis; the other axes get as many cells as keep them nearly cubic (at least 1). On success `out`
 * owns its arrays (free them with scc_isosurface_free); on failure `out` is zeroed and nothing is
 * left allocated. An SDF with no surface in the box gives SCC_MT_OK with zero triangles. */
scc_mt_status scc_marching_tetrahedra(const scc_sdf* sdf, scc_aabb box, int resolution, double iso,
                                       const scc_allocator* alloc, scc_isosurface* out);

void scc_isosurface_free(scc_isosurface* s, const scc_allocator* alloc);

#endif
