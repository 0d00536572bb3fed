// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: the GImpact-mesh-vs-SDF collision algorithm, its registration, the
// closest-points path, calculateTimeOfImpact and the optional hard clamp (see bridge.h).
// The method (speculative contacts with distance = gap at step start, restitution 0, written
// straight into the manifold) follows notes/bullet-integration.md section 3.4 A.
#include "sdfccd_bullet/bridge.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <new>
#include <set>
#include <unordered_map>
#include <vector>

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionShapes/btSdfCollisionShape.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <LinearMath/btPoolAllocator.h>
#include <LinearMath/btTransformUtil.h>

SDFCCD_BULLET_NAMESPACE_BEGIN

namespace {

const sdfccd_SdfId kNullSdf = { 0, 0 };
const int kQueryCapacity = 64;

// Dispatchers that have a bridge (for the "registered twice" check across bridges).
std::mutex g_registry_mutex;
std::set<const btCollisionDispatcher*> g_registered;

sdfccd_Vec3 v3(const btVector3& v)
{
    sdfccd_Vec3 r = { (double)v.x(), (double)v.y(), (double)v.z() };
    return r;
}
btVector3 bt(const sdfccd_Vec3& v) { return btVector3((btScalar)v.x, (btScalar)v.y, (btScalar)v.z); }

sdfccd_Pose toPose(const btTransform& t)
{
    sdfccd_Pose p;
    p.position = v3(t.getOrigin());
    btQuaternion q = t.getRotation();
    p.orientation.w = q.w();
    p.orientation.x = q.x();
    p.orientation.y = q.y();
    p.orientation.z = q.z();
    return p;
}

// Start and end pose of a body over a step, and the constant velocities that connect them in
// Bullet's motion model (origin lerp + exponential-map rotation), which is also sdfccd's.
struct BodyMotion {
    btTransform t0, t1;
    btVector3 v, w;
    sdfccd_RigidMotion rigid() const
    {
        sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
        m.pose = toPose(t0);
        m.linear_velocity = v3(v);
        m.angular_velocity = v3(w);
        return m;
    }
    btTransform at(double t) const
    {
        btTransform r;
        btTransformUtil::integrateTransform(t0, v, w, (btScalar)t, r);
        return r;
    }
};

BodyMotion motionOf(const btCollisionObject* co, const btTransform& wrapper_transform, double dt)
{
    BodyMotion m;
    m.t0 = m.t1 = wrapper_transform;
    m.v.setZero();
    m.w.setZero();
    if (!(dt > 0)) return m;
    // Kinematic first: Bullet's idiom for a kinematic body (mass 0 plus CF_KINEMATIC_OBJECT)
    // leaves CF_STATIC_OBJECT set as well.
    if (co->isKinematicObject()) {
        // saveKinematicState has already moved the world transform to the END of the step and
        // set the interpolation velocities; rebuild the start pose by integrating backwards.
        m.v = co->getInterpolationLinearVelocity();
        m.w = co->getInterpolationAngularVelocity();
        btTransformUtil::integrateTransform(wrapper_transform, -m.v, -m.w, (btScalar)dt, m.t0);
        // Re-derive the velocities from the pair of poses so the model reproduces t1 exactly.
        btTransformUtil::calculateVelocity(m.t0, m.t1, (btScalar)dt, m.v, m.w);
        return m;
    }
    if (co->isStaticObject()) return m;
    // Dynamic: world transform = start, interpolation transform = predicted end (set by
    // predictUnconstraintMotion before the narrow phase). A child offset (compound) is kept.
    btTransform child = co->getWorldTransform().inverseTimes(wrapper_transform);
    m.t1 = co->getInterpolationWorldTransform() * child;
    btTransformUtil::calculateVelocity(m.t0, m.t1, (btScalar)dt, m.v, m.w);
    return m;
}

// A GImpact triangle mesh packed for sdfccd (scaled, local frame) and the handle built from it.
struct MeshEntry {
    sdfccd_MeshId id = { 0, 0 };
    btVector3 scaling;
    int source_triangles = 0;
    std::vector<double> vertices;
    std::vector<uint32_t> indices;
    bool ok = false;
};

int gimpactTriangleCount(const btGImpactShapeInterface* g)
{
    if (g->getGImpactShapeType() == CONST_GIMPACT_TRIMESH_SHAPE) {
        const btGImpactMeshShape* m = static_cast<const btGImpactMeshShape*>(g);
        int n = 0;
        for (int i = 0; i < m->getMeshPartCount(); ++i) n += m->getMeshPart(i)->getNumChildShapes();
        return n;
    }
    return g->getNumChildShapes();
}

void packPart(const btGImpactMeshShapePart* part, MeshEntry& e)
{
    part->lockChildShapes();
    const uint32_t base = (uint32_t)(e.vertices.size() / 3);
    const int nv = part->getVertexCount();
    for (int i = 0; i < nv; ++i) {
        btVector3 v;
        part->getVertex(i, v); // scaled by the shape's local scaling
        e.vertices.push_back(v.x());
        e.vertices.push_back(v.y());
        e.vertices.push_back(v.z());
    }
    btGImpactMeshShapePart::TrimeshPrimitiveManager* pm =
        const_cast<btGImpactMeshShapePart*>(part)->getTrimeshPrimitiveManager();
    const int nt = part->getNumChildShapes();
    for (int t = 0; t < nt; ++t) {
        unsigned int a, b, c;
        pm->get_indices(t, a, b, c);
        if ((int)a >= nv || (int)b >= nv || (int)c >= nv) continue;
        // Drop zero-area triangles here (stricter than the library's own check, so the triangle
        // numbering the library reports is ours).
        const double* va = &e.vertices[3 * (base + a)];
        const double* vb = &e.vertices[3 * (base + b)];
        const double* vc = &e.vertices[3 * (base + c)];
        btVector3 A(va[0], va[1], va[2]), B(vb[0], vb[1], vb[2]), C(vc[0], vc[1], vc[2]);
        double s = std::max((B - A).length2(), (C - A).length2());
        if (!((double)(B - A).cross(C - A).length() > 1e-10 * s)) continue;
        e.indices.push_back(base + a);
        e.indices.push_back(base + b);
        e.indices.push_back(base + c);
    }
    part->unlockChildShapes();
}

// btSdfCollisionShape sampled through queryPoint, as an sdfccd callback SDF.
struct BtSdfData {
    btSdfCollisionShape* shape;
    btVector3 lo, hi;
    double hole_value;
};

double btSdfEval(sdfccd_Vec3 p, sdfccd_Vec3* out_grad, void* user)
{
    BtSdfData* d = static_cast<BtSdfData*>(user);
    btVector3 x = bt(p);
    btVector3 eps = (d->hi - d->lo) * btScalar(1e-6);
    btVector3 q = x;
    q.setMax(d->lo + eps);
    q.setMin(d->hi - eps);
    btVector3 out = x - q;
    double outside = (double)out.length();
    btScalar dist = 0;
    btVector3 n(0, 0, 0);
    bool ok = d->shape->queryPoint(q, dist, n);
    btVector3 g;
    double phi;
    if (ok) {
        phi = (double)dist + outside; // outside the grid: distance to the box plus the boundary value
        g = outside > 0 ? out / btScalar(outside) : n;
    } else {
        // A cell without data (narrow-band grids): far from the surface by construction.
        phi = d->hole_value + outside;
        g = x - (d->lo + d->hi) * btScalar(0.5);
    }
    if (out_grad) {
        btScalar l = g.length();
        *out_grad = v3(l > btScalar(0) ? g / l : btVector3(0, 0, 1));
    }
    return phi;
}

struct BtSdfEntry {
    sdfccd_SdfId id = { 0, 0 };
    std::unique_ptr<BtSdfData> data;
};

struct Candidate {
    btVector3 local; // material point in the mesh's frame
    btVector3 pA0, pB0, n0;
    double d;        // gap at step start along n0
    int triangle;
};

double triArea(const btVector3& a, const btVector3& b, const btVector3& c) { return (double)(b - a).cross(c - a).length(); }

// Up to `k` well-spread candidates: the deepest (smallest gap), then the one farthest from it,
// the one maximising the triangle, the one maximising the quad (sum of the three triangles it
// forms with the others). Spread is measured in the plane of the first contact (points projected
// along its normal), so a point right above another adds nothing; among candidates within 5% of
// the best spread the one with the smallest gap wins (it is the one the solver must respect).
std::vector<int> selectSpread(const std::vector<Candidate>& c, int k)
{
    std::vector<int> out;
    if (c.empty() || k <= 0) return out;
    int first = 0;
    for (int i = 1; i < (int)c.size(); ++i)
        if (c[i].d < c[first].d) first = i;
    out.push_back(first);
    const btVector3 nref = c[first].n0;
    std::vector<btVector3> p(c.size());
    for (size_t i = 0; i < c.size(); ++i) p[i] = c[i].pA0 - nref * nref.dot(c[i].pA0);
    std::vector<char> taken(c.size(), 0);
    taken[first] = 1;
    std::vector<double> score(c.size());
    while ((int)out.size() < k) {
        double best = 0;
        for (size_t i = 0; i < c.size(); ++i) {
            if (taken[i]) continue;
            const btVector3& q = p[i];
            double s;
            if (out.size() == 1) s = (double)(q - p[out[0]]).length();
            else if (out.size() == 2) s = triArea(p[out[0]], p[out[1]], q);
            else s = triArea(p[out[0]], p[out[1]], q) + triArea(p[out[1]], p[out[2]], q) + triArea(p[out[2]], p[out[0]], q);
            score[i] = s;
            best = std::max(best, s);
        }
        // Nothing adds spread: a single point (distance 1e-6) or all on a line/inside (area 1e-12).
        if (best <= (out.size() == 1 ? 1e-6 : 1e-12)) break;
        int pick = -1;
        for (size_t i = 0; i < c.size(); ++i)
            if (!taken[i] && score[i] >= 0.95 * best && (pick < 0 || c[i].d < c[pick].d)) pick = (int)i;
        taken[pick] = 1;
        out.push_back(pick);
    }
    return out;
}

} // namespace

class MeshSdfAlgorithm;

// ---------------------------------------------------------------------------------------------
class BridgeImpl
{
public:
    explicit BridgeImpl(const Config& c) : cfg(c)
    {
        cfg.max_contacts = std::max(1, std::min(cfg.max_contacts, 4));
        if (!(cfg.contact_margin >= 0)) cfg.contact_margin = 0;
    }
    ~BridgeImpl()
    {
        for (auto& m : meshes)
            if (m.second.id.index1) sdfccd_destroy_mesh(m.second.id);
        for (auto& s : bt_sdfs)
            if (s.second.id.index1) sdfccd_destroy_sdf(s.second.id);
    }

    // One body's shape -> packed sdfccd mesh (NULL if not a supported GImpact mesh).
    const MeshEntry* meshFor(const btCollisionShape* shape)
    {
        if (shape->getShapeType() != GIMPACT_SHAPE_PROXYTYPE) return nullptr;
        const btGImpactShapeInterface* g = static_cast<const btGImpactShapeInterface*>(shape);
        if (g->getGImpactShapeType() == CONST_GIMPACT_COMPOUND_SHAPE) return nullptr;
        int tris = gimpactTriangleCount(g);
        auto it = meshes.find(shape);
        if (it != meshes.end()) {
            if (it->second.scaling == shape->getLocalScaling() && it->second.source_triangles == tris)
                return it->second.ok ? &it->second : nullptr;
            if (it->second.id.index1) sdfccd_destroy_mesh(it->second.id);
            meshes.erase(it);
        }
        MeshEntry& e = meshes[shape];
        e.scaling = shape->getLocalScaling();
        e.source_triangles = tris;
        if (g->getGImpactShapeType() == CONST_GIMPACT_TRIMESH_SHAPE) {
            const btGImpactMeshShape* m = static_cast<const btGImpactMeshShape*>(g);
            for (int i = 0; i < m->getMeshPartCount(); ++i) packPart(m->getMeshPart(i), e);
        } else {
            packPart(static_cast<const btGImpactMeshShapePart*>(g), e);
        }
        if (e.indices.empty()) return nullptr;
        sdfccd_MeshDef def = sdfccd_default_mesh_def();
        def.vertices = e.vertices.data();
        def.vertex_count = (uint32_t)(e.vertices.size() / 3);
        def.indices = e.indices.data();
        def.triangle_count = (uint32_t)(e.indices.size() / 3);
        def.drop_degenerate = 1;
        e.ok = sdfccd_create_mesh(&def, &e.id) == SDFCCD_OK;
        return e.ok ? &e : nullptr;
    }

    // One body's shape -> the SDF handle to query (null handle if unsupported).
    sdfccd_SdfId sdfFor(const btCollisionShape* shape)
    {
        const int type = shape->getShapeType();
        if (type == cfg.sdf_shape_type)
            if (const SdfShape* s = dynamic_cast<const SdfShape*>(shape)) return s->querySdf();
        if (type == SDF_SHAPE_PROXYTYPE && cfg.handle_bt_sdf_shape)
            if (const btSdfCollisionShape* s = dynamic_cast<const btSdfCollisionShape*>(shape)) return btSdfFor(s);
        return kNullSdf;
    }

    sdfccd_SdfId btSdfFor(const btSdfCollisionShape* shape)
    {
        auto it = bt_sdfs.find(shape);
        if (it != bt_sdfs.end()) return it->second.id;
        BtSdfEntry& e = bt_sdfs[shape];
        e.data.reset(new BtSdfData);
        e.data->shape = const_cast<btSdfCollisionShape*>(shape); // queryPoint is non-const but only reads
        btTransform id;
        id.setIdentity();
        shape->getAabb(id, e.data->lo, e.data->hi);
        e.data->hole_value = 0.05 * (double)(e.data->hi - e.data->lo).length();
        sdfccd_CallbackSdfDef def = sdfccd_default_callback_sdf_def();
        def.eval = btSdfEval;
        def.user = e.data.get();
        def.lipschitz = 1.0;
        def.bounds.lo = v3(e.data->lo);
        def.bounds.hi = v3(e.data->hi);
        if (sdfccd_create_callback_sdf(&def, &e.id) != SDFCCD_OK) e.id = kNullSdf;
        return e.id;
    }

    bool supports(const btCollisionShape* mesh, const btCollisionShape* sdf) const
    {
        if (mesh->getShapeType() != GIMPACT_SHAPE_PROXYTYPE) return false;
        if (static_cast<const btGImpactShapeInterface*>(mesh)->getGImpactShapeType() == CONST_GIMPACT_COMPOUND_SHAPE)
            return false;
        const int type = sdf->getShapeType();
        if (type == cfg.sdf_shape_type && dynamic_cast<const SdfShape*>(sdf)) return true;
        return type == SDF_SHAPE_PROXYTYPE && cfg.handle_bt_sdf_shape && dynamic_cast<const btSdfCollisionShape*>(sdf);
    }

    // Runs the query for one pair and collects the contact candidates. Returns false when there
    // is nothing to write (no hit, unsupported shapes, or an error).
    bool query(const btCollisionObject* mo, const btTransform& mt, const btCollisionObject* so, const btTransform& st,
               double dt, double margin, std::vector<Candidate>& cands, bool& speculative, sdfccd_QueryResult& res)
    {
        cands.clear();
        const MeshEntry* me = meshFor(mo->getCollisionShape());
        sdfccd_SdfId sdf = sdfFor(so->getCollisionShape());
        if (!me || !sdf.index1) return false;
        BodyMotion M = motionOf(mo, mt, dt), S = motionOf(so, st, dt);
        sdfccd_RigidMotion mm = M.rigid(), sm = S.rigid();
        sdfccd_QueryParams params = cfg.query;
        params.margin = margin;
        sdfccd_Contact contacts[kQueryCapacity];
        auto start = std::chrono::steady_clock::now();
        sdfccd_Status status = sdfccd_query_mesh(sdf, &sm, me->id, &mm, 0.0, dt > 0 ? dt : 0.0, &params, contacts,
                                                 kQueryCapacity, &res);
        stats.query_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        stats.queries++;
        if (status != SDFCCD_OK) {
            stats.query_errors++;
            return false;
        }
        stats.last_state = (int)res.state;
        if (!res.hit) {
            stats.last_toi_fraction = 1;
            return false;
        }
        stats.hits++;
        stats.last_toi_fraction = res.fraction;
        speculative = res.state != SDFCCD_STATE_PENETRATING && res.toi > 0;
        const double toi = res.toi;
        const btTransform Mt = M.at(toi), St = S.at(toi);

        // Maps a contact (mesh-local material point, SDF-local surface point and normal, at the
        // TOI or at the end of the step) to the manifold's frame at the start of the step.
        auto add = [&](const btVector3& local, const btVector3& qB, const btVector3& nL, int tri) {
            for (const Candidate& o : cands)
                if ((o.local - local).length2() <= btScalar(1e-12)) return; // same material point
            Candidate c;
            c.local = local;
            c.pA0 = M.t0 * local;
            c.pB0 = S.t0 * qB;
            c.n0 = S.t0.getBasis() * nL;
            c.d = (double)c.n0.dot(c.pA0 - c.pB0);
            c.triangle = tri;
            cands.push_back(c);
        };
        // A material point constrained by its own closest surface point at the START of the step
        // (gap phi(t0), normal grad phi(t0)): the form used for features found at the end pose,
        // whose end-pose normal may point out of the wrong side when the prediction is deep.
        const btTransform S0_inv = S.t0.inverse();
        auto addFromStart = [&](const btVector3& local, int tri) {
            btVector3 q = S0_inv * (M.t0 * local);
            double phi = 0;
            sdfccd_Vec3 g;
            if (sdfccd_sdf_eval(sdf, v3(q), &phi, &g) != SDFCCD_OK) return;
            btVector3 nL = bt(g);
            btScalar len = nL.length();
            if (!(len > btScalar(0))) return;
            nL /= len;
            add(local, q - nL * (btScalar)phi, nL, tri);
        };
        // The vertices of the triangles `tris` that are within `accept` of the SDF at pose (Mx, Sx):
        // a face landing flat gives its corners, which the solver needs for a stable rest.
        const double accept = margin + std::max(params.contact_slop, 1e-4);
        auto addVertices = [&](const std::vector<uint32_t>& tris, const btTransform& Mx, const btTransform& Sx, bool from_start) {
            const btTransform Sx_inv = Sx.inverse();
            for (uint32_t t : tris) {
                for (int j = 0; j < 3; ++j) {
                    const double* v = &me->vertices[3 * me->indices[3 * t + j]];
                    btVector3 local((btScalar)v[0], (btScalar)v[1], (btScalar)v[2]);
                    btVector3 q = Sx_inv * (Mx * local);
                    double phi = 0;
                    sdfccd_Vec3 g;
                    if (sdfccd_sdf_eval(sdf, v3(q), &phi, &g) != SDFCCD_OK || !(phi <= accept)) continue;
                    if (from_start) {
                        addFromStart(local, (int)t);
                        continue;
                    }
                    btVector3 nL = bt(g);
                    btScalar len = nL.length();
                    if (!(len > btScalar(0))) continue;
                    nL /= len;
                    add(local, q - nL * (btScalar)phi, nL, (int)t);
                }
            }
        };
        // Contacts reported at pose (Mx, Sx) -> candidates, plus their triangles' vertices.
        auto addContacts = [&](const sdfccd_Contact* cs, int count, const btTransform& Mx, const btTransform& Sx, bool from_start) {
            const btTransform Sx_inv = Sx.inverse(), Mx_inv = Mx.inverse();
            std::vector<uint32_t> tris;
            for (int i = 0; i < count; ++i) {
                const sdfccd_Contact& k = cs[i];
                btVector3 p = bt(k.point), nw = bt(k.normal);
                if (from_start) {
                    addFromStart(Mx_inv * p, (int)k.triangle);
                } else {
                    btVector3 q = Sx_inv * p;
                    btVector3 nL = Sx.getBasis().transpose() * nw;
                    add(Mx_inv * p, q - nL * (btScalar)k.distance, nL, (int)k.triangle);
                }
                if (k.triangle < me->indices.size() / 3 && std::find(tris.begin(), tris.end(), k.triangle) == tris.end())
                    tris.push_back(k.triangle);
            }
            addVertices(tris, Mx, Sx, from_start);
        };
        addContacts(contacts, std::min(res.contact_count, kQueryCapacity), Mt, St, false);

        // For an impact inside the step, the features in contact at the END of the step get
        // speculative constraints too (the classic speculative-contact rule: whatever the
        // predicted motion would push in is limited to its gap at the start of the step, along
        // its normal at the start). Without them a body that pivots about its first contact
        // swings the rest of itself into the SDF when it rotates fast. One discrete (DCD) query
        // at the predicted end pose, in impact steps only.
        if (dt > 0 && speculative) {
            sdfccd_RigidMotion m1 = sdfccd_default_rigid_motion(), s1 = sdfccd_default_rigid_motion();
            m1.pose = toPose(M.t1);
            s1.pose = toPose(S.t1);
            sdfccd_QueryParams dcd = params;
            dcd.method = SDFCCD_METHOD_DCD;
            sdfccd_QueryResult r1;
            sdfccd_Contact end_contacts[kQueryCapacity];
            auto t_start = std::chrono::steady_clock::now();
            sdfccd_Status st1 = sdfccd_query_mesh(sdf, &s1, me->id, &m1, 0.0, 0.0, &dcd, end_contacts, kQueryCapacity, &r1);
            stats.query_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
            stats.end_pose_queries++;
            if (st1 == SDFCCD_OK && r1.hit)
                addContacts(end_contacts, std::min(r1.contact_count, kQueryCapacity), M.t1, S.t1, true);
        }
        return !cands.empty();
    }

    void process(MeshSdfAlgorithm& alg, const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw,
                 const btDispatcherInfo& info, btManifoldResult* out, btPersistentManifold* manifold, bool closest);

    double timeOfImpact(const btCollisionObject* mo, const btCollisionObject* so, double dt)
    {
        if (!(dt > 0)) return 1.0;
        const MeshEntry* me = meshFor(mo->getCollisionShape());
        sdfccd_SdfId sdf = sdfFor(so->getCollisionShape());
        if (!me || !sdf.index1) return 1.0;
        BodyMotion M = motionOf(mo, mo->getWorldTransform(), dt), S = motionOf(so, so->getWorldTransform(), dt);
        sdfccd_RigidMotion mm = M.rigid(), sm = S.rigid();
        sdfccd_QueryParams params = cfg.query;
        params.margin = 0;
        sdfccd_QueryResult res;
        if (sdfccd_query_mesh(sdf, &sm, me->id, &mm, 0.0, dt, &params, nullptr, 0, &res) != SDFCCD_OK || !res.hit)
            return 1.0;
        return std::max(0.0, std::min(1.0, res.fraction));
    }

    // ---- hard clamp ----
    struct PairRecord { const btCollisionObject* mesh; const btCollisionObject* sdf; };
    void clampPre(btDynamicsWorld* world)
    {
        starts.clear();
        pairs.clear();
        const btCollisionObjectArray& objs = world->getCollisionObjectArray();
        for (int i = 0; i < objs.size(); ++i) {
            const btCollisionObject* o = objs[i];
            if (o->getCollisionShape()->getShapeType() == GIMPACT_SHAPE_PROXYTYPE && !o->isStaticOrKinematicObject())
                starts[o] = o->getWorldTransform();
        }
    }
    void clampPost(btDynamicsWorld* world, double dt)
    {
        for (const PairRecord& p : pairs) {
            auto it = starts.find(p.mesh);
            if (it == starts.end()) continue;
            btRigidBody* body = const_cast<btRigidBody*>(btRigidBody::upcast(p.mesh));
            if (!body) continue;
            const MeshEntry* me = meshFor(p.mesh->getCollisionShape());
            sdfccd_SdfId sdf = sdfFor(p.sdf->getCollisionShape());
            if (!me || !sdf.index1) continue;
            sdfccd_RigidMotion sm = sdfccd_default_rigid_motion();
            sm.pose = toPose(p.sdf->getWorldTransform());
            // 1. Does the end pose penetrate deeper than the tolerance?
            sdfccd_RigidMotion end = sdfccd_default_rigid_motion();
            end.pose = toPose(body->getWorldTransform());
            sdfccd_QueryParams params = cfg.query;
            params.margin = -clamp_tolerance;
            sdfccd_QueryResult res;
            if (sdfccd_query_mesh(sdf, &sm, me->id, &end, 0, 0, &params, nullptr, 0, &res) != SDFCCD_OK || !res.hit)
                continue;
            // 2. The first time along the step's motion at which the penetration reaches the
            //    tolerance (same margin); move the body back to that pose. A body that already
            //    started the step that deep is left to the ordinary contacts.
            BodyMotion M;
            M.t0 = it->second;
            M.t1 = body->getWorldTransform();
            btTransformUtil::calculateVelocity(M.t0, M.t1, (btScalar)dt, M.v, M.w);
            sdfccd_RigidMotion mm = M.rigid();
            sdfccd_Contact c[4];
            // Back to where the penetration was half the tolerance (so the next step does not
            // start at the threshold), or to the tolerance itself if the step began deeper.
            bool found = false;
            const double margins[2] = { -0.5 * clamp_tolerance, -clamp_tolerance };
            for (double mg : margins) {
                params.margin = mg;
                sdfccd_Status cst = sdfccd_query_mesh(sdf, &sm, me->id, &mm, 0, dt, &params, c, 4, &res);
                if (cst == SDFCCD_OK && res.hit && res.state != SDFCCD_STATE_PENETRATING) {
                    found = true;
                    break;
                }
            }
            if (!found) continue;
            body->setCenterOfMassTransform(M.at(res.toi));
            if (res.contact_count > 0) {
                btVector3 nrm = bt(c[0].normal);
                btVector3 v = body->getLinearVelocity();
                btScalar vn = v.dot(nrm);
                if (vn < 0) body->setLinearVelocity(v - nrm * vn);
            }
            stats.clamps++;
        }
        (void)world;
    }

    Config cfg;
    Stats stats;
    std::unordered_map<const btCollisionShape*, MeshEntry> meshes;
    std::unordered_map<const btCollisionShape*, BtSdfEntry> bt_sdfs;
    btCollisionDispatcher* dispatcher = nullptr;
    btDiscreteDynamicsWorld* clamp_world = nullptr;
    double clamp_tolerance = 1e-3;
    std::unordered_map<const btCollisionObject*, btTransform> starts;
    std::vector<PairRecord> pairs;
    std::vector<Candidate> scratch;

    struct CreateFunc;
    std::unique_ptr<CreateFunc> fn[4]; // contact: plain, swapped; closest: plain, swapped
    btGImpactCollisionAlgorithm::CreateFunc gimpact_fn;
};

// ---------------------------------------------------------------------------------------------
class MeshSdfAlgorithm : public btCollisionAlgorithm
{
public:
    MeshSdfAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, BridgeImpl* bridge, bool swapped, bool closest)
        : btCollisionAlgorithm(ci), m_bridge(bridge), m_manifold(nullptr), m_swapped(swapped), m_closest(closest)
    {
    }
    ~MeshSdfAlgorithm() override
    {
        if (m_manifold) m_dispatcher->releaseManifold(m_manifold);
    }

    void processCollision(const btCollisionObjectWrapper* body0Wrap, const btCollisionObjectWrapper* body1Wrap,
                          const btDispatcherInfo& dispatchInfo, btManifoldResult* resultOut) override
    {
        const btCollisionObjectWrapper* mw = m_swapped ? body1Wrap : body0Wrap;
        const btCollisionObjectWrapper* sw = m_swapped ? body0Wrap : body1Wrap;
        // Fixed manifold order whatever the dispatcher's order: A = mesh, B = SDF.
        if (!m_manifold) m_manifold = m_dispatcher->getNewManifold(mw->getCollisionObject(), sw->getCollisionObject());
        resultOut->setPersistentManifold(m_manifold);
        m_bridge->process(*this, mw, sw, dispatchInfo, resultOut, m_manifold, m_closest);
    }

    btScalar calculateTimeOfImpact(btCollisionObject* body0, btCollisionObject* body1, const btDispatcherInfo& dispatchInfo,
                                   btManifoldResult*) override
    {
        const btCollisionObject* mesh = m_swapped ? body1 : body0;
        const btCollisionObject* sdf = m_swapped ? body0 : body1;
        return (btScalar)m_bridge->timeOfImpact(mesh, sdf, dispatchInfo.m_timeStep);
    }

    void getAllContactManifolds(btManifoldArray& manifoldArray) override
    {
        if (m_manifold) manifoldArray.push_back(m_manifold);
    }

private:
    BridgeImpl* m_bridge;
    btPersistentManifold* m_manifold;
    bool m_swapped;
    bool m_closest;
};

// Bullet's collision-algorithm pool hands out 192-byte elements in both Debian builds; the
// algorithm stays far below (and falls back to btAlignedAlloc if a pool is smaller).
static_assert(sizeof(MeshSdfAlgorithm) <= 192, "MeshSdfAlgorithm must fit Bullet's collision-algorithm pool element");

struct BridgeImpl::CreateFunc : public btCollisionAlgorithmCreateFunc {
    BridgeImpl* bridge;
    bool closest;
    CreateFunc(BridgeImpl* b, bool swapped, bool closest_points) : bridge(b), closest(closest_points) { m_swapped = swapped; }

    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* w0,
                                                   const btCollisionObjectWrapper* w1) override
    {
        const btCollisionObjectWrapper* mw = m_swapped ? w1 : w0;
        const btCollisionObjectWrapper* sw = m_swapped ? w0 : w1;
        if (!bridge->supports(mw->getCollisionShape(), sw->getCollisionShape())) {
            bridge->stats.fallbacks++;
            if (!closest) return bridge->gimpact_fn.CreateCollisionAlgorithm(ci, w0, w1);
            btCollisionDispatcher* d = dynamic_cast<btCollisionDispatcher*>(ci.m_dispatcher1);
            if (!d) return nullptr;
            btCollisionAlgorithmCreateFunc* f = d->getCollisionConfiguration()->getClosestPointsAlgorithmCreateFunc(
                w0->getCollisionShape()->getShapeType(), w1->getCollisionShape()->getShapeType());
            return f ? f->CreateCollisionAlgorithm(ci, w0, w1) : nullptr;
        }
        void* mem = nullptr;
        btCollisionDispatcher* d = dynamic_cast<btCollisionDispatcher*>(ci.m_dispatcher1);
        btPoolAllocator* pool = d ? d->getCollisionConfiguration()->getCollisionAlgorithmPool() : nullptr;
        if (pool && pool->getElementSize() >= (int)sizeof(MeshSdfAlgorithm))
            mem = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(MeshSdfAlgorithm));
        else
            mem = btAlignedAlloc(sizeof(MeshSdfAlgorithm), 16); // freeCollisionAlgorithm falls back to btAlignedFree
        return new (mem) MeshSdfAlgorithm(ci, bridge, m_swapped, closest);
    }
};

void BridgeImpl::process(MeshSdfAlgorithm&, const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw,
                         const btDispatcherInfo& info, btManifoldResult* out, btPersistentManifold* manifold, bool closest)
{
    const btCollisionObject* mo = mw->getCollisionObject();
    const btCollisionObject* so = sw->getCollisionObject();
    const double dt = closest ? 0.0 : (double)info.m_timeStep;
    const double margin = closest ? std::max(0.0, (double)out->m_closestPointDistanceThreshold) : cfg.contact_margin;
    bool speculative = false;
    sdfccd_QueryResult res;
    if (!closest && clamp_world) pairs.push_back(PairRecord{ mo, so });
    bool any = query(mo, mw->getWorldTransform(), so, sw->getWorldTransform(), dt, margin, scratch, speculative, res);
    if (!any) {
        if (!closest) manifold->clearManifold();
        return;
    }
    std::vector<int> pick = selectSpread(scratch, cfg.max_contacts);
    if (closest) {
        for (int i : pick) out->addContactPoint(scratch[i].n0, scratch[i].pB0, (btScalar)scratch[i].d);
        return;
    }
    // Keep the solver's warm-start impulses of points that persist (same material point).
    btManifoldPoint old[MANIFOLD_CACHE_SIZE];
    const int n_old = manifold->getNumContacts();
    for (int i = 0; i < n_old; ++i) old[i] = manifold->getContactPoint(i);
    manifold->clearManifold();
    const btScalar match = manifold->getContactBreakingThreshold();
    const btTransform& worldA = mo->getWorldTransform();
    const btTransform& worldB = so->getWorldTransform();
    for (int i : pick) {
        const Candidate& c = scratch[i];
        btManifoldPoint pt(worldA.invXform(c.pA0), worldB.invXform(c.pB0), c.n0, (btScalar)c.d);
        pt.m_positionWorldOnA = c.pA0;
        pt.m_positionWorldOnB = c.pB0;
        pt.m_combinedFriction = gCalculateCombinedFrictionCallback(mo, so);
        pt.m_combinedRestitution = speculative ? btScalar(0) : gCalculateCombinedRestitutionCallback(mo, so);
        pt.m_combinedRollingFriction = gCalculateCombinedRollingFrictionCallback(mo, so);
        pt.m_combinedSpinningFriction = gCalculateCombinedSpinningFrictionCallback(mo, so);
        btPlaneSpace1(pt.m_normalWorldOnB, pt.m_lateralFrictionDir1, pt.m_lateralFrictionDir2);
        pt.m_index1 = c.triangle;
        for (int j = 0; j < n_old; ++j) {
            if ((old[j].m_localPointA - pt.m_localPointA).length2() < match * match) {
                pt.m_appliedImpulse = old[j].m_appliedImpulse;
                pt.m_appliedImpulseLateral1 = old[j].m_appliedImpulseLateral1;
                pt.m_appliedImpulseLateral2 = old[j].m_appliedImpulseLateral2;
                pt.m_lifeTime = old[j].m_lifeTime;
                break;
            }
        }
        manifold->addManifoldPoint(pt, true);
        if (speculative) stats.speculative_contacts++;
        else stats.ordinary_contacts++;
    }
}

// ---------------------------------------------------------------------------------------------
namespace {

void clampPreTick(btDynamicsWorld* world, btScalar)
{
    static_cast<BridgeImpl*>(world->getWorldUserInfo())->clampPre(world);
}
void clampPostTick(btDynamicsWorld* world, btScalar dt)
{
    static_cast<BridgeImpl*>(world->getWorldUserInfo())->clampPost(world, dt);
}

struct Probe {
    btVector3 verts[3];
    int idx[3];
    btTriangleIndexVertexArray mesh;
    btGImpactMeshShape gimpact;
    btCollisionObject gimpact_object;
    Probe()
        : verts{ btVector3(0, 0, 0), btVector3(1, 0, 0), btVector3(0, 1, 0) }, idx{ 0, 1, 2 },
          mesh(1, idx, 3 * (int)sizeof(int), 3, &verts[0][0], (int)sizeof(btVector3)), gimpact(&mesh)
    {
        gimpact.updateBound();
        gimpact_object.setCollisionShape(&gimpact);
    }
};

// True when the dispatcher creates our algorithm for (a, b) in `table`.
bool createsOurs(btCollisionDispatcher* d, btCollisionObject& a, btCollisionObject& b, ebtDispatcherQueryType table)
{
    btCollisionObjectWrapper wa(nullptr, a.getCollisionShape(), &a, a.getWorldTransform(), -1, -1);
    btCollisionObjectWrapper wb(nullptr, b.getCollisionShape(), &b, b.getWorldTransform(), -1, -1);
    btCollisionAlgorithm* alg = d->findAlgorithm(&wa, &wb, nullptr, table);
    bool ours = dynamic_cast<MeshSdfAlgorithm*>(alg) != nullptr;
    if (alg) {
        alg->~btCollisionAlgorithm();
        d->freeCollisionAlgorithm(alg);
    }
    return ours;
}

} // namespace

// ---------------------------------------------------------------------------------------------
const char* statusString(Status s)
{
    switch (s) {
    case Status::Ok: return "Ok";
    case Status::AlreadyRegistered: return "AlreadyRegistered";
    case Status::TooLate: return "TooLate";
    case Status::Overwritten: return "Overwritten";
    case Status::NotRegistered: return "NotRegistered";
    case Status::InvalidArgument: return "InvalidArgument";
    }
    return "?";
}

std::size_t collisionAlgorithmSize() { return sizeof(MeshSdfAlgorithm); }

Bridge::Bridge(const Config& config) : m_impl(new BridgeImpl(config))
{
    m_impl->fn[0].reset(new BridgeImpl::CreateFunc(m_impl, false, false));
    m_impl->fn[1].reset(new BridgeImpl::CreateFunc(m_impl, true, false));
    m_impl->fn[2].reset(new BridgeImpl::CreateFunc(m_impl, false, true));
    m_impl->fn[3].reset(new BridgeImpl::CreateFunc(m_impl, true, true));
}

Bridge::~Bridge()
{
    if (m_impl->dispatcher) {
        std::lock_guard<std::mutex> lock(g_registry_mutex);
        g_registered.erase(m_impl->dispatcher);
    }
    delete m_impl;
}

Status Bridge::registerWith(btCollisionWorld* world)
{
    if (!world) return Status::InvalidArgument;
    btCollisionDispatcher* d = dynamic_cast<btCollisionDispatcher*>(world->getDispatcher());
    if (!d) return Status::InvalidArgument;
    if (m_impl->dispatcher) return Status::AlreadyRegistered;
    {
        std::lock_guard<std::mutex> lock(g_registry_mutex);
        if (g_registered.count(d)) return Status::AlreadyRegistered;
    }
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    bool late = false;
    for (int i = 0; i < objs.size(); ++i) {
        int t = objs[i]->getCollisionShape()->getShapeType();
        if (t == GIMPACT_SHAPE_PROXYTYPE || t == m_impl->cfg.sdf_shape_type ||
            (m_impl->cfg.handle_bt_sdf_shape && t == SDF_SHAPE_PROXYTYPE))
            late = true;
    }
    if (late) return Status::TooLate;
    return registerWith(d);
}

Status Bridge::registerWith(btCollisionDispatcher* d)
{
    const Config& cfg = m_impl->cfg;
    if (!d) return Status::InvalidArgument;
    if (!(cfg.sdf_shape_type > CONCAVE_SHAPES_START_HERE && cfg.sdf_shape_type < CONCAVE_SHAPES_END_HERE) ||
        cfg.sdf_shape_type == GIMPACT_SHAPE_PROXYTYPE)
        return Status::InvalidArgument;
    if (m_impl->dispatcher) return Status::AlreadyRegistered;
    {
        std::lock_guard<std::mutex> lock(g_registry_mutex);
        if (g_registered.count(d)) return Status::AlreadyRegistered;
        if (d->getNumManifolds() > 0) return Status::TooLate;
        g_registered.insert(d);
    }
    // GImpact first: its registerAlgorithm overwrites every (GIMPACT, x) and (x, GIMPACT) slot.
    btGImpactCollisionAlgorithm::registerAlgorithm(d);
    std::vector<int> types(1, cfg.sdf_shape_type);
    if (cfg.handle_bt_sdf_shape && cfg.sdf_shape_type != SDF_SHAPE_PROXYTYPE) types.push_back(SDF_SHAPE_PROXYTYPE);
    for (int t : types) {
        d->registerCollisionCreateFunc(GIMPACT_SHAPE_PROXYTYPE, t, m_impl->fn[0].get());
        d->registerCollisionCreateFunc(t, GIMPACT_SHAPE_PROXYTYPE, m_impl->fn[1].get());
        if (cfg.closest_points) {
            d->registerClosestPointsCreateFunc(GIMPACT_SHAPE_PROXYTYPE, t, m_impl->fn[2].get());
            d->registerClosestPointsCreateFunc(t, GIMPACT_SHAPE_PROXYTYPE, m_impl->fn[3].get());
        }
    }
    m_impl->dispatcher = d;
    return verify();
}

Status Bridge::verify() const
{
    btCollisionDispatcher* d = m_impl->dispatcher;
    if (!d) return Status::NotRegistered;
    const Config& cfg = m_impl->cfg;
    Probe probe;
    SdfShape ours(kNullSdf, cfg.sdf_shape_type);
    btCollisionObject ours_object;
    ours_object.setCollisionShape(&ours);
    btSdfCollisionShape theirs;
    btCollisionObject theirs_object;
    theirs_object.setCollisionShape(&theirs);
    std::vector<btCollisionObject*> sdfs(1, &ours_object);
    if (cfg.handle_bt_sdf_shape && cfg.sdf_shape_type != SDF_SHAPE_PROXYTYPE) sdfs.push_back(&theirs_object);
    for (btCollisionObject* s : sdfs) {
        if (!createsOurs(d, probe.gimpact_object, *s, BT_CONTACT_POINT_ALGORITHMS) ||
            !createsOurs(d, *s, probe.gimpact_object, BT_CONTACT_POINT_ALGORITHMS))
            return Status::Overwritten;
        if (cfg.closest_points && (!createsOurs(d, probe.gimpact_object, *s, BT_CLOSEST_POINT_ALGORITHMS) ||
                                   !createsOurs(d, *s, probe.gimpact_object, BT_CLOSEST_POINT_ALGORITHMS)))
            return Status::Overwritten;
    }
    return Status::Ok;
}

void Bridge::unregister()
{
    btCollisionDispatcher* d = m_impl->dispatcher;
    if (!d) return;
    btCollisionConfiguration* cc = d->getCollisionConfiguration();
    std::vector<int> types(1, m_impl->cfg.sdf_shape_type); // the slots registerWith() wrote
    if (m_impl->cfg.handle_bt_sdf_shape && m_impl->cfg.sdf_shape_type != SDF_SHAPE_PROXYTYPE) types.push_back(SDF_SHAPE_PROXYTYPE);
    for (int t : types) {
        d->registerCollisionCreateFunc(GIMPACT_SHAPE_PROXYTYPE, t, cc->getCollisionAlgorithmCreateFunc(GIMPACT_SHAPE_PROXYTYPE, t));
        d->registerCollisionCreateFunc(t, GIMPACT_SHAPE_PROXYTYPE, cc->getCollisionAlgorithmCreateFunc(t, GIMPACT_SHAPE_PROXYTYPE));
        d->registerClosestPointsCreateFunc(GIMPACT_SHAPE_PROXYTYPE, t,
                                           cc->getClosestPointsAlgorithmCreateFunc(GIMPACT_SHAPE_PROXYTYPE, t));
        d->registerClosestPointsCreateFunc(t, GIMPACT_SHAPE_PROXYTYPE,
                                           cc->getClosestPointsAlgorithmCreateFunc(t, GIMPACT_SHAPE_PROXYTYPE));
    }
    std::lock_guard<std::mutex> lock(g_registry_mutex);
    g_registered.erase(d);
    m_impl->dispatcher = nullptr;
}

Status Bridge::setHardClamp(btDiscreteDynamicsWorld* world, bool on, double tolerance)
{
    if (!world) return Status::InvalidArgument;
    if (!m_impl->dispatcher) return Status::NotRegistered;
    if (on) {
        if (world->getWorldUserInfo() && world->getWorldUserInfo() != m_impl) return Status::InvalidArgument;
        m_impl->clamp_tolerance = tolerance > 0 ? tolerance : 1e-3;
        world->setInternalTickCallback(clampPreTick, m_impl, true);
        world->setInternalTickCallback(clampPostTick, m_impl, false);
        m_impl->clamp_world = world;
    } else {
        if (m_impl->clamp_world == world) {
            world->setInternalTickCallback(nullptr, nullptr, true);
            world->setInternalTickCallback(nullptr, nullptr, false);
        }
        m_impl->clamp_world = nullptr;
        m_impl->pairs.clear();
        m_impl->starts.clear();
    }
    return Status::Ok;
}

bool Bridge::hardClampEnabled() const { return m_impl->clamp_world != nullptr; }

double Bridge::timeOfImpact(const btCollisionObject* mesh_body, const btCollisionObject* sdf_body, double dt)
{
    if (!mesh_body || !sdf_body) return 1.0;
    return m_impl->timeOfImpact(mesh_body, sdf_body, dt);
}

void Bridge::invalidateShape(const btCollisionShape* shape)
{
    auto it = m_impl->meshes.find(shape);
    if (it != m_impl->meshes.end()) {
        if (it->second.id.index1) sdfccd_destroy_mesh(it->second.id);
        m_impl->meshes.erase(it);
    }
    auto jt = m_impl->bt_sdfs.find(shape);
    if (jt != m_impl->bt_sdfs.end()) {
        if (jt->second.id.index1) sdfccd_destroy_sdf(jt->second.id);
        m_impl->bt_sdfs.erase(jt);
    }
}

const Config& Bridge::config() const { return m_impl->cfg; }
Stats Bridge::stats() const { return m_impl->stats; }
void Bridge::resetStats() { m_impl->stats = Stats(); }

SDFCCD_BULLET_NAMESPACE_END
