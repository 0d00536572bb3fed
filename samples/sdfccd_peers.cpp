// SPDX-License-Identifier: MIT
// sdfccd_peers: the evaluation suite's peers on the data set of sdfccd_bench (issue 4).
//   sdfccd_peers CASES.txt [N]   -> CSV on stdout: id,peer,hit,toi,micros (first N cases per mesh)
// The SDF of each case file (the torus) becomes a triangle mesh with sdfccd_extract_isosurface
// (marching tetrahedra, 96 cells across the torus), and each case is run by
//  - "GImpact (discrete, end of step)": Bullet's btGImpactMeshShape for the moving mesh against a
//    btGImpactMeshShape of the torus mesh, one contactPairTest at the end pose, as a Bullet world
//    stepping at the case's time step sees it (toi = DT when touching);
//  - "FCL CCD (sampled, 100 steps)": fcl::continuousCollide between two BVHModel<OBBRSS> meshes,
//    linear-interpolation motion (constant linear and angular velocity about the frame origin: the
//    case file's motion model), solver CCDC_NAIVE with 100 sub-steps; toi = fraction * DT.
//    FCL 0.7's conservative-advancement solver (PEER_FCL_SOLVER=ca) found no contact on the first
//    four cases of each mesh and took 0.14-0.6 s per query on this torus mesh, so it is not the
//    default; PEER_FCL_MOTION=screw selects screw motion.
// Timing covers the query only (shapes are built once per mesh). Progress goes to stderr.
#include <btBulletCollisionCommon.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <fcl/fcl.h>

#include <chrono>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "sdfccd/sdfccd.h"
#include "scenes/scene.h" // takeMeshArrays

namespace {

const int kResolution = 40; // marching cells along the box's longest side (32 cm): 8 mm cells, about 27K triangles

struct TriMesh {
    std::vector<double> v;   // 3 per vertex
    std::vector<int> f;      // 3 per triangle
};

struct Case {
    std::string id, mesh;
    double dt;
    double p[3], q[4], vel[3], w[3];
};

bool loadObj(const std::string& path, TriMesh& m)
{
    std::ifstream in(path);
    if (!in) return false;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ss(line);
        std::string tag;
        ss >> tag;
        if (tag == "v") {
            double x, y, z;
            ss >> x >> y >> z;
            m.v.insert(m.v.end(), { x, y, z });
        } else if (tag == "f") {
            int a, b, c;
            ss >> a >> b >> c;
            m.f.insert(m.f.end(), { a - 1, b - 1, c - 1 });
        }
    }
    return !m.f.empty();
}

// x(t) = P + V t + R(W t) R(Q) x_local as a rotation (quaternion w,x,y,z) and translation at t.
void poseAt(const Case& c, double t, double q_out[4], double p_out[3])
{
    double a = std::sqrt(c.w[0] * c.w[0] + c.w[1] * c.w[1] + c.w[2] * c.w[2]) * t;
    double qw[4] = { 1, 0, 0, 0 };
    if (a > 0) {
        double s = std::sin(a / 2) / (a / t);
        qw[0] = std::cos(a / 2);
        qw[1] = c.w[0] * s;
        qw[2] = c.w[1] * s;
        qw[3] = c.w[2] * s;
    }
    const double* b = c.q;
    q_out[0] = qw[0] * b[0] - qw[1] * b[1] - qw[2] * b[2] - qw[3] * b[3];
    q_out[1] = qw[0] * b[1] + qw[1] * b[0] + qw[2] * b[3] - qw[3] * b[2];
    q_out[2] = qw[0] * b[2] - qw[1] * b[3] + qw[2] * b[0] + qw[3] * b[1];
    q_out[3] = qw[0] * b[3] + qw[1] * b[2] - qw[2] * b[1] + qw[3] * b[0];
    for (int k = 0; k < 3; ++k) p_out[k] = c.p[k] + c.vel[k] * t;
}

struct BulletMesh {
    std::vector<btScalar> v;
    std::vector<int> f;
    std::unique_ptr<btTriangleIndexVertexArray> tiva;
    std::unique_ptr<btGImpactMeshShape> shape;
    explicit BulletMesh(const TriMesh& m)
    {
        v.assign(m.v.begin(), m.v.end());
        f = m.f;
        tiva.reset(new btTriangleIndexVertexArray((int)f.size() / 3, f.data(), 3 * (int)sizeof(int), (int)v.size() / 3, v.data(),
                                                  3 * (int)sizeof(btScalar)));
        shape.reset(new btGImpactMeshShape(tiva.get()));
        shape->updateBound();
    }
};

struct AnyContact : btCollisionWorld::ContactResultCallback {
    bool hit = false;
    btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*, int, int) override
    {
        if (cp.getDistance() <= 0) hit = true;
        return 0;
    }
};

std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> fclMesh(const TriMesh& m)
{
    std::vector<fcl::Vector3d> v;
    std::vector<fcl::Triangle> t;
    for (size_t i = 0; i < m.v.size(); i += 3) v.emplace_back(m.v[i], m.v[i + 1], m.v[i + 2]);
    for (size_t i = 0; i < m.f.size(); i += 3) t.emplace_back(m.f[i], m.f[i + 1], m.f[i + 2]);
    auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
    model->beginModel();
    model->addSubModel(v, t);
    model->endModel();
    return model;
}

fcl::Transform3d fclPose(const double q[4], const double p[3])
{
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.linear() = fcl::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
    tf.translation() = fcl::Vector3d(p[0], p[1], p[2]);
    return tf;
}

double elapsedUs(std::chrono::steady_clock::time_point a)
{
    return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - a).count();
}

}  // namespace

int main(int argc, char** argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s CASES.txt [N per mesh]\n", argv[0]);
        return 2;
    }
    std::string path = argv[1];
    int limit = argc >= 3 ? std::atoi(argv[2]) : 1 << 30;
    std::string dir = path.substr(0, path.find_last_of('/') + 1);
    std::ifstream in(path);
    if (!in) {
        std::fprintf(stderr, "sdfccd_peers: cannot open %s\n", path.c_str());
        return 1;
    }
    std::map<std::string, TriMesh> meshes;
    double major = 0.1, minor = 0.05;
    std::vector<Case> cases;
    std::map<std::string, int> per_mesh;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ss(line);
        std::string tag;
        ss >> tag;
        if (tag == "sdf") {
            std::string name, kind;
            ss >> name >> kind;
            if (kind != "torus") {
                std::fprintf(stderr, "sdfccd_peers: only torus SDFs are supported\n");
                return 1;
            }
            ss >> major >> minor;
        } else if (tag == "mesh") {
            std::string name, kind;
            ss >> name >> kind;
            TriMesh m;
            if (kind == "triangle") {
                for (int i = 0; i < 9; ++i) { double x; ss >> x; m.v.push_back(x); }
                m.f = { 0, 1, 2 };
            } else {
                std::string file;
                ss >> file;
                if (!loadObj(dir + file, m)) {
                    std::fprintf(stderr, "sdfccd_peers: cannot read %s\n", (dir + file).c_str());
                    return 1;
                }
            }
            meshes[name] = m;
        } else if (tag == "case") {
            Case c;
            std::string sdf;
            ss >> c.id >> sdf >> c.mesh >> c.dt >> c.p[0] >> c.p[1] >> c.p[2] >> c.q[0] >> c.q[1] >> c.q[2] >> c.q[3] >> c.vel[0] >> c.vel[1] >>
                c.vel[2] >> c.w[0] >> c.w[1] >> c.w[2];
            if (per_mesh[c.mesh]++ < limit) cases.push_back(c);
        }
    }

    // The torus as a triangle mesh (what a mesh-only engine would collide against).
    sdfccd_SdfId torus;
    sdfccd_MeshId iso;
    double ext = major + minor + 0.01;
    sdfccd_Aabb box = { { -ext, -ext, -minor - 0.01 }, { ext, ext, minor + 0.01 } };
    if (sdfccd_create_torus(major, minor, &torus) != SDFCCD_OK || sdfccd_extract_isosurface(torus, box, kResolution, &iso) != SDFCCD_OK) {
        std::fprintf(stderr, "sdfccd_peers: %s\n", sdfccd_last_error());
        return 1;
    }
    sdfccd_MeshInfo info;
    TriMesh tm;
    std::vector<uint32_t> f;
    const bool copied = scenes::takeMeshArrays(iso, tm.v, f, info); // destroys iso
    sdfccd_destroy_sdf(torus);
    if (!copied) return 1;
    tm.f.assign(f.begin(), f.end());
    std::fprintf(stderr, "[peers] torus mesh: %u triangles; %zu cases\n", info.triangle_count, cases.size());

    // Bullet world with GImpact registered.
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
    btDbvtBroadphase broadphase;
    btCollisionWorld world(&dispatcher, &broadphase, &config);
    BulletMesh torusMesh(tm);
    btCollisionObject torusObj;
    torusObj.setCollisionShape(torusMesh.shape.get());
    world.addCollisionObject(&torusObj);
    std::map<std::string, std::unique_ptr<BulletMesh>> bmeshes;
    for (auto& kv : meshes) bmeshes[kv.first].reset(new BulletMesh(kv.second));

    auto fclTorus = fclMesh(tm);
    std::map<std::string, std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>>> fmeshes;
    for (auto& kv : meshes) fmeshes[kv.first] = fclMesh(kv.second);

    std::printf("id,peer,hit,toi,micros\n");
    int done = 0;
    for (const Case& c : cases) {
        double q1[4], p1[3], q0[4], p0[3];
        poseAt(c, 0.0, q0, p0);
        poseAt(c, c.dt, q1, p1);
        {
            BulletMesh& bm = *bmeshes[c.mesh];
            btCollisionObject obj;
            obj.setCollisionShape(bm.shape.get());
            btTransform tr;
            tr.setOrigin(btVector3(btScalar(p1[0]), btScalar(p1[1]), btScalar(p1[2])));
            tr.setRotation(btQuaternion(btScalar(q1[1]), btScalar(q1[2]), btScalar(q1[3]), btScalar(q1[0])));
            obj.setWorldTransform(tr);
            world.addCollisionObject(&obj);
            auto t0 = std::chrono::steady_clock::now();
            world.performDiscreteCollisionDetection();
            double us = elapsedUs(t0);
            bool hit = false;
            for (int i = 0; i < dispatcher.getNumManifolds(); ++i) {
                btPersistentManifold* mf = dispatcher.getManifoldByIndexInternal(i);
                for (int k = 0; k < mf->getNumContacts(); ++k)
                    if (mf->getContactPoint(k).getDistance() <= 0) hit = true;
            }
            world.removeCollisionObject(&obj);
            std::printf("%s,GImpact (discrete end of step),%d,%.17g,%.3f\n", c.id.c_str(), hit ? 1 : 0, c.dt, us);
        }
        {
            fcl::ContinuousCollisionRequestd req;
            static const char* mt = std::getenv("PEER_FCL_MOTION");
            static const char* sv = std::getenv("PEER_FCL_SOLVER");
            req.ccd_motion_type = mt && std::strcmp(mt, "screw") == 0 ? fcl::CCDM_SCREW : fcl::CCDM_LINEAR;
            req.ccd_solver_type = sv && std::strcmp(sv, "ca") == 0 ? fcl::CCDC_CONSERVATIVE_ADVANCEMENT : fcl::CCDC_NAIVE;
            req.gjk_solver_type = fcl::GST_LIBCCD;
            req.num_max_iterations = 100;
            req.toc_err = 1e-6;
            fcl::ContinuousCollisionResultd res;
            auto t0 = std::chrono::steady_clock::now();
            fcl::continuousCollide(fmeshes[c.mesh].get(), fclPose(q0, p0), fclPose(q1, p1), fclTorus.get(), fcl::Transform3d::Identity(),
                                   fcl::Transform3d::Identity(), req, res);
            double us = elapsedUs(t0);
            std::printf("%s,FCL CCD (sampled 100 steps),%d,%.17g,%.3f\n", c.id.c_str(), res.is_collide ? 1 : 0,
                        res.is_collide ? res.time_of_contact * c.dt : c.dt, us);
        }
        if (++done % 64 == 0) std::fprintf(stderr, "[peers] %d/%zu\n", done, cases.size());
    }
    world.removeCollisionObject(&torusObj);
    return 0;
}
