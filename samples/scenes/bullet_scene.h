// SPDX-License-Identifier: MIT
/** @file bullet_scene.h  Base of the rigid scenes: a btDiscreteDynamicsWorld stepped with the
 * sdfccd bridge registered (GImpact meshes against SdfShape / btSdfCollisionShape), or, with
 * Options::stock, the same SDF surfaces as btBvhTriangleMeshShape triangle meshes (their
 * isosurface from sdfccd_extract_isosurface) against Bullet's own GImpact algorithm: what users
 * do today. Both variants build the same bodies from the same code.
 */
#ifndef SDFCCD_SCENES_BULLET_SCENE_H
#define SDFCCD_SCENES_BULLET_SCENE_H

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/CollisionShapes/btSdfCollisionShape.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include "sdfccd_bullet/sdfccd_bullet.h"
#include "scene.h"

namespace scenes {

/** A Bullet dynamics world (default collision configuration, dispatcher, DBVT broadphase,
 * sequential-impulse solver) with `gravity`, and `bridge` registered with it; with a null
 * `bridge`, Bullet's own GImpact algorithm instead (the stock variant). The setup shared by every
 * Bullet scene and the cube benchmark (samples/bullet_cube_bench.cpp). `bridge` must outlive it. */
struct BulletWorld {
    BulletWorld(const btVector3& gravity, sdfccd_bullet::Bridge* bridge);
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher;
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world;
    /** The bridge's registerWith() result (Ok for the stock variant). */
    sdfccd_bullet::Status status = sdfccd_bullet::Status::Ok;
};

class BulletScene : public Scene {
public:
    /** A world with the bridge's Config() (the run's method, margin, guarantee and threads aside). */
    BulletScene(const Options& opt, const btVector3& gravity, int up_axis);
    ~BulletScene() override;

    void step(int i, double dt) override;
    StepCost cost() const override;
    /** Writes step i's bodies and manifold points to f (SDFCCD_SCENES_TRACE; samples/scenes/README.md). */
    void traceStep(std::FILE* f, int i) const;
    double energy() const override;
    const char* precision() const override { return SDFCCD_BULLET_PRECISION_NAME; }
    std::string describe() const override;

    /** Called before step i (fire shots, move kinematic bodies). */
    virtual void beforeStep(int i) {}

    /** A dynamic (mass > 0) or static GImpact body of `mesh` at `pos` with orientation `rot`. */
    btRigidBody* addMeshBody(const std::shared_ptr<MeshData>& mesh, double mass, const btVector3& pos,
                             const btQuaternion& rot = btQuaternion::getIdentity());
    /** A static SDF surface at `pos`/`rot`: SdfShape of `sdf` through the bridge, or (stock) the
     * isosurface of `sdf` inside `bounds` (local frame) at `stock_resolution` cells along the longest
     * axis as a btBvhTriangleMeshShape. `exact`/`exact_mesh` is the measuring reference. The scene
     * takes ownership of `sdf`, `exact` and `exact_mesh` (destroyed with the scene; `exact` may equal `sdf`).
     * `feature_size`: the SDF's smallest feature (SdfShape::setFeatureSize; 0: none smaller than a face). */
    Collider& addStaticSdf(const std::string& name, sdfccd_SdfId sdf, const btVector3& pos, const btQuaternion& rot,
                           sdfccd_Aabb bounds, int stock_resolution, sdfccd_SdfId exact, sdfccd_MeshId exact_mesh = sdfccd_MeshId(),
                           double feature_size = 0);
    /** A static btSdfCollisionShape read from a .cdf file (bridge variant; stock: the isosurface of
     * `grid`, the same file loaded by sdfccd). `grid` (owned) is also the measuring reference. */
    Collider& addStaticBtSdf(const std::string& name, const std::string& cdf_path, sdfccd_SdfId grid, const btVector3& pos,
                             int stock_resolution);
    /** Owns an SDF handle (destroyed with the scene). */
    sdfccd_SdfId own(sdfccd_SdfId id);

    btDiscreteDynamicsWorld* world() { return m_world; }
    sdfccd_bullet::Bridge* bridge() { return m_bridge.get(); }
    const Options& options() const { return m_opt; }

protected:
    void syncBodies();
    std::string m_description;

private:
    struct GImpactAsset;
    struct StockMesh;
    GImpactAsset* assetFor(const std::shared_ptr<MeshData>& mesh);

    Options m_opt;
    btVector3 m_gravity;
    std::unique_ptr<sdfccd_bullet::Bridge> m_bridge;
    std::unique_ptr<BulletWorld> m_bullet;          // destroyed before the bridge
    btDiscreteDynamicsWorld* m_world = nullptr;     // &m_bullet->world
    btCollisionDispatcher* m_dispatcher = nullptr;  // &m_bullet->dispatcher
    std::vector<std::unique_ptr<GImpactAsset>> m_assets;
    std::vector<std::unique_ptr<StockMesh>> m_stock;
    std::vector<std::unique_ptr<btCollisionShape>> m_shapes;
    std::vector<std::unique_ptr<btDefaultMotionState>> m_motions;
    std::vector<std::unique_ptr<btRigidBody>> m_rigid;
    std::vector<int> m_bodyIndex; // m_rigid[i] -> bodies index or -1 (statics)
    std::vector<std::vector<char>> m_files;
    std::vector<sdfccd_SdfId> m_sdfs;
    std::vector<sdfccd_MeshId> m_meshes;
    int m_up;
};

/** Rotation of `angle` radians about `axis`. */
btQuaternion axisAngle(double ax, double ay, double az, double angle);
/** A deterministic pseudo-random orientation (index i). */
btQuaternion tumble(int i);

} // namespace scenes

#endif
