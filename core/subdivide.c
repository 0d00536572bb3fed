/* SPDX-License-Identifier: MIT
 * sdfccd core: adaptive triangle subdivision for extra contacts at the time of impact
 * (Pelletier-Guenette et al. 2025, Section 4.5, Fig. 3).
 *
 * A region (first the whole triangle) holding a known contact is split at its centroid g into
 * A = (b, c, g), B = (a, g, c), C = (a, b, g) (Eq. 21). The child holding the known contact keeps
 * it; DCD searches each other child for its deepest point, and a child whose deepest point is in
 * contact (phi <= margin + contact_slop) yields a new contact and is split in turn. Children
 * with no contact are dropped (a Lipschitz test rejects most of them without DCD). Splitting
 * stops below the minimum area or at the depth cap (edge contacts never yield non-collinear
 * points, so without a cap they recurse to the area floor), and the search stops as soon as
 * two extra points that are not collinear with the first contact are known. */
#include "ccd.h"

#define MAX_REGIONS 96

typedef struct sub_region {
    double c[3][3]; /* corners as barycentric weights of the full triangle */
    double pt[3];   /* the known contact inside, as weights of the full triangle */
    int depth;      /* 0 for the whole triangle */
} sub_region;

static scc_vec3 from_bary(const scc_vec3 tri[3], const double b[3])
{
    return scc_add(scc_add(scc_scale(tri[0], b[0]), scc_scale(tri[1], b[1])), scc_scale(tri[2], b[2]));
}

/* Weights of point q (full-triangle weights) relative to the region's corners. */
static void local_weights(const sub_region* r, const double q[3], double out[3])
{
    double a00 = r->c[0][0] - r->c[2][0], a01 = r->c[1][0] - r->c[2][0];
    double a10 = r->c[0][1] - r->c[2][1], a11 = r->c[1][1] - r->c[2][1];
    double b0 = q[0] - r->c[2][0], b1 = q[1] - r->c[2][1];
    double det = a00 * a11 - a01 * a10;
    if (det == 0.0) { out[0] = out[1] = out[2] = 1.0 / 3.0; return; }
    out[0] = (b0 * a11 - a01 * b1) / det;
    out[1] = (a00 * b1 - b0 * a10) / det;
    out[2] = 1.0 - out[0] - out[1];
}

static double region_fraction(const sub_region* r)
{
    double a00 = r->c[0][0] - r->c[2][0], a01 = r->c[1][0] - r->c[2][0];
    double a10 = r->c[0][1] - r->c[2][1], a11 = r->c[1][1] - r->c[2][1];
    return fabs(a00 * a11 - a01 * a10);
}

static int noncollinear(scc_vec3 a, scc_vec3 b, scc_vec3 c, double scale2)
{
    return scc_triangle_area2(a, b, c) > 1e-6 * scale2;
}

int scc_subdivide(const scc_sdf* sdf, const scc_vec3 tri[3], const double primary[3], const scc_params* p,
                  scc_contact* out, int capacity, int64_t* io_evals)
{
    const double threshold = p->margin + p->contact_slop;
    const double full_area = 0.5 * scc_triangle_area2(tri[0], tri[1], tri[2]);
    double scale2 = fmax(scc_len2(scc_sub(tri[1], tri[0])), fmax(scc_len2(scc_sub(tri[2], tri[1])), scc_len2(scc_sub(tri[0], tri[2]))));
    const double dup2 = 1e-8 * scale2;
    const scc_vec3 p0 = from_bary(tri, primary);

    /* Extra contacts need their deepest point only to within a fraction of the slop. */
    scc_params dcd_params = *p;
    dcd_params.dist_tol = fmax(p->dist_tol, 0.01 * p->contact_slop);
    sub_region queue[MAX_REGIONS];
    int head = 0, tail = 0, count = 0;
    sub_region root = { { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } }, { primary[0], primary[1], primary[2] }, 0 };
    queue[tail++] = root;

    while (head < tail && count < capacity && *io_evals < p->max_evals) {
        sub_region r = queue[head++];
        if (full_area * region_fraction(&r) / 3.0 < p->sub_min_area || r.depth >= p->sub_max_depth) continue;
        double g[3];
        for (int j = 0; j < 3; ++j) g[j] = (r.c[0][j] + r.c[1][j] + r.c[2][j]) / 3.0;
        sub_region kids[3];
        /* Eq. 21: A = (b, c, g), B = (a, g, c), C = (a, b, g). */
        const double* corners[3][3] = { { r.c[1], r.c[2], g }, { r.c[0], g, r.c[2] }, { r.c[0], r.c[1], g } };
        for (int k = 0; k < 3; ++k) {
            kids[k].depth = r.depth + 1;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) kids[k].c[i][j] = corners[k][i][j];
        }
        double lw[3];
        local_weights(&r, r.pt, lw);
        int home = (lw[0] <= lw[1] && lw[0] <= lw[2]) ? 0 : (lw[1] <= lw[0] && lw[1] <= lw[2]) ? 1 : 2;
        for (int k = 0; k < 3 && count < capacity; ++k) {
            if (k == home) {
                for (int j = 0; j < 3; ++j) kids[k].pt[j] = r.pt[j];
                if (tail < MAX_REGIONS) queue[tail++] = kids[k];
                continue;
            }
            scc_vec3 sub[3];
            for (int i = 0; i < 3; ++i) sub[i] = from_bary(tri, kids[k].c[i]);
            /* Exact cull: phi(c) - L r > threshold means no point of the child is in contact. */
            scc_vec3 mid = scc_scale(scc_add(scc_add(sub[0], sub[1]), sub[2]), 1.0 / 3.0);
            double rad = fmax(scc_dist(mid, sub[0]), fmax(scc_dist(mid, sub[1]), scc_dist(mid, sub[2])));
            scc_aabb box = { scc_sub(mid, scc_v3(rad, rad, rad)), scc_add(mid, scc_v3(rad, rad, rad)) };
            ++*io_evals;
            if (scc_sdf_eval(sdf, mid, NULL) - scc_sdf_lipschitz(sdf, &box) * rad > threshold) continue;
            scc_dcd_result d = scc_dcd(sdf, sub, &dcd_params);
            *io_evals += d.evals;
            if (!(d.phi <= threshold)) continue; /* no contact in this child: drop it */
            for (int j = 0; j < 3; ++j)
                kids[k].pt[j] = d.bary[0] * kids[k].c[0][j] + d.bary[1] * kids[k].c[1][j] + d.bary[2] * kids[k].c[2][j];
            int dup = scc_len2(scc_sub(d.point, p0)) <= dup2;
            for (int i = 0; i < count && !dup; ++i) dup = scc_len2(scc_sub(d.point, out[i].point)) <= dup2;
            if (tail < MAX_REGIONS) queue[tail++] = kids[k];
            if (dup) continue;
            scc_contact* c = &out[count++];
            c->point = d.point;
            c->normal = d.normal;
            c->distance = d.phi;
            for (int j = 0; j < 3; ++j) c->bary[j] = kids[k].pt[j];
            c->kind = SCC_CONTACT_SUBDIVISION;
            /* Two extra points not collinear with the first contact suffice (Section 4.5). */
            for (int i = 0; i + 1 < count; ++i)
                if (noncollinear(p0, out[i].point, c->point, scale2)) return count;
        }
    }
    return count;
}
