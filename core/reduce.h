/* SPDX-License-Identifier: MIT
 * sdfccd core: reduction of a contact set to a few points (reduce.c). Stateless; the set is read
 * through an accessor, so the mesh query's contacts and the ABI's contact points share one routine
 * and nothing is copied or allocated. */
#ifndef SCC_REDUCE_H
#define SCC_REDUCE_H

#include <stddef.h>
#include <stdint.h>
#include "scc_math.h"

/* What the reduction reads of one contact: its place (a point on the SDF's surface), the normal
 * there, its gap (smaller: deeper) and an id that breaks ties independently of the set's order. */
typedef struct scc_reduce_item {
    scc_vec3 p, n;
    double gap;
    uint64_t id;
} scc_reduce_item;

typedef void scc_reduce_get_fn(const void* set, size_t i, scc_reduce_item* out);

/* Most hull vertices the area phase keeps; points beyond it are chosen by spread alone. */
#define SCC_REDUCE_HULL_MAX 32

/* Chooses at most k of the n contacts of `set` and writes their indices to out[0..k-1], in the order
 * chosen; returns the count. The first is `first` when >= 0, else the deepest (among equally deep
 * ones the farthest from their centre); then the point farthest from it, then the points adding most
 * area to the polygon of the chosen ones (projected on the plane of the first one's normal), then,
 * once none adds area, the points farthest from every chosen one. A point within `tol` (>= 0) of a
 * chosen one is never chosen; choices stop when the best adds no more than `tol` of spread. Ties (scores
 * within 1e-9 relative) go to the smaller gap, then the smaller id, then the lower index. `scratch`
 * (n doubles, or NULL) makes it O(n) per choice instead of O(n k); the result is the same. */
size_t scc_reduce(const void* set, size_t n, scc_reduce_get_fn* get, double tol, long first, size_t k, int32_t* out, double* scratch);

/* Share of the best weighted score within which the deepest point is chosen instead. */
#define SCC_REDUCE_SHARE 0.95

/* scc_reduce with every score after the first point (distance, area) multiplied by
 * exp(-(gap - first gap) / depth_scale) when depth_scale > 0: deeper points win over far ones; and
 * then, among the points scoring at least SCC_REDUCE_SHARE of the best (and more than tol), the one
 * with the smallest gap (then smaller id, lower index) is chosen. The first point: gaps within
 * 1e-3 tol count as equal, and among those the first in index order farther than tol beyond the
 * ones before it from their centre (rounding in the gaps does not flip it from step to step); the
 * contact plane is the deepest point's (smallest gap, lower index), distances measured on it.
 * depth_scale 0: scc_reduce. */
size_t scc_reduce_weighted(const void* set, size_t n, scc_reduce_get_fn* get, double tol, double depth_scale, long first, size_t k,
                           int32_t* out, double* scratch);

/* The previous step's kept points, for a reduction that keeps a resting contact set's points (and
 * their order) from step to step: `ids` (n of them, in the order they were chosen then). At every
 * choice, a candidate with one of these ids (not taken) replaces the point the reduction would pick
 * when its gap is at most `depth` (m) above that point's and, after the first choice, its score is
 * at least `share` of that point's (and adds more than tol); among several, the one earliest in
 * `ids` (then the smaller gap, the lower index). The first point kept this way also gives the
 * contact plane (its normal). */
typedef struct scc_reduce_keep {
    const uint64_t* ids;
    size_t n;
    double depth;
    double share;
} scc_reduce_keep;

/* scc_reduce_weighted with the previous step's points preferred (keep NULL or keep->n 0: the same as
 * scc_reduce_weighted). O(n keep->n) more reads of the set per choice. */
size_t scc_reduce_kept(const void* set, size_t n, scc_reduce_get_fn* get, double tol, double depth_scale, const scc_reduce_keep* keep,
                       size_t k, int32_t* out, double* scratch);

/* Cover points (cover.c): up to k more indices of `set`, none in chosen[0..chosen_count-1], each the
 * point whose end gap could fall furthest below `depth` while every held point (chosen, then picked)
 * stays out, for a turn of `tilt` (m per m) of the body about an axis in the contact plane; a held
 * point bounds only points of similar normal and points within `tol` of it are never picked. Ties go
 * to the smaller gap, then the lower index. Returns the count written to out. O(n (chosen + k) k). */
size_t scc_cover(const void* set, size_t n, scc_reduce_get_fn* get, const int32_t* chosen, size_t chosen_count, double tilt,
                 double depth, double tol, size_t k, int32_t* out);

/* Warm starting by place (the persistence an engine's manifold gives a point that stays where it
 * was): for each of the n points in order, the nearest of the m previous points not matched yet whose
 * squared distance is below tol2 (strictly; equal distances: the lower index), else -1, into
 * match[i]. `used` (m bytes) is scratch. O(n m). */
void scc_match_points(const scc_vec3* previous, size_t m, const scc_vec3* points, size_t n, double tol2, int32_t* match,
                      unsigned char* used);

#endif
