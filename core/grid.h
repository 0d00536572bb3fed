/* SPDX-License-Identifier: MIT
 * sdfccd core: grid signed distance fields on Discregrid's 32-node cubic Lagrange
 * (serendipity) cells, the layout Bullet's btMiniSDF reads (shared notes
 * sdf-format-and-assets.md, sections 2-6).
 *
 * A grid holds one or more fields (field 0 is the SDF); each field has a node array, a cell
 * table (32 node ids per stored cell, in slot order) and a map from every full-grid cell to a
 * stored cell or SCC_GRID_NO_CELL (a culled cell).
 *
 * Evaluation of field 0 through the scc_sdf interface never returns a sentinel:
 *  - inside the domain, in a cell with values: the cubic interpolant and its gradient (as
 *    Discregrid and Bullet compute them, gradient not normalised);
 *  - in a culled cell (or one touching a "not sampled" node): a conservative value whose sign
 *    is the side of the surface and whose magnitude is a lower bound on the distance, with a
 *    unit gradient pointing away from the nearest cell that has values (see eval_hole in grid.c);
 *  - outside the domain box: a lower bound built from the distance d to the box and the value
 *    phi(p) at the nearest box point p (see scc_grid_eval).
 * All routines are pure; evaluation is thread-safe. Memory comes from the caller's allocator.
 * Files: the element in grid_cell.c, storage and evaluation in grid.c, the derived bounds
 * (scc_grid_finalize) in grid_bounds.c, building in grid_build.c.
 */
#ifndef SCC_GRID_H
#define SCC_GRID_H

#include <stddef.h>
#include <stdint.h>
#include "alloc.h"
#include "grid_cell.h"
#include "mesh.h"
#include "sdf.h"

#define SCC_GRID_NO_CELL 0xFFFFFFFFu
/* Discregrid's "not sampled" node value (DBL_MAX). */
#define SCC_GRID_NO_VALUE 1.7976931348623157e308
/* Limits of loaded and built grids: domain coordinates and node values within +-1e100, cells at
 * least 1e-50 wide, so distances, squares and gradients (value / cell size) stay finite. */
#define SCC_GRID_MAX_COORDINATE 1e100
#define SCC_GRID_MIN_CELL 1e-50

/* ---- grid data ---- */

typedef struct scc_grid_field {
    double* nodes;        /* node_count values */
    uint64_t node_count;
    uint32_t* cells;      /* 32 * cell_count node ids, slot order; NULL for a dense field 0 in
                             Discregrid's numbering (ids computed: scc_grid_cell_ids) */
    /* nodes: node_count values; NULL for a dense field 0 (values in scc_grid.blocks) */
    uint64_t cell_count;
    uint32_t* map;        /* n_cells entries: stored cell index or SCC_GRID_NO_CELL */
} scc_grid_field;

typedef struct scc_grid {
    scc_sdf base;              /* must stay first */
    scc_vec3 lo, hi;           /* domain */
    uint32_t res[3];           /* cells per axis */
    scc_vec3 h, inv_h;         /* cell size and its inverse as stored in the file */
    uint64_t n_cells;          /* res[0] * res[1] * res[2] */
    uint32_t field_count;
    scc_grid_field* fields;    /* field_count entries */

    /* Derived data for field 0 (scc_grid_finalize). */
    float* block_lipschitz;    /* max of the cell bounds per block of 4^3 cells (cells without values: 1) */
    float* block_grad;         /* per block of SCC_GRID_GRAD_BLOCK^3 cells, 6 floats: the least then the largest value of each
                                  component of grad phi over its cells (their Bernstein enclosures,
                                  rounded outward); -inf / +inf when a cell of the block has no values */
    float* cell_lipschitz;     /* per stored cell of field 0: bound on |grad phi| inside it, or -1
                                  when the cell touches a not-sampled node (then it has no value) */
    uint32_t* hole_source;     /* n_cells entries when some cell has no value, else NULL: for a cell
                                  without value, the full index of the nearest (Chebyshev) cell with
                                  values, with bit 31 set when the cell lies inside (phi < 0) */
    uint64_t valued_cells;     /* cells of field 0 with values */
    double band;               /* known lower bound on |phi| in cells without value (0 if unknown) */
    double lipschitz_max;      /* max of cell_lipschitz */
    int outside_positive;      /* every boundary node >= 0: outside the box phi is positive */
    int dense_layout;          /* field 0 is dense in Discregrid's numbering: fields[0].cells and
                                  fields[0].nodes are NULL (node_count stays the file's count) and
                                  the values live in `blocks` (vertex_block NULL) */
    double* blocks;            /* field 0 built in-tree or dense: 7 values per grid vertex
                                  (scc_grid_dense_block_index); fields[0].nodes/cells are NULL */
    uint64_t block_count;      /* doubles in blocks */
    uint32_t* vertex_block;    /* narrow band built in-tree: per grid vertex, its block in `blocks`
                                  (only vertices of kept cells have one); NULL when dense */
    double* bernstein;         /* (scc_grid_finalize) 32 x 64: row k holds node slot k's share of each of a
                                  cell's 64 tensor Bernstein coefficients (scc_cell_bernstein, transposed) */
    double* axis_coef;         /* (scc_grid_finalize) per axis d, per cell m along it, the pair
                                  c0 = 2/(hi-lo), c1 = (hi+lo)/(hi-lo) of the cell's interval exactly as
                                  Discregrid and Bullet compute them per query: 2 (res[0]+res[1]+res[2])
                                  doubles, axis 0 first; spares six divisions per evaluation */
    int direct;                /* field 0 dense in vertex blocks, identity map, every cell valued:
                                  evaluation goes from the cell straight to its 8 blocks */
    scc_allocator allocator;   /* what freed the arrays (copied at creation) */
} scc_grid;

/* Cells per axis of a block of block_grad, and the blocks per axis. */
#define SCC_GRID_GRAD_BLOCK 2
static inline uint32_t scc_grid_grad_blocks(const scc_grid* g, int d) { return (g->res[d] + SCC_GRID_GRAD_BLOCK - 1) / SCC_GRID_GRAD_BLOCK; }
static inline size_t scc_grid_grad_block_count(const scc_grid* g)
{
    return (size_t)scc_grid_grad_blocks(g, 0) * scc_grid_grad_blocks(g, 1) * scc_grid_grad_blocks(g, 2);
}

/* A task runner: runs task(ctx, i) for every i in [0, count), possibly in parallel, and
 * returns when all are done. `stage` tells progress reporters which phase runs
 * (SCC_GRID_STAGE_*). Returns nonzero when the caller asked to cancel (the builder then
 * stops with SCC_GRID_BUILD_CANCELLED). */
typedef void scc_task_fn(void* ctx, uint32_t task);
typedef int scc_parallel_for_fn(void* user, int stage, uint32_t count, scc_task_fn* task, void* ctx);
enum { SCC_GRID_STAGE_NODES = 0, SCC_GRID_STAGE_CELLS = 1, SCC_GRID_STAGE_CORNERS = 2, SCC_GRID_STAGE_EDGES = 3 };

/* Allocates an empty grid header with `field_count` zeroed field records and sets the geometry:
 * h = (hi - lo) / res and inv_h = 1 / h, as Discregrid computes them. Returns NULL on OOM.
 * The caller fills the fields (arrays allocated with the same allocator) and then calls
 * scc_grid_finalize. */
scc_grid* scc_grid_create(const scc_allocator* a, scc_vec3 lo, scc_vec3 hi, const uint32_t res[3], uint32_t field_count);
/* The same with h and inv_h given (a file's stored values). */
scc_grid* scc_grid_create_raw(const scc_allocator* a, scc_vec3 lo, scc_vec3 hi, const uint32_t res[3],
                              scc_vec3 h, scc_vec3 inv_h, uint32_t field_count);
void scc_grid_destroy(scc_grid* g);

/* Results of scc_grid_finalize. */
typedef enum scc_grid_status {
    SCC_GRID_OK = 0,
    SCC_GRID_OUT_OF_MEMORY,
    SCC_GRID_EMPTY,           /* field 0 has no cell with values */
    SCC_GRID_CANCELLED,       /* parallel_for reported a cancel */
    SCC_GRID_TOO_LARGE,       /* more than 2^31 - 1 cells */
    SCC_GRID_STEEP            /* a cell's gradient bound overflows (values huge for the cell size) */
} scc_grid_status;

/* Computes the derived data of field 0 (grid_bounds.c): adopts the vertex-block layout for a
 * dense field 0, per-cell gradient bounds, the hole sources for culled cells, per-block bounds,
 * whether phi >= 0 on the domain boundary, and fills the scc_sdf interface. Safe to call once after the fields are set.
 * `band`: a known lower bound on |phi| inside culled cells (0 when unknown). */
scc_grid_status scc_grid_finalize(scc_grid* g, double band, scc_parallel_for_fn* parallel_for, void* parallel_user);

/* The 32 node ids of stored cell c of `field` (from the table, or computed into `scratch` for
 * a dense field 0). */
const uint32_t* scc_grid_cell_ids(const scc_grid* g, uint32_t field, uint32_t c, uint32_t scratch[32]);

/* Position of dense node `l` (Discregrid's numbering) in the vertex-block layout: vertex
 * (i,j,k) owns the 7 values [7b, 7b+7), b = i + (nx+1)(j + (ny+1)k): its own value, then the
 * two nodes of each of the x, y and z edges starting at it. A cell's 32 values then come from
 * 8 blocks (4 pairs of neighbours), which keeps evaluation cache- and TLB-friendly. */
uint64_t scc_grid_dense_block_index(const uint32_t res[3], uint64_t l);
/* Value of node `id` (file numbering) of `field`, whatever the storage (NAN for a band grid built
 * in-tree, whose node numbering only exists in the files it saves). */
double scc_grid_node_value(const scc_grid* g, uint32_t field, uint64_t id);

/* Bytes owned by the grid (header, fields, derived arrays). */
size_t scc_grid_memory(const scc_grid* g);

/* ---- evaluation ---- */

/* Raw interpolation of `field` at p, exactly as Discregrid/Bullet do it (inclusive domain
 * test, cell clamp, 2/h gradient scaling). Returns 0 (no value: outside the domain, culled
 * cell or a not-sampled node) or 1 and writes *out_value and, when out_grad is not NULL, the
 * (unnormalised) gradient. */
int scc_grid_interpolate(const scc_grid* g, uint32_t field, scc_vec3 p, double* out_value, scc_vec3* out_grad);

/* Field 0 as an SDF (the scc_sdf eval function): see the header comment for the three cases. */
double scc_grid_eval(const scc_sdf* self, scc_vec3 p, scc_vec3* out_grad);

/* scc_grid_eval at n points (out_g may be NULL): the same numbers, with a dense grid's cell
 * loads started ahead of the points that need them. */
void scc_grid_eval_batch(const scc_grid* g, const scc_vec3* p, size_t n, double* out_v, scc_vec3* out_g);

/* x86-64 with GCC or Clang: the direct grids' evaluation also compiled for AVX (no FMA: the same
 * bits), chosen at finalize when the processor has it (scc_grid_avx). */
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__) && !defined(SCC_CELL_PLAIN_C) && !defined(SCC_GRID_NO_AVX)
#define SCC_GRID_AVX 1
double scc_grid_eval_avx(const scc_sdf* self, scc_vec3 p, scc_vec3* out_grad);
#else
#define SCC_GRID_AVX 0
#endif
/* 1 when the AVX evaluation is available and the processor runs it. */
int scc_grid_avx(void);

/* Bound on |grad phi| of field 0 inside `box` (the scc_sdf lipschitz_in function): the max of
 * the per-cell bounds of the cells the box touches; at least 1 where the box touches a cell
 * without values; 1 + the global bound where the box leaves the domain. */
double scc_grid_lipschitz_in(const scc_sdf* self, const scc_aabb* box);

/* Full-grid index of the cell containing p (clamped into the grid). */
uint64_t scc_grid_cell_of(const scc_grid* g, scc_vec3 p);

/* ---- dense node numbering (section 2 of the notes) ---- */

/* Number of nodes of a dense field. */
uint64_t scc_grid_dense_node_count(const uint32_t res[3]);
/* Position of dense node `l`, computed in Discregrid's order of operations. */
scc_vec3 scc_grid_dense_node_position(const scc_grid* g, uint64_t l);
/* The 32 dense node ids of full-grid cell (i, j, k), in slot order. */
void scc_grid_dense_cell_nodes(const uint32_t res[3], uint32_t i, uint32_t j, uint32_t k, uint32_t out[32]);

/* ---- building ---- */


/* The function sampled at the nodes: value at p. Must be thread-safe. `state` is a scratch word
 * private to the calling task (UINT32_MAX at the task's start; consecutive calls of a task are
 * at nearby nodes), e.g. for a nearest-triangle hint. The value must not depend on it.
 * `cap` (> 0, possibly INFINITY): the builder only needs the value when |value| < cap; when
 * |value| >= cap the function may return any value of magnitude >= cap (e.g. cap itself). */
typedef double scc_grid_sample_fn(void* user, scc_vec3 p, uint32_t* state, double cap);

typedef struct scc_grid_build_def {
    scc_vec3 lo, hi;           /* domain (lo < hi) */
    uint32_t res[3];           /* cells per axis (>= 1) */
    double band;               /* > 0: cull cells whose 32 node values all have |v| >= band + |h|
                                  (cell diagonal); <= 0 or INFINITY: dense */
    scc_grid_sample_fn* sample;
    void* sample_user;
    double sample_lipschitz;   /* > 0: a Lipschitz bound L of the sampled function (1 for exact
                                  distances); lets a narrow-band build skip the edge nodes of cells
                                  that are certainly culled, and gives culled cells the known bound
                                  |phi| >= band + |h| (1 - L). 0: unknown (every node sampled, no
                                  known bound in culled cells). */
    scc_parallel_for_fn* parallel_for; /* NULL: serial */
    void* parallel_user;
    uint64_t max_bytes;        /* > 0: limit on what a narrow-band build holds at once for its
                                  nodes (corner values, candidate and final blocks, lists, cell
                                  map); an allocation that would pass it is not made and the build
                                  returns SCC_GRID_BUILD_OVER_LIMIT. 0: no limit */
    uint64_t* needed_bytes;    /* may be NULL: with OVER_LIMIT, the total the refused allocation
                                  would have reached */
} scc_grid_build_def;

typedef enum scc_grid_build_status {
    SCC_GRID_BUILD_OK = 0,
    SCC_GRID_BUILD_OUT_OF_MEMORY,
    SCC_GRID_BUILD_TOO_LARGE,  /* node or cell count beyond 32-bit ids */
    SCC_GRID_BUILD_EMPTY_BAND, /* the band culled every cell */
    SCC_GRID_BUILD_BAD_VALUE,  /* the sample function returned NaN or infinity */
    SCC_GRID_BUILD_CANCELLED,
    SCC_GRID_BUILD_OVER_LIMIT  /* the band's node storage would pass def->max_bytes */
} scc_grid_build_status;

/* Builds a one-field grid (dense in Discregrid's layout, or narrow-band). */
scc_grid_build_status scc_grid_build(const scc_allocator* a, const scc_grid_build_def* def, scc_grid** out_grid);

/* Discregrid's automatic domain: the box of the vertices, max enlarged by 1e-3 |diag|, then
 * min lowered by 1e-3 |diag'| of the enlarged box. */
scc_aabb scc_grid_fit_domain(scc_aabb vertex_box);

#endif
