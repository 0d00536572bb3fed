/* SPDX-License-Identifier: MIT
 * sdfccd core: analytic signed distance fields with exact gradients, CSG and transforms.
 * Each struct embeds scc_sdf first; the *_init functions fill the interface. */
#ifndef SCC_SDF_ANALYTIC_H
#define SCC_SDF_ANALYTIC_H

#include "sdf.h"

typedef struct scc_sdf_sphere { scc_sdf base; double radius; } scc_sdf_sphere;
typedef struct scc_sdf_box { scc_sdf base; scc_vec3 half; double radius; } scc_sdf_box; /* radius > 0: rounded */
typedef struct scc_sdf_torus { scc_sdf base; double major, minor; } scc_sdf_torus;
typedef struct scc_sdf_capsule { scc_sdf base; double half_height, radius; } scc_sdf_capsule;
typedef struct scc_sdf_cylinder { scc_sdf base; double half_height, radius; } scc_sdf_cylinder;
typedef struct scc_sdf_half_space { scc_sdf base; scc_vec3 normal; double offset; } scc_sdf_half_space;
typedef struct scc_sdf_spike_grid {
    scc_sdf base;
    double spacing, base_radius, height;
    int count_x, count_y;
    double x0, y0; /* centre of cone (0, 0) */
} scc_sdf_spike_grid;

typedef enum scc_csg_op { SCC_CSG_UNION, SCC_CSG_INTERSECTION, SCC_CSG_DIFFERENCE } scc_csg_op;
typedef struct scc_sdf_csg { scc_sdf base; scc_csg_op op; const scc_sdf* a; const scc_sdf* b; } scc_sdf_csg;
typedef struct scc_sdf_transform { scc_sdf base; const scc_sdf* child; scc_xform xf; double scale; } scc_sdf_transform;

/* Parameters are validated by the caller (the ABI layer): positive sizes, finite values. */
void scc_sdf_sphere_init(scc_sdf_sphere* s, double radius);
void scc_sdf_box_init(scc_sdf_box* s, scc_vec3 half, double radius);
void scc_sdf_torus_init(scc_sdf_torus* s, double major, double minor);
void scc_sdf_capsule_init(scc_sdf_capsule* s, double half_height, double radius);
void scc_sdf_cylinder_init(scc_sdf_cylinder* s, double half_height, double radius);
void scc_sdf_half_space_init(scc_sdf_half_space* s, scc_vec3 unit_normal, double offset);
void scc_sdf_spike_grid_init(scc_sdf_spike_grid* s, double spacing, double base_radius, double height, int nx, int ny);
void scc_sdf_csg_init(scc_sdf_csg* s, scc_csg_op op, const scc_sdf* a, const scc_sdf* b);
void scc_sdf_transform_init(scc_sdf_transform* s, const scc_sdf* child, scc_xform xf, double scale);

#endif
