// SPDX-License-Identifier: MIT
// Bullet bridge tests (built once per Bullet precision). Usage: bridge_tests [test-name ...];
// no argument runs every test. Prints one line per failed check and a closing
// "N passed, N failed"; exits non-zero on any failure.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionShapes/btSdfCollisionShape.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <LinearMath/btPoolAllocator.h>

#include "sdfccd_bullet/sdfccd_bullet.h"

#ifndef SDFCCD_DATA_DIR
#error "SDFCCD_DATA_DIR must be defined"
#endif

using sdfccd_bullet::Bridge;
using sdfccd_bullet::SdfShape;
using sdfccd_bullet::Status;

static int g_pass = 0, g_fail = 0;
#define CHECK(cond, ...)                                                         \
    do {                                                                         \
        if (cond) {                                                              \
            ++g_pass;                                                            \
        } else {                                                                 \
            ++g_fail;                                                            \
            std::fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
            std::fprintf(stderr, __VA_ARGS__);                                   \
            std::fputc('\n', stderr);                                            \
        }                                                                        \
    } while (0)

static const double kDt = 1.0 / 60.0;
static const bool kVerbose = std::getenv("SDFCCD_TEST_VERBOSE") != nullptr;

// ---- scene helpers ----

// A triangle mesh Bullet can wrap in a btGImpactMeshShape (arrays owned here).
struct TriMesh {
    std::vector<btScalar> v;
    std::vector<int> f;
    std::unique_ptr<btTriangleIndexVertexArray> tiva;
    std::unique_ptr<btGImpactMeshShape> shape;
    void finish()
    {
        tiva.reset(new btTriangleIndexVertexArray((int)f.size() / 3, f.data(), 3 * (int)sizeof(int), (int)v.size() / 3,
                                                  v.data(), 3 * (int)sizeof(btScalar)));
        shape.reset(new btGImpactMeshShape(tiva.get()));
        shape->updateBound();
    }
};

// Box with half extents h, 12 counter-clockwise (outward) triangles.
static std::unique_ptr<TriMesh> makeBox(btVector3 h)
{
    std::unique_ptr<TriMesh> m(new TriMesh);
    for (int i = 0; i < 8; ++i) {
        m->v.push_back((i & 1) ? h.x() : -h.x());
        m->v.push_back((i & 2) ? h.y() : -h.y());
        m->v.push_back((i & 4) ? h.z() : -h.z());
    }
    const int faces[12][3] = { { 0, 2, 1 }, { 1, 2, 3 }, { 4, 5, 6 }, { 5, 7, 6 }, { 0, 1, 4 }, { 1, 5, 4 },
                               { 2, 6, 3 }, { 3, 6, 7 }, { 0, 4, 2 }, { 2, 4, 6 }, { 1, 3, 5 }, { 3, 7, 5 } };
    for (auto& t : faces) m->f.insert(m->f.end(), t, t + 3);
    m->finish();
    return m;
}

struct World {
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher;
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world;
    std::vector<std::unique_ptr<btRigidBody>> bodies;
    std::vector<std::unique_ptr<btMotionState>> states;
    World() : dispatcher(&config), world(&dispatcher, &broadphase, &solver, &config)
    {
        world.setGravity(btVector3(0, 0, -9.81));
    }
    ~World()
    {
        for (auto& b : bodies) world.removeRigidBody(b.get());
    }
    btRigidBody* add(btCollisionShape* shape, btScalar mass, const btVector3& pos, const btVector3& inertia_box_half = btVector3(0, 0, 0))
    {
        btTransform t;
        t.setIdentity();
        t.setOrigin(pos);
        states.emplace_back(new btDefaultMotionState(t));
        btVector3 inertia(0, 0, 0);
        if (mass > 0) {
            btBoxShape box(inertia_box_half);
            box.calculateLocalInertia(mass, inertia);
        }
        btRigidBody::btRigidBodyConstructionInfo ci(mass, states.back().get(), shape, inertia);
        bodies.emplace_back(new btRigidBody(ci));
        world.addRigidBody(bodies.back().get());
        return bodies.back().get();
    }
    void step() { world.stepSimulation((btScalar)kDt, 1, (btScalar)kDt); }
};

static sdfccd_SdfId makeBoxSdf(double hx, double hy, double hz)
{
    sdfccd_SdfId id = { 0, 0 };
    sdfccd_Vec3 h = { hx, hy, hz };
    sdfccd_Status st = sdfccd_create_box(h, &id);
    CHECK(st == SDFCCD_OK, "sdfccd_create_box: %s", sdfccd_last_error());
    return id;
}

static double phiAt(sdfccd_SdfId sdf, const btVector3& p)
{
    sdfccd_Vec3 q = { (double)p.x(), (double)p.y(), (double)p.z() };
    double v = 0;
    sdfccd_sdf_eval(sdf, q, &v, nullptr);
    return v;
}

// ---- the 200 m/s cube on a 0.1 m slab ----

// Runs the scene; returns false if something could not be set up. `bridge_on` false = only
// GImpact's own registration (the baseline that tunnels).
struct CubeRun {
    std::vector<double> z, vz;
    int impact_step = -1; // first step whose motion deviates from free fall
};

static CubeRun runCube(bool bridge_on, bool mesh_first, int steps, sdfccd_bullet::Stats* stats_out = nullptr)
{
    CubeRun r;
    sdfccd_SdfId slab = makeBoxSdf(5, 5, 0.05);
    {
        Bridge bridge;
        World w;
        if (bridge_on) {
            Status s = bridge.registerWith(&w.world);
            CHECK(s == Status::Ok, "registerWith: %s", sdfccd_bullet::statusString(s));
        } else {
            btGImpactCollisionAlgorithm::registerAlgorithm(&w.dispatcher);
        }
        SdfShape slab_shape(slab);
        std::unique_ptr<TriMesh> cube = makeBox(btVector3(0.5, 0.5, 0.5));
        btRigidBody* body = nullptr;
        if (mesh_first) {
            body = w.add(cube->shape.get(), 1, btVector3(0, 0, 5), btVector3(0.5, 0.5, 0.5));
            w.add(&slab_shape, 0, btVector3(0, 0, 0));
        } else {
            w.add(&slab_shape, 0, btVector3(0, 0, 0));
            body = w.add(cube->shape.get(), 1, btVector3(0, 0, 5), btVector3(0.5, 0.5, 0.5));
        }
        body->setLinearVelocity(btVector3(0, 0, -200));
        body->setActivationState(DISABLE_DEACTIVATION);
        double free_z = 5, free_v = -200;
        for (int i = 0; i < steps; ++i) {
            w.step();
            free_v += -9.81 * kDt;
            free_z += free_v * kDt;
            double z = body->getCenterOfMassPosition().z();
            r.z.push_back(z);
            r.vz.push_back(body->getLinearVelocity().z());
            if (r.impact_step < 0 && std::fabs(z - free_z) > 1e-3) r.impact_step = i;
        }
        if (stats_out) *stats_out = bridge.stats();
    }
    sdfccd_destroy_sdf(slab);
    return r;
}

static void testCube(bool mesh_first)
{
    const char* order = mesh_first ? "mesh added first" : "SDF added first";
    sdfccd_bullet::Stats stats;
    CubeRun r = runCube(true, mesh_first, 120, &stats);
    // Free fall from z = 5 at 200 m/s: the bottom face (z - 0.5) reaches the slab top (0.05)
    // during step 2 (index 1), when the centre goes from 1.667 to -1.67.
    CHECK(r.impact_step == 1, "%s: impact step %d, expected 1", order, r.impact_step);
    if (r.impact_step >= 0)
        CHECK(std::fabs(r.z[r.impact_step] - 0.55) <= 1e-3, "%s: z after the impact step %.6f, expected 0.550 +- 0.001", order,
              r.z[r.impact_step]);
    double zmin = 1e9, zmax = -1e9;
    for (size_t i = (size_t)std::max(r.impact_step, 0); i < r.z.size(); ++i) {
        zmin = std::min(zmin, r.z[i]);
        zmax = std::max(zmax, r.z[i]);
    }
    CHECK(zmin >= 0.55 - 1e-3 && zmax <= 0.55 + 1e-3, "%s: after impact z in [%.6f, %.6f], expected 0.550 +- 0.001", order, zmin, zmax);
    CHECK(std::fabs(r.z.back() - 0.55) <= 1e-3, "%s: final z %.6f", order, r.z.back());
    CHECK(std::fabs(r.vz.back()) <= 0.05, "%s: final vertical speed %.4f m/s, expected at rest", order, r.vz.back());
    CHECK(stats.speculative_contacts > 0 && stats.ordinary_contacts > 0, "%s: contacts speculative %lld ordinary %lld", order,
          (long long)stats.speculative_contacts, (long long)stats.ordinary_contacts);
    std::printf("cube (%s, %s): impact step %d, z after impact %.6f, final z %.6f, final vz %.2e, %lld queries, "
                "%.1f us per query\n",
                order, SDFCCD_BULLET_PRECISION_NAME, r.impact_step, r.impact_step >= 0 ? r.z[r.impact_step] : NAN, r.z.back(),
                r.vz.back(), (long long)stats.queries, stats.queries ? 1e6 * stats.query_seconds / stats.queries : 0.0);
}

static void test_cube_mesh_first() { testCube(true); }
static void test_cube_sdf_first() { testCube(false); }

static void test_cube_tunnels_without_bridge()
{
    for (int order = 0; order < 2; ++order) {
        CubeRun r = runCube(false, order == 0, 30);
        CHECK(r.impact_step < 0, "without the bridge the cube should never be stopped (deviated at step %d)", r.impact_step);
        CHECK(r.z.back() < -50, "without the bridge the cube should tunnel: final z %.3f", r.z.back());
    }
}

// ---- a spinning GImpact bar hitting a torus SDF ----

// Deepest of the bar's corners, edge midpoints, face centres and centre in the SDF (<= 0).
static double barPenetration(sdfccd_SdfId sdf, const btTransform& t, const btVector3& half)
{
    double worst = 0;
    for (int c = 0; c < 27; ++c) {
        btVector3 l((c % 3 - 1) * half.x(), ((c / 3) % 3 - 1) * half.y(), (c / 9 - 1) * half.z());
        worst = std::min(worst, phiAt(sdf, t * l));
    }
    for (int k = -8; k <= 8; ++k) // along the bottom long edges too
        for (int e = 0; e < 4; ++e) {
            btVector3 l(k * half.x() / 8, (e & 1 ? 1 : -1) * half.y(), (e & 2 ? 1 : -1) * half.z());
            worst = std::min(worst, phiAt(sdf, t * l));
        }
    return -worst;
}

static void test_torus_spinning()
{
    // A 2.4 m bar spinning about the vertical axis (and tumbling a little) falls at 60 m/s onto a
    // torus (ring radius 1, tube 0.25) and must come to rest across the ring on the tube tops:
    // centre height 0.25 + 0.1 = 0.35.
    sdfccd_SdfId torus = { 0, 0 };
    CHECK(sdfccd_create_torus(1.0, 0.25, &torus) == SDFCCD_OK, "torus: %s", sdfccd_last_error());
    const btVector3 half(1.2, 0.1, 0.1);
    double worst = 0, z_impact = NAN;
    int first_contact = -1;
    sdfccd_bullet::Stats stats;
    btVector3 final_pos, final_v;
    {
        Bridge bridge;
        World w;
        CHECK(bridge.registerWith(&w.world) == Status::Ok, "register");
        SdfShape shape(torus);
        std::unique_ptr<TriMesh> bar = makeBox(half);
        w.add(&shape, 0, btVector3(0, 0, 0));
        btRigidBody* body = w.add(bar->shape.get(), 1, btVector3(0, 0, 3.0), half);
        body->setLinearVelocity(btVector3(0, 0, -60)); // 1 m per step: four tube radii
        body->setAngularVelocity(btVector3(2, 0, 20)); // 0.33 rad per step about z
        body->setActivationState(DISABLE_DEACTIVATION);
        for (int i = 0; i < 120; ++i) {
            w.step();
            const btTransform& t = body->getWorldTransform();
            worst = std::max(worst, barPenetration(torus, t, half));
            if (first_contact < 0 && bridge.stats().hits > 0) {
                first_contact = i;
                z_impact = t.getOrigin().z();
            }
            if (kVerbose)
                std::printf("  torus step %d: pos (%.3f %.3f %.3f) v (%.2f %.2f %.2f) w (%.2f %.2f %.2f) pen %.4f hits %lld\n", i,
                            t.getOrigin().x(), t.getOrigin().y(), t.getOrigin().z(), body->getLinearVelocity().x(),
                            body->getLinearVelocity().y(), body->getLinearVelocity().z(), body->getAngularVelocity().x(),
                            body->getAngularVelocity().y(), body->getAngularVelocity().z(), barPenetration(torus, t, half),
                            (long long)bridge.stats().hits);
        }
        stats = bridge.stats();
        final_pos = body->getCenterOfMassPosition();
        final_v = body->getLinearVelocity();
    }
    CHECK(first_contact == 2, "first hit in step %d, expected 2 (the bar reaches the tubes during the third step)", first_contact);
    CHECK(z_impact > 0.35 - 0.02, "after the impact step the bar is at z %.4f, below the tube tops", z_impact);
    CHECK(worst <= 0.02, "deepest end-of-step penetration %.4f m (tolerance 0.02 m)", worst);
    CHECK(std::fabs(final_pos.z() - 0.35) <= 0.01 && final_pos.length() < 0.5, "final centre (%.3f %.3f %.3f), expected resting at z 0.35",
          final_pos.x(), final_pos.y(), final_pos.z());
    CHECK(final_v.length() < 0.1, "not at rest: %.3f m/s", final_v.length());
    std::printf("torus: first hit in step %d, z after it %.4f, deepest end-of-step penetration %.5f m, rests at z %.4f, %lld speculative "
                "+ %lld ordinary contacts\n",
                first_contact, z_impact, worst, final_pos.z(), (long long)stats.speculative_contacts, (long long)stats.ordinary_contacts);
    sdfccd_destroy_sdf(torus);
}

// ---- a moving (kinematic) SDF body: a slab rising at 20 m/s lifts a resting cube ----

static void test_kinematic_sdf()
{
    sdfccd_SdfId slab = makeBoxSdf(3, 3, 0.05);
    double worst_gap = 1e9, final_gap = 0;
    sdfccd_bullet::Stats stats;
    {
        Bridge bridge;
        World w;
        CHECK(bridge.registerWith(&w.world) == Status::Ok, "register");
        SdfShape shape(slab);
        std::unique_ptr<TriMesh> cube = makeBox(btVector3(0.5, 0.5, 0.5));
        btRigidBody* platform = w.add(&shape, 0, btVector3(0, 0, 0));
        platform->setCollisionFlags(platform->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
        platform->setActivationState(DISABLE_DEACTIVATION);
        btRigidBody* body = w.add(cube->shape.get(), 1, btVector3(0, 0, 1.2), btVector3(0.5, 0.5, 0.5));
        body->setActivationState(DISABLE_DEACTIVATION);
        const double speed = 20; // 0.33 m per step: more than three slab thicknesses
        for (int i = 0; i < 30; ++i) {
            btTransform t;
            t.setIdentity();
            t.setOrigin(btVector3(0, 0, (btScalar)(speed * kDt * (i + 1))));
            platform->getMotionState()->setWorldTransform(t); // kinematic: the motion state drives it
            w.step();
            double gap = body->getCenterOfMassPosition().z() - 0.5 - (platform->getCenterOfMassPosition().z() + 0.05);
            worst_gap = std::min(worst_gap, gap);
            final_gap = gap;
            if (kVerbose)
                std::printf("  kinematic step %d: platform %.4f cube %.4f gap %.5f\n", i, platform->getCenterOfMassPosition().z(),
                            body->getCenterOfMassPosition().z(), gap);
        }
        stats = bridge.stats();
    }
    CHECK(stats.hits > 0, "no contact with the moving slab");
    CHECK(worst_gap >= -0.01, "the cube sank %.4f m into the rising slab", -worst_gap);
    CHECK(final_gap <= 0.05, "the cube is not riding on the slab (gap %.4f m)", final_gap);
    std::printf("kinematic slab at 20 m/s: cube-slab gap min %.5f m, final %.5f m, %lld queries\n", worst_gap, final_gap,
                (long long)stats.queries);
    sdfccd_destroy_sdf(slab);
}

// ---- a dynamic SDF body: an SDF ball at 100 m/s onto a static GImpact floor of two triangles ----

static void test_dynamic_sdf_on_mesh_floor()
{
    sdfccd_SdfId ball = { 0, 0 };
    CHECK(sdfccd_create_sphere(0.5, &ball) == SDFCCD_OK, "sphere");
    double z_after = NAN, z_final = NAN, v_final = NAN;
    int impact = -1;
    {
        Bridge bridge;
        World w;
        CHECK(bridge.registerWith(&w.world) == Status::Ok, "register");
        // The floor: a zero-thickness 10 m square (two counter-clockwise triangles facing +z).
        std::unique_ptr<TriMesh> floor(new TriMesh);
        const btScalar v[12] = { -5, -5, 0, 5, -5, 0, 5, 5, 0, -5, 5, 0 };
        const int f[6] = { 0, 1, 2, 0, 2, 3 };
        floor->v.assign(v, v + 12);
        floor->f.assign(f, f + 6);
        floor->finish();
        SdfShape shape(ball);
        w.add(floor->shape.get(), 0, btVector3(0, 0, 0));
        btRigidBody* body = w.add(&shape, 1, btVector3(0, 0, 4), btVector3(0.5, 0.5, 0.5));
        body->setLinearVelocity(btVector3(0, 0, -100)); // 1.67 m per step
        body->setActivationState(DISABLE_DEACTIVATION);
        for (int i = 0; i < 90; ++i) {
            w.step();
            if (impact < 0 && bridge.stats().hits > 0) {
                impact = i;
                z_after = body->getCenterOfMassPosition().z();
            }
        }
        z_final = body->getCenterOfMassPosition().z();
        v_final = body->getLinearVelocity().length();
    }
    CHECK(impact == 2, "impact in step %d, expected 2", impact);
    CHECK(std::fabs(z_after - 0.5) <= 1e-3, "z after the impact step %.5f, expected 0.5", z_after);
    CHECK(std::fabs(z_final - 0.5) <= 1e-3 && v_final < 0.05, "final z %.5f speed %.4f, expected resting at 0.5", z_final, v_final);
    std::printf("dynamic SDF ball on a GImpact floor: impact step %d, z after it %.5f, final z %.5f\n", impact, z_after, z_final);
    sdfccd_destroy_sdf(ball);
}

// ---- a GImpact mesh dropped into the concave box .cdf through Bullet's btSdfCollisionShape ----

static bool loadFile(const std::string& path, std::vector<char>& out)
{
    std::ifstream f(path, std::ios::binary);
    if (!f) return false;
    out.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    return !out.empty();
}

static void test_cdf_concave_box()
{
    std::vector<char> bytes;
    std::string path = std::string(SDFCCD_DATA_DIR) + "/sdf/concave_box_r32.cdf";
    if (!loadFile(path, bytes)) {
        CHECK(false, "cannot read %s", path.c_str());
        return;
    }
    btSdfCollisionShape cdf;
    CHECK(cdf.initializeSDF(bytes.data(), (int)bytes.size()), "btSdfCollisionShape::initializeSDF failed");
    // The tray is a 2 m x 2 m x 0.2 m plate (|z| <= 0.1) with a shallow dimple in the middle.
    // Find the top of its flat part at x = 0.5 (the first zero crossing of phi going down).
    btScalar d = 0;
    btVector3 n;
    double floor_z = NAN;
    double prev = NAN;
    for (int i = 0; i <= 1100; ++i) {
        double z = 0.55 - i * 0.001;
        if (!cdf.queryPoint(btVector3(0.5, 0, (btScalar)z), d, n)) continue;
        if (prev > 0 && d <= 0) {
            floor_z = z + 0.001 * (double)d / ((double)d - prev);
            break;
        }
        prev = d;
    }
    CHECK(std::fabs(floor_z - 0.1) < 0.01, "the tray's top at x = 0.5 is at z = %.4f, expected 0.1", floor_z);
    if (!std::isfinite(floor_z)) return;

    const btVector3 half(0.1, 0.1, 0.1);
    sdfccd_bullet::Stats stats;
    double worst = 1e9, final_z = 0, final_v = 0;
    int impact = -1;
    {
        Bridge bridge;
        World w;
        CHECK(bridge.registerWith(&w.world) == Status::Ok, "register");
        std::unique_ptr<TriMesh> cube = makeBox(half);
        w.add(&cdf, 0, btVector3(0, 0, 0));
        btRigidBody* body = w.add(cube->shape.get(), 1, btVector3(0.5, 0, 0.45), half);
        body->setLinearVelocity(btVector3(0, 0, -40)); // 0.67 m per step: three times the plate's thickness
        body->setActivationState(DISABLE_DEACTIVATION);
        for (int i = 0; i < 120; ++i) {
            w.step();
            double z = body->getCenterOfMassPosition().z();
            worst = std::min(worst, z - half.z() - floor_z);
            if (impact < 0 && bridge.stats().hits > 0) impact = i;
            if (kVerbose)
                std::printf("  cdf step %d: z %.4f vz %.3f queries %lld hits %lld errors %lld state %d toi %.3f\n", i, z,
                            body->getLinearVelocity().z(), (long long)bridge.stats().queries, (long long)bridge.stats().hits,
                            (long long)bridge.stats().query_errors, bridge.stats().last_state, bridge.stats().last_toi_fraction);
        }
        final_z = body->getCenterOfMassPosition().z();
        final_v = body->getLinearVelocity().length();
        stats = bridge.stats();
    }
    CHECK(impact >= 0, "no contact with the .cdf shape");
    CHECK(std::fabs(final_z - half.z() - floor_z) <= 0.01, "resting bottom at %.4f, floor at %.4f (tolerance 0.01 m, grid SDF)",
          final_z - half.z(), floor_z);
    CHECK(worst >= -0.01, "the cube went %.4f m below the floor", -worst);
    CHECK(final_v < 0.05, "not at rest: speed %.4f", final_v);
    std::printf("cdf concave box: floor at z = %.4f, cube bottom rests at %.4f (lowest %.4f), impact step %d, %lld queries\n",
                floor_z, final_z - half.z(), worst + floor_z, impact, (long long)stats.queries);
}

// ---- a convex box resting on our shape through the triangulation path; ray test ----

static void test_convex_box_on_triangulation()
{
    sdfccd_SdfId ground = makeBoxSdf(2, 2, 0.25);
    {
        Bridge bridge;
        World w;
        CHECK(bridge.registerWith(&w.world) == Status::Ok, "register");
        SdfShape shape(ground);
        shape.setTriangulationResolution(32);
        btBoxShape box(btVector3(0.2, 0.2, 0.2));
        w.add(&shape, 0, btVector3(0, 0, 0));
        btRigidBody* body = w.add(&box, 1, btVector3(0.3, -0.2, 1.0), btVector3(0.2, 0.2, 0.2));
        for (int i = 0; i < 180; ++i) w.step();
        CHECK(shape.getTriangulationTriangleCount() > 0, "no triangulation");
        double z = body->getCenterOfMassPosition().z();
        CHECK(std::fabs(z - 0.45) <= 0.005, "convex box rests at z %.5f, expected 0.45 +- 0.005", z);
        CHECK(body->getLinearVelocity().length() < 0.05, "convex box not at rest: %.4f m/s", body->getLinearVelocity().length());
        // A ray straight down hits the top face at z = 0.25.
        btVector3 from(-1.0, 1.0, 3.0), to(-1.0, 1.0, -3.0);
        btCollisionWorld::ClosestRayResultCallback ray(from, to);
        w.world.rayTest(from, to, ray);
        CHECK(ray.hasHit() && std::fabs(ray.m_hitPointWorld.z() - 0.25) < 1e-3, "ray test: hit %d at z %.5f", (int)ray.hasHit(),
              ray.hasHit() ? (double)ray.m_hitPointWorld.z() : NAN);
        std::printf("convex box on triangulation (%d triangles): rests at z = %.5f; ray hit z = %.5f\n",
                    shape.getTriangulationTriangleCount(), z, ray.hasHit() ? (double)ray.m_hitPointWorld.z() : NAN);
    }
    sdfccd_destroy_sdf(ground);
}

// ---- shape unit checks: AABB with local scaling, type id ----

static void test_shape_aabb()
{
    sdfccd_SdfId ball = { 0, 0 };
    CHECK(sdfccd_create_sphere(1.0, &ball) == SDFCCD_OK, "sphere");
    {
        SdfShape s(ball);
        CHECK(s.getShapeType() == FAST_CONCAVE_MESH_PROXYTYPE, "default type %d", s.getShapeType());
        CHECK(s.isConcave(), "not concave");
        SdfShape s2(ball, 27);
        CHECK(s2.getShapeType() == 27, "configured type %d", s2.getShapeType());
        s.setLocalScaling(btVector3(2, 3, 4));
        btTransform t;
        t.setIdentity();
        t.setOrigin(btVector3(10, 0, 0));
        btVector3 lo, hi;
        s.getAabb(t, lo, hi);
        CHECK((lo - btVector3(8, -3, -4)).length() < 1e-5 && (hi - btVector3(12, 3, 4)).length() < 1e-5,
              "scaled AABB (%g %g %g)-(%g %g %g)", lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
        // Rotated 90 degrees about z: x and y extents swap.
        t.setRotation(btQuaternion(btVector3(0, 0, 1), SIMD_HALF_PI));
        s.getAabb(t, lo, hi);
        CHECK(std::fabs(hi.x() - 13) < 1e-4 && std::fabs(hi.y() - 2) < 1e-4 && std::fabs(hi.z() - 4) < 1e-4,
              "rotated scaled AABB max (%g %g %g)", hi.x(), hi.y(), hi.z());
        // The query SDF carries the scaling: a uniformly scaled ball of radius 2.
        s.setLocalScaling(btVector3(2, 2, 2));
        double v = phiAt(s.querySdf(), btVector3(3, 0, 0));
        CHECK(std::fabs(v - 1.0) < 1e-9, "scaled sphere phi(3,0,0) = %g, expected 1", v);
        // Non-uniform: a lower bound of the stretched distance.
        s.setLocalScaling(btVector3(1, 1, 3));
        v = phiAt(s.querySdf(), btVector3(0, 0, 4));
        CHECK(v <= 1.0 + 1e-9 && v > 0, "stretched sphere phi(0,0,4) = %g, expected in (0, 1]", v);
    }
    sdfccd_destroy_sdf(ball);

    // An unbounded SDF (a half-space) has an infinite box and no triangulation until bounds are set.
    sdfccd_SdfId ground = { 0, 0 };
    sdfccd_Vec3 up = { 0, 0, 1 };
    CHECK(sdfccd_create_half_space(up, 0.0, &ground) == SDFCCD_OK, "half-space");
    {
        SdfShape s(ground);
        CHECK(!s.hasFiniteBounds(), "half-space bounds should be infinite");
        CHECK(s.buildTriangulation() == 0, "no triangulation without bounds");
        SdfShape t(ground);
        t.setLocalBounds(btVector3(-2, -2, -1), btVector3(2, 2, 0));
        btTransform id;
        id.setIdentity();
        btVector3 lo, hi;
        t.getAabb(id, lo, hi);
        CHECK(t.hasFiniteBounds() && (hi - btVector3(2, 2, 0)).length() < 1e-6, "bounded half-space AABB max (%g %g %g)", hi.x(), hi.y(),
              hi.z());
        CHECK(t.buildTriangulation() > 0, "bounded half-space triangulation");
    }
    sdfccd_destroy_sdf(ground);
}

// ---- registration: order, twice, too late; closest points; calculateTimeOfImpact ----

static void test_registration()
{
    {
        Bridge bridge;
        World w;
        CHECK(bridge.verify() == Status::NotRegistered, "verify before register");
        Status s = bridge.registerWith(&w.world);
        CHECK(s == Status::Ok, "register: %s", sdfccd_bullet::statusString(s));
        CHECK(bridge.verify() == Status::Ok, "verify after register");
        s = bridge.registerWith(&w.world);
        CHECK(s == Status::AlreadyRegistered, "second call: %s", sdfccd_bullet::statusString(s));
        Bridge other;
        s = other.registerWith(&w.world);
        CHECK(s == Status::AlreadyRegistered, "other bridge, same dispatcher: %s", sdfccd_bullet::statusString(s));
        // The wrong order: GImpact's registration after ours silently replaces it.
        btGImpactCollisionAlgorithm::registerAlgorithm(&w.dispatcher);
        s = bridge.verify();
        CHECK(s == Status::Overwritten, "wrong order not detected: %s", sdfccd_bullet::statusString(s));
        bridge.unregister();
        CHECK(bridge.verify() == Status::NotRegistered, "verify after unregister");
    }
    {
        // Too late: a GImpact body is already in the world.
        Bridge bridge;
        World w;
        std::unique_ptr<TriMesh> cube = makeBox(btVector3(0.5, 0.5, 0.5));
        w.add(cube->shape.get(), 1, btVector3(0, 0, 3), btVector3(0.5, 0.5, 0.5));
        Status s = bridge.registerWith(&w.world);
        CHECK(s == Status::TooLate, "too late not detected: %s", sdfccd_bullet::statusString(s));
        CHECK(bridge.verify() == Status::NotRegistered, "a refused registration must change nothing");
    }
    {
        // The algorithm object fits Bullet's collision-algorithm pool element.
        btDefaultCollisionConfiguration config;
        int element = config.getCollisionAlgorithmPool()->getElementSize();
        CHECK(sdfccd_bullet::collisionAlgorithmSize() <= (size_t)element, "algorithm %zu B, pool element %d B",
              sdfccd_bullet::collisionAlgorithmSize(), element);
        std::printf("collision algorithm %zu B, Bullet pool element %d B\n", sdfccd_bullet::collisionAlgorithmSize(), element);
    }
    {
        // A non-concave type id is refused.
        sdfccd_bullet::Config cfg;
        cfg.sdf_shape_type = BOX_SHAPE_PROXYTYPE;
        Bridge bridge(cfg);
        World w;
        CHECK(bridge.registerWith(&w.world) == Status::InvalidArgument, "convex type id accepted");
    }
}

struct CountContacts : public btCollisionWorld::ContactResultCallback {
    int n = 0;
    double dmin = 1e9, dmax = -1e9;
    btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*, int,
                             int) override
    {
        ++n;
        dmin = std::min(dmin, (double)cp.getDistance());
        dmax = std::max(dmax, (double)cp.getDistance());
        return 0;
    }
};

static void test_closest_points_and_toi()
{
    sdfccd_SdfId slab = makeBoxSdf(5, 5, 0.05);
    {
        Bridge bridge;
        World w;
        CHECK(bridge.registerWith(&w.world) == Status::Ok, "register");
        SdfShape shape(slab);
        std::unique_ptr<TriMesh> cube = makeBox(btVector3(0.5, 0.5, 0.5));
        btRigidBody* ground = w.add(&shape, 0, btVector3(0, 0, 0));
        btRigidBody* body = w.add(cube->shape.get(), 1, btVector3(0, 0, 0.549), btVector3(0.5, 0.5, 0.5)); // 1 mm deep
        CountContacts pair;
        pair.m_closestDistanceThreshold = 0.005;
        w.world.contactPairTest(body, ground, pair);
        CHECK(pair.n >= 3 && pair.n <= 4, "contactPairTest found %d points", pair.n);
        CHECK(pair.dmin >= -1.5e-3 && pair.dmax <= -0.5e-3, "contactPairTest distances [%.5f, %.5f], expected -0.001", pair.dmin,
              pair.dmax);
        CountContacts swapped; // the SDF as the first object of the query
        swapped.m_closestDistanceThreshold = 0.005;
        w.world.contactPairTest(ground, body, swapped);
        CHECK(swapped.n == pair.n && swapped.dmin >= -1.5e-3 && swapped.dmax <= -0.5e-3,
              "contactPairTest(sdf, mesh): %d points in [%.5f, %.5f]", swapped.n, swapped.dmin, swapped.dmax);
        CountContacts all;
        all.m_closestDistanceThreshold = 0.005;
        w.world.contactTest(body, all);
        CHECK(all.n == pair.n, "contactTest found %d points, contactPairTest %d", all.n, pair.n);

        // calculateTimeOfImpact: from z = 2 to z = -2 over the step; touching at z = 0.55.
        btTransform t0, t1;
        t0.setIdentity();
        t0.setOrigin(btVector3(0, 0, 2));
        t1.setIdentity();
        t1.setOrigin(btVector3(0, 0, -2));
        body->setWorldTransform(t0);
        body->setInterpolationWorldTransform(t1);
        double f = bridge.timeOfImpact(body, ground, 1.0);
        CHECK(std::fabs(f - 0.3625) < 1e-4, "timeOfImpact %.6f, expected 0.3625", f);
        // The same through the algorithm object the dispatcher creates (both orders).
        for (int order = 0; order < 2; ++order) {
            btCollisionObject* a = order ? (btCollisionObject*)ground : (btCollisionObject*)body;
            btCollisionObject* b = order ? (btCollisionObject*)body : (btCollisionObject*)ground;
            btCollisionObjectWrapper wa(nullptr, a->getCollisionShape(), a, a->getWorldTransform(), -1, -1);
            btCollisionObjectWrapper wb(nullptr, b->getCollisionShape(), b, b->getWorldTransform(), -1, -1);
            btCollisionAlgorithm* alg = w.dispatcher.findAlgorithm(&wa, &wb, nullptr, BT_CONTACT_POINT_ALGORITHMS);
            CHECK(alg != nullptr, "no algorithm");
            if (!alg) continue;
            btDispatcherInfo info;
            info.m_timeStep = 1.0;
            btManifoldResult result(&wa, &wb);
            double g = alg->calculateTimeOfImpact(a, b, info, &result);
            CHECK(std::fabs(g - 0.3625) < 1e-4, "calculateTimeOfImpact (order %d) %.6f", order, g);
            alg->~btCollisionAlgorithm();
            w.dispatcher.freeCollisionAlgorithm(alg);
        }
    }
    sdfccd_destroy_sdf(slab);
}

// ---- optional hard clamp: a bar tumbling fast onto the torus's tube ----

// The bar (0.8 m) hits the tube end first while spinning at 25 rad/s: the speculative contacts
// are linear, so without the clamp it pivots and ends some steps partly inside the tube.
static double runTumble(bool clamp, int* clamps)
{
    sdfccd_SdfId torus = { 0, 0 };
    CHECK(sdfccd_create_torus(1.0, 0.25, &torus) == SDFCCD_OK, "torus");
    const btVector3 half(0.4, 0.1, 0.1);
    double worst = 0;
    {
        Bridge bridge;
        World w;
        CHECK(bridge.registerWith(&w.world) == Status::Ok, "register");
        if (clamp) CHECK(bridge.setHardClamp(&w.world, true, 1e-3) == Status::Ok, "hard clamp on");
        SdfShape shape(torus);
        std::unique_ptr<TriMesh> bar = makeBox(half);
        w.add(&shape, 0, btVector3(0, 0, 0));
        btRigidBody* body = w.add(bar->shape.get(), 1, btVector3(1.0, 0, 3.0), half);
        body->setLinearVelocity(btVector3(0, 0, -60));
        body->setAngularVelocity(btVector3(0, 25, 0));
        body->setActivationState(DISABLE_DEACTIVATION);
        for (int i = 0; i < 60; ++i) {
            w.step();
            worst = std::max(worst, barPenetration(torus, body->getWorldTransform(), half));
        }
        *clamps = (int)bridge.stats().clamps;
        CHECK(bridge.hardClampEnabled() == clamp, "hardClampEnabled");
        if (clamp) CHECK(bridge.setHardClamp(&w.world, false) == Status::Ok, "hard clamp off");
    }
    sdfccd_destroy_sdf(torus);
    return worst;
}

static void test_hard_clamp()
{
    int clamps_off = 0, clamps_on = 0;
    double off = runTumble(false, &clamps_off);
    double on = runTumble(true, &clamps_on);
    CHECK(clamps_off == 0, "clamp corrections while off: %d", clamps_off);
    CHECK(clamps_on > 0, "the clamp never acted");
    // The clamp works on the mesh's triangles (the library's queries) while this measures sample
    // points on the bar, hence a little slack over the 1 mm tolerance.
    CHECK(on <= 2e-3, "with the hard clamp the deepest end-of-step penetration is %.5f m (tolerance 0.001)", on);
    std::printf("hard clamp: deepest end-of-step penetration %.5f m without, %.5f m with (%d corrections)\n", off, on, clamps_on);
}

// ---------------------------------------------------------------------------------------------
struct Test {
    const char* name;
    void (*fn)();
};
static const Test kTests[] = {
    { "cube_mesh_first", test_cube_mesh_first },
    { "cube_sdf_first", test_cube_sdf_first },
    { "cube_tunnels_without_bridge", test_cube_tunnels_without_bridge },
    { "torus_spinning", test_torus_spinning },
    { "kinematic_sdf", test_kinematic_sdf },
    { "dynamic_sdf_on_mesh_floor", test_dynamic_sdf_on_mesh_floor },
    { "cdf_concave_box", test_cdf_concave_box },
    { "convex_box_on_triangulation", test_convex_box_on_triangulation },
    { "shape_aabb", test_shape_aabb },
    { "registration", test_registration },
    { "closest_points_and_toi", test_closest_points_and_toi },
    { "hard_clamp", test_hard_clamp },
};

int main(int argc, char** argv)
{
    std::printf("sdfccd Bullet bridge tests, btScalar = %s\n", SDFCCD_BULLET_PRECISION_NAME);
    int ran = 0;
    for (const Test& t : kTests) {
        bool run = argc < 2;
        for (int i = 1; i < argc; ++i)
            if (std::strcmp(argv[i], t.name) == 0) run = true;
        if (!run) continue;
        int before = g_fail;
        t.fn();
        std::printf("[%s] %s\n", g_fail == before ? "ok" : "FAILED", t.name);
        ++ran;
    }
    if (ran == 0) {
        std::fprintf(stderr, "no test matched\n");
        return 2;
    }
    if (sdfccd_byte_count() != 0) {
        ++g_fail;
        std::fprintf(stderr, "FAIL: %lld bytes of sdfccd memory still allocated\n", (long long)sdfccd_byte_count());
    } else {
        ++g_pass;
    }
    std::printf("%d passed, %d failed\n", g_pass, g_fail);
    return g_fail == 0 ? 0 : 1;
}
