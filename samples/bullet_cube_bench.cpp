// SPDX-License-Identifier: MIT
// Measures the Bullet bridge on the notes' reference scene: a 1 m GImpact cube (12 triangles) at
// 200 m/s onto a 0.1 m SDF slab, 1/60 s steps, 120 steps. Prints CSV (one row per variant):
//   variant,precision,steps,z_after_impact,rest_z,rest_speed,ccd_queries,end_pose_queries,
//   ccd_ms_total,ccd_us_per_step,step_us_mean
// Variants: the bridge with the mesh added first and with the SDF added first, and the peer
// "GImpact vs a marching-cubes mesh of the slab" (Bullet's own GImpact-GImpact path, no CCD).
// Usage: bullet_cube_bench [steps]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include "sdfccd_bullet/sdfccd_bullet.h"
#include "scenes/bullet_scene.h" // BulletWorld (the scenes' world setup), takeMeshArrays

namespace {

const double kDt = 1.0 / 60.0;

struct Mesh {
    std::vector<btScalar> v;
    std::vector<int> f;
    std::unique_ptr<btTriangleIndexVertexArray> tiva;
    std::unique_ptr<btGImpactMeshShape> shape;
    void finish()
    {
        tiva.reset(new btTriangleIndexVertexArray((int)f.size() / 3, f.data(), 3 * (int)sizeof(int), (int)v.size() / 3, v.data(),
                                                  3 * (int)sizeof(btScalar)));
        shape.reset(new btGImpactMeshShape(tiva.get()));
        shape->updateBound();
    }
};

std::unique_ptr<Mesh> unitCube()
{
    std::unique_ptr<Mesh> m(new Mesh);
    for (int i = 0; i < 8; ++i)
        for (int k = 0; k < 3; ++k) m->v.push_back((i >> k & 1) ? 0.5f : -0.5f);
    const int f[36] = { 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5 };
    m->f.assign(f, f + 36);
    m->finish();
    return m;
}

// The slab's surface as a triangle mesh (sdfccd_extract_isosurface).
std::unique_ptr<Mesh> slabMesh(sdfccd_SdfId slab)
{
    sdfccd_Aabb box = { { -5.2, -5.2, -0.3 }, { 5.2, 5.2, 0.3 } };
    sdfccd_MeshId id;
    if (sdfccd_extract_isosurface(slab, box, 104, &id) != SDFCCD_OK) return nullptr;
    sdfccd_MeshInfo info;
    std::vector<double> v;
    std::vector<uint32_t> f;
    if (!scenes::takeMeshArrays(id, v, f, info)) return nullptr;
    std::unique_ptr<Mesh> m(new Mesh);
    m->v.assign(v.begin(), v.end());
    m->f.assign(f.begin(), f.end());
    m->finish();
    return m;
}

enum Variant { kBridgeMeshFirst, kBridgeSdfFirst, kGImpactPeer };

void run(Variant variant, int steps, sdfccd_SdfId slab)
{
    sdfccd_bullet::Bridge bridge;
    scenes::BulletWorld bw(btVector3(0, 0, -9.81), variant == kGImpactPeer ? nullptr : &bridge);
    if (bw.status != sdfccd_bullet::Status::Ok) std::exit(1);
    btDiscreteDynamicsWorld& world = bw.world;

    sdfccd_bullet::SdfShape sdf_shape(slab);
    std::unique_ptr<Mesh> peer;
    btCollisionShape* ground_shape = &sdf_shape;
    if (variant == kGImpactPeer) {
        peer = slabMesh(slab);
        if (!peer) std::exit(1);
        ground_shape = peer->shape.get();
    }
    btRigidBody ground(0, nullptr, ground_shape);
    std::unique_ptr<Mesh> cube = unitCube();
    btTransform start(btQuaternion::getIdentity(), btVector3(0, 0, 5));
    btDefaultMotionState ms(start);
    btRigidBody body(1, &ms, cube->shape.get(), btVector3(btScalar(1) / 6, btScalar(1) / 6, btScalar(1) / 6));
    body.setLinearVelocity(btVector3(0, 0, -200));
    body.setActivationState(DISABLE_DEACTIVATION);
    if (variant == kBridgeSdfFirst) {
        world.addRigidBody(&ground);
        world.addRigidBody(&body);
    } else {
        world.addRigidBody(&body);
        world.addRigidBody(&ground);
    }
    double z_impact = NAN, free_z = 5, free_v = -200, step_seconds = 0;
    for (int i = 0; i < steps; ++i) {
        auto t0 = std::chrono::steady_clock::now();
        world.stepSimulation((btScalar)kDt, 1, (btScalar)kDt);
        step_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        free_v -= 9.81 * kDt;
        free_z += free_v * kDt;
        double z = body.getCenterOfMassPosition().z();
        if (std::isnan(z_impact) && std::fabs(z - free_z) > 1e-3) z_impact = z;
    }
    sdfccd_bullet::Stats s = bridge.stats();
    static const char* names[] = { "bridge_mesh_first", "bridge_sdf_first", "gimpact_vs_marching_cubes_mesh" };
    std::printf("%s,%s,%d,%.6f,%.6f,%.3g,%lld,%lld,%.3f,%.1f,%.1f\n", names[variant], SDFCCD_BULLET_PRECISION_NAME, steps, z_impact,
                (double)body.getCenterOfMassPosition().z(), (double)body.getLinearVelocity().length(), (long long)s.queries,
                (long long)s.end_pose_queries, 1e3 * s.query_seconds, 1e6 * s.query_seconds / steps, 1e6 * step_seconds / steps);
    world.removeRigidBody(&body);
    world.removeRigidBody(&ground);
}

} // namespace

int main(int argc, char** argv)
{
    int steps = argc > 1 ? std::atoi(argv[1]) : 120;
    if (steps < 1) steps = 120;
    sdfccd_SdfId slab;
    if (sdfccd_create_box(sdfccd_Vec3{ 5, 5, 0.05 }, &slab) != SDFCCD_OK) return 1;
    std::printf("variant,precision,steps,z_after_impact,rest_z,rest_speed,ccd_queries,end_pose_queries,ccd_ms_total,"
                "ccd_us_per_step,step_us_mean\n");
    run(kBridgeMeshFirst, steps, slab);
    run(kBridgeSdfFirst, steps, slab);
    run(kGImpactPeer, steps, slab);
    sdfccd_destroy_sdf(slab);
    return 0;
}
