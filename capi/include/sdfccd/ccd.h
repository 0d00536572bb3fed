/* SPDX-License-Identifier: MIT */
/** @file ccd.h  Continuous (and discrete) collision queries between moving triangles and an SDF.
 *
 * Time: a query covers [t0, t1] seconds (t1 >= t0). Results give `toi` in seconds and
 * `fraction` = (toi - t0) / (t1 - t0) in [0, 1] (0 when t1 == t0).
 *
 * Frames: mesh vertices are in the mesh's local frame; the SDF is evaluated in its local
 * frame; results (points, normals) are in the WORLD frame at time `toi`. A NULL SDF motion
 * means the SDF is static at the world origin, so world = SDF frame.
 *
 * Contact: a point x is in contact when phi(x) <= margin. The time of impact is the first
 * time at which some point of the moving triangle(s) is in contact.
 *
 * Methods (Pelletier-Guenette et al., SCA 2025):
 *  - FWGSS (default): Frank-Wolfe with golden-section line searches (Algorithm 2).
 *  - FW: the temporally modified Frank-Wolfe method (Section 4.2).
 *  - DCD: Macklin et al. 2020 discrete detection at the end pose only (toi = t1 when in contact).
 *  - CERTIFIED: Lipschitz branch and bound; brackets the first TOI in [toi_lower, toi] with no
 *    false negatives when the SDF's Lipschitz bound is true (exact analytic SDFs).
 * Known misses: FW and FWGSS are local methods. They can miss a contact or report a later one when
 * the trajectory grazes the surface or crosses several thin features in one interval (the paper
 * reports about 1% of random cases with at least one triangle missed); CERTIFIED is the check.
 */
#ifndef SDFCCD_CCD_H
#define SDFCCD_CCD_H

#include "mesh.h"
#include "sdf.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The narrow-phase method of a query (sdfccd_QueryParams::method); the README compares them. */
typedef enum sdfccd_Method {
    SDFCCD_METHOD_FWGSS = 0, /**< Frank-Wolfe with golden-section search (the paper's Algorithm 2). Default. */
    SDFCCD_METHOD_FW,        /**< Frank-Wolfe with line search along the motion (Section 4.2). */
    SDFCCD_METHOD_DCD,       /**< Discrete: deepest point at the end pose (Macklin et al. 2020); misses tunnelling. */
    SDFCCD_METHOD_CERTIFIED, /**< Lipschitz branch and bound: no contact before toi_lower (ground truth; slow). */
    SDFCCD_METHOD_COUNT      /**< Number of methods (not a method). */
} sdfccd_Method;

/** Every cap and tolerance of a query. Must be initialised with sdfccd_default_query_params(). */
typedef struct sdfccd_QueryParams {
    sdfccd_Method method;          /**< Default FWGSS. */
    double margin;                 /**< Contact when phi <= margin (m). Default 0. */
    double time_tolerance;         /**< Absolute time tolerance of line searches and convergence (s). Default 1e-7. */
    double distance_tolerance;     /**< Spatial convergence tolerance (m). Default 1e-7. */
    int32_t max_iterations;        /**< Frank-Wolfe outer iterations. Default 32. */
    int32_t max_line_search_iterations; /**< Golden-section iterations per line search, in [1, 4096]. Default 64. */
    int32_t fwgss_restarts;        /**< FWGSS: extra descents from the other two vertices after the Section 4.4 start
                                        (0 = the paper's single descent, up to 2). They share the shrinking interval and
                                        correct local minima and later entries. Default 2. */
    int32_t fwgss_vertex_trace;    /**< FWGSS: before the descents, each vertex path is advanced conservatively
                                        (steps of (phi - margin) / (L * speed), which cannot skip a crossing) for
                                        at most this many steps; a contact found there bounds the TOI. 0 = off
                                        (the paper's method). Default 64. */
    int32_t subdivision;           /**< Adaptive triangle subdivision at the TOI (Section 4.5). Default 1 (on). */
    double subdivision_min_area;   /**< Smallest sub-triangle area searched (m^2). Default 1e-4 (1 cm^2). */
    int32_t subdivision_max_depth; /**< Levels of recursive splitting (1 = only the paper's first three regions). Default 3. */
    double contact_slop;           /**< Extra contacts at the TOI are kept when phi <= margin + contact_slop (m). Default 1e-4. */
    double toi_window;             /**< Mesh query: triangles whose TOI is within this of the earliest also give contacts (s). Default 1e-5. */
    double max_rotation_per_segment; /**< Intervals are split so no segment rotates more than this (rad). Default pi. */
    double certified_time_tolerance; /**< CERTIFIED: width of the returned TOI bracket (s). Default 1e-7. */
    int32_t certified_max_regions; /**< CERTIFIED: cap on processed regions per triangle. Default 2000000. */
    int32_t broad_phase;           /**< Mesh query: bounding-sphere hierarchy culling. Default 1 (on). */
    int32_t internal_value;        /**< Set by sdfccd_default_query_params(); do not change. */
    int64_t max_sdf_evaluations;   /**< Total SDF evaluations one query may spend (>= 1), shared by every interval
                                        segment, triangle and the broad phase. When it runs out the query returns
                                        ::SDFCCD_STATE_NOT_CONVERGED with the earliest contact witnessed so far
                                        (`hit` = 1) or none. The solvers check it once per iteration, so a query
                                        may exceed it by about one iteration (a few line searches). Default
                                        SDFCCD_DEFAULT_MAX_SDF_EVALUATIONS, chosen so that no query on the built-in
                                        SDFs runs longer than about a second on the 2-core machine of the README's
                                        figures: the costliest evaluations there take about 200 ns of CPU (a triangle
                                        spinning at 0.9e6 rad over a 32^3 grid, FWGSS: 0.41 s per query;
                                        samples/sdfccd_worst), analytic fields 50-80 ns; with both cores shared by
                                        about 11 runnable processes the same query took 1.5 s of wall time. The time
                                        of a query is about this budget times the cost of one evaluation, so callback
                                        SDFs and deep CSG or transform trees (one evaluation evaluates every node)
                                        take proportionally longer. */
    int32_t fwgss_secant_entry;    /**< FWGSS: once the current point is in contact at the iterate's time and not at the
                                        interval start, its entry time is found by regula falsi with the Illinois
                                        modification on that sign change (a handful of evaluations) instead of the
                                        paper's golden-section search of |phi| (Algorithm 2 line 13). 0 = the paper's
                                        search. Default 1. */
    int32_t fwgss_speed_tolerance; /**< FWGSS: the spatial tolerance is the distance the fastest point of the triangle
                                        travels in time_tolerance (speed bound x time_tolerance), so a spatial error
                                        costs at most about time_tolerance; 0 = distance_tolerance. Default 1. */
    int32_t fwgss_clear_proof;     /**< FWGSS: before the descents, at most this many SDF evaluations try to prove that the
                                        triangle stays clear of the field (conservative advancement of sub-triangles with
                                        the field's Lipschitz bound, split when stalled); when it succeeds the triangle
                                        has no contact and the descents are skipped. A proof, so it never loses a contact.
                                        0 = off. Default 32. */
    int32_t fwgss_brent_spatial;   /**< FWGSS: the spatial line searches (Algorithm 2 lines 22-31) use Brent's method
                                        (parabolic steps safeguarded by golden section), which needs fewer SDF
                                        evaluations where phi is smooth along the segment (data set: 11-24 % fewer per
                                        query, 0 false negatives), but in test_sweep it misses one more case (2 of 982
                                        instead of 1) and leaves more cases unconverged; 0 = the paper's
                                        golden-section search. Default 0. */
    double fwgss_gap_tolerance;    /**< FWGSS: far from the surface the line searches stop early, by this fraction g of the
                                        gap (phi - margin): a spatial search at a tolerance of g x the current point's gap
                                        when that exceeds the spatial tolerance, a temporal search (not in contact) once
                                        its bracket is narrower than g x the smallest gap sampled / (Lipschitz bound x
                                        speed bound), which cannot hide a contact of the searched path (phi stays above
                                        (1 - g) x that gap on the bracket). Searches at contact keep the full precision.
                                        Finite, >= 0; 0 = off. Default 0.5. */
    int64_t certified_max_bytes;   /**< CERTIFIED: most bytes the region store of one triangle's search may hold (>= 1),
                                        counted at its peak, when a growing store holds its old and new arrays (64 bytes
                                        per region). Checked before growing: when the next growth would pass it the search
                                        stops with ::SDFCCD_STATE_NOT_CONVERGED, the earliest contact witnessed so far
                                        (`hit` = 1) or none, and `toi_lower` the time before which no contact is proven.
                                        A mesh query searches one triangle at a time, so this bounds the whole query's
                                        region store. Default SDFCCD_DEFAULT_CERTIFIED_MAX_BYTES. */
    int32_t fwgss_derivative_spatial; /**< FWGSS: the spatial line searches at full precision (at or next to contact,
                                        where fwgss_gap_tolerance does not loosen them) use the gradient: the segment's
                                        end is tried first, then secant steps on the slope of phi along the segment
                                        (regula falsi with the Illinois modification, safeguarded by bisection), a
                                        handful of evaluations where golden section needs about 25; when phi falls,
                                        rises and falls again along the segment, golden section as with 0. Far from the
                                        surface golden section (or Brent, fwgss_brent_spatial) stays. 0 = golden section
                                        everywhere. Default 1. */
    int32_t fwgss_restart_at_witness; /**< FWGSS: a restart (fwgss_restarts) begins at the time of the earliest contact
                                        witnessed so far instead of at t0: its spatial steps find a part of the triangle
                                        in contact there and it searches back for that part's entry, without first
                                        searching the whole interval along the vertex's path. 0 = restarts begin at t0.
                                        Default 1. */
    int32_t fwgss_kink_guard;      /**< FWGSS on fields whose gradient may jump, where the slope of phi is not trusted
                                        (ours, issue 20). On the analytic ones (box, cylinder, spike grid, CSG,
                                        transformed and callback SDFs): the spatial line searches use golden section
                                        (fwgss_derivative_spatial is ignored); on non-convex ones, after the vertex
                                        descents four more start from the edge midpoints and the centroid (when
                                        fwgss_restarts > 0); and the earliest contact found is checked 1 us earlier by
                                        spatial steps from its weights and from each vertex; when the triangle touches
                                        there too, the time is moved back and bisected to the time tolerance. This
                                        finds contacts where a sharp feature (box edge or corner, knife edge, spike tip)
                                        crosses an edge or the inside of the triangle, which the alternating temporal and
                                        spatial searches approach in micrometre steps and answer late. Grids may sample
                                        smooth shapes: at 1 a grid query gets the extra starts and the check only when
                                        the gradient turns by more than 0.2 rad within 1 mm of the earliest contact; at 2
                                        every grid query gets the whole guard. Smooth analytic fields (sphere, torus,
                                        capsule, rounded box, half-space) are unaffected. At 1 and 2, on the analytic
                                        fields with kinks and on grids, FWGSS's answer is then checked by the certified
                                        method's search over [t0, TOI] (no hit: the whole interval) seeded with its
                                        witness (on grids bounding phi per cell by a first-order Taylor form, and
                                        only where the cells along the path bound |grad phi| above 2.25): it
                                        stops once no contact is proven more than max(0.3 x time_tolerance, 1e-8 s) before
                                        the witness, or after 128 x FWGSS's evaluations + 16384 (grids: + 65536; at
                                        most 10^6), and an earlier contact it finds replaces the answer; on the convex ones (box,
                                        cylinder) the golden-section searches and the 1 us check are left to it. Per-kind
                                        data set (samples/report, section 2b) and costs: README. 0 = off, 1 (default) or 2. */
    int32_t fwgss_verify;          /**< FWGSS: where fwgss_kink_guard applies to an analytic field with gradient jumps
                                        or to a grid, the answer is checked by the certified search seeded with FWGSS's
                                        witness (an earlier contact found replaces it; at most 128x FWGSS's evaluations
                                        + 16384, grids + 65536; a check stopped short of the witness is followed by
                                        FWGSS's spatial steps from the stretch it left unproven, and runs again from a
                                        contact they find). 0 = no check (the guard's searches instead), as before issue 20.
                                        Default 1. The Bullet bridge sets 0: a triangle resting at its contact level
                                        keeps the check busy at every step, and its guarantee backs the answer. */
} sdfccd_QueryParams;

/** Default of sdfccd_QueryParams::max_sdf_evaluations. */
#define SDFCCD_DEFAULT_MAX_SDF_EVALUATIONS 2000000
/** Default of sdfccd_QueryParams::certified_max_bytes: 32 MiB, i.e. at most 262,144 regions in the store after
 * its last doubling (24 MiB while it doubles). */
#define SDFCCD_DEFAULT_CERTIFIED_MAX_BYTES 33554432
/** Largest total rotation (rad) of a query's motions over [t0, t1] (sum of the angular speeds of the
 * body and the SDF times t1 - t0). Beyond it the rotation angle's rounding error exceeds about
 * 1e-10 rad and the motion model is no longer accurate: the query returns ::SDFCCD_INVALID_ARGUMENT. */
#define SDFCCD_MAX_ROTATION_ANGLE 1e6
/** Largest magnitude of any coordinate a query accepts: vertices, positions, centres, velocities,
 * angular velocities, mesh bounds, and each motion's displacement |v| (t1 - t0). Squares of such
 * values stay finite, so no intermediate overflows; larger inputs give ::SDFCCD_INVALID_ARGUMENT. */
#define SDFCCD_MAX_QUERY_MAGNITUDE 1e150

/** The default query parameters (see each field of ::sdfccd_QueryParams). */
SDFCCD_API sdfccd_QueryParams sdfccd_default_query_params(void);

/** Rigid motion over the interval (the paper's Eq. 14). At t0 the body's frame has pose
 * (position, orientation). The centre g = pose applied to `local_center` moves with constant
 * `linear_velocity`; the body spins with constant world `angular_velocity` (rad/s) about g:
 *   x(t) = g(t0) + v (t - t0) + R(w (t - t0)) (x(t0) - g(t0)).
 * This equals Bullet's integration (origin lerp plus exponential-map rotation) for a body whose
 * origin is its centre of mass. */
typedef struct sdfccd_RigidMotion {
    sdfccd_Pose pose;              /**< Pose at t0. */
    sdfccd_Vec3 local_center;      /**< Centre of rotation, in the local frame. Default 0. */
    sdfccd_Vec3 linear_velocity;   /**< m/s, world frame. */
    sdfccd_Vec3 angular_velocity;  /**< rad/s, world frame. */
} sdfccd_RigidMotion;

/** Identity pose, zero velocities, centre at the local origin. */
SDFCCD_API sdfccd_RigidMotion sdfccd_default_rigid_motion(void);

/** Result states. Never a sentinel value. */
typedef enum sdfccd_ResultState {
    SDFCCD_STATE_NO_HIT = 0,       /**< No contact over [t0, t1]. */
    SDFCCD_STATE_HIT,              /**< First contact at `toi` in (t0, t1]. */
    SDFCCD_STATE_PENETRATING,      /**< Already in contact at t0 (toi = t0). */
    SDFCCD_STATE_NOT_CONVERGED     /**< An iteration cap was reached. `hit` says whether a contact was
                                        nevertheless witnessed (then toi/contacts are the best estimate). */
} sdfccd_ResultState;

/** Where a contact comes from. */
typedef enum sdfccd_ContactKind {
    SDFCCD_CONTACT_PRIMARY = 0,    /**< The TOI point of a triangle. */
    SDFCCD_CONTACT_SUBDIVISION     /**< An extra point found by adaptive subdivision at the TOI. */
} sdfccd_ContactKind;

/** One contact at the time of impact. */
typedef struct sdfccd_Contact {
    sdfccd_Vec3 point;        /**< World point on the triangle at `toi`. */
    sdfccd_Vec3 normal;       /**< World unit normal (grad phi), pointing out of the SDF. */
    double distance;          /**< phi at the point at `toi` (<= margin + contact_slop). */
    double gap_t0;            /**< phi of the same material point at t0 (for speculative contacts). */
    double toi;               /**< Time of impact of this contact's triangle (s). */
    double barycentric[3];    /**< Weights of the triangle's vertices 0, 1, 2. */
    uint32_t triangle;        /**< Triangle index in the mesh (0 for single-triangle queries). */
    sdfccd_ContactKind kind;  /**< Primary (the triangle's TOI point) or from subdivision. */
} sdfccd_Contact;

/** Summary of a query: the earliest time of impact over all triangles and the work done. */
typedef struct sdfccd_QueryResult {
    sdfccd_ResultState state; /**< Hit, no hit, penetrating at t0, or not converged. */
    int32_t hit;              /**< 1 when a contact was found (state HIT or PENETRATING, or NOT_CONVERGED with a witness). */
    double toi;               /**< Time of impact (s); t1 when there is no hit. */
    double fraction;          /**< (toi - t0) / (t1 - t0). */
    double toi_lower;         /**< Lower end of the TOI bracket: CERTIFIED proves no contact before it;
                                   other methods report toi here. */
    int32_t contact_count;    /**< Contacts written to the caller's array (mesh queries: a reduction when more were found). */
    int32_t contacts_found;   /**< Contacts found (may exceed the array capacity). */
    int64_t iterations;       /**< Outer iterations (or regions for CERTIFIED), summed over triangles. */
    int64_t sdf_evaluations;  /**< SDF evaluations, summed over triangles. */
    int64_t triangles_tested; /**< Triangles that reached the narrow phase. */
} sdfccd_QueryResult;

/** One triangle under rigid motion against an SDF (static when `sdf_motion` is NULL).
 * `triangle` holds the three vertices in the body's local frame. Contacts go to
 * `out_contacts[0 .. capacity-1]` (may be NULL when capacity is 0).
 * Errors: non-finite input, t1 < t0, t1 - t0 overflowing, a magnitude above SDFCCD_MAX_QUERY_MAGNITUDE,
 * a rotation above SDFCCD_MAX_ROTATION_ANGLE, a zero-area triangle (::SDFCCD_DEGENERATE), bad handle. */
SDFCCD_API sdfccd_Status sdfccd_query_triangle(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
    const sdfccd_Vec3 triangle[3], const sdfccd_RigidMotion* motion, double t0, double t1,
    const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
    sdfccd_QueryResult* out_result);

/** One triangle whose vertices move linearly in the world from `start` (at t0) to `end` (at t1),
 * as cloth and deformable vertices do. */
SDFCCD_API sdfccd_Status sdfccd_query_triangle_linear(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
    const sdfccd_Vec3 start[3], const sdfccd_Vec3 end[3], double t0, double t1,
    const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
    sdfccd_QueryResult* out_result);

/** A rigid mesh against an SDF: the earliest TOI over all triangles and the contacts at it
 * (triangles whose TOI lies within params->toi_window of the earliest, plus subdivision
 * contacts). The search interval shrinks as earlier hits are found. Contacts are written earliest
 * first; when more are found than `capacity`, the ones written are a reduction of the set, not its
 * first ones: the deepest contact at the earliest time, then the points spreading most over the contact region
 * (sdfccd_reduce_contacts() on their surface points, with distance_tolerance as the same-place
 * distance), so `contact_count` may be below `capacity`. The linear and workspace variants do the same. */
SDFCCD_API sdfccd_Status sdfccd_query_mesh(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
    sdfccd_MeshId mesh, const sdfccd_RigidMotion* motion, double t0, double t1,
    const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
    sdfccd_QueryResult* out_result);

/** A deforming mesh: the mesh's topology with per-vertex world positions at t0 (`start`) and t1
 * (`end`), 3 * vertex_count doubles each, moving linearly. */
SDFCCD_API sdfccd_Status sdfccd_query_mesh_linear(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sdf_motion,
    sdfccd_MeshId mesh, const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0, double t1,
    const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
    sdfccd_QueryResult* out_result);

/** A reusable workspace for queries: the scratch storage of the broad phase, the contact buffers
 * and the certified search's (FWGSS's check on fields with kinks and on grids: its first 1,024
 * regions and its sample cache, 80,896 bytes, and on grids its cell cache, 54,272 bytes, each
 * allocated at the first check that needs it), kept from call to call so that, after a first
 * query of a given size, queries through it allocate nothing (a physics engine querying every
 * pair every step should keep one per thread), and a query takes only a few KB of the calling
 * thread's stack. A workspace may be used by one thread at a time; it holds no handle. */
typedef struct sdfccd_Workspace sdfccd_Workspace;

/** Creates an empty workspace (it grows on first use). */
SDFCCD_API sdfccd_Status sdfccd_create_workspace(sdfccd_Workspace** out_workspace);
/** Frees a workspace and its storage. NULL is a no-op. */
SDFCCD_API void sdfccd_destroy_workspace(sdfccd_Workspace* workspace);
/** Bytes the workspace holds (0 for NULL). */
SDFCCD_API int64_t sdfccd_workspace_bytes(const sdfccd_Workspace* workspace);

/** sdfccd_query_triangle with the certified search's scratch in `workspace` (not NULL); same
 * results. Without a workspace a triangle query whose check runs allocates that scratch and frees
 * it before returning. */
SDFCCD_API sdfccd_Status sdfccd_query_triangle_ws(sdfccd_Workspace* workspace, sdfccd_SdfId sdf,
    const sdfccd_RigidMotion* sdf_motion, const sdfccd_Vec3 triangle[3], const sdfccd_RigidMotion* motion, double t0,
    double t1, const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
    sdfccd_QueryResult* out_result);

/** sdfccd_query_triangle_linear with the certified search's scratch in `workspace` (not NULL); same results. */
SDFCCD_API sdfccd_Status sdfccd_query_triangle_linear_ws(sdfccd_Workspace* workspace, sdfccd_SdfId sdf,
    const sdfccd_RigidMotion* sdf_motion, const sdfccd_Vec3 start[3], const sdfccd_Vec3 end[3], double t0, double t1,
    const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity, sdfccd_QueryResult* out_result);

/** sdfccd_query_mesh with its scratch storage in `workspace` (not NULL); same results. */
SDFCCD_API sdfccd_Status sdfccd_query_mesh_ws(sdfccd_Workspace* workspace, sdfccd_SdfId sdf,
    const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh, const sdfccd_RigidMotion* motion, double t0, double t1,
    const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
    sdfccd_QueryResult* out_result);

/** sdfccd_query_mesh_linear with its scratch storage in `workspace` (not NULL); same results. */
SDFCCD_API sdfccd_Status sdfccd_query_mesh_linear_ws(sdfccd_Workspace* workspace, sdfccd_SdfId sdf,
    const sdfccd_RigidMotion* sdf_motion, sdfccd_MeshId mesh, const sdfccd_Vec3* start, const sdfccd_Vec3* end, double t0,
    double t1, const sdfccd_QueryParams* params, sdfccd_Contact* out_contacts, int32_t capacity,
    sdfccd_QueryResult* out_result);

/** Kinds of query in a batch (which fields of sdfccd_BatchQuery are read). */
typedef enum sdfccd_BatchKind {
    SDFCCD_BATCH_TRIANGLE = 0,     /**< sdfccd_query_triangle: `triangle` (3 local vertices), `motion`. */
    SDFCCD_BATCH_TRIANGLE_LINEAR,  /**< sdfccd_query_triangle_linear: `triangle` (start), `triangle_end`. */
    SDFCCD_BATCH_MESH,             /**< sdfccd_query_mesh: `mesh`, `motion`. */
    SDFCCD_BATCH_MESH_LINEAR       /**< sdfccd_query_mesh_linear: `mesh`, `start`, `end`. */
} sdfccd_BatchKind;

/** One independent query of a batch: the arguments of the matching single query, and its status. */
typedef struct sdfccd_BatchQuery {
    sdfccd_BatchKind kind;                 /**< Which single query this is. */
    sdfccd_SdfId sdf;                      /**< The SDF queried. */
    const sdfccd_RigidMotion* sdf_motion;  /**< NULL: static SDF. */
    sdfccd_MeshId mesh;                    /**< Mesh kinds. */
    const sdfccd_Vec3* triangle;           /**< Triangle kinds: 3 vertices (local, or world start for linear). */
    const sdfccd_Vec3* triangle_end;       /**< SDFCCD_BATCH_TRIANGLE_LINEAR: 3 world vertices at t1. */
    const sdfccd_Vec3* start;              /**< SDFCCD_BATCH_MESH_LINEAR: vertex_count world positions at t0. */
    const sdfccd_Vec3* end;                /**< SDFCCD_BATCH_MESH_LINEAR: vertex_count world positions at t1. */
    const sdfccd_RigidMotion* motion;      /**< Rigid kinds. */
    double t0;                             /**< Start of the interval (s). */
    double t1;                             /**< End of the interval (s), >= t0. */
    const sdfccd_QueryParams* params;      /**< Query parameters (not NULL; sdfccd_default_query_params()). */
    sdfccd_Contact* out_contacts;          /**< Each query needs its own output storage. */
    int32_t capacity;                      /**< Entries of out_contacts. */
    sdfccd_QueryResult* out_result;        /**< The query's result (not NULL). */
    sdfccd_Status status;                  /**< Out: the query's status. */
} sdfccd_BatchQuery;

/** Runs `count` independent queries on `threads` threads (the calling thread and threads - 1 POSIX
 * threads started for the call, 1 <= threads <= 256; no busy-waiting). Results are bitwise
 * identical to running the queries one by one, whatever the thread count. Every query's status
 * is in its `status`; the return value is ::SDFCCD_OK when all succeeded, else the first failing
 * query's status (with its message in sdfccd_last_error()). The queries' inputs may be shared
 * (handles, params, motions) but not their outputs. */
SDFCCD_API sdfccd_Status sdfccd_query_batch(sdfccd_BatchQuery* queries, int32_t count, int32_t threads);

#ifdef __cplusplus
}
#endif
#endif
