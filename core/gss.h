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

/* Brent's minimiser over [a, b] (a <= b): parabolic steps safeguarded by golden section; the same
 * result struct. Converges superlinearly near a smooth minimum. */
scc_gss_result scc_brent_minimize(double a, double b, double tol, int max_iter, scc_gss_fn* f, void* ctx);

#endif
