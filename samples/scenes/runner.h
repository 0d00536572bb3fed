// SPDX-License-Identifier: MIT
/** @file runner.h  Steps a scene and measures it against the exact SDFs.
 *
 * After every step, phi of every collider's exact reference is evaluated at every sample point
 * (vertices, and lattice points on coarse meshes) of every active body near it. From that:
 *  - max penetration over the run (-min phi, m) and where;
 *  - first contact: the first step with some sample at phi <= 1 mm; first CCD hit (bridge/queries);
 *  - tunnelled bodies: a body whose centre got deeper inside a collider than its own half-thickness,
 *    or fell below a collider's kill height (through the floor);
 *  - rest over the last second of simulated time: the largest displacement of any body centre from
 *    its position one second before the end, and the largest vertex-speed bound |v| + |w| radius;
 *  - energy (kinetic + potential): the largest gain in one step (shots excluded);
 *  - cost: wall time per step, CCD time per step and its share, contacts per step.
 *
 * A non-finite body position or velocity, SDF value or energy (a scene that defines energy) stops
 * the run at that step: Summary::non_finite says what and checkSummary fails every check. A
 * measurement query (sdfccd_sdf_eval, sdfccd_mesh_signed_distance) that fails on finite points
 * stops it too (Summary::measure_error; the runner exits 2): a failed query is never "no
 * penetration".
 */
#ifndef SDFCCD_SCENES_RUNNER_H
#define SDFCCD_SCENES_RUNNER_H

#include <cstdio>
#include <string>

#include "scene.h"

namespace scenes {

struct RunConfig {
    int steps = 0;
    double dt = 0;
    std::string csv;      /**< Per-step CSV file ("" = none). */
    std::string snapshot; /**< Folder of PNG snapshots ("" = none). */
    bool progress = true; /**< Progress line on stderr (about once per second of wall time). */
    /** Table 4 probe: before every step up to the first contact, run the CCD of every body-collider
     * pair through the C ABI on the motion the step will take (pose, v + g dt, w) with `probe_params`:
     * once as a mesh query (the library's broad phase; total time, triangles tested) and once per
     * triangle passing a conservative bounding-sphere test (per-triangle time statistics, each the
     * fastest of 3 identical runs). */
    bool probe = false;
    sdfccd_QueryParams probe_params = sdfccd_default_query_params();
    /** Test hook (--inject-nan STEP[,KIND]): after step `inject_step` the runner poisons what it
     * measures with a NaN, to prove the checks fail on it. KIND: "position" (the first active
     * body's centre), "velocity" (the first active rigid body's linear velocity), "energy" (the
     * scene's energy), "phi" (the first SDF value measured), "query" (the first measured point, so
     * the measurement query fails). -1: off. */
    int inject_step = -1;
    std::string inject_kind = "position";
};

struct Summary {
    std::string scene, method, precision, description;
    bool stock = false, subdivision = true;
    int steps = 0;
    double dt = 0;
    double max_penetration = 0;    /**< m, >= 0. */
    int max_penetration_step = -1;
    double max_penetration_ccd = 0; /**< m: the same samples against the SDF the CCD is given (a grid's own field; else = the reference). */
    std::string max_penetration_where;
    double end_penetration = 0;    /**< At the last step. */
    int first_contact_step = -1;   /**< First step with a sample at phi <= 1 mm. */
    int first_hit_step = -1;       /**< First step whose CCD found contact. */
    double ccd_ms_to_first_hit = 0;/**< CCD time summed over steps up to and including first_hit_step. */
    double step_ms_to_first_hit = 0;
    int tunnelled = 0;             /**< Bodies that tunnelled at some step. */
    std::string tunnelled_names;
    double rest_drift = 0;         /**< m, max centre displacement over the last second. */
    double rest_speed = 0;         /**< m/s, max over bodies and the last second of |v| + |w| radius. */
    int moving_at_end = 0;         /**< Bodies with vertex-speed bound > 0.05 m/s at the end. */
    double energy_start = 0, energy_end = 0, energy_max_gain = 0;
    double contacts_per_step = 0;
    double step_ms = 0;            /**< Mean wall time per step. */
    double ccd_ms = 0;             /**< Mean CCD time per step. */
    int64_t ccd_queries = 0;
    int64_t hits = 0;              /**< CCD queries (pair-steps for the bridge) that found contact over the run. */
    int64_t query_errors = 0;      /**< CCD queries of the scene that failed (StepCost::query_errors). */
    int non_finite_step = -1;      /**< First step with a non-finite position, velocity, SDF value or energy (the run stops there). */
    std::string non_finite;        /**< What was not finite. */
    std::string measure_error;     /**< A measurement query that failed on finite points (the run stops there; the runner exits 2). */
    double sdf_evals_per_step = -1; /**< Mean SDF evaluations per step of the collision pipeline (-1: unknown). */
    int body_count = 0;
    int64_t deep_samples = 0;      /**< Sample-steps with phi < -1 mm. */
    int64_t freezes = 0;           /**< Steps whose collision response froze what still hit (cloth; StepCost::freezes). */
    // Table 4 probe (RunConfig::probe), over the steps up to and including the first probe hit.
    int probe_steps = 0;           /**< Steps probed (-1 when no hit within the run). */
    double probe_total_ms = 0;     /**< Mesh queries: total time. */
    int64_t probe_tri_tested = 0;  /**< Mesh queries: triangles that reached the narrow phase. */
    double probe_step_ms = 0;      /**< Step wall time over the probed steps, minus the bridge's own CCD time. */
    int64_t probe_tri_count = 0;   /**< Per-triangle queries made. */
    double probe_tri_mean_us = 0, probe_tri_min_us = 0, probe_tri_max_us = 0, probe_tri_sd_us = 0;
    double probe_tri_evals_mean = 0;   /**< SDF evaluations per triangle query (deterministic). */
    int64_t probe_mesh_evals = 0;      /**< SDF evaluations of the mesh queries. */
};

/** Runs `scene` for cfg.steps steps of cfg.dt. `csv` (may be NULL) receives per-step rows. */
Summary runScene(Scene& scene, const RunConfig& cfg, std::FILE* csv);
void printSummary(const Summary& s, std::FILE* out);
/** Checks "key=value,key=value" limits (see the runner's --help); false with the violations in *why. */
bool checkSummary(const Summary& s, const std::string& spec, std::string* why);

} // namespace scenes

#endif
