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
    return scc_gss_run(a, b, fa, fb, tol, slope, max_iter, f, ctx);
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
    return scc_deriv_run(f0, d0, tol, max_iter, f, ctx, out, f1);
}
