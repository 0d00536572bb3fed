/* SPDX-License-Identifier: MIT
 * sdfccd core: the contact set of one mesh against one SDF over a step (contacts.c). Stateless but
 * for the workspace's scratch; points, surface points and normals in the SDF's frame at t0. */
#ifndef SCC_CONTACTS_H
#define SCC_CONTACTS_H

#include "ccd.h"

typedef enum scc_feature_kind { SCC_FEATURE_VERTEX, SCC_FEATURE_EDGE, SCC_FEATURE_FACE } scc_feature_kind;

typedef struct scc_contact_point {
    scc_vec3 point;      /* the material point at t0 */
    scc_vec3 surface;    /* the surface point that holds it, at t0 */
    scc_vec3 normal;     /* unit, out of the SDF */
    double gap;          /* normal . (point - surface) */
    double toi;          /* t0 (start pose) or the CCD's time of impact */
    double bary[3];
    uint32_t triangle;
    scc_feature_kind kind;
    uint32_t feature;
    uint64_t id;
} scc_contact_point;

typedef struct scc_contact_set {
    size_t candidates;   /* found before the reduction */
    size_t written;      /* the reduction, at most the capacity */
    int started_in_contact; /* a start-pose point was within the margin (the CCD is not run) */
    int ccd_ran;
    scc_state ccd_state; /* NO_HIT when the CCD did not run */
    double toi;          /* the CCD's first TOI; t0 when started in contact; t1 when none */
    int64_t evals;
} scc_contact_set;

typedef struct scc_contact_params {
    scc_params query;        /* method, margin (contact when phi <= margin), caps */
    double vertex_distance;  /* vertices of a touching triangle within this of the margin are points too */
    double same_place;       /* the reduction's same-place distance */
} scc_contact_params;

/* The feature (vertex, edge or face) of triangle t at barycentric weights b, and its stable id,
 * into c's triangle, kind, feature and id. */
void scc_classify_feature(const scc_mesh* mesh, uint32_t t, const double b[3], scc_contact_point* c);

/* Candidates of the step [mm->t0, mm->t1] (rigid or per-vertex linear motion) reduced to at most
 * `capacity` points in out. Returns 0 on allocation failure. */
int scc_generate_contacts(const scc_sdf* sdf, const scc_mesh_motion* mm, const scc_contact_params* cp, scc_workspace* ws,
                          scc_contact_point* out, int capacity, scc_contact_set* sum);

#endif
