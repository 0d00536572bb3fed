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

} // namespace

struct SdfShape::Impl {
    BT_DECLARE_ALIGNED_ALLOCATOR();
    sdfccd_SdfId sdf;
    bool valid = false;
    btVector3 lo, hi; // unscaled local bounds
    btVector3 scaling{ 1, 1, 1 };
    int resolution = 48;
    double feature_size = 0;
    sdfccd_SdfId scaled = kNullSdf; // owned, created on demand
    bool scaled_valid = false;
    // The triangulation, built on first use.
    bool triangulated = false;
    std::vector<btScalar> vertices;
    std::vector<int> indices;
    std::unique_ptr<btTriangleIndexVertexArray> mesh_interface;
    std::unique_ptr<btBvhTriangleMeshShape> bvh;
    int misuse_reported = 0; // the last misuse reported (Status + 1; 0: none)
    void drop();       // everything derived from the handle, bounds and resolution
    void dropScaled(); // the scaled query SDF
};

SdfShape::SdfShape(sdfccd_SdfId sdf, int shape_type) : m_impl(new Impl)
{
    Impl& d = *m_impl;
    d.sdf = sdf;
    m_shapeType = shape_type;
    d.lo.setValue(-BT_LARGE_FLOAT, -BT_LARGE_FLOAT, -BT_LARGE_FLOAT);
    d.hi.setValue(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT);
    sdfccd_SdfInfo info;
    d.valid = sdfccd_sdf_get_info(sdf, &info) == SDFCCD_OK;
    if (!d.valid) {
        // An empty box at the origin (not the whole world): nothing pairs with a dead shape.
        d.lo.setValue(0, 0, 0);
        d.hi.setValue(0, 0, 0);
    } else {
        for (int i = 0; i < 3; ++i) { // the bounds within the domain
            const double lo = std::max(coord(info.bounds.lo, i), coord(info.domain.lo, i));
            const double hi = std::min(coord(info.bounds.hi, i), coord(info.domain.hi, i));
            if (std::isfinite(lo)) d.lo[i] = (btScalar)lo;
            if (std::isfinite(hi)) d.hi[i] = (btScalar)hi;
        }
    }
}

SdfShape::~SdfShape()
{
    m_impl->drop();
}

void SdfShape::Impl::drop()
{
    dropScaled();
    bvh.reset();
    mesh_interface.reset();
    vertices.clear();
    indices.clear();
    triangulated = false;
}

void SdfShape::Impl::dropScaled()
{
    if (scaled.index1 != 0) sdfccd_destroy_sdf(scaled);
    scaled = kNullSdf;
    scaled_valid = false;
}

bool SdfShape::isValid() const { return m_impl->valid; }
sdfccd_SdfId SdfShape::sdf() const { return m_impl->sdf; }
void SdfShape::setFeatureSize(double size) { m_impl->feature_size = size > 0 ? size : 0; }
int SdfShape::getTriangulationResolution() const { return m_impl->resolution; }
const std::vector<btScalar>& SdfShape::triangulationVertices() const { return m_impl->vertices; }
const std::vector<int>& SdfShape::triangulationIndices() const { return m_impl->indices; }
const btVector3& SdfShape::getLocalScaling() const { return m_impl->scaling; }

void SdfShape::setLocalBounds(const btVector3& lo, const btVector3& hi)
{
    m_impl->lo = lo;
    m_impl->hi = hi;
    m_impl->drop();
}

void SdfShape::getLocalBounds(btVector3& lo, btVector3& hi) const
{
    lo = m_impl->lo;
    hi = m_impl->hi;
}

double SdfShape::getFeatureSize() const
{
    const btVector3 s = m_impl->scaling.absolute();
    return m_impl->feature_size * (double)btMin(s.x(), btMin(s.y(), s.z()));
}

bool SdfShape::hasFiniteBounds() const
{
    const Impl& d = *m_impl;
    for (int i = 0; i < 3; ++i) // (NaN fails every comparison)
        if (!(d.lo[i] > -BT_LARGE_FLOAT && d.hi[i] < BT_LARGE_FLOAT && d.hi[i] >= d.lo[i])) return false;
    return true;
}

void SdfShape::setTriangulationResolution(int cells)
{
    m_impl->resolution = std::max(1, std::min(cells, 1024));
    m_impl->drop();
}

void SdfShape::setLocalScaling(const btVector3& scaling)
{
    Impl& d = *m_impl;
    btVector3 s = scaling.absolute();
    for (int i = 0; i < 3; ++i)
        if (!(s[i] > btScalar(0))) s[i] = btScalar(1); // zero or NaN scaling is meaningless here
    if (s == d.scaling) return;
    d.scaling = s;
    d.dropScaled(); // (the triangulation is unscaled: its BVH shape scales)
    if (d.bvh) d.bvh->setLocalScaling(d.scaling);
}

sdfccd_SdfId SdfShape::querySdf() const
{
    Impl& d = *m_impl;
    if (d.scaling == btVector3(1, 1, 1)) return d.sdf;
    if (d.scaled_valid) return d.scaled;
    d.scaled_valid = true;
    const double sx = d.scaling.x(), sy = d.scaling.y(), sz = d.scaling.z();
    const sdfccd_Status st = sx == sy && sy == sz ? sdfccd_create_transformed(d.sdf, sdfccd_pose_identity(), sx, &d.scaled)
                                                  : sdfccd_create_stretched(d.sdf, sdfccd_Vec3{ sx, sy, sz }, &d.scaled);
    if (st != SDFCCD_OK) d.scaled = kNullSdf;
    return d.scaled;
}

void SdfShape::getAabb(const btTransform& t, btVector3& aabbMin, btVector3& aabbMax) const
{
    if (!hasFiniteBounds()) {
        aabbMin.setValue(-BT_LARGE_FLOAT, -BT_LARGE_FLOAT, -BT_LARGE_FLOAT);
        aabbMax.setValue(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT);
        return;
    }
    btVector3 lo = m_impl->lo * m_impl->scaling, hi = m_impl->hi * m_impl->scaling; // scaling is positive
    btTransformAabb(lo, hi, getMargin(), t, aabbMin, aabbMax);
}

void SdfShape::calculateLocalInertia(btScalar mass, btVector3& inertia) const
{
    if (!hasFiniteBounds()) {
        inertia.setValue(0, 0, 0);
        return;
    }
    btVector3 e = (m_impl->hi - m_impl->lo) * m_impl->scaling;
    btScalar k = mass / btScalar(12);
    inertia.setValue(k * (e.y() * e.y() + e.z() * e.z()), k * (e.x() * e.x() + e.z() * e.z()),
                     k * (e.x() * e.x() + e.y() * e.y()));
}

int SdfShape::buildTriangulation() const
{
    Impl& d = *m_impl;
    if (d.triangulated) return getTriangulationTriangleCount();
    d.triangulated = true;
    if (!hasFiniteBounds()) return 0;
    // Pad the box by a little more than a cell so the surface is not capped at the bounds.
    btVector3 ext = d.hi - d.lo;
    double cell = std::max((double)ext.x(), std::max((double)ext.y(), (double)ext.z())) / d.resolution;
    if (!(cell > 0)) return 0;
    double pad = 1.5 * cell;
    sdfccd_Aabb box;
    box.lo.x = d.lo.x() - pad; box.lo.y = d.lo.y() - pad; box.lo.z = d.lo.z() - pad;
    box.hi.x = d.hi.x() + pad; box.hi.y = d.hi.y() + pad; box.hi.z = d.hi.z() + pad;
    sdfccd_MeshId mesh;
    if (sdfccd_extract_isosurface(d.sdf, box, d.resolution + 3, &mesh) != SDFCCD_OK) return 0;
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
    d.vertices.assign(v.begin(), v.end()); // double -> btScalar
    d.indices.assign(f.begin(), f.end());
    d.mesh_interface.reset(new btTriangleIndexVertexArray((int)info.triangle_count, d.indices.data(), 3 * (int)sizeof(int),
                                                          (int)info.vertex_count, d.vertices.data(), 3 * (int)sizeof(btScalar)));
    d.bvh.reset(new btBvhTriangleMeshShape(d.mesh_interface.get(), true, true));
    d.bvh->setLocalScaling(d.scaling);
    return (int)info.triangle_count;
}

int SdfShape::getTriangulationTriangleCount() const
{
    return (int)(m_impl->indices.size() / 3);
}

void SdfShape::processAllTriangles(btTriangleCallback* callback, const btVector3& aabbMin, const btVector3& aabbMax) const
{
    // A registered bridge handles every GImpact mesh against a valid SdfShape, so Bullet's GImpact
    // algorithm asking for our triangles means the bridge is not in charge of the pair (reported
    // once per shape and diagnosis).
    if (m_impl->valid) detail::reportGImpactMisuse(callback, this, m_impl->misuse_reported);
    if (!m_impl->triangulated) buildTriangulation();
    if (m_impl->bvh) m_impl->bvh->processAllTriangles(callback, aabbMin, aabbMax);
}

SDFCCD_BULLET_NAMESPACE_END
