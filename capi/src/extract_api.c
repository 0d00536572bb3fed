/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: isosurface extraction (extract.h) over core/marching_tetrahedra. */
#include "capi_internal.h"
#include "../../core/marching_tetrahedra.h"

static sdfccd_Status extract_isosurface_held(sdfccd_SdfId sdf, sdfccd_Aabb box, int32_t resolution,
                                        sdfccd_MeshId* out_mesh)
{
    sdfccd_Status st = sdfccd__check_ptr(out_mesh, "out_mesh");
    if (st != SDFCCD_OK) return st;
    sdfccd__sdf* s = sdfccd__sdf_acquire(sdf);
    if (!s) return SDFCCD_INVALID_HANDLE;
    if ((st = sdfccd__check_vec(box.lo, "box.lo")) != SDFCCD_OK) return st;
    if ((st = sdfccd__check_vec(box.hi, "box.hi")) != SDFCCD_OK) return st;
    if (!(box.hi.x > box.lo.x && box.hi.y > box.lo.y && box.hi.z > box.lo.z))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_extract_isosurface: the box is empty (hi must exceed lo on every axis)");
    if (resolution < 1 || resolution > SCC_MT_MAX_RESOLUTION)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_extract_isosurface: resolution %d is outside [1, %d]",
                             (int)resolution, SCC_MT_MAX_RESOLUTION);
    /* About 8 bytes per lattice point (resolution 1024 asked for 8.3 GB): checked before allocating. */
    const double need = 8.0 * ((double)resolution + 1.0) * ((double)resolution + 1.0) * ((double)resolution + 1.0);
    if (need > SDFCCD_EXTRACT_MAX_BYTES)
        return sdfccd__error(SDFCCD_OUT_OF_MEMORY, "sdfccd_extract_isosurface: resolution %d needs about %.4g bytes, above SDFCCD_EXTRACT_MAX_BYTES (%.4g)",
                             (int)resolution, need, (double)SDFCCD_EXTRACT_MAX_BYTES);

    scc_isosurface iso;
    scc_mt_status ms = scc_marching_tetrahedra(s->sdf, sdfccd__box(box), resolution, 0.0, sdfccd__allocator(), &iso);
    if (ms == SCC_MT_OUT_OF_MEMORY) return sdfccd__oom("sdfccd_extract_isosurface");
    if (ms == SCC_MT_TOO_LARGE)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_extract_isosurface: the mesh would exceed 2^32 vertices or triangles");
    if (ms != SCC_MT_OK)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_extract_isosurface: invalid box or resolution");
    if (iso.triangle_count == 0) {
        scc_isosurface_free(&iso, sdfccd__allocator());
        return sdfccd__error(SDFCCD_DEGENERATE, "sdfccd_extract_isosurface: no surface (phi = 0) inside the box");
    }
    /* scc_vec3 is three doubles, the layout sdfccd_MeshDef expects. */
    st = sdfccd__mesh_create((const double*)iso.vertices, iso.vertex_count, iso.indices, iso.triangle_count,
                             1, "sdfccd_extract_isosurface", out_mesh);
    scc_isosurface_free(&iso, sdfccd__allocator());
    return st;
}

sdfccd_Status sdfccd_extract_isosurface(sdfccd_SdfId sdf, sdfccd_Aabb box, int32_t resolution,
                                        sdfccd_MeshId* out_mesh)
{
    SDFCCD__HELD_CALL(extract_isosurface_held(sdf, box, resolution, out_mesh));
}
