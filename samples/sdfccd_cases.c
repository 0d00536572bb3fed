/* SPDX-License-Identifier: MIT
 * sdfccd_cases: runs a benchmark case file (version 1, DESIGN.md) and prints one CSV row per case.
 *
 *   sdfccd_cases [--method dcd|fw|fwgss|certified] [--no-subdivision] [--margin M] FILE
 *
 * Output header: id,hit,toi,x,y,z,nx,ny,nz,triangles_tested,sdf_evals,micros
 * Errors (unreadable file, bad record, unknown name) go to stderr with the line number; the exit
 * status is 0 on success, 1 on a bad file, 2 on bad usage.
 * tests/fuzz/fuzz_cases.c includes this file with SDFCCD_CASES_NO_MAIN to fuzz run_file(). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sdfccd/sdfccd.h"

#define MAX_NAMES 256
#define MAX_TOKENS 32

typedef struct named_sdf { char name[64]; sdfccd_SdfId id; } named_sdf;
typedef struct named_mesh { char name[64]; sdfccd_MeshId id; } named_mesh;

typedef struct runner {
    named_sdf sdfs[MAX_NAMES];
    int sdf_count;
    named_mesh meshes[MAX_NAMES];
    int mesh_count;
    sdfccd_QueryParams params;
    const char* file;
    char dir[4096]; /* folder of the case file: relative paths resolve against it */
    sdfccd_Contact* contacts;
    int capacity;
    int csv_header_printed; /* the CSV header goes out with the first result, never before an error */
} runner;

static void print_csv_header(runner* r)
{
    if (r->csv_header_printed) return;
    printf("id,hit,toi,x,y,z,nx,ny,nz,triangles_tested,sdf_evals,micros\n");
    r->csv_header_printed = 1;
}

static void usage(FILE* f)
{
    fprintf(f,
            "usage: sdfccd_cases [--method dcd|fw|fwgss|certified] [--no-subdivision] [--margin M] FILE\n"
            "Runs a benchmark case file (format v1, see the README) and prints CSV:\n"
            "id,hit,toi,x,y,z,nx,ny,nz,triangles_tested,sdf_evals,micros\n"
            "Defaults: --method fwgss, subdivision on, --margin 0.\n");
}

static int fail_line(const runner* r, int line, const char* msg, const char* detail)
{
    fprintf(stderr, "sdfccd_cases: %s:%d: %s%s%s\n", r->file, line, msg, detail ? ": " : "", detail ? detail : "");
    return 0;
}

static int parse_doubles(char** tok, int n, double* out)
{
    for (int i = 0; i < n; ++i) {
        char* end;
        errno = 0;
        out[i] = strtod(tok[i], &end);
        if (*end != '\0' || errno == ERANGE || !isfinite(out[i])) return 0;
    }
    return 1;
}

static void resolve(const runner* r, const char* path, char* out, size_t size)
{
    if (path[0] == '/' || r->dir[0] == '\0') snprintf(out, size, "%s", path);
    else snprintf(out, size, "%s/%s", r->dir, path);
}

static const sdfccd_SdfId* find_sdf(const runner* r, const char* name)
{
    for (int i = 0; i < r->sdf_count; ++i)
        if (!strcmp(r->sdfs[i].name, name)) return &r->sdfs[i].id;
    return NULL;
}

static const sdfccd_MeshId* find_mesh(const runner* r, const char* name)
{
    for (int i = 0; i < r->mesh_count; ++i)
        if (!strcmp(r->meshes[i].name, name)) return &r->meshes[i].id;
    return NULL;
}

static int record_sdf(runner* r, int line, char** t, int n)
{
    if (n < 3) return fail_line(r, line, "sdf record needs NAME KIND ...", NULL);
    if (r->sdf_count == MAX_NAMES) return fail_line(r, line, "too many sdf records", NULL);
    if (strlen(t[1]) >= sizeof r->sdfs[0].name) return fail_line(r, line, "name too long", t[1]);
    if (find_sdf(r, t[1])) return fail_line(r, line, "duplicate sdf name", t[1]);
    double v[3];
    sdfccd_Status st;
    sdfccd_SdfId id;
    if (!strcmp(t[2], "sphere")) {
        if (n != 4 || !parse_doubles(t + 3, 1, v)) return fail_line(r, line, "expected: sdf NAME sphere R", NULL);
        st = sdfccd_create_sphere(v[0], &id);
    } else if (!strcmp(t[2], "box")) {
        if (n != 6 || !parse_doubles(t + 3, 3, v)) return fail_line(r, line, "expected: sdf NAME box HX HY HZ", NULL);
        st = sdfccd_create_box((sdfccd_Vec3){ v[0], v[1], v[2] }, &id);
    } else if (!strcmp(t[2], "torus")) {
        if (n != 5 || !parse_doubles(t + 3, 2, v)) return fail_line(r, line, "expected: sdf NAME torus R r", NULL);
        st = sdfccd_create_torus(v[0], v[1], &id);
    } else if (!strcmp(t[2], "grid")) {
        if (n != 4) return fail_line(r, line, "expected: sdf NAME grid PATH", NULL);
        char path[8192];
        resolve(r, t[3], path, sizeof path);
        st = sdfccd_load_grid(path, &id);
    } else {
        return fail_line(r, line, "unknown sdf kind (sphere, box, torus, grid)", t[2]);
    }
    if (st != SDFCCD_OK) return fail_line(r, line, sdfccd_status_string(st), sdfccd_last_error());
    snprintf(r->sdfs[r->sdf_count].name, sizeof r->sdfs[0].name, "%s", t[1]);
    r->sdfs[r->sdf_count++].id = id;
    return 1;
}

static int record_mesh(runner* r, int line, char** t, int n)
{
    if (n < 3) return fail_line(r, line, "mesh record needs NAME KIND ...", NULL);
    if (r->mesh_count == MAX_NAMES) return fail_line(r, line, "too many mesh records", NULL);
    if (strlen(t[1]) >= sizeof r->meshes[0].name) return fail_line(r, line, "name too long", t[1]);
    if (find_mesh(r, t[1])) return fail_line(r, line, "duplicate mesh name", t[1]);
    sdfccd_Status st;
    sdfccd_MeshId id;
    if (!strcmp(t[2], "triangle")) {
        double v[9];
        if (n != 12 || !parse_doubles(t + 3, 9, v)) return fail_line(r, line, "expected: mesh NAME triangle AX AY AZ BX BY BZ CX CY CZ", NULL);
        const uint32_t idx[3] = { 0, 1, 2 };
        sdfccd_MeshDef def = sdfccd_default_mesh_def();
        def.vertices = v;
        def.vertex_count = 3;
        def.indices = idx;
        def.triangle_count = 1;
        st = sdfccd_create_mesh(&def, &id);
    } else if (!strcmp(t[2], "file")) {
        if (n != 4) return fail_line(r, line, "expected: mesh NAME file PATH", NULL);
        char path[8192];
        resolve(r, t[3], path, sizeof path);
        sdfccd_MeshLoadDef def = sdfccd_default_mesh_load_def();
        st = sdfccd_load_mesh(path, &def, &id);
    } else {
        return fail_line(r, line, "unknown mesh kind (triangle, file)", t[2]);
    }
    if (st != SDFCCD_OK) return fail_line(r, line, sdfccd_status_string(st), sdfccd_last_error());
    snprintf(r->meshes[r->mesh_count].name, sizeof r->meshes[0].name, "%s", t[1]);
    r->meshes[r->mesh_count++].id = id;
    return 1;
}

static double now_micros(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e6 + ts.tv_nsec * 1e-3;
}

static int record_case(runner* r, int line, char** t, int n)
{
    if (n != 18) return fail_line(r, line, "expected: case ID SDF MESH DT PX PY PZ QW QX QY QZ VX VY VZ WX WY WZ", NULL);
    const sdfccd_SdfId* sdf = find_sdf(r, t[2]);
    if (!sdf) return fail_line(r, line, "unknown sdf", t[2]);
    const sdfccd_MeshId* mesh = find_mesh(r, t[3]);
    if (!mesh) return fail_line(r, line, "unknown mesh", t[3]);
    double v[14];
    if (!parse_doubles(t + 4, 14, v)) return fail_line(r, line, "a number is malformed or not finite", NULL);
    if (!(v[0] >= 0.0)) return fail_line(r, line, "DT must be >= 0", t[4]);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = (sdfccd_Vec3){ v[1], v[2], v[3] };
    m.pose.orientation = (sdfccd_Quat){ v[4], v[5], v[6], v[7] };
    m.linear_velocity = (sdfccd_Vec3){ v[8], v[9], v[10] };
    m.angular_velocity = (sdfccd_Vec3){ v[11], v[12], v[13] };
    sdfccd_QueryResult res;
    print_csv_header(r);
    double t0 = now_micros();
    sdfccd_Status st = sdfccd_query_mesh(*sdf, NULL, *mesh, &m, 0.0, v[0], &r->params, r->contacts, r->capacity, &res);
    double micros = now_micros() - t0;
    if (st != SDFCCD_OK) return fail_line(r, line, sdfccd_status_string(st), sdfccd_last_error());
    if (res.hit && res.contact_count > 0) {
        const sdfccd_Contact* c = &r->contacts[0];
        printf("%s,1,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%lld,%lld,%.3f\n", t[1], res.toi, c->point.x, c->point.y, c->point.z,
               c->normal.x, c->normal.y, c->normal.z, (long long)res.triangles_tested, (long long)res.sdf_evaluations, micros);
    } else {
        printf("%s,0,,,,,,,,%lld,%lld,%.3f\n", t[1], (long long)res.triangles_tested, (long long)res.sdf_evaluations, micros);
    }
    return 1;
}

static int run_file(runner* r, FILE* f)
{
    char buf[16384];
    int line = 0, header = 0, ok = 1;
    while (ok && fgets(buf, sizeof buf, f)) {
        ++line;
        if (!strchr(buf, '\n') && !feof(f)) return fail_line(r, line, "line too long", NULL);
        char* hash = strchr(buf, '#');
        if (hash) *hash = '\0';
        char* tok[MAX_TOKENS];
        int n = 0;
        for (char* s = strtok(buf, " \t\r\n"); s; s = strtok(NULL, " \t\r\n")) {
            if (n == MAX_TOKENS) return fail_line(r, line, "too many tokens", NULL);
            tok[n++] = s;
        }
        if (n == 0) continue;
        if (!header) {
            if (n != 2 || strcmp(tok[0], "sdfccd-cases") || strcmp(tok[1], "1"))
                return fail_line(r, line, "the first record must be 'sdfccd-cases 1'", NULL);
            header = 1;
            continue;
        }
        if (!strcmp(tok[0], "sdf")) ok = record_sdf(r, line, tok, n);
        else if (!strcmp(tok[0], "mesh")) ok = record_mesh(r, line, tok, n);
        else if (!strcmp(tok[0], "case")) ok = record_case(r, line, tok, n);
        else ok = fail_line(r, line, "unknown record", tok[0]);
        fflush(stdout);
    }
    if (ok && !header) return fail_line(r, line, "empty file (no 'sdfccd-cases 1' header)", NULL);
    if (ok) print_csv_header(r); /* a file without cases still gives a (header-only) CSV */
    return ok;
}

#ifndef SDFCCD_CASES_NO_MAIN
int main(int argc, char** argv)
{
    static runner r;
    r.params = sdfccd_default_query_params();
    const char* file = NULL;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) { usage(stdout); return 0; }
        if (!strcmp(argv[i], "--no-subdivision")) { r.params.subdivision = 0; continue; }
        if (!strcmp(argv[i], "--method") && i + 1 < argc) {
            const char* m = argv[++i];
            if (!strcmp(m, "dcd")) r.params.method = SDFCCD_METHOD_DCD;
            else if (!strcmp(m, "fw")) r.params.method = SDFCCD_METHOD_FW;
            else if (!strcmp(m, "fwgss")) r.params.method = SDFCCD_METHOD_FWGSS;
            else if (!strcmp(m, "certified")) r.params.method = SDFCCD_METHOD_CERTIFIED;
            else { fprintf(stderr, "sdfccd_cases: unknown method '%s'\n", m); usage(stderr); return 2; }
            continue;
        }
        if (!strcmp(argv[i], "--margin") && i + 1 < argc) {
            char* end;
            r.params.margin = strtod(argv[++i], &end);
            if (*end || !isfinite(r.params.margin)) { fprintf(stderr, "sdfccd_cases: bad margin '%s'\n", argv[i]); return 2; }
            continue;
        }
        if (argv[i][0] == '-' && argv[i][1] != '\0') { fprintf(stderr, "sdfccd_cases: unknown option '%s'\n", argv[i]); usage(stderr); return 2; }
        if (file) { fprintf(stderr, "sdfccd_cases: more than one FILE\n"); usage(stderr); return 2; }
        file = argv[i];
    }
    if (!file) { usage(stderr); return 2; }
    r.file = file;
    const char* slash = strrchr(file, '/');
    if (slash) snprintf(r.dir, sizeof r.dir, "%.*s", (int)(slash - file), file);
    FILE* f = fopen(file, "r");
    if (!f) { fprintf(stderr, "sdfccd_cases: cannot open '%s': %s\n", file, strerror(errno)); return 1; }
    r.capacity = 64;
    r.contacts = malloc(sizeof *r.contacts * (size_t)r.capacity);
    int ok = r.contacts && run_file(&r, f);
    fclose(f);
    free(r.contacts);
    for (int i = 0; i < r.sdf_count; ++i) sdfccd_destroy_sdf(r.sdfs[i].id);
    for (int i = 0; i < r.mesh_count; ++i) sdfccd_destroy_mesh(r.meshes[i].id);
    return ok ? 0 : 1;
}
#endif
