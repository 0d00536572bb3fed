// SPDX-License-Identifier: MIT
/** @file bridge.h  Registers sdfccd's triangle-SDF continuous collision detection in Bullet.
 *
 * What it does (Bullet 3.24):
 *  - registers ONE collision algorithm, AFTER btGImpactCollisionAlgorithm::registerAlgorithm
 *    (which it calls itself), for these pairs in both body orders, in the contact-point and the
 *    closest-point tables (so contactTest/contactPairTest work):
 *      btGImpactMeshShape (top level or a child of a btCompoundShape) vs SdfShape, and vs
 *      Bullet's btSdfCollisionShape (type 29, sampled through queryPoint; Config::handle_bt_sdf_shape);
 *      any convex shape (btBoxShape, spheres, hulls...) vs SdfShape (Config::convex_shapes),
 *      as triangles: a box's 12, other shapes' btShapeHull hull;
 *      SdfShape vs SdfShape (Config::sdf_pairs): the moving one's isosurface triangulation
 *      against the other's field.
 *  - the contact model, per pair and step: the features within the step's reach at the start
 *    pose, the CCD's contact set at the first time of impact of the predicted motion (start pose
 *    = world transform, end pose = interpolation transform) and the features touching at the end
 *    pose, each written as a point held by its surface point and normal at the start of the step
 *    (a speculative contact with gap d > 0 lets the solver close at most d; restitution 0). The
 *    set is reduced to the manifold's 4 points (deepest, then the largest contact area), and cover
 *    points (sdfccd_cover_contacts) go into up to three more manifolds where the 4 leave the body
 *    free to turn into the surface. Points of the same material point as the last step's keep
 *    their warm-start impulses; Bullet's contact added, processed, started and ended callbacks
 *    fire as for its own manifolds.
 *  - Bridge::check(world) reports misuse (not registered, registered too late, overwritten,
 *    an SdfShape with a dead handle); while a world steps, Bullet's
 *    GImpact algorithm colliding with an SdfShape (the bridge not in charge) goes to the misuse
 *    handler, which asserts in debug builds (setMisuseHandler).
 *  - the guarantee (on by default, Config::guard_tolerance): after Bullet integrates a step, every
 *    dynamic body that can reach an SDF has its executed motion (start pose to the pose the solver
 *    produced) checked with the CCD; a body that went deeper than the tolerance is put back at its
 *    time of impact (see Config::guard_tolerance for its velocity).
 *
 * Manifold convention: body A = the mesh (or convex/moving SDF) body, body B = the SDF body; the
 * normal is grad phi (out of the SDF, towards the mesh); the point on B is on the surface;
 * distance < 0 means penetration; m_index0 = the triangle of the mesh (of the hull for convex
 * shapes), m_index1 = the SDF wrapper's index.
 *
 * Known limits: the speculative constraint is linear, so a body that rotates a lot in one step
 * can end slightly inside (the next step's contacts push it out); restitution at impact speed is
 * lost (the impact step only slows the body to gap/dt); Bullet's compound algorithm only gives a
 * child a pair when its box overlaps the SDF's box at the START of the step, so a compound child
 * faster than its own size per step can still pass through a thin SDF; GImpact compound shapes
 * (btGImpactCompoundShape) fall back to GImpact's own algorithm (which sees the SdfShape's
 * triangulation, without CCD).
 */
#ifndef SDFCCD_BULLET_BRIDGE_H
#define SDFCCD_BULLET_BRIDGE_H

#include <cstddef>
#include <cstdint>
#include <string>

#include "sdfccd/sdfccd.h"
#include "config.h"
#include "sdf_shape.h"

class btCollisionDispatcher;
class btCollisionShape;
class btCollisionWorld;
class btCollisionObject;
class btDiscreteDynamicsWorld;

class btSdfCollisionShape;

SDFCCD_BULLET_NAMESPACE_BEGIN

/** Outcome of registration and verification. */
enum class Status {
    Ok = 0,
    AlreadyRegistered, /**< This bridge, or another one, is already registered with the dispatcher. */
    TooLate,           /**< The world already holds GImpact or SDF bodies: their pairs may keep the
                            algorithm they were created with. Register right after creating the world. */
    Overwritten,       /**< verify(): the dispatcher no longer finds our algorithm for GImpact vs SDF,
                            e.g. btGImpactCollisionAlgorithm::registerAlgorithm was called after us. */
    NotRegistered,     /**< verify() before a successful registerWith(). */
    InvalidArgument,   /**< NULL world/dispatcher, a dispatcher that is not a btCollisionDispatcher,
                            or a shape type id that is not concave. */
    InvalidShape       /**< check(): an SdfShape in the world wraps a null or destroyed sdfccd handle. */
};

/** Constant name of a status, e.g. "TooLate". */
const char* statusString(Status s);

/** A misuse report: `status` is the likely mistake, `message` a sentence saying it and what to do
 * (valid during the call), `shape` the SdfShape that saw it, `user` what setMisuseHandler got. */
typedef void (*MisuseHandler)(Status status, const char* message, const btCollisionShape* shape, void* user);

/** Sets the process-wide handler of misuse the bridge notices while a world steps, and returns
 * the previous one. NULL restores the default, which asserts in debug builds of the bridge
 * library (NDEBUG not defined) and does nothing in release builds (the bridge never aborts
 * there). Tests and applications that want their own report (log, exception at their level,
 * counter) install theirs.
 *
 * What is noticed: Bullet's own GImpact algorithm asking a valid SdfShape for its triangles
 * (processAllTriangles from GImpact's callback). A registered, working bridge handles every
 * GImpact mesh against a valid SdfShape, so this means the world's bridge is not in charge of
 * the pair: the mesh collides with the shape's triangulation without CCD and can pass through.
 * It happens in the first step in which such a pair's boxes overlap, once per SdfShape and
 * diagnosis (a world registered too late is reported NotRegistered before the registration and
 * TooLate after it). `status`:
 *  NotRegistered  no bridge is registered in this process;
 *  Overwritten    a registered bridge's verify() fails (its create functions were replaced);
 *  TooLate        otherwise: the pair's algorithm predates the registration, or this world's
 *                 dispatcher has no bridge while another world's has.
 * Bridge::check(world) tells exactly which. Not noticed: convex shapes going through Bullet's
 * convex-concave algorithm (intended with Config::convex_shapes off), ray tests and sweeps
 * (they use the triangulation by design), and Bullet's btSdfCollisionShape (not ours). */
MisuseHandler setMisuseHandler(MisuseHandler handler, void* user = nullptr);

/** Size in bytes of the bridge's collision-algorithm object. It is taken from Bullet's
 * collision-algorithm pool when it fits the pool's element size (192 B in Debian's float and
 * float64 builds; a static_assert keeps it within that), and from btAlignedAlloc otherwise. */
std::size_t collisionAlgorithmSize();

/** Options of a Bridge, fixed at construction (defaults as stated per field). */
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
    /** Contacts written per pair and step into the pair's first manifold, 1..4 (a Bullet manifold
     * holds 4). Up to 12 more go into three further manifolds, where the first 4 leave the body free
     * to sink deeper than guard_tolerance by turning about them. Default 4. */
    int max_contacts = 4;
    /** The guarantee (m; <= 0: off). When the bridge is registered with a dynamics world
     * (registerWith(btCollisionWorld*)), an action it adds (run after Bullet integrates each step)
     * checks the executed motion of every dynamic body whose swept box meets an SDF's: from its
     * pose at the start of the step to the pose the solver produced (constant velocities, shortest
     * rotation), every compound child and convex shape as its triangles. If any point went deeper
     * than this below an SDF's surface (sdfccd_guard_step_rigid: a certificate, the CCD, a discrete
     * check of the pose it keeps), the body goes back along that motion to where it was within half of this (the paper's
     * rule: never advance past a time of impact). Its velocity: the first time, kept, for the next
     * step's contacts, which start at the time of impact and respond with every point and friction;
     * rolled back again in the next step, it loses its velocity into the surface (its centre's, then
     * an inelastic impulse with Coulomb friction at the contact point; the SDF body counts as
     * infinitely heavy). A body that starts a step deeper is left to the contacts. Bodies clear of
     * every SDF's box cost nothing. Off with query.method DCD (the discrete baseline). Default 0.0005. */
    double guard_tolerance = 0.0005;
    /** Handle convex shapes (box, sphere, capsule, hulls...) against SdfShape with the same
     * CCD (box: its 12 triangles; others: their btShapeHull). Off: Bullet's convex-concave
     * algorithm against the shape's triangulation (no CCD). Default on. */
    bool convex_shapes = true;
    /** Handle SdfShape vs SdfShape: the moving shape's triangulation (SdfShape::buildTriangulation)
     * against the other's field. Off: such pairs have no algorithm and pass through each other
     * (check() cannot see that; keep it on unless no two SDF bodies can meet). Default on. */
    bool sdf_pairs = true;
    /** Threads for the queries of a step (1..256; default 1: every query runs in the narrow phase,
     * pair by pair, on Bullet's thread). With more, the first pair of each step that the bridge
     * processes runs the queries of EVERY pair the world's broad phase holds for it (the start-pose
     * query, then the CCD queries, then the end-pose queries, each stage as one sdfccd_query_batch
     * on this many threads), and each pair then takes its results from there. The results are
     * bitwise those the pair would have computed itself, so the simulation is the same whatever the
     * count. Needs registerWith(btCollisionWorld*) (the pair cache is the world's). Not batched,
     * and queried in the narrow phase as before: compound children, pairs with the face search, a
     * btSdfCollisionShape, the DCD baseline (query.method DCD), closest-point queries. An SdfShape
     * made from a callback SDF is then evaluated from several threads at once: its callback must be
     * thread-safe (the library's built-in SDFs are). Stats::batched_queries counts the queries used
     * from a batch. */
    int batch_threads = 1;
    /** Query parameters passed to sdfccd_query_mesh (margin is replaced by contact_margin): the
     * library's defaults except fwgss_restarts (0): the bridge's discrete query over every
     * feature within the step's travel catches what a restart would correct; and fwgss_verify (0):
     * the certified check costs thousands of evaluations per resting triangle every step, and the
     * guarantee puts back what a late time of impact lets through. */
    sdfccd_QueryParams query;
    /** The defaults stated above. */
    Config() : query(sdfccd_default_query_params()) { query.fwgss_restarts = 0; query.fwgss_verify = 0; }
};

/** Counters for measurements (all since construction or resetStats()). */
struct Stats {
    int64_t queries = 0;               /**< CCD queries (sdfccd_query_mesh over the step) made by the algorithm. */
    int64_t end_pose_queries = 0;      /**< Discrete queries (at the start pose over the step's reach, at the predicted end pose). */
    int64_t queries_skipped = 0;       /**< CCD queries not run because the start-pose query settled them: nothing
                                            within reach (its broad phase proves no contact), or the step starts in
                                            contact (the CCD would report penetration at the start with the same features). */
    int64_t requeries = 0;             /**< Queries repeated because the contact buffer was too small. */
    int64_t sdf_evaluations = 0;       /**< SDF evaluations of all those queries (the library's count). */
    int64_t own_evaluations = 0;       /**< The bridge's own SDF evaluations (closest points at the start of the step). */
    int64_t candidates = 0;            /**< Contact candidates before the reduction to 4 points. */
    double query_seconds = 0;          /**< Wall time inside all those calls. */
    int64_t hits = 0;                  /**< Pair-steps with contact: CCD hits and steps that start in contact. */
    int64_t speculative_contacts = 0;  /**< Contacts written for impacts inside a step. */
    int64_t ordinary_contacts = 0;     /**< Contacts written for features in contact at step start. */
    int64_t query_errors = 0;          /**< Queries that failed or had no mesh/SDF to work with (no contacts written). */
    int64_t fallbacks = 0;             /**< Pairs handed back to Bullet's algorithm (GImpact compounds, dead SdfShapes). */
    int64_t guard_queries = 0;         /**< Executed motions checked by the guarantee (one per body part and SDF). */
    int64_t rollbacks = 0;             /**< Bodies the guarantee put back at their time of impact. */
    int64_t guard_skipped = 0;         /**< Checks the guarantee settled without a CCD: bodies that did not move,
                                            and motions sdfccd_guard_step_rigid's certificate proved clear. */
    int64_t face_regions = 0;          /**< Regions visited by the face search (SdfShape::setFeatureSize). */
    int64_t batched_queries = 0;       /**< Queries whose results came from a step's batch (Config::batch_threads);
                                            they are counted in queries, end_pose_queries and sdf_evaluations too. */
    int64_t batches = 0;               /**< sdfccd_query_batch calls (Config::batch_threads; up to 3 per step). */
    double last_toi_fraction = 1;      /**< Fraction of the last hit (1 when none). */
    int last_state = 0;                /**< sdfccd_ResultState of the last query. */
};

class BridgeImpl;
struct BridgeAccess;

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
    /** A bridge with `config` (not registered anywhere yet: see registerWith()). */
    explicit Bridge(const Config& config = Config());
    /** Frees the bridge's caches; never touches the dispatcher (see the class's lifetime note). */
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

    /** Checks how the bridge is used in `world` (call after adding bodies, e.g. before the first
     * step; a few microseconds per pair). Returns the first problem found, with a sentence in
     * `*message` if given:
     *  NotRegistered  this bridge is not registered with the world's dispatcher;
     *  Overwritten    something replaced our create functions after registerWith();
     *  InvalidShape   an SdfShape in the world has a null or destroyed sdfccd handle;
     *  TooLate        a mesh-SDF pair still has an algorithm created before registerWith();
     *  Ok             none of these (the message mentions failed queries, if any). */
    Status check(btCollisionWorld* world, std::string* message = nullptr) const;

    /** Restores the dispatcher's slots to the collision configuration's defaults (note: this also
     * drops GImpact's registration for those pairs), removes the guarantee's action
     * from the world and forgets the dispatcher. */
    void unregister();


    /** Time of impact of `mesh_body` moving from its world transform to its interpolation
     * transform, against `sdf_body` (likewise) over `dt` seconds, as a fraction in [0, 1]
     * (1 when there is no contact). The algorithm's calculateTimeOfImpact returns the same. */
    double timeOfImpact(const btCollisionObject* mesh_body, const btCollisionObject* sdf_body, double dt);

    /** Drops the packed copy of a GImpact mesh shape: call after changing its vertices, or
     * before deleting the shape if another shape may be created at the same address. */
    void invalidateShape(const btCollisionShape* shape);

    /** The .cdf bytes `shape` was initialised from (btSdfCollisionShape::initializeSDF): the bridge then
     * evaluates the shape's field with sdfccd's grid evaluator of the same file (the same interpolant,
     * several times faster than queryPoint, with per-cell gradient bounds for its culling) instead of
     * sampling queryPoint. InvalidArgument (nothing changes) when sdfccd cannot load the bytes or their
     * field differs from the shape's at sample points (other bytes). Call before stepping; the shape
     * keeps the grid until invalidateShape(shape). */
    Status setBtSdfData(const btSdfCollisionShape* shape, const void* data, size_t size);

    /** The configuration the bridge was made with. */
    const Config& config() const;
    /** The counters since construction or the last resetStats(). */
    Stats stats() const;
    /** Sets every counter of stats() back to its initial value. */
    void resetStats();

private:
    friend struct BridgeAccess; // the bridge's own sources reach the implementation through it
    BridgeImpl* m_impl;
};

SDFCCD_BULLET_NAMESPACE_END

#endif
