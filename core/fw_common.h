/* SPDX-License-Identifier: MIT
 * sdfccd core: state shared by the two spatio-temporal Frank-Wolfe solvers (fw.c, fwgss.c):
 * the shrinking time bound, the earliest witnessed contact, and evaluation helpers. */
#ifndef SCC_FW_COMMON_H
#define SCC_FW_COMMON_H

#include "ccd.h"
#include "sdf_analytic.h"
#include "sdf_user.h"

#include <string.h>

typedef struct scc_fw_state {
    const scc_sdf* sdf;
    const scc_sdf_torus* torus; /* sdf when it is the built-in torus (NULL otherwise): tested once per sample (scc_fw_sdf) */
    const scc_sdf_user* user;   /* sdf when it is a user's field (NULL otherwise): its function called without its eval (scc_fw_sdf) */
    double margin;          /* p->margin, one load per sample instead of two */
    const scc_tri_motion* m;
    const scc_params* p;
    double ts, te;          /* the interval; te shrinks to the earliest witnessed contact */
    int hit;
    double hit_t, hit_b[3];
    double b[3];            /* current barycentric weights */
    int64_t evals;
    double dist_tol;        /* spatial tolerance of this solve (m) */
    double time_slope;      /* FWGSS: early stop of signed temporal searches (scc_gss_minimize_gap), 0: none */
    /* Closed-form rigid motion (static SDF): x(t) = g0 + v tau + R(w tau) r0, tau = t - t0, with
     * the vertices' offsets r0 from the centre precomputed once and the rotation's sine and
     * cosine cached for the last time evaluated (spatial searches evaluate many points at one
     * time). Same Eq. 14 as motion.c, without a quaternion product per point. */
    int fast;
    int kinked; /* FWGSS: the field's gradient may jump and fwgss_kink_guard is on */
    scc_vec3 g0, v, w, axis, r0[3];
    double t0, wlen;
    double cache_t, cache_c, cache_s;
    double base_t, base_c, base_s; /* rotation angle's sine and cosine at base_t (mid-interval) */
    /* The offset r of the last weights evaluated (pt_b, compared bit for bit) with axis x r and
     * axis . r: a temporal search or a vertex trace evaluates one point at many times. */
    scc_vec3 kr0[3];     /* axis x r0[i] */
    double kd0[3];       /* axis . r0[i] */
    int pt_valid;
    double pt_b[3];
    scc_vec3 pt_r, pt_kr;
    double pt_kd;
} scc_fw_state;

/* Fills the closed-form motion cache of s (s->m set); leaves s->fast = 0 when the motion is not
 * a rigid body against a static SDF. */
void scc_fw_prepare_motion(scc_fw_state* s);

/* The Taylor series of sin(d) / d and cos(d) in x = d * d (degrees 20 and 22, first omitted terms
 * below 2e-18 for |d| <= 1.6). Horner's rule alone is a chain of 11 dependent multiply-adds, which
 * a temporal search waits for at every sample; here the eight highest coefficients are combined by
 * Estrin's scheme (pairs, then x^2 and x^4: three levels) and the last four steps are Horner's.
 * The inner part's rounding differs from Horner's by units in the last place of a value below
 * 3e-6, scaled by x^4 in the result, so the result keeps Horner's bits unless it lies within about
 * 1e-21 of a rounding boundary (no sample of the report's data sets does: their answers are
 * unchanged bit for bit). Entry j multiplies x^(11 - j); the sine has one coefficient less (0).
 * Both run as the two lanes of one vector where the compiler has vector extensions, with the same
 * operations per lane as the scalar code, so the same bits. */
static inline void scc_sincos_series(double d2, double* out_sd, double* out_cd)
{
    static const double ks[12] = { 0.0, 1.0 / 51090942171709440000.0, -1.0 / 121645100408832000.0, 1.0 / 355687428096000.0,
                                   -1.0 / 1307674368000.0, 1.0 / 6227020800.0, -1.0 / 39916800.0, 1.0 / 362880.0,
                                   -1.0 / 5040.0, 1.0 / 120.0, -1.0 / 6.0, 1.0 };
    static const double kc[12] = { -1.0 / 1124000727777607680000.0, 1.0 / 2432902008176640000.0, -1.0 / 6402373705728000.0,
                                   1.0 / 20922789888000.0, -1.0 / 87178291200.0, 1.0 / 479001600.0, -1.0 / 3628800.0,
                                   1.0 / 40320.0, -1.0 / 720.0, 1.0 / 24.0, -0.5, 1.0 };
#if (defined(__GNUC__) || defined(__clang__)) && !defined(SCC_SERIES_PLAIN_C)
    typedef double v2d __attribute__((vector_size(16)));
#define SCC_K2(j) ((v2d){ ks[j], kc[j] })
    const v2d x = { d2, d2 }, x2 = x * x, x4 = x2 * x2;
    const v2d p0 = SCC_K2(7) + SCC_K2(6) * x, p1 = SCC_K2(5) + SCC_K2(4) * x;
    const v2d p2 = SCC_K2(3) + SCC_K2(2) * x, p3 = SCC_K2(1) + SCC_K2(0) * x;
    v2d acc = (p0 + p1 * x2) + (p2 + p3 * x2) * x4;
    for (int j = 8; j < 12; ++j) acc = acc * x + SCC_K2(j);
#undef SCC_K2
    *out_sd = acc[0];
    *out_cd = acc[1];
#else
    const double x2 = d2 * d2, x4 = x2 * x2;
    double r[2];
    for (int lane = 0; lane < 2; ++lane) {
        const double* k = lane ? kc : ks;
        const double p0 = k[7] + k[6] * d2, p1 = k[5] + k[4] * d2, p2 = k[3] + k[2] * d2, p3 = k[1] + k[0] * d2;
        double acc = (p0 + p1 * x2) + (p2 + p3 * x2) * x4;
        for (int j = 8; j < 12; ++j) acc = acc * d2 + k[j];
        r[lane] = acc;
    }
    *out_sd = r[0];
    *out_cd = r[1];
#endif
}

/* The rotation's cosine and sine at time t into the cache (s->wlen > 0). The angle is base + d with
 * d the rotation since base_t (mid-interval, |d| <= pi/2 in a segment of at most half a turn): sin d
 * and cos d by their Taylor series, whose first omitted terms are below 2e-18 for |d| <= 1.6, then
 * the angle-sum formulas; cheaper than a libm sincos per time evaluated. Larger |d|: libm. */
static inline void scc_fw_angle_cs(const scc_fw_state* s, double t, double* out_c, double* out_s)
{
    double d = s->wlen * (t - s->base_t);
    if (fabs(d) <= 1.6) {
        double d2 = d * d, sd, cd;
        scc_sincos_series(d2, &sd, &cd);
        sd *= d;
        *out_c = s->base_c * cd - s->base_s * sd;
        *out_s = s->base_s * cd + s->base_c * sd;
    } else {
        double a = s->wlen * (t - s->t0);
        *out_c = cos(a);
        *out_s = sin(a);
    }
}

/* The same into the cache. */
static inline void scc_fw_angle_at(scc_fw_state* s, double t)
{
    scc_fw_angle_cs(s, t, &s->cache_c, &s->cache_s);
    s->cache_t = t;
}

/* Rodrigues' formula with the rotation's cosine c and sine sn. */
static inline scc_vec3 scc_fw_rodrigues_cs(const scc_fw_state* s, scc_vec3 r, scc_vec3 kr, double kd, double c, double sn)
{
    return scc_add(scc_add(scc_scale(r, c), scc_scale(kr, sn)), scc_scale(s->axis, kd * (1.0 - c)));
}

/* Rodrigues' formula with the cached cosine and sine. */
static inline scc_vec3 scc_fw_rodrigues(const scc_fw_state* s, scc_vec3 r, scc_vec3 kr, double kd)
{
    return scc_fw_rodrigues_cs(s, r, kr, kd, s->cache_c, s->cache_s);
}

/* Offset R(w tau) r at time t by Rodrigues' formula, with kr = axis x r and kd = axis . r given
 * (constant for one point); the rotation's sine and cosine are cached for the last time. */
static inline scc_vec3 scc_fw_rotate_pre(scc_fw_state* s, double t, scc_vec3 r, scc_vec3 kr, double kd)
{
    if (s->wlen == 0.0) return r;
    if (t != s->cache_t) scc_fw_angle_at(s, t);
    return scc_fw_rodrigues(s, r, kr, kd);
}

/* Point with weights b at time t (SDF frame) and its velocity when vel is not NULL. */
static inline scc_vec3 scc_fw_point(scc_fw_state* s, const double b[3], double t, scc_vec3* vel)
{
    if (!s->fast) return scc_tri_point_at(s->m, b, t, vel);
    if (!s->pt_valid || memcmp(b, s->pt_b, sizeof s->pt_b) != 0) {
        memcpy(s->pt_b, b, sizeof s->pt_b);
        s->pt_r = scc_add(scc_add(scc_scale(s->r0[0], b[0]), scc_scale(s->r0[1], b[1])), scc_scale(s->r0[2], b[2]));
        s->pt_kr = scc_cross(s->axis, s->pt_r);
        s->pt_kd = scc_dot(s->axis, s->pt_r);
        s->pt_valid = 1;
    }
    scc_vec3 rr = scc_fw_rotate_pre(s, t, s->pt_r, s->pt_kr, s->pt_kd);
    if (vel) *vel = scc_add(s->v, scc_cross(s->w, rr));
    return scc_add(scc_madd(s->g0, s->v, t - s->t0), rr);
}

/* One point of the triangle (fixed weights) followed over time: a temporal search or a vertex trace
 * evaluates it at many times. Its offset terms are those scc_fw_point computes (the same bits),
 * set once, so a sample skips scc_fw_point's cache check. */
typedef struct scc_fw_path {
    double b[3];
    int motion;     /* 0: scc_tri_point_at; 1: closed form, no spin; 2: closed form with spin */
    scc_vec3 r, kr; /* offset r from the centre at t0 and axis x r (closed-form motion) */
    double kd;      /* axis . r */
} scc_fw_path;

static inline void scc_fw_path_init(const scc_fw_state* s, const double b[3], scc_fw_path* out)
{
    out->b[0] = b[0]; out->b[1] = b[1]; out->b[2] = b[2];
    out->motion = !s->fast ? 0 : (s->wlen != 0.0 ? 2 : 1);
    if (!s->fast) return;
    out->r = scc_add(scc_add(scc_scale(s->r0[0], b[0]), scc_scale(s->r0[1], b[1])), scc_scale(s->r0[2], b[2]));
    out->kr = scc_cross(s->axis, out->r);
    out->kd = scc_dot(s->axis, out->r);
}

/* scc_fw_path_init(s, s->b, out) right after scc_fw_point(s, s->b, ..) (scc_fw_eval): the offset terms
 * are the ones that call left in the point cache, computed from the same weights (the same bits). */
static inline void scc_fw_path_of_current(const scc_fw_state* s, scc_fw_path* out)
{
    out->b[0] = s->b[0]; out->b[1] = s->b[1]; out->b[2] = s->b[2];
    out->motion = !s->fast ? 0 : (s->wlen != 0.0 ? 2 : 1);
    if (!s->fast) return;
    out->r = s->pt_r;
    out->kr = s->pt_kr;
    out->kd = s->pt_kd;
}

/* scc_fw_point(s, path->b, t, NULL), the same bits. A path is sampled at a new time nearly always (99 %
 * in the data set's vertex traces), so the angle is computed without looking at the cache first. */
static inline scc_vec3 scc_fw_path_point(scc_fw_state* s, const scc_fw_path* path, double t)
{
    scc_vec3 rr;
    if (path->motion == 2) { /* the common case first */
        scc_fw_angle_at(s, t);
        rr = scc_fw_rodrigues(s, path->r, path->kr, path->kd);
    } else if (path->motion == 1) {
        rr = path->r;
    } else {
        return scc_tri_point_at(s->m, path->b, t, NULL);
    }
    return scc_add(scc_madd(s->g0, s->v, t - s->t0), rr);
}

/* scc_fw_path_point without the rotation cache (the same bits): nothing is stored, so the samples
 * of several paths at different times do not depend on each other through the state (the vertex
 * traces run side by side, fwgss.c). */
static inline scc_vec3 scc_fw_path_point_pure(const scc_fw_state* s, const scc_fw_path* path, double t)
{
    scc_vec3 rr;
    if (path->motion == 2) {
        double c, sn;
        scc_fw_angle_cs(s, t, &c, &sn);
        rr = scc_fw_rodrigues_cs(s, path->r, path->kr, path->kd, c, sn);
    } else if (path->motion == 1) {
        rr = path->r;
    } else {
        return scc_tri_point_at(s->m, path->b, t, NULL);
    }
    return scc_add(scc_madd(s->g0, s->v, t - s->t0), rr);
}

/* The three vertices at time t and, when with_velocity, their velocities (else st->v is left
 * unset on the closed-form path: the spatial steps need only the positions). */
static inline void scc_fw_tri_state_ex(scc_fw_state* s, double t, scc_tri_state* st, int with_velocity)
{
    if (!s->fast) {
        scc_tri_state_at(s->m, t, st);
        return;
    }
    st->t = t;
    scc_vec3 g = scc_madd(s->g0, s->v, t - s->t0);
    for (int i = 0; i < 3; ++i) {
        scc_vec3 rr = scc_fw_rotate_pre(s, t, s->r0[i], s->kr0[i], s->kd0[i]);
        st->x[i] = scc_add(g, rr);
        if (with_velocity) st->v[i] = scc_add(s->v, scc_cross(s->w, rr));
    }
}

/* The three vertices and their velocities at time t. */
static inline void scc_fw_tri_state(scc_fw_state* s, double t, scc_tri_state* st) { scc_fw_tri_state_ex(s, t, st, 1); }

/* The three vertices at time t (st->v unset on the closed-form path). */
static inline void scc_fw_tri_points(scc_fw_state* s, double t, scc_tri_state* st) { scc_fw_tri_state_ex(s, t, st, 0); }

/* phi (and its gradient when g is not NULL) at x: the built-in torus (the data set's field) inline, by
 * one test of a pointer set once per solve (scc_fw_begin) instead of scc_sdf_eval_builtin's tests of the
 * kind and the eval pointer per sample; any other field by one call of its eval function, which keeps
 * the solvers' loops short (the same values: the eval functions of the inlined kinds run the same code). */
SCC_HOT_INLINE double scc_fw_sdf(const scc_fw_state* s, scc_vec3 x, scc_vec3* g)
{
    if (s->torus) return scc_sdf_torus_value(s->torus, x, g);
    if (s->user) return scc_sdf_user_value(s->user, x, g);
    return s->sdf->eval(s->sdf, x, g);
}

/* Records a contact witness (phi <= margin) at time t with weights b: shrinks te. */
static inline void scc_fw_witness(scc_fw_state* s, double t, const double b[3], double phi)
{
    if (phi <= s->margin && (!s->hit || t < s->hit_t)) {
        s->hit = 1;
        s->hit_t = t;
        s->hit_b[0] = b[0]; s->hit_b[1] = b[1]; s->hit_b[2] = b[2];
        if (t < s->te) s->te = t;
    }
}

/* phi (and gradient, velocity) of the current weights at time t; records witnesses. */
static inline double scc_fw_eval(scc_fw_state* s, const double b[3], double t, scc_vec3* x, scc_vec3* g, scc_vec3* v)
{
    *x = scc_fw_point(s, b, t, v);
    double phi = scc_fw_sdf(s, *x, g);
    s->evals++;
    scc_fw_witness(s, t, b, phi);
    return phi;
}

void scc_fw_begin(scc_fw_state* s, const scc_sdf* sdf, const scc_tri_motion* m, const scc_params* p, double ta, double tb);
/* Section 4.4: the vertex minimising v . grad phi at ts; sets s->b. */
void scc_fw_start_vertex(scc_fw_state* s);
/* The three vertices ordered by the Section 4.4 score (most promising first). */
void scc_fw_start_order(scc_fw_state* s, int order[3]);
/* Index of the vertex minimising grad . vertex (Eq. 15), given the three products d[j] = g . x[j]
 * (the first on ties). */
static inline int scc_fw_support_of(const double d[3])
{
    int s = 0;
    for (int j = 1; j < 3; ++j)
        if (d[j] < d[s]) s = j;
    return s;
}

/* Index of the vertex of `st` minimising grad . vertex (Eq. 15). Inline: a spatial step takes it
 * at every iteration. */
static inline int scc_fw_support(const scc_tri_state* st, scc_vec3 g)
{
    const double d[3] = { scc_dot(g, st->x[0]), scc_dot(g, st->x[1]), scc_dot(g, st->x[2]) };
    return scc_fw_support_of(d);
}
/* Fills `out` from the solver state once the iterations end. */
void scc_fw_finish(scc_fw_state* s, int converged, int64_t iterations, scc_tri_hit* out);

#endif
