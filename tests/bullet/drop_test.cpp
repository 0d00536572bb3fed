// SPDX-License-Identifier: MIT
// The drop (issue 19, "Done when"): 20 GImpact bodies (bullet3's torus x2, mass 1, and bunny,
// mass 4, alternating), tumbling, 6 of them thrown down at 10 m/s, dropped onto an analytic ground
// (a box, top at y = 0), an analytic torus lying on it (R 2, r 0.5) and bullet3's bunny as a grid
// SDF (data/sdf/generated/bullet3_bunny_r16.cdf) in an SdfShape scaled x4, through the bridge with
// Config() defaults. At the end of every step the penetration of every vertex of every body is
// measured against the SDF of each collider (the analytic ones exactly; the bunny against its own
// field, the scaled grid the SdfShape collides with): at most 1 cm at every step, and the bodies
// must reach the colliders (the deepest contact is measured, not assumed).
// Usage: drop_test [steps] [--guard T]  (T: Config::guard_tolerance; 0 turns the guarantee off,
// which makes this test fail: the demonstration that it can).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include "sdfccd_bullet/sdfccd_bullet.h"
#include "bullet_check.h"

#ifndef SDFCCD_DATA_DIR
#error "SDFCCD_DATA_DIR must be defined (the project's data/ folder)"
#endif

static const double kDt = 1.0 / 60.0;
static const double kLimit = 0.01;

// A GImpact mesh from an OBJ file (the library's reader), kept with its arrays.
struct Mesh {
    std::vector<btScalar> v;
    std::vector<int> f;
    std::unique_ptr<btTriangleIndexVertexArray> tiva;
    std::unique_ptr<btGImpactMeshShape> shape;
    double lo_y = 0;
};

static bool loadMesh(const std::string& path, double scale, Mesh& m)
{
    sdfccd_MeshLoadDef def = sdfccd_default_mesh_load_def();
    def.scale = scale;
    sdfccd_MeshId id{};
    if (sdfccd_load_mesh(path.c_str(), &def, &id) != SDFCCD_OK) return false;
    sdfccd_MeshInfo info;
    sdfccd_mesh_get_info(id, &info);
    std::vector<double> v(3 * (size_t)info.vertex_count);
    std::vector<uint32_t> f(3 * (size_t)info.triangle_count);
    sdfccd_mesh_get_data(id, v.data(), f.data());
    sdfccd_destroy_mesh(id);
    m.v.assign(v.begin(), v.end());
    m.f.assign(f.begin(), f.end());
    m.lo_y = INFINITY;
    for (size_t i = 1; i < v.size(); i += 3) m.lo_y = std::min(m.lo_y, v[i]);
    m.tiva.reset(new btTriangleIndexVertexArray((int)info.triangle_count, m.f.data(), 3 * (int)sizeof(int), (int)info.vertex_count,
                                                m.v.data(), 3 * (int)sizeof(btScalar)));
    m.shape.reset(new btGImpactMeshShape(m.tiva.get()));
    m.shape->setMargin(0); // as Bullet's GImpact demo
    m.shape->updateBound();
    return true;
}

// A static collider: the SDF the shape collides with, measured in its local frame.
struct Collider {
    const char* name;
    sdfccd_SdfId measure;
    btTransform frame;
};

int main(int argc, char** argv)
{
    int steps = 150;
    double guard = -1;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--guard") && i + 1 < argc) guard = std::atof(argv[++i]);
        else steps = std::max(1, std::atoi(argv[i]));
    }
    std::printf("drop test, btScalar = %s, %d steps%s\n", SDFCCD_BULLET_PRECISION_NAME, steps, guard >= 0 ? " (guard set)" : "");
    const std::string data = SDFCCD_DATA_DIR;
    Mesh torus, bunny;
    CHECK(loadMesh(data + "/bullet3/torus_textured.obj", 2.0, torus), "torus: %s", sdfccd_last_error());
    CHECK(loadMesh(data + "/bullet3/bunny.obj", 1.0, bunny), "bunny: %s", sdfccd_last_error());
    sdfccd_SdfId ground{}, ring{}, grid{}, grid4{};
    CHECK(sdfccd_create_box(sdfccd_Vec3{ 30, 1, 30 }, &ground) == SDFCCD_OK, "box");
    CHECK(sdfccd_create_torus(2, 0.5, &ring) == SDFCCD_OK, "torus");
    CHECK(sdfccd_load_grid((data + "/sdf/generated/bullet3_bunny_r16.cdf").c_str(), &grid) == SDFCCD_OK, "grid: %s", sdfccd_last_error());
    CHECK(sdfccd_create_transformed(grid, sdfccd_pose_identity(), 4.0, &grid4) == SDFCCD_OK, "scaled grid: %s", sdfccd_last_error());
    if (g_fail) return 1;
    { // the world, its shapes and the bridge go before the SDFs they use
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
    world.setGravity(btVector3(0, -10, 0));
    sdfccd_bullet::Config cfg;
    if (guard >= 0) cfg.guard_tolerance = guard;
    sdfccd_bullet::Bridge bridge(cfg);
    CHECK(bridge.registerWith(&world) == sdfccd_bullet::Status::Ok, "registerWith");

    // The colliders: ground (top y = 0), the lying torus (axis y) and the bunny grid x4 on the ground.
    sdfccd_bullet::SdfShape groundShape(ground), ringShape(ring), bunnyShape(grid);
    bunnyShape.setLocalScaling(btVector3(4, 4, 4));
    std::vector<Collider> colliders = {
        { "ground", ground, btTransform(btQuaternion::getIdentity(), btVector3(0, -1, 0)) },
        { "torus", ring, btTransform(btQuaternion(btVector3(1, 0, 0), (btScalar)(-M_PI / 2)), btVector3(-6, 0.5, 0)) },
        { "bunny grid x4", grid4, btTransform(btQuaternion::getIdentity(), btVector3(6, (btScalar)(-4 * bunny.lo_y), 0)) },
    };
    btCollisionShape* shapes[3] = { &groundShape, &ringShape, &bunnyShape };
    std::vector<std::unique_ptr<btRigidBody>> statics, bodies;
    for (int i = 0; i < 3; ++i) {
        btRigidBody::btRigidBodyConstructionInfo ci(0, nullptr, shapes[i]);
        ci.m_startWorldTransform = colliders[(size_t)i].frame;
        statics.emplace_back(new btRigidBody(ci));
        statics.back()->setFriction(0.9f);
        world.addRigidBody(statics.back().get());
    }
    // 20 bodies over the torus and the bunny, two layers, tumbling; every third thrown down at 10 m/s.
    std::vector<Mesh*> kinds;
    for (int k = 0; k < 20; ++k) {
        Mesh* m = k % 2 ? &bunny : &torus;
        const btScalar mass = k % 2 ? 4 : 1;
        btVector3 inertia;
        m->shape->calculateLocalInertia(mass, inertia);
        const btVector3 pos((btScalar)(k % 5 < 2 ? -7.5 + 3 * (k % 5) : 3 + 3 * (k % 5 - 2)), (btScalar)(5 + 4 * (k / 10) + 1.0 * (k % 3)),
                            (btScalar)(-3 + 3 * ((k / 5) % 2) + 1.5 * (k % 2)));
        btRigidBody::btRigidBodyConstructionInfo ci(mass, nullptr, m->shape.get(), inertia);
        ci.m_startWorldTransform = btTransform(btQuaternion(btVector3(1, (btScalar)(0.3 * k), 0.5).normalized(), (btScalar)(0.7 * k)), pos);
        bodies.emplace_back(new btRigidBody(ci));
        bodies.back()->setFriction(0.5f);
        if (k % 3 == 0) bodies.back()->setLinearVelocity(btVector3(0, -10, 0));
        bodies.back()->setAngularVelocity(btVector3((btScalar)(0.5 * (k % 4)), 1, (btScalar)(-0.3 * (k % 5))));
        world.addRigidBody(bodies.back().get());
        kinds.push_back(m);
    }

    // Every step: every vertex of every body against every collider's SDF (in its local frame).
    std::vector<sdfccd_Vec3> pts;
    std::vector<double> phi;
    double worst = 0, closest = INFINITY;
    int worst_step = -1, over = 0;
    const char* worst_where = "";
    for (int step = 0; step < steps; ++step) {
        world.stepSimulation((btScalar)kDt, 1, (btScalar)kDt);
        double step_worst = 0;
        for (const Collider& c : colliders) {
            const btTransform inv = c.frame.inverse();
            pts.clear();
            for (size_t b = 0; b < bodies.size(); ++b) {
                const btTransform t = inv * bodies[b]->getWorldTransform();
                const std::vector<btScalar>& v = kinds[b]->v;
                for (size_t i = 0; i < v.size(); i += 3) {
                    const btVector3 p = t * btVector3(v[i], v[i + 1], v[i + 2]);
                    pts.push_back(sdfccd_Vec3{ (double)p.x(), (double)p.y(), (double)p.z() });
                }
            }
            phi.resize(pts.size());
            CHECK(sdfccd_sdf_eval_batch(c.measure, pts.data(), (int32_t)pts.size(), phi.data(), nullptr) == SDFCCD_OK, "eval: %s",
                  sdfccd_last_error());
            for (double f : phi) {
                closest = std::min(closest, f);
                if (-f > step_worst) step_worst = -f;
                if (-f > worst) {
                    worst = -f;
                    worst_step = step;
                    worst_where = c.name;
                }
            }
        }
        if (step_worst > kLimit) {
            ++over;
            if (over <= 5) std::fprintf(stderr, "step %d: a vertex %.4f m deep\n", step, step_worst);
        }
    }
    const sdfccd_bullet::Stats& st = bridge.stats();
    std::printf("max penetration %.5f m (step %d, in %s), steps over %.0f mm: %d; rollbacks %lld, guard checks %lld\n", worst, worst_step,
                worst_where, kLimit * 1e3, over, (long long)st.rollbacks, (long long)st.guard_queries);
    CHECK(over == 0, "%d steps with a vertex deeper than %.3f m (max %.5f m at step %d in %s)", over, kLimit, worst, worst_step, worst_where);
    CHECK(closest < 0.005, "the bodies never came within 5 mm of a collider (closest %.4f m)", closest);
    CHECK(st.hits > 0, "no contact");
    for (auto& b : bodies) world.removeRigidBody(b.get());
    for (auto& b : statics) world.removeRigidBody(b.get());
    bridge.unregister();
    }
    for (sdfccd_SdfId id : { grid4, grid, ring, ground }) sdfccd_destroy_sdf(id);
    return checkSummary();
}
