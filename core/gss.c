/* SPDX-License-Identifier: MIT
 * sdfccd core: golden-section search, Pelletier-Guenette et al. 2025, Algorithm 1 (Section 3.4).
 * Two fixes to the printed pseudocode: the loop runs while the bracket is WIDER than the
 * tolerance, and the tolerance is absolute (a relative one, tol * (l1 + l2), never stops
 * near l = 0 and is meaningless for intervals that straddle zero). Also here (ours): Brent's
 * minimiser, and a line search with derivatives that FWGSS uses near contact. */
#include "gss.h"
#include "scc_math.h"

#include <math.h>

scc_gss_result scc_gss_minimize(double a, double b, double tol, int max_iter, scc_gss_fn* f, void* ctx)
{
    return scc_gss_minimize_gap(a, b, tol, 0.0, max_iter, f, ctx);
}

scc_gss_result scc_gss_minimize_gap(double a, double b, double tol, double slope, int max_iter, scc_gss_fn* f, void* ctx)
{
    return scc_gss_minimize_from(a, b, NAN, NAN, tol, slope, max_iter, f, ctx);
}

scc_gss_result scc_gss_minimize_from(double a, double b, double fa, double fb, double tol, double slope, int max_iter, scc_gss_fn* f, void* ctx)
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
        if (slope > 0.0) {
            double m = scc_fmin(scc_fmin(f0, f1), scc_fmin(f2, f3));
            if (m > 0.0 && fabs(l3 - l0) * slope <= m) { flat = 1; break; }
        }
        ++it;
        if (scc_fmin(f0, f1) < scc_fmin(f2, f3)) {
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

/* Brent's minimiser (golden-section steps safeguarding parabolic interpolation through the three
 * best points; R. Brent, Algorithms for Minimization without Derivatives, 1973, ch. 5). Same
 * contract as scc_gss_minimize over [a, b] with a <= b; ends when the bracket around the best
 * point is narrower than about 2 tol. Near a smooth minimum it needs a handful of evaluations where
 * golden section needs log(tol / (b - a)) / log(0.618). */
scc_gss_result scc_brent_minimize(double a, double b, double tol, int max_iter, scc_gss_fn* f, void* ctx)
{
    const double cg = 0.38196601125010515; /* 1 - 1/phi */
    scc_gss_result res;
    double x = a + cg * (b - a), w = x, v = x;
    double fx = f(x, ctx), fw = fx, fv = fx;
    res.evals = 1;
    double d = 0.0, e = 0.0;
    int it = 0;
    for (; it < max_iter; ++it) {
        double m = 0.5 * (a + b);
        double tol1 = tol * 0.5 + 1e-15 * fabs(x), tol2 = 2.0 * tol1;
        if (fabs(x - m) <= tol2 - 0.5 * (b - a)) break;
        int golden = 1;
        if (fabs(e) > tol1) {
            /* parabola through (v, fv), (w, fw), (x, fx) */
            double r = (x - w) * (fx - fv), q = (x - v) * (fx - fw), p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if (q > 0.0) p = -p;
            q = fabs(q);
            double e_prev = e;
            e = d;
            if (fabs(p) < fabs(0.5 * q * e_prev) && p > q * (a - x) && p < q * (b - x)) {
                d = p / q;
                double u = x + d;
                if (u - a < tol2 || b - u < tol2) d = x < m ? tol1 : -tol1;
                golden = 0;
            }
        }
        if (golden) {
            e = (x < m ? b : a) - x;
            d = cg * e;
        }
        double u = fabs(d) >= tol1 ? x + d : x + (d > 0.0 ? tol1 : -tol1);
        double fu = f(u, ctx);
        res.evals++;
        if (fu <= fx) {
            if (u < x) b = x; else a = x;
            v = w; fv = fw;
            w = x; fw = fx;
            x = u; fx = fu;
        } else {
            if (u < x) a = u; else b = u;
            if (fu <= fw || w == x) {
                v = w; fv = fw;
                w = u; fw = fu;
            } else if (fu <= fv || v == x || v == w) {
                v = u; fv = fu;
            }
        }
    }
    res.converged = it < max_iter;
    res.l = x;
    res.f = fx;
    return res;
}

int scc_deriv_minimize(double f0, double d0, double tol, int max_iter, scc_gss_dfn* f, void* ctx, scc_gss_result* out, double* f1)
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
