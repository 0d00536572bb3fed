/* SPDX-License-Identifier: MIT
 * sdfccd core: isosurface extraction by marching tetrahedra over a padded regular grid.
 * See marching_tetrahedra.h for the method and its guarantees. Used by the Bullet bridge (a cached
 * triangulation for Bullet's triangle paths) and by benchmarks (an SDF's surface as a mesh). */
#include "marching_tetrahedra.h"

#include <float.h>
#include <string.h>

/* ---- edge -> vertex map (open addressing; key 0 means empty) ---- */

typedef struct edge_map {
    uint64_t* keys;
    uint32_t* values;
    size_t cap;   /* power of two */
    size_t count;
} edge_map;

static uint64_t hash64(uint64_t x)
{
    x ^= x >> 33; x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33; x *= 0xc4ceb9fe1a85ec53ULL;
    x ^= x >> 33;
    return x;
}

static void edge_map_free(edge_map* m, const scc_allocator* a)
{
    scc_free(a, m->keys, m->cap * sizeof(uint64_t));
    scc_free(a, m->values, m->cap * sizeof(uint32_t));
    memset(m, 0, sizeof *m);
}

static int edge_map_init(edge_map* m, const scc_allocator* a, size_t cap)
{
    memset(m, 0, sizeof *m);
    m->keys = (uint64_t*)scc_alloc(a, cap * sizeof(uint64_t));
    m->values = (uint32_t*)scc_alloc(a, cap * sizeof(uint32_t));
    m->cap = cap;
    if (!m->keys || !m->values) { edge_map_free(m, a); return 0; }
    memset(m->keys, 0, cap * sizeof(uint64_t));
    return 1;
}

/* Returns the slot of `key` (stored as key + 1), which is empty when the key is absent. */
static size_t edge_map_slot(const edge_map* m, uint64_t key)
{
    size_t mask = m->cap - 1, i = (size_t)hash64(key) & mask;
    while (m->keys[i] != 0 && m->keys[i] != key + 1) i = (i + 1) & mask;
    return i;
}

static int edge_map_rehash(edge_map* m, const scc_allocator* a)
{
    edge_map n;
    if (m->cap > SIZE_MAX / 4 / sizeof(uint64_t)) return 0;
    if (!edge_map_init(&n, a, m->cap * 2)) return 0;
    for (size_t i = 0; i < m->cap; ++i) {
        if (!m->keys[i]) continue;
        size_t s = edge_map_slot(&n, m->keys[i] - 1);
        n.keys[s] = m->keys[i];
        n.values[s] = m->values[i];
    }
    n.count = m->count;
    edge_map_free(m, a);
    *m = n;
    return 1;
}

/* ---- the extractor ---- */

typedef struct mc_ctx {
    const scc_sdf* sdf;
    const scc_allocator* a;
    double iso;
    scc_vec3 lo, h;        /* grid origin (real node 0,0,0) and cell size per axis */
    int64_t n[3];          /* cells per axis */
    int64_t e[3];          /* extended nodes per axis: n + 3 (one virtual layer each side) */
    double* values;        /* extended node values */
    size_t values_count;
    edge_map map;
    scc_isosurface* out;
    scc_mt_status fail;
} mc_ctx;

static int64_t node_id(const mc_ctx* c, int64_t i, int64_t j, int64_t k)
{
    return (i + 1) + c->e[0] * ((j + 1) + c->e[1] * (k + 1));
}

static int is_virtual(const mc_ctx* c, int64_t i, int64_t j, int64_t k)
{
    return i < 0 || j < 0 || k < 0 || i > c->n[0] || j > c->n[1] || k > c->n[2];
}

static scc_vec3 node_pos(const mc_ctx* c, int64_t i, int64_t j, int64_t k)
{
    return scc_v3(c->lo.x + (double)i * c->h.x, c->lo.y + (double)j * c->h.y, c->lo.z + (double)k * c->h.z);
}

/* A tetrahedron corner: grid coordinates, position, value. */
typedef struct mc_corner {
    int64_t i, j, k;
    int bits;          /* corner of the cube: x = 1, y = 2, z = 4 */
    scc_vec3 p;
    double v;
    int real;
} mc_corner;

/* Point where phi = iso on the edge a-b (values straddle iso). Safeguarded regula falsi (Illinois)
 * on the true field when both ends are real nodes, linear interpolation otherwise. */
static scc_vec3 edge_point(const mc_ctx* c, const mc_corner* a, const mc_corner* b)
{
    double fa = a->v - c->iso, fb = b->v - c->iso;
    double ta = 0.0, tb = 1.0;
    double t = fa / (fa - fb);
    if (a->real && b->real) {
        double tol = 1e-9 * scc_maxc(c->h);
        int side = 0;
        for (int it = 0; it < 24; ++it) {
            t = (ta * fb - tb * fa) / (fb - fa);
            if (!(t > ta && t < tb)) t = 0.5 * (ta + tb);
            double f = scc_sdf_eval(c->sdf, scc_lerp(a->p, b->p, t), NULL) - c->iso;
            if (!isfinite(f)) break;
            if (fabs(f) <= tol) break;
            if ((f < 0.0) == (fa < 0.0)) {
                ta = t; fa = f;
                if (side == -1) fb *= 0.5;
                side = -1;
            } else {
                tb = t; fb = f;
                if (side == 1) fa *= 0.5;
                side = 1;
            }
            if ((tb - ta) * scc_dist(a->p, b->p) <= tol) break;
        }
    }
    t = scc_clamp(t, 1e-3, 1.0 - 1e-3);
    return scc_lerp(a->p, b->p, t);
}

/* Vertex index of the crossing on edge a-b (created once per grid edge). UINT32_MAX on failure. */
static uint32_t edge_vertex(mc_ctx* c, const mc_corner* a, const mc_corner* b)
{
    /* In the Kuhn split the corners of one tetrahedron are nested: the edge goes from the
     * corner whose bits are a subset of the other's, along the 0/1 direction (bits xor). */
    const mc_corner* lo = a;
    const mc_corner* hi = b;
    if ((a->bits & b->bits) != a->bits) { lo = b; hi = a; }
    int dir = lo->bits ^ hi->bits; /* 1..7 */
    uint64_t key = (uint64_t)node_id(c, lo->i, lo->j, lo->k) * 7u + (uint64_t)(dir - 1);
    if ((c->map.count + 1) * 2 > c->map.cap && !edge_map_rehash(&c->map, c->a)) {
        c->fail = SCC_MT_OUT_OF_MEMORY;
        return UINT32_MAX;
    }
    size_t s = edge_map_slot(&c->map, key);
    if (c->map.keys[s]) return c->map.values[s];
    scc_isosurface* o = c->out;
    if (o->vertex_count == UINT32_MAX - 1) { c->fail = SCC_MT_TOO_LARGE; return UINT32_MAX; }
    if (!scc_array_reserve(c->a, (void**)&o->vertices, &o->vertex_capacity, sizeof(scc_vec3), (size_t)o->vertex_count + 1, 256)) {
        c->fail = SCC_MT_OUT_OF_MEMORY;
        return UINT32_MAX;
    }
    o->vertices[o->vertex_count] = edge_point(c, lo, hi);
    c->map.keys[s] = key + 1;
    c->map.values[s] = o->vertex_count;
    c->map.count++;
    return o->vertex_count++;
}

/* Appends triangle (a, b, c), flipped if needed so its normal points along `outward`. */
static void emit(mc_ctx* c, uint32_t a, uint32_t b, uint32_t d, scc_vec3 outward)
{
    if (c->fail) return;
    scc_isosurface* o = c->out;
    if (o->triangle_count == UINT32_MAX / 3) { c->fail = SCC_MT_TOO_LARGE; return; }
    if (!scc_array_reserve(c->a, (void**)&o->indices, &o->index_capacity, sizeof(uint32_t), 3 * ((size_t)o->triangle_count + 1), 256)) {
        c->fail = SCC_MT_OUT_OF_MEMORY;
        return;
    }
    scc_vec3 pa = o->vertices[a], pb = o->vertices[b], pd = o->vertices[d];
    scc_vec3 n = scc_cross(scc_sub(pb, pa), scc_sub(pd, pa));
    uint32_t* f = o->indices + 3 * (size_t)o->triangle_count;
    f[0] = a;
    if (scc_dot(n, outward) >= 0.0) { f[1] = b; f[2] = d; }
    else { f[1] = d; f[2] = b; }
    o->triangle_count++;
}

static void polygonise_tet(mc_ctx* c, const mc_corner* t[4])
{
    int in[4], nin = 0, out[4], nout = 0;
    for (int q = 0; q < 4; ++q) {
        if (t[q]->v < c->iso) in[nin++] = q;
        else out[nout++] = q;
    }
    if (nin == 0 || nout == 0) return;
    scc_vec3 cin = scc_v3(0, 0, 0), cout = scc_v3(0, 0, 0);
    for (int q = 0; q < nin; ++q) cin = scc_add(cin, t[in[q]]->p);
    for (int q = 0; q < nout; ++q) cout = scc_add(cout, t[out[q]]->p);
    scc_vec3 outward = scc_sub(scc_scale(cout, 1.0 / nout), scc_scale(cin, 1.0 / nin));
    if (nin == 1 || nout == 1) {
        /* One corner separated from the other three: one triangle. */
        int lone = nin == 1 ? in[0] : out[0];
        const int* others = nin == 1 ? out : in;
        uint32_t v[3];
        for (int q = 0; q < 3; ++q) {
            v[q] = edge_vertex(c, t[lone], t[others[q]]);
            if (v[q] == UINT32_MAX) return;
        }
        emit(c, v[0], v[1], v[2], outward);
    } else {
        /* Two and two: the crossings a-c, a-d, b-d, b-c form a quad, in this cyclic order. */
        const mc_corner *A = t[in[0]], *B = t[in[1]], *C = t[out[0]], *D = t[out[1]];
        uint32_t ac = edge_vertex(c, A, C), ad = edge_vertex(c, A, D);
        uint32_t bd = edge_vertex(c, B, D), bc = edge_vertex(c, B, C);
        if (c->fail) return;
        emit(c, ac, ad, bd, outward);
        emit(c, ac, bd, bc, outward);
    }
}

void scc_isosurface_free(scc_isosurface* s, const scc_allocator* alloc)
{
    if (!s) return;
    scc_free(alloc, s->vertices, s->vertex_capacity * sizeof(scc_vec3));
    scc_free(alloc, s->indices, s->index_capacity * sizeof(uint32_t));
    memset(s, 0, sizeof *s);
}

scc_mt_status scc_marching_tetrahedra(const scc_sdf* sdf, scc_aabb box, int resolution, double iso,
                                       const scc_allocator* alloc, scc_isosurface* out)
{
    if (!out) return SCC_MT_BAD_INPUT;
    memset(out, 0, sizeof *out);
    if (!sdf || !alloc || resolution < 1 || resolution > SCC_MT_MAX_RESOLUTION || !isfinite(iso))
        return SCC_MT_BAD_INPUT;
    if (!scc_vfinite(box.lo) || !scc_vfinite(box.hi)) return SCC_MT_BAD_INPUT;
    scc_vec3 ext = scc_sub(box.hi, box.lo);
    if (!(ext.x > 0.0 && ext.y > 0.0 && ext.z > 0.0)) return SCC_MT_BAD_INPUT;

    mc_ctx c;
    memset(&c, 0, sizeof c);
    c.sdf = sdf;
    c.a = alloc;
    c.iso = iso;
    c.lo = box.lo;
    c.out = out;
    double cell = scc_maxc(ext) / resolution;
    double e3[3] = { ext.x, ext.y, ext.z };
    double h3[3];
    for (int ax = 0; ax < 3; ++ax) {
        double cells = ceil(e3[ax] / cell - 1e-9);
        c.n[ax] = cells < 1.0 ? 1 : (int64_t)cells;
        h3[ax] = e3[ax] / (double)c.n[ax];
        c.e[ax] = c.n[ax] + 3;
    }
    c.h = scc_v3(h3[0], h3[1], h3[2]);
    c.values_count = (size_t)(c.e[0] * c.e[1] * c.e[2]);
    if (c.values_count > SIZE_MAX / sizeof(double)) return SCC_MT_OUT_OF_MEMORY;
    c.values = (double*)scc_alloc(alloc, c.values_count * sizeof(double));
    if (!c.values) return SCC_MT_OUT_OF_MEMORY;
    if (!edge_map_init(&c.map, alloc, 1024)) {
        scc_free(alloc, c.values, c.values_count * sizeof(double));
        return SCC_MT_OUT_OF_MEMORY;
    }

    /* Sample: virtual nodes (and non-finite samples) count as outside, one cell above iso. */
    double outside = iso + scc_maxc(c.h);
    for (int64_t k = -1; k <= c.n[2] + 1; ++k)
        for (int64_t j = -1; j <= c.n[1] + 1; ++j)
            for (int64_t i = -1; i <= c.n[0] + 1; ++i) {
                double v = outside;
                if (!is_virtual(&c, i, j, k)) {
                    v = scc_sdf_eval(sdf, node_pos(&c, i, j, k), NULL);
                    if (!isfinite(v)) v = outside;
                }
                c.values[node_id(&c, i, j, k)] = v;
            }

    /* The six Kuhn tetrahedra: corner 0, then one axis, then two, then corner 7. */
    static const int perms[6][3] = { { 1, 2, 4 }, { 1, 4, 2 }, { 2, 1, 4 }, { 2, 4, 1 }, { 4, 1, 2 }, { 4, 2, 1 } };
    for (int64_t k = -1; k <= c.n[2] && !c.fail; ++k)
        for (int64_t j = -1; j <= c.n[1] && !c.fail; ++j)
            for (int64_t i = -1; i <= c.n[0] && !c.fail; ++i) {
                mc_corner corner[8];
                int any_in = 0, any_out = 0;
                for (int b = 0; b < 8; ++b) {
                    mc_corner* q = &corner[b];
                    q->i = i + (b & 1);
                    q->j = j + ((b >> 1) & 1);
                    q->k = k + ((b >> 2) & 1);
                    q->bits = b;
                    q->p = node_pos(&c, q->i, q->j, q->k);
                    q->v = c.values[node_id(&c, q->i, q->j, q->k)];
                    q->real = !is_virtual(&c, q->i, q->j, q->k);
                    if (q->v < iso) any_in = 1; else any_out = 1;
                }
                if (!(any_in && any_out)) continue;
                for (int t = 0; t < 6 && !c.fail; ++t) {
                    const mc_corner* tet[4] = { &corner[0], &corner[perms[t][0]],
                                                &corner[perms[t][0] | perms[t][1]], &corner[7] };
                    polygonise_tet(&c, tet);
                }
            }

    edge_map_free(&c.map, alloc);
    scc_free(alloc, c.values, c.values_count * sizeof(double));
    if (c.fail) {
        scc_isosurface_free(out, alloc);
        return c.fail;
    }
    return SCC_MT_OK;
}
