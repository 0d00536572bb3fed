// SPDX-License-Identifier: MIT
/** @file config.h  Precision check and namespace of the sdfccd Bullet bridge.
 *
 * The bridge is built once per btScalar (sdfccd_bullet for pkg-config `bullet`, sdfccd_bullet_f64
 * for `bullet-float64`). A mismatch with BT_USE_DOUBLE_PRECISION fails to compile (static_assert
 * on SDFCCD_BULLET_SCALAR_BYTES) and to link (inline namespace f32 or f64).
 */
#ifndef SDFCCD_BULLET_CONFIG_H
#define SDFCCD_BULLET_CONFIG_H

#include <LinearMath/btScalar.h>

#if defined(BT_USE_DOUBLE_PRECISION)
#  define SDFCCD_BULLET_PRECISION_NAME "double"
#  define SDFCCD_BULLET_NAMESPACE_BEGIN namespace sdfccd_bullet { inline namespace f64 {
#else
/** "float" or "double": the btScalar these headers were compiled with (for reports and CSV). */
#  define SDFCCD_BULLET_PRECISION_NAME "float"
/** Opens namespace sdfccd_bullet and its precision's inline namespace (f32, or f64 with
 * BT_USE_DOUBLE_PRECISION). */
#  define SDFCCD_BULLET_NAMESPACE_BEGIN namespace sdfccd_bullet { inline namespace f32 {
#endif
/** Closes what SDFCCD_BULLET_NAMESPACE_BEGIN opened. */
#define SDFCCD_BULLET_NAMESPACE_END } }

#if defined(SDFCCD_BULLET_SCALAR_BYTES)
static_assert(sizeof(btScalar) == SDFCCD_BULLET_SCALAR_BYTES,
              "sdfccd_bullet: BT_USE_DOUBLE_PRECISION does not match the bridge library you link "
              "(use sdfccd_bullet with pkg-config 'bullet', sdfccd_bullet_f64 with 'bullet-float64')");
#endif

#endif
