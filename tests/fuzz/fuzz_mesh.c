/* SPDX-License-Identifier: MIT
 * libFuzzer target: mesh import (sdfccd_load_mesh). The input's first byte picks the format,
 * the rest is written to a temporary file with that extension: .obj (the library's own double
 * precision reader, most inputs) or .stl (assimp's reader). PLY and OFF are not fuzzed: assimp
 * 5.2.5's PLY reader can spin forever on a malformed file, and its OFF reader allocates over 2 GB
 * for a 195-byte file declaring a huge vertex count (README). A mesh that loads gets its
 * info, topology, signed distances and one query; no library memory may remain afterwards. */
#include <unistd.h>

#include "fuzz_common.h"

static int64_t g_bytes;
static sdfccd_SdfId g_ball;
static char g_path[2][128];

int LLVMFuzzerInitialize(int* argc, char*** argv)
{
    (void)argc;
    (void)argv;
    static const char* ext[2] = { "obj", "stl" };
    for (int i = 0; i < 2; ++i) snprintf(g_path[i], sizeof g_path[i], "/tmp/sdfccd-fuzz-mesh-%ld.%s", (long)getpid(), ext[i]);
    if (sdfccd_create_sphere(0.5, &g_ball)) abort();
    g_bytes = sdfccd_byte_count();
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    if (size == 0) return 0;
    const int fmt = data[0] < 200 ? 0 : 1;
    FILE* f = fopen(g_path[fmt], "wb");
    if (!f) abort();
    if (size > 1 && fwrite(data + 1, 1, size - 1, f) != size - 1) abort();
    fclose(f);
    sdfccd_MeshLoadDef d = sdfccd_default_mesh_load_def();
    d.merge_vertices = data[0] & 1;
    d.drop_degenerate = (data[0] >> 1) & 1;
    sdfccd_MeshId m;
    sdfccd_Status st = sdfccd_load_mesh(g_path[fmt], &d, &m);
    remove(g_path[fmt]);
    if (st != SDFCCD_OK) {
        FZ_CHECK(sdfccd_last_error()[0], "load status %d without a message", (int)st);
        FZ_CHECK(sdfccd_byte_count() == g_bytes, "a failed load leaked %lld bytes", (long long)(sdfccd_byte_count() - g_bytes));
        return 0;
    }
    sdfccd_MeshInfo info;
    FZ_CHECK(sdfccd_mesh_get_info(m, &info) == SDFCCD_OK && info.triangle_count > 0, "mesh info");
    sdfccd_MeshTopology topo;
    FZ_CHECK(sdfccd_mesh_get_topology(m, &topo) == SDFCCD_OK, "topology");
    sdfccd_Vec3 pts[2] = { { 0, 0, 0 }, info.bounds.hi };
    double dist[2];
    if (sdfccd_mesh_signed_distance(m, pts, 2, 1, dist, NULL) == SDFCCD_OK)
        FZ_CHECK(isfinite(dist[0]) && isfinite(dist[1]), "signed distance %g %g", dist[0], dist[1]);
    sdfccd_RigidMotion mo = sdfccd_default_rigid_motion();
    mo.linear_velocity = (sdfccd_Vec3){ 0, 0, -1 };
    mo.angular_velocity = (sdfccd_Vec3){ 1, 0, 0 };
    sdfccd_QueryParams p = sdfccd_default_query_params();
    p.max_sdf_evaluations = 200000;
    sdfccd_Contact c[8];
    sdfccd_QueryResult r;
    double t = fz_now();
    st = sdfccd_query_mesh(g_ball, NULL, m, &mo, 0.0, 1.0, &p, c, 8, &r);
    fz_note_time(fz_now() - t, st == SDFCCD_OK ? r.sdf_evaluations : 0);
    if (st == SDFCCD_OK) fz_check_result(&r, c, 8, 0.0, 1.0, &p);
    else FZ_CHECK(sdfccd_last_error()[0], "query status %d without a message", (int)st);
    sdfccd_destroy_mesh(m);
    FZ_CHECK(sdfccd_byte_count() == g_bytes, "%lld bytes left after destroying the mesh", (long long)(sdfccd_byte_count() - g_bytes));
    return 0;
}
