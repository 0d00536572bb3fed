/* SPDX-License-Identifier: MIT
 * sdfccd_bench: the evaluation experiments (issues 4 and 9). Each experiment prints one CSV table
 * on stdout (progress on stderr); sdfccd_bench_report turns a directory of them into report.md
 * (scripts/bench_report.sh runs the whole chain). Public ABI only.
 *
 *   sdfccd_bench list                      the experiments
 *   sdfccd_bench NAME [options] > NAME.csv run one
 * Options: --dataset DIR (data set cache, default samples/report/dataset), --quick (64 cases per
 * mesh, fewer repeats), --smoke (4 cases per mesh, for ctest), --baseline (also run the previous
 * FWGSS defaults, interleaved, in experiments that compare configurations), --threads N (batch).
 * Seeded: the same command gives the same cases and accuracy figures; timings vary with the
 * machine and its load (the machine this runs on is shared, so compare configurations measured in
 * the same run, and prefer SDF-evaluation counts). */
#include "bench/bench_common.h"
#include "bench/bench_kinds.h"

/* ------------------------------------------------------------------ configurations */

typedef struct options {
    const char* dataset_dir;
    int quick;     /* 0 full, 1 quick, 2 smoke */
    int baseline;
    int threads;
} options;

/* FWGSS configurations compared by the experiments: today's defaults, the previous defaults
 * (before issue 9's parameters: golden-section entry search, fixed spatial tolerance, no clear
 * proof, no gap tolerance, golden-section spatial searches, restarts from t0; the closed-form motion, the interior spatial step, the shared and
 * refined vertex traces and the start at the broad phase's candidate time are not switchable), and the paper's
 * configuration (no vertex trace, no restarts). */
typedef enum fw_config { CFG_NEW, CFG_BASELINE, CFG_PAPER, CFG_COUNT } fw_config;
static const char* k_cfg_name[CFG_COUNT] = { "new", "baseline", "paper" };

static sdfccd_QueryParams config_params(fw_config c, int subdivision)
{
    sdfccd_QueryParams p = sdfccd_default_query_params();
    p.subdivision = subdivision;
    if (c == CFG_BASELINE || c == CFG_PAPER) {
        p.fwgss_secant_entry = 0;
        p.fwgss_speed_tolerance = 0;
        p.fwgss_clear_proof = 0;
        p.fwgss_gap_tolerance = 0.0;
        p.fwgss_derivative_spatial = 0;
        p.fwgss_restart_at_witness = 0;
    }
    if (c == CFG_PAPER) {
        p.fwgss_vertex_trace = 0;
        p.fwgss_restarts = 0;
    }
    return p;
}

static sdfccd_QueryParams method_params(sdfccd_Method m, int subdivision)
{
    sdfccd_QueryParams p = sdfccd_default_query_params();
    p.method = m;
    p.subdivision = subdivision;
    return p;
}

static int n_configs(const options* o) { return o->baseline ? CFG_COUNT : 1; }

/* ------------------------------------------------------------------ experiments */

static void exp_dataset(const options* o)
{
    dataset ds;
    build_dataset(o->dataset_dir, &ds, o->quick);
    printf("mesh,triangles,cases,rejected,mean_regions,mean_ground_truth_ms,seed\n");
    for (int k = 0; k < 2; ++k) {
        double reg = 0, us = 0;
        for (int i = 0; i < ds.n_per_mesh; ++i) {
            reg += (double)ds.c[k * ds.n_per_mesh + i].gt_regions;
            us += ds.c[k * ds.n_per_mesh + i].gt_us;
        }
        printf("%s,%u,%d,%d,%.0f,%.2f,%u\n", k_mesh_name[k], ds.mesh[k].nt, ds.n_per_mesh, ds.rejected[k], reg / ds.n_per_mesh,
               us / ds.n_per_mesh * 1e-3, SEED);
    }
    free_dataset(&ds);
}

static void exp_brute(const options* o)
{
    dataset ds;
    build_dataset(o->dataset_dir, &ds, o->quick);
    int nb = o->quick >= 2 ? 1 : (o->quick ? 8 : 128);
    printf("id,certified_lower,certified_toi,brute_force_toi,difference,queries\n");
    for (int k = 0; k < 2; ++k)
        for (int i = 0; i < nb; ++i) {
            const bcase* c = &ds.c[k * ds.n_per_mesh + i];
            long long q = 0;
            double t = brute_force(&ds, c, &q);
            printf("%s,%.17g,%.17g,%.17g,%.6g,%lld\n", c->id, c->gt_lower, c->gt_toi, t, isfinite(t) ? t - c->gt_toi : NAN, q);
        }
    free_dataset(&ds);
}

/* Every method on every case, one row per case (Tables 1 and 2). */
static void exp_accuracy(const options* o)
{
    dataset ds;
    build_dataset(o->dataset_dir, &ds, o->quick);
    struct { const char* name; sdfccd_QueryParams p; } m[6] = {
        { "DCD", method_params(SDFCCD_METHOD_DCD, 0) },
        { "FW", method_params(SDFCCD_METHOD_FW, 0) },
        { "FWGSS", config_params(CFG_NEW, 0) },
        { "FWGSS+subdivision", config_params(CFG_NEW, 1) },
        { "FWGSS-baseline", config_params(CFG_BASELINE, 0) },
        { "FWGSS-paper", config_params(CFG_PAPER, 0) },
    };
    int nm = o->baseline ? 6 : 4;
    int n = ds.n_per_mesh;
    run_result* rr = calloc((size_t)ds.n, sizeof *rr);
    printf("method,id,mesh,hit,state,toi,gt_hit,gt_lower,gt_toi,speed,micros,sdf_evals,triangles_tested,contacts\n");
    for (int k = 0; k < nm; ++k) {
        progress("accuracy: %s on %d cases", m[k].name, ds.n);
        run_method(&ds, &m[k].p, 0, n, rr);
        for (int i = 0; i < ds.n; ++i) {
            const bcase* c = &ds.c[i];
            const run_result* r = &rr[i];
            sdfccd_Vec3 v = c->m.linear_velocity;
            printf("%s,%s,%s,%d,%d,%.17g,%d,%.17g,%.17g,%.6g,%.2f,%lld,%lld,%d\n", m[k].name, c->id, k_mesh_name[c->mesh], r->hit, r->state,
                   r->toi, c->gt_hit, c->gt_lower, c->gt_toi, sqrt(v.x * v.x + v.y * v.y + v.z * v.z), r->us, r->evals, r->tested, r->contacts);
        }
    }
    free(rr);
    free_dataset(&ds);
}

/* Speed versus accuracy: every method's caps and tolerances swept, plus the FWGSS configurations
 * (today's defaults, the previous defaults, the paper's), on the first cases of each mesh. */
static void exp_front(const options* o)
{
    dataset ds;
    build_dataset(o->dataset_dir, &ds, o->quick);
    int ns = o->quick >= 2 ? 2 : (o->quick ? 32 : 512);
    if (ns > ds.n_per_mesh) ns = ds.n_per_mesh;
    struct sweep { const char* method; char setting[64]; sdfccd_QueryParams p; } sw[48];
    int n = 0;
    const int caps[6] = { 2, 4, 8, 16, 32, 64 };
    const char* names[3] = { "DCD", "FW", "FWGSS-paper" };
    for (int m = 0; m < 3; ++m)
        for (int i = 0; i < 6; ++i) {
            sw[n].method = names[m];
            sw[n].p = m == 0 ? method_params(SDFCCD_METHOD_DCD, 0) : (m == 1 ? method_params(SDFCCD_METHOD_FW, 0) : config_params(CFG_PAPER, 0));
            sw[n].p.max_iterations = caps[i];
            sw[n].p.max_line_search_iterations = 2 * caps[i];
            snprintf(sw[n].setting, sizeof sw[n].setting, "iter=%d ls=%d", caps[i], 2 * caps[i]);
            ++n;
        }
    /* FWGSS (today's algorithm): the vertex trace and restarts swept at the default caps */
    const int trace[4] = { 0, 8, 16, 64 };
    for (int r = 0; r <= 2; ++r)
        for (int i = 0; i < 4; ++i) {
            sw[n].method = "FWGSS";
            sw[n].p = config_params(CFG_NEW, 0);
            sw[n].p.fwgss_restarts = r;
            sw[n].p.fwgss_vertex_trace = trace[i];
            snprintf(sw[n].setting, sizeof sw[n].setting, "restarts=%d trace=%d", r, trace[i]);
            ++n;
        }
    for (int c = 0; c < CFG_COUNT; ++c) {
        sw[n].method = c == CFG_NEW ? "FWGSS-defaults" : (c == CFG_BASELINE ? "FWGSS-previous-defaults" : "FWGSS-paper-config");
        sw[n].p = config_params((fw_config)c, 0);
        snprintf(sw[n].setting, sizeof sw[n].setting, "%s", k_cfg_name[c]);
        ++n;
    }
    const double ctol[4] = { 1e-3, 1e-4, 1e-5, 1e-6 };
    for (int i = 0; i < 4; ++i) {
        sw[n].method = "Certified";
        sw[n].p = certified_params();
        sw[n].p.certified_time_tolerance = ctol[i];
        snprintf(sw[n].setting, sizeof sw[n].setting, "tol=%.0e", ctol[i]);
        ++n;
    }
    run_result* rr = calloc((size_t)(2 * ns), sizeof *rr);
    printf("method,setting,cases,mean_us,fn_rate,fp_rate,mean_abs_dtoi,sdf_evals\n");
    for (int s = 0; s < n; ++s) {
        progress("front: %s %s", sw[s].method, sw[s].setting);
        run_method(&ds, &sw[s].p, 0, ns, rr);
        acc_summary a = summarise(&ds, rr, 0, ns, -1);
        printf("%s,%s,%d,%.4g,%.6g,%.6g,%.6g,%.1f\n", sw[s].method, sw[s].setting, 2 * ns, a.mean_us, a.fn_rate, a.fp_rate, a.mean_abs_dtoi,
               a.evals);
    }
    free(rr);
    free_dataset(&ds);
}

/* The issue-9 targets: the data set's triangle and shuriken through the mesh query (broad phase on,
 * subdivision off) and the triangle against a 32^3 grid of the torus; every configuration on every
 * case, interleaved, R repeats; per case the fastest repeat. */
static void exp_targets(const options* o)
{
    dataset ds;
    build_dataset(o->dataset_dir, &ds, o->quick);
    sdfccd_SdfId grid;
    sdfccd_GridDef gd = sdfccd_default_grid_def();
    gd.resolution[0] = gd.resolution[1] = gd.resolution[2] = 32; /* the default: fitted to the torus's box */
    CHECK(sdfccd_create_grid_from_sdf(ds.torus, &gd, &grid));
    int R = o->quick >= 2 ? 1 : (o->quick ? 3 : 5);
    int nc = n_configs(o);
    sdfccd_Workspace* ws;
    CHECK(sdfccd_create_workspace(&ws));
    sdfccd_Contact contacts[64];
    printf("scene,config,cases,mean_us,median_us,sdf_evals_per_query,fn,fp,mean_abs_dtoi,repeats\n");
    for (int scene = 0; scene < 3; ++scene) {
        int mesh = scene == 1;
        sdfccd_SdfId sdf = scene == 2 ? grid : ds.torus;
        int n = ds.n_per_mesh;
        double* best = malloc((size_t)(nc * n) * sizeof *best);
        run_result* rr = calloc((size_t)(nc * n), sizeof *rr);
        for (int i = 0; i < nc * n; ++i) best[i] = INFINITY;
        sdfccd_QueryParams p[CFG_COUNT];
        for (int c = 0; c < nc; ++c) p[c] = config_params((fw_config)c, 0);
        for (int r = 0; r < R; ++r)
            for (int i = 0; i < n; ++i)
                for (int c = 0; c < nc; ++c) {
                    const bcase* bc = &ds.c[mesh * n + i];
                    sdfccd_QueryResult res;
                    double t0 = now_us();
                    CHECK(sdfccd_query_mesh_ws(ws, sdf, NULL, ds.mid[mesh], &bc->m, 0.0, DT, &p[c], contacts, 64, &res));
                    double us = now_us() - t0;
                    run_result* o2 = &rr[c * n + i];
                    if (us < best[c * n + i]) best[c * n + i] = us;
                    o2->hit = res.hit;
                    o2->state = (int)res.state;
                    o2->toi = res.toi;
                    o2->evals = (long long)res.sdf_evaluations;
                    o2->tested = (long long)res.triangles_tested;
                }
        const char* names[3] = { "triangle", "shuriken", "triangle-grid32" };
        for (int c = 0; c < nc; ++c) {
            /* summarise() takes both meshes' rows: put this scene's rows in place */
            run_result* full = calloc((size_t)ds.n, sizeof *full);
            for (int i = 0; i < n; ++i) {
                full[mesh * n + i] = rr[c * n + i];
                full[mesh * n + i].us = best[c * n + i];
            }
            acc_summary a = summarise(&ds, full, 0, n, mesh);
            /* the grid approximates the torus: its misses against the torus's certified TOI are not the solver's */
            if (scene == 2) printf("%s,%s,%d,%.3f,%.3f,%.1f,,,,%d\n", names[scene], k_cfg_name[c], n, a.mean_us, a.median_us, a.evals, R);
            else
                printf("%s,%s,%d,%.3f,%.3f,%.1f,%d,%d,%.4g,%d\n", names[scene], k_cfg_name[c], n, a.mean_us, a.median_us, a.evals, a.fn, a.fp,
                       a.mean_abs_dtoi, R);
            free(full);
        }
        free(best);
        free(rr);
    }
    sdfccd_destroy_workspace(ws);
    sdfccd_destroy_sdf(grid);
    free_dataset(&ds);
}

/* ---- the scaling scene (Table 3): the armadillo falling onto the spike grid ---- */

static sdfccd_Quat quat_mul(sdfccd_Quat a, sdfccd_Quat b)
{
    return (sdfccd_Quat){ a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w };
}
static sdfccd_Vec3 quat_rotate(sdfccd_Quat q, sdfccd_Vec3 v)
{
    sdfccd_Quat p = { 0, v.x, v.y, v.z }, c = { q.w, -q.x, -q.y, -q.z };
    sdfccd_Quat r = quat_mul(quat_mul(q, p), c);
    return (sdfccd_Vec3){ r.x, r.y, r.z };
}

typedef struct fall_result {
    double total_ms;
    int steps, hit;
    double toi, toi_lower;
    long long tested, evals;
} fall_result;

/* The armadillo (lowest point 5 cm above the spike tips, 2 m/s down, gravity, slow spin about
 * its box centre) stepped at 1/60 s until the first step with a contact. Between steps the pose
 * advances by the motion model (centre moves, body spins about it) and gravity changes v. */
static fall_result fall(sdfccd_SdfId spikes, sdfccd_MeshId mesh, const double lo[3], const double hi[3], const sdfccd_QueryParams* p,
                        sdfccd_Workspace* ws)
{
    fall_result fr;
    memset(&fr, 0, sizeof fr);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.local_center = (sdfccd_Vec3){ 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]) };
    m.pose.position = (sdfccd_Vec3){ 0.013, -0.021, 0.1 + 0.05 - lo[2] };
    m.linear_velocity = (sdfccd_Vec3){ 0, 0, -2.0 };
    m.angular_velocity = (sdfccd_Vec3){ 0.3, 0.2, 1.0 };
    sdfccd_Contact out[64];
    double t = 0.0;
    for (int step = 0; step < 120; ++step) {
        sdfccd_QueryResult r;
        double t0 = now_us();
        CHECK(sdfccd_query_mesh_ws(ws, spikes, NULL, mesh, &m, t, t + DT, p, out, 64, &r));
        fr.total_ms += (now_us() - t0) * 1e-3;
        fr.tested += (long long)r.triangles_tested;
        fr.evals += (long long)r.sdf_evaluations;
        fr.steps = step + 1;
        if (r.hit) {
            fr.hit = 1;
            fr.toi = r.toi;
            fr.toi_lower = r.toi_lower;
            break;
        }
        /* g(t + DT) = g + v DT; R(t + DT) = exp(w DT) R; the origin follows from the centre */
        sdfccd_Vec3 w = m.angular_velocity;
        double a = sqrt(w.x * w.x + w.y * w.y + w.z * w.z) * DT, s = a > 0 ? sin(0.5 * a) / (a / DT) : 0.5 * DT;
        sdfccd_Quat dq = { cos(0.5 * a), w.x * s, w.y * s, w.z * s };
        sdfccd_Vec3 c0 = quat_rotate(m.pose.orientation, m.local_center);
        sdfccd_Vec3 g = { m.pose.position.x + c0.x + m.linear_velocity.x * DT, m.pose.position.y + c0.y + m.linear_velocity.y * DT,
                          m.pose.position.z + c0.z + m.linear_velocity.z * DT };
        m.pose.orientation = quat_mul(dq, m.pose.orientation);
        sdfccd_Vec3 c1 = quat_rotate(m.pose.orientation, m.local_center);
        m.pose.position = (sdfccd_Vec3){ g.x - c1.x, g.y - c1.y, g.z - c1.z };
        m.linear_velocity.z -= 9.81 * DT;
        t += DT;
    }
    return fr;
}

static void exp_scaling(const options* o)
{
    sdfccd_MeshId src_id;
    sdfccd_Status st = sdfccd_load_mesh(SDFCCD_BENCH_DATA_DIR "/libigl-tutorial-data/armadillo.obj", NULL, &src_id);
    if (st != SDFCCD_OK) die("loading the armadillo");
    mesh_data src;
    mesh_from_handle(src_id, &src);
    sdfccd_destroy_mesh(src_id);
    for (uint32_t i = 0; i < src.nv; ++i) { /* y up -> z up */
        double y = src.v[3 * i + 1], z = src.v[3 * i + 2];
        src.v[3 * i + 1] = -z;
        src.v[3 * i + 2] = y;
    }
    int levels = o->quick >= 2 ? 1 : 3;
    mesh_data lv[3], m25;
    simplify_to(&src, 1000, &lv[0]);
    if (levels > 1) {
        simplify_to(&src, 10000, &lv[1]);
        simplify_to(&src, 25000, &m25);
        subdivide4(&m25, &lv[2]);
        mesh_free(&m25);
    }
    sdfccd_SpikeGridDef sd = sdfccd_default_spike_grid_def();
    sdfccd_SdfId spikes;
    CHECK(sdfccd_create_spike_grid(&sd, &spikes));
    sdfccd_Workspace* ws;
    CHECK(sdfccd_create_workspace(&ws));
    int R = o->quick ? 2 : 7;
    printf("triangles,method,broad_phase,repeat,total_ms,steps,toi,toi_lower,tested,sdf_evals\n");
    for (int L = 0; L < levels; ++L) {
        sdfccd_MeshId mesh = mesh_create(&lv[L]);
        sdfccd_MeshInfo info;
        CHECK(sdfccd_mesh_get_info(mesh, &info));
        double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
        for (uint32_t i = 0; i < lv[L].nv; ++i)
            for (int k = 0; k < 3; ++k) {
                lo[k] = fmin(lo[k], lv[L].v[3 * i + k]);
                hi[k] = fmax(hi[k], lv[L].v[3 * i + k]);
            }
        /* SDFCCD_BENCH_SCALING_LEVEL=0|1|2: that mesh size alone (1K, 10K, 100K; a short run for profiling) */
        if (getenv("SDFCCD_BENCH_SCALING_LEVEL") && L != atoi(getenv("SDFCCD_BENCH_SCALING_LEVEL"))) continue;
        /* the certified bracket of the scene, once */
        /* SDFCCD_BENCH_SCALING_METHOD=NAME: that configuration alone (e.g. for callgrind's instruction counts) */
        const char* only = getenv("SDFCCD_BENCH_SCALING_METHOD");
        if (!only || !strcmp(only, "Certified")) {
            sdfccd_QueryParams pc = certified_params();
            fall_result c = fall(spikes, mesh, lo, hi, &pc, ws);
            printf("%u,Certified,1,0,%.4f,%d,%.12g,%.12g,%lld,%lld\n", info.triangle_count, c.total_ms, c.steps, c.toi, c.toi_lower, c.tested, c.evals);
        }
        struct { const char* name; sdfccd_QueryParams p; } m[5] = {
            { "DCD", method_params(SDFCCD_METHOD_DCD, 1) },
            { "FWGSS", config_params(CFG_NEW, 1) },
            { "FWGSS-no-check", config_params(CFG_NEW, 1) },
            { "FWGSS-baseline", config_params(CFG_BASELINE, 1) },
            { "FWGSS-paper", config_params(CFG_PAPER, 1) },
        };
        m[2].p.fwgss_verify = 0; /* the defaults without the certified check of the answer (the Bullet bridge's setting) */
        int nm = o->baseline ? 5 : 3;
        for (int bp = 1; bp >= 0; --bp) {
            if (!bp && (L == 2 || o->quick)) continue; /* without the hierarchy 100K takes seconds per repeat */
            int reps = bp ? R : (R > 3 ? 3 : R);
            for (int r = 0; r < reps; ++r)
                for (int k = 0; k < nm; ++k) { /* interleaved: the configurations see the same load */
                    if (only && strcmp(only, m[k].name)) continue;
                    sdfccd_QueryParams p = m[k].p;
                    p.broad_phase = bp;
                    p.max_sdf_evaluations = INT64_MAX; /* the brute-force rows (17M evaluations at 100K) are measured whole */
                    fall_result f = fall(spikes, mesh, lo, hi, &p, ws);
                    printf("%u,%s,%d,%d,%.4f,%d,%.12g,%.12g,%lld,%lld\n", info.triangle_count, m[k].name, bp, r, f.total_ms, f.steps, f.toi,
                           f.toi_lower, f.tested, f.evals);
                    fflush(stdout);
                }
        }
        progress("scaling: %u triangles done", info.triangle_count);
        sdfccd_destroy_mesh(mesh);
        mesh_free(&lv[L]);
    }
    sdfccd_destroy_workspace(ws);
    sdfccd_destroy_sdf(spikes);
    mesh_free(&src);
}

/* The data set (both meshes) as one sdfccd_query_batch on 1 and on N threads, interleaved repeats;
 * `identical` checks the results against the single-thread batch bit for bit. */
static void exp_batch(const options* o)
{
    dataset ds;
    build_dataset(o->dataset_dir, &ds, o->quick);
    int n = ds.n, threads = o->threads > 1 ? o->threads : 2;
    sdfccd_QueryParams p = config_params(CFG_NEW, 0);
    sdfccd_BatchQuery* q = calloc((size_t)n, sizeof *q);
    sdfccd_QueryResult* r1 = calloc((size_t)n, sizeof *r1);
    sdfccd_QueryResult* rn = calloc((size_t)n, sizeof *rn);
    sdfccd_Contact* c = calloc((size_t)n * 8, sizeof *c);
    int R = o->quick >= 2 ? 1 : 5;
    printf("threads,repeat,queries,wall_ms,identical\n");
    for (int rep = 0; rep < R; ++rep)
        for (int pass = 0; pass < 2; ++pass) {
            int th = pass == 0 ? 1 : threads;
            sdfccd_QueryResult* out = pass == 0 ? r1 : rn;
            for (int i = 0; i < n; ++i) {
                memset(&q[i], 0, sizeof q[i]);
                q[i].kind = SDFCCD_BATCH_MESH;
                q[i].sdf = ds.torus;
                q[i].mesh = ds.mid[ds.c[i].mesh];
                q[i].motion = &ds.c[i].m;
                q[i].t0 = 0.0;
                q[i].t1 = DT;
                q[i].params = &p;
                q[i].out_contacts = c + 8 * i;
                q[i].capacity = 8;
                q[i].out_result = &out[i];
            }
            double t0 = now_us();
            CHECK(sdfccd_query_batch(q, n, th));
            double ms = (now_us() - t0) * 1e-3;
            int same = pass == 0 || memcmp(r1, rn, (size_t)n * sizeof *r1) == 0;
            printf("%d,%d,%d,%.3f,%d\n", th, rep, n, ms, same);
            fflush(stdout);
        }
    free(q);
    free(r1);
    free(rn);
    free(c);
    free_dataset(&ds);
}

/* Cost per SDF evaluation inside a query, split by a differential measurement through the public
 * ABI: the torus as a user (callback) SDF that evaluates the field `repeat` times per call. The
 * query time grows by (repeat - 1) x evaluations x field cost, which gives the field's cost; the
 * rest of the time per evaluation is the motion, the solver and the dispatch. The five evaluations
 * of one call are independent, so that difference is the field's throughput; a third variant chains
 * them (each one's point depends on the one before's value), which gives the field's latency, as the
 * solver sees it (each sample waits for the one before). Each is run with the callback in both of
 * its forms (sdfccd_CallbackSdfDef::eval, the point as an sdfccd_Vec3, and ::eval_xyz, the point as
 * three coordinates), beside the built-in torus.
 * SDFCCD_BENCH_MESH=triangle|shuriken runs one mesh only; SDFCCD_BENCH_COST_ONLY=K runs one pass of
 * variant K only (k_cost_variant's order: for callgrind). */
typedef struct torus_cb { int repeat; } torus_cb;

/* The torus at (px, y, z), px passed through an empty asm statement that may change it, which
 * keeps the compiler from folding the repeats (no instruction; the volatile variable used before
 * stored and reloaded the point, a store-to-load round trip in the chain of every call). */
static inline double torus_at(double px, double y, double z, sdfccd_Vec3* g)
{
#if defined(__GNUC__) || defined(__clang__)
    __asm__ volatile("" : "+x"(px));
#else
    volatile double pv = px;
    px = pv;
#endif
    double q = sqrt(px * px + y * y);
    double dx = q - 0.1, d = sqrt(dx * dx + z * z);
    if (g) {
        double s = d > 0 ? 1.0 / d : 0.0, r = q > 0 ? dx / q : 0.0;
        *g = (sdfccd_Vec3){ px * r * s, y * r * s, z * s };
    }
    return d - 0.05;
}

/* `repeat` independent evaluations (the processor overlaps them: the field's throughput). */
static double torus_eval(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    const torus_cb* t = user;
    double phi = 0.0;
    for (int k = 0; k < t->repeat; ++k) phi = torus_at(p.x, p.y, p.z, g);
    return phi;
}

/* `repeat` chained evaluations: each one's point depends on the one before's value (x + 0 * phi, one
 * multiply and one add more in the chain), as a solver's next sample does (the field's latency). */
static double torus_eval_chained(sdfccd_Vec3 p, sdfccd_Vec3* g, void* user)
{
    const torus_cb* t = user;
    double phi = 0.0;
    for (int k = 0; k < t->repeat; ++k) phi = torus_at(p.x + 0.0 * phi, p.y, p.z, g);
    return phi;
}

/* The same two with the point as three coordinates (sdfccd_SdfEvalXyzFcn). */
static double torus_eval_xyz(double x, double y, double z, sdfccd_Vec3* g, void* user)
{
    const torus_cb* t = user;
    double phi = 0.0;
    for (int k = 0; k < t->repeat; ++k) phi = torus_at(x, y, z, g);
    return phi;
}

static double torus_eval_xyz_chained(double x, double y, double z, sdfccd_Vec3* g, void* user)
{
    const torus_cb* t = user;
    double phi = 0.0;
    for (int k = 0; k < t->repeat; ++k) phi = torus_at(x + 0.0 * phi, y, z, g);
    return phi;
}

/* The calling thread's CPU time (us): unlike the wall clock, not inflated while other processes
 * hold the CPU. The cost experiment's clock (SDFCCD_BENCH_CPU_TIME=0: the wall clock). */
static double thread_cpu_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e6 + ts.tv_nsec * 1e-3;
}

/* The cost experiment's variants: the field called `repeat` times per evaluation, chained or not, in
 * one of the callback's two forms; form -1 is the built-in torus. */
typedef struct cost_variant { int form, repeat, chained; } cost_variant;
static const cost_variant k_cost_variant[7] = { { 0, 1, 0 }, { 0, 5, 0 }, { -1, 1, 0 }, { 0, 5, 1 }, { 1, 1, 0 }, { 1, 5, 0 }, { 1, 5, 1 } };
static const char* const k_cost_form[2] = { "eval", "eval_xyz" };

static void exp_cost(const options* o)
{
    double (*clock_us)(void) = getenv("SDFCCD_BENCH_CPU_TIME") && !atoi(getenv("SDFCCD_BENCH_CPU_TIME")) ? now_us : thread_cpu_us;
    dataset ds;
    build_dataset(o->dataset_dir, &ds, o->quick);
    sdfccd_Workspace* ws;
    CHECK(sdfccd_create_workspace(&ws));
    sdfccd_QueryParams p = config_params(CFG_NEW, 0);
    sdfccd_Contact contacts[16];
    enum { NV = 7 };
    torus_cb cb[NV];
    sdfccd_SdfId sdf[NV];
    for (int k = 0; k < NV; ++k) {
        const cost_variant* v = &k_cost_variant[k];
        cb[k].repeat = v->repeat;
        if (v->form < 0) {
            sdf[k] = ds.torus;
            continue;
        }
        sdfccd_CallbackSdfDef d = sdfccd_default_callback_sdf_def();
        if (v->form == 0) d.eval = v->chained ? torus_eval_chained : torus_eval;
        else d.eval_xyz = v->chained ? torus_eval_xyz_chained : torus_eval_xyz;
        d.user = &cb[k];
        d.bounds = (sdfccd_Aabb){ { -0.15, -0.15, -0.05 }, { 0.15, 0.15, 0.05 } };
        d.smooth = 1; /* as the built-in torus: no kink guard, no certified check */
        CHECK(sdfccd_create_callback_sdf(&d, &sdf[k]));
    }
    const int only_k = getenv("SDFCCD_BENCH_COST_ONLY") ? atoi(getenv("SDFCCD_BENCH_COST_ONLY")) : -1;
    int R = o->quick >= 2 || only_k >= 0 ? 1 : (o->quick ? 5 : 15); /* the fastest of the repeats: more of them find a quieter moment on a shared machine */
    printf("mesh,callback,queries,evals_per_query,ns_per_evaluation,ns_field,ns_motion_solver_dispatch,ns_per_evaluation_builtin_torus,"
           "ns_field_latency,ns_rest_after_field_latency\n");
    const char* only = getenv("SDFCCD_BENCH_MESH"); /* one mesh only (a shorter run) */
    for (int mesh = 0; mesh < 2; ++mesh) {
        if (only && strcmp(only, k_mesh_name[mesh]) != 0) continue;
        int n = ds.n_per_mesh;
        double best[NV];
        for (int k = 0; k < NV; ++k) best[k] = INFINITY;
        long long evals = 0;
        for (int rep = 0; rep < R; ++rep)
            for (int k = 0; k < NV; ++k) { /* interleaved, so that every variant meets the same moments of a shared machine */
                if (only_k >= 0 && k != only_k) continue;
                long long e = 0;
                double t0 = clock_us();
                for (int i = 0; i < n; ++i) {
                    sdfccd_QueryResult res;
                    CHECK(sdfccd_query_mesh_ws(ws, sdf[k], NULL, ds.mid[mesh], &ds.c[mesh * n + i].m, 0.0, DT, &p, contacts, 16, &res));
                    e += (long long)res.sdf_evaluations;
                }
                best[k] = fmin(best[k], clock_us() - t0);
                if (k == 0) evals = e;
            }
        for (int form = 0; form < 2; ++form) {
            const double one = form == 0 ? best[0] : best[4], five = form == 0 ? best[1] : best[5], chained = form == 0 ? best[3] : best[6];
            double per = one * 1e3 / (double)evals, field = (five - one) * 1e3 / (4.0 * (double)evals);
            double latency = (chained - one) * 1e3 / (4.0 * (double)evals);
            printf("%s,%s,%d,%.1f,%.1f,%.1f,%.1f,%.1f,%.1f,%.1f\n", k_mesh_name[mesh], k_cost_form[form], n, (double)evals / n, per, field,
                   per - field, best[2] * 1e3 / (double)evals, latency, per - latency);
        }
    }
    for (int k = 0; k < NV; ++k)
        if (k_cost_variant[k].form >= 0) sdfccd_destroy_sdf(sdf[k]);
    sdfccd_destroy_workspace(ws);
    free_dataset(&ds);
}

/* ---- the floor of a dependent sample (issue 20 item 4) ---- */

/* The rotation's sine and cosine about a base angle, by a Taylor series in d^2 (Estrin's scheme for
 * the eight highest terms, then Horner's), the same depth of arithmetic as the solver's per new time. */
static inline void chain_sincos(double d, double* s, double* c)
{
    static const double ks[12] = { 0.0, 1.0 / 51090942171709440000.0, -1.0 / 121645100408832000.0, 1.0 / 355687428096000.0,
                                   -1.0 / 1307674368000.0, 1.0 / 6227020800.0, -1.0 / 39916800.0, 1.0 / 362880.0,
                                   -1.0 / 5040.0, 1.0 / 120.0, -1.0 / 6.0, 1.0 };
    static const double kc[12] = { -1.0 / 1124000727777607680000.0, 1.0 / 2432902008176640000.0, -1.0 / 6402373705728000.0,
                                   1.0 / 20922789888000.0, -1.0 / 87178291200.0, 1.0 / 479001600.0, -1.0 / 3628800.0,
                                   1.0 / 40320.0, -1.0 / 720.0, 1.0 / 24.0, -0.5, 1.0 };
    const double x = d * d, x2 = x * x, x4 = x2 * x2;
    double r[2];
    for (int lane = 0; lane < 2; ++lane) {
        const double* k = lane ? kc : ks;
        double acc = (k[7] + k[6] * x + (k[5] + k[4] * x) * x2) + (k[3] + k[2] * x + (k[1] + k[0] * x) * x2) * x4;
        for (int j = 8; j < 12; ++j) acc = acc * x + k[j];
        r[lane] = acc;
    }
    *s = r[0] * d;
    *c = r[1];
}

/* One rotating point's path (centre g0 + v t, offset r turning about `axis` at w rad/s). */
typedef struct chain_path { sdfccd_Vec3 g0, v, r, kr, axis; double kd, w, base_c, base_s; } chain_path;

/* The point at time t: sine and cosine, the angle sum, Rodrigues' formula, the centre. */
static inline sdfccd_Vec3 chain_point(const chain_path* q, double t)
{
    double sd, cd;
    chain_sincos(q->w * (t - 0.008), &sd, &cd);
    const double c = q->base_c * cd - q->base_s * sd, s = q->base_s * cd + q->base_c * sd, k = q->kd * (1.0 - c);
    return (sdfccd_Vec3){ q->g0.x + q->v.x * t + q->r.x * c + q->kr.x * s + q->axis.x * k,
                          q->g0.y + q->v.y * t + q->r.y * c + q->kr.y * s + q->axis.y * k,
                          q->g0.z + q->v.z * t + q->r.z * c + q->kr.z * s + q->axis.z * k };
}

/* The time per sample of loops whose every sample depends on the one before's value, as a secant
 * step's does, with nothing else in them: the floor such a sample costs on this machine, whatever
 * solver issues it. The torus is the cost experiment's user callback (called through a pointer the
 * compiler cannot see through), so these compare with section 5's columns:
 *   field: the next point is the last one moved by 1e-12 x phi (the field's latency and the call);
 *   field eval_xyz: the same through the callback's other form (the point as three coordinates);
 *   spatial: a point on a segment, phi and its gradient, the slope, a secant step on the slope;
 *   temporal: a point at a new time on a rotating path (as above), phi, a secant step in time;
 *   temporal x2: two such chains that do not depend on each other, one sample of each per turn (the
 *   time per sample when a solver keeps two searches in flight). */
static void exp_chain(const options* o)
{
    (void)o;
    torus_cb one = { 1 };
    double (*volatile eval_ptr)(sdfccd_Vec3, sdfccd_Vec3*, void*) = torus_eval;
    double (*const eval)(sdfccd_Vec3, sdfccd_Vec3*, void*) = eval_ptr;
    double (*volatile xyz_ptr)(double, double, double, sdfccd_Vec3*, void*) = torus_eval_xyz;
    double (*const eval_xyz)(double, double, double, sdfccd_Vec3*, void*) = xyz_ptr;
    const chain_path q[2] = {
        { { 0.02, 0.1, 0.03 }, { 0.3, -1.0, 0.5 }, { 0.01, 0.02, -0.005 }, { 0.003, -0.01, 0.02 }, { 0.267, 0.534, 0.801 }, 0.004, 40.0, 0.955336, 0.295520 },
        { { -0.1, 0.02, 0.01 }, { -0.5, 0.2, 1.0 }, { -0.02, 0.01, 0.01 }, { 0.01, 0.01, -0.02 }, { 0.801, 0.267, 0.534 }, -0.002, 25.0, 0.980067, 0.198669 },
    };
    const int n = o->quick ? 200000 : 1000000, passes = o->quick ? 5 : 15;
    double best[5] = { INFINITY, INFINITY, INFINITY, INFINITY, INFINITY }, sink = 0.0;
    for (int pass = 0; pass < passes; ++pass) {
        double t0 = thread_cpu_us();
        sdfccd_Vec3 x = { 0.12, 0.01, 0.02 };
        for (int i = 0; i < n; ++i) {
            const double f = eval(x, NULL, &one);
            x.x = 0.12 + 1e-12 * f;
            sink += f;
        }
        best[0] = fmin(best[0], thread_cpu_us() - t0);

        t0 = thread_cpu_us();
        x = (sdfccd_Vec3){ 0.12, 0.01, 0.02 };
        for (int i = 0; i < n; ++i) {
            const double f = eval_xyz(x.x, x.y, x.z, NULL, &one);
            x.x = 0.12 + 1e-12 * f;
            sink += f;
        }
        best[4] = fmin(best[4], thread_cpu_us() - t0);

        t0 = thread_cpu_us();
        const sdfccd_Vec3 a = { 0.1, 0.02, 0.04 }, d = { -0.03, 0.02, -0.01 };
        double l = 0.3, l_prev = 0.1, s_prev = 0.5;
        for (int i = 0; i < n; ++i) {
            sdfccd_Vec3 g;
            const double f = eval((sdfccd_Vec3){ a.x + d.x * l, a.y + d.y * l, a.z + d.z * l }, &g, &one);
            const double slope = g.x * d.x + g.y * d.y + g.z * d.z;
            const double next = l - slope * (l - l_prev) / (slope - s_prev);
            l_prev = l;
            s_prev = slope + 1e-3;
            l = 0.3 + 1e-12 * next; /* the step's value kept in the chain, the segment's middle kept */
            sink += f;
        }
        best[1] = fmin(best[1], thread_cpu_us() - t0);

        t0 = thread_cpu_us();
        double t = 0.005, lo = 0.0, hi = 0.0166, f_hi = -0.01;
        for (int i = 0; i < n; ++i) {
            const double f = eval(chain_point(&q[0], t), NULL, &one) - 1e-4;
            const double next = hi - f_hi * (hi - lo) / (f_hi - f);
            t = 0.005 + 1e-12 * next;
            sink += f;
        }
        best[2] = fmin(best[2], thread_cpu_us() - t0);

        t0 = thread_cpu_us();
        double u[2] = { 0.005, 0.006 };
        for (int i = 0; i < n / 2; ++i)
            for (int j = 0; j < 2; ++j) {
                const double f = eval(chain_point(&q[j], u[j]), NULL, &one) - 1e-4;
                const double next = hi - f_hi * (hi - lo) / (f_hi - f);
                u[j] = 0.005 + 0.001 * j + 1e-12 * next;
                sink += f;
            }
        best[3] = fmin(best[3], thread_cpu_us() - t0);
    }
    static const char* name[5] = { "field", "spatial", "temporal", "temporal x2", "field eval_xyz" };
    printf("chain,samples,ns_per_sample\n");
    for (int k = 0; k < 5; ++k) printf("%s,%d,%.1f\n", name[k], k == 3 ? n / 2 * 2 : n, best[k] * 1e3 / (double)(k == 3 ? n / 2 * 2 : n));
    if (sink == 1234.5) fprintf(stderr, "-\n"); /* keeps the loops' values live */
}

/* Every answer of the data set, exactly (hexadecimal floats), for the methods whose results must not
 * change when the solver's code is made faster: FWGSS (defaults, and with subdivision), FW and DCD.
 * `diff` two runs to compare builds bit for bit.
 * SDFCCD_BENCH_MESH=triangle|shuriken restricts it to one mesh and SDFCCD_BENCH_METHOD to one method
 * (a short run for callgrind; a method name that matches none runs nothing: the loading alone);
 * SDFCCD_BENCH_REPEAT=N runs the queries N times (the first pass printed; for perf). */
static void exp_fingerprint(const options* o)
{
    dataset ds;
    build_dataset(o->dataset_dir, &ds, o->quick);
    const char* only = getenv("SDFCCD_BENCH_MESH");
    const char* only_method = getenv("SDFCCD_BENCH_METHOD");
    struct { const char* name; sdfccd_QueryParams p; } m[4] = {
        { "FWGSS", config_params(CFG_NEW, 0) },
        { "FWGSS+subdivision", config_params(CFG_NEW, 1) },
        { "FW", method_params(SDFCCD_METHOD_FW, 0) },
        { "DCD", method_params(SDFCCD_METHOD_DCD, 0) },
    };
    sdfccd_Workspace* ws;
    CHECK(sdfccd_create_workspace(&ws));
    sdfccd_Contact out[64];
    printf("method,id,hit,state,toi,toi_lower,evals,contacts,point,normal,distance\n");
    const int repeat = getenv("SDFCCD_BENCH_REPEAT") ? atoi(getenv("SDFCCD_BENCH_REPEAT")) : 1;
    for (int pass = 0; pass < repeat; ++pass)
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < ds.n; ++i) {
            const bcase* c = &ds.c[i];
            if ((only && strcmp(only, k_mesh_name[c->mesh]) != 0) || (only_method && strcmp(only_method, m[k].name) != 0)) continue;
            sdfccd_QueryResult r;
            CHECK(sdfccd_query_mesh_ws(ws, ds.torus, NULL, ds.mid[c->mesh], &c->m, 0.0, DT, &m[k].p, out, 64, &r));
            if (pass > 0) continue;
            const sdfccd_Contact* f = &out[0];
            printf("%s,%s,%d,%d,%a,%a,%lld,%d,%a %a %a,%a %a %a,%a\n", m[k].name, c->id, r.hit, (int)r.state, r.toi, r.toi_lower,
                   (long long)r.sdf_evaluations, (int)r.contacts_found, r.hit ? f->point.x : 0.0, r.hit ? f->point.y : 0.0,
                   r.hit ? f->point.z : 0.0, r.hit ? f->normal.x : 0.0, r.hit ? f->normal.y : 0.0, r.hit ? f->normal.z : 0.0,
                   r.hit ? f->distance : 0.0);
        }
    sdfccd_destroy_workspace(ws);
    free_dataset(&ds);
}

/* ---- the data set per SDF kind (issue 20) ---- */

static const char* kinds_dir(const options* o)
{
    static char dir[1024];
    snprintf(dir, sizeof dir, "%s_kinds", o->dataset_dir);
    return dir;
}

/* Every case of every kind, one row per case and method (the per-kind accuracy table). */
static void exp_kinds(const options* o)
{
    kinds_set ks;
    build_kinds(kinds_dir(o), &ks, o->quick);
    struct { const char* name; sdfccd_QueryParams p; } m[6] = {
        { "FWGSS", config_params(CFG_NEW, 0) },
        { "FWGSS-guard-off", config_params(CFG_NEW, 0) },
        { "FWGSS-guard-2", config_params(CFG_NEW, 0) },
        { "FW", method_params(SDFCCD_METHOD_FW, 0) },
        { "FWGSS-baseline", config_params(CFG_BASELINE, 0) },
        { "FWGSS-paper", config_params(CFG_PAPER, 0) },
    };
    m[1].p.fwgss_kink_guard = 0; /* FWGSS before issue 20 */
    m[2].p.fwgss_kink_guard = 2; /* the guard on every grid query too */
    int nm = o->baseline ? 6 : (getenv("SDFCCD_BENCH_FWGSS_ONLY") ? 1 : 4); /* the variable: quick runs of the defaults only */
    run_result* rr = calloc((size_t)ks.n_per_kind, sizeof *rr);
    printf("method,id,kind,hit,state,toi,gt_hit,gt_state,gt_lower,gt_toi,micros,sdf_evals,gt_regions\n");
    for (int j = 0; j < nm; ++j)
        for (int k = 0; k < KINDS_COUNT; ++k) {
            progress("kinds: %s on %s", m[j].name, k_kind_name[k]);
            kinds_run(&ks, k, &m[j].p, ks.n_per_kind, rr);
            for (int i = 0; i < ks.n_per_kind; ++i) {
                const bcase* c = &ks.c[k * ks.n_per_kind + i];
                const run_result* r = &rr[i];
                printf("%s,%s,%s,%d,%d,%.17g,%d,%d,%.17g,%.17g,%.2f,%lld,%lld\n", m[j].name, c->id, k_kind_name[k], r->hit, r->state, r->toi, c->gt_hit,
                       c->gt_state, c->gt_lower, c->gt_toi, r->us, r->evals, c->gt_regions);
            }
        }
    free(rr);
    free_kinds(&ks);
}

/* Speed versus accuracy per kind: FWGSS's restarts and vertex trace swept, FWGSS without the kink
 * guard (before issue 20), the paper's FWGSS with its caps swept, FW, DCD, and the certified method
 * at two bracket widths. */
static void exp_kinds_front(const options* o)
{
    kinds_set ks;
    build_kinds(kinds_dir(o), &ks, o->quick);
    struct sweep { const char* method; char setting[64]; sdfccd_QueryParams p; } sw[32];
    int n = 0;
    const int trace[3] = { 0, 16, 64 };
    for (int r = 0; r <= 2; ++r)
        for (int i = 0; i < 3; ++i) {
            sw[n].method = "FWGSS";
            sw[n].p = config_params(CFG_NEW, 0);
            sw[n].p.fwgss_restarts = r;
            sw[n].p.fwgss_vertex_trace = trace[i];
            snprintf(sw[n].setting, sizeof sw[n].setting, "restarts=%d trace=%d", r, trace[i]);
            ++n;
        }
    for (int g = 0; g <= 2; g += 2) {
        sw[n].method = g ? "FWGSS-guard-2" : "FWGSS-guard-off";
        sw[n].p = config_params(CFG_NEW, 0);
        sw[n].p.fwgss_kink_guard = g;
        snprintf(sw[n].setting, sizeof sw[n].setting, "defaults");
        ++n;
    }
    const int caps[3] = { 4, 16, 64 };
    for (int i = 0; i < 3; ++i) {
        sw[n].method = "FWGSS-paper";
        sw[n].p = config_params(CFG_PAPER, 0);
        sw[n].p.max_iterations = caps[i];
        sw[n].p.max_line_search_iterations = 2 * caps[i];
        snprintf(sw[n].setting, sizeof sw[n].setting, "iter=%d ls=%d", caps[i], 2 * caps[i]);
        ++n;
    }
    sw[n].method = "FW";
    sw[n].p = method_params(SDFCCD_METHOD_FW, 0);
    snprintf(sw[n].setting, sizeof sw[n].setting, "defaults");
    ++n;
    sw[n].method = "DCD";
    sw[n].p = method_params(SDFCCD_METHOD_DCD, 0);
    snprintf(sw[n].setting, sizeof sw[n].setting, "defaults");
    ++n;
    const double ctol[2] = { 1e-4, 1e-6 };
    for (int i = 0; i < 2; ++i) {
        sw[n].method = "Certified";
        sw[n].p = certified_params();
        sw[n].p.certified_time_tolerance = ctol[i];
        snprintf(sw[n].setting, sizeof sw[n].setting, "tol=%.0e", ctol[i]);
        ++n;
    }
    int ns = o->quick >= 2 ? 2 : (o->quick ? 32 : 256);
    if (ns > ks.n_per_kind) ns = ks.n_per_kind;
    run_result* rr = calloc((size_t)ns, sizeof *rr);
    printf("kind,method,setting,cases,mean_us,fn_rate,fp_rate,mean_abs_dtoi,sdf_evals\n");
    for (int k = 0; k < KINDS_COUNT; ++k)
        for (int s = 0; s < n; ++s) {
            progress("kinds_front: %s %s %s", k_kind_name[k], sw[s].method, sw[s].setting);
            kinds_run(&ks, k, &sw[s].p, ns, rr);
            int fn = 0, fp = 0, cmp = 0;
            double us = 0, ev = 0, dt = 0;
            for (int i = 0; i < ns; ++i) {
                const bcase* c = &ks.c[k * ks.n_per_kind + i];
                const run_result* r = &rr[i];
                us += r->us;
                ev += (double)r->evals;
                if (c->gt_hit && (!r->hit || r->toi > c->gt_toi + TOI_TOL)) fn++;
                if (r->hit && (!c->gt_hit || r->toi < c->gt_lower - TOI_TOL)) fp++;
                if (c->gt_hit && r->hit) {
                    double d = r->toi > c->gt_toi ? r->toi - c->gt_toi : (r->toi < c->gt_lower ? c->gt_lower - r->toi : 0.0);
                    dt += d;
                    ++cmp;
                }
            }
            printf("%s,%s,%s,%d,%.4g,%.6g,%.6g,%.6g,%.1f\n", k_kind_name[k], sw[s].method, sw[s].setting, ns, us / ns, (double)fn / ns, (double)fp / ns,
                   cmp ? dt / cmp : 0.0, ev / ns);
        }
    free(rr);
    free_kinds(&ks);
}

/* ------------------------------------------------------------------ the table */

typedef struct experiment { const char* name; void (*run)(const options*); const char* what; } experiment;

static const experiment k_experiments[] = {
    { "dataset", exp_dataset, "build or reuse the data set and its certified ground truth; one summary row per mesh" },
    { "brute", exp_brute, "the paper's brute-force ground truth on the first cases, against the certified bracket" },
    { "accuracy", exp_accuracy, "every method on every case (Tables 1-2); --baseline adds the previous and the paper's FWGSS" },
    { "front", exp_front, "speed versus accuracy: caps, tolerances, restarts and vertex trace swept; the three FWGSS configurations" },
    { "targets", exp_targets, "issue 9's targets: triangle, shuriken, triangle vs 32^3 grid; --baseline interleaves the previous defaults" },
    { "scaling", exp_scaling, "the armadillo falling on the spike grid at 1K/10K/100K (Table 3) with the certified TOI" },
    { "batch", exp_batch, "the data set as one sdfccd_query_batch on 1 and --threads N threads" },
    { "kinds", exp_kinds, "the data set per SDF kind (issue 20): FWGSS with the kink guard at levels 1 (default), 0 and 2, and FW on every case; --baseline adds the previous and the paper's FWGSS" },
    { "kinds_front", exp_kinds_front, "speed versus accuracy per SDF kind: FWGSS restarts and trace, the paper's caps, FW, DCD, certified" },
    { "fingerprint", exp_fingerprint, "every answer of the data set in hexadecimal (FWGSS, with subdivision, FW, DCD): diff two builds bit for bit" },
    { "cost", exp_cost, "cost per SDF evaluation in a query: the field and the rest (motion, solver, dispatch), measured differentially" },
    { "chain", exp_chain, "the time per sample of a chain of dependent samples (field, spatial, temporal; two temporal chains interleaved)" },
};
#define N_EXPERIMENTS ((int)(sizeof k_experiments / sizeof k_experiments[0]))

static int usage(const char* argv0)
{
    fprintf(stderr, "usage: %s list | NAME [--dataset DIR] [--quick|--smoke] [--baseline] [--threads N] > NAME.csv\n", argv0);
    return 2;
}

int main(int argc, char** argv)
{
    if (argc < 2) return usage(argv[0]);
    if (!strcmp(argv[1], "list")) {
        for (int i = 0; i < N_EXPERIMENTS; ++i) printf("%-10s %s\n", k_experiments[i].name, k_experiments[i].what);
        return 0;
    }
    options o = { SDFCCD_BENCH_SOURCE_DIR "/samples/report/dataset", 0, 0, 2 };
    for (int i = 2; i < argc; ++i) {
        if (!strcmp(argv[i], "--dataset") && i + 1 < argc) o.dataset_dir = argv[++i];
        else if (!strcmp(argv[i], "--quick")) o.quick = 1;
        else if (!strcmp(argv[i], "--smoke")) o.quick = 2;
        else if (!strcmp(argv[i], "--baseline")) o.baseline = 1;
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc) o.threads = atoi(argv[++i]);
        else return usage(argv[0]);
    }
    for (int i = 0; i < N_EXPERIMENTS; ++i)
        if (!strcmp(argv[1], k_experiments[i].name)) {
            k_experiments[i].run(&o);
            return 0;
        }
    fprintf(stderr, "%s: no experiment '%s' (try '%s list')\n", argv[0], argv[1], argv[0]);
    return 2;
}
