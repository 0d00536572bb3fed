/* SPDX-License-Identifier: MIT
 * Benchmark case files (cases.h): the parser and runner behind samples/sdfccd_cases.c and the
 * Python package's run_cases, so both give the same rows and the same messages. One record per line
 * (README "Case files"); each `case` runs sdfccd_query_mesh against a static SDF. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "capi_internal.h"
#include "../../core/ccd.h"
#include "sdfccd/cases.h"

#define CASES_MAX_NAMES 256
#define CASES_MAX_TOKENS 32
#define CASES_LINE 16384
#define CASES_CONTACTS 64 /* contact array of each query (the CLI's historical capacity) */

typedef struct named_sdf { char name[64]; sdfccd_SdfId id; } named_sdf;
typedef struct named_mesh { char name[64]; sdfccd_MeshId id; } named_mesh;

struct sdfccd_CaseRun {
    sdfccd_CaseRow* rows;
    int64_t count, capacity;
};

/* A line source: a FILE or a memory buffer, read the way fgets reads. */
typedef struct cases_source {
    FILE* f;
    const char* mem;
    size_t size, pos;
    int eof;
} cases_source;

/* fgets on either source: up to n - 1 bytes, through the first '\n'; NULL at the end. */
static char* source_gets(cases_source* s, char* buf, int n)
{
    if (s->f) {
        char* r = fgets(buf, n, s->f);
        s->eof = feof(s->f) != 0;
        return r;
    }
    int k = 0;
    while (k < n - 1) {
        if (s->pos >= s->size) { s->eof = 1; break; }
        char c = s->mem[s->pos++];
        buf[k++] = c;
        if (c == '\n') break;
    }
    if (k == 0) return NULL;
    buf[k] = '\0';
    return buf;
}

typedef struct cases_runner {
    named_sdf sdfs[CASES_MAX_NAMES];
    int sdf_count;
    named_mesh meshes[CASES_MAX_NAMES];
    int mesh_count;
    const sdfccd_CaseRunDef* def;
    const char* file;
    char dir[4096]; /* relative paths resolve against it ("" = current directory) */
    sdfccd_Contact* contacts;
    sdfccd_CaseRun* run;
    sdfccd_Status status; /* of the failure that stopped the run */
} cases_runner;

/* Stops the run: the message "FILE:LINE: msg[: detail]" with `status`; returns 0. */
static int fail_line(cases_runner* r, sdfccd_Status status, int line, const char* msg, const char* detail)
{
    char copy[512]; /* detail may be the thread's message itself, which sdfccd__error overwrites */
    snprintf(copy, sizeof copy, "%s", detail ? detail : "");
    r->status = sdfccd__error(status, "%s:%d: %s%s%s", r->file, line, msg, detail ? ": " : "", copy);
    return 0;
}

/* The status of a failing library call, with its name as the message and its message as detail. */
static int fail_call(cases_runner* r, int line, sdfccd_Status st)
{
    return fail_line(r, st, line, sdfccd_status_string(st), sdfccd_last_error());
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

static void resolve(const cases_runner* r, const char* path, char* out, size_t size)
{
    if (path[0] == '/' || r->dir[0] == '\0') snprintf(out, size, "%s", path);
    else snprintf(out, size, "%s/%s", r->dir, path);
}

static const sdfccd_SdfId* find_sdf(const cases_runner* r, const char* name)
{
    for (int i = 0; i < r->sdf_count; ++i)
        if (!strcmp(r->sdfs[i].name, name)) return &r->sdfs[i].id;
    return NULL;
}

static const sdfccd_MeshId* find_mesh(const cases_runner* r, const char* name)
{
    for (int i = 0; i < r->mesh_count; ++i)
        if (!strcmp(r->meshes[i].name, name)) return &r->meshes[i].id;
    return NULL;
}

static int record_sdf(cases_runner* r, int line, char** t, int n)
{
    const sdfccd_Status F = SDFCCD_FORMAT_ERROR;
    if (n < 3) return fail_line(r, F, line, "sdf record needs NAME KIND ...", NULL);
    if (r->sdf_count == CASES_MAX_NAMES) return fail_line(r, F, line, "too many sdf records", NULL);
    if (strlen(t[1]) >= sizeof r->sdfs[0].name) return fail_line(r, F, line, "name too long", t[1]);
    if (find_sdf(r, t[1])) return fail_line(r, F, line, "duplicate sdf name", t[1]);
    double v[3];
    sdfccd_Status st;
    sdfccd_SdfId id;
    if (!strcmp(t[2], "sphere")) {
        if (n != 4 || !parse_doubles(t + 3, 1, v)) return fail_line(r, F, line, "expected: sdf NAME sphere R", NULL);
        st = sdfccd_create_sphere(v[0], &id);
    } else if (!strcmp(t[2], "box")) {
        if (n != 6 || !parse_doubles(t + 3, 3, v)) return fail_line(r, F, line, "expected: sdf NAME box HX HY HZ", NULL);
        st = sdfccd_create_box((sdfccd_Vec3){ v[0], v[1], v[2] }, &id);
    } else if (!strcmp(t[2], "torus")) {
        if (n != 5 || !parse_doubles(t + 3, 2, v)) return fail_line(r, F, line, "expected: sdf NAME torus R r", NULL);
        st = sdfccd_create_torus(v[0], v[1], &id);
    } else if (!strcmp(t[2], "rounded_box")) {
        double w[4];
        if (n != 7 || !parse_doubles(t + 3, 4, w)) return fail_line(r, F, line, "expected: sdf NAME rounded_box HX HY HZ R", NULL);
        st = sdfccd_create_rounded_box((sdfccd_Vec3){ w[0], w[1], w[2] }, w[3], &id);
    } else if (!strcmp(t[2], "csg")) {
        /* a combination of two earlier records (issue 20: CSG with sharp seams in the data set) */
        static const char* ops[3] = { "union", "intersection", "difference" };
        int op = -1;
        for (int k = 0; n == 6 && k < 3; ++k)
            if (!strcmp(t[3], ops[k])) op = k;
        if (op < 0) return fail_line(r, F, line, "expected: sdf NAME csg union|intersection|difference A B", NULL);
        const sdfccd_SdfId* a = find_sdf(r, t[4]);
        const sdfccd_SdfId* b = find_sdf(r, t[5]);
        if (!a || !b) return fail_line(r, F, line, "unknown sdf", a ? t[5] : t[4]);
        st = sdfccd_create_csg((sdfccd_CsgOp)op, *a, *b, &id);
    } else if (!strcmp(t[2], "grid")) {
        if (n != 4) return fail_line(r, F, line, "expected: sdf NAME grid PATH", NULL);
        char path[8192];
        resolve(r, t[3], path, sizeof path);
        st = sdfccd_load_grid(path, &id);
    } else {
        return fail_line(r, F, line, "unknown sdf kind (sphere, box, rounded_box, torus, csg, grid)", t[2]);
    }
    if (st != SDFCCD_OK) return fail_call(r, line, st);
    snprintf(r->sdfs[r->sdf_count].name, sizeof r->sdfs[0].name, "%s", t[1]);
    r->sdfs[r->sdf_count++].id = id;
    return 1;
}

static int record_mesh(cases_runner* r, int line, char** t, int n)
{
    const sdfccd_Status F = SDFCCD_FORMAT_ERROR;
    if (n < 3) return fail_line(r, F, line, "mesh record needs NAME KIND ...", NULL);
    if (r->mesh_count == CASES_MAX_NAMES) return fail_line(r, F, line, "too many mesh records", NULL);
    if (strlen(t[1]) >= sizeof r->meshes[0].name) return fail_line(r, F, line, "name too long", t[1]);
    if (find_mesh(r, t[1])) return fail_line(r, F, line, "duplicate mesh name", t[1]);
    sdfccd_Status st;
    sdfccd_MeshId id;
    if (!strcmp(t[2], "triangle")) {
        double v[9];
        if (n != 12 || !parse_doubles(t + 3, 9, v))
            return fail_line(r, F, line, "expected: mesh NAME triangle AX AY AZ BX BY BZ CX CY CZ", NULL);
        const uint32_t idx[3] = { 0, 1, 2 };
        sdfccd_MeshDef def = sdfccd_default_mesh_def();
        def.vertices = v;
        def.vertex_count = 3;
        def.indices = idx;
        def.triangle_count = 1;
        st = sdfccd_create_mesh(&def, &id);
    } else if (!strcmp(t[2], "file")) {
        if (n != 4) return fail_line(r, F, line, "expected: mesh NAME file PATH", NULL);
        char path[8192];
        resolve(r, t[3], path, sizeof path);
        sdfccd_MeshLoadDef def = sdfccd_default_mesh_load_def();
        st = sdfccd_load_mesh(path, &def, &id);
    } else {
        return fail_line(r, F, line, "unknown mesh kind (triangle, file)", t[2]);
    }
    if (st != SDFCCD_OK) return fail_call(r, line, st);
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

/* The CSV's state column: the result state, a NOT_CONVERGED split by what stopped it. */
static sdfccd_CaseState case_state(const sdfccd_QueryResult* res, const sdfccd_QueryParams* p)
{
    switch (res->state) {
    case SDFCCD_STATE_HIT: return SDFCCD_CASE_HIT;
    case SDFCCD_STATE_NO_HIT: return SDFCCD_CASE_NO_HIT;
    case SDFCCD_STATE_PENETRATING: return SDFCCD_CASE_PENETRATING;
    default: break;
    }
    if (res->sdf_evaluations >= p->max_sdf_evaluations) return SDFCCD_CASE_BUDGET;
    return p->method == SDFCCD_METHOD_CERTIFIED ? SDFCCD_CASE_REGION_CAP : SDFCCD_CASE_ITERATION_CAP;
}

/* Appends a row (copying its id); 0 when out of memory. */
static int push_row(sdfccd_CaseRun* run, const sdfccd_CaseRow* row)
{
    if (run->count == run->capacity) {
        int64_t cap = run->capacity ? 2 * run->capacity : 64;
        sdfccd_CaseRow* rows = sdfccd__alloc(sizeof *rows * (size_t)cap);
        if (!rows) return 0;
        if (run->count) memcpy(rows, run->rows, sizeof *rows * (size_t)run->count);
        sdfccd__free(run->rows, sizeof *rows * (size_t)run->capacity);
        run->rows = rows;
        run->capacity = cap;
    }
    size_t len = strlen(row->id) + 1;
    char* id = sdfccd__alloc(len);
    if (!id) return 0;
    memcpy(id, row->id, len);
    run->rows[run->count] = *row;
    run->rows[run->count++].id = id;
    return 1;
}

static int record_case(cases_runner* r, int line, char** t, int n)
{
    const sdfccd_Status F = SDFCCD_FORMAT_ERROR;
    if (n != 18) return fail_line(r, F, line, "expected: case ID SDF MESH DT PX PY PZ QW QX QY QZ VX VY VZ WX WY WZ", NULL);
    const sdfccd_SdfId* sdf = find_sdf(r, t[2]);
    if (!sdf) return fail_line(r, F, line, "unknown sdf", t[2]);
    const sdfccd_MeshId* mesh = find_mesh(r, t[3]);
    if (!mesh) return fail_line(r, F, line, "unknown mesh", t[3]);
    double v[14];
    if (!parse_doubles(t + 4, 14, v)) return fail_line(r, F, line, "a number is malformed or not finite", NULL);
    if (!(v[0] >= 0.0)) return fail_line(r, F, line, "DT must be >= 0", t[4]);
    sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
    m.pose.position = (sdfccd_Vec3){ v[1], v[2], v[3] };
    m.pose.orientation = (sdfccd_Quat){ v[4], v[5], v[6], v[7] };
    m.linear_velocity = (sdfccd_Vec3){ v[8], v[9], v[10] };
    m.angular_velocity = (sdfccd_Vec3){ v[11], v[12], v[13] };
    sdfccd_QueryResult res;
    double start = now_micros();
    sdfccd_Status st = sdfccd_query_mesh(*sdf, NULL, *mesh, &m, 0.0, v[0], &r->def->params, r->contacts, CASES_CONTACTS, &res);
    double micros = now_micros() - start;
    if (st != SDFCCD_OK) return fail_call(r, line, st);
    sdfccd_CaseRow row;
    row.id = t[1];
    row.line = line;
    row.state = case_state(&res, &r->def->params);
    row.hit = res.hit && res.contact_count > 0;
    row.toi = NAN;
    row.point = row.normal = (sdfccd_Vec3){ NAN, NAN, NAN };
    if (row.hit) {
        row.toi = res.toi;
        row.point = r->contacts[0].point;
        row.normal = r->contacts[0].normal;
    }
    row.triangles_tested = res.triangles_tested;
    row.sdf_evaluations = res.sdf_evaluations;
    row.micros = micros;
    if (!push_row(r->run, &row)) {
        r->status = sdfccd__error(SDFCCD_OUT_OF_MEMORY, "%s:%d: out of memory while storing a row", r->file, line);
        return 0;
    }
    if (r->def->on_row) r->def->on_row(&row, r->def->user);
    return 1;
}

/* Splits `s` at blanks (" \t\r\n") in place; returns the token count, or -1 over `max`. */
static int tokenize(char* s, char** tok, int max)
{
    int n = 0;
    for (;;) {
        while (*s && strchr(" \t\r\n", *s)) ++s;
        if (!*s) return n;
        if (n == max) return -1;
        tok[n++] = s;
        while (*s && !strchr(" \t\r\n", *s)) ++s;
        if (*s) *s++ = '\0';
    }
}

static int run_source(cases_runner* r, cases_source* src, char* buf)
{
    int line = 0, header = 0, ok = 1;
    while (ok && source_gets(src, buf, CASES_LINE)) {
        ++line;
        if (!strchr(buf, '\n') && !src->eof) return fail_line(r, SDFCCD_FORMAT_ERROR, line, "line too long", NULL);
        char* hash = strchr(buf, '#');
        if (hash) *hash = '\0';
        char* tok[CASES_MAX_TOKENS];
        int n = tokenize(buf, tok, CASES_MAX_TOKENS);
        if (n < 0) return fail_line(r, SDFCCD_FORMAT_ERROR, line, "too many tokens", NULL);
        if (n == 0) continue;
        if (!header) {
            if (n != 2 || strcmp(tok[0], "sdfccd-cases") || strcmp(tok[1], "1"))
                return fail_line(r, SDFCCD_FORMAT_ERROR, line, "the first record must be 'sdfccd-cases 1'", NULL);
            header = 1;
            continue;
        }
        if (!strcmp(tok[0], "sdf")) ok = record_sdf(r, line, tok, n);
        else if (!strcmp(tok[0], "mesh")) ok = record_mesh(r, line, tok, n);
        else if (!strcmp(tok[0], "case")) ok = record_case(r, line, tok, n);
        else ok = fail_line(r, SDFCCD_FORMAT_ERROR, line, "unknown record", tok[0]);
    }
    if (ok && src->f && ferror(src->f)) return fail_line(r, SDFCCD_IO_ERROR, line, "read error", NULL);
    if (ok && !header) return fail_line(r, SDFCCD_FORMAT_ERROR, line, "empty file (no 'sdfccd-cases 1' header)", NULL);
    return ok;
}

sdfccd_CaseRunDef sdfccd_default_case_run_def(void)
{
    sdfccd_CaseRunDef d;
    SDFCCD__DEF_BEGIN(d);
    d.params = sdfccd_default_query_params();
    return d;
}

const char* sdfccd_case_state_string(sdfccd_CaseState state)
{
    static const char* const names[SDFCCD_CASE_STATE_COUNT] = { "hit", "no_hit", "penetrating", "budget", "region_cap",
                                                                "iteration_cap" };
    return (unsigned)state < SDFCCD_CASE_STATE_COUNT ? names[state] : "?";
}

void sdfccd_destroy_case_run(sdfccd_CaseRun* run)
{
    if (!run) return;
    for (int64_t i = 0; i < run->count; ++i) sdfccd__free((void*)run->rows[i].id, strlen(run->rows[i].id) + 1);
    sdfccd__free(run->rows, sizeof *run->rows * (size_t)run->capacity);
    sdfccd__free(run, sizeof *run);
}

int64_t sdfccd_case_run_row_count(const sdfccd_CaseRun* run) { return run ? run->count : 0; }

const sdfccd_CaseRow* sdfccd_case_run_rows(const sdfccd_CaseRun* run) { return run && run->count ? run->rows : NULL; }

/* The checks of both entry points: def, out_run and the query parameters. */
static sdfccd_Status check_args(const char* fn, const sdfccd_CaseRunDef* def, sdfccd_CaseRun** out_run)
{
    sdfccd_Status st = SDFCCD__CHECK_DEF_ARGS(fn, def, out_run, "out_run", "sdfccd_default_case_run_def");
    if (st != SDFCCD_OK) return st;
    scc_params checked;
    return sdfccd__convert_params(&def->params, fn, &checked);
}

/* Shared by both entry points (after check_args): runs the source, frees what the file created. */
static sdfccd_Status run_cases(cases_source* src, const char* file, const char* dir,
                               const sdfccd_CaseRunDef* def, sdfccd_CaseRun** out_run)
{
    sdfccd_Status st;
    cases_runner* r = sdfccd__calloc(sizeof *r);
    char* buf = sdfccd__alloc(CASES_LINE);
    if (r) {
        r->contacts = sdfccd__alloc(sizeof *r->contacts * CASES_CONTACTS);
        r->run = sdfccd__calloc(sizeof *r->run);
    }
    int ok = 0;
    if (r && buf && r->contacts && r->run) {
        r->def = def;
        r->file = def->name ? def->name : file;
        snprintf(r->dir, sizeof r->dir, "%s", def->base_dir ? def->base_dir : dir);
        ok = run_source(r, src, buf);
        st = ok ? SDFCCD_OK : r->status;
        for (int i = 0; i < r->sdf_count; ++i) sdfccd_destroy_sdf(r->sdfs[i].id);
        for (int i = 0; i < r->mesh_count; ++i) sdfccd_destroy_mesh(r->meshes[i].id);
    } else {
        st = sdfccd__oom("a case run");
    }
    sdfccd__free(buf, CASES_LINE);
    if (r) {
        sdfccd__free(r->contacts, sizeof *r->contacts * CASES_CONTACTS);
        if (ok) *out_run = r->run;
        else sdfccd_destroy_case_run(r->run);
        sdfccd__free(r, sizeof *r);
    }
    return st;
}

sdfccd_Status sdfccd_run_case_file(const char* path, const sdfccd_CaseRunDef* def, sdfccd_CaseRun** out_run)
{
    if (out_run) *out_run = NULL;
    if (!path) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_run_case_file: path is NULL");
    sdfccd_Status st = check_args("sdfccd_run_case_file", def, out_run);
    if (st != SDFCCD_OK) return st;
    FILE* f = fopen(path, "r");
    if (!f) return sdfccd__error(SDFCCD_IO_ERROR, "cannot open '%s': %s", path, strerror(errno));
    char dir[4096] = "";
    const char* slash = strrchr(path, '/');
    if (slash) snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    cases_source src = { f, NULL, 0, 0, 0 };
    st = run_cases(&src, path, dir, def, out_run);
    fclose(f);
    return st;
}

sdfccd_Status sdfccd_run_case_memory(const char* text, size_t size, const sdfccd_CaseRunDef* def, sdfccd_CaseRun** out_run)
{
    if (out_run) *out_run = NULL;
    if (!text && size) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_run_case_memory: text is NULL");
    sdfccd_Status st = check_args("sdfccd_run_case_memory", def, out_run);
    if (st != SDFCCD_OK) return st;
    cases_source src = { NULL, text, size, 0, 0 };
    return run_cases(&src, "memory", "", def, out_run);
}
