/* SPDX-License-Identifier: MIT
 * sdfccd core: the face search (faces.c), points of large faces within a distance of an SDF. */
#ifndef SCC_FACES_H
#define SCC_FACES_H

#include "contacts.h"

/* A point of a face inside the SDF keeps the field's normal when it is within about 25 degrees of
 * the face's direction out of the SDF (a face on a smooth surface); otherwise it is pushed out
 * along the face's normal. */
#define SCC_FACE_NORMAL_AGREEMENT 0.9

/* The face search at time `time` of mm's motion (see faces.c): regions with edges at most `size`,
 * points with phi <= accept, each held by its surface point (SDF frame at `time`). Writes at most
 * `capacity` points to out and the count found to *out_found; adds the regions visited and the SDF
 * evaluations to the counters. Returns 0 on allocation failure. */
int scc_search_faces(const scc_sdf* sdf, const scc_mesh_motion* mm, double time, double size, double accept, const scc_params* base,
                     scc_workspace* ws, scc_contact_point* out, size_t capacity, size_t* out_found, int64_t* io_regions, int64_t* io_evals);

#endif
