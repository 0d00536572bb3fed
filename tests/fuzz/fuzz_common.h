/* SPDX-License-Identifier: MIT
 * Shared helpers of the libFuzzer targets: a byte reader that turns fuzzer input into doubles
 * (mostly small coordinates, sometimes raw bit patterns or boundary values), the checks every
 * OK query result must pass, and the slowest-query record printed at exit. */
#ifndef SDFCCD_FUZZ_COMMON_H
#define SDFCCD_FUZZ_COMMON_H

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sdfccd/sdfccd.h"

typedef struct fuzz_in {
    const uint8_t* p;
    size_t n;
} fuzz_in;

static inline uint8_t fz_u8(fuzz_in* in)
{
    if (!in->n) return 0;
    --in->n;
    return *in->p++;
}

static inline uint32_t fz_u32(fuzz_in* in)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = v << 8 | fz_u8(in);
    return v;
}

/* A double: 3/4 of selectors give a value in [-4, 4] with 16-bit resolution, then raw IEEE
 * bit patterns (NaN, inf, subnormals, anything), then a table of boundary values. */
static inline double fz_double(fuzz_in* in)
{
    static const double special[16] = { 0.0, -0.0, 1e-300, -1e-300, 1e300, 1e154, 1e150, -1e150, DBL_MAX, -DBL_MAX,
                                        INFINITY, -INFINITY, NAN, 1e6, 1e-7, 3.14159265358979323846 };
    uint8_t sel = fz_u8(in);
    if (sel < 192) {
        uint16_t v = (uint16_t)(fz_u8(in) << 8 | fz_u8(in));
        return -4.0 + 8.0 * v / 65535.0;
    }
    if (sel < 240) {
        uint64_t b = 0;
        for (int i = 0; i < 8; ++i) b = b << 8 | fz_u8(in);
        double d;
        memcpy(&d, &b, 8);
        return d;
    }
    return special[sel - 240];
}

static inline sdfccd_Vec3 fz_vec(fuzz_in* in)
{
    sdfccd_Vec3 v;
    v.x = fz_double(in);
    v.y = fz_double(in);
    v.z = fz_double(in);
    return v;
}

static inline double fz_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The slowest single query of this process, printed at exit (the closing note's figure). */
static double g_fz_worst = 0.0;
static int64_t g_fz_worst_evals = 0;
static int64_t g_fz_queries = 0;
static void fz_report(void)
{
    fprintf(stderr, "sdfccd-fuzz: %lld queries, slowest %.3f s (%lld SDF evaluations)\n", (long long)g_fz_queries, g_fz_worst,
            (long long)g_fz_worst_evals);
}
static inline void fz_note_time(double seconds, int64_t evals)
{
    static int registered = 0;
    if (!registered) { atexit(fz_report); registered = 1; }
    ++g_fz_queries;
    if (seconds > g_fz_worst) { g_fz_worst = seconds; g_fz_worst_evals = evals; }
}

#define FZ_CHECK(cond, ...)                                                           \
    do {                                                                              \
        if (!(cond)) {                                                                \
            fprintf(stderr, "sdfccd-fuzz: check failed: %s: ", #cond);              \
            fprintf(stderr, __VA_ARGS__);                                             \
            fprintf(stderr, "\n");                                                    \
            abort();                                                                  \
        }                                                                             \
    } while (0)

/* Slack over the evaluation budget: the solvers check it once per iteration, and one iteration
 * runs at most a few line searches of max_line_search_iterations (<= 4096) evaluations each. */
#define FZ_BUDGET_SLACK (8 * 4096 + 1024)

/* Every OK result: state and hit agree, toi and toi_lower finite in [t0, t1], fraction in [0, 1],
 * the evaluation budget held, and every contact finite with a unit normal. */
static inline void fz_check_result(const sdfccd_QueryResult* r, const sdfccd_Contact* c, int32_t capacity, double t0, double t1,
                                   const sdfccd_QueryParams* p)
{
    FZ_CHECK(r->state >= SDFCCD_STATE_NO_HIT && r->state <= SDFCCD_STATE_NOT_CONVERGED, "state %d", (int)r->state);
    FZ_CHECK(r->hit == 0 || r->hit == 1, "hit %d", r->hit);
    FZ_CHECK(r->state != SDFCCD_STATE_NO_HIT || !r->hit, "NO_HIT with hit");
    FZ_CHECK((r->state != SDFCCD_STATE_HIT && r->state != SDFCCD_STATE_PENETRATING) || r->hit, "HIT without hit");
    FZ_CHECK(isfinite(r->toi) && r->toi >= t0 && r->toi <= t1, "toi %.17g not in [%.17g, %.17g]", r->toi, t0, t1);
    FZ_CHECK(isfinite(r->toi_lower) && r->toi_lower >= t0 && r->toi_lower <= r->toi, "toi_lower %.17g (toi %.17g, t0 %.17g)",
             r->toi_lower, r->toi, t0);
    FZ_CHECK(isfinite(r->fraction) && r->fraction >= 0.0 && r->fraction <= 1.0, "fraction %.17g", r->fraction);
    FZ_CHECK(r->contact_count >= 0 && r->contact_count <= capacity && r->contact_count <= r->contacts_found, "contact counts %d %d",
             r->contact_count, r->contacts_found);
    FZ_CHECK(r->hit || r->contacts_found == 0, "contacts without a hit");
    FZ_CHECK(r->sdf_evaluations >= 0 && r->sdf_evaluations <= p->max_sdf_evaluations + FZ_BUDGET_SLACK,
             "%lld SDF evaluations over the budget %lld", (long long)r->sdf_evaluations, (long long)p->max_sdf_evaluations);
    for (int32_t i = 0; i < r->contact_count; ++i) {
        const sdfccd_Contact* k = &c[i];
        FZ_CHECK(isfinite(k->point.x) && isfinite(k->point.y) && isfinite(k->point.z), "contact %d point", i);
        FZ_CHECK(isfinite(k->normal.x) && isfinite(k->normal.y) && isfinite(k->normal.z), "contact %d normal", i);
        double nl = sqrt(k->normal.x * k->normal.x + k->normal.y * k->normal.y + k->normal.z * k->normal.z);
        FZ_CHECK(fabs(nl - 1.0) <= 1e-6, "contact %d normal length %.17g", i, nl);
        FZ_CHECK(isfinite(k->distance) && isfinite(k->gap_t0), "contact %d distance %g gap %g", i, k->distance, k->gap_t0);
        FZ_CHECK(isfinite(k->toi) && k->toi >= t0 && k->toi <= t1, "contact %d toi %.17g", i, k->toi);
        for (int j = 0; j < 3; ++j) FZ_CHECK(isfinite(k->barycentric[j]), "contact %d barycentric", i);
    }
}

#endif
