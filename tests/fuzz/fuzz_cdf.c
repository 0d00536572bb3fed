/* SPDX-License-Identifier: MIT
 * libFuzzer target: the .cdf loader from memory (sdfccd_load_grid_memory). A grid that loads is
 * evaluated at fixed points (inside, on the domain boundary, outside, far away) and queried with
 * one moving triangle by FWGSS and by the certified method: values and gradients must be finite,
 * the Lipschitz bound finite and positive, and every OK query result valid (fuzz_common.h). */
#include "fuzz_common.h"

static int64_t g_bytes;

int LLVMFuzzerInitialize(int* argc, char*** argv)
{
    (void)argc;
    (void)argv;
    g_bytes = sdfccd_byte_count();
    return 0;
}

static sdfccd_Vec3 mix(sdfccd_Aabb b, double u, double v, double w)
{
    return (sdfccd_Vec3){ b.lo.x + u * (b.hi.x - b.lo.x), b.lo.y + v * (b.hi.y - b.lo.y), b.lo.z + w * (b.hi.z - b.lo.z) };
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    sdfccd_SdfId g;
    if (sdfccd_load_grid_memory(data, size, &g) != SDFCCD_OK) {
        FZ_CHECK(sdfccd_last_error()[0], "a failed load without a message");
        FZ_CHECK(sdfccd_byte_count() == g_bytes, "a failed load leaked %lld bytes", (long long)(sdfccd_byte_count() - g_bytes));
        return 0;
    }
    sdfccd_SdfInfo info;
    FZ_CHECK(sdfccd_sdf_get_info(g, &info) == SDFCCD_OK, "get_info");
    const sdfccd_Aabb dom = info.domain;
    const double uvw[][3] = { { 0.5, 0.5, 0.5 }, { 0, 0, 0 }, { 1, 1, 1 }, { 0.25, 0.75, 0.5 }, { -0.5, 0.5, 0.5 }, { 2, -1, 3 }, { 1e6, 0, 0 } };
    for (size_t i = 0; i < sizeof uvw / sizeof uvw[0]; ++i) {
        sdfccd_Vec3 p = mix(dom, uvw[i][0], uvw[i][1], uvw[i][2]), gr;
        double v;
        FZ_CHECK(sdfccd_sdf_eval(g, p, &v, &gr) == SDFCCD_OK, "eval");
        FZ_CHECK(isfinite(v) && isfinite(gr.x) && isfinite(gr.y) && isfinite(gr.z), "value %g gradient (%g %g %g) at point %zu", v,
                 gr.x, gr.y, gr.z, i);
    }
    double L;
    sdfccd_Aabb box = { mix(dom, 0.1, 0.1, 0.1), mix(dom, 0.9, 0.9, 0.9) };
    if (sdfccd_grid_lipschitz_bound(g, box, &L) == SDFCCD_OK) FZ_CHECK(isfinite(L) && L >= 0.0, "Lipschitz bound %g", L);
    /* a triangle sweeping through the domain's centre */
    const sdfccd_Vec3 c = mix(dom, 0.5, 0.5, 0.5);
    const double ext = fmax(dom.hi.x - dom.lo.x, fmax(dom.hi.y - dom.lo.y, dom.hi.z - dom.lo.z));
    sdfccd_Vec3 tri[3] = { { 0, 0, 0 }, { 0.1 * ext, 0, 0 }, { 0, 0.1 * ext, 0 } };
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = (sdfccd_Vec3){ c.x, c.y, dom.hi.z + 0.5 * ext };
    m.linear_velocity = (sdfccd_Vec3){ 0, 0, -2.0 * ext };
    m.angular_velocity = (sdfccd_Vec3){ 0.5, 0.2, 0 };
    for (int method = 0; method < SDFCCD_METHOD_COUNT; ++method) {
        sdfccd_QueryParams p = sdfccd_default_query_params();
        p.method = (sdfccd_Method)method;
        p.max_sdf_evaluations = 200000;
        p.certified_max_regions = 20000;
        sdfccd_Contact cs[8];
        sdfccd_QueryResult r;
        double t = fz_now();
        sdfccd_Status st = sdfccd_query_triangle(g, NULL, tri, &m, 0.0, 1.0, &p, cs, 8, &r);
        fz_note_time(fz_now() - t, st == SDFCCD_OK ? r.sdf_evaluations : 0);
        if (st == SDFCCD_OK) fz_check_result(&r, cs, 8, 0.0, 1.0, &p);
        else FZ_CHECK(sdfccd_last_error()[0], "query status %d without a message", (int)st);
    }
    sdfccd_destroy_sdf(g);
    FZ_CHECK(sdfccd_byte_count() == g_bytes, "%lld bytes left after destroying the grid", (long long)(sdfccd_byte_count() - g_bytes));
    return 0;
}
