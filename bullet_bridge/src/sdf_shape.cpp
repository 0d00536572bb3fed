// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: the SDF collision shape (see sdf_shape.h).
#include "sdfccd_bullet/sdf_shape.h"

#include "internal.h"

#include <algorithm>
#include <cmath>

#include <BulletCollision/CollisionShapes/btBvhTriangleMeshShape.h>
#include <BulletCollision/CollisionShapes/btTriangleIndexVertexArray.h>
#include <LinearMath/btAabbUtil2.h>

SDFCCD_BULLET_NAMESPACE_BEGIN

using detail::kNullSdf;

namespace {

double coord(const sdfccd_Vec3& v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }

// Destroys the scaled query SDF, if any.
void dropScaled(sdfccd_SdfId& scaled, bool& valid)
{
    if (scaled.index1 != 0) sdfccd_destroy_sdf(scaled);
    scaled = kNullSdf;
    valid = false;
}

double stretchEval(sdfccd_Vec3 p, sdfccd_Vec3* out_grad, void* user)
{
    // phi(x) = min(s) * phi_child(x / s): never above the distance to the stretched solid.
    const SdfShape* shape = static_cast<const SdfShape*>(user);
    const btVector3& sc = shape->getLocalScaling();
    const double s[3] = { (double)sc.x(), (double)sc.y(), (double)sc.z() }, smin = std::min(s[0], std::min(s[1], s[2]));
    sdfccd_Vec3 q = { p.x / s[0], p.y / s[1], p.z / s[2] };
    double v = 0.0;
    sdfccd_Vec3 g = { 0, 0, 1 };
    if (sdfccd_sdf_eval(shape->sdf(), q, &v, &g) != SDFCCD_OK) v = INFINITY;
    if (out_grad) {
        sdfccd_Vec3 h = { g.x * smin / s[0], g.y * smin / s[1], g.z * smin / s[2] };
        *out_grad = h;
    }
    return smin * v;
}

} // namespace

SdfShape::SdfShape(sdfccd_SdfId sdf, int shape_type)
    : m_sdf(sdf), m_valid(false), m_scaling(1, 1, 1), m_margin(0), m_resolution(48), m_scaled(kNullSdf), m_scaledValid(false),
      m_triangulated(false), m_meshInterface(nullptr), m_bvh(nullptr), m_misuseReported(0)
{
    m_shapeType = shape_type;
    m_lo.setValue(-BT_LARGE_FLOAT, -BT_LARGE_FLOAT, -BT_LARGE_FLOAT);
    m_hi.setValue(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT);
    sdfccd_SdfInfo info;
    m_valid = sdfccd_sdf_get_info(sdf, &info) == SDFCCD_OK;
    if (!m_valid) {
        // An empty box at the origin (not the whole world): nothing pairs with a dead shape.
        m_lo.setValue(0, 0, 0);
        m_hi.setValue(0, 0, 0);
    } else {
        for (int i = 0; i < 3; ++i) { // the bounds within the domain
            const double lo = std::max(coord(info.bounds.lo, i), coord(info.domain.lo, i));
            const double hi = std::min(coord(info.bounds.hi, i), coord(info.domain.hi, i));
            if (std::isfinite(lo)) m_lo[i] = (btScalar)lo;
            if (std::isfinite(hi)) m_hi[i] = (btScalar)hi;
        }
    }
}

SdfShape* SdfShape::create(sdfccd_SdfId sdf, int shape_type, sdfccd_Status* status)
{
    sdfccd_SdfInfo info;
    sdfccd_Status st = sdfccd_sdf_get_info(sdf, &info);
    if (status) *status = st;
    if (st != SDFCCD_OK) return nullptr;
    return new SdfShape(sdf, shape_type);
}

SdfShape::~SdfShape()
{
    dropDerived();
}

void SdfShape::dropDerived() const
{
    dropScaled(m_scaled, m_scaledValid);
    delete m_bvh;
    m_bvh = nullptr;
    delete m_meshInterface;
    m_meshInterface = nullptr;
    m_vertices.clear();
    m_indices.clear();
    m_triangulated = false;
}

void SdfShape::setLocalBounds(const btVector3& lo, const btVector3& hi)
{
    m_lo = lo;
    m_hi = hi;
    dropDerived();
}

void SdfShape::getLocalBounds(btVector3& lo, btVector3& hi) const
{
    lo = m_lo;
    hi = m_hi;
}

double SdfShape::getFeatureSize() const
{
    const btVector3 s = m_scaling.absolute();
    return m_featureSize * (double)btMin(s.x(), btMin(s.y(), s.z()));
}

bool SdfShape::hasFiniteBounds() const
{
    for (int i = 0; i < 3; ++i) // (NaN fails every comparison)
        if (!(m_lo[i] > -BT_LARGE_FLOAT && m_hi[i] < BT_LARGE_FLOAT && m_hi[i] >= m_lo[i])) return false;
    return true;
}

void SdfShape::setTriangulationResolution(int cells)
{
    m_resolution = std::max(1, std::min(cells, 1024));
    dropDerived();
}

void SdfShape::setLocalScaling(const btVector3& scaling)
{
    btVector3 s = scaling.absolute();
    for (int i = 0; i < 3; ++i)
        if (!(s[i] > btScalar(0))) s[i] = btScalar(1); // zero or NaN scaling is meaningless here
    if (s == m_scaling) return;
    m_scaling = s;
    dropScaled(m_scaled, m_scaledValid); // (the triangulation is unscaled: its BVH shape scales)
    if (m_bvh) m_bvh->setLocalScaling(m_scaling);
}

sdfccd_SdfId SdfShape::querySdf() const
{
    if (m_scaling == btVector3(1, 1, 1)) return m_sdf;
    if (m_scaledValid) return m_scaled;
    m_scaledValid = true;
    const double sx = m_scaling.x(), sy = m_scaling.y(), sz = m_scaling.z();
    sdfccd_Status st;
    if (sx == sy && sy == sz) {
        st = sdfccd_create_transformed(m_sdf, sdfccd_pose_identity(), sx, &m_scaled);
    } else {
        sdfccd_CallbackSdfDef def = sdfccd_default_callback_sdf_def();
        def.eval = stretchEval;
        def.user = const_cast<SdfShape*>(this);
        if (hasFiniteBounds()) { // (else the default's infinite bounds)
            def.bounds.lo = sdfccd_Vec3{ m_lo.x() * sx, m_lo.y() * sy, m_lo.z() * sz };
            def.bounds.hi = sdfccd_Vec3{ m_hi.x() * sx, m_hi.y() * sy, m_hi.z() * sz };
        }
        st = sdfccd_create_callback_sdf(&def, &m_scaled);
    }
    if (st != SDFCCD_OK) m_scaled = kNullSdf;
    return m_scaled;
}

void SdfShape::getAabb(const btTransform& t, btVector3& aabbMin, btVector3& aabbMax) const
{
    if (!hasFiniteBounds()) {
        aabbMin.setValue(-BT_LARGE_FLOAT, -BT_LARGE_FLOAT, -BT_LARGE_FLOAT);
        aabbMax.setValue(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT);
        return;
    }
    btVector3 lo = m_lo * m_scaling, hi = m_hi * m_scaling; // scaling is positive
    btTransformAabb(lo, hi, m_margin, t, aabbMin, aabbMax);
}

void SdfShape::calculateLocalInertia(btScalar mass, btVector3& inertia) const
{
    if (!hasFiniteBounds()) {
        inertia.setValue(0, 0, 0);
        return;
    }
    btVector3 e = (m_hi - m_lo) * m_scaling;
    btScalar k = mass / btScalar(12);
    inertia.setValue(k * (e.y() * e.y() + e.z() * e.z()), k * (e.x() * e.x() + e.z() * e.z()),
                     k * (e.x() * e.x() + e.y() * e.y()));
}

int SdfShape::buildTriangulation() const
{
    if (m_triangulated) return getTriangulationTriangleCount();
    m_triangulated = true;
    if (!hasFiniteBounds()) return 0;
    // Pad the box by a little more than a cell so the surface is not capped at the bounds.
    btVector3 ext = m_hi - m_lo;
    double cell = std::max((double)ext.x(), std::max((double)ext.y(), (double)ext.z())) / m_resolution;
    if (!(cell > 0)) return 0;
    double pad = 1.5 * cell;
    sdfccd_Aabb box;
    box.lo.x = m_lo.x() - pad; box.lo.y = m_lo.y() - pad; box.lo.z = m_lo.z() - pad;
    box.hi.x = m_hi.x() + pad; box.hi.y = m_hi.y() + pad; box.hi.z = m_hi.z() + pad;
    sdfccd_MeshId mesh;
    if (sdfccd_extract_isosurface(m_sdf, box, m_resolution + 3, &mesh) != SDFCCD_OK) return 0;
    sdfccd_MeshInfo info;
    if (sdfccd_mesh_get_info(mesh, &info) != SDFCCD_OK) {
        sdfccd_destroy_mesh(mesh);
        return 0;
    }
    std::vector<double> v(3 * (size_t)info.vertex_count);
    std::vector<uint32_t> f(3 * (size_t)info.triangle_count);
    sdfccd_Status st = sdfccd_mesh_get_data(mesh, v.data(), f.data());
    sdfccd_destroy_mesh(mesh);
    if (st != SDFCCD_OK || info.triangle_count == 0) return 0;
    m_vertices.assign(v.begin(), v.end()); // double -> btScalar
    m_indices.assign(f.begin(), f.end());
    m_meshInterface = new btTriangleIndexVertexArray((int)info.triangle_count, m_indices.data(), 3 * (int)sizeof(int),
                                                     (int)info.vertex_count, m_vertices.data(), 3 * (int)sizeof(btScalar));
    m_bvh = new btBvhTriangleMeshShape(m_meshInterface, true, true);
    m_bvh->setLocalScaling(m_scaling);
    return (int)info.triangle_count;
}

int SdfShape::getTriangulationTriangleCount() const
{
    return (int)(m_indices.size() / 3);
}

void SdfShape::processAllTriangles(btTriangleCallback* callback, const btVector3& aabbMin, const btVector3& aabbMax) const
{
    // A registered bridge handles every GImpact mesh against a valid SdfShape, so Bullet's GImpact
    // algorithm asking for our triangles means the bridge is not in charge of the pair (reported
    // once per shape and diagnosis).
    if (m_valid && detail::isGImpactCallback(callback)) detail::reportGImpactMisuse(this, m_misuseReported);
    if (!m_triangulated) buildTriangulation();
    if (m_bvh) m_bvh->processAllTriangles(callback, aabbMin, aabbMax);
}

SDFCCD_BULLET_NAMESPACE_END
