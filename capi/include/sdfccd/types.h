/* SPDX-License-Identifier: MIT */
/** @file types.h  Plain value types shared by the whole ABI (vectors, poses, boxes, and the handles
 * of SDFs and meshes). All scalars are double, metres and seconds. */
#ifndef SDFCCD_TYPES_H
#define SDFCCD_TYPES_H

#include "base.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A point or vector in metres (or m/s, rad/s). */
typedef struct sdfccd_Vec3 {
    double x; /**< x component. */
    double y; /**< y component. */
    double z; /**< z component. */
} sdfccd_Vec3;

/** A unit quaternion, scalar part first (w, x, y, z), as in the case file. Non-unit input is
 * normalised by the functions that take it; a zero quaternion is rejected. */
typedef struct sdfccd_Quat {
    double w; /**< Scalar part (cos of half the angle). */
    double x; /**< x of the vector part (axis times sin of half the angle). */
    double y; /**< y of the vector part. */
    double z; /**< z of the vector part. */
} sdfccd_Quat;

/** A rigid pose: x_world = rotate(orientation, x_local) + position. */
typedef struct sdfccd_Pose {
    sdfccd_Vec3 position;    /**< Translation (m), world frame. */
    sdfccd_Quat orientation; /**< Rotation from the local to the world frame. */
} sdfccd_Pose;

/** An axis-aligned box. */
typedef struct sdfccd_Aabb {
    sdfccd_Vec3 lo; /**< Lower corner (min x, y, z). */
    sdfccd_Vec3 hi; /**< Upper corner (max x, y, z). */
} sdfccd_Aabb;

/* Handles: the objects the library makes are named by these values, one type per kind of
 * object so that they cannot be mixed up. Each is generation-checked (a handle of a destroyed
 * object gives ::SDFCCD_INVALID_HANDLE, even when its slot is reused); a null handle has
 * index1 == 0 (zero-initialise to get one). */

/** Handle to an SDF (sdf.h). */
typedef struct sdfccd_SdfId {
    uint32_t index1;     /**< Slot + 1; 0 is the null handle. */
    uint32_t generation; /**< Generation of the slot when the handle was made. */
} sdfccd_SdfId;

/** Handle to a triangle mesh (mesh.h). */
typedef struct sdfccd_MeshId {
    uint32_t index1;     /**< Slot + 1; 0 is the null handle. */
    uint32_t generation; /**< Generation of the slot when the handle was made. */
} sdfccd_MeshId;

/** The identity pose. */
SDFCCD_API sdfccd_Pose sdfccd_pose_identity(void);

#ifdef __cplusplus
}
#endif
#endif
