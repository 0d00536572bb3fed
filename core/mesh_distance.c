/* SPDX-License-Identifier: MIT
 * sdfccd core: exact signed distance to a triangle mesh. The magnitude is the exact minimum
 * over triangles (BVH nearest query); the sign comes from the angle-weighted pseudonormal of
 * the nearest feature (Baerentzen and Aanaes, IEEE TVCG 11(3), 2005): face normal for a face,
 * the sum of the two adjacent face normals for an edge, the incidence-angle-weighted sum for
 * a vertex. That sign is exact for closed, consistently oriented (2-manifold) meshes, so the
 * topology is checked and reported to the caller.
 */
#include "mesh_distance.h"

#include <stdlib.h>
#include <string.h>

typedef struct edge_rec {
    uint64_t key;   /* (min vertex << 32) | max vertex */
    uint32_t slot;  /* 3 * triangle + local edge */
    uint32_t forward; /* 1 when the triangle runs min -> max */
} edge_rec;

static int edge_cmp(const void* a, const void* b)
{
    const edge_rec* x = a;
    const edge_rec* y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->slot < y->slot ? -1 : (x->slot > y->slot);
}

/* Sorted edge records of the mesh (3 per triangle); NULL on OOM. */
static edge_rec* sorted_edges(const scc_allocator* a, const scc_mesh* mesh)
{
    const size_t n = (size_t)mesh->triangle_count * 3;
    edge_rec* e = scc_alloc(a, n * sizeof *e);
    if (!e) return NULL;
    for (uint32_t t = 0; t < mesh->triangle_count; ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t u = mesh->indices[3 * t + k], v = mesh->indices[3 * t + (k + 1) % 3];
            edge_rec* r = &e[3 * (size_t)t + k];
            r->key = u < v ? ((uint64_t)u << 32) | v : ((uint64_t)v << 32) | u;
            r->slot = 3 * t + (uint32_t)k;
            r->forward = u < v;
        }
    qsort(e, n, sizeof *e, edge_cmp);
    return e;
}

static void topology_from_edges(const scc_mesh* mesh, const edge_rec* e, scc_mesh_topology* out)
{
    memset(out, 0, sizeof *out);
    const size_t n = (size_t)mesh->triangle_count * 3;
    for (size_t i = 0; i < n;) {
        size_t j = i + 1;
        while (j < n && e[j].key == e[i].key) ++j;
        const size_t c = j - i;
        if (c == 1) out->boundary_edges++;
        else if (c > 2) out->nonmanifold_edges++;
        else if (e[i].forward == e[i + 1].forward) out->inconsistent_edges++;
        i = j;
    }
    double vol = 0.0;
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        scc_vec3 v[3];
        scc_mesh_triangle(mesh, t, v);
        vol += scc_dot(v[0], scc_cross(v[1], v[2]));
    }
    out->volume = vol / 6.0;
    out->closed = out->boundary_edges == 0 && out->nonmanifold_edges == 0 && out->inconsistent_edges == 0;
}

int scc_mesh_topology_check(const scc_allocator* a, const scc_mesh* mesh, scc_mesh_topology* out)
{
    edge_rec* e = sorted_edges(a, mesh);
    if (!e && mesh->triangle_count) return 0;
    topology_from_edges(mesh, e, out);
    scc_free(a, e, (size_t)mesh->triangle_count * 3 * sizeof *e);
    return 1;
}

static double mesh_sdf_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* out_grad)
{
    scc_tri_nearest nr;
    scc_vec3 normal;
    const double dist = scc_mesh_sdf_query((const scc_mesh_sdf*)self, p, &nr, &normal);
    if (out_grad) {
        const scc_vec3 d = scc_sub(p, nr.point);
        const double l = scc_len(d);
        /* grad of the signed distance: sign * (p - closest) / |p - closest|; on the surface,
         * the pseudonormal. */
        *out_grad = l > 0.0 ? scc_scale(d, (dist < 0.0 ? -1.0 : 1.0) / l) : normal;
    }
    return dist;
}

int scc_mesh_sdf_init(scc_mesh_sdf* m, const scc_allocator* a, const scc_mesh* mesh)
{
    memset(m, 0, sizeof *m);
    m->allocator = *a;
    m->mesh = mesh;
    const uint32_t nt = mesh->triangle_count, nv = mesh->vertex_count;
    m->face_normal = scc_alloc(a, (size_t)nt * sizeof(scc_vec3));
    m->edge_normal = scc_alloc(a, (size_t)nt * 3 * sizeof(scc_vec3));
    m->vertex_normal = scc_alloc(a, (size_t)nv * sizeof(scc_vec3));
    edge_rec* e = sorted_edges(a, mesh);
    if (!m->face_normal || !m->edge_normal || !m->vertex_normal || !e || !scc_tri_bvh_build(&m->bvh, a, mesh)) {
        scc_free(a, e, (size_t)nt * 3 * sizeof *e);
        scc_mesh_sdf_destroy(m);
        return 0;
    }
    topology_from_edges(mesh, e, &m->topology);

    for (uint32_t i = 0; i < nv; ++i) m->vertex_normal[i] = scc_v3(0, 0, 0);
    for (uint32_t t = 0; t < nt; ++t) {
        scc_vec3 v[3];
        scc_mesh_triangle(mesh, t, v);
        const scc_vec3 n = scc_normalize_or(scc_cross(scc_sub(v[1], v[0]), scc_sub(v[2], v[0])), scc_v3(0, 0, 0));
        m->face_normal[t] = n;
        for (int k = 0; k < 3; ++k) {
            const scc_vec3 e1 = scc_sub(v[(k + 1) % 3], v[k]), e2 = scc_sub(v[(k + 2) % 3], v[k]);
            const double angle = atan2(scc_len(scc_cross(e1, e2)), scc_dot(e1, e2));
            const uint32_t vi = mesh->indices[3 * t + k];
            m->vertex_normal[vi] = scc_madd(m->vertex_normal[vi], n, angle);
        }
    }
    for (uint32_t i = 0; i < nv; ++i) m->vertex_normal[i] = scc_normalize_or(m->vertex_normal[i], scc_v3(0, 0, 0));
    /* Edge pseudonormals: the sum of the normals of every triangle sharing the edge. */
    const size_t ne = (size_t)nt * 3;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].key == e[i].key) ++j;
        scc_vec3 s = scc_v3(0, 0, 0);
        for (size_t k = i; k < j; ++k) s = scc_add(s, m->face_normal[e[k].slot / 3]);
        s = scc_normalize_or(s, scc_v3(0, 0, 0));
        for (size_t k = i; k < j; ++k) m->edge_normal[e[k].slot] = s;
        i = j;
    }
    scc_free(a, e, ne * sizeof *e);

    m->base.eval = mesh_sdf_eval;
    m->base.lipschitz_in = NULL;
    m->base.domain.lo = scc_v3(-INFINITY, -INFINITY, -INFINITY);
    m->base.domain.hi = scc_v3(INFINITY, INFINITY, INFINITY);
    m->base.bounds = mesh->bounds;
    m->base.lipschitz = 1.0;
    m->base.kind = SCC_SDF_CALLBACK;
    m->base.convex = 0; /* a mesh is not known to be convex */
    m->base.convex_in = NULL;
    return 1;
}

void scc_mesh_sdf_destroy(scc_mesh_sdf* m)
{
    const scc_allocator* a = &m->allocator;
    if (!a->free) return;
    const uint32_t nt = m->mesh ? m->mesh->triangle_count : 0, nv = m->mesh ? m->mesh->vertex_count : 0;
    scc_free(a, m->face_normal, (size_t)nt * sizeof(scc_vec3));
    scc_free(a, m->edge_normal, (size_t)nt * 3 * sizeof(scc_vec3));
    scc_free(a, m->vertex_normal, (size_t)nv * sizeof(scc_vec3));
    m->face_normal = m->edge_normal = m->vertex_normal = NULL;
    scc_tri_bvh_destroy(&m->bvh);
}

double scc_mesh_sdf_query(const scc_mesh_sdf* m, scc_vec3 p, scc_tri_nearest* out_nearest, scc_vec3* out_normal)
{
    uint32_t hint = UINT32_MAX;
    return scc_mesh_sdf_query_hint(m, p, &hint, out_nearest, out_normal);
}

static scc_vec3 feature_normal(const scc_mesh_sdf* m, uint32_t t, scc_tri_feature f)
{
    switch (f) {
    case SCC_TRI_V0: return m->vertex_normal[m->mesh->indices[3 * t]];
    case SCC_TRI_V1: return m->vertex_normal[m->mesh->indices[3 * t + 1]];
    case SCC_TRI_V2: return m->vertex_normal[m->mesh->indices[3 * t + 2]];
    case SCC_TRI_E01: return m->edge_normal[3 * t];
    case SCC_TRI_E12: return m->edge_normal[3 * t + 1];
    case SCC_TRI_E20: return m->edge_normal[3 * t + 2];
    default: return m->face_normal[t];
    }
}

double scc_mesh_sdf_distance_capped(const scc_mesh_sdf* m, scc_vec3 p, uint32_t* hint, double cap)
{
    scc_tri_nearest nr;
    if (!scc_tri_bvh_nearest_within(&m->bvh, p, *hint, cap < INFINITY ? cap * cap : INFINITY, &nr)) return cap;
    *hint = nr.slot;
    const double d = sqrt(nr.dist2);
    if (!(d < cap)) return cap;
    return scc_dot(scc_sub(p, nr.point), feature_normal(m, nr.triangle, nr.feature)) >= 0.0 ? d : -d;
}

double scc_mesh_sdf_query_hint(const scc_mesh_sdf* m, scc_vec3 p, uint32_t* hint, scc_tri_nearest* out_nearest,
                               scc_vec3* out_normal)
{
    scc_tri_nearest nr;
    scc_vec3 n = scc_v3(0, 0, 1);
    double dist = INFINITY;
    if (scc_tri_bvh_nearest_hint(&m->bvh, p, *hint, &nr)) {
        *hint = nr.slot;
        n = feature_normal(m, nr.triangle, nr.feature);
        const double d = sqrt(nr.dist2);
        dist = scc_dot(scc_sub(p, nr.point), n) >= 0.0 ? d : -d;
    } else {
        memset(&nr, 0, sizeof nr);
    }
    if (out_nearest) *out_nearest = nr;
    if (out_normal) *out_normal = n;
    return dist;
}
