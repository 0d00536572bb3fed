/* SPDX-License-Identifier: MIT
 * sdfccd core: analytic SDFs (exact distances and gradients), CSG and rigid+uniform-scale
 * transforms. These are the analytic fields of the paper's scenes (Section 5: box, sphere,
 * torus of Fig. 2, spike grid of Fig. 10 / Table 3, the CSG hoop of Fig. 8).
 * Every field here is 1-Lipschitz, which the certified TOI relies on. */
#include "sdf_analytic.h"

static const scc_vec3 k_up = { 0.0, 0.0, 1.0 };

static scc_aabb box_infinite(void)
{
    scc_aabb b = { { -INFINITY, -INFINITY, -INFINITY }, { INFINITY, INFINITY, INFINITY } };
    return b;
}

static scc_aabb box_sym(scc_vec3 h)
{
    scc_aabb b = { scc_scale(h, -1.0), h };
    return b;
}

static void base_init(scc_sdf* b, scc_sdf_eval_fn* fn, scc_sdf_kind kind, scc_aabb bounds)
{
    b->eval = fn;
    b->lipschitz_in = NULL;
    b->convex_in = NULL;
    b->domain = box_infinite();
    b->bounds = bounds;
    b->lipschitz = 1.0;
    b->kind = kind;
    /* The signed distance of a convex shape is a convex function. */
    b->convex = kind == SCC_SDF_SPHERE || kind == SCC_SDF_BOX || kind == SCC_SDF_ROUNDED_BOX || kind == SCC_SDF_CAPSULE ||
                kind == SCC_SDF_CYLINDER || kind == SCC_SDF_HALF_SPACE;
    b->smooth = kind == SCC_SDF_SPHERE || kind == SCC_SDF_TORUS || kind == SCC_SDF_CAPSULE || kind == SCC_SDF_ROUNDED_BOX ||
                kind == SCC_SDF_HALF_SPACE;
}


/* ---- sphere ---- */
double scc_sdf_sphere_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    return scc_sdf_sphere_value((const scc_sdf_sphere*)self, p, g);
}
void scc_sdf_sphere_init(scc_sdf_sphere* s, double r)
{
    base_init(&s->base, scc_sdf_sphere_eval, SCC_SDF_SPHERE, box_sym(scc_v3(r, r, r)));
    s->radius = r;
}

/* ---- box and rounded box: inner box of half (h - r), inflated by r ---- */
double scc_sdf_box_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    return scc_sdf_box_value((const scc_sdf_box*)self, p, g);
}
void scc_sdf_box_init(scc_sdf_box* s, scc_vec3 half, double radius)
{
    base_init(&s->base, scc_sdf_box_eval, radius > 0.0 ? SCC_SDF_ROUNDED_BOX : SCC_SDF_BOX, box_sym(half));
    s->half = half;
    s->radius = radius;
}

/* ---- torus around z ---- */
double scc_sdf_torus_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    return scc_sdf_torus_value((const scc_sdf_torus*)self, p, g);
}
/* phi = h(rho, z) with h(a, z) = |(a - R, z)| - r convex, and nondecreasing in a where a >= R; rho
 * is convex, so phi is convex wherever rho >= R on a convex set (the outer half of the torus). */
static int torus_convex_in(const scc_sdf* self, const scc_aabb* b)
{
    const scc_sdf_torus* s = (const scc_sdf_torus*)self;
    double dx = b->lo.x > 0.0 ? b->lo.x : (b->hi.x < 0.0 ? -b->hi.x : 0.0);
    double dy = b->lo.y > 0.0 ? b->lo.y : (b->hi.y < 0.0 ? -b->hi.y : 0.0);
    return dx * dx + dy * dy >= s->major * s->major;
}

void scc_sdf_torus_init(scc_sdf_torus* s, double major, double minor)
{
    double e = major + minor;
    base_init(&s->base, scc_sdf_torus_eval, SCC_SDF_TORUS, box_sym(scc_v3(e, e, minor)));
    s->base.convex_in = torus_convex_in;
    s->major = major;
    s->minor = minor;
}

/* ---- capsule along z ---- */
double scc_sdf_capsule_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    return scc_sdf_capsule_value((const scc_sdf_capsule*)self, p, g);
}
void scc_sdf_capsule_init(scc_sdf_capsule* s, double hh, double r)
{
    base_init(&s->base, scc_sdf_capsule_eval, SCC_SDF_CAPSULE, box_sym(scc_v3(r, r, hh + r)));
    s->half_height = hh;
    s->radius = r;
}

/* ---- cylinder along z with flat caps ---- */
double scc_sdf_cylinder_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    return scc_sdf_cylinder_value((const scc_sdf_cylinder*)self, p, g);
}
void scc_sdf_cylinder_init(scc_sdf_cylinder* s, double hh, double r)
{
    base_init(&s->base, scc_sdf_cylinder_eval, SCC_SDF_CYLINDER, box_sym(scc_v3(r, r, hh)));
    s->half_height = hh;
    s->radius = r;
}

/* ---- half-space n.x <= offset ---- */
double scc_sdf_half_space_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    return scc_sdf_half_space_value((const scc_sdf_half_space*)self, p, g);
}
void scc_sdf_half_space_init(scc_sdf_half_space* s, scc_vec3 n, double offset)
{
    scc_aabb b = box_infinite();
    /* An axis-aligned half-space has one finite side. */
    if (n.x == 0.0 && n.y == 0.0) { if (n.z > 0) b.hi.z = offset / n.z; else b.lo.z = offset / n.z; }
    else if (n.x == 0.0 && n.z == 0.0) { if (n.y > 0) b.hi.y = offset / n.y; else b.lo.y = offset / n.y; }
    else if (n.y == 0.0 && n.z == 0.0) { if (n.x > 0) b.hi.x = offset / n.x; else b.lo.x = offset / n.x; }
    base_init(&s->base, scc_sdf_half_space_eval, SCC_SDF_HALF_SPACE, b);
    s->normal = n;
    s->offset = offset;
}

/* ---- spike grid: ground slab z <= 0 united with upright cones ----
 * A cone is a solid of revolution, so its 3D distance is the 2D distance to its meridian
 * triangle (0,0) (R,0) (0,H) in the (rho, z) half-plane. */

/* Closest point to p on segment ab (2D). */
static void closest_on_segment2(double px, double pz, double ax, double az, double bx, double bz, double* cx, double* cz)
{
    double dx = bx - ax, dz = bz - az;
    double t = ((px - ax) * dx + (pz - az) * dz) / (dx * dx + dz * dz);
    t = scc_clamp(t, 0.0, 1.0);
    *cx = ax + t * dx;
    *cz = az + t * dz;
}

/* Signed distance from (rho, z) to the cone's meridian triangle, gradient in (rho, z). */
static double cone_distance2(double rho, double z, double R, double H, double* grho, double* gz)
{
    /* Boundary edges of the meridian triangle: the base (0,0)-(R,0) and the slant (R,0)-(0,H).
     * The third edge lies on the axis of revolution and is not part of the surface. */
    const double vx[3] = { 0.0, R, 0.0 }, vz[3] = { 0.0, 0.0, H };
    double best = INFINITY, bx = 0.0, bz = 0.0;
    for (int i = 0; i < 2; ++i) {
        int j = i + 1;
        double cx, cz;
        closest_on_segment2(rho, z, vx[i], vz[i], vx[j], vz[j], &cx, &cz);
        double d2 = (rho - cx) * (rho - cx) + (z - cz) * (z - cz);
        if (d2 < best) { best = d2; bx = cx; bz = cz; }
    }
    double d = sqrt(best);
    int inside = rho >= 0.0 && z >= 0.0 && rho / R + z / H <= 1.0;
    if (d > 0.0) {
        double s = inside ? -1.0 : 1.0;
        *grho = s * (rho - bx) / d;
        *gz = s * (z - bz) / d;
    } else {
        /* On the boundary: use the outward normal of the slanted side. */
        double n = sqrt(H * H + R * R);
        *grho = H / n;
        *gz = R / n;
    }
    return inside ? -d : d;
}

/* The cone cell nearest p in x and y, clamped to the grid (clamped before rounding too: a far
 * point's index must not overflow an int). */
static void spike_cell(const scc_sdf_spike_grid* s, scc_vec3 p, int* ci, int* cj)
{
    const int i = (int)lround(scc_clamp((p.x - s->x0) / s->spacing, -1.0, (double)s->count_x));
    const int j = (int)lround(scc_clamp((p.y - s->y0) / s->spacing, -1.0, (double)s->count_y));
    *ci = i < 0 ? 0 : (i >= s->count_x ? s->count_x - 1 : i);
    *cj = j < 0 ? 0 : (j >= s->count_y ? s->count_y - 1 : j);
}

static double spike_grid_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    const scc_sdf_spike_grid* s = (const scc_sdf_spike_grid*)self;
    double best = p.z; /* ground slab z <= 0 */
    scc_vec3 bg = k_up;
    {
        int ci, cj;
        spike_cell(s, p, &ci, &cj);
        for (int j = cj - 1; j <= cj + 1; ++j) {
            if (j < 0 || j >= s->count_y) continue;
            for (int i = ci - 1; i <= ci + 1; ++i) {
                if (i < 0 || i >= s->count_x) continue;
                double dx = p.x - (s->x0 + i * s->spacing), dy = p.y - (s->y0 + j * s->spacing);
                double rho = scc_hypot2(dx, dy);
                double grho, gz;
                double d = cone_distance2(rho, p.z, s->base_radius, s->height, &grho, &gz);
                if (d < best) {
                    best = d;
                    double ex = rho > 0.0 ? dx / rho : 1.0, ey = rho > 0.0 ? dy / rho : 0.0;
                    bg = scc_v3(grho * ex, grho * ey, gz);
                }
            }
        }
    }
    if (g) *g = bg;
    return best;
}

/* phi is the distance to the union of convex pieces (the ground slab and the cones), their minimum:
 * it is convex on a box where one piece is nearer than every other at every point (ours). With c the
 * box's centre and h its half-diagonal, each piece's distance changes by at most h over the box, so
 * piece k decides the whole box when d_k(c) + h < d_j(c) - h for every other piece j: the ground and
 * the cones of the 3 x 3 cells about c's (clamped) cell, tested here; every other cone's axis is at
 * least 1.5 spacings away horizontally, so it is at least 1.5 spacing - base radius away. */
static int spike_grid_convex_in(const scc_sdf* self, const scc_aabb* box)
{
    const scc_sdf_spike_grid* s = (const scc_sdf_spike_grid*)self;
    const scc_vec3 c = scc_scale(scc_add(box->lo, box->hi), 0.5);
    const double h = 0.5 * scc_dist(box->lo, box->hi);
    if (!(h < 0.25 * s->spacing) || !scc_vfinite(c)) return 0;
    const double far = 1.5 * s->spacing - s->base_radius;
    double best = c.z, second = far; /* the ground; the far cones' bound */
    int ci, cj;
    spike_cell(s, c, &ci, &cj);
    /* A cone's distance is at least max(rho - R, z - H) (its bounding cylinder), so a cone whose bound
     * exceeds best + 2h + the rounding margin can be neither the nearest piece nor make the test fail:
     * its exact distance is skipped (the answer is the same). The own cell's cone goes first. */
    double lb[9];
    int n = 0;
    for (int j = cj - 1; j <= cj + 1; ++j)
        for (int i = ci - 1; i <= ci + 1; ++i, ++n) {
            lb[n] = INFINITY;
            if (j < 0 || j >= s->count_y || i < 0 || i >= s->count_x) continue;
            const double rho = scc_hypot2(c.x - (s->x0 + i * s->spacing), c.y - (s->y0 + j * s->spacing));
            lb[n] = fmax(rho - s->base_radius, c.z - s->height);
        }
    for (int pass = 0; pass < 2; ++pass)
        for (int k = 0; k < 9; ++k) {
            if ((pass == 0) != (k == 4) || !(lb[k] < INFINITY)) continue;
            /* |second| <= max(|best|, far), so this bounds the rounding margin below whatever second ends up */
            const double eps_max = 1e-12 * (2.0 * fabs(best) + fabs(far) + s->spacing + s->height);
            if (lb[k] > best + 2.0 * h + eps_max) continue;
            const int i = ci - 1 + k % 3, j = cj - 1 + k / 3;
            double grho, gz;
            const double d = cone_distance2(scc_hypot2(c.x - (s->x0 + i * s->spacing), c.y - (s->y0 + j * s->spacing)), c.z, s->base_radius,
                                            s->height, &grho, &gz);
            if (d < best) {
                second = fmin(second, best);
                best = d;
            } else {
                second = fmin(second, d);
            }
        }
    /* the margin covers the rounding of the distances (relative 1e-12 of the sizes involved) */
    const double eps = 1e-12 * (fabs(best) + fabs(second) + s->spacing + s->height);
    return best + 2.0 * h + eps < second;
}

void scc_sdf_spike_grid_init(scc_sdf_spike_grid* s, double spacing, double base_radius, double height, int nx, int ny)
{
    scc_aabb b = box_infinite();
    b.hi.z = height;
    base_init(&s->base, spike_grid_eval, SCC_SDF_SPIKE_GRID, b);
    s->base.convex_in = spike_grid_convex_in;
    s->spacing = spacing;
    s->base_radius = base_radius;
    s->height = height;
    s->count_x = nx;
    s->count_y = ny;
    s->x0 = -0.5 * spacing * (nx - 1);
    s->y0 = -0.5 * spacing * (ny - 1);
}

/* ---- CSG ---- */
static double csg_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    const scc_sdf_csg* s = (const scc_sdf_csg*)self;
    scc_vec3 ga, gb;
    double a = scc_sdf_eval(s->a, p, g ? &ga : NULL);
    double b = scc_sdf_eval(s->b, p, g ? &gb : NULL);
    if (isnan(a) || isnan(b)) { /* fmin/fmax would drop the NaN and let a NaN point touch */
        if (g) *g = scc_v3(NAN, NAN, NAN);
        return NAN;
    }
    switch (s->op) {
    case SCC_CSG_UNION:
        if (g) *g = a <= b ? ga : gb;
        return fmin(a, b);
    case SCC_CSG_INTERSECTION:
        if (g) *g = a >= b ? ga : gb;
        return fmax(a, b);
    default: /* difference: a minus b */
        if (g) *g = a >= -b ? ga : scc_scale(gb, -1.0);
        return fmax(a, -b);
    }
}

static scc_aabb aabb_union(scc_aabb a, scc_aabb b) { scc_aabb r = { scc_vmin(a.lo, b.lo), scc_vmax(a.hi, b.hi) }; return r; }
static scc_aabb aabb_intersection(scc_aabb a, scc_aabb b) { scc_aabb r = { scc_vmax(a.lo, b.lo), scc_vmin(a.hi, b.hi) }; return r; }

void scc_sdf_csg_init(scc_sdf_csg* s, scc_csg_op op, const scc_sdf* a, const scc_sdf* b)
{
    scc_aabb bounds = op == SCC_CSG_UNION ? aabb_union(a->bounds, b->bounds)
                    : op == SCC_CSG_INTERSECTION ? aabb_intersection(a->bounds, b->bounds) : a->bounds;
    base_init(&s->base, csg_eval, SCC_SDF_CSG, bounds);
    s->base.domain = aabb_intersection(a->domain, b->domain);
    s->base.lipschitz = fmax(a->lipschitz, b->lipschitz);
    s->base.convex = op == SCC_CSG_INTERSECTION && a->convex && b->convex; /* max of convex functions */
    s->op = op;
    s->a = a;
    s->b = b;
}

/* ---- rigid transform and uniform scale ---- */
static double transform_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* g)
{
    const scc_sdf_transform* s = (const scc_sdf_transform*)self;
    scc_vec3 local = scc_scale(scc_xform_apply_inv(s->xf, p), 1.0 / s->scale);
    /* A point so far that dividing by a small scale overflows: clamped, which underestimates the
     * distance (conservative) and keeps value and gradient finite. */
    if (!scc_vfinite(local) && !isnan(local.x + local.y + local.z))
        local = scc_vmax(scc_vmin(local, scc_v3(1e300, 1e300, 1e300)), scc_v3(-1e300, -1e300, -1e300));
    scc_vec3 gl;
    double v = scc_sdf_eval(s->child, local, g ? &gl : NULL);
    if (g) *g = scc_quat_rotate(s->xf.q, gl);
    return v * s->scale;
}

/* World box of a transformed local box (infinite stays infinite). */
static scc_aabb transform_box(scc_aabb b, scc_xform xf, double scale)
{
    if (!scc_vfinite(b.lo) || !scc_vfinite(b.hi)) return box_infinite();
    scc_aabb r = { { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    for (int i = 0; i < 8; ++i) {
        scc_vec3 c = scc_v3(i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z);
        c = scc_xform_apply(xf, scc_scale(c, scale));
        r.lo = scc_vmin(r.lo, c);
        r.hi = scc_vmax(r.hi, c);
    }
    return r;
}

static int transform_convex_in(const scc_sdf* self, const scc_aabb* box)
{
    const scc_sdf_transform* s = (const scc_sdf_transform*)self;
    if (!s->child->convex_in) return 0;
    scc_xform inv = { scc_quat_conj(s->xf.q), scc_quat_rotate(scc_quat_conj(s->xf.q), scc_scale(s->xf.p, -1.0)) };
    scc_aabb local = transform_box(*box, inv, 1.0);
    local.lo = scc_scale(local.lo, 1.0 / s->scale);
    local.hi = scc_scale(local.hi, 1.0 / s->scale);
    return s->child->convex_in(s->child, &local);
}

void scc_sdf_transform_init(scc_sdf_transform* s, const scc_sdf* child, scc_xform xf, double scale)
{
    base_init(&s->base, transform_eval, SCC_SDF_TRANSFORM, transform_box(child->bounds, xf, scale));
    s->base.domain = transform_box(child->domain, xf, scale);
    s->base.lipschitz = child->lipschitz;
    s->base.convex = child->convex; /* an affine change of variables keeps convexity */
    s->base.convex_in = transform_convex_in;
    s->child = child;
    s->xf = xf;
    s->scale = scale;
}
