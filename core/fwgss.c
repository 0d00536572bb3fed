/* SPDX-License-Identifier: MIT
 * sdfccd core: Frank-Wolfe with golden-section line searches, FWGSS (Pelletier-Guenette et al.
 * 2025, Algorithm 2, Sections 4.3-4.4). Each iteration solves a temporal line search (unsigned
 * distance backwards in time when the iterate is in contact, else signed distance in the
 * direction of Eq. 17) and then a spatial line search towards the support vertex at the new time.
 * Every evaluated point in contact is a witness that shrinks the time interval, so the earliest
 * witnessed time converges to the first time of impact from above. */
#include "fw_common.h"
#include "gss.h"

static double phi_at_time(double t, void* c)
{
    scc_fw_state* s = c;
    scc_vec3 x = scc_tri_point_at(s->m, s->b, t, NULL);
    double phi = scc_sdf_eval(s->sdf, x, NULL);
    s->evals++;
    scc_fw_witness(s, t, s->b, phi);
    return phi - s->p->margin;
}

static double unsigned_phi_at_time(double t, void* c) { return fabs(phi_at_time(t, c)); }

typedef struct space_ctx {
    scc_fw_state* s;
    scc_vec3 a, b;      /* segment from the iterate to the support vertex */
    double ba[3], bb[3];
    double t;
} space_ctx;

static double phi_on_segment(double l, void* c)
{
    space_ctx* k = c;
    double phi = scc_sdf_eval(k->s->sdf, scc_lerp(k->a, k->b, l), NULL);
    k->s->evals++;
    if (phi <= k->s->p->margin) {
        double b[3];
        for (int j = 0; j < 3; ++j) b[j] = (1.0 - l) * k->ba[j] + l * k->bb[j];
        scc_fw_witness(k->s, k->t, b, phi);
    }
    return phi;
}

void scc_fwgss(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p, scc_tri_hit* out)
{
    scc_fw_state s;
    scc_fw_begin(&s, sdf, m, p, ta, tb);
    scc_fw_start_vertex(&s);
    double t = ta;
    int converged = 0;
    int64_t it = 0;
    while (it < p->max_iter) {
        ++it;
        /* Temporal sub-problem (lines 5-21). */
        scc_vec3 x, g, v;
        double phi = scc_fw_eval(&s, s.b, t, &x, &g, &v);
        scc_gss_result ls;
        if (phi <= p->margin)
            ls = scc_gss_minimize(s.ts, t, p->time_tol, p->max_ls_iter, unsigned_phi_at_time, &s);
        else if (scc_dot(g, v) > 0.0) /* d = -1: moving away, look back in time */
            ls = scc_gss_minimize(s.ts, t, p->time_tol, p->max_ls_iter, phi_at_time, &s);
        else
            ls = scc_gss_minimize(t, s.te, p->time_tol, p->max_ls_iter, phi_at_time, &s);
        double tn = fmin(ls.l, s.te);

        /* Spatial sub-problem at the new time (lines 22-31). */
        scc_vec3 xn, gn;
        scc_fw_eval(&s, s.b, tn, &xn, &gn, &v);
        scc_tri_state st;
        scc_tri_state_at(m, tn, &st);
        int sv = scc_fw_support(&st, gn);
        double len = scc_dist(st.x[sv], xn);
        double step = 0.0;
        if (len > p->dist_tol) {
            space_ctx k = { &s, xn, st.x[sv], { s.b[0], s.b[1], s.b[2] }, { sv == 0, sv == 1, sv == 2 }, tn };
            scc_gss_result sp = scc_gss_minimize(0.0, 1.0, p->dist_tol / len, p->max_ls_iter, phi_on_segment, &k);
            for (int j = 0; j < 3; ++j) s.b[j] = (1.0 - sp.l) * s.b[j] + sp.l * (j == sv);
            step = sp.l * len;
        }
        int small = fabs(tn - t) <= p->time_tol && step <= p->dist_tol; /* line 32 */
        t = tn;
        if (small) { converged = 1; break; }
    }
    scc_fw_finish(&s, converged, it, out);
}
