/* SPDX-License-Identifier: MIT */
/** @file sampled.h  Fields known only by samples (e.g. an engine's own grid): comparing an SDF with one, and an SDF from one. */
#ifndef SDFCCD_SAMPLED_H
#define SDFCCD_SAMPLED_H

#include "types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A field known by samples: writes phi at `p` to `*out_value` and returns 1, or returns 0 where
 * it has no value (e.g. a cell without data). */
typedef int32_t sdfccd_SampleFcn(sdfccd_Vec3 p, double* out_value, void* user);

/** Compares `sdf` with `sample` at the n x n x n points (i + 0.5) / n of the way across `box` per
 * axis (1 <= n <= 256; `box` finite, lo <= hi): the largest |phi - sample| where `sample` has a
 * value (0 when it has none; INFINITY for a non-finite sample) into `*out_max_difference`, and the
 * number of such points into `*out_compared` (may be NULL). Outputs are unchanged on error. */
SDFCCD_API sdfccd_Status sdfccd_sdf_compare_samples(sdfccd_SdfId sdf, sdfccd_SampleFcn* sample, void* user, sdfccd_Aabb box,
                                                    int32_t n, double* out_max_difference, int32_t* out_compared);

/** A field known by samples with gradients: writes phi at `p` to `*out_value` and its gradient
 * (unit length) to `*out_grad` and returns 1, or returns 0 where it has no value. */
typedef int32_t sdfccd_SampleGradFcn(sdfccd_Vec3 p, double* out_value, sdfccd_Vec3* out_grad, void* user);

/** An SDF from a field sampled inside `box` (finite, lo <= hi), such as an engine's grid. A point is
 * moved to the nearest point of the box shrunk by 1e-6 of its size per axis, where `sample` is
 * asked; phi is the sample plus the distance moved, and outside the box the gradient points away
 * from it. Where `sample` has no value, phi is `hole_value` (finite) plus that distance, the
 * gradient pointing away from the box centre. Its Lipschitz bound is taken as 1 and its bounds are
 * `box`; its kind is ::SDFCCD_SDF_CALLBACK. `sample` must be pure and thread-safe and `user` must
 * outlive the SDF. */
SDFCCD_API sdfccd_Status sdfccd_create_sampled_sdf(sdfccd_SampleGradFcn* sample, void* user, sdfccd_Aabb box, double hole_value,
                                                   sdfccd_SdfId* out_sdf);

#ifdef __cplusplus
}
#endif

#endif
