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
    double bary[3];          /* ROLLED_BACK by the CCD: the point's weights on the triangle */
    double level;            /* ROLLED_BACK by the CCD: the level it reached (-tolerance, lower if it started deep) */
    double min_gap_start;    /* smallest phi at t0 of a contact the queries saw (INFINITY: none) */
    scc_state query_state;   /* state of the last mesh query */
    int64_t evals;           /* SDF evaluations, all queries */
    int queries;             /* mesh queries run (1, or more when some triangles started deep) */
    uint32_t deep_triangles; /* triangles that started deeper than the tolerance */
    /* scc_guard_step only: */
    int pinned;              /* no time after t0 is safe: the body is to stay at its start pose */
    int certified;           /* the motion was proven clear without a CCD (or did not move) */
    int64_t uncertified;     /* triangles the certificate left to the CCD (-1: it did not apply) */
    int bisections;          /* 1 when the discrete check moved the safe time */
} scc_guard_out;

/* Checks the motion `mm` (rigid or per-vertex linear) over [mm->t0, mm->t1]: the earliest time a
 * point reaches phi = -tolerance (a triangle that starts deeper: its start depth - tolerance). `p`
 * gives the method and caps (its margin and subdivision are not used). Returns 0 on allocation failure. */
int scc_guard(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, double tolerance, scc_workspace* ws,
              scc_guard_out* out);

/* What an engine does after a step (the rigid motion `mm` it executed): where to put the body.
 * (0) A motion that does not move relative to a static SDF is CLEAR (nothing gets deeper).
 * (1) The certificate (scc_bsh_certify) at level -tolerance/2 proves the nodes of the mesh's BSH
 *     that stay clear; when all do, CLEAR without a CCD; otherwise the checks below skip them.
 * (2) scc_guard at the tolerance. A rollback goes back further, to the first time a point was at
 *     -tolerance/2 (scc_guard over [t0, toi] at half the tolerance; else the first point's own time
 *     at that level), so that the body starts the next step shallower than the tolerance.
 * (3) The pose at the safe time is checked with the discrete query (another local search: it
 *     catches what the CCD missed, e.g. a large triangle reaching the surface in two places) at
 *     -tolerance (-tolerance/2 after a rollback); a point found there sends the body back: pinned
 *     at t0 when the start pose has a point below -tolerance/2, else to the last time that check
 *     finds none (bisection, 12 halvings); `pinned` when that is t0.
 * INSIDE_AT_START returns after (2) (left to the contacts). Rigid motion only (mm->body). */
int scc_guard_step(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, double tolerance, scc_workspace* ws,
                   scc_guard_out* out);

/* Whether a check's rollback at `toi` goes back before the body's earliest so far (`best_toi`; the
 * end of the step at first). A body checked part by part against several SDFs goes back to the
 * earliest of its rollbacks; of equal times the first one checked is kept. */
static inline int scc_guard_earlier(int rolled_back, double toi, double best_toi)
{
    return rolled_back && toi < best_toi;
}

/* The guard's broad phase (Section 4.6): a box holding a rigid body at every time of a step in which
 * its origin moves on the segment o0 -> o1 while it turns by `angle` (rad, <= pi) about a fixed axis
 * through the origin at a constant rate. `a` and `b` hold it at the two ends. Without a turn their
 * union holds the whole translation. With one, a point at distance r <= `reach` from the origin
 * leaves the segment between its end positions by at most r angle^2 / 8 (its acceleration r angle^2
 * over the step, zero at both ends): the union grown by that much, cut by the origin segment's box
 * grown by `reach`. Inputs are not checked here. */
void scc_swept_aabb(const scc_aabb* a, const scc_aabb* b, scc_vec3 o0, scc_vec3 o1, double reach, double angle, scc_aabb* out);

/* A rigid body's velocity state for the guard's response (world frame). */
typedef struct scc_body_state {
    scc_vec3 center;         /* centre of mass */
    scc_vec3 v, w;           /* linear velocity of the centre, angular velocity */
    double inv_mass;
    double inv_inertia[9];   /* world inverse inertia tensor, row-major */
} scc_body_state;

/* The velocity a rolled-back body leaves with (an SDF body `sdf_body`, NULL: static, counts as
 * infinitely heavy). `pinned`: the body takes the SDF body's motion (at rest relative to it).
 * Else, when `repeated` (the body was rolled back in the previous step as well: its contacts did not
 * stop it), it loses its velocity into the surface at `point` along `normal`: first its centre's,
 * then, if the point still approaches (a spin), an inelastic impulse at the point along the normal
 * makes the approach zero, with Coulomb friction `mu` reducing the point's tangential velocity by at
 * most mu times that impulse. Otherwise the velocity is kept (the next step's contacts take the impact). */
void scc_guard_response(scc_vec3 point, scc_vec3 normal, int pinned, int repeated, const scc_body_state* sdf_body, double mu,
                        scc_body_state* body);

/* One contact of a body after an engine's solve (world frame): where the impulses act, the unit
 * normal from the SDF to the body, the SDF's velocity there, the friction impulse the solver applied
 * to the body there, the solver's normal impulse and the Coulomb coefficient. */
typedef struct scc_held_contact {
    scc_vec3 point, normal, surface_velocity, applied;
    double normal_impulse, mu;
} scc_held_contact;

/* Gauss-Seidel passes of scc_friction_hold over the contacts, and the most contacts of one call. */
#define SCC_HOLD_PASSES 16
#define SCC_HOLD_MAX 64

/* Static friction an engine's solve left out (Bullet's one friction direction per point leaves the
 * other free): passes over the contacts (at most SCC_HOLD_MAX) each add the tangential impulse that
 * stops the point sliding relative to the SDF, with the solver's friction and the added one together
 * kept within the point's Coulomb cone (mu times the solver's normal impulse and any added one), and
 * a normal impulse (>= 0) wherever the added turn would make a point approach the surface faster than
 * after the solve. `held` (count) receives each point's added impulse; `body`'s velocities are updated. */
void scc_friction_hold(const scc_held_contact* c, size_t count, scc_vec3* held, scc_body_state* body);

#endif
