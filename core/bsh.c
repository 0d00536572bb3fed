/* SPDX-License-Identifier: MIT
 * sdfccd core: bounding-sphere hierarchy and padded sphere tracing (Section 4.6 of
 * Pelletier-Guenette et al., SCA 2025). The contract and the padding argument are in bsh.h. */
#include "bsh.h"
#include "select_kth.h"
#include "min_heap.h"

#include <string.h>

/* ---------------------------------------------------------------- spheres */

/* Smallest sphere through or around three points: the circumsphere for an acute triangle,
 * the longest edge's diametral sphere otherwise. The radius is re-measured from the vertices so
 * round-off can only make it larger. */
static void triangle_sphere(scc_vec3 a, scc_vec3 b, scc_vec3 c, scc_vec3* out_c, double* out_r)
{
    scc_vec3 ab = scc_sub(b, a), ac = scc_sub(c, a), bc = scc_sub(c, b);
    double dA = scc_dot(ab, ac), dB = -scc_dot(ab, bc), dC = scc_dot(ac, bc);
    scc_vec3 centre;
    if (dA <= 0.0) centre = scc_scale(scc_add(b, c), 0.5);
    else if (dB <= 0.0) centre = scc_scale(scc_add(a, c), 0.5);
    else if (dC <= 0.0) centre = scc_scale(scc_add(a, b), 0.5);
    else {
        scc_vec3 n = scc_cross(ab, ac);
        double n2 = scc_len2(n);
        if (n2 > 0.0) {
            scc_vec3 num = scc_cross(scc_sub(scc_scale(ac, scc_len2(ab)), scc_scale(ab, scc_len2(ac))), n);
            centre = scc_add(a, scc_scale(num, 0.5 / n2));
        } else {
            centre = scc_scale(scc_add(scc_add(a, b), c), 1.0 / 3.0);
        }
    }
    double r = fmax(scc_dist(centre, a), fmax(scc_dist(centre, b), scc_dist(centre, c)));
    *out_c = centre;
    *out_r = r * (1.0 + 1e-12);
}

/* Smallest sphere containing two spheres. */
static void merge_spheres(scc_vec3 c1, double r1, scc_vec3 c2, double r2, scc_vec3* out_c, double* out_r)
{
    double d = scc_dist(c1, c2);
    if (d + r2 <= r1) { *out_c = c1; *out_r = r1; return; }
    if (d + r1 <= r2) { *out_c = c2; *out_r = r2; return; }
    double r = 0.5 * (d + r1 + r2);
    *out_c = scc_madd(c1, scc_sub(c2, c1), (r - r1) / d);
    *out_r = r * (1.0 + 1e-12);
}

/* ---------------------------------------------------------------- build */

typedef struct build_ctx {
    const scc_mesh* mesh;
    scc_bsh_node* nodes;
    uint32_t* order;      /* triangle indices, permuted during the build */
    scc_vec3* centroid;   /* per triangle */
    uint32_t next;        /* next free node index */
} build_ctx;

static void build_node(build_ctx* b, uint32_t index, uint32_t lo, uint32_t hi)
{
    scc_bsh_node* node = &b->nodes[index];
    const scc_mesh* m = b->mesh;
    if (hi - lo == 1) {
        scc_vec3 v[3];
        scc_mesh_triangle(m, b->order[lo], v);
        triangle_sphere(v[0], v[1], v[2], &node->center, &node->radius);
        node->first = b->order[lo];
        node->is_leaf = 1;
        return;
    }
    scc_aabb cb = { { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    scc_aabb vb = cb;
    for (uint32_t i = lo; i < hi; ++i) {
        scc_vec3 c = b->centroid[b->order[i]];
        cb.lo = scc_vmin(cb.lo, c);
        cb.hi = scc_vmax(cb.hi, c);
        scc_vec3 v[3];
        scc_mesh_triangle(m, b->order[i], v);
        for (int k = 0; k < 3; ++k) {
            vb.lo = scc_vmin(vb.lo, v[k]);
            vb.hi = scc_vmax(vb.hi, v[k]);
        }
    }
    scc_vec3 ext = scc_sub(cb.hi, cb.lo);
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    uint32_t mid = lo + (hi - lo) / 2;
    scc_select_kth(b->order, b->centroid, axis, lo, hi, mid);
    uint32_t left = b->next;
    b->next += 2;
    node->first = left;
    node->is_leaf = 0;
    build_node(b, left, lo, mid);
    build_node(b, left + 1, mid, hi);
    node = &b->nodes[index];

    /* Two valid spheres; keep the smaller: the children merged, or the vertex box's centre with
     * the farthest vertex. */
    scc_vec3 cm;
    double rm;
    merge_spheres(b->nodes[left].center, b->nodes[left].radius, b->nodes[left + 1].center, b->nodes[left + 1].radius, &cm, &rm);
    scc_vec3 cv = scc_scale(scc_add(vb.lo, vb.hi), 0.5);
    double rv = 0.0;
    for (uint32_t i = lo; i < hi; ++i) {
        scc_vec3 v[3];
        scc_mesh_triangle(m, b->order[i], v);
        for (int k = 0; k < 3; ++k) rv = fmax(rv, scc_len2(scc_sub(v[k], cv)));
    }
    rv = sqrt(rv) * (1.0 + 1e-12);
    if (rv < rm) { node->center = cv; node->radius = rv; }
    else { node->center = cm; node->radius = rm; }
}

scc_bsh* scc_bsh_build(const scc_mesh* mesh, const scc_allocator* alloc)
{
    uint32_t n = mesh->triangle_count;
    if (n == 0) return NULL;
    uint32_t count = 2 * n - 1;
    size_t node_bytes = (size_t)count * sizeof(scc_bsh_node);
    scc_bsh* bsh = scc_alloc(alloc, sizeof *bsh);
    scc_bsh_node* nodes = scc_alloc(alloc, node_bytes);
    uint32_t* order = scc_alloc(alloc, (size_t)n * sizeof *order);
    scc_vec3* centroid = scc_alloc(alloc, (size_t)n * sizeof *centroid);
    if (!bsh || !nodes || !order || !centroid) {
        scc_free(alloc, bsh, sizeof *bsh);
        scc_free(alloc, nodes, node_bytes);
        scc_free(alloc, order, (size_t)n * sizeof *order);
        scc_free(alloc, centroid, (size_t)n * sizeof *centroid);
        return NULL;
    }
    for (uint32_t t = 0; t < n; ++t) {
        scc_vec3 v[3];
        scc_mesh_triangle(mesh, t, v);
        order[t] = t;
        centroid[t] = scc_scale(scc_add(scc_add(v[0], v[1]), v[2]), 1.0 / 3.0);
    }
    build_ctx b = { mesh, nodes, order, centroid, 1 };
    build_node(&b, 0, 0, n);
    scc_free(alloc, order, (size_t)n * sizeof *order);
    scc_free(alloc, centroid, (size_t)n * sizeof *centroid);
    bsh->nodes = nodes;
    bsh->node_count = count;
    bsh->triangle_count = n;
    double rsum = 0.0;
    for (uint32_t i = 0; i < count; ++i)
        if (nodes[i].is_leaf) rsum += nodes[i].radius;
    bsh->leaf_radius = rsum / n;
    bsh->bytes = sizeof *bsh + node_bytes;
    return bsh;
}

void scc_bsh_destroy(scc_bsh* bsh, const scc_allocator* alloc)
{
    if (!bsh) return;
    scc_free(alloc, bsh->nodes, (size_t)bsh->node_count * sizeof(scc_bsh_node));
    scc_free(alloc, bsh, sizeof *bsh);
}

/* ---------------------------------------------------------------- refit */

static void refit_node(const scc_bsh* bsh, const scc_mesh* mesh, const scc_vec3* start, const scc_vec3* end,
                       scc_bsh_moving_node* out, uint32_t i)
{
    const scc_bsh_node* n = &bsh->nodes[i];
    if (n->is_leaf) {
        const uint32_t* f = mesh->indices + 3 * n->first;
        double r0, r1;
        triangle_sphere(start[f[0]], start[f[1]], start[f[2]], &out[i].c0, &r0);
        triangle_sphere(end[f[0]], end[f[1]], end[f[2]], &out[i].c1, &r1);
        out[i].radius = fmax(r0, r1);
        return;
    }
    refit_node(bsh, mesh, start, end, out, n->first);
    refit_node(bsh, mesh, start, end, out, n->first + 1);
    const scc_bsh_moving_node* a = &out[n->first];
    const scc_bsh_moving_node* b = &out[n->first + 1];
    double r0, r1;
    merge_spheres(a->c0, a->radius, b->c0, b->radius, &out[i].c0, &r0);
    merge_spheres(a->c1, a->radius, b->c1, b->radius, &out[i].c1, &r1);
    /* Each point's offset from the lerped centre is the lerp of its end offsets, so the larger
     * end radius covers every time in between. */
    out[i].radius = fmax(r0, r1);
}

void scc_bsh_refit_linear(const scc_bsh* bsh, const scc_mesh* mesh, const scc_vec3* start, const scc_vec3* end,
                          scc_bsh_moving_node* out)
{
    if (bsh->node_count) refit_node(bsh, mesh, start, end, out, 0);
}

/* ---------------------------------------------------------------- traversal */

#define MARCH_MAX_STEPS 48
/* A march stalls where the sphere's clearance is below this fraction of its radius (plus 1 nm). In
 * the ordered search (scc_bsh_traverse) a node's candidate time only sets where its children's
 * marches (an inner node) or its regions below the leaf (a leaf) start, which step on from there
 * anyway: closing in on it further only adds steps (100K scaling scene: 4,304 -> 4,133 evaluations,
 * 10K 5,860 -> 5,800, 1K 8,662 -> 8,638). */
#define MARCH_TOL 1e-3
#define MARCH_TOL_INNER_ORDERED 0.02
#define MARCH_TOL_LEAF_ORDERED 0.1
#define SEG_MARCHING 0x80000000u /* a node being marched: `key` is the time of its next evaluation */
#define SEG_REGION 0x40000000u /* a region below a leaf (sub_triangle): `sub` names it */

typedef struct segment {
    double ta, tm, tb;
    scc_quat q[3];    /* rigid body pose at ta, tm, tb */
    scc_vec3 p[3];
} segment;

typedef struct item {
    double key;       /* candidate time (a node being marched: the time of its next evaluation) */
    uint32_t node;
    uint32_t seg;     /* | SEG_MARCHING for a node being marched, | SEG_REGION for a region below a leaf */
    uint32_t sub;     /* a region: its depth (top byte) and the child taken at each level (2 bits each);
                         a node being marched: the evaluations of its march so far */
    uint32_t tri;     /* a region: its triangle's record (below_tri) */
} item;

SCC_MIN_HEAP(item_heap, item, key)

typedef struct trav {
    const scc_bsh* bsh;
    const scc_bsh_moving_node* moving;
    const scc_mesh_query_in* in;
    double lipschitz;
    double w_body2;           /* |w_body|^2 */
    segment* seg;
    uint32_t nseg;            /* 0 until the segments are laid out */
    scc_bsh_stats* stats;
} trav;

/* A bound on |grad phi| where the mesh can be over [ta, tb]: the SDF's own bound inside the box
 * its root sphere sweeps (grids bound the gradient per cell, scc_sdf_lipschitz), never above the
 * global one. Every point phi is evaluated at and every material point it bounds lie in that box
 * (a convex set), so the Lipschitz arguments below hold with it. A moving SDF keeps the global bound. */
static double region_lipschitz(const scc_bsh* bsh, const scc_bsh_moving_node* moving, const scc_mesh_motion* mm, const scc_sdf* sdf,
                               double ta, double tb)
{
    const double global = sdf->lipschitz > 0.0 ? sdf->lipschitz : 1.0;
    if (!sdf->lipschitz_in || (mm->sdf && (scc_len2(mm->sdf->v) > 0.0 || scc_len2(mm->sdf->w) > 0.0))) return global;
    scc_vec3 a, b;
    double r;
    if (moving) { /* linear motion: the root's spheres at both ends hold the mesh all along */
        a = moving[0].c0;
        b = moving[0].c1;
        r = moving[0].radius;
    } else if (mm->body) { /* rigid: every point stays within r of the centre, which moves on a line */
        r = scc_dist(bsh->nodes[0].center, mm->body->c_local) + bsh->nodes[0].radius;
        a = scc_rigid_center_at(mm->body, ta);
        b = scc_rigid_center_at(mm->body, tb);
    } else {
        return global;
    }
    a = scc_sdf_frame_point(mm->sdf, ta, a);
    b = scc_sdf_frame_point(mm->sdf, tb, b);
    r += 1e-9 * (1.0 + r);
    const scc_vec3 pad = scc_v3(r, r, r);
    scc_aabb box = { scc_sub(scc_vmin(a, b), pad), scc_add(scc_vmax(a, b), pad) };
    const double L = scc_sdf_lipschitz(sdf, &box);
    return L > 0.0 && L < global ? L : global;
}

static double node_radius(const trav* tr, uint32_t i)
{
    return tr->moving ? tr->moving[i].radius : tr->bsh->nodes[i].radius;
}

/* Node centre in the SDF frame at time t, using a precomputed body pose (rigid motion). */
static scc_vec3 centre_at(const trav* tr, uint32_t i, double t, const scc_quat* q, const scc_vec3* p)
{
    scc_vec3 w;
    const scc_mesh_motion* mm = tr->in->mm;
    if (tr->moving) {
        double span = mm->t1 - mm->t0;
        double s = span > 0.0 ? (t - mm->t0) / span : 0.0;
        w = scc_lerp(tr->moving[i].c0, tr->moving[i].c1, s);
    } else {
        w = scc_add(scc_quat_rotate(*q, tr->bsh->nodes[i].center), *p);
    }
    return scc_sdf_frame_point(mm->sdf, t, w);
}

/* Upper bound on the acceleration (SDF frame) of a node's centre. */
static double centre_accel_bound(const trav* tr, uint32_t i)
{
    const scc_mesh_motion* mm = tr->in->mm;
    if (!mm->sdf) {
        if (tr->moving) return 0.0;
        return tr->w_body2 * scc_dist(tr->bsh->nodes[i].center, mm->body->c_local);
    }
    scc_tri_motion m;
    memset(&m, 0, sizeof m);
    m.sdf = mm->sdf;
    m.t0 = mm->t0;
    m.t1 = mm->t1;
    if (tr->moving) {
        m.kind = SCC_TRI_LINEAR;
        for (int k = 0; k < 3; ++k) { m.start[k] = tr->moving[i].c0; m.end[k] = tr->moving[i].c1; }
    } else {
        m.kind = SCC_TRI_RIGID;
        m.body = mm->body;
        for (int k = 0; k < 3; ++k) m.local[k] = tr->bsh->nodes[i].center;
    }
    return scc_tri_accel_bound(&m);
}

static double field(trav* tr, scc_vec3 x)
{
    tr->stats->evals += 1;
    return scc_sdf_eval(tr->in->sdf, x, NULL);
}

enum { MARCH_CLEAR, MARCH_STALLED, MARCH_PAUSED };

/* Marches node i's padded sphere along the chord of segment s from time *io_t (after *io_steps
 * evaluations of this march) towards `to`, stalling at a clearance below rel_tol times its radius.
 * Returns MARCH_STALLED with the candidate time in *io_t, MARCH_CLEAR when the sphere stays clear
 * up to `to`, or MARCH_PAUSED when its next evaluation would be later than `pause` (the earliest
 * other item of the queue): the march goes on from *io_t when the queue reaches it. So every
 * evaluation is made in time order across the whole queue, and none is spent after a contact found
 * meanwhile (ours; the 100K scaling scene: 410 of 1,227 march evaluations were later than the
 * search's final end). */
static int march(trav* tr, uint32_t i, uint32_t s, double to, double pause, double rel_tol, double* io_t, uint32_t* io_steps)
{
    const segment* sg = &tr->seg[s];
    if (*io_steps == 0) {
        if (tr->in->mm->node_clear && tr->in->mm->node_clear[i]) return MARCH_CLEAR; /* proven clear (scc_bsh_certify) */
        tr->stats->nodes_visited += 1;
    }
    scc_vec3 A = centre_at(tr, i, sg->ta, &sg->q[0], &sg->p[0]);
    scc_vec3 M = centre_at(tr, i, sg->tm, &sg->q[1], &sg->p[1]);
    scc_vec3 B = centre_at(tr, i, sg->tb, &sg->q[2], &sg->p[2]);
    double span = sg->tb - sg->ta;
    double pad = scc_dist(M, scc_scale(scc_add(A, B), 0.5));
    pad = scc_fmax(pad, centre_accel_bound(tr, i) * span * span * 0.125);
    double R = node_radius(tr, i) + pad;
    R += 1e-12 * (1.0 + R);
    double tol = rel_tol * R + 1e-9;
    scc_vec3 D = scc_sub(B, A);
    double len = scc_len(D);
    double t = *io_t;
    for (;;) {
        double f = span > 0.0 ? (t - sg->ta) / span : 0.0;
        double phi = field(tr, scc_madd(A, D, f));
        *io_steps += 1;
        double clear = (phi - tr->in->p->margin) / tr->lipschitz - R;
        if (!(clear > tol)) { *io_t = t; return MARCH_STALLED; }
        if (!(len > 0.0) || !(span > 0.0)) return MARCH_CLEAR;
        t += clear * span / len;
        if (t > to) return MARCH_CLEAR;
        *io_t = t;
        if (*io_steps >= MARCH_MAX_STEPS) return MARCH_STALLED; /* the step cap: a lower bound all the same */
        if (t > pause) return MARCH_PAUSED;
    }
}

/* ---------------------------------------------------------------- below the leaf */

/* A leaf's sphere holds its triangle loosely (a long triangle's sphere is as wide as its longest
 * edge), so its candidate time can precede the triangle's first contact by the time the body takes
 * to move that radius (the 100K scaling scene: 5-18 mm spheres, 3-7 ms before the triangles' TOIs,
 * and 33 triangles searched where one had the contact). So the tracing goes on below the leaf (ours):
 * a sub-triangle (barycentric corners) whose points lie within rad of its centroid c(t) cannot
 * touch before t + ((phi(c) - margin) / K - rad) / S, S the triangle's speed bound; one that cannot
 * advance by its radius is split in four. The regions join the traversal's queue, so the search
 * stays earliest first over nodes and regions alike, and a triangle goes to the narrow phase when
 * its earliest region stalls at REGION_MAX_DEPTH levels (or after REGION_MAX_EVALS evaluations of
 * its regions, for a face landing flat, where every region stalls together): the time of that
 * region is then a proven lower bound of its contacts. A triangle whose regions all pass the end
 * of the searched interval is never searched. A region found in contact goes at once, and so does
 * a leaf whose sphere touches at the query's start (a resting contact, where the narrow phase is
 * cheap and the regions would only add evaluations: Bullet bunny scene 289,491 evaluations
 * before the regions, 332,550 with them for these, 295,055 without). */
#define REGION_MAX_DEPTH 5
#define REGION_MAX_EVALS 48
/* a triangle's region count lives in 7 bits beside its mark; 127 with the mark would read as "searched" */
_Static_assert(REGION_MAX_EVALS < 127, "REGION_MAX_EVALS must stay below 127");
/* A region advances while its clearance is at least this fraction of its radius, and is split only
 * below it: a short step costs one evaluation, a split four (100K scaling scene: split below the full
 * radius 5,064 evaluations, below a quarter of it 4,696; 10K 7,213 -> 5,895, 1K 9,571 -> 8,662). */
#define REGION_STEP_MIN 0.25
/* A region's centroid is interpolated (region_step) where that pads its radius by at most this fraction. */
#define REGION_CHORD_PAD 0.05

/* A triangle bounded below its leaf: its motion and speed bound, taken once for all its regions.
 * The same records list every triangle marked in `tested`, so the traversal can clear only those. */
typedef struct below_tri {
    scc_tri_motion m;
    double speed;
    double accel; /* a bound on the acceleration of its points (scc_tri_accel_bound) */
    uint32_t triangle;
} below_tri;

/* The barycentric corners (u[i], v[i], 1 - u[i] - v[i]) of the region `sub`: the child taken at
 * each level (0..2 keep corner 0..2, 3 is the middle one). */
static void sub_triangle(uint32_t sub, double u[3], double v[3])
{
    u[0] = 1; u[1] = 0; u[2] = 0;
    v[0] = 0; v[1] = 1; v[2] = 0;
    const uint32_t depth = sub >> 24;
    for (uint32_t d = 0; d < depth; ++d) {
        const uint32_t k = (sub >> (2 * d)) & 3u;
        double mu[3], mv[3];
        for (int i = 0; i < 3; ++i) {
            const int j = (i + 1) % 3;
            mu[i] = 0.5 * (u[i] + u[j]);
            mv[i] = 0.5 * (v[i] + v[j]);
        }
        /* child k keeps corner k and the midpoints of its two edges; child 3 is the midpoints' triangle */
        if (k == 0) { u[1] = mu[0]; u[2] = mu[2]; v[1] = mv[0]; v[2] = mv[2]; }
        else if (k == 1) { u[0] = mu[0]; u[2] = mu[1]; v[0] = mv[0]; v[2] = mv[1]; }
        else if (k == 2) { u[0] = mu[2]; u[1] = mu[1]; v[0] = mv[2]; v[1] = mv[1]; }
        else { for (int i = 0; i < 3; ++i) { u[i] = mu[i]; v[i] = mv[i]; } }
    }
}

/* The point with weights (u, v, 1 - u - v) of the triangle x[0..2]. */
static scc_vec3 bary_point(const scc_vec3 x[3], double u, double v)
{
    return scc_add(scc_add(scc_scale(x[0], u), scc_scale(x[1], v)), scc_scale(x[2], 1.0 - u - v));
}

/* One step of region `it` (of the triangle of leaf it.node) from its time: 1 when it advanced
 * (it->key moved on) or was split (children written to kids[0..3], *n_kids = 4); 0 when it
 * stalls (in contact, or at the depth limit). */
static int region_step(trav* tr, const below_tri* bt, item* it, item kids[4], int* n_kids)
{
    const scc_tri_motion* mp = &bt->m;
    const double speed = bt->speed;
    *n_kids = 0;
    if (!(speed > 0.0)) return 0;
    double u[3], v[3];
    sub_triangle(it->sub, u, v);
    const double cu = (u[0] + u[1] + u[2]) / 3.0, cv = (v[0] + v[1] + v[2]) / 3.0;
    scc_vec3 c;
    double rad = 0.0;
    if (mp->kind == SCC_TRI_RIGID) {
        /* a rigid motion keeps distances: the radius from the body-frame corners, only the centroid posed */
        const scc_vec3 lc = bary_point(mp->local, cu, cv);
        for (int i = 0; i < 3; ++i) rad = fmax(rad, scc_dist(bary_point(mp->local, u[i], v[i]), lc));
        uint32_t s = it->seg & ~SEG_REGION;
        while (s + 1 < tr->nseg && it->key > tr->seg[s].tb) ++s;
        const segment* sg = tr->nseg ? &tr->seg[s] : NULL;
        const double span = sg ? sg->tb - sg->ta : 0.0;
        const double pad = bt->accel * span * span * 0.125;
        if (sg && !mp->sdf && pad <= REGION_CHORD_PAD * rad) {
            /* On a static field, where it costs little, the centroid is taken on the chord of the
             * segment holding the time (its poses at both ends are at hand) rather than posed: the
             * chord is within accel T^2 / 8 of the path (as a node's centre, march), accel bounding
             * the acceleration of every point of the triangle. */
            it->seg = s | SEG_REGION;
            const scc_vec3 A = scc_add(scc_quat_rotate(sg->q[0], lc), sg->p[0]);
            const scc_vec3 B = scc_add(scc_quat_rotate(sg->q[2], lc), sg->p[2]);
            c = scc_lerp(A, B, span > 0.0 ? (it->key - sg->ta) / span : 0.0);
            rad += pad + 1e-12 * (1.0 + scc_len(c)); /* the poses' rounding */
        } else {
            const double bc[3] = { cu, cv, 1.0 - cu - cv };
            c = scc_tri_point_at(mp, bc, it->key, NULL);
        }
    } else {
        scc_tri_state st;
        scc_tri_state_at(mp, it->key, &st);
        c = bary_point(st.x, cu, cv);
        for (int i = 0; i < 3; ++i) rad = fmax(rad, scc_dist(bary_point(st.x, u[i], v[i]), c));
    }
    rad += 1e-9 * (1.0 + rad); /* the corners' rounding */
    const double gap = field(tr, c) - tr->in->p->margin;
    if (!(gap > 0.0)) return 0; /* in contact at this time: the triangle's turn */
    const double clear = gap / tr->lipschitz - rad;
    if (clear > REGION_STEP_MIN * rad) { /* a useful step (REGION_STEP_MIN) */
        it->key += clear / speed;
        return 1;
    }
    const uint32_t depth = it->sub >> 24;
    if (depth >= REGION_MAX_DEPTH) return 0;
    for (uint32_t k = 0; k < 4; ++k) {
        kids[k] = *it;
        kids[k].sub = ((depth + 1) << 24) | (it->sub & 0xffffffu) | (k << (2 * depth));
    }
    *n_kids = 4;
    return 1;
}

/* The traversal's records of marked triangles (below_tri), growing in their workspace slot. */
typedef struct below_list {
    below_tri* a;
    size_t n, cap;
} below_list;

/* Appends a record for `triangle` (its motion too when `with_motion`); NULL when out of memory. */
static below_tri* below_add(below_list* L, scc_workspace* ws, const scc_mesh_motion* mm, uint32_t triangle, int with_motion)
{
    if (L->n == L->cap) {
        const size_t cap = L->cap ? 2 * L->cap : 64;
        below_tri* a = scc_alloc(ws->alloc, cap * sizeof *a);
        if (!a) return NULL;
        if (L->n) memcpy(a, L->a, L->n * sizeof *a);
        scc_free(ws->alloc, L->a, L->cap * sizeof *a);
        L->a = a;
        L->cap = cap;
        scc_ws_adopt(ws, SCC_WS_BELOW, a, cap * sizeof *a);
    }
    below_tri* b = &L->a[L->n++];
    b->triangle = triangle;
    b->speed = b->accel = 0.0;
    if (with_motion) {
        scc_mesh_triangle_motion(mm, triangle, &b->m);
        b->speed = scc_tri_speed_bound(&b->m);
        b->accel = scc_tri_accel_bound(&b->m);
    }
    return b;
}

static int traverse_static(trav* tr, double t_end, scc_bsh_visit_fn* visit, void* user)
{
    /* DCD: the pose at t_end only. Depth-first with an explicit stack (depth <= 64 for a
     * median-split tree of up to 2^30 triangles, but grow it anyway). */
    const scc_bsh* b = tr->bsh;
    scc_workspace* ws = tr->in->ws;
    scc_quat q = scc_quat_identity();
    scc_vec3 p = scc_v3(0, 0, 0);
    if (!tr->moving) scc_rigid_pose_at(tr->in->mm->body, t_end, &q, &p);
    size_t n = 0;
    uint32_t* stack = scc_ws_get(ws, SCC_WS_STACK, 128 * sizeof *stack);
    if (!stack) return 0;
    size_t cap = ws->slot[SCC_WS_STACK].bytes / sizeof *stack;
    const scc_allocator* alloc = ws->alloc;
    stack[n++] = 0;
    int ok = 1;
    double te = t_end;
    while (n && ok) {
        uint32_t i = stack[--n];
        if (tr->in->mm->node_clear && tr->in->mm->node_clear[i]) continue; /* proven clear (scc_bsh_certify) */
        tr->stats->nodes_visited += 1;
        scc_vec3 c = centre_at(tr, i, t_end, &q, &p);
        double clear = (field(tr, c) - tr->in->p->margin) / tr->lipschitz - node_radius(tr, i) * (1.0 + 1e-12);
        if (clear > 0.0) continue;
        if (b->nodes[i].is_leaf) {
            tr->stats->candidates += 1;
            ok = visit(user, b->nodes[i].first, t_end, &te);
            continue;
        }
        if (n + 2 > cap) {
            uint32_t* ns = scc_alloc(alloc, 2 * cap * sizeof *ns);
            if (!ns) { ok = 0; break; }
            memcpy(ns, stack, n * sizeof *ns);
            scc_free(alloc, stack, ws->slot[SCC_WS_STACK].bytes);
            stack = ns;
            cap *= 2;
            scc_ws_adopt(ws, SCC_WS_STACK, stack, cap * sizeof *stack);
        }
        stack[n++] = b->nodes[i].first + 1;
        stack[n++] = b->nodes[i].first;
    }
    return ok;
}

int scc_bsh_traverse(const scc_bsh* bsh, const scc_bsh_moving_node* moving, const scc_mesh_query_in* in, double t_end,
                     scc_bsh_visit_fn* visit, void* user, scc_bsh_stats* stats)
{
    const scc_mesh_motion* mm = in->mm;
    const scc_params* p = in->p;
    scc_workspace* ws = in->ws;
    stats->evals = stats->nodes_visited = stats->candidates = 0;
    if (!bsh || bsh->node_count == 0) return 1;
    if (!mm->body && !moving) return 0; /* linear motion needs the refit */
    trav tr;
    tr.bsh = bsh;
    tr.moving = moving;
    tr.in = in;
    tr.lipschitz = region_lipschitz(bsh, moving, mm, in->sdf, p->method == SCC_METHOD_DCD ? t_end : mm->t0, t_end);
    tr.w_body2 = mm->body && !moving ? scc_len2(mm->body->w) : 0.0;
    tr.stats = stats;
    tr.seg = NULL;
    tr.nseg = 0;
    if (p->method == SCC_METHOD_DCD) return traverse_static(&tr, t_end, visit, user);

    /* Segments: no more than min(pi, max_rotation) of relative rotation each. */
    double w = (mm->body && !moving ? scc_len(mm->body->w) : 0.0) + (mm->sdf ? scc_len(mm->sdf->w) : 0.0);
    double limit = p->max_rotation > 0.0 ? scc_fmin(p->max_rotation, SCC_PI) : SCC_PI;
    double angle = w * fabs(t_end - mm->t0);
    uint32_t nseg = 1;
    if (angle > limit) {
        double k = ceil(angle / limit);
        nseg = k > 1e5 ? 100000u : (uint32_t)k;
    }
    {
        /* Padding ~ A T^2 / 8 for a segment of length T: split until a point on the root's rim
         * is padded by at most twice the mean leaf radius. */
        double r_root = moving ? moving[0].radius : bsh->nodes[0].radius;
        double A = centre_accel_bound(&tr, 0) + w * w * r_root;
        double target = 2.0 * (moving ? 0.0 : bsh->leaf_radius);
        if (moving) {
            double rs = 0.0;
            for (uint32_t i = 0; i < bsh->node_count; ++i)
                if (bsh->nodes[i].is_leaf) rs += moving[i].radius;
            target = 2.0 * rs / bsh->triangle_count;
        }
        double T = fabs(t_end - mm->t0);
        if (A > 0.0 && target > 0.0) {
            double k = ceil(T * sqrt(A / (8.0 * target)));
            if (k > 64.0) k = 64.0;
            if (k > nseg) nseg = (uint32_t)k;
        }
    }
    segment* seg = scc_ws_get(ws, SCC_WS_SEGMENTS, nseg * sizeof *seg);
    /* per triangle: bit 7 searched (or being bounded below its leaf), bits 0-6 its regions' evaluations;
     * zero between traversals (each clears the triangles it recorded), so only new storage is cleared here */
    const int fresh = ws->slot[SCC_WS_TESTED].bytes < (size_t)bsh->triangle_count;
    uint8_t* tested = scc_ws_get(ws, SCC_WS_TESTED, (size_t)bsh->triangle_count);
    if (tested && fresh) memset(tested, 0, ws->slot[SCC_WS_TESTED].bytes);
    below_list marked = { ws->slot[SCC_WS_BELOW].p, 0, ws->slot[SCC_WS_BELOW].bytes / sizeof(below_tri) };
    /* the heap grows in its workspace slot (its storage is handed back at the end) */
    item_heap heap = { ws->slot[SCC_WS_HEAP].p, 0, ws->slot[SCC_WS_HEAP].bytes / sizeof(item), ws->alloc, 0, 0 };
    if (heap.cap * sizeof(item) != ws->slot[SCC_WS_HEAP].bytes) { /* not the heap's own storage: start afresh */
        scc_free(ws->alloc, heap.a, ws->slot[SCC_WS_HEAP].bytes);
        heap.a = NULL;
        heap.cap = 0;
    }
    int ok = seg && tested;
    if (ok) {
        tr.seg = seg;
        tr.nseg = nseg;
        for (uint32_t s = 0; s < nseg; ++s) {
            segment* sg = &seg[s];
            sg->ta = mm->t0 + (t_end - mm->t0) * s / nseg;
            sg->tb = s + 1 == nseg ? t_end : mm->t0 + (t_end - mm->t0) * (s + 1) / nseg;
            sg->tm = 0.5 * (sg->ta + sg->tb);
            const double ts[3] = { sg->ta, sg->tm, sg->tb };
            for (int k = 0; k < 3; ++k) {
                if (!moving) scc_rigid_pose_at(mm->body, ts[k], &sg->q[k], &sg->p[k]);
                else { sg->q[k] = scc_quat_identity(); sg->p[k] = scc_v3(0, 0, 0); }
            }
            item root = { sg->ta, 0, s | SEG_MARCHING, 0, 0 };
            if (!(ok = item_heap_push(&heap, root))) break;
        }
    }
    /* Below the leaf only where a triangle spared is worth the regions' evaluations: in a mesh (a lone
     * triangle has no other candidate to be ordered against, and FWGSS's prove_clear is its clear
     * proof) whose narrow phase checks every answer by the certified search on an analytic field with
     * kinks (scc_fwgss_verified; hundreds to thousands of evaluations per triangle: 100K scaling scene
     * 8,061 -> 6,437 evaluations). Not on grids, whose check runs only where the cells are sharp: Table
     * 4's bunny on the torus grid (94.7 evaluations per triangle) went 15,340 -> 17,541 with it. */
    const int below = bsh->triangle_count > 1 && p->method == SCC_METHOD_FWGSS && in->sdf->kind != SCC_SDF_GRID &&
                      scc_fwgss_verified(in->sdf, p);
    /* Ordered (there too, after the step's start): a march pauses where its next evaluation is later
     * than the queue's first item, and children wait in the queue for their march, so every evaluation
     * comes in time order and none is spent after a contact found meanwhile (march). Elsewhere, and for
     * the nodes touching at the start (the resting contacts, all of the same time, whose order the
     * queue's history sets), a node is marched whole when its parent's turn comes, as before: the
     * answers stay those of before where the triangles are cheap, and the resting contacts are searched
     * in the same order (Table 4's shuriken: 2,605 evaluations, 2,771 in another order). */
    const int ordered = below;
    double te = t_end;
    while (ok && heap.n && stats->evals < p->max_evals) { /* marching alone may use up the budget */
        item it = item_heap_pop(&heap);
        if (it.key > te) break;
        uint32_t s = it.seg & ~(SEG_MARCHING | SEG_REGION);
        if (it.seg & SEG_MARCHING) {
            const int ord = ordered && it.key > mm->t0;
            const double pause = ord && heap.n ? heap.a[0].key : INFINITY;
            const double rel_tol = !ord ? MARCH_TOL : bsh->nodes[it.node].is_leaf ? MARCH_TOL_LEAF_ORDERED : MARCH_TOL_INNER_ORDERED;
            const int r = march(&tr, it.node, s, scc_fmin(seg[s].tb, te), pause, rel_tol, &it.key, &it.sub);
            if (r == MARCH_STALLED) it.seg = s, it.sub = 0; /* a candidate at it.key */
            if (r != MARCH_CLEAR) ok = item_heap_push(&heap, it);
            continue;
        }
        const scc_bsh_node* n = &bsh->nodes[it.node];
        if (it.seg & SEG_REGION) {
            uint8_t* rec = &tested[n->first];
            if (*rec == 0xffu) continue; /* searched already */
            item kids[4];
            int n_kids;
            const int64_t before = stats->evals;
            const int moved = (*rec & 0x7fu) < REGION_MAX_EVALS && region_step(&tr, &marked.a[it.tri], &it, kids, &n_kids);
            *rec = (uint8_t)(0x80u | ((*rec & 0x7fu) + (stats->evals - before)));
            if (moved) {
                if (n_kids == 0 && it.key <= te) ok = item_heap_push(&heap, it);
                for (int k = 0; k < n_kids && ok; ++k) ok = item_heap_push(&heap, kids[k]);
                continue;
            }
            /* stalled: the earliest region of the triangle (the queue's first), a lower bound of its contacts */
            *rec = 0xffu;
            stats->candidates += 1;
            ok = visit(user, n->first, it.key, &te);
            continue;
        }
        if (n->is_leaf) {
            uint32_t t = n->first;
            if (tested[t]) continue; /* bounded below its leaf already (from an earlier segment) or searched */
            const int regions = below && it.key > mm->t0;
            if (!below_add(&marked, ws, mm, t, regions)) { ok = 0; break; } /* recorded before marked: cleared at the end */
            if (!regions) { /* its sphere touches at the start (a resting contact): the triangle's turn */
                tested[t] = 0xffu;
                stats->candidates += 1;
                ok = visit(user, t, it.key, &te);
                continue;
            }
            tested[t] = 0x80u;
            /* the whole triangle is no tighter than its leaf's sphere, which has just stalled: its four halves start */
            for (uint32_t k = 0; k < 4 && ok; ++k) {
                item r = { it.key, it.node, s | SEG_REGION, (1u << 24) | k, (uint32_t)(marked.n - 1) };
                ok = item_heap_push(&heap, r);
            }
            continue;
        }
        /* the children are marched from the parent's candidate time: when the queue reaches them (ordered), or now */
        const int later = ordered && it.key > mm->t0;
        for (uint32_t k = 0; k < 2 && ok; ++k) {
            item c = { it.key, n->first + k, s | SEG_MARCHING, 0, 0 };
            if (later) { ok = item_heap_push(&heap, c); continue; }
            if (march(&tr, c.node, s, scc_fmin(seg[s].tb, te), INFINITY, MARCH_TOL, &c.key, &c.sub) != MARCH_STALLED) continue;
            c.seg = s;
            c.sub = 0;
            ok = item_heap_push(&heap, c);
        }
    }
    scc_ws_adopt(ws, SCC_WS_HEAP, heap.a, heap.cap * sizeof(item));
    for (size_t i = 0; i < marked.n; ++i) tested[marked.a[i].triangle] = 0;
    return ok;
}

/* The certificate of one node and, where it fails, of its children (scc_bsh_certify). */
enum { CERT_TIME_SPLITS = 2 };
typedef struct cert_ctx {
    const scc_bsh* bsh;
    const scc_mesh_motion* mm;
    const scc_sdf* sdf;
    const scc_params* dcd; /* the second stage's local search at leaves (NULL: none) */
    double level, lipschitz, lin, ang, tm; /* lin = |v| T, ang = |w| T, tm the middle of the interval */
    scc_quat q;
    scc_vec3 p;                            /* the pose at tm */
    uint8_t* clear;
    scc_workspace* ws;       /* vertex records for the leaves' DCD (NULL: none) */
    scc_vertex_trace* traces;
    int64_t evals, left;
} cert_ctx;

/* Second stage at a leaf over [ta, tb]: the triangle's deepest point at the middle time (DCD,
 * Section 3.2) less K times the farthest any of its points moves in half the interval (half_path);
 * where that fails with the deepest point still above the level, each half of the interval is
 * tried the same way (at most `splits` times deep). */
static int leaf_clear(cert_ctx* c, const scc_tri_motion* m, double ta, double tb, double half_path, int splits)
{
    scc_tri_state st;
    scc_tri_state_at(m, 0.5 * (ta + tb), &st);
    scc_dcd_result d = scc_dcd_traced(c->sdf, st.x, m->trace, st.t, c->dcd);
    c->evals += d.evals;
    if (d.phi - c->lipschitz * half_path > c->level) return 1;
    if (splits <= 0 || !(d.phi > c->level)) return 0;
    const double mid = 0.5 * (ta + tb);
    return leaf_clear(c, m, ta, mid, 0.5 * half_path, splits - 1) && leaf_clear(c, m, mid, tb, 0.5 * half_path, splits - 1);
}

static void certify_node(cert_ctx* c, uint32_t i)
{
    const scc_bsh_node* n = &c->bsh->nodes[i];
    const scc_mesh_motion* mm = c->mm;
    scc_vec3 x = scc_sdf_frame_point(mm->sdf, c->tm, scc_add(scc_quat_rotate(c->q, n->center), c->p));
    double half_path = 0.5 * (c->lin + c->ang * (scc_dist(n->center, mm->body->c_local) + n->radius));
    double low = scc_sdf_eval(c->sdf, x, NULL) - c->lipschitz * (n->radius + half_path);
    c->evals += 1;
    if (!(low > c->level) && n->is_leaf && c->dcd) {
        scc_tri_motion m;
        scc_mesh_triangle_motion(mm, n->first, &m);
        if (c->traces) scc_triangle_traces(c->traces, mm->mesh, n->first, c->ws->trace_epoch, m.trace);
        if (leaf_clear(c, &m, mm->t0, mm->t1, half_path, CERT_TIME_SPLITS)) low = INFINITY;
    }
    if (low > c->level) { /* NaN fails */
        c->clear[i] = 1;
        return;
    }
    c->clear[i] = 0;
    if (n->is_leaf) {
        c->left += 1;
        return;
    }
    certify_node(c, n->first);
    certify_node(c, n->first + 1);
}

int64_t scc_bsh_certify(const scc_bsh* bsh, const scc_mesh_motion* mm, const scc_sdf* sdf, double level, const scc_params* dcd,
                        uint8_t* clear, scc_workspace* ws, int64_t* io_evals)
{
    if (!bsh || !bsh->node_count || !mm->body) return -1;
    if (mm->sdf && (scc_len2(mm->sdf->v) > 0.0 || scc_len2(mm->sdf->w) > 0.0)) return -1; /* a moving SDF frame */
    cert_ctx c;
    c.bsh = bsh;
    c.mm = mm;
    c.sdf = sdf;
    c.dcd = dcd;
    c.level = level;
    c.lipschitz = region_lipschitz(bsh, NULL, mm, sdf, mm->t0, mm->t1);
    double T = fabs(mm->t1 - mm->t0);
    c.lin = scc_len(mm->body->v) * T;
    c.ang = scc_len(mm->body->w) * T;
    c.lin += 1e-12 * (1.0 + c.lin); /* rounding of the poses */
    c.tm = 0.5 * (mm->t0 + mm->t1);
    scc_rigid_pose_at(mm->body, c.tm, &c.q, &c.p);
    c.clear = clear;
    c.ws = ws;
    c.traces = ws && dcd && mm->mesh->vertex_count > 0 ? scc_mesh_traces(ws, mm->mesh) : NULL; /* (none: evaluated per leaf) */
    c.evals = 0;
    c.left = 0;
    certify_node(&c, 0);
    *io_evals += c.evals;
    return c.left;
}
