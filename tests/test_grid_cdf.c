/* SPDX-License-Identifier: MIT
 * Grid SDFs, part 1: the 32-node element against its defining properties, Discregrid .cdf
 * reading and writing, compatibility with files made by Discregrid's own GenerateSDF
 * (box.cdf byte layout and node values; the generated bunny and torus grids), sparse
 * multi-field files, and corrupt or truncated files. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"
#include "test_internal.h"

#ifndef SDFCCD_TEST_TMP_DIR
#define SDFCCD_TEST_TMP_DIR "."
#endif

static unsigned char* read_all(const char* path, size_t* out_size)
{
    FILE* f = fopen(path, "rb");
    ck_assert_msg(f != NULL, "cannot open %s", path);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char* b = malloc((size_t)n + 1);
    ck_assert_int_eq(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *out_size = (size_t)n;
    return b;
}

static sdfccd_SdfId load_grid(const char* rel)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", SDFCCD_DATA_DIR, rel);
    sdfccd_SdfId g;
    sdfccd_Status st = sdfccd_load_grid(path, &g);
    ck_assert_msg(st == SDFCCD_OK, "load %s: %s", path, sdfccd_last_error());
    return g;
}

/* ---------------- the element ---------------- */

START_TEST(test_element_kronecker_and_unity)
{
    double N[32], dN[32][3];
    for (int b = 0; b < 32; ++b) {
        scc_cell_shape(scc_cell_node_local(b), N, dN);
        for (int a = 0; a < 32; ++a) ck_assert_double_near(N[a], a == b ? 1.0 : 0.0, 1e-14);
    }
    test_rng rng = { 11 };
    for (int it = 0; it < 200; ++it) {
        scc_vec3 xi = scc_v3(test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1));
        scc_cell_shape(xi, N, dN);
        double s = 0, g[3] = { 0, 0, 0 };
        for (int a = 0; a < 32; ++a) { s += N[a]; for (int d = 0; d < 3; ++d) g[d] += dN[a][d]; }
        ck_assert_double_near(s, 1.0, 1e-14);
        for (int d = 0; d < 3; ++d) ck_assert_double_near(g[d], 0.0, 1e-13);
    }
}
END_TEST

/* Every polynomial of total degree <= 3 is reproduced, values and derivatives; derivatives
 * also match central differences of the shape functions. */
START_TEST(test_element_cubic_reproduction)
{
    test_rng rng = { 12 };
    for (int trial = 0; trial < 20; ++trial) {
        double c[20];
        for (int i = 0; i < 20; ++i) c[i] = test_rng_uniform(&rng, -1, 1);
        /* monomials x^a y^b z^c with a+b+c <= 3, in a fixed order */
        #define POLY(x, y, z, out, gx, gy, gz) do { \
            int k_ = 0; out = gx = gy = gz = 0; \
            for (int a_ = 0; a_ <= 3; ++a_) for (int b_ = 0; a_ + b_ <= 3; ++b_) for (int c_ = 0; a_ + b_ + c_ <= 3; ++c_, ++k_) { \
                out += c[k_] * pow(x, a_) * pow(y, b_) * pow(z, c_); \
                gx += a_ ? c[k_] * a_ * pow(x, a_ - 1) * pow(y, b_) * pow(z, c_) : 0; \
                gy += b_ ? c[k_] * b_ * pow(x, a_) * pow(y, b_ - 1) * pow(z, c_) : 0; \
                gz += c_ ? c[k_] * c_ * pow(x, a_) * pow(y, b_) * pow(z, c_ - 1) : 0; } } while (0)
        double v[32];
        for (int a = 0; a < 32; ++a) {
            scc_vec3 p = scc_cell_node_local(a);
            double gx, gy, gz;
            POLY(p.x, p.y, p.z, v[a], gx, gy, gz);
        }
        for (int it = 0; it < 20; ++it) {
            scc_vec3 xi = scc_v3(test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1));
            double N[32], dN[32][3], f = 0, g[3] = { 0, 0, 0 };
            scc_cell_shape(xi, N, dN);
            for (int a = 0; a < 32; ++a) { f += v[a] * N[a]; for (int d = 0; d < 3; ++d) g[d] += v[a] * dN[a][d]; }
            double ef, ex, ey, ez;
            POLY(xi.x, xi.y, xi.z, ef, ex, ey, ez);
            ck_assert_double_near(f, ef, 1e-12);
            ck_assert_double_near(g[0], ex, 1e-11);
            ck_assert_double_near(g[1], ey, 1e-11);
            ck_assert_double_near(g[2], ez, 1e-11);
            /* central differences of each shape function */
            const double e = 1e-6;
            for (int d = 0; d < 3; ++d) {
                double Np[32], Nm[32];
                scc_vec3 xp = xi, xm = xi;
                if (d == 0) { xp.x += e; xm.x -= e; } else if (d == 1) { xp.y += e; xm.y -= e; } else { xp.z += e; xm.z -= e; }
                scc_cell_shape(xp, Np, NULL);
                scc_cell_shape(xm, Nm, NULL);
                for (int a = 0; a < 32; ++a) ck_assert_double_near(dN[a][d], (Np[a] - Nm[a]) / (2 * e), 1e-8);
            }
        }
        #undef POLY
    }
}
END_TEST

/* The factored evaluator equals the sum over the shape functions. */
START_TEST(test_element_fused_eval)
{
    test_rng rng = { 13 };
    for (int it = 0; it < 2000; ++it) {
        double v[32], N[32], dN[32][3];
        for (int a = 0; a < 32; ++a) v[a] = test_rng_uniform(&rng, -2, 2);
        scc_vec3 xi = scc_v3(test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1), test_rng_uniform(&rng, -1, 1));
        scc_cell_shape(xi, N, dN);
        double f = 0, g[3] = { 0, 0, 0 }, ff, gg[3];
        for (int a = 0; a < 32; ++a) { f += v[a] * N[a]; for (int d = 0; d < 3; ++d) g[d] += v[a] * dN[a][d]; }
        scc_cell_eval(v, xi, &ff, gg);
        ck_assert_double_near(ff, f, 1e-13);
        for (int d = 0; d < 3; ++d) ck_assert_double_near(gg[d], g[d], 1e-12);
        scc_cell_eval(v, xi, &ff, NULL);
        ck_assert_double_near(ff, f, 1e-13);
    }
}
END_TEST

/* The vertex-block layout is one-to-one: every dense node gets its own slot. */
START_TEST(test_block_index_bijective)
{
    const uint32_t res[3] = { 3, 5, 4 };
    const uint64_t n = scc_grid_dense_node_count(res), nb = 7 * 4 * 6 * 5;
    unsigned char* seen = calloc(nb, 1);
    for (uint64_t l = 0; l < n; ++l) {
        const uint64_t b = scc_grid_dense_block_index(res, l);
        ck_assert_uint_lt(b, nb);
        ck_assert_int_eq(seen[b], 0);
        seen[b] = 1;
    }
    free(seen);
}
END_TEST

/* The table of the notes: slot 9 = (+1/3,-1,-1), 10 = (-1/3,-1,+1), 12 = (-1/3,+1,-1),
 * 18 = (+1,-1/3,-1), 20 = (-1,-1/3,+1), 26 = (-1,+1,-1/3), 28 = (+1,-1,-1/3). */
START_TEST(test_element_slot_order)
{
    struct { int slot; double x, y, z; } t[] = {
        { 1, 1, -1, -1 }, { 2, -1, 1, -1 }, { 4, -1, -1, 1 }, { 9, 1.0 / 3, -1, -1 }, { 10, -1.0 / 3, -1, 1 },
        { 12, -1.0 / 3, 1, -1 }, { 18, 1, -1.0 / 3, -1 }, { 20, -1, -1.0 / 3, 1 }, { 26, -1, 1, -1.0 / 3 }, { 28, 1, -1, -1.0 / 3 },
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; ++i) {
        scc_vec3 p = scc_cell_node_local(t[i].slot);
        ck_assert_double_eq(p.x, t[i].x);
        ck_assert_double_eq(p.y, t[i].y);
        ck_assert_double_eq(p.z, t[i].z);
    }
}
END_TEST

/* ---------------- Discregrid's box.cdf ---------------- */

START_TEST(test_box_cdf_loads_and_matches_analytic)
{
    sdfccd_SdfId id = load_grid("sdf/upstream/box.cdf");
    sdfccd_GridInfo info;
    ck_assert_int_eq(sdfccd_grid_get_info(id, &info), SDFCCD_OK);
    ck_assert_int_eq(info.resolution[0], 5);
    ck_assert_int_eq(info.node_count, 1296);
    ck_assert_int_eq(info.cell_count, 125);
    ck_assert_int_eq(info.stored_cells, 125);
    ck_assert_int_eq(info.file_bytes, 27040);
    ck_assert_double_eq(info.domain.hi.x, 1.0034641016151378);
    ck_assert_double_eq(info.domain.lo.x, -1.0034701016151377);
    scc_grid* g = test_grid_of(id);
    /* Node values equal the exact box distance at the positions of section 2. */
    for (uint64_t l = 0; l < g->fields[0].node_count; ++l)
        ck_assert_double_near(scc_grid_node_value(g, 0, l), test_box_distance(sdfccd__pv(scc_grid_dense_node_position(g, l)), 1.0), 1e-12);
    /* Cell tables equal the dense formulas of section 4. */
    uint32_t ids[32];
    for (uint32_t k = 0, l = 0; k < 5; ++k)
        for (uint32_t j = 0; j < 5; ++j)
            for (uint32_t i = 0; i < 5; ++i, ++l) {
                scc_grid_dense_cell_nodes(g->res, i, j, k, ids);
                uint32_t scratch[32];
                ck_assert_int_eq(memcmp(ids, scc_grid_cell_ids(g, 0, l, scratch), sizeof ids), 0);
                ck_assert_uint_eq(g->fields[0].map[l], l);
            }
    /* Evaluation reproduces every node value, and in the cells next to a face centre, where the
     * box distance is linear (z - 1 on both sides of the face), the cubic reproduces it exactly. */
    for (uint64_t l = 0; l < g->fields[0].node_count; ++l) {
        double v;
        ck_assert_int_eq(sdfccd_sdf_eval(id, sdfccd__pv(scc_grid_dense_node_position(g, l)), &v, NULL), SDFCCD_OK);
        ck_assert_double_near(v, scc_grid_node_value(g, 0, l), 1e-12);
    }
    test_rng rng = { 5 };
    for (int it = 0; it < 500; ++it) {
        sdfccd_Vec3 p = { test_rng_uniform(&rng, -0.2, 0.2), test_rng_uniform(&rng, -0.2, 0.2), test_rng_uniform(&rng, 0.61, 1.003) };
        double v;
        sdfccd_Vec3 gr;
        ck_assert_int_eq(sdfccd_sdf_eval(id, p, &v, &gr), SDFCCD_OK);
        ck_assert_double_near(v, p.z - 1.0, 1e-12);
        ck_assert_double_near(gr.x, 0.0, 1e-11);
        ck_assert_double_near(gr.y, 0.0, 1e-11);
        ck_assert_double_near(gr.z, 1.0, 1e-11);
    }
    ck_assert_int_eq(sdfccd_destroy_sdf(id), SDFCCD_OK);
}
END_TEST

/* The compatibility test of issue 3: our builder on Discregrid's box.obj at 5x5x5 with the
 * default (fitted) domain gives box.cdf's layout exactly and its node values within 1e-12. */
START_TEST(test_box_obj_build_matches_discregrid)
{
    sdfccd_MeshId mesh = test_load_mesh("discregrid/box.obj");
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 5;
    def.threads = 2;
    sdfccd_SdfId ours;
    ck_assert_msg(sdfccd_create_grid_from_mesh(mesh, &def, &ours) == SDFCCD_OK, "%s", sdfccd_last_error());
    char path[512];
    snprintf(path, sizeof path, "%s/grid_box_r5_ours.cdf", SDFCCD_TEST_TMP_DIR);
    ck_assert_msg(sdfccd_save_grid(ours, path) == SDFCCD_OK, "%s", sdfccd_last_error());
    size_t na, nb;
    unsigned char* a = read_all(path, &na);
    char ref[512];
    snprintf(ref, sizeof ref, "%s/sdf/upstream/box.cdf", SDFCCD_DATA_DIR);
    unsigned char* b = read_all(ref, &nb);
    ck_assert_uint_eq(na, nb);
    /* header (domain, resolution, h, 1/h, counts) byte for byte */
    ck_assert_int_eq(memcmp(a, b, 140), 0);
    /* node values within 1e-12, identical signs away from the surface */
    const size_t n_nodes = 1296, nodes_at = 140;
    double max_diff = 0;
    for (size_t i = 0; i < n_nodes; ++i) {
        double x, y;
        memcpy(&x, a + nodes_at + 8 * i, 8);
        memcpy(&y, b + nodes_at + 8 * i, 8);
        max_diff = fmax(max_diff, fabs(x - y));
        if (fabs(y) > 1e-9) ck_assert_int_eq(signbit(x), signbit(y));
    }
    ck_assert_msg(max_diff <= 1e-12, "max node difference %g", max_diff);
    /* cell tables and map byte for byte */
    const size_t rest = nodes_at + 8 * n_nodes;
    ck_assert_int_eq(memcmp(a + rest, b + rest, na - rest), 0);
    fprintf(stderr, "box.obj 5^3 vs Discregrid box.cdf: max node difference %.3g, %s\n", max_diff,
            memcmp(a, b, na) == 0 ? "files identical byte for byte" : "files differ only in node round-off");
    free(a);
    free(b);
    remove(path);
    ck_assert_int_eq(sdfccd_destroy_sdf(ours), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}
END_TEST

/* Load then save gives the original bytes (dense and sparse multi-field). */
static void roundtrip(const char* rel)
{
    char src[512], dst[512];
    snprintf(src, sizeof src, "%s/%s", SDFCCD_DATA_DIR, rel);
    snprintf(dst, sizeof dst, "%s/grid_roundtrip.cdf", SDFCCD_TEST_TMP_DIR);
    sdfccd_SdfId id = load_grid(rel);
    ck_assert_int_eq(sdfccd_save_grid(id, dst), SDFCCD_OK);
    size_t na, nb;
    unsigned char* a = read_all(src, &na);
    unsigned char* b = read_all(dst, &nb);
    ck_assert_uint_eq(na, nb);
    ck_assert_int_eq(memcmp(a, b, na), 0);
    sdfccd_GridInfo info;
    ck_assert_int_eq(sdfccd_grid_get_info(id, &info), SDFCCD_OK);
    ck_assert_int_eq(info.file_bytes, (int64_t)na);
    free(a);
    free(b);
    remove(dst);
    ck_assert_int_eq(sdfccd_destroy_sdf(id), SDFCCD_OK);
}

START_TEST(test_roundtrip_bytes)
{
    roundtrip("sdf/upstream/box.cdf");
    roundtrip("sdf/generated/bullet3_torus_r16.cdf");
    roundtrip("sdf/generated/bullet3_bunny_r24_densitymap_s002.cdm");
}
END_TEST

/* Our builds of the meshes Discregrid's files were made from, at the same resolution and the
 * default domain, agree with them. Both sample the exact mesh distance at bit-identical node
 * positions, so magnitudes differ only by round-off in the point-triangle distance (about
 * 1e-16 times coordinates below 1 here); 1e-10 leaves a wide margin while any real difference
 * (a wrong nearest feature) would be of the order of the mesh's edge length, ~1e-2.
 * Signs: Discregrid weights a vertex pseudonormal by acos(|cos angle|), not the angle, so at
 * obtuse corners its sign can be wrong (notes section 7). Every node where the signs differ
 * must have the same magnitude and our sign must agree with the winding number there; those
 * nodes are counted and reported, and cells touching them are left out of the evaluation
 * comparison. */
static void compare_with_generated(const char* mesh_rel, const char* cdf_rel, int res, int max_flips)
{
    sdfccd_MeshId mesh = test_load_mesh(mesh_rel);
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = res;
    sdfccd_SdfId ours, theirs = load_grid(cdf_rel);
    ck_assert_msg(sdfccd_create_grid_from_mesh(mesh, &def, &ours) == SDFCCD_OK, "%s", sdfccd_last_error());
    scc_grid* a = test_grid_of(ours);
    scc_grid* b = test_grid_of(theirs);
    const scc_mesh* m = test_mesh_of(mesh);
    ck_assert_int_eq(memcmp(&a->lo, &b->lo, sizeof a->lo), 0);
    ck_assert_int_eq(memcmp(&a->hi, &b->hi, sizeof a->hi), 0);
    ck_assert_int_eq(memcmp(&a->h, &b->h, sizeof a->h), 0);
    ck_assert_int_eq(memcmp(&a->inv_h, &b->inv_h, sizeof a->h), 0);
    ck_assert_uint_eq(a->fields[0].node_count, b->fields[0].node_count);
    ck_assert_int_eq(a->dense_layout, 1); /* both dense: the loaded table was recognised and dropped */
    ck_assert_int_eq(b->dense_layout, 1);
    double max_diff = 0;
    int flips = 0;
    uint32_t flipped[64];
    for (uint64_t i = 0; i < a->fields[0].node_count; ++i) {
        const double x = scc_grid_node_value(a, 0, i), y = scc_grid_node_value(b, 0, i);
        if (fabs(y) > 1e-9 && (x < 0) != (y < 0)) {
            ck_assert_double_near(fabs(x), fabs(y), 1e-10);
            const double w = test_winding_number(m, scc_grid_dense_node_position(a, i));
            ck_assert_msg((w > 0.5) == (x < 0), "node %llu: our sign %g disagrees with the winding number %g", (unsigned long long)i, x, w);
            ck_assert_int_lt(flips, 64);
            flipped[flips++] = (uint32_t)i;
            continue;
        }
        max_diff = fmax(max_diff, fabs(x - y));
    }
    fprintf(stderr, "%s r%d vs Discregrid %s: max node difference %.3g; %d nodes with Discregrid's sign wrong (winding number)\n",
            mesh_rel, res, cdf_rel, max_diff, flips);
    ck_assert_msg(max_diff <= 1e-10, "max node difference %g", max_diff);
    ck_assert_int_le(flips, max_flips);
    /* Evaluation agrees inside the domain (same nodes, same element). */
    test_rng rng = { 77 };
    int compared = 0;
    for (int it = 0; it < 2000; ++it) {
        sdfccd_Vec3 p = { test_rng_uniform(&rng, a->lo.x, a->hi.x), test_rng_uniform(&rng, a->lo.y, a->hi.y), test_rng_uniform(&rng, a->lo.z, a->hi.z) };
        const uint64_t l = scc_grid_cell_of(a, sdfccd__v(p));
        int touches = 0;
        uint32_t scratch[32];
        const uint32_t* ids = scc_grid_cell_ids(a, 0, (uint32_t)l, scratch);
        for (int s = 0; s < 32; ++s)
            for (int f = 0; f < flips; ++f) touches |= ids[s] == flipped[f];
        if (touches) continue;
        double va, vb;
        sdfccd_Vec3 ga, gb;
        ck_assert_int_eq(sdfccd_sdf_eval(ours, p, &va, &ga), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_sdf_eval(theirs, p, &vb, &gb), SDFCCD_OK);
        ck_assert_double_near(va, vb, 1e-9);
        ck_assert_double_near(ga.x, gb.x, 1e-7);
        ck_assert_double_near(ga.y, gb.y, 1e-7);
        ck_assert_double_near(ga.z, gb.z, 1e-7);
        ++compared;
    }
    ck_assert_int_gt(compared, 1900);
    ck_assert_int_eq(sdfccd_destroy_sdf(ours), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(theirs), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}

START_TEST(test_generated_bunny_and_torus)
{
    compare_with_generated("bullet3/bunny.obj", "sdf/generated/bullet3_bunny_r16.cdf", 16, 8);
    compare_with_generated("bullet3/torus_textured.obj", "sdf/generated/bullet3_torus_r16.cdf", 16, 8);
}
END_TEST

/* The sparse two-field density-map file: loads, keeps both fields, and in culled cells the
 * conservative value has the side of our dense build of the same mesh and a magnitude no larger
 * than the distance there; in kept cells it equals the dense build. */
START_TEST(test_sparse_multifield_cdm)
{
    sdfccd_SdfId sp = load_grid("sdf/generated/bullet3_bunny_r24_densitymap_s002.cdm");
    sdfccd_GridInfo info;
    ck_assert_int_eq(sdfccd_grid_get_info(sp, &info), SDFCCD_OK);
    ck_assert_int_eq(info.field_count, 2);
    ck_assert_int_eq(info.stored_cells, 10550);
    ck_assert_int_eq(info.node_count, 83551);
    ck_assert_int_eq(info.cell_count, 24 * 24 * 24);
    ck_assert_int_lt(info.valued_cells, info.cell_count);
    sdfccd_MeshId mesh = test_load_mesh("bullet3/bunny.obj");
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 24;
    sdfccd_SdfId dense;
    ck_assert_int_eq(sdfccd_create_grid_from_mesh(mesh, &def, &dense), SDFCCD_OK);
    scc_grid* g = test_grid_of(sp);
    test_rng rng = { 99 };
    int culled = 0, kept = 0;
    for (int it = 0; it < 4000; ++it) {
        sdfccd_Vec3 p = { test_rng_uniform(&rng, g->lo.x, g->hi.x), test_rng_uniform(&rng, g->lo.y, g->hi.y), test_rng_uniform(&rng, g->lo.z, g->hi.z) };
        double vs, vd, raw;
        sdfccd_Vec3 gs;
        int32_t has;
        ck_assert_int_eq(sdfccd_sdf_eval(sp, p, &vs, &gs), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_sdf_eval(dense, p, &vd, NULL), SDFCCD_OK);
        ck_assert_int_eq(sdfccd_grid_interpolate(sp, 0, p, &raw, NULL, &has), SDFCCD_OK);
        ck_assert(isfinite(vs) && isfinite(gs.x) && isfinite(gs.y) && isfinite(gs.z));
        if (has) {
            ++kept;
            ck_assert_double_near(vs, raw, 0.0);
            ck_assert_double_near(vs, vd, 1e-9);
        } else {
            ++culled;
            ck_assert_msg((vs < 0) == (vd < 0), "culled cell at (%g %g %g): sign %g vs dense %g", p.x, p.y, p.z, vs, vd);
            ck_assert_msg(fabs(vs) <= fabs(vd) + 1e-3, "culled value %g exceeds |phi| %g", vs, vd);
            ck_assert_double_near(gs.x * gs.x + gs.y * gs.y + gs.z * gs.z, 1.0, 1e-9);
        }
    }
    ck_assert_int_gt(culled, 100);
    ck_assert_int_gt(kept, 100);
    /* field 1 (density) is readable through the raw interpolation */
    int32_t has = 0;
    double v;
    sdfccd_Vec3 c = { 0.5 * (g->lo.x + g->hi.x), 0.5 * (g->lo.y + g->hi.y), 0.5 * (g->lo.z + g->hi.z) };
    ck_assert_int_eq(sdfccd_grid_interpolate(sp, 1, c, &v, NULL, &has), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_grid_interpolate(sp, 2, c, &v, NULL, &has), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_destroy_sdf(sp), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_sdf(dense), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_destroy_mesh(mesh), SDFCCD_OK);
}
END_TEST

/* ---------------- corrupt files ---------------- */

static void expect_format_error(const unsigned char* data, size_t n, const char* what)
{
    sdfccd_SdfId id;
    sdfccd_Status st = sdfccd_load_grid_memory(data, n, &id);
    ck_assert_msg(st == SDFCCD_FORMAT_ERROR, "%s: status %s (%s)", what, sdfccd_status_string(st), sdfccd_last_error());
    ck_assert(strlen(sdfccd_last_error()) > 0);
}

static void put_u64(unsigned char* b, size_t at, uint64_t v) { memcpy(b + at, &v, 8); }
static void put_u32(unsigned char* b, size_t at, uint32_t v) { memcpy(b + at, &v, 4); }
static void put_f64(unsigned char* b, size_t at, double v) { memcpy(b + at, &v, 8); }

START_TEST(test_corrupt_files)
{
    char ref[512];
    snprintf(ref, sizeof ref, "%s/sdf/upstream/box.cdf", SDFCCD_DATA_DIR);
    size_t n;
    unsigned char* orig = read_all(ref, &n);
    unsigned char* b = malloc(n + 16);
    /* every truncation */
    for (size_t len = 0; len < n; len += (len < 200 ? 1 : 97)) {
        memcpy(b, orig, n);
        char what[64];
        snprintf(what, sizeof what, "truncated to %zu", len);
        expect_format_error(b, len, what);
    }
    memcpy(b, orig, n);
    expect_format_error(b, n - 1, "one byte short");
    b[n] = 0;
    expect_format_error(b, n + 1, "one trailing byte");
    /* inconsistent header values */
    const size_t nodes_at = 140, cells_at = nodes_at + 8 * 1296 + 8 /* outer */ + 8 /* count */;
    const size_t map_at = cells_at + 128 * 125 + 8 + 8;
    struct { const char* what; size_t at; int kind; uint64_t u; double d; } cases[] = {
        { "resolution 0", 48, 4, 0, 0 },
        { "resolution mismatch", 52, 4, 6, 0 },
        { "n_cells mismatch", 108, 8, 124, 0 },
        { "h mismatch", 60, 'd', 0, 0.5 },
        { "1/h mismatch", 84, 'd', 0, 2.0 },
        { "NaN domain", 0, 'd', 0, NAN },
        { "min > max", 24, 'd', 0, -2.0 },
        { "no fields", 116, 8, 0, 0 },
        { "huge field count", 116, 8, 1ull << 40, 0 },
        { "node outer count", 124, 8, 2, 0 },
        { "node count oversized", 132, 8, 1ull << 40, 0 },
        { "node count too small", 132, 8, 1000, 0 },
        { "NaN node", nodes_at + 8 * 17, 'd', 0, NAN },
        { "cell outer count", nodes_at + 8 * 1296, 8, 3, 0 },
        { "cell count oversized", cells_at - 8, 8, 1ull << 50, 0 },
        { "more cells than grid", cells_at - 8, 8, 126, 0 },
        { "node id out of range", cells_at + 4 * 77, 4, 1296, 0 },
        { "node id huge", cells_at + 4 * 5, 4, 0xFFFFFFFFu, 0 },
        { "map outer count", map_at - 16, 8, 0, 0 },
        { "map length", map_at - 8, 8, 124, 0 },
        { "map entry out of range", map_at + 4 * 3, 4, 125, 0 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        memcpy(b, orig, n);
        if (cases[i].kind == 4) put_u32(b, cases[i].at, (uint32_t)cases[i].u);
        else if (cases[i].kind == 8) put_u64(b, cases[i].at, cases[i].u);
        else put_f64(b, cases[i].at, cases[i].d);
        expect_format_error(b, n, cases[i].what);
    }
    /* a not-sampled node (DBL_MAX) in field 0: the file loads; the cells around it have no raw
     * value, and evaluation there falls back to a finite conservative value of the right side */
    memcpy(b, orig, n);
    {
        uint32_t ids[32];
        const uint32_t res[3] = { 5, 5, 5 };
        scc_grid_dense_cell_nodes(res, 4, 2, 2, ids); /* a cell holding the box's +x face */
        put_f64(b, nodes_at + 8 * (size_t)ids[1], 1.7976931348623157e308);
        sdfccd_SdfId id;
        ck_assert_int_eq(sdfccd_load_grid_memory(b, n, &id), SDFCCD_OK);
        sdfccd_GridInfo gi;
        ck_assert_int_eq(sdfccd_grid_get_info(id, &gi), SDFCCD_OK);
        ck_assert_int_lt(gi.valued_cells, 125);
        scc_grid* g = test_grid_of(id);
        const sdfccd_Vec3 p = { g->lo.x + 4.6 * g->h.x, g->lo.y + 2.5 * g->h.y, g->lo.z + 2.5 * g->h.z };
        double v, raw;
        sdfccd_Vec3 gr;
        int32_t has;
        ck_assert_int_eq(sdfccd_grid_interpolate(id, 0, p, &raw, NULL, &has), SDFCCD_OK);
        ck_assert_int_eq(has, 0);
        ck_assert_int_eq(sdfccd_sdf_eval(id, p, &v, &gr), SDFCCD_OK);
        const double exact = test_box_distance(p, 1.0); /* the point is inside the box, in the +x face cell */
        ck_assert_msg(isfinite(v) && (v < 0) == (exact < 0) && fabs(v) <= fabs(exact) + 1e-12, "fallback %g, box distance %g", v, exact);
        ck_assert_double_near(gr.x * gr.x + gr.y * gr.y + gr.z * gr.z, 1.0, 1e-9);
        ck_assert_int_eq(sdfccd_destroy_sdf(id), SDFCCD_OK);
    }
    /* every cell culled: a valid file but no SDF */
    memcpy(b, orig, n);
    for (int i = 0; i < 125; ++i) put_u32(b, map_at + 4 * (size_t)i, 0xFFFFFFFFu);
    expect_format_error(b, n, "all cells culled");
    /* random single-byte corruption: a status or a valid grid, never a crash (ASan checks) */
    test_rng rng = { 4242 };
    for (int it = 0; it < 400; ++it) {
        memcpy(b, orig, n);
        size_t at = (size_t)(test_rng_next(&rng) % n);
        b[at] ^= (unsigned char)(1u + test_rng_next(&rng) % 255u);
        sdfccd_SdfId id;
        sdfccd_Status st = sdfccd_load_grid_memory(b, n, &id);
        ck_assert(st == SDFCCD_OK || st == SDFCCD_FORMAT_ERROR);
        if (st == SDFCCD_OK) {
            double v;
            sdfccd_Vec3 gr;
            sdfccd_Vec3 p = { test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2) };
            ck_assert_int_eq(sdfccd_sdf_eval(id, p, &v, &gr), SDFCCD_OK);
            ck_assert_int_eq(sdfccd_destroy_sdf(id), SDFCCD_OK);
        }
    }
    /* files */
    sdfccd_SdfId id;
    ck_assert_int_eq(sdfccd_load_grid(SDFCCD_DATA_DIR "/no/such/file.cdf", &id), SDFCCD_IO_ERROR);
    ck_assert_int_eq(sdfccd_load_grid(NULL, &id), SDFCCD_INVALID_ARGUMENT);
    char path[512];
    snprintf(path, sizeof path, "%s/grid_empty.cdf", SDFCCD_TEST_TMP_DIR);
    FILE* f = fopen(path, "wb");
    fclose(f);
    ck_assert_int_eq(sdfccd_load_grid(path, &id), SDFCCD_FORMAT_ERROR);
    remove(path);
    /* saving: not a grid, unwritable path */
    sdfccd_SdfId sphere;
    ck_assert_int_eq(sdfccd_create_sphere(1.0, &sphere), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_save_grid(sphere, path), SDFCCD_INVALID_ARGUMENT);
    sdfccd_GridInfo info;
    ck_assert_int_eq(sdfccd_grid_get_info(sphere, &info), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_destroy_sdf(sphere), SDFCCD_OK);
    sdfccd_SdfId box;
    ck_assert_int_eq(sdfccd_load_grid_memory(orig, n, &box), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_save_grid(box, SDFCCD_TEST_TMP_DIR "/no/such/dir/x.cdf"), SDFCCD_IO_ERROR);
    ck_assert_int_eq(sdfccd_destroy_sdf(box), SDFCCD_OK);
    free(orig);
    free(b);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("grid_cdf");
    TCase* tc = tcase_create("element");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_element_kronecker_and_unity);
    tcase_add_test(tc, test_element_cubic_reproduction);
    tcase_add_test(tc, test_element_slot_order);
    tcase_add_test(tc, test_element_fused_eval);
    tcase_add_test(tc, test_block_index_bijective);
    suite_add_tcase(s, tc);
    tc = tcase_create("files");
    test_add_memory_fixture(tc);
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_box_cdf_loads_and_matches_analytic);
    tcase_add_test(tc, test_box_obj_build_matches_discregrid);
    tcase_add_test(tc, test_roundtrip_bytes);
    tcase_add_test(tc, test_generated_bunny_and_torus);
    tcase_add_test(tc, test_sparse_multifield_cdm);
    tcase_add_test(tc, test_corrupt_files);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
