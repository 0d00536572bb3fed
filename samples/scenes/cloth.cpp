// SPDX-License-Identifier: MIT
// cloth (Fig. 9): a mass-spring cloth over the bunny SDF, through the C ABI's per-vertex motion
// queries (sdfccd_query_mesh_linear, sdfccd_query_triangle_linear). Z up, g = -9.81.
//
// The cloth: 21 x 21 vertices over 0.8 x 0.8 m (800 triangles), 0.2 kg, dropped flat from 10 cm
// above a 50 cm bunny (bunny.obj x0.25, baked to a 32^3 grid; measured against the exact mesh
// distance) standing on a ground box. Faces are measured on a lattice (density 3).
//
// The integrator (a small one, written for this scene): backward Euler (Baraff & Witkin, "Large
// steps in cloth simulation", 1998) with structural, shear and bending springs (stiffness scaled so
// k dt^2 / m = 0.25), their damping along the spring and a mild mass damping (1/s), solved with 30
// conjugate-gradient iterations on the spring Jacobians; the vertices of last step's contacts are
// held (velocity 0: static friction) by filtering them out of the solve, and stay held while within
// 2 cm of a collider (a cloth triangle resting on an ear tip touches it inside, not at a vertex).
// Then 8 Jacobi passes of strain limiting (edges at most 5% longer than at rest; held vertices do
// not move).
// Collision, each step (the paper's rule: the simulation does not advance past a time of impact):
// the predicted positions x* = x + dt v give each vertex a displacement D over the step; every
// triangle that can reach a collider is queried with sdfccd_query_triangle_linear (margin 1 mm)
// on the motion x -> x + D, and
//  - a triangle that first touches at toi in (0, dt] has its vertices put back where they were at
//    that toi (D scaled by toi/dt; a vertex shared by several keeps the earliest): at its first
//    time of impact the whole triangle is outside the margin surface;
//  - a triangle already within the margin at the start (resting on the surface) turns each of its
//    contacts into "no displacement into the surface" on its vertices (D.n >= 0, or back to half
//    the margin when closer than that).
// Placing some vertices back changes the motion of their neighbours' triangles, so the queries run
// again on the new motion until nothing changes by more than 10 um (8 passes at most; then the
// triangles that still reach the surface inside the step do not move in it, counted as
// "response_freezes"). Velocities are (x_new - x) / dt, less their component into the surface at
// every contact met. Without subdivision the first contact of a triangle is found all the same
// (FWGSS minimises over the whole triangle); subdivision adds contacts at that time.
//   cloth      10 ms steps (300 steps: 3 s)
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
const int kMaxSweeps = 8;   // CCD passes of the collision response per step before the freeze
const double kStill = 1e-5; // m: a smaller change of a vertex's displacement ends the passes
const int kCgIterations = 30;      // conjugate-gradient iterations of the implicit step
const double kMassDamping = 1.0;   // 1/s: mild damping of every vertex's velocity
const double kHoldDistance = 0.02; // m: a held vertex stays held while this close to a collider (half an edge)

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
        const size_t N = 3 * (size_t)n;
        std::vector<double> force(N, 0);
        for (int i = 0; i < n; ++i) force[3 * (size_t)i + 2] = m * gravity[2];
        // Per spring: unit direction and the stiffness block -df/dx = k (d d^T + max(0, 1 - L/l)(I - d d^T)).
        std::vector<double> dir(3 * m_springs.size()), soft(m_springs.size());
        for (size_t si = 0; si < m_springs.size(); ++si) {
            const Spring& s = m_springs[si];
            double d[3], dv[3];
            for (int q = 0; q < 3; ++q) {
                d[q] = m_x[3 * (size_t)s.b + q] - m_x[3 * (size_t)s.a + q];
                dv[q] = m_v[3 * (size_t)s.b + q] - m_v[3 * (size_t)s.a + q];
            }
            double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            soft[si] = 0;
            if (len < 1e-12) {
                dir[3 * si] = dir[3 * si + 1] = dir[3 * si + 2] = 0;
                continue;
            }
            for (int q = 0; q < 3; ++q) dir[3 * si + q] = d[q] / len;
            soft[si] = std::max(0.0, 1 - s.rest / len);
            double rel = (d[0] * dv[0] + d[1] * dv[1] + d[2] * dv[2]) / len;
            double fmag = k * (len - s.rest) + damp * rel;
            for (int q = 0; q < 3; ++q) {
                force[3 * (size_t)s.a + q] += fmag * d[q] / len;
                force[3 * (size_t)s.b + q] -= fmag * d[q] / len;
            }
        }
        // Backward Euler (Baraff & Witkin 1998): (M (1 + h c) + h^2 K + h D) dv = h (f - h K v), with
        // K the springs' stiffness, D their damping along the spring, c a mild mass damping; solved by
        // conjugate gradients filtered on the vertices held by a contact of the last step (dv = -v:
        // they stick, a Coulomb cone wide enough for this scene).
        const double c_mass = kMassDamping;
        auto apply = [&](const std::vector<double>& in, std::vector<double>& out, double wk, double wd) {
            for (size_t i = 0; i < N; ++i) out[i] = m * (1 + dt * c_mass) * in[i];
            for (size_t si = 0; si < m_springs.size(); ++si) {
                const Spring& s = m_springs[si];
                const double* e = &dir[3 * si];
                double u[3];
                for (int q = 0; q < 3; ++q) u[q] = in[3 * (size_t)s.a + q] - in[3 * (size_t)s.b + q];
                const double ue = u[0] * e[0] + u[1] * e[1] + u[2] * e[2];
                const double along = wk * k * (1 - soft[si]) + wd * damp, across = wk * k * soft[si];
                for (int q = 0; q < 3; ++q) {
                    const double y = along * ue * e[q] + across * u[q];
                    out[3 * (size_t)s.a + q] += y;
                    out[3 * (size_t)s.b + q] -= y;
                }
            }
        };
        // Held: a vertex of a contact last step, or held before, that is within kHoldDistance of
        // a collider (a contact on a triangle holds only its vertices close to the surface; a held
        // vertex does not flick between in and out of contact).
        std::vector<char> held((size_t)n, 0);
        m_planes_held.assign((size_t)n, 0);
        for (const VertexPlane& vp : m_held) held[vp.v] = m_planes_held[vp.v] = 1;
        if (m_was_held.size() == (size_t)n)
            for (int i = 0; i < n; ++i) held[(size_t)i] |= m_was_held[(size_t)i];
        for (int i = 0; i < n; ++i) {
            if (!held[(size_t)i]) continue;
            bool near = m_planes_held.size() == (size_t)n && m_planes_held[(size_t)i];
            for (const Collider& c : colliders) {
                const double* xi = &m_x[3 * (size_t)i];
                sdfccd_Vec3 pl{ xi[0] - c.frame.p[0], xi[1] - c.frame.p[1], xi[2] - c.frame.p[2] };
                double phi = 1e300;
                if (sdfccd_sdf_eval(c.ccd, pl, &phi, nullptr) == SDFCCD_OK && phi < kHoldDistance) near = true;
            }
            held[(size_t)i] = near ? 1 : 0;
        }
        m_was_held = held;
        std::vector<double> b(N), kv(N, 0), x(N, 0), r(N), p(N), q(N);
        {
            std::vector<double> mv(N);
            // K v alone: mass term removed by apply(in) - m(1 + h c) in.
            apply(m_v, kv, 1, 0);
            for (size_t i = 0; i < N; ++i) kv[i] -= m * (1 + dt * c_mass) * m_v[i];
            for (size_t i = 0; i < N; ++i) b[i] = dt * (force[i] - dt * kv[i] - c_mass * m * m_v[i]);
        }
        for (int i = 0; i < n; ++i)
            if (held[(size_t)i])
                for (int c3 = 0; c3 < 3; ++c3) x[3 * (size_t)i + c3] = -m_v[3 * (size_t)i + c3];
        auto filter = [&](std::vector<double>& y) {
            for (int i = 0; i < n; ++i)
                if (held[(size_t)i]) y[3 * (size_t)i] = y[3 * (size_t)i + 1] = y[3 * (size_t)i + 2] = 0;
        };
        apply(x, q, dt * dt, dt);
        for (size_t i = 0; i < N; ++i) r[i] = b[i] - q[i];
        filter(r);
        p = r;
        double rr = 0;
        for (size_t i = 0; i < N; ++i) rr += r[i] * r[i];
        const double rr0 = rr;
        for (int it = 0; it < kCgIterations && rr > 1e-20 * rr0 && rr > 0; ++it) {
            apply(p, q, dt * dt, dt);
            filter(q);
            double pq = 0;
            for (size_t i = 0; i < N; ++i) pq += p[i] * q[i];
            if (!(pq > 0)) break;
            const double a = rr / pq;
            double rr_new = 0;
            for (size_t i = 0; i < N; ++i) {
                x[i] += a * p[i];
                r[i] -= a * q[i];
                rr_new += r[i] * r[i];
            }
            const double beta = rr_new / rr;
            rr = rr_new;
            for (size_t i = 0; i < N; ++i) p[i] = r[i] + beta * p[i];
        }
        std::vector<double> xs(m_x.size());
        for (size_t i = 0; i < m_x.size(); ++i) {
            m_v[i] += x[i];
            xs[i] = m_x[i] + dt * m_v[i];
        }
        strainLimit(xs, held);
        std::vector<VertexPlane> planes;
        collide(xs, dt, planes);
        m_held = planes;
        for (size_t i = 0; i < m_x.size(); ++i) {
            m_v[i] = (xs[i] - m_x[i]) / dt;
            m_x[i] = xs[i];
        }
        // No velocity into the surface where a vertex met it.
        for (const VertexPlane& vp : planes) {
            double* v = &m_v[3 * (size_t)vp.v];
            const double vn = v[0] * vp.n[0] + v[1] * vp.n[1] + v[2] * vp.n[2];
            if (vn < 0)
                for (int q = 0; q < 3; ++q) v[q] -= vn * vp.n[q];
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

    // Held vertices do not move (infinite mass); the free end of a spring takes the whole correction.
    void strainLimit(std::vector<double>& x, const std::vector<char>& held)
    {
        for (int pass = 0; pass < 8; ++pass) {
            std::vector<double> corr(x.size(), 0);
            std::vector<int> cnt(x.size() / 3, 0);
            for (const Spring& s : m_springs) {
                double len = dist(&x[3 * (size_t)s.a], &x[3 * (size_t)s.b]), max_len = 1.05 * s.rest;
                if (len <= max_len || len < 1e-12) continue;
                const bool ha = held[(size_t)s.a] != 0, hb = held[(size_t)s.b] != 0;
                if (ha && hb) continue;
                double c = (ha || hb ? 1.0 : 0.5) * (len - max_len) / len;
                for (int q = 0; q < 3; ++q) {
                    double d = x[3 * (size_t)s.b + q] - x[3 * (size_t)s.a + q];
                    if (!ha) corr[3 * (size_t)s.a + q] += c * d;
                    if (!hb) corr[3 * (size_t)s.b + q] -= c * d;
                }
                ++cnt[(size_t)s.a];
                ++cnt[(size_t)s.b];
            }
            for (size_t i = 0; i < cnt.size(); ++i)
                if (cnt[i])
                    for (int q = 0; q < 3; ++q) x[3 * i + q] += corr[3 * i + q] / cnt[i];
        }
    }

    // One contact constraint on a vertex's displacement D over the step: D . n >= r.
    struct VertexPlane {
        uint32_t v;
        double n[3], r;
    };

    // The per-triangle CCD of the cloth's motion x0 -> x0 + D (every triangle that can reach a
    // collider), with the kind of answer each gives:
    //  - HIT at toi in (0, dt]: the triangle's vertices are moved back to their positions at the
    //    toi (D scaled by toi / dt, the smallest factor over the vertex's triangles): at its first
    //    time of impact the whole triangle is at the margin, never inside;
    //  - PENETRATING (within the margin at the start of the step, e.g. resting on the surface):
    //    each contact becomes "D . n >= r" on the triangle's vertices (no motion into the surface;
    //    r pushes a vertex back to half the margin when it started closer than that).
    // Returns the number of answers that changed D by more than kStill (10 um: a vertex stopped
    // within 10 um past its time of impact is 1% of the margin inside it).
    int sweep(const std::vector<double>& x0, std::vector<double>& D, double dt, std::vector<VertexPlane>& planes, bool freeze)
    {
        const MeshData& mesh = *bodies[0].mesh;
        const int nv = mesh.vertexCount();
        sdfccd_QueryParams params = sdfccd_default_query_params();
        params.method = m_opt.method;
        params.subdivision = m_opt.subdivision ? 1 : 0;
        params.margin = kMargin;
        std::vector<double> scale(nv, 1.0);
        std::vector<sdfccd_Contact> buf(32);
        size_t planes_before = planes.size();
        int changed = 0;
        for (const Collider& c : colliders) {
            // World = collider frame shifted by p (no rotation in this scene): positions in its frame.
            std::vector<sdfccd_Vec3> va((size_t)nv), vb((size_t)nv);
            for (int i = 0; i < nv; ++i) {
                const double* a = &x0[3 * (size_t)i];
                const double* d = &D[3 * (size_t)i];
                va[(size_t)i] = sdfccd_Vec3{ a[0] - c.frame.p[0], a[1] - c.frame.p[1], a[2] - c.frame.p[2] };
                vb[(size_t)i] = sdfccd_Vec3{ va[(size_t)i].x + d[0], va[(size_t)i].y + d[1], va[(size_t)i].z + d[2] };
            }
            sdfccd_QueryResult res;
            auto t0 = std::chrono::steady_clock::now();
            sdfccd_Status st = sdfccd_query_mesh_linear(c.ccd, nullptr, mesh.handle, va.data(), vb.data(), 0, dt, &params, nullptr, 0, &res);
            ++m_cost.ccd_queries;
            if (st == SDFCCD_OK) m_cost.triangles_tested += res.triangles_tested;
            else ++m_cost.query_errors;
            if (st != SDFCCD_OK || !res.hit) {
                m_cost.ccd_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                continue;
            }
            ++m_cost.hits;
            for (int t = 0; t < mesh.triangleCount(); ++t) {
                sdfccd_Vec3 s0[3], s1[3];
                uint32_t tv[3];
                double reach = 0, phi_min = 1e300;
                for (int k = 0; k < 3; ++k) {
                    tv[k] = mesh.f[3 * (size_t)t + k];
                    s0[k] = va[tv[k]];
                    s1[k] = vb[tv[k]];
                    const double* d = &D[3 * (size_t)tv[k]];
                    reach = std::max(reach, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
                    double phi;
                    sdfccd_sdf_eval(c.ccd, s0[k], &phi, nullptr);
                    phi_min = std::min(phi_min, phi);
                }
                double edge = 0;
                for (int k = 0; k < 3; ++k) {
                    const sdfccd_Vec3& a = s0[k];
                    const sdfccd_Vec3& b = s0[(k + 1) % 3];
                    edge = std::max(edge, std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z)));
                }
                if (phi_min > reach + edge + kMargin) continue; // cannot reach the surface this step
                sdfccd_QueryResult tr;
                if (sdfccd_query_triangle_linear(c.ccd, nullptr, s0, s1, 0, dt, &params, buf.data(), (int32_t)buf.size(), &tr) != SDFCCD_OK) {
                    ++m_cost.query_errors;
                    continue;
                }
                if (!tr.hit) continue;
                if (freeze && tr.state != SDFCCD_STATE_PENETRATING) {
                    // Last resort after the iteration cap: a triangle that still reaches the
                    // surface inside the step does not move this step.
                    for (uint32_t v : tv) {
                        const double* d = &D[3 * (size_t)v];
                        if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > kStill * kStill) ++changed;
                        scale[v] = 0;
                    }
                    continue;
                }
                if (tr.state != SDFCCD_STATE_PENETRATING && tr.toi > 0) {
                    const double f = std::max(0.0, std::min(1.0, tr.toi / dt));
                    double moved = 0;
                    for (uint32_t v : tv) {
                        scale[v] = std::min(scale[v], f);
                        const double* d = &D[3 * (size_t)v];
                        moved = std::max(moved, (1 - f) * std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
                    }
                    if (moved > kStill) ++changed;
                }
                for (int k = 0; k < tr.contact_count; ++k) {
                    const sdfccd_Contact& ct = buf[(size_t)k];
                    for (uint32_t v : tv) {
                        VertexPlane vp;
                        vp.v = v;
                        vp.n[0] = ct.normal.x;
                        vp.n[1] = ct.normal.y;
                        vp.n[2] = ct.normal.z;
                        vp.r = tr.state == SDFCCD_STATE_PENETRATING ? std::max(0.0, 0.5 * kMargin - ct.distance) : 0.0;
                        planes.push_back(vp);
                    }
                }
            }
            m_cost.ccd_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        // Vertices of triangles that hit: their positions at the (earliest) time of impact.
        for (int v = 0; v < nv; ++v)
            if (scale[(size_t)v] < 1)
                for (int q = 0; q < 3; ++q) D[3 * (size_t)v + q] *= scale[(size_t)v];
        // Contacts of triangles within the margin at the start: no motion into the surface (a
        // vertex stopped at a time of impact loses what is left of its inward part too).
        for (int pass = 0; pass < 4; ++pass)
            for (size_t i = planes_before; i < planes.size(); ++i) {
                const VertexPlane& vp = planes[i];
                double* d = &D[3 * (size_t)vp.v];
                const double dn = d[0] * vp.n[0] + d[1] * vp.n[1] + d[2] * vp.n[2];
                if (dn >= vp.r) continue;
                for (int q = 0; q < 3; ++q) d[q] += (vp.r - dn) * vp.n[q];
                if (vp.r - dn > kStill && pass == 0) ++changed;
            }
        return changed;
    }

    // The collision response: the vertices' displacements over the step are cut back until no
    // triangle reaches the surface (see sweep); the last word is a freeze of what still hits.
    // Returns the contact planes met (their normals remove the inward velocity afterwards).
    void collide(std::vector<double>& xs, double dt, std::vector<VertexPlane>& planes)
    {
        const size_t n = m_x.size();
        std::vector<double> D(n);
        for (size_t i = 0; i < n; ++i) D[i] = xs[i] - m_x[i];
        m_cost.contacts = 0;
        planes.clear();
        int iter = 0;
        size_t last_pass = 0; // the contacts of the last pass are the step's contacts
        for (; iter < kMaxSweeps; ++iter) {
            last_pass = planes.size();
            if (sweep(m_x, D, dt, planes, false) == 0) break;
        }
        if (iter == kMaxSweeps) {
            ++m_cost.freezes;
            while (sweep(m_x, D, dt, planes, true) > 0 && iter++ < 2 * kMaxSweeps) {
            }
        }
        m_cost.contacts = (int)(planes.size() - last_pass);
        for (size_t i = 0; i < n; ++i) xs[i] = m_x[i] + D[i];
    }

    Options m_opt;
    StepCost m_cost;
    std::vector<sdfccd_SdfId> m_owned;
    sdfccd_MeshId m_exact{};
    std::vector<double> m_x, m_v;
    std::vector<Spring> m_springs;
    std::vector<VertexPlane> m_held; // the contacts of the last step: their vertices stick
    std::vector<char> m_was_held, m_planes_held;    // per vertex: held in the last step
};

Scene* createCloth(const Options& opt) { return built(new Cloth(opt)); }

} // namespace

void appendClothScenes(std::vector<SceneEntry>& t)
{
    t.push_back({ "cloth", "Fig. 9: a mass-spring cloth over the bunny SDF, 10 ms steps (C ABI, per-vertex motion)", createCloth, 300, 0.01 });
    t.push_back({ "cloth-1ms", "Fig. 9: the same cloth at 1 ms steps", createCloth, 1500, 0.001 });
}

} // namespace scenes
