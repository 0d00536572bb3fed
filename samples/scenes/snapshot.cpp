// SPDX-License-Identifier: MIT
// A small headless rasteriser: orthographic camera, z-buffer, flat Lambert shading; PNG output
// (the format written here: IHDR, the "Sub" row filter, one zlib-compressed IDAT, IEND).
#include "snapshot.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sys/stat.h>
#include <zlib.h>

namespace scenes {

namespace {

const int kW = 640, kH = 480;

uint32_t crc32(const unsigned char* p, size_t n, uint32_t crc = 0)
{
    static uint32_t table[256];
    static bool init = false;
    if (!init) {
        for (uint32_t i = 0; i < 256; ++i) {
            uint32_t c = i;
            for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            table[i] = c;
        }
        init = true;
    }
    crc = ~crc;
    for (size_t i = 0; i < n; ++i) crc = table[(crc ^ p[i]) & 0xff] ^ (crc >> 8);
    return ~crc;
}

void put32(std::vector<unsigned char>& out, uint32_t v)
{
    for (int s = 24; s >= 0; s -= 8) out.push_back((unsigned char)(v >> s));
}

void chunk(std::FILE* f, const char* type, const std::vector<unsigned char>& data)
{
    std::vector<unsigned char> buf;
    put32(buf, (uint32_t)data.size());
    buf.insert(buf.end(), type, type + 4);
    buf.insert(buf.end(), data.begin(), data.end());
    uint32_t c = crc32(buf.data() + 4, buf.size() - 4);
    put32(buf, c);
    std::fwrite(buf.data(), 1, buf.size(), f);
}

bool writePng(const std::string& path, const std::vector<unsigned char>& rgb, int w, int h)
{
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return false;
    const unsigned char sig[8] = { 137, 80, 78, 71, 13, 10, 26, 10 };
    std::fwrite(sig, 1, 8, f);
    std::vector<unsigned char> ihdr;
    put32(ihdr, (uint32_t)w);
    put32(ihdr, (uint32_t)h);
    const unsigned char rest[5] = { 8, 2, 0, 0, 0 }; // 8-bit RGB
    ihdr.insert(ihdr.end(), rest, rest + 5);
    chunk(f, "IHDR", ihdr);
    // Scanlines with the Sub filter (each byte minus the same channel of the pixel to its left),
    // which turns flat-shaded areas into runs of zeros, then zlib.
    std::vector<unsigned char> raw;
    raw.reserve((size_t)h * (3 * w + 1));
    for (int y = 0; y < h; ++y) {
        raw.push_back(1);
        const unsigned char* row = &rgb[(size_t)y * 3 * w];
        for (int x = 0; x < 3 * w; ++x) raw.push_back((unsigned char)(row[x] - (x >= 3 ? row[x - 3] : 0)));
    }
    uLongf zlen = compressBound((uLong)raw.size());
    std::vector<unsigned char> z(zlen);
    if (compress2(z.data(), &zlen, raw.data(), (uLong)raw.size(), 9) != Z_OK) {
        std::fclose(f);
        return false;
    }
    z.resize(zlen);
    chunk(f, "IDAT", z);
    chunk(f, "IEND", std::vector<unsigned char>());
    bool ok = std::ferror(f) == 0;
    return std::fclose(f) == 0 && ok;
}

struct V3 {
    double x, y, z;
};
V3 sub(V3 a, V3 b) { return V3{ a.x - b.x, a.y - b.y, a.z - b.z }; }
V3 cross(V3 a, V3 b) { return V3{ a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x }; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 unit(V3 a)
{
    double n = std::sqrt(dot(a, a));
    return n > 0 ? V3{ a.x / n, a.y / n, a.z / n } : a;
}

struct Camera {
    V3 right, upv, fwd, centre;
    double scale; // pixels per metre
    V3 project(V3 p) const
    {
        V3 d = sub(p, centre);
        return V3{ kW / 2.0 + scale * dot(d, right), kH / 2.0 - scale * dot(d, upv), dot(d, fwd) };
    }
};

struct Raster {
    std::vector<unsigned char> rgb;
    std::vector<double> depth;
    Raster() : rgb((size_t)kW * kH * 3), depth((size_t)kW * kH, 1e300)
    {
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                unsigned char g = (unsigned char)(235 - 40 * y / kH);
                unsigned char* p = &rgb[3 * ((size_t)y * kW + x)];
                p[0] = g;
                p[1] = g;
                p[2] = (unsigned char)std::min(255, g + 10);
            }
    }
    // A triangle with world positions a, b, c; colour blended per vertex.
    void triangle(const Camera& cam, V3 a, V3 b, V3 c, const double* ca, const double* cb, const double* cc)
    {
        V3 n = unit(cross(sub(b, a), sub(c, a)));
        V3 light = unit(V3{ -0.4 * cam.right.x + 0.8 * cam.upv.x - 0.5 * cam.fwd.x, -0.4 * cam.right.y + 0.8 * cam.upv.y - 0.5 * cam.fwd.y,
                            -0.4 * cam.right.z + 0.8 * cam.upv.z - 0.5 * cam.fwd.z });
        double shade = 0.3 + 0.7 * std::fabs(dot(n, light)); // two-sided
        V3 p[3] = { cam.project(a), cam.project(b), cam.project(c) };
        double x0 = std::floor(std::min(p[0].x, std::min(p[1].x, p[2].x))), x1 = std::ceil(std::max(p[0].x, std::max(p[1].x, p[2].x)));
        double y0 = std::floor(std::min(p[0].y, std::min(p[1].y, p[2].y))), y1 = std::ceil(std::max(p[0].y, std::max(p[1].y, p[2].y)));
        int ix0 = std::max(0, (int)x0), ix1 = std::min(kW - 1, (int)x1), iy0 = std::max(0, (int)y0), iy1 = std::min(kH - 1, (int)y1);
        double area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
        if (std::fabs(area) < 1e-12) return;
        for (int y = iy0; y <= iy1; ++y)
            for (int x = ix0; x <= ix1; ++x) {
                double px = x + 0.5, py = y + 0.5;
                double w0 = ((p[1].x - px) * (p[2].y - py) - (p[2].x - px) * (p[1].y - py)) / area;
                double w1 = ((p[2].x - px) * (p[0].y - py) - (p[0].x - px) * (p[2].y - py)) / area;
                double w2 = 1 - w0 - w1;
                if (w0 < 0 || w1 < 0 || w2 < 0) continue;
                double d = w0 * p[0].z + w1 * p[1].z + w2 * p[2].z;
                size_t k = (size_t)y * kW + x;
                if (d >= depth[k]) continue;
                depth[k] = d;
                for (int ch = 0; ch < 3; ++ch)
                    rgb[3 * k + ch] = (unsigned char)std::min(255.0, shade * (w0 * ca[ch] + w1 * cb[ch] + w2 * cc[ch]));
            }
    }
    void mark(const Camera& cam, V3 w, int r)
    {
        V3 p = cam.project(w);
        for (int y = (int)p.y - r; y <= (int)p.y + r; ++y)
            for (int x = (int)p.x - r; x <= (int)p.x + r; ++x) {
                if (x < 0 || y < 0 || x >= kW || y >= kH) continue;
                unsigned char* q = &rgb[3 * ((size_t)y * kW + x)];
                q[0] = 230;
                q[1] = 20;
                q[2] = 20;
            }
    }
};

void bodySamples(const Body& b, std::vector<V3>& out)
{
    int n = b.mesh->sampleCount();
    out.resize((size_t)n);
    for (int i = 0; i < n; ++i) {
        double w[3];
        if (b.deformable) std::memcpy(w, &b.world[3 * (size_t)i], sizeof w);
        else b.frame.apply(&b.mesh->samples[3 * (size_t)i], w);
        out[(size_t)i] = V3{ w[0], w[1], w[2] };
    }
}

} // namespace

struct Snapshotter::Impl {
    bool framed = false;
    Camera cam;
    double lo[3], hi[3];
};

Snapshotter::Snapshotter(const std::string& dir) : m_dir(dir), m_impl(new Impl)
{
    if (!dir.empty()) mkdir(dir.c_str(), 0777);
}

Snapshotter::~Snapshotter() { delete m_impl; }

void Snapshotter::write(Scene& scene, const std::vector<std::vector<double>>& sample_phi, const char* label, int step)
{
    Impl& im = *m_impl;
    std::vector<V3> pts;
    if (!im.framed) {
        // Frame the bodies (first picture) with a margin of half their extent, at least 0.5 m,
        // or the scene's own view box when it sets one.
        double lo[3] = { 1e300, 1e300, 1e300 }, hi[3] = { -1e300, -1e300, -1e300 };
        for (const Body& b : scene.bodies) {
            if (!b.active) continue;
            bodySamples(b, pts);
            for (V3 p : pts) {
                double q[3] = { p.x, p.y, p.z };
                for (int k = 0; k < 3; ++k) {
                    lo[k] = std::min(lo[k], q[k]);
                    hi[k] = std::max(hi[k], q[k]);
                }
            }
        }
        if (scene.view.lo.x < scene.view.hi.x) {
            lo[0] = scene.view.lo.x; lo[1] = scene.view.lo.y; lo[2] = scene.view.lo.z;
            hi[0] = scene.view.hi.x; hi[1] = scene.view.hi.y; hi[2] = scene.view.hi.z;
        } else {
            double ext = 0;
            for (int k = 0; k < 3; ++k) ext = std::max(ext, hi[k] - lo[k]);
            double pad = std::max(0.5 * ext, 0.05);
            for (int k = 0; k < 3; ++k) {
                lo[k] -= pad;
                hi[k] += pad;
            }
        }
        std::memcpy(im.lo, lo, sizeof lo);
        std::memcpy(im.hi, hi, sizeof hi);
        V3 up{ scene.up[0], scene.up[1], scene.up[2] };
        // Look from the front-right, 30 degrees above the horizon.
        V3 side = std::fabs(up.z) > 0.5 ? V3{ 1, -1.6, 0 } : V3{ 1, 0, 1.6 };
        V3 fwd = unit(V3{ -side.x - 0.9 * up.x, -side.y - 0.9 * up.y, -side.z - 0.9 * up.z });
        V3 right = unit(cross(fwd, up));
        V3 upv = cross(right, fwd);
        im.cam.fwd = fwd;
        im.cam.right = right;
        im.cam.upv = upv;
        im.cam.centre = V3{ 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]) };
        double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
        im.cam.scale = 0.95 * std::min(kW, kH) / std::max(diag, 1e-6);
        im.framed = true;
    }
    Raster r;
    // Colliders: their isosurface inside the view box (in each collider's local frame).
    const double grey[3] = { 150, 170, 200 };
    for (const Collider& c : scene.colliders) {
        sdfccd_SdfId sdf = c.exact;
        if (!sdf.index1) sdf = c.render;
        if (!sdf.index1) continue;
        double llo[3] = { 1e300, 1e300, 1e300 }, lhi[3] = { -1e300, -1e300, -1e300 };
        for (int corner = 0; corner < 8; ++corner) {
            double w[3] = { corner & 1 ? im.hi[0] : im.lo[0], corner & 2 ? im.hi[1] : im.lo[1], corner & 4 ? im.hi[2] : im.lo[2] }, l[3];
            c.frame.applyInverse(w, l);
            for (int k = 0; k < 3; ++k) {
                llo[k] = std::min(llo[k], l[k]);
                lhi[k] = std::max(lhi[k], l[k]);
            }
        }
        double blo[3] = { c.bounds.lo.x, c.bounds.lo.y, c.bounds.lo.z }, bhi[3] = { c.bounds.hi.x, c.bounds.hi.y, c.bounds.hi.z };
        bool empty = false;
        for (int k = 0; k < 3; ++k) {
            llo[k] = std::max(llo[k], blo[k]);
            lhi[k] = std::min(lhi[k], bhi[k]);
            if (llo[k] >= lhi[k]) empty = true;
        }
        if (empty) continue;
        sdfccd_MeshId mesh;
        sdfccd_Aabb box{ { llo[0], llo[1], llo[2] }, { lhi[0], lhi[1], lhi[2] } };
        if (sdfccd_extract_isosurface(sdf, box, 96, &mesh) != SDFCCD_OK) continue;
        sdfccd_MeshInfo info;
        std::vector<double> v;
        std::vector<uint32_t> f;
        if (!takeMeshArrays(mesh, v, f, info)) continue;
        std::vector<V3> wv(info.vertex_count);
        for (uint32_t i = 0; i < info.vertex_count; ++i) {
            double w[3];
            c.frame.apply(&v[3 * (size_t)i], w);
            wv[i] = V3{ w[0], w[1], w[2] };
        }
        for (uint32_t t = 0; t < info.triangle_count; ++t)
            r.triangle(im.cam, wv[f[3 * t]], wv[f[3 * t + 1]], wv[f[3 * t + 2]], grey, grey, grey);
    }
    // Bodies; vertices deeper than 1 mm red.
    const double tan[3] = { 235, 190, 120 }, red[3] = { 255, 30, 30 };
    for (size_t bi = 0; bi < scene.bodies.size(); ++bi) {
        const Body& b = scene.bodies[bi];
        if (!b.active) continue;
        bodySamples(b, pts);
        const std::vector<double>* phi = bi < sample_phi.size() && sample_phi[bi].size() == pts.size() ? &sample_phi[bi] : nullptr;
        const std::vector<uint32_t>& f = b.mesh->f;
        for (size_t t = 0; t + 2 < f.size(); t += 3) {
            const double* col[3];
            for (int k = 0; k < 3; ++k) col[k] = phi && (*phi)[f[t + k]] < -1e-3 ? red : tan;
            r.triangle(im.cam, pts[f[t]], pts[f[t + 1]], pts[f[t + 2]], col[0], col[1], col[2]);
        }
        if (phi)
            for (size_t i = 0; i < pts.size(); ++i)
                if ((*phi)[i] < -1e-3) r.mark(im.cam, pts[i], 2);
    }
    char name[64];
    std::snprintf(name, sizeof name, "/%s_step%04d.png", label, step);
    std::string path = m_dir + name;
    if (!writePng(path, r.rgb, kW, kH)) std::fprintf(stderr, "sdfccd_scenes: cannot write %s\n", path.c_str());
    else std::fprintf(stderr, "snapshot %s\n", path.c_str());
}

} // namespace scenes
