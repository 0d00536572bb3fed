// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge, internal: what the bridge's source files share.
//   shape_cache.cpp    Bullet shapes -> sdfccd meshes (GImpact, convex hulls, SDF triangulations)
//                      and SDF handles (SdfShape, btSdfCollisionShape)
//   contact_policy.cpp the queries of one pair and step, the contact set, its reduction to the
//                      manifolds' points, and writing them with Bullet's callbacks
//   algorithm.cpp      the collision algorithm, its create functions, registration, check()
//   guard.cpp          the guarantee: an action checks each body's executed motion after the step
//                      and puts a body that went into an SDF back at its time of impact
#ifndef SDFCCD_BULLET_INTERNAL_H
#define SDFCCD_BULLET_INTERNAL_H

#include <memory>
#include <unordered_map>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/Dynamics/btActionInterface.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionShapes/btSdfCollisionShape.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <LinearMath/btTransformUtil.h>

#include "sdfccd_bullet/bridge.h"

SDFCCD_BULLET_NAMESPACE_BEGIN
namespace detail {

const sdfccd_SdfId kNullSdf = { 0, 0 };

inline sdfccd_Vec3 v3(const btVector3& v)
{
    sdfccd_Vec3 r = { (double)v.x(), (double)v.y(), (double)v.z() };
    return r;
}
inline btVector3 bt(const sdfccd_Vec3& v) { return btVector3((btScalar)v.x, (btScalar)v.y, (btScalar)v.z); }
sdfccd_Pose toPose(const btTransform& t);
// A top-level object as Bullet's dispatcher sees it (its own shape at its world transform).
struct ObjectWrapper : btCollisionObjectWrapper {
    explicit ObjectWrapper(const btCollisionObject* o) : btCollisionObjectWrapper(nullptr, o->getCollisionShape(), o, o->getWorldTransform(), -1, -1) {}
};

// Start and end pose of a body (or compound child) over a step, and the constant velocities that
// connect them in Bullet's motion model (origin lerp + exponential-map rotation), sdfccd's too.
struct BodyMotion {
    btTransform t0, t1;
    btVector3 v, w;
    sdfccd_RigidMotion rigid() const;
    btTransform at(double t) const;
};
// `wrapper_transform` is the wrapper's world transform (a compound child's includes its offset).
BodyMotion motionOf(const btCollisionObject* co, const btTransform& wrapper_transform, double dt);

// A shape packed as a triangle mesh for sdfccd (scaled, in the shape's local frame).
struct MeshEntry {
    sdfccd_MeshId id = { 0, 0 };
    btVector3 scaling;
    btScalar margin = 0;
    int source_count = 0;
    double radius = 0; // largest vertex distance from the local origin
    std::vector<double> vertices;
    std::vector<uint32_t> indices;
    bool ok = false;
};

// Packed meshes and SDF handles per Bullet shape (keyed by address; see Bridge::invalidateShape).
class ShapeCache
{
public:
    ~ShapeCache();
    /** The shape as a triangle mesh: GImpact meshes and parts, convex shapes (box corners, other
     * convex shapes through btShapeHull), SdfShape (its isosurface triangulation). NULL otherwise. */
    const MeshEntry* meshFor(const btCollisionShape* shape);
    /** The SDF handle of an SdfShape (with its scaling) or of a btSdfCollisionShape. Null otherwise. */
    sdfccd_SdfId sdfFor(const btCollisionShape* shape, int sdf_shape_type, bool bt_sdf);
    /** Bridge::setBtSdfData: the shape's field from sdfccd's grid of its .cdf bytes. */
    bool setBtSdfData(const btSdfCollisionShape* shape, const void* data, size_t size);
    void invalidate(const btCollisionShape* shape);

private:
    sdfccd_SdfId btSdfFor(const btSdfCollisionShape* shape);
    std::unordered_map<const btCollisionShape*, MeshEntry> m_meshes;
    // A btSdfCollisionShape's field: its grid (setBtSdfData), else queryPoint (sdfccd_create_sampled_sdf).
    std::unordered_map<const btCollisionShape*, sdfccd_SdfId> m_bt_sdfs;
};

// One contact candidate, in the frames at the START of the step.
struct Candidate {
    btVector3 local;  // material point in the mesh's (wrapper's) frame
    btVector3 pA0;    // that point at step start (world)
    btVector3 pB0;    // the SDF surface point it is constrained by (world, at step start)
    btVector3 n0;     // normal at step start (world, out of the SDF)
    double d;         // gap at step start along n0 (negative: penetrating)
    int triangle;
    bool speculative; // from an impact later in the step (restitution 0)
};

// Storage the contact policy reuses from pair to pair and step to step (no allocation once grown).
struct PairScratch {
    std::vector<std::pair<uint32_t, double>> tris; // triangles of the CCD's contacts and their TOI
    std::vector<uint32_t> pose_tris;              // triangles of a discrete query's contacts
    std::vector<std::pair<uint32_t, uint32_t>> pose_vertices;                 // (vertex, triangle)
    std::vector<std::pair<uint32_t, std::pair<double, uint32_t>>> toi_vertices; // (vertex, (TOI, triangle))
    std::vector<sdfccd_ContactPoint> face_points;  // the face search's points
    std::vector<btManifoldPoint> old_points, new_points; // a pair's manifold points, last step and this one
    std::vector<char> matched;                    // old points that persist
};

// The inputs of one pair's queries in a step: gather() and the batch prefetch build them alike.
struct PairPlan {
    const MeshEntry* me = nullptr;
    sdfccd_SdfId sdf = kNullSdf;
    BodyMotion M, S;            // in the SDF's frame when static_sdf
    bool static_sdf = false;
    btTransform sdf_world;      // the SDF's world pose (static_sdf)
    sdfccd_RigidMotion mm, sm_value;
    sdfccd_QueryParams params;  // Config::query with the pair's margin
    bool continuous = true;     // not the DCD baseline
    double margin = 0, start_margin = 0, travel = 0, feature_size = 0;
    const sdfccd_RigidMotion* sm() const { return static_sdf ? nullptr : &sm_value; }
};

// One query's arguments, compared byte for byte with those of a batched query.
struct QueryInput {
    sdfccd_SdfId sdf;
    sdfccd_MeshId mesh;
    int has_sdf_motion;
    sdfccd_RigidMotion sdf_motion, motion;
    double t1;
    sdfccd_QueryParams params;
};
QueryInput queryInput(sdfccd_SdfId sdf, sdfccd_MeshId mesh, const sdfccd_RigidMotion* sm, const sdfccd_RigidMotion& m, double t1,
                      const sdfccd_QueryParams& p);

// The stages of a pair's queries in a step, in their order.
enum QueryStage { kStageStart = 0, kStageCcd = 1, kStageEnd = 2 };

// A query run ahead in a step's batch (Config::batch_threads), keyed by its pair and stage.
struct CachedQuery {
    QueryInput in;
    sdfccd_Status status = SDFCCD_OK;
    sdfccd_QueryResult result;
    std::vector<sdfccd_Contact> contacts; // capacity given to the query
};
struct PairStageKey {
    const btCollisionObject* mesh;
    const btCollisionObject* sdf;
    int stage;
    bool operator==(const PairStageKey& o) const { return mesh == o.mesh && sdf == o.sdf && stage == o.stage; }
};
struct PairStageHash {
    size_t operator()(const PairStageKey& k) const
    {
        return std::hash<const void*>()(k.mesh) * 31u + std::hash<const void*>()(k.sdf) * 7u + (size_t)k.stage;
    }
};

class MeshSdfAlgorithm;

/** True when `callback` is Bullet's GImpact algorithm's triangle callback (btGImpactTriangleCallback). */
bool isGImpactCallback(const btTriangleCallback* callback);
/** Diagnoses Bullet's GImpact algorithm colliding with `shape` and reports it through the misuse
 * handler unless the diagnosis equals the last one reported for the shape (`last_reported`:
 * 0 = none, else the Status + 1; updated). */
void reportGImpactMisuse(const btCollisionShape* shape, int& last_reported);
// The guarantee's action (Config::guard_tolerance): added to a dynamics world at registration,
// removed by unregister().
void guardAttach(BridgeImpl* impl, btCollisionWorld* world);
void guardDetach(BridgeImpl* impl);
// soft_body.cpp: the (btSoftBody, SDF) pairs, registered and restored with the rigid ones.
void softRegister(BridgeImpl* impl, btCollisionDispatcher* d);
void softAttach(BridgeImpl* impl, btCollisionWorld* world);
void softUnregister(BridgeImpl* impl);
void softForget(BridgeImpl* impl);
// Calls the handler of setMisuseHandler (or the default one).
void callMisuseHandler(Status status, const char* message, const btCollisionShape* shape);

} // namespace detail

class BridgeImpl
{
public:
    explicit BridgeImpl(const Config& c);
    ~BridgeImpl();

    // Which side of a pair is the mesh and which the SDF (false if the bridge does not handle it).
    bool orient(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1, bool& mesh_is_body1) const;
    bool isOurSdf(const btCollisionShape* s) const;
    bool isMeshLike(const btCollisionShape* s) const;

    // contact_policy.cpp
    // The pair's query inputs (false: no mesh or SDF to work with).
    bool plan(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, double dt, double margin, detail::PairPlan& P);
    // The discrete queries' parameters (start and end pose) with margin `dcd_margin`.
    sdfccd_QueryParams discreteParams(const detail::PairPlan& P, double dcd_margin) const;
    bool faceSearch(const detail::PairPlan& P) const; // the face search runs for this pair
    // Config::batch_threads: runs the queries of every pair of `world`'s pair cache the bridge
    // handles and that the batch covers, stage by stage, into batch_cache (replacing it).
    void prefetch(double dt, double margin);
    // The batched result of (mesh, sdf, stage) when its inputs are exactly `in`, else NULL; *ran
    // tells whether the batch ran that query (a result it cannot give: an error, or more contacts
    // than the batch had room for, which the caller queries again).
    const detail::CachedQuery* batched(const btCollisionObject* mo, const btCollisionObject* so, int stage, const detail::QueryInput& in,
                                       bool* ran) const;
    bool gather(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, double dt, double margin,
                std::vector<detail::Candidate>& cands, double* out_radius, btVector3* out_w);
    // Writes the pair's points into manifolds[0..manifold_count) (4 each; the first one is the
    // pair's primary manifold, which fires started/ended).
    void process(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, const btDispatcherInfo& info,
                 btManifoldResult* out, btPersistentManifold* const* manifolds, int manifold_count, bool closest);
    double timeOfImpact(const btCollisionObject* mo, const btCollisionObject* so, double dt);

    // guard.cpp
    // After the step: checks every dynamic body's executed motion against the SDFs it can reach.
    void guardStep(btCollisionWorld* world, double dt);
    // The step's start poses, once per step (the first narrow-phase call).
    void snapshotStartPoses(const btCollisionWorld* world);

    Config cfg;
    Stats stats;
    detail::ShapeCache shapes;
    btCollisionDispatcher* dispatcher = nullptr;
    // The guarantee: the world its action is in, the objects' poses at the start of the step
    // (by world array index), the steps it has checked and the step of the last snapshot.
    btDynamicsWorld* guard_world = nullptr;
    std::unique_ptr<btActionInterface> guard;
    std::vector<std::pair<const btCollisionObject*, btTransform>> start_poses;
    int64_t guard_step = 0, snapshot_step = -1;
    // Scratch (the narrow phase is single-threaded in Debian's Bullet builds).
    std::vector<detail::Candidate> scratch;
    std::vector<int32_t> pick;                  // the chosen candidates
    detail::PairScratch work;
    std::vector<sdfccd_ContactPoint> cover_set; // the candidates for the reduction and the cover points
    std::vector<sdfccd_Contact> contacts, start_contacts;
    sdfccd_Workspace* workspace = nullptr; // the queries' scratch storage (no allocation per query)
    // Config::batch_threads: the world whose pair cache the batch reads (registerWith(world)) and
    // the last batch's results.
    btCollisionWorld* batch_world = nullptr;
    std::unordered_map<detail::PairStageKey, detail::CachedQuery, detail::PairStageHash> batch_cache;

    struct CreateFunc;
    std::unique_ptr<CreateFunc> fn[2]; // contact points, closest points
    btGImpactCollisionAlgorithm::CreateFunc gimpact_fn;
};

// The implementation of a Bridge, for the bridge's own sources (Bridge befriends it).
struct BridgeAccess {
    static BridgeImpl* of(Bridge& b) { return b.m_impl; }
};

SDFCCD_BULLET_NAMESPACE_END

#endif
