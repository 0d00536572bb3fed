/* SPDX-License-Identifier: MIT
 * sdfccd core: Frank-Wolfe for triangle-SDF CCD (Pelletier-Guenette et al. 2025, Section 4.2).
 * Minimises phi over (u, v, w, t) with the step alpha = 2 / (i + 2); the spatial direction is the
 * support vertex (Eq. 15-16), the temporal direction is Eq. 17, and every witnessed contact
 * (phi <= margin) shrinks the time interval. Also the helpers shared with FWGSS. */
#include "fw_common.h"

void scc_fw_begin(scc_fw_state* s, const scc_sdf* sdf, const scc_tri_motion* m, const scc_params* p, double ta, double tb)
{
    s->sdf = sdf;
    s->torus = sdf->kind == SCC_SDF_TORUS && sdf->eval == scc_sdf_torus_eval ? (const scc_sdf_torus*)sdf : NULL;
    s->user = sdf->eval == scc_sdf_user_eval ? (const scc_sdf_user*)sdf : NULL;
    s->margin = p->margin;
    s->m = m;
    s->p = p;
    s->ts = ta;
    s->te = tb;
    s->hit = 0;
    s->hit_t = tb;
    s->evals = 0;
    s->b[0] = 1.0; s->b[1] = 0.0; s->b[2] = 0.0;
    s->dist_tol = p->dist_tol;
    s->time_slope = 0.0;
    scc_fw_prepare_motion(s);
}

void scc_fw_prepare_motion(scc_fw_state* s)
{
    const scc_tri_motion* m = s->m;
    s->fast = m->kind == SCC_TRI_RIGID && m->sdf == NULL;
    s->cache_t = NAN;
    s->pt_valid = 0;
    s->wlen = 0.0;
    if (!s->fast) return;
    const scc_rigid* r = m->body;
    s->t0 = r->t0;
    s->g0 = scc_rigid_center_at(r, r->t0);
    s->v = r->v;
    s->w = r->w;
    s->wlen = scc_len(r->w);
    s->axis = s->wlen > 0.0 ? scc_scale(r->w, 1.0 / s->wlen) : scc_v3(0, 0, 1);
    for (int i = 0; i < 3; ++i) {
        s->r0[i] = scc_quat_rotate(r->q0, scc_sub(m->local[i], r->c_local));
        s->kr0[i] = scc_cross(s->axis, s->r0[i]);
        s->kd0[i] = scc_dot(s->axis, s->r0[i]);
    }
    s->base_t = isfinite(s->ts) && isfinite(s->te) ? 0.5 * (s->ts + s->te) : s->t0;
    double a = s->wlen * (s->base_t - s->t0);
    s->base_c = cos(a);
    s->base_s = sin(a);
}

void scc_fw_start_order(scc_fw_state* s, int order[3])
{
    scc_tri_state st;
    scc_fw_tri_state(s, s->ts, &st);
    double score[3];
    for (int i = 0; i < 3; ++i) {
        double b[3] = { i == 0, i == 1, i == 2 };
        scc_vec3 g;
        double phi = scc_fw_sdf(s, st.x[i], &g);
        s->evals++;
        scc_fw_witness(s, s->ts, b, phi);
        score[i] = scc_dot(st.v[i], g);
        order[i] = i;
    }
    for (int i = 1; i < 3; ++i)
        for (int j = i; j > 0 && score[order[j]] < score[order[j - 1]]; --j) {
            int tmp = order[j];
            order[j] = order[j - 1];
            order[j - 1] = tmp;
        }
}

void scc_fw_start_vertex(scc_fw_state* s)
{
    int order[3];
    scc_fw_start_order(s, order);
    s->b[0] = order[0] == 0; s->b[1] = order[0] == 1; s->b[2] = order[0] == 2;
}

void scc_fw_finish(scc_fw_state* s, int converged, int64_t iterations, scc_tri_hit* out)
{
    out->iterations = iterations;
    out->hit = s->hit;
    if (s->hit) {
        out->toi = s->hit_t;
        for (int j = 0; j < 3; ++j) out->bary[j] = s->hit_b[j];
        out->point = scc_fw_point(s, s->hit_b, s->hit_t, NULL);
        out->distance = scc_fw_sdf(s, out->point, &out->normal);
        s->evals++;
        out->state = !converged ? SCC_NOT_CONVERGED : (s->hit_t <= s->ts ? SCC_PENETRATING : SCC_HIT);
    } else {
        out->toi = s->te;
        out->bary[0] = s->b[0]; out->bary[1] = s->b[1]; out->bary[2] = s->b[2];
        out->point = scc_v3(0, 0, 0);
        out->normal = scc_v3(0, 0, 1);
        out->distance = INFINITY;
        out->state = converged ? SCC_NO_HIT : SCC_NOT_CONVERGED;
    }
    out->toi_lower = out->toi;
    out->evals = s->evals;
}

void scc_fw(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p, scc_tri_hit* out)
{
    scc_fw_state s;
    scc_fw_begin(&s, sdf, m, p, ta, tb);
    scc_fw_start_vertex(&s);
    double t = ta;
    int converged = 0;
    int64_t it = 0;
    while (it < p->max_iter && s.evals < p->max_evals) {
        double alpha = 2.0 / ((double)it + 2.0);
        ++it;
        scc_vec3 x, g, v;
        double phi = scc_fw_eval(&s, s.b, t, &x, &g, &v);
        double d = phi <= p->margin ? -1.0 : (scc_dot(g, v) > 0.0 ? -1.0 : 1.0); /* Eq. 17 */
        scc_tri_state st;
        scc_fw_tri_points(&s, t, &st);
        int sv = scc_fw_support(&st, g);
        double tn = scc_clamp(t + alpha * (s.te - s.ts) * d, s.ts, s.te); /* Eq. 18-19 */
        double bn[3];
        for (int j = 0; j < 3; ++j) bn[j] = (1.0 - alpha) * s.b[j] + alpha * (j == sv); /* Eq. 20 */
        scc_vec3 xn = scc_fw_point(&s, bn, tn, NULL);
        int small = fabs(tn - t) <= p->time_tol && scc_dist(xn, x) <= p->dist_tol;
        t = tn;
        for (int j = 0; j < 3; ++j) s.b[j] = bn[j];
        if (small) { converged = 1; break; }
    }
    scc_fw_finish(&s, converged, it, out);
}
