/* SPDX-License-Identifier: MIT
 * sdfccd core: point-triangle closest point by the Voronoi-region walk over barycentric
 * tests (as described in Ericson, "Real-Time Collision Detection", section 5.1.5), and a
 * median-split AABB hierarchy over triangles with a best-first nearest query.
 */
#include "tri_bvh.h"
#include "select_kth.h"

#include <string.h>

double scc_closest_point_triangle(scc_vec3 p, scc_vec3 a, scc_vec3 b, scc_vec3 c, scc_vec3* out_point, scc_tri_feature* out_feature)
{
    const scc_vec3 ab = scc_sub(b, a), ac = scc_sub(c, a), ap = scc_sub(p, a);
    scc_vec3 q;
    scc_tri_feature f;
    const double d1 = scc_dot(ab, ap), d2 = scc_dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) { q = a; f = SCC_TRI_V0; goto done; }
    const scc_vec3 bp = scc_sub(p, b);
    const double d3 = scc_dot(ab, bp), d4 = scc_dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) { q = b; f = SCC_TRI_V1; goto done; }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double t = d1 / (d1 - d3);
        q = scc_madd(a, ab, t); f = SCC_TRI_E01; goto done;
    }
    const scc_vec3 cp = scc_sub(p, c);
    const double d5 = scc_dot(ab, cp), d6 = scc_dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) { q = c; f = SCC_TRI_V2; goto done; }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double t = d2 / (d2 - d6);
        q = scc_madd(a, ac, t); f = SCC_TRI_E20; goto done;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        q = scc_madd(b, scc_sub(c, b), t); f = SCC_TRI_E12; goto done;
    }
    {
        const double den = va + vb + vc;
        if (!(den > 0.0)) { /* degenerate triangle: nearest of the three edges */
            scc_vec3 best = a;
            double bd = INFINITY;
            const scc_vec3 e0[3] = { a, b, c }, e1[3] = { b, c, a };
            const scc_tri_feature ef[3] = { SCC_TRI_E01, SCC_TRI_E12, SCC_TRI_E20 };
            f = SCC_TRI_E01;
            for (int i = 0; i < 3; ++i) {
                const scc_vec3 e = scc_sub(e1[i], e0[i]);
                const double l2 = scc_len2(e);
                const double t = l2 > 0.0 ? scc_clamp(scc_dot(scc_sub(p, e0[i]), e) / l2, 0.0, 1.0) : 0.0;
                const scc_vec3 x = scc_madd(e0[i], e, t);
                const double dd = scc_len2(scc_sub(p, x));
                if (dd < bd) { bd = dd; best = x; f = ef[i]; }
            }
            q = best;
            goto done;
        }
        const double v = vb / den, w = vc / den;
        q = scc_add(a, scc_add(scc_scale(ab, v), scc_scale(ac, w)));
        f = SCC_TRI_FACE;
    }
done:
    if (out_point) *out_point = q;
    if (out_feature) *out_feature = f;
    return scc_len2(scc_sub(p, q));
}

/* ---- build ---- */

typedef struct build_state {
    scc_tri_bvh* bvh;
    uint32_t* order;     /* mesh triangles, permuted by the build */
    scc_vec3* centroid;  /* per mesh triangle */
    const scc_mesh* mesh;
} build_state;

static scc_aabb tri_box(const scc_mesh* m, uint32_t t)
{
    scc_vec3 v[3];
    scc_mesh_triangle(m, t, v);
    scc_aabb b = { scc_vmin(v[0], scc_vmin(v[1], v[2])), scc_vmax(v[0], scc_vmax(v[1], v[2])) };
    return b;
}

static void build_node(build_state* s, uint32_t node, uint32_t lo, uint32_t hi)
{
    scc_tri_bvh* bvh = s->bvh;
    scc_aabb box = tri_box(s->mesh, s->order[lo]);
    scc_aabb cbox = { s->centroid[s->order[lo]], s->centroid[s->order[lo]] };
    for (uint32_t i = lo + 1; i < hi; ++i) {
        scc_aabb tb = tri_box(s->mesh, s->order[i]);
        box.lo = scc_vmin(box.lo, tb.lo); box.hi = scc_vmax(box.hi, tb.hi);
        cbox.lo = scc_vmin(cbox.lo, s->centroid[s->order[i]]); cbox.hi = scc_vmax(cbox.hi, s->centroid[s->order[i]]);
    }
    bvh->nodes[node].box = box;
    if (hi - lo <= 8) {
        bvh->nodes[node].first = lo;
        bvh->nodes[node].count = hi - lo;
        return;
    }
    const scc_vec3 ext = scc_sub(cbox.hi, cbox.lo);
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const uint32_t mid = lo + (hi - lo) / 2;
    scc_select_kth(s->order, s->centroid, axis, lo, hi, mid);
    const uint32_t left = bvh->node_count;
    bvh->node_count += 2;
    bvh->nodes[node].first = left;
    bvh->nodes[node].count = 0;
    build_node(s, left, lo, mid);
    build_node(s, left + 1, mid, hi);
}

int scc_tri_bvh_build(scc_tri_bvh* bvh, const scc_allocator* a, const scc_mesh* mesh)
{
    memset(bvh, 0, sizeof *bvh);
    bvh->allocator = *a;
    const uint32_t n = mesh->triangle_count;
    if (n == 0) return 1;
    bvh->node_capacity = 2 * n;
    bvh->nodes = scc_alloc(a, (size_t)bvh->node_capacity * sizeof *bvh->nodes);
    bvh->tris = scc_alloc(a, (size_t)n * 3 * sizeof(scc_vec3));
    bvh->tri_index = scc_alloc(a, (size_t)n * sizeof(uint32_t));
    bvh->tri_boxes = scc_alloc(a, (size_t)n * sizeof(scc_aabb));
    uint32_t* order = scc_alloc(a, (size_t)n * sizeof *order);
    scc_vec3* centroid = scc_alloc(a, (size_t)n * sizeof *centroid);
    bvh->tri_count = n; /* before any failure: destroy frees the arrays with sizes from this count */
    if (!bvh->nodes || !bvh->tris || !bvh->tri_index || !bvh->tri_boxes || !order || !centroid) {
        scc_free(a, order, (size_t)n * sizeof *order);
        scc_free(a, centroid, (size_t)n * sizeof *centroid);
        scc_tri_bvh_destroy(bvh);
        return 0;
    }
    for (uint32_t t = 0; t < n; ++t) {
        scc_vec3 v[3];
        scc_mesh_triangle(mesh, t, v);
        centroid[t] = scc_scale(scc_add(v[0], scc_add(v[1], v[2])), 1.0 / 3.0);
        order[t] = t;
    }
    build_state s = { bvh, order, centroid, mesh };
    bvh->node_count = 1;
    build_node(&s, 0, 0, n);
    for (uint32_t i = 0; i < n; ++i) {
        bvh->tri_index[i] = order[i];
        scc_mesh_triangle(mesh, order[i], bvh->tris + 3 * (size_t)i);
        bvh->tri_boxes[i] = tri_box(mesh, order[i]);
    }
    scc_free(a, order, (size_t)n * sizeof *order);
    scc_free(a, centroid, (size_t)n * sizeof *centroid);
    return 1;
}

void scc_tri_bvh_destroy(scc_tri_bvh* bvh)
{
    const scc_allocator* a = &bvh->allocator;
    if (!a->free) return;
    scc_free(a, bvh->nodes, (size_t)bvh->node_capacity * sizeof *bvh->nodes);
    scc_free(a, bvh->tris, (size_t)bvh->tri_count * 3 * sizeof(scc_vec3));
    scc_free(a, bvh->tri_index, (size_t)bvh->tri_count * sizeof(uint32_t));
    scc_free(a, bvh->tri_boxes, (size_t)bvh->tri_count * sizeof(scc_aabb));
    bvh->nodes = NULL; bvh->tris = NULL; bvh->tri_index = NULL; bvh->tri_boxes = NULL;
    bvh->tri_count = 0; bvh->node_count = 0; bvh->node_capacity = 0;
}

/* ---- query ---- */

/* Squared distance from p to a box (0 inside). Plain comparisons: fmax is a libm call here. */
static inline double box_dist2(const scc_aabb* b, scc_vec3 p)
{
    double d = 0.0, t;
    t = b->lo.x - p.x; if (t > 0.0) d += t * t; else { t = p.x - b->hi.x; if (t > 0.0) d += t * t; }
    t = b->lo.y - p.y; if (t > 0.0) d += t * t; else { t = p.y - b->hi.y; if (t > 0.0) d += t * t; }
    t = b->lo.z - p.z; if (t > 0.0) d += t * t; else { t = p.z - b->hi.z; if (t > 0.0) d += t * t; }
    return d;
}

int scc_tri_bvh_nearest(const scc_tri_bvh* bvh, scc_vec3 p, scc_tri_nearest* out)
{
    return scc_tri_bvh_nearest_hint(bvh, p, UINT32_MAX, out);
}

int scc_tri_bvh_nearest_hint(const scc_tri_bvh* bvh, scc_vec3 p, uint32_t hint, scc_tri_nearest* out)
{
    return scc_tri_bvh_nearest_within(bvh, p, hint, INFINITY, out);
}

int scc_tri_bvh_nearest_within(const scc_tri_bvh* bvh, scc_vec3 p, uint32_t hint, double max_dist2, scc_tri_nearest* out)
{
    if (bvh->tri_count == 0) return 0;
    /* Depth-first, nearer child first, pruning boxes no nearer than the best so far. The
     * median split keeps the depth below 2 + log2(n), so 96 entries are plenty. */
    uint32_t stack[96];
    double stack_d[96];
    int sp = 0;
    double best = max_dist2;
    int found = 0;
    scc_tri_nearest r = { INFINITY, p, 0, 0, SCC_TRI_FACE };
    if (hint < bvh->tri_count) {
        const scc_vec3* v = bvh->tris + 3 * (size_t)hint;
        scc_vec3 q;
        scc_tri_feature f;
        const double d2 = scc_closest_point_triangle(p, v[0], v[1], v[2], &q, &f);
        if (d2 < best) {
            best = d2;
            found = 1;
            r.dist2 = d2; r.point = q; r.feature = f;
            r.triangle = bvh->tri_index[hint];
            r.slot = hint;
        }
    }
    stack[sp] = 0; stack_d[sp] = box_dist2(&bvh->nodes[0].box, p); ++sp;
    while (sp > 0) {
        --sp;
        if (stack_d[sp] >= best) continue;
        const scc_tri_bvh_node* nd = &bvh->nodes[stack[sp]];
        if (nd->count) {
            for (uint32_t i = nd->first; i < nd->first + nd->count; ++i) {
                if (box_dist2(&bvh->tri_boxes[i], p) >= best) continue;
                const scc_vec3* v = bvh->tris + 3 * (size_t)i;
                scc_vec3 q;
                scc_tri_feature f;
                const double d2 = scc_closest_point_triangle(p, v[0], v[1], v[2], &q, &f);
                if (d2 < best) {
                    best = d2;
                    found = 1;
                    r.dist2 = d2; r.point = q; r.triangle = bvh->tri_index[i]; r.slot = i; r.feature = f;
                }
            }
            continue;
        }
        const uint32_t l = nd->first, rr = nd->first + 1;
        const double dl = box_dist2(&bvh->nodes[l].box, p), dr = box_dist2(&bvh->nodes[rr].box, p);
        if (sp + 2 > 96) continue; /* cannot happen with the median split */
        /* push the farther first so the nearer is popped first */
        if (dl < dr) {
            if (dr < best) { stack[sp] = rr; stack_d[sp] = dr; ++sp; }
            if (dl < best) { stack[sp] = l; stack_d[sp] = dl; ++sp; }
        } else {
            if (dl < best) { stack[sp] = l; stack_d[sp] = dl; ++sp; }
            if (dr < best) { stack[sp] = rr; stack_d[sp] = dr; ++sp; }
        }
    }
    *out = r;
    return found;
}
