/* SPDX-License-Identifier: MIT */
/** @file contact.h  What a physics engine needs from the CCD over one step: the contact set of a
 * mesh against an SDF (generated, and reduced to the engine's manifold size), and the no-tunnelling
 * guarantee (the executed motion checked for a time of impact, and the safe pose).
 *
 * The rule (Pelletier-Guenette et al., SCA 2025, Section 4): the simulation never advances past a
 * time of impact. An engine integrates a step with whatever contacts it has; then, for every body
 * that can reach an SDF, it hands the motion the body executed over the step to sdfccd_guard_rigid().
 * When some point of the body went deeper than the tolerance before the end of the step, the guard
 * returns the first such time and the pose there; the engine puts the body at that pose and removes
 * its velocity into the surface along the returned normal. Whatever moved the body (a contact's
 * impulse, a kick from another body, a joint), it does not pass through the surface.
 *
 * Time, frames and units as in ccd.h: seconds over [t0, t1], world frame, metres.
 */
#ifndef SDFCCD_CONTACT_H
#define SDFCCD_CONTACT_H

#include "ccd.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The executed rigid motion from two poses (what the engine's solver produced over [t0, t1]): the
 * centre (`local_center` in the body frame; for Bullet the centre of mass, i.e. the body origin,
 * (0, 0, 0)) moves linearly from its start to its end position, and the body turns by the shortest
 * arc from start to end orientation, q_end * conj(q_start) with the sign that gives an angle of at
 * most pi, at constant world angular velocity about the centre (Eq. 14). The motion's pose at t1 is
 * `end` up to rounding.
 *
 * Two poses cannot tell a turn of more than half a revolution from the shorter turn the other way:
 * an engine that knows the angular velocity it integrated (Bullet: the body's angular velocity over
 * the step) should fill ::sdfccd_RigidMotion itself with it; the CCD splits any rotation into
 * segments of at most sdfccd_QueryParams::max_rotation_per_segment.
 *
 * Errors (::SDFCCD_INVALID_ARGUMENT): a NULL pointer, a non-finite value, an orientation whose norm
 * differs from 1 by more than 1e-4 (within that it is normalised), t1 <= t0, a coordinate above
 * SDFCCD_MAX_QUERY_MAGNITUDE. */
SDFCCD_API sdfccd_Status sdfccd_rigid_motion_from_poses(const sdfccd_Pose* start, const sdfccd_Pose* end, sdfccd_Vec3 local_center,
                                                        double t0, double t1, sdfccd_RigidMotion* out_motion);

/** Settings of the guard. Must be initialised with sdfccd_default_guard_params(). */
typedef struct sdfccd_GuardParams {
    double tolerance;          /**< Depth (m, > 0) a point may reach below the surface before the guard acts, and the
                                    accuracy of the returned safe pose: no point the CCD finds is deeper than this at
                                    it. Default 5e-4. */
    sdfccd_QueryParams query;  /**< CCD settings of the check (default: sdfccd_default_query_params()). Its `margin`
                                    and `subdivision` are not used (the guard's level is -tolerance and it needs the
                                    first point only); its time tolerance is tightened so that the TOI is late by at
                                    most a tenth of the tolerance in depth. ::SDFCCD_METHOD_DCD is refused (it tests
                                    the end pose only); ::SDFCCD_METHOD_CERTIFIED gives the guarantee with no false
                                    negatives on exact SDFs, at a much higher cost. */
    int32_t internal_value;    /**< Set by sdfccd_default_guard_params(); do not change. */
} sdfccd_GuardParams;

/** The default guard settings (see each field of ::sdfccd_GuardParams). */
SDFCCD_API sdfccd_GuardParams sdfccd_default_guard_params(void);

/** What the guard found. */
typedef enum sdfccd_GuardState {
    SDFCCD_GUARD_CLEAR = 0,          /**< No point of the body went deeper than the tolerance during the motion:
                                          the body may take its end pose. */
    SDFCCD_GUARD_ROLLED_BACK = 1,    /**< One did: `safe_pose` is the pose at `toi`, where no point the CCD found is
                                          deeper than the tolerance. */
    SDFCCD_GUARD_INSIDE_AT_START = 2 /**< Part of the body already started deeper than the tolerance, and the motion
                                          took no point past its level (below): the body may take its end pose, and the
                                          contacts are to push it out. */
} sdfccd_GuardState;

/** The outcome of sdfccd_guard_rigid().
 *
 * Bodies that start inside: a triangle whose deepest point at t0 is deeper than the tolerance
 * (a resting body slightly inside, or one pushed in by a stack) is held to its own level, its
 * start depth minus the tolerance: it may not sink further by more than the tolerance in the step,
 * and every other triangle keeps the level -tolerance. So such a body is not frozen at t0 every
 * step, and the rest of it stays guarded. Known limits: a triangle that starts deeper than half the
 * thickness of a thin feature can cross it; the start depth comes from a local search (DCD), so a
 * triangle whose check still reports contact at t0 has its level lowered to what the check saw, and
 * after three such corrections it is left out of the check (as is every triangle still reporting
 * contact at t0 when the guard has run 8 queries). */
typedef struct sdfccd_GuardResult {
    sdfccd_GuardState state;   /**< Clear, rolled back, or inside at the start. */
    double toi;                /**< Seconds in [t0, t1]. ROLLED_BACK: the time of the safe pose, not after the first time
                                    a point reached its level and before it by about the query's time tolerance
                                    (tightened so that no point moves more than a tenth of the tolerance in it); t1
                                    otherwise. */
    double fraction;           /**< (toi - t0) / (t1 - t0) (0 when t1 == t0). */
    sdfccd_Pose safe_pose;     /**< The mesh pose at `toi` along the executed motion (its end pose unless ROLLED_BACK). */
    sdfccd_Vec3 point;         /**< ROLLED_BACK: the world point of the body that reached its level first, at `toi`
                                    (else zero). */
    sdfccd_Vec3 normal;        /**< ROLLED_BACK: the unit SDF normal there (grad phi, out of the SDF, world frame): the
                                    engine removes the body's velocity into the surface along it (else zero). */
    double min_gap_start;      /**< Smallest phi at t0 of the points the check saw (diagnostic; INFINITY when it saw
                                    none within the tolerance of the surface). */
    uint32_t triangle;         /**< ROLLED_BACK: the triangle of `point`. */
    int32_t deep_triangles;    /**< Triangles that started deeper than the tolerance (held to their own level). */
    sdfccd_ResultState query_state; /**< State of the CCD's last query. ::SDFCCD_STATE_NOT_CONVERGED: its evaluation
                                    budget ran out, so CLEAR is not proven (ROLLED_BACK still is a real contact). */
    int32_t queries;           /**< Mesh queries run: 1, more when part of the body started deep. */
    int64_t sdf_evaluations;   /**< SDF evaluations, all queries. */
    int32_t pinned;            /**< sdfccd_guard_step_rigid(): 1 when no time after t0 is safe (the body stays at its
                                    start pose); 0 otherwise and from sdfccd_guard_rigid(). */
    int32_t certified;         /**< sdfccd_guard_step_rigid(): 1 when the motion was proven clear without a CCD (or
                                    did not move relative to a static SDF). */
} sdfccd_GuardResult;

/** The guarantee: checks the executed motion of a rigid mesh against one SDF (itself possibly moving
 * with `sdf_motion`, NULL = static at the world origin) with the CCD; if any point reached
 * phi <= -tolerance before t1, the result says ::SDFCCD_GUARD_ROLLED_BACK with the earliest such
 * time and the pose there. Never advances past a time of impact (up to the CCD's known misses,
 * ccd.h). Bodies that start inside: see ::sdfccd_GuardResult. Uses the workspace (not NULL): no
 * allocation after a first call of a given size. `executed` may rotate by any angle (the CCD
 * splits it).
 *
 * Errors: NULL pointers, params not from sdfccd_default_guard_params(), tolerance not finite and
 * > 0, the DCD method, and whatever sdfccd_query_mesh_ws() refuses (::SDFCCD_INVALID_ARGUMENT,
 * ::SDFCCD_INVALID_HANDLE); ::SDFCCD_OUT_OF_MEMORY. On error `out` is not written. */
SDFCCD_API sdfccd_Status sdfccd_guard_rigid(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
                                            sdfccd_MeshId mesh, const sdfccd_RigidMotion* executed, double t0, double t1,
                                            const sdfccd_GuardParams* params, sdfccd_GuardResult* out);

/** The guarantee as an engine applies it after a step: where to put the body. The same check as
 * sdfccd_guard_rigid() (same params; rigid motion; `sdf_motion` NULL or the SDF's motion), with:
 *  - a certificate first, which proves most of a motion clear without a CCD: phi is K-Lipschitz (the
 *    SDF's bound), so along a point path of length L from phi0 to phi1 the minimum is at least
 *    (phi0 + phi1 - K L) / 2; with every point's speed bounded by |v| + |w| d (d its distance from
 *    the centre of rotation), a point stays within h = (|v| + |w| d) T / 2 of where it is at the
 *    middle of the step. Each sphere of the mesh's bounding-sphere hierarchy (centre c, radius r)
 *    is evaluated once, at c at the middle time: where phi(c) - K (r + h) > -tolerance/2 the sphere
 *    is clear at every time of the step, and the CCD and the discrete checks below skip it. A leaf
 *    that fails is tried with its triangle's deepest point at the middle time (DCD) less K h, and
 *    where that fails above the level, on each half of the step the same way (twice deep): that
 *    stage is as sure as the DCD's local search, the same kind of search as the CCD it replaces.
 *    Only the triangles near the surface that move (a sliding body's contact) reach the CCD. A
 *    motion that does not move relative to a static SDF (a sleeping body) is ::SDFCCD_GUARD_CLEAR at
 *    no cost. The certificate
 *    applies when the SDF does not move (`sdf_motion` NULL or with zero velocities); its first stage
 *    is exact, as sure as the SDF's Lipschitz bound;
 *  - the safe time: when a point reaches -tolerance, the body goes back further, to the first time
 *    a point reached -tolerance/2 (so that the next step starts shallower than the tolerance);
 *  - a discrete check of the pose at that time (the deepest point of every triangle the certificate
 *    left, DCD): if a point is deeper than the tolerance there (half the tolerance after a rollback;
 *    what the CCD's local search missed), the body stays at its start pose when that pose already
 *    has a point deeper than tolerance/2, else the safe time is bisected (12 halvings of [t0, toi])
 *    to the last time that check finds no point deeper than tolerance/2. `out->pinned` is 1 when
 *    the safe time is t0.
 * Tolerance semantics: CLEAR: no point went below -tolerance at any time of the step (a triangle
 * that starts deeper: below its own level, see ::sdfccd_GuardResult), as far as the certificate (exact
 * up to its DCD stage), the CCD and the discrete check at t1 can see. ROLLED_BACK: no point went
 * below -tolerance before `toi`, and at `safe_pose` the discrete check finds no point below
 * -tolerance/2, except when pinned at a start pose that already had one. A body that starts deep
 * (::SDFCCD_GUARD_INSIDE_AT_START) is left to the contacts. Errors: as sdfccd_guard_rigid(). */
SDFCCD_API sdfccd_Status sdfccd_guard_step_rigid(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
                                                 sdfccd_MeshId mesh, const sdfccd_RigidMotion* executed, double t0, double t1,
                                                 const sdfccd_GuardParams* params, sdfccd_GuardResult* out);

/** A rigid body's velocity state (world frame), for sdfccd_guard_response(). */
typedef struct sdfccd_BodyState {
    sdfccd_Vec3 center;            /**< Centre of mass (m), at the safe pose. */
    sdfccd_Vec3 linear_velocity;   /**< Of the centre of mass (m/s). */
    sdfccd_Vec3 angular_velocity;  /**< rad/s. */
    double inverse_mass;           /**< 1/kg, >= 0 (0: immovable). */
    double inverse_inertia[9];     /**< World inverse inertia tensor, row-major (symmetric, positive semi-definite). */
} sdfccd_BodyState;

/** The velocity a body leaves with after sdfccd_guard_step_rigid() rolled it back (`result`; any
 * other state leaves `body` unchanged). The SDF's body `sdf_body` (NULL: static) counts as
 * infinitely heavy. Pinned: the body takes the SDF body's motion (at rest relative to it).
 * Otherwise, when `repeated` is nonzero (the body was rolled back in the previous step too: its
 * contacts did not stop it), it loses its velocity into the surface at `result->point` along
 * `result->normal`: first its centre's, then, if that point still approaches (a spin), an inelastic
 * impulse there along the normal makes the approach zero, with Coulomb friction (`friction` >= 0)
 * reducing the point's tangential velocity by at most friction times that impulse. A body rolled
 * back for the first time keeps its velocity: the next step starts in contact and its contacts take
 * the impact. Errors (::SDFCCD_INVALID_ARGUMENT): NULL result or body, non-finite values, a negative
 * friction or inverse mass. */
SDFCCD_API sdfccd_Status sdfccd_guard_response(const sdfccd_GuardResult* result, int32_t repeated, const sdfccd_BodyState* sdf_body,
                                               double friction, sdfccd_BodyState* body);

/** Which feature of the mesh a contact point lies on (from its barycentric weights, 1e-6). */
typedef enum sdfccd_FeatureKind {
    SDFCCD_FEATURE_VERTEX = 0, /**< A vertex of the mesh (`feature` is its index). */
    SDFCCD_FEATURE_EDGE = 1,   /**< An edge of `triangle`: `feature` (0, 1, 2) is the corner it is opposite. */
    SDFCCD_FEATURE_FACE = 2    /**< The inside of `triangle` (`feature` is 0). */
} sdfccd_FeatureKind;

/** One contact point of a mesh against an SDF over a step, as an engine's solver takes it: the
 * material point of the mesh and the surface point and normal that hold it, all at the START of the
 * step (t0), world frame. A speculative contact (gap > 0) lets the solver close at most the gap in
 * the step; a negative gap is a penetration to push out. */
typedef struct sdfccd_ContactPoint {
    sdfccd_Vec3 point;          /**< The mesh's material point at t0 (world, m). */
    sdfccd_Vec3 surface_point;  /**< The point of the SDF's surface that holds it (found at `toi`), at t0 (world, m); gap is
                                     normal . (point - surface_point). */
    sdfccd_Vec3 normal;         /**< Unit normal out of the SDF (world), at t0. */
    double gap;                 /**< Signed gap at t0 along the normal (m); negative: penetrating. */
    double toi;                 /**< When the constraint was found: t0 for points of the start pose, the time of impact
                                     for points from the CCD (s). */
    double barycentric[3];      /**< Weights of the material point on its triangle's vertices 0, 1, 2. */
    uint32_t triangle;          /**< Triangle index in the mesh. */
    sdfccd_FeatureKind feature_kind; /**< Vertex, edge or face. */
    uint32_t feature;           /**< Vertex index (VERTEX), corner opposite the edge (EDGE), 0 (FACE). */
    uint64_t id;                /**< Feature id, the same from step to step for the same feature (warm starting): the
                                     vertex index, (1 << 62) + 3 triangle + corner for an edge, (2 << 62) + triangle for
                                     a face. */
} sdfccd_ContactPoint;

/** Reduces a contact set to at most `capacity` points (a pure function of its input: no handle, no
 * allocation). Chosen, in order: the deepest point (smallest gap; among equally deep ones, within
 * 1e-9 m, the one farthest from their centre, a corner of a face landing flat), the point farthest
 * from it, then the points adding most area to the polygon of the chosen ones (collinear points:
 * the ones extending the segment), and, once no point adds area, the points farthest from every
 * chosen one. Distances and areas are between the `surface_point`s projected on the plane of the
 * first point's normal. A point within `same_place_distance` (m, >= 0) of a chosen one is never
 * chosen, and choosing stops when the best adds no more than that; so the count may be smaller than
 * both `count` and `capacity`. Ties (within 1e-9 relative) go to the smaller gap, then the smaller
 * `id`, then the lower index: with distinct ids the choice does not depend on the order of the
 * input. Writes the chosen indices into `points` to out_indices[0 .. *out_count - 1] (in the order
 * chosen). O(count x capacity^2) in the worst case.
 * Errors (::SDFCCD_INVALID_ARGUMENT): NULL pointers (points may be NULL when count is 0), count or
 * capacity < 0, same_place_distance not finite or < 0, a non-finite point, normal or gap. */
SDFCCD_API sdfccd_Status sdfccd_reduce_contacts(const sdfccd_ContactPoint* points, int32_t count, double same_place_distance,
                                                int32_t* out_indices, int32_t capacity, int32_t* out_count);

/** The previous step's points of a pair, for a reduction that keeps a resting contact set's points,
 * and their order, from step to step (an engine's solver visits them in order and warm-starts them
 * by place; a set that trades one point for an equally good one every step makes a resting body
 * rock). At each choice of the reduction, a candidate whose ::sdfccd_ContactPoint::id is in `ids`
 * (and is not within the same-place distance of a chosen point) replaces the point the reduction
 * would choose when its gap is at most `depth` above that point's and, after the first point, its
 * score (distance or added area, weighted as the reduction weights it) is at least `share` times
 * that point's and adds something; among several, the one earliest in `ids`, then the smaller gap,
 * then the lower index. So a new point deeper by more than `depth`, or scoring more than 1 / share
 * times every previous one, still wins. A previous first point also gives the contact plane (its
 * normal). `ids` is read during the call only. */
typedef struct sdfccd_KeepPrevious {
    const uint64_t* ids;  /**< The ids of the points kept in the previous step, in the order returned then (NULL with count 0: none). */
    int32_t count;        /**< Entries of ids (>= 0). */
    double depth;         /**< m, finite, >= 0. */
    double share;         /**< In [0, 1] (0: any previous point that adds something; 1: only as good ones). */
} sdfccd_KeepPrevious;

/** sdfccd_reduce_contacts_weighted() that prefers the previous step's points (`previous`, see
 * ::sdfccd_KeepPrevious; NULL or a count of 0: the same result as sdfccd_reduce_contacts_weighted()).
 * The same guarantees: deterministic, never two points within `same_place_distance`, never a prefix of
 * the set. O(count x previous->count) more reads per choice. Errors: as
 * sdfccd_reduce_contacts_weighted(), and a negative count, ids NULL with count > 0, depth not finite
 * and >= 0, share outside [0, 1]. */
SDFCCD_API sdfccd_Status sdfccd_reduce_contacts_kept(const sdfccd_ContactPoint* points, int32_t count, double same_place_distance,
                                                     double depth_scale, const sdfccd_KeepPrevious* previous, int32_t* out_indices,
                                                     int32_t capacity, int32_t* out_count);

/** Cover points: the points to hold after a reduction (sdfccd_reduce_contacts()) where the chosen
 * ones still leave the body free to sink. A chosen point j with gap g_j keeps a point i of similar
 * normal (cosine at least 0.9) from ending deeper than g_j + tilt * |i - j| (surface points) while
 * the body turns by at most `tilt` (m per m, the body's angular speed across the normal times the
 * step) about an axis in the contact plane; the point whose bound exceeds its own gap by most,
 * and by more than `depth` (m), is held next, until none is left or `capacity` are written. A point
 * within `same_place_distance` of a held one is never picked. Ties go to the smaller gap, then the
 * lower index. Writes the indices into `points` to out_indices[0 .. *out_count - 1], in the order
 * picked, none of them in `chosen`. No allocation. O(count (chosen_count + capacity) capacity).
 * Errors (::SDFCCD_INVALID_ARGUMENT): NULL pointers (points / chosen may be NULL with a zero count),
 * negative counts, an index of `chosen` outside [0, count), tilt, depth or same_place_distance not
 * finite and >= 0, a non-finite point, normal or gap. */
SDFCCD_API sdfccd_Status sdfccd_cover_contacts(const sdfccd_ContactPoint* points, int32_t count, const int32_t* chosen,
                                               int32_t chosen_count, double tilt, double depth, double same_place_distance,
                                               int32_t* out_indices, int32_t capacity, int32_t* out_count);

/** Warm starting by place: which point of a pair's previous contact set each new point continues,
 * so that it keeps its accumulated impulses and lifetime (what an engine's persistent manifold does
 * for a point that stays where it was, as Bullet's btPersistentManifold::getCacheEntry does). For
 * each of the `count` `points` in order, out_match[i] is the index of the nearest of the
 * `previous_count` `previous` points not matched to an earlier point, among those closer than
 * `distance` (m; strictly), or -1 when there is none; of equally near ones, the lower index. Give
 * both sets in the same frame, one that moves with the body (Bullet: the points' positions in
 * body A's frame, m_localPointA), so that a resting point matches itself. A pure function (no
 * handle, no allocation up to 4096 previous points). O(count x previous_count).
 * Errors (nothing written): ::SDFCCD_INVALID_ARGUMENT for a negative count, a NULL array with a
 * count > 0, `distance` not finite and >= 0, a non-finite point; ::SDFCCD_OUT_OF_MEMORY. */
SDFCCD_API sdfccd_Status sdfccd_match_contacts(const sdfccd_Vec3* previous, int32_t previous_count, const sdfccd_Vec3* points,
                                               int32_t count, double distance, int32_t* out_match);

/** sdfccd_reduce_contacts() for the points of a step, some of which may only reach the surface late in
 * it: after the first point every score (distance, area) is multiplied by
 * exp(-(gap - first gap) / depth_scale), so a point about to touch wins over a far one that spreads
 * the polygon more; and among the points scoring at least 95 % of the best, the one with the
 * smallest gap is chosen (then the smaller id, the lower index). The first point: gaps within a
 * thousandth of same_place_distance count as equally deep (rounding of an engine's float gaps), and
 * among those the farthest from their centre, a later point only by more than same_place_distance
 * (so the choice does not flip from step to step); the contact plane is the deepest point's (the
 * smallest gap, the lower index), and these distances are measured on it too. `depth_scale` (m, finite, >= 0; 0: sdfccd_reduce_contacts()). Same guarantees:
 * deterministic, never two points within `same_place_distance`, never a prefix of the set.
 * Errors: as sdfccd_reduce_contacts(), and a negative or non-finite depth_scale. */
SDFCCD_API sdfccd_Status sdfccd_reduce_contacts_weighted(const sdfccd_ContactPoint* points, int32_t count, double same_place_distance,
                                                         double depth_scale, int32_t* out_indices, int32_t capacity, int32_t* out_count);

/** What sdfccd_search_faces() found. */
typedef struct sdfccd_FaceSearch {
    int32_t count;           /**< Points written (all found, or 0 when they did not fit). */
    int32_t found;           /**< Points found: the room a call needs. */
    int64_t regions;         /**< Regions visited. */
    int64_t sdf_evaluations; /**< SDF evaluations of the call. */
} sdfccd_FaceSearch;

/** The face search, for SDFs with features smaller than the mesh's faces (a plate over a grid of
 * spikes), where the mesh queries' points (one per triangle, subdivision only around a point in
 * contact) can all lie clear of the surface while features between them pierce a face. At the
 * mesh pose `pose` and the SDF pose `sdf_pose` (NULL: the identity), every face with an edge
 * longer than `region_size` is split into 4 at its edge midpoints, down to regions with no longer
 * edge; a region whose centre is farther from the surface than the SDF's Lipschitz bound times its
 * radius plus `accept` is dropped; the deepest point (DCD with `params`, no subdivision) of each
 * remaining region is a point when its phi <= accept. It is held by its closest surface point and
 * the field's normal, unless it lies inside the SDF where the field's normal is more than about
 * 25 degrees from the face's direction out of the surface (a tip through the face: the gradient
 * inside a cone points out of its side): then by the point where the line along that direction
 * leaves the SDF, with that direction as its normal (within 4 region sizes; else as before). Faces
 * with no edge longer than region_size are left to the mesh queries. Points in the world frame,
 * `toi` 0, ids as ::sdfccd_ContactPoint. All or nothing: when more than `capacity` are found,
 * `out->count` is 0 and `out->found` is the room needed (the search is deterministic: call again).
 * Uses the workspace: no allocation after a first call of a given size. Errors
 * (::SDFCCD_INVALID_ARGUMENT unless said): NULL ws, pose, params or out, out_points NULL with
 * capacity > 0, capacity < 0, region_size not finite and > 0, accept not finite, a non-finite pose,
 * params not from sdfccd_default_query_params(), dead handles (::SDFCCD_INVALID_HANDLE). */
SDFCCD_API sdfccd_Status sdfccd_search_faces(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_Pose* sdf_pose, sdfccd_MeshId mesh,
                                             const sdfccd_Pose* pose, double region_size, double accept, const sdfccd_QueryParams* params,
                                             sdfccd_ContactPoint* out_points, int32_t capacity, sdfccd_FaceSearch* out);

/** Settings of contact generation. Must be initialised with sdfccd_default_contact_params(). */
typedef struct sdfccd_ContactParams {
    sdfccd_QueryParams query;    /**< The CCD of the step (method, caps); `query.margin` is the contact distance: a
                                      point touches when phi <= margin (default 0). ::SDFCCD_METHOD_DCD: the discrete
                                      baseline (the end pose's query decides whether the step has contact). */
    double vertex_distance;      /**< The vertices of a triangle the CCD finds in contact are points too when they are
                                      within this (or query.contact_slop, the larger) of the margin at its time of
                                      impact (a face landing flat gives its corners). m, >= 0. Default 0.02. */
    double same_place_distance;  /**< Points whose surface points are closer than this are one place: the reduction
                                      keeps one. m, >= 0; 0 (default): a thousandth of the mesh's radius, at least 1e-6 m. */
    double feature_size;         /**< The SDF's smallest feature (m, >= 0): when > 0 and query.subdivision is on, the
                                      face search (sdfccd_search_faces(), regions of 0.4 x this) adds the points of
                                      faces larger than the features. Default 0 (off). */
    int32_t reduced_count;       /**< Points of the reduction (>= 0; 0, the default: the whole capacity). The rest of the
                                      capacity is for cover points (cover_depth). */
    double cover_depth;          /**< When > 0: after the reduction, cover points (sdfccd_cover_contacts()) with this
                                      depth and the body's turn over the step fill the rest of the capacity. m, >= 0.
                                      Default 0 (none). */
    double end_skip_travel;      /**< When > 0 (continuous methods): a step whose travel (the farthest a mesh point can
                                      move relative to the SDF) is at most this runs no end-pose query, whose features
                                      are then the start pose's moved by at most this. The Bullet bridge passes its
                                      guarantee's tolerance. m, >= 0. Default 0 (always run). */
    sdfccd_KeepPrevious previous; /**< The points of this pair kept in the previous step, which the reduction prefers
                                      (::sdfccd_KeepPrevious). Default: none (ids NULL, count 0), depth 5e-4 m (the
                                      guarantee's default tolerance), share 0.8. */
    int32_t internal_value;      /**< Set by sdfccd_default_contact_params(); do not change. */
} sdfccd_ContactParams;

/** The default contact settings (see each field of ::sdfccd_ContactParams). */
SDFCCD_API sdfccd_ContactParams sdfccd_default_contact_params(void);

/** Summary of a contact set. */
typedef struct sdfccd_ContactSet {
    int32_t count;               /**< Points written: the reduction of the candidates to the caller's capacity, then
                                      any cover points. */
    int32_t candidates;          /**< Candidates found before the reduction. */
    int32_t started_in_contact;  /**< 1 when a point of the start pose was within the margin (the CCD is then not
                                      run: it could only report contact at t0). */
    int32_t ccd_ran;             /**< 1 when the CCD ran over the step. */
    sdfccd_ResultState ccd_state; /**< Its state (::SDFCCD_STATE_NO_HIT when it did not run). */
    double toi;                  /**< The CCD's first time of impact; t0 when started in contact; t1 when none. */
    int64_t sdf_evaluations;     /**< SDF evaluations of the call (all of them). */
    int32_t reduced;             /**< The first `reduced` points are the reduction, the rest (count - reduced) cover points. */
    int32_t discrete_queries;    /**< Discrete mesh queries run (start pose, end pose). */
    int64_t own_evaluations;     /**< Of sdf_evaluations, those outside the mesh queries and the face search (the
                                      closest surface points at t0 of the discrete queries' points and vertices). */
    int64_t face_regions;        /**< Regions the face search visited. */
} sdfccd_ContactSet;

/** The contact set an engine needs for one mesh against one SDF over a step [t0, t1]: points with
 * normal, signed gap at t0, time of impact, triangle and a feature id stable across steps (see
 * ::sdfccd_ContactPoint), each held by a surface point and normal found at some time in the step
 * and expressed at t0 (a speculative contact: the solver may close at most the gap in the step).
 * Let R be the mesh's radius (the largest distance of a vertex from its centre of rotation) and
 * the reach the farthest any point can travel relative to the SDF in the step. In order:
 *  1. a discrete query (DCD, subdivision regions not below (0.1 R)^2) at t0 with margin + reach:
 *     when its broad phase culls every triangle the step has no contact (nothing else runs);
 *  2. with feature_size > 0 and query.subdivision on, the face search at t0 within margin + reach;
 *  3. unless a point of 1 or 2 is already within the margin, the CCD over the step: its contact set
 *     at the first time of impact (each point held by the surface point and normal it touches
 *     there) and the vertices of those triangles within vertex_distance of the margin then. No hit:
 *     no contact (but the face search's points and then 1's count);
 *  4. the points of 1 and those of a discrete query at t1 within the margin, and the vertices of
 *     their triangles within the same distance at that pose, each held by its own closest surface
 *     point at t0 (1's within margin + reach; with a start in contact, at least margin + vertex_distance).
 * With query.method ::SDFCCD_METHOD_DCD, 3's query is the end pose's and 1 runs after it when the
 * step has contact; with t1 == t0 only 3 runs (closest points at that pose).
 * The candidates are reduced to min(capacity, reduced_count) points by the weighted reduction
 * (sdfccd_reduce_contacts_weighted() with depth scale min(0.1 R, 0.3 m); never a prefix of the
 * set), then cover points fill the rest of the capacity when cover_depth > 0. With a static SDF
 * (sdf_motion NULL or at rest) the field is evaluated in its own frame. Uses the workspace: no
 * allocation after a first call of a given size. Errors: as sdfccd_query_mesh_ws(), params not from
 * sdfccd_default_contact_params(), a distance not finite and >= 0, reduced_count < 0, out_points
 * NULL with capacity > 0; on error nothing is written. */
SDFCCD_API sdfccd_Status sdfccd_generate_contacts(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
                                                  sdfccd_MeshId mesh, const sdfccd_RigidMotion* motion, double t0, double t1,
                                                  const sdfccd_ContactParams* params, sdfccd_ContactPoint* out_points,
                                                  int32_t capacity, sdfccd_ContactSet* out_set);

/** One pair of sdfccd_generate_contacts_batch(): the arguments of sdfccd_generate_contacts() and
 * its status. */
typedef struct sdfccd_ContactPair {
    sdfccd_SdfId sdf;                     /**< The SDF. */
    const sdfccd_RigidMotion* sdf_motion; /**< NULL: a static SDF at the origin. */
    sdfccd_MeshId mesh;                   /**< The mesh. */
    const sdfccd_RigidMotion* motion;     /**< The mesh's rigid motion over [t0, t1]. */
    double t0;                            /**< Start of the step (s). */
    double t1;                            /**< End of the step (s). */
    const sdfccd_ContactParams* params;   /**< From sdfccd_default_contact_params(). */
    sdfccd_ContactPoint* out_points;      /**< Room for `capacity` points (the reduction when the set is larger). */
    int32_t capacity;                     /**< Size of out_points. */
    sdfccd_ContactSet* out_set;           /**< Written: the set's summary. */
    sdfccd_Status status;                 /**< Written: the pair's status. */
} sdfccd_ContactPair;

/** sdfccd_generate_contacts() for `count` pairs on `thread_count` threads (the calling thread and
 * thread_count - 1 more), thread k with workspaces[k]: no allocation after a first call of a given
 * size. Each pair's result is exactly the single call's, whatever the thread count. Returns the
 * first failing pair's status (its message in sdfccd_last_error()), the others are still run.
 * Errors (::SDFCCD_INVALID_ARGUMENT): pairs or workspaces NULL (pairs may be NULL when count is 0),
 * count < 0, thread_count outside [1, 256], a NULL workspace. */
SDFCCD_API sdfccd_Status sdfccd_generate_contacts_batch(sdfccd_Workspace* const* workspaces, int32_t thread_count,
                                                        sdfccd_ContactPair* pairs, int32_t count);

/** sdfccd_generate_contacts() for a deforming mesh (cloth, soft bodies): the mesh's topology with
 * per-vertex world positions at t0 (`start`) and t1 (`end`), vertex_count each, moving linearly. */
SDFCCD_API sdfccd_Status sdfccd_generate_contacts_linear(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
                                                         sdfccd_MeshId mesh, const sdfccd_Vec3* start, const sdfccd_Vec3* end,
                                                         double t0, double t1, const sdfccd_ContactParams* params,
                                                         sdfccd_ContactPoint* out_points, int32_t capacity, sdfccd_ContactSet* out_set);

/** The guarantee for a deforming mesh: sdfccd_guard_rigid() with each vertex moving linearly from
 * `start` (t0) to `end` (t1), world positions, vertex_count each. `out->safe_pose` is the identity
 * (unused); the safe positions, the vertices at `out->toi`, go to `out_positions` (vertex_count
 * entries; may be NULL), the end positions unless ROLLED_BACK. */
SDFCCD_API sdfccd_Status sdfccd_guard_linear(sdfccd_Workspace* ws, sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
                                             sdfccd_MeshId mesh, const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0,
                                             double t1, const sdfccd_GuardParams* params, sdfccd_GuardResult* out,
                                             sdfccd_Vec3* out_positions);

/* ---- Per-vertex linear motion (soft bodies, cloth): a point's path to a level and distance
 * certificates, the steps an engine bridge takes before a face query (Section 4, each vertex moving
 * linearly; core/soft.c). Every position is in the SDF's frame. ---- */

/** A remembered lower bound of the SDF near some anchors: any point set whose corners each lie
 * within d of their anchor (a point: anchor[0] alone) has phi >= bound - lipschitz * d. Kept from
 * step to step, a node or face that stays far from the surface needs no SDF evaluation. Start
 * from sdfccd_empty_distance_cert() (never a zeroed struct: bound 0 would claim phi >= 0). */
typedef struct sdfccd_DistanceCert {
    sdfccd_Vec3 anchor[3]; /**< the corners the bound was found at (SDF frame, length units) */
    double bound;          /**< phi >= bound at the anchors and minus lipschitz * d within d; -INFINITY: certifies nothing */
} sdfccd_DistanceCert;

/** A certificate that certifies nothing (bound -INFINITY, anchors at the origin). */
SDFCCD_API sdfccd_DistanceCert sdfccd_empty_distance_cert(void);

/** The lower bound of phi that `cert` gives over `count` (1..3) corners moving linearly from start[k]
 * to end[k]: cert->bound - lipschitz * (the largest distance of a corner to its anchor at either end
 * of its path; linear paths are farthest from a point at an end). No SDF evaluation.
 * Errors (INVALID_ARGUMENT, nothing written): a NULL pointer, count outside 1..3, lipschitz not
 * finite and > 0, a start or end corner not finite. */
SDFCCD_API sdfccd_Status sdfccd_distance_cert_bound(const sdfccd_DistanceCert* cert, const sdfccd_Vec3* start, const sdfccd_Vec3* end,
                                                    int32_t count, double lipschitz, double* out_bound);

/** Where a point moving linearly first reaches a level of the SDF (sdfccd_point_first_hit()). */
typedef struct sdfccd_PointHit {
    int32_t hit;           /**< 1 when the path reaches phi <= level + 1e-6, 0 when it stays above */
    double fraction;       /**< the first such fraction of the path, in [0, 1] (0 when not hit) */
    double distance;       /**< phi there */
    sdfccd_Vec3 gradient;  /**< the SDF's gradient there (SDF frame, not normalised) */
    double start_distance; /**< phi at the start of the path (always evaluated) */
} sdfccd_PointHit;

/** The first point of the path start -> end (SDF frame) where phi <= level + 1e-6, by conservative
 * advancement: with phi `lipschitz`-Lipschitz (at least the SDF's own bound, sdfccd_sdf_get_info()),
 * a step of (phi - level) / lipschitz along the path cannot jump over the level, so a hit is never
 * missed and never late. At most 200 evaluations; after them the point reached counts as the hit
 * (early, never late). A path that starts at or below the level hits at fraction 0. Adds the SDF
 * evaluations to *io_sdf_evaluations (may be NULL). Errors (nothing written): INVALID_HANDLE,
 * INVALID_ARGUMENT for out NULL, start, end or level not finite, lipschitz not finite and > 0. */
SDFCCD_API sdfccd_Status sdfccd_point_first_hit(sdfccd_SdfId sdf, sdfccd_Vec3 start, sdfccd_Vec3 end, double level, double lipschitz,
                                                sdfccd_PointHit* out, int64_t* io_sdf_evaluations);

/** Is a triangle moving linearly from start[] to end[] (SDF frame) certified to keep phi >= level
 * everywhere on it over the whole motion? First by *cert (no evaluation); else by a new lower bound
 * of phi over the start triangle: phi at its centroid minus lipschitz times its radius, split into
 * four pieces at the edge midpoints (up to 3 times, at most 85 evaluations) where that is too low,
 * against level + lipschitz times the largest corner motion. A new bound replaces *cert (anchored
 * at start[]). *out_clear = 0 means "not certified" (the triangle may come near the surface: run
 * the CCD), never "it hits"; a triangle whose interior comes near the surface while its corners
 * stay far is never certified. Adds the SDF evaluations to *io_sdf_evaluations (may be NULL).
 * Errors (nothing written): INVALID_HANDLE, INVALID_ARGUMENT for a NULL pointer, a corner or level
 * not finite, lipschitz not finite and > 0. */
SDFCCD_API sdfccd_Status sdfccd_triangle_clear(sdfccd_SdfId sdf, sdfccd_DistanceCert* cert, const sdfccd_Vec3 start[3],
                                               const sdfccd_Vec3 end[3], double level, double lipschitz, int32_t* out_clear,
                                               int64_t* io_sdf_evaluations);

/** The guard's verdict on one node over a step (sdfccd_guard_point()). */
typedef struct sdfccd_PointGuard {
    int32_t clear;        /**< 1 when the certificate alone keeps the path above -tolerance (no SDF evaluation) */
    double level;         /**< the level the path is held to: -tolerance, or (a start deeper than the tolerance) the start's phi - 0.1 tolerance */
    int32_t hit;          /**< 1 when the path goes below `level`: the node goes back to `fraction` */
    double fraction;      /**< where it goes back to, in [0, 1]: the first reach of level + tolerance / 2 when earlier than the first reach of level (0 when not hit) */
    sdfccd_Vec3 gradient; /**< the SDF's gradient at the first reach of `level` (SDF frame, not normalised; the direction to stop the node's velocity along) */
} sdfccd_PointGuard;

/** The no-tunnelling guard for one point moving linearly from start to end (SDF frame): its path may
 * not go deeper than the tolerance, nor, when it starts deeper, deeper than it started (minus a tenth
 * of the tolerance). A path that does goes back to where it first came within half the tolerance of
 * that level (sdfccd_point_first_hit(), so never late). `cert` (e.g. from a previous step's
 * sdfccd_point_first_hit() start distance, anchored at that start) skips every evaluation when it
 * keeps the path above -tolerance. Adds the SDF evaluations to *io_sdf_evaluations (may be NULL).
 * Errors (nothing written): INVALID_HANDLE, INVALID_ARGUMENT for a NULL cert or out, start or end
 * not finite, tolerance or lipschitz not finite and > 0. */
SDFCCD_API sdfccd_Status sdfccd_guard_point(sdfccd_SdfId sdf, const sdfccd_DistanceCert* cert, sdfccd_Vec3 start, sdfccd_Vec3 end,
                                            double tolerance, double lipschitz, sdfccd_PointGuard* out, int64_t* io_sdf_evaluations);

/** Where a segment moving linearly (its ends from start[0], start[1] to end[0], end[1], SDF frame;
 * a rope's link) first comes down to `level`: its inner points every h <= spacing (h = the longer of
 * its start and end lengths / n, n = 1 + ceil(that length / spacing)), each path checked by
 * sdfccd_point_first_hit() at level + lipschitz h / 2, so that no point between two of them reaches
 * the level first. The ends themselves are not checked (they are nodes). out->start_distance is 0.
 * Adds the SDF evaluations to *io_sdf_evaluations (may be NULL). Errors (nothing written):
 * INVALID_HANDLE, INVALID_ARGUMENT for a NULL pointer, an end or level not finite, spacing or
 * lipschitz not finite and > 0, more than 1e6 points. */
SDFCCD_API sdfccd_Status sdfccd_segment_first_hit(sdfccd_SdfId sdf, const sdfccd_Vec3 start[2], const sdfccd_Vec3 end[2], double level,
                                                  double spacing, double lipschitz, sdfccd_PointHit* out, int64_t* io_sdf_evaluations);

/** The guard's verdict on one face over a step (sdfccd_guard_face()). */
typedef struct sdfccd_FaceGuard {
    int32_t hit;         /**< 1: the face's corners go back to `fraction` of their motion */
    double fraction;     /**< in [0, 1] (0: back to the start; 0 when not hit) */
    int32_t stop;        /**< 1: a crossing; the corners lose their velocity into `normal` there */
    sdfccd_Vec3 normal;  /**< the SDF's normal at the crossing (SDF frame, unit; valid when stop is 1) */
    int32_t queries;     /**< triangle queries run (sdfccd_query_triangle_linear()) */
} sdfccd_FaceGuard;

/** The no-tunnelling guard for one face whose corners move linearly from start[] to end[] (SDF
 * frame): no point of it may go below `level` (<= 0; a soft body: the lowest of its nodes' levels,
 * sdfccd_guard_point()). Skipped without a query when sdfccd_triangle_clear() certifies it (with
 * `cert`). A face that starts below `level` may not end deeper than its deepest start point minus a
 * tenth of the tolerance (else back to its start, stop 0). A face that crosses goes back to where it
 * first came within half the tolerance of the level (or to its start when `last_pass` is non-zero:
 * an engine repeating the guard over the faces whose nodes it moved ends that way). `params`: the
 * query settings (the margin is the guard's own), its time tolerances against the step's `duration`
 * (s, > 0). Adds the SDF evaluations to
 * *io_sdf_evaluations (may be NULL). Errors (nothing written): INVALID_HANDLE, DEGENERATE for a
 * zero-area start (its corners are checked on their own), INVALID_ARGUMENT for a NULL pointer, a
 * corner or level not finite, tolerance, lipschitz or duration not finite and > 0, or a failing query's status. */
SDFCCD_API sdfccd_Status sdfccd_guard_face(sdfccd_SdfId sdf, sdfccd_DistanceCert* cert, const sdfccd_Vec3 start[3], const sdfccd_Vec3 end[3],
                                           double level, double tolerance, double lipschitz, const sdfccd_QueryParams* params,
                                           double duration, int32_t last_pass, sdfccd_FaceGuard* out, int64_t* io_sdf_evaluations);

/** One check of sdfccd_guard_body(): a mesh (a body, or one part of it) against an SDF over the step. */
typedef struct sdfccd_GuardPair {
    sdfccd_SdfId sdf;                     /**< The SDF. */
    const sdfccd_RigidMotion* sdf_motion; /**< Its motion (NULL: static at the world origin). */
    sdfccd_MeshId mesh;                   /**< The mesh. */
    sdfccd_RigidMotion executed;          /**< The motion the mesh executed over the step. */
} sdfccd_GuardPair;

/** What sdfccd_guard_body() found. */
typedef struct sdfccd_GuardBodyResult {
    sdfccd_GuardResult first; /**< The earliest rollback (`index`'s result); CLEAR with toi t1 when none. */
    int32_t index;            /**< Its pair (the first of equal times), -1 when no pair rolled back. */
    int32_t certified;        /**< Pairs proven clear without a CCD. */
    int32_t failed;           /**< Pairs whose check returned an error: skipped. */
    sdfccd_Status error;      /**< The first such error (::SDFCCD_OK when none). */
    int64_t sdf_evaluations;  /**< SDF evaluations of every check. */
} sdfccd_GuardBodyResult;

/** The guarantee for one body over a step: sdfccd_guard_step_rigid() on each pair (its parts against
 * the SDFs it can reach), and the earliest rollback of all, where the body goes back to. A pair whose
 * check fails (its errors are sdfccd_guard_step_rigid()'s) is skipped and counted; the others still
 * guard the body. Errors (nothing written): ::SDFCCD_INVALID_ARGUMENT for a NULL `out` or `params`,
 * `count` < 0, NULL `pairs` with `count` > 0. */
SDFCCD_API sdfccd_Status sdfccd_guard_body(sdfccd_Workspace* ws, const sdfccd_GuardPair* pairs, int32_t count, double t0, double t1,
                                           const sdfccd_GuardParams* params, sdfccd_GuardBodyResult* out);

/** The box a rigid body can occupy at any time of a step (the guard's broad phase, world frame, m),
 * for the motion sdfccd_rigid_motion_from_poses() makes of its two poses about its origin (for
 * Bullet the centre of mass): the origin moves linearly from `start`'s position to `end`'s, and the
 * body turns at a constant rate by the shortest arc between the two orientations (angle a <= pi).
 * `start_box` and `end_box` hold the body at the two poses; `reach` (m) bounds its points' distance
 * from the origin. Without a turn (equal orientations) the result is the union of the two boxes.
 * With one, a point leaves the segment between its two end positions by at most reach a^2 / 8, so
 * the union grows by that much on every side, and each side is then cut to the origin segment's box
 * grown by `reach` where that is tighter. `reach` is not used without a turn.
 *
 * Errors (::SDFCCD_INVALID_ARGUMENT, nothing written): a NULL pointer, a NaN box coordinate (infinite
 * ones are allowed: an unbounded body), a non-finite pose or a zero orientation, and with a turn a
 * `reach` that is not finite and >= 0. */
SDFCCD_API sdfccd_Status sdfccd_swept_aabb(const sdfccd_Aabb* start_box, const sdfccd_Aabb* end_box, const sdfccd_Pose* start,
                                           const sdfccd_Pose* end, double reach, sdfccd_Aabb* out_box);

/** One SDF of sdfccd_guard_world(): its field, its motion over the step and its body. */
typedef struct sdfccd_GuardSdf {
    sdfccd_SdfId sdf;          /**< The SDF, in the frame of its poses. */
    sdfccd_Pose start;         /**< Its pose at t0. */
    sdfccd_Pose end;           /**< Its pose at t1 (equal to `start`: it does not move). */
    sdfccd_Aabb start_box;     /**< Its world box at `start` (sdfccd_swept_aabb() makes the box of its motion from these). */
    sdfccd_Aabb end_box;       /**< Its world box at `end`. */
    double reach;              /**< A bound (m, >= 0) on its points' distance from its origin (sdfccd_swept_aabb()). */
    double friction;           /**< Its Coulomb coefficient (>= 0); a rolled-back body's is the product with the body's. */
    uint64_t shape_key;        /**< Nonzero: a part with the same key is this SDF's own surface and is not checked
                                    against it (the engine's shape identity, e.g. its address). 0: none. */
    int32_t body;              /**< The index in `bodies` of the dynamic body that carries this SDF, else -1: that body is
                                    not checked against it, and a response against it takes that body's state as the call
                                    has it then (after its own rollback, if it had one). */
    int32_t has_state;         /**< 1: `state` is the SDF's (kinematic or static) rigid body, which the response counts as
                                    infinitely heavy; 0: a static SDF without a body. Not used when `body` >= 0. */
    sdfccd_BodyState state;    /**< See `has_state`. */
} sdfccd_GuardSdf;

/** One mesh of a body of sdfccd_guard_world(): the body itself, or a part of a compound. */
typedef struct sdfccd_GuardPart {
    sdfccd_MeshId mesh;        /**< The mesh, in the part's frame. */
    sdfccd_Pose offset;        /**< The part's pose in the body frame (the identity for a body that is one mesh). */
    uint64_t shape_key;        /**< See sdfccd_GuardSdf::shape_key (0: none). */
} sdfccd_GuardPart;

/** One dynamic body of sdfccd_guard_world(): where it was and where the engine's step put it. */
typedef struct sdfccd_GuardRigidBody {
    sdfccd_Pose start;              /**< Its pose at t0. */
    sdfccd_Pose end;                /**< Its pose at t1, as the engine integrated it. */
    sdfccd_Aabb start_box;          /**< Its world box at `start`. */
    sdfccd_Aabb end_box;            /**< Its world box at `end`. */
    double reach;                   /**< A bound (m, >= 0) on its points' distance from its origin. */
    const sdfccd_GuardPart* parts;  /**< Its meshes (`part_count`; may be NULL when 0). */
    int32_t part_count;             /**< >= 0. */
    double friction;                /**< Its Coulomb coefficient (>= 0). */
    sdfccd_BodyState state;         /**< At `end`: centre of mass, velocities after the solve, inverse mass, world inverse
                                         inertia. The executed motion turns about this centre. */
} sdfccd_GuardRigidBody;

/** What sdfccd_guard_world() did to one body. */
typedef struct sdfccd_GuardWorldResult {
    int32_t rolled_back;       /**< 1 when the body went back to a time of impact. */
    int32_t sdf;               /**< The index in `sdfs` of the SDF it went back for, else -1. */
    int32_t part;              /**< The index in its parts of the part that reached it first, else -1. */
    sdfccd_Pose pose;          /**< Where the body is to be: its safe pose when rolled back, else its `end` pose. */
    sdfccd_BodyState state;    /**< Its state there: when rolled back, its centre and inertia at `pose` and the velocities
                                    sdfccd_guard_response() leaves it; else its `state`. */
    sdfccd_GuardResult guard;  /**< The part's check (the part's safe pose and the SDF's point and normal at the time of
                                    impact); CLEAR with toi t1 when the body was not rolled back. */
    int32_t queries;           /**< (part, SDF) checks run for it. */
    int32_t failures;          /**< Checks that returned an error: skipped, the others still guard the body. */
    int64_t sdf_evaluations;   /**< SDF evaluations of its checks. */
} sdfccd_GuardWorldResult;

/** Optional engine hook of sdfccd_guard_world(), called once for each body it rolls back, in body
 * order, before that body's response: the engine puts body `body` at `pose` and may overwrite
 * `state` (filled with the body's centre and inertia at `pose` as the library computes them) and
 * `friction` (the product of the two coefficients) with its own, e.g. in its own precision. */
typedef void (*sdfccd_GuardPlaceFn)(void* user, int32_t body, int32_t sdf, const sdfccd_Pose* pose, sdfccd_BodyState* state,
                                    double* friction);

/** The guarantee for a whole world after an engine's step (Section 4: the simulation never
 * advances past a time of impact), with plain arrays: the SDFs with their two poses, and every
 * dynamic body with its two poses, its meshes and its state. For each body in order:
 *  - broad phase: the box it can occupy over the step (sdfccd_swept_aabb() of its boxes, grown by
 *    the tolerance) against each SDF's; a pair where neither moved (equal start and end poses: a
 *    sleeping body on a static SDF) costs no query;
 *  - each part against each SDF it can reach (SDFs outer, parts inner): the part's executed motion
 *    (sdfccd_rigid_motion_from_poses() of the body's poses times its offset, turning about the
 *    body's centre) checked by sdfccd_guard_step_rigid(), the SDF moving with the motion of its own
 *    two poses; the earliest rollback of all wins (the first of equal times);
 *  - a rolled-back body goes to the hitting part's safe pose times the inverse of its offset; when
 *    that SDF moves, the body is carried with it from the time of impact to the SDF's end pose (it
 *    keeps its place relative to the SDF instead of being left inside it);
 *  - its velocity: sdfccd_guard_response() with `repeated` = 1 (it loses its velocity into the
 *    surface), the SDF's state as described in ::sdfccd_GuardSdf, friction the product of the two.
 * `place` (NULL: none) is called with `place_user` for each rolled-back body, see ::sdfccd_GuardPlaceFn.
 * `results` (`body_count`) receives each body's outcome; the engine applies `pose` and `state`.
 *
 * Uses the workspace: no allocation after a first call of a given size. Errors
 * (::SDFCCD_INVALID_ARGUMENT, ::SDFCCD_INVALID_HANDLE; nothing written, `place` not called): NULL
 * `ws` or `params`, params not from sdfccd_default_guard_params() or refused by the guard, negative
 * counts, NULL arrays with a count > 0, t1 <= t0 or not finite, a pose that is not finite, not unit
 * (1e-4) or above SDFCCD_MAX_QUERY_MAGNITUDE, an SDF whose two poses give no motion
 * (sdfccd_rigid_motion_from_poses()), a NaN box, a reach or friction not finite and >= 0, an SDF's
 * `body` outside [-1, body_count), a non-finite state, a stale SDF or mesh handle. A failing
 * check of one pair is counted in the body's `failures` and skipped. */
SDFCCD_API sdfccd_Status sdfccd_guard_world(sdfccd_Workspace* ws, const sdfccd_GuardSdf* sdfs, int32_t sdf_count,
                                            const sdfccd_GuardRigidBody* bodies, int32_t body_count, double t0, double t1,
                                            const sdfccd_GuardParams* params, sdfccd_GuardPlaceFn place, void* place_user,
                                            sdfccd_GuardWorldResult* results);

/** A contact of a rigid body on an SDF after an engine's solve, for sdfccd_friction_hold() (world frame). */
typedef struct sdfccd_HeldContact {
    sdfccd_Vec3 point;            /**< Where the impulses act (m). */
    sdfccd_Vec3 normal;           /**< Unit contact normal, from the SDF towards the body. */
    sdfccd_Vec3 surface_velocity; /**< The SDF's velocity at `point` (m/s; zero for a static SDF). */
    sdfccd_Vec3 friction_impulse; /**< Friction impulse the solver applied to the body at the point (N s; its part
                                       along the normal is ignored). */
    double normal_impulse;        /**< Normal impulse the solver applied at the point (N s, >= 0; 0: the point
                                       carried no load and holds nothing). */
    double friction;              /**< Coulomb coefficient (>= 0). */
} sdfccd_HeldContact;

/** Static friction that an engine's solve left out, for a body at rest on an SDF. A solver that
 * gives each contact point one friction direction (Bullet's default: along the point's sliding
 * velocity) leaves the other tangent direction free, so a body that should stick can creep. When
 * every loaded contact point (normal_impulse > 0) moves slower than `rest_speed` (m/s) relative to
 * the SDF (the engine's resting-contact speed; an impact or a fast slide is left to the solver),
 * this adds at each contact the tangential impulse that stops the point sliding relative to the SDF
 * (`surface_velocity`), such that the solver's friction impulse and the added one together stay
 * within the point's Coulomb cone (|friction_impulse + added| <= friction * normal_impulse): a
 * sticking body stops, a sliding one keeps the friction the cone allows. Sixteen Gauss-Seidel passes
 * over the points in order (deterministic; more than 64 points are held 64 at a time, in order).
 * `body` (its velocities after the solve; the SDF counts as infinitely heavy) gets the new
 * velocities; `impulses` (`count` entries, may be NULL) receives the added impulse per point (zero
 * when the body is not at rest). Errors (::SDFCCD_INVALID_ARGUMENT, nothing written): NULL `body`,
 * NULL `contacts` with `count` > 0, `count` < 0, non-finite values, a zero normal, a negative normal
 * impulse, friction, inverse mass or `rest_speed`. */
SDFCCD_API sdfccd_Status sdfccd_friction_hold(const sdfccd_HeldContact* contacts, int32_t count, double rest_speed, sdfccd_BodyState* body,
                                              sdfccd_Vec3* impulses);

#ifdef __cplusplus
}
#endif
#endif
