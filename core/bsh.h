/* SPDX-License-Identifier: MIT
 * sdfccd core: the bounding-sphere hierarchy (BSH) broad phase of the mesh query
 * (Pelletier-Guenette et al., SCA 2025, Section 4.6).
 *
 * A binary tree of spheres over a mesh's triangles, built once per mesh in the mesh's local
 * frame (one triangle per leaf). A rigid motion moves every sphere rigidly, so the tree is used
 * as built; per-vertex linear motion (cloth, deformables) refits it per query: every node gets a
 * start and an end centre and one radius that covers its triangles at every time in between.
 *
 * Culling is padded sphere tracing. The interval is split into segments that rotate (relative to
 * the SDF) at most min(pi, params->max_rotation), and finely enough that the padding of a point at
 * the root sphere's rim stays below twice the mean leaf radius (at most 64 segments), since the
 * padding shrinks with the square of the segment length; on each segment a node's centre path c(t) is
 * replaced by its chord L(t) (the lerp between the segment's end centres) and the sphere's radius
 * is padded by
 *     pad = max(|c(tm) - L(tm)|,  A (tb - ta)^2 / 8),
 * the first term being the paper's heuristic (true versus linear mid-interval centre) and the
 * second the interpolation-error bound for a path with acceleration at most A (an upper bound
 * from the motion). The second term makes the padding a proof that c(t) stays within pad of the
 * chord. The padded sphere is then marched along the chord: with a Lipschitz bound K of the
 * field, a sphere of radius R centred at x is clear while (phi(x) - margin) / K > R, and it can
 * advance by the excess. A node whose march stalls (excess below a small tolerance, or the step
 * cap reached) is a candidate at that time, which is a lower bound of any contact of its
 * triangles (as long as K is a true Lipschitz bound). Candidates are processed earliest first
 * (a priority queue keyed by that time); a child is marched from its parent's candidate time.
 * Where the narrow phase is costly (a mesh queried by FWGSS whose answers the certified search checks,
 * on an analytic field with kinks) the tracing goes on below a leaf over its triangle's sub-triangles,
 * in the same queue (bsh.c, "below the leaf": a leaf's sphere can be much wider than its triangle);
 * the triangle goes to the caller at the time its earliest sub-triangle stalls, or never when they
 * all pass the interval's end. There (after the step's start) the search is also ordered: a march
 * pauses where its next evaluation would be later than the queue's first item and resumes when the
 * queue reaches it, so no evaluation is spent after a contact found meanwhile, and a node stalls at a
 * looser clearance (its time only starts its children or its regions). The caller may shrink the end
 * of the searched interval (every narrow-phase hit does), which stops the march of everything later.
 *
 * DCD (end pose only) uses the same tree statically: a node is culled when its sphere at the end
 * pose is clear.
 */
#ifndef SCC_BSH_H
#define SCC_BSH_H

#include <stddef.h>
#include <stdint.h>
#include "alloc.h"
#include "ccd.h"
#include "mesh.h"
#include "sdf.h"
#include "workspace.h"

typedef struct scc_bsh_node {
    scc_vec3 center;   /* local frame */
    double radius;     /* covers every vertex of the node's triangles */
    uint32_t first;    /* inner: index of the left child (the right one is first + 1); leaf: triangle index */
    uint32_t is_leaf;
} scc_bsh_node;

typedef struct scc_bsh {
    scc_bsh_node* nodes;  /* node 0 is the root */
    uint32_t node_count;  /* 2 * triangle_count - 1 */
    uint32_t triangle_count;
    double leaf_radius;   /* mean radius of the leaf spheres (sets how finely a spinning motion is split) */
    size_t bytes;         /* everything this hierarchy allocated, the struct included */
} scc_bsh;

/* Builds the hierarchy over `mesh` (top-down median split of triangle centroids on the longest
 * axis). Returns NULL when out of memory or when the mesh has no triangle. */
scc_bsh* scc_bsh_build(const scc_mesh* mesh, const scc_allocator* alloc);
void scc_bsh_destroy(scc_bsh* bsh, const scc_allocator* alloc);

/* A node refitted for per-vertex linear motion: at time fraction s every point of the node's
 * triangles lies within `radius` of lerp(c0, c1, s). */
typedef struct scc_bsh_moving_node {
    scc_vec3 c0, c1;
    double radius;
} scc_bsh_moving_node;

/* Refits `bsh` (built on `mesh`'s topology) for vertices moving linearly from `start` to `end`
 * (world positions). `out` holds bsh->node_count nodes. */
void scc_bsh_refit_linear(const scc_bsh* bsh, const scc_mesh* mesh, const scc_vec3* start, const scc_vec3* end,
                          scc_bsh_moving_node* out);

/* Counters of one traversal. */
typedef struct scc_bsh_stats {
    int64_t evals;          /* SDF evaluations spent marching (nodes and the sub-triangles below leaves) */
    int64_t nodes_visited;  /* node-segment marches */
    int64_t candidates;     /* leaves handed to the visitor */
} scc_bsh_stats;

/* Called for each candidate triangle, earliest candidate time first, at most once per triangle.
 * `t_candidate` is the time at which its padded sphere may first touch. The visitor may lower
 * *io_t_end (the end of the searched interval). Return 0 to abort the traversal (out of memory). */
typedef int scc_bsh_visit_fn(void* user, uint32_t triangle, double t_candidate, double* io_t_end);

/* Traverses `bsh` for the query `in` (field, motion `in->mm`, parameters `in->p`) over
 * [in->mm->t0, t_end]: continuous (padded sphere tracing) unless `in->p->method` is DCD, which
 * tests the pose at t_end only. `moving` is the refit for linear motion (NULL for rigid motion;
 * required when in->mm->body is NULL). Scratch storage comes from `in->ws` (workspace.h), which
 * keeps it for the next traversal. Returns 0 on allocation failure, when the visitor aborts, or
 * when linear motion comes without its refit. */
int scc_bsh_traverse(const scc_bsh* bsh, const scc_bsh_moving_node* moving, const scc_mesh_query_in* in, double t_end,
                     scc_bsh_visit_fn* visit, void* user, scc_bsh_stats* stats);

/* The guard's certificate (no CCD): for a rigid motion over [mm->t0, mm->t1] (T long) against a
 * static SDF (or one whose frame does not move), every point of the body moves at a speed of at most
 * |v| + |w| d (d its distance from the centre of rotation), so within T/2 of the middle time tm it
 * stays within h = (|v| T + |w| T d) / 2 of where it is at tm. Node i of `bsh` (centre c, radius r)
 * is therefore proven clear of phi <= level at every time of the interval when
 *     phi(c(tm)) - K (r + h) > level,   d = |c - centre of rotation| + r,
 * K the field's Lipschitz bound. With `dcd` (not NULL), a leaf that fails gets a second stage: its
 * triangle's deepest point at tm by DCD (params `dcd`), phi_min, and it is clear when
 * phi_min - K h > level (as sure as that local search, like the CCD it replaces); where that fails
 * with phi_min > level, each half of the interval is tried the same way (h halves), twice deep. Writes clear[i] = 1
 * for each node so proven, whose subtree is then skipped, and 0 for the others; returns the number
 * of leaves not proven clear (the triangles the CCD must still check), or -1 when the motion is not
 * one it applies to (nothing written). Adds its SDF evaluations (one per node, plus the DCDs) to
 * *io_evals. `ws` (may be NULL) holds vertex records (scc_mesh_traces) so that the leaves' DCDs at
 * the middle time evaluate each vertex once. */
int64_t scc_bsh_certify(const scc_bsh* bsh, const scc_mesh_motion* mm, const scc_sdf* sdf, double level, const scc_params* dcd,
                        uint8_t* clear, scc_workspace* ws, int64_t* io_evals);

#endif
