// SPDX-License-Identifier: MIT
/** @file bridge.h  Registers sdfccd's triangle-SDF continuous collision detection in Bullet.
 *
 * What it does (Bullet 3.24; see notes/bullet-integration.md for the reasons):
 *  - registers ONE collision algorithm, AFTER btGImpactCollisionAlgorithm::registerAlgorithm
 *    (which it calls itself), for these pairs in both body orders, in the contact-point and the
 *    closest-point tables (so contactTest/contactPairTest work):
 *      btGImpactMeshShape (top level or a child of a btCompoundShape) vs SdfShape, and vs
 *      Bullet's btSdfCollisionShape (type 29, sampled through queryPoint; Config::handle_bt_sdf_shape);
 *      any convex shape (btBoxShape, spheres, hulls...) vs SdfShape (Config::convex_shapes),
 *      as triangles: a box's 12, other shapes' btShapeHull hull;
 *      SdfShape vs SdfShape (Config::sdf_pairs): the moving one's isosurface triangulation
 *      against the other's field.
 *  - the contact model, per pair and step (contact_policy.cpp):
 *      1. a discrete query at the start pose (world transform) with the margin widened by the
 *         step's travel finds every feature that can reach the surface in the step; when its
 *         broad phase culls every triangle the step has no contact and nothing else runs;
 *      2. unless a feature is already within the margin (the step STARTS in contact), one CCD
 *         query (sdfccd_query_mesh) over the step from the start pose to the predicted end pose
 *         (interpolation transform); its whole contact set at the earliest time of impact is
 *         kept (every triangle in the library's TOI window, with subdivision contacts), plus
 *         those triangles' vertices within Config::vertex_distance; no hit, no contact;
 *      2b. whenever the step has any contact, also when it starts in contact, the start-pose
 *         features and those of a discrete query at the predicted end pose; each feature found
 *         is constrained by its own closest surface point at the start of the step
 *         (speculative contacts for the rest of the motion: resting, sliding and tipping over an
 *         edge cannot sink, and a fast body is held by its whole front, not one point);
 *         with Config::query.method DCD (the discrete baseline) step 2 always runs, first;
 *      3. every candidate is expressed at the start of the step (distance = gap along the normal,
 *         negative when penetrating) and the set is reduced to the manifold's 4 points: the
 *         deepest, then the points that maximise the contact polygon's area (as Bullet's
 *         sortCachedPoints and Box2D do), deterministically and never two at one place;
 *      4. points carry over the last step's warm-start impulses when they are the same material
 *         point, and the contact added (CF_CUSTOM_MATERIAL_CALLBACK), processed, started and
 *         ended callbacks fire as for Bullet's own manifolds.
 *    A point with gap d > 0 lets the solver close at most d in the step, so the mesh stops on
 *    the surface in its impact step; such speculative points have restitution 0.
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
    /** Contacts written per pair and step, 1..4 (the manifold holds 4). Default 4. */
    int max_contacts = 4;
    /** The vertices of a triangle in contact that are within this distance (m) of the surface at
     * the triangle's time of impact are contact candidates too (a face landing flat gives its
     * corners). Default 0.02 m. */
    double vertex_distance = 0.02;
    /** The reduction to 4 points weighs a candidate's spread (distance, area) by
     * exp(-(its gap - the deepest gap) / scale): points about to touch are preferred to features
     * that might only reach the surface late in the step. The scale is the smaller of this
     * (default 0.3 m) and spread_depth_fraction times the mesh's radius. */
    double spread_depth_scale = 0.3;
    /** The reduction's depth scale relative to the mesh's radius (the largest distance of a vertex
     * from the mesh's origin); <= 0: spread_depth_scale alone. Default 0.1: for a body a few
     * centimetres across, a fixed 0.3 m scale lets features millimetres above the surface win the
     * manifold by their larger spread (a 9 cm torus lying flat held its outer rim 4-6 mm up
     * instead of its bottom ring in contact, stood on one point and wobbled like Euler's disk). */
    double spread_depth_fraction = 0.1;
    /** Extra manifolds per pair (0..3), for up to 4 more points each. The first 4 points (the
     * deepest and the points spreading the contact polygon) span the whole candidate set, far
     * speculative points included, so a body tipping flat can have ONE point in its contact patch,
     * pivot about it and sink the rest of the patch. The extra points go where the held points
     * still leave the body free to sink: the candidate that could end deepest, for any rotation
     * about an axis in the contact plane up to the body's angular speed (relative to the SDF) plus
     * kick_angular_speed, while every held point ends out of the surface, is held next, until no
     * candidate could end deeper than cover_depth (see contact_policy.cpp). Default 3. */
    int extra_manifolds = 3;
    /** Angular speed (rad/s) a body may gain within a step from contacts solved with it (another
     * body landing on it, a mesh-mesh pair) on top of its own. It widens the extra points' bound
     * and the start-pose query's reach (kick_angular_speed x the mesh's radius x dt), and that
     * query then also runs in steps whose predicted motion has no contact. Default 0: with the
     * end-of-step projection it changes no penetration figure of the Bullet re-creations, and
     * 1 rad/s costs the landscape scene about 30% more per step (more queries and candidates);
     * it lets piles settle sooner (gimpact-demo: rest speed over the last second 0.06 -> 0 m/s). */
    double kick_angular_speed = 0.0;
    /** Depth (m) a candidate may reach, under that bound, without being held. Default 0.002. */
    double cover_depth = 0.002;
    /** Opt-in (negative: off, the default): the older rule for the extra points, used instead of
     * the one above: ONE extra manifold with up to 4 points spread over the candidates within
     * this distance (m) of the deepest gap that the first 4 points leave out (the contact patch
     * around the deepest point). The paper's rigid scenes (samples/scenes) use 0.02. */
    double patch_band = -1;
    /** Opt-in (<= 0: off, the default): the face search. With subdivision on, the mesh's triangles
     * with an edge longer than this (m) are also searched region by region (split at the edge
     * midpoints down to regions with no edge longer than it; regions the SDF's Lipschitz bound
     * shows out of reach are dropped; each leaf's deepest point from the library's DCD), at the
     * start pose over the step's reach (the DCD baseline: at the end pose within the margin).
     * The library's queries give one point per triangle and subdivide only around a point in
     * contact, so a face over SDF features smaller than itself (a coarse box on a spike grid)
     * can have its vertices and those points clear while features between them pierce it.
     * Cost: about (edge / size)^2 regions per triangle lying within the reach of a surface (a
     * face flat on the ground is never dropped), so only for scenes that need it: the paper's
     * spikes scene uses 0.02. Stats::face_regions counts the regions visited. */
    double face_search_size = 0;
    /** In the discrete queries (start and end pose), adaptive subdivision does not split regions
     * smaller than (discrete_subdivision_scale x the mesh's radius)^2: such regions' points lie
     * within about that distance of the triangle's vertices, which are contact candidates
     * already. Large triangles (a bar's face across a torus's two tube tops) still give their
     * interior contacts. Cuts the landscape's SDF evaluations per step by 2.5x (its 1,002-triangle
     * tori are no longer subdivided) with the same penetration; the CCD query keeps the library's
     * subdivision. 0: the library's subdivision_min_area everywhere. Default 0.1. */
    double discrete_subdivision_scale = 0.1;
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
     * feature within the step's travel catches what a restart would correct, for about 20% fewer
     * SDF evaluations per query (landscape scene). */
    sdfccd_QueryParams query;
    /** The defaults stated above. */
    Config() : query(sdfccd_default_query_params()) { query.fwgss_restarts = 0; }
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
    int64_t guard_bisections = 0;      /**< Unused since the guarantee's discrete check moved into the core (0). */
    int64_t face_regions = 0;          /**< Regions visited by the face search (Config::face_search_size). */
    int64_t batched_queries = 0;       /**< Queries whose results came from a step's batch (Config::batch_threads);
                                            they are counted in queries, end_pose_queries and sdf_evaluations too. */
    int64_t batches = 0;               /**< sdfccd_query_batch calls (Config::batch_threads; up to 3 per step). */
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

    /** The configuration the bridge was made with. */
    const Config& config() const;
    /** The counters since construction or the last resetStats(). */
    Stats stats() const;
    /** Sets every counter of stats() back to its initial value. */
    void resetStats();

    /** The implementation object (internal: for the bridge's own algorithm and tests; its type
     * is not part of the installed headers). */
    BridgeImpl* impl() { return m_impl; }

private:
    BridgeImpl* m_impl;
};

SDFCCD_BULLET_NAMESPACE_END

#endif
