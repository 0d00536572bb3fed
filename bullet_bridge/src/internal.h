// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge, internal: what the bridge's source files share.
//   shape_cache.cpp    Bullet shapes -> sdfccd meshes (GImpact, convex hulls, SDF triangulations)
//                      and SDF handles (SdfShape, btSdfCollisionShape)
//   contact_policy.cpp a pair's contact set in a step (the core's generator, batched over pairs),
//                      written into its manifolds with Bullet's callbacks
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

// The pose `dt` before the object's current one: its pose moved back by its velocities (a kinematic
// object's, or one that is no rigid body, by its interpolation velocities), undoing Bullet's integration.
btTransform poseBefore(const btCollisionObject* co, double dt);
// A rigid body's centre of mass, velocities and inverse mass and world inertia, as the C API takes them.
sdfccd_BodyState bodyState(const btRigidBody* b);

// The motion of a body (or compound child: `wrapper_transform` includes its offset) over a step:
// from its start pose to its end pose with the constant velocities that connect them in Bullet's
// motion model (origin lerp + exponential-map rotation), sdfccd's too.
sdfccd_RigidMotion motionOf(const btCollisionObject* co, const btTransform& wrapper_transform, double dt);

// A shape packed as a triangle mesh for sdfccd (scaled, in the shape's local frame).
struct MeshEntry {
    sdfccd_MeshId id = { 0, 0 };
    btVector3 scaling;
    btScalar margin = 0;
    int source_count = 0;
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

// A pair's manifold points, last step and this one (reused: no allocation once grown), their
// places on the mesh body (m_localPointA) and the old point each new one continues (-1: none).
struct PairScratch {
    std::vector<btManifoldPoint> old_points, new_points;
    std::vector<sdfccd_Vec3> old_places, new_places;
    std::vector<int32_t> match;
    std::vector<char> matched; // old points that persist
};

// Manifolds a pair has beyond its first (for the cover points).
const int kExtraManifolds = 3;

// The ids of a pair's reduced points in the last step (its first manifold's), which the next step's
// reduction prefers (sdfccd_KeepPrevious): a resting set keeps its points and their slots.
struct KeptIds {
    uint64_t ids[MANIFOLD_CACHE_SIZE];
    int32_t count;
};

// One pair's arguments of sdfccd_generate_contacts (compared byte for byte with a batch's; the
// previous ids by value in `kept`, params.previous.ids NULL) and its result.
struct PairInput {
    sdfccd_SdfId sdf;
    sdfccd_MeshId mesh;
    sdfccd_RigidMotion motion, sdf_motion;
    double dt;
    sdfccd_ContactParams params;
    int32_t capacity;
    KeptIds kept;
};
struct PairResult {
    PairInput in;
    sdfccd_ContactParams run_params; // in.params with previous pointing at in.kept
    sdfccd_Status status = SDFCCD_OK;
    sdfccd_ContactSet set;
    std::vector<sdfccd_ContactPoint> points;
};
typedef std::pair<const btCollisionObject*, const btCollisionObject*> ObjectPair; // (mesh, SDF)
struct ObjectPairHash {
    size_t operator()(const ObjectPair& k) const { return std::hash<const void*>()(k.first) * 31u + std::hash<const void*>()(k.second); }
};

// The kept ids of a pair's algorithm when it is the bridge's (contact points), else NULL.
KeptIds* keptIdsOf(btCollisionAlgorithm* algorithm);

/** When `callback` is Bullet's GImpact algorithm's (btGImpactTriangleCallback), i.e. that algorithm
 * collides with `shape`: diagnoses why and reports it through the misuse handler unless the diagnosis
 * equals the last one reported for the shape (`last_reported`: 0 = none, else the Status + 1; updated). */
void reportGImpactMisuse(const btTriangleCallback* callback, const btCollisionShape* shape, int& last_reported);
// The guarantee's action (Config::guard_tolerance): added to a dynamics world at registration,
// removed by unregister().
void guardAttach(BridgeImpl* impl, btCollisionWorld* world);
void guardDetach(BridgeImpl* impl);
// soft_body.cpp: the (btSoftBody, SDF) pairs, registered and restored with the rigid ones; their
// algorithm (w0: the soft body or the SDF) made by the bridge's create function.
struct SoftState;
void softRegister(BridgeImpl* impl);
btCollisionAlgorithm* softAlgorithm(BridgeImpl* impl, const btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* w0);
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
    // The pair's arguments of sdfccd_generate_contacts (false: no mesh or SDF to work with).
    bool pairInput(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, double dt, double margin, int capacity,
                   const detail::KeptIds* kept, detail::PairInput& in);
    int stepCapacity() const;                                   // points per pair and step (all its manifolds)
    bool generate(detail::PairResult& r, sdfccd_Workspace* ws); // r.in -> r.set, r.points
    // Config::batch_threads: the contact sets of every pair of the world's pair cache the bridge
    // handles (top level, SdfShape), on the threads, into batch_cache (replacing it).
    void runBatch(double dt, double margin);
    // The batched set of (mesh, sdf) when its inputs are exactly `in` (running the batch when they
    // are not there), else NULL.
    const detail::PairResult* batched(const btCollisionObject* mo, const btCollisionObject* so, const detail::PairInput& in);
    // Writes the pair's points into manifolds[0..manifold_count) (4 each; the first one is the
    // pair's primary manifold, which fires started/ended).
    // `kept` (NULL for closest points): the pair's reduced ids of the last step, updated.
    void process(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, const btDispatcherInfo& info,
                 btManifoldResult* out, btPersistentManifold* const* manifolds, int manifold_count, bool closest, detail::KeptIds* kept);
    double timeOfImpact(const btCollisionObject* mo, const btCollisionObject* so, double dt);

    // guard.cpp
    // After the step: checks every dynamic body's executed motion against the SDFs it can reach.
    void guardStep(btCollisionWorld* world, double dt);
    // The step's start poses, once per step (the first narrow-phase call).
    void snapshotStartPoses(const btCollisionWorld* world);
    // contact_policy.cpp: static friction on the step's manifolds (held_manifolds) that Bullet's one
    // friction direction per point left out.
    void holdFriction(btCollisionWorld* world, double dt);
    std::vector<const btPersistentManifold*> held_manifolds;

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
    detail::PairScratch work;
    detail::PairResult single;             // a pair's set computed in the narrow phase
    sdfccd_Workspace* workspace = nullptr; // the narrow phase's and the guarantee's (no allocation per query)
    // Config::batch_threads: the world whose pair cache the batch reads (registerWith(world)), a
    // workspace per thread and the last batch's results.
    btCollisionWorld* batch_world = nullptr;
    std::vector<sdfccd_Workspace*> batch_ws;
    std::unordered_map<detail::ObjectPair, detail::PairResult, detail::ObjectPairHash> batch_cache;

    std::shared_ptr<detail::SoftState> soft; // soft_body.cpp (deleted where it is complete)

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
