/* SPDX-License-Identifier: MIT
 * sdfccd core: small vector, quaternion and 3x3 matrix helpers (double precision).
 * Header-only, static inline. Quaternions are stored w first, as in the case file. */
#ifndef SCC_MATH_H
#define SCC_MATH_H

#include <math.h>
#include <stddef.h>

#define SCC_PI 3.14159265358979323846

/* A branch the caller expects to be taken (laid out as the fall-through path): only the code's layout
 * changes. */
#if defined(__GNUC__) || defined(__clang__)
#define SCC_LIKELY(x) __builtin_expect(!!(x), 1)
#else
#define SCC_LIKELY(x) (x)
#endif

typedef struct scc_vec3 { double x, y, z; } scc_vec3;
typedef struct scc_quat { double w, x, y, z; } scc_quat;
/* Row-major 3x3 matrix: m[row][col]. */
typedef struct scc_mat3 { double m[3][3]; } scc_mat3;

static inline scc_vec3 scc_v3(double x, double y, double z) { scc_vec3 r = { x, y, z }; return r; }
static inline scc_vec3 scc_add(scc_vec3 a, scc_vec3 b) { return scc_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline scc_vec3 scc_sub(scc_vec3 a, scc_vec3 b) { return scc_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline scc_vec3 scc_scale(scc_vec3 a, double s) { return scc_v3(a.x * s, a.y * s, a.z * s); }
static inline scc_vec3 scc_madd(scc_vec3 a, scc_vec3 b, double s) { return scc_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline double scc_dot(scc_vec3 a, scc_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline scc_vec3 scc_cross(scc_vec3 a, scc_vec3 b)
{
    return scc_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double scc_len2(scc_vec3 a) { return scc_dot(a, a); }
static inline double scc_len(scc_vec3 a) { return sqrt(scc_dot(a, a)); }
static inline double scc_dist(scc_vec3 a, scc_vec3 b) { return scc_len(scc_sub(a, b)); }
/* Lengths that neither overflow nor underflow in the squares (hypot-style): the plain formula
 * when every coordinate is in [1e-150, 1e150] or zero, else the coordinates scaled by the largest. */
static inline double scc_hypot3(double x, double y, double z)
{
    /* The common case first: 4e-300 <= s <= 1e299 implies every coordinate < 1e150, the largest
     * >= 1e-150 and s >= 1e-300, the plain formula's conditions below; so the same result, with
     * two comparisons instead of the coordinates' magnitudes. */
    const double s0 = x * x + y * y + z * z;
    if (SCC_LIKELY(s0 >= 4e-300 && s0 <= 1e299)) return sqrt(s0);
    /* a NaN coordinate gives NaN either way below: plain comparisons (no libm call) suffice */
    double ax = fabs(x), ay = fabs(y), az = fabs(z);
    double m = ax > ay ? ax : ay;
    m = m > az ? m : az;
    if (m <= 1e150 && m >= 1e-150) {
        double s = x * x + y * y + z * z;
        if (s >= 1e-300) return sqrt(s);
    }
    if (!(m > 0.0) || isinf(m)) return m; /* 0, inf or NaN */
    x /= m; y /= m; z /= m;
    return m * sqrt(x * x + y * y + z * z);
}
/* scc_hypot3(x, y, 0) bit for bit, without the third coordinate's work on the common path; always
 * inlined (the torus evaluates it twice per sample in the solvers' hot loops). */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((always_inline))
#endif
static inline double scc_hypot2(double x, double y)
{
    const double s0 = x * x + y * y; /* the common case first, as in scc_hypot3 */
    if (SCC_LIKELY(s0 >= 4e-300 && s0 <= 1e299)) return sqrt(s0);
    double ax = fabs(x), ay = fabs(y);
    double m = ax > ay ? ax : ay;
    if (m <= 1e150 && m >= 1e-150) {
        double s = x * x + y * y; /* + 0 * 0 in scc_hypot3: the same value (s is not -0) */
        if (s >= 1e-300) return sqrt(s);
    }
    return scc_hypot3(x, y, 0.0);
}
/* fmin and fmax as the C library's (x86-64 glibc: minsd / maxsd, the other operand for a NaN, the
 * second operand when equal, e.g. -0 and +0), inline instead of a call. */
static inline double scc_fmin(double a, double b) { return a < b ? a : (b == b ? b : a); }
static inline double scc_fmax(double a, double b) { return a > b ? a : (b == b ? b : a); }
static inline double scc_len_safe(scc_vec3 a) { return scc_hypot3(a.x, a.y, a.z); }
static inline scc_vec3 scc_lerp(scc_vec3 a, scc_vec3 b, double t) { return scc_madd(a, scc_sub(b, a), t); }
static inline scc_vec3 scc_mul(scc_vec3 a, scc_vec3 b) { return scc_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline scc_vec3 scc_vabs(scc_vec3 a) { return scc_v3(fabs(a.x), fabs(a.y), fabs(a.z)); }
static inline scc_vec3 scc_vmax(scc_vec3 a, scc_vec3 b) { return scc_v3(fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z)); }
static inline scc_vec3 scc_vmin(scc_vec3 a, scc_vec3 b) { return scc_v3(fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z)); }
static inline double scc_maxc(scc_vec3 a) { return fmax(a.x, fmax(a.y, a.z)); }
/* Unit vector; returns `fallback` when the length is below 1e-300. */
static inline scc_vec3 scc_normalize_or(scc_vec3 a, scc_vec3 fallback)
{
    double l = scc_len(a);
    return l > 1e-300 ? scc_scale(a, 1.0 / l) : fallback;
}
static inline int scc_vfinite(scc_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static inline double scc_clamp(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

static inline scc_quat scc_quat_identity(void) { scc_quat q = { 1.0, 0.0, 0.0, 0.0 }; return q; }
static inline scc_quat scc_quat_mul(scc_quat a, scc_quat b)
{
    scc_quat r;
    r.w = a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z;
    r.x = a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y;
    r.y = a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x;
    r.z = a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w;
    return r;
}
static inline scc_quat scc_quat_conj(scc_quat q) { scc_quat r = { q.w, -q.x, -q.y, -q.z }; return r; }
static inline double scc_quat_norm(scc_quat q) { return sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z); }
static inline scc_quat scc_quat_normalize(scc_quat q)
{
    double n = scc_quat_norm(q);
    if (!(n > 0.0)) return scc_quat_identity();
    scc_quat r = { q.w / n, q.x / n, q.y / n, q.z / n };
    return r;
}
/* Rotation by the rotation vector `rv` (axis times angle in radians): the exponential map. */
static inline scc_quat scc_quat_from_rotvec(scc_vec3 rv)
{
    double a = scc_len(rv);
    scc_quat q;
    if (a < 1e-8) {
        /* Taylor expansion of sin(a/2)/a keeps the map smooth at zero. */
        double s = 0.5 - a * a / 48.0;
        q.w = 1.0 - a * a / 8.0; q.x = rv.x * s; q.y = rv.y * s; q.z = rv.z * s;
        return scc_quat_normalize(q);
    }
    double s = sin(0.5 * a) / a;
    q.w = cos(0.5 * a); q.x = rv.x * s; q.y = rv.y * s; q.z = rv.z * s;
    return q;
}
static inline scc_vec3 scc_quat_rotate(scc_quat q, scc_vec3 v)
{
    /* v' = v + 2w (u x v) + 2 u x (u x v), u = (x, y, z) */
    scc_vec3 u = scc_v3(q.x, q.y, q.z);
    scc_vec3 t = scc_scale(scc_cross(u, v), 2.0);
    return scc_add(scc_add(v, scc_scale(t, q.w)), scc_cross(u, t));
}
static inline scc_mat3 scc_mat3_from_quat(scc_quat q)
{
    scc_mat3 r;
    double xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
    double xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
    double wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
    r.m[0][0] = 1 - 2 * (yy + zz); r.m[0][1] = 2 * (xy - wz);     r.m[0][2] = 2 * (xz + wy);
    r.m[1][0] = 2 * (xy + wz);     r.m[1][1] = 1 - 2 * (xx + zz); r.m[1][2] = 2 * (yz - wx);
    r.m[2][0] = 2 * (xz - wy);     r.m[2][1] = 2 * (yz + wx);     r.m[2][2] = 1 - 2 * (xx + yy);
    return r;
}
static inline scc_vec3 scc_mat3_mulv(const scc_mat3* a, scc_vec3 v)
{
    return scc_v3(a->m[0][0] * v.x + a->m[0][1] * v.y + a->m[0][2] * v.z,
                  a->m[1][0] * v.x + a->m[1][1] * v.y + a->m[1][2] * v.z,
                  a->m[2][0] * v.x + a->m[2][1] * v.y + a->m[2][2] * v.z);
}
/* Transpose times vector: the inverse rotation for an orthonormal matrix. */
static inline scc_vec3 scc_mat3_tmulv(const scc_mat3* a, scc_vec3 v)
{
    return scc_v3(a->m[0][0] * v.x + a->m[1][0] * v.y + a->m[2][0] * v.z,
                  a->m[0][1] * v.x + a->m[1][1] * v.y + a->m[2][1] * v.z,
                  a->m[0][2] * v.x + a->m[1][2] * v.y + a->m[2][2] * v.z);
}
static inline scc_mat3 scc_mat3_mul(const scc_mat3* a, const scc_mat3* b)
{
    scc_mat3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            r.m[i][j] = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] + a->m[i][2] * b->m[2][j];
    return r;
}

/* A rigid transform x' = R x + p. */
typedef struct scc_xform { scc_quat q; scc_vec3 p; } scc_xform;
static inline scc_vec3 scc_xform_apply(scc_xform t, scc_vec3 x) { return scc_add(scc_quat_rotate(t.q, x), t.p); }
static inline scc_vec3 scc_xform_apply_inv(scc_xform t, scc_vec3 x)
{
    return scc_quat_rotate(scc_quat_conj(t.q), scc_sub(x, t.p));
}

/* Axis-aligned box. */
typedef struct scc_aabb { scc_vec3 lo, hi; } scc_aabb;
/* Euclidean distance from p to the box (0 inside). */
static inline double scc_aabb_distance(const scc_aabb* b, scc_vec3 p)
{
    scc_vec3 d = scc_vmax(scc_vmax(scc_sub(b->lo, p), scc_sub(p, b->hi)), scc_v3(0, 0, 0));
    return scc_len(d);
}

#endif
