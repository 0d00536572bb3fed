/* SPDX-License-Identifier: MIT
 * sdfccd_bake: builds a Discregrid-compatible grid SDF (.cdf) from a mesh file.
 *
 *   sdfccd_bake MESH -r N [-d "minx miny minz maxx maxy maxz" | --pad P] [--band W] [-t threads]
 *               [-i] [--allow-open] [--samples K] -o OUT.cdf
 *   sdfccd_bake --check GRID.cdf
 *   sdfccd_bake --version
 *
 * -r takes one count (N^3 cells) or three ("NX NY NZ" or NX,NY,NZ). Without -d the domain is
 * Discregrid's fitted box. Prints progress to standard error (a bar on a terminal, else a line
 * per 10 %) and a summary: cells, nodes, bytes, build time, and the max / RMS error of the grid against the
 * exact mesh distance at K random points of the domain (default 20000).
 * --check loads a .cdf (from here, Discregrid or elsewhere) and says whether it behaves like a
 * distance field: the CCD steps along paths by the grid's bound on |grad phi|, so a grid whose
 * bound is far above 1 (sign errors, floating pockets) can hide contacts between its samples.
 * Exit status: 0 on success, 1 when the mesh cannot be loaded or the grid built, written or read (the
 * library's message on stderr), 2 on bad usage, 3 when --check finds a grid that is not a distance field.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "sdfccd/sdfccd.h"

static void usage(FILE* f)
{
    fprintf(f,
            "usage: sdfccd_bake MESH -r N [-d \"minx miny minz maxx maxy maxz\" | --pad P] [--band W] [-t threads]\n"
            "                   [-i] [--allow-open] [--samples K] -o OUT.cdf\n"
            "  MESH          any mesh file assimp reads (OBJ is read in double precision)\n"
            "  -r N          cells per axis: N, or \"NX NY NZ\" / NX,NY,NZ\n"
            "  -d BOX        domain (metres, mesh frame); default: the mesh box enlarged by 0.1%% of its diagonal\n"
            "  --pad P       with the default domain: add P metres on every side\n"
            "  --band W      keep only cells within W (+ one cell diagonal) of the surface; default dense\n"
            "  -t T          threads (default: all cores)\n"
            "  -i            store -phi (positive inside), for containers\n"
            "  --allow-open  build even if the mesh is not closed (signs near holes are unreliable)\n"
            "  --samples K   random points for the error summary (default 20000, 0 to skip)\n"
            "  -o OUT        output .cdf file\n"
            "  --version     print the library version and configuration, then exit\n"
            "       sdfccd_bake --check GRID.cdf\n"
            "  --check FILE  describe a .cdf and warn when it is not a distance field (exit 3)\n");
}

static int fail(const char* what, sdfccd_Status st)
{
    fprintf(stderr, "sdfccd_bake: error: %s: %s (%s)\n", what, sdfccd_last_error(), sdfccd_status_string(st));
    return 1;
}

static int parse_numbers(const char* s, double* out, int max)
{
    int n = 0;
    const char* p = s;
    while (*p && n < max) {
        while (*p == ' ' || *p == ',' || *p == '\t') ++p;
        if (!*p) break;
        char* end;
        errno = 0;
        double v = strtod(p, &end);
        if (end == p || errno) return -1;
        out[n++] = v;
        p = end;
    }
    while (*p == ' ' || *p == ',' || *p == '\t') ++p;
    return *p ? -1 : n;
}

static int s_tty = 0;
static int s_last_tenth = -1; /* last 10 % step printed when stderr is not a terminal */
static int32_t progress(double f, void* user)
{
    (void)user;
    if (!s_tty) {
        const int tenth = (int)floor(f * 10.0 + 1e-9);
        while (s_last_tenth < tenth) fprintf(stderr, "  building: %d%%\n", 10 * ++s_last_tenth);
        fflush(stderr);
        return 0;
    }
    const int width = 40, filled = (int)(f * width + 0.5);
    fprintf(stderr, "\r  building [");
    for (int i = 0; i < width; ++i) fputc(i < filled ? '#' : ' ', stderr);
    fprintf(stderr, "] %5.1f%%", 100.0 * f);
    if (f >= 1.0) fputc('\n', stderr);
    fflush(stderr);
    return 0;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A cubic cell's bound on |grad phi| is looser than the field's slope: the meshes baked here give 1.7
 * to 3.6 at 5 to 64 cells per axis. Twice the loosest of them marks a field that is not a distance. */
#define STEEP_BOUND 8.0

static void print_grid(const sdfccd_GridInfo* gi)
{
    printf("grid: %d x %d x %d cells, domain [%.9g %.9g %.9g] - [%.9g %.9g %.9g], cell size %.6g x %.6g x %.6g\n", gi->resolution[0],
           gi->resolution[1], gi->resolution[2], gi->domain.lo.x, gi->domain.lo.y, gi->domain.lo.z, gi->domain.hi.x, gi->domain.hi.y,
           gi->domain.hi.z, gi->cell_size.x, gi->cell_size.y, gi->cell_size.z);
}

/* --check: per-cell gradient bounds of a loaded grid, the steepest cell and a verdict. */
static int check_grid(const char* path)
{
    sdfccd_SdfId grid;
    sdfccd_Status st = sdfccd_load_grid(path, &grid);
    if (st) return fail("reading the grid", st);
    sdfccd_GridInfo gi;
    sdfccd_grid_get_info(grid, &gi);
    print_grid(&gi);
    printf("cells: %lld with values of %lld; nodes: %lld; fields: %d\n", (long long)gi.valued_cells, (long long)gi.cell_count,
           (long long)gi.node_count, gi.field_count);
    long long steep = 0;
    double worst = 0.0;
    sdfccd_Aabb worst_box = gi.domain;
    const sdfccd_Vec3 h = gi.cell_size, e = { 1e-6 * h.x, 1e-6 * h.y, 1e-6 * h.z };
    for (int k = 0; k < gi.resolution[2]; ++k)
        for (int j = 0; j < gi.resolution[1]; ++j)
            for (int i = 0; i < gi.resolution[0]; ++i) {
                const sdfccd_Vec3 lo = { gi.domain.lo.x + i * h.x, gi.domain.lo.y + j * h.y, gi.domain.lo.z + k * h.z };
                const sdfccd_Aabb cell = { lo, { lo.x + h.x, lo.y + h.y, lo.z + h.z } };
                const sdfccd_Aabb inner = { { cell.lo.x + e.x, cell.lo.y + e.y, cell.lo.z + e.z }, { cell.hi.x - e.x, cell.hi.y - e.y, cell.hi.z - e.z } };
                double bound = 0.0;
                if (sdfccd_grid_lipschitz_bound(grid, inner, &bound)) continue;
                if (bound > STEEP_BOUND) ++steep;
                if (bound > worst) { worst = bound; worst_box = cell; }
            }
    printf("gradient bound: |grad phi| <= %.4g (a distance field has 1; cubic cells' bounds reach about 4)\n", gi.max_lipschitz);
    printf("steepest cell: bound %.4g in [%.6g %.6g %.6g] - [%.6g %.6g %.6g]\n", worst, worst_box.lo.x, worst_box.lo.y, worst_box.lo.z,
           worst_box.hi.x, worst_box.hi.y, worst_box.hi.z);
    sdfccd_destroy_sdf(grid);
    if (steep == 0) {
        printf("verdict: a distance field (every cell's bound <= %g)\n", STEEP_BOUND);
        return 0;
    }
    printf("warning: %s is not a distance field: %lld cells have a gradient bound above %g. The CCD can miss contacts there "
           "(sign errors or a pocket of negative values between samples); re-bake it from its mesh with sdfccd_bake.\n",
           path, steep, STEEP_BOUND);
    return 3;
}

int main(int argc, char** argv)
{
    const char *mesh_path = NULL, *out_path = NULL;
    sdfccd_GridDef def = sdfccd_default_grid_def();
    int have_r = 0, samples = 20000;
    for (int i = 1; i < argc; ++i) {
        const char* a = argv[i];
        const int has_next = i + 1 < argc;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) { usage(stdout); return 0; }
        else if (!strcmp(a, "--check")) {
            if (!has_next || argc != 3) { fprintf(stderr, "sdfccd_bake: error: --check takes one .cdf file and no other option\n"); return 2; }
            return check_grid(argv[2]);
        } else if (!strcmp(a, "--version")) { printf("sdfccd_bake %s (%s)\n", sdfccd_version_string(), sdfccd_configuration_string()); return 0; }
        else if (!strcmp(a, "-r") && has_next) {
            double v[3];
            int n = parse_numbers(argv[++i], v, 3);
            if (n != 1 && n != 3) { fprintf(stderr, "sdfccd_bake: error: -r expects 1 or 3 counts, got '%s'\n", argv[i]); return 2; }
            for (int k = 0; k < 3; ++k) {
                double c = v[n == 1 ? 0 : k];
                if (!(c >= 1 && c <= 4096) || c != floor(c)) { fprintf(stderr, "sdfccd_bake: error: resolution '%s' must be whole numbers in [1, 4096]\n", argv[i]); return 2; }
                def.resolution[k] = (int32_t)c;
            }
            have_r = 1;
        } else if (!strcmp(a, "-d") && has_next) {
            double v[6];
            if (parse_numbers(argv[++i], v, 6) != 6) { fprintf(stderr, "sdfccd_bake: error: -d expects 6 numbers, got '%s'\n", argv[i]); return 2; }
            def.fit_domain = 0;
            def.domain = (sdfccd_Aabb){ { v[0], v[1], v[2] }, { v[3], v[4], v[5] } };
        } else if (!strcmp(a, "--pad") && has_next) {
            double v;
            if (parse_numbers(argv[++i], &v, 1) != 1 || !(v >= 0)) { fprintf(stderr, "sdfccd_bake: error: --pad expects a width >= 0, got '%s'\n", argv[i]); return 2; }
            def.padding = v;
        } else if (!strcmp(a, "--band") && has_next) {
            double v;
            if (parse_numbers(argv[++i], &v, 1) != 1 || !(v > 0)) { fprintf(stderr, "sdfccd_bake: error: --band expects a positive width, got '%s'\n", argv[i]); return 2; }
            def.band = v;
        } else if (!strcmp(a, "-t") && has_next) {
            double v;
            if (parse_numbers(argv[++i], &v, 1) != 1 || !(v >= 0 && v <= 256) || v != floor(v)) { fprintf(stderr, "sdfccd_bake: error: -t expects 0..256, got '%s'\n", argv[i]); return 2; }
            def.threads = (int32_t)v;
        } else if (!strcmp(a, "--samples") && has_next) {
            double v;
            if (parse_numbers(argv[++i], &v, 1) != 1 || !(v >= 0 && v <= 1e8)) { fprintf(stderr, "sdfccd_bake: error: --samples expects a count, got '%s'\n", argv[i]); return 2; }
            samples = (int)v;
        } else if (!strcmp(a, "-i") || !strcmp(a, "--invert")) def.invert = 1;
        else if (!strcmp(a, "--allow-open")) def.allow_open_mesh = 1;
        else if (!strcmp(a, "-o") && has_next) out_path = argv[++i];
        else if (a[0] == '-' && a[1]) { fprintf(stderr, "sdfccd_bake: error: unknown or incomplete option '%s'\n", a); usage(stderr); return 2; }
        else if (!mesh_path) mesh_path = a;
        else { fprintf(stderr, "sdfccd_bake: error: more than one mesh given ('%s', '%s')\n", mesh_path, a); return 2; }
    }
    if (!mesh_path || !out_path || !have_r) {
        fprintf(stderr, "sdfccd_bake: error: %s\n", !mesh_path ? "no mesh file given" : (!out_path ? "no output file given (-o)" : "no resolution given (-r)"));
        usage(stderr);
        return 2;
    }
    s_tty = isatty(2);

    sdfccd_MeshId mesh;
    sdfccd_Status st = sdfccd_load_mesh(mesh_path, NULL, &mesh);
    if (st) return fail("loading the mesh", st);
    sdfccd_MeshInfo mi;
    sdfccd_mesh_get_info(mesh, &mi);
    sdfccd_MeshTopology topo;
    sdfccd_mesh_get_topology(mesh, &topo);
    printf("mesh: %s: %u vertices, %u triangles (%u degenerate dropped), %s, volume %.6g\n", mesh_path, mi.vertex_count, mi.triangle_count,
           mi.dropped_triangles, topo.closed ? "closed" : "NOT closed", topo.volume);

    def.progress = progress;
    const double t0 = now();
    sdfccd_SdfId grid;
    st = sdfccd_create_grid_from_mesh(mesh, &def, &grid);
    const double build_s = now() - t0;
    if (st) { sdfccd_destroy_mesh(mesh); return fail("building the grid", st); }
    st = sdfccd_save_grid(grid, out_path);
    if (st) { sdfccd_destroy_sdf(grid); sdfccd_destroy_mesh(mesh); return fail("writing the file", st); }

    sdfccd_GridInfo gi;
    sdfccd_grid_get_info(grid, &gi);
    print_grid(&gi);
    printf("cells: %lld stored of %lld%s; nodes: %lld; memory: %lld bytes; file: %lld bytes -> %s\n", (long long)gi.stored_cells,
           (long long)gi.cell_count, def.band > 0 ? " (narrow band)" : "", (long long)gi.node_count, (long long)gi.memory_bytes,
           (long long)gi.file_bytes, out_path);
    printf("build time: %.3f s (%d threads%s)\n", build_s, def.threads, def.threads == 0 ? " = all cores" : "");

    if (samples > 0) {
        sdfccd_Vec3* p = malloc((size_t)samples * sizeof *p);
        double* exact = malloc((size_t)samples * sizeof *exact);
        if (!p || !exact) { fprintf(stderr, "sdfccd_bake: error: out of memory for the error summary\n"); return 1; }
        uint64_t s = 0x5DFCCDull;
        for (int i = 0; i < samples; ++i) {
            double u[3];
            for (int k = 0; k < 3; ++k) {
                s = s * 6364136223846793005ull + 1442695040888963407ull;
                u[k] = (double)(s >> 11) * (1.0 / 9007199254740992.0);
            }
            p[i] = (sdfccd_Vec3){ gi.domain.lo.x + u[0] * (gi.domain.hi.x - gi.domain.lo.x), gi.domain.lo.y + u[1] * (gi.domain.hi.y - gi.domain.lo.y),
                                  gi.domain.lo.z + u[2] * (gi.domain.hi.z - gi.domain.lo.z) };
        }
        st = sdfccd_mesh_signed_distance(mesh, p, samples, def.allow_open_mesh, exact, NULL);
        if (st) return fail("computing exact distances", st);
        double max_e = 0, sum2 = 0;
        int n = 0, culled = 0;
        for (int i = 0; i < samples; ++i) {
            double v;
            int32_t has;
            sdfccd_grid_interpolate(grid, 0, p[i], &v, NULL, &has);
            if (!has) { ++culled; continue; }
            const double e = fabs(v - (def.invert ? -exact[i] : exact[i]));
            max_e = fmax(max_e, e);
            sum2 += e * e;
            ++n;
        }
        const double diag = sqrt(pow(gi.domain.hi.x - gi.domain.lo.x, 2) + pow(gi.domain.hi.y - gi.domain.lo.y, 2) + pow(gi.domain.hi.z - gi.domain.lo.z, 2));
        printf("error vs exact mesh distance at %d random points in the domain%s: max %.3g m (%.2g of the diagonal), RMS %.3g m\n", n,
               culled ? " with values" : "", max_e, max_e / diag, n ? sqrt(sum2 / n) : 0.0);
        if (culled) printf("  (%d points fell in culled cells, where the grid returns a conservative bound)\n", culled);
        free(p);
        free(exact);
    }
    sdfccd_destroy_sdf(grid);
    sdfccd_destroy_mesh(mesh);
    return 0;
}
