/* SPDX-License-Identifier: MIT
 * sdfccd_grid_bench: grid SDF figures, printed as CSV (benchmark,shape,resolution,threads,metric,value).
 *
 *   sdfccd_grid_bench [--data DIR] [--quick] [--only eval|build|accuracy]
 *
 *  eval:     nanoseconds per value+gradient query on a 64^3 grid sampled from an analytic sphere,
 *            box and torus, against the analytic SDF itself, in one run; through the ABI per point
 *            (sdfccd_sdf_eval, which includes the handle lookup) and in batches of 1024 points
 *            (sdfccd_sdf_eval_batch, one lookup per batch: close to the core's own cost);
 *            at 1M uniform random points (cache- and TLB-hostile: every query lands in a random
 *            cell of a 50 MB grid) and along a random walk with quarter-cell steps (coherent, as
 *            the queries of a moving triangle are).
 *  build:    seconds to bake the armadillo (86,482 triangles) at 64^3 on 1 and 2 threads, dense
 *            and with a narrow band of 2 % of the domain diagonal.
 *  accuracy: max and RMS error of the armadillo grid against the exact mesh distance at 16^3,
 *            32^3, 64^3 and 128^3, over random points of the domain and over points within 1 %
 *            of the box diagonal of the surface.
 * --quick uses 32^3 for build and stops accuracy at 64^3 (for smoke runs).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sdfccd/sdfccd.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static uint64_t s_rng = 0x1234567ull;
static double uniform(double lo, double hi)
{
    s_rng = s_rng * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (double)(s_rng >> 11) * (1.0 / 9007199254740992.0);
}

static void check(sdfccd_Status st, const char* what)
{
    if (st) {
        fprintf(stderr, "sdfccd_grid_bench: %s: %s (%s)\n", what, sdfccd_last_error(), sdfccd_status_string(st));
        exit(1);
    }
}

static void row(const char* bench, const char* shape, int res, int threads, const char* metric, double value)
{
    printf("%s,%s,%d,%d,%s,%.6g\n", bench, shape, res, threads, metric, value);
    fflush(stdout);
}

/* ns per query: the best of 5 passes over the points. */
static double time_abi(sdfccd_SdfId id, const sdfccd_Vec3* p, int n, double* sink)
{
    double best = INFINITY;
    for (int rep = 0; rep < 5; ++rep) {
        const double t0 = now();
        double acc = 0;
        for (int i = 0; i < n; ++i) {
            double v;
            sdfccd_Vec3 g;
            sdfccd_sdf_eval(id, p[i], &v, &g);
            acc += v + g.x;
        }
        best = fmin(best, (now() - t0) / n * 1e9);
        *sink += acc;
    }
    return best;
}

static double time_batch(sdfccd_SdfId id, const sdfccd_Vec3* p, int n, double* sink)
{
    enum { B = 1024 };
    double v[B];
    sdfccd_Vec3 g[B];
    double best = INFINITY;
    for (int rep = 0; rep < 5; ++rep) {
        const double t0 = now();
        double acc = 0;
        for (int i = 0; i < n; i += B) {
            const int m = n - i < B ? n - i : B;
            sdfccd_sdf_eval_batch(id, p + i, m, v, g);
            for (int k = 0; k < m; ++k) acc += v[k] + g[k].x;
        }
        best = fmin(best, (now() - t0) / n * 1e9);
        *sink += acc;
    }
    return best;
}

static void bench_eval(void)
{
    const char* names[3] = { "sphere", "box", "torus" };
    enum { N = 1000000 };
    sdfccd_Vec3* p = malloc(N * sizeof *p);
    double sink = 0;
    for (int k = 0; k < 3; ++k) {
        sdfccd_SdfId a, g;
        if (k == 0) check(sdfccd_create_sphere(0.5, &a), "sphere");
        else if (k == 1) check(sdfccd_create_box((sdfccd_Vec3){ 0.5, 0.35, 0.25 }, &a), "box");
        else check(sdfccd_create_torus(0.4, 0.15, &a), "torus");
        sdfccd_GridDef def = sdfccd_default_grid_def();
        def.resolution[0] = def.resolution[1] = def.resolution[2] = 64;
        def.fit_domain = 0;
        def.domain = (sdfccd_Aabb){ { -0.6, -0.6, -0.6 }, { 0.6, 0.6, 0.6 } };
        check(sdfccd_create_grid_from_sdf(a, &def, &g), "grid from SDF");
        for (int i = 0; i < N; ++i) p[i] = (sdfccd_Vec3){ uniform(-0.6, 0.6), uniform(-0.6, 0.6), uniform(-0.6, 0.6) };
        const double ga = time_abi(g, p, N, &sink), aa = time_abi(a, p, N, &sink);
        const double gc = time_batch(g, p, N, &sink), ac = time_batch(a, p, N, &sink);
        /* coherent access, as a sweeping triangle queries: a random walk with steps of a quarter cell */
        sdfccd_Vec3* w = malloc(N * sizeof *w);
        w[0] = p[0];
        const double step = 0.25 * 1.2 / 64;
        for (int i = 1; i < N; ++i) {
            sdfccd_Vec3 q = { w[i - 1].x + uniform(-step, step), w[i - 1].y + uniform(-step, step), w[i - 1].z + uniform(-step, step) };
            if (fabs(q.x) > 0.6 || fabs(q.y) > 0.6 || fabs(q.z) > 0.6) q = p[i];
            w[i] = q;
        }
        const double gw = time_batch(g, w, N, &sink), aw = time_batch(a, w, N, &sink);
        free(w);
        double max_e = 0;
        for (int i = 0; i < N; i += 10) {
            double va, vg;
            sdfccd_sdf_eval(a, p[i], &va, NULL);
            sdfccd_sdf_eval(g, p[i], &vg, NULL);
            max_e = fmax(max_e, fabs(va - vg));
        }
        char shape[64];
        snprintf(shape, sizeof shape, "%s_grid", names[k]);
        row("eval", shape, 64, 1, "ns_per_query_abi", ga);
        row("eval", shape, 64, 1, "ns_per_query_batch", gc);
        row("eval", names[k], 0, 1, "ns_per_query_abi", aa);
        row("eval", names[k], 0, 1, "ns_per_query_batch", ac);
        row("eval", shape, 64, 1, "ratio_grid_over_analytic_batch", gc / ac);
        row("eval", shape, 64, 1, "ns_per_query_batch_coherent", gw);
        row("eval", names[k], 0, 1, "ns_per_query_batch_coherent", aw);
        row("eval", shape, 64, 1, "ratio_grid_over_analytic_batch_coherent", gw / aw);
        row("eval", shape, 64, 1, "max_abs_error_vs_analytic", max_e);
        sdfccd_GridInfo gi;
        sdfccd_grid_get_info(g, &gi);
        row("eval", shape, 64, 1, "memory_bytes", (double)gi.memory_bytes);
        sdfccd_destroy_sdf(g);
        sdfccd_destroy_sdf(a);
    }
    if (sink == 42.0) printf("#\n");
    free(p);
}

static void bench_build(sdfccd_MeshId mesh, int res)
{
    for (int threads = 1; threads <= 2; ++threads) {
        sdfccd_GridDef def = sdfccd_default_grid_def();
        def.resolution[0] = def.resolution[1] = def.resolution[2] = res;
        def.threads = threads;
        sdfccd_SdfId g;
        const double t0 = now();
        check(sdfccd_create_grid_from_mesh(mesh, &def, &g), "build");
        const double s = now() - t0;
        row("build", "armadillo", res, threads, "seconds", s);
        if (threads == 1) {
            sdfccd_GridInfo gi;
            sdfccd_grid_get_info(g, &gi);
            row("build", "armadillo", res, threads, "nodes", (double)gi.node_count);
            row("build", "armadillo", res, threads, "memory_bytes", (double)gi.memory_bytes);
            row("build", "armadillo", res, threads, "file_bytes", (double)gi.file_bytes);
        }
        sdfccd_destroy_sdf(g);
    }
    /* the same with a narrow band of 2 % of the box diagonal (memory and time saved) */
    for (int threads = 1; threads <= 2; ++threads) {
        sdfccd_GridDef def = sdfccd_default_grid_def();
        def.resolution[0] = def.resolution[1] = def.resolution[2] = res;
        def.threads = threads;
        def.band = 0.02 * 1.51685; /* the armadillo's fitted domain diagonal is 1.51685 m */
        sdfccd_SdfId g;
        const double t0 = now();
        check(sdfccd_create_grid_from_mesh(mesh, &def, &g), "band build");
        const double s = now() - t0;
        row("build_band", "armadillo", res, threads, "seconds", s);
        if (threads == 1) {
            sdfccd_GridInfo gi;
            sdfccd_grid_get_info(g, &gi);
            row("build_band", "armadillo", res, threads, "band_m", def.band);
            row("build_band", "armadillo", res, threads, "stored_cells", (double)gi.stored_cells);
            row("build_band", "armadillo", res, threads, "nodes", (double)gi.node_count);
            row("build_band", "armadillo", res, threads, "memory_bytes", (double)gi.memory_bytes);
            row("build_band", "armadillo", res, threads, "file_bytes", (double)gi.file_bytes);
        }
        sdfccd_destroy_sdf(g);
    }
}

static void bench_accuracy(sdfccd_MeshId mesh, int max_res)
{
    enum { N = 20000 };
    sdfccd_MeshInfo mi;
    sdfccd_mesh_get_info(mesh, &mi);
    sdfccd_Vec3* p = malloc(2 * N * sizeof *p);
    double* exact = malloc(2 * N * sizeof *exact);
    /* fitted domain of the mesh (what the builds below use) */
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 1;
    sdfccd_SdfId probe;
    check(sdfccd_create_grid_from_mesh(mesh, &def, &probe), "probe");
    sdfccd_GridInfo gi;
    sdfccd_grid_get_info(probe, &gi);
    sdfccd_destroy_sdf(probe);
    const sdfccd_Aabb d = gi.domain;
    const double diag = sqrt(pow(d.hi.x - d.lo.x, 2) + pow(d.hi.y - d.lo.y, 2) + pow(d.hi.z - d.lo.z, 2));
    /* N uniform points, then N points within 1 % of the diagonal of the surface (rejection) */
    for (int i = 0; i < N; ++i) p[i] = (sdfccd_Vec3){ uniform(d.lo.x, d.hi.x), uniform(d.lo.y, d.hi.y), uniform(d.lo.z, d.hi.z) };
    check(sdfccd_mesh_signed_distance(mesh, p, N, 0, exact, NULL), "exact");
    int nn = 0;
    enum { B = 65536 };
    sdfccd_Vec3* cand = malloc(B * sizeof *cand);
    double* ce = malloc(B * sizeof *ce);
    for (int round = 0; nn < N && round < 64; ++round) {
        for (int i = 0; i < B; ++i) cand[i] = (sdfccd_Vec3){ uniform(d.lo.x, d.hi.x), uniform(d.lo.y, d.hi.y), uniform(d.lo.z, d.hi.z) };
        check(sdfccd_mesh_signed_distance(mesh, cand, B, 0, ce, NULL), "exact");
        for (int i = 0; i < B && nn < N; ++i)
            if (fabs(ce[i]) < 0.01 * diag) { p[N + nn] = cand[i]; exact[N + nn] = ce[i]; ++nn; }
    }
    free(cand);
    free(ce);
    const int n_near = nn;
    row("accuracy", "armadillo", 0, 0, "domain_diagonal_m", diag);
    for (int res = 16; res <= max_res; res *= 2) {
        def.resolution[0] = def.resolution[1] = def.resolution[2] = res;
        def.threads = 0;
        sdfccd_SdfId g;
        const double t0 = now();
        check(sdfccd_create_grid_from_mesh(mesh, &def, &g), "build");
        const double secs = now() - t0;
        double max_all = 0, sum_all = 0, max_near = 0, sum_near = 0;
        for (int i = 0; i < N + n_near; ++i) {
            double v;
            sdfccd_sdf_eval(g, p[i], &v, NULL);
            const double e = fabs(v - exact[i]);
            if (i < N) { max_all = fmax(max_all, e); sum_all += e * e; }
            else { max_near = fmax(max_near, e); sum_near += e * e; }
        }
        sdfccd_grid_get_info(g, &gi);
        row("accuracy", "armadillo", res, 0, "max_abs_error_m", max_all);
        row("accuracy", "armadillo", res, 0, "rms_error_m", sqrt(sum_all / N));
        row("accuracy", "armadillo", res, 0, "max_abs_error_near_surface_m", max_near);
        row("accuracy", "armadillo", res, 0, "rms_error_near_surface_m", sqrt(sum_near / (n_near ? n_near : 1)));
        row("accuracy", "armadillo", res, 0, "memory_bytes", (double)gi.memory_bytes);
        row("accuracy", "armadillo", res, 0, "build_seconds_all_cores", secs);
        sdfccd_destroy_sdf(g);
    }
    free(p);
    free(exact);
}

int main(int argc, char** argv)
{
    const char* data = SDFCCD_DATA_DIR;
    const char* only = NULL;
    int quick = 0;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--data") && i + 1 < argc) data = argv[++i];
        else if (!strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
        else if (!strcmp(argv[i], "--quick")) quick = 1;
        else { fprintf(stderr, "usage: sdfccd_grid_bench [--data DIR] [--quick] [--only eval|build|accuracy]\n"); return 2; }
    }
    printf("benchmark,shape,resolution,threads,metric,value\n");
    if (!only || !strcmp(only, "eval")) bench_eval();
    if (only && !strcmp(only, "eval")) return 0;
    char path[1024];
    snprintf(path, sizeof path, "%s/libigl-tutorial-data/armadillo.obj", data);
    sdfccd_MeshId mesh;
    const double t0 = now();
    check(sdfccd_load_mesh(path, NULL, &mesh), "loading the armadillo");
    sdfccd_MeshInfo mi;
    sdfccd_mesh_get_info(mesh, &mi);
    row("load", "armadillo", 0, 1, "seconds", now() - t0);
    row("load", "armadillo", 0, 1, "triangles", mi.triangle_count);
    if (!only || !strcmp(only, "build")) bench_build(mesh, quick ? 32 : 64);
    if (!only || !strcmp(only, "accuracy")) bench_accuracy(mesh, quick ? 64 : 128);
    sdfccd_destroy_mesh(mesh);
    return 0;
}
