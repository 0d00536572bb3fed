// SPDX-License-Identifier: MIT
/** @file sdfccd_bullet.h  Umbrella header of the sdfccd Bullet bridge.
 *
 * Minimal use (see samples/bullet_hello.cpp for a complete program):
 *   sdfccd_bullet::Bridge bridge;                 // create before the world, destroy after it
 *   ... create dispatcher, broadphase, solver, world ...
 *   bridge.registerWith(world);                   // before adding GImpact or SDF bodies
 *   sdfccd_bullet::SdfShape ground(sdf_handle);   // any sdfccd SDF: analytic, CSG, grid
 *   ... add bodies with btGImpactMeshShape and SdfShape (or btSdfCollisionShape) shapes, step ...
 */
#ifndef SDFCCD_BULLET_SDFCCD_BULLET_H
#define SDFCCD_BULLET_SDFCCD_BULLET_H

#include "config.h"
#include "sdf_shape.h"
#include "bridge.h"

#endif
