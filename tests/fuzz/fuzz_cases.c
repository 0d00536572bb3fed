/* SPDX-License-Identifier: MIT
 * libFuzzer target: the benchmark case-file parser and runner (samples/sdfccd_cases.c, included
 * with its main() left out) on fuzzer-written case files read from memory. Its CSV goes to
 * /dev/null and its error lines to a sink; relative file paths resolve in a folder that does not
 * exist. Every handle the file creates is destroyed and no library memory may remain. */
#include <stdio.h>

static FILE* g_sink;
#define SDFCCD_CASES_NO_MAIN 1
#undef stderr
#define stderr g_sink
#include "../../samples/sdfccd_cases.c"
#undef stderr
#define stderr stderr

#include "fuzz_common.h"

static void (*const g_usage_unused)(FILE*) = usage; /* the included main()'s helper */

static int64_t g_bytes;

int LLVMFuzzerInitialize(int* argc, char*** argv)
{
    (void)argc;
    (void)argv;
    (void)g_usage_unused;
    g_sink = fopen("/dev/null", "w");
    if (!g_sink || !freopen("/dev/null", "w", stdout)) abort();
    g_bytes = sdfccd_byte_count();
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    static runner r;
    memset(&r, 0, sizeof r);
    r.params = sdfccd_default_query_params();
    r.file = "fuzz";
    snprintf(r.dir, sizeof r.dir, "/nonexistent-sdfccd-fuzz");
    r.capacity = 8;
    sdfccd_Contact contacts[8];
    r.contacts = contacts;
    if (size == 0) return 0; /* fmemopen refuses an empty buffer */
    FILE* f = fmemopen((void*)data, size, "r");
    if (!f) return 0;
    run_file(&r, f);
    fclose(f);
    for (int i = 0; i < r.sdf_count; ++i) sdfccd_destroy_sdf(r.sdfs[i].id);
    for (int i = 0; i < r.mesh_count; ++i) sdfccd_destroy_mesh(r.meshes[i].id);
    FZ_CHECK(sdfccd_byte_count() == g_bytes, "%lld bytes left after a case file", (long long)(sdfccd_byte_count() - g_bytes));
    return 0;
}
