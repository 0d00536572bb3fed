/* SPDX-License-Identifier: MIT
 * Case files in the library (cases.h, issues 20 and 22): rows with the closed-form time of impact,
 * every result state of the CSV's `state` column reached by the cap that names it, the exact
 * "FILE:LINE: ..." messages of malformed files, no rows and no memory left after an error, and the
 * row callback in file order. Public ABI only. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

/* A sphere of radius 0.1 and a triangle around the local origin starting 0.3 m above it. */
static const char* k_head = "sdfccd-cases 1\n"
                            "sdf ball sphere 0.1   # comment\n"
                            "mesh tri triangle -0.01 -0.01 0  0.01 -0.01 0  0 0.01 0\n";

static sdfccd_Status run_text(const char* text, const sdfccd_CaseRunDef* def, sdfccd_CaseRun** run)
{
    return sdfccd_run_case_memory(text, strlen(text), def, run);
}

static void append_case(char* buf, size_t size, const char* id, double z, double vz, double wz)
{
    size_t n = strlen(buf);
    snprintf(buf + n, size - n, "case %s ball tri 0.016666666666666666 0 0 %.17g 1 0 0 0 0 0 %.17g 0 0 %.17g\n", id, z, vz, wz);
}

START_TEST(test_rows_and_closed_form)
{
    char text[4096];
    snprintf(text, sizeof text, "%s", k_head);
    append_case(text, sizeof text, "fall", 0.3, -30.0, 0.0);   /* reaches z = 0.1 at 0.2 / 30 s */
    append_case(text, sizeof text, "away", 0.3, 30.0, 0.0);    /* moves away: no hit */
    append_case(text, sizeof text, "inside", 0.05, 0.0, 0.0);  /* starts inside */
    sdfccd_CaseRunDef def = sdfccd_default_case_run_def();
    sdfccd_CaseRun* run = NULL;
    ck_assert_int_eq(run_text(text, &def, &run), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_case_run_row_count(run), 3);
    const sdfccd_CaseRow* r = sdfccd_case_run_rows(run);
    ck_assert_str_eq(r[0].id, "fall");
    ck_assert_int_eq(r[0].line, 4);
    ck_assert_int_eq(r[0].hit, 1);
    ck_assert_int_eq(r[0].state, SDFCCD_CASE_HIT);
    ck_assert_double_near(r[0].toi, 0.2 / 30.0, 1e-7);
    ck_assert_double_near(r[0].point.z, 0.1, 1e-5);
    ck_assert_double_near(r[0].normal.z, 1.0, 1e-6);
    ck_assert_int_eq(r[0].triangles_tested, 1);
    ck_assert(r[0].sdf_evaluations > 0 && r[0].micros >= 0.0);
    ck_assert_str_eq(r[1].id, "away");
    ck_assert_int_eq(r[1].hit, 0);
    ck_assert_int_eq(r[1].state, SDFCCD_CASE_NO_HIT);
    ck_assert(isnan(r[1].toi) && isnan(r[1].point.x) && isnan(r[1].normal.z));
    ck_assert_int_eq(r[2].state, SDFCCD_CASE_PENETRATING);
    ck_assert_int_eq(r[2].hit, 1);
    ck_assert(r[2].toi == 0.0);
    sdfccd_destroy_case_run(run);
    sdfccd_destroy_case_run(NULL);
    ck_assert_int_eq(sdfccd_case_run_row_count(NULL), 0);
    ck_assert_ptr_null(sdfccd_case_run_rows(NULL));
}
END_TEST

/* Each cap gives its own state: the evaluation budget "budget", the certified region cap
 * "region_cap", the Frank-Wolfe iteration cap "iteration_cap". */
START_TEST(test_states_of_caps)
{
    char text[4096];
    snprintf(text, sizeof text, "%s", k_head);
    append_case(text, sizeof text, "spin", 0.3, -30.0, 200.0);
    struct { sdfccd_Method method; int64_t budget; int32_t regions; int32_t iterations; sdfccd_CaseState want; } c[4] = {
        { SDFCCD_METHOD_FWGSS, 5, 2000000, 32, SDFCCD_CASE_BUDGET },
        { SDFCCD_METHOD_CERTIFIED, 5, 2000000, 32, SDFCCD_CASE_BUDGET },
        { SDFCCD_METHOD_CERTIFIED, 2000000, 1, 32, SDFCCD_CASE_REGION_CAP },
        { SDFCCD_METHOD_FW, 2000000, 2000000, 1, SDFCCD_CASE_ITERATION_CAP },
    };
    for (int i = 0; i < 4; ++i) {
        sdfccd_CaseRunDef def = sdfccd_default_case_run_def();
        def.params.method = c[i].method;
        def.params.max_sdf_evaluations = c[i].budget;
        def.params.certified_max_regions = c[i].regions;
        def.params.max_iterations = c[i].iterations;
        sdfccd_CaseRun* run = NULL;
        ck_assert_int_eq(run_text(text, &def, &run), SDFCCD_OK);
        const sdfccd_CaseRow* r = sdfccd_case_run_rows(run);
        ck_assert_msg(r[0].state == c[i].want, "config %d: state %s, expected %s", i, sdfccd_case_state_string(r[0].state),
                      sdfccd_case_state_string(c[i].want));
        sdfccd_destroy_case_run(run);
    }
    ck_assert_str_eq(sdfccd_case_state_string(SDFCCD_CASE_BUDGET), "budget");
    ck_assert_str_eq(sdfccd_case_state_string(SDFCCD_CASE_NO_HIT), "no_hit");
    ck_assert_str_eq(sdfccd_case_state_string((sdfccd_CaseState)99), "?");
}
END_TEST

static void count_row(const sdfccd_CaseRow* row, void* user)
{
    int* seen = user;
    ck_assert_int_eq(row->line, 4 + *seen); /* file order */
    ++*seen;
}

START_TEST(test_errors)
{
    static const struct { const char* tail; sdfccd_Status st; const char* msg; } bad[] = {
        { "foo bar\n", SDFCCD_FORMAT_ERROR, "t.cases:4: unknown record: foo" },
        { "sdf ball sphere 1\n", SDFCCD_FORMAT_ERROR, "t.cases:4: duplicate sdf name: ball" },
        { "sdf s sphere 1e999\n", SDFCCD_FORMAT_ERROR, "t.cases:4: expected: sdf NAME sphere R" },
        { "sdf s sphere -1\n", SDFCCD_INVALID_ARGUMENT, "t.cases:4: SDFCCD_INVALID_ARGUMENT: " },
        { "sdf s cone 1\n", SDFCCD_FORMAT_ERROR, "t.cases:4: unknown sdf kind (sphere, box, rounded_box, torus, csg, grid): cone" },
        { "case c nope tri 0.1 0 0 1 1 0 0 0 0 0 0 0 0 0\n", SDFCCD_FORMAT_ERROR, "t.cases:4: unknown sdf: nope" },
        { "case c ball tri -1 0 0 1 1 0 0 0 0 0 0 0 0 0\n", SDFCCD_FORMAT_ERROR, "t.cases:4: DT must be >= 0: -1" },
        { "case c ball tri 0.1 0 0 1 0 0 0 0 0 0 0 0 0 0\n", SDFCCD_INVALID_ARGUMENT, "t.cases:4: SDFCCD_INVALID_ARGUMENT: " },
        { "mesh m file missing.obj\n", SDFCCD_IO_ERROR, "t.cases:4: SDFCCD_IO_ERROR: sdfccd_load_mesh: cannot open '/nonexistent-dir/missing.obj'" },
        { "mesh m triangle 0 0 0 1 0 0 2 0 0\n", SDFCCD_DEGENERATE, "t.cases:4: SDFCCD_DEGENERATE: " },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        char text[4096];
        snprintf(text, sizeof text, "%s%s", k_head, bad[i].tail);
        sdfccd_CaseRunDef def = sdfccd_default_case_run_def();
        def.name = "t.cases";
        def.base_dir = "/nonexistent-dir";
        sdfccd_CaseRun* run = (sdfccd_CaseRun*)&def; /* must come back NULL */
        ck_assert_int_eq(run_text(text, &def, &run), bad[i].st);
        ck_assert_ptr_null(run);
        ck_assert_msg(!strncmp(sdfccd_last_error(), bad[i].msg, strlen(bad[i].msg)), "case %zu: '%s', expected '%s...'", i,
                      sdfccd_last_error(), bad[i].msg);
    }
    /* Rows made before an error reached the callback; none are returned. */
    char text[4096];
    snprintf(text, sizeof text, "%s", k_head);
    append_case(text, sizeof text, "a", 0.3, -30.0, 0.0);
    append_case(text, sizeof text, "b", 0.3, -30.0, 0.0);
    strcat(text, "case c ball tri 0.1 0 0 nan 1 0 0 0 0 0 0 0 0 0\n");
    sdfccd_CaseRunDef def = sdfccd_default_case_run_def();
    int seen = 0;
    def.on_row = count_row;
    def.user = &seen;
    sdfccd_CaseRun* run = NULL;
    ck_assert_int_eq(run_text(text, &def, &run), SDFCCD_FORMAT_ERROR);
    ck_assert_str_eq(sdfccd_last_error(), "memory:6: a number is malformed or not finite");
    ck_assert_int_eq(seen, 2);
    ck_assert_ptr_null(run);
    /* Header, empty input, long lines. */
    ck_assert_int_eq(run_text("", &def, &run), SDFCCD_FORMAT_ERROR);
    ck_assert_str_eq(sdfccd_last_error(), "memory:0: empty file (no 'sdfccd-cases 1' header)");
    ck_assert_int_eq(run_text("sdfccd-cases 2\n", &def, &run), SDFCCD_FORMAT_ERROR);
    ck_assert_str_eq(sdfccd_last_error(), "memory:1: the first record must be 'sdfccd-cases 1'");
    static char longline[20000];
    memset(longline, 'x', sizeof longline - 1);
    ck_assert_int_eq(run_text(longline, &def, &run), SDFCCD_FORMAT_ERROR);
    ck_assert_str_eq(sdfccd_last_error(), "memory:1: line too long");
    /* A file without cases: no rows, success. */
    ck_assert_int_eq(run_text(k_head, &def, &run), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_case_run_row_count(run), 0);
    sdfccd_destroy_case_run(run);
    /* Arguments. */
    ck_assert_int_eq(sdfccd_run_case_file(NULL, &def, &run), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_run_case_file("x", NULL, &run), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_run_case_memory(k_head, strlen(k_head), &def, NULL), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_run_case_memory(NULL, 3, &def, &run), SDFCCD_INVALID_ARGUMENT);
    sdfccd_CaseRunDef raw;
    memset(&raw, 0, sizeof raw);
    ck_assert_int_eq(sdfccd_run_case_memory(k_head, strlen(k_head), &raw, &run), SDFCCD_INVALID_ARGUMENT);
    def.params.margin = NAN;
    ck_assert_int_eq(sdfccd_run_case_memory(k_head, strlen(k_head), &def, &run), SDFCCD_INVALID_ARGUMENT);
    ck_assert_int_eq(sdfccd_run_case_file("/nonexistent-dir/x.cases", &def, &run), SDFCCD_INVALID_ARGUMENT);
    def = sdfccd_default_case_run_def();
    ck_assert_int_eq(sdfccd_run_case_file("/nonexistent-dir/x.cases", &def, &run), SDFCCD_IO_ERROR);
    ck_assert_str_eq(sdfccd_last_error(), "cannot open '/nonexistent-dir/x.cases': No such file or directory");
}
END_TEST

/* The data folder's example file, by path: relative mesh paths resolve against its folder. */
START_TEST(test_example_file)
{
    sdfccd_CaseRunDef def = sdfccd_default_case_run_def();
    sdfccd_CaseRun* run = NULL;
    ck_assert_int_eq(sdfccd_run_case_file(SDFCCD_DATA_DIR "/cases/example.cases", &def, &run), SDFCCD_OK);
    ck_assert_int_eq(sdfccd_case_run_row_count(run), 6);
    ck_assert_str_eq(sdfccd_case_run_rows(run)[3].id, "miss");
    ck_assert_int_eq(sdfccd_case_run_rows(run)[3].state, SDFCCD_CASE_NO_HIT);
    sdfccd_destroy_case_run(run);
}
END_TEST

typedef struct failing { long long allocs, fail_at, live; } failing;

static void* f_alloc(size_t size, void* user)
{
    failing* f = user;
    if (++f->allocs == f->fail_at) return NULL;
    f->live += (long long)size;
    return malloc(size);
}

static void f_free(void* p, size_t size, void* user)
{
    ((failing*)user)->live -= (long long)size;
    free(p);
}

/* Allocation failure at every N: the run fails with SDFCCD_OUT_OF_MEMORY (the failing record's
 * message) or succeeds, and gives every byte back. */
START_TEST(test_allocation_failure)
{
    static char text[16384];
    snprintf(text, sizeof text, "%s", k_head);
    for (int i = 0; i < 70; ++i) append_case(text, sizeof text, "c", 0.3, -30.0, 0.0); /* rows outgrow 64 */
    int completed = 0;
    for (long long n = 1; n < 1000 && !completed; ++n) {
        failing f = { 0, n, 0 };
        ck_assert_int_eq(sdfccd_set_allocator(f_alloc, f_free, &f), SDFCCD_OK);
        sdfccd_CaseRunDef def = sdfccd_default_case_run_def();
        sdfccd_CaseRun* run = NULL;
        sdfccd_Status st = run_text(text, &def, &run);
        if (st == SDFCCD_OK) {
            completed = f.allocs < n;
            ck_assert_int_eq(sdfccd_case_run_row_count(run), 70);
            sdfccd_destroy_case_run(run);
        } else {
            ck_assert_msg(st == SDFCCD_OUT_OF_MEMORY, "n = %lld: %s (%s)", n, sdfccd_status_string(st), sdfccd_last_error());
            ck_assert_ptr_null(run);
            ck_assert(sdfccd_last_error()[0] != '\0');
        }
        ck_assert_int_eq(sdfccd_byte_count(), 0);
        ck_assert_int_eq(f.live, 0);
        ck_assert_int_eq(sdfccd_set_allocator(NULL, NULL, NULL), SDFCCD_OK);
    }
    ck_assert(completed);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("cases");
    TCase* tc = tcase_create("cases");
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_rows_and_closed_form);
    tcase_add_test(tc, test_states_of_caps);
    tcase_add_test(tc, test_errors);
    tcase_add_test(tc, test_example_file);
    tcase_add_test(tc, test_allocation_failure);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
