/* SPDX-License-Identifier: MIT
 * sdfccd_bench's data set per SDF kind (issue 20 item 1): the data set's triangle (about 10 cm)
 * against every kind of SDF the library offers, smooth and not: the torus, a box, an 8 mm plate,
 * CSG with sharp seams (a cube minus a ball, a cube intersected with a ball), a rounded box, and two
 * grids baked from meshes with sharp features (bullet3's concave box, 32^3 .cdf in data/; a spiky
 * slab, a procedural mesh baked here). Per kind, seeded: a target point on the surface, about a
 * third of the paths grazing it (moving along the tangent plane, the centre passing up to 4 cm
 * above it), the others coming in; a travel of half to two and a half triangle sizes (5 cm) per
 * 1/60 s step and spins up to 300 rad/s. Ground truth: the certified method on exactly the
 * numbers written to the case file (for grids, certified against the grid itself, with its
 * per-cell Lipschitz bounds). Cases whose certified answer did not converge, or that start in
 * contact, are rejected; certified no-hit cases are kept (they count false positives).
 * Included once, by sdfccd_bench.c, after bench_common.h. */
#ifndef SDFCCD_BENCH_KINDS_H
#define SDFCCD_BENCH_KINDS_H

#define KINDS_GEN_VERSION 1
#define KINDS_COUNT 8
#define KINDS_SPIN_MAX 300.0 /* rad/s */

static const char* k_kind_name[KINDS_COUNT] = { "torus", "box", "plate", "csg-difference", "csg-intersection", "rounded-box", "grid-concave-box",
                                                "grid-spikes" };

typedef struct kinds_set {
    int n_per_kind, n;
    bcase* c;      /* bcase.mesh holds the kind */
    mesh_data tri;
    sdfccd_MeshId mid;
    sdfccd_SdfId sdf[KINDS_COUNT];
    double lo[KINDS_COUNT][3], hi[KINDS_COUNT][3]; /* where targets are sampled */
    int rejected[KINDS_COUNT];
} kinds_set;

/* A closed slab 40 x 40 cm, 4 cm thick, topped by 4 x 4 square pyramids 8 cm tall (sharp apexes,
 * ridges and valleys): the mesh the spike grid is baked from. */
static void make_spike_slab(mesh_data* m)
{
    const int N = 4;
    const double c = 0.1, x0 = -0.2, H = 0.08, D = 0.04;
    const int nc = (N + 1) * (N + 1);
    m->nv = (uint32_t)(2 * nc + N * N);
    m->nt = (uint32_t)(4 * N * N + 2 * N * N + 4 * 2 * N);
    m->v = malloc(3 * (size_t)m->nv * sizeof *m->v);
    m->f = malloc(3 * (size_t)m->nt * sizeof *m->f);
#define TV(i, j) ((i) * (N + 1) + (j))
#define AV(i, j) (nc + (i) * N + (j))
#define BV(i, j) (nc + N * N + (i) * (N + 1) + (j))
    for (int i = 0; i <= N; ++i)
        for (int j = 0; j <= N; ++j) {
            double* t = m->v + 3 * TV(i, j);
            double* b = m->v + 3 * BV(i, j);
            t[0] = b[0] = x0 + i * c;
            t[1] = b[1] = x0 + j * c;
            t[2] = 0.0;
            b[2] = -D;
        }
    for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) {
            double* a = m->v + 3 * AV(i, j);
            a[0] = x0 + (i + 0.5) * c;
            a[1] = x0 + (j + 0.5) * c;
            a[2] = H;
        }
    uint32_t* f = m->f;
    int t = 0;
#define TRI(a, b, cc) do { f[3 * t] = (uint32_t)(a); f[3 * t + 1] = (uint32_t)(b); f[3 * t + 2] = (uint32_t)(cc); ++t; } while (0)
    for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) {
            int a = AV(i, j);
            TRI(TV(i, j), TV(i + 1, j), a); /* counter-clockwise seen from above */
            TRI(TV(i + 1, j), TV(i + 1, j + 1), a);
            TRI(TV(i + 1, j + 1), TV(i, j + 1), a);
            TRI(TV(i, j + 1), TV(i, j), a);
            TRI(BV(i, j), BV(i + 1, j + 1), BV(i + 1, j)); /* bottom, facing down */
            TRI(BV(i, j), BV(i, j + 1), BV(i + 1, j + 1));
        }
    for (int k = 0; k < N; ++k) {
        TRI(TV(k, 0), BV(k, 0), BV(k + 1, 0)); /* y = min, facing -y */
        TRI(TV(k, 0), BV(k + 1, 0), TV(k + 1, 0));
        TRI(TV(k, N), BV(k + 1, N), BV(k, N)); /* y = max */
        TRI(TV(k, N), TV(k + 1, N), BV(k + 1, N));
        TRI(TV(0, k), BV(0, k + 1), BV(0, k)); /* x = min */
        TRI(TV(0, k), TV(0, k + 1), BV(0, k + 1));
        TRI(TV(N, k), BV(N, k), BV(N, k + 1)); /* x = max */
        TRI(TV(N, k), BV(N, k + 1), TV(N, k + 1));
    }
#undef TRI
#undef TV
#undef AV
#undef BV
}

static void set_box(kinds_set* ks, int k, double x, double y, double z)
{
    ks->lo[k][0] = -x; ks->lo[k][1] = -y; ks->lo[k][2] = -z;
    ks->hi[k][0] = x; ks->hi[k][1] = y; ks->hi[k][2] = z;
}

/* The SDFs, and (when f is not NULL) their case-file records. The spike grid is baked into
 * dir/spikes.cdf when it is not there yet. */
static void kinds_create(kinds_set* ks, const char* dir, FILE* f)
{
    CHECK(sdfccd_create_torus(0.1, 0.05, &ks->sdf[0]));
    set_box(ks, 0, 0.16, 0.16, 0.06);
    CHECK(sdfccd_create_box((sdfccd_Vec3){ 0.1, 0.07, 0.05 }, &ks->sdf[1]));
    set_box(ks, 1, 0.11, 0.08, 0.06);
    CHECK(sdfccd_create_box((sdfccd_Vec3){ 0.15, 0.15, 0.004 }, &ks->sdf[2]));
    set_box(ks, 2, 0.16, 0.16, 0.014);
    sdfccd_SdfId cube, b1, b2;
    CHECK(sdfccd_create_box((sdfccd_Vec3){ 0.1, 0.1, 0.1 }, &cube));
    CHECK(sdfccd_create_sphere(0.125, &b1));
    CHECK(sdfccd_create_sphere(0.13, &b2));
    CHECK(sdfccd_create_csg(SDFCCD_CSG_DIFFERENCE, cube, b1, &ks->sdf[3]));
    set_box(ks, 3, 0.11, 0.11, 0.11);
    CHECK(sdfccd_create_csg(SDFCCD_CSG_INTERSECTION, cube, b2, &ks->sdf[4]));
    set_box(ks, 4, 0.11, 0.11, 0.11);
    sdfccd_destroy_sdf(cube);
    sdfccd_destroy_sdf(b1);
    sdfccd_destroy_sdf(b2);
    CHECK(sdfccd_create_rounded_box((sdfccd_Vec3){ 0.08, 0.06, 0.04 }, 0.02, &ks->sdf[5]));
    set_box(ks, 5, 0.11, 0.09, 0.07);
    CHECK(sdfccd_load_grid(SDFCCD_BENCH_DATA_DIR "/sdf/concave_box_r32.cdf", &ks->sdf[6]));
    char path[2048];
    snprintf(path, sizeof path, "%s/spikes.cdf", dir);
    if (sdfccd_load_grid(path, &ks->sdf[7]) != SDFCCD_OK) {
        mesh_data sm;
        make_spike_slab(&sm);
        sdfccd_MeshId smid = mesh_create(&sm);
        sdfccd_GridDef gd = sdfccd_default_grid_def();
        gd.resolution[0] = gd.resolution[1] = 12;
        gd.resolution[2] = 4;
        gd.padding = 0.02;
        gd.threads = 1;
        CHECK(sdfccd_create_grid_from_mesh(smid, &gd, &ks->sdf[7]));
        CHECK(sdfccd_save_grid(ks->sdf[7], path));
        sdfccd_destroy_mesh(smid);
        mesh_free(&sm);
    }
    for (int k = 6; k < 8; ++k) {
        sdfccd_SdfInfo info;
        CHECK(sdfccd_sdf_get_info(ks->sdf[k], &info));
        const double in = k == 6 ? 0.05 : 0.01; /* targets well inside the domain */
        ks->lo[k][0] = info.domain.lo.x + in; ks->lo[k][1] = info.domain.lo.y + in; ks->lo[k][2] = info.domain.lo.z + in;
        ks->hi[k][0] = info.domain.hi.x - in; ks->hi[k][1] = info.domain.hi.y - in; ks->hi[k][2] = info.domain.hi.z - in;
    }
    if (f) {
        fprintf(f, "sdf torus torus 0.1 0.05\nsdf box box 0.1 0.07 0.05\nsdf plate box 0.15 0.15 0.004\n");
        fprintf(f, "sdf cube box 0.1 0.1 0.1\nsdf ball125 sphere 0.125\nsdf ball13 sphere 0.13\n");
        fprintf(f, "sdf csg-difference csg difference cube ball125\nsdf csg-intersection csg intersection cube ball13\n");
        fprintf(f, "sdf rounded-box rounded_box 0.08 0.06 0.04 0.02\n");
        fprintf(f, "sdf grid-concave-box grid ../../../data/sdf/concave_box_r32.cdf\nsdf grid-spikes grid spikes.cdf\n");
    }
}

/* A point on the surface of kind k (Newton projection x -= phi grad from a random point of the
 * sampling box) with its unit normal. */
static void surface_point(const kinds_set* ks, int k, rng* r, sdfccd_Vec3* out_x, sdfccd_Vec3* out_n)
{
    for (;;) {
        sdfccd_Vec3 x = { rng_uniform(r, ks->lo[k][0], ks->hi[k][0]), rng_uniform(r, ks->lo[k][1], ks->hi[k][1]),
                          rng_uniform(r, ks->lo[k][2], ks->hi[k][2]) };
        double phi = 1.0;
        sdfccd_Vec3 g = { 0, 0, 0 };
        for (int it = 0; it < 40 && fabs(phi) > 1e-9; ++it) {
            CHECK(sdfccd_sdf_eval(ks->sdf[k], x, &phi, &g));
            double gl = g.x * g.x + g.y * g.y + g.z * g.z;
            if (!(gl > 0.25)) break;
            x.x -= phi * g.x / gl; x.y -= phi * g.y / gl; x.z -= phi * g.z / gl;
        }
        CHECK(sdfccd_sdf_eval(ks->sdf[k], x, &phi, &g));
        double gl = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
        int inside = x.x >= ks->lo[k][0] && x.x <= ks->hi[k][0] && x.y >= ks->lo[k][1] && x.y <= ks->hi[k][1] && x.z >= ks->lo[k][2] &&
                     x.z <= ks->hi[k][2];
        if (fabs(phi) < 1e-7 && gl > 0.5 && inside) {
            *out_x = x;
            *out_n = (sdfccd_Vec3){ g.x / gl, g.y / gl, g.z / gl };
            return;
        }
    }
}

/* The numbers written to the case file (%.9g): the motion as read back from them. */
static double r9(double v)
{
    char b[64];
    snprintf(b, sizeof b, "%.9g", v);
    return strtod(b, NULL);
}

static sdfccd_RigidMotion kinds_motion(const kinds_set* ks, int k, rng* r)
{
    sdfccd_Vec3 x, n;
    surface_point(ks, k, r, &x, &n);
    const int grazing = rng_uniform(r, 0, 3) < 1.0;
    sdfccd_Vec3 d;
    double h;
    if (grazing) {
        /* along the tangent plane, dipping by up to 0.1 rad, the centre passing 0-4 cm above x */
        sdfccd_Vec3 u = rng_unit(r);
        double un = u.x * n.x + u.y * n.y + u.z * n.z;
        d = (sdfccd_Vec3){ u.x - un * n.x, u.y - un * n.y, u.z - un * n.z };
        double dl = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        if (dl < 1e-6) d = (sdfccd_Vec3){ n.y, -n.x, 0 }, dl = sqrt(n.x * n.x + n.y * n.y);
        if (dl < 1e-6) d = (sdfccd_Vec3){ 1, 0, 0 }, dl = 1;
        double dip = rng_uniform(r, 0.0, 0.1);
        d = (sdfccd_Vec3){ d.x / dl * cos(dip) - n.x * sin(dip), d.y / dl * cos(dip) - n.y * sin(dip), d.z / dl * cos(dip) - n.z * sin(dip) };
        h = rng_uniform(r, 0.0, 0.04);
    } else {
        /* into the surface within 60 degrees of the normal, the centre reaching 0-3 cm above x */
        for (;;) {
            sdfccd_Vec3 u = rng_unit(r);
            double s = rng_uniform(r, 0.0, 0.9);
            d = (sdfccd_Vec3){ -n.x + s * u.x, -n.y + s * u.y, -n.z + s * u.z };
            double dl = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
            d = (sdfccd_Vec3){ d.x / dl, d.y / dl, d.z / dl };
            if (d.x * n.x + d.y * n.y + d.z * n.z < -0.5) break;
        }
        h = rng_uniform(r, 0.0, 0.03);
    }
    const double travel = rng_uniform(r, 0.5, 2.5) * 0.1; /* per step: half to two and a half triangle sizes */
    const double f = rng_uniform(r, 0.15, 0.95);          /* when the centre passes x + h n */
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    sdfccd_Vec3 v = { d.x * travel / DT, d.y * travel / DT, d.z * travel / DT };
    m.linear_velocity = (sdfccd_Vec3){ r9(v.x), r9(v.y), r9(v.z) };
    m.pose.position = (sdfccd_Vec3){ r9(x.x + h * n.x - v.x * f * DT), r9(x.y + h * n.y - v.y * f * DT), r9(x.z + h * n.z - v.z * f * DT) };
    sdfccd_Vec3 axis = rng_unit(r);
    double ang = rng_uniform(r, 0, M_PI);
    m.pose.orientation = (sdfccd_Quat){ r9(cos(ang / 2)), r9(axis.x * sin(ang / 2)), r9(axis.y * sin(ang / 2)), r9(axis.z * sin(ang / 2)) };
    sdfccd_Vec3 w = rng_unit(r);
    double wm = rng_uniform(r, 0.0, KINDS_SPIN_MAX);
    m.angular_velocity = (sdfccd_Vec3){ r9(w.x * wm), r9(w.y * wm), r9(w.z * wm) };
    return m;
}

static int kinds_ground_truth(kinds_set* ks, bcase* c)
{
    sdfccd_QueryParams p = certified_params();
    sdfccd_QueryResult r;
    double t0 = now_us();
    CHECK(sdfccd_query_mesh(ks->sdf[c->mesh], NULL, ks->mid, &c->m, 0.0, DT, &p, NULL, 0, &r));
    c->gt_us = now_us() - t0;
    c->gt_hit = r.hit;
    c->gt_state = (int)r.state;
    c->gt_lower = r.toi_lower;
    c->gt_toi = r.toi;
    c->gt_regions = (long long)r.iterations;
    return r.state == SDFCCD_STATE_HIT || r.state == SDFCCD_STATE_NO_HIT;
}

static void kinds_write(const char* dir, kinds_set* ks)
{
    FILE* f = open_out(dir, "cases.txt");
    fprintf(f, "sdfccd-cases 1\n# The data set per SDF kind (issue 20), made by sdfccd_bench kinds (seed %u, generator %d): %d cases per kind,\n",
            SEED, KINDS_GEN_VERSION, ks->n_per_kind);
    fprintf(f, "# about a third grazing, spins up to %.0f rad/s, 0.5-2.5 triangle sizes per step; certified TOI in ground_truth.csv.\n", KINDS_SPIN_MAX);
    kinds_create(ks, dir, f); /* only the records: the handles are made again below */
    for (int k = 0; k < KINDS_COUNT; ++k) sdfccd_destroy_sdf(ks->sdf[k]);
    const double* v = ks->tri.v;
    fprintf(f, "mesh triangle triangle %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7],
            v[8]);
    for (int i = 0; i < ks->n; ++i) {
        const bcase* c = &ks->c[i];
        const sdfccd_RigidMotion* m = &c->m;
        fprintf(f, "case %s %s triangle %.17g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", c->id, k_kind_name[c->mesh], DT,
                m->pose.position.x, m->pose.position.y, m->pose.position.z, m->pose.orientation.w, m->pose.orientation.x, m->pose.orientation.y,
                m->pose.orientation.z, m->linear_velocity.x, m->linear_velocity.y, m->linear_velocity.z, m->angular_velocity.x,
                m->angular_velocity.y, m->angular_velocity.z);
    }
    fclose(f);
    f = open_out(dir, "ground_truth.csv");
    fprintf(f, "# sdfccd_bench kinds ground truth, seed %u, generator %d, %d per kind, rejected", SEED, KINDS_GEN_VERSION, ks->n_per_kind);
    for (int k = 0; k < KINDS_COUNT; ++k) fprintf(f, " %d", ks->rejected[k]);
    fprintf(f, "\nid,hit,state,toi_lower,toi,regions,micros\n");
    for (int i = 0; i < ks->n; ++i) {
        const bcase* c = &ks->c[i];
        fprintf(f, "%s,%d,%d,%.17g,%.17g,%lld,%.1f\n", c->id, c->gt_hit, c->gt_state, c->gt_lower, c->gt_toi, c->gt_regions, c->gt_us);
    }
    fclose(f);
}

/* Reads a cached set (cases.txt and ground_truth.csv of this generator with at least n_per_kind
 * per kind); returns 1 when every case was found. */
static int kinds_read(const char* dir, kinds_set* ks)
{
    char path[2048];
    snprintf(path, sizeof path, "%s/ground_truth.csv", dir);
    FILE* g = fopen(path, "r");
    if (!g) return 0;
    char line[1024];
    unsigned seed = 0;
    int gen = 0, per = 0;
    int ok = fgets(line, sizeof line, g) && sscanf(line, "# sdfccd_bench kinds ground truth, seed %u, generator %d, %d per kind", &seed, &gen, &per) == 3 &&
             seed == SEED && gen == KINDS_GEN_VERSION && per >= ks->n_per_kind && fgets(line, sizeof line, g);
    for (int k = 0; ok && k < KINDS_COUNT; ++k)
        for (int j = 0; ok && j < per; ++j) {
            bcase tmp;
            memset(&tmp, 0, sizeof tmp);
            ok = fgets(line, sizeof line, g) && sscanf(line, "%31[^,],%d,%d,%lf,%lf,%lld,%lf", tmp.id, &tmp.gt_hit, &tmp.gt_state, &tmp.gt_lower,
                                                      &tmp.gt_toi, &tmp.gt_regions, &tmp.gt_us) == 7;
            if (ok && j < ks->n_per_kind) ks->c[k * ks->n_per_kind + j] = tmp;
        }
    fclose(g);
    if (!ok) return 0;
    snprintf(path, sizeof path, "%s/cases.txt", dir);
    FILE* f = fopen(path, "r");
    int found = 0;
    while (f && fgets(line, sizeof line, f)) {
        char id[32], sdf[32], mesh[32];
        double dt;
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        if (sscanf(line, "case %31s %31s %31s %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", id, sdf, mesh, &dt, &m.pose.position.x,
                   &m.pose.position.y, &m.pose.position.z, &m.pose.orientation.w, &m.pose.orientation.x, &m.pose.orientation.y, &m.pose.orientation.z,
                   &m.linear_velocity.x, &m.linear_velocity.y, &m.linear_velocity.z, &m.angular_velocity.x, &m.angular_velocity.y,
                   &m.angular_velocity.z) != 17)
            continue;
        for (int k = 0; k < KINDS_COUNT; ++k) {
            if (strcmp(sdf, k_kind_name[k])) continue;
            int j = atoi(strrchr(id, '-') + 1);
            if (j < ks->n_per_kind && !strcmp(ks->c[k * ks->n_per_kind + j].id, id)) {
                ks->c[k * ks->n_per_kind + j].m = m;
                ks->c[k * ks->n_per_kind + j].mesh = k;
                ++found;
            }
        }
    }
    if (f) fclose(f);
    return found == ks->n;
}

static void build_kinds(const char* dir, kinds_set* ks, int quick)
{
    memset(ks, 0, sizeof *ks);
    ks->n_per_kind = quick >= 2 ? 4 : (quick ? 64 : 512);
    ks->n = KINDS_COUNT * ks->n_per_kind;
    ks->c = calloc((size_t)ks->n, sizeof *ks->c);
    make_triangle(&ks->tri);
    ks->mid = mesh_create(&ks->tri);
    mkdir_p(dir);
    if (kinds_read(dir, ks)) {
        kinds_create(ks, dir, NULL);
        progress("reusing the cached per-kind data set and certified ground truth in %s", dir);
        return;
    }
    kinds_create(ks, dir, NULL);
    for (int k = 0; k < KINDS_COUNT; ++k) {
        rng r = { SEED + 7919u * (unsigned)(k + 1) };
        int accepted = 0, rejected = 0;
        double t_start = now_us();
        while (accepted < ks->n_per_kind) {
            bcase* c = &ks->c[k * ks->n_per_kind + accepted];
            c->mesh = k;
            c->m = kinds_motion(ks, k, &r);
            snprintf(c->id, sizeof c->id, "%s-%04d", k_kind_name[k], accepted);
            if (kinds_ground_truth(ks, c)) accepted++;
            else rejected++;
        }
        ks->rejected[k] = rejected;
        progress("ground truth %s: %d cases (%.1f s, %d rejected)", k_kind_name[k], accepted, (now_us() - t_start) * 1e-6, rejected);
    }
    kinds_write(dir, ks);
    kinds_create(ks, dir, NULL);
}

static void free_kinds(kinds_set* ks)
{
    for (int k = 0; k < KINDS_COUNT; ++k) sdfccd_destroy_sdf(ks->sdf[k]);
    sdfccd_destroy_mesh(ks->mid);
    mesh_free(&ks->tri);
    free(ks->c);
}

/* One query per case of kind k (first..first+count), results in out[0..count). */
static void kinds_run(const kinds_set* ks, int k, const sdfccd_QueryParams* p, int count, run_result* out)
{
    sdfccd_Contact contacts[64];
    for (int i = 0; i < count; ++i) {
        const bcase* c = &ks->c[k * ks->n_per_kind + i];
        sdfccd_QueryResult r;
        double t0 = now_us();
        CHECK(sdfccd_query_mesh(ks->sdf[k], NULL, ks->mid, &c->m, 0.0, DT, p, contacts, 64, &r));
        run_result* o = &out[i];
        o->us = now_us() - t0;
        o->hit = r.hit;
        o->state = (int)r.state;
        o->toi = r.toi;
        o->evals = (long long)r.sdf_evaluations;
        o->tested = (long long)r.triangles_tested;
        o->contacts = r.contacts_found;
    }
}

#endif
