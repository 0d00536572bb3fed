/* SPDX-License-Identifier: MIT
 * sdfccd core: shared types of the narrow-phase solvers (DCD, FW, FWGSS, certified),
 * adaptive subdivision and the triangle and mesh queries. Stateless: every routine takes
 * its inputs and writes an output struct. All points are in the SDF's local frame. */
#ifndef SCC_CCD_H
#define SCC_CCD_H

#include <stdint.h>
#include "alloc.h"
#include "mesh.h"
#include "motion.h"
#include "sdf.h"
#include "workspace.h"

typedef enum scc_method { SCC_METHOD_FWGSS, SCC_METHOD_FW, SCC_METHOD_DCD, SCC_METHOD_CERTIFIED } scc_method;

typedef struct scc_params {
    scc_method method;
    double margin;          /* contact when phi <= margin */
    double time_tol;        /* absolute (s) */
    double dist_tol;        /* absolute (m) */
    int max_iter;
    int max_ls_iter;
    int fwgss_restarts;     /* extra FWGSS descents from the other vertices (0..2) */
    int fwgss_vertex_trace; /* conservative-advancement steps per vertex before the descents (0: off) */
    int subdivision;
    double sub_min_area;    /* m^2 */
    int sub_max_depth;      /* levels of splitting */
    double contact_slop;    /* m */
    double toi_window;      /* s */
    double max_rotation;    /* rad per segment */
    double cert_time_tol;   /* s */
    int64_t cert_max_regions;
    int64_t cert_max_bytes; /* bytes the region store of one certified search may hold (0: no limit) */
    int broad_phase;
    int fwgss_secant;       /* FWGSS entry time by Illinois regula falsi once a sign change is bracketed */
    int fwgss_speed_tol;    /* FWGSS spatial tolerance = speed bound x time_tol (else dist_tol) */
    int fwgss_brent_spatial; /* FWGSS spatial line searches by Brent's method (else golden section) */
    int fwgss_clear_budget; /* FWGSS: evaluations of the no-contact proof tried before the descents (0: off) */
    double fwgss_gap_tol;   /* FWGSS: line searches far from the surface stop early by this fraction of the gap */
    int fwgss_deriv_spatial; /* FWGSS: spatial line searches at full precision use the gradient (scc_deriv_minimize) */
    int fwgss_verify;       /* FWGSS on fields with gradient jumps (kinked analytic fields, grids): the answer checked by scc_fwgss_verify */
    int fwgss_kink_guard;   /* FWGSS on fields with gradient jumps (0 off, 1 grids after a check, 2 grids always): golden section, more starts, the 1 us probe */
    int fwgss_restart_at_witness; /* FWGSS: restarts begin at the earliest witness's time (else at ts) */
    int64_t max_evals;      /* SDF evaluation budget of this call (> 0); solvers stop at it (NOT_CONVERGED) */
} scc_params;

typedef enum scc_state { SCC_NO_HIT, SCC_HIT, SCC_PENETRATING, SCC_NOT_CONVERGED } scc_state;

/* Outcome of one triangle over one interval. */
typedef struct scc_tri_hit {
    scc_state state;
    int hit;                /* a contact was witnessed */
    double toi;             /* earliest witnessed contact time (the interval end when no hit) */
    double toi_lower;       /* certified: no contact before this; other methods: = toi */
    double bary[3];         /* contact point weights */
    scc_vec3 point;         /* contact point at toi */
    scc_vec3 normal;        /* grad phi at the point */
    double distance;        /* phi at the point */
    int64_t iterations;
    int64_t evals;
} scc_tri_hit;

typedef enum scc_contact_kind { SCC_CONTACT_PRIMARY, SCC_CONTACT_SUBDIVISION } scc_contact_kind;

typedef struct scc_contact {
    scc_vec3 point, normal; /* SDF frame, at toi */
    double distance;        /* phi at toi */
    double gap_t0;          /* phi of the same material point at the query's t0 */
    double toi;
    double bary[3];
    uint32_t triangle;
    scc_contact_kind kind;
} scc_contact;

/* ---- DCD (Section 3.2, Macklin et al. 2020): deepest point of a static triangle ---- */
typedef struct scc_dcd_result {
    double phi;
    scc_vec3 point, normal;
    double bary[3];         /* weights of tri[0..2] */
    int iterations, evals, converged;
} scc_dcd_result;
scc_dcd_result scc_dcd(const scc_sdf* sdf, const scc_vec3 tri[3], const scc_params* p);
/* The same with the vertices' values shared between the triangles of one mesh query (the same
 * answer, fewer evaluations): rec[i] (NULL, or rec NULL: none) is vertex i's record, fresh for the
 * query (hit_t INFINITY) or holding phi at the pose of time t (hit_t == t, hit_phi); a fresh record
 * is filled. The tri[] of every triangle at time t must come from the same pose computation. */
scc_dcd_result scc_dcd_traced(const scc_sdf* sdf, const scc_vec3 tri[3], scc_vertex_trace* const rec[3], double t, const scc_params* p);

/* ---- CCD on one interval [ta, tb] with at most max_rotation of rotation ---- */
void scc_fwgss(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p, scc_tri_hit* out);
void scc_fw(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p, scc_tri_hit* out);
/* Returns 0 on allocation failure (out untouched), 1 otherwise. Allocates through ws->alloc; the
 * check and the clear proof below keep their scratch in `ws` (slots SCC_WS_CHECK, SCC_WS_CELLS). */
int scc_certified(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                  scc_workspace* ws, scc_tri_hit* out);

/* FWGSS's answer checked on a field whose gradient may jump (issue 20; certified.c): the certified
 * search over [ta, toi] (no hit: [ta, tb]) seeded with FWGSS's witness, stopped once no contact is
 * proven more than max(SCC_VERIFY_TOL_FRACTION x time_tol, SCC_VERIFY_TOL) before it (3e-8 s at the
 * default time_tol: at 1e-7 s the 100K scaling scene's TOI was 1.5e-8 s after the certified bracket;
 * at 3e-8 s it is inside, at 1K, 10K and 100K), or after SCC_VERIFY_FACTOR x FWGSS's
 * evaluations + SCC_VERIFY_BASE_EVALS (at most SCC_VERIFY_MAX_EVALS). A search stopped at a cap short of
 * the witness is followed by scc_fwgss_probe from its unresolved region and run again seeded with the
 * contact found (at most SCC_VERIFY_PROBES times); the answer stands unless an earlier contact was
 * witnessed. An earlier contact found replaces it, bracketed to the certified
 * time tolerance. Returns 0 on allocation failure. */
#define SCC_VERIFY_TOL 1e-8
#define SCC_VERIFY_TOL_FRACTION 0.3
#define SCC_VERIFY_FACTOR 128
#define SCC_VERIFY_BASE_EVALS 16384
#define SCC_VERIFY_GRID_BASE_EVALS 65536 /* grids (their bound is certified.c's per-cell Taylor form) */
#define SCC_VERIFY_GRID_MIN_LIPSCHITZ 2.25 /* grids are checked where their cells' gradient bound along the path exceeds this */
#define SCC_VERIFY_MAX_EVALS 1000000
#define SCC_VERIFY_PROBES 2 /* rounds of scc_fwgss_probe when the check stops at a cap short of FWGSS's witness */
int scc_fwgss_verify(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                     scc_workspace* ws, scc_tri_hit* io);
/* A search for a contact in (t_lo, t_hi) near the weights b (fwgss.c; the check's fallback when it stops
 * at a cap with its lower bound t_lo more than tol before t_hi): the minimum of phi over the triangle by
 * FWGSS's spatial steps at t_lo + tol / 2, then at times 4x further each, up to t_hi; a contact found
 * is moved back to where the triangle enters (FWGSS's kink probe). At most max_evals evaluations; out
 * is a hit at the earliest contact found, or no hit. */
void scc_fwgss_probe(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p, double t_lo, double t_hi,
                     const double b[3], double tol, int64_t max_evals, scc_tri_hit* out);
/* scc_fwgss_verify, and with `force` also where FWGSS's own no-contact proof held (io a no-hit made
 * from a contact after tb: the check then proves [ta, tb] clear or finds a contact there). */
int scc_fwgss_check(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                    scc_workspace* ws, int force, scc_tri_hit* io);
/* The certified search over [ta, tb] within `budget` evaluations, for a short clear proof: no hit
 * with state SCC_NO_HIT proves [ta, tb] free of contact; a stop at the budget (SCC_NOT_CONVERGED)
 * still proves none before out->toi_lower, and a hit is a witness at out->toi. Returns 0 on
 * allocation failure. */
int scc_certified_clear(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p, scc_workspace* ws,
                        int64_t budget, scc_tri_hit* out);
/* Whether scc_fwgss_verify checks FWGSS on this field: fields with gradient jumps (analytic kinked
 * fields, grids, user fields) with fwgss_kink_guard and fwgss_verify on. On grids the search bounds
 * phi per cell by a first-order Taylor form (certified.c), not by the cells' Lipschitz bounds, and
 * runs only where the cells the triangle sweeps have a gradient bound above
 * SCC_VERIFY_GRID_MIN_LIPSCHITZ (a crease; a smooth shape's grid stays near 1). */
int scc_fwgss_verified(const scc_sdf* sdf, const scc_params* p);
/* The bending bound of the certified search on analytic fields, for tests (certified.c): K >= 0 with
 * phi(x) >= phi(c) + g.(x - c) - K |x - c|^2 / 2 for every x within rad of c, g the gradient
 * scc_sdf_eval gives at c (0 where phi is convex); INFINITY when unknown. */
double scc_sdf_bend_bound(const scc_sdf* sdf, scc_vec3 c, double rad);
/* The lower bounds of phi that the check uses on a grid, for tests: over the sub-triangle with weights
 * (u[i], v[i], 1 - u[i] - v[i]) of motion m over [ta, tb]; `local` 1: every cell's Hessian bound over
 * its part of the region's box (0: the whole cell's where the box lies inside it); 2: the bound from
 * the gradient intervals of the blocks the box touches instead. Returns 0 when the bound does not
 * apply (not a grid, the box leaves the domain of a grid not positive outside it, spans more than 3
 * cells per axis (512 blocks in all) or touches a cell without values). */
int scc_grid_region_bound(const scc_sdf* sdf, const scc_tri_motion* m, const double u[3], const double v[3], double ta, double tb, int local,
                          double* out_bound);

/* ---- adaptive triangle subdivision at the TOI (Section 4.5) ----
 * `tri` is the triangle at the TOI, `primary` the weights of the first contact. Writes up to
 * `capacity` extra contacts (weights w.r.t. tri, point, normal, phi) and returns their count. */
int scc_subdivide(const scc_sdf* sdf, const scc_vec3 tri[3], const double primary[3], const scc_params* p,
                  scc_contact* out, int capacity, int64_t* io_evals);
#define SCC_MAX_SUBDIVISION_CONTACTS 8

/* ---- triangle and mesh queries ---- */
typedef struct scc_query_summary {
    scc_state state;
    int hit;
    double toi, toi_lower;
    int contacts_found;     /* may exceed the capacity */
    int contacts_written;   /* written to the caller's array (mesh query: a reduction when found > capacity) */
    int64_t iterations, evals, triangles_tested;
} scc_query_summary;

/* One triangle over [ta, tb] (within the motion's [t0, t1]): splits large rotations, runs the method, then subdivision.
 * Returns 0 on allocation failure. Contacts: primary first, then subdivision points. The certified
 * searches' scratch is in `ws` (scc_certified). */
int scc_query_triangle(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                       scc_workspace* ws, uint32_t triangle_index, scc_contact* out, int capacity,
                       scc_query_summary* sum);
/* scc_query_triangle, except that with `raw` (not NULL) an FWGSS search of one segment on a field
 * whose answers are checked (scc_fwgss_verified) stops before the check: *deferred = 1, *raw holds
 * FWGSS's answer, `sum` its counts and no contact is written. The mesh query checks such answers
 * once its earliest contact is known (mesh_query.c), by scc_triangle_finish_deferred: the check over
 * [ta, tb] (a contact of raw after tb becomes a proof owed up to tb), then the contacts, exactly as
 * scc_query_triangle would have (with the same tb); `sum` then counts only what the finish added. */
int scc_query_triangle_deferred(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                                scc_workspace* ws, uint32_t triangle_index, scc_contact* out, int capacity,
                                scc_query_summary* sum, scc_tri_hit* raw, int* deferred);
int scc_triangle_finish_deferred(const scc_sdf* sdf, const scc_tri_motion* m, double ta, double tb, const scc_params* p,
                                 scc_workspace* ws, uint32_t triangle_index, scc_tri_hit raw, scc_contact* out,
                                 int capacity, scc_query_summary* sum);

/* A mesh whose triangles all follow one motion template: rigid (`body` set, vertices local) or
 * linear (`start`/`end` world vertex arrays). Returns 0 on allocation failure. */
typedef struct scc_mesh_motion {
    const scc_mesh* mesh;
    const scc_rigid* body;      /* rigid when not NULL */
    const scc_vec3* start;      /* linear: world vertices at t0 */
    const scc_vec3* end;        /* linear: world vertices at t1 */
    const scc_rigid* sdf;       /* NULL: static SDF */
    double t0, t1;
    /* Optional per-triangle contact levels (NULL: params->margin for every triangle): triangle t is in
     * contact when phi <= tri_margin[t]. Each must be <= params->margin, which the broad phase culls
     * with; -INFINITY leaves the triangle out. Used by the guard (guard.c); the FWGSS vertex traces are
     * then kept per triangle, since a vertex's neighbours may have different levels. */
    const double* tri_margin;
    /* Optional per-node flags of mesh->bsh (NULL: none): a node flagged 1 is proven clear of every
     * level of the query over the whole motion (scc_bsh_certify, bsh.h), so the broad phase skips it
     * and its subtree. Only read when the broad phase runs on mesh->bsh. */
    const uint8_t* node_clear;
} scc_mesh_motion;

/* The inputs of one mesh query: the field, the mesh's motion, the parameters and the scratch
 * storage (workspace.h). The narrow phase (mesh_query.c) and the broad phase it hands them to
 * (scc_bsh_traverse, bsh.h) read the same ones. */
typedef struct scc_mesh_query_in {
    const scc_sdf* sdf;
    const scc_mesh_motion* mm;
    const scc_params* p;
    scc_workspace* ws;
} scc_mesh_query_in;

int scc_query_mesh(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, const scc_allocator* alloc,
                   scc_contact* out, int capacity, scc_query_summary* sum);
/* A bound on the speed (SDF frame) of any point of the mesh over [mm->t0, mm->t1]. */
double scc_mesh_speed_bound(const scc_mesh_motion* mm);
/* The motion of triangle t of the mesh motion `mm` (what the mesh query tests per triangle). */
void scc_mesh_triangle_motion(const scc_mesh_motion* mm, uint32_t t, scc_tri_motion* out);
/* One vertex record per mesh vertex in `ws` (SCC_WS_TRACES) under a new epoch (ws->trace_epoch):
 * every record stale until handed out. NULL when out of memory. */
scc_vertex_trace* scc_mesh_traces(scc_workspace* ws, const scc_mesh* mesh);
/* The records of triangle t's vertices, made fresh (empty) where they are stale for `epoch`. */
void scc_triangle_traces(scc_vertex_trace* traces, const scc_mesh* mesh, uint32_t t, uint32_t epoch, scc_vertex_trace* out[3]);
/* The same with the scratch storage in a caller-kept workspace (workspace.h): after a first query
 * of a given size, later ones allocate nothing. */
int scc_query_mesh_ws(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, scc_workspace* ws, scc_contact* out,
                      int capacity, scc_query_summary* sum);

/* scc_query_mesh with instrumentation for benchmarks (mesh_query.c): `probe` (may be NULL) is
 * called with begin = 1 right before and begin = 0 right after each narrow-phase triangle test,
 * so a caller can time triangles; *out_broad_evals (may be NULL) receives the broad phase's
 * share of sum->evals. */
typedef void scc_mesh_probe_fn(void* user, uint32_t triangle, int begin);
int scc_query_mesh_probed(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_params* p, scc_workspace* ws,
                          scc_contact* out, int capacity, scc_query_summary* sum, scc_mesh_probe_fn* probe, void* probe_user,
                          int64_t* out_broad_evals);

#endif
