// SPDX-License-Identifier: MIT
/** @file soft_body.h  Bullet soft bodies (btSoftBody: cloth, ropes, volumetric bodies) against SDFs.
 *
 * Bridge::registerWith() also registers the bridge for (btSoftBody, SdfShape) and (btSoftBody,
 * btSdfCollisionShape) in both body orders (world: btSoftRigidDynamicsWorld with
 * btSoftBodyRigidBodyCollisionConfiguration). Each step, the soft body's nodes move linearly from
 * their positions at the start of the step (btSoftBody::Node::m_q) to the predicted ones (m_x), and
 * the C API's sdfccd_soft_contacts() (sdfccd/soft.h) gives their contact planes, within the soft
 * body's collision margin plus Config::contact_margin. Against a static or kinematic SDF body, in a
 * btSoftRigidDynamicsWorld with Bullet's own solver, the planes are held inside Bullet's position
 * iterations (sdfccd_soft_hold(): friction kDF x the SDF body's friction), so a draped cloth comes to
 * rest. Otherwise each plane is a btSoftBody::RContact (kCHR, kKHR and kDF as in Bullet). A moving
 * SDF body is followed in its own frame (a kinematic body's start pose from its velocity). With
 * Config::query.method DCD (the discrete baseline) the nodes are checked at their predicted
 * positions only and the automatic guard is off.
 *
 * The guarantee, sdfccd_soft_guard(): no node or face point (rope: link point) ends a step deeper
 * than the tolerance past its time of impact; a node put back loses its velocity into the surface.
 * With Bullet's own (CPU) solver in a btSoftRigidDynamicsWorld it runs by itself after each
 * soft-body solve, in every internal step, with the rigid bodies' tolerance Config::guard_tolerance
 * (<= 0: off): the bridge wraps the world's solver (put back by
 * Bridge::unregister(); the world frees it otherwise). With other solvers, call
 * guardSoftBodies() after each stepSimulation with at most one internal step.
 *
 * Not covered: btDeformableMultiBodyDynamicsWorld, whose solver takes node and face contacts of
 * its own kind and ignores the RContacts the bridge writes, and does not use the soft-rigid world's
 * solver the guard wraps.
 */
#ifndef SDFCCD_BULLET_SOFT_BODY_H
#define SDFCCD_BULLET_SOFT_BODY_H

#include <cstdint>

#include "bridge.h"

class btSoftRigidDynamicsWorld;

SDFCCD_BULLET_NAMESPACE_BEGIN

/** Counters of the soft-body side of a bridge (since its construction). */
struct SoftBodyStats {
    int64_t pair_steps = 0;     /**< (soft body, SDF) pairs processed in collision detection. */
    int64_t node_contacts = 0;  /**< Contacts (RContacts or held planes) of nodes whose own path meets the SDF. */
    int64_t face_contacts = 0;  /**< Contacts of face points (one per node of the face). */
    int64_t face_queries = 0;   /**< sdfccd_query_triangle_linear calls (contacts and guard). */
    int64_t sdf_evaluations = 0;/**< SDF evaluations of all those queries and of the node checks. */
    int64_t guard_nodes = 0;    /**< Nodes the guard moved back to a time of impact. */
    int64_t query_errors = 0;   /**< Queries that failed (no contact written for that face). */
    int64_t refused = 0;        /**< Pairs refused: an SdfShape with a dead handle (reported as misuse). */
};

/** The soft-body counters of `bridge`. */
SoftBodyStats softBodyStats(const Bridge& bridge);

/** The soft-body guarantee (sdfccd_soft_guard(), see the file comment) for the step just taken by
 * `world`, over every soft body the bridge collided with an SDF in it, from its nodes' start
 * positions to their positions now. Returns 0 at once when the automatic guard already checked that
 * step. Returns the number of nodes moved, or -1 on bad input (NULL world, tolerance (m) not > 0,
 * bridge not registered with the world's dispatcher). */
int guardSoftBodies(Bridge& bridge, btSoftRigidDynamicsWorld* world, double tolerance = 5e-4);

SDFCCD_BULLET_NAMESPACE_END

#endif
