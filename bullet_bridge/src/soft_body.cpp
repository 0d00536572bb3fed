// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: btSoftBody against SDFs (soft_body.h). Per-vertex linear motion over the
// step (the paper's deformable case, Section 4 with linearly moving vertices; the cloth of Fig. 9):
// node paths by conservative advancement on the SDF, faces by sdfccd_query_triangle_linear; the
// contacts become Bullet's btSoftBody::RContact, and guardSoftBodies() never lets a node or face
// point end past its time of impact.
#include "internal.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <set>

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodySolvers.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include "sdfccd_bullet/soft_body.h"

SDFCCD_BULLET_NAMESPACE_BEGIN
namespace detail {

void callMisuseHandler(Status status, const char* message, const btCollisionShape* shape);

namespace {

struct D3 {
    double x, y, z;
};
inline D3 d3(const btVector3& v) { return D3{ (double)v.x(), (double)v.y(), (double)v.z() }; }
inline D3 operator+(D3 a, D3 b) { return D3{ a.x + b.x, a.y + b.y, a.z + b.z }; }
inline D3 operator-(D3 a, D3 b) { return D3{ a.x - b.x, a.y - b.y, a.z - b.z }; }
inline D3 operator*(D3 a, double s) { return D3{ a.x * s, a.y * s, a.z * s }; }
inline double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline double len(D3 a) { return std::sqrt(dot(a, a)); }
inline sdfccd_Vec3 sv(D3 a) { return sdfccd_Vec3{ a.x, a.y, a.z }; }
inline D3 fromSv(const sdfccd_Vec3& a) { return D3{ a.x, a.y, a.z }; }
inline btVector3 btv(D3 a) { return btVector3((btScalar)a.x, (btScalar)a.y, (btScalar)a.z); }

// A rigid frame in double precision (the SDF body's pose at the start of the step).
struct Frame {
    double r[3][3];
    D3 o;
    explicit Frame(const btTransform& t)
    {
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) r[i][j] = (double)t.getBasis()[i][j];
        o = d3(t.getOrigin());
    }
    D3 toLocal(D3 p) const
    {
        const D3 d = p - o;
        return D3{ r[0][0] * d.x + r[1][0] * d.y + r[2][0] * d.z, r[0][1] * d.x + r[1][1] * d.y + r[2][1] * d.z,
                   r[0][2] * d.x + r[1][2] * d.y + r[2][2] * d.z };
    }
    D3 dirToWorld(D3 v) const
    {
        return D3{ r[0][0] * v.x + r[0][1] * v.y + r[0][2] * v.z, r[1][0] * v.x + r[1][1] * v.y + r[1][2] * v.z,
                   r[2][0] * v.x + r[2][1] * v.y + r[2][2] * v.z };
    }
    D3 toWorld(D3 p) const { return dirToWorld(p) + o; }
    D3 dirToLocal(D3 v) const { return toLocal(v + o); }
};

// A lower bound of phi near a triangle's corners (or a point's) in the SDF's frame (contact.h). Kept
// from step to step, so resting nodes and faces cost no SDF evaluation.
using Cert = sdfccd_DistanceCert;

// The step of one (soft body, SDF body) pair, kept for the guard: the nodes' start positions and the
// SDF body's pose; the certificates of its nodes and faces.
struct SoftRecord {
    const btSoftBody* soft = nullptr;
    const btCollisionObject* sdf_object = nullptr;
    sdfccd_SdfId sdf = kNullSdf;
    btTransform sdf_pose;
    std::vector<D3> start;
    bool fresh = false;
    std::vector<Cert> node_certs, face_certs;
    // The contact planes collide() found, in the SDF body's frame (n . x + offset >= 0 on the free
    // side), each held after Bullet's solve (holdRecord).
    struct Hold {
        int node;
        D3 normal;
        double offset, friction;
    };
    std::vector<Hold> holds;
    void setSdf(sdfccd_SdfId id) // another field: the certificates say nothing about it
    {
        if (id.index1 != sdf.index1 || id.generation != sdf.generation) node_certs.clear(), face_certs.clear();
        sdf = id;
    }
    void sizeCerts(int nodes, int faces)
    {
        if (node_certs.size() != (size_t)nodes) node_certs.assign((size_t)nodes, sdfccd_empty_distance_cert());
        if (face_certs.size() != (size_t)faces) face_certs.assign((size_t)faces, sdfccd_empty_distance_cert());
    }
};

// Does the certificate keep n corners moving from x0[] to x1[] at or above `need`
// (sdfccd_distance_cert_bound)? Decided here, without the API call, unless within rounding of need.
bool certClears(const Cert& cert, const D3* x0, const D3* x1, int n, double L, double need)
{
    if (!(cert.bound > -HUGE_VAL)) return false;
    double d = 0;
    for (int k = 0; k < n; ++k) {
        const D3 a = fromSv(cert.anchor[k]);
        d = std::max(d, std::max(len(x0[k] - a), len(x1[k] - a)));
    }
    const double fast = cert.bound - L * d;
    if (std::fabs(fast - need) > 1e-9) return fast >= need;
    sdfccd_Vec3 s[3], e[3];
    for (int k = 0; k < n; ++k) s[k] = sv(x0[k]), e[k] = sv(x1[k]);
    double b;
    return sdfccd_distance_cert_bound(&cert, s, e, n, L, &b) == SDFCCD_OK && b >= need;
}

struct SoftState;

class SoftSdfAlgorithm : public btCollisionAlgorithm
{
public:
    SoftSdfAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, SoftState* s, bool swapped)
        : btCollisionAlgorithm(ci), m_state(s), m_swapped(swapped) {}
    void processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1, const btDispatcherInfo& info,
                          btManifoldResult* out) override;
    btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&, btManifoldResult*) override
    {
        return 1; // soft bodies have no rigid time of impact; their CCD runs in processCollision
    }
    void getAllContactManifolds(btManifoldArray&) override {} // contacts live in btSoftBody::m_rcontacts

private:
    SoftState* m_state;
    bool m_swapped;
};

struct SoftCreateFunc : btCollisionAlgorithmCreateFunc {
    SoftState* state = nullptr;
    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper*,
                                                   const btCollisionObjectWrapper*) override
    {
        void* mem = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(SoftSdfAlgorithm));
        return new (mem) SoftSdfAlgorithm(ci, state, m_swapped);
    }
};

struct SoftState {
    BridgeImpl* impl = nullptr;
    SoftCreateFunc fn[2]; // (soft, sdf) and (sdf, soft)
    std::vector<std::pair<int, int>> slots;
    btCollisionDispatcher* dispatcher = nullptr;
    SoftBodyStats stats;
    std::map<std::pair<const void*, const void*>, SoftRecord> records;
    std::set<const btCollisionShape*> reported;
    std::vector<sdfccd_Contact> contacts;
    // The automatic guard (registerWith a btSoftRigidDynamicsWorld): the world, its solver as it was,
    // and whether the world owned it.
    btSoftRigidDynamicsWorld* world = nullptr;
    btSoftBodySolver* inner = nullptr;
    class GuardingSolver* wrapper = nullptr;
    bool world_owned_inner = false;
    bool guarded_this_step = false;
    bool auto_guard = true;
    double auto_tolerance = 5e-4;
    // Per node of the pair being processed (2 i: its own path, 2 i + 1: its faces): the most restrictive
    // plane found of each kind (the one the node's start position is closest to).
    struct Plane {
        double dist;
        D3 normal;
        double offset;
        bool face;
    };
    std::vector<Plane> planes;
};

std::mutex g_soft_mutex;
std::map<const BridgeImpl*, std::unique_ptr<SoftState>> g_soft;

SoftState* softOf(const BridgeImpl* impl)
{
    std::lock_guard<std::mutex> lock(g_soft_mutex);
    auto it = g_soft.find(impl);
    return it == g_soft.end() ? nullptr : it->second.get();
}

double lipschitzOf(sdfccd_SdfId sdf)
{
    sdfccd_SdfInfo info;
    if (sdfccd_sdf_get_info(sdf, &info) != SDFCCD_OK || !(info.lipschitz >= 1.0) || !std::isfinite(info.lipschitz)) return 1.0;
    return info.lipschitz;
}

// First point of the segment a -> b (SDF frame) where phi <= level + 1e-6 (sdfccd_point_first_hit:
// conservative advancement, early, never late); false when the segment stays above. *phi_a: phi at a.
bool pointHit(sdfccd_SdfId sdf, D3 a, D3 b, double level, double L, double* out_f, double* out_phi, D3* out_grad, int64_t* evals,
              double* phi_a = nullptr)
{
    sdfccd_PointHit h;
    const bool ok = sdfccd_point_first_hit(sdf, sv(a), sv(b), level, L, &h, evals) == SDFCCD_OK;
    if (phi_a) *phi_a = ok ? h.start_distance : -HUGE_VAL;
    if (!ok || !h.hit) return false;
    *out_f = h.fraction;
    *out_phi = h.distance;
    *out_grad = fromSv(h.gradient);
    return true;
}

D3 unit(D3 v)
{
    const double l = len(v);
    return l > 0 ? v * (1 / l) : D3{ 0, 0, 1 };
}

// Bullet's soft-rigid contact terms for a node against the SDF body (how btSoftBody's own
// collision handler fills RContact: impulse matrix, anchor, ima dt, friction, hardness).
void addContact(btSoftBody* psb, btSoftBody::Node& n, const btCollisionObject* co, D3 normal, double offset)
{
    const double dt = psb->m_sst.sdt;
    const btRigidBody* rb = btRigidBody::upcast(co);
    const btScalar ima = n.m_im;
    const btScalar imb = rb ? rb->getInvMass() : btScalar(0);
    if (!(ima + imb > 0)) return;
    const btTransform& wtr = co->getWorldTransform();
    const btVector3 nrm = btv(normal);
    const btVector3 ra = n.m_x - wtr.getOrigin();
    const btVector3 va = rb ? rb->getVelocityInLocalPoint(ra) * btScalar(dt) : btVector3(0, 0, 0);
    const btVector3 vr = (n.m_x - n.m_q) - va;
    const btScalar dn = vr.dot(nrm);
    const btVector3 fv = vr - nrm * dn;
    const btScalar fc = psb->m_cfg.kDF * co->getFriction();
    // Impulse matrix: (1/dt) (ima I + imb I - [ra]x Iw^-1 [ra]x)^-1.
    btMatrix3x3 iwi;
    if (rb)
        iwi = rb->getInvInertiaTensorWorld();
    else
        iwi.setValue(0, 0, 0, 0, 0, 0, 0, 0, 0);
    const btMatrix3x3 cr(0, -ra.z(), ra.y(), ra.z(), 0, -ra.x(), -ra.y(), ra.x(), 0);
    btMatrix3x3 k = cr * iwi * cr;
    btMatrix3x3 m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m[i][j] = (i == j ? ima + imb : btScalar(0)) - k[i][j];
    btSoftBody::RContact c;
    c.m_cti.m_colObj = co;
    c.m_cti.m_normal = nrm;
    c.m_cti.m_offset = (btScalar)offset;
    c.m_cti.m_bary = btVector3(0, 0, 0);
    c.m_node = &n;
    c.t1.setZero();
    c.t2.setZero();
    c.m_c0 = m.inverse() * btScalar(1 / dt);
    c.m_c1 = ra;
    c.m_c2 = ima * btScalar(dt);
    c.m_c3 = fv.length2() < (dn * fc * dn * fc) ? btScalar(0) : 1 - fc;
    c.m_c4 = co->isStaticOrKinematicObject() ? psb->m_cfg.kKHR : psb->m_cfg.kCHR;
    psb->m_rcontacts.push_back(c);
    if (rb) const_cast<btRigidBody*>(rb)->activate();
}

sdfccd_QueryParams faceParams(const BridgeImpl* impl, double level)
{
    sdfccd_QueryParams p = impl->cfg.query;
    p.margin = level;
    return p;
}

// Is the face moving from s[] to e[] certified above `need` (an old certificate, or a new one at s[];
// sdfccd_triangle_clear)?
bool faceClear(sdfccd_SdfId sdf, Cert& cert, const D3 s[3], const D3 e[3], double need, double L, int64_t* evals)
{
    if (certClears(cert, s, e, 3, L, need)) return true; // the kept certificate: no handle lookup
    const sdfccd_Vec3 ss[3] = { sv(s[0]), sv(s[1]), sv(s[2]) }, ee[3] = { sv(e[0]), sv(e[1]), sv(e[2]) };
    int32_t clear = 0;
    return sdfccd_triangle_clear(sdf, &cert, ss, ee, need, L, &clear, evals) == SDFCCD_OK && clear;
}

// The SDF body's pose at the start of the step: a kinematic body (or, after the rigid step, any
// moving one) is already at its end pose, so its velocity is integrated back over dt.
btTransform startPose(const btCollisionObject* co, double dt)
{
    const btRigidBody* rb = btRigidBody::upcast(co);
    if (!rb || (rb->isStaticObject() && !rb->isKinematicObject()) || !(dt > 0)) return co->getWorldTransform(); // (mass 0: both flags)
    btTransform x;
    btTransformUtil::integrateTransform(co->getWorldTransform(), -rb->getLinearVelocity(), -rb->getAngularVelocity(), (btScalar)dt, x);
    return x;
}

void collide(SoftState* st, btSoftBody* psb, const btCollisionObjectWrapper* sw)
{
    BridgeImpl* impl = st->impl;
    const btCollisionObject* co = sw->getCollisionObject();
    const btCollisionShape* shape = sw->getCollisionShape();
    ++st->stats.pair_steps;
    const sdfccd_SdfId sdf = impl->shapes.sdfFor(shape, impl->cfg.sdf_shape_type, impl->cfg.handle_bt_sdf_shape);
    sdfccd_SdfInfo info;
    if (sdf.index1 == 0 || sdfccd_sdf_get_info(sdf, &info) != SDFCCD_OK) {
        ++st->stats.refused;
        if (st->reported.insert(shape).second)
            callMisuseHandler(Status::InvalidShape,
                              "a soft body meets an SdfShape whose sdfccd handle is null or destroyed: it gets no contacts "
                              "from it (keep the SDF alive while the shape is in a world)",
                              shape);
        return;
    }
    const double L = lipschitzOf(sdf);
    const Frame F(sw->getWorldTransform());
    // Bullet's soft bodies keep their collision shape's margin from rigid surfaces: the contact planes
    // lie that far out of the SDF, and the CCD looks Config::contact_margin beyond them.
    const double soft_margin = std::max(0.0, (double)psb->getCollisionShape()->getMargin());
    const double margin = soft_margin + impl->cfg.contact_margin;
    int64_t evals = 0;

    SoftRecord& rec = st->records[std::make_pair((const void*)psb, (const void*)co)];
    rec.soft = psb;
    rec.sdf_object = co;
    rec.setSdf(sdf);
    rec.sdf_pose = co->isKinematicObject() ? startPose(co, psb->m_sst.sdt) : sw->getWorldTransform();
    rec.fresh = true;
    const int nn = psb->m_nodes.size();
    rec.sizeCerts(nn, psb->m_faces.size() + psb->m_links.size());
    rec.start.resize((size_t)nn);
    for (int i = 0; i < nn; ++i) rec.start[(size_t)i] = d3(psb->m_nodes[i].m_q);

    st->planes.assign(2 * (size_t)nn, SoftState::Plane{ HUGE_VAL, D3{ 0, 0, 1 }, 0, false });
    auto offer = [&](int i, D3 nw, double offset, bool face) {
        const double dist = dot(nw, d3(psb->m_nodes[i].m_q)) + offset;
        SoftState::Plane& pl = st->planes[2 * (size_t)i + (face ? 1 : 0)];
        if (dist < pl.dist) pl = SoftState::Plane{ dist, nw, offset, face };
    };
    // Nodes: each one's path from m_q to the predicted m_x (DCD, the discrete baseline: m_x alone).
    const bool dcd = impl->cfg.query.method == SDFCCD_METHOD_DCD;
    // Against a static or kinematic SDF body, with the bridge's solver wrapper in place, the contacts
    // are held inside Bullet's position iterations (holdIteration) instead of becoming RContacts.
    const bool hold = !dcd && co->isStaticOrKinematicObject() && st->wrapper;
    const double friction = (double)(psb->m_cfg.kDF * co->getFriction());
    rec.holds.clear();
    for (int i = 0; i < nn; ++i) {
        btSoftBody::Node& n = psb->m_nodes[i];
        if (n.m_battach) continue;
        double f, phi;
        D3 g;
        const D3 b = F.toLocal(d3(n.m_x)), a = dcd ? b : F.toLocal(d3(n.m_q));
        Cert& cert = rec.node_certs[(size_t)i];
        if (certClears(cert, &a, &b, 1, L, margin)) continue;
        const bool hit = pointHit(sdf, a, b, margin, L, &f, &phi, &g, &evals, &cert.bound);
        cert.anchor[0] = sv(a);
        if (!hit) continue;
        const D3 p = a + (b - a) * f;
        const D3 nl = unit(g);
        const D3 nw = F.dirToWorld(nl);
        offer(i, nw, -dot(nw, F.toWorld(p - nl * (phi - soft_margin))), false);
    }

    // Faces: per-vertex linear motion; a contact inside a face holds each of its nodes. A face point
    // counts when it comes 0.7 of the way into the soft margin (the nodes hold the rest; a face lying
    // on the surface at the margin then needs no query). Halfway, the planes of faces sagging over the
    // bunny's curved top came and went every few steps: the Fig. 9 cloth never rested (0.03-0.05 m/s
    // against 0.005-0.015 m/s at 0.2-0.4 of the margin).
    const double dt = psb->m_sst.sdt;
    const double face_level = soft_margin > 0 ? 0.3 * soft_margin : margin;
    const sdfccd_QueryParams qp = faceParams(impl, face_level);
    if (st->contacts.size() < 8) st->contacts.resize(8);
    for (int fi = 0; fi < psb->m_faces.size(); ++fi) {
        btSoftBody::Face& face = psb->m_faces[fi];
        D3 s[3], e[3];
        for (int k = 0; k < 3; ++k) {
            s[k] = F.toLocal(d3(face.m_n[k]->m_q));
            e[k] = F.toLocal(d3(face.m_n[k]->m_x));
        }
        if (faceClear(sdf, rec.face_certs[(size_t)fi], s, e, face_level, L, &evals)) continue;
        sdfccd_Vec3 ss[3] = { sv(s[0]), sv(s[1]), sv(s[2]) }, ee[3] = { sv(e[0]), sv(e[1]), sv(e[2]) };
        sdfccd_QueryResult res;
        const sdfccd_Status status =
            sdfccd_query_triangle_linear(sdf, nullptr, ss, ee, 0.0, dt, &qp, st->contacts.data(), 8, &res);
        ++st->stats.face_queries;
        if (status == SDFCCD_DEGENERATE) continue; // a collapsed face: its nodes are checked on their own
        if (status != SDFCCD_OK) {
            ++st->stats.query_errors;
            continue;
        }
        evals += res.sdf_evaluations;
        if (!res.hit) continue;
        for (int j = 0; j < res.contact_count; ++j) {
            const sdfccd_Contact& c = st->contacts[(size_t)j];
            const double wmax = std::max(c.barycentric[0], std::max(c.barycentric[1], c.barycentric[2]));
            if (wmax > 0.99) continue; // at a node: that node's own path gives its contact
            const double f = dt > 0 ? c.toi / dt : 0;
            const D3 p = fromSv(c.point), nl = unit(fromSv(c.normal));
            // Held at the level it was found at: a plane higher up would lift the face off that level, the
            // next step would find no contact, and the face would fall back (an oscillation).
            const D3 surface = p - nl * (c.distance - face_level);
            const D3 nw = F.dirToWorld(nl);
            for (int k = 0; k < 3; ++k) {
                if (c.barycentric[k] < 0.01 || face.m_n[k]->m_battach) continue;
                const D3 xk = s[k] + (e[k] - s[k]) * f;
                // The plane through the surface point moved by the node's offset from the face point:
                // while every node stays on its side, the face point stays on the surface's.
                offer((int)(face.m_n[k] - &psb->m_nodes[0]), nw, -dot(nw, F.toWorld(surface + (xk - p))), true);
            }
        }
    }
    for (int i = 0; i < 2 * nn; ++i) {
        const SoftState::Plane& pl = st->planes[(size_t)i];
        if (!(pl.dist < HUGE_VAL)) continue;
        btSoftBody::Node& n = psb->m_nodes[i / 2];
        if (hold) {
            rec.holds.push_back(SoftRecord::Hold{ i / 2, F.dirToLocal(pl.normal), pl.offset + dot(pl.normal, F.o), friction });
            ++(pl.face ? st->stats.face_contacts : st->stats.node_contacts);
            continue;
        }
        addContact(psb, n, co, pl.normal, pl.offset);
        ++(pl.face ? st->stats.face_contacts : st->stats.node_contacts);
    }
    st->stats.sdf_evaluations += evals;
}

void SoftSdfAlgorithm::processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                                        const btDispatcherInfo&, btManifoldResult*)
{
    const btCollisionObjectWrapper* softw = m_swapped ? w1 : w0;
    const btCollisionObjectWrapper* sdfw = m_swapped ? w0 : w1;
    btSoftBody* psb = const_cast<btSoftBody*>(btSoftBody::upcast(softw->getCollisionObject()));
    if (!psb || !m_state) return;
    collide(m_state, psb, sdfw);
}

// Removes the node's velocity into the surface (normal nw, world).
void stopInto(btSoftBody::Node& n, D3 nw)
{
    const btVector3 nrm = btv(nw);
    const btScalar vn = n.m_v.dot(nrm);
    if (vn < 0) n.m_v -= nrm * vn;
}

// One pass over the contact planes collide() found for the soft body's nodes (Section 4's contacts
// with per-vertex linear motion), solved the way Bullet solves its links, by position projection: a
// node below a plane goes onto it (in the SDF body's frame); a node above it is free (Bullet's
// RContact would pull it down toward the plane by kKHR times its height every step, and nodes held
// up by the cloth would swing). Friction (Coulomb, kDF times the body's friction): the node's
// sideways motion over the step stops while it is within friction times its pushes so far; the last
// pass shortens a longer one by that much and sets the velocity of the nodes it moved by Bullet's
// rule, v = (x - q) / dt damped by kDP, never more outward than the solver left it. push: per plane.
void holdIteration(SoftState* st, btSoftBody* psb, std::vector<double>& push, bool last)
{
    const double vc = psb->m_sst.sdt > 0 ? (1.0 - psb->m_cfg.kDP) / psb->m_sst.sdt : 0.0;
    size_t hi = 0;
    for (auto& r : st->records) {
        SoftRecord& rec = r.second;
        if (rec.soft != psb || !rec.fresh) continue;
        const Frame F0(rec.sdf_pose), F(rec.sdf_object->getWorldTransform());
        for (const SoftRecord::Hold& h : rec.holds) {
            double& pushed = push[hi++];
            btSoftBody::Node& n = psb->m_nodes[h.node];
            if (!(n.m_im > 0)) continue;
            D3 x = F.toLocal(d3(n.m_x));
            const double d = dot(h.normal, x) + h.offset;
            if (d < 0) {
                x = x - h.normal * d;
                pushed -= d;
            }
            if (!(pushed > 0)) continue;
            const D3 step = x - F0.toLocal(rec.start[(size_t)h.node]), side = step - h.normal * dot(step, h.normal);
            const double sl = len(side), lim = h.friction * pushed;
            if (sl <= lim) x = x - side;
            else if (last) x = x - side * (lim / sl);
            n.m_x = btv(F.toWorld(x));
            if (!last) continue;
            const D3 nw = F.dirToWorld(h.normal);
            D3 v = (d3(n.m_x) - rec.start[(size_t)h.node]) * vc;
            const double out = dot(v, nw) - std::max(dot(d3(n.m_v), nw), 0.0);
            if (out > 0) v = v - nw * out;
            n.m_v = btv(v);
            ++st->stats.held_nodes;
        }
    }
}

// Bullet's soft-body position solve (btSoftBody::solveConstraints) with the contact planes held
// after each of its piterations passes: one call per pass with piterations = 1 is the same solve
// (links and anchors are prepared from m_q, velocities set from m_x - m_q at the end of each call)
// when the body has no velocity or drift passes and no clusters; otherwise the planes are held once,
// after the solve.
void solveHeld(SoftState* st, btSoftBody* psb)
{
    bool any = false;
    for (auto& r : st->records) any = any || (r.second.soft == psb && r.second.fresh && !r.second.holds.empty());
    if (!any) {
        psb->solveConstraints();
        return;
    }
    size_t count = 0;
    for (auto& r : st->records)
        if (r.second.soft == psb && r.second.fresh) count += r.second.holds.size();
    std::vector<double> push(count, 0.0);
    const int passes = psb->m_cfg.piterations;
    if (passes <= 1 || psb->m_cfg.viterations > 0 || psb->m_cfg.diterations > 0 || psb->m_clusters.size() > 0) {
        psb->solveConstraints();
        holdIteration(st, psb, push, true);
        return;
    }
    psb->m_cfg.piterations = 1;
    for (int k = 0; k < passes; ++k) {
        psb->solveConstraints();
        holdIteration(st, psb, push, k + 1 == passes);
    }
    psb->m_cfg.piterations = passes;
}

int guardRecord(SoftState* st, SoftRecord& rec, double tol)
{
    btSoftBody* psb = const_cast<btSoftBody*>(rec.soft);
    const int nn = psb->m_nodes.size();
    if ((size_t)nn != rec.start.size()) return 0;
    // Start positions in the SDF's frame at the start of the step, end positions in its frame now (a
    // moving SDF body: the relative motion, linear in its frame).
    const Frame F0(rec.sdf_pose), F(rec.sdf_object->getWorldTransform());
    const double L = lipschitzOf(rec.sdf);
    int64_t evals = 0;
    std::vector<char> moved((size_t)nn, 0);
    std::vector<double> level((size_t)nn, -tol);
    std::vector<D3> S((size_t)nn);
    rec.sizeCerts(nn, psb->m_faces.size() + psb->m_links.size());
    auto endOf = [&](int i) { return F.toLocal(d3(psb->m_nodes[i].m_x)); };
    std::vector<char> touched((size_t)nn, 0), touched_next((size_t)nn, 0);
    // Bullet's own rule after its position solve: v = (x - q) / dt, damped by kDP.
    const double inv_dt = psb->m_sst.sdt > 0 ? (1.0 - psb->m_cfg.kDP) / psb->m_sst.sdt : 0.0;
    auto setEnd = [&](int i, D3 local) {
        // The node's executed motion is now start -> here: its velocity says so (then loses its part
        // into the surface, stopInto).
        const D3 w = F.toWorld(local);
        psb->m_nodes[i].m_x = btv(w);
        psb->m_nodes[i].m_v = btv((w - rec.start[(size_t)i]) * inv_dt);
        moved[(size_t)i] = 1;
        touched_next[(size_t)i] = 1;
    };
    // Nodes (sdfccd_guard_point: each one's level, and where it goes back to).
    for (int i = 0; i < nn; ++i) {
        S[(size_t)i] = F0.toLocal(rec.start[(size_t)i]);
        const D3 e = endOf(i);
        if (certClears(rec.node_certs[(size_t)i], &S[(size_t)i], &e, 1, L, -tol)) continue; // sdfccd_guard_point's first check
        sdfccd_PointGuard pg;
        if (sdfccd_guard_point(rec.sdf, &rec.node_certs[(size_t)i], sv(S[(size_t)i]), sv(e), tol, L, &pg, &evals) != SDFCCD_OK) continue;
        level[(size_t)i] = pg.level;
        if (!pg.hit) continue;
        setEnd(i, S[(size_t)i] + (e - S[(size_t)i]) * pg.fraction);
        stopInto(psb->m_nodes[i], F.dirToWorld(unit(fromSv(pg.gradient))));
    }
    // Faces, repeated while a pass moves nodes (a moved node changes its faces' motion).
    const double dt = psb->m_sst.sdt > 0 ? psb->m_sst.sdt : 1.0;
    if (st->contacts.size() < 8) st->contacts.resize(8);
    // After `passes` passes a face still crossing goes back to its start (where the last check left
    // it), and so on for the faces of the nodes that moves, until none crosses: every change puts
    // nodes at their start, so this ends.
    const int passes = 4;
    for (int pass = 0; pass <= passes + nn; ++pass) {
        bool changed = false;
        // Links of a body without faces (ropes): points along each link every h at most (tol / 2), each
        // path held to its level + L h / 2, so no point between them goes below the level either.
        for (int li = 0; psb->m_faces.size() == 0 && li < psb->m_links.size(); ++li) {
            const btSoftBody::Link& link = psb->m_links[li];
            const int a = (int)(link.m_n[0] - &psb->m_nodes[0]), b = (int)(link.m_n[1] - &psb->m_nodes[0]);
            if (pass > 0 && !touched[(size_t)a] && !touched[(size_t)b]) continue;
            const D3 s[3] = { S[(size_t)a], S[(size_t)b], S[(size_t)b] }, e[3] = { endOf(a), endOf(b), endOf(b) };
            const double lev = std::min(level[(size_t)a], level[(size_t)b]);
            if (faceClear(rec.sdf, rec.face_certs[(size_t)(psb->m_faces.size() + li)], s, e, lev, L, &evals)) continue;
            const sdfccd_Vec3 ss[2] = { sv(s[0]), sv(s[1]) }, ee[2] = { sv(e[0]), sv(e[1]) };
            sdfccd_PointHit hit;
            if (sdfccd_segment_first_hit(rec.sdf, ss, ee, lev, 0.5 * tol, L, &hit, &evals) != SDFCCD_OK || !hit.hit) continue;
            const double first = hit.fraction;
            const D3 grad = fromSv(hit.gradient);
            const double f = pass >= passes ? 0.0 : first;
            for (int k = 0; k < 2; ++k) {
                setEnd(k ? b : a, s[k] + (e[k] - s[k]) * f);
                stopInto(psb->m_nodes[k ? b : a], F.dirToWorld(unit(grad)));
            }
            changed = true;
        }
        for (int fi = 0; fi < psb->m_faces.size(); ++fi) {
            btSoftBody::Face& face = psb->m_faces[fi];
            int idx[3];
            D3 s[3], e[3];
            double lev = 0;
            for (int k = 0; k < 3; ++k) {
                idx[k] = (int)(face.m_n[k] - &psb->m_nodes[0]);
                s[k] = S[(size_t)idx[k]];
                e[k] = endOf(idx[k]);
                lev = std::min(lev, level[(size_t)idx[k]]);
            }
            if (pass > 0 && !touched[(size_t)idx[0]] && !touched[(size_t)idx[1]] && !touched[(size_t)idx[2]]) continue;
            if (certClears(rec.face_certs[(size_t)fi], s, e, 3, L, lev)) continue; // what sdfccd_guard_face checks first
            const sdfccd_Vec3 ss[3] = { sv(s[0]), sv(s[1]), sv(s[2]) }, ee[3] = { sv(e[0]), sv(e[1]), sv(e[2]) };
            sdfccd_FaceGuard fg;
            const sdfccd_Status status = sdfccd_guard_face(rec.sdf, &rec.face_certs[(size_t)fi], ss, ee, lev, tol, L, &st->impl->cfg.query,
                                                           dt, pass >= passes, &fg, &evals);
            if (status != SDFCCD_OK) {
                if (status != SDFCCD_DEGENERATE) ++st->stats.query_errors;
                continue;
            }
            st->stats.face_queries += fg.queries;
            if (!fg.hit) continue;
            for (int k = 0; k < 3; ++k) {
                setEnd(idx[k], s[k] + (e[k] - s[k]) * fg.fraction);
                if (fg.stop) stopInto(*face.m_n[k], F.dirToWorld(unit(fromSv(fg.normal))));
            }
            changed = true;
        }
        if (!changed) break;
        touched.swap(touched_next); // the next pass checks the faces of the nodes this one moved
        std::fill(touched_next.begin(), touched_next.end(), 0);
    }
    st->stats.sdf_evaluations += evals;
    int count = 0;
    for (int i = 0; i < nn; ++i) count += moved[(size_t)i] ? 1 : 0;
    return count;
}

// The world's soft-body solver, private in btSoftRigidDynamicsWorld, reached through an explicit
// instantiation (where access is not checked), so that the guard runs right after the soft-body solve.
template <typename Tag, typename Tag::type M>
struct Reach {
    friend typename Tag::type reach(Tag) { return M; }
};
struct SolverField {
    typedef btSoftBodySolver* btSoftRigidDynamicsWorld::*type;
    friend type reach(SolverField);
};
struct OwnsField {
    typedef bool btSoftRigidDynamicsWorld::*type;
    friend type reach(OwnsField);
};
template struct Reach<SolverField, &btSoftRigidDynamicsWorld::m_softBodySolver>;
template struct Reach<OwnsField, &btSoftRigidDynamicsWorld::m_ownsSolver>;

int guardWorld(SoftState* st, btSoftRigidDynamicsWorld* world, double tolerance)
{
    std::set<const void*> live;
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    for (int i = 0; i < objs.size(); ++i) live.insert(objs[i]);
    BridgeImpl* impl = st->impl;
    int moved = 0;
    // Pairs collision detection saw this step: their recorded start positions.
    for (auto it = st->records.begin(); it != st->records.end();) {
        SoftRecord& rec = it->second;
        if (!live.count(rec.soft) || !live.count(rec.sdf_object)) { // removed from the world: forget it
            it = st->records.erase(it);
            continue;
        }
        if (rec.fresh) moved += guardRecord(st, rec, tolerance);
        ++it;
    }
    // Pairs it did not see: Bullet's box of a soft body covers its predicted nodes, not their paths, so
    // a body crossing a thin SDF within one step never gets a pair. Checked from m_q (the start of the
    // step) when the nodes' swept box meets the SDF body's box.
    btSoftBodyArray& softs = world->getSoftBodyArray();
    for (int b = 0; b < softs.size(); ++b) {
        btSoftBody* psb = softs[b];
        if (psb->m_nodes.size() == 0) continue;
        btVector3 lo = psb->m_nodes[0].m_q, hi = lo;
        for (int i = 0; i < psb->m_nodes.size(); ++i) {
            lo.setMin(psb->m_nodes[i].m_q);
            lo.setMin(psb->m_nodes[i].m_x);
            hi.setMax(psb->m_nodes[i].m_q);
            hi.setMax(psb->m_nodes[i].m_x);
        }
        for (int i = 0; i < objs.size(); ++i) {
            const btCollisionObject* co = objs[i];
            if (co == psb) continue;
            auto key = std::make_pair((const void*)psb, (const void*)co);
            auto found = st->records.find(key);
            if (found != st->records.end() && found->second.fresh) continue;
            const sdfccd_SdfId sdf = impl->shapes.sdfFor(co->getCollisionShape(), impl->cfg.sdf_shape_type, impl->cfg.handle_bt_sdf_shape);
            if (sdf.index1 == 0) continue;
            btVector3 bmin, bmax, smin, smax; // the SDF body's box at the start and at the end of the step
            co->getCollisionShape()->getAabb(co->getWorldTransform(), bmin, bmax);
            co->getCollisionShape()->getAabb(startPose(co, psb->m_sst.sdt), smin, smax);
            bmin.setMin(smin);
            bmax.setMax(smax);
            const btScalar reach = (btScalar)tolerance;
            if (bmin.x() > hi.x() + reach || bmin.y() > hi.y() + reach || bmin.z() > hi.z() + reach ||
                bmax.x() < lo.x() - reach || bmax.y() < lo.y() - reach || bmax.z() < lo.z() - reach)
                continue;
            SoftRecord& rec = st->records[key];
            rec.soft = psb;
            rec.sdf_object = co;
            rec.setSdf(sdf);
            rec.sdf_pose = startPose(co, psb->m_sst.sdt);
            rec.start.resize((size_t)psb->m_nodes.size());
            for (int k = 0; k < psb->m_nodes.size(); ++k) rec.start[(size_t)k] = d3(psb->m_nodes[k].m_q);
            moved += guardRecord(st, rec, tolerance);
        }
    }
    for (auto& r : st->records) r.second.fresh = false;
    st->stats.guard_nodes += moved;
    return moved;
}


// Bullet's solver, with the guard after each solve (the world owns this wrapper; the wrapper owns the
// solver it wraps when the world did).
class GuardingSolver : public btSoftBodySolver
{
public:
    GuardingSolver(btSoftBodySolver* inner, bool owns, SoftState* st, btSoftRigidDynamicsWorld* world)
        : m_inner(inner), m_owns(owns), m_state(st), m_world(world)
    {
        m_timeScale = inner->getTimeScale();
        m_numberOfPositionIterations = inner->getNumberOfPositionIterations();
        m_numberOfVelocityIterations = inner->getNumberOfVelocityIterations();
    }
    ~GuardingSolver() override
    {
        if (m_state && m_state->wrapper == this) m_state->wrapper = nullptr; // the world is going away
        if (m_owns) {
            m_inner->~btSoftBodySolver();
            btAlignedFree(m_inner);
        }
    }
    SolverTypes getSolverType() const override { return m_inner->getSolverType(); }
    bool checkInitialized() override { return m_inner->checkInitialized(); }
    void optimize(btAlignedObjectArray<btSoftBody*>& bodies, bool force) override { m_inner->optimize(bodies, force); }
    void copyBackToSoftBodies(bool move) override { m_inner->copyBackToSoftBodies(move); }
    void predictMotion(btScalar dt) override { m_inner->predictMotion(dt); }
    void solveConstraints(btScalar dt) override
    {
        if (m_state && m_state->dispatcher) { // Bullet's solver's loop, with the contact planes held
            btSoftBodyArray& softs = m_world->getSoftBodyArray();
            for (int i = 0; i < softs.size(); ++i)
                if (softs[i]->isActive() && !softs[i]->isStaticObject()) solveHeld(m_state, softs[i]);
            for (auto& r : m_state->records) r.second.holds.clear(); // this step's planes
        } else {
            m_inner->solveConstraints(dt);
        }
        if (m_state && m_state->dispatcher && m_state->auto_guard && m_state->impl->cfg.query.method != SDFCCD_METHOD_DCD) {
            guardWorld(m_state, m_world, m_state->auto_tolerance);
            m_state->guarded_this_step = true;
        }
    }
    void updateSoftBodies() override { m_inner->updateSoftBodies(); }
    void processCollision(btSoftBody* b, const btCollisionObjectWrapper* w) override { m_inner->processCollision(b, w); }
    void processCollision(btSoftBody* a, btSoftBody* b) override { m_inner->processCollision(a, b); }
    void setNumberOfPositionIterations(int n) override { m_inner->setNumberOfPositionIterations(n); }
    int getNumberOfPositionIterations() override { return m_inner->getNumberOfPositionIterations(); }
    void setNumberOfVelocityIterations(int n) override { m_inner->setNumberOfVelocityIterations(n); }
    int getNumberOfVelocityIterations() override { return m_inner->getNumberOfVelocityIterations(); }

    btSoftBodySolver* m_inner;
    bool m_owns;
    SoftState* m_state;
    btSoftRigidDynamicsWorld* m_world;
};

} // namespace

void softRegister(BridgeImpl* impl, btCollisionDispatcher* d)
{
    std::unique_ptr<SoftState> st(new SoftState);
    st->impl = impl;
    st->dispatcher = d;
    st->fn[0].state = st.get();
    st->fn[1].state = st.get();
    st->fn[1].m_swapped = true;
    st->slots.push_back(std::make_pair((int)SOFTBODY_SHAPE_PROXYTYPE, impl->cfg.sdf_shape_type));
    if (impl->cfg.handle_bt_sdf_shape) st->slots.push_back(std::make_pair((int)SOFTBODY_SHAPE_PROXYTYPE, (int)SDF_SHAPE_PROXYTYPE));
    for (const auto& s : st->slots) {
        d->registerCollisionCreateFunc(s.first, s.second, &st->fn[0]);
        d->registerCollisionCreateFunc(s.second, s.first, &st->fn[1]);
    }
    std::lock_guard<std::mutex> lock(g_soft_mutex);
    g_soft[impl] = std::move(st);
}


void softAttach(BridgeImpl* impl, btCollisionWorld* cw)
{
    btSoftRigidDynamicsWorld* world = dynamic_cast<btSoftRigidDynamicsWorld*>(cw);
    SoftState* st = softOf(impl);
    if (!world || !st || st->wrapper) return;
    btSoftBodySolver*& slot = world->*reach(SolverField());
    bool& owns = world->*reach(OwnsField());
    if (!slot || slot->getSolverType() != btSoftBodySolver::DEFAULT_SOLVER) return; // only Bullet's CPU solver
    void* mem = btAlignedAlloc(sizeof(GuardingSolver), 16);
    GuardingSolver* g = new (mem) GuardingSolver(slot, owns, st, world);
    st->world = world;
    st->inner = slot;
    st->world_owned_inner = owns;
    st->wrapper = g;
    slot = g;
    owns = true; // the world frees the wrapper (and the wrapper its solver when the world owned it)
    btSoftBodyArray& softs = world->getSoftBodyArray();
    for (int i = 0; i < softs.size(); ++i) softs[i]->setSoftBodySolver(g);
}

// Puts the world's own solver back (the world must still exist: see Bridge's lifetime note).
void softDetach(SoftState* st)
{
    if (!st->wrapper || !st->world) return;
    btSoftRigidDynamicsWorld* world = st->world;
    btSoftBodySolver*& slot = world->*reach(SolverField());
    bool& owns = world->*reach(OwnsField());
    if (slot == st->wrapper) {
        slot = st->inner;
        owns = st->world_owned_inner;
        btSoftBodyArray& softs = world->getSoftBodyArray();
        for (int i = 0; i < softs.size(); ++i) softs[i]->setSoftBodySolver(st->inner);
        GuardingSolver* g = st->wrapper;
        g->m_owns = false;
        g->m_state = nullptr;
        g->~GuardingSolver();
        btAlignedFree(g);
    }
    st->wrapper = nullptr;
    st->world = nullptr;
}

void softUnregister(BridgeImpl* impl)
{
    SoftState* st = softOf(impl);
    if (!st || !st->dispatcher) return;
    softDetach(st);
    btCollisionConfiguration* cc = st->dispatcher->getCollisionConfiguration();
    for (const auto& s : st->slots) {
        st->dispatcher->registerCollisionCreateFunc(s.first, s.second, cc->getCollisionAlgorithmCreateFunc(s.first, s.second));
        st->dispatcher->registerCollisionCreateFunc(s.second, s.first, cc->getCollisionAlgorithmCreateFunc(s.second, s.first));
    }
    st->dispatcher = nullptr;
    st->records.clear();
}

void softForget(BridgeImpl* impl)
{
    SoftState* st = softOf(impl);
    if (st && st->wrapper) st->wrapper->m_state = nullptr; // the world still holds it: make it a plain solver
    std::lock_guard<std::mutex> lock(g_soft_mutex);
    g_soft.erase(impl);
}

} // namespace detail

SoftBodyStats softBodyStats(const Bridge& bridge)
{
    const detail::SoftState* st = detail::softOf(BridgeAccess::of(const_cast<Bridge&>(bridge)));
    return st ? st->stats : SoftBodyStats();
}

bool setSoftBodyGuard(Bridge& bridge, bool on, double tolerance)
{
    detail::SoftState* st = detail::softOf(BridgeAccess::of(bridge));
    if (!st || !(tolerance > 0) || !std::isfinite(tolerance)) return false;
    st->auto_guard = on;
    st->auto_tolerance = tolerance;
    st->guarded_this_step = false;
    return st->wrapper != nullptr;
}

int guardSoftBodies(Bridge& bridge, btSoftRigidDynamicsWorld* world, double tolerance)
{
    if (!world || !(tolerance > 0) || !std::isfinite(tolerance)) return -1;
    detail::SoftState* st = detail::softOf(BridgeAccess::of(bridge));
    if (!st || !st->dispatcher || st->dispatcher != world->getDispatcher()) return -1;
    if (st->world == world && st->guarded_this_step) { // the automatic guard already checked this step
        st->guarded_this_step = false;
        return 0;
    }
    return detail::guardWorld(st, world, tolerance);
}

SDFCCD_BULLET_NAMESPACE_END
