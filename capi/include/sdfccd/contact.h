/* SPDX-License-Identifier: MIT */
/** @file contact.h  What a physics engine needs from the CCD over one step: the no-tunnelling
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
 * thickness of a thin feature can cross it; the start depth comes from a local search (DCD), and a
 * triangle whose check still reports contact at t0 after three corrections of its level is left out
 * of the check (counted in `deep_triangles`). */
typedef struct sdfccd_GuardResult {
    sdfccd_GuardState state;   /**< Clear, rolled back, or inside at the start. */
    double toi;                /**< Seconds in [t0, t1]: the time of the safe pose, at most a time tolerance before the
                                    first time a point reached its level when ROLLED_BACK; t1 otherwise. */
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

#ifdef __cplusplus
}
#endif
#endif
