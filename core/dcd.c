/* SPDX-License-Identifier: MIT
 * sdfccd core: triangle-SDF discrete collision detection (Pelletier-Guenette et al. 2025,
 * Section 3.2, after Macklin et al. 2020). Frank-Wolfe over the barycentric coordinates:
 * start at the vertex with the smallest phi, pick the support vertex minimising
 * grad phi . vertex (Eq. 4), golden-section line search towards it (Algorithm 1). */
#include "ccd.h"
#include "gss.h"

typedef struct segment_ctx {
    const scc_sdf* sdf;
    scc_vec3 a, b;
} segment_ctx;

static double segment_phi(double l, void* c)
{
    const segment_ctx* s = c;
    return scc_sdf_eval(s->sdf, scc_lerp(s->a, s->b, l), NULL);
}

/* The search from the vertex values phi[3] (`evals` of them evaluated here). */
static scc_dcd_result dcd_from(const scc_sdf* sdf, const scc_vec3 tri[3], const double phi[3], int evals, const scc_params* p)
{
    scc_dcd_result r;
    int best = 0;
    for (int i = 1; i < 3; ++i)
        if (phi[i] < phi[best]) best = i;
    r.evals = evals;
    r.iterations = 0;
    r.converged = 0;
    double b[3] = { 0, 0, 0 };
    b[best] = 1.0;
    scc_vec3 x = tri[best];
    scc_vec3 g;
    double fx = scc_sdf_eval(sdf, x, &g);
    r.evals++;
    while (r.iterations < p->max_iter && r.evals < p->max_evals) {
        r.iterations++;
        int s = 0;
        double ds = scc_dot(g, tri[0]);
        for (int j = 1; j < 3; ++j) {
            double d = scc_dot(g, tri[j]);
            if (d < ds) { ds = d; s = j; }
        }
        /* Frank-Wolfe gap: no vertex descends along the gradient, x is stationary. */
        double len = scc_dist(tri[s], x);
        if (ds >= scc_dot(g, x) || len <= p->dist_tol) { r.converged = 1; break; }
        segment_ctx ctx = { sdf, x, tri[s] };
        scc_gss_result ls = scc_gss_minimize(0.0, 1.0, p->dist_tol / len, p->max_ls_iter, segment_phi, &ctx);
        r.evals += ls.evals;
        if (!(ls.f < fx)) { r.converged = 1; break; } /* no improvement along the segment */
        scc_vec3 xn = scc_lerp(x, tri[s], ls.l);
        for (int j = 0; j < 3; ++j) b[j] *= 1.0 - ls.l;
        b[s] += ls.l;
        double step = scc_dist(xn, x);
        x = xn;
        fx = scc_sdf_eval(sdf, x, &g);
        r.evals++;
        if (step <= p->dist_tol) { r.converged = 1; break; }
    }
    r.phi = fx;
    r.point = x;
    r.normal = g;
    for (int j = 0; j < 3; ++j) r.bary[j] = b[j];
    return r;
}

scc_dcd_result scc_dcd(const scc_sdf* sdf, const scc_vec3 tri[3], const scc_params* p)
{
    double phi[3];
    for (int i = 0; i < 3; ++i) phi[i] = scc_sdf_eval(sdf, tri[i], NULL);
    return dcd_from(sdf, tri, phi, 3, p);
}

scc_dcd_result scc_dcd_traced(const scc_sdf* sdf, const scc_vec3 tri[3], scc_vertex_trace* const rec[3], double t, const scc_params* p)
{
    double phi[3];
    int evals = 0;
    for (int i = 0; i < 3; ++i) {
        scc_vertex_trace* r = rec ? rec[i] : NULL;
        if (r && r->hit_t == t) {
            phi[i] = r->hit_phi;
            continue;
        }
        phi[i] = scc_sdf_eval(sdf, tri[i], NULL);
        ++evals;
        if (r && r->hit_t == INFINITY) {
            r->hit_t = t;
            r->hit_phi = phi[i];
        }
    }
    return dcd_from(sdf, tri, phi, evals, p);
}
