// SPDX-License-Identifier: MIT
// Grid files written by sdfccd load in Bullet: btSdfCollisionShape::initializeSDF accepts them and
// queryPoint agrees with our evaluator at random points. Compiled once per Bullet precision
// (pkg-config `bullet` = float, `bullet-float64` = double); tolerances depend on it because the
// float build stores the domain, cell size and inverse cell size as float (notes section 1).
#include <BulletCollision/CollisionShapes/btSdfCollisionShape.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "sdfccd/sdfccd.h"

#ifdef BT_USE_DOUBLE_PRECISION
static_assert(sizeof(btScalar) == 8, "BT_USE_DOUBLE_PRECISION must come with a double Bullet");
static const char* kPrecision = "double";
#else
static_assert(sizeof(btScalar) == 4, "the float Bullet build has a 4-byte btScalar");
static const char* kPrecision = "float";
#endif

static int g_failures = 0;
#define CHECK(cond, ...)                                                       \
    do {                                                                       \
        if (!(cond)) {                                                         \
            std::fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
            std::fprintf(stderr, __VA_ARGS__);                                 \
            std::fprintf(stderr, "\n");                                        \
            ++g_failures;                                                      \
        }                                                                      \
    } while (0)

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

static std::vector<char> read_file(const std::string& path)
{
    std::vector<char> data;
    FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return data;
    std::fseek(f, 0, SEEK_END);
    long n = std::ftell(f);
    std::fseek(f, 0, SEEK_SET);
    data.resize((size_t)n);
    if (std::fread(data.data(), 1, data.size(), f) != data.size()) data.clear();
    std::fclose(f);
    return data;
}

// Saves `grid`, loads the bytes into Bullet and compares queryPoint with sdfccd at `count`
// random points of the domain box enlarged by 10 % (so some fall outside).
static void compare(const char* name, sdfccd_SdfId grid, int count)
{
    std::string path = std::string(SDFCCD_TEST_TMP_DIR) + "/grid_bullet_" + kPrecision + "_" + name + ".cdf";
    sdfccd_Status st = sdfccd_save_grid(grid, path.c_str());
    CHECK(st == SDFCCD_OK, "%s: save: %s", name, sdfccd_last_error());
    std::vector<char> bytes = read_file(path);
    std::remove(path.c_str());
    CHECK(!bytes.empty(), "%s: cannot read back %s", name, path.c_str());
    sdfccd_GridInfo info;
    sdfccd_grid_get_info(grid, &info);
    CHECK((int64_t)bytes.size() == info.file_bytes, "%s: file size %zu, info says %lld", name, bytes.size(), (long long)info.file_bytes);

    btSdfCollisionShape shape;
    const bool ok = shape.initializeSDF(bytes.data(), (int)bytes.size());
    CHECK(ok, "%s: btSdfCollisionShape::initializeSDF rejected our file", name);
    if (!ok) return;

    const double ext[3] = { info.domain.hi.x - info.domain.lo.x, info.domain.hi.y - info.domain.lo.y, info.domain.hi.z - info.domain.lo.z };
    const double size = std::fmax(ext[0], std::fmax(ext[1], ext[2]));
    const double h[3] = { info.cell_size.x, info.cell_size.y, info.cell_size.z };
#ifdef BT_USE_DOUBLE_PRECISION
    const double tol_v = 1e-12 * size, tol_g = 1e-9, guard = 1e-12;
#else
    // float geometry: positions are located with a relative error of about 1e-7 of the domain
    // size, which moves phi by at most |grad| * 1e-7 * size; the gradient jumps across cell faces,
    // so points within 1e-5 of a face (in cell units) are not compared there.
    const double tol_v = 2e-6 * size, tol_g = 2e-3, guard = 1e-5;
#endif
    Rng rng{ 12345u + (uint64_t)count };
    int compared = 0, outside = 0;
    double max_dv = 0, max_dg = 0;
    for (int i = 0; i < count; ++i) {
        sdfccd_Vec3 p = { rng.uniform(info.domain.lo.x - 0.05 * ext[0], info.domain.hi.x + 0.05 * ext[0]),
                          rng.uniform(info.domain.lo.y - 0.05 * ext[1], info.domain.hi.y + 0.05 * ext[1]),
                          rng.uniform(info.domain.lo.z - 0.05 * ext[2], info.domain.hi.z + 0.05 * ext[2]) };
        // skip points whose cell (or inside/outside status) is ambiguous at this precision
        const double pc[3] = { p.x, p.y, p.z }, lo[3] = { info.domain.lo.x, info.domain.lo.y, info.domain.lo.z };
        bool near_face = false;
        for (int d = 0; d < 3; ++d) {
            const double u = (pc[d] - lo[d]) / h[d];
            near_face |= std::fabs(u - std::round(u)) < guard;
        }
        if (near_face) continue;
        double ours = 0;
        sdfccd_Vec3 og = { 0, 0, 0 };
        int32_t has = 0;
        sdfccd_grid_interpolate(grid, 0, p, &ours, &og, &has);
        btScalar dist = 0;
        btVector3 normal(0, 0, 0);
        const bool theirs = shape.queryPoint(btVector3((btScalar)p.x, (btScalar)p.y, (btScalar)p.z), dist, normal);
        CHECK(theirs == (has != 0), "%s: point (%g %g %g): Bullet has value %d, sdfccd %d", name, p.x, p.y, p.z, (int)theirs, has);
        if (!theirs || !has) { ++outside; continue; }
        const double dv = std::fabs((double)dist - ours);
        const double dg = std::fmax(std::fabs((double)normal.x() - og.x), std::fmax(std::fabs((double)normal.y() - og.y), std::fabs((double)normal.z() - og.z)));
        max_dv = std::fmax(max_dv, dv);
        max_dg = std::fmax(max_dg, dg);
        CHECK(dv <= tol_v, "%s: point (%g %g %g): Bullet %.12g, sdfccd %.12g", name, p.x, p.y, p.z, (double)dist, ours);
        CHECK(dg <= tol_g, "%s: point (%g %g %g): gradient differs by %g", name, p.x, p.y, p.z, dg);
        // our SDF evaluation equals the raw interpolation where both have a value
        double v;
        sdfccd_Vec3 g;
        sdfccd_sdf_eval(grid, p, &v, &g);
        CHECK(v == ours, "%s: eval %.17g vs interpolate %.17g", name, v, ours);
        ++compared;
    }
    std::printf("%s Bullet, %s: %d points compared (%d without value in both), max |dphi| %.3g, max |dgrad| %.3g\n", kPrecision, name, compared,
                outside, max_dv, max_dg);
    CHECK(compared > count / 5, "%s: only %d points compared", name, compared);
}

static sdfccd_MeshId load_mesh(const char* rel)
{
    std::string path = std::string(SDFCCD_DATA_DIR) + "/" + rel;
    sdfccd_MeshId m{ 0, 0 };
    sdfccd_Status st = sdfccd_load_mesh(path.c_str(), nullptr, &m);
    CHECK(st == SDFCCD_OK, "load %s: %s", path.c_str(), sdfccd_last_error());
    return m;
}

int main()
{
    // 1. Discregrid's box.obj at 8^3 (dense)
    sdfccd_MeshId box = load_mesh("discregrid/box.obj");
    sdfccd_GridDef def = sdfccd_default_grid_def();
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 8;
    sdfccd_SdfId g;
    CHECK(sdfccd_create_grid_from_mesh(box, &def, &g) == SDFCCD_OK, "%s", sdfccd_last_error());
    compare("box_r8", g, 3000);
    sdfccd_destroy_sdf(g);
    sdfccd_destroy_mesh(box);

    // 2. the bunny at 16^3 (dense, fitted asymmetric domain) and 7 x 11 x 9 cells
    sdfccd_MeshId bunny = load_mesh("bullet3/bunny.obj");
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 16;
    CHECK(sdfccd_create_grid_from_mesh(bunny, &def, &g) == SDFCCD_OK, "%s", sdfccd_last_error());
    compare("bunny_r16", g, 3000);
    sdfccd_destroy_sdf(g);
    def.resolution[0] = 7; def.resolution[1] = 11; def.resolution[2] = 9;
    CHECK(sdfccd_create_grid_from_mesh(bunny, &def, &g) == SDFCCD_OK, "%s", sdfccd_last_error());
    compare("bunny_7x11x9", g, 3000);
    sdfccd_destroy_sdf(g);

    // 3. a narrow-band (sparse) torus grid: culled cells have no value in both
    sdfccd_MeshId torus = load_mesh("bullet3/torus_textured.obj");
    def.resolution[0] = def.resolution[1] = def.resolution[2] = 24;
    def.fit_domain = 0;
    def.domain = sdfccd_Aabb{ { -1, -1, -1 }, { 1, 1, 1 } };
    def.band = 0.05;
    CHECK(sdfccd_create_grid_from_mesh(torus, &def, &g) == SDFCCD_OK, "%s", sdfccd_last_error());
    sdfccd_GridInfo info;
    sdfccd_grid_get_info(g, &info);
    CHECK(info.stored_cells < info.cell_count / 2, "band grid should be sparse (%lld of %lld)", (long long)info.stored_cells, (long long)info.cell_count);
    compare("torus_band_r24", g, 3000);
    sdfccd_destroy_sdf(g);
    sdfccd_destroy_mesh(torus);
    sdfccd_destroy_mesh(bunny);

    // 4. the two-field sparse density map, loaded and written back by sdfccd
    sdfccd_SdfId cdm;
    std::string cdm_path = std::string(SDFCCD_DATA_DIR) + "/sdf/generated/bullet3_bunny_r24_densitymap_s002.cdm";
    CHECK(sdfccd_load_grid(cdm_path.c_str(), &cdm) == SDFCCD_OK, "%s", sdfccd_last_error());
    compare("bunny_densitymap_resaved", cdm, 3000);
    sdfccd_destroy_sdf(cdm);

    // 5. an analytic torus sampled into a grid
    sdfccd_SdfId t;
    sdfccd_create_torus(0.4, 0.15, &t);
    def = sdfccd_default_grid_def();
    def.resolution[0] = 20; def.resolution[1] = 20; def.resolution[2] = 8;
    CHECK(sdfccd_create_grid_from_sdf(t, &def, &g) == SDFCCD_OK, "%s", sdfccd_last_error());
    compare("analytic_torus", g, 3000);
    sdfccd_destroy_sdf(g);
    sdfccd_destroy_sdf(t);

    CHECK(sdfccd_byte_count() == 0, "leak: %lld bytes", (long long)sdfccd_byte_count());
    if (g_failures) std::fprintf(stderr, "%d failures\n", g_failures);
    return g_failures ? EXIT_FAILURE : EXIT_SUCCESS;
}
