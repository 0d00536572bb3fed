// SPDX-License-Identifier: MIT
/** @file bridge.h  Registers sdfccd's triangle-SDF continuous collision detection in Bullet.
 *
 * What it does (Bullet 3.24; see notes/bullet-integration.md for the reasons):
 *  - registers a collision algorithm for btGImpactMeshShape against SdfShape (both body orders)
 *    and, optionally, against Bullet's own btSdfCollisionShape (type 29, sampled through
 *    queryPoint), AFTER btGImpactCollisionAlgorithm::registerAlgorithm, which it calls itself;
 *  - registers the same pairs in the closest-points table, so contactTest/contactPairTest work;
 *  - per step and pair: takes the mesh's start pose (world transform) and predicted end pose
 *    (interpolation transform), the SDF body's likewise (static: fixed; kinematic: rebuilt
 *    backwards from its velocities), runs ONE CCD sdfccd_query_mesh over [0, dt] (plus, in a
 *    step with an impact, one discrete query at the predicted end pose), and writes at
 *    most four well-spread contacts straight into the pair's manifold. Each contact's distance
 *    is the gap at the start of the step along the contact normal, so the solver lets the mesh
 *    travel exactly to the surface in the impact step. Contacts of an impact inside the step
 *    are speculative (restitution 0); contacts of features already within the contact margin
 *    at the start of the step are ordinary ones (restitution from Bullet's callback).
 *  - optional hard clamp (off by default), see setHardClamp().
 *
 * Manifold convention: body A = the mesh, body B = the SDF; the normal is grad phi (pointing
 * out of the SDF, towards the mesh); the point on B is on the surface; distance < 0 means
 * penetration. Points are written directly, so gContactAddedCallback/gContactStartedCallback
 * are not called for them.
 *
 * Known limits: the speculative constraint is linear, so a body that rotates a lot in one step
 * can end slightly inside (the next step's ordinary contacts push it out; the hard clamp
 * prevents it); restitution at impact speed is lost (the impact step only slows the body to
 * gap/dt); GImpact compound shapes fall back to GImpact's own algorithm (which sees the
 * SdfShape's triangulation, without CCD).
 */
#ifndef SDFCCD_BULLET_BRIDGE_H
#define SDFCCD_BULLET_BRIDGE_H

#include <cstddef>
#include <cstdint>

#include "sdfccd/sdfccd.h"
#include "config.h"
#include "sdf_shape.h"

class btCollisionDispatcher;
class btCollisionWorld;
class btCollisionObject;
class btDiscreteDynamicsWorld;

SDFCCD_BULLET_NAMESPACE_BEGIN

/** Outcome of registration and verification. */
enum class Status {
    Ok = 0,
    AlreadyRegistered, /**< This bridge, or another one, is already registered with the dispatcher. */
    TooLate,           /**< The world already holds GImpact or SDF bodies: their pairs may keep the
                            algorithm they were created with. Register right after creating the world. */
    Overwritten,       /**< verify(): the dispatcher no longer finds our algorithm for GImpact vs SDF,
                            e.g. btGImpactCollisionAlgorithm::registerAlgorithm was called after us. */
    NotRegistered,     /**< verify()/setHardClamp() before a successful registerWith(). */
    InvalidArgument    /**< NULL world/dispatcher, a dispatcher that is not a btCollisionDispatcher,
                            a shape type id that is not concave, or setHardClamp() without a
                            btDiscreteDynamicsWorld. */
};

/** Constant name of a status, e.g. "TooLate". */
const char* statusString(Status s);

/** Size in bytes of the bridge's collision-algorithm object. It is taken from Bullet's
 * collision-algorithm pool when it fits the pool's element size (192 B in Debian's float and
 * float64 builds; a static_assert keeps it within that), and from btAlignedAlloc otherwise. */
std::size_t collisionAlgorithmSize();

struct Config {
    /** Shape type id of SdfShape bodies (default 23, FAST_CONCAVE_MESH_PROXYTYPE). */
    int sdf_shape_type = kDefaultSdfShapeType;
    /** Also handle GImpact vs Bullet's btSdfCollisionShape (type 29). Default on. */
    bool handle_bt_sdf_shape = true;
    /** Register the closest-points table too (contactTest, contactPairTest). Default on. */
    bool closest_points = true;
    /** Features within this distance (m) of the SDF count as in contact (the query's margin).
     * Default 0.01 m. Resting bodies hover at distance 0; the margin keeps their contacts alive. */
    double contact_margin = 0.01;
    /** Contacts written per pair and step, 1..4 (the manifold holds 4). Default 4. */
    int max_contacts = 4;
    /** Query parameters passed to sdfccd_query_mesh (margin is replaced by contact_margin).
     * The library's defaults. Keep subdivision on: a long triangle lying across two separate
     * contact regions (a bar across a torus's ring) has only one primary contact, and
     * subdivision finds the other (without it that test scene falls through). It is also the
     * main cost: 180 instead of 40 us per step in the 200 m/s cube scene. */
    sdfccd_QueryParams query;
    Config() : query(sdfccd_default_query_params()) {}
};

/** Counters for measurements (all since construction or resetStats()). */
struct Stats {
    int64_t queries = 0;               /**< CCD queries (sdfccd_query_mesh over the step) made by the algorithm. */
    int64_t end_pose_queries = 0;      /**< Discrete queries at the predicted end pose (impact steps only). */
    double query_seconds = 0;          /**< Wall time inside all those calls. */
    int64_t hits = 0;                  /**< Queries that found contact (hit). */
    int64_t speculative_contacts = 0;  /**< Contacts written for impacts inside a step. */
    int64_t ordinary_contacts = 0;     /**< Contacts written for features in contact at step start. */
    int64_t query_errors = 0;          /**< Queries that returned an error status (no contacts written). */
    int64_t fallbacks = 0;             /**< Pairs handed to GImpact's algorithm (unsupported shapes). */
    int64_t clamps = 0;                /**< Hard-clamp corrections. */
    double last_toi_fraction = 1;      /**< Fraction of the last hit (1 when none). */
    int last_state = 0;                /**< sdfccd_ResultState of the last query. */
};

class BridgeImpl;

/** The bridge: owns the create functions Bullet's dispatcher points to, the packed copies of
 * GImpact meshes, and the SDF wrappers of btSdfCollisionShape objects.
 *
 * Lifetime: the dispatcher keeps pointers into the bridge, so the bridge must outlive every use
 * of the dispatcher (create it before the world and destroy it after), or call unregister()
 * while the dispatcher still exists. The destructor never touches the dispatcher.
 *
 * Threads: the bridge's caches and counters are not locked. Bullet's narrow phase runs on one
 * thread in the Debian builds (no BT_THREADSAFE); with a multithreaded dispatcher, use one
 * bridge per world and do not step worlds that share a bridge concurrently. */
class Bridge
{
public:
    explicit Bridge(const Config& config = Config());
    ~Bridge();
    Bridge(const Bridge&) = delete;
    Bridge& operator=(const Bridge&) = delete;

    /** THE registration call. Calls btGImpactCollisionAlgorithm::registerAlgorithm on the world's
     * dispatcher, then registers our algorithm for (GImpact, SDF) and (SDF, GImpact), for the
     * SdfShape type id and (if enabled) type 29, in the contact-point and closest-point tables,
     * then verifies that the dispatcher finds it. Must be called before any GImpact or SDF body is
     * added (otherwise TooLate and nothing is changed). Calling it twice, or with a dispatcher
     * another bridge uses, gives AlreadyRegistered and changes nothing. */
    Status registerWith(btCollisionWorld* world);
    /** The same for a bare dispatcher (e.g. a collision-only setup). It cannot see bodies, so
     * "too late" is only detected when the dispatcher already holds manifolds. */
    Status registerWith(btCollisionDispatcher* dispatcher);

    /** Probes the dispatcher: Ok when both body orders (and both tables) still create our
     * algorithm; Overwritten when something replaced it (the wrong registration order);
     * NotRegistered before registerWith(). Cheap; safe to call at any time. */
    Status verify() const;

    /** Restores the dispatcher's slots to the collision configuration's defaults (note: this also
     * drops GImpact's registration for those pairs) and forgets the dispatcher. */
    void unregister();

    /** Optional hard clamp (off by default). With it on, internal pre- and post-tick callbacks
     * of `world` save each GImpact body's start pose and, after integration, move a mesh that
     * ends a step inside an SDF by more than `tolerance` (m) back to its time of impact and
     * remove its velocity into the surface. It uses the world's single tick-callback slot pair
     * and world user info (it fails with InvalidArgument if a callback is already installed);
     * off restores them to none. Costs one extra query per mesh-SDF pair and step. */
    Status setHardClamp(btDiscreteDynamicsWorld* world, bool on, double tolerance = 1e-3);
    bool hardClampEnabled() const;

    /** Time of impact of `mesh_body` moving from its world transform to its interpolation
     * transform, against `sdf_body` (likewise) over `dt` seconds, as a fraction in [0, 1]
     * (1 when there is no contact). The algorithm's calculateTimeOfImpact returns the same. */
    double timeOfImpact(const btCollisionObject* mesh_body, const btCollisionObject* sdf_body, double dt);

    /** Drops the packed copy of a GImpact mesh shape: call after changing its vertices, or
     * before deleting the shape if another shape may be created at the same address. */
    void invalidateShape(const btCollisionShape* shape);

    const Config& config() const;
    Stats stats() const;
    void resetStats();

    BridgeImpl* impl() { return m_impl; }

private:
    BridgeImpl* m_impl;
};

SDFCCD_BULLET_NAMESPACE_END

#endif
