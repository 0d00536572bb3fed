/* SPDX-License-Identifier: MIT
 * sdfccd core: the signed distance field interface (a black box to every solver).
 *
 * Conventions (DESIGN.md): metres; phi < 0 inside; grad phi points outward and is the
 * contact normal. An SDF is evaluated in its own local frame.
 *
 * Every concrete SDF embeds `scc_sdf` as its FIRST member, so a pointer to the concrete
 * struct is a pointer to the interface. Evaluation must be pure and thread-safe: solvers
 * call it from several threads at once on the same object.
 */
#ifndef SCC_SDF_H
#define SCC_SDF_H

#include "scc_math.h"

typedef struct scc_sdf scc_sdf;

/* Value at p; writes the gradient to *out_grad when out_grad is not NULL. The gradient
 * should have unit length where the field is a true distance; it must never be NaN. */
typedef double scc_sdf_eval_fn(const scc_sdf* self, scc_vec3 p, scc_vec3* out_grad);

/* Optional: an upper bound on |grad phi| (a Lipschitz constant) valid inside `box`.
 * Grids use it to give per-cell bounds; when NULL the global `lipschitz` is used. */
typedef double scc_sdf_lipschitz_fn(const scc_sdf* self, const scc_aabb* box);

/* Optional: 1 when phi is convex on the whole box (NULL: use the global `convex` flag). */
typedef int scc_sdf_convex_fn(const scc_sdf* self, const scc_aabb* box);

typedef enum scc_sdf_kind {
    SCC_SDF_SPHERE, SCC_SDF_BOX, SCC_SDF_ROUNDED_BOX, SCC_SDF_TORUS, SCC_SDF_CAPSULE,
    SCC_SDF_CYLINDER, SCC_SDF_HALF_SPACE, SCC_SDF_SPIKE_GRID, SCC_SDF_CSG, SCC_SDF_TRANSFORM,
    SCC_SDF_CALLBACK, SCC_SDF_GRID, SCC_SDF_KIND_COUNT
} scc_sdf_kind;

struct scc_sdf {
    scc_sdf_eval_fn* eval;
    scc_sdf_lipschitz_fn* lipschitz_in; /* may be NULL */
    /* Where the values are meaningful (a grid's box). Analytic fields: +-INFINITY. */
    scc_aabb domain;
    /* A box that contains every point with phi <= 0 (may be infinite, e.g. a half-space). */
    scc_aabb bounds;
    /* Global bound on |grad phi|: 1 for exact distance fields and their min/max/rigid combos. */
    double lipschitz;
    /* 1 when phi is a convex function (the signed distance of a convex shape): then
     * phi(x) >= phi(c) + grad(c) . (x - c), which the certified TOI uses. 0 when unknown. */
    int convex;
    scc_sdf_convex_fn* convex_in; /* may be NULL */
    /* 1 when the gradient is continuous outside the surface (no edges, corners, tips or seams):
     * FWGSS then needs neither its kink guard nor the certified check (fwgss.c, certified.c).
     * 0 when it may jump or is unknown. */
    int smooth;
    scc_sdf_kind kind;
};

/* A user's field (the public API's sdfccd_create_callback_sdf): the user's function, of the public
 * type sdfccd_SdfEvalFcn or sdfccd_SdfEvalXyzFcn (one of the two is set), and its pointer. eval is scc_sdf_user_eval (sdf_user.h), which calls the
 * function; the solvers call it directly for phi alone (fw_common.h), one call less per sample. The
 * function is kept as a generic function pointer (core does not include the public headers;
 * sdf_user.h converts it back to its type). */
typedef void scc_generic_fn(void);
typedef struct scc_sdf_user {
    scc_sdf base; /* first member; eval = scc_sdf_user_eval */
    scc_generic_fn* fn;     /* sdfccd_SdfEvalFcn, or NULL */
    scc_generic_fn* fn_xyz; /* sdfccd_SdfEvalXyzFcn (the point as three coordinates), or NULL */
    void* user;
} scc_sdf_user;

/* phi of a user's field (scc_sdf_user) and its gradient when g is not NULL: (0, 0, 1) where the
 * function leaves it unset or writes a non-finite one (never NaN to a solver). */
double scc_sdf_user_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g);

static inline double scc_sdf_eval(const scc_sdf* s, scc_vec3 p, scc_vec3* out_grad)
{
    return s->eval(s, p, out_grad);
}

/* Lipschitz bound valid inside `box` (falls back to the global bound). */
static inline double scc_sdf_lipschitz(const scc_sdf* s, const scc_aabb* box)
{
    return s->lipschitz_in ? s->lipschitz_in(s, box) : s->lipschitz;
}

/* 1 when phi is known to be convex on `box`. */
static inline int scc_sdf_convex_in(const scc_sdf* s, const scc_aabb* box)
{
    return s->convex || (s->convex_in && s->convex_in(s, box));
}

#endif
