/* SPDX-License-Identifier: MIT */
/** @file cases.h  Benchmark case files (format version 1, README "Case files"): parse one, run each
 * case as a rigid-mesh query against a static SDF, and get one row per case.
 *
 * This is the one implementation behind the `sdfccd_cases` tool (which prints the rows as CSV) and
 * the Python package's `sdfccd.run_cases` (which returns them as a numpy array), so both give the
 * same values bit for bit and the same error messages. The library prints nothing: a bad record
 * stops the run with a status and the message "FILE:LINE: what: detail" (sdfccd_last_error()).
 */
#ifndef SDFCCD_CASES_H
#define SDFCCD_CASES_H

#include "ccd.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The result state of one case, as the CSV's `state` column names it (sdfccd_case_state_string()). */
typedef enum sdfccd_CaseState {
    SDFCCD_CASE_HIT = 0,        /**< "hit": the query converged on a first contact (::SDFCCD_STATE_HIT). */
    SDFCCD_CASE_NO_HIT,         /**< "no_hit": no contact over the step (::SDFCCD_STATE_NO_HIT). */
    SDFCCD_CASE_PENETRATING,    /**< "penetrating": in contact at the start (::SDFCCD_STATE_PENETRATING). */
    SDFCCD_CASE_BUDGET,         /**< "budget": ::SDFCCD_STATE_NOT_CONVERGED with the evaluation budget
                                     (sdfccd_QueryParams::max_sdf_evaluations) spent; a hit is then a witness,
                                     not a converged or certified time of impact. */
    SDFCCD_CASE_REGION_CAP,     /**< "region_cap": CERTIFIED ::SDFCCD_STATE_NOT_CONVERGED below the evaluation
                                     budget: its region store reached certified_max_regions or the memory cap
                                     certified_max_bytes. */
    SDFCCD_CASE_ITERATION_CAP,  /**< "iteration_cap": FW, FWGSS or DCD ::SDFCCD_STATE_NOT_CONVERGED below the
                                     evaluation budget (an iteration cap). */
    SDFCCD_CASE_STATE_COUNT     /**< Number of states (not a state). */
} sdfccd_CaseState;

/** "hit", "no_hit", "penetrating", "budget", "region_cap", "iteration_cap" ("?" for another value). */
SDFCCD_API const char* sdfccd_case_state_string(sdfccd_CaseState state);

/** One case's result: the columns of `sdfccd_cases`' CSV. */
typedef struct sdfccd_CaseRow {
    const char* id;              /**< The case's ID token (owned by the run, valid until it is destroyed). */
    int32_t line;                /**< Line of the `case` record in the file (1-based). */
    int32_t hit;                 /**< 1 when a contact with a contact point was found. */
    sdfccd_CaseState state;      /**< The query's result state. */
    double toi;                  /**< Time of impact (s); NaN when hit is 0 (an empty CSV field). */
    sdfccd_Vec3 point;           /**< First contact's world point; NaN when hit is 0. */
    sdfccd_Vec3 normal;          /**< First contact's normal; NaN when hit is 0. */
    int64_t triangles_tested;    /**< sdfccd_QueryResult::triangles_tested. */
    int64_t sdf_evaluations;     /**< sdfccd_QueryResult::sdf_evaluations. */
    double micros;               /**< Wall time of the query (microseconds, CLOCK_MONOTONIC): a timing, never
                                      reproducible bit for bit. */
} sdfccd_CaseRow;

/** Called after each case, in file order, with the row just made (valid during the call only). */
typedef void sdfccd_CaseRowFcn(const sdfccd_CaseRow* row, void* user);

/** How a case file runs. Initialise with sdfccd_default_case_run_def(). */
typedef struct sdfccd_CaseRunDef {
    sdfccd_QueryParams params;   /**< Parameters of every query. Default sdfccd_default_query_params(). */
    sdfccd_CaseRowFcn* on_row;   /**< May be NULL. */
    void* user;                  /**< Passed to `on_row`. */
    /** File name used in messages; NULL (default): the path given (sdfccd_run_case_memory: "memory"). */
    const char* name;
    /** Folder that relative grid and mesh paths resolve against; NULL (default): the case file's folder
     * (sdfccd_run_case_memory: the current directory). */
    const char* base_dir;
    int32_t internal_value;      /**< Set by sdfccd_default_case_run_def(); do not change. */
} sdfccd_CaseRunDef;

/** Defaults: default query parameters, no row callback, names and folders from the path. */
SDFCCD_API sdfccd_CaseRunDef sdfccd_default_case_run_def(void);

/** A finished run: its rows, in file order. */
typedef struct sdfccd_CaseRun sdfccd_CaseRun;

/** Runs the case file at `path`. On success `*out_run` holds one row per case (destroy it with
 * sdfccd_destroy_case_run()); every SDF and mesh the file created is destroyed before it returns.
 * Errors (`*out_run` is then NULL, the rows made before the error went to `on_row` only):
 * ::SDFCCD_IO_ERROR "cannot open 'PATH': reason"; ::SDFCCD_FORMAT_ERROR "FILE:LINE: what[: detail]"
 * for a malformed record (missing header, unknown record or kind, wrong field count, a number that is
 * malformed or not finite, a duplicate or unknown name, a line over 16383 bytes); a failing library call
 * of a record (loading a grid or mesh, creating a shape, the query) gives that call's status and
 * "FILE:LINE: STATUS_NAME: its message"; ::SDFCCD_INVALID_ARGUMENT for bad arguments or params. */
SDFCCD_API sdfccd_Status sdfccd_run_case_file(const char* path, const sdfccd_CaseRunDef* def, sdfccd_CaseRun** out_run);

/** The same for the `size` bytes of a case file held in memory. */
SDFCCD_API sdfccd_Status sdfccd_run_case_memory(const char* text, size_t size, const sdfccd_CaseRunDef* def,
                                                sdfccd_CaseRun** out_run);

/** Number of rows (0 for NULL). */
SDFCCD_API int64_t sdfccd_case_run_row_count(const sdfccd_CaseRun* run);

/** The rows, an array of sdfccd_case_run_row_count() entries (NULL for NULL or no rows). */
SDFCCD_API const sdfccd_CaseRow* sdfccd_case_run_rows(const sdfccd_CaseRun* run);

/** Frees a run and its rows. NULL is a no-op. */
SDFCCD_API void sdfccd_destroy_case_run(sdfccd_CaseRun* run);

#ifdef __cplusplus
}
#endif
#endif
