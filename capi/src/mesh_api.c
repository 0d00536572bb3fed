/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: mesh objects (mesh.h): creation with validation and the broad-phase hierarchy,
 * handles, inspection, the topology report and exact signed distance queries. Loading from files
 * is in mesh_import.c and obj_reader.c. */
#include "capi_internal.h"
#include "../../core/bsh.h"
#include "../../core/mesh_distance.h"

#include <string.h>

/* ---------------- mesh objects ---------------- */

sdfccd_Status sdfccd__mesh_create(const double* vertices, uint32_t vertex_count, const uint32_t* indices,
                                     uint32_t triangle_count, int drop_degenerate, const char* what,
                                  sdfccd_MeshId* out_mesh)
{
    if (!vertices || !indices) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: vertices or indices is NULL", what);
    if (vertex_count == 0 || triangle_count == 0)
        return sdfccd__error(SDFCCD_DEGENERATE, "%s: the mesh is empty (%u vertices, %u triangles)", what, vertex_count, triangle_count);
    if (vertex_count > (1u << 30) || triangle_count > (1u << 30))
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: too many vertices or triangles", what);
    for (uint32_t i = 0; i < 3 * vertex_count; ++i)
        if (!isfinite(vertices[i]))
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: vertex %u has a non-finite coordinate", what, i / 3);
    uint32_t kept = 0;
    for (uint32_t t = 0; t < triangle_count; ++t) {
        const uint32_t* f = indices + 3 * t;
        if (f[0] >= vertex_count || f[1] >= vertex_count || f[2] >= vertex_count)
            return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "%s: triangle %u has a vertex index out of range (%u vertices)", what, t, vertex_count);
        scc_vec3 a = { vertices[3 * f[0]], vertices[3 * f[0] + 1], vertices[3 * f[0] + 2] };
        scc_vec3 b = { vertices[3 * f[1]], vertices[3 * f[1] + 1], vertices[3 * f[1] + 2] };
        scc_vec3 c = { vertices[3 * f[2]], vertices[3 * f[2] + 1], vertices[3 * f[2] + 2] };
        const int degenerate = scc_triangle_is_degenerate(a, b, c);
        if (degenerate && !drop_degenerate)
            return sdfccd__error(SDFCCD_DEGENERATE, "%s: triangle %u (vertices %u %u %u) has zero area", what, t, f[0], f[1], f[2]);
        kept += !degenerate;
    }
    if (kept == 0) return sdfccd__error(SDFCCD_DEGENERATE, "%s: every triangle has zero area", what);

    size_t vbytes = (size_t)vertex_count * sizeof(scc_vec3);
    size_t ibytes = (size_t)kept * 3 * sizeof(uint32_t);
    sdfccd__mesh* m = sdfccd__calloc(sizeof *m);
    void* block = sdfccd__alloc(vbytes + ibytes);
    if (!m || !block) {
        sdfccd__free(m, sizeof *m);
        sdfccd__free(block, vbytes + ibytes);
        return sdfccd__oom("a mesh");
    }
    scc_vec3* v = block;
    uint32_t* idx = (uint32_t*)((char*)block + vbytes);
    scc_aabb box = { { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    double r2 = 0.0;
    for (uint32_t i = 0; i < vertex_count; ++i) {
        v[i] = scc_v3(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
        box.lo = scc_vmin(box.lo, v[i]);
        box.hi = scc_vmax(box.hi, v[i]);
        r2 = fmax(r2, scc_len2(v[i]));
    }
    uint32_t k = 0;
    for (uint32_t t = 0; t < triangle_count; ++t) {
        const uint32_t* f = indices + 3 * t;
        if (scc_triangle_is_degenerate(v[f[0]], v[f[1]], v[f[2]])) continue;
        idx[3 * k] = f[0]; idx[3 * k + 1] = f[1]; idx[3 * k + 2] = f[2];
        ++k;
    }
    m->block = block;
    m->block_size = vbytes + ibytes;
    m->mesh.vertices = v;
    m->mesh.indices = idx;
    m->mesh.vertex_count = vertex_count;
    m->mesh.triangle_count = kept;
    m->mesh.bounds = box;
    m->mesh.radius = sqrt(r2);
    m->dropped_triangles = triangle_count - kept;
    m->refs = 1;
    m->bsh = scc_bsh_build(&m->mesh, sdfccd__allocator()); /* broad phase of the mesh query */
    if (!m->bsh) {
        sdfccd__free(block, m->block_size);
        sdfccd__free(m, sizeof *m);
        return sdfccd__oom("a mesh's bounding-sphere hierarchy");
    }
    m->mesh.bsh = m->bsh;
    sdfccd_MeshId id = { 0, 0 };
    if (!sdfccd__registry_add(m, SDFCCD__KIND_MESH, &id.index1, &id.generation)) {
        scc_bsh_destroy(m->bsh, sdfccd__allocator());
        sdfccd__free(block, m->block_size);
        sdfccd__free(m, sizeof *m);
        return sdfccd__oom("a mesh handle");
    }
    *out_mesh = id;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_create_mesh(const sdfccd_MeshDef* def, sdfccd_MeshId* out_mesh)
{
    sdfccd_Status st;
    if ((st = SDFCCD__CHECK_DEF_ARGS("sdfccd_create_mesh", def, out_mesh, "out_mesh", "sdfccd_default_mesh_def"))) return st;
    return sdfccd__mesh_create(def->vertices, def->vertex_count, def->indices, def->triangle_count,
                               def->drop_degenerate, "sdfccd_create_mesh", out_mesh);
}

static sdfccd_Status mesh_get_info_held(sdfccd_MeshId id, sdfccd_MeshInfo* out_info)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_info, "sdfccd_mesh_get_info: out_info"))) return st;
    sdfccd__mesh* m = sdfccd__mesh_acquire(id);
    if (!m) return SDFCCD_INVALID_HANDLE;
    out_info->vertex_count = m->mesh.vertex_count;
    out_info->triangle_count = m->mesh.triangle_count;
    out_info->dropped_triangles = m->dropped_triangles;
    out_info->bounds = sdfccd__pbox(m->mesh.bounds);
    out_info->memory_bytes = (int64_t)(m->block_size + sizeof *m + (m->bsh ? m->bsh->bytes : 0));
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_mesh_get_info(sdfccd_MeshId id, sdfccd_MeshInfo* out_info)
{
    SDFCCD__HELD_CALL(mesh_get_info_held(id, out_info));
}

static sdfccd_Status mesh_get_data_held(sdfccd_MeshId id, double* out_vertices, uint32_t* out_indices)
{
    sdfccd__mesh* m = sdfccd__mesh_acquire(id);
    if (!m) return SDFCCD_INVALID_HANDLE;
    if (out_vertices)
        for (uint32_t i = 0; i < m->mesh.vertex_count; ++i) {
            out_vertices[3 * i] = m->mesh.vertices[i].x;
            out_vertices[3 * i + 1] = m->mesh.vertices[i].y;
            out_vertices[3 * i + 2] = m->mesh.vertices[i].z;
        }
    if (out_indices) memcpy(out_indices, m->mesh.indices, (size_t)m->mesh.triangle_count * 3 * sizeof(uint32_t));
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_mesh_get_data(sdfccd_MeshId id, double* out_vertices, uint32_t* out_indices)
{
    SDFCCD__HELD_CALL(mesh_get_data_held(id, out_vertices, out_indices));
}

/* ---------------- topology and distance ---------------- */

sdfccd_Status sdfccd__mesh_topology_message(const scc_mesh_topology* t, const char* fn)
{
    if (!t->closed)
        return sdfccd__error(SDFCCD_DEGENERATE,
                             "%s: the mesh is not closed (%u boundary, %u non-manifold, %u inconsistently oriented edges); "
                          "signs would be wrong (set allow_open_mesh to build anyway)",
                          fn, t->boundary_edges, t->nonmanifold_edges, t->inconsistent_edges);
    if (!(t->volume > 0.0))
        return sdfccd__error(SDFCCD_DEGENERATE, "%s: the mesh is inside out (signed volume %g <= 0); flip its triangles", fn, t->volume);
    return SDFCCD_OK;
}

static sdfccd_Status mesh_get_topology_held(sdfccd_MeshId mesh, sdfccd_MeshTopology* out_topology)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_topology, "sdfccd_mesh_get_topology: out_topology"))) return st;
    sdfccd__mesh* m = sdfccd__mesh_acquire(mesh);
    if (!m) return SDFCCD_INVALID_HANDLE;
    scc_mesh_topology t;
    if (!scc_mesh_topology_check(sdfccd__allocator(), &m->mesh, &t)) return sdfccd__oom("a topology check");
    out_topology->boundary_edges = t.boundary_edges;
    out_topology->nonmanifold_edges = t.nonmanifold_edges;
    out_topology->inconsistent_edges = t.inconsistent_edges;
    out_topology->volume = t.volume;
    out_topology->closed = t.closed;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_mesh_get_topology(sdfccd_MeshId mesh, sdfccd_MeshTopology* out_topology)
{
    SDFCCD__HELD_CALL(mesh_get_topology_held(mesh, out_topology));
}

static sdfccd_Status mesh_signed_distance_held(sdfccd_MeshId mesh, const sdfccd_Vec3* points, int32_t count, int32_t allow_open,
                                          double* out_distances, sdfccd_Vec3* out_closest)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_points("sdfccd_mesh_signed_distance", points, count, out_distances, "out_distances"))) return st;
    sdfccd__mesh* m = sdfccd__mesh_acquire(mesh);
    if (!m) return SDFCCD_INVALID_HANDLE;
    scc_mesh_sdf ms;
    if (!scc_mesh_sdf_init(&ms, sdfccd__allocator(), &m->mesh)) return sdfccd__oom("a mesh distance structure");
    if (!allow_open && (st = sdfccd__mesh_topology_message(&ms.topology, "sdfccd_mesh_signed_distance"))) {
        scc_mesh_sdf_destroy(&ms);
        return st;
    }
    uint32_t hint = UINT32_MAX;
    for (int32_t i = 0; i < count; ++i) {
        scc_tri_nearest nr;
        out_distances[i] = scc_mesh_sdf_query_hint(&ms, sdfccd__v(points[i]), &hint, &nr, NULL);
        if (out_closest) out_closest[i] = sdfccd__pv(nr.point);
    }
    scc_mesh_sdf_destroy(&ms);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_mesh_signed_distance(sdfccd_MeshId mesh, const sdfccd_Vec3* points, int32_t count, int32_t allow_open,
                                          double* out_distances, sdfccd_Vec3* out_closest)
{
    SDFCCD__HELD_CALL(mesh_signed_distance_held(mesh, points, count, allow_open, out_distances, out_closest));
}
