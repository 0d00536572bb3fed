/* SPDX-License-Identifier: MIT
 * sdfccd_cases: runs a benchmark case file (version 1, README "Case files") and prints one CSV row
 * per case.
 *
 *   sdfccd_cases [--method dcd|fw|fwgss|certified] [--no-subdivision] [--margin M] FILE
 *
 * Output header: id,hit,state,toi,x,y,z,nx,ny,nz,triangles_tested,sdf_evals,micros
 * The parser and runner are the library's (sdfccd/cases.h, also behind the Python package's
 * run_cases); this program only prints. Errors (unreadable file, bad record, unknown name) go to
 * stderr with the line number; the exit status is 0 on success, 1 on a bad file, 2 on bad usage. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sdfccd/sdfccd.h"

static const char* const k_header = "id,hit,state,toi,x,y,z,nx,ny,nz,triangles_tested,sdf_evals,micros";

static void usage(FILE* f)
{
    fprintf(f,
            "usage: sdfccd_cases [--method dcd|fw|fwgss|certified] [--no-subdivision] [--margin M] FILE\n"
            "Runs a benchmark case file (format v1, see the README) and prints CSV:\n"
            "%s\n"
            "state: hit, no_hit, penetrating, budget (evaluation budget spent), region_cap (certified region\n"
            "store full), iteration_cap. Defaults: --method fwgss, subdivision on, --margin 0.\n",
            k_header);
}

/* Prints each row as the library makes it; the CSV header goes out with the first row, never
 * before an error. */
static void print_row(const sdfccd_CaseRow* row, void* user)
{
    int* header_printed = user;
    if (!*header_printed) printf("%s\n", k_header);
    *header_printed = 1;
    const char* state = sdfccd_case_state_string(row->state);
    if (row->hit)
        printf("%s,1,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%lld,%lld,%.3f\n", row->id, state, row->toi, row->point.x,
               row->point.y, row->point.z, row->normal.x, row->normal.y, row->normal.z, (long long)row->triangles_tested,
               (long long)row->sdf_evaluations, row->micros);
    else
        printf("%s,0,%s,,,,,,,,%lld,%lld,%.3f\n", row->id, state, (long long)row->triangles_tested,
               (long long)row->sdf_evaluations, row->micros);
    fflush(stdout);
}

int main(int argc, char** argv)
{
    sdfccd_CaseRunDef def = sdfccd_default_case_run_def();
    const char* file = NULL;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) { usage(stdout); return 0; }
        if (!strcmp(argv[i], "--no-subdivision")) { def.params.subdivision = 0; continue; }
        if (!strcmp(argv[i], "--method") && i + 1 < argc) {
            const char* m = argv[++i];
            if (!strcmp(m, "dcd")) def.params.method = SDFCCD_METHOD_DCD;
            else if (!strcmp(m, "fw")) def.params.method = SDFCCD_METHOD_FW;
            else if (!strcmp(m, "fwgss")) def.params.method = SDFCCD_METHOD_FWGSS;
            else if (!strcmp(m, "certified")) def.params.method = SDFCCD_METHOD_CERTIFIED;
            else { fprintf(stderr, "sdfccd_cases: unknown method '%s'\n", m); usage(stderr); return 2; }
            continue;
        }
        if (!strcmp(argv[i], "--margin") && i + 1 < argc) {
            char* end;
            def.params.margin = strtod(argv[++i], &end);
            if (*end || !isfinite(def.params.margin)) { fprintf(stderr, "sdfccd_cases: bad margin '%s'\n", argv[i]); return 2; }
            continue;
        }
        if (argv[i][0] == '-' && argv[i][1] != '\0') { fprintf(stderr, "sdfccd_cases: unknown option '%s'\n", argv[i]); usage(stderr); return 2; }
        if (file) { fprintf(stderr, "sdfccd_cases: more than one FILE\n"); usage(stderr); return 2; }
        file = argv[i];
    }
    if (!file) { usage(stderr); return 2; }
    int header_printed = 0;
    def.on_row = print_row;
    def.user = &header_printed;
    sdfccd_CaseRun* run = NULL;
    sdfccd_Status st = sdfccd_run_case_file(file, &def, &run);
    if (st != SDFCCD_OK) {
        fprintf(stderr, "sdfccd_cases: %s\n", sdfccd_last_error());
        return 1;
    }
    if (!header_printed) printf("%s\n", k_header); /* a file without cases still gives a (header-only) CSV */
    sdfccd_destroy_case_run(run);
    return 0;
}
