/* SPDX-License-Identifier: MIT */
/** @file sampled.h  Comparing an SDF with a field known only by samples (e.g. an engine's own grid). */
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

#ifdef __cplusplus
}
#endif

#endif
