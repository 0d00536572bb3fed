// SPDX-License-Identifier: MIT
// The sdfccd Bullet bridge in one page: a GImpact cube thrown at 200 m/s onto a thin SDF slab
// stops on its surface instead of tunnelling through it.
#include <cstdio>

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include "sdfccd_bullet/sdfccd_bullet.h"

int main()
{
    sdfccd_bullet::Bridge bridge; // create it before the world, destroy it after

    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
    world.setGravity(btVector3(0, 0, -9.81));
    if (bridge.registerWith(&world) != sdfccd_bullet::Status::Ok) return 1; // before adding bodies

    // Ground: a 10 m x 10 m x 0.1 m slab as an sdfccd SDF (any analytic, CSG or grid SDF works).
    sdfccd_SdfId slab;
    sdfccd_create_box(sdfccd_Vec3{ 5, 5, 0.05 }, &slab);
    sdfccd_bullet::SdfShape ground_shape(slab);
    btRigidBody ground(0, nullptr, &ground_shape);
    world.addRigidBody(&ground);

    // A 1 m cube as a GImpact triangle mesh: 8 corners, 12 counter-clockwise triangles.
    btScalar v[24];
    for (int i = 0; i < 8; ++i)
        for (int k = 0; k < 3; ++k) v[3 * i + k] = (i >> k & 1) ? 0.5f : -0.5f;
    int f[36] = { 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                  2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5 };
    btTriangleIndexVertexArray mesh(12, f, 3 * sizeof(int), 8, v, 3 * sizeof(btScalar));
    btGImpactMeshShape cube_shape(&mesh);
    cube_shape.updateBound();
    btTransform start(btQuaternion::getIdentity(), btVector3(0, 0, 5));
    btDefaultMotionState motion(start);
    btRigidBody cube(1, &motion, &cube_shape, btVector3(1 / 6.f, 1 / 6.f, 1 / 6.f)); // inertia of a unit cube
    cube.setLinearVelocity(btVector3(0, 0, -200)); // 3.3 m per step: ten times the slab's thickness
    world.addRigidBody(&cube);

    for (int i = 0; i < 60; ++i) world.stepSimulation(1 / 60.f, 1, 1 / 60.f);
    double z = cube.getCenterOfMassPosition().z();
    std::printf("cube centre after 1 s: z = %.4f m (resting on the slab: 0.55)\n", z);

    world.removeRigidBody(&cube);
    world.removeRigidBody(&ground);
    sdfccd_destroy_sdf(slab);
    return z > 0.54 && z < 0.56 ? 0 : 1;
}
