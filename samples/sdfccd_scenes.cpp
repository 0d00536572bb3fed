// SPDX-License-Identifier: MIT
// sdfccd_scenes: runs one named scene headless and prints what it measured.
//
//   sdfccd_scenes --list
//   sdfccd_scenes NAME [--method fwgss|fw|dcd|certified] [--no-subdivision] [--steps N] [--dt S]
//                 [--csv FILE] [--snapshot DIR] [--precision float|double] [--stock] [--quick]
//                 [--margin M] [--guard T] [--solver-iterations N] [--batch-threads N] [--data DIR]
//                 [--check KEY=LIMIT,...] [--quiet] [--table4] [--inject-nan STEP[,KIND]]
//
// The Bullet scenes run the bridge's Config(); --margin M, --guard T (Config::guard_tolerance, the
// guarantee; 0: off; off with --method dcd) and --batch-threads N (Config::batch_threads) set its
// physical options, --solver-iterations N the scene's btContactSolverInfo::m_numIterations.
// --table4 adds the paper's Table 4 figures (the CCD of the coming step through the C ABI, timed,
// up to the first contact; see runner.h) as a "table4" line of the summary.
// The Bullet build (float or double btScalar) is a separate library, so this program is built
// twice: sdfccd_scenes (float Bullet) and sdfccd_scenes_f64 (double). --precision runs the
// sibling executable with the same arguments when it names the other one.
//
// --check evaluates limits on the summary and exits 1 on a violation (the stability tests). Every
// key needs a number. A run that met a non-finite position, velocity, SDF value or energy fails
// every check (and exits 1 even without --check); a failed measurement query exits 2.
//   max_pen=M       max penetration over the run <= M (m)
//   max_pen_ccd=M   the same against the SDF the CCD is given (a grid's own field) <= M (m)
//   min_max_pen=M   max penetration >= M (asserts that a method fails)
//   fails=M         max penetration > M or at least one tunnelled body (a method fails)
//   tunnelled=N     tunnelled bodies <= N;  min_tunnelled=N  >= N
//   rest_speed=V    max vertex-speed bound over the last second <= V (m/s)
//   rest_drift=D    max centre displacement over the last second <= D (m)
//   moving=N        bodies still moving (> 0.05 m/s) at the end <= N
//   energy_gain=E   largest energy gain in one step <= E (J)
//   contact=1       some sample came within 1 mm (contact=0: none did)
//   hit=N           at least N CCD queries found contact (bridge: pair-steps with contact)
//   queries=N       at least N CCD queries were made (the pipeline ran; for methods that never hit)
//   query_errors=N  at most N CCD queries failed; without this key every check implies query_errors=0
//
// --inject-nan STEP[,KIND] is a test hook: after step STEP the runner puts a NaN into what it
// measures (KIND position: the first active body's centre (default); velocity: the first rigid
// body's linear velocity; energy; phi: an SDF value; query: a measured point, so the measurement
// query fails and the runner exits 2). The ctests scenes.inject_nan.* prove the checks see it.
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

#include "sdfccd_bullet/config.h"
#include "scenes/runner.h"
#include "scenes/scene.h"

#ifndef SDFCCD_DATA_DIR
#define SDFCCD_DATA_DIR "data"
#endif

namespace {

void usage(std::FILE* f)
{
    std::fprintf(f,
                 "usage: sdfccd_scenes --list\n"
                 "       sdfccd_scenes NAME [--method fwgss|fw|dcd|certified] [--no-subdivision] [--steps N] [--dt S]\n"
                 "                     [--csv FILE] [--snapshot DIR] [--precision float|double] [--stock] [--quick]\n"
                 "                     [--margin M] [--guard T] [--solver-iterations N] [--batch-threads N] [--data DIR]\n"
                 "                     [--check KEY=LIMIT,...] [--quiet] [--table4]\n"
                 "                     [--inject-nan STEP[,position|velocity|energy|phi|query]]  (test hook)\n"
                 "check keys: max_pen max_pen_ccd min_max_pen fails tunnelled min_tunnelled rest_speed rest_drift moving energy_gain\n"
                 "            contact hit queries query_errors (see samples/sdfccd_scenes.cpp)\n");
}

// Runs the sibling build (sdfccd_scenes <-> sdfccd_scenes_f64) with the same arguments.
int execSibling(const char* want, char** argv)
{
    char self[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0) {
        std::fprintf(stderr, "sdfccd_scenes: cannot find my own path to run the %s build\n", want);
        return 2;
    }
    self[n] = 0;
    std::string dir(self);
    dir = dir.substr(0, dir.find_last_of('/') + 1);
    std::string exe = dir + (std::strcmp(want, "double") == 0 ? "sdfccd_scenes_f64" : "sdfccd_scenes");
    execv(exe.c_str(), argv);
    std::fprintf(stderr, "sdfccd_scenes: cannot run %s (%s): was the %s Bullet build configured?\n", exe.c_str(), std::strerror(errno), want);
    return 2;
}

} // namespace

int main(int argc, char** argv)
{
    using namespace scenes;
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (std::strcmp(argv[1], "--list") == 0) {
        for (const SceneEntry& e : sceneTable()) std::printf("%-18s %5d steps of %.4g s  %s\n", e.name, e.steps, e.dt, e.summary);
        return 0;
    }
    if (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
        usage(stdout);
        return 0;
    }
    Options opt;
    opt.data_dir = std::getenv("SDFCCD_DATA_DIR") ? std::getenv("SDFCCD_DATA_DIR") : SDFCCD_DATA_DIR;
    RunConfig cfg;
    std::string name = argv[1], check, precision = SDFCCD_BULLET_PRECISION_NAME;
    int steps = -1;
    double dt = -1;
    bool quiet = false;
    for (int i = 2; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&](const char* what) -> const char* {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "sdfccd_scenes: %s needs %s\n", a.c_str(), what);
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--method") {
            if (!parseMethod(value("a method"), &opt.method)) {
                std::fprintf(stderr, "sdfccd_scenes: unknown method '%s'\n", argv[i]);
                return 2;
            }
        } else if (a == "--no-subdivision") opt.subdivision = false;
        else if (a == "--steps") steps = std::atoi(value("a count"));
        else if (a == "--dt") dt = std::atof(value("seconds"));
        else if (a == "--csv") cfg.csv = value("a file");
        else if (a == "--snapshot") cfg.snapshot = value("a folder");
        else if (a == "--precision") precision = value("float or double");
        else if (a == "--stock") opt.stock = true;
        else if (a == "--quick") opt.quick = true;
        else if (a == "--margin") opt.margin = std::atof(value("metres"));
        else if (a == "--batch-threads") opt.batch_threads = std::atoi(value("a thread count"));
        else if (a == "--solver-iterations") opt.solver_iterations = std::atoi(value("a count"));
        else if (a == "--guard") opt.guard = std::atof(value("metres (0: off)"));
        else if (a == "--data") opt.data_dir = value("a folder");
        else if (a == "--check") check = value("limits");
        else if (a == "--quiet") quiet = true;
        else if (a == "--table4") cfg.probe = true;
        else if (a == "--inject-nan") {
            std::string v = value("STEP[,KIND]");
            size_t comma = v.find(',');
            const std::string step = v.substr(0, comma);
            char* end = nullptr;
            const long n = std::strtol(step.c_str(), &end, 10);
            cfg.inject_step = step.empty() || *end != 0 || n > INT_MAX ? -1 : (int)n;
            if (comma != std::string::npos) cfg.inject_kind = v.substr(comma + 1);
            const std::string k = cfg.inject_kind;
            if (cfg.inject_step < 0 || (k != "position" && k != "velocity" && k != "energy" && k != "phi" && k != "query")) {
                std::fprintf(stderr, "sdfccd_scenes: --inject-nan STEP[,position|velocity|energy|phi|query]\n");
                return 2;
            }
        }
        else {
            std::fprintf(stderr, "sdfccd_scenes: unknown option '%s'\n", a.c_str());
            usage(stderr);
            return 2;
        }
    }
    if (precision != "float" && precision != "double") {
        std::fprintf(stderr, "sdfccd_scenes: --precision float or double\n");
        return 2;
    }
    if (precision != SDFCCD_BULLET_PRECISION_NAME) return execSibling(precision.c_str(), argv);
    const SceneEntry* e = findScene(name);
    if (!e) {
        std::fprintf(stderr, "sdfccd_scenes: no scene '%s' (--list shows them)\n", name.c_str());
        return 2;
    }
    cfg.steps = steps > 0 ? steps : e->steps;
    cfg.dt = dt > 0 ? dt : e->dt;
    cfg.progress = !quiet;
    cfg.probe_params.method = opt.method;
    cfg.probe_params.subdivision = opt.subdivision ? 1 : 0;
    std::FILE* csv = nullptr;
    if (!cfg.csv.empty()) {
        csv = std::fopen(cfg.csv.c_str(), "w");
        if (!csv) {
            std::fprintf(stderr, "sdfccd_scenes: cannot write %s\n", cfg.csv.c_str());
            return 2;
        }
    }
    Summary s;
    {
        std::unique_ptr<Scene> scene(e->create(opt));
        if (!scene) {
            std::fprintf(stderr, "sdfccd_scenes: scene '%s' could not be built\n", name.c_str());
            if (csv) std::fclose(csv);
            return 2;
        }
        s = runScene(*scene, cfg, csv);
    }
    if (csv) std::fclose(csv);
    s.scene = name;
    s.method = methodName(opt.method);
    s.stock = opt.stock;
    s.subdivision = opt.subdivision;
    printSummary(s, stdout);
    if (sdfccd_byte_count() != 0) std::fprintf(stderr, "sdfccd_scenes: %lld bytes of sdfccd memory not freed\n", (long long)sdfccd_byte_count());
    if (!s.measure_error.empty()) {
        std::fprintf(stderr, "sdfccd_scenes: measurement failed at %s\n", s.measure_error.c_str());
        return 2;
    }
    if (!check.empty()) {
        std::string why;
        if (!checkSummary(s, check, &why)) {
            std::printf("CHECK FAILED (%s): %s\n", check.c_str(), why.c_str());
            return 1;
        }
        std::printf("check passed: %s\n", check.c_str());
    }
    if (s.non_finite_step >= 0) return 1;
    return sdfccd_byte_count() == 0 ? 0 : 1;
}
