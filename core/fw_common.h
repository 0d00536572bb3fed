/* SPDX-License-Identifier: MIT
 * sdfccd core: state shared by the two spatio-temporal Frank-Wolfe solvers (fw.c, fwgss.c):
 * the shrinking time bound, the earliest witnessed contact, and evaluation helpers. */
#ifndef SCC_FW_COMMON_H
#define SCC_FW_COMMON_H

#include "ccd.h"

typedef struct scc_fw_state {
    const scc_sdf* sdf;
    const scc_tri_motion* m;
    const scc_params* p;
    double ts, te;          /* the interval; te shrinks to the earliest witnessed contact */
    int hit;
    double hit_t, hit_b[3];
    double b[3];            /* current barycentric weights */
    int64_t evals;
} scc_fw_state;

/* Records a contact witness (phi <= margin) at time t with weights b: shrinks te. */
static inline void scc_fw_witness(scc_fw_state* s, double t, const double b[3], double phi)
{
    if (phi <= s->p->margin && (!s->hit || t < s->hit_t)) {
        s->hit = 1;
        s->hit_t = t;
        s->hit_b[0] = b[0]; s->hit_b[1] = b[1]; s->hit_b[2] = b[2];
        if (t < s->te) s->te = t;
    }
}

/* phi (and gradient, velocity) of the current weights at time t; records witnesses. */
static inline double scc_fw_eval(scc_fw_state* s, const double b[3], double t, scc_vec3* x, scc_vec3* g, scc_vec3* v)
{
    *x = scc_tri_point_at(s->m, b, t, v);
    double phi = scc_sdf_eval(s->sdf, *x, g);
    s->evals++;
    scc_fw_witness(s, t, b, phi);
    return phi;
}

void scc_fw_begin(scc_fw_state* s, const scc_sdf* sdf, const scc_tri_motion* m, const scc_params* p, double ta, double tb);
/* Section 4.4: the vertex minimising v . grad phi at ts; sets s->b. */
void scc_fw_start_vertex(scc_fw_state* s);
/* The three vertices ordered by the Section 4.4 score (most promising first). */
void scc_fw_start_order(scc_fw_state* s, int order[3]);
/* Index of the vertex of `st` minimising grad . vertex (Eq. 15). */
int scc_fw_support(const scc_tri_state* st, scc_vec3 g);
/* Fills `out` from the solver state once the iterations end. */
void scc_fw_finish(scc_fw_state* s, int converged, int64_t iterations, scc_tri_hit* out);

#endif
