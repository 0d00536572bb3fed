/* SPDX-License-Identifier: MIT
 * libFuzzer target: the benchmark case-file parser and runner (sdfccd_run_case_memory, cases.h: the
 * code behind sdfccd_cases and the Python package's run_cases) on fuzzer-written case files. Relative
 * file paths resolve in a folder that does not exist. A run either fails with a message or gives
 * rows with a known state and finite values when hit; every handle the file creates is destroyed
 * and no library memory may remain once the run is freed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_common.h"
#include "sdfccd/sdfccd.h"

static int64_t g_bytes;

int LLVMFuzzerInitialize(int* argc, char*** argv)
{
    (void)argc;
    (void)argv;
    g_bytes = sdfccd_byte_count();
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    sdfccd_CaseRunDef def = sdfccd_default_case_run_def();
    def.name = "fuzz";
    def.base_dir = "/nonexistent-sdfccd-fuzz";
    sdfccd_CaseRun* run = NULL;
    sdfccd_Status st = sdfccd_run_case_memory((const char*)data, size, &def, &run);
    if (st != SDFCCD_OK) {
        FZ_CHECK(run == NULL, "a failed run returned rows");
        FZ_CHECK(sdfccd_last_error()[0] != '\0', "status %d without a message", (int)st);
    } else {
        const sdfccd_CaseRow* rows = sdfccd_case_run_rows(run);
        for (int64_t i = 0; i < sdfccd_case_run_row_count(run); ++i) {
            FZ_CHECK(rows[i].state >= 0 && rows[i].state < SDFCCD_CASE_STATE_COUNT, "row %lld: state %d", (long long)i,
                     (int)rows[i].state);
            FZ_CHECK(!rows[i].hit || (isfinite(rows[i].toi) && isfinite(rows[i].point.x) && isfinite(rows[i].normal.z)),
                     "row %lld: a hit with non-finite values", (long long)i);
        }
        sdfccd_destroy_case_run(run);
    }
    FZ_CHECK(sdfccd_byte_count() == g_bytes, "%lld bytes left after a case file", (long long)(sdfccd_byte_count() - g_bytes));
    return 0;
}
