/* SPDX-License-Identifier: MIT
 * sdfccd core: golden-section search (the paper's Algorithm 1, Section 3.4). */
#ifndef SCC_GSS_H
#define SCC_GSS_H

#include "scc_math.h"

typedef double scc_gss_fn(double l, void* ctx);

typedef struct scc_gss_result {
    double l;      /* the minimiser returned by Algorithm 1 (l0, the bracket midpoint or l3) */
    double f;      /* f(l) */
    int evals;     /* function evaluations used */
    int converged; /* 0 when max_iter stopped it before the bracket was narrower than tol */
} scc_gss_result;

/* Minimises f over [a, b] (a <= b, or a > b for a reversed interval). Iterates while the
 * bracket is wider than the absolute tolerance `tol` (the printed while-condition of
 * Algorithm 1 is inverted by a typo; this is the intended loop) and at most max_iter times.
 * Returns the best of the final bracket's ends and its midpoint, as Algorithm 1 does. */
scc_gss_result scc_gss_minimize(double a, double b, double tol, int max_iter, scc_gss_fn* f, void* ctx);

/* The same, also stopping (converged) once the bracket's width times `slope` is at most the
 * smallest value sampled so far, when that is positive (ours). With `slope` = 2 x a Lipschitz bound
 * of f in l, f stays above half that value over the whole final bracket: no zero of f inside it
 * is skipped, while far from zero the search ends early. slope <= 0: scc_gss_minimize. */
scc_gss_result scc_gss_minimize_gap(double a, double b, double tol, double slope, int max_iter, scc_gss_fn* f, void* ctx);

/* scc_gss_minimize_gap with f(a) and f(b) already known (fa, fb; NaN: unknown), which are not
 * evaluated again: the same samples and result, up to two evaluations fewer. */
scc_gss_result scc_gss_minimize_from(double a, double b, double fa, double fb, double tol, double slope, int max_iter, scc_gss_fn* f, void* ctx);

/* Brent's minimiser over [a, b] (a <= b): parabolic steps safeguarded by golden section; the same
 * result struct. Converges superlinearly near a smooth minimum. */
scc_gss_result scc_brent_minimize(double a, double b, double tol, int max_iter, scc_gss_fn* f, void* ctx);

/* f(l) and its derivative f'(l) (in *df). */
typedef double scc_gss_dfn(double l, double* df, void* ctx);

/* Minimises f over [0, 1] from f(0) = f0 and f'(0) = d0 using derivatives (ours): the end l = 1
 * is evaluated first and is the answer when f still descends there and f(1) < f0; otherwise the
 * sign change of f' in [0, 1] is closed by secant steps on f' (regula falsi with the Illinois
 * modification, a bisection after two steps that did not halve the bracket) until the bracket is
 * narrower than tol or max_iter steps. The result is the evaluated point with the smallest f.
 * Returns 0 (out untouched but for *f1) when f descends at l = 1 and yet f(1) >= f0, i.e. f' changes
 * sign more than once: the caller then searches without derivatives, with f(1) in *f1. d0 >= 0
 * gives l = 0 without an evaluation. */
int scc_deriv_minimize(double f0, double d0, double tol, int max_iter, scc_gss_dfn* f, void* ctx, scc_gss_result* out, double* f1);

/* The bodies of scc_gss_minimize_from and scc_deriv_minimize, inline: a solver that calls them with
 * its own static f gets f inlined too (no call per sample). */
#if defined(__GNUC__) || defined(__clang__)
#define SCC_GSS_INLINE static inline __attribute__((always_inline))
#else
#define SCC_GSS_INLINE static inline
#endif

SCC_GSS_INLINE scc_gss_result scc_gss_run(double a, double b, double fa, double fb, double tol, double slope, int max_iter, scc_gss_fn* f, void* ctx)
{
    const double r = 0.61803398874989484820; /* 1/phi */
    const double rc = 1.0 - r;
    scc_gss_result res;
    double a0 = 0.0, a1 = rc, a2 = r, a3 = 1.0;
    double l0 = a, l3 = b;
    double f0 = fa, f3 = fb;
    res.evals = 0;
    if (isnan(f0)) {
        f0 = f(l0, ctx);
        res.evals++;
    }
    if (a == b) {
        res.l = a; res.f = f0; res.converged = 1;
        return res;
    }
    if (isnan(f3)) {
        f3 = f(l3, ctx);
        res.evals++;
    }
    double l1 = a + (b - a) * a1, l2 = a + (b - a) * a2;
    double f1 = f(l1, ctx), f2 = f(l2, ctx);
    res.evals += 2;
    int it = 0, flat = 0;
    while (fabs(l3 - l0) > tol && it < max_iter) {
        const double m01 = scc_fmin(f0, f1), m23 = scc_fmin(f2, f3); /* once for both tests */
        if (slope > 0.0) {
            double m = scc_fmin(m01, m23);
            if (m > 0.0 && fabs(l3 - l0) * slope <= m) { flat = 1; break; }
        }
        ++it;
        if (m01 < m23) {
            a3 = a2; l3 = l2; f3 = f2;
            a2 = a1; l2 = l1; f2 = f1;
            a1 = r * a2 + rc * a0;
            l1 = a + (b - a) * a1;
            f1 = f(l1, ctx);
        } else {
            a0 = a1; l0 = l1; f0 = f1;
            a1 = a2; l1 = l2; f1 = f2;
            a2 = r * a1 + rc * a3;
            l2 = a + (b - a) * a2;
            f2 = f(l2, ctx);
        }
        res.evals++;
    }
    res.converged = flat || fabs(l3 - l0) <= tol;
    double lmid = a + (b - a) * 0.5 * (a0 + a3);
    double fmid = f(lmid, ctx);
    res.evals++;
    if (f0 < fmid && f0 < f3) { res.l = l0; res.f = f0; }
    else if (fmid < f3) { res.l = lmid; res.f = fmid; }
    else { res.l = l3; res.f = f3; }
    return res;
}

SCC_GSS_INLINE int scc_deriv_run(double f0, double d0, double tol, int max_iter, scc_gss_dfn* f, void* ctx, scc_gss_result* out, double* f1)
{
    scc_gss_result res = { 0.0, f0, 0, 1 };
    if (!(d0 < 0.0)) {
        *out = res;
        return 1;
    }
    double dhi;
    const double fhi = f(1.0, &dhi, ctx);
    *f1 = fhi;
    res.evals = 1;
    if (!(dhi > 0.0)) {
        if (!(fhi < f0)) return 0; /* f fell, rose and fell again: more than one sign change of f' */
        res.l = 1.0;
        res.f = fhi;
        *out = res;
        return 1;
    }
    if (fhi < res.f) { res.l = 1.0; res.f = fhi; }
    double lo = 0.0, hi = 1.0, dlo = d0;
    int it = 0, side = 0, slow = 0;
    while (hi - lo > tol && it < max_iter) {
        ++it;
        const double width = hi - lo;
        double l;
        if (slow >= 2) {
            l = 0.5 * (lo + hi);
            slow = 0;
        } else {
            l = lo - dlo * (hi - lo) / (dhi - dlo);
            const double m = 0.25 * tol; /* strictly inside, as the entry search keeps its samples */
            if (!(l > lo + m)) l = lo + m;
            if (!(l < hi - m)) l = hi - m;
        }
        double dl;
        const double fl = f(l, &dl, ctx);
        res.evals++;
        if (fl < res.f) { res.l = l; res.f = fl; }
        if (dl < 0.0) {
            lo = l;
            dlo = dl;
            if (side == -1) dhi *= 0.5;
            side = -1;
        } else if (dl > 0.0) {
            hi = l;
            dhi = dl;
            if (side == 1) dlo *= 0.5;
            side = 1;
        } else {
            break; /* a stationary point (or a NaN slope): nothing better to bracket */
        }
        slow = hi - lo > 0.5 * width ? slow + 1 : 0;
    }
    res.converged = hi - lo <= tol || it < max_iter;
    *out = res;
    return 1;
}

#endif
