// SPDX-License-Identifier: MIT
// sdfccd_grid_vs_bullet: value + gradient of the same .cdf grid through sdfccd and through Bullet's
// own evaluator (btSdfCollisionShape::queryPoint, the double build), in one process, on the same
// points. Prints CSV: grid,resolution,pattern,evaluator,ns_per_point (median of the repeats),
// ratio (Bullet / this evaluator, from the same repeat), max_abs_diff (value against Bullet).
// Times are the thread's CPU time (CLOCK_THREAD_CPUTIME_ID), the evaluators taking turns on chunks.
//
//   sdfccd_grid_vs_bullet [--points N] [--repeats R] [--data DIR]
//
// Grids: the concave box of pybullet's example (data/sdf/concave_box_r32.cdf, 32^3) and a 64^3 torus
// (R 0.1, r 0.05), baked in process and saved to a temporary .cdf that both load. Patterns: `random` (uniform
// points in the domain: a random cell each time) and `walk` (a random walk of quarter-cell steps,
// coherent like the samples of a moving triangle). sdfccd is measured per point through the ABI
// (sdfccd_sdf_eval, one handle lookup each) and in batches of 256 (sdfccd_sdf_eval_batch).
#include <BulletCollision/CollisionShapes/btSdfCollisionShape.h>

#include <algorithm>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <time.h>

#include "sdfccd/sdfccd.h"

#ifndef BT_USE_DOUBLE_PRECISION
#error "sdfccd_grid_vs_bullet compares against the double Bullet build"
#endif

namespace {

struct Rng {
    uint64_t s;
    double uniform(double lo, double hi)
    {
        uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        return lo + (hi - lo) * (double)(z >> 11) * (1.0 / 9007199254740992.0);
    }
};

// This thread's CPU time (the machine is shared: time spent descheduled is not the evaluator's).
double now()
{
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

std::vector<char> read_all(const std::string& path)
{
    std::vector<char> data;
    FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return data;
    std::fseek(f, 0, SEEK_END);
    const long n = std::ftell(f);
    std::fseek(f, 0, SEEK_SET);
    data.resize(n > 0 ? (size_t)n : 0);
    if (std::fread(data.data(), 1, data.size(), f) != data.size()) data.clear();
    std::fclose(f);
    return data;
}

[[noreturn]] void die(const char* what)
{
    std::fprintf(stderr, "sdfccd_grid_vs_bullet: %s: %s\n", what, sdfccd_last_error());
    std::exit(1);
}

// Points strictly inside the domain (both evaluators answer there), shrunk by 1e-6 of the extent.
std::vector<sdfccd_Vec3> make_points(const sdfccd_GridInfo& info, bool walk, int n)
{
    const double lo[3] = { info.domain.lo.x, info.domain.lo.y, info.domain.lo.z };
    const double hi[3] = { info.domain.hi.x, info.domain.hi.y, info.domain.hi.z };
    double a[3], b[3], step[3];
    for (int d = 0; d < 3; ++d) {
        const double pad = 1e-6 * (hi[d] - lo[d]);
        a[d] = lo[d] + pad;
        b[d] = hi[d] - pad;
        step[d] = 0.25 * (hi[d] - lo[d]) / (double)info.resolution[d];
    }
    Rng rng{ walk ? 99u : 7u };
    std::vector<sdfccd_Vec3> pts((size_t)n);
    double p[3] = { 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2]) };
    for (int i = 0; i < n; ++i) {
        for (int d = 0; d < 3; ++d) {
            if (walk) {
                p[d] += rng.uniform(-step[d], step[d]);
                if (p[d] < a[d] || p[d] > b[d]) p[d] = 2.0 * (p[d] < a[d] ? a[d] : b[d]) - p[d];
            } else {
                p[d] = rng.uniform(a[d], b[d]);
            }
        }
        pts[(size_t)i] = { p[0], p[1], p[2] };
    }
    return pts;
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

void compare(const char* name, const std::string& path, int npoints, int repeats)
{
    sdfccd_SdfId grid;
    if (sdfccd_load_grid(path.c_str(), &grid) != SDFCCD_OK) die(path.c_str());
    sdfccd_GridInfo info;
    if (sdfccd_grid_get_info(grid, &info) != SDFCCD_OK) die("grid info");
    std::vector<char> bytes = read_all(path);
    btSdfCollisionShape shape;
    if (bytes.empty() || !shape.initializeSDF(bytes.data(), (int)bytes.size())) {
        std::fprintf(stderr, "sdfccd_grid_vs_bullet: Bullet did not load %s\n", path.c_str());
        std::exit(1);
    }
    for (int pattern = 0; pattern < 2; ++pattern) {
        const bool walk = pattern == 1;
        const std::vector<sdfccd_Vec3> pts = make_points(info, walk, npoints);
        std::vector<double> values(pts.size()), theirs(pts.size());
        std::vector<sdfccd_Vec3> grads(pts.size());
        std::vector<double> t_abi, t_batch, t_bullet, r_abi, r_batch;
        double sink = 0;
        for (int r = 0; r < repeats; ++r) {
            // The three evaluators take turns on chunks of 2048 points, so a change of the machine's
            // load hits all three alike (the machine is shared); at each turn they work on chunks a
            // third of the points apart, so none finds the cells another just brought into the cache.
            double bullet = 0, abi = 0, batch = 0;
            const size_t chunk = 2048, nchunks = (pts.size() + chunk - 1) / chunk;
            for (size_t k = 0; k < nchunks; ++k) {
                size_t c0 = k * chunk, c1 = std::min(pts.size(), c0 + chunk);
                double t = now();
                for (size_t i = c0; i < c1; ++i) {
                    btScalar dist = 0;
                    btVector3 normal(0, 0, 0);
                    shape.queryPoint(btVector3(pts[i].x, pts[i].y, pts[i].z), dist, normal);
                    theirs[i] = dist;
                    sink += normal.x();
                }
                bullet += now() - t;
                c0 = ((k + nchunks / 3) % nchunks) * chunk;
                c1 = std::min(pts.size(), c0 + chunk);
                t = now();
                for (size_t i = c0; i < c1; ++i)
                    if (sdfccd_sdf_eval(grid, pts[i], &values[i], &grads[i]) != SDFCCD_OK) die("eval");
                abi += now() - t;
                c0 = ((k + 2 * nchunks / 3) % nchunks) * chunk;
                c1 = std::min(pts.size(), c0 + chunk);
                t = now();
                for (size_t i = c0; i < c1; i += 256) {
                    const int32_t n = (int32_t)std::min<size_t>(256, c1 - i);
                    if (sdfccd_sdf_eval_batch(grid, &pts[i], n, &values[i], &grads[i]) != SDFCCD_OK) die("eval batch");
                }
                batch += now() - t;
            }
            const double per = 1e9 / (double)pts.size();
            t_bullet.push_back(bullet * per);
            t_abi.push_back(abi * per);
            t_batch.push_back(batch * per);
            r_abi.push_back(bullet / abi);
            r_batch.push_back(bullet / batch);
        }
        double max_diff = 0;
        for (size_t i = 0; i < pts.size(); ++i) max_diff = std::max(max_diff, std::fabs(values[i] - theirs[i]));
        const char* pat = walk ? "walk" : "random";
        const int res = info.resolution[0];
        std::printf("%s,%d,%s,bullet,%.1f,1.00,0\n", name, res, pat, median(t_bullet));
        std::printf("%s,%d,%s,sdfccd_eval,%.1f,%.2f,%.3g\n", name, res, pat, median(t_abi), median(r_abi), max_diff);
        std::printf("%s,%d,%s,sdfccd_eval_batch,%.1f,%.2f,%.3g\n", name, res, pat, median(t_batch), median(r_batch), max_diff);
        if (sink == 12345.678) std::printf("#\n");
    }
    sdfccd_destroy_sdf(grid);
}

std::string bake(sdfccd_SdfId (*make)(), int res, const char* file)
{
    sdfccd_SdfId source = make();
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = res;
    sdfccd_SdfId grid;
    if (sdfccd_create_grid_from_sdf(source, &def, &grid) != SDFCCD_OK) die("bake");
    const char* tmp = std::getenv("TMPDIR");
    std::string path = std::string(tmp && *tmp ? tmp : "/tmp") + "/" + file;
    if (sdfccd_save_grid(grid, path.c_str()) != SDFCCD_OK) die("save");
    sdfccd_destroy_sdf(grid);
    sdfccd_destroy_sdf(source);
    return path;
}

sdfccd_SdfId make_torus()
{
    sdfccd_SdfId t;
    if (sdfccd_create_torus(0.10, 0.05, &t) != SDFCCD_OK) die("torus");
    return t;
}

} // namespace

int main(int argc, char** argv)
{
    int npoints = 200000, repeats = 5;
    std::string data = SDFCCD_DATA_DIR;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--points") && i + 1 < argc) npoints = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--data") && i + 1 < argc) data = argv[++i];
        else {
            std::fprintf(stderr, "usage: sdfccd_grid_vs_bullet [--points N] [--repeats R] [--data DIR]\n");
            return 2;
        }
    }
    if (npoints < 256 || repeats < 1) {
        std::fprintf(stderr, "sdfccd_grid_vs_bullet: --points must be >= 256 and --repeats >= 1\n");
        return 2;
    }
    std::printf("grid,resolution,pattern,evaluator,ns_per_point,ratio_bullet_over_this,max_abs_diff_value\n");
    compare("concave_box", data + "/sdf/concave_box_r32.cdf", npoints, repeats);
    compare("torus", bake(make_torus, 64, "sdfccd_grid_vs_bullet_torus64.cdf"), npoints, repeats);
    return 0;
}
