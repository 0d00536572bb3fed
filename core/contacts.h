/* SPDX-License-Identifier: MIT
 * sdfccd core: the contact set of one mesh against one SDF over a step (contacts.c). Stateless but
 * for the workspace's scratch; points, surface points and normals in the SDF's frame at t0. */
#ifndef SCC_CONTACTS_H
#define SCC_CONTACTS_H

#include "ccd.h"
#include "reduce.h"

typedef enum scc_feature_kind { SCC_FEATURE_VERTEX, SCC_FEATURE_EDGE, SCC_FEATURE_FACE } scc_feature_kind;

typedef struct scc_contact_point {
    scc_vec3 point;      /* the material point at t0 */
    scc_vec3 surface;    /* the surface point that holds it (found at `toi`) */
    scc_vec3 normal;     /* unit, out of the SDF */
    double gap;          /* normal . (point - surface) */
    double toi;          /* t0 (start pose), the CCD's time of impact, t1 (end pose) */
    double bary[3];
    uint32_t triangle;
    scc_feature_kind kind;
    uint32_t feature;
    uint64_t id;
} scc_contact_point;

typedef struct scc_contact_set {
    size_t candidates;      /* found before the reduction */
    size_t written;         /* points written: the reduction, then cover points */
    size_t reduced;         /* the first `reduced` written are the reduction */
    int started_in_contact; /* a start-pose point was within the margin (the CCD is not run) */
    int ccd_ran;
    int discrete_queries;   /* start- and end-pose queries run */
    scc_state ccd_state;    /* NO_HIT when the CCD did not run */
    double toi;             /* the CCD's first TOI; t0 when started in contact; t1 when none */
    int64_t evals;          /* every SDF evaluation of the call */
    int64_t own_evals;      /* those outside the mesh queries and the face search (closest points) */
    int64_t face_regions;   /* regions the face search visited */
} scc_contact_set;

typedef struct scc_contact_params {
    scc_params query;        /* method, margin (contact when phi <= margin), caps */
    double vertex_distance;  /* vertices of a triangle the CCD finds within this (or contact_slop) of the margin are points too */
    double same_place;       /* the reduction's same-place distance; 0: 1e-3 x the mesh's radius, at least 1e-6 */
    double feature_size;     /* the SDF's smallest feature (> 0 with subdivision: the face search) */
    int reduced;             /* points of the reduction (0: the whole capacity); the rest of the capacity: cover points */
    double cover_depth;      /* the cover points' depth (m; 0: none) */
    double end_skip_travel;  /* > 0 (continuous): no end-pose query when the step's travel is at most this */
    scc_reduce_keep keep;    /* the previous step's points, preferred by the reduction (keep.n 0: none) */
} scc_contact_params;

/* The feature (vertex, edge or face) of triangle t at barycentric weights b, and its stable id,
 * into c's triangle, kind, feature and id. */
void scc_classify_feature(const scc_mesh* mesh, uint32_t t, const double b[3], scc_contact_point* c);

/* Candidates of the step [mm->t0, mm->t1] (rigid or per-vertex linear motion) reduced to at most
 * `capacity` points in out (see contacts.c for the rules). Returns 0 on allocation failure. */
int scc_generate_contacts(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_contact_params* cp, scc_workspace* ws,
                          scc_contact_point* out, int capacity, scc_contact_set* sum);

#endif
