// SPDX-License-Identifier: MIT
/** @file sdf_shape.h  A Bullet collision shape backed by an sdfccd signed distance field.
 *
 * SdfShape is a btConcaveShape. Against GImpact meshes (btGImpactMeshShape) it gets continuous
 * collision detection from the bridge's algorithm (see bridge.h). Against everything else
 * (convex bodies, ray tests, convex sweeps, GImpact compounds) Bullet uses its generic
 * concave-shape path, which calls processAllTriangles: the shape answers with a cached
 * triangulation of its zero level set (sdfccd_extract_isosurface), built on first use.
 */
#ifndef SDFCCD_BULLET_SDF_SHAPE_H
#define SDFCCD_BULLET_SDF_SHAPE_H

#include <vector>

#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>
#include <BulletCollision/CollisionShapes/btConcaveShape.h>

#include "sdfccd/sdfccd.h"
#include "config.h"

class btBvhTriangleMeshShape;
class btTriangleIndexVertexArray;

SDFCCD_BULLET_NAMESPACE_BEGIN

/** The default shape type id: FAST_CONCAVE_MESH_PROXYTYPE (23). No Bullet 3.24 class uses it,
 * and it avoids id 29 (SDF_SHAPE_PROXYTYPE), which Bullet's convex-concave algorithm hard-casts
 * to btSdfCollisionShape (a convex body touching any other type-29 shape crashes). */
const int kDefaultSdfShapeType = FAST_CONCAVE_MESH_PROXYTYPE;

/** A static or moving Bullet shape whose surface is the zero level set of an sdfccd SDF (any
 * analytic, CSG, grid or callback SDF). Collides with GImpact meshes, convex shapes and other
 * SdfShapes through the bridge's CCD once Bridge::registerWith() was called; with everything else
 * through its cached triangulation. */
class SdfShape : public btConcaveShape
{
public:
    /** Wraps `sdf` (not owned: keep it alive while the shape lives, destroy it afterwards).
     * The SDF's local frame is the shape's frame, i.e. the collision object's centre-of-mass
     * frame. `shape_type` must be a concave id (20 < id < 30) that no other shape in the world
     * uses; the bridge must be registered with the same id (Config::sdf_shape_type). */
    explicit SdfShape(sdfccd_SdfId sdf, int shape_type = kDefaultSdfShapeType);
    /** The checked way to make a shape: NULL (and `*status` set, if given) when `sdf` is not a live
     * sdfccd handle (null, destroyed, or never created), instead of a shape nothing collides with. */
    static SdfShape* create(sdfccd_SdfId sdf, int shape_type = kDefaultSdfShapeType, sdfccd_Status* status = nullptr);
    /** False when the handle was not a live sdfccd SDF at construction. Such a shape has an empty
     * box at its origin, the bridge refuses its pairs, and Bridge::check() reports InvalidShape
     * (as it does for a handle destroyed while the shape is in a world). */
    bool isValid() const { return m_valid; }
    ~SdfShape() override;
    SdfShape(const SdfShape&) = delete;
    SdfShape& operator=(const SdfShape&) = delete;

    /** The wrapped handle, as given. */
    sdfccd_SdfId sdf() const { return m_sdf; }

    /** The handle collision queries should use: the wrapped SDF with the local scaling applied.
     * Uniform scaling is exact (a transformed SDF). Non-uniform scaling (sx, sy, sz) uses
     * min(s) * phi(x / s), which is never larger than the true distance of the stretched shape,
     * so contacts come early rather than late. Created on demand, owned by the shape. A null
     * handle (index1 == 0) when the scaled SDF could not be created. */
    sdfccd_SdfId querySdf() const;

    /** The box the shape occupies in its local frame (unscaled): the SDF's bounds (every point
     * with phi <= 0), intersected with its domain. Unbounded SDFs (a half-space) need
     * setLocalBounds(), otherwise the box is +-BT_LARGE_FLOAT and no triangulation is built. */
    void setLocalBounds(const btVector3& lo, const btVector3& hi);
    /** The local box (unscaled) into `lo` and `hi`. */
    void getLocalBounds(btVector3& lo, btVector3& hi) const;
    /** False when the local box is unbounded (+-BT_LARGE_FLOAT), e.g. a half-space without setLocalBounds(). */
    bool hasFiniteBounds() const;

    /** The size (m, unscaled) of the field's smallest features, e.g. the base radius of a grid of
     * spikes; 0 (the default) when every feature is larger than the faces of the meshes meeting it.
     * When positive, the bridge also searches each mesh face region by region down to a part of this
     * size, so a feature between a face's vertices is found (Stats::face_regions). */
    void setFeatureSize(double size) { m_featureSize = size > 0 ? size : 0; }
    /** The feature size times the smallest local scaling factor. */
    double getFeatureSize() const;

    /** Cells along the longest axis of the triangulation grid (default 48). Changing it drops
     * the cached triangulation. */
    void setTriangulationResolution(int cells);
    /** Cells along the longest axis of the triangulation grid. */
    int getTriangulationResolution() const { return m_resolution; }
    /** Builds the triangulation now (it is otherwise built on the first processAllTriangles).
     * Returns the number of triangles (0 when there is no finite box or no surface in it). */
    int buildTriangulation() const;
    /** Triangles of the cached triangulation (0 if not built). */
    int getTriangulationTriangleCount() const;
    /** The cached triangulation (unscaled local frame; empty if not built): x, y, z per vertex
     * and three vertex indices per triangle. The bridge samples a moving SdfShape with it
     * against another SDF. */
    const std::vector<btScalar>& triangulationVertices() const { return m_vertices; }
    /** Three indices into triangulationVertices() per triangle. */
    const std::vector<int>& triangulationIndices() const { return m_indices; }

    // ---- btCollisionShape ----
    /** Local box scaled component-wise by the local scaling, padded by the margin, then
     * transformed by `t` (the box of the rotated box). */
    void getAabb(const btTransform& t, btVector3& aabbMin, btVector3& aabbMax) const override;
    /** Scales the shape about its local origin, component-wise by |scaling| (a zero or NaN component
     * counts as 1); querySdf() then gives the scaled field. */
    void setLocalScaling(const btVector3& scaling) override;
    /** The local scaling (default 1, 1, 1). */
    const btVector3& getLocalScaling() const override { return m_scaling; }
    /** Inertia of a solid box filling the scaled local bounds (zero when they are infinite).
     * Bullet only calls this for dynamic bodies; pass your own inertia if you know better. */
    void calculateLocalInertia(btScalar mass, btVector3& inertia) const override;
    /** "sdfccd_SdfShape" (Bullet's serializer and debug output). */
    const char* getName() const override { return "sdfccd_SdfShape"; }
    /** Collision margin (m) added to the box; the bridge's contact margin is Config::contact_margin. */
    void setMargin(btScalar margin) override { m_margin = margin; }
    /** The collision margin set with setMargin(). */
    btScalar getMargin() const override { return m_margin; }

    // ---- btConcaveShape ----
    /** Reports the cached isosurface triangles (scaled, local frame) overlapping the box. When the
     * caller is Bullet's GImpact algorithm (the bridge is not handling a GImpact mesh against
     * this shape), the misuse handler hears of it first, once per shape and diagnosis
     * (setMisuseHandler). */
    void processAllTriangles(btTriangleCallback* callback, const btVector3& aabbMin,
                             const btVector3& aabbMax) const override;

private:
    void dropDerived() const;

    sdfccd_SdfId m_sdf;
    bool m_valid;
    btVector3 m_lo, m_hi;          // unscaled local bounds
    btVector3 m_scaling;
    btScalar m_margin;
    int m_resolution;
    double m_featureSize = 0;
    mutable sdfccd_SdfId m_scaled; // owned, created on demand
    mutable bool m_scaledValid;
    // Triangulation (built lazily; Bullet's narrow phase is single-threaded in the Debian build).
    mutable bool m_triangulated;
    mutable std::vector<btScalar> m_vertices;
    mutable std::vector<int> m_indices;
    mutable btTriangleIndexVertexArray* m_meshInterface;
    mutable btBvhTriangleMeshShape* m_bvh;
    mutable int m_misuseReported; // last misuse diagnosis reported for the shape (Status + 1; 0: none)
};

SDFCCD_BULLET_NAMESPACE_END

#endif
