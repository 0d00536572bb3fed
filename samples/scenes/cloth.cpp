// SPDX-License-Identifier: MIT
// cloth (Fig. 9): a mass-spring cloth over the bunny SDF, through the C ABI's per-vertex motion
// queries (sdfccd_query_mesh_linear, sdfccd_query_triangle_linear). Z up, g = -9.81.
//
// The cloth: 21 x 21 vertices over 0.8 x 0.8 m (800 triangles), 0.2 kg, dropped flat from 10 cm
// above a 50 cm bunny (bunny.obj x0.25, baked to a 32^3 grid; measured against the exact mesh
// distance) standing on a ground box. Faces are measured on a lattice (density 3).
//
// The integrator (a small one, written for this scene): symplectic Euler with structural, shear
// and bending springs (stiffness scaled so k dt^2 / m = 0.25, stable at 1 and 10 ms) and light
// damping, then 8 Jacobi passes of strain limiting (edges at most 5% longer than at rest).
// Collision, each step: the predicted positions x* = x + dt v; if sdfccd_query_mesh_linear over
// the whole cloth finds contact, every triangle near the SDF is queried with
// sdfccd_query_triangle_linear (margin 1 mm); every contact it returns (one per triangle, plus
// the subdivision contacts when enabled) becomes a plane constraint "the contact point of the
// triangle at x* stays on the outer side of the plane through the surface point with normal n",
// projected onto the triangle's vertices with its barycentric weights (4 Gauss-Seidel passes).
// Velocities are then (x_new - x) / dt. So with one contact per triangle a face can pivot about it
// and let the SDF through elsewhere; subdivision adds the contacts that hold the face.
//   cloth      10 ms steps (150 steps: 1.5 s)
//   cloth-1ms  1 ms steps (1500 steps)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "scenes.h"

namespace scenes {

namespace {

const int kN = 21;
const double kSize = 0.8, kMass = 0.2, kMargin = 1e-3;

struct Spring {
    int a, b;
    double rest;
};

class Cloth : public Scene {
public:
    explicit Cloth(const Options& opt) : m_opt(opt) {}
    ~Cloth() override
    {
        for (sdfccd_SdfId id : m_owned) sdfccd_destroy_sdf(id);
        if (m_exact.index1) sdfccd_destroy_mesh(m_exact);
    }

    bool build()
    {
        gravity[2] = -9.81;
        ccd_margin = kMargin;
        std::shared_ptr<MeshData> file = loadDataMesh(m_opt, "bullet3/bunny.obj", 0.25);
        if (!file) return false;
        // bunny.obj is Y up: turn it to Z up, (x, y, z) -> (x, -z, y).
        std::vector<double> bv = file->v;
        for (size_t i = 0; i < bv.size(); i += 3) {
            double y = bv[i + 1], z = bv[i + 2];
            bv[i + 1] = -z;
            bv[i + 2] = y;
        }
        std::shared_ptr<MeshData> bunny = makeMesh("bunny", bv, file->f);
        sdfccd_SdfId grid = gridFromMesh(bunny->handle, 32, 0.05, "bunny grid");
        if (grid.index1 == 0) return false;
        m_owned.push_back(grid);
        sdfccd_MeshDef def = sdfccd_default_mesh_def();
        def.vertices = bunny->v.data();
        def.vertex_count = (uint32_t)bunny->vertexCount();
        def.indices = bunny->f.data();
        def.triangle_count = (uint32_t)bunny->triangleCount();
        def.drop_degenerate = 1;
        sdfccd_create_mesh(&def, &m_exact);
        sdfccd_GridInfo gi;
        sdfccd_grid_get_info(grid, &gi);
        double bottom = bunny->bounds.lo.z, top = bunny->bounds.hi.z;
        Collider c;
        c.name = "bunny_grid";
        c.ccd = c.render = grid;
        c.exact_mesh = m_exact;
        c.bounds = gi.domain;
        c.frame.p[2] = -bottom; // standing on z = 0
        colliders.push_back(c);
        sdfccd_SdfId ground{};
        sdfccd_create_box(sdfccd_Vec3{ 1, 1, 0.25 }, &ground);
        m_owned.push_back(ground);
        Collider g;
        g.name = "ground";
        g.ccd = g.exact = ground;
        g.frame.p[2] = -0.25;
        g.bounds = sdfccd_Aabb{ { -1.05, -1.05, -0.3 }, { 1.05, 1.05, 0.3 } };
        g.killBelow(up, -0.05);
        colliders.push_back(g);

        // The cloth, flat, 10 cm above the bunny's top.
        std::vector<double> v;
        std::vector<uint32_t> f;
        double z0 = top - bottom + 0.1;
        for (int j = 0; j < kN; ++j)
            for (int i = 0; i < kN; ++i) {
                v.push_back(-0.5 * kSize + kSize * i / (kN - 1));
                v.push_back(-0.5 * kSize + kSize * j / (kN - 1));
                v.push_back(z0);
            }
        for (int j = 0; j + 1 < kN; ++j)
            for (int i = 0; i + 1 < kN; ++i) {
                uint32_t a = (uint32_t)(j * kN + i), b = a + 1, c2 = a + kN, d = c2 + 1;
                const uint32_t t[6] = { a, b, d, a, d, c2 };
                f.insert(f.end(), t, t + 6);
            }
        std::shared_ptr<MeshData> mesh = makeMesh("cloth", v, f);
        mesh->finish(3);
        mesh->half_thickness = 1e9; // a sheet: penetration is measured, tunnelling by the kill plane only
        m_x = v;
        m_v.assign(v.size(), 0);
        auto add = [&](int a, int b) { m_springs.push_back({ a, b, dist(&v[3 * a], &v[3 * b]) }); };
        for (int j = 0; j < kN; ++j)
            for (int i = 0; i < kN; ++i) {
                int a = j * kN + i;
                if (i + 1 < kN) add(a, a + 1);
                if (j + 1 < kN) add(a, a + kN);
                if (i + 1 < kN && j + 1 < kN) {
                    add(a, a + kN + 1);
                    add(a + 1, a + kN);
                }
                if (i + 2 < kN) add(a, a + 2);
                if (j + 2 < kN) add(a, a + 2 * kN);
            }
        Body b;
        b.name = "cloth";
        b.mesh = mesh;
        b.deformable = true;
        mesh->samplesFor(m_x.data(), b.world);
        bodies.push_back(b);
        view = sdfccd_Aabb{ { -0.5, -0.5, -0.05 }, { 0.5, 0.5, z0 + 0.05 } };
        return true;
    }

    void step(int, double dt) override
    {
        int n = kN * kN;
        double m = kMass / n, k = 0.25 * m / (dt * dt), damp = 0.02 * m / dt;
        std::vector<double> force(3 * (size_t)n, 0);
        for (int i = 0; i < n; ++i) force[3 * (size_t)i + 2] = m * gravity[2];
        for (const Spring& s : m_springs) {
            double d[3], dv[3];
            for (int q = 0; q < 3; ++q) {
                d[q] = m_x[3 * (size_t)s.b + q] - m_x[3 * (size_t)s.a + q];
                dv[q] = m_v[3 * (size_t)s.b + q] - m_v[3 * (size_t)s.a + q];
            }
            double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (len < 1e-12) continue;
            double rel = (d[0] * dv[0] + d[1] * dv[1] + d[2] * dv[2]) / len;
            double fmag = k * (len - s.rest) + damp * rel;
            for (int q = 0; q < 3; ++q) {
                force[3 * (size_t)s.a + q] += fmag * d[q] / len;
                force[3 * (size_t)s.b + q] -= fmag * d[q] / len;
            }
        }
        std::vector<double> xs(m_x.size());
        for (size_t i = 0; i < m_x.size(); ++i) {
            m_v[i] += dt * force[i] / m;
            xs[i] = m_x[i] + dt * m_v[i];
        }
        strainLimit(xs);
        collide(xs, dt);
        for (size_t i = 0; i < m_x.size(); ++i) {
            m_v[i] = (xs[i] - m_x[i]) / dt;
            m_x[i] = xs[i];
        }
        bodies[0].mesh->samplesFor(m_x.data(), bodies[0].world);
    }

    StepCost cost() const override { return m_cost; }
    double energy() const override { return NAN; }
    std::string describe() const override
    {
        std::ostringstream s;
        s << "mass-spring cloth " << kN << "x" << kN << " through the C ABI (query_mesh_linear + query_triangle_linear), "
          << methodName(m_opt.method) << (m_opt.subdivision ? " + subdivision" : "") << ", margin " << kMargin << " m";
        return s.str();
    }

private:
    static double dist(const double* a, const double* b)
    {
        double d[3] = { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
        return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }

    void strainLimit(std::vector<double>& x)
    {
        for (int pass = 0; pass < 8; ++pass) {
            std::vector<double> corr(x.size(), 0);
            std::vector<int> cnt(x.size() / 3, 0);
            for (const Spring& s : m_springs) {
                double len = dist(&x[3 * (size_t)s.a], &x[3 * (size_t)s.b]), max_len = 1.05 * s.rest;
                if (len <= max_len || len < 1e-12) continue;
                double c = 0.5 * (len - max_len) / len;
                for (int q = 0; q < 3; ++q) {
                    double d = x[3 * (size_t)s.b + q] - x[3 * (size_t)s.a + q];
                    corr[3 * (size_t)s.a + q] += c * d;
                    corr[3 * (size_t)s.b + q] -= c * d;
                }
                ++cnt[(size_t)s.a];
                ++cnt[(size_t)s.b];
            }
            for (size_t i = 0; i < cnt.size(); ++i)
                if (cnt[i])
                    for (int q = 0; q < 3; ++q) x[3 * i + q] += corr[3 * i + q] / cnt[i];
        }
    }

    struct PlaneContact {
        uint32_t v[3];
        double w[3], q[3], n[3]; // barycentric weights, point on the margin surface, normal
    };

    void collide(std::vector<double>& xs, double dt)
    {
        const MeshData& mesh = *bodies[0].mesh;
        sdfccd_QueryParams params = sdfccd_default_query_params();
        params.method = m_opt.method;
        params.subdivision = m_opt.subdivision ? 1 : 0;
        params.margin = kMargin;
        std::vector<PlaneContact> planes;
        std::vector<sdfccd_Contact> buf(32);
        m_cost.contacts = 0;
        for (const Collider& c : colliders) {
            // World = collider frame shifted by p (no rotation in this scene): positions in its frame.
            std::vector<double> a(m_x.size()), b(xs.size());
            for (size_t i = 0; i < a.size(); ++i) {
                a[i] = m_x[i] - c.frame.p[i % 3];
                b[i] = xs[i] - c.frame.p[i % 3];
            }
            sdfccd_QueryResult res;
            auto t0 = std::chrono::steady_clock::now();
            std::vector<sdfccd_Vec3> va(a.size() / 3), vb(b.size() / 3);
            for (size_t i = 0; i < va.size(); ++i) {
                va[i] = sdfccd_Vec3{ a[3 * i], a[3 * i + 1], a[3 * i + 2] };
                vb[i] = sdfccd_Vec3{ b[3 * i], b[3 * i + 1], b[3 * i + 2] };
            }
            sdfccd_Status st = sdfccd_query_mesh_linear(c.ccd, nullptr, mesh.handle, va.data(), vb.data(), 0, dt, &params, nullptr, 0, &res);
            ++m_cost.ccd_queries;
            if (st == SDFCCD_OK) m_cost.triangles_tested += res.triangles_tested;
            if (st != SDFCCD_OK || !res.hit) {
                m_cost.ccd_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                continue;
            }
            ++m_cost.hits;
            for (int t = 0; t < mesh.triangleCount(); ++t) {
                sdfccd_Vec3 s0[3], s1[3];
                double reach = 0, phi_min = 1e300;
                for (int k = 0; k < 3; ++k) {
                    uint32_t vi = mesh.f[3 * (size_t)t + k];
                    s0[k] = sdfccd_Vec3{ a[3 * vi], a[3 * vi + 1], a[3 * vi + 2] };
                    s1[k] = sdfccd_Vec3{ b[3 * vi], b[3 * vi + 1], b[3 * vi + 2] };
                    reach = std::max(reach, dist(&a[3 * vi], &b[3 * vi]));
                    double phi;
                    sdfccd_sdf_eval(c.ccd, s0[k], &phi, nullptr);
                    phi_min = std::min(phi_min, phi);
                }
                double edge = std::max(dist(&a[3 * mesh.f[3 * t]], &a[3 * mesh.f[3 * t + 1]]),
                                       std::max(dist(&a[3 * mesh.f[3 * t + 1]], &a[3 * mesh.f[3 * t + 2]]),
                                                dist(&a[3 * mesh.f[3 * t + 2]], &a[3 * mesh.f[3 * t]])));
                if (phi_min > reach + edge + kMargin) continue; // cannot reach the surface this step
                sdfccd_QueryResult tr;
                if (sdfccd_query_triangle_linear(c.ccd, nullptr, s0, s1, 0, dt, &params, buf.data(), (int32_t)buf.size(), &tr) != SDFCCD_OK ||
                    !tr.hit)
                    continue;
                for (int k = 0; k < tr.contact_count; ++k) {
                    const sdfccd_Contact& ct = buf[(size_t)k];
                    PlaneContact pc;
                    for (int q = 0; q < 3; ++q) {
                        pc.v[q] = mesh.f[3 * (size_t)t + q];
                        pc.w[q] = ct.barycentric[q];
                    }
                    const double n[3] = { ct.normal.x, ct.normal.y, ct.normal.z };
                    const double p[3] = { ct.point.x, ct.point.y, ct.point.z };
                    for (int q = 0; q < 3; ++q) {
                        pc.n[q] = n[q];
                        pc.q[q] = p[q] - (ct.distance - kMargin) * n[q] + c.frame.p[q]; // back to world
                    }
                    planes.push_back(pc);
                }
            }
            m_cost.ccd_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        m_cost.contacts = (int)planes.size();
        for (int pass = 0; pass < 4; ++pass)
            for (const PlaneContact& pc : planes) {
                double p[3] = { 0, 0, 0 }, ww = 0;
                for (int k = 0; k < 3; ++k) {
                    ww += pc.w[k] * pc.w[k];
                    for (int q = 0; q < 3; ++q) p[q] += pc.w[k] * xs[3 * (size_t)pc.v[k] + q];
                }
                double cval = (p[0] - pc.q[0]) * pc.n[0] + (p[1] - pc.q[1]) * pc.n[1] + (p[2] - pc.q[2]) * pc.n[2];
                if (cval >= 0 || ww <= 0) continue;
                for (int k = 0; k < 3; ++k)
                    for (int q = 0; q < 3; ++q) xs[3 * (size_t)pc.v[k] + q] -= cval * pc.w[k] / ww * pc.n[q];
            }
    }

    Options m_opt;
    StepCost m_cost;
    std::vector<sdfccd_SdfId> m_owned;
    sdfccd_MeshId m_exact{};
    std::vector<double> m_x, m_v;
    std::vector<Spring> m_springs;
};

Scene* createCloth(const Options& opt) { return built(new Cloth(opt)); }

} // namespace

void appendClothScenes(std::vector<SceneEntry>& t)
{
    t.push_back({ "cloth", "Fig. 9: a mass-spring cloth over the bunny SDF, 10 ms steps (C ABI, per-vertex motion)", createCloth, 150, 0.01 });
    t.push_back({ "cloth-1ms", "Fig. 9: the same cloth at 1 ms steps", createCloth, 1500, 0.001 });
}

} // namespace scenes
