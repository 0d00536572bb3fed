/* SPDX-License-Identifier: MIT
 * sdfccd core: reduction of a contact set to at most k points, for the contact sets an engine
 * needs (contact.h) and the mesh query's output (the contacts at the time of impact, Section 4.5,
 * when the caller's buffer is smaller than the set). Ours, in the spirit of Box2D's and Bullet's
 * manifold reduction: deepest first, then the points that maximise the contact area, never two
 * points at one place, deterministic. With the caller's scratch (n doubles) a choice costs O(n) reads
 * of the set (O(n) times the hull's size while area decides); without it, O(n k). */
#include "reduce.h"

#include <string.h>

typedef struct reducer {
    const void* set;
    size_t n;
    scc_reduce_get_fn* get;
    double tol;
    scc_vec3 nref;             /* the contact plane's normal (the first point's) */
    const int32_t* chosen;     /* out[0..m-1] */
    size_t m;
    int32_t hull[SCC_REDUCE_HULL_MAX]; /* counter-clockwise about nref (when hull_n >= 3) */
    scc_vec3 hp[SCC_REDUCE_HULL_MAX];  /* the hull's points on the contact plane */
    size_t hull_n;             /* 2: a segment hull[0]-hull[1] */
    double* mind;              /* optional, n: distance on the plane to the nearest chosen point, -1 when
                                  within tol of one (taken); NULL: recomputed from the chosen points */
    double depth_scale;        /* > 0: scores weighted by exp(-(gap - first gap) / depth_scale) */
    double gap0;               /* the first point's gap */
    const scc_reduce_keep* keep; /* the previous step's points (NULL: none) */
} reducer;

static scc_reduce_item item(const reducer* r, size_t i)
{
    scc_reduce_item it;
    r->get(r->set, i, &it);
    return it;
}

/* A point on the contact plane through the origin. */
static scc_vec3 flat(const reducer* r, scc_vec3 p) { return scc_sub(p, scc_scale(r->nref, scc_dot(r->nref, p))); }

/* Twice the signed area of (a, b, q) about nref. */
static double area2(const reducer* r, scc_vec3 a, scc_vec3 b, scc_vec3 q) { return scc_dot(scc_cross(scc_sub(b, a), scc_sub(q, a)), r->nref); }

/* 1 when candidate (score s, item it, index i) beats the best so far (bs, bit, bi); scores within
 * 1e-9 relative tie. */
static int beats(double s, const scc_reduce_item* it, size_t i, double bs, const scc_reduce_item* bit, long bi)
{
    if (bi < 0) return 1;
    double scale = 1e-9 * fmax(fabs(s), fabs(bs));
    if (s > bs + scale) return 1;
    if (s < bs - scale) return 0;
    if (it->gap != bit->gap) return it->gap < bit->gap;
    if (it->id != bit->id) return it->id < bit->id;
    return (long)i < bi;
}

/* 1 when point p is within tol of a chosen point (or is chosen). */
static int taken(const reducer* r, size_t i, scc_vec3 p)
{
    if (r->mind) return r->mind[i] < 0.0;
    for (size_t j = 0; j < r->m; ++j) {
        if ((size_t)r->chosen[j] == i) return 1;
        if (scc_dist(item(r, (size_t)r->chosen[j]).p, p) <= r->tol) return 1;
    }
    return 0;
}

/* The area (x2) point q adds to the hull; for a segment hull, the triangle's, or with `along` the
 * length by which q extends the segment. */
static double gain(const reducer* r, scc_vec3 q, int along)
{
    if (r->hull_n == 2) {
        scc_vec3 a = r->hp[0], b = r->hp[1];
        if (!along) return fabs(area2(r, a, b, q));
        scc_vec3 ab = scc_sub(b, a);
        double len = scc_len(ab);
        if (!(len > 0.0)) return 0.0;
        double s = scc_dot(ab, scc_sub(q, a)) / len;
        return fmax(0.0, fmax(-s, s - len));
    }
    double added = 0.0;
    for (size_t e = 0; e < r->hull_n; ++e) {
        double s = area2(r, r->hp[e], r->hp[(e + 1) % r->hull_n], q);
        if (s < 0.0) added -= s;
    }
    return added;
}

/* Puts chosen point i (plane point q) on the hull: a segment grows to a triangle or is extended,
 * a polygon replaces the chain of edges q sees. */
static void hull_add(reducer* r, int32_t i, scc_vec3 q, int along)
{
    if (r->hull_n == 2) {
        scc_vec3 a = flat(r, item(r, (size_t)r->hull[0]).p), b = flat(r, item(r, (size_t)r->hull[1]).p);
        if (along) {
            /* q replaces the end it lies beyond */
            if (scc_dot(scc_sub(b, a), scc_sub(q, a)) < 0.0) r->hull[0] = i;
            else r->hull[1] = i;
            return;
        }
        if (area2(r, a, b, q) > 0.0) r->hull[2] = i;
        else { r->hull[2] = r->hull[1]; r->hull[1] = i; }
        r->hull_n = 3;
        return;
    }
    int32_t next[SCC_REDUCE_HULL_MAX + 1];
    size_t k = 0, h = r->hull_n;
    for (size_t v = 0; v < h; ++v) {
        scc_vec3 prev = flat(r, item(r, (size_t)r->hull[(v + h - 1) % h]).p), cur = flat(r, item(r, (size_t)r->hull[v]).p),
                 nxt = flat(r, item(r, (size_t)r->hull[(v + 1) % h]).p);
        int in_seen = area2(r, prev, cur, q) < 0.0, out_seen = area2(r, cur, nxt, q) < 0.0;
        if (!(in_seen && out_seen)) next[k++] = r->hull[v];
        if (!in_seen && out_seen) next[k++] = i;
    }
    for (size_t v = 0; v < k && v < SCC_REDUCE_HULL_MAX; ++v) r->hull[v] = next[v];
    r->hull_n = k < SCC_REDUCE_HULL_MAX ? k : SCC_REDUCE_HULL_MAX;
}

/* The hull's plane points, after it changed. */
static void hull_points(reducer* r)
{
    for (size_t v = 0; v < r->hull_n; ++v) r->hp[v] = flat(r, item(r, (size_t)r->hull[v]).p);
}

/* Records the choice of item j in the scratch: items within tol of it are taken, the others' nearest
 * chosen distance shrinks. */
static void chosen(reducer* r, size_t j)
{
    if (!r->mind) return;
    const scc_reduce_item c = item(r, j);
    const scc_vec3 qc = flat(r, c.p);
    for (size_t i = 0; i < r->n; ++i) {
        if (r->mind[i] < 0.0) continue;
        scc_reduce_item it = item(r, i);
        if (i == j || scc_dist(it.p, c.p) <= r->tol) r->mind[i] = -1.0;
        else r->mind[i] = fmin(r->mind[i], scc_dist(flat(r, it.p), qc));
    }
}

/* The score of unchosen item i (`it`): its distance to the chosen points (first choice after the
 * first point, or `fill`), else the area it adds (`along`: the length it extends a segment by);
 * weighted by depth when depth_scale > 0. */
static double score(const reducer* r, size_t i, const scc_reduce_item* it, int along, int fill)
{
    scc_vec3 q = flat(r, it->p);
    double s;
    if (r->m == 1 || fill) {
        if (r->mind) {
            s = r->mind[i];
        } else {
            s = INFINITY;
            for (size_t j = 0; j < r->m; ++j) s = fmin(s, scc_dist(flat(r, item(r, (size_t)r->chosen[j]).p), q));
        }
    } else {
        s = gain(r, q, along);
    }
    /* a point far from the surface (that may reach it late in the step) counts less than one
       about to touch */
    if (r->depth_scale > 0.0) s *= exp(-(it->gap - r->gap0) / r->depth_scale);
    return s;
}

/* The rank of `id` among the previous step's points, -1 when it is not one of them. */
static long keep_rank(const reducer* r, uint64_t id)
{
    for (size_t j = 0; j < r->keep->n; ++j)
        if (r->keep->ids[j] == id) return (long)j;
    return -1;
}

/* The previous step's point that replaces `pick` (see scc_reduce_keep), -1 when none. The first choice
 * compares depth only; later ones the score of the pass too (`along`, `fill`), which must exceed
 * `enough`. */
static long keep_choice(const reducer* r, long pick, int first_choice, int along, int fill, double enough)
{
    if (!r->keep || r->keep->n == 0 || pick < 0) return -1;
    const scc_reduce_item pit = item(r, (size_t)pick);
    const double floor_s = first_choice ? 0.0 : r->keep->share * score(r, (size_t)pick, &pit, along, fill);
    long best = -1, best_rank = 0;
    double best_gap = 0.0;
    for (size_t i = 0; i < r->n; ++i) {
        scc_reduce_item it = item(r, i);
        const long rank = keep_rank(r, it.id);
        if (rank < 0 || !(it.gap <= pit.gap + r->keep->depth)) continue;
        if (!first_choice) {
            if (taken(r, i, it.p)) continue;
            const double s = score(r, i, &it, along, fill);
            if (!(s >= floor_s) || !(s > enough)) continue;
        }
        if (best < 0 || rank < best_rank || (rank == best_rank && it.gap < best_gap)) {
            best = (long)i;
            best_rank = rank;
            best_gap = it.gap;
        }
    }
    return best;
}

static size_t reduce(const void* set, size_t n, scc_reduce_get_fn* get, double tol, double depth_scale, long first,
                     const scc_reduce_keep* keep, size_t k, int32_t* out, double* scratch);

size_t scc_reduce(const void* set, size_t n, scc_reduce_get_fn* get, double tol, long first, size_t k, int32_t* out, double* scratch)
{
    return reduce(set, n, get, tol, 0.0, first, NULL, k, out, scratch);
}

size_t scc_reduce_weighted(const void* set, size_t n, scc_reduce_get_fn* get, double tol, double depth_scale, long first, size_t k,
                           int32_t* out, double* scratch)
{
    return reduce(set, n, get, tol, depth_scale, first, NULL, k, out, scratch);
}

size_t scc_reduce_kept(const void* set, size_t n, scc_reduce_get_fn* get, double tol, double depth_scale, const scc_reduce_keep* keep,
                       size_t k, int32_t* out, double* scratch)
{
    return reduce(set, n, get, tol, depth_scale, -1, keep, k, out, scratch);
}

static size_t reduce(const void* set, size_t n, scc_reduce_get_fn* get, double tol, double depth_scale, long first,
                     const scc_reduce_keep* keep, size_t k, int32_t* out, double* scratch)
{
    if (n == 0 || k == 0) return 0;
    reducer r;
    memset(&r, 0, sizeof r);
    r.set = set;
    r.n = n;
    r.get = get;
    r.tol = tol;
    r.nref = scc_v3(0, 0, 1);
    r.chosen = out;
    r.mind = scratch;
    r.depth_scale = depth_scale;
    r.keep = keep;
    /* the first point: given, or the deepest; among equally deep ones (a face landing flat) the one
     * farthest from their centre, a corner, so the polygon grows to the region's corners */
    long best = first >= 0 && (size_t)first < n ? first : -1;
    long deepest = -1; /* the smallest gap, the lower index on ties */
    for (size_t i = 0; best < 0 && i < n; ++i)
        if (deepest < 0 || item(&r, i).gap < item(&r, (size_t)deepest).gap) deepest = (long)i;
    /* weighted: distances on the plane of the deepest point's normal from the start */
    const int plane = best < 0 && depth_scale > 0.0;
    if (plane) r.nref = scc_normalize_or(item(&r, (size_t)deepest).n, scc_v3(0, 0, 1));
    /* the previous step's first point, when about as deep: it also gives the contact plane */
    if (best < 0 && (best = keep_choice(&r, deepest, 1, 0, 0, 0.0)) >= 0) r.nref = scc_normalize_or(item(&r, (size_t)best).n, scc_v3(0, 0, 1));
    if (best < 0) {
        const double g0 = item(&r, (size_t)deepest).gap;
        const double same = fmax(1e-9 * fmax(1.0, fabs(g0)), depth_scale > 0.0 ? 1e-3 * tol : 0.0);
        scc_vec3 c = scc_v3(0, 0, 0);
        double cnt = 0.0;
        for (size_t i = 0; i < n; ++i) {
            scc_reduce_item it = item(&r, i);
            if (it.gap <= g0 + same) { c = scc_add(c, plane ? flat(&r, it.p) : it.p); cnt += 1.0; }
        }
        c = scc_scale(c, 1.0 / cnt);
        double bs = 0.0;
        scc_reduce_item bit = { { 0, 0, 0 }, { 0, 0, 0 }, 0, 0 };
        for (size_t i = 0; i < n; ++i) {
            scc_reduce_item it = item(&r, i);
            if (!(it.gap <= g0 + same)) continue;
            double s = scc_dist(plane ? flat(&r, it.p) : it.p, c);
            if (plane ? (best < 0 || s > bs + tol) : beats(s, &it, i, bs, &bit, best)) { best = (long)i; bs = s; bit = it; }
        }
    }
    out[r.m++] = (int32_t)best;
    r.gap0 = item(&r, (size_t)best).gap;
    if (!plane) r.nref = scc_normalize_or(item(&r, (size_t)best).n, scc_v3(0, 0, 1));
    if (r.mind) {
        for (size_t i = 0; i < n; ++i) r.mind[i] = INFINITY;
        chosen(&r, (size_t)best);
    }
    int fill = 0; /* 1 once no point adds area: spread alone */
    while (r.m < k) {
        long pick = -1;
        double bs = 0.0;
        int along = 0;
        scc_reduce_item bit = { { 0, 0, 0 }, { 0, 0, 0 }, 0, 0 };
        for (int pass = 0; pass < 2 && pick < 0; ++pass) {
            /* pass 1 on a segment: no point leaves its line, so extend it */
            if (pass == 1 && !(r.hull_n == 2 && !fill)) break;
            along = pass;
            for (size_t i = 0; i < n; ++i) {
                scc_reduce_item it = item(&r, i);
                if (taken(&r, i, it.p)) continue;
                double s = score(&r, i, &it, along, fill);
                if (beats(s, &it, i, bs, &bit, pick)) { pick = (long)i; bs = s; bit = it; }
            }
            /* what counts as adding: tol of length, or tol times the segment's length of area */
            double seg = r.hull_n >= 2 ? scc_dist(r.hp[0], r.hp[1]) : 0.0;
            double enough = (r.m == 1 || fill || along) ? tol : tol * seg;
            if (pick >= 0 && !(bs > enough)) pick = -1;
            /* weighted: among the points within SCC_REDUCE_SHARE of the best, the deepest */
            if (pick >= 0 && r.depth_scale > 0.0) {
                const double floor_s = SCC_REDUCE_SHARE * bs;
                for (size_t i = 0; i < n; ++i) {
                    scc_reduce_item it = item(&r, i);
                    if ((long)i == pick || !(it.gap < bit.gap || (it.gap == bit.gap && it.id < bit.id)) || taken(&r, i, it.p)) continue;
                    if (score(&r, i, &it, along, fill) >= floor_s) { pick = (long)i; bit = it; }
                }
            }
            const long kept = keep_choice(&r, pick, 0, along, fill, enough);
            if (kept >= 0) pick = kept;
        }
        if (pick < 0) {
            if (fill || r.m == 1) break;
            fill = 1;
            continue;
        }
        scc_vec3 q = flat(&r, item(&r, (size_t)pick).p);
        out[r.m++] = (int32_t)pick;
        chosen(&r, (size_t)pick);
        if (fill) continue;
        if (r.m == 2) {
            r.hull[0] = out[0];
            r.hull[1] = (int32_t)pick;
            r.hull_n = 2;
            hull_points(&r);
        } else if (r.hull_n < SCC_REDUCE_HULL_MAX) {
            hull_add(&r, (int32_t)pick, q, along);
            hull_points(&r);
        } else {
            fill = 1;
        }
    }
    return r.m;
}

void scc_match_points(const scc_vec3* previous, size_t m, const scc_vec3* points, size_t n, double tol2, int32_t* match,
                      unsigned char* used)
{
    for (size_t j = 0; j < m; ++j) used[j] = 0;
    for (size_t i = 0; i < n; ++i) {
        long best = -1;
        double best_d2 = tol2;
        for (size_t j = 0; j < m; ++j) {
            const double d2 = scc_len2(scc_sub(previous[j], points[i]));
            if (!used[j] && d2 < best_d2) {
                best_d2 = d2;
                best = (long)j;
            }
        }
        if (best >= 0) used[best] = 1;
        match[i] = (int32_t)best;
    }
}
