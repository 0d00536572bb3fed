// SPDX-License-Identifier: MIT
// Shared helpers of the scene library: meshes, frames, method names, the table lookup.
#include "scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace scenes {

const char* Scene::precision() const { return "n/a (no Bullet)"; }

MeshData::~MeshData()
{
    if (handle.index1) sdfccd_destroy_mesh(handle);
}

void MeshData::finish(int density)
{
    if (!handle.index1 && !f.empty()) {
        sdfccd_MeshDef def = sdfccd_default_mesh_def();
        def.vertices = v.data();
        def.vertex_count = (uint32_t)vertexCount();
        def.indices = f.data();
        def.triangle_count = (uint32_t)triangleCount();
        def.drop_degenerate = 1;
        if (sdfccd_create_mesh(&def, &handle) != SDFCCD_OK)
            std::fprintf(stderr, "sdfccd_scenes: mesh %s: %s\n", name.c_str(), sdfccd_last_error());
    }
    int nv = vertexCount();
    this->density = density;
    samplesFor(v.data(), samples);
    radius = 0;
    bounds.lo = sdfccd_Vec3{ 1e300, 1e300, 1e300 };
    bounds.hi = sdfccd_Vec3{ -1e300, -1e300, -1e300 };
    for (int i = 0; i < nv; ++i) {
        const double* p = &v[3 * i];
        radius = std::max(radius, std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]));
        bounds.lo.x = std::min(bounds.lo.x, p[0]);
        bounds.lo.y = std::min(bounds.lo.y, p[1]);
        bounds.lo.z = std::min(bounds.lo.z, p[2]);
        bounds.hi.x = std::max(bounds.hi.x, p[0]);
        bounds.hi.y = std::max(bounds.hi.y, p[1]);
        bounds.hi.z = std::max(bounds.hi.z, p[2]);
    }
    half_thickness = 0.5 * std::min(bounds.hi.x - bounds.lo.x, std::min(bounds.hi.y - bounds.lo.y, bounds.hi.z - bounds.lo.z));
}

void MeshData::samplesFor(const double* x, std::vector<double>& out) const
{
    out.assign(x, x + v.size());
    if (density <= 1) return;
    for (int t = 0; t < triangleCount(); ++t) {
        const double* a = &x[3 * f[3 * t]];
        const double* b = &x[3 * f[3 * t + 1]];
        const double* c = &x[3 * f[3 * t + 2]];
        for (int i = 0; i <= density; ++i)
            for (int j = 0; i + j <= density; ++j) {
                int k = density - i - j;
                if (i == density || j == density || k == density) continue; // the vertices
                for (int d = 0; d < 3; ++d) out.push_back((i * a[d] + j * b[d] + k * c[d]) / density);
            }
    }
}

std::shared_ptr<MeshData> makeMesh(const std::string& name, std::vector<double> v, std::vector<uint32_t> f)
{
    std::shared_ptr<MeshData> m(new MeshData);
    m->name = name;
    m->v = std::move(v);
    m->f = std::move(f);
    m->finish();
    return m;
}

bool takeMeshArrays(sdfccd_MeshId id, std::vector<double>& v, std::vector<uint32_t>& f, sdfccd_MeshInfo& info)
{
    bool ok = sdfccd_mesh_get_info(id, &info) == SDFCCD_OK;
    if (ok) {
        v.assign(3 * (size_t)info.vertex_count, 0.0);
        f.assign(3 * (size_t)info.triangle_count, 0u);
        ok = sdfccd_mesh_get_data(id, v.data(), f.data()) == SDFCCD_OK;
    }
    if (!ok) std::fprintf(stderr, "sdfccd_scenes: cannot read a mesh: %s\n", sdfccd_last_error());
    sdfccd_destroy_mesh(id);
    return ok;
}

std::shared_ptr<MeshData> loadDataMesh(const Options& opt, const std::string& file, double scale, const char* name)
{
    std::shared_ptr<MeshData> m = loadMesh(opt.data_dir + "/" + file, scale);
    if (m && name) m->name = name;
    return m;
}

sdfccd_SdfId gridFromMesh(sdfccd_MeshId mesh, int resolution, double padding, const char* what)
{
    sdfccd_GridDef gd = sdfccd_default_grid_def();
    gd.resolution[0] = gd.resolution[1] = gd.resolution[2] = resolution;
    gd.padding = padding;
    gd.threads = 2;
    sdfccd_SdfId grid{};
    if (sdfccd_create_grid_from_mesh(mesh, &gd, &grid) != SDFCCD_OK) {
        std::fprintf(stderr, "sdfccd_scenes: %s: %s\n", what, sdfccd_last_error());
        return sdfccd_SdfId{};
    }
    return grid;
}

std::shared_ptr<MeshData> loadMesh(const std::string& path, double scale)
{
    sdfccd_MeshLoadDef def = sdfccd_default_mesh_load_def();
    def.scale = scale;
    sdfccd_MeshId id;
    if (sdfccd_load_mesh(path.c_str(), &def, &id) != SDFCCD_OK) {
        std::fprintf(stderr, "sdfccd_scenes: cannot load %s: %s\n", path.c_str(), sdfccd_last_error());
        return nullptr;
    }
    sdfccd_MeshInfo info;
    std::vector<double> v;
    std::vector<uint32_t> f;
    if (!takeMeshArrays(id, v, f, info)) return nullptr;
    // Body frame = the centre of the mesh's box (Bullet puts the centre of mass at the body origin).
    double c[3] = { 0.5 * (info.bounds.lo.x + info.bounds.hi.x), 0.5 * (info.bounds.lo.y + info.bounds.hi.y),
                    0.5 * (info.bounds.lo.z + info.bounds.hi.z) };
    for (size_t i = 0; i < v.size(); ++i) v[i] -= c[i % 3];
    std::string name = path.substr(path.find_last_of('/') + 1);
    name = name.substr(0, name.find('.'));
    return makeMesh(name, std::move(v), std::move(f));
}

void Frame::apply(const double* x, double* out) const
{
    for (int r = 0; r < 3; ++r) out[r] = R[3 * r] * x[0] + R[3 * r + 1] * x[1] + R[3 * r + 2] * x[2] + p[r];
}

void Frame::applyInverse(const double* x, double* out) const
{
    double d[3] = { x[0] - p[0], x[1] - p[1], x[2] - p[2] };
    for (int c = 0; c < 3; ++c) out[c] = R[c] * d[0] + R[3 + c] * d[1] + R[6 + c] * d[2];
}

Frame Frame::fromPose(const sdfccd_Pose& pose)
{
    Frame f;
    double w = pose.orientation.w, x = pose.orientation.x, y = pose.orientation.y, z = pose.orientation.z;
    double n = std::sqrt(w * w + x * x + y * y + z * z);
    w /= n; x /= n; y /= n; z /= n;
    double R[9] = { 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y) };
    std::memcpy(f.R, R, sizeof R);
    f.p[0] = pose.position.x;
    f.p[1] = pose.position.y;
    f.p[2] = pose.position.z;
    return f;
}

sdfccd_Pose Frame::toPose() const
{
    // Shepperd's method.
    double tr = R[0] + R[4] + R[8], w, x, y, z;
    if (tr > 0) {
        double s = 2 * std::sqrt(tr + 1);
        w = 0.25 * s; x = (R[7] - R[5]) / s; y = (R[2] - R[6]) / s; z = (R[3] - R[1]) / s;
    } else if (R[0] > R[4] && R[0] > R[8]) {
        double s = 2 * std::sqrt(1 + R[0] - R[4] - R[8]);
        w = (R[7] - R[5]) / s; x = 0.25 * s; y = (R[1] + R[3]) / s; z = (R[2] + R[6]) / s;
    } else if (R[4] > R[8]) {
        double s = 2 * std::sqrt(1 + R[4] - R[0] - R[8]);
        w = (R[2] - R[6]) / s; x = (R[1] + R[3]) / s; y = 0.25 * s; z = (R[5] + R[7]) / s;
    } else {
        double s = 2 * std::sqrt(1 + R[8] - R[0] - R[4]);
        w = (R[3] - R[1]) / s; x = (R[2] + R[6]) / s; y = (R[5] + R[7]) / s; z = 0.25 * s;
    }
    sdfccd_Pose pose;
    pose.position = sdfccd_Vec3{ p[0], p[1], p[2] };
    pose.orientation = sdfccd_Quat{ w, x, y, z };
    return pose;
}

const char* methodName(sdfccd_Method m)
{
    switch (m) {
    case SDFCCD_METHOD_FWGSS: return "fwgss";
    case SDFCCD_METHOD_FW: return "fw";
    case SDFCCD_METHOD_DCD: return "dcd";
    case SDFCCD_METHOD_CERTIFIED: return "certified";
    default: return "?";
    }
}

bool parseMethod(const std::string& s, sdfccd_Method* out)
{
    for (int m = 0; m < SDFCCD_METHOD_COUNT; ++m)
        if (s == methodName((sdfccd_Method)m)) {
            *out = (sdfccd_Method)m;
            return true;
        }
    return false;
}

const SceneEntry* findScene(const std::string& name)
{
    for (const SceneEntry& e : sceneTable())
        if (name == e.name) return &e;
    return nullptr;
}

} // namespace scenes
