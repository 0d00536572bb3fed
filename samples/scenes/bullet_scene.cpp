// SPDX-License-Identifier: MIT
// BulletScene: the world, the bridge (or Bullet's stock GImpact path), bodies and static SDFs.
#include "bullet_scene.h"

#include <chrono>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>

#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>

namespace scenes {

struct BulletScene::GImpactAsset {
    std::shared_ptr<MeshData> mesh;
    std::vector<btScalar> v;
    std::vector<int> f;
    std::unique_ptr<btTriangleIndexVertexArray> tiva;
    std::unique_ptr<btGImpactMeshShape> shape;
};

struct BulletScene::StockMesh {
    std::vector<btScalar> v;
    std::vector<int> f;
    std::unique_ptr<btTriangleIndexVertexArray> tiva;
    std::unique_ptr<btBvhTriangleMeshShape> shape;
};

btQuaternion axisAngle(double ax, double ay, double az, double angle)
{
    return btQuaternion(btVector3((btScalar)ax, (btScalar)ay, (btScalar)az).normalized(), (btScalar)angle);
}

btQuaternion tumble(int i)
{
    // Golden-ratio sequence on the sphere of axes, angles spread over [0, 2 pi).
    double a = 2.399963229728653 * i, z = 1 - (2.0 * ((i * 7) % 13) + 1) / 13.0;
    double r = std::sqrt(std::max(0.0, 1 - z * z));
    return axisAngle(r * std::cos(a), r * std::sin(a), z, std::fmod(1.7 * i + 0.4, 6.283185307179586));
}

BulletWorld::BulletWorld(const btVector3& gravity, sdfccd_bullet::Bridge* bridge)
    : dispatcher(&config), world(&dispatcher, &broadphase, &solver, &config)
{
    world.setGravity(gravity);
    if (bridge) status = bridge->registerWith(&world);
    else btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
}

BulletScene::BulletScene(const Options& opt, const btVector3& gravity, int up_axis)
    : m_opt(opt), m_gravity(gravity), m_up(up_axis)
{
    up[0] = up[1] = up[2] = 0;
    up[up_axis] = 1;
    for (int k = 0; k < 3; ++k) this->gravity[k] = (double)gravity[k];
    sdfccd_bullet::Config cfg;
    cfg.query.method = opt.method;
    cfg.query.subdivision = opt.subdivision ? 1 : 0;
    if (opt.margin >= 0) cfg.contact_margin = opt.margin;
    if (!std::isnan(opt.guard)) cfg.guard_tolerance = opt.guard > 0 ? opt.guard : 0;
    if (opt.batch_threads >= 1) cfg.batch_threads = opt.batch_threads;
    ccd_margin = cfg.contact_margin;
    if (!opt.stock) m_bridge.reset(new sdfccd_bullet::Bridge(cfg)); // before the world, destroyed after it
    if (m_bridge && !(cfg.guard_tolerance > 0)) m_description += " [guarantee off]";
    m_bullet.reset(new BulletWorld(gravity, m_bridge.get()));
    m_world = &m_bullet->world;
    m_dispatcher = &m_bullet->dispatcher;
    if (opt.solver_iterations > 0) m_world->getSolverInfo().m_numIterations = opt.solver_iterations;
    if (m_bullet->status != sdfccd_bullet::Status::Ok)
        std::fprintf(stderr, "sdfccd_scenes: bridge registration failed: %s\n", sdfccd_bullet::statusString(m_bullet->status));
}

BulletScene::~BulletScene()
{
    for (auto& b : m_rigid) m_world->removeRigidBody(b.get());
    m_rigid.clear();
    m_bullet.reset();
    m_world = nullptr;
    m_dispatcher = nullptr;
    m_shapes.clear();
    m_stock.clear();
    m_assets.clear();
    m_bridge.reset();
    for (sdfccd_SdfId id : m_sdfs) sdfccd_destroy_sdf(id);
    for (sdfccd_MeshId id : m_meshes) sdfccd_destroy_mesh(id);
}

sdfccd_SdfId BulletScene::own(sdfccd_SdfId id)
{
    if (id.index1) m_sdfs.push_back(id);
    return id;
}

BulletScene::GImpactAsset* BulletScene::assetFor(const std::shared_ptr<MeshData>& mesh)
{
    for (auto& a : m_assets)
        if (a->mesh == mesh) return a.get();
    std::unique_ptr<GImpactAsset> a(new GImpactAsset);
    a->mesh = mesh;
    a->v.assign(mesh->v.begin(), mesh->v.end());
    a->f.assign(mesh->f.begin(), mesh->f.end());
    a->tiva.reset(new btTriangleIndexVertexArray(mesh->triangleCount(), a->f.data(), 3 * (int)sizeof(int),
                                                 mesh->vertexCount(), a->v.data(), 3 * (int)sizeof(btScalar)));
    a->shape.reset(new btGImpactMeshShape(a->tiva.get()));
    a->shape->setMargin(0); // as Bullet's GImpact demo
    a->shape->updateBound();
    m_assets.push_back(std::move(a));
    return m_assets.back().get();
}

btRigidBody* BulletScene::addMeshBody(const std::shared_ptr<MeshData>& mesh, double mass, const btVector3& pos,
                                      const btQuaternion& rot)
{
    GImpactAsset* a = assetFor(mesh);
    btVector3 inertia(0, 0, 0);
    if (mass > 0) a->shape->calculateLocalInertia((btScalar)mass, inertia);
    m_motions.emplace_back(new btDefaultMotionState(btTransform(rot, pos)));
    btRigidBody::btRigidBodyConstructionInfo info((btScalar)mass, m_motions.back().get(), a->shape.get(), inertia);
    m_rigid.emplace_back(new btRigidBody(info));
    btRigidBody* body = m_rigid.back().get();
    m_world->addRigidBody(body);
    if (mass > 0) {
        Body b;
        b.name = mesh->name;
        b.mesh = mesh;
        bodies.push_back(b);
        m_bodyIndex.push_back((int)bodies.size() - 1);
    } else {
        m_bodyIndex.push_back(-1);
    }
    syncBodies();
    return body;
}

static Frame frameOf(const btTransform& t)
{
    Frame f;
    const btMatrix3x3& b = t.getBasis();
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) f.R[3 * r + c] = (double)b[r][c];
    for (int k = 0; k < 3; ++k) f.p[k] = (double)t.getOrigin()[k];
    return f;
}

Collider& BulletScene::addStaticSdf(const std::string& name, sdfccd_SdfId sdf, const btVector3& pos, const btQuaternion& rot,
                                    sdfccd_Aabb bounds, int stock_resolution, sdfccd_SdfId exact, sdfccd_MeshId exact_mesh,
                                    double feature_size)
{
    own(sdf);
    if (exact.index1 && (exact.index1 != sdf.index1 || exact.generation != sdf.generation)) own(exact);
    if (exact_mesh.index1) m_meshes.push_back(exact_mesh);
    btCollisionShape* shape = nullptr;
    if (m_opt.stock) {
        std::unique_ptr<StockMesh> sm(new StockMesh);
        sdfccd_MeshId id{};
        sdfccd_Status st = sdfccd_extract_isosurface(sdf, bounds, stock_resolution, &id);
        sdfccd_MeshInfo info;
        std::vector<double> v;
        std::vector<uint32_t> f;
        if (st != SDFCCD_OK) {
            std::fprintf(stderr, "sdfccd_scenes: isosurface of %s failed: %s\n", name.c_str(), sdfccd_last_error());
        } else if (takeMeshArrays(id, v, f, info)) {
            sm->v.assign(v.begin(), v.end());
            sm->f.assign(f.begin(), f.end());
            sm->tiva.reset(new btTriangleIndexVertexArray((int)info.triangle_count, sm->f.data(), 3 * (int)sizeof(int),
                                                          (int)info.vertex_count, sm->v.data(), 3 * (int)sizeof(btScalar)));
            sm->shape.reset(new btBvhTriangleMeshShape(sm->tiva.get(), true));
            shape = sm->shape.get();
            char buf[128];
            std::snprintf(buf, sizeof buf, " [stock %s: %u triangles]", name.c_str(), info.triangle_count);
            m_description += buf;
        }
        m_stock.push_back(std::move(sm));
        if (!shape) {
            m_shapes.emplace_back(new btEmptyShape());
            shape = m_shapes.back().get();
        }
    } else {
        sdfccd_bullet::SdfShape* s = new sdfccd_bullet::SdfShape(sdf);
        s->setFeatureSize(feature_size);
        if (!s->hasFiniteBounds()) s->setLocalBounds(btVector3((btScalar)bounds.lo.x, (btScalar)bounds.lo.y, (btScalar)bounds.lo.z),
                                                     btVector3((btScalar)bounds.hi.x, (btScalar)bounds.hi.y, (btScalar)bounds.hi.z));
        m_shapes.emplace_back(s);
        shape = s;
    }
    btTransform t(rot, pos);
    m_rigid.emplace_back(new btRigidBody(0, nullptr, shape));
    m_rigid.back()->setWorldTransform(t);
    m_rigid.back()->setFriction(0.9f);
    m_world->addRigidBody(m_rigid.back().get());
    m_bodyIndex.push_back(-1);
    Collider c;
    c.name = name;
    c.frame = frameOf(t);
    c.exact = exact;
    c.exact_mesh = exact_mesh;
    c.ccd = sdf;
    c.bounds = bounds;
    colliders.push_back(c);
    return colliders.back();
}

Collider& BulletScene::addStaticBtSdf(const std::string& name, const std::string& cdf_path, sdfccd_SdfId grid, const btVector3& pos,
                                      int stock_resolution)
{
    sdfccd_GridInfo gi;
    sdfccd_grid_get_info(grid, &gi);
    if (m_opt.stock)
        return addStaticSdf(name, grid, pos, btQuaternion::getIdentity(), gi.domain, stock_resolution, grid);
    own(grid);
    std::ifstream in(cdf_path, std::ios::binary);
    m_files.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    btSdfCollisionShape* s = new btSdfCollisionShape();
    if (!s->initializeSDF(m_files.back().data(), (int)m_files.back().size()))
        std::fprintf(stderr, "sdfccd_scenes: btSdfCollisionShape::initializeSDF(%s) failed\n", cdf_path.c_str());
    m_shapes.emplace_back(s);
    // The bridge evaluates the shape with sdfccd's grid of the same bytes (not queryPoint).
    if (m_bridge && m_bridge->setBtSdfData(s, m_files.back().data(), m_files.back().size()) != sdfccd_bullet::Status::Ok)
        std::fprintf(stderr, "sdfccd_scenes: Bridge::setBtSdfData(%s) failed\n", cdf_path.c_str());
    btTransform t(btQuaternion::getIdentity(), pos);
    m_rigid.emplace_back(new btRigidBody(0, nullptr, s));
    m_rigid.back()->setWorldTransform(t);
    m_world->addRigidBody(m_rigid.back().get());
    m_bodyIndex.push_back(-1);
    Collider c;
    c.name = name;
    c.frame = frameOf(t);
    c.exact = grid;
    c.ccd = grid;
    c.bounds = gi.domain;
    colliders.push_back(c);
    m_description += " [btSdfCollisionShape]";
    return colliders.back();
}

void BulletScene::syncBodies()
{
    for (size_t i = 0; i < m_rigid.size(); ++i) {
        int k = m_bodyIndex[i];
        if (k < 0) continue;
        const btRigidBody* r = m_rigid[i].get();
        Body& b = bodies[(size_t)k];
        b.frame = frameOf(r->getWorldTransform());
        for (int j = 0; j < 3; ++j) {
            b.v[j] = (double)r->getLinearVelocity()[j];
            b.w[j] = (double)r->getAngularVelocity()[j];
        }
        b.active = r->isInWorld();
    }
}

void BulletScene::step(int i, double dt)
{
    beforeStep(i);
    m_world->stepSimulation((btScalar)dt, 1, (btScalar)dt);
    syncBodies();
    // SDFCCD_SCENES_TRACE=FILE: every dynamic body's centre, velocity and spin, and every manifold point
    // (triangle, lifetime, point on the mesh, normal, gap, normal and friction impulses, the solver's
    // friction direction) after each step, for diagnosing contacts that do not come to rest.
    static std::FILE* trace = std::getenv("SDFCCD_SCENES_TRACE") ? std::fopen(std::getenv("SDFCCD_SCENES_TRACE"), "w") : nullptr;
    if (trace) traceStep(trace, i);
}

void BulletScene::traceStep(std::FILE* f, int i) const
{
    for (size_t k = 0; k < m_rigid.size(); ++k) {
        const btRigidBody* r = m_rigid[k].get();
        if (r->getInvMass() == 0) continue;
        const btVector3 p = r->getCenterOfMassPosition(), v = r->getLinearVelocity(), w = r->getAngularVelocity();
        std::fprintf(f, "B %d %zu p %.7f %.7f %.7f v %.3e %.3e %.3e w %.3e %.3e %.3e\n", i, k, (double)p[0], (double)p[1], (double)p[2],
                     (double)v[0], (double)v[1], (double)v[2], (double)w[0], (double)w[1], (double)w[2]);
    }
    for (int m = 0; m < m_dispatcher->getNumManifolds(); ++m) {
        btPersistentManifold* mf = m_dispatcher->getManifoldByIndexInternal(m);
        for (int j = 0; j < mf->getNumContacts(); ++j) {
            const btManifoldPoint& c = mf->getContactPoint(j);
            const btVector3 &a = c.m_positionWorldOnA, &n = c.m_normalWorldOnB, &d = c.m_lateralFrictionDir1;
            std::fprintf(f, "C %d m%d j%d tri %d life %d pA %.5f %.5f %.5f n %.4f %.4f %.4f d %.3e imp %.4e lat1 %.4e lat2 %.4e dir1 %.3f %.3f %.3f\n",
                         i, m, j, c.m_index0, c.m_lifeTime, (double)a[0], (double)a[1], (double)a[2], (double)n[0], (double)n[1], (double)n[2],
                         (double)c.m_distance1, (double)c.m_appliedImpulse, (double)c.m_appliedImpulseLateral1, (double)c.m_appliedImpulseLateral2,
                         (double)d[0], (double)d[1], (double)d[2]);
        }
    }
    std::fflush(f);
}

StepCost BulletScene::cost() const
{
    StepCost c;
    if (m_bridge) {
        sdfccd_bullet::Stats s = m_bridge->stats();
        c.ccd_seconds = s.query_seconds;
        c.ccd_queries = s.queries + s.end_pose_queries;
        c.hits = s.hits;
        c.query_errors = s.query_errors;
        c.sdf_evaluations = s.sdf_evaluations + s.own_evaluations;
    }
    c.triangles_tested = -1;
    int n = m_dispatcher->getNumManifolds();
    for (int k = 0; k < n; ++k) c.contacts += m_dispatcher->getManifoldByIndexInternal(k)->getNumContacts();
    return c;
}

double BulletScene::energy() const
{
    double e = 0;
    for (size_t i = 0; i < m_rigid.size(); ++i) {
        const btRigidBody* r = m_rigid[i].get();
        if (m_bodyIndex[i] < 0 || r->getInvMass() == 0 || !r->isInWorld()) continue;
        double m = 1.0 / (double)r->getInvMass();
        btVector3 v = r->getLinearVelocity();
        btVector3 wl = r->getAngularVelocity() * r->getWorldTransform().getBasis(); // R^T w
        btVector3 inv = r->getInvInertiaDiagLocal();
        e += 0.5 * m * (double)v.length2();
        for (int k = 0; k < 3; ++k)
            if (inv[k] > 0) e += 0.5 * (double)(wl[k] * wl[k]) / (double)inv[k];
        e -= m * (double)m_gravity.dot(r->getCenterOfMassPosition());
    }
    return e;
}

std::string BulletScene::describe() const
{
    std::ostringstream s;
    s << bodies.size() << " dynamic meshes, " << colliders.size() << " SDF colliders, "
      << (m_opt.stock ? "stock (SDF surfaces as btBvhTriangleMeshShape, Bullet's GImpact algorithm)"
                      : std::string("bridge, ") + methodName(m_opt.method) + (m_opt.subdivision ? " + subdivision" : ""))
      << m_description;
    return s.str();
}

} // namespace scenes
