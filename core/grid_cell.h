/* SPDX-License-Identifier: MIT
 * sdfccd core: the grid's element, the 32-node cubic Lagrange (serendipity) cell (slot numbering
 * in grid_cell.c; shared notes sdf-format-and-assets.md section 3). Local coordinates xi are in
 * [-1,1]^3. Pure functions.
 */
#ifndef SCC_GRID_CELL_H
#define SCC_GRID_CELL_H

#include "scc_math.h"

/* Local coordinates (in [-1,1]^3) of the node in slot `slot` (0..31). */
scc_vec3 scc_cell_node_local(int slot);
/* Shape functions N[32] at local point xi; when dN is not NULL also dN/dxi (dN[a][d]). */
void scc_cell_shape(scc_vec3 xi, double N[32], double dN[32][3]);
/* sum_a v[a] N_a(xi) and, when out_grad is not NULL, its derivatives with respect to xi, in a
 * factored form (about 4x fewer operations than going through scc_cell_shape). */
void scc_cell_eval(const double v[32], scc_vec3 xi, double* out_value, double out_grad[3]);
/* The tensor cubic Bernstein form of the shape functions on [-1,1]^3: out[s][a] is coefficient
 * s = i + 4j + 16k (i, j, k in 0..3 along x, y, z) of shape function a, so the interpolant of node
 * values v has the Bernstein coefficients b[s] = sum_a out[s][a] v[a]. */
void scc_cell_bernstein(double out[64][32]);

#endif
