// SPDX-License-Identifier: MIT
/** @file bridge.h  Registers sdfccd's triangle-SDF continuous collision detection in Bullet.
 *
 * One collision algorithm handles GImpact meshes (alone or in a btCompoundShape), convex shapes and
 * other SdfShapes against SdfShape and btSdfCollisionShape, in both of Bullet's tables. Per pair and
 * step it writes the contact set (the start pose within the step's reach and the CCD's first time of
 * impact, reduced to the manifold's points) through Bullet's manifolds and callbacks; after each step
 * the guarantee puts a body that went into an SDF back at its time of impact (README, contact model).
 *
 * Manifold convention: body A = the mesh body, body B = the SDF body; the normal is grad phi (out
 * of the SDF); distance < 0 means penetration; m_index0 = the mesh's triangle. Known limits:
 * restitution at impact speed is lost; btGImpactCompoundShape falls back to GImpact's algorithm.
 */
#ifndef SDFCCD_BULLET_BRIDGE_H
#define SDFCCD_BULLET_BRIDGE_H

#include <cstddef>
#include <cstdint>
#include <string>

#include "sdfccd/sdfccd.h"
#include "config.h"
#include "sdf_shape.h"

class btCollisionShape;
class btCollisionWorld;
class btCollisionObject;

class btSdfCollisionShape;

SDFCCD_BULLET_NAMESPACE_BEGIN

/** Outcome of registration and verification. */
enum class Status {
    Ok = 0,
    AlreadyRegistered, /**< A bridge is already registered with the dispatcher. */
    TooLate,           /**< The world already holds GImpact or SDF bodies: register right after creating it. */
    Overwritten,       /**< Something replaced our algorithm after registration (e.g. GImpact's registerAlgorithm). */
    NotRegistered,     /**< No successful registerWith() yet. */
    InvalidArgument,   /**< A NULL or unsupported world or dispatcher, or a shape type id that is not concave. */
    InvalidShape       /**< An SdfShape wraps a null or destroyed sdfccd handle. */
};

/** Constant name of a status, e.g. "TooLate". */
const char* statusString(Status s);

/** A misuse report: the likely mistake, a sentence on what to do (valid during the call), the shape. */
typedef void (*MisuseHandler)(Status status, const char* message, const btCollisionShape* shape, void* user);

/** Sets the process-wide misuse handler and returns the previous one (NULL: the default, which
 * asserts in debug builds and does nothing otherwise). Called when Bullet's own GImpact algorithm
 * collides with an SdfShape, i.e. no working bridge handles the pair (Bridge::check says why). */
MisuseHandler setMisuseHandler(MisuseHandler handler, void* user = nullptr);

/** Size in bytes of the bridge's collision-algorithm object (it fits Bullet's algorithm pool). */
std::size_t collisionAlgorithmSize();

/** Options of a Bridge, fixed at construction. */
struct Config {
    /** Shape type id of SdfShape bodies (default 23, FAST_CONCAVE_MESH_PROXYTYPE). */
    int sdf_shape_type = kDefaultSdfShapeType;
    /** Also handle GImpact vs Bullet's btSdfCollisionShape (type 29). Default on. */
    bool handle_bt_sdf_shape = true;
    /** Features within this distance (m) of the SDF count as in contact. Default 0.01 m. */
    double contact_margin = 0.01;
    /** Contacts per pair and step in the pair's first manifold, 1..4 (cover points may add up to
     * three more manifolds). Default 4. */
    int max_contacts = 4;
    /** The guarantee's tolerance (m; <= 0: off; default 0.0005). After each step of a dynamics world,
     * a dynamic body whose executed motion went deeper than this into an SDF goes back along it to
     * its time of impact and loses its velocity into the surface. Off with query.method DCD. */
    double guard_tolerance = 0.0005;
    /** Handle convex shapes against SdfShape as triangles (a box's 12, others' btShapeHull).
     * Off: Bullet's convex-concave algorithm on the triangulation, no CCD. Default on. */
    bool convex_shapes = true;
    /** Threads for the contact sets of a step (1..256; default 1). With more, the first pair of a step
     * makes the sets of every pair in the world's pair cache (sdfccd_generate_contacts_batch; needs
     * registerWith(world); a callback SDF must then be thread-safe); each set is bitwise the one the
     * pair would make itself. */
    int batch_threads = 1;
    /** Query parameters (margin replaced by contact_margin): the library's defaults without FWGSS
     * restarts and the certified check (the discrete queries and the guarantee catch their misses). */
    sdfccd_QueryParams query;
    /** The defaults stated above. */
    Config() : query(sdfccd_default_query_params()) { query.fwgss_restarts = 0; query.fwgss_verify = 0; }
};

/** Counters for measurements (all since construction or resetStats()). */
struct Stats {
    int64_t queries = 0;               /**< CCD queries over the step (sdfccd_ContactSet::ccd_ran). */
    int64_t end_pose_queries = 0;      /**< Discrete queries (at the start pose over the step's reach, at the predicted end pose). */
    int64_t queries_skipped = 0;       /**< Pair-steps without a CCD query: nothing within reach (the start-pose query's
                                            broad phase proves no contact), or the step starts in contact. */
    int64_t sdf_evaluations = 0;       /**< SDF evaluations of the mesh queries and the face search (the library's count). */
    int64_t own_evaluations = 0;       /**< The other SDF evaluations of contact generation (closest points at the start of
                                            the step; sdfccd_ContactSet::own_evaluations). */
    int64_t candidates = 0;            /**< Contact candidates before the reduction to 4 points. */
    double query_seconds = 0;          /**< Wall time inside all those calls. */
    int64_t hits = 0;                  /**< Pair-steps with contact: CCD hits and steps that start in contact. */
    int64_t speculative_contacts = 0;  /**< Contacts written for impacts inside a step. */
    int64_t ordinary_contacts = 0;     /**< Contacts written for features in contact at step start. */
    int64_t query_errors = 0;          /**< Queries that failed or had no mesh/SDF to work with (no contacts written). */
    int64_t guard_queries = 0;         /**< Executed motions checked by the guarantee (one per body part and SDF). */
    int64_t rollbacks = 0;             /**< Bodies the guarantee put back at their time of impact. */
    int64_t face_regions = 0;          /**< Regions visited by the face search (SdfShape::setFeatureSize). */
    int64_t batched_queries = 0;       /**< Queries of contact sets taken from a step's batch (Config::batch_threads);
                                            they are counted in queries, end_pose_queries and sdf_evaluations too. */
    int64_t batches = 0;               /**< sdfccd_generate_contacts_batch calls (Config::batch_threads; one per step). */
    double last_toi_fraction = 1;      /**< Fraction of the last hit (1 when none). */
    int last_state = 0;                /**< sdfccd_ResultState of the last query. */
};

class BridgeImpl;
struct BridgeAccess;

/** The bridge: its create functions, packed meshes and SDF wrappers. The dispatcher points into
 * it, so create it before the world and destroy it after (or unregister() first). Not locked: one
 * bridge per world, and no two worlds sharing one stepped at once. */
class Bridge
{
public:
    /** A bridge with `config`, not yet registered. */
    explicit Bridge(const Config& config = Config());
    /** Frees the caches; never touches the dispatcher. */
    ~Bridge();
    Bridge(const Bridge&) = delete;
    Bridge& operator=(const Bridge&) = delete;

    /** Registers the bridge with the world's dispatcher (after GImpact's own registration, which it
     * calls) for every pair it handles, in both tables, then verifies it. TooLate when the world
     * already holds GImpact or SDF bodies or contact manifolds, AlreadyRegistered when a bridge is;
     * nothing changes then. */
    Status registerWith(btCollisionWorld* world);

    /** Ok when the dispatcher still creates our algorithm, Overwritten when something replaced
     * it, NotRegistered before registerWith(). Cheap. */
    Status verify() const;

    /** The first misuse found in `world` (NotRegistered, Overwritten, InvalidShape; else Ok), with
     * a sentence in `*message` if given. Call after adding bodies. */
    Status check(btCollisionWorld* world, std::string* message = nullptr) const;

    /** Restores the dispatcher's defaults (GImpact's registration too), removes the guarantee's
     * action and forgets the dispatcher. */
    void unregister();

    /** Time of impact, as a fraction of `dt` in [0, 1] (1: none), of `mesh_body` against
     * `sdf_body`, each moving from its world to its interpolation transform. */
    double timeOfImpact(const btCollisionObject* mesh_body, const btCollisionObject* sdf_body, double dt);

    /** Drops what the bridge keeps for `shape`: call after changing its vertices or before
     * deleting it. */
    void invalidateShape(const btCollisionShape* shape);

    /** The .cdf bytes `shape` was initialised from: the bridge (rigid and soft pairs) then evaluates
     * the field with sdfccd's grid of the same file instead of queryPoint. InvalidArgument, nothing
     * changed, when the bytes do not load or give another field. Call before stepping. */
    Status setBtSdfData(const btSdfCollisionShape* shape, const void* data, size_t size);

/** The configuration the bridge was made with. */
    const Config& config() const;
    /** The counters since construction or the last resetStats(). */
    Stats stats() const;
    /** Sets every counter of stats() back to its initial value. */
    void resetStats();

private:
    friend struct BridgeAccess;
    BridgeImpl* m_impl;
};

SDFCCD_BULLET_NAMESPACE_END

#endif
