/* SPDX-License-Identifier: MIT
 * sdfccd core: golden-section search, Pelletier-Guenette et al. 2025, Algorithm 1 (Section 3.4).
 * Two fixes to the printed pseudocode: the loop runs while the bracket is WIDER than the
 * tolerance, and the tolerance is absolute (a relative one, tol * (l1 + l2), never stops
 * near l = 0 and is meaningless for intervals that straddle zero). */
#include "gss.h"

#include <math.h>

scc_gss_result scc_gss_minimize(double a, double b, double tol, int max_iter, scc_gss_fn* f, void* ctx)
{
    const double r = 0.61803398874989484820; /* 1/phi */
    const double rc = 1.0 - r;
    scc_gss_result res;
    double a0 = 0.0, a1 = rc, a2 = r, a3 = 1.0;
    double l0 = a, l3 = b;
    double f0 = f(l0, ctx), f3;
    res.evals = 1;
    if (a == b) {
        res.l = a; res.f = f0; res.converged = 1;
        return res;
    }
    f3 = f(l3, ctx);
    double l1 = a + (b - a) * a1, l2 = a + (b - a) * a2;
    double f1 = f(l1, ctx), f2 = f(l2, ctx);
    res.evals += 3;
    int it = 0;
    while (fabs(l3 - l0) > tol && it < max_iter) {
        ++it;
        if (fmin(f0, f1) < fmin(f2, f3)) {
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
    res.converged = fabs(l3 - l0) <= tol;
    double lmid = a + (b - a) * 0.5 * (a0 + a3);
    double fmid = f(lmid, ctx);
    res.evals++;
    if (f0 < fmid && f0 < f3) { res.l = l0; res.f = f0; }
    else if (fmid < f3) { res.l = lmid; res.f = fmid; }
    else { res.l = l3; res.f = f3; }
    return res;
}
