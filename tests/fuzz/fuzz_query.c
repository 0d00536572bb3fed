/* SPDX-License-Identifier: MIT
 * libFuzzer target: the query API with fuzzer-chosen values for every input and every
 * sdfccd_QueryParams field, on analytic, CSG, transformed, callback and grid SDFs, through all
 * four query entry points. Every OK result is validated (fuzz_common.h) and every query is run
 * twice and must give bitwise identical results. The evaluation budget is chosen in
 * [-1, SDFCCD_DEFAULT_MAX_SDF_EVALUATIONS], so the slowest query found (printed at exit) is the
 * worst case of the defaults. */
#include "fuzz_common.h"

static sdfccd_SdfId g_grid;
static sdfccd_MeshId g_mesh;
static int64_t g_bytes;

/* A wobbly sphere: |p| - r + a sin(f x), gradient exact, |grad| <= 1 + a f. */
typedef struct wobble { double r, a, f; } wobble;
static double wobble_eval(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    const wobble* w = user;
    double m = fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z)));
    double l = m > 0.0 ? m * sqrt((p.x / m) * (p.x / m) + (p.y / m) * (p.y / m) + (p.z / m) * (p.z / m)) : 0.0;
    if (g) {
        sdfccd_Vec3 n = l > 0.0 ? (sdfccd_Vec3){ p.x / l, p.y / l, p.z / l } : (sdfccd_Vec3){ 0, 0, 1 };
        n.x += w->a * w->f * cos(w->f * p.x);
        *g = n;
    }
    return l - w->r + w->a * sin(w->f * p.x);
}

/* The same field with the point as three coordinates (sdfccd_CallbackSdfDef::eval_xyz). */
static double wobble_eval_xyz(double x, double y, double z, sdfccd_Vec3* g, void* user)
{
    return wobble_eval((sdfccd_Vec3){ x, y, z }, g, user);
}

int LLVMFuzzerInitialize(int* argc, char*** argv)
{
    (void)argc;
    (void)argv;
    sdfccd_SdfId torus;
    if (sdfccd_create_torus(0.5, 0.2, &torus)) abort();
    sdfccd_GridDef d = sdfccd_default_grid_def();
    d.resolution[0] = d.resolution[1] = d.resolution[2] = 6;
    d.threads = 1;
    if (sdfccd_create_grid_from_sdf(torus, &d, &g_grid)) abort();
    sdfccd_destroy_sdf(torus);
    /* a tetrahedron */
    static const double v[12] = { 0, 0, 0, 0.3, 0, 0, 0, 0.3, 0, 0, 0, 0.3 };
    static const uint32_t idx[12] = { 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3 };
    sdfccd_MeshDef md = sdfccd_default_mesh_def();
    md.vertices = v;
    md.vertex_count = 4;
    md.indices = idx;
    md.triangle_count = 4;
    if (sdfccd_create_mesh(&md, &g_mesh)) abort();
    g_bytes = sdfccd_byte_count();
    return 0;
}

static int32_t fz_int(fuzz_in* in, int32_t lo, int32_t hi)
{
    uint8_t sel = fz_u8(in);
    if (sel < 224) return lo + (int32_t)(fz_u32(in) % (uint32_t)(hi - lo + 1));
    return (int32_t)fz_u32(in); /* anything, including negative and huge */
}

typedef struct made { sdfccd_SdfId ids[4]; int n; } made;

static int keep(made* m, sdfccd_Status st, sdfccd_SdfId id, sdfccd_SdfId* out)
{
    if (st != SDFCCD_OK) return 0;
    m->ids[m->n++] = id;
    *out = id;
    return 1;
}

/* An analytic shape with fuzzed dimensions (creation may refuse them). */
static int make_analytic(fuzz_in* in, made* m, sdfccd_SdfId* out)
{
    sdfccd_SdfId id = { 0, 0 };
    sdfccd_Status st;
    switch (fz_u8(in) % 8) {
    case 0: st = sdfccd_create_sphere(fz_double(in), &id); break;
    case 1: st = sdfccd_create_box(fz_vec(in), &id); break;
    case 2: {
        sdfccd_Vec3 h = fz_vec(in);
        st = sdfccd_create_rounded_box(h, fz_double(in), &id);
        break;
    }
    case 3: {
        double a = fz_double(in);
        st = sdfccd_create_torus(a, fz_double(in), &id);
        break;
    }
    case 4: {
        double a = fz_double(in);
        st = sdfccd_create_capsule(a, fz_double(in), &id);
        break;
    }
    case 5: {
        double a = fz_double(in);
        st = sdfccd_create_cylinder(a, fz_double(in), &id);
        break;
    }
    case 6: {
        sdfccd_Vec3 n = fz_vec(in);
        st = sdfccd_create_half_space(n, fz_double(in), &id);
        break;
    }
    default: {
        sdfccd_SpikeGridDef d = sdfccd_default_spike_grid_def();
        d.spacing = fz_double(in);
        d.base_radius = fz_double(in);
        d.height = fz_double(in);
        d.count_x = fz_int(in, -1, 8);
        d.count_y = fz_int(in, -1, 8);
        st = sdfccd_create_spike_grid(&d, &id);
        break;
    }
    }
    return keep(m, st, id, out);
}

static sdfccd_Pose fz_pose(fuzz_in* in)
{
    sdfccd_Pose p;
    p.position = fz_vec(in);
    p.orientation.w = fz_double(in);
    p.orientation.x = fz_double(in);
    p.orientation.y = fz_double(in);
    p.orientation.z = fz_double(in);
    return p;
}

static int make_sdf(fuzz_in* in, made* m, wobble* w, sdfccd_SdfId* out)
{
    sdfccd_SdfId a, b, id = { 0, 0 };
    switch (fz_u8(in) % 6) {
    case 0: return make_analytic(in, m, out);
    case 1: { /* CSG of two analytic shapes */
        int op = fz_u8(in) % 4; /* 3 is not a valid operation */
        if (!make_analytic(in, m, &a) || !make_analytic(in, m, &b)) return 0;
        return keep(m, sdfccd_create_csg((sdfccd_CsgOp)op, a, b, &id), id, out);
    }
    case 2: { /* transformed analytic shape or grid */
        if (fz_u8(in) & 1) a = g_grid;
        else if (!make_analytic(in, m, &a)) return 0;
        sdfccd_Pose p = fz_pose(in);
        return keep(m, sdfccd_create_transformed(a, p, fz_double(in), &id), id, out);
    }
    case 3: { /* callback */
        w->r = 0.05 + fabs(fmod(fz_double(in), 2.0));
        w->a = fabs(fmod(fz_double(in), 0.1));
        w->f = fabs(fmod(fz_double(in), 20.0));
        if (!isfinite(w->r) || !isfinite(w->a) || !isfinite(w->f)) return 0;
        sdfccd_CallbackSdfDef d = sdfccd_default_callback_sdf_def();
        if (w->f > 10.0) d.eval_xyz = wobble_eval_xyz; /* the other form, chosen by bytes already read */
        else d.eval = wobble_eval;
        d.user = w;
        d.lipschitz = 1.0 + w->a * w->f;
        return keep(m, sdfccd_create_callback_sdf(&d, &id), id, out);
    }
    default: *out = g_grid; return 1;
    }
}

static sdfccd_RigidMotion fz_motion(fuzz_in* in)
{
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    if (fz_u8(in) & 1) m.pose = fz_pose(in);
    m.local_center = fz_vec(in);
    m.linear_velocity = fz_vec(in);
    m.angular_velocity = fz_vec(in);
    return m;
}

static void fz_params(fuzz_in* in, sdfccd_QueryParams* p)
{
    *p = sdfccd_default_query_params();
    uint8_t mask = fz_u8(in); /* which groups of fields keep their defaults */
    p->method = (sdfccd_Method)(fz_u8(in) % (SDFCCD_METHOD_COUNT + 1));
    if (mask & 1) {
        p->margin = fz_double(in);
        p->time_tolerance = fz_double(in);
        p->distance_tolerance = fz_double(in);
    }
    if (mask & 2) {
        p->max_iterations = fz_int(in, 0, 200);
        p->max_line_search_iterations = fz_int(in, 0, 200);
        p->fwgss_restarts = fz_int(in, -1, 3);
        p->fwgss_vertex_trace = fz_int(in, -1, 200);
    }
    if (mask & 4) {
        p->subdivision = fz_int(in, 0, 1);
        p->subdivision_min_area = fz_double(in);
        p->subdivision_max_depth = fz_int(in, 0, 33);
        p->contact_slop = fz_double(in);
        p->toi_window = fz_double(in);
    }
    if (mask & 8) {
        p->max_rotation_per_segment = fz_double(in);
        p->certified_time_tolerance = fz_double(in);
        p->certified_max_regions = fz_int(in, 0, 100000);
    }
    if (mask & 16) p->broad_phase = fz_int(in, 0, 1);
    if (!(mask & 32)) { /* with bit 32 set the default budget stays */
        /* log-uniform up to the default, so most inputs run fast */
        const int e = fz_u8(in) % 25;
        const uint32_t b = fz_u32(in);
        p->max_sdf_evaluations = b == 0xFFFFFFFFu ? -1 : (int64_t)(b % (1u << e));
        if (p->max_sdf_evaluations > SDFCCD_DEFAULT_MAX_SDF_EVALUATIONS) p->max_sdf_evaluations = SDFCCD_DEFAULT_MAX_SDF_EVALUATIONS;
    }
    if (mask & 64) p->internal_value = (int32_t)fz_u32(in);
    if (mask & 128) { /* log-uniform, from -1 (refused) up to 2 GiB */
        const int e = fz_u8(in) % 32;
        p->certified_max_bytes = (int64_t)(fz_u32(in) % (1u << e)) - 1;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    fuzz_in in = { data, size };
    made m = { { { 0, 0 } }, 0 };
    wobble w = { 1, 0, 0 };
    sdfccd_SdfId sdf;
    if (!make_sdf(&in, &m, &w, &sdf)) goto done;
    sdfccd_QueryParams p;
    fz_params(&in, &p);
    const int entry = fz_u8(&in) % 4;
    const int moving_sdf = fz_u8(&in) & 1;
    sdfccd_RigidMotion sm = fz_motion(&in), bm = fz_motion(&in);
    double t0 = fz_double(&in), t1 = fz_double(&in);
    sdfccd_Vec3 tri[3], tri_end[3];
    for (int i = 0; i < 3; ++i) tri[i] = fz_vec(&in);
    for (int i = 0; i < 3; ++i) tri_end[i] = fz_vec(&in);
    sdfccd_Vec3 start[4], end[4];
    for (int i = 0; i < 4; ++i) start[i] = fz_vec(&in);
    for (int i = 0; i < 4; ++i) end[i] = fz_vec(&in);
    const int32_t capacity = fz_u8(&in) % 10;
    /* The FWGSS switches, read last so that older corpus inputs keep their meaning (an exhausted
     * input reads 0: every switch at its default). Bit k flips switch k; bit 7 also fuzzes the
     * clear proof's budget and the gap tolerance. */
    const uint8_t flips = fz_u8(&in);
    if (flips & 1) p.fwgss_secant_entry = !p.fwgss_secant_entry;
    if (flips & 2) p.fwgss_speed_tolerance = !p.fwgss_speed_tolerance;
    if (flips & 4) p.fwgss_brent_spatial = !p.fwgss_brent_spatial;
    if (flips & 8) p.fwgss_derivative_spatial = !p.fwgss_derivative_spatial;
    if (flips & 16) p.fwgss_restart_at_witness = !p.fwgss_restart_at_witness;
    if (flips & 32) p.fwgss_kink_guard = !p.fwgss_kink_guard;
    if (flips & 128) {
        p.fwgss_clear_proof = fz_int(&in, -1, 300);
        p.fwgss_gap_tolerance = fz_double(&in);
    }

    sdfccd_Contact c[2][16];
    sdfccd_QueryResult r[2];
    sdfccd_Status st[2];
    for (int k = 0; k < 2; ++k) {
        memset(c[k], 0x5A, sizeof c[k]);
        memset(&r[k], 0x5A, sizeof r[k]);
        const sdfccd_RigidMotion* smp = moving_sdf ? &sm : NULL;
        double t = fz_now();
        switch (entry) {
        case 0: st[k] = sdfccd_query_triangle(sdf, smp, tri, &bm, t0, t1, &p, c[k], capacity, &r[k]); break;
        case 1: st[k] = sdfccd_query_triangle_linear(sdf, smp, tri, tri_end, t0, t1, &p, c[k], capacity, &r[k]); break;
        case 2: st[k] = sdfccd_query_mesh(sdf, smp, g_mesh, &bm, t0, t1, &p, c[k], capacity, &r[k]); break;
        default: st[k] = sdfccd_query_mesh_linear(sdf, smp, g_mesh, start, end, t0, t1, &p, c[k], capacity, &r[k]); break;
        }
        t = fz_now() - t;
        fz_note_time(t, st[k] == SDFCCD_OK ? r[k].sdf_evaluations : 0);
        if (getenv("SDFCCD_FUZZ_VERBOSE"))
            fprintf(stderr, "entry %d method %d status %s (%s) state %d evals %lld budget %lld time %.3f s\n", entry, (int)p.method,
                    sdfccd_status_string(st[k]), st[k] ? sdfccd_last_error() : "", st[k] ? -1 : (int)r[k].state,
                    st[k] ? 0LL : (long long)r[k].sdf_evaluations, (long long)p.max_sdf_evaluations, t);
        if (st[k] == SDFCCD_OK) fz_check_result(&r[k], c[k], capacity, t0, t1, &p);
        else FZ_CHECK(st[k] > 0 && st[k] < SDFCCD_STATUS_COUNT && sdfccd_last_error()[0], "status %d without a message", (int)st[k]);
    }
    FZ_CHECK(st[0] == st[1], "status differs between two identical queries: %d %d", (int)st[0], (int)st[1]);
    if (st[0] == SDFCCD_OK) {
        FZ_CHECK(!memcmp(&r[0], &r[1], sizeof r[0]), "results of two identical queries differ");
        FZ_CHECK(!memcmp(c[0], c[1], sizeof c[0]), "contacts of two identical queries differ");
    }
done:
    for (int i = m.n - 1; i >= 0; --i) sdfccd_destroy_sdf(m.ids[i]);
    FZ_CHECK(sdfccd_byte_count() == g_bytes, "%lld bytes still allocated after the input (%lld before)",
             (long long)sdfccd_byte_count(), (long long)g_bytes);
    return 0;
}
