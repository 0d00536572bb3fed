// SPDX-License-Identifier: MIT
// The thin-body battery (issue 19, "Done when"): the data set's 4 mm shuriken
// (samples/report/dataset/shuriken.obj, 446 vertices, 72 mm across) as a 50 g btGImpactMeshShape
// body, shot at 100-500 m/s into 1 cm walls and 1-2 cm spherical shells, at oblique incidence from
// 0 to 80 degrees, in a random orientation, spinning about its own axis or tumbling at up to
// 200 rad/s. The targets are an analytic box wall, a CSG shell (the difference of two spheres) and
// a grid wall baked here from the analytic wall (sdfccd_create_grid_from_sdf). Through the bridge
// with Config() defaults every shot must stop: no pass-through and no point of the body deeper
// than 1 mm at the end of any step, measured at every vertex and at a lattice of points on every
// face against the exact (analytic) SDF. The same shots with stock Bullet (GImpact against the
// SDF's isosurface as a btBvhTriangleMeshShape) must pass through in some shots, so the battery is
// proven hard. Seeded (std::mt19937 with its own mapping to numbers: the same shots everywhere).
// Usage: thin_body_battery [shots-per-target]; prints one line per failed check, every shot with
// SDFCCD_TEST_VERBOSE, and the figures.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include "sdfccd_bullet/sdfccd_bullet.h"
#include "bullet_check.h"

#ifndef SDFCCD_SHURIKEN_OBJ
#error "SDFCCD_SHURIKEN_OBJ must be defined (path of samples/report/dataset/shuriken.obj)"
#endif

using sdfccd_bullet::Bridge;
using sdfccd_bullet::SdfShape;
using sdfccd_bullet::Status;


static const double kDt = 1.0 / 60.0;
static const double kMass = 0.05;
static const double kMaxPenetration = 1e-3;
static const int kSteps = 6;       // the impact comes in the first step; five more after it
static const int kLattice = 3;     // face points: barycentric lattice with 3 divisions per edge

// ---- the shuriken ----
struct Shuriken {
    std::vector<btScalar> v;  // x, y, z per vertex (metres, centred at the origin, thickness along z)
    std::vector<int> f;       // three vertex indices per triangle
    std::vector<btVector3> probes; // vertices and face lattice points (local frame)
    double radius = 0;
};

static bool loadShuriken(Shuriken& s)
{
    std::ifstream in(SDFCCD_SHURIKEN_OBJ);
    std::string line;
    while (in && std::getline(in, line)) {
        std::istringstream ls(line);
        std::string tag;
        ls >> tag;
        if (tag == "v") {
            double x, y, z;
            ls >> x >> y >> z;
            s.v.push_back((btScalar)x);
            s.v.push_back((btScalar)y);
            s.v.push_back((btScalar)z);
            s.radius = std::max(s.radius, std::sqrt(x * x + y * y + z * z));
        } else if (tag == "f") {
            for (int k = 0; k < 3; ++k) {
                std::string w;
                ls >> w;
                s.f.push_back(std::atoi(w.c_str()) - 1);
            }
        }
    }
    if (s.v.empty() || s.f.empty()) return false;
    for (size_t i = 0; i < s.f.size(); i += 3) {
        btVector3 a(s.v[3 * s.f[i]], s.v[3 * s.f[i] + 1], s.v[3 * s.f[i] + 2]);
        btVector3 b(s.v[3 * s.f[i + 1]], s.v[3 * s.f[i + 1] + 1], s.v[3 * s.f[i + 1] + 2]);
        btVector3 c(s.v[3 * s.f[i + 2]], s.v[3 * s.f[i + 2] + 1], s.v[3 * s.f[i + 2] + 2]);
        // Interior and edge lattice points (the corners are the vertices, added below once).
        for (int p = 0; p <= kLattice; ++p)
            for (int q = 0; p + q <= kLattice; ++q) {
                const int r = kLattice - p - q;
                if (p == kLattice || q == kLattice || r == kLattice) continue;
                s.probes.push_back((a * (btScalar)p + b * (btScalar)q + c * (btScalar)r) / (btScalar)kLattice);
            }
    }
    for (size_t i = 0; i < s.v.size(); i += 3) s.probes.push_back(btVector3(s.v[i], s.v[i + 1], s.v[i + 2]));
    return true;
}

// ---- targets ----
struct Target {
    const char* name;
    sdfccd_SdfId exact;    // the analytic SDF penetration is measured against
    sdfccd_SdfId collide;  // the SDF the bridge collides with (the grid for the grid wall)
    double thickness;
    btVector3 hit;         // a point on the surface the shots aim at, and the outward normal there
    btVector3 normal;
    sdfccd_Aabb mesh_box;  // where the stock run's isosurface is extracted
    int mesh_resolution;
};

static sdfccd_SdfId boxSdf(double hx, double hy, double hz)
{
    sdfccd_SdfId id = { 0, 0 };
    sdfccd_Vec3 h = { hx, hy, hz };
    CHECK(sdfccd_create_box(h, &id) == SDFCCD_OK, "box: %s", sdfccd_last_error());
    return id;
}

// A shell: the sphere of radius R minus the sphere of radius R - t, centred at the origin.
static sdfccd_SdfId shellSdf(double R, double t)
{
    sdfccd_SdfId outer = { 0, 0 }, inner = { 0, 0 }, shell = { 0, 0 };
    CHECK(sdfccd_create_sphere(R, &outer) == SDFCCD_OK && sdfccd_create_sphere(R - t, &inner) == SDFCCD_OK, "spheres: %s",
          sdfccd_last_error());
    CHECK(sdfccd_create_csg(SDFCCD_CSG_DIFFERENCE, outer, inner, &shell) == SDFCCD_OK, "csg: %s", sdfccd_last_error());
    sdfccd_destroy_sdf(outer);
    sdfccd_destroy_sdf(inner);
    return shell;
}

static double phiAt(sdfccd_SdfId sdf, const btVector3& p)
{
    sdfccd_Vec3 q = { (double)p.x(), (double)p.y(), (double)p.z() };
    double v = 0;
    sdfccd_Status st = sdfccd_sdf_eval(sdf, q, &v, nullptr);
    CHECK(st == SDFCCD_OK && std::isfinite(v), "phi at (%g %g %g): %s", q.x, q.y, q.z, sdfccd_last_error());
    return st == SDFCCD_OK && std::isfinite(v) ? v : -INFINITY;
}

// Deepest penetration (>= 0) of the body's probe points at pose t (the SDF sits at the origin).
static double penetration(const Shuriken& s, sdfccd_SdfId sdf, const btTransform& t, std::vector<sdfccd_Vec3>& pts, std::vector<double>& phi)
{
    pts.resize(s.probes.size());
    phi.resize(s.probes.size());
    for (size_t i = 0; i < s.probes.size(); ++i) {
        const btVector3 p = t * s.probes[i];
        pts[i].x = (double)p.x();
        pts[i].y = (double)p.y();
        pts[i].z = (double)p.z();
    }
    sdfccd_Status st = sdfccd_sdf_eval_batch(sdf, pts.data(), (int32_t)pts.size(), phi.data(), nullptr);
    CHECK(st == SDFCCD_OK, "sdf_eval_batch: %s", sdfccd_last_error());
    if (st != SDFCCD_OK) return INFINITY;
    double worst = 0;
    for (double v : phi) worst = std::max(worst, std::isfinite(v) ? -v : INFINITY);
    return worst;
}

// Smallest phi along the segment a-b down to `floor` (sphere tracing: phi is 1-Lipschitz). Used
// on the body's centre: phi < -0.4 x thickness (the middle fifth of the material; a stopped
// shuriken's centre is at least about 1 mm out of the surface) means the body went through.
static double minPhiOnSegment(sdfccd_SdfId sdf, const btVector3& a, const btVector3& b, double floor)
{
    const double len = (double)(b - a).length();
    double lo = INFINITY;
    for (double s = 0;;) {
        const btVector3 p = len > 0 ? a + (b - a) * (btScalar)(s / len) : a;
        const double f = phiAt(sdf, p);
        lo = std::min(lo, f);
        if (f < floor || s >= len) break;
        s = std::min(len, s + std::max(f - floor, 1e-4));
    }
    return lo;
}

// ---- shots ----
struct Shot {
    int target;
    double speed, incidence_deg, spin;
    bool tumbling;
    btQuaternion orientation;
    btVector3 dir, start, angular;
};

// Uniform double in [0, 1) from the generator's raw output (std's distributions differ between
// standard libraries; this mapping does not).

static Shot makeShot(std::mt19937& g, int target, const Target& T)
{
    Shot s;
    s.target = target;
    s.speed = 100 + 400 * uniform01(g);
    s.incidence_deg = 80 * uniform01(g);
    // A uniformly random orientation (Shoemake's method).
    const double u1 = uniform01(g), u2 = uniform01(g), u3 = uniform01(g);
    s.orientation = btQuaternion((btScalar)(std::sqrt(1 - u1) * std::sin(2 * M_PI * u2)), (btScalar)(std::sqrt(1 - u1) * std::cos(2 * M_PI * u2)),
                                 (btScalar)(std::sqrt(u1) * std::sin(2 * M_PI * u3)), (btScalar)(std::sqrt(u1) * std::cos(2 * M_PI * u3)));
    s.orientation.normalize();
    s.tumbling = uniform01(g) < 0.5;
    s.spin = 200 * uniform01(g);
    btVector3 axis = btVector3(0, 0, 1);
    if (s.tumbling) {
        const double z = 2 * uniform01(g) - 1, a = 2 * M_PI * uniform01(g), r = std::sqrt(std::max(0.0, 1 - z * z));
        axis = btVector3((btScalar)(r * std::cos(a)), (btScalar)(r * std::sin(a)), (btScalar)z);
    } else {
        axis = btMatrix3x3(s.orientation) * axis; // about the shuriken's own axis
    }
    s.angular = axis * (btScalar)s.spin;
    // Direction: into the surface, at the incidence angle from its inward normal, in a random plane.
    const btVector3 n = T.normal;
    btVector3 t1, t2;
    btPlaneSpace1(n, t1, t2);
    const double az = 2 * M_PI * uniform01(g), th = s.incidence_deg * M_PI / 180;
    const btVector3 tangent = t1 * (btScalar)std::cos(az) + t2 * (btScalar)std::sin(az);
    s.dir = (-n * (btScalar)std::cos(th) + tangent * (btScalar)std::sin(th)).normalized();
    // The centre starts clear of the surface (by more than the body's radius) and reaches the aim
    // point within the first step.
    const double reach = s.speed * kDt * (0.3 + 0.6 * uniform01(g));
    const double dist = std::max(reach, (0.05 + 1.1 * T.thickness + 0.04) / std::max(0.17, std::cos(th)));
    s.start = T.hit - s.dir * (btScalar)dist;
    return s;
}

struct Outcome {
    bool crossed = false;
    double max_pen = 0;
    int first_deep_step = -1;
};

// One shot in a fresh world. `ground`: the collision shape of the target (an SdfShape, or the
// stock run's triangle mesh); `bridge`: register the bridge with Config() defaults.
static Outcome fire(const Shuriken& sh, btGImpactMeshShape* mesh, btCollisionShape* ground, const Target& T, const Shot& s, bool bridge_on,
                    sdfccd_bullet::Stats* stats)
{
    Outcome o;
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
    world.setGravity(btVector3(0, 0, -9.81));
    std::unique_ptr<Bridge> bridge;
    if (bridge_on) {
        bridge.reset(new Bridge());
        CHECK(bridge->registerWith(&world) == Status::Ok, "register");
    } else {
        btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
    }
    btTransform id;
    id.setIdentity();
    btRigidBody::btRigidBodyConstructionInfo gci(0, nullptr, ground, btVector3(0, 0, 0));
    gci.m_startWorldTransform = id;
    btRigidBody wall(gci);
    world.addRigidBody(&wall);
    // A thin disk's inertia (radius of the shuriken's blades).
    const double r = sh.radius;
    const btVector3 inertia((btScalar)(0.25 * kMass * r * r), (btScalar)(0.25 * kMass * r * r), (btScalar)(0.5 * kMass * r * r));
    btTransform start(s.orientation, s.start);
    btRigidBody::btRigidBodyConstructionInfo bci((btScalar)kMass, nullptr, mesh, inertia);
    bci.m_startWorldTransform = start;
    btRigidBody body(bci);
    body.setLinearVelocity(s.dir * (btScalar)s.speed);
    body.setAngularVelocity(s.angular);
    body.setActivationState(DISABLE_DEACTIVATION);
    world.addRigidBody(&body);
    std::vector<sdfccd_Vec3> pts;
    std::vector<double> phi;
    for (int step = 0; step < kSteps; ++step) {
        const btVector3 c0 = body.getWorldTransform().getOrigin();
        world.stepSimulation((btScalar)kDt, 1, (btScalar)kDt);
        const btVector3 c1 = body.getWorldTransform().getOrigin();
        if (minPhiOnSegment(T.exact, c0, c1, -0.4 * T.thickness) < -0.4 * T.thickness) o.crossed = true;
        const double pen = penetration(sh, T.exact, body.getWorldTransform(), pts, phi);
        if (pen > kMaxPenetration && o.first_deep_step < 0) o.first_deep_step = step;
        if (std::getenv("SDFCCD_BATTERY_TRACE"))
            std::printf("    step %d: centre (%.4f %.4f %.4f) v (%.2f %.2f %.2f) w %.1f, deepest %.5f m%s\n", step, (double)c1.x(), (double)c1.y(),
                        (double)c1.z(), (double)body.getLinearVelocity().x(), (double)body.getLinearVelocity().y(),
                        (double)body.getLinearVelocity().z(), (double)body.getAngularVelocity().length(), pen,
                        bridge ? (" rollbacks " + std::to_string(bridge->stats().rollbacks)).c_str() : "");
        o.max_pen = std::max(o.max_pen, pen);
    }
    if (bridge) *stats = bridge->stats();
    world.removeRigidBody(&body);
    world.removeRigidBody(&wall);
    return o;
}

int main(int argc, char** argv)
{
    std::printf("thin-body battery, btScalar = %s\n", SDFCCD_BULLET_PRECISION_NAME);
    const int per_target = argc > 1 ? std::max(1, std::atoi(argv[1])) : 16;
    Shuriken sh;
    CHECK(loadShuriken(sh), "could not read %s", SDFCCD_SHURIKEN_OBJ);
    if (g_fail) return 1;
    btTriangleIndexVertexArray tiva((int)sh.f.size() / 3, sh.f.data(), 3 * (int)sizeof(int), (int)sh.v.size() / 3, sh.v.data(),
                                    3 * (int)sizeof(btScalar));
    btGImpactMeshShape mesh(&tiva);
    mesh.updateBound();

    // Targets: a 1 cm analytic wall (x = +-5 mm), a CSG shell of radius 0.25 m and 1.5 cm, a second
    // one of 1 cm and 2 cm... (thickness per target below), and the grid of the analytic wall.
    std::vector<Target> targets;
    const double hx = 0.005;
    sdfccd_SdfId wall = boxSdf(hx, 2.0, 2.0);
    {
        Target t = { "analytic wall", wall, wall, 2 * hx, btVector3((btScalar)hx, 0, 0), btVector3(1, 0, 0),
                     { { -0.02, -0.2, -0.2 }, { 0.02, 0.2, 0.2 } }, 100 };
        targets.push_back(t);
    }
    const double shell_t[2] = { 0.01, 0.02 };
    std::vector<sdfccd_SdfId> shells;
    for (double th : shell_t) {
        const double R = 0.25;
        shells.push_back(shellSdf(R, th));
        Target t = { th < 0.015 ? "CSG shell 1 cm" : "CSG shell 2 cm", shells.back(), shells.back(), th,
                     btVector3((btScalar)R, 0, 0), btVector3(1, 0, 0), { { -0.26, -0.26, -0.26 }, { 0.26, 0.26, 0.26 } }, 130 };
        targets.push_back(t);
    }
    // The grid: the analytic wall (2 m x 2 m here) sampled on a small grid whose cell walls fall
    // on the wall's mid-plane (x = 0), so the cubic cells next to each face hold a linear field.
    sdfccd_SdfId grid_src = boxSdf(hx, 1.0, 1.0), grid = { 0, 0 };
    {
        sdfccd_GridDef def = sdfccd_default_grid_def();
        def.resolution[0] = 6;
        def.resolution[1] = 16;
        def.resolution[2] = 16;
        def.fit_domain = 0;
        def.domain.lo.x = -0.045;
        def.domain.hi.x = 0.045;
        def.domain.lo.y = def.domain.lo.z = -1.04;
        def.domain.hi.y = def.domain.hi.z = 1.04;
        def.threads = 1;
        CHECK(sdfccd_create_grid_from_sdf(grid_src, &def, &grid) == SDFCCD_OK, "grid: %s", sdfccd_last_error());
        Target t = { "grid wall", grid_src, grid, 2 * hx, btVector3((btScalar)hx, 0, 0), btVector3(1, 0, 0),
                     { { -0.02, -0.2, -0.2 }, { 0.02, 0.2, 0.2 } }, 100 };
        targets.push_back(t);
    }

    std::mt19937 gen(20261126u);
    std::vector<Shot> shots;
    for (size_t t = 0; t < targets.size(); ++t)
        for (int i = 0; i < per_target; ++i) shots.push_back(makeShot(gen, (int)t, targets[t]));

    // ---- through the bridge, Config() defaults ----
    int crossed = 0, deep = 0;
    double worst = 0;
    int64_t query_errors = 0, hits = 0;
    const char* only = std::getenv("SDFCCD_BATTERY_SHOT");
    for (size_t i = 0; i < shots.size(); ++i) {
        if (only && std::atoi(only) != (int)i) continue;
        const Shot& s = shots[i];
        const Target& T = targets[s.target];
        SdfShape shape(T.collide);
        sdfccd_bullet::Stats st;
        const Outcome o = fire(sh, &mesh, &shape, T, s, true, &st);
        query_errors += st.query_errors;
        hits += st.hits;
        crossed += o.crossed;
        deep += o.max_pen > kMaxPenetration;
        worst = std::max(worst, o.max_pen);
        if (kVerbose || o.crossed || o.max_pen > kMaxPenetration)
            std::printf("  bridge shot %3zu %-15s %5.1f m/s incidence %4.1f deg %s %6.1f rad/s: %s, deepest %.5f m (first over 1 mm at step %d)\n", i,
                        T.name, s.speed, s.incidence_deg, s.tumbling ? "tumbling" : "axial   ", s.spin, o.crossed ? "THROUGH" : "stopped",
                        o.max_pen, o.first_deep_step);
    }
    std::printf("bridge (%s): %zu shots, %d through, %d deeper than 1 mm, deepest %.5f m, %lld pair-steps with contact\n",
                SDFCCD_BULLET_PRECISION_NAME, shots.size(), crossed, deep, worst, (long long)hits);
    CHECK(crossed == 0, "%d of %zu shots went through with the bridge", crossed, shots.size());
    CHECK(worst <= kMaxPenetration, "deepest penetration %.5f m (limit %.3f), %d shots over", worst, kMaxPenetration, deep);
    CHECK(query_errors == 0, "%lld bridge queries failed", (long long)query_errors);
    CHECK(hits > 0, "the bridge never saw a contact");

    // ---- stock Bullet: GImpact against the isosurface as a triangle mesh (one shot in two) ----
    int stock_crossed = 0, stock_shots = 0;
    for (size_t t = 0; t < targets.size(); ++t) {
        const Target& T = targets[t];
        sdfccd_MeshId iso = { 0, 0 };
        CHECK(sdfccd_extract_isosurface(T.exact, T.mesh_box, T.mesh_resolution, &iso) == SDFCCD_OK, "isosurface of %s: %s", T.name,
              sdfccd_last_error());
        sdfccd_MeshInfo info;
        CHECK(sdfccd_mesh_get_info(iso, &info) == SDFCCD_OK, "mesh info: %s", sdfccd_last_error());
        std::vector<double> vd((size_t)info.vertex_count * 3);
        std::vector<uint32_t> fi((size_t)info.triangle_count * 3);
        CHECK(sdfccd_mesh_get_data(iso, vd.data(), fi.data()) == SDFCCD_OK, "mesh arrays: %s", sdfccd_last_error());
        sdfccd_destroy_mesh(iso);
        std::vector<btScalar> vs(vd.begin(), vd.end());
        std::vector<int> is(fi.begin(), fi.end());
        btTriangleIndexVertexArray arr((int)is.size() / 3, is.data(), 3 * (int)sizeof(int), (int)vs.size() / 3, vs.data(),
                                       3 * (int)sizeof(btScalar));
        btBvhTriangleMeshShape tri(&arr, true);
        for (size_t i = 0; i < shots.size(); i += 2) {
            if (shots[i].target != (int)t) continue;
            const Outcome o = fire(sh, &mesh, &tri, T, shots[i], false, nullptr);
            ++stock_shots;
            stock_crossed += o.crossed;
            if (kVerbose)
                std::printf("  stock shot %3zu %-15s: %s, deepest %.5f m\n", i, T.name, o.crossed ? "THROUGH" : "stopped", o.max_pen);
        }
    }
    std::printf("stock Bullet (%s, GImpact vs isosurface mesh): %d of %d shots through\n", SDFCCD_BULLET_PRECISION_NAME, stock_crossed,
                stock_shots);
    CHECK(stock_crossed > 0, "stock Bullet stopped all %d shots: the battery is not hard", stock_shots);

    sdfccd_destroy_sdf(wall);
    for (sdfccd_SdfId s : shells) sdfccd_destroy_sdf(s);
    sdfccd_destroy_sdf(grid_src);
    sdfccd_destroy_sdf(grid);
    if (sdfccd_byte_count() != 0) {
        ++g_fail;
        std::fprintf(stderr, "FAIL: %lld bytes of sdfccd memory still allocated\n", (long long)sdfccd_byte_count());
    }
    return checkSummary();
}
