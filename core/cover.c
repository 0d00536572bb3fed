/* SPDX-License-Identifier: MIT
 * sdfccd core: cover points, the contact points an engine adds to a reduced set where the chosen
 * points still leave the body free to sink (ours, for the paper's response rule, Section 4: the
 * simulation does not advance past a time of impact, so every point that could go in must be held).
 * A held point j at gap d_j keeps the body's other points near it out as long as the body turns by
 * at most `tilt` (m per m) about an axis in the contact plane: point i can then end no deeper than
 * d_j + tilt * |p_i - p_j| relative to where it starts, so its shortfall is that bound minus d_i. The
 * point with the largest shortfall beyond `depth` is held next, until none is left. Points whose
 * normals differ (cosine below 0.9) do not bound each other. Stateless and allocation-free. */
#include "reduce.h"

#include <math.h>

#define SCC_COVER_SIMILAR_NORMAL 0.9

/* 1 when index i is among held[0..m-1]. */
static int is_held(const int32_t* held, size_t m, size_t i)
{
    for (size_t j = 0; j < m; ++j)
        if ((size_t)held[j] == i) return 1;
    return 0;
}

size_t scc_cover(const void* set, size_t n, scc_reduce_get_fn* get, const int32_t* chosen, size_t chosen_count, double tilt,
                 double depth, double tol, size_t k, int32_t* out)
{
    size_t picked = 0;
    if (chosen_count == 0 || n == 0) return 0;
    while (picked < k) {
        long pick = -1;
        double worst = depth, pick_gap = 0.0;
        for (size_t i = 0; i < n; ++i) {
            if (is_held(chosen, chosen_count, i) || is_held(out, picked, i)) continue;
            scc_reduce_item a;
            get(set, i, &a);
            double bound = INFINITY;
            int same_place = 0;
            for (size_t h = 0; h < chosen_count + picked && !same_place; ++h) {
                scc_reduce_item b;
                get(set, (size_t)(h < chosen_count ? chosen[h] : out[h - chosen_count]), &b);
                const double dist = scc_len(scc_sub(a.p, b.p));
                if (dist <= tol) same_place = 1; /* never two points at one place */
                else if (scc_dot(a.n, b.n) >= SCC_COVER_SIMILAR_NORMAL) bound = fmin(bound, b.gap + tilt * dist);
            }
            if (same_place) continue;
            const double shortfall = bound - a.gap; /* how deep i may end while the held points stay out */
            if (shortfall > worst || (pick >= 0 && shortfall == worst && a.gap < pick_gap)) {
                worst = shortfall;
                pick = (long)i;
                pick_gap = a.gap;
            }
        }
        if (pick < 0) break;
        out[picked++] = (int32_t)pick;
    }
    return picked;
}
