/* SPDX-License-Identifier: MIT */
/** @file sdf.h  Signed distance fields: analytic shapes, CSG, user callbacks, and evaluation.
 *
 * Conventions: metres; phi < 0 inside, phi > 0 outside; the gradient points outward and is
 * the contact normal. An SDF lives in its own local frame; queries place it in the world
 * with a pose or a rigid motion (ccd.h).
 *
 * Handles are small values. A null handle has index1 == 0. Destroying a handle that a
 * combination (union, transform...) still uses is allowed: the combination keeps the
 * shape alive until it is destroyed itself.
 */
#ifndef SDFCCD_SDF_H
#define SDFCCD_SDF_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Kinds of SDF, as reported by sdfccd_sdf_get_info(). */
typedef enum sdfccd_SdfKind {
    SDFCCD_SDF_SPHERE,      /**< sdfccd_create_sphere() */
    SDFCCD_SDF_BOX,         /**< sdfccd_create_box() */
    SDFCCD_SDF_ROUNDED_BOX, /**< sdfccd_create_rounded_box() */
    SDFCCD_SDF_TORUS,       /**< sdfccd_create_torus() */
    SDFCCD_SDF_CAPSULE,     /**< sdfccd_create_capsule() */
    SDFCCD_SDF_CYLINDER,    /**< sdfccd_create_cylinder() */
    SDFCCD_SDF_HALF_SPACE,  /**< sdfccd_create_half_space() */
    SDFCCD_SDF_SPIKE_GRID,  /**< sdfccd_create_spike_grid() */
    SDFCCD_SDF_CSG,         /**< sdfccd_create_csg() */
    SDFCCD_SDF_TRANSFORM,   /**< sdfccd_create_transformed() */
    SDFCCD_SDF_CALLBACK,    /**< sdfccd_create_callback_sdf() */
    SDFCCD_SDF_GRID,        /**< A grid (grid.h): built, or loaded from a `.cdf` file. */
    SDFCCD_SDF_KIND_COUNT   /**< Number of kinds (not a kind). */
} sdfccd_SdfKind;

/** Sphere of radius `radius` > 0 centred at the origin. Exact distance. */
SDFCCD_API sdfccd_Status sdfccd_create_sphere(double radius, sdfccd_SdfId* out_sdf);
/** Box with half extents `half` (all > 0), centred at the origin, axis-aligned. Exact distance. */
SDFCCD_API sdfccd_Status sdfccd_create_box(sdfccd_Vec3 half, sdfccd_SdfId* out_sdf);
/** Box of half extents `half` whose edges and corners are rounded with radius `radius`
 * (0 <= radius <= min half extent); the outer size stays `half`. Exact distance. */
SDFCCD_API sdfccd_Status sdfccd_create_rounded_box(sdfccd_Vec3 half, double radius, sdfccd_SdfId* out_sdf);
/** Torus around the z axis, ring radius `major` > `minor` > 0, in the xy plane. Exact distance. */
SDFCCD_API sdfccd_Status sdfccd_create_torus(double major, double minor, sdfccd_SdfId* out_sdf);
/** Capsule along z: segment from (0,0,-half_height) to (0,0,+half_height), radius `radius`. Exact. */
SDFCCD_API sdfccd_Status sdfccd_create_capsule(double half_height, double radius, sdfccd_SdfId* out_sdf);
/** Solid cylinder along z, |z| <= half_height, radius `radius`, flat caps. Exact distance. */
SDFCCD_API sdfccd_Status sdfccd_create_cylinder(double half_height, double radius, sdfccd_SdfId* out_sdf);
/** Half-space {x : dot(normal, x) <= offset}; `normal` is normalised. Exact distance (phi is linear). */
SDFCCD_API sdfccd_Status sdfccd_create_half_space(sdfccd_Vec3 normal, double offset, sdfccd_SdfId* out_sdf);

/** The paper's spike grid (Fig. 10, Table 3): a square field of upright cones on a ground
 * plane z = 0. Cones are spaced `spacing` apart in x and y, centred on the origin, `count_x`
 * by `count_y` of them; each has base radius `base_radius` (<= spacing / 2) and height
 * `height`. phi is the exact distance to the union of the ground slab (z <= 0) and the nearest
 * cones (each point tests the cones of its own and the 8 neighbouring cells), so it is
 * 1-Lipschitz. Beyond the grid's edge only the ground remains. */
typedef struct sdfccd_SpikeGridDef {
    double spacing;         /**< Distance between neighbouring cone axes (m), > 0. */
    double base_radius;     /**< Cone base radius (m), in (0, spacing / 2]. */
    double height;          /**< Cone height above the ground (m), > 0. */
    int32_t count_x;        /**< Cones along x, in [1, 100000]. */
    int32_t count_y;        /**< Cones along y, in [1, 100000]. */
    int32_t internal_value; /**< Set by sdfccd_default_spike_grid_def(); do not change. */
} sdfccd_SpikeGridDef;
/** Defaults: spacing 0.1 m, base radius 0.05 m, height 0.1 m, 20 x 20 cones. */
SDFCCD_API sdfccd_SpikeGridDef sdfccd_default_spike_grid_def(void);
/** Creates the spike grid `def` describes. Errors: bad def (::SDFCCD_INVALID_ARGUMENT). */
SDFCCD_API sdfccd_Status sdfccd_create_spike_grid(const sdfccd_SpikeGridDef* def, sdfccd_SdfId* out_sdf);

/** Boolean combinations. Union = min(a, b); intersection = max(a, b); difference (a minus b)
 * = max(a, -b). The results are 1-Lipschitz but are exact distances only outside (union) or in
 * simple cases; the certified method relies only on the Lipschitz bound. */
typedef enum sdfccd_CsgOp {
    SDFCCD_CSG_UNION,        /**< min(a, b) */
    SDFCCD_CSG_INTERSECTION, /**< max(a, b) */
    SDFCCD_CSG_DIFFERENCE    /**< a minus b: max(a, -b) */
} sdfccd_CsgOp;
/** Creates the combination `op` of `a` and `b`; the new SDF keeps both alive (they may be
 * destroyed by the caller afterwards). */
SDFCCD_API sdfccd_Status sdfccd_create_csg(sdfccd_CsgOp op, sdfccd_SdfId a, sdfccd_SdfId b, sdfccd_SdfId* out_sdf);

/** `child` placed with `pose` and uniformly scaled by `scale` > 0:
 * phi(x) = scale * phi_child(inverse(pose)(x) / scale). Rigid motion and uniform scale keep distances exact.
 * `scale` must be in [1e-100, 1e100] and the pose's position within 1e150 per coordinate (beyond,
 * the division or the product overflows); else ::SDFCCD_INVALID_ARGUMENT. */
SDFCCD_API sdfccd_Status sdfccd_create_transformed(sdfccd_SdfId child, sdfccd_Pose pose, double scale, sdfccd_SdfId* out_sdf);

/** `child` stretched by `scale` > 0 along each local axis (a non-uniform scaling):
 * phi(x) = min(scale) * phi_child(x / scale), componentwise. It has the stretched shape's surface
 * and sign, and never exceeds its distance (a lower bound, exact for a uniform scale). Each factor
 * must be in [1e-100, 1e100], else ::SDFCCD_INVALID_ARGUMENT. The new SDF keeps `child` alive; its
 * kind is ::SDFCCD_SDF_TRANSFORM. */
SDFCCD_API sdfccd_Status sdfccd_create_stretched(sdfccd_SdfId child, sdfccd_Vec3 scale, sdfccd_SdfId* out_sdf);

/** A user SDF. `eval` returns phi at p (local frame) and writes the gradient to *out_grad when
 * out_grad is not NULL. It must be pure and thread-safe. `lipschitz` bounds |grad phi|
 * everywhere (1 for a true distance field); the certified method is only as sound as this bound.
 * `bounds` must contain every point with phi <= 0 (use +-INFINITY if unbounded). */
typedef double sdfccd_SdfEvalFcn(sdfccd_Vec3 p, sdfccd_Vec3* out_grad, void* user);
/** ::sdfccd_SdfEvalFcn with the point as three coordinates: the same contract. The coordinates travel in
 * registers, where a 24-byte ::sdfccd_Vec3 argument travels through memory on x86-64 (System V and
 * Windows), a store and a reload on every call; a solver's next sample waits for them, so this form
 * costs less per SDF evaluation (the evaluation report's section 5 measures both forms). */
typedef double sdfccd_SdfEvalXyzFcn(double x, double y, double z, sdfccd_Vec3* out_grad, void* user);
/** Describes a user SDF (see ::sdfccd_SdfEvalFcn). Initialise with sdfccd_default_callback_sdf_def().
 * Exactly one of `eval` and `eval_xyz` is set. */
typedef struct sdfccd_CallbackSdfDef {
    sdfccd_SdfEvalFcn* eval; /**< phi and its gradient, the point as an ::sdfccd_Vec3; or NULL when `eval_xyz` is set. */
    void* user;              /**< Passed to `eval`. */
    double lipschitz;        /**< Bound on |grad phi| everywhere (> 0). */
    sdfccd_Aabb bounds;      /**< Contains every point with phi <= 0 (+-INFINITY if unbounded). */
    /** 1: phi is smooth outside the surface, i.e. its gradient is continuous there (no edges,
     * corners, cone tips or CSG seams; a sphere, a torus, a capsule, a rounded box are). FWGSS then
     * skips what it does against gradient jumps (sdfccd_QueryParams::fwgss_kink_guard's extra
     * descents and sdfccd_QueryParams::fwgss_verify's certified check), as it does for the built-in
     * smooth shapes: a torus given as a callback takes about 150 SDF evaluations per triangle query
     * instead of about 570. Declaring a field with kinks smooth can make FWGSS answer late or miss
     * where the gradient jumps. 0 (default): not known to be smooth, checked. Other values:
     * ::SDFCCD_INVALID_ARGUMENT. */
    int32_t smooth;
    /** phi and its gradient, the point as three coordinates (::sdfccd_SdfEvalXyzFcn), passed by value in
     * registers; or NULL when `eval` is set. Called the same way and as often as `eval` would be. */
    sdfccd_SdfEvalXyzFcn* eval_xyz;
    int32_t internal_value; /**< Set by sdfccd_default_callback_sdf_def(); do not change. */
} sdfccd_CallbackSdfDef;
/** Defaults: eval and eval_xyz NULL (one must be set), user NULL, lipschitz 1, infinite bounds, smooth 0. */
SDFCCD_API sdfccd_CallbackSdfDef sdfccd_default_callback_sdf_def(void);
/** Creates a user SDF. The library does not check that `eval` (or `eval_xyz`) keeps `lipschitz`.
 * ::SDFCCD_INVALID_ARGUMENT when neither or both of `eval` and `eval_xyz` are set. */
SDFCCD_API sdfccd_Status sdfccd_create_callback_sdf(const sdfccd_CallbackSdfDef* def, sdfccd_SdfId* out_sdf);

/** Releases the handle. The shape's memory is freed once no combination and no call in flight
 * (on any thread) uses it. */
SDFCCD_API sdfccd_Status sdfccd_destroy_sdf(sdfccd_SdfId sdf);

/** Value (and gradient when out_grad is not NULL) at p, in the SDF's local frame. */
SDFCCD_API sdfccd_Status sdfccd_sdf_eval(sdfccd_SdfId sdf, sdfccd_Vec3 p, double* out_value, sdfccd_Vec3* out_grad);

/** sdfccd_sdf_eval() at `count` points with one handle lookup (the same values bit for bit):
 * `out_values[i]` (and `out_grads[i]` when out_grads is not NULL) for `points[i]`. Every point is
 * checked before any is evaluated (::SDFCCD_INVALID_ARGUMENT names the first non-finite one). */
SDFCCD_API sdfccd_Status sdfccd_sdf_eval_batch(sdfccd_SdfId sdf, const sdfccd_Vec3* points, int32_t count, double* out_values,
                                               sdfccd_Vec3* out_grads);

/** What sdfccd_sdf_get_info() reports. */
typedef struct sdfccd_SdfInfo {
    sdfccd_SdfKind kind;  /**< What created the SDF. */
    sdfccd_Aabb domain;   /**< Where values are exact (a grid's box); +-INFINITY for analytic shapes. */
    sdfccd_Aabb bounds;   /**< Contains every point with phi <= 0 (may be infinite). */
    double lipschitz;     /**< Global bound on |grad phi|. */
    int64_t memory_bytes; /**< Bytes owned by this shape alone (children not counted). */
} sdfccd_SdfInfo;
/** Describes an SDF. */
SDFCCD_API sdfccd_Status sdfccd_sdf_get_info(sdfccd_SdfId sdf, sdfccd_SdfInfo* out_info);

#ifdef __cplusplus
}
#endif
#endif
