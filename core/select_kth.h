/* SPDX-License-Identifier: MIT
 * sdfccd core: the median split shared by the two hierarchy builders (bsh.c, tri_bvh.c):
 * quickselect on an index array by one coordinate of a per-item point. */
#ifndef SCC_SELECT_KTH_H
#define SCC_SELECT_KTH_H

#include <stdint.h>
#include "scc_math.h"

static inline double scc_axis_of(scc_vec3 v, int axis) { return axis == 0 ? v.x : (axis == 1 ? v.y : v.z); }

/* Partially sorts order[lo, hi) so that order[k] holds the item whose key point[order[k]] (along
 * `axis`) is the k-th smallest: quickselect with a median-of-three pivot and a three-way partition,
 * so equal keys always make progress. Deterministic. */
static inline void scc_select_kth(uint32_t* order, const scc_vec3* point, int axis, uint32_t lo, uint32_t hi, uint32_t k)
{
    while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        const double a = scc_axis_of(point[order[lo]], axis), b = scc_axis_of(point[order[mid]], axis),
                     c = scc_axis_of(point[order[hi - 1]], axis);
        const double pivot = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        uint32_t lt = lo, i = lo, gt = hi; /* [lo,lt) < pivot, [lt,i) == pivot, [gt,hi) > pivot */
        while (i < gt) {
            const double v = scc_axis_of(point[order[i]], axis);
            if (v < pivot) { uint32_t tmp = order[i]; order[i] = order[lt]; order[lt] = tmp; ++lt; ++i; }
            else if (v > pivot) { --gt; uint32_t tmp = order[i]; order[i] = order[gt]; order[gt] = tmp; }
            else ++i;
        }
        if (k < lt) hi = lt;
        else if (k >= gt) lo = gt;
        else return;
    }
}

#endif
