/* SPDX-License-Identifier: MIT
 * sdfccd C ABI: reading and writing Discregrid .cdf/.cdm files (the raw layout of
 * CubicLagrangeDiscreteGrid::save, which Bullet's btMiniSDF::load also reads; shared notes
 * sdf-format-and-assets.md section 1). The reader validates every count against the bytes
 * left before allocating or reading, and every node id and cell-map entry against its array,
 * so a corrupt file gives a status and never an out-of-bounds access. */
#include "grid_internal.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static int host_is_little_endian(void)
{
    const uint32_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

/* ---------------- reading ---------------- */

typedef struct reader {
    const unsigned char* data;
    size_t size, pos;
} reader;

static sdfccd_Status fmt(const reader* r, const char* what)
{
    return sdfccd__error(SDFCCD_FORMAT_ERROR, "sdfccd_load_grid: %s (at byte %zu of %zu)", what, r->pos, r->size);
}

static int rd(reader* r, void* out, size_t n)
{
    if (r->size - r->pos < n) return 0;
    if (n) memcpy(out, r->data + r->pos, n); /* out is NULL for an empty array */
    r->pos += n;
    return 1;
}

static sdfccd_Status parse(const unsigned char* data, size_t size, sdfccd_SdfId* out_grid)
{
    reader r = { data, size, 0 };
    double dom[6], h[3], ih[3];
    uint32_t res[3];
    uint64_t n_cells, n_fields, outer;
    if (!rd(&r, dom, sizeof dom) || !rd(&r, res, sizeof res) || !rd(&r, h, sizeof h) || !rd(&r, ih, sizeof ih) ||
        !rd(&r, &n_cells, 8) || !rd(&r, &n_fields, 8))
        return fmt(&r, "file too short for the header");
    for (int i = 0; i < 3; ++i) {
        if (!isfinite(dom[i]) || !isfinite(dom[3 + i]) || !(dom[i] < dom[3 + i])) { r.pos = 0; return fmt(&r, "domain is not finite or min >= max"); }
        /* Beyond these, distances between domain points overflow (a domain of +-1e308 loaded and
         * every evaluation was NaN) or gradients (value / cell size) do. */
        if (fabs(dom[i]) > SCC_GRID_MAX_COORDINATE || fabs(dom[3 + i]) > SCC_GRID_MAX_COORDINATE) { r.pos = 0; return fmt(&r, "domain coordinate above 1e100 in magnitude"); }
        if (res[i] == 0) { r.pos = 48; return fmt(&r, "a resolution is 0"); }
        const double ext = dom[3 + i] - dom[i];
        if (!(ext / res[i] >= SCC_GRID_MIN_CELL)) { r.pos = 48; return fmt(&r, "cell size below 1e-50"); }
        if (!isfinite(h[i]) || !(h[i] > 0.0) || fabs(h[i] * res[i] - ext) > 1e-9 * ext) { r.pos = 60; return fmt(&r, "cell size does not match domain / resolution"); }
        if (!isfinite(ih[i]) || fabs(h[i] * ih[i] - 1.0) > 1e-9) { r.pos = 84; return fmt(&r, "inverse cell size does not match the cell size"); }
    }
    const uint64_t full = (uint64_t)res[0] * res[1] * res[2];
    if (n_cells != full) { r.pos = 108; return fmt(&r, "cell count differs from the product of the resolution"); }
    if (n_cells > 0x7FFFFFFEull) { r.pos = 108; return fmt(&r, "more than 2^31 - 2 cells"); }
    if (n_fields == 0 || n_fields > 1024) { r.pos = 116; return fmt(&r, "field count is 0 or implausibly large"); }
    /* The smallest possible file for these counts: each field needs 3 counts and its map. */
    if ((size - r.pos) / (24 + 4 * (n_cells ? n_cells : 1)) < n_fields) return fmt(&r, "file too short for the field count and cell maps");

    const scc_vec3 lo = scc_v3(dom[0], dom[1], dom[2]), hi = scc_v3(dom[3], dom[4], dom[5]);
    scc_grid* g = scc_grid_create_raw(sdfccd__allocator(), lo, hi, res, scc_v3(h[0], h[1], h[2]), scc_v3(ih[0], ih[1], ih[2]), (uint32_t)n_fields);
    if (!g) return sdfccd__oom("a grid");
    const scc_allocator* a = sdfccd__allocator();
    sdfccd_Status st = SDFCCD_OK;

    /* node arrays */
    if (!rd(&r, &outer, 8)) { st = fmt(&r, "file ends before the node arrays"); goto fail; }
    if (outer != n_fields) { st = fmt(&r, "number of node arrays differs from the field count"); goto fail; }
    for (uint64_t f = 0; f < n_fields; ++f) {
        uint64_t count;
        if (!rd(&r, &count, 8)) { st = fmt(&r, "file ends in a node array count"); goto fail; }
        if (count > (size - r.pos) / 8) { st = fmt(&r, "node array larger than the rest of the file"); goto fail; }
        if (count > 0xFFFFFFFFull) { st = fmt(&r, "node array count beyond 32-bit ids"); goto fail; }
        scc_grid_field* fd = &g->fields[f];
        if (count) {
            fd->nodes = scc_alloc(a, (size_t)count * 8);
            if (!fd->nodes) { st = sdfccd__oom("grid nodes"); goto fail; }
        }
        fd->node_count = count;
        const size_t at = r.pos;
        rd(&r, fd->nodes, (size_t)count * 8);
        for (uint64_t i = 0; i < count; ++i)
            if (!(fabs(fd->nodes[i]) <= SCC_GRID_MAX_COORDINATE) && fd->nodes[i] != SCC_GRID_NO_VALUE) {
                r.pos = at + 8 * i;
                st = fmt(&r, "node value is NaN, infinite or above 1e100 in magnitude (other than the not-sampled marker)");
                goto fail;
            }
    }
    /* cell arrays */
    if (!rd(&r, &outer, 8)) { st = fmt(&r, "file ends before the cell arrays"); goto fail; }
    if (outer != n_fields) { st = fmt(&r, "number of cell arrays differs from the field count"); goto fail; }
    for (uint64_t f = 0; f < n_fields; ++f) {
        uint64_t count;
        if (!rd(&r, &count, 8)) { st = fmt(&r, "file ends in a cell array count"); goto fail; }
        if (count > (size - r.pos) / 128) { st = fmt(&r, "cell array larger than the rest of the file"); goto fail; }
        if (count > n_cells) { st = fmt(&r, "more stored cells than grid cells"); goto fail; }
        scc_grid_field* fd = &g->fields[f];
        if (count) {
            fd->cells = scc_alloc(a, (size_t)count * 128);
            if (!fd->cells) { st = sdfccd__oom("grid cells"); goto fail; }
        }
        fd->cell_count = count;
        const size_t at = r.pos;
        rd(&r, fd->cells, (size_t)count * 128);
        for (uint64_t i = 0; i < count * 32; ++i)
            if (fd->cells[i] >= fd->node_count) { r.pos = at + 4 * i; st = fmt(&r, "cell references a node id out of range"); goto fail; }
    }
    /* cell maps */
    if (!rd(&r, &outer, 8)) { st = fmt(&r, "file ends before the cell maps"); goto fail; }
    if (outer != n_fields) { st = fmt(&r, "number of cell maps differs from the field count"); goto fail; }
    for (uint64_t f = 0; f < n_fields; ++f) {
        uint64_t count;
        if (!rd(&r, &count, 8)) { st = fmt(&r, "file ends in a cell map count"); goto fail; }
        if (count != n_cells) { st = fmt(&r, "cell map length differs from the cell count"); goto fail; }
        if (count > (size - r.pos) / 4) { st = fmt(&r, "cell map larger than the rest of the file"); goto fail; }
        scc_grid_field* fd = &g->fields[f];
        fd->map = scc_alloc(a, (size_t)count * 4);
        if (!fd->map) { st = sdfccd__oom("grid cell map"); goto fail; }
        const size_t at = r.pos;
        rd(&r, fd->map, (size_t)count * 4);
        for (uint64_t i = 0; i < count; ++i)
            if (fd->map[i] != SCC_GRID_NO_CELL && fd->map[i] >= fd->cell_count) { r.pos = at + 4 * i; st = fmt(&r, "cell map entry out of range"); goto fail; }
    }
    if (r.pos != size) { st = fmt(&r, "trailing bytes after the last cell map"); goto fail; }

    sdfccd__pool pool;
    sdfccd__pool_init(&pool, 0, NULL, NULL);
    switch (scc_grid_finalize(g, 0.0, sdfccd__pool_parallel_for, &pool)) {
    case SCC_GRID_OK: break;
    case SCC_GRID_EMPTY: st = sdfccd__error(SDFCCD_FORMAT_ERROR, "sdfccd_load_grid: field 0 has no cell with values"); goto fail;
    case SCC_GRID_TOO_LARGE: st = sdfccd__error(SDFCCD_FORMAT_ERROR, "sdfccd_load_grid: too many cells"); goto fail;
    case SCC_GRID_STEEP: st = sdfccd__error(SDFCCD_FORMAT_ERROR, "sdfccd_load_grid: node values too large for the cell size (a gradient bound overflows)"); goto fail;
    default: st = sdfccd__oom("grid bounds"); goto fail;
    }
    return sdfccd__grid_register(g, out_grid);
fail:
    scc_grid_destroy(g);
    return st;
}

sdfccd_Status sdfccd_load_grid_memory(const void* data, size_t size, sdfccd_SdfId* out_grid)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(data, "sdfccd_load_grid_memory: data")) || (st = sdfccd__check_ptr(out_grid, "sdfccd_load_grid_memory: out_grid"))) return st;
    if (!host_is_little_endian()) return sdfccd__error(SDFCCD_UNSUPPORTED, "sdfccd_load_grid: .cdf files are little-endian; this host is not");
    return parse(data, size, out_grid);
}

sdfccd_Status sdfccd_load_grid(const char* path, sdfccd_SdfId* out_grid)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(path, "sdfccd_load_grid: path")) || (st = sdfccd__check_ptr(out_grid, "sdfccd_load_grid: out_grid"))) return st;
    if (!host_is_little_endian()) return sdfccd__error(SDFCCD_UNSUPPORTED, "sdfccd_load_grid: .cdf files are little-endian; this host is not");
    FILE* f = fopen(path, "rb");
    if (!f) return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_grid: cannot open '%s': %s", path, strerror(errno));
    /* A directory opens for reading on Linux and reports an absurd size (it asked for 9.2e18 bytes). */
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0 || !S_ISREG(sb.st_mode)) {
        fclose(f);
        return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_grid: '%s' is not a regular file", path);
    }
    long size = -1;
    if (fseek(f, 0, SEEK_END) == 0) size = ftell(f);
    if (size < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_grid: cannot determine the size of '%s'", path);
    }
    if (size == 0) {
        fclose(f);
        return sdfccd__error(SDFCCD_FORMAT_ERROR, "sdfccd_load_grid: '%s' is empty", path);
    }
    unsigned char* buf = sdfccd__alloc((size_t)size);
    if (!buf) { fclose(f); return sdfccd__oom("a file buffer"); }
    const size_t got = fread(buf, 1, (size_t)size, f);
    const int err = ferror(f);
    fclose(f);
    if (got != (size_t)size || err) {
        sdfccd__free(buf, (size_t)size);
        return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_load_grid: cannot read '%s'", path);
    }
    st = parse(buf, (size_t)size, out_grid);
    sdfccd__free(buf, (size_t)size);
    if (st) {
        /* prefix the path to the parser's message */
        char msg[400];
        snprintf(msg, sizeof msg, "%s", sdfccd_last_error());
        sdfccd__error(st, "%s ['%s']", msg, path);
    }
    return st;
}

/* ---------------- writing ---------------- */

static int wr(FILE* f, const void* p, size_t n) { return n == 0 || fwrite(p, 1, n, f) == n; }

static sdfccd_Status save_grid_held(sdfccd_SdfId grid, const char* path)
{
    sdfccd_Status st;
    if ((st = sdfccd__check_ptr(path, "sdfccd_save_grid: path"))) return st;
    scc_grid* g;
    if ((st = sdfccd__grid_acquire(grid, "sdfccd_save_grid", &g))) return st;
    if (!host_is_little_endian()) return sdfccd__error(SDFCCD_UNSUPPORTED, "sdfccd_save_grid: .cdf files are little-endian; this host is not");
    FILE* f = fopen(path, "wb");
    if (!f) return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_save_grid: cannot create '%s': %s", path, strerror(errno));
    /* A band grid built in-tree keeps field 0 in vertex blocks: number its nodes (first use in
     * cell order) and build the id table the file needs. */
    double* band_nodes = NULL;
    uint32_t* band_cells = NULL;
    size_t band_nodes_bytes = 0, band_cells_bytes = 0;
    if (g->vertex_block) {
        const scc_grid_field* fd = &g->fields[0];
        band_nodes_bytes = (size_t)fd->node_count * sizeof(double);
        band_cells_bytes = (size_t)fd->cell_count * 128;
        const size_t key_bytes = (size_t)g->block_count * sizeof(uint32_t);
        band_nodes = sdfccd__alloc(band_nodes_bytes);
        band_cells = sdfccd__alloc(band_cells_bytes);
        uint32_t* id_of_key = sdfccd__alloc(key_bytes);
        if (!band_nodes || !band_cells || !id_of_key) {
            sdfccd__free(band_nodes, band_nodes_bytes);
            sdfccd__free(band_cells, band_cells_bytes);
            sdfccd__free(id_of_key, key_bytes);
            fclose(f);
            remove(path);
            return sdfccd__oom("a band grid's node numbering");
        }
        memset(id_of_key, 0xFF, key_bytes);
        uint64_t next = 0;
        for (uint64_t l = 0; l < g->n_cells; ++l) {
            const uint32_t c = fd->map[l];
            if (c == SCC_GRID_NO_CELL) continue;
            const uint32_t i = (uint32_t)(l % g->res[0]), j = (uint32_t)((l / g->res[0]) % g->res[1]), k = (uint32_t)(l / ((uint64_t)g->res[0] * g->res[1]));
            uint32_t ids[32];
            scc_grid_dense_cell_nodes(g->res, i, j, k, ids);
            for (int a = 0; a < 32; ++a) {
                const uint64_t bi = scc_grid_dense_block_index(g->res, ids[a]);
                const uint64_t key = 7 * (uint64_t)g->vertex_block[bi / 7] + bi % 7;
                if (id_of_key[key] == 0xFFFFFFFFu) {
                    id_of_key[key] = (uint32_t)next;
                    band_nodes[next++] = g->blocks[key];
                }
                band_cells[(size_t)c * 32 + a] = id_of_key[key];
            }
        }
        sdfccd__free(id_of_key, key_bytes);
    }

    const double dom[6] = { g->lo.x, g->lo.y, g->lo.z, g->hi.x, g->hi.y, g->hi.z };
    const double h[3] = { g->h.x, g->h.y, g->h.z }, ih[3] = { g->inv_h.x, g->inv_h.y, g->inv_h.z };
    const uint64_t n_cells = g->n_cells, n_fields = g->field_count;
    int ok = wr(f, dom, sizeof dom) && wr(f, g->res, 12) && wr(f, h, sizeof h) && wr(f, ih, sizeof ih) &&
             wr(f, &n_cells, 8) && wr(f, &n_fields, 8);
    ok = ok && wr(f, &n_fields, 8);
    for (uint32_t i = 0; ok && i < g->field_count; ++i) {
        const uint64_t c = g->fields[i].node_count;
        ok = wr(f, &c, 8);
        if (g->fields[i].nodes) ok = ok && wr(f, g->fields[i].nodes, (size_t)c * 8);
        else if (i == 0 && band_nodes) ok = ok && wr(f, band_nodes, (size_t)c * 8);
        else { /* dense field 0 in the vertex-block layout: back to file order */
            double buf[1024];
            for (uint64_t k = 0; ok && k < c; k += 1024) {
                const uint64_t m = c - k < 1024 ? c - k : 1024;
                for (uint64_t q = 0; q < m; ++q) buf[q] = scc_grid_node_value(g, i, k + q);
                ok = wr(f, buf, (size_t)m * 8);
            }
        }
    }
    ok = ok && wr(f, &n_fields, 8);
    for (uint32_t i = 0; ok && i < g->field_count; ++i) {
        const uint64_t c = g->fields[i].cell_count;
        ok = wr(f, &c, 8);
        if (g->fields[i].cells) ok = ok && wr(f, g->fields[i].cells, (size_t)c * 128);
        else if (i == 0 && band_cells) ok = ok && wr(f, band_cells, (size_t)c * 128);
        else /* dense field 0: the table is implied; write it out */
            for (uint64_t k = 0; ok && k < c; ++k) {
                uint32_t scratch[32];
                ok = wr(f, scc_grid_cell_ids(g, i, (uint32_t)k, scratch), 128);
            }
    }
    ok = ok && wr(f, &n_fields, 8);
    for (uint32_t i = 0; ok && i < g->field_count; ++i) ok = wr(f, &n_cells, 8) && wr(f, g->fields[i].map, (size_t)n_cells * 4);
    sdfccd__free(band_nodes, band_nodes_bytes);
    sdfccd__free(band_cells, band_cells_bytes);
    if (fclose(f) != 0) ok = 0;
    if (!ok) {
        remove(path);
        return sdfccd__error(SDFCCD_IO_ERROR, "sdfccd_save_grid: writing '%s' failed", path);
    }
    return SDFCCD_OK;
}

sdfccd_Status sdfccd_save_grid(sdfccd_SdfId grid, const char* path)
{
    SDFCCD__HELD_CALL(save_grid_held(grid, path));
}
