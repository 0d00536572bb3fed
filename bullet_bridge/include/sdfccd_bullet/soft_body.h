// SPDX-License-Identifier: MIT
/** @file soft_body.h  Bullet soft bodies (btSoftBody: cloth, ropes, volumetric bodies) against SDFs.
 *
 * Bridge::registerWith() also registers the bridge for (btSoftBody, SdfShape) and (btSoftBody,
 * btSdfCollisionShape) in both body orders (world: btSoftRigidDynamicsWorld with
 * btSoftBodyRigidBodyCollisionConfiguration). Each step, in Bullet's collision detection, the soft
 * body's nodes move linearly from their positions at the start of the step (btSoftBody::Node::m_q)
 * to the positions the solver predicts (m_x): every node's path is checked with the CCD against
 * the SDF within the soft body's collision margin plus Config::contact_margin (its contact plane at
 * that margin), every face's per-vertex linear motion (sdfccd_query_triangle_linear) for a point
 * coming 0.7 of the way into that margin (each of its face's nodes gets a plane shifted by its offset
 * from the point, so that the face point cannot pass while the nodes hold theirs). The normal is the
 * SDF gradient at the contact. Against a static or kinematic SDF body in a btSoftRigidDynamicsWorld
 * with Bullet's own solver, the planes are held inside Bullet's position iterations like its links
 * (a node below its plane goes onto it, one above it is free; Coulomb friction with kDF x the SDF
 * body's friction), so a draped cloth comes to rest; Bullet's soft RContact (kKHR) let the cloth's
 * weight pull nodes through and pulled nodes above their plane down toward it. Against a dynamic SDF
 * body, or under another solver, each contact is a btSoftBody::RContact (kCHR, kKHR and kDF as in
 * Bullet). A moving SDF body: the guard checks the nodes' motion
 * relative to it, from their positions in its frame at the start of the step (a kinematic body's
 * pose there from its velocity) to their positions in its frame at the end, linearly in its frame.
 * Tested with a kinematic body (moving_sdf) and a dynamic one (dynamic_sdf).
 * With Config::query.method DCD (the discrete baseline) the nodes are checked at their predicted
 * positions only and the automatic guard is off.
 * Not covered: btDeformableMultiBodyDynamicsWorld. Its solver takes node and face contacts of
 * another kind (btSoftBody::m_nodeRigidContacts and m_faceRigidContacts, with their own Jacobians,
 * solved in its implicit velocity solve) and ignores the RContacts the bridge writes; the guard
 * wraps the soft-rigid world's btSoftBodySolver, which that world does not use. Not attempted.
 *
 * Cost: a node or face whose SDF distance is certified (a lower bound by the Lipschitz bound over
 * the face, split into pieces) beyond what its motion can close skips the CCD; the certificate is
 * kept while its nodes stay near where it was made, so a resting cloth costs about one SDF
 * evaluation per node and step.
 *
 * The guarantee: a node or face point that ended a step deeper than the tolerance goes back along
 * its motion to its time of impact, and the nodes lose their velocity into the surface there. In a
 * body without faces (a rope) the points along each link are held too. When
 * the bridge is registered with a btSoftRigidDynamicsWorld using Bullet's own (CPU) soft-body
 * solver, it runs by itself right after each soft-body solve, in every internal step: the bridge
 * wraps the world's solver (Bullet's soft-rigid world offers no callback after that solve; the
 * wrapper is put back by Bridge::unregister(), and the world frees it otherwise). Other solvers, or
 * a world registered as a bare dispatcher: call guardSoftBodies() after each stepSimulation with at
 * most one internal step.
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
    int64_t held_nodes = 0;     /**< Nodes a held plane moved in the solve's last pass (per plane and step). */
};

/** The soft-body counters of `bridge`. */
SoftBodyStats softBodyStats(const Bridge& bridge);

/** Turns the automatic guard (see the file comment) on or off and sets its tolerance (m, > 0;
 * default on, 5e-4). Returns true when the automatic guard is installed in a world (false: bad
 * tolerance, bridge never registered, or no btSoftRigidDynamicsWorld with Bullet's solver). */
bool setSoftBodyGuard(Bridge& bridge, bool on, double tolerance = 5e-4);

/** The soft-body guarantee for the step just taken by `world` (see the file comment). Returns 0
 * at once when the automatic guard already checked that step. Checks the
 * motion of every soft body the bridge collided with an SDF in that step, from its nodes'
 * positions at the start of the step to their positions now: a node whose path went deeper than
 * `tolerance` (m, > 0) below the surface, or a face whose motion took a point of it that deep, is
 * put back at the first time it reached that depth (a face: its three nodes), and its nodes'
 * velocity into the surface is removed. Repeats over the faces whose nodes moved until no face
 * crosses (at most a few passes; then the nodes of a face still crossing go back to their start
 * positions, where the last check left them). Nodes and faces already deeper at the start may not
 * end deeper than they started (a face that does goes back to its start). Returns the number of nodes moved, or -1 on bad input (NULL
 * world, tolerance not > 0, bridge not registered with the world's dispatcher). */
int guardSoftBodies(Bridge& bridge, btSoftRigidDynamicsWorld* world, double tolerance = 5e-4);

SDFCCD_BULLET_NAMESPACE_END

#endif
