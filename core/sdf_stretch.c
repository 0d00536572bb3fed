/* SPDX-License-Identifier: MIT
 * sdfccd core: an SDF stretched by a different factor along each axis (an engine's non-uniform
 * local scaling of a shape). Distances do not stretch with the shape, so the field is the child's
 * at x / s times the smallest factor: phi(x) = min(s) * phi_child(x / s). Its gradient,
 * min(s) * grad_child / s, is no longer than the child's, so it keeps the child's Lipschitz bound,
 * sign and zero set, and it never exceeds the distance to the stretched solid (the certified TOI
 * and the solvers' steps need a lower bound, not the exact distance; paper Section 3.1). */
#include "sdf_stretch.h"

static double stretch_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    const scc_sdf_stretch* s = (const scc_sdf_stretch*)self;
    scc_vec3 q = scc_v3(p.x / s->scale.x, p.y / s->scale.y, p.z / s->scale.z);
    /* A point so far that dividing by a small factor overflows: clamped (as a transform does). */
    if (!scc_vfinite(q) && !isnan(q.x + q.y + q.z)) q = scc_vmax(scc_vmin(q, scc_v3(1e300, 1e300, 1e300)), scc_v3(-1e300, -1e300, -1e300));
    scc_vec3 gc;
    const double v = scc_sdf_eval(s->child, q, g ? &gc : NULL);
    if (g) *g = scc_v3(gc.x * s->min_scale / s->scale.x, gc.y * s->min_scale / s->scale.y, gc.z * s->min_scale / s->scale.z);
    return s->min_scale * v;
}

/* The box scaled per axis (infinite stays infinite: the factors are positive). */
static scc_aabb stretch_box(scc_aabb b, scc_vec3 k)
{
    scc_aabb r = { scc_v3(b.lo.x * k.x, b.lo.y * k.y, b.lo.z * k.z), scc_v3(b.hi.x * k.x, b.hi.y * k.y, b.hi.z * k.z) };
    return r;
}

/* The child's bound over the box taken back to its frame. */
static double stretch_lipschitz_in(const scc_sdf* self, const scc_aabb* box)
{
    const scc_sdf_stretch* s = (const scc_sdf_stretch*)self;
    const scc_aabb local = stretch_box(*box, scc_v3(1.0 / s->scale.x, 1.0 / s->scale.y, 1.0 / s->scale.z));
    return scc_sdf_lipschitz(s->child, &local);
}

void scc_sdf_stretch_init(scc_sdf_stretch* s, const scc_sdf* child, scc_vec3 scale)
{
    s->base.eval = stretch_eval;
    s->base.lipschitz_in = child->lipschitz_in ? stretch_lipschitz_in : NULL;
    s->base.domain = stretch_box(child->domain, scale);
    s->base.bounds = stretch_box(child->bounds, scale);
    s->base.lipschitz = child->lipschitz;
    s->base.convex = child->convex; /* a convex function of a linear map of x, times a positive factor */
    s->base.convex_in = NULL;
    s->base.smooth = child->smooth; /* a linear change of variables keeps the gradient continuous */
    s->base.kind = SCC_SDF_TRANSFORM;
    s->child = child;
    s->scale = scale;
    s->min_scale = fmin(scale.x, fmin(scale.y, scale.z));
}
