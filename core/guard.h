/* SPDX-License-Identifier: MIT
 * sdfccd core: the no-tunnelling guarantee (guard.c). Stateless: the inputs of a mesh query, the
 * tolerance, and a result struct. Points and normals are in the SDF's local frame. */
#ifndef SCC_GUARD_H
#define SCC_GUARD_H

#include "ccd.h"

typedef enum scc_guard_state { SCC_GUARD_CLEAR, SCC_GUARD_ROLLED_BACK, SCC_GUARD_INSIDE_AT_START } scc_guard_state;

typedef struct scc_guard_out {
    scc_guard_state state;
    double toi;              /* the safe time: t1 unless ROLLED_BACK */
    scc_vec3 point, normal;  /* ROLLED_BACK: the first point to reach its level, and grad phi there, at toi */
    uint32_t triangle;       /* ROLLED_BACK: its triangle */
    double min_gap_start;    /* smallest phi at t0 of a contact the queries saw (INFINITY: none) */
    scc_state query_state;   /* state of the last mesh query */
    int64_t evals;           /* SDF evaluations, all queries */
    int queries;             /* mesh queries run (1, or more when some triangles started deep) */
    uint32_t deep_triangles; /* triangles that started deeper than the tolerance */
} scc_guard_out;

/* Checks the motion `mm` (rigid or per-vertex linear) over [mm->t0, mm->t1]: the earliest time a
 * point reaches phi = -tolerance (a triangle that starts deeper: its start depth - tolerance). `p`
 * gives the method and caps (its margin and subdivision are not used). Returns 0 on allocation failure. */
int scc_guard(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, double tolerance, scc_workspace* ws,
              scc_guard_out* out);

#endif
