/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: the Wavefront OBJ reader of sdfccd_load_mesh, in double precision.
 * Debian's assimp stores positions as 32-bit floats, which would round every coordinate of an
 * OBJ file written with more digits and break agreement with Discregrid (which parses doubles),
 * so OBJ files are read here: `v x y z` and `f` records (polygons fan-triangulated, `i/t/n`
 * forms, negative relative indices); every other record is ignored. Numbers are parsed with
 * strtod (the C locale's '.' decimal point). */
#include "mesh_import.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A growable array of `elem`-byte records (core/alloc.h's scc_array_reserve, counted allocator). */
typedef struct growbuf { void* p; size_t used, cap, elem; } growbuf;

static int grow_push(growbuf* b, const void* v)
{
    if (!scc_array_reserve(sdfccd__allocator(), &b->p, &b->cap, b->elem, b->used + 1, 1024)) return 0;
    memcpy((char*)b->p + b->used * b->elem, v, b->elem);
    b->used++;
    return 1;
}

sdfccd_Status sdfccd__load_obj(const char* path, const sdfccd_MeshLoadDef* d, sdfccd_MeshId* out_mesh)
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
    if (!st) st = sdfccd__finish_imported_mesh(v.p, (uint32_t)v.used, t.p, (uint32_t)t.used, d, path, out_mesh);
    sdfccd__free(v.p, v.cap * v.elem);
    sdfccd__free(t.p, t.cap * t.elem);
    return st;
}
