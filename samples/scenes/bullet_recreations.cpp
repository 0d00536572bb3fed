// SPDX-License-Identifier: MIT
// Bullet's own sample scenes, re-created from their parameters (notes/bullet-sample-scenes.md)
// with the SDF collider swapped in; each also runs --stock (the same SDF surface as a
// btBvhTriangleMeshShape against Bullet's GImpact algorithm).
//
//  gimpact-demo   Bullet 2.x GimpactTestDemo: Y up, g = -10, 1/60 s. GImpact tori (bullet3
//                 torus_textured x2: R 1 m, r 0.5 m, mass 1) and bunnies (bunny.obj, 2 m, mass 4)
//                 tumbling onto an SDF floor box (top at y = -9), a lying analytic torus
//                 (R 2, r 0.5) and a grid SDF bunny (32^3 grid; measured against the exact mesh
//                 distance). bullet3's bunny.obj is already 2 m long (the demo's own bunny data
//                 scaled x4 is about that size), so it is used at scale 1 (mass 4).
//                 12 bodies (quick: 4).
//  gimpact-shot-50/200/500   the same, plus a torus mesh shot at the lying torus at 50, 200 or
//                 500 m/s at step 60 (the demo's "shoot" key).
//  sdf-box        pybullet's signedDistanceField.py: Z up, g = -10, 1/240 s, concave_box.cdf
//                 (data/sdf/concave_box_r32.cdf) static at the origin through our SdfShape, with a
//                 9 cm torus (torus x0.06, mass 0.1) and small GImpact meshes (bunny x0.05 = 10 cm,
//                 cube x0.08, torus x0.06; 9 bodies, quick: 3) dropped in.
//  sdf-box-btsdf  the same through Bullet's own btSdfCollisionShape read from the same file.
//  sdf-box-torus  the 9 cm torus dropped alone (the bridge issue's 5 mm limit and rest).
//  sdf-box-btsdf-torus  the torus alone through btSdfCollisionShape (the bridge samples it
//                 through queryPoint: Config::handle_bt_sdf_shape).
//  landscape      BenchmarkDemo "landscape": Y up, g = -10, 1/60 s, 5 solver iterations; 200
//                 GImpact bodies (cubes x2, tori x2, alternating) on a 10 x 10 grid 6 m apart,
//                 two layers at y = 20 and 26, dropped on the wavy landscape
//                 h = 3 sin(x/8) cos(z/8) over 80 x 80 m (quick: 5 x 5, one layer).
//  landscape-grid the same field baked into a grid SDF in-tree (sdfccd_create_grid_from_sdf, 1 m
//                 cells, 82 x 21 x 82); stock: the grid's isosurface as a triangle mesh.
#include <cmath>
#include <cstdio>

#include "bullet_scene.h"
#include "scenes.h"

namespace scenes {

namespace {

const double kPi = 3.14159265358979323846;

sdfccd_MeshId createMesh(const MeshData& m)
{
    sdfccd_MeshDef def = sdfccd_default_mesh_def();
    def.vertices = m.v.data();
    def.vertex_count = (uint32_t)m.vertexCount();
    def.indices = m.f.data();
    def.triangle_count = (uint32_t)m.triangleCount();
    def.drop_degenerate = 1;
    sdfccd_MeshId id{};
    if (sdfccd_create_mesh(&def, &id) != SDFCCD_OK) std::fprintf(stderr, "sdfccd_scenes: mesh %s: %s\n", m.name.c_str(), sdfccd_last_error());
    return id;
}

// ---------------------------------------------------------------------------------------------
class GImpactDemo : public BulletScene {
public:
    GImpactDemo(const Options& opt, double shot_speed) : BulletScene(opt, btVector3(0, -10, 0), 1), m_shotSpeed(shot_speed) {}

    bool build()
    {
        const Options& o = options();
        std::shared_ptr<MeshData> torus = loadDataMesh(o, "bullet3/torus_textured.obj", 2.0, "torus");
        std::shared_ptr<MeshData> bunny = loadDataMesh(o, "bullet3/bunny.obj", 1.0, "bunny");
        if (!torus || !bunny) return false;

        // Floor: a 60 x 2 x 60 m box, top at y = -9.
        sdfccd_SdfId floor;
        sdfccd_create_box(sdfccd_Vec3{ 30, 1, 30 }, &floor);
        Collider& f = addStaticSdf("floor", floor, btVector3(0, -10, 0), btQuaternion::getIdentity(),
                                   sdfccd_Aabb{ { -30.5, -1.5, -30.5 }, { 30.5, 1.5, 30.5 } }, 60, floor);
        f.killBelow(up, -11);
        // A torus lying on the floor (axis = y): analytic.
        sdfccd_SdfId ring;
        sdfccd_create_torus(2, 0.5, &ring);
        addStaticSdf("lying_torus", ring, btVector3(-6, -8.5, 0), axisAngle(1, 0, 0, -kPi / 2),
                     sdfccd_Aabb{ { -2.6, -2.6, -0.6 }, { 2.6, 2.6, 0.6 } }, 64, ring);
        // The bunny as a grid SDF, sitting on the floor; measured against the exact mesh distance.
        sdfccd_MeshId bunny_mesh = createMesh(*bunny);
        sdfccd_SdfId grid = gridFromMesh(bunny_mesh, 32, 0.3, "bunny grid");
        if (grid.index1 == 0) return false;
        sdfccd_GridInfo gi;
        sdfccd_grid_get_info(grid, &gi);
        addStaticSdf("bunny_grid", grid, btVector3(6, (btScalar)(-9 - bunny->bounds.lo.y), 0), btQuaternion::getIdentity(), gi.domain,
                     48, grid, bunny_mesh);
        colliders.back().exact = sdfccd_SdfId();
        colliders.back().render = grid;

        int n = o.quick ? 4 : 12;
        for (int k = 0; k < n; ++k) {
            btVector3 pos((btScalar)(-6 + 6 * (k % 3)), (btScalar)(-3 + 4.5 * (k / 6)), (btScalar)((k / 3) % 2 ? 2.5 : -2.5));
            bool is_torus = (k % 2) == 0;
            btRigidBody* b = addMeshBody(is_torus ? torus : bunny, is_torus ? 1 : 4, pos, tumble(k + 1));
            b->setFriction(0.5f);
        }
        if (m_shotSpeed > 0) {
            m_shot = addMeshBody(torus, 1, m_shotFrom, tumble(42));
            bodies.back().name = "shot";
            world()->removeRigidBody(m_shot); // fired at step kShotStep
            bodies.back().active = false;
        }
        char buf[96];
        std::snprintf(buf, sizeof buf, "%s", m_shotSpeed > 0 ? " [shot torus fired at step 60]" : "");
        m_description += buf;
        return true;
    }

    void beforeStep(int i) override
    {
        if (!m_shot || i != kShotStep) return;
        btVector3 dir = (m_target - m_shotFrom).normalized();
        m_shot->setLinearVelocity(dir * (btScalar)m_shotSpeed);
        m_shot->setAngularVelocity(btVector3(0, 0, 0));
        m_shot->setActivationState(DISABLE_DEACTIVATION);
        world()->addRigidBody(m_shot);
    }
    bool injects(int i) const override { return m_shot && i == kShotStep; }

private:
    static const int kShotStep = 60;
    double m_shotSpeed;
    btRigidBody* m_shot = nullptr;
    btVector3 m_shotFrom = btVector3(0, 6, 24);
    btVector3 m_target = btVector3(-6, -8.5, 0); // the lying torus's centre
};

template <int kShot> Scene* createGImpactDemo(const Options& opt) { return built(new GImpactDemo(opt, kShot)); }

// ---------------------------------------------------------------------------------------------
class SdfBox : public BulletScene {
public:
    /** `bt_sdf`: the tray is Bullet's btSdfCollisionShape (else our SdfShape); `torus_alone`: only
     * the 9 cm torus is dropped. */
    SdfBox(const Options& opt, bool bt_sdf, bool torus_alone)
        : BulletScene(opt, btVector3(0, 0, -10), 2), m_btSdf(bt_sdf), m_torusAlone(torus_alone)
    {
    }

    bool build()
    {
        const Options& o = options();
        std::string cdf = o.data_dir + "/sdf/concave_box_r32.cdf";
        sdfccd_SdfId grid{};
        if (sdfccd_load_grid(cdf.c_str(), &grid) != SDFCCD_OK) {
            std::fprintf(stderr, "sdfccd_scenes: %s: %s\n", cdf.c_str(), sdfccd_last_error());
            return false;
        }
        Collider* c;
        if (m_btSdf) {
            c = &addStaticBtSdf("concave_box", cdf, grid, btVector3(0, 0, 0), 96);
        } else {
            sdfccd_GridInfo gi;
            sdfccd_grid_get_info(grid, &gi);
            c = &addStaticSdf("concave_box", grid, btVector3(0, 0, 0), btQuaternion::getIdentity(), gi.domain, 96, grid);
        }
        c->killBelow(up, -0.2); // the tray is |z| <= 0.1
        std::shared_ptr<MeshData> torus = loadDataMesh(o, "bullet3/torus_textured.obj", 0.06, "torus9cm");
        std::shared_ptr<MeshData> bunny = loadDataMesh(o, "bullet3/bunny.obj", 0.05, "bunny");
        std::shared_ptr<MeshData> cube = loadDataMesh(o, "bullet3/cube.obj", 0.08, "cube8cm");
        if (!torus || !bunny || !cube) return false;
        btRigidBody* t = addMeshBody(torus, 0.1, btVector3(0.5f, 0, 0.5f), axisAngle(1, 0.3, 0, 0.7));
        t->setActivationState(DISABLE_DEACTIVATION);
        if (!m_torusAlone) {
            int n = o.quick ? 3 : 9;
            for (int i = 0; i < n; ++i) {
                const std::shared_ptr<MeshData>& m = i % 3 == 0 ? bunny : i % 3 == 1 ? cube : torus;
                btRigidBody* b = addMeshBody(m, 0.1, btVector3((btScalar)(-0.6 + 0.15 * i), 0.2f, (btScalar)(0.4 + 0.05 * i)), tumble(i + 3));
                b->setActivationState(DISABLE_DEACTIVATION);
            }
        }
        return true;
    }

private:
    bool m_btSdf, m_torusAlone;
};

template <bool kBtSdf, bool kTorusAlone> Scene* createSdfBox(const Options& opt) { return built(new SdfBox(opt, kBtSdf, kTorusAlone)); }

// ---------------------------------------------------------------------------------------------
// The landscape: the normalised height-field distance (y - h) / sqrt(1 + |grad h|^2) (first-order
// exact; h's radius of curvature is >= 21 m, so the error is far below a millimetre at the
// depths measured), intersected with a box |x|, |z| <= 40, -12 <= y <= 8.
const double kAmp = 3, kWave = 8, kHalf = 40;

double landscapeEval(sdfccd_Vec3 p, sdfccd_Vec3* g, void*)
{
    double sx = std::sin(p.x / kWave), cx = std::cos(p.x / kWave), sz = std::sin(p.z / kWave), cz = std::cos(p.z / kWave);
    double h = kAmp * sx * cz;
    double hx = kAmp / kWave * cx * cz, hz = -kAmp / kWave * sx * sz;
    double n = std::sqrt(1 + hx * hx + hz * hz);
    double d = (p.y - h) / n;
    sdfccd_Vec3 grad = { -hx / n, 1 / n, -hz / n };
    // Box |x|, |z| <= 40, y in [-12, 8]: exact box distance, then the intersection max(d, box).
    double q[3] = { std::fabs(p.x) - kHalf, std::fabs(p.y + 2) - 10, std::fabs(p.z) - kHalf };
    double outside = 0, inside = std::max(q[0], std::max(q[1], q[2]));
    for (double e : q) outside += std::max(e, 0.0) * std::max(e, 0.0);
    double box = outside > 0 ? std::sqrt(outside) : inside;
    if (box > d) {
        d = box;
        double s[3] = { p.x < 0 ? -1.0 : 1.0, p.y + 2 < 0 ? -1.0 : 1.0, p.z < 0 ? -1.0 : 1.0 };
        if (outside > 0) {
            double r = std::sqrt(outside);
            grad = sdfccd_Vec3{ s[0] * std::max(q[0], 0.0) / r, s[1] * std::max(q[1], 0.0) / r, s[2] * std::max(q[2], 0.0) / r };
        } else {
            int k = q[0] >= q[1] && q[0] >= q[2] ? 0 : q[1] >= q[2] ? 1 : 2;
            grad = sdfccd_Vec3{ k == 0 ? s[0] : 0, k == 1 ? s[1] : 0, k == 2 ? s[2] : 0 };
        }
    }
    if (g) *g = grad;
    return d;
}

class Landscape : public BulletScene {
public:
    /** `grid`: the field baked into a grid SDF (1 m cells) and the bodies collide with that. */
    Landscape(const Options& opt, bool grid) : BulletScene(opt, btVector3(0, -10, 0), 1), m_grid(grid) {}

    bool build()
    {
        const Options& o = options();
        if (o.solver_iterations <= 0) world()->getSolverInfo().m_numIterations = 5; /* the benchmark demo's */
        world()->getSolverInfo().m_solverMode |= SOLVER_ENABLE_FRICTION_DIRECTION_CACHING;
        sdfccd_CallbackSdfDef def = sdfccd_default_callback_sdf_def();
        def.eval = landscapeEval;
        // |grad| of (y - h)/n is at most ~1.15 for |grad h| <= 3/8 sqrt(2); 1.2 bounds it.
        def.lipschitz = 1.2;
        def.bounds = sdfccd_Aabb{ { -kHalf, -12, -kHalf }, { kHalf, kAmp, kHalf } };
        sdfccd_SdfId land{};
        if (sdfccd_create_callback_sdf(&def, &land) != SDFCCD_OK) return false;
        sdfccd_SdfId field = land;
        if (m_grid) { // 1 m cells over the field's box (y up to its top, 8 m): the terrain's 50 m waves to about 1e-5 m
            sdfccd_GridDef gd = sdfccd_default_grid_def();
            gd.fit_domain = 0;
            gd.domain = sdfccd_Aabb{ { -kHalf - 1, -12.5, -kHalf - 1 }, { kHalf + 1, 8.5, kHalf + 1 } };
            gd.resolution[0] = gd.resolution[2] = 2 * (int)kHalf + 2;
            gd.resolution[1] = 21;
            if (sdfccd_create_grid_from_sdf(land, &gd, &field) != SDFCCD_OK) {
                std::fprintf(stderr, "sdfccd_scenes: landscape grid: %s\n", sdfccd_last_error());
                sdfccd_destroy_sdf(land);
                return false;
            }
        }
        // (the analytic field stays the measuring reference)
        Collider& c = addStaticSdf("landscape", field, btVector3(0, 0, 0), btQuaternion::getIdentity(),
                                   sdfccd_Aabb{ { -kHalf - 0.5, -12.5, -kHalf - 0.5 }, { kHalf + 0.5, kAmp + 1, kHalf + 0.5 } }, 128, land);
        c.killBelow(up, -12);
        for (auto& b : rigidStatics()) b->setFriction(0.9f);
        std::shared_ptr<MeshData> cube = loadDataMesh(o, "bullet3/cube.obj", 2.0, "cube");
        std::shared_ptr<MeshData> torus = loadDataMesh(o, "bullet3/torus_textured.obj", 2.0, "torus");
        if (!cube || !torus) return false;
        int side = o.quick ? 5 : 10, layers = o.quick ? 1 : 2;
        int k = 0;
        for (int l = 0; l < layers; ++l)
            for (int i = 0; i < side; ++i)
                for (int j = 0; j < side; ++j, ++k) {
                    btVector3 pos((btScalar)(6 * (i - 0.5 * (side - 1))), (btScalar)(20 + 6 * l), (btScalar)(6 * (j - 0.5 * (side - 1))));
                    addMeshBody(k % 2 ? torus : cube, 1, pos, tumble(k));
                }
        return true;
    }

private:
    bool m_grid;

    std::vector<btRigidBody*> rigidStatics()
    {
        std::vector<btRigidBody*> out;
        btCollisionObjectArray& objs = world()->getCollisionObjectArray();
        for (int i = 0; i < objs.size(); ++i)
            if (btRigidBody* r = btRigidBody::upcast(objs[i]))
                if (r->getInvMass() == 0) out.push_back(r);
        return out;
    }
};

template <bool kGrid> Scene* createLandscape(const Options& opt) { return built(new Landscape(opt, kGrid)); }

} // namespace

void appendBulletRecreations(std::vector<SceneEntry>& t)
{
    t.push_back({ "gimpact-demo", "Bullet's GImpact demo: tori and bunnies onto an SDF floor, lying torus and grid bunny (Y up, 1/60 s)",
                  createGImpactDemo<0>, 480, 1.0 / 60 });
    t.push_back({ "gimpact-shot-50", "gimpact-demo plus a torus shot at 50 m/s into the lying torus at step 60", createGImpactDemo<50>, 480,
                  1.0 / 60 });
    t.push_back({ "gimpact-shot-200", "gimpact-demo plus a torus shot at 200 m/s", createGImpactDemo<200>, 480, 1.0 / 60 });
    t.push_back({ "gimpact-shot-500", "gimpact-demo plus a torus shot at 500 m/s", createGImpactDemo<500>, 480, 1.0 / 60 });
    t.push_back({ "sdf-box", "pybullet's SDF example: small GImpact meshes into concave_box.cdf through our SdfShape (Z up, 1/240 s)",
                  createSdfBox<false, false>, 480, 1.0 / 240 });
    t.push_back({ "sdf-box-btsdf", "sdf-box through Bullet's own btSdfCollisionShape (same .cdf file)", createSdfBox<true, false>, 480,
                  1.0 / 240 });
    t.push_back({ "sdf-box-torus", "the 9 cm GImpact torus dropped alone into concave_box.cdf", createSdfBox<false, true>, 480,
                  1.0 / 240 });
    t.push_back({ "sdf-box-btsdf-torus", "sdf-box-torus through Bullet's own btSdfCollisionShape (same .cdf file)",
                  createSdfBox<true, true>, 480, 1.0 / 240 });
    t.push_back({ "landscape", "BenchmarkDemo landscape: 200 GImpact cubes and tori on a wavy SDF landscape (Y up, 1/60 s)", createLandscape<false>,
                  300, 1.0 / 60 });
    t.push_back({ "landscape-grid", "the landscape baked into a grid SDF (1 m cells; stock: the grid's isosurface)", createLandscape<true>, 300,
                  1.0 / 60 });
}

} // namespace scenes
