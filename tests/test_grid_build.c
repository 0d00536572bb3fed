/* SPDX-License-Identifier: MIT
 * Grid SDFs, part 2: building from analytic SDFs and meshes (accuracy and convergence against
 * closed forms, thread-count independence, progress), the narrow band (memory, conservative
 * culled values against the exact mesh distance), values outside the domain (lower bounds),
 * the per-cell gradient bounds against sampled gradients, the grid inside CCD queries, mesh
 * import of several formats, and argument errors. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"
#include "test_internal.h"

#ifndef SDFCCD_TEST_TMP_DIR
#define SDFCCD_TEST_TMP_DIR "."
#endif

static sdfccd_SdfId sphere_grid(double radius, int res, int threads, double band)
{
    sdfccd_SdfId s, g;
    ck_assert_int_eq(sdfccd_create_sphere(radius, &s), SDFCCD_OK);
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = res;
    def.fit_domain = 0;
    def.domain = (sdfccd_Aabb){ { -1.5 * radius, -1.5 * radius, -1.5 * radius }, { 1.5 * radius, 1.5 * radius, 1.5 * radius } };
    def.threads = threads;
    def.band = band;
    ck_assert_msg(sdfccd_create_grid_from_sdf(s, &def, &g) == SDFCCD_OK, "%s", sdfccd_last_error());
    ck_assert_int_eq(sdfccd_destroy_sdf(s), SDFCCD_OK);
    return g;
}

static double max_sphere_error(sdfccd_SdfId g, double r, double* out_grad_err)
{
    test_rng rng = { 21 };
    double e = 0, ge = 0;
    for (int i = 0; i < 4000; ++i) {
        sdfccd_Vec3 p = { test_rng_uniform(&rng, -1.2 * r, 1.2 * r), test_rng_uniform(&rng, -1.2 * r, 1.2 * r), test_rng_uniform(&rng, -1.2 * r, 1.2 * r) };
        double v;
        sdfccd_Vec3 gr;
        ck_assert_int_eq(sdfccd_sdf_eval(g, p, &v, &gr), SDFCCD_OK);
        double l = sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
        if (l < 0.3 * r) continue; /* the cone point at the centre is not smooth */
        e = fmax(e, fabs(v - (l - r)));
        ge = fmax(ge, fabs(gr.x - p.x / l) + fabs(gr.y - p.y / l) + fabs(gr.z - p.z / l));
    }
    if (out_grad_err) *out_grad_err = ge;
    return e;
}

/* A sphere sampled on grids of 8^3, 16^3 and 32^3 cells: errors against the closed form drop at
 * least 8-fold per halving of h (the cubic element converges like h^4 on smooth fields). */
START_TEST(test_sphere_convergence)
{
    double prev = INFINITY;
    for (int res = 8; res <= 32; res *= 2) {
        sdfccd_SdfId g = sphere_grid(0.5, res, 0, 0.0);
        double ge;
        double e = max_sphere_error(g, 0.5, &ge);
        fprintf(stderr, "sphere r=0.5 on %d^3: max |phi error| %.3g, max gradient error %.3g\n", res, e, ge);
        ck_assert(e < prev / 8.0);
        /* Measured max |phi error| 0.0128, 0.000245, 2.78e-5 and gradient error 0.275, 0.0176, 0.00326 at 8, 16, 32. */
        if (res == 32) { ck_assert(e < 5e-5); ck_assert(ge < 5e-3); }
        prev = e;
        ck_assert_int_eq(sdfccd_destroy_sdf(g), SDFCCD_OK);
    }
}
END_TEST

typedef struct progress_log { int calls; double last; int monotone; } progress_log;
static int32_t on_progress(double f, void* user)
{
    progress_log* p = user;
    if (f < p->last) p->monotone = 0;
    p->last = f;
    p->calls++;
    return 0;
}

/* Cancels at the first report after `cancel_after` calls. */
typedef struct cancel_log { int calls, cancel_after; double last; } cancel_log;
static int32_t cancel_progress(double f, void* user)
{
    cancel_log* c = user;
    c->last = f;
    return ++c->calls > c->cancel_after;
}

/* 1 and 2 threads give bit-identical grids; progress rises to 1. */
START_TEST(test_threads_identical_and_progress)
{
    sdfccd_MeshId mesh = test_load_mesh("bullet3/torus_textured.obj");
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = 12; def.resolution[1] = 20; def.resolution[2] = 9;
    sdfccd_SdfId a, b;
    def.threads = 1;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &a), SDFCCD_OK);
    progress_log log = { 0, -1.0, 1 };
    def.threads = 2;
    def.progress = on_progress;
    def.progress_user = &log;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &b), SDFCCD_OK);
    scc_grid *ga, *gb;
    ga = test_grid_of(a);
    gb = test_grid_of(b);
    ck_assert_uint_eq(ga->fields[0].node_count, gb->fields[0].node_count);
    for (uint64_t l = 0; l < ga->fields[0].node_count; ++l) ck_assert(scc_grid_node_value(ga, 0, l) == scc_grid_node_value(gb, 0, l));
    ck_assert_int_eq(memcmp(ga->cell_lipschitz, gb->cell_lipschitz, ga->fields[0].cell_count * 4), 0);
    ck_assert_int_gt(log.calls, 2);
    ck_assert_int_eq(log.monotone, 1);
    ck_assert_double_eq(log.last, 1.0);
    sdfccd_GridInfo info;
    ck_assert_int_eq(sdfccd_grid_get_info(b, &info), SDFCCD_OK);
    ck_assert_int_eq(info.resolution[1], 20);
    ck_assert_int_eq(info.cell_count, 12 * 20 * 9);
    ck_assert_int_eq(sdfccd_destroy_sdf(a), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(b), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}
END_TEST

/* A progress callback that returns nonzero cancels the build: SDFCCD_CANCELLED, no handle, every
 * byte freed (the memory fixture), on 1 and 2 threads, in the mesh and the SDF builders, dense and
 * narrow band; the callback is not called again after it cancelled. */
START_TEST(test_progress_cancels)
{
    sdfccd_MeshId mesh = test_load_mesh("bullet3/cube.obj");
    sdfccd_SdfId sphere;
    ck_assert_int_eq(sdfccd_create_sphere(0.5, &sphere), SDFCCD_OK);
    for (int threads = 1; threads <= 2; ++threads)
        for (int band = 0; band <= 1; ++band)
            for (int after = 0; after <= 3; after += 3) {
                sdfccd_GridDef def = sdfccd_default_grid_def();
                def.resolution[0] = def.resolution[1] = def.resolution[2] = 24;
                def.threads = threads;
                def.band = band ? 0.05 : 0.0;
                cancel_log c = { 0, after, -1.0 };
                def.progress = cancel_progress;
                def.progress_user = &c;
                sdfccd_SdfId g = { 0, 0 };
                ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_CANCELLED);
                ck_assert_uint_eq(g.index1, 0);
                ck_assert_int_eq(c.calls, after + 1);
                ck_assert(c.last < 1.0);
                ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "cancelled"));
                c.calls = 0;
                def.fit_domain = 0;
                def.domain = (sdfccd_Aabb){ { -1, -1, -1 }, { 1, 1, 1 } };
                ck_assert_int_eq(sdfccd_create_grid_from_sdf(sphere, &def, &g), SDFCCD_CANCELLED);
                ck_assert_int_eq(c.calls, after + 1);
            }
    ck_assert_str_eq(sdfccd_status_string(SDFCCD_CANCELLED), "SDFCCD_CANCELLED");
    sdfccd_destroy_sdf(sphere);
    sdfccd_destroy_mesh(mesh);
}
END_TEST

/* Narrow band on the bunny: fewer cells and bytes than dense; kept cells equal the dense grid;
 * in culled cells band <= |value| <= |exact distance| with the exact sign, unit gradient. The
 * band grid saves and reloads (sparse file), and the reloaded grid keeps the sign and the lower
 * bound (its band is unknown, so only |value| <= |exact| is required). */
START_TEST(test_narrow_band)
{
    sdfccd_MeshId mesh = test_load_mesh("bullet3/bunny.obj");
    sdfccd_MeshInfo mi;
    ck_assert_int_eq(sdfccd_mesh_get_info(mesh, &mi), SDFCCD_OK);
    /* a domain with room around the bunny, as a scene would use */
    const scc_vec3 ext = scc_sub(sdfccd__v(mi.bounds.hi), sdfccd__v(mi.bounds.lo));
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 40;
    def.fit_domain = 0;
    def.domain.lo = sdfccd__pv(scc_sub(sdfccd__v(mi.bounds.lo), scc_scale(ext, 0.3)));
    def.domain.hi = sdfccd__pv(scc_add(sdfccd__v(mi.bounds.hi), scc_scale(ext, 0.3)));
    sdfccd_SdfId dense, band;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &dense), SDFCCD_OK);
    sdfccd_GridInfo di, bi;
    ck_assert_int_eq(sdfccd_grid_get_info(dense, &di), SDFCCD_OK);
    const double w = di.cell_size.x;
    def.band = w;
    progress_log log = { 0, -1.0, 1 };
    def.progress = on_progress;
    def.progress_user = &log;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &band), SDFCCD_OK);
    ck_assert_int_eq(log.monotone, 1);
    ck_assert_double_eq(log.last, 1.0);
    ck_assert_int_eq(sdfccd_grid_get_info(band, &bi), SDFCCD_OK);
    fprintf(stderr, "bunny 40^3: dense %lld cells %lld nodes %lld bytes; band %.3g m: %lld cells %lld nodes %lld bytes\n",
            (long long)di.stored_cells, (long long)di.node_count, (long long)di.memory_bytes, w, (long long)bi.stored_cells,
            (long long)bi.node_count, (long long)bi.memory_bytes);
    ck_assert_int_lt(bi.stored_cells, di.stored_cells / 3);
    ck_assert_int_lt(bi.memory_bytes, di.memory_bytes / 2);
    ck_assert_double_eq(bi.band, w);

    char path[512];
    snprintf(path, sizeof path, "%s/grid_band.cdf", SDFCCD_TEST_TMP_DIR);
    ck_assert_int_eq(sdfccd_save_grid(band, path), SDFCCD_OK);
    sdfccd_SdfId reloaded;
    ck_assert_int_eq(sdfccd_load_grid(path, &reloaded), SDFCCD_OK);
    remove(path);

    enum { N = 3000 };
    sdfccd_Vec3* p = malloc(N * sizeof *p);
    double* exact = malloc(N * sizeof *exact);
    test_rng rng = { 31 };
    for (int i = 0; i < N; ++i)
        p[i] = (sdfccd_Vec3){ test_rng_uniform(&rng, di.domain.lo.x, di.domain.hi.x), test_rng_uniform(&rng, di.domain.lo.y, di.domain.hi.y),
                              test_rng_uniform(&rng, di.domain.lo.z, di.domain.hi.z) };
    ck_assert_int_eq(sdfccd_mesh_signed_distance(mesh, p, N, 0, exact, NULL), SDFCCD_OK);
    int culled = 0;
    for (int i = 0; i < N; ++i) {
        double vb, vd, vr, raw;
        sdfccd_Vec3 gb, gr;
        int32_t has;
        ck_assert_int_eq(sdfccd_sdf_eval(band, p[i], &vb, &gb), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_sdf_eval(dense, p[i], &vd, NULL), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_sdf_eval(reloaded, p[i], &vr, &gr), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_grid_interpolate(band, 0, p[i], &raw, NULL, &has), SDFCCD_OK);
        if (has) {
            ck_assert_double_eq(vb, vd);
            ck_assert_double_eq(vr, vd);
            continue;
        }
        ++culled;
        ck_assert_msg((vb < 0) == (exact[i] < 0), "culled sign %g vs exact %g", vb, exact[i]);
        ck_assert(fabs(vb) >= w - 1e-12);
        ck_assert_msg(fabs(vb) <= fabs(exact[i]) + 1e-12, "culled |%g| above exact %g", vb, exact[i]);
        ck_assert_double_near(gb.x * gb.x + gb.y * gb.y + gb.z * gb.z, 1.0, 1e-9);
        ck_assert((vr < 0) == (exact[i] < 0));
        ck_assert(fabs(vr) <= fabs(exact[i]) + 1e-12);
        ck_assert(fabs(vr) > 0.0);
    }
    ck_assert_int_gt(culled, N / 3);
    free(p);
    free(exact);
    ck_assert_int_eq(sdfccd_destroy_sdf(reloaded), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(band), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(dense), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}
END_TEST

/* Outside the domain the value is a lower bound on the exact distance (up to the grid's own
 * error at the boundary), at least the distance to the box, with a finite non-zero gradient;
 * it is continuous across the boundary. */
START_TEST(test_outside_domain)
{
    sdfccd_MeshId mesh = test_load_mesh("bullet3/bunny.obj");
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 24;
    sdfccd_SdfId g;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_OK);
    sdfccd_GridInfo info;
    ck_assert_int_eq(sdfccd_grid_get_info(g, &info), SDFCCD_OK);
    const scc_aabb dom = sdfccd__box(info.domain);
    const scc_vec3 c = scc_scale(scc_add(dom.lo, dom.hi), 0.5), e = scc_sub(dom.hi, dom.lo);
    enum { N = 3000 };
    sdfccd_Vec3* p = malloc(N * sizeof *p);
    double* exact = malloc(N * sizeof *exact);
    test_rng rng = { 41 };
    int n = 0;
    while (n < N) {
        scc_vec3 q = scc_v3(c.x + e.x * test_rng_uniform(&rng, -1.5, 1.5), c.y + e.y * test_rng_uniform(&rng, -1.5, 1.5), c.z + e.z * test_rng_uniform(&rng, -1.5, 1.5));
        if (scc_aabb_distance(&dom, q) > 0) p[n++] = sdfccd__pv(q);
    }
    ck_assert_int_eq(sdfccd_mesh_signed_distance(mesh, p, N, 0, exact, NULL), SDFCCD_OK);
    for (int i = 0; i < N; ++i) {
        double v;
        sdfccd_Vec3 gr;
        ck_assert_int_eq(sdfccd_sdf_eval(g, p[i], &v, &gr), SDFCCD_OK);
        const double d = scc_aabb_distance(&dom, sdfccd__v(p[i]));
        ck_assert(v >= d - 1e-12);
        ck_assert_msg(v <= exact[i] + 1e-3, "outside value %g above exact %g", v, exact[i]); /* 1e-3: grid error at 24^3 */
        const double gl = sqrt(gr.x * gr.x + gr.y * gr.y + gr.z * gr.z);
        ck_assert(isfinite(gl) && gl > 0.1 && gl <= 1.5);
    }
    /* the surface is inside the fitted domain: bounds are the domain */
    sdfccd_SdfInfo si;
    ck_assert_int_eq(sdfccd_sdf_get_info(g, &si), SDFCCD_OK);
    ck_assert_double_eq(si.bounds.lo.x, dom.lo.x);
    ck_assert_double_eq(si.bounds.hi.z, dom.hi.z);
    /* very far points: finite values and gradients */
    {
        double v;
        sdfccd_Vec3 gr;
        ck_assert_int_eq(sdfccd_sdf_eval(g, (sdfccd_Vec3){ 1e200, -3e200, 2e200 }, &v, &gr), SDFCCD_OK);
        ck_assert(isfinite(v) && v >= 2.9e200 && isfinite(gr.x) && isfinite(gr.y) && isfinite(gr.z));
        ck_assert_double_eq(gr.y, -1.0);
    }
    /* continuity across the max-x face */
    for (int i = 0; i < 200; ++i) {
        sdfccd_Vec3 q = { dom.hi.x, test_rng_uniform(&rng, dom.lo.y, dom.hi.y), test_rng_uniform(&rng, dom.lo.z, dom.hi.z) };
        double v0, v1;
        ck_assert_int_eq(sdfccd_sdf_eval(g, q, &v0, NULL), SDFCCD_OK);
        q.x += 1e-9;
        ck_assert_int_eq(sdfccd_sdf_eval(g, q, &v1, NULL), SDFCCD_OK);
        ck_assert_double_near(v0, v1, 1e-8);
    }
    free(p);
    free(exact);
    ck_assert_int_eq(sdfccd_destroy_sdf(g), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}
END_TEST

/* Per-cell bounds: in every cell of a coarse torus grid, |grad phi| sampled on a 6^3 lattice
 * stays below the cell's bound, and the bound of a box covers finite differences of points
 * inside it. */
START_TEST(test_lipschitz_bounds)
{
    sdfccd_MeshId mesh = test_load_mesh("bullet3/torus_textured.obj");
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 10;
    sdfccd_SdfId id;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &id), SDFCCD_OK);
    scc_grid* g;
    g = test_grid_of(id);
    double worst_ratio = 0, sum_ratio = 0;
    for (uint64_t l = 0; l < g->n_cells; ++l) {
        const uint32_t i = (uint32_t)(l % 10), j = (uint32_t)(l / 10 % 10), k = (uint32_t)(l / 100);
        const scc_vec3 lo = scc_v3(g->lo.x + i * g->h.x, g->lo.y + j * g->h.y, g->lo.z + k * g->h.z);
        double mx = 0;
        for (int a = 0; a < 6; ++a)
            for (int b = 0; b < 6; ++b)
                for (int c = 0; c < 6; ++c) {
                    scc_vec3 p = scc_v3(lo.x + g->h.x * (0.01 + 0.98 * a / 5.0), lo.y + g->h.y * (0.01 + 0.98 * b / 5.0), lo.z + g->h.z * (0.01 + 0.98 * c / 5.0));
                    scc_vec3 gr;
                    scc_grid_eval(&g->base, p, &gr);
                    mx = fmax(mx, scc_len(gr));
                }
        const double bound = g->cell_lipschitz[g->fields[0].map[l]];
        ck_assert_msg(mx <= bound, "cell %llu: sampled |grad| %g above bound %g", (unsigned long long)l, mx, bound);
        worst_ratio = fmax(worst_ratio, bound / mx);
        sum_ratio += bound / mx;
    }
    fprintf(stderr, "torus 10^3 per-cell gradient bounds: mean bound/sampled max %.3f, worst %.3f, global %.3f\n",
            sum_ratio / (double)g->n_cells, worst_ratio, g->lipschitz_max);
    test_rng rng = { 51 };
    for (int it = 0; it < 300; ++it) {
        scc_vec3 c = scc_v3(test_rng_uniform(&rng, g->lo.x, g->hi.x), test_rng_uniform(&rng, g->lo.y, g->hi.y), test_rng_uniform(&rng, g->lo.z, g->hi.z));
        const double r = test_rng_uniform(&rng, 0.01, it % 3 ? 0.3 : 0.8); /* some boxes use the block maxima */
        sdfccd_Aabb box = { sdfccd__pv(scc_sub(c, scc_v3(r, r, r))), sdfccd__pv(scc_add(c, scc_v3(r, r, r))) };
        double L;
        ck_assert_int_eq(sdfccd_grid_lipschitz_bound(id, box, &L), SDFCCD_OK);
        for (int s = 0; s < 20; ++s) {
            scc_vec3 x = scc_v3(test_rng_uniform(&rng, box.lo.x, box.hi.x), test_rng_uniform(&rng, box.lo.y, box.hi.y), test_rng_uniform(&rng, box.lo.z, box.hi.z));
            scc_vec3 y = scc_v3(test_rng_uniform(&rng, box.lo.x, box.hi.x), test_rng_uniform(&rng, box.lo.y, box.hi.y), test_rng_uniform(&rng, box.lo.z, box.hi.z));
            const double fx = scc_grid_eval(&g->base, x, NULL), fy = scc_grid_eval(&g->base, y, NULL);
            ck_assert(fabs(fx - fy) <= L * scc_dist(x, y) + 1e-12);
        }
    }
    ck_assert_int_eq(sdfccd_destroy_sdf(id), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}
END_TEST

/* The grid runs through the CCD queries unchanged: a triangle falling onto a sphere grid gets
 * the same TOI as on the analytic sphere, within the grid error over the speed. */
START_TEST(test_ccd_on_grid)
{
    sdfccd_SdfId sphere, grid = sphere_grid(0.5, 32, 0, 0.0);
    ck_assert_int_eq(sdfccd_create_sphere(0.5, &sphere), SDFCCD_OK);
    sdfccd_Vec3 tri[3] = { { -0.1, -0.1, 0.7 }, { 0.1, -0.1, 0.7 }, { 0.0, 0.12, 0.7 } };
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.linear_velocity = (sdfccd_Vec3){ 0.0, 0.0, -12.0 };
    const sdfccd_Method methods[] = { SDFCCD_METHOD_FWGSS, SDFCCD_METHOD_FW, SDFCCD_METHOD_DCD, SDFCCD_METHOD_CERTIFIED };
    const double toi = (0.7 - 0.5) / 12.0; /* the lowest point (0, -0.1, 0.7) is at |p| = 0.707: first contact near t = 0.0167 */
    for (size_t k = 0; k < sizeof methods / sizeof methods[0]; ++k) {
        sdfccd_QueryParams qp = sdfccd_default_query_params();
        qp.method = methods[k];
        qp.certified_max_regions = 200000;
        sdfccd_QueryResult ra, rg;
        sdfccd_Contact ca[4], cg[4];
        ck_assert_int_eq(sdfccd_query_triangle(sphere, NULL, tri, &m, 0.0, 1.0 / 30.0, &qp, ca, 4, &ra), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_query_triangle(grid, NULL, tri, &m, 0.0, 1.0 / 30.0, &qp, cg, 4, &rg), SDFCCD_OK);
        ck_assert_msg(ra.hit && rg.hit, "method %d: analytic hit %d, grid hit %d", methods[k], ra.hit, rg.hit);
        if (methods[k] == SDFCCD_METHOD_CERTIFIED) {
            /* the certified lower end of the bracket: no contact before it on either field */
            /* sound on both fields; as tight on the grid as on the sphere when the sphere's is tight */
            ck_assert_msg(rg.toi_lower <= toi + 1e-7, "certified lower %.9g above the TOI", rg.toi_lower);
            if (ra.toi_lower > toi - 1e-4)
                ck_assert_msg(rg.toi_lower > toi - 1e-4, "certified lower %.9g (analytic %.9g)", rg.toi_lower, ra.toi_lower);
        } else {
            ck_assert_msg(fabs(ra.toi - rg.toi) < 1e-5 / 12.0 + 2e-6, "method %d: toi %.9g vs %.9g", methods[k], ra.toi, rg.toi);
        }
        if (methods[k] == SDFCCD_METHOD_FWGSS) ck_assert_double_near(rg.toi, toi, 1e-5);
    }
    /* the mesh query: a small cube falling onto the sphere grid and the analytic sphere */
    sdfccd_MeshId cube = test_load_mesh("bullet3/cube.obj");
    sdfccd_RigidMotion cm = sdfccd_default_rigid_motion();
    cm.pose.position = (sdfccd_Vec3){ 0.05, -0.03, 0.5 + 0.5 * 0.2 + 0.1 };
    cm.linear_velocity = (sdfccd_Vec3){ 0.0, 0.0, -9.0 };
    sdfccd_MeshLoadDef ld = sdfccd_default_mesh_load_def();
    ld.scale = 0.2;
    sdfccd_MeshId small;
    ck_assert_int_eq(sdfccd_load_mesh(SDFCCD_DATA_DIR "/bullet3/cube.obj", &ld, &small), SDFCCD_OK);
    sdfccd_QueryParams qp = sdfccd_default_query_params();
    sdfccd_QueryResult ra, rg;
    sdfccd_Contact ca[16], cg[16];
    ck_assert_int_eq(sdfccd_query_mesh(sphere, NULL, small, &cm, 0.0, 1.0 / 30.0, &qp, ca, 16, &ra), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_query_mesh(grid, NULL, small, &cm, 0.0, 1.0 / 30.0, &qp, cg, 16, &rg), SDFCCD_OK);
    ck_assert(ra.hit && rg.hit);
    ck_assert_msg(fabs(ra.toi - rg.toi) < 1e-5, "mesh query toi %.9g vs %.9g", ra.toi, rg.toi);
    ck_assert_double_near(cg[0].normal.z, ca[0].normal.z, 1e-3);
    ck_assert_int_eq(sdfccd_destroy_mesh(small), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(cube), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(sphere), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(grid), SDFCCD_OK);
}
END_TEST

/* ---------------- mesh import ---------------- */

static void write_text(const char* path, const char* text)
{
    FILE* f = fopen(path, "wb");
    ck_assert(f != NULL);
    fputs(text, f);
    fclose(f);
}

static void expect_mesh(const char* path, uint32_t tris, int closed)
{
    sdfccd_MeshId m;
    sdfccd_Status st = sdfccd_load_mesh(path, NULL, &m);
    ck_assert_msg(st == SDFCCD_OK, "%s: %s", path, sdfccd_last_error());
    sdfccd_MeshInfo info;
    ck_assert_int_eq(sdfccd_mesh_get_info(m, &info), SDFCCD_OK);
    ck_assert_uint_eq(info.triangle_count, tris);
    sdfccd_MeshTopology t;
    ck_assert_int_eq(sdfccd_mesh_get_topology(m, &t), SDFCCD_OK);
    ck_assert_int_eq(t.closed, closed);
    if (closed) ck_assert_double_near(t.volume, 1.0, 1e-6);
    ck_assert_int_eq(sdfccd_destroy_mesh(m), SDFCCD_OK);
}

START_TEST(test_mesh_import_formats)
{
    char path[512];
    /* unit cube as quads in OBJ (with texture/normal indices and a negative index), OFF, ASCII STL and PLY */
    snprintf(path, sizeof path, "%s/grid_cube_quads.obj", SDFCCD_TEST_TMP_DIR);
    write_text(path, "# unit cube, quads\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nvt 0 0\nvn 0 0 1\n"
                     "f 1/1/1 4/1/1 3/1/1 2/1/1\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf -8 -4 -1 -5\n");
    expect_mesh(path, 12, 1);
    remove(path);
    snprintf(path, sizeof path, "%s/grid_cube.off", SDFCCD_TEST_TMP_DIR);
    write_text(path, "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
    expect_mesh(path, 12, 1);
    remove(path);
    snprintf(path, sizeof path, "%s/grid_cube.stl", SDFCCD_TEST_TMP_DIR);
    {
        const int q[6][4] = { { 0, 3, 2, 1 }, { 4, 5, 6, 7 }, { 0, 1, 5, 4 }, { 1, 2, 6, 5 }, { 2, 3, 7, 6 }, { 3, 0, 4, 7 } };
        const int vv[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } };
        FILE* f = fopen(path, "wb");
        fprintf(f, "solid cube\n");
        for (int i = 0; i < 6; ++i)
            for (int t = 0; t < 2; ++t) {
                const int idx[3] = { q[i][0], q[i][1 + t], q[i][2 + t] };
                fprintf(f, " facet normal 0 0 0\n  outer loop\n");
                for (int k = 0; k < 3; ++k) fprintf(f, "   vertex %d %d %d\n", vv[idx[k]][0], vv[idx[k]][1], vv[idx[k]][2]);
                fprintf(f, "  endloop\n endfacet\n");
            }
        fprintf(f, "endsolid cube\n");
        fclose(f);
    }
    expect_mesh(path, 12, 1); /* STL stores every triangle's corners: merging makes it closed */
    remove(path);
    snprintf(path, sizeof path, "%s/grid_cube.ply", SDFCCD_TEST_TMP_DIR);
    write_text(path, "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nelement face 6\n"
                     "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                     "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
    expect_mesh(path, 12, 1);
    remove(path);

    /* errors: missing, unreadable, no triangles, bad index */
    sdfccd_MeshId m;
    ck_assert_int_eq(sdfccd_load_mesh(SDFCCD_TEST_TMP_DIR "/no_such_mesh.ply", NULL, &m), SDFCCD_IO_ERROR);
    ck_assert_int_eq(sdfccd_load_mesh(SDFCCD_TEST_TMP_DIR "/no_such_mesh.obj", NULL, &m), SDFCCD_IO_ERROR);
    snprintf(path, sizeof path, "%s/grid_garbage.ply", SDFCCD_TEST_TMP_DIR);
    write_text(path, "this is not a mesh file \x01\x02\x03\n");
    ck_assert_int_eq(sdfccd_load_mesh(path, NULL, &m), SDFCCD_FORMAT_ERROR);
    ck_assert(strlen(sdfccd_last_error()) > 10);
    remove(path);
    snprintf(path, sizeof path, "%s/grid_points.obj", SDFCCD_TEST_TMP_DIR);
    write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    ck_assert_int_eq(sdfccd_load_mesh(path, NULL, &m), SDFCCD_DEGENERATE);
    ck_assert(strstr(sdfccd_last_error(), "no triangles") != NULL);
    write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    ck_assert_int_eq(sdfccd_load_mesh(path, NULL, &m), SDFCCD_FORMAT_ERROR);
    write_text(path, "v 0 0 0\nv 1 0 x\n");
    ck_assert_int_eq(sdfccd_load_mesh(path, NULL, &m), SDFCCD_FORMAT_ERROR);
    remove(path);
    snprintf(path, sizeof path, "%s/grid_empty.stl", SDFCCD_TEST_TMP_DIR);
    write_text(path, "solid empty\nendsolid empty\n");
    sdfccd_Status st = sdfccd_load_mesh(path, NULL, &m);
    ck_assert_msg(st == SDFCCD_DEGENERATE || st == SDFCCD_FORMAT_ERROR, "empty STL: %s", sdfccd_status_string(st));
    remove(path);
    ck_assert_int_eq(sdfccd_load_mesh(NULL, NULL, &m), SDFCCD_INVALID_ARGUMENT);
    sdfccd_MeshLoadDef ld = sdfccd_default_mesh_load_def();
    ld.scale = 0.0;
    ck_assert_int_eq(sdfccd_load_mesh(SDFCCD_DATA_DIR "/bullet3/cube.obj", &ld, &m), SDFCCD_INVALID_ARGUMENT);
    ld.scale = 2.0;
    ck_assert_int_eq(sdfccd_load_mesh(SDFCCD_DATA_DIR "/bullet3/cube.obj", &ld, &m), SDFCCD_OK);
    sdfccd_MeshInfo info;
    ck_assert_int_eq(sdfccd_mesh_get_info(m, &info), SDFCCD_OK);
    ck_assert_double_eq(info.bounds.hi.x, 1.0);
    ck_assert_int_eq(sdfccd_destroy_mesh(m), SDFCCD_OK);
    /* the textured torus (v/vt/vn faces) welds to its 501 positions and is closed */
    sdfccd_MeshId tor = test_load_mesh("bullet3/torus_textured.obj");
    sdfccd_MeshTopology t;
    ck_assert_int_eq(sdfccd_mesh_get_topology(tor, &t), SDFCCD_OK);
    ck_assert_int_eq(t.closed, 1);
    ck_assert_int_eq(sdfccd_mesh_get_info(tor, &info), SDFCCD_OK);
    ck_assert_uint_eq(info.vertex_count, 501);
    ck_assert_uint_eq(info.triangle_count, 1002);
    ck_assert_int_eq(sdfccd_destroy_mesh(tor), SDFCCD_OK);
}
END_TEST

static double core_sphere_sample(void* user, scc_vec3 p, uint32_t* state, double cap)
{
    (void)user; (void)state; (void)cap;
    return scc_len(p) - 0.5;
}

/* The core builder with an unknown Lipschitz bound (0) and a band: every node is sampled, the
 * band grid matches the dense one in kept cells, and culled cells keep their side. */
START_TEST(test_core_band_unknown_lipschitz)
{
    scc_grid_build_def d;
    memset(&d, 0, sizeof d);
    d.lo = scc_v3(-1, -1, -1);
    d.hi = scc_v3(1, 1, 1);
    d.res[0] = d.res[1] = d.res[2] = 10;
    d.sample = core_sphere_sample;
    scc_grid *dense = NULL, *band = NULL;
    ck_assert_int_eq(scc_grid_build(sdfccd__allocator(), &d, &dense), SCC_GRID_BUILD_OK);
    d.band = 0.1;
    d.sample_lipschitz = 0.0;
    ck_assert_int_eq(scc_grid_build(sdfccd__allocator(), &d, &band), SCC_GRID_BUILD_OK);
    ck_assert_uint_lt(band->fields[0].cell_count, dense->fields[0].cell_count);
    ck_assert_double_eq(band->band, 0.0);
    test_rng rng = { 61 };
    for (int i = 0; i < 2000; ++i) {
        scc_vec3 p = scc_v3(test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1));
        double raw;
        const double vb = scc_grid_eval(&band->base, p, NULL), vd = scc_grid_eval(&dense->base, p, NULL);
        if (scc_grid_interpolate(band, 0, p, &raw, NULL)) ck_assert_double_eq(vb, vd);
        else ck_assert((vb < 0) == (scc_len(p) < 0.5) && fabs(vb) <= fabs(scc_len(p) - 0.5) + 1e-12);
    }
    scc_grid_destroy(dense);
    scc_grid_destroy(band);
}
END_TEST

/* Peak of the library's allocations, through the allocator hooks. */
typedef struct peak_counter { int64_t now, peak; } peak_counter;
static void* peak_alloc(size_t n, void* user)
{
    peak_counter* c = user;
    c->now += (int64_t)n;
    if (c->now > c->peak) c->peak = c->now;
    return malloc(n);
}
static void peak_free(void* p, size_t n, void* user)
{
    peak_counter* c = user;
    c->now -= (int64_t)n;
    free(p);
}

/* Issue 11 ("memory"): a narrow-band build never allocates the dense node array (8 bytes per node
 * of the full grid); it used to sample that array first. The peak of everything the build
 * allocates (mesh distance structure, scratch, the grid and its derived tables) stays below the
 * dense array alone, while the dense build of the same grid does allocate at least that much,
 * and the band grid still equals the dense one in every kept cell. */
START_TEST(test_band_never_dense)
{
    peak_counter c = { 0, 0 };
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    ck_assert_int_eq(sdfccd_set_allocator(peak_alloc, peak_free, &c), SDFCCD_OK);
    /* an analytic sphere at 60 x 64 x 56, dense and band: the dense build is the control */
    sdfccd_SdfId sphere;
    ck_assert_int_eq(sdfccd_create_sphere(0.5, &sphere), SDFCCD_OK);
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = 60;
    def.resolution[1] = 64;
    def.resolution[2] = 56;
    def.padding = 0.05;
    def.threads = 2;
    const uint32_t res[3] = { 60, 64, 56 };
    const int64_t dense_array = 8 * (int64_t)scc_grid_dense_node_count(res);
    sdfccd_SdfId g[2];
    int64_t peak[2];
    for (int band = 0; band < 2; ++band) {
        def.band = band ? 0.004 : 0.0;
        c.peak = c.now;
        const int64_t before = c.now;
        ck_assert_msg(sdfccd_create_grid_from_sdf(sphere, &def, &g[band]) == SDFCCD_OK, "%s", sdfccd_last_error());
        peak[band] = c.peak - before;
    }
    fprintf(stderr, "sphere 60x64x56: dense node array %lld bytes; build peak dense %lld, band %lld\n", (long long)dense_array,
            (long long)peak[0], (long long)peak[1]);
    ck_assert_int_ge(peak[0], dense_array); /* the measurement sees the dense array */
    ck_assert_int_lt(peak[1], dense_array); /* the band build never allocates it */
    sdfccd_GridInfo di, bi;
    ck_assert_int_eq(sdfccd_grid_get_info(g[0], &di), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_grid_get_info(g[1], &bi), SDFCCD_OK);
    ck_assert_int_lt(bi.stored_cells, di.stored_cells / 4);
    test_rng rng = { 77 };
    int compared = 0;
    for (int i = 0; i < 4000; ++i) {
        sdfccd_Vec3 p = { test_rng_uniform(&rng, -0.6, 0.6), test_rng_uniform(&rng, -0.6, 0.6), test_rng_uniform(&rng, -0.6, 0.6) };
        double vd, vb;
        int32_t hd, hb;
        ck_assert_int_eq(sdfccd_grid_interpolate(g[0], 0, p, &vd, NULL, &hd), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_grid_interpolate(g[1], 0, p, &vb, NULL, &hb), SDFCCD_OK);
        if (!hb) continue;
        ck_assert_int_eq(hd, 1);
        ck_assert_double_eq(vb, vd); /* kept cells hold the dense grid's values */
        ++compared;
    }
    ck_assert_int_gt(compared, 10);
    ck_assert_int_eq(sdfccd_destroy_sdf(g[0]), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(g[1]), SDFCCD_OK);

    /* max_bytes on a band build: the builder refuses the allocation that would pass the limit and
     * names the total it needed; with exactly that figure the step passes (the next may need
     * more), and with one byte less the same step fails again. */
    def.band = 0.004;
    def.max_bytes = 12 * 61 * 65 * 57 + 8 * 60 * 64 * 56; /* passes the check made before sampling */
    long long needed = 0;
    sdfccd_Status st = SDFCCD_OK;
    int steps = 0;
    while ((st = sdfccd_create_grid_from_sdf(sphere, &def, &g[1])) == SDFCCD_OUT_OF_MEMORY) {
        ck_assert_int_eq(sscanf(strstr(sdfccd_last_error(), "needs ") + 6, "%lld", &needed), 1);
        ck_assert_int_gt(needed, def.max_bytes);
        def.max_bytes = needed;
        ck_assert_int_lt(++steps, 6);
    }
    ck_assert_int_eq(st, SDFCCD_OK);
    ck_assert_int_ge(steps, 2); /* at least the candidate blocks and the final blocks were refused */
    ck_assert_int_eq(sdfccd_destroy_sdf(g[1]), SDFCCD_OK);
    def.max_bytes = needed - 1;
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(sphere, &def, &g[1]), SDFCCD_OUT_OF_MEMORY);
    ck_assert_ptr_nonnull(strstr(sdfccd_last_error(), "node storage"));
    def.max_bytes = (int64_t)4 << 30;
    ck_assert_int_eq(sdfccd_destroy_sdf(sphere), SDFCCD_OK);

    /* a mesh (the cube) at 128^3, band only: the peak includes the mesh distance structure */
    sdfccd_MeshId mesh = test_load_mesh("bullet3/cube.obj");
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 128;
    const uint32_t res128[3] = { 128, 128, 128 };
    const int64_t dense128 = 8 * (int64_t)scc_grid_dense_node_count(res128);
    def.band = 0.004;
    c.peak = c.now;
    const int64_t before = c.now;
    ck_assert_msg(sdfccd_create_grid_from_mesh(mesh, &def, &g[1]) == SDFCCD_OK, "%s", sdfccd_last_error());
    fprintf(stderr, "cube mesh 128^3: dense node array %lld bytes; band build peak %lld\n", (long long)dense128, (long long)(c.peak - before));
    ck_assert_int_lt(c.peak - before, dense128);
    ck_assert_int_eq(sdfccd_destroy_sdf(g[1]), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_byte_count(), 0);
    ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_OK);
}
END_TEST

typedef struct eval_job { sdfccd_SdfId grid; const sdfccd_Vec3* p; double* out; int n, failed; } eval_job;
static void* eval_thread(void* arg)
{
    eval_job* j = arg;
    for (int i = 0; i < j->n; ++i) {
        sdfccd_Vec3 g;
        if (sdfccd_sdf_eval(j->grid, j->p[i], &j->out[i], &g) != SDFCCD_OK) {
            j->failed++;
            j->out[i] = NAN;
            continue;
        }
        j->out[i] += 1e-3 * (g.x + g.y + g.z);
    }
    return NULL;
}

/* Evaluation is thread-safe: four threads evaluating one band grid at once (holes, outside
 * points and kept cells) give exactly the serial results, and every call returns SDFCCD_OK. */
START_TEST(test_concurrent_eval)
{
    sdfccd_MeshId mesh = test_load_mesh("bullet3/torus_textured.obj");
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 20;
    def.band = 0.05;
    def.padding = 0.2;
    sdfccd_SdfId g;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_OK);
    enum { N = 20000, T = 4 };
    sdfccd_Vec3* p = malloc(N * sizeof *p);
    double* serial = malloc(N * sizeof *serial);
    double* par = malloc(T * N * sizeof *par);
    test_rng rng = { 71 };
    for (int i = 0; i < N; ++i) p[i] = (sdfccd_Vec3){ test_rng_uniform(&rng, -1.2, 1.2), test_rng_uniform(&rng, -0.6, 0.6), test_rng_uniform(&rng, -1.2, 1.2) };
    eval_job js = { g, p, serial, N, 0 };
    eval_thread(&js);
    ck_assert_msg(js.failed == 0, "%d of %d serial evaluations failed", js.failed, N);
    pthread_t th[T];
    eval_job jobs[T];
    for (int t = 0; t < T; ++t) {
        jobs[t] = (eval_job){ g, p, par + (size_t)t * N, N, 0 };
        ck_assert_int_eq(pthread_create(&th[t], NULL, eval_thread, &jobs[t]), 0);
    }
    for (int t = 0; t < T; ++t) pthread_join(th[t], NULL);
    for (int t = 0; t < T; ++t) {
        ck_assert_msg(jobs[t].failed == 0, "thread %d: %d of %d concurrent evaluations failed", t, jobs[t].failed, N);
        ck_assert_int_eq(memcmp(serial, par + (size_t)t * N, N * sizeof(double)), 0);
    }
    free(p);
    free(serial);
    free(par);
    ck_assert_int_eq(sdfccd_destroy_sdf(g), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}
END_TEST

/* Every evaluation path of a grid gives the bits of the reference scc_grid_eval (SSE2 code): the
 * evaluator chosen at finalize (the AVX build where the processor has it), the core batch (cell
 * loads ahead, block reuse) with and without gradients, and the ABI's single and batch calls; on a
 * dense grid (the direct path) and a narrow band, at points inside and outside the domain, random
 * and on a walk of small steps (consecutive points in one cell). */
START_TEST(test_eval_paths_identical)
{
    enum { N = 6000 };
    sdfccd_Vec3* p = malloc(N * sizeof *p);
    scc_vec3* q = malloc(N * sizeof *q);
    double *ref = malloc(N * sizeof *ref), *v = malloc(N * sizeof *v), *w = malloc(N * sizeof *w);
    scc_vec3 *rg = malloc(N * sizeof *rg), *gg = malloc(N * sizeof *gg);
    sdfccd_Vec3* ag = malloc(N * sizeof *ag);
    test_rng rng = { 5 };
    for (int i = 0; i < N; ++i) {
        if (i < N / 2 || i == 0) /* random, a fifth of them outside the domain */
            q[i] = scc_v3(test_rng_uniform(&rng, -0.22, 0.22), test_rng_uniform(&rng, -0.22, 0.22), test_rng_uniform(&rng, -0.22, 0.22));
        else /* a walk of 2 mm steps (cells are 10 mm) */
            q[i] = scc_add(q[i - 1], scc_v3(test_rng_uniform(&rng, -0.002, 0.002), test_rng_uniform(&rng, -0.002, 0.002),
                                            test_rng_uniform(&rng, -0.002, 0.002)));
        p[i] = (sdfccd_Vec3){ q[i].x, q[i].y, q[i].z };
    }
    for (int band = 0; band < 2; ++band) {
        sdfccd_SdfId id = sphere_grid(0.1, 30, 1, band ? 0.02 : 0.0);
        const scc_grid* g = test_grid_of(id);
        ck_assert_int_eq(g->direct, !band);
        ck_assert(g->base.eval == (SCC_GRID_AVX && scc_grid_avx() ? scc_grid_eval_avx : scc_grid_eval));
        for (int i = 0; i < N; ++i) ref[i] = scc_grid_eval(&g->base, q[i], &rg[i]);
        for (int i = 0; i < N; ++i) v[i] = g->base.eval(&g->base, q[i], &gg[i]);
        ck_assert_msg(memcmp(v, ref, N * sizeof *v) == 0 && memcmp(gg, rg, N * sizeof *gg) == 0, "finalize's evaluator (band %d)", band);
        for (size_t n = 1; n <= N; n = n * 7 + 3) { /* batch lengths 1, 10, 73, 514, 3601 */
            scc_grid_eval_batch(g, q, n, v, gg);
            scc_grid_eval_batch(g, q, n, w, NULL);
            ck_assert_msg(memcmp(v, ref, n * sizeof *v) == 0 && memcmp(gg, rg, n * sizeof *gg) == 0 && memcmp(w, ref, n * sizeof *w) == 0,
                          "core batch of %zu (band %d)", n, band);
        }
        ck_assert_int_eq(sdfccd_sdf_eval_batch(id, p, N, v, ag), SDFCCD_OK);
        for (int i = 0; i < N; ++i) gg[i] = scc_v3(ag[i].x, ag[i].y, ag[i].z);
        ck_assert_msg(memcmp(v, ref, N * sizeof *v) == 0 && memcmp(gg, rg, N * sizeof *gg) == 0, "sdfccd_sdf_eval_batch (band %d)", band);
        for (int i = 0; i < N; ++i) ck_assert_int_eq(sdfccd_sdf_eval(id, p[i], &w[i], &ag[i]), SDFCCD_OK);
        for (int i = 0; i < N; ++i) gg[i] = scc_v3(ag[i].x, ag[i].y, ag[i].z);
        ck_assert_msg(memcmp(w, ref, N * sizeof *w) == 0 && memcmp(gg, rg, N * sizeof *gg) == 0, "sdfccd_sdf_eval (band %d)", band);
        ck_assert_int_eq(sdfccd_destroy_sdf(id), SDFCCD_OK);
    }
    free(p); free(q); free(ref); free(v); free(w); free(rg); free(gg); free(ag);
}
END_TEST

static double sphere_cb(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    (void)user;
    const double l = sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    if (g) *g = l > 0 ? (sdfccd_Vec3){ p.x / l, p.y / l, p.z / l } : (sdfccd_Vec3){ 0, 0, 1 };
    return l - 0.5;
}

START_TEST(test_bad_defs)
{
    sdfccd_MeshId mesh = test_load_mesh("bullet3/cube.obj");
    sdfccd_SdfId g, sphere, plane;
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[1] = 0;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_INVALID_ARGUMENT);
    def = sdfccd_default_grid_def();
    def.padding = -1.0;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_INVALID_ARGUMENT);
    def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 4;
    def.padding = 0.25;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_OK);
    sdfccd_GridInfo pinfo;
    ck_assert_int_eq(sdfccd_grid_get_info(g, &pinfo), SDFCCD_OK);
    ck_assert(pinfo.domain.hi.x > 0.75 && pinfo.domain.hi.x < 0.76 && pinfo.domain.lo.z < -0.75);
    ck_assert_int_eq(sdfccd_destroy_sdf(g), SDFCCD_OK);
    def = sdfccd_default_grid_def();
    def.band = NAN;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_INVALID_ARGUMENT);
    def = sdfccd_default_grid_def();
    def.fit_domain = 0;
    def.domain = (sdfccd_Aabb){ { 1, 0, 0 }, { 0, 1, 1 } };
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_INVALID_ARGUMENT);
    def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 2000;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_INVALID_ARGUMENT);
    sdfccd_GridDef junk;
    memset(&junk, 0, sizeof junk);
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &junk, &g), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, NULL, &g), SDFCCD_INVALID_ARGUMENT);
    def = sdfccd_default_grid_def();
    ck_assert_int_eq(sdfccd_create_grid_from_mesh((sdfccd_MeshId){ 0, 0 }, &def, &g), SDFCCD_INVALID_HANDLE);
    /* a band that leaves no cell: a tiny band far from the surface */
    def.fit_domain = 0;
    def.domain = (sdfccd_Aabb){ { 5, 5, 5 }, { 6, 6, 6 } };
    def.band = 1e-3;
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 4;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &g), SDFCCD_INVALID_ARGUMENT);
    /* a band grid of a callback SDF with Lipschitz bound 3: culled cells still evaluate to the
     * right side with a magnitude below the distance */
    {
        sdfccd_SdfId cb, bg;
        sdfccd_CallbackSdfDef cdef = sdfccd_default_callback_sdf_def();
        cdef.eval = sphere_cb;
        cdef.lipschitz = 3.0; /* a valid, loose bound: the band's known lower bound drops to 0 */
        cdef.bounds = (sdfccd_Aabb){ { -0.5, -0.5, -0.5 }, { 0.5, 0.5, 0.5 } };
        ck_assert_int_eq(sdfccd_create_callback_sdf(&cdef, &cb), SDFCCD_OK);
        {
            sdfccd_GridDef bdef = sdfccd_default_grid_def();
            bdef.resolution[0] = bdef.resolution[1] = bdef.resolution[2] = 12;
            bdef.fit_domain = 0;
            bdef.domain = (sdfccd_Aabb){ { -1, -1, -1 }, { 1, 1, 1 } };
            bdef.band = 0.1;
            ck_assert_int_eq(sdfccd_create_grid_from_sdf(cb, &bdef, &bg), SDFCCD_OK);
            double v;
            ck_assert_int_eq(sdfccd_sdf_eval(bg, (sdfccd_Vec3){ 0.9, 0.9, 0.9 }, &v, NULL), SDFCCD_OK);
            ck_assert(v > 0.0 && v <= sqrt(3 * 0.81) - 0.5 + 1e-12);
            ck_assert_int_eq(sdfccd_sdf_eval(bg, (sdfccd_Vec3){ 0.0, 0.0, 0.05 }, &v, NULL), SDFCCD_OK);
            ck_assert(v < 0.0 && v >= -0.5 - 1e-9);
            ck_assert_int_eq(sdfccd_destroy_sdf(bg), SDFCCD_OK);
            ck_assert_int_eq(sdfccd_destroy_sdf(cb), SDFCCD_OK);
        }
    }
    /* an unbounded SDF needs an explicit domain */
    ck_assert_int_eq(sdfccd_create_half_space((sdfccd_Vec3){ 0, 0, 1 }, 0.0, &plane), SDFCCD_OK);
    def = sdfccd_default_grid_def();
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(plane, &def, &g), SDFCCD_INVALID_ARGUMENT);
    def.fit_domain = 0;
    def.domain = (sdfccd_Aabb){ { -1, -1, -1 }, { 1, 1, 1 } };
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 4;
    ck_assert_int_eq(sdfccd_create_grid_from_sdf(plane, &def, &g), SDFCCD_OK);
    /* the half-space grid: exact inside the domain (phi is linear); above it the lower bound
     * sqrt(d^2 + phi(q)^2), below it phi(q) - d (exact here), and infinite bounds since the
     * surface crosses the domain boundary */
    double v;
    ck_assert_int_eq(sdfccd_sdf_eval(g, (sdfccd_Vec3){ 0.3, -0.2, 0.4 }, &v, NULL), SDFCCD_OK);
    ck_assert_double_near(v, 0.4, 1e-12);
    ck_assert_int_eq(sdfccd_sdf_eval(g, (sdfccd_Vec3){ 0.3, -0.2, 3.0 }, &v, NULL), SDFCCD_OK);
    ck_assert_double_near(v, sqrt(5.0), 1e-12);
    ck_assert_int_eq(sdfccd_sdf_eval(g, (sdfccd_Vec3){ 0.3, -0.2, -3.0 }, &v, NULL), SDFCCD_OK);
    ck_assert_double_near(v, -3.0, 1e-12);
    sdfccd_SdfInfo si;
    ck_assert_int_eq(sdfccd_sdf_get_info(g, &si), SDFCCD_OK);
    ck_assert(isinf(si.bounds.hi.z));
    ck_assert_int_eq(sdfccd_destroy_sdf(g), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(plane), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &sphere), SDFCCD_OK);
    double b;
    ck_assert_int_eq(sdfccd_grid_lipschitz_bound(sphere, (sdfccd_Aabb){ { 0, 0, 0 }, { 1, 1, 1 } }, &b), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_destroy_sdf(sphere), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("grid_build");
    TCase* tc = tcase_create("build");
    test_add_memory_fixture(tc);
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_sphere_convergence);
    tcase_add_test(tc, test_threads_identical_and_progress);
    tcase_add_test(tc, test_progress_cancels);
    tcase_add_test(tc, test_narrow_band);
    tcase_add_test(tc, test_outside_domain);
    tcase_add_test(tc, test_lipschitz_bounds);
    tcase_add_test(tc, test_ccd_on_grid);
    tcase_add_test(tc, test_mesh_import_formats);
    tcase_add_test(tc, test_bad_defs);
    tcase_add_test(tc, test_core_band_unknown_lipschitz);
    tcase_add_test(tc, test_band_never_dense);
    tcase_add_test(tc, test_concurrent_eval);
    tcase_add_test(tc, test_eval_paths_identical);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
