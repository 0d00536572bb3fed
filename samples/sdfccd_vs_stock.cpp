// SPDX-License-Identifier: MIT
// sdfccd_vs_stock: the cost of a Bullet scene through the sdfccd bridge and through stock Bullet
// (the same SDF surface as a btBvhTriangleMeshShape against Bullet's GImpact algorithm), measured
// in the SAME process: both worlds are built from the same scene code and stepped alternately
// (bridge then stock on even steps, stock then bridge on odd ones), so both see the same machine
// load. Each repeat builds both worlds afresh; the summary row is the median over repeats.
//
//   sdfccd_vs_stock [NAME] [--steps N] [--repeats R] [--quick] [--batch-threads N] [--guard T] [--data DIR]
//
// --batch-threads N: the bridge runs each step's queries as batches on N threads (Config::batch_threads).
// --guard T: the bridge's Config::guard_tolerance (the guarantee; 0: off, to measure what it costs).
//
// NAME defaults to landscape (any Bullet scene of `sdfccd_scenes --list` works). Prints CSV:
//   repeat,bridge_ms,stock_ms,ratio,bridge_contact_ms,stock_contact_ms,contact_ratio,
//   bridge_sdf_evals,bridge_queries,bridge_skipped,contact_from_step
// *_ms are mean wall times per step (inside stepSimulation only); ratio = bridge / stock;
// contact_* are the same over the steps from the first one in which either world has a contact
// point (the free fall before it costs both almost nothing); bridge_sdf_evals and
// bridge_queries are per step (all SDF evaluations of the bridge's queries and its own; CCD plus
// discrete queries), bridge_skipped the CCD queries per step the bridge did not need to run.
// The last row is `median` (the median of each column over the repeats). Comment lines (#) give
// the scene, precision and the load average before and after. Timings are wall clock: on a
// shared machine compare the ratio, which both worlds share the load of.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "scenes/bullet_scene.h"
#include "scenes/scene.h"

#ifndef SDFCCD_DATA_DIR
#define SDFCCD_DATA_DIR "data"
#endif

namespace {

struct Row {
    double bridge_ms = 0, stock_ms = 0, ratio = 0, bridge_contact_ms = 0, stock_contact_ms = 0, contact_ratio = 0;
    double evals = 0, queries = 0, skipped = 0, contact_from = -1;
};

std::string loadAverage()
{
    std::FILE* f = std::fopen("/proc/loadavg", "r");
    if (!f) return "unknown";
    char buf[128] = { 0 };
    if (!std::fgets(buf, sizeof buf, f)) buf[0] = 0;
    std::fclose(f);
    std::string s(buf);
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    return s;
}

double median(std::vector<double> v)
{
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void printRow(const char* name, const Row& r)
{
    std::printf("%s,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.0f,%.2f,%.2f,%.0f\n", name, r.bridge_ms, r.stock_ms, r.ratio, r.bridge_contact_ms,
                r.stock_contact_ms, r.contact_ratio, r.evals, r.queries, r.skipped, r.contact_from);
}

} // namespace

int main(int argc, char** argv)
{
    using namespace scenes;
    std::string name = "landscape";
    Options opt;
    opt.data_dir = std::getenv("SDFCCD_DATA_DIR") ? std::getenv("SDFCCD_DATA_DIR") : SDFCCD_DATA_DIR;
    int steps = -1, repeats = 3;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&]() -> const char* {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "sdfccd_vs_stock: %s needs a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--steps") steps = std::atoi(value());
        else if (a == "--repeats") repeats = std::atoi(value());
        else if (a == "--quick") opt.quick = true;
        else if (a == "--data") opt.data_dir = value();
        else if (a == "--batch-threads") opt.batch_threads = std::atoi(value());
        else if (a == "--guard") opt.guard = std::atof(value());
        else if (a == "--help" || a == "-h") {
            std::printf("usage: sdfccd_vs_stock [NAME] [--steps N] [--repeats R] [--quick] [--batch-threads N] [--guard T] [--data DIR]\n");
            return 0;
        } else if (!a.empty() && a[0] != '-') name = a;
        else {
            std::fprintf(stderr, "sdfccd_vs_stock: unknown option '%s'\n", a.c_str());
            return 2;
        }
    }
    const SceneEntry* e = findScene(name);
    if (!e || repeats < 1) {
        std::fprintf(stderr, "sdfccd_vs_stock: no scene '%s' (sdfccd_scenes --list) or repeats < 1\n", name.c_str());
        return 2;
    }
    if (steps <= 0) steps = e->steps;
    const double dt = e->dt;
    std::printf("# scene %s, btScalar %s, %d steps of %.4g s, %d repeats; load average before: %s\n", name.c_str(),
                SDFCCD_BULLET_PRECISION_NAME, steps, dt, repeats, loadAverage().c_str());
    std::printf("repeat,bridge_ms,stock_ms,ratio,bridge_contact_ms,stock_contact_ms,contact_ratio,bridge_sdf_evals,bridge_queries,"
                "bridge_skipped,contact_from_step\n");
    std::vector<Row> rows;
    for (int r = 0; r < repeats; ++r) {
        Options ob = opt, os = opt;
        ob.stock = false;
        os.stock = true;
        std::unique_ptr<Scene> bridge_scene(e->create(ob)), stock_scene(e->create(os));
        BulletScene* bs = dynamic_cast<BulletScene*>(bridge_scene.get());
        if (!bs || !stock_scene || !dynamic_cast<BulletScene*>(stock_scene.get())) {
            std::fprintf(stderr, "sdfccd_vs_stock: scene '%s' could not be built or is not a Bullet scene\n", name.c_str());
            return 2;
        }
        const sdfccd_bullet::Stats s0 = bs->bridge()->stats();
        std::vector<double> tb((size_t)steps), ts((size_t)steps);
        int contact_from = -1;
        for (int i = 0; i < steps; ++i) {
            Scene* order[2] = { bridge_scene.get(), stock_scene.get() };
            if ((i + r) % 2) std::swap(order[0], order[1]);
            for (Scene* s : order) {
                auto t0 = std::chrono::steady_clock::now();
                s->step(i, dt);
                double ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                (s == bridge_scene.get() ? tb : ts)[(size_t)i] = ms;
            }
            if (contact_from < 0 && (bridge_scene->cost().contacts > 0 || stock_scene->cost().contacts > 0)) contact_from = i;
        }
        const sdfccd_bullet::Stats s1 = bs->bridge()->stats();
        Row row;
        double sb = 0, ss = 0, cb = 0, cs = 0;
        for (int i = 0; i < steps; ++i) {
            sb += tb[(size_t)i];
            ss += ts[(size_t)i];
            if (contact_from >= 0 && i >= contact_from) {
                cb += tb[(size_t)i];
                cs += ts[(size_t)i];
            }
        }
        row.bridge_ms = sb / steps;
        row.stock_ms = ss / steps;
        row.ratio = ss > 0 ? sb / ss : 0;
        const int nc = contact_from >= 0 ? steps - contact_from : 0;
        row.bridge_contact_ms = nc ? cb / nc : 0;
        row.stock_contact_ms = nc ? cs / nc : 0;
        row.contact_ratio = cs > 0 ? cb / cs : 0;
        row.evals = (double)(s1.sdf_evaluations + s1.own_evaluations - s0.sdf_evaluations - s0.own_evaluations) / steps;
        row.queries = (double)(s1.queries + s1.end_pose_queries - s0.queries - s0.end_pose_queries) / steps;
        row.skipped = (double)(s1.queries_skipped - s0.queries_skipped) / steps;
        row.contact_from = contact_from;
        rows.push_back(row);
        printRow(std::to_string(r + 1).c_str(), row);
        std::fflush(stdout);
    }
    Row m;
    auto col = [&](double Row::*f) {
        std::vector<double> v;
        for (const Row& r : rows) v.push_back(r.*f);
        return median(v);
    };
    m.bridge_ms = col(&Row::bridge_ms);
    m.stock_ms = col(&Row::stock_ms);
    m.ratio = col(&Row::ratio);
    m.bridge_contact_ms = col(&Row::bridge_contact_ms);
    m.stock_contact_ms = col(&Row::stock_contact_ms);
    m.contact_ratio = col(&Row::contact_ratio);
    m.evals = col(&Row::evals);
    m.queries = col(&Row::queries);
    m.skipped = col(&Row::skipped);
    m.contact_from = col(&Row::contact_from);
    printRow("median", m);
    std::printf("# load average after: %s\n", loadAverage().c_str());
    return 0;
}
