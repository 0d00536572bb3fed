/* SPDX-License-Identifier: MIT */
/** @file soft.h  One step of a soft body (cloth, rope, volumetric body) against an SDF: the contact
 * planes of its nodes and faces, holding a node on its planes inside an engine's position solve, and
 * the no-tunnelling guard after the solve. Nodes move linearly over the step (the paper's deformable
 * case, Section 4). Paths are advanced with the SDF's Lipschitz bound (sdfccd_sdf_get_info(), taken
 * as 1 when below 1). An engine bridge only converts its own types to these arrays and back. */
#ifndef SDFCCD_SOFT_H
#define SDFCCD_SOFT_H

#include "contact.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A rigid frame (the SDF body's pose): world = rotation * local + origin. */
typedef struct sdfccd_Frame {
    double rotation[3][3]; /**< Rotation matrix, rotation[row][column]. */
    sdfccd_Vec3 origin;    /**< Origin of the local frame in world coordinates. */
} sdfccd_Frame;

/** A soft body over one step: its nodes' world positions at the start and the end of the step and
 * its topology. */
typedef struct sdfccd_SoftBody {
    int32_t node_count;       /**< Number of nodes (>= 0). */
    const sdfccd_Vec3* start; /**< Node positions at the start of the step (world), node_count. */
    const sdfccd_Vec3* end;   /**< Node positions at the end of the step (world): predicted ones for contacts, the solved ones for the guard. */
    const uint8_t* pinned;    /**< Per node, non-zero: pinned by the engine (gets no contact plane). NULL: none. */
    int32_t face_count;       /**< Number of faces (>= 0). */
    const int32_t* faces;     /**< Three node indices per face (may be NULL when face_count is 0). */
    int32_t link_count;       /**< Number of links (>= 0); the guard checks them only in a body without faces (a rope). */
    const int32_t* links;     /**< Two node indices per link (may be NULL when link_count is 0). */
    int32_t single_precision; /**< Non-zero: the engine stores positions in float; positions the guard and the hold write are rounded so, and later checks see what the engine will hold. */
} sdfccd_SoftBody;

/** A contact plane of one node: normal . x + offset >= 0 on the free side. */
typedef struct sdfccd_SoftPlane {
    int32_t node;             /**< The node it holds. */
    int32_t face;             /**< 1: from a point inside one of the node's faces, 0: from the node's own path. */
    sdfccd_Vec3 normal;       /**< Unit normal (world): the SDF's gradient at the contact. */
    double offset;            /**< Offset (world). */
    sdfccd_Vec3 local_normal; /**< The same plane in the SDF's frame. */
    double local_offset;      /**< Its offset in the SDF's frame. */
    double start_distance;    /**< normal . (the node's start position) + offset (world). */
} sdfccd_SoftPlane;

/** Settings of sdfccd_soft_contacts(). */
typedef struct sdfccd_SoftContactParams {
    sdfccd_QueryParams query; /**< Face queries (the margin is set by the function); method DCD checks the nodes at their end positions only. */
    double soft_margin;       /**< The soft body's collision margin (m, >= 0): the planes lie that far out of the SDF. */
    double contact_margin;    /**< How far beyond the planes a node's path counts (m, >= 0). */
    double duration;          /**< The step (s); a face's contact time is a fraction of it. */
} sdfccd_SoftContactParams;

/** Counters the soft-body functions add to (set them to 0 once). */
typedef struct sdfccd_SoftStats {
    int64_t face_queries;    /**< Triangle queries run (sdfccd_query_triangle_linear()). */
    int64_t query_errors;    /**< Face queries that failed (that face got no contact). */
    int64_t sdf_evaluations; /**< SDF evaluations. */
} sdfccd_SoftStats;

/** The contact planes of a soft body against `sdf` (posed by `frame`) over a step.
 * A node's path is checked by sdfccd_point_first_hit() down to soft_margin + contact_margin. A
 * contact there gives a plane at the soft margin.
 *
 * A face's per-vertex linear motion is checked by sdfccd_query_triangle_linear() down to 0.3 of
 * the soft margin (the contact margin when the soft margin is 0). A contact inside the face gives
 * each of its nodes a plane: the one through the surface point shifted by that node's offset from
 * the face point, so the face point cannot pass while the nodes hold.
 *
 * Nodes and faces certified clear (`node_certs`, `face_certs`: node_count and face_count entries,
 * kept by the caller from step to step, sdfccd_empty_distance_cert() at first) cost no query.
 *
 * Per node, only the most restrictive plane of each kind is kept (the one its start position is
 * closest to). They go to `out_planes` (capacity >= 2 node_count), in node order, the node's own
 * plane first, and their number to `*out_count`. Failed face queries are counted in `io_stats`,
 * not returned.
 *
 * Errors (nothing written): INVALID_HANDLE; INVALID_ARGUMENT for a NULL pointer, a count < 0, a
 * node index out of range, a margin not finite and >= 0, capacity too small. */
SDFCCD_API sdfccd_Status sdfccd_soft_contacts(sdfccd_SdfId sdf, const sdfccd_Frame* frame, const sdfccd_SoftBody* body,
                                              const sdfccd_SoftContactParams* params, sdfccd_DistanceCert* node_certs,
                                              sdfccd_DistanceCert* face_certs, sdfccd_SoftPlane* out_planes, int32_t capacity,
                                              int32_t* out_count, sdfccd_SoftStats* io_stats);

/** One pass of holding nodes on their contact planes (planes from sdfccd_soft_contacts(), their
 * local_normal and local_offset), run after each of an engine's position iterations. Positions are
 * world ones; the planes hold in the SDF body's frame now (`frame`); the node's step is measured
 * from `start` (world) seen in the frame at the start of the step (`start_frame`).
 *
 * A node below its plane goes onto it; one above it is free. Coulomb friction: the node's sideways
 * step stops while it is within `friction` times the pushes its plane gave so far
 * (`pushes`, one per plane, 0 at the first pass). With `last` non-zero, a longer sideways step is
 * shortened by that much instead, and the velocity of every node a plane has pushed is set to
 * velocity_scale * (x - start) (x as stored), never more outward than it was.
 *
 * Nodes with inverse mass <= 0 are left alone. `*out_held` (may be NULL) gets the number of
 * (plane, node) updates of a last pass. Errors (nothing written): INVALID_ARGUMENT for a NULL
 * pointer, a count < 0, a plane's node out of range. */
SDFCCD_API sdfccd_Status sdfccd_soft_hold(const sdfccd_Frame* start_frame, const sdfccd_Frame* frame, const sdfccd_Vec3* start,
                                          sdfccd_Vec3* positions, sdfccd_Vec3* velocities, const double* inverse_masses,
                                          int32_t node_count, const sdfccd_SoftPlane* planes, int32_t plane_count, double friction,
                                          double* pushes, double velocity_scale, int32_t last, int32_t single_precision,
                                          int32_t* out_held);

/** A rigid body a node touches, as sdfccd_soft_node_contact() sees it (world frame). */
typedef struct sdfccd_SoftRigid {
    sdfccd_Vec3 origin;           /**< Its centre of mass (m). */
    sdfccd_Vec3 linear_velocity;  /**< Of the centre of mass (m/s). */
    sdfccd_Vec3 angular_velocity; /**< (rad/s). */
    double inverse_mass;          /**< 1/kg; 0 for a static or kinematic body. */
    double inverse_inertia[3][3]; /**< Inverse inertia tensor (world); zeros for a static or kinematic body. */
} sdfccd_SoftRigid;

/** The terms of a node's contact with a rigid body in a position-based soft-body solver, as
 * Bullet's own soft-rigid collision handler computes them (btSoftBody::RContact m_c0 to m_c3). */
typedef struct sdfccd_SoftNodeContact {
    double impulse[3][3]; /**< (1/dt) (ima I + imb I - [r]x Iw^-1 [r]x)^-1: the impulse that cancels a unit relative displacement. */
    sdfccd_Vec3 arm;      /**< r: the node's end position minus the body's origin (m). */
    double mass_dt;       /**< The node's inverse mass times dt. */
    double friction_keep; /**< 0 when static friction holds (the node's sideways motion relative to the body's point at most friction times its normal motion), else 1 - friction. */
} sdfccd_SoftNodeContact;

/** The contact terms of a node (inverse mass `inverse_mass`, moving from `start` to `end` over a
 * step of `duration` s) with `body` along the unit contact normal `normal` (world), with the
 * combined friction coefficient `friction`. With `single_precision` non-zero every operation is
 * rounded as a float engine rounds it (its inputs being floats), so that such an engine gets its
 * own numbers. Errors (nothing written): INVALID_ARGUMENT for a NULL pointer, a duration not
 * finite and > 0, or a node and a body without inverse mass. */
SDFCCD_API sdfccd_Status sdfccd_soft_node_contact(sdfccd_Vec3 start, sdfccd_Vec3 end, double inverse_mass, const sdfccd_SoftRigid* body,
                                                  sdfccd_Vec3 normal, double friction, double duration, int32_t single_precision,
                                                  sdfccd_SoftNodeContact* out);

/** What sdfccd_soft_guard() decided for one node. */
typedef struct sdfccd_SoftGuardNode {
    int32_t moved;        /**< 1: the node goes to `position` with `velocity`. */
    int32_t stop;         /**< 1: it lost its velocity into `normal`. */
    sdfccd_Vec3 position; /**< Its new end position (world; before single-precision rounding). */
    sdfccd_Vec3 normal;   /**< Unit normal (world) the velocity was stopped along. */
    sdfccd_Vec3 velocity; /**< Its new velocity (world; 0 when not moved): velocity_scale * (position - start), less its part into `normal` when stop; computed as a float engine does when the body is single_precision. */
} sdfccd_SoftGuardNode;

/** The no-tunnelling guard of a soft body's step against `sdf`: the SDF's frame at the start of
 * the step `start_frame` (start positions are seen in it) and now `frame` (end positions).
 *
 * Nodes by sdfccd_guard_point(). Then faces by sdfccd_guard_face() at the lowest of their nodes'
 * levels; a body without faces checks its links by sdfccd_segment_first_hit() with points every
 * tolerance / 2. That pass is repeated over the faces (links) whose nodes moved. After four passes,
 * a face still crossing goes back to its start, and so on until none crosses.
 *
 * `node_certs` (node_count) and `face_certs` (face_count + link_count) are the caller's
 * certificates. `out_nodes` (node_count) gets what happens to each node. `*out_moved` (may be NULL)
 * gets the number of nodes moved. `duration` is the step (s, > 0). A moved node's velocity is
 * velocity_scale * (its displacement over the step), as the engine sets it after its position solve
 * (1 / duration, or a damped rule such as Bullet's (1 - kDP) / dt). Failed checks are counted in
 * `io_stats` and skipped.
 *
 * Errors (nothing written): INVALID_HANDLE; INVALID_ARGUMENT for a NULL pointer, a count < 0, a
 * node index out of range, tolerance or duration not finite and > 0, velocity_scale not finite;
 * OUT_OF_MEMORY. */
SDFCCD_API sdfccd_Status sdfccd_soft_guard(sdfccd_SdfId sdf, const sdfccd_Frame* start_frame, const sdfccd_Frame* frame,
                                           const sdfccd_SoftBody* body, double tolerance, double duration, double velocity_scale,
                                           const sdfccd_QueryParams* query, sdfccd_DistanceCert* node_certs,
                                           sdfccd_DistanceCert* face_certs, sdfccd_SoftGuardNode* out_nodes, int32_t* out_moved,
                                           sdfccd_SoftStats* io_stats);

#ifdef __cplusplus
}
#endif
#endif
