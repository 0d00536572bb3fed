/* SPDX-License-Identifier: MIT
 * sdfccd core: an SDF stretched along its axes (sdf_stretch.c). */
#ifndef SCC_SDF_STRETCH_H
#define SCC_SDF_STRETCH_H

#include "sdf.h"

typedef struct scc_sdf_stretch {
    scc_sdf base;
    const scc_sdf* child;
    scc_vec3 scale;   /* per axis, > 0 */
    double min_scale; /* the smallest component of scale */
} scc_sdf_stretch;

/* phi(x) = min(s) * phi_child(x / s) per component (validated by the caller: s finite, > 0). */
void scc_sdf_stretch_init(scc_sdf_stretch* s, const scc_sdf* child, scc_vec3 scale);

#endif
