// SPDX-License-Identifier: MIT
/** @file sdf_shape.h  A Bullet collision shape backed by an sdfccd signed distance field. */
#ifndef SDFCCD_BULLET_SDF_SHAPE_H
#define SDFCCD_BULLET_SDF_SHAPE_H

#include <memory>
#include <vector>

#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>
#include <BulletCollision/CollisionShapes/btConcaveShape.h>

#include "sdfccd/sdfccd.h"
#include "config.h"

SDFCCD_BULLET_NAMESPACE_BEGIN

/** The default shape type id, FAST_CONCAVE_MESH_PROXYTYPE (23): no Bullet class uses it, and
 * Bullet casts every type-29 shape to btSdfCollisionShape. */
const int kDefaultSdfShapeType = FAST_CONCAVE_MESH_PROXYTYPE;

/** A Bullet shape whose surface is the zero level set of an sdfccd SDF. Meshes, convex shapes and
 * other SdfShapes collide with it through the bridge's CCD; everything else (rays, sweeps) through
 * a cached triangulation of the surface. */
class SdfShape : public btConcaveShape
{
public:
    /** Wraps `sdf` (not owned; keep it alive while the shape lives) in the body's frame.
     * `shape_type`: a concave id no other shape uses, the bridge's Config::sdf_shape_type. */
    explicit SdfShape(sdfccd_SdfId sdf, int shape_type = kDefaultSdfShapeType);
    /** False when the handle was not live at construction: an empty box, and no pairs. */
    bool isValid() const;
    ~SdfShape() override;
    SdfShape(const SdfShape&) = delete;
    SdfShape& operator=(const SdfShape&) = delete;

    /** The wrapped handle, as given. */
    sdfccd_SdfId sdf() const;

    /** The wrapped SDF with the local scaling (owned by the shape; null handle on failure).
     * Non-uniform scaling s gives min(s) phi(x / s), never above the stretched shape's distance. */
    sdfccd_SdfId querySdf() const;

    /** Sets the unscaled local box (default: the SDF's bounds within its domain; unbounded SDFs
     * such as a half-space need it for a triangulation). */
    void setLocalBounds(const btVector3& lo, const btVector3& hi);
    /** The local box (unscaled) into `lo` and `hi`. */
    void getLocalBounds(btVector3& lo, btVector3& hi) const;
    /** False when the local box is unbounded. */
    bool hasFiniteBounds() const;

    /** The size (m, unscaled) of the field's smallest features (default 0: larger than the faces
     * meeting it). When positive, the bridge searches each face region by region down to it. */
    void setFeatureSize(double size);
    /** The feature size times the smallest local scaling factor. */
    double getFeatureSize() const;

    /** Cells along the longest axis of the triangulation grid (default 48). */
    void setTriangulationResolution(int cells);
    /** Cells along the longest axis of the triangulation grid. */
    int getTriangulationResolution() const;
    /** Builds the triangulation now (else on first use); its triangle count. */
    int buildTriangulation() const;
    /** Triangles of the cached triangulation (0 if not built). */
    int getTriangulationTriangleCount() const;
    /** The triangulation's vertices (x, y, z each; unscaled; empty if not built). */
    const std::vector<btScalar>& triangulationVertices() const;
    /** Three indices into triangulationVertices() per triangle. */
    const std::vector<int>& triangulationIndices() const;

    // ---- btCollisionShape ----
    /** The scaled local box, padded by the margin, transformed by `t`. */
    void getAabb(const btTransform& t, btVector3& aabbMin, btVector3& aabbMax) const override;
    /** Scales the shape about its origin by |scaling| (a zero or NaN component counts as 1). */
    void setLocalScaling(const btVector3& scaling) override;
    /** The local scaling (default 1, 1, 1). */
    const btVector3& getLocalScaling() const override;
    /** Inertia of a solid box filling the scaled local box (zero when unbounded). */
    void calculateLocalInertia(btScalar mass, btVector3& inertia) const override;
    /** "sdfccd_SdfShape" (Bullet's serializer and debug output). */
    const char* getName() const override { return "sdfccd_SdfShape"; }

    // ---- btConcaveShape ----
    /** The triangulation's triangles (scaled) overlapping the box; Bullet's GImpact algorithm
     * asking is reported as misuse (setMisuseHandler). */
    void processAllTriangles(btTriangleCallback* callback, const btVector3& aabbMin,
                             const btVector3& aabbMax) const override;

private:
    struct Impl; // the handle, bounds, scaling and the cached triangulation (sdf_shape.cpp)
    std::unique_ptr<Impl> m_impl;
};

SDFCCD_BULLET_NAMESPACE_END

#endif
