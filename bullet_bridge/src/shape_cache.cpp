// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: Bullet shapes as sdfccd meshes and SDF handles (see internal.h).
#include "internal.h"

#include <BulletCollision/CollisionShapes/btShapeHull.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

SDFCCD_BULLET_NAMESPACE_BEGIN
namespace detail {

sdfccd_Pose toPose(const btTransform& t)
{
    sdfccd_Pose p;
    p.position = v3(t.getOrigin());
    btQuaternion q = t.getRotation();
    p.orientation.w = q.w();
    p.orientation.x = q.x();
    p.orientation.y = q.y();
    p.orientation.z = q.z();
    return p;
}

btTransform poseBefore(const btCollisionObject* co, double dt)
{
    const btRigidBody* rb = btRigidBody::upcast(co);
    const bool kin = co->isKinematicObject() || !rb;
    btTransform t;
    btTransformUtil::integrateTransform(co->getWorldTransform(), -(kin ? co->getInterpolationLinearVelocity() : rb->getLinearVelocity()),
                                        -(kin ? co->getInterpolationAngularVelocity() : rb->getAngularVelocity()), (btScalar)dt, t);
    return t;
}

sdfccd_RigidMotion motionOf(const btCollisionObject* co, const btTransform& wrapper_transform, double dt)
{
    btTransform t0 = wrapper_transform, t1 = wrapper_transform;
    btVector3 v(0, 0, 0), w(0, 0, 0);
    // A compound child's offset from its body (identity for a top-level shape).
    const btTransform child = co->getWorldTransform().inverseTimes(wrapper_transform);
    // Kinematic first: Bullet's idiom for a kinematic body (mass 0 plus CF_KINEMATIC_OBJECT)
    // leaves CF_STATIC_OBJECT set as well. saveKinematicState has already moved its world transform
    // to the END of the step: the start pose is rebuilt by integrating backwards. A dynamic body's
    // interpolation transform is its predicted end (predictUnconstraintMotion).
    const bool kinematic = co->isKinematicObject(), moving = dt > 0 && (kinematic || !co->isStaticObject());
    if (moving && kinematic) {
        t0 = poseBefore(co, dt) * child;
    } else if (moving) {
        t1 = co->getInterpolationWorldTransform() * child;
    }
    if (moving) btTransformUtil::calculateVelocity(t0, t1, (btScalar)dt, v, w); // a static body's stay exactly 0
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose = toPose(t0);
    m.linear_velocity = v3(v);
    m.angular_velocity = v3(w);
    return m;
}

namespace {

// Appends triangle (a, b, c). Zero-area ones are dropped by sdfccd_create_mesh (drop_degenerate,
// the core's one zero-area rule), which numbers the others in order: its triangle numbers are then
// the ones of the shape's triangles left.
void pushTriangle(MeshEntry& e, uint32_t a, uint32_t b, uint32_t c)
{
    e.indices.push_back(a);
    e.indices.push_back(b);
    e.indices.push_back(c);
}

void pushVertex(MeshEntry& e, const btVector3& v)
{
    e.vertices.push_back((double)v.x());
    e.vertices.push_back((double)v.y());
    e.vertices.push_back((double)v.z());
}

void packPart(const btGImpactMeshShapePart* part, MeshEntry& e)
{
    part->lockChildShapes();
    const uint32_t base = (uint32_t)(e.vertices.size() / 3);
    const int nv = part->getVertexCount();
    for (int i = 0; i < nv; ++i) {
        btVector3 v;
        part->getVertex(i, v); // scaled by the shape's local scaling
        pushVertex(e, v);
    }
    btGImpactMeshShapePart::TrimeshPrimitiveManager* pm =
        const_cast<btGImpactMeshShapePart*>(part)->getTrimeshPrimitiveManager();
    const int nt = part->getNumChildShapes();
    for (int t = 0; t < nt; ++t) {
        unsigned int a, b, c;
        pm->get_indices(t, a, b, c);
        if ((int)a >= nv || (int)b >= nv || (int)c >= nv) continue;
        pushTriangle(e, base + a, base + b, base + c);
    }
    part->unlockChildShapes();
}

int gimpactCount(const btGImpactShapeInterface* g)
{
    if (g->getGImpactShapeType() == CONST_GIMPACT_TRIMESH_SHAPE) {
        const btGImpactMeshShape* m = static_cast<const btGImpactMeshShape*>(g);
        int n = 0;
        for (int i = 0; i < m->getMeshPartCount(); ++i) n += m->getMeshPart(i)->getNumChildShapes();
        return n;
    }
    return g->getNumChildShapes();
}

// The box with its collision margin (Bullet's box surface), 12 outward triangles.
void packBox(const btBoxShape* box, MeshEntry& e)
{
    const btVector3 h = box->getHalfExtentsWithMargin();
    for (int i = 0; i < 8; ++i)
        pushVertex(e, btVector3((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z()));
    static const uint32_t faces[12][3] = { { 0, 2, 1 }, { 1, 2, 3 }, { 4, 5, 6 }, { 5, 7, 6 }, { 0, 1, 4 }, { 1, 5, 4 },
                                           { 2, 6, 3 }, { 3, 6, 7 }, { 0, 4, 2 }, { 2, 4, 6 }, { 1, 3, 5 }, { 3, 7, 5 } };
    for (const auto& f : faces) pushTriangle(e, f[0], f[1], f[2]);
}

// Any other convex shape: the hull of its support points (margin included) in 42+ directions.
void packConvex(const btConvexShape* convex, MeshEntry& e)
{
    btShapeHull hull(convex);
    if (!hull.buildHull(0, 1)) return;
    for (int i = 0; i < hull.numVertices(); ++i) pushVertex(e, hull.getVertexPointer()[i]);
    const unsigned int* idx = hull.getIndexPointer();
    for (int t = 0; t < hull.numTriangles(); ++t) pushTriangle(e, idx[3 * t], idx[3 * t + 1], idx[3 * t + 2]);
}

// An SdfShape as the moving side of an SDF-SDF pair: its isosurface triangulation, scaled.
void packSdfShape(const SdfShape* s, MeshEntry& e)
{
    s->buildTriangulation();
    const std::vector<btScalar>& v = s->triangulationVertices();
    const std::vector<int>& f = s->triangulationIndices();
    const btVector3& k = s->getLocalScaling();
    for (size_t i = 0; i + 2 < v.size(); i += 3) pushVertex(e, btVector3(v[i], v[i + 1], v[i + 2]) * k);
    for (size_t i = 0; i + 2 < f.size(); i += 3) pushTriangle(e, (uint32_t)f[i], (uint32_t)f[i + 1], (uint32_t)f[i + 2]);
}

// The number that must not change for a cached pack to stay valid.
int sourceCount(const btCollisionShape* shape)
{
    if (shape->getShapeType() == GIMPACT_SHAPE_PROXYTYPE)
        return gimpactCount(static_cast<const btGImpactShapeInterface*>(shape));
    if (const SdfShape* s = dynamic_cast<const SdfShape*>(shape)) return s->getTriangulationResolution();
    return 0;
}

// queryPoint as the sampled field of sdfccd_create_sampled_sdf (its normal normalised).
int32_t queryPointField(sdfccd_Vec3 p, double* out_value, sdfccd_Vec3* out_grad, void* shape)
{
    btScalar d = 0;
    btVector3 n(0, 0, 0);
    if (!static_cast<btSdfCollisionShape*>(shape)->queryPoint(bt(p), d, n)) return 0;
    *out_value = (double)d;
    const btScalar l = n.length();
    *out_grad = v3(l > btScalar(0) ? n / l : btVector3(0, 0, 1));
    return 1;
}

// queryPoint as a sample of the field (sdfccd_sdf_compare_samples).
int32_t queryPointSample(sdfccd_Vec3 p, double* out_value, void* shape)
{
    sdfccd_Vec3 unused;
    return queryPointField(p, out_value, &unused, shape);
}

// The shape's box in its own frame, and its diagonal.
sdfccd_Aabb localBox(const btCollisionShape* shape, double* diagonal)
{
    btVector3 lo, hi;
    shape->getAabb(btTransform::getIdentity(), lo, hi);
    *diagonal = (double)(hi - lo).length();
    const sdfccd_Aabb box = { v3(lo), v3(hi) };
    return box;
}

} // namespace

ShapeCache::~ShapeCache()
{
    while (!m_meshes.empty()) invalidate(m_meshes.begin()->first);
    while (!m_bt_sdfs.empty()) invalidate(m_bt_sdfs.begin()->first);
}

const MeshEntry* ShapeCache::meshFor(const btCollisionShape* shape)
{
    const int type = shape->getShapeType();
    const btGImpactShapeInterface* g = nullptr;
    const SdfShape* sdf_shape = nullptr;
    if (type == GIMPACT_SHAPE_PROXYTYPE) {
        g = static_cast<const btGImpactShapeInterface*>(shape);
        if (g->getGImpactShapeType() == CONST_GIMPACT_COMPOUND_SHAPE) return nullptr;
    } else if (!shape->isConvex()) {
        sdf_shape = dynamic_cast<const SdfShape*>(shape);
        if (!sdf_shape) return nullptr;
    }
    const int count = sourceCount(shape);
    auto it = m_meshes.find(shape);
    if (it != m_meshes.end()) {
        const MeshEntry& e = it->second;
        if (e.scaling == shape->getLocalScaling() && e.margin == shape->getMargin() && e.source_count == count)
            return e.ok ? &e : nullptr;
        invalidate(shape);
    }
    MeshEntry& e = m_meshes[shape];
    e.scaling = shape->getLocalScaling();
    e.margin = shape->getMargin();
    e.source_count = count;
    if (g) {
        if (g->getGImpactShapeType() == CONST_GIMPACT_TRIMESH_SHAPE) {
            const btGImpactMeshShape* m = static_cast<const btGImpactMeshShape*>(g);
            for (int i = 0; i < m->getMeshPartCount(); ++i) packPart(m->getMeshPart(i), e);
        } else {
            packPart(static_cast<const btGImpactMeshShapePart*>(g), e);
        }
    } else if (sdf_shape) {
        packSdfShape(sdf_shape, e);
    } else if (type == BOX_SHAPE_PROXYTYPE) {
        packBox(static_cast<const btBoxShape*>(shape), e);
    } else {
        packConvex(static_cast<const btConvexShape*>(shape), e);
    }
    if (e.indices.empty()) return nullptr;
    sdfccd_MeshDef def = sdfccd_default_mesh_def();
    def.vertices = e.vertices.data();
    def.vertex_count = (uint32_t)(e.vertices.size() / 3);
    def.indices = e.indices.data();
    def.triangle_count = (uint32_t)(e.indices.size() / 3);
    def.drop_degenerate = 1;
    e.ok = sdfccd_create_mesh(&def, &e.id) == SDFCCD_OK;
    return e.ok ? &e : nullptr;
}

sdfccd_SdfId ShapeCache::sdfFor(const btCollisionShape* shape, int sdf_shape_type, bool bt_sdf)
{
    const int type = shape->getShapeType();
    if (type == sdf_shape_type)
        if (const SdfShape* s = dynamic_cast<const SdfShape*>(shape)) return s->querySdf();
    if (type == SDF_SHAPE_PROXYTYPE && bt_sdf)
        if (const btSdfCollisionShape* s = dynamic_cast<const btSdfCollisionShape*>(shape)) return btSdfFor(s);
    return kNullSdf;
}

sdfccd_SdfId ShapeCache::btSdfFor(const btSdfCollisionShape* shape)
{
    auto it = m_bt_sdfs.find(shape);
    if (it != m_bt_sdfs.end()) return it->second;
    // queryPoint in the shape's box (queryPoint is non-const but only reads).
    double diagonal;
    const sdfccd_Aabb box = localBox(shape, &diagonal);
    sdfccd_SdfId& sdf = m_bt_sdfs[shape];
    if (sdfccd_create_sampled_sdf(queryPointField, const_cast<btSdfCollisionShape*>(shape), box, 0.05 * diagonal, &sdf) != SDFCCD_OK)
        sdf = kNullSdf;
    return sdf;
}

bool ShapeCache::setBtSdfData(const btSdfCollisionShape* shape, const void* data, size_t size)
{
    sdfccd_SdfId grid;
    if (!shape || !data || sdfccd_load_grid_memory(data, size, &grid) != SDFCCD_OK) return false;
    // The same field as the shape's (queryPoint) at 125 points of its box, to the float build's precision.
    double diagonal, diff = 0;
    const sdfccd_Aabb box = localBox(shape, &diagonal);
    if (sdfccd_sdf_compare_samples(grid, queryPointSample, const_cast<btSdfCollisionShape*>(shape), box, 5, &diff, nullptr) != SDFCCD_OK ||
        !(diff <= 1e-5 * diagonal)) {
        sdfccd_destroy_sdf(grid);
        return false;
    }
    invalidate(shape);
    m_bt_sdfs[shape] = grid; // (the grid is the field, not queryPoint)
    return true;
}

void ShapeCache::invalidate(const btCollisionShape* shape)
{
    auto it = m_meshes.find(shape);
    if (it != m_meshes.end()) {
        if (it->second.id.index1) sdfccd_destroy_mesh(it->second.id);
        m_meshes.erase(it);
    }
    auto jt = m_bt_sdfs.find(shape);
    if (jt != m_bt_sdfs.end()) {
        if (jt->second.index1) sdfccd_destroy_sdf(jt->second);
        m_bt_sdfs.erase(jt);
    }
}

} // namespace detail
SDFCCD_BULLET_NAMESPACE_END
