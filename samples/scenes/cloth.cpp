// SPDX-License-Identifier: MIT
// cloth (Fig. 9): Bullet's own cloth (btSoftBodyHelpers::CreatePatch, btSoftRigidDynamicsWorld)
// dropped over the bunny SDF, with the bridge's soft-body contacts (per-vertex linear motion of
// nodes and faces, soft_body.h). Z up, g = -9.81.
//
// The cloth: 21 x 21 nodes over 0.8 x 0.8 m (800 triangles, structural, shear and bending links),
// 0.2 kg, dropped flat from 10 cm above a 50 cm bunny (bunny.obj x0.25, baked to a 32^3 grid;
// measured against the exact mesh distance) standing on a ground box. Faces are measured on a
// lattice (density 3). The soft body's collision margin (kMargin) keeps its contact planes off
// the surface; penetration is measured against phi = 0.
// Variants: the run's method goes to the bridge (Config::query); DCD is the discrete baseline
// (nodes checked at their predicted positions only, the guard off); --stock: no bridge, the bunny as
// its isosurface (btBvhTriangleMeshShape, Bullet's soft-concave path) and the ground as a
// btBoxShape. cloth-btsdf: the bunny as Bullet's btSdfCollisionShape (the same grid saved as .cdf),
// through the bridge or (--stock) Bullet alone.
//   cloth        10 ms steps (300 steps: 3 s)
//   cloth-1ms    1 ms steps (3000 steps)
//   cloth-btsdf  10 ms steps, btSdfCollisionShape
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unistd.h>

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/CollisionShapes/btSdfCollisionShape.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include "scenes.h"
#include "sdfccd_bullet/sdfccd_bullet.h"
#include "sdfccd_bullet/soft_body.h"

namespace scenes {

namespace {

const int kN = 21;
const double kSize = 0.8, kMass = 0.2, kMargin = 0.01, kDamping = 0.05;

class Cloth : public Scene {
public:
    Cloth(const Options& opt, bool btsdf) : m_opt(opt), m_btsdf(btsdf) {}
    ~Cloth() override
    {
        if (m_world) {
            if (m_cloth) m_world->removeSoftBody(m_cloth);
            for (auto& r : m_rigid) m_world->removeRigidBody(r.get());
        }
        delete m_cloth;
        if (m_bridge) m_bridge->unregister();
        m_world.reset();
        m_rigid.clear();
        m_shapes.clear();
        for (sdfccd_SdfId id : m_owned) sdfccd_destroy_sdf(id);
        if (m_exact.index1) sdfccd_destroy_mesh(m_exact);
    }

    bool build()
    {
        gravity[2] = -9.81;
        ccd_margin = kMargin;
        std::shared_ptr<MeshData> file = loadDataMesh(m_opt, "bullet3/bunny.obj", 0.25);
        if (!file) return false;
        // bunny.obj is Y up: turn it to Z up, (x, y, z) -> (x, -z, y).
        std::vector<double> bv = file->v;
        for (size_t i = 0; i < bv.size(); i += 3) {
            double y = bv[i + 1], z = bv[i + 2];
            bv[i + 1] = -z;
            bv[i + 2] = y;
        }
        std::shared_ptr<MeshData> bunny = makeMesh("bunny", bv, file->f);
        sdfccd_SdfId grid = gridFromMesh(bunny->handle, 32, 0.05, "bunny grid");
        if (grid.index1 == 0) return false;
        m_owned.push_back(grid);
        sdfccd_MeshDef def = sdfccd_default_mesh_def();
        def.vertices = bunny->v.data();
        def.vertex_count = (uint32_t)bunny->vertexCount();
        def.indices = bunny->f.data();
        def.triangle_count = (uint32_t)bunny->triangleCount();
        def.drop_degenerate = 1;
        sdfccd_create_mesh(&def, &m_exact);
        sdfccd_GridInfo gi;
        sdfccd_grid_get_info(grid, &gi);
        const double bottom = bunny->bounds.lo.z, top = bunny->bounds.hi.z;

        // The world: Bullet's soft-rigid world, the bridge registered before any body.
        m_config.reset(new btSoftBodyRigidBodyCollisionConfiguration());
        m_dispatcher.reset(new btCollisionDispatcher(m_config.get()));
        m_broadphase.reset(new btDbvtBroadphase());
        m_solver.reset(new btSequentialImpulseConstraintSolver());
        m_world.reset(new btSoftRigidDynamicsWorld(m_dispatcher.get(), m_broadphase.get(), m_solver.get(), m_config.get()));
        m_world->setGravity(btVector3(0, 0, -9.81f));
        m_world->getWorldInfo().m_gravity = btVector3(0, 0, -9.81f);
        m_world->getWorldInfo().m_sparsesdf.Initialize();
        if (!m_opt.stock) {
            sdfccd_bullet::Config cfg;
            cfg.query.method = m_opt.method;
            cfg.query.subdivision = m_opt.subdivision ? 1 : 0;
            if (m_opt.margin >= 0) cfg.contact_margin = m_opt.margin;
            m_bridge.reset(new sdfccd_bullet::Bridge(cfg));
            if (m_bridge->registerWith(m_world.get()) != sdfccd_bullet::Status::Ok) {
                std::fprintf(stderr, "cloth: Bridge::registerWith failed\n");
                return false;
            }
        }

        // The bunny, standing on z = 0.
        const btVector3 at(0, 0, (btScalar)-bottom);
        btCollisionShape* bunny_shape = nullptr;
        if (m_btsdf) {
            bunny_shape = btSdfShape(grid);
            if (!bunny_shape) return false;
        } else if (m_opt.stock) {
            bunny_shape = isosurface(grid, gi.domain, 64);
            if (!bunny_shape) return false;
        } else {
            bunny_shape = new sdfccd_bullet::SdfShape(grid);
        }
        addStatic(bunny_shape, at);
        Collider c;
        c.name = "bunny_grid";
        c.ccd = c.render = grid;
        c.exact_mesh = m_exact;
        c.bounds = gi.domain;
        c.frame.p[2] = -bottom;
        colliders.push_back(c);
        sdfccd_SdfId ground{};
        sdfccd_create_box(sdfccd_Vec3{ 1, 1, 0.25 }, &ground);
        m_owned.push_back(ground);
        if (m_opt.stock) addStatic(new btBoxShape(btVector3(1, 1, 0.25f)), btVector3(0, 0, -0.25f));
        else addStatic(new sdfccd_bullet::SdfShape(ground), btVector3(0, 0, -0.25f));
        Collider g;
        g.name = "ground";
        g.ccd = g.exact = ground;
        g.frame.p[2] = -0.25;
        g.bounds = sdfccd_Aabb{ { -1.05, -1.05, -0.3 }, { 1.05, 1.05, 0.3 } };
        g.killBelow(up, -0.05);
        colliders.push_back(g);

        // The cloth, flat, 10 cm above the bunny's top.
        const btScalar z0 = (btScalar)(top - bottom + 0.1), h = (btScalar)(0.5 * kSize);
        m_cloth = btSoftBodyHelpers::CreatePatch(m_world->getWorldInfo(), btVector3(-h, -h, z0), btVector3(h, -h, z0),
                                                 btVector3(-h, h, z0), btVector3(h, h, z0), kN, kN, 0, true);
        m_cloth->getCollisionShape()->setMargin((btScalar)kMargin);
        m_cloth->m_cfg.kDF = 0.8f;
        m_cloth->m_cfg.piterations = 8;
        m_cloth->m_materials[0]->m_kLST = 0.9f;
        m_cloth->generateBendingConstraints(2, m_cloth->m_materials[0]);
        m_cloth->setTotalMass((btScalar)kMass);
        m_world->addSoftBody(m_cloth);
        std::vector<double> v;
        std::vector<uint32_t> f;
        for (int i = 0; i < m_cloth->m_nodes.size(); ++i)
            for (int k = 0; k < 3; ++k) v.push_back((double)m_cloth->m_nodes[i].m_x[k]);
        for (int i = 0; i < m_cloth->m_faces.size(); ++i)
            for (int k = 0; k < 3; ++k) f.push_back((uint32_t)(m_cloth->m_faces[i].m_n[k] - &m_cloth->m_nodes[0]));
        std::shared_ptr<MeshData> mesh = makeMesh("cloth", v, f);
        mesh->finish(3);
        mesh->half_thickness = 1e9; // a sheet: penetration is measured, tunnelling by the kill plane only
        Body b;
        b.name = "cloth";
        b.mesh = mesh;
        b.deformable = true;
        bodies.push_back(b);
        sync();
        if (m_bridge) {
            std::string msg;
            if (m_bridge->check(m_world.get(), &msg) != sdfccd_bullet::Status::Ok)
                std::fprintf(stderr, "cloth: Bridge::check: %s\n", msg.c_str());
        }
        view = sdfccd_Aabb{ { -0.5, -0.5, -0.05 }, { 0.5, 0.5, (double)z0 + 0.05 } };
        return true;
    }

    void step(int, double dt) override
    {
        // Bullet's kDP damps a fraction of the velocity per step: 5% per 10 ms at any step.
        m_cloth->m_cfg.kDP = (btScalar)(1 - std::pow(1 - kDamping, dt / 0.01));
        const int64_t before = m_bridge ? contactsFound() : 0;
        m_world->stepSimulation((btScalar)dt, 0, (btScalar)dt);
        m_step_contacts = m_bridge ? contactsFound() - before : 0;
        sync();
    }

    StepCost cost() const override
    {
        StepCost c;
        if (m_bridge) {
            const sdfccd_bullet::SoftBodyStats s = sdfccd_bullet::softBodyStats(*m_bridge);
            c.ccd_queries = s.face_queries;
            c.hits = s.node_contacts + s.face_contacts;
            c.query_errors = s.query_errors;
            c.sdf_evaluations = s.sdf_evaluations;
            c.freezes = s.guard_nodes;
        }
        c.triangles_tested = -1;
        // The bridge's contacts of the step (RContacts, or planes held in Bullet's position iterations).
        c.contacts = m_bridge ? (int)m_step_contacts : m_cloth ? m_cloth->m_rcontacts.size() : 0;
        return c;
    }
    double energy() const override { return NAN; }
    const char* precision() const override { return SDFCCD_BULLET_PRECISION_NAME; }
    std::string describe() const override
    {
        std::ostringstream s;
        s << "btSoftBody cloth " << kN << "x" << kN << " (CreatePatch) on the bunny "
          << (m_btsdf ? "btSdfCollisionShape" : m_opt.stock ? "isosurface (btBvhTriangleMeshShape)" : "SdfShape");
        if (m_opt.stock) s << ", stock Bullet (no bridge)";
        else s << ", bridge " << methodName(m_opt.method) << (m_opt.subdivision ? " + subdivision" : "")
               << (m_opt.method == SDFCCD_METHOD_DCD ? " (discrete, no guard)" : " + guard");
        s << ", soft margin " << kMargin << " m";
        return s.str();
    }

private:
    int64_t contactsFound() const
    {
        const sdfccd_bullet::SoftBodyStats s = sdfccd_bullet::softBodyStats(*m_bridge);
        return s.node_contacts + s.face_contacts;
    }

    void sync()
    {
        std::vector<double> x(3 * (size_t)m_cloth->m_nodes.size());
        for (int i = 0; i < m_cloth->m_nodes.size(); ++i)
            for (int k = 0; k < 3; ++k) x[3 * (size_t)i + k] = (double)m_cloth->m_nodes[i].m_x[k];
        bodies[0].mesh->samplesFor(x.data(), bodies[0].world);
    }

    void addStatic(btCollisionShape* shape, const btVector3& at)
    {
        m_shapes.emplace_back(shape);
        btRigidBody::btRigidBodyConstructionInfo ci(0, nullptr, shape);
        ci.m_startWorldTransform.setIdentity();
        ci.m_startWorldTransform.setOrigin(at);
        ci.m_friction = 0.8f;
        m_rigid.emplace_back(new btRigidBody(ci));
        m_world->addRigidBody(m_rigid.back().get());
    }

    // The grid as Bullet's btSdfCollisionShape (saved as .cdf, read back by Bullet).
    btCollisionShape* btSdfShape(sdfccd_SdfId grid)
    {
        const std::string path = "/tmp/sdfccd_cloth_bunny_" + std::to_string((long)getpid()) + ".cdf";
        if (sdfccd_save_grid(grid, path.c_str()) != SDFCCD_OK) {
            std::fprintf(stderr, "cloth: sdfccd_save_grid(%s): %s\n", path.c_str(), sdfccd_last_error());
            return nullptr;
        }
        std::ifstream in(path, std::ios::binary);
        m_file.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        std::remove(path.c_str());
        btSdfCollisionShape* s = new btSdfCollisionShape();
        if (!s->initializeSDF(m_file.data(), (int)m_file.size())) {
            std::fprintf(stderr, "cloth: btSdfCollisionShape::initializeSDF failed\n");
            delete s;
            return nullptr;
        }
        // The bridge reads the same bytes with sdfccd's grid evaluator (not queryPoint).
        if (m_bridge && m_bridge->setBtSdfData(s, m_file.data(), m_file.size()) != sdfccd_bullet::Status::Ok)
            std::fprintf(stderr, "cloth: Bridge::setBtSdfData failed\n");
        return s;
    }

    // The grid's isosurface as a btBvhTriangleMeshShape (what stock Bullet users collide with).
    btCollisionShape* isosurface(sdfccd_SdfId grid, sdfccd_Aabb box, int res)
    {
        sdfccd_MeshId id{};
        std::vector<double> v;
        std::vector<uint32_t> f;
        sdfccd_MeshInfo info;
        if (sdfccd_extract_isosurface(grid, box, res, &id) != SDFCCD_OK || !takeMeshArrays(id, v, f, info)) {
            std::fprintf(stderr, "cloth: isosurface failed\n");
            return nullptr;
        }
        m_iso_v.assign(v.begin(), v.end());
        m_iso_f.assign(f.begin(), f.end());
        m_iso.reset(new btTriangleIndexVertexArray((int)(m_iso_f.size() / 3), m_iso_f.data(), 3 * (int)sizeof(int),
                                                   (int)(m_iso_v.size() / 3), m_iso_v.data(), 3 * (int)sizeof(btScalar)));
        return new btBvhTriangleMeshShape(m_iso.get(), true);
    }

    Options m_opt;
    bool m_btsdf;
    std::vector<sdfccd_SdfId> m_owned;
    sdfccd_MeshId m_exact{};
    std::unique_ptr<btSoftBodyRigidBodyCollisionConfiguration> m_config;
    std::unique_ptr<btCollisionDispatcher> m_dispatcher;
    std::unique_ptr<btDbvtBroadphase> m_broadphase;
    std::unique_ptr<btSequentialImpulseConstraintSolver> m_solver;
    std::unique_ptr<sdfccd_bullet::Bridge> m_bridge;
    std::unique_ptr<btSoftRigidDynamicsWorld> m_world;
    std::vector<std::unique_ptr<btCollisionShape>> m_shapes;
    std::vector<std::unique_ptr<btRigidBody>> m_rigid;
    btSoftBody* m_cloth = nullptr;
    int64_t m_step_contacts = 0;
    std::vector<char> m_file;
    std::vector<btScalar> m_iso_v;
    std::vector<int> m_iso_f;
    std::unique_ptr<btTriangleIndexVertexArray> m_iso;
};

Scene* createCloth(const Options& opt) { return built(new Cloth(opt, false)); }
Scene* createClothBtSdf(const Options& opt) { return built(new Cloth(opt, true)); }

} // namespace

void appendClothScenes(std::vector<SceneEntry>& t)
{
    t.push_back({ "cloth", "Fig. 9: Bullet's btSoftBody cloth over the bunny SDF, 10 ms steps (bridge soft-body contacts)", createCloth, 300, 0.01 });
    t.push_back({ "cloth-1ms", "Fig. 9: the same cloth at 1 ms steps", createCloth, 3000, 0.001 });
    t.push_back({ "cloth-btsdf", "the same cloth over the bunny as Bullet's btSdfCollisionShape, 10 ms steps", createClothBtSdf, 300, 0.01 });
}

} // namespace scenes
