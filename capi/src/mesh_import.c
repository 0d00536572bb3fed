/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: sdfccd_load_mesh, triangle mesh import from files: `.obj` through our own reader
 * in double precision (obj_reader.c), every other format through assimp's C API (triangulation,
 * node transforms; float positions), then exact-position vertex welding shared by both. */
#include "mesh_import.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <sys/stat.h>
#include <stdlib.h>
#include <string.h>

#if SDFCCD_HAVE_ASSIMP
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#endif

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

sdfccd_Status sdfccd__finish_imported_mesh(double* verts, uint32_t nv, uint32_t* idx, uint32_t nt, const sdfccd_MeshLoadDef* d,
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

static int has_obj_extension(const char* path)
{
    size_t n = strlen(path);
    if (n < 4) return 0;
    const char* e = path + n - 4;
    return e[0] == '.' && (e[1] == 'o' || e[1] == 'O') && (e[2] == 'b' || e[2] == 'B') && (e[3] == 'j' || e[3] == 'J');
}

/* 1 when the extension of `path` (after the last '.') is one of the ';'-separated `formats`. */
static int format_allowed(const char* path, const char* formats)
{
    if (!formats) return 1;
    const char* dot = strrchr(path, '.');
    const char* slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash)) return 0;
    const char* ext = dot + 1;
    const size_t n = strlen(ext);
    for (const char* s = formats; *s;) {
        const char* e = strchr(s, ';');
        const size_t len = e ? (size_t)(e - s) : strlen(s);
        if (len == n && n > 0) {
            size_t i = 0;
            while (i < n && tolower((unsigned char)s[i]) == tolower((unsigned char)ext[i])) ++i;
            if (i == n) return 1;
        }
        if (!e) break;
        s = e + 1;
    }
    return 0;
}

/* A regular file of at most max_bytes (a directory or a device could hang or mislead a reader). */
static sdfccd_Status check_file(const char* path, int64_t max_bytes)
{
    struct stat sb;
    if (stat(path, &sb) != 0) return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_mesh: cannot open '%s': %s", path, strerror(errno));
    if (!S_ISREG(sb.st_mode)) return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_mesh: '%s' is not a regular file", path);
    if ((int64_t)sb.st_size > max_bytes)
        return sdfccd__error(SDFCCD_UNSUPPORTED, "sdfccd_load_mesh: '%s' has %lld bytes, above max_file_bytes (%lld)", path,
                             (long long)sb.st_size, (long long)max_bytes);
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_load_mesh(const char* path, const sdfccd_MeshLoadDef* def, sdfccd_MeshId* out_mesh)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(path, "sdfccd_load_mesh: path")) || (st = sdfccd__check_ptr(out_mesh, "sdfccd_load_mesh: out_mesh"))) return st;
    sdfccd_MeshLoadDef d = def ? *def : sdfccd_default_mesh_load_def();
    if ((st = sdfccd__check_def(d.internal_value, "sdfccd_load_mesh", "def was", "sdfccd_default_mesh_load_def"))) return st;
    if (!isfinite(d.scale) || d.scale == 0.0)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_load_mesh: scale = %g must be finite and non-zero", d.scale);
    if (d.max_file_bytes < 1)
        return sdfccd__error(SDFCCD_INVALID_ARGUMENT, "sdfccd_load_mesh: max_file_bytes = %lld must be >= 1", (long long)d.max_file_bytes);
    if (!format_allowed(path, d.formats))
        return sdfccd__error(SDFCCD_UNSUPPORTED, "sdfccd_load_mesh: the format of '%s' is not among the accepted formats \"%s\"", path, d.formats);
    if ((st = check_file(path, d.max_file_bytes))) return st;
    if (has_obj_extension(path)) return sdfccd__load_obj(path, &d, out_mesh);
#if !SDFCCD_HAVE_ASSIMP
    return sdfccd__error(SDFCCD_UNSUPPORTED, "sdfccd_load_mesh: this build has no assimp (configure with SDFCCD_WITH_ASSIMP=ON); only .obj files load");
#else
    FILE* probe = fopen(path, "rb");
    if (!probe) return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_mesh: cannot open '%s': %s", path, strerror(errno));
    fclose(probe);

    /* Validation first: assimp checks counts and indices before its other steps, whose asserts
     * abort the process on inconsistent data. */
    const struct aiScene* scene = aiImportFile(path, aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_PreTransformVertices);
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
    st = sdfccd__finish_imported_mesh(verts, (uint32_t)nv, idx, out_t, &d, path, out_mesh);
    sdfccd__free(verts, vbytes);
    sdfccd__free(idx, ibytes);
    return st;
#endif
}
