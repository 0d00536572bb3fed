/* SPDX-License-Identifier: MIT
 * sdfccd_worst: the slowest single queries we know of (issue 11), timed with the default
 * parameters (evaluation budget, certified region cap), one CSV row per input and method:
 *   input,method,status,state,hit,sdf_evaluations,peak_bytes,seconds_median,seconds_max,cpu_seconds_median
 * seconds_* (wall clock) are over --repeats runs (default 3) of the same query; cpu_seconds is the
 * thread's CPU time, which a loaded machine (other processes sharing the cores) does not inflate;
 * peak_bytes is the most the library held at once during the query (allocator hooks), above what
 * it held before.
 *
 * The inputs are the pathological ones: a triangle (and a 1,656-triangle sheet) sliding 1 nm
 * above a non-convex surface, which no bound can prune, on analytic, CSG, grid and mesh-baked
 * grid SDFs; a rotation just below SDFCCD_MAX_ROTATION_ANGLE; an interval split into a million
 * segments. Public ABI only. Timings vary with the machine's load: compare evaluations too.
 *
 *   sdfccd_worst [--repeats N] [--only SUBSTRING] [--grid RES (of the grids, default 64)] > worst.csv */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "sdfccd/sdfccd.h"

typedef struct peak_counter { int64_t now, peak; } peak_counter;
static peak_counter g_count;
static void* count_alloc(size_t n, void* user)
{
    peak_counter* c = user;
    c->now += (int64_t)n;
    if (c->now > c->peak) c->peak = c->now;
    return malloc(n);
}
static void count_free(void* p, size_t n, void* user)
{
    peak_counter* c = user;
    c->now -= (int64_t)n;
    free(p);
}

static double clock_s(clockid_t id)
{
    struct timespec t;
    clock_gettime(id, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void check(sdfccd_Status st, const char* what)
{
    if (st != SDFCCD_OK) {
        fprintf(stderr, "sdfccd_worst: %s: %s\n", what, sdfccd_last_error());
        exit(1);
    }
}

/* A flat sheet of nx x ny quads, `size` wide, in the plane z = height, centred at (cx, 0). */
static sdfccd_MeshId make_sheet(int nx, int ny, double size, double cx, double height)
{
    int nv = (nx + 1) * (ny + 1);
    double* v = malloc(sizeof(double) * 3 * (size_t)nv);
    uint32_t* idx = malloc(sizeof(uint32_t) * 6 * (size_t)(nx * ny));
    for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) {
            double* p = v + 3 * (j * (nx + 1) + i);
            p[0] = cx + size * ((double)i / nx - 0.5);
            p[1] = size * ((double)j / ny - 0.5);
            p[2] = height;
        }
    uint32_t* f = idx;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            uint32_t a = (uint32_t)(j * (nx + 1) + i), b = a + 1, c = a + (uint32_t)(nx + 1), d = c + 1;
            *f++ = a; *f++ = b; *f++ = d;
            *f++ = a; *f++ = d; *f++ = c;
        }
    sdfccd_MeshDef d = sdfccd_default_mesh_def();
    d.vertices = v;
    d.vertex_count = (uint32_t)nv;
    d.indices = idx;
    d.triangle_count = (uint32_t)(2 * nx * ny);
    sdfccd_MeshId mesh;
    check(sdfccd_create_mesh(&d, &mesh), "sheet");
    free(v);
    free(idx);
    return mesh;
}

typedef struct input {
    const char* name;
    sdfccd_SdfId sdf;
    const sdfccd_MeshId* mesh; /* NULL: the single triangle */
    sdfccd_Vec3 tri[3];
    sdfccd_RigidMotion motion;
    double max_rotation;  /* 0: default */
} input;

static const char* k_method[SDFCCD_METHOD_COUNT] = { "FWGSS", "FW", "DCD", "CERTIFIED" };

static int cmp_double(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

static void run(const input* in, int repeats)
{
    for (int method = 0; method < SDFCCD_METHOD_COUNT; ++method) {
        if (method == SDFCCD_METHOD_DCD) continue; /* one pose: never the slowest */
        sdfccd_QueryParams p = sdfccd_default_query_params();
        p.method = (sdfccd_Method)method;
        if (in->max_rotation > 0.0) p.max_rotation_per_segment = in->max_rotation;
        double t[16], cpu[16];
        sdfccd_Status st = SDFCCD_OK;
        sdfccd_QueryResult r;
        memset(&r, 0, sizeof r);
        int64_t peak = 0;
        for (int k = 0; k < repeats; ++k) {
            sdfccd_Contact c[8];
            const int64_t before = g_count.now;
            g_count.peak = g_count.now;
            double t0 = clock_s(CLOCK_MONOTONIC), c0 = clock_s(CLOCK_THREAD_CPUTIME_ID);
            if (in->mesh) st = sdfccd_query_mesh(in->sdf, NULL, *in->mesh, &in->motion, 0.0, 1.0, &p, c, 8, &r);
            else st = sdfccd_query_triangle(in->sdf, NULL, in->tri, &in->motion, 0.0, 1.0, &p, c, 8, &r);
            t[k] = clock_s(CLOCK_MONOTONIC) - t0;
            cpu[k] = clock_s(CLOCK_THREAD_CPUTIME_ID) - c0;
            if (g_count.peak - before > peak) peak = g_count.peak - before;
        }
        qsort(t, (size_t)repeats, sizeof t[0], cmp_double);
        qsort(cpu, (size_t)repeats, sizeof cpu[0], cmp_double);
        printf("%s,%s,%s,%d,%d,%lld,%lld,%.4f,%.4f,%.4f\n", in->name, k_method[method], sdfccd_status_string(st), st ? -1 : (int)r.state,
               st ? 0 : (int)r.hit, st ? 0LL : (long long)r.sdf_evaluations, (long long)peak, t[repeats / 2], t[repeats - 1], cpu[repeats / 2]);
        fflush(stdout);
    }
}

int main(int argc, char** argv)
{
    int repeats = 3, res = 64;
    const char* only = NULL;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
        else if (!strcmp(argv[i], "--grid") && i + 1 < argc) res = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: sdfccd_worst [--repeats N] [--only SUBSTRING] [--grid RES] > worst.csv\n");
            return 2;
        }
    }
    if (repeats < 1) repeats = 1;
    if (repeats > 16) repeats = 16;
    if (res < 4 || res > 512) res = 64;
    check(sdfccd_set_allocator(count_alloc, count_free, &g_count), "allocator");

    /* The torus (non-convex), as an analytic field, a CSG union, a grid of it (64^3 unless --grid), and a grid
     * from the torus's extracted mesh (a mesh SDF). */
    sdfccd_SdfId torus, sphere, ball, csg, grid, mesh_grid;
    check(sdfccd_create_torus(1.0, 0.25, &torus), "torus");
    check(sdfccd_create_sphere(0.3, &sphere), "sphere");
    sdfccd_Pose far = { { 0.0, 0.0, -3.0 }, { 1, 0, 0, 0 } };
    check(sdfccd_create_transformed(sphere, far, 1.0, &ball), "ball");
    check(sdfccd_create_csg(SDFCCD_CSG_UNION, torus, ball, &csg), "union");
    sdfccd_GridDef gd = sdfccd_default_grid_def();
    gd.resolution[0] = gd.resolution[1] = gd.resolution[2] = (uint32_t)res;
    gd.threads = 2;
    check(sdfccd_create_grid_from_sdf(torus, &gd, &grid), "torus grid");
    /* A mesh SDF: the torus extracted as a triangle mesh, baked into a grid from that mesh.
     * Its top is near z = 0.25; the sheet and triangle slide just above it. */
    sdfccd_MeshId tmesh;
    const sdfccd_Aabb box = { { -1.4, -1.4, -0.4 }, { 1.4, 1.4, 0.4 } };
    check(sdfccd_extract_isosurface(torus, box, 96, &tmesh), "torus mesh");
    if (only && !strstr("meshgrid", only) && !strstr(only, "meshgrid")) mesh_grid = grid; /* not needed: skip the slow bake */
    else check(sdfccd_create_grid_from_mesh(tmesh, &gd, &mesh_grid), "torus mesh grid");
    double top = 0.0;
    for (int i = 0; i <= 200; ++i) { /* the highest surface point over the line y = 0 */
        const double x = 0.8 + 0.4 * i / 200.0;
        double v;
        check(sdfccd_sdf_eval(mesh_grid, (sdfccd_Vec3){ x, 0.0, 0.3 }, &v, NULL), "eval");
        if (0.3 - v > top) top = 0.3 - v;
    }
    const double zm = top + 1e-9;
    const double z = 0.25 + 1e-9;
    sdfccd_RigidMotion slide = sdfccd_default_rigid_motion();
    slide.linear_velocity.x = 0.5;
    sdfccd_MeshId sheet = make_sheet(36, 23, 3.0, 0.0, z);
    sdfccd_MeshId sheet_m = make_sheet(36, 23, 3.0, 0.0, zm);
    sdfccd_RigidMotion spin = sdfccd_default_rigid_motion();
    spin.pose.position.x = 2.0;
    spin.linear_velocity.x = -1.0;
    spin.angular_velocity.z = 0.9 * SDFCCD_MAX_ROTATION_ANGLE;
    sdfccd_RigidMotion turn = spin;
    turn.angular_velocity.z = 1e4;

#define TRI(a) { { 0.5, -0.3, a }, { 1.5, -0.3, a }, { 1.0, 0.4, a } }
#define SMALL { { 0, 0, 0 }, { 0.5, 0, 0 }, { 0, 0.5, 0 } }
    input inputs[] = {
        { "tri-1nm-torus", torus, NULL, TRI(z), slide, 0 },
        { "tri-1nm-csg", csg, NULL, TRI(z), slide, 0 },
        { "tri-1nm-grid", grid, NULL, TRI(z), slide, 0 },
        { "tri-1nm-meshgrid", mesh_grid, NULL, TRI(zm), slide, 0 },
        { "sheet1656-1nm-torus", torus, &sheet, SMALL, slide, 0 },
        { "sheet1656-1nm-grid", grid, &sheet, SMALL, slide, 0 },
        { "sheet1656-1nm-meshgrid", mesh_grid, &sheet_m, SMALL, slide, 0 },
        { "tri-spin-0.9e6rad", torus, NULL, SMALL, spin, 0 },
        { "tri-spin-0.9e6rad-grid", grid, NULL, SMALL, spin, 0 },
        { "tri-spin-0.9e6rad-meshgrid", mesh_grid, NULL, SMALL, spin, 0 },
        { "tri-1e6-segments", torus, NULL, SMALL, turn, 1e-2 },
    };
#undef TRI
#undef SMALL
    printf("input,method,status,state,hit,sdf_evaluations,peak_bytes,seconds_median,seconds_max,cpu_seconds_median\n");
    for (size_t i = 0; i < sizeof inputs / sizeof inputs[0]; ++i)
        if (!only || strstr(inputs[i].name, only)) run(&inputs[i], repeats);

    sdfccd_destroy_mesh(sheet);
    sdfccd_destroy_mesh(sheet_m);
    sdfccd_destroy_mesh(tmesh);
    if (mesh_grid.index1 != grid.index1) sdfccd_destroy_sdf(mesh_grid);
    sdfccd_SdfId all[] = { grid, csg, ball, sphere, torus };
    for (size_t i = 0; i < sizeof all / sizeof all[0]; ++i) sdfccd_destroy_sdf(all[i]);
    return 0;
}
