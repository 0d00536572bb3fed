/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: triangle mesh import through assimp's C API (triangulation, node transforms,
 * exact-position vertex welding), the mesh topology report and exact signed distance queries. */
#include "grid_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../core/mesh_distance.h"

#if SDFCCD_HAVE_ASSIMP
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#endif

#define LOAD_DEF_MAGIC 0x5DFCCD32

sdfccd_MeshLoadDef sdfccd_default_mesh_load_def(void)
{
    sdfccd_MeshLoadDef d;
    memset(&d, 0, sizeof d);
    d.scale = 1.0;
    d.merge_vertices = 1;
    d.drop_degenerate = 1;
    d.internal_value = LOAD_DEF_MAGIC;
    return d;
}


/* ---------------- welding and mesh creation shared by both readers ---------------- */

/* Open-addressing table keyed by the exact bits of a position (with -0 folded into +0). */
typedef struct weld_table {
    uint32_t* slots; /* vertex index + 1; 0 = empty */
    size_t cap;      /* power of two */
} weld_table;

static uint64_t hash_pos(const double* p)
{
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (int i = 0; i < 3; ++i) {
        double v = p[i] == 0.0 ? 0.0 : p[i];
        uint64_t b;
        memcpy(&b, &v, 8);
        h ^= b + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
    }
    return h ^ (h >> 31);
}

static int same_pos(const double* a, const double* b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

/* Welds `verts` in place (when merge is set), rewrites `idx`, and creates the mesh handle. */
static sdfccd_Status finish_mesh(double* verts, uint32_t nv, uint32_t* idx, uint32_t nt, const sdfccd_MeshLoadDef* d,
                                 const char* path, sdfccd_MeshId* out_mesh)
{
    if (nt == 0 || nv == 0) return sdfccd__error(SDFCCD_DEGENERATE, "sdfccd_load_mesh: '%s' contains no triangles", path);
    for (uint32_t i = 0; i < 3 * nv; ++i) verts[i] *= d->scale;
    uint32_t out_v = nv;
    if (d->merge_vertices) {
        weld_table wt = { NULL, 16 };
        while (wt.cap < 2 * (size_t)nv) wt.cap *= 2;
        wt.slots = sdfccd__calloc(wt.cap * sizeof(uint32_t));
        uint32_t* remap = sdfccd__alloc((size_t)nv * sizeof(uint32_t));
        if (!wt.slots || !remap) {
            sdfccd__free(wt.slots, wt.cap * sizeof(uint32_t));
            sdfccd__free(remap, (size_t)nv * sizeof(uint32_t));
            return sdfccd__oom("an imported mesh");
        }
        out_v = 0;
        for (uint32_t i = 0; i < nv; ++i) {
            const double* p = verts + 3 * (size_t)i;
            size_t slot = (size_t)hash_pos(p) & (wt.cap - 1);
            uint32_t id = UINT32_MAX;
            while (wt.slots[slot]) {
                const uint32_t c = wt.slots[slot] - 1;
                if (same_pos(verts + 3 * (size_t)c, p)) { id = c; break; }
                slot = (slot + 1) & (wt.cap - 1);
            }
            if (id == UINT32_MAX) {
                id = out_v++;
                memmove(verts + 3 * (size_t)id, p, 3 * sizeof(double));
                wt.slots[slot] = id + 1;
            }
            remap[i] = id;
        }
        for (size_t k = 0; k < 3 * (size_t)nt; ++k) idx[k] = remap[idx[k]];
        sdfccd__free(wt.slots, wt.cap * sizeof(uint32_t));
        sdfccd__free(remap, (size_t)nv * sizeof(uint32_t));
    }
    char what[300];
    snprintf(what, sizeof what, "sdfccd_load_mesh('%s')", path);
    return sdfccd__mesh_create(verts, out_v, idx, nt, d->drop_degenerate, what, out_mesh);
}

/* ---------------- Wavefront OBJ, read in double precision ----------------
 * Debian's assimp stores positions as 32-bit floats, which would round every coordinate of an
 * OBJ file written with more digits and break agreement with Discregrid (which parses doubles),
 * so OBJ files are read here: `v x y z` and `f` records (polygons fan-triangulated, `i/t/n`
 * forms, negative relative indices); every other record is ignored. */

typedef struct growbuf { void* p; size_t used, cap, elem; } growbuf;

static int grow_push(growbuf* b, const void* v)
{
    if (b->used == b->cap) {
        size_t nc = b->cap ? 2 * b->cap : 1024;
        void* np = sdfccd__alloc(nc * b->elem);
        if (!np) return 0;
        if (b->p) memcpy(np, b->p, b->used * b->elem);
        sdfccd__free(b->p, b->cap * b->elem);
        b->p = np;
        b->cap = nc;
    }
    memcpy((char*)b->p + b->used * b->elem, v, b->elem);
    b->used++;
    return 1;
}

static sdfccd_Status load_obj(const char* path, const sdfccd_MeshLoadDef* d, sdfccd_MeshId* out_mesh)
{
    FILE* f = fopen(path, "rb");
    if (!f) return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_mesh: cannot open '%s': %s", path, strerror(errno));
    growbuf v = { NULL, 0, 0, 3 * sizeof(double) }, t = { NULL, 0, 0, 3 * sizeof(uint32_t) };
    sdfccd_Status st = SDFCCD_OK;
    char line[4096];
    unsigned long lineno = 0;
    int bad_line = 0;
    while (fgets(line, sizeof line, f)) {
        ++lineno;
        size_t len = strlen(line);
        if (len == sizeof line - 1 && line[len - 1] != '\n' && !feof(f)) {
            st = sdfccd__error(SDFCCD_FORMAT_ERROR, "sdfccd_load_mesh: '%s' line %lu is longer than %zu characters", path, lineno, sizeof line - 2);
            break;
        }
        char* s = line;
        while (*s == ' ' || *s == '\t') ++s;
        if (s[0] == 'v' && (s[1] == ' ' || s[1] == '\t')) {
            double p[3];
            char* e = s + 1;
            for (int k = 0; k < 3; ++k) {
                char* next;
                p[k] = strtod(e, &next);
                if (next == e || !isfinite(p[k])) { bad_line = 1; break; }
                e = next;
            }
            if (bad_line) { st = sdfccd__error(SDFCCD_FORMAT_ERROR, "sdfccd_load_mesh: '%s' line %lu: bad vertex", path, lineno); break; }
            if (!grow_push(&v, p)) { st = sdfccd__oom("an imported mesh"); break; }
        } else if (s[0] == 'f' && (s[1] == ' ' || s[1] == '\t')) {
            uint32_t first = 0, prev = 0;
            int n = 0;
            char* e = s + 1;
            for (;;) {
                while (*e == ' ' || *e == '\t') ++e;
                if (*e == '\0' || *e == '\n' || *e == '\r' || *e == '#') break;
                char* next;
                long long k = strtoll(e, &next, 10);
                if (next == e) { bad_line = 1; break; }
                while (*next && *next != ' ' && *next != '\t' && *next != '\n' && *next != '\r') ++next; /* skip /t/n */
                e = next;
                long long vi = k > 0 ? k - 1 : (long long)v.used + k;
                if (k == 0 || vi < 0 || vi >= (long long)v.used) { bad_line = 1; break; }
                const uint32_t id = (uint32_t)vi;
                if (n == 0) first = id;
                else if (n >= 2) {
                    const uint32_t tri[3] = { first, prev, id };
                    if (!grow_push(&t, tri)) { st = sdfccd__oom("an imported mesh"); break; }
                }
                prev = id;
                ++n;
            }
            if (st) break;
            if (bad_line) { st = sdfccd__error(SDFCCD_FORMAT_ERROR, "sdfccd_load_mesh: '%s' line %lu: bad face (index out of range or malformed)", path, lineno); break; }
        }
    }
    if (!st && ferror(f)) st = sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_mesh: cannot read '%s'", path);
    fclose(f);
    if (!st && (v.used > (1u << 30) || t.used > (1u << 30)))
        st = sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_load_mesh: '%s' is too large", path);
    if (!st) st = finish_mesh(v.p, (uint32_t)v.used, t.p, (uint32_t)t.used, d, path, out_mesh);
    sdfccd__free(v.p, v.cap * v.elem);
    sdfccd__free(t.p, t.cap * t.elem);
    return st;
}

static int has_obj_extension(const char* path)
{
    size_t n = strlen(path);
    if (n < 4) return 0;
    const char* e = path + n - 4;
    return e[0] == '.' && (e[1] == 'o' || e[1] == 'O') && (e[2] == 'b' || e[2] == 'B') && (e[3] == 'j' || e[3] == 'J');
}

sdfccd_Status sdfccd_load_mesh(const char* path, const sdfccd_MeshLoadDef* def, sdfccd_MeshId* out_mesh)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(path, "sdfccd_load_mesh: path")) || (st = sdfccd__check_ptr(out_mesh, "sdfccd_load_mesh: out_mesh"))) return st;
    sdfccd_MeshLoadDef d = def ? *def : sdfccd_default_mesh_load_def();
    if (d.internal_value != LOAD_DEF_MAGIC)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_load_mesh: def was not initialised with sdfccd_default_mesh_load_def()");
    if (!isfinite(d.scale) || d.scale == 0.0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_load_mesh: scale = %g must be finite and non-zero", d.scale);
    if (has_obj_extension(path)) return load_obj(path, &d, out_mesh);
#if !SDFCCD_HAVE_ASSIMP
    return sdfccd__error(SDFCCD_UNSUPPORTED, "sdfccd_load_mesh: this build has no assimp (configure with SDFCCD_WITH_ASSIMP=ON); only .obj files load");
#else
    FILE* probe = fopen(path, "rb");
    if (!probe) return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_mesh: cannot open '%s': %s", path, strerror(errno));
    fclose(probe);

    const struct aiScene* scene = aiImportFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices);
    if (!scene) return sdfccd__error(SDFCCD_FORMAT_ERROR, "sdfccd_load_mesh: assimp cannot read '%s': %s", path, aiGetErrorString());
    uint64_t nv = 0, nt = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const struct aiMesh* mesh = scene->mMeshes[m];
        nv += mesh->mNumVertices;
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) nt += mesh->mFaces[f].mNumIndices == 3;
    }
    if (nt == 0 || nv == 0) {
        aiReleaseImport(scene);
        return sdfccd__error(SDFCCD_DEGENERATE, "sdfccd_load_mesh: '%s' contains no triangles", path);
    }
    if (nv > (1u << 30) || nt > (1u << 30)) {
        aiReleaseImport(scene);
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_load_mesh: '%s' is too large", path);
    }
    const size_t vbytes = (size_t)nv * 3 * sizeof(double), ibytes = (size_t)nt * 3 * sizeof(uint32_t);
    double* verts = sdfccd__alloc(vbytes);
    uint32_t* idx = sdfccd__alloc(ibytes);
    if (!verts || !idx) {
        sdfccd__free(verts, vbytes);
        sdfccd__free(idx, ibytes);
        aiReleaseImport(scene);
        return sdfccd__oom("an imported mesh");
    }
    uint32_t out_t = 0, base = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const struct aiMesh* mesh = scene->mMeshes[m];
        for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
            verts[3 * ((size_t)base + i)] = mesh->mVertices[i].x;
            verts[3 * ((size_t)base + i) + 1] = mesh->mVertices[i].y;
            verts[3 * ((size_t)base + i) + 2] = mesh->mVertices[i].z;
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const struct aiFace* face = &mesh->mFaces[f];
            if (face->mNumIndices != 3) continue;
            if (face->mIndices[0] >= mesh->mNumVertices || face->mIndices[1] >= mesh->mNumVertices || face->mIndices[2] >= mesh->mNumVertices) continue;
            for (int k = 0; k < 3; ++k) idx[3 * (size_t)out_t + k] = base + face->mIndices[k];
            ++out_t;
        }
        base += mesh->mNumVertices;
    }
    aiReleaseImport(scene);
    st = finish_mesh(verts, (uint32_t)nv, idx, out_t, &d, path, out_mesh);
    sdfccd__free(verts, vbytes);
    sdfccd__free(idx, ibytes);
    return st;
#endif
}

/* ---------------- topology and distance ---------------- */

sdfccd_Status sdfccd_mesh_get_topology(sdfccd_MeshId mesh, sdfccd_MeshTopology* out_topology)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(out_topology, "sdfccd_mesh_get_topology: out_topology"))) return st;
    sdfccd__mesh* m = sdfccd__mesh_lookup(mesh);
    if (!m) return SDFCCD_INVALID_HANDLE;
    scc_mesh_topology t;
    if (scc_mesh_topology_check(sdfccd__allocator(), &m->mesh, &t) != 0) return sdfccd__oom("a topology check");
    out_topology->boundary_edges = t.boundary_edges;
    out_topology->nonmanifold_edges = t.nonmanifold_edges;
    out_topology->inconsistent_edges = t.inconsistent_edges;
    out_topology->volume = t.volume;
    out_topology->closed = t.closed;
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_mesh_signed_distance(sdfccd_MeshId mesh, const sdfccd_Vec3* points, int32_t count, int32_t allow_open,
                                          double* out_distances, sdfccd_Vec3* out_closest)
{
    sdfccd_Status st;
    if (count < 0) return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_mesh_signed_distance: count = %d < 0", count);
    if (count > 0 && ((st = sdfccd__check_ptr(points, "sdfccd_mesh_signed_distance: points")) ||
                      (st = sdfccd__check_ptr(out_distances, "sdfccd_mesh_signed_distance: out_distances"))))
        return st;
    for (int32_t i = 0; i < count; ++i)
        if ((st = sdfccd__check_vec(points[i], "sdfccd_mesh_signed_distance: a point"))) return st;
    sdfccd__mesh* m = sdfccd__mesh_lookup(mesh);
    if (!m) return SDFCCD_INVALID_HANDLE;
    scc_mesh_sdf ms;
    if (scc_mesh_sdf_init(&ms, sdfccd__allocator(), &m->mesh) != 0) return sdfccd__oom("a mesh distance structure");
    if (!allow_open && (st = sdfccd__mesh_topology_message(&ms.topology, "sdfccd_mesh_signed_distance"))) {
        scc_mesh_sdf_destroy(&ms);
        return st;
    }
    uint32_t hint = UINT32_MAX;
    for (int32_t i = 0; i < count; ++i) {
        scc_mesh_distance_result r;
        scc_mesh_sdf_query_hint(&ms, sdfccd__v(points[i]), &hint, &r);
        out_distances[i] = r.distance;
        if (out_closest) out_closest[i] = sdfccd__pv(r.closest);
    }
    scc_mesh_sdf_destroy(&ms);
    return SDFCCD_OK;
}
