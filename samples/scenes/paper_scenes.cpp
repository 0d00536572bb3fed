// SPDX-License-Identifier: MIT
// The paper's experiments (Pelletier-Guenette et al., SCA 2025, Section 5.1, Figs 1, 2, 5-8,
// 10-12) as rigid Bullet scenes with the bridge, and kinematic scenes through the C ABI.
// Metres and seconds, Z up, g = -9.81, 60 steps per second; each scene models no more than it needs.
//
//  shuriken        the data set's 888-triangle shuriken (10 cm) thrown edge-on at 500 m/s, spinning
//                  30 rad/s, into an implicit breastplate: a 2 cm spherical shell (R 0.6 m) cut by a
//                  box (CSG). Fig. 1. A centre path through the shell's material counts as tunnelled.
//  skateboard      a deck-and-wheels mesh (5 boxes, 60 triangles) sliding down a 20 degree analytic
//                  ramp onto a rail (a 2.5 cm capsule) over the ground (three static SDF bodies). Fig. 5.
//  pyramids        two coarse pyramids (6 triangles, data/meshes/pyramid.obj) dropped from 1 m onto
//                  an analytic box, one apex down. Fig. 6.
//  bunny           the bunny (bunny.obj x0.25, 50 cm) dropped onto a grid SDF baked from the torus
//                  mesh (torus_textured.obj, 64^3 grid: at 32^3 its error near the contacts was 1 mm, the
//                  margin itself), measured against the exact mesh distance. Fig. 7.
//  hoop            a square hoop (box minus box as 4 bars, 2 cm thick) whose hole (0.996 m) is the
//                  diameter of an analytic sphere (1 m) less 4 mm, so it must stop on it, dropped
//                  from 3 m above the equator (13 cm per step there; the overlap window is about
//                  8 cm tall). Going past the equator by 30 cm counts as tunnelled. Fig. 8.
//  spikes          a coarse 12-triangle 0.5 m box onto the spike grid (faces measured on a lattice
//                  of 231 points each); run with --no-subdivision for the paper's failing case. Fig. 10.
//  triangle-flat   one 0.5 m triangle falling flat on an analytic box (lattice-measured). Fig. 11.
// Kinematic (the C ABI, no Bullet; the body is driven with a commanded velocity every step and
// stops at the reported time of impact; penetration is also sampled INSIDE each step along the
// executed motion):
//  torus-crossings a sphere mesh (r 2 cm, 320 triangles) pushed rightward at 36 m/s (0.6 m per
//                  step) through a 30 cm torus: one step crosses its surface four times. Fig. 2.
//  spin360         the pyramid turning 360 degrees in one step about a horizontal axis, its base
//                  1 cm above a box (Bullet clamps rotation per step, so this is the C ABI). Fig. 12.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "bullet_scene.h"
#include "scenes.h"

namespace scenes {

namespace {

const double kPi = 3.14159265358979323846;
const double kG = 9.81;
// The scenes run the bridge's Config(). The paper's response rule (Section 4, after Eq. 12: the
// simulation does not advance past a time of impact) is the bridge's guarantee, on by default
// (--guard 0 turns it off, --guard T sets its tolerance; off with the DCD baseline).

// Appends an axis-aligned box (half extents h, centre c) to v/f, triangles counter-clockwise outward.
void appendBox(std::vector<double>& v, std::vector<uint32_t>& f, const double* h, const double* c)
{
    uint32_t base = (uint32_t)(v.size() / 3);
    for (int i = 0; i < 8; ++i)
        for (int k = 0; k < 3; ++k) v.push_back(c[k] + ((i >> k & 1) ? h[k] : -h[k]));
    const uint32_t t[36] = { 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5 };
    for (uint32_t i : t) f.push_back(base + i);
}

sdfccd_Pose poseOf(double x, double y, double z, const btQuaternion& q)
{
    sdfccd_Pose p;
    p.position = sdfccd_Vec3{ x, y, z };
    p.orientation = sdfccd_Quat{ (double)q.w(), (double)q.x(), (double)q.y(), (double)q.z() };
    return p;
}

// Small CSG builder whose intermediate handles are owned by the scene.
struct Csg {
    BulletScene* s;
    sdfccd_SdfId box(double hx, double hy, double hz)
    {
        sdfccd_SdfId id{};
        sdfccd_create_box(sdfccd_Vec3{ hx, hy, hz }, &id);
        return s->own(id);
    }
    sdfccd_SdfId sphere(double r)
    {
        sdfccd_SdfId id{};
        sdfccd_create_sphere(r, &id);
        return s->own(id);
    }
    sdfccd_SdfId at(sdfccd_SdfId child, double x, double y, double z, const btQuaternion& q = btQuaternion::getIdentity())
    {
        sdfccd_SdfId id{};
        sdfccd_create_transformed(child, poseOf(x, y, z, q), 1, &id);
        return s->own(id);
    }
    sdfccd_SdfId op(sdfccd_CsgOp o, sdfccd_SdfId a, sdfccd_SdfId b)
    {
        sdfccd_SdfId id{};
        sdfccd_create_csg(o, a, b, &id);
        return s->own(id);
    }
};

// The ground: a box with its top at z = top.
Collider& addGround(BulletScene& s, double top, double half = 3)
{
    sdfccd_SdfId g{};
    sdfccd_create_box(sdfccd_Vec3{ half, half, 0.25 }, &g);
    Collider& c = s.addStaticSdf("ground", g, btVector3(0, 0, (btScalar)(top - 0.25)), btQuaternion::getIdentity(),
                                 sdfccd_Aabb{ { -half - 0.1, -half - 0.1, -0.35 }, { half + 0.1, half + 0.1, 0.35 } }, 64, g);
    c.killBelow(s.up, top - 0.25);
    return c;
}

class PaperScene : public BulletScene {
public:
    explicit PaperScene(const Options& opt) : BulletScene(opt, btVector3(0, 0, (btScalar)-kG), 2) {}
};

// ---------------------------------------------------------------------------------------------
class Shuriken : public PaperScene {
public:
    using PaperScene::PaperScene;
    bool build()
    {
        std::shared_ptr<MeshData> m = loadDataMesh(options(), "../samples/report/dataset/shuriken.obj", 1, "shuriken");
        if (!m) return false;
        Csg c{ this };
        sdfccd_SdfId shell = c.op(SDFCCD_CSG_DIFFERENCE, c.sphere(0.6), c.sphere(0.58));
        sdfccd_SdfId plate = c.op(SDFCCD_CSG_INTERSECTION, shell, c.at(c.box(0.15, 0.3, 0.35), -0.5, 0, 0));
        Collider& col = addStaticSdf("breastplate", plate, btVector3(0.6f, 0, 1), btQuaternion::getIdentity(),
                                     sdfccd_Aabb{ { -0.66, -0.32, -0.37 }, { -0.3, 0.32, 0.37 } }, 96, plate);
        // Through the plate: the centre's path over a step passes through the shell's material
        // (the shuriken may also bounce off the ground, pass under the plate's edge and fly up
        // behind it: that is not tunnelling).
        col.kill_swept = true;
        addGround(*this, 0, 5);
        btRigidBody* b = addMeshBody(m, 0.1, btVector3(-4, 0, 1));
        b->setLinearVelocity(btVector3(500, 0, 0));
        b->setAngularVelocity(btVector3(0, 0, 30));
        b->setActivationState(DISABLE_DEACTIVATION);
        view = sdfccd_Aabb{ { -0.3, -0.4, 0.6 }, { 0.5, 0.4, 1.4 } };
        return true;
    }
};

// ---------------------------------------------------------------------------------------------
class Skateboard : public PaperScene {
public:
    using PaperScene::PaperScene;
    bool build()
    {
        std::vector<double> v;
        std::vector<uint32_t> f;
        const double deck[3] = { 0.4, 0.1, 0.01 }, dc[3] = { 0, 0, 0.05 };
        appendBox(v, f, deck, dc);
        const double wheel[3] = { 0.03, 0.025, 0.02 };
        for (int i = 0; i < 4; ++i) {
            const double wc[3] = { i & 1 ? 0.3 : -0.3, i & 2 ? 0.07 : -0.07, 0.02 };
            appendBox(v, f, wheel, wc);
        }
        for (size_t i = 2; i < v.size(); i += 3) v[i] -= 0.03; // body frame at the centre of the mesh's box
        std::shared_ptr<MeshData> board = makeMesh("skateboard", v, f);
        Csg c{ this };
        const double th = 20 * kPi / 180;
        sdfccd_SdfId ramp = c.at(c.box(1.2, 0.4, 0.05), 0, 0, 0.6, axisAngle(0, 1, 0, th));
        sdfccd_SdfId capsule{};
        sdfccd_create_capsule(0.6, 0.025, &capsule);
        own(capsule);
        sdfccd_SdfId rail = c.at(capsule, 1.95, 0, 0.2, axisAngle(0, 1, 0, kPi / 2));
        sdfccd_SdfId ground = c.at(c.box(4, 4, 0.25), 0, 0, -0.25);
        // Three static bodies, as in a scene built from objects: each pair gets its own manifold
        // (one CSG union of the three was one pair: the wheels on the ramp and the deck on the
        // rail shared 8 contact points, and the rear wheels dipped 15 mm into the ramp's edge).
        addStaticSdf("ramp", ramp, btVector3(0, 0, 0), btQuaternion::getIdentity(), sdfccd_Aabb{ { -1.3, -0.5, 0.05 }, { 1.3, 0.5, 1.15 } },
                     96, ramp);
        addStaticSdf("rail", rail, btVector3(0, 0, 0), btQuaternion::getIdentity(), sdfccd_Aabb{ { 1.25, -0.1, 0.1 }, { 2.65, 0.1, 0.3 } },
                     128, rail);
        Collider& g = addStaticSdf("ground", ground, btVector3(0, 0, 0), btQuaternion::getIdentity(),
                                   sdfccd_Aabb{ { -4.1, -4.1, -0.6 }, { 4.1, 4.1, 0.1 } }, 32, ground);
        g.killBelow(up, -0.1);
        // Start 0.3 m up the slope from the ramp's low end, aligned with the slope, 5 cm above it
        // (it lands on the ramp first: Table 4 measures up to that first contact).
        const double s = 0.9, lift = 0.05 + 0.03 + 0.05; // local x on the ramp's top face; height above its centre plane
        btVector3 pos((btScalar)(s * std::cos(th) + lift * std::sin(th)), 0, (btScalar)(0.6 - s * std::sin(th) + lift * std::cos(th)));
        btRigidBody* b = addMeshBody(board, 2, pos, axisAngle(0, 1, 0, th));
        b->setFriction(0.05f);
        b->setActivationState(DISABLE_DEACTIVATION);
        // The board comes to rest on the ramp's edge, the rail and the ground at once (about 20
        // contacts on three pairs) with friction 0.05: Bullet's default 10 sequential-impulse
        // iterations leave it creeping about 1 mm/s, by an amount that changes with any harmless
        // perturbation (FWGSS, float: hard clamp 0.5 / 1 / 0.3 mm gave a rest drift of 0.76 / 1.31
        // / 1.36 mm over the last second; 20 iterations 0.56-1.28 mm). Like the paper's simulator,
        // which solves its contacts, it gets 50 iterations: drift 0.13-0.22 mm over the same
        // perturbations and precisions (--solver-iterations N overrides).
        if (options().solver_iterations <= 0) world()->getSolverInfo().m_numIterations = 50;
        view = sdfccd_Aabb{ { 0.3, -0.6, -0.1 }, { 2.4, 0.6, 0.9 } };
        return true;
    }
};

// ---------------------------------------------------------------------------------------------
class Pyramids : public PaperScene {
public:
    using PaperScene::PaperScene;
    bool build()
    {
        std::shared_ptr<MeshData> m = loadDataMesh(options(), "meshes/pyramid.obj", 1, "pyramid");
        if (!m) return false;
        m->finish(12);
        Collider& g = addGround(*this, 0, 1);
        (void)g;
        btRigidBody* a = addMeshBody(m, 1, btVector3(-0.25f, 0, 1), axisAngle(1, 0, 0, kPi)); // apex down
        btRigidBody* b = addMeshBody(m, 1, btVector3(0.25f, 0, 1), axisAngle(1, 0.5, 0, 0.5));
        a->setActivationState(DISABLE_DEACTIVATION);
        b->setActivationState(DISABLE_DEACTIVATION);
        view = sdfccd_Aabb{ { -0.6, -0.4, -0.2 }, { 0.6, 0.4, 0.5 } };
        return true;
    }
};

// ---------------------------------------------------------------------------------------------
class BunnyOnGrid : public PaperScene {
public:
    using PaperScene::PaperScene;
    bool build()
    {
        const Options& o = options();
        std::shared_ptr<MeshData> torus = loadDataMesh(o, "bullet3/torus_textured.obj", 1);
        std::shared_ptr<MeshData> bunny = loadDataMesh(o, "bullet3/bunny.obj", 0.25, "bunny");
        if (!torus || !bunny) return false;
        sdfccd_SdfId grid = gridFromMesh(torus->handle, 64, 0.1, "torus grid");
        if (grid.index1 == 0) return false;
        sdfccd_GridInfo gi;
        sdfccd_grid_get_info(grid, &gi);
        // Lying torus (its axis, y in the file, turned to z); the exact reference is the mesh itself.
        sdfccd_MeshId exact{};
        {
            sdfccd_MeshDef def = sdfccd_default_mesh_def();
            def.vertices = torus->v.data();
            def.vertex_count = (uint32_t)torus->vertexCount();
            def.indices = torus->f.data();
            def.triangle_count = (uint32_t)torus->triangleCount();
            sdfccd_create_mesh(&def, &exact);
        }
        Collider& c = addStaticSdf("torus_grid", grid, btVector3(0, 0, 0.25f), axisAngle(1, 0, 0, kPi / 2), gi.domain, 64, grid, exact);
        c.exact = sdfccd_SdfId();
        c.render = grid;
        addGround(*this, 0, 2);
        btRigidBody* b = addMeshBody(bunny, 1, btVector3(0.45f, 0, 1.2f), axisAngle(1, 0, 0, kPi / 2));
        b->setActivationState(DISABLE_DEACTIVATION);
        // The bunny lands balanced on the torus' rim and the ground at once; at Bullet's default 10
        // solver iterations its contacts under-converge and it tips over slowly (rest speed 0.069
        // m/s, drift 5.2 mm over the last second with the guarantee; 0.05 m/s at a 0.2 mm guard).
        // Like the skateboard it gets 50 iterations, a physical parameter of the scene
        // (--solver-iterations N overrides).
        if (o.solver_iterations <= 0) world()->getSolverInfo().m_numIterations = 50;
        view = sdfccd_Aabb{ { -0.8, -0.8, -0.1 }, { 0.8, 0.8, 0.9 } };
        return true;
    }
};

// ---------------------------------------------------------------------------------------------
class Hoop : public PaperScene {
public:
    using PaperScene::PaperScene;
    bool build()
    {
        // Four bars around a 0.996 m square hole: outer half 0.7, thickness 2 cm.
        std::vector<double> v;
        std::vector<uint32_t> f;
        const double t = 0.01, in = 0.498, out = 0.7, mid = 0.5 * (in + out), w = 0.5 * (out - in);
        const double hx[3] = { out, w, t }, hy[3] = { w, in, t };
        const double c0[3] = { 0, mid, 0 }, c1[3] = { 0, -mid, 0 }, c2[3] = { mid, 0, 0 }, c3[3] = { -mid, 0, 0 };
        appendBox(v, f, hx, c0);
        appendBox(v, f, hx, c1);
        appendBox(v, f, hy, c2);
        appendBox(v, f, hy, c3);
        std::shared_ptr<MeshData> hoop = makeMesh("hoop", v, f);
        hoop->finish(6);
        hoop->half_thickness = 1e9; // its centre is in the hole (inside the sphere): only the kill plane counts
        sdfccd_SdfId ball{};
        sdfccd_create_sphere(0.5, &ball);
        Collider& c = addStaticSdf("sphere", ball, btVector3(0, 0, 1), btQuaternion::getIdentity(),
                                   sdfccd_Aabb{ { -0.6, -0.6, -0.6 }, { 0.6, 0.6, 0.6 } }, 64, ball);
        c.killBelow(up, 0.7); // the hoop's centre 30 cm below the sphere's equator: it went over
        addGround(*this, -1, 3);
        btRigidBody* b = addMeshBody(hoop, 1, btVector3(0, 0, 4));
        b->setActivationState(DISABLE_DEACTIVATION);
        view = sdfccd_Aabb{ { -0.9, -0.9, 0.3 }, { 0.9, 0.9, 1.7 } };
        return true;
    }
};

// ---------------------------------------------------------------------------------------------
class Spikes : public PaperScene {
public:
    using PaperScene::PaperScene;
    bool build()
    {
        std::shared_ptr<MeshData> box = loadDataMesh(options(), "bullet3/cube.obj", 0.5, "coarse_box");
        if (!box) return false;
        box->finish(20);
        sdfccd_SpikeGridDef def = sdfccd_default_spike_grid_def();
        sdfccd_SdfId spikes{};
        if (sdfccd_create_spike_grid(&def, &spikes) != SDFCCD_OK) return false;
        // The tips are smaller than the coarse box's faces: the library's queries give one point per
        // triangle (Frank-Wolfe from its vertices, which sit between tips) and subdivide only around a
        // point in contact, so a face could sink into tips while its vertices stayed clear (21.7 mm).
        // The shape states its smallest feature, the cones' base radius; the bridge then searches each
        // face region by region (SdfShape::setFeatureSize). Part of the subdivision (--no-subdivision).
        Collider& c = addStaticSdf("spike_grid", spikes, btVector3(0, 0, 0), btQuaternion::getIdentity(),
                                   sdfccd_Aabb{ { -1.05, -1.05, -0.3 }, { 1.05, 1.05, 0.12 } }, 128, spikes, sdfccd_MeshId(),
                                   def.base_radius);
        c.killBelow(up, 0.25 + 0.05); // the box's centre within 5 cm of resting on the ground plane
        for (int i = 0; i < def.count_x; ++i) // the tips, measured at the faces' closest points
            for (int j = 0; j < def.count_y; ++j) {
                c.feature_points.push_back((i - 0.5 * (def.count_x - 1)) * def.spacing);
                c.feature_points.push_back((j - 0.5 * (def.count_y - 1)) * def.spacing);
                c.feature_points.push_back(def.height);
            }
        btRigidBody* b = addMeshBody(box, 1, btVector3(0.02f, 0.03f, 0.6f), axisAngle(0, 0, 1, 0.3));
        b->setActivationState(DISABLE_DEACTIVATION);
        view = sdfccd_Aabb{ { -0.5, -0.5, -0.05 }, { 0.5, 0.5, 0.5 } };
        return true;
    }
};

// ---------------------------------------------------------------------------------------------
class TriangleFlat : public PaperScene {
public:
    using PaperScene::PaperScene;
    bool build()
    {
        const double r = 0.5 / std::sqrt(3.0); // side 0.5 m
        std::vector<double> v;
        for (int i = 0; i < 3; ++i) {
            double a = 2 * kPi * i / 3;
            v.push_back(r * std::cos(a));
            v.push_back(r * std::sin(a));
            v.push_back(0);
        }
        std::shared_ptr<MeshData> tri = makeMesh("triangle", v, { 0, 1, 2 });
        tri->finish(20);
        tri->half_thickness = 0.005; // a sheet: "tunnelled" when its centre is 5 mm inside
        addGround(*this, 0, 1);
        btRigidBody* b = addMeshBody(tri, 0.5, btVector3(0, 0, 0.5f));
        b->setActivationState(DISABLE_DEACTIVATION);
        view = sdfccd_Aabb{ { -0.4, -0.4, -0.1 }, { 0.4, 0.4, 0.3 } };
        return true;
    }
};

template <class T> Scene* create(const Options& opt) { return built(new T(opt)); }

// ---------------------------------------------------------------------------------------------
// Kinematic scenes through the C ABI.

// Rotation matrix of the rotation vector r (angle |r|).
void rotationMatrix(const double* r, double* R)
{
    double a = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (a < 1e-300) {
        const double I[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
        std::memcpy(R, I, sizeof I);
        return;
    }
    double x = r[0] / a, y = r[1] / a, z = r[2] / a, c = std::cos(a), s = std::sin(a), C = 1 - c;
    const double M[9] = { c + x * x * C, x * y * C - z * s, x * z * C + y * s, y * x * C + z * s, c + y * y * C,
                          y * z * C - x * s, z * x * C - y * s, z * y * C + x * s, c + z * z * C };
    std::memcpy(R, M, sizeof M);
}

// The body frame at time t of the motion (v, w) from `f0` (rotation about the body origin).
Frame frameAt(const Frame& f0, const double* v, const double* w, double t)
{
    double rv[3] = { w[0] * t, w[1] * t, w[2] * t }, R[9];
    rotationMatrix(rv, R);
    Frame f;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) f.R[3 * r + c] = R[3 * r] * f0.R[c] + R[3 * r + 1] * f0.R[3 + c] + R[3 * r + 2] * f0.R[6 + c];
    for (int k = 0; k < 3; ++k) f.p[k] = f0.p[k] + v[k] * t;
    return f;
}

class KinematicScene : public Scene {
public:
    explicit KinematicScene(const Options& opt) : m_opt(opt)
    {
        m_params = sdfccd_default_query_params();
        m_params.method = opt.method;
        m_params.subdivision = opt.subdivision ? 1 : 0;
        m_params.margin = opt.margin >= 0 ? opt.margin : 1e-3; // the paper's 1 mm margin
        ccd_margin = m_params.margin;
    }
    ~KinematicScene() override
    {
        for (sdfccd_SdfId id : m_owned) sdfccd_destroy_sdf(id);
    }
    /** Commanded linear and angular velocity for step i (world). */
    virtual void command(int i, double dt, double* v, double* w) = 0;

    void step(int i, double dt) override
    {
        Body& b = bodies[0];
        double v[3], w[3];
        command(i, dt, v, w);
        sdfccd_RigidMotion motion = sdfccd_default_rigid_motion();
        motion.pose = b.frame.toPose();
        motion.linear_velocity = sdfccd_Vec3{ v[0], v[1], v[2] };
        motion.angular_velocity = sdfccd_Vec3{ w[0], w[1], w[2] };
        double toi = dt;
        int contacts = 0;
        for (const Collider& c : colliders) {
            sdfccd_RigidMotion sm = sdfccd_default_rigid_motion();
            sm.pose = c.frame.toPose();
            sdfccd_QueryResult res;
            std::vector<sdfccd_Contact> buf(64);
            auto t0 = std::chrono::steady_clock::now();
            sdfccd_Status st = sdfccd_query_mesh(c.ccd, &sm, b.mesh->handle, &motion, 0, dt, &m_params, buf.data(), (int32_t)buf.size(), &res);
            m_cost.ccd_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            ++m_cost.ccd_queries;
            if (st != SDFCCD_OK) {
                ++m_cost.query_errors;
                std::fprintf(stderr, "sdfccd_scenes: query failed: %s\n", sdfccd_last_error());
                continue;
            }
            m_cost.triangles_tested += res.triangles_tested;
            if (res.hit) {
                ++m_cost.hits;
                contacts += res.contact_count;
                toi = std::min(toi, res.toi);
            }
        }
        m_cost.contacts = contacts;
        // Penetration along the executed motion [0, toi], sampled 32 times.
        Frame f0 = b.frame;
        std::vector<double> world;
        for (int k = 1; k <= 32; ++k) {
            Frame fk = frameAt(f0, v, w, toi * k / 32);
            for (const Collider& c : colliders) {
                for (int s = 0; s < b.mesh->sampleCount(); ++s) {
                    double x[3], l[3], phi;
                    fk.apply(&b.mesh->samples[3 * (size_t)s], x);
                    c.frame.applyInverse(x, l);
                    sdfccd_sdf_eval(c.exact, sdfccd_Vec3{ l[0], l[1], l[2] }, &phi, nullptr);
                    m_swept = std::max(m_swept, -phi);
                }
            }
        }
        b.frame = frameAt(f0, v, w, toi);
        bool stopped = toi < dt;
        for (int k = 0; k < 3; ++k) {
            b.v[k] = stopped ? 0 : v[k];
            b.w[k] = stopped ? 0 : w[k];
        }
    }
    StepCost cost() const override { return m_cost; }
    double energy() const override { return NAN; }
    double sweptPenetration() const override { return m_swept; }
    std::string describe() const override
    {
        std::ostringstream s;
        s << "kinematic through the C ABI, " << methodName(m_opt.method) << (m_opt.subdivision ? " + subdivision" : "")
          << ", margin " << m_params.margin << " m, body stops at the reported TOI";
        return s.str();
    }

protected:
    sdfccd_SdfId own(sdfccd_SdfId id)
    {
        m_owned.push_back(id);
        return id;
    }
    Options m_opt;
    sdfccd_QueryParams m_params;
    StepCost m_cost;
    double m_swept = 0;
    std::vector<sdfccd_SdfId> m_owned;
};

// An icosphere of radius r, `levels` subdivisions.
std::shared_ptr<MeshData> icosphere(double r, int levels)
{
    const double t = (1 + std::sqrt(5.0)) / 2;
    std::vector<double> v = { -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0, 0, -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, t, 0, -1, t, 0, 1, -t, 0, -1, -t, 0, 1 };
    std::vector<uint32_t> f = { 0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
                                3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1 };
    for (int l = 0; l < levels; ++l) {
        std::vector<uint32_t> nf;
        std::vector<std::pair<uint64_t, uint32_t>> cache;
        auto mid = [&](uint32_t a, uint32_t b) {
            uint64_t key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            for (auto& e : cache)
                if (e.first == key) return e.second;
            for (int k = 0; k < 3; ++k) v.push_back(0.5 * (v[3 * a + k] + v[3 * b + k]));
            uint32_t id = (uint32_t)(v.size() / 3 - 1);
            cache.push_back(std::make_pair(key, id));
            return id;
        };
        for (size_t i = 0; i < f.size(); i += 3) {
            uint32_t a = f[i], b = f[i + 1], c = f[i + 2], ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
            const uint32_t n[12] = { a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca };
            nf.insert(nf.end(), n, n + 12);
        }
        f.swap(nf);
    }
    for (size_t i = 0; i < v.size(); i += 3) {
        double n = std::sqrt(v[i] * v[i] + v[i + 1] * v[i + 1] + v[i + 2] * v[i + 2]);
        for (int k = 0; k < 3; ++k) v[i + k] *= r / n;
    }
    return makeMesh("sphere", v, f);
}

class TorusCrossings : public KinematicScene {
public:
    explicit TorusCrossings(const Options& opt) : KinematicScene(opt)
    {
        sdfccd_SdfId torus{};
        sdfccd_create_torus(0.1, 0.05, &torus); // 30 cm wide
        own(torus);
        Collider c;
        c.name = "torus";
        c.exact = c.ccd = torus;
        c.bounds = sdfccd_Aabb{ { -0.16, -0.16, -0.06 }, { 0.16, 0.16, 0.06 } };
        c.kill_normal[0] = 1; // the sphere's centre inside or past the left tube
        c.kill_offset = -0.1;
        colliders.push_back(c);
        Body b;
        b.name = "sphere";
        b.mesh = icosphere(0.02, 2);
        b.frame.p[0] = -0.3;
        bodies.push_back(b);
        view = sdfccd_Aabb{ { -0.35, -0.17, -0.1 }, { 0.35, 0.17, 0.1 } };
    }
    void command(int, double, double* v, double* w) override
    {
        v[0] = 36; // 0.6 m per 1/60 s step: through both tubes of the torus
        v[1] = v[2] = 0;
        w[0] = w[1] = w[2] = 0;
    }
};

class Spin360 : public KinematicScene {
public:
    explicit Spin360(const Options& opt) : KinematicScene(opt)
    {
        sdfccd_SdfId box{};
        sdfccd_create_box(sdfccd_Vec3{ 1, 1, 0.25 }, &box);
        own(box);
        Collider c;
        c.name = "box";
        c.exact = c.ccd = box;
        c.frame.p[2] = -0.25; // top at z = 0
        c.bounds = sdfccd_Aabb{ { -1.05, -1.05, -0.3 }, { 1.05, 1.05, 0.3 } };
        c.killBelow(up, 0.1); // body origin 6 cm lower than its start: it went into the box
        colliders.push_back(c);
        Body b;
        b.name = "pyramid";
        b.mesh = loadDataMesh(opt, "meshes/pyramid.obj", 1);
        if (!b.mesh) return;
        b.mesh->finish(12);
        b.frame.p[2] = 0.16; // base (local z = -0.15) 1 cm above the box; corners (r 0.18) sweep 2 cm into it
        bodies.push_back(b);
        view = sdfccd_Aabb{ { -0.3, -0.3, -0.1 }, { 0.3, 0.3, 0.4 } };
    }
    void command(int, double dt, double* v, double* w) override
    {
        v[0] = v[1] = v[2] = 0;
        w[0] = 2 * kPi / dt; // one full turn per step about x
        w[1] = w[2] = 0;
    }
};

Scene* createTorusCrossings(const Options& opt) { return new TorusCrossings(opt); }
Scene* createSpin360(const Options& opt)
{
    Spin360* s = new Spin360(opt);
    if (s->bodies.empty()) {
        delete s;
        return nullptr;
    }
    return s;
}

} // namespace

void appendPaperScenes(std::vector<SceneEntry>& t)
{
    t.push_back({ "shuriken", "Fig. 1: the 888-triangle shuriken at 500 m/s into an implicit breastplate (CSG)", create<Shuriken>, 60, 1.0 / 60 });
    t.push_back({ "torus-crossings", "Fig. 2: a sphere mesh pushed through a torus, crossing its surface 4 times in one step (kinematic, C ABI)",
                  createTorusCrossings, 10, 1.0 / 60 });
    t.push_back({ "skateboard", "Fig. 5: a skateboard slides down an analytic ramp onto a rail", create<Skateboard>, 180, 1.0 / 60 });
    t.push_back({ "pyramids", "Fig. 6: two coarse pyramids onto an analytic box", create<Pyramids>, 120, 1.0 / 60 });
    t.push_back({ "bunny", "Fig. 7: the bunny onto a grid SDF (baked from the torus mesh)", create<BunnyOnGrid>, 120, 1.0 / 60 });
    t.push_back({ "hoop", "Fig. 8: a square hoop whose hole equals the diameter of an analytic sphere, dropped over it", create<Hoop>, 60, 1.0 / 60 });
    t.push_back({ "spikes", "Fig. 10: a coarse 12-triangle box onto the spike grid (try --no-subdivision)", create<Spikes>, 120, 1.0 / 60 });
    t.push_back({ "triangle-flat", "Fig. 11: a single triangle falling flat on a box", create<TriangleFlat>, 90, 1.0 / 60 });
    t.push_back({ "spin360", "Fig. 12: a pyramid turning 360 degrees in one step onto a box (kinematic, C ABI)", createSpin360, 10, 1.0 / 60 });
}

} // namespace scenes
