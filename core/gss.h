/* SPDX-License-Identifier: MIT
 * sdfccd core: golden-section search (the paper's Algorithm 1, Section 3.4). */
#ifndef SCC_GSS_H
#define SCC_GSS_H

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

#endif
