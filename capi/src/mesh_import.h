/* SPDX-License-Identifier: MIT
 * sdfccd C ABI internals of sdfccd_load_mesh: the readers (mesh_import.c, obj_reader.c). */
#ifndef SDFCCD_MESH_IMPORT_H
#define SDFCCD_MESH_IMPORT_H

#include "capi_internal.h"

/* Scales `verts` (3 * nv), welds equal positions in place when d->merge_vertices is set (rewriting
 * `idx`, 3 * nt), and creates the mesh handle. `path` names the file in messages. The arrays stay
 * the caller's. */
sdfccd_Status sdfccd__finish_imported_mesh(double* verts, uint32_t nv, uint32_t* idx, uint32_t nt, const sdfccd_MeshLoadDef* d,
                                          const char* path, sdfccd_MeshId* out_mesh);
/* Reads a Wavefront OBJ file in double precision (obj_reader.c). */
sdfccd_Status sdfccd__load_obj(const char* path, const sdfccd_MeshLoadDef* d, sdfccd_MeshId* out_mesh);

#endif
