/* SPDX-License-Identifier: MIT
 * sdfccd core: the face search (ours). The mesh queries give one point per triangle (the DCD's
 * deepest point, Section 3.2, and adaptive subdivision around a point in contact, Section 4.5): a
 * face lying over features smaller than itself (a grid of spikes) can have every vertex and every
 * point they find clear of the surface while features between them pierce it. The search splits
 * each face with an edge longer than the region size into 4 at its edge midpoints, down to regions
 * with no longer edge, drops a region whose centroid is farther from the surface than the SDF's
 * Lipschitz bound times its radius plus the acceptance distance (no point of it can be within it),
 * and gives each remaining leaf's deepest point (DCD) within the acceptance distance. */
#include "faces.h"

#include <string.h>

/* A region of a face: its corners as barycentric weights of the face's vertices. */
typedef struct face_region {
    double b[3][3];
} face_region;

static scc_vec3 at_bary(const scc_vec3 v[3], const double b[3])
{
    return scc_add(scc_add(scc_scale(v[0], b[0]), scc_scale(v[1], b[1])), scc_scale(v[2], b[2]));
}

static double longest2(const scc_vec3 c[3])
{
    return fmax(scc_len2(scc_sub(c[1], c[0])), fmax(scc_len2(scc_sub(c[2], c[1])), scc_len2(scc_sub(c[0], c[2]))));
}

static void midpoint(const double a[3], const double b[3], double out[3])
{
    for (int k = 0; k < 3; ++k) out[k] = 0.5 * (a[k] + b[k]);
}

/* A found point: material point x (SDF frame at the search time), held by surface point q and normal n. */
static void put(scc_contact_point* out, size_t cap, size_t* found, uint32_t t, const double bary[3], scc_vec3 x, scc_vec3 q, scc_vec3 n,
                double time, const scc_mesh* mesh)
{
    if (*found < cap) {
        scc_contact_point* c = &out[*found];
        memset(c, 0, sizeof *c);
        c->point = x;
        c->normal = n;
        c->gap = scc_dot(n, scc_sub(x, q));
        c->surface = q;
        c->toi = time;
        for (int k = 0; k < 3; ++k) c->bary[k] = bary[k];
        scc_classify_feature(mesh, t, bary, c);
    }
    ++*found;
}

int scc_search_faces(const scc_sdf* sdf, const scc_mesh_motion* mm, double time, double size, double accept, const scc_params* base,
                     scc_workspace* ws, scc_contact_point* out, size_t capacity, size_t* out_found, int64_t* io_regions, int64_t* io_evals)
{
    const scc_mesh* mesh = mm->mesh;
    const double lip = sdf->lipschitz > 0.0 ? sdf->lipschitz : 1.0;
    const double size2 = size * size;
    scc_params p = *base;
    p.method = SCC_METHOD_DCD;
    p.margin = accept;
    p.subdivision = 0;
    size_t found = 0, cap_stack = ws->slot[SCC_WS_FACES].bytes / sizeof(face_region);
    face_region* stack = ws->slot[SCC_WS_FACES].p;
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        scc_tri_motion m;
        scc_mesh_triangle_motion(mm, t, &m);
        scc_vec3 v[3]; /* the face's vertices in the body's frame (rigid) or at t0 (linear) */
        for (int k = 0; k < 3; ++k) {
            const double b[3] = { k == 0, k == 1, k == 2 };
            v[k] = m.kind == SCC_TRI_RIGID ? m.local[k] : scc_tri_point_at(&m, b, time, NULL);
        }
        if (!(longest2(v) > size2)) continue; /* the mesh queries cover it */
        /* the face's direction out of the SDF when the face rests on it: against its outward normal */
        scc_tri_state st;
        scc_tri_state_at(&m, time, &st);
        const scc_vec3 u = scc_normalize_or(scc_cross(scc_sub(st.x[2], st.x[0]), scc_sub(st.x[1], st.x[0])), scc_v3(0, 0, 0));
        size_t top = 0;
        if (cap_stack < 1) {
            if (!(stack = scc_ws_get(ws, SCC_WS_FACES, 64 * sizeof *stack))) return 0;
            cap_stack = ws->slot[SCC_WS_FACES].bytes / sizeof *stack;
        }
        memset(&stack[0], 0, sizeof stack[0]);
        for (int k = 0; k < 3; ++k) stack[0].b[k][k] = 1.0;
        top = 1;
        while (top > 0) {
            const face_region r = stack[--top];
            ++*io_regions;
            scc_vec3 c[3];
            for (int k = 0; k < 3; ++k) c[k] = at_bary(v, r.b[k]);
            const scc_vec3 mid = scc_scale(scc_add(scc_add(c[0], c[1]), c[2]), 1.0 / 3.0);
            const double rad = fmax(scc_dist(c[0], mid), fmax(scc_dist(c[1], mid), scc_dist(c[2], mid)));
            double bm[3];
            for (int k = 0; k < 3; ++k) bm[k] = (r.b[0][k] + r.b[1][k] + r.b[2][k]) / 3.0;
            const double phi = scc_sdf_eval(sdf, scc_tri_point_at(&m, bm, time, NULL), NULL);
            ++*io_evals;
            if (!(phi - lip * rad <= accept)) continue;
            if (longest2(c) > size2) {
                if (top + 4 > cap_stack) {
                    face_region* grown = scc_alloc(ws->alloc, 2 * cap_stack * sizeof *grown);
                    if (!grown) return 0;
                    memcpy(grown, stack, top * sizeof *stack);
                    scc_free(ws->alloc, stack, ws->slot[SCC_WS_FACES].bytes);
                    scc_ws_adopt(ws, SCC_WS_FACES, grown, 2 * cap_stack * sizeof *grown);
                    stack = grown;
                    cap_stack *= 2;
                }
                double m01[3], m12[3], m20[3];
                midpoint(r.b[0], r.b[1], m01);
                midpoint(r.b[1], r.b[2], m12);
                midpoint(r.b[2], r.b[0], m20);
                const double* kids[4][3] = { { r.b[0], m01, m20 }, { m01, r.b[1], m12 }, { m20, m12, r.b[2] }, { m12, m20, m01 } };
                for (int q = 0; q < 4; ++q, ++top)
                    for (int k = 0; k < 3; ++k) memcpy(stack[top].b[k], kids[q][k], sizeof stack[top].b[k]);
                continue;
            }
            /* a leaf: its deepest point (DCD) within the acceptance distance */
            scc_tri_motion leaf = m;
            for (int k = 0; k < 3; ++k) {
                if (m.kind == SCC_TRI_RIGID) leaf.local[k] = c[k];
                else {
                    leaf.start[k] = at_bary(m.start, r.b[k]);
                    leaf.end[k] = at_bary(m.end, r.b[k]);
                }
                leaf.trace[k] = NULL;
            }
            scc_contact k[1 + SCC_MAX_SUBDIVISION_CONTACTS];
            scc_query_summary s;
            if (!scc_query_triangle(sdf, &leaf, time, time, &p, ws, t, k, 1 + SCC_MAX_SUBDIVISION_CONTACTS, &s)) return 0;
            *io_evals += s.evals;
            if (!s.hit || s.contacts_found < 1) continue;
            double bary[3];
            for (int j = 0; j < 3; ++j) bary[j] = k[0].bary[0] * r.b[0][j] + k[0].bary[1] * r.b[1][j] + k[0].bary[2] * r.b[2][j];
            const scc_vec3 x = k[0].point, n = scc_normalize_or(k[0].normal, u);
            /* A point inside the SDF where the field's normal is far from the face's (a tip through
             * the face: inside a cone the gradient points out of its side, mostly sideways) is
             * pushed out along the face's normal instead, to where that line leaves the SDF (the
             * tip's apex), as a face resting on a vertex is. */
            if (k[0].distance < 0.0 && scc_len2(u) > 0.0 && scc_dot(n, u) < SCC_FACE_NORMAL_AGREEMENT) {
                scc_vec3 e = x;
                double ph = k[0].distance, walked = 0.0;
                for (int it = 0; it < 64 && ph < 0.0 && walked < 4.0 * size; ++it) {
                    const double step = fmax(-ph / lip, 1e-7);
                    e = scc_add(e, scc_scale(u, step));
                    walked += step;
                    ph = scc_sdf_eval(sdf, e, NULL);
                    ++*io_evals;
                }
                if (ph >= -1e-6 && walked < 4.0 * size) {
                    put(out, capacity, &found, t, bary, x, e, u, time, mesh);
                    continue;
                }
            }
            put(out, capacity, &found, t, bary, x, scc_sub(x, scc_scale(n, k[0].distance)), n, time, mesh);
        }
    }
    *out_found = found;
    return 1;
}
