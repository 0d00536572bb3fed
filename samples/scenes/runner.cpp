// SPDX-License-Identifier: MIT
// The measuring loop shared by the runner, the stability tests and the benchmark.
#include "runner.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "snapshot.h"

namespace scenes {

namespace {

const double kContactPhi = 1e-3; // a sample this close counts as touching (first contact)
const double kDeepPhi = -1e-3;   // deeper than the 1 mm collision margin

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// World positions of a body's samples, its centre last.
void worldSamples(const Body& b, std::vector<double>& out)
{
    int n = b.mesh->sampleCount();
    out.resize(3 * (size_t)n + 3);
    double c[3] = { 0, 0, 0 };
    if (b.deformable) {
        std::copy(b.world.begin(), b.world.begin() + 3 * (size_t)n, out.begin());
        int nv = b.mesh->vertexCount();
        for (int i = 0; i < nv; ++i)
            for (int k = 0; k < 3; ++k) c[k] += b.world[3 * (size_t)i + k] / nv;
    } else {
        for (int i = 0; i < n; ++i) b.frame.apply(&b.mesh->samples[3 * (size_t)i], &out[3 * (size_t)i]);
        for (int k = 0; k < 3; ++k) c[k] = b.frame.p[k];
    }
    for (int k = 0; k < 3; ++k) out[3 * (size_t)n + k] = c[k];
}

// The point of triangle (a, b, c) closest to p (Voronoi regions of the vertices, edges, face).
void closestOnTriangle(const double* p, const double* a, const double* b, const double* c, double* out)
{
    double ab[3], ac[3], ap[3];
    for (int k = 0; k < 3; ++k) {
        ab[k] = b[k] - a[k];
        ac[k] = c[k] - a[k];
        ap[k] = p[k] - a[k];
    }
    auto set = [&](double u, double v) { // out = a + u ab + v ac
        for (int k = 0; k < 3; ++k) out[k] = a[k] + u * ab[k] + v * ac[k];
    };
    const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) return set(0, 0);
    double bp[3], cp[3];
    for (int k = 0; k < 3; ++k) {
        bp[k] = p[k] - b[k];
        cp[k] = p[k] - c[k];
    }
    const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) return set(1, 0);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return set(d1 / (d1 - d3), 0);
    const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) return set(0, 1);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return set(0, d2 / (d2 - d6));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6)); // on edge bc
        for (int k = 0; k < 3; ++k) out[k] = b[k] + w * (c[k] - b[k]);
        return;
    }
    const double den = 1.0 / (va + vb + vc);
    set(vb * den, vc * den);
}

// Distance from p to a box (0 inside).
double boxDistance(const sdfccd_Aabb& b, const double* p)
{
    double lo[3] = { b.lo.x, b.lo.y, b.lo.z }, hi[3] = { b.hi.x, b.hi.y, b.hi.z }, d2 = 0;
    for (int k = 0; k < 3; ++k) {
        double e = std::max(std::max(lo[k] - p[k], p[k] - hi[k]), 0.0);
        d2 += e * e;
    }
    return std::sqrt(d2);
}

struct Measure {
    double min_phi = 1e300;
    double min_phi_ccd = 1e300;                  // against the SDF the CCD works on (a grid: its own field)
    int min_body = -1, min_collider = -1, min_sample = -1;
    double min_where[3] = { NAN, NAN, NAN };     // world position of the deepest sample
    int64_t deep = 0;
    std::vector<double> body_min;                // per body
    std::vector<std::vector<double>> sample_phi; // per body, per sample (for snapshots)
    std::vector<char> tunnelled;                 // per body, this step
    std::vector<std::array<double, 3>> centre;   // per body, after the last step (swept kill planes)
    std::string non_finite;                      // this step: the first non-finite position or SDF value met
    std::string error;                           // this step: the first measurement query that failed
    int inject = 0;                              // test hook (RunConfig::inject_kind): 1 NaN phi, 2 NaN query point
};

bool allFinite(const double* p, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(p[i])) return false;
    return true;
}

std::string bodyName(const Scene& scene, size_t bi) { return scene.bodies[bi].name + "#" + std::to_string(bi); }

void noteNonFinite(Measure& m, const std::string& what)
{
    if (m.non_finite.empty()) m.non_finite = what;
}

// A measurement query failed on finite points: the step's figures are not measurements.
void noteError(Measure& m, const char* call, const std::string& where)
{
    if (m.error.empty()) m.error = std::string(call) + " failed (" + where + "): " + sdfccd_last_error();
}

// Where each body's centre is now (before the first step: the swept kill planes' start).
void recordCentres(const Scene& scene, Measure& m)
{
    m.centre.resize(scene.bodies.size());
    std::vector<double> pts;
    for (size_t bi = 0; bi < scene.bodies.size(); ++bi) {
        worldSamples(scene.bodies[bi], pts);
        m.centre[bi] = { pts[pts.size() - 3], pts[pts.size() - 2], pts[pts.size() - 1] };
    }
}

void measure(Scene& scene, Measure& m)
{
    size_t nb = scene.bodies.size();
    m.min_phi = 1e300;
    m.min_phi_ccd = 1e300;
    m.min_body = m.min_collider = m.min_sample = -1;
    m.deep = 0;
    m.non_finite.clear();
    m.error.clear();
    m.body_min.assign(nb, 1e300);
    m.sample_phi.resize(nb);
    m.tunnelled.assign(nb, 0);
    for (size_t bi = 0; bi < nb; ++bi) m.sample_phi[bi].assign((size_t)scene.bodies[bi].mesh->sampleCount(), 1e300);
    std::vector<double> pts;
    for (size_t ci = 0; ci < scene.colliders.size(); ++ci) {
        const Collider& c = scene.colliders[ci];
        // Gather the samples of the bodies near this collider (mesh distances run as one batch).
        std::vector<sdfccd_Vec3> batch;
        std::vector<std::pair<size_t, size_t>> owner; // (body, first index in batch)
        for (size_t bi = 0; bi < nb; ++bi) {
            const Body& b = scene.bodies[bi];
            if (!b.active) continue;
            worldSamples(b, pts);
            if (!allFinite(pts.data(), pts.size())) {
                noteNonFinite(m, "position of " + bodyName(scene, bi));
                continue;
            }
            size_t n = pts.size() / 3;
            double lc[3];
            c.frame.applyInverse(&pts[3 * (n - 1)], lc);
            // Past the kill plane counts only over the collider's footprint (a body that leaves a
            // floor over its edge and falls has not tunnelled).
            const double blo[3] = { c.bounds.lo.x, c.bounds.lo.y, c.bounds.lo.z }, bhi[3] = { c.bounds.hi.x, c.bounds.hi.y, c.bounds.hi.z };
            auto overFootprint = [&](const double* local) {
                for (int k = 0; k < 3; ++k)
                    if (std::fabs(c.kill_normal[k]) < 0.5 && (local[k] < blo[k] || local[k] > bhi[k])) return false;
                return true;
            };
            const double* cur = &pts[3 * (n - 1)];
            if (!c.kill_swept) {
                if (overFootprint(lc) && dot3(cur, c.kill_normal) > c.kill_offset) m.tunnelled[bi] = 1;
            } else if (bi < m.centre.size() && c.exact.index1) {
                // The centre's path over the step, every 2 mm: deeper inside than the body's
                // half-thickness anywhere on it = it went through.
                const double* prev = m.centre[bi].data();
                double d[3] = { cur[0] - prev[0], cur[1] - prev[1], cur[2] - prev[2] };
                const int ns = (int)std::min(20000.0, std::ceil(std::sqrt(dot3(d, d)) / 0.002)) + 1;
                for (int j = 0; j <= ns && !m.tunnelled[bi]; ++j) {
                    double x[3], xl[3], phi = 1e300;
                    for (int k = 0; k < 3; ++k) x[k] = prev[k] + d[k] * j / ns;
                    c.frame.applyInverse(x, xl);
                    if (sdfccd_sdf_eval(c.exact, sdfccd_Vec3{ xl[0], xl[1], xl[2] }, &phi, nullptr) != SDFCCD_OK) {
                        noteError(m, "sdfccd_sdf_eval", "swept centre of " + bodyName(scene, bi) + " in " + c.name);
                        break;
                    }
                    if (!std::isfinite(phi)) {
                        noteNonFinite(m, "SDF value of " + c.name + " at the swept centre of " + bodyName(scene, bi));
                        break;
                    }
                    if (phi < -b.mesh->half_thickness) m.tunnelled[bi] = 1;
                }
            }
            double reach = b.deformable ? 1e300 : b.mesh->radius;
            if (boxDistance(c.bounds, lc) > reach + 0.05) continue;
            owner.push_back(std::make_pair(bi, batch.size()));
            for (size_t i = 0; i < n; ++i) {
                double l[3];
                c.frame.applyInverse(&pts[3 * i], l);
                batch.push_back(sdfccd_Vec3{ l[0], l[1], l[2] });
            }
        }
        if (batch.empty()) continue;
        if (m.inject == 2) { // test hook: a NaN point, so the query fails
            batch[0].x = NAN;
            m.inject = 0;
        }
        std::vector<double> phi(batch.size(), 1e300);
        if (c.exact_mesh.index1) {
            if (sdfccd_mesh_signed_distance(c.exact_mesh, batch.data(), (int32_t)batch.size(), 0, phi.data(), nullptr) != SDFCCD_OK) {
                noteError(m, "sdfccd_mesh_signed_distance", "samples in " + c.name);
                continue;
            }
        } else {
            bool failed = false;
            for (size_t i = 0; i < batch.size() && !failed; ++i)
                if (sdfccd_sdf_eval(c.exact, batch[i], &phi[i], nullptr) != SDFCCD_OK) failed = true;
            if (failed) {
                noteError(m, "sdfccd_sdf_eval", "samples in " + c.name);
                continue;
            }
        }
        if (m.inject == 1) { // test hook: a NaN SDF value
            phi[0] = NAN;
            m.inject = 0;
        }
        for (size_t i = 0; i < phi.size(); ++i)
            if (!std::isfinite(phi[i])) {
                noteNonFinite(m, "SDF value of " + c.name + " at a sample");
                break;
            }
        // The CCD's own SDF where it differs from the reference (a grid baked from a mesh): how
        // deep the samples are in the field the CCD was given, apart from the grid's own error.
        if (c.ccd.index1 && (c.exact_mesh.index1 || c.ccd.index1 != c.exact.index1 || c.ccd.generation != c.exact.generation)) {
            for (size_t k = 0; k < owner.size(); ++k) {
                size_t first = owner[k].second, end = k + 1 < owner.size() ? owner[k + 1].second : batch.size();
                for (size_t i = first; i + 1 < end; ++i) {
                    double p = 1e300;
                    if (sdfccd_sdf_eval(c.ccd, batch[i], &p, nullptr) != SDFCCD_OK) {
                        noteError(m, "sdfccd_sdf_eval", "samples in the CCD's SDF of " + c.name);
                        break;
                    }
                    if (!std::isfinite(p)) noteNonFinite(m, "SDF value of the CCD's SDF of " + c.name);
                    m.min_phi_ccd = std::min(m.min_phi_ccd, p);
                }
            }
        } else {
            for (size_t k = 0; k < owner.size(); ++k) {
                size_t first = owner[k].second, end = k + 1 < owner.size() ? owner[k + 1].second : batch.size();
                for (size_t i = first; i + 1 < end; ++i) m.min_phi_ccd = std::min(m.min_phi_ccd, phi[i]);
            }
        }
        for (size_t k = 0; k < owner.size(); ++k) {
            size_t bi = owner[k].first, first = owner[k].second;
            size_t end = k + 1 < owner.size() ? owner[k + 1].second : batch.size();
            size_t n = end - first - 1; // samples; the centre is last
            std::vector<double>& sp = m.sample_phi[bi];
            for (size_t i = 0; i < n; ++i) {
                double p = phi[first + i];
                sp[i] = std::min(sp[i], p);
                if (p < m.body_min[bi]) m.body_min[bi] = p;
                if (p < m.min_phi) {
                    m.min_phi = p;
                    m.min_body = (int)bi;
                    m.min_collider = (int)ci;
                    m.min_sample = (int)i;
                    const sdfccd_Vec3& l = batch[first + i];
                    const double lp[3] = { l.x, l.y, l.z };
                    c.frame.apply(lp, m.min_where);
                }
            }
            if (phi[end - 1] < -scene.bodies[bi].mesh->half_thickness) m.tunnelled[bi] = 1;
        }
        // The collider's sharp features: each rigid body's triangles at their points closest to
        // them (sample index -2 in the CSV). Both fields agree here (features are given for exact SDFs).
        if (c.feature_points.empty() || !c.exact.index1) continue;
        for (const auto& o : owner) {
            const Body& b = scene.bodies[o.first];
            if (b.deformable) continue;
            const MeshData& mesh = *b.mesh;
            std::vector<double> tri(mesh.v.size()); // vertices in the collider's frame
            for (int i = 0; i < mesh.vertexCount(); ++i) {
                double w[3];
                b.frame.apply(&mesh.v[3 * (size_t)i], w);
                c.frame.applyInverse(w, &tri[3 * (size_t)i]);
            }
            double centre[3];
            c.frame.applyInverse(b.frame.p, centre);
            for (size_t fi = 0; fi + 2 < c.feature_points.size(); fi += 3) {
                const double* fp = &c.feature_points[fi];
                const double d[3] = { fp[0] - centre[0], fp[1] - centre[1], fp[2] - centre[2] };
                if (dot3(d, d) > mesh.radius * mesh.radius * 1.01 + 1e-6) continue;
                for (int t = 0; t < mesh.triangleCount(); ++t) {
                    double q[3];
                    closestOnTriangle(fp, &tri[3 * (size_t)mesh.f[3 * (size_t)t]], &tri[3 * (size_t)mesh.f[3 * (size_t)t + 1]],
                                      &tri[3 * (size_t)mesh.f[3 * (size_t)t + 2]], q);
                    double p = 1e300;
                    if (sdfccd_sdf_eval(c.exact, sdfccd_Vec3{ q[0], q[1], q[2] }, &p, nullptr) != SDFCCD_OK) {
                        noteError(m, "sdfccd_sdf_eval", "feature points of " + c.name);
                        continue;
                    }
                    if (!std::isfinite(p)) {
                        noteNonFinite(m, "SDF value of " + c.name + " at a feature point");
                        continue;
                    }
                    if (p < kDeepPhi) ++m.deep;
                    m.min_phi_ccd = std::min(m.min_phi_ccd, p);
                    if (p < m.body_min[o.first]) m.body_min[o.first] = p;
                    if (p < m.min_phi) {
                        m.min_phi = p;
                        m.min_body = (int)o.first;
                        m.min_collider = (int)ci;
                        m.min_sample = -2;
                        c.frame.apply(q, m.min_where);
                    }
                }
            }
        }
    }
    for (size_t bi = 0; bi < nb; ++bi)
        for (double p : m.sample_phi[bi])
            if (p < kDeepPhi) ++m.deep;
    recordCentres(scene, m);
}

double speedBound(const Body& b, const std::vector<double>& prev_world, double dt)
{
    if (b.deformable) {
        double s = 0;
        for (size_t i = 0; i + 2 < b.world.size() && i + 2 < prev_world.size(); i += 3) {
            double d[3] = { b.world[i] - prev_world[i], b.world[i + 1] - prev_world[i + 1], b.world[i + 2] - prev_world[i + 2] };
            s = std::max(s, std::sqrt(dot3(d, d)) / dt);
        }
        return s;
    }
    return std::sqrt(dot3(b.v, b.v)) + std::sqrt(dot3(b.w, b.w)) * b.mesh->radius;
}

// Table 4's probe: the CCD of every body-collider pair on the motion of the coming step.
struct ProbeStats {
    double sum = 0, sum2 = 0, mn = 1e300, mx = 0, evals = 0;
    int64_t n = 0;
};

bool probeStep(Scene& scene, const RunConfig& cfg, Summary& s, ProbeStats& ps)
{
    sdfccd_QueryParams params = cfg.probe_params;
    params.margin = scene.ccd_margin;
    bool hit = false;
    std::vector<sdfccd_Contact> buf(64);
    for (const Body& b : scene.bodies) {
        if (!b.active || b.deformable || !b.mesh->handle.index1) continue;
        sdfccd_RigidMotion motion = sdfccd_default_rigid_motion();
        motion.pose = b.frame.toPose();
        double v[3];
        for (int k = 0; k < 3; ++k) v[k] = b.v[k] + scene.gravity[k] * cfg.dt;
        motion.linear_velocity = sdfccd_Vec3{ v[0], v[1], v[2] };
        motion.angular_velocity = sdfccd_Vec3{ b.w[0], b.w[1], b.w[2] };
        double speed = std::sqrt(dot3(v, v)), spin = std::sqrt(dot3(b.w, b.w));
        for (const Collider& c : scene.colliders) {
            if (!c.ccd.index1) continue;
            double lc[3];
            c.frame.applyInverse(b.frame.p, lc);
            if (boxDistance(c.bounds, lc) > b.mesh->radius + speed * cfg.dt + scene.ccd_margin + 0.05) continue;
            sdfccd_RigidMotion sm = sdfccd_default_rigid_motion();
            sm.pose = c.frame.toPose();
            sdfccd_QueryResult res;
            auto t0 = std::chrono::steady_clock::now();
            sdfccd_Status st = sdfccd_query_mesh(c.ccd, &sm, b.mesh->handle, &motion, 0, cfg.dt, &params, buf.data(), (int32_t)buf.size(), &res);
            s.probe_total_ms += 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            if (st != SDFCCD_OK) continue;
            s.probe_tri_tested += res.triangles_tested;
            s.probe_mesh_evals += res.sdf_evaluations;
            if (res.hit) hit = true;
            // Per triangle: those whose bounding sphere can come within the margin during the step.
            const MeshData& m = *b.mesh;
            for (int t = 0; t < m.triangleCount(); ++t) {
                sdfccd_Vec3 tri[3];
                double cen[3] = { 0, 0, 0 }, r = 0;
                for (int k = 0; k < 3; ++k) {
                    const double* p = &m.v[3 * (size_t)m.f[3 * t + k]];
                    tri[k] = sdfccd_Vec3{ p[0], p[1], p[2] };
                    for (int d = 0; d < 3; ++d) cen[d] += p[d] / 3;
                }
                for (int k = 0; k < 3; ++k) {
                    double d[3] = { tri[k].x - cen[0], tri[k].y - cen[1], tri[k].z - cen[2] };
                    r = std::max(r, std::sqrt(dot3(d, d)));
                }
                double wc[3], l[3], phi = -1e300; // a failed evaluation keeps the triangle (it is timed, not measured)
                b.frame.apply(cen, wc);
                c.frame.applyInverse(wc, l);
                sdfccd_sdf_eval(c.ccd, sdfccd_Vec3{ l[0], l[1], l[2] }, &phi, nullptr);
                double reach = r + speed * cfg.dt + spin * cfg.dt * (std::sqrt(dot3(cen, cen)) + r) + params.margin;
                if (phi > reach) continue;
                // The fastest of 3 identical runs (the machine is shared; the answer is deterministic).
                sdfccd_QueryResult tr;
                double us = 1e300;
                for (int rep = 0; rep < 3; ++rep) {
                    auto q0 = std::chrono::steady_clock::now();
                    sdfccd_query_triangle(c.ccd, &sm, tri, &motion, 0, cfg.dt, &params, buf.data(), (int32_t)buf.size(), &tr);
                    us = std::min(us, 1e6 * std::chrono::duration<double>(std::chrono::steady_clock::now() - q0).count());
                }
                ps.sum += us;
                ps.sum2 += us * us;
                ps.mn = std::min(ps.mn, us);
                ps.mx = std::max(ps.mx, us);
                ps.evals += (double)tr.sdf_evaluations;
                ++ps.n;
            }
        }
    }
    return hit;
}

} // namespace

Summary runScene(Scene& scene, const RunConfig& cfg, std::FILE* csv)
{
    Summary s;
    s.steps = cfg.steps;
    s.dt = cfg.dt;
    s.precision = scene.precision();
    s.description = scene.describe();
    s.body_count = (int)scene.bodies.size();
    if (csv)
        std::fprintf(csv, "step,time,min_phi,deep_samples,contacts,ccd_ms,step_ms,ccd_queries,hits,energy,max_speed,tunnelled,"
                     "b0_x,b0_y,b0_z,b0_vx,b0_vy,b0_vz,b0_w,deepest_sample,deepest_x,deepest_y,deepest_z,min_phi_ccd_sdf\n");
    Measure m;
    recordCentres(scene, m);
    std::vector<char> tunnelled(scene.bodies.size(), 0);
    int window = std::max(1, (int)std::lround(1.0 / cfg.dt));
    int window_start = std::max(0, cfg.steps - window);
    std::vector<std::array<double, 3>> ref;
    std::vector<std::vector<double>> prev_world(scene.bodies.size());
    double total_step = 0, prev_energy = scene.energy();
    s.energy_start = prev_energy;
    StepCost prev_cost = scene.cost();
    StepCost start_cost = prev_cost;
    double contacts_sum = 0;
    auto wall0 = std::chrono::steady_clock::now();
    auto last_progress = wall0;
    Snapshotter snap(cfg.snapshot);
    bool probe_done = false;
    ProbeStats ps;
    for (int i = 0; i < cfg.steps; ++i) {
        for (size_t bi = 0; bi < scene.bodies.size(); ++bi)
            if (scene.bodies[bi].deformable) prev_world[bi] = scene.bodies[bi].world;
        bool probing = cfg.probe && s.probe_steps >= 0 && !probe_done;
        if (probing) {
            probe_done = probeStep(scene, cfg, s, ps);
            ++s.probe_steps;
        }
        auto t0 = std::chrono::steady_clock::now();
        scene.step(i, cfg.dt);
        double step_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        total_step += step_s;
        StepCost c = scene.cost();
        double ccd_s = c.ccd_seconds - prev_cost.ccd_seconds;
        if (probing) s.probe_step_ms += 1e3 * (step_s - ccd_s);
        contacts_sum += c.contacts;
        if (i == cfg.inject_step) { // test hook (RunConfig::inject_step)
            m.inject = cfg.inject_kind == "phi" ? 1 : cfg.inject_kind == "query" ? 2 : 0;
            for (Body& b : scene.bodies) {
                if (!b.active) continue;
                if (cfg.inject_kind == "position") {
                    if (b.deformable) b.world[0] = NAN;
                    else b.frame.p[0] = NAN;
                    break;
                }
                if (cfg.inject_kind == "velocity" && !b.deformable) {
                    b.v[0] = NAN;
                    break;
                }
            }
        }
        measure(scene, m);
        if (!m.error.empty()) {
            s.measure_error = "step " + std::to_string(i) + ": " + m.error;
            break;
        }
        if (scene.sweptPenetration() > s.max_penetration) {
            s.max_penetration = scene.sweptPenetration();
            s.max_penetration_step = i;
            s.max_penetration_where = "inside the step (executed motion)";
        }
        if (m.min_phi_ccd < 1e299) s.max_penetration_ccd = std::max(s.max_penetration_ccd, std::max(0.0, -m.min_phi_ccd));
        if (m.min_phi < 1e299) {
            double pen = std::max(0.0, -m.min_phi);
            if (pen > s.max_penetration) {
                s.max_penetration = pen;
                s.max_penetration_step = i;
                s.max_penetration_where = scene.bodies[(size_t)m.min_body].name + "#" + std::to_string(m.min_body) + " in " +
                                          scene.colliders[(size_t)m.min_collider].name;
            }
            if (i == cfg.steps - 1) s.end_penetration = pen;
        }
        s.deep_samples += m.deep;
        bool first_contact_now = false;
        if (s.first_contact_step < 0 && m.min_phi <= kContactPhi) {
            s.first_contact_step = i;
            first_contact_now = true;
        }
        if (s.first_hit_step < 0) {
            s.ccd_ms_to_first_hit += 1e3 * ccd_s;
            s.step_ms_to_first_hit += 1e3 * step_s;
            if (c.hits > prev_cost.hits) s.first_hit_step = i;
        }
        int tun_now = 0;
        for (size_t bi = 0; bi < scene.bodies.size(); ++bi) {
            if (m.tunnelled[bi]) ++tun_now;
            if (m.tunnelled[bi] && !tunnelled[bi]) {
                tunnelled[bi] = 1;
                ++s.tunnelled;
                if (!s.tunnelled_names.empty()) s.tunnelled_names += ",";
                s.tunnelled_names += scene.bodies[bi].name + "#" + std::to_string(bi) + "@" + std::to_string(i);
            }
        }
        double e = scene.energy();
        if (i == cfg.inject_step && cfg.inject_kind == "energy") e = NAN;
        // Stop at the first non-finite value: later figures would be NaN-blind.
        std::string non_finite = m.non_finite;
        for (size_t bi = 0; bi < scene.bodies.size() && non_finite.empty(); ++bi) {
            const Body& b = scene.bodies[bi];
            if (b.active && !b.deformable && !(allFinite(b.v, 3) && allFinite(b.w, 3))) non_finite = "velocity of " + bodyName(scene, bi);
        }
        if (non_finite.empty() && std::isfinite(s.energy_start) && !std::isfinite(e)) non_finite = "energy";
        if (!non_finite.empty()) {
            s.non_finite_step = i;
            s.non_finite = non_finite;
            break;
        }
        if (!scene.injects(i) && std::isfinite(e) && std::isfinite(prev_energy)) s.energy_max_gain = std::max(s.energy_max_gain, e - prev_energy);
        prev_energy = e;
        double max_speed = 0;
        for (size_t bi = 0; bi < scene.bodies.size(); ++bi)
            if (scene.bodies[bi].active) max_speed = std::max(max_speed, speedBound(scene.bodies[bi], prev_world[bi], cfg.dt));
        if (i == window_start) {
            ref.resize(scene.bodies.size());
            for (size_t bi = 0; bi < scene.bodies.size(); ++bi) {
                const Body& b = scene.bodies[bi];
                std::vector<double> w;
                worldSamples(b, w);
                ref[bi] = { w[w.size() - 3], w[w.size() - 2], w[w.size() - 1] };
            }
        }
        if (i >= window_start) {
            s.rest_speed = std::max(s.rest_speed, max_speed);
            for (size_t bi = 0; bi < scene.bodies.size(); ++bi) {
                std::vector<double> w;
                worldSamples(scene.bodies[bi], w);
                double d[3] = { w[w.size() - 3] - ref[bi][0], w[w.size() - 2] - ref[bi][1], w[w.size() - 1] - ref[bi][2] };
                s.rest_drift = std::max(s.rest_drift, std::sqrt(dot3(d, d)));
            }
        }
        if (i == cfg.steps - 1) {
            for (size_t bi = 0; bi < scene.bodies.size(); ++bi)
                if (scene.bodies[bi].active && speedBound(scene.bodies[bi], prev_world[bi], cfg.dt) > 0.05) ++s.moving_at_end;
        }
        if (csv) {
            std::fprintf(csv, "%d,%.6f,%.6g,%lld,%d,%.4f,%.4f,%lld,%lld,%.6g,%.4g,%d", i, (i + 1) * cfg.dt,
                         m.min_phi < 1e299 ? m.min_phi : NAN, (long long)m.deep, c.contacts, 1e3 * ccd_s, 1e3 * step_s,
                         (long long)c.ccd_queries, (long long)c.hits, e, max_speed, tun_now);
            // The first body's centre and velocity (per-step traces of single-body scenes).
            double b0[7] = { NAN, NAN, NAN, NAN, NAN, NAN, NAN };
            if (!scene.bodies.empty()) {
                const Body& b = scene.bodies[0];
                std::vector<double> w;
                worldSamples(b, w);
                for (int k = 0; k < 3; ++k) {
                    b0[k] = w[w.size() - 3 + (size_t)k];
                    b0[3 + k] = b.v[k];
                }
                b0[6] = std::sqrt(dot3(b.w, b.w));
            }
            std::fprintf(csv, ",%.6f,%.6f,%.6f,%.5g,%.5g,%.5g,%.5g", b0[0], b0[1], b0[2], b0[3], b0[4], b0[5], b0[6]);
            // Where the deepest sample of the step is (its index in its body's samples: vertices first).
            std::fprintf(csv, ",%d,%.6f,%.6f,%.6f,%.6g\n", m.min_sample, m.min_where[0], m.min_where[1], m.min_where[2],
                         m.min_phi_ccd < 1e299 ? m.min_phi_ccd : NAN);
        }
        if (snap.enabled() && (first_contact_now || i == cfg.steps - 1))
            snap.write(scene, m.sample_phi, first_contact_now ? "first_contact" : "end", i);
        prev_cost = c;
        auto now = std::chrono::steady_clock::now();
        if (cfg.progress && std::chrono::duration<double>(now - last_progress).count() > 2.0) {
            last_progress = now;
            std::fprintf(stderr, "\r  step %d/%d  max pen %.4g m  %.2f ms/step   ", i + 1, cfg.steps, s.max_penetration,
                         1e3 * total_step / (i + 1));
        }
    }
    if (cfg.progress && std::chrono::duration<double>(last_progress - wall0).count() > 0) std::fprintf(stderr, "\n");
    if (cfg.probe) {
        if (!probe_done) s.probe_steps = -1;
        s.probe_tri_count = ps.n;
        if (ps.n > 0) {
            s.probe_tri_mean_us = ps.sum / ps.n;
            s.probe_tri_min_us = ps.mn;
            s.probe_tri_max_us = ps.mx;
            s.probe_tri_sd_us = std::sqrt(std::max(0.0, ps.sum2 / ps.n - s.probe_tri_mean_us * s.probe_tri_mean_us));
            s.probe_tri_evals_mean = ps.evals / ps.n;
        }
    }
    StepCost end = scene.cost();
    s.energy_end = prev_energy;
    s.contacts_per_step = cfg.steps ? contacts_sum / cfg.steps : 0;
    s.step_ms = cfg.steps ? 1e3 * total_step / cfg.steps : 0;
    s.ccd_ms = cfg.steps ? 1e3 * (end.ccd_seconds - start_cost.ccd_seconds) / cfg.steps : 0;
    s.ccd_queries = end.ccd_queries - start_cost.ccd_queries;
    s.hits = end.hits - start_cost.hits;
    s.query_errors = end.query_errors - start_cost.query_errors;
    if (cfg.steps && end.sdf_evaluations >= 0 && start_cost.sdf_evaluations >= 0)
        s.sdf_evals_per_step = (double)(end.sdf_evaluations - start_cost.sdf_evaluations) / cfg.steps;
    s.freezes = end.freezes - start_cost.freezes;
    return s;
}

void printSummary(const Summary& s, std::FILE* out)
{
    std::fprintf(out, "scene %s  (%s, btScalar %s, %d steps of %.4g s)\n", s.scene.c_str(), s.description.c_str(),
                 s.precision.c_str(), s.steps, s.dt);
    if (s.non_finite_step >= 0)
        std::fprintf(out, "  NON-FINITE          %s at step %d: the run stopped there and every check fails\n", s.non_finite.c_str(),
                     s.non_finite_step);
    if (!s.measure_error.empty())
        std::fprintf(out, "  MEASUREMENT ERROR   %s: the run stopped there (exit 2)\n", s.measure_error.c_str());
    std::fprintf(out, "  max_penetration_m   %.6f  (step %d%s%s)\n", s.max_penetration, s.max_penetration_step,
                 s.max_penetration_where.empty() ? "" : ", ", s.max_penetration_where.c_str());
    std::fprintf(out, "  max_pen_ccd_sdf_m   %.6f  (the same samples against the SDF the CCD is given: differs where it is a grid)\n",
                 s.max_penetration_ccd);
    std::fprintf(out, "  end_penetration_m   %.6f\n", s.end_penetration);
    std::fprintf(out, "  deep_sample_steps   %lld  (samples deeper than 1 mm, summed over steps)\n", (long long)s.deep_samples);
    if (s.freezes > 0) std::fprintf(out, "  response_freezes    %lld  (steps whose collision response hit its iteration cap)\n", (long long)s.freezes);
    std::fprintf(out, "  first_contact_step  %d  (first sample within 1 mm)\n", s.first_contact_step);
    std::fprintf(out, "  first_hit_step      %d  (first CCD contact; ccd %.3f ms, steps %.3f ms up to it)\n", s.first_hit_step,
                 s.ccd_ms_to_first_hit, s.step_ms_to_first_hit);
    std::fprintf(out, "  tunnelled           %d%s%s\n", s.tunnelled, s.tunnelled_names.empty() ? "" : "  ", s.tunnelled_names.c_str());
    std::fprintf(out, "  rest_drift_m        %.6f  (max centre displacement over the last second)\n", s.rest_drift);
    std::fprintf(out, "  rest_speed_mps      %.6f  (max |v| + |w| r over the last second)\n", s.rest_speed);
    std::fprintf(out, "  moving_at_end       %d of %d\n", s.moving_at_end, s.body_count);
    std::fprintf(out, "  energy_J            start %.6g  end %.6g  max gain in one step %.6g\n", s.energy_start, s.energy_end,
                 s.energy_max_gain);
    std::fprintf(out, "  contacts_per_step   %.2f\n", s.contacts_per_step);
    std::fprintf(out, "  step_ms             %.4f\n", s.step_ms);
    std::fprintf(out, "  ccd_ms              %.4f  (%.1f%% of the step, %lld queries)\n", s.ccd_ms,
                 s.step_ms > 0 ? 100 * s.ccd_ms / s.step_ms : 0.0, (long long)s.ccd_queries);
    std::fprintf(out, "  ccd_hits            %lld  (queries that found contact; query errors %lld)\n", (long long)s.hits,
                 (long long)s.query_errors);
    if (s.sdf_evals_per_step >= 0) std::fprintf(out, "  sdf_evals_per_step  %.0f\n", s.sdf_evals_per_step);
    if (s.probe_steps != 0) {
        double share = s.probe_total_ms + s.probe_step_ms > 0 ? 100 * s.probe_total_ms / (s.probe_total_ms + s.probe_step_ms) : 0;
        std::fprintf(out, "  table4              steps %d  total_ms %.3f  runtime_pct %.1f  tri_tested %lld  per-triangle (%lld): mean_us %.2f "
                     "min_us %.2f max_us %.2f sd_us %.2f evals_mean %.1f  mesh_evals %lld\n",
                     s.probe_steps, s.probe_total_ms, share, (long long)s.probe_tri_tested, (long long)s.probe_tri_count, s.probe_tri_mean_us,
                     s.probe_tri_min_us, s.probe_tri_max_us, s.probe_tri_sd_us, s.probe_tri_evals_mean, (long long)s.probe_mesh_evals);
    }
}

bool checkSummary(const Summary& s, const std::string& spec, std::string* why)
{
    std::stringstream in(spec);
    std::string item;
    bool ok = true, errors_checked = false;
    std::ostringstream msg;
    // A run that met a non-finite value or a failed measurement measured nothing: every check fails.
    std::string broken;
    if (s.non_finite_step >= 0) broken = "non-finite " + s.non_finite + " at step " + std::to_string(s.non_finite_step);
    else if (!s.measure_error.empty()) broken = "measurement error at " + s.measure_error;
    if (!broken.empty()) msg << broken << "; ";
    while (std::getline(in, item, ',')) {
        if (item.empty()) continue;
        size_t eq = item.find('=');
        std::string key = item.substr(0, eq);
        char* end = nullptr;
        double lim = eq == std::string::npos ? NAN : std::strtod(item.c_str() + eq + 1, &end);
        if (eq == std::string::npos || end == item.c_str() + eq + 1 || *end != 0 || !std::isfinite(lim)) {
            msg << "check '" << item << "' needs KEY=NUMBER; ";
            ok = false;
            continue;
        }
        bool pass;
        double val;
        if (key == "max_pen") { val = s.max_penetration; pass = val <= lim; }
        else if (key == "max_pen_ccd") { val = s.max_penetration_ccd; pass = val <= lim; }
        else if (key == "min_max_pen") { val = s.max_penetration; pass = val >= lim; }
        else if (key == "tunnelled") { val = s.tunnelled; pass = val <= lim; }
        else if (key == "min_tunnelled") { val = s.tunnelled; pass = val >= lim; }
        else if (key == "fails") { val = s.max_penetration; pass = s.max_penetration > lim || s.tunnelled > 0; }
        else if (key == "rest_speed") { val = s.rest_speed; pass = val <= lim; }
        else if (key == "rest_drift") { val = s.rest_drift; pass = val <= lim; }
        else if (key == "moving") { val = s.moving_at_end; pass = val <= lim; }
        else if (key == "energy_gain") { val = s.energy_max_gain; pass = val <= lim; }
        else if (key == "contact" && (lim == 0 || lim == 1)) { val = s.first_contact_step; pass = (val >= 0) == (lim == 1); }
        else if (key == "hit") { val = (double)s.hits; pass = val >= lim; }
        else if (key == "queries") { val = (double)s.ccd_queries; pass = val >= lim; }
        else if (key == "query_errors") { val = (double)s.query_errors; pass = val <= lim; errors_checked = true; }
        else {
            msg << "unknown check '" << item << "'; ";
            ok = false;
            continue;
        }
        if (!broken.empty()) {
            ok = false;
            msg << key << ": not measured; ";
        } else if (!pass) {
            ok = false;
            msg << key << ": measured " << val << ", limit " << lim << "; ";
        }
    }
    // Failed CCD queries wrote no contacts: no check passes over them unless the spec allows some.
    if (!errors_checked && s.query_errors > 0) {
        ok = false;
        msg << "query_errors: measured " << s.query_errors << ", limit 0 (implied by every check); ";
    }
    if (why) *why = msg.str();
    return ok && broken.empty();
}

} // namespace scenes
