/* SPDX-License-Identifier: MIT
 * FWGSS under last-bit changes of its inputs (issue 20 item 2): the per-kind data set's cases on
 * the fields with gradient jumps (samples/report/dataset_kinds), each run as given and with several
 * perturbations that move every number of the rigid motion (position, orientation, velocities) by
 * at most two units in the last place. The certified ground truth does not move at this scale
 * (the TOI moves by about 1e-16 relative), so a perturbed run must not miss (no hit, or a TOI more
 * than 1 us after the certified one) nor hit falsely (more than 1 us before it, or with no certified
 * contact). Public ABI only: the cases go through the library's case-file runner. Main at 0bb0668
 * misses box-0066 under one of the default perturbations (0.65 ms late: its certified check stopped
 * at its store's cap short of FWGSS's late answer and let it stand). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "test_util.h"

#define KINDS_DIR SDFCCD_DATA_DIR "/../samples/report/dataset_kinds"
#define TOI_TOL 1e-6
#define MOTION_NUMBERS 13 /* position 3, orientation 4, linear velocity 3, angular velocity 3 */

/* Cases per kind and perturbations per case of the ctest run (SDFCCD_TEST_PERTURB_CASES and
 * SDFCCD_TEST_PERTURB_COUNT override them for a longer run). */
#define DEFAULT_CASES 128
#define DEFAULT_PERTURBATIONS 4

typedef struct gt_row {
    char id[40];
    int hit;
    double lower, toi;
} gt_row;

typedef struct tally {
    const gt_row* gt;
    int n_gt;
    int rows, misses, fps;
    long long evals;
    long long base_evals;  /* the last case's run as given */
    double worst;          /* the largest evaluations of a perturbed run / of its case as given */
    char worst_id[48];
} tally;

static const gt_row* find_gt(const tally* t, const char* id)
{
    for (int i = 0; i < t->n_gt; ++i)
        if (!strcmp(t->gt[i].id, id)) return &t->gt[i];
    return NULL;
}

static void on_row(const sdfccd_CaseRow* row, void* user)
{
    tally* t = user;
    char id[40];
    snprintf(id, sizeof id, "%s", row->id);
    char* sep = strchr(id, '~'); /* "<case>~<perturbation>" */
    if (sep) *sep = '\0';
    const int perturbed = sep && strcmp(sep + 1, "0");
    if (!perturbed) t->base_evals = (long long)row->sdf_evaluations;
    else if ((double)row->sdf_evaluations > t->worst * (double)t->base_evals) {
        t->worst = (double)row->sdf_evaluations / (double)t->base_evals;
        snprintf(t->worst_id, sizeof t->worst_id, "%s", row->id);
    }
    const gt_row* g = find_gt(t, id);
    ck_assert_msg(g != NULL, "%s: no ground truth", row->id);
    ++t->rows;
    t->evals += (long long)row->sdf_evaluations;
    const int miss = g->hit && (!row->hit || row->toi > g->toi + TOI_TOL);
    const int fp = row->hit && (!g->hit || row->toi < g->toi - TOI_TOL);
    if (miss || fp)
        fprintf(stderr, "%s: %s: FWGSS hit %d toi %.17g (%lld evaluations), certified hit %d [%.17g, %.17g]\n", row->id, miss ? "miss" : "false positive",
                (int)row->hit, row->toi, (long long)row->sdf_evaluations, g->hit, g->lower, g->toi);
    t->misses += miss;
    t->fps += fp;
}

/* x moved by k units in the last place */
static double ulps(double x, int k)
{
    for (; k > 0; --k) x = nextafter(x, INFINITY);
    for (; k < 0; ++k) x = nextafter(x, -INFINITY);
    return x;
}

/* A fixed pseudo-random number per (case, perturbation, number): -2..2 units in the last place. */
static int shift_of(unsigned c, unsigned j, unsigned i)
{
    uint64_t h = (uint64_t)c * 0x9E3779B97F4A7C15ull ^ (uint64_t)(j + 1) * 0xC2B2AE3D27D4EB4Full ^ (uint64_t)(i + 1) * 0x165667B19E3779F9ull;
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    return (int)(h % 5) - 2;
}

static int env_int(const char* name, int fallback)
{
    const char* v = getenv(name);
    return v && atoi(v) > 0 ? atoi(v) : fallback;
}

static char* append(char* buf, size_t* len, size_t* cap, const char* s)
{
    const size_t n = strlen(s);
    if (*len + n + 1 > *cap) {
        *cap = 2 * (*len + n + 1);
        buf = realloc(buf, *cap);
        ck_assert_ptr_nonnull(buf);
    }
    memcpy(buf + *len, s, n + 1);
    *len += n;
    return buf;
}

START_TEST(test_last_bits_of_the_motion)
{
    static const char* const kinds[] = { "box", "plate", "csg-difference", "csg-intersection", "grid-concave-box", "grid-spikes" };
    const int n_kinds = (int)(sizeof kinds / sizeof kinds[0]);
    const int per_kind = env_int("SDFCCD_TEST_PERTURB_CASES", DEFAULT_CASES);
    const int perturbations = env_int("SDFCCD_TEST_PERTURB_COUNT", DEFAULT_PERTURBATIONS);
    /* the ground truth */
    enum { MAX_GT = 8192 };
    static gt_row gt[MAX_GT];
    int n_gt = 0;
    char line[1024];
    FILE* f = fopen(KINDS_DIR "/ground_truth.csv", "r");
    ck_assert_ptr_nonnull(f);
    while (fgets(line, sizeof line, f)) {
        gt_row g;
        int state;
        if (sscanf(line, "%39[^,],%d,%d,%lf,%lf", g.id, &g.hit, &state, &g.lower, &g.toi) != 5) continue;
        ck_assert_int_lt(n_gt, MAX_GT);
        gt[n_gt++] = g;
    }
    fclose(f);
    /* the header (SDFs and the triangle) as it is, then each chosen case as given and perturbed */
    size_t len = 0, cap = 1 << 16;
    char* text = malloc(cap);
    ck_assert_ptr_nonnull(text);
    text[0] = '\0';
    int taken[16] = { 0 };
    unsigned c_index = 0;
    f = fopen(KINDS_DIR "/cases.txt", "r");
    ck_assert_ptr_nonnull(f);
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, "case ", 5)) {
            if (!strncmp(line, "sdf ", 4) || !strncmp(line, "mesh ", 5) || !strncmp(line, "sdfccd-cases", 12)) text = append(text, &len, &cap, line);
            continue;
        }
        char id[40], kind[40], mesh[40];
        double dt, v[MOTION_NUMBERS];
        ck_assert_int_eq(sscanf(line, "case %39s %39s %39s %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", id, kind, mesh, &dt, &v[0], &v[1], &v[2],
                                &v[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9], &v[10], &v[11], &v[12]),
                         17);
        ++c_index;
        int k = -1;
        for (int i = 0; i < n_kinds; ++i)
            if (!strcmp(kind, kinds[i])) k = i;
        if (k < 0 || taken[k] >= per_kind) continue;
        ++taken[k];
        for (int j = 0; j <= perturbations; ++j) {
            char rec[1024];
            int n = snprintf(rec, sizeof rec, "case %s~%d %s %s %.17g", id, j, kind, mesh, dt);
            for (int i = 0; i < MOTION_NUMBERS; ++i)
                n += snprintf(rec + n, sizeof rec - (size_t)n, " %.17g", j == 0 ? v[i] : ulps(v[i], shift_of(c_index, (unsigned)j, (unsigned)i)));
            snprintf(rec + n, sizeof rec - (size_t)n, "\n");
            text = append(text, &len, &cap, rec);
        }
    }
    fclose(f);
    for (int k = 0; k < n_kinds; ++k) ck_assert_int_eq(taken[k], per_kind);
    tally t = { gt, n_gt, 0, 0, 0, 0, 0, 0.0, "" };
    sdfccd_CaseRunDef def = sdfccd_default_case_run_def();
    def.on_row = on_row;
    def.user = &t;
    def.base_dir = KINDS_DIR;
    sdfccd_CaseRun* run = NULL;
    ck_assert_int_eq(sdfccd_run_case_memory(text, len, &def, &run), SDFCCD_OK);
    free(text);
    sdfccd_destroy_case_run(run);
    printf("last bits of the motion: %d runs (%d cases per kind x %d kinds, each as given and %d times perturbed): %d misses, %d false positives, "
           "%.1f evaluations per run, at most %.2fx its case's as given (%s)\n",
           t.rows, per_kind, n_kinds, perturbations, t.misses, t.fps, (double)t.evals / t.rows, t.worst, t.worst_id);
    fflush(stdout);
    ck_assert_int_eq(t.rows, per_kind * n_kinds * (perturbations + 1));
    ck_assert_int_eq(t.misses, 0);
    ck_assert_int_eq(t.fps, 0);
}
END_TEST

int main(void)
{
    Suite* s = suite_create("perturb");
    TCase* tc = tcase_create("core");
    tcase_set_timeout(tc, 600);
    test_add_memory_fixture(tc);
    tcase_add_test(tc, test_last_bits_of_the_motion);
    suite_add_tcase(s, tc);
    return test_run_suite(s);
}
