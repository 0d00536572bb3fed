// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: btSoftBody against SDFs (soft_body.h). The step's logic is the C API's
// (sdfccd/soft.h: contact planes, holding nodes on them, the guard); this file converts Bullet's
// nodes and faces to its arrays, turns planes into RContacts or holds them inside Bullet's solve,
// and runs the guard after the solve.
#include "internal.h"

#include <cmath>
#include <map>
#include <set>
#include <typeinfo>

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <sdfccd/soft.h>

#include "sdfccd_bullet/soft_body.h"

SDFCCD_BULLET_NAMESPACE_BEGIN
namespace detail {
namespace {

const int32_t kSinglePrecision = sizeof(btScalar) == 4 ? 1 : 0;

sdfccd_Frame frameOf(const btTransform& t)
{
    sdfccd_Frame f;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) f.rotation[i][j] = (double)t.getBasis()[i][j];
    f.origin = v3(t.getOrigin());
    return f;
}

// The step of one (soft body, SDF body) pair, kept for the solve and the guard: the nodes' start
// positions and the SDF body's pose then, the certificates of its nodes and faces (links), and the
// contact planes held in Bullet's solve (solveHeld) with the pair's friction.
struct SoftRecord {
    const btSoftBody* soft = nullptr;
    const btCollisionObject* sdf_object = nullptr;
    sdfccd_SdfId sdf = kNullSdf;
    btTransform sdf_pose;
    std::vector<sdfccd_Vec3> start;
    bool fresh = false;
    std::vector<sdfccd_DistanceCert> node_certs, face_certs;
    std::vector<sdfccd_SoftPlane> holds;
    double friction = 0;
    void begin(const btSoftBody* psb, const btCollisionObject* co, sdfccd_SdfId id, const btTransform& pose)
    {
        if (id.index1 != sdf.index1 || id.generation != sdf.generation) // another field: the certificates say nothing about it
            node_certs.clear(), face_certs.clear();
        soft = psb, sdf_object = co, sdf = id, sdf_pose = pose;
        start.resize((size_t)psb->m_nodes.size());
        for (int k = 0; k < psb->m_nodes.size(); ++k) start[(size_t)k] = v3(psb->m_nodes[k].m_q);
    }
};

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

// Bullet's CPU solver (a copy of the world's btDefaultSoftBodySolver) with the contact planes held in
// its solve and the guard after it, in every internal step. The world owns it.
struct GuardingSolver : btDefaultSoftBodySolver {
    GuardingSolver(const btDefaultSoftBodySolver& inner, SoftState* st) : btDefaultSoftBodySolver(inner), state(st) {}
    ~GuardingSolver() override;
    void solveConstraints(btScalar dt) override;
    SoftState* state; // NULL once the bridge is gone: a plain solver
};

} // namespace

struct SoftState {
    BridgeImpl* impl = nullptr; // its dispatcher: the one the pairs are registered with (NULL: none)
    SoftBodyStats stats;
    sdfccd_SoftStats totals = { 0, 0, 0 }; // the C functions' counters (face queries, errors, evaluations)
    std::map<std::pair<const void*, const void*>, SoftRecord> records;
    std::set<const btCollisionShape*> reported;
    // The automatic guard (registerWith a btSoftRigidDynamicsWorld): the world, the solver it had when
    // the caller owns that one (NULL: the world did, and it is freed), and the wrapper put in its place.
    btSoftRigidDynamicsWorld* world = nullptr;
    btSoftBodySolver* inner = nullptr;
    GuardingSolver* wrapper = nullptr;
    bool guarded_this_step = false;
    // Scratch of the C API calls: the body's arrays, nodes in the hold, the guard's verdicts.
    std::vector<sdfccd_Vec3> end, x, v;
    std::vector<uint8_t> pinned;
    std::vector<int32_t> faces, links;
    std::vector<double> inverse_mass;
    std::vector<sdfccd_SoftPlane> planes;
    std::vector<sdfccd_SoftGuardNode> guarded;

    // The body as the C API sees it: start positions rec.start, end positions its nodes' m_x now;
    // rec's certificates sized to it.
    sdfccd_SoftBody bodyOf(const btSoftBody* psb, SoftRecord& rec)
    {
        const int nn = psb->m_nodes.size(), nf = psb->m_faces.size(), nl = psb->m_links.size();
        if (rec.node_certs.size() != (size_t)nn) rec.node_certs.assign((size_t)nn, sdfccd_empty_distance_cert());
        if (rec.face_certs.size() != (size_t)(nf + nl)) rec.face_certs.assign((size_t)(nf + nl), sdfccd_empty_distance_cert());
        end.resize((size_t)nn);
        pinned.resize((size_t)nn);
        for (int i = 0; i < nn; ++i) end[(size_t)i] = v3(psb->m_nodes[i].m_x), pinned[(size_t)i] = psb->m_nodes[i].m_battach ? 1 : 0;
        faces.resize(3 * (size_t)nf);
        for (int f = 0; f < nf; ++f)
            for (int k = 0; k < 3; ++k) faces[3 * (size_t)f + k] = (int32_t)(psb->m_faces[f].m_n[k] - &psb->m_nodes[0]);
        links.resize(2 * (size_t)nl);
        for (int l = 0; l < nl; ++l)
            for (int k = 0; k < 2; ++k) links[2 * (size_t)l + k] = (int32_t)(psb->m_links[l].m_n[k] - &psb->m_nodes[0]);
        return sdfccd_SoftBody{ nn, rec.start.data(), end.data(), pinned.data(), nf, faces.data(), nl, links.data(), kSinglePrecision };
    }
};

namespace {

SoftState* softOf(const BridgeImpl* impl) { return impl->soft.get(); }

// Bullet's rule for a node's velocity after its position solve: (x - q) / dt, damped by kDP.
double velocityScale(const btSoftBody* psb) { return psb->m_sst.sdt > 0 ? (1.0 - psb->m_cfg.kDP) / psb->m_sst.sdt : 0.0; }

// A node's RContact against the SDF body: the terms of Bullet's own collision handler (impulse
// matrix, anchor, ima dt, friction) from sdfccd_soft_node_contact(), hardness kKHR or kCHR.
void addContact(btSoftBody* psb, btSoftBody::Node& n, const btCollisionObject* co, const btVector3& nrm, double offset)
{
    const btRigidBody* rb = btRigidBody::upcast(co);
    sdfccd_SoftRigid body = { v3(co->getWorldTransform().getOrigin()), { 0, 0, 0 }, { 0, 0, 0 }, 0, { { 0 } } };
    if (rb) {
        body.linear_velocity = v3(rb->getLinearVelocity()), body.angular_velocity = v3(rb->getAngularVelocity());
        body.inverse_mass = rb->getInvMass();
        const btMatrix3x3& iwi = rb->getInvInertiaTensorWorld();
        for (int i = 0; i < 9; ++i) body.inverse_inertia[i / 3][i % 3] = iwi[i / 3][i % 3];
    }
    sdfccd_SoftNodeContact t;
    if (sdfccd_soft_node_contact(v3(n.m_q), v3(n.m_x), n.m_im, &body, v3(nrm), psb->m_cfg.kDF * co->getFriction(), psb->m_sst.sdt,
                                 kSinglePrecision, &t) != SDFCCD_OK)
        return;
    btSoftBody::RContact c;
    c.m_cti.m_colObj = co;
    c.m_cti.m_normal = nrm;
    c.m_cti.m_offset = (btScalar)offset;
    c.m_cti.m_bary = btVector3(0, 0, 0);
    c.m_node = &n;
    c.t1.setZero();
    c.t2.setZero();
    for (int i = 0; i < 3; ++i) c.m_c0[i] = bt(sdfccd_Vec3{ t.impulse[i][0], t.impulse[i][1], t.impulse[i][2] });
    c.m_c1 = bt(t.arm);
    c.m_c2 = (btScalar)t.mass_dt;
    c.m_c3 = (btScalar)t.friction_keep;
    c.m_c4 = co->isStaticOrKinematicObject() ? psb->m_cfg.kKHR : psb->m_cfg.kCHR;
    psb->m_rcontacts.push_back(c);
    if (rb) const_cast<btRigidBody*>(rb)->activate();
}

// The SDF body's pose at the start of the step: a kinematic body (or, after the rigid step, any
// moving one) is already at its end pose, so its velocity is integrated back over dt.
btTransform startPose(const btCollisionObject* co, double dt)
{
    const btRigidBody* rb = btRigidBody::upcast(co);
    if (!rb || (rb->isStaticObject() && !rb->isKinematicObject()) || !(dt > 0)) return co->getWorldTransform(); // (mass 0: both flags)
    return poseBefore(co, dt);
}

// The contact planes of the pair (sdfccd_soft_contacts): held in Bullet's solve against a static or
// kinematic SDF body when the bridge wraps the solver, RContacts otherwise.
void SoftSdfAlgorithm::processCollision(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1,
                                        const btDispatcherInfo&, btManifoldResult*)
{
    const btCollisionObjectWrapper* sw = m_swapped ? w0 : w1;
    btSoftBody* psb = const_cast<btSoftBody*>(btSoftBody::upcast((m_swapped ? w1 : w0)->getCollisionObject()));
    SoftState* st = m_state;
    if (!psb || !st) return;
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
    SoftRecord& rec = st->records[std::make_pair((const void*)psb, (const void*)co)];
    rec.begin(psb, co, sdf, co->isKinematicObject() ? startPose(co, psb->m_sst.sdt) : sw->getWorldTransform());
    rec.fresh = true;
    const bool hold = impl->cfg.query.method != SDFCCD_METHOD_DCD && co->isStaticOrKinematicObject() && st->wrapper;
    rec.friction = (double)(psb->m_cfg.kDF * co->getFriction());
    rec.holds.clear();
    // Bullet's soft bodies keep their collision shape's margin from rigid surfaces.
    const sdfccd_SoftContactParams params = { impl->cfg.query, std::max(0.0, (double)psb->getCollisionShape()->getMargin()),
                                              impl->cfg.contact_margin, psb->m_sst.sdt };
    const sdfccd_SoftBody body = st->bodyOf(psb, rec);
    const sdfccd_Frame frame = frameOf(sw->getWorldTransform());
    st->planes.resize(2 * (size_t)body.node_count);
    int32_t count = 0;
    if (sdfccd_soft_contacts(sdf, &frame, &body, &params, rec.node_certs.data(), rec.face_certs.data(), st->planes.data(),
                             (int32_t)st->planes.size(), &count, &st->totals) != SDFCCD_OK)
        ++st->totals.query_errors;
    for (int32_t k = 0; k < count; ++k) {
        const sdfccd_SoftPlane& pl = st->planes[(size_t)k];
        ++(pl.face ? st->stats.face_contacts : st->stats.node_contacts);
        if (hold)
            rec.holds.push_back(pl);
        else
            addContact(psb, psb->m_nodes[pl.node], co, bt(pl.normal), pl.offset);
    }
}

// Bullet's soft-body position solve (btSoftBody::solveConstraints) with the contact planes held
// (sdfccd_soft_hold, every pair of the body in turn on the same nodes) after each of its piterations
// passes: one call per pass with piterations = 1 is the same solve (links and anchors are prepared
// from m_q, velocities set from m_x - m_q at the end of each call) when the body has no velocity or
// drift passes and no clusters; otherwise the planes are held once, after the solve.
void solveHeld(SoftState* st, btSoftBody* psb)
{
    std::vector<SoftRecord*> recs;
    size_t count = 0;
    for (auto& r : st->records)
        if (r.second.soft == psb && r.second.fresh && !r.second.holds.empty()) recs.push_back(&r.second), count += r.second.holds.size();
    const int passes = psb->m_cfg.piterations;
    const bool split = passes > 1 && psb->m_cfg.viterations <= 0 && psb->m_cfg.diterations <= 0 && psb->m_clusters.size() == 0;
    if (count > 0 && split) psb->m_cfg.piterations = 1;
    std::vector<double> push(count, 0.0); // per plane, over the passes
    const double vc = velocityScale(psb);
    const size_t nn = (size_t)psb->m_nodes.size();
    st->x.resize(nn), st->v.resize(nn), st->inverse_mass.resize(nn);
    for (int k = 0; k < (count > 0 && split ? passes : 1); ++k) {
        psb->solveConstraints();
        for (SoftRecord* rec : recs)
            for (const sdfccd_SoftPlane& h : rec->holds) {
                const btSoftBody::Node& n = psb->m_nodes[h.node];
                st->x[(size_t)h.node] = v3(n.m_x), st->v[(size_t)h.node] = v3(n.m_v), st->inverse_mass[(size_t)h.node] = n.m_im;
            }
        size_t hi = 0;
        for (SoftRecord* rec : recs) {
            const sdfccd_Frame F0 = frameOf(rec->sdf_pose), F = frameOf(rec->sdf_object->getWorldTransform());
            sdfccd_soft_hold(&F0, &F, rec->start.data(), st->x.data(), st->v.data(), st->inverse_mass.data(), (int32_t)nn,
                             rec->holds.data(), (int32_t)rec->holds.size(), rec->friction, push.data() + hi, vc,
                             !split || k + 1 == passes, kSinglePrecision, nullptr);
            hi += rec->holds.size();
        }
        for (SoftRecord* rec : recs)
            for (const sdfccd_SoftPlane& h : rec->holds)
                psb->m_nodes[h.node].m_x = bt(st->x[(size_t)h.node]), psb->m_nodes[h.node].m_v = bt(st->v[(size_t)h.node]);
    }
    psb->m_cfg.piterations = passes;
}

// The guard of one pair (sdfccd_soft_guard): start positions in the SDF's frame at the start of the
// step, end positions in its frame now. A node it moves gets Bullet's velocity for its new motion,
// minus its part into the surface (computed there).
int guardRecord(SoftState* st, SoftRecord& rec, double tol)
{
    btSoftBody* psb = const_cast<btSoftBody*>(rec.soft);
    const int nn = psb->m_nodes.size();
    if ((size_t)nn != rec.start.size()) return 0;
    const sdfccd_SoftBody body = st->bodyOf(psb, rec);
    const sdfccd_Frame F0 = frameOf(rec.sdf_pose), F = frameOf(rec.sdf_object->getWorldTransform());
    st->guarded.resize((size_t)nn);
    int32_t moved = 0;
    const double dt = psb->m_sst.sdt > 0 ? psb->m_sst.sdt : 1.0;
    if (sdfccd_soft_guard(rec.sdf, &F0, &F, &body, tol, dt, velocityScale(psb), &st->impl->cfg.query, rec.node_certs.data(), rec.face_certs.data(),
                          st->guarded.data(), &moved, &st->totals) != SDFCCD_OK) {
        ++st->totals.query_errors;
        return 0;
    }
    for (int i = 0; i < nn; ++i) {
        const sdfccd_SoftGuardNode& g = st->guarded[(size_t)i];
        if (g.moved) psb->m_nodes[i].m_x = bt(g.position), psb->m_nodes[i].m_v = bt(g.velocity);
    }
    return moved;
}

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
            lo.setMin(psb->m_nodes[i].m_q), lo.setMin(psb->m_nodes[i].m_x);
            hi.setMax(psb->m_nodes[i].m_q), hi.setMax(psb->m_nodes[i].m_x);
        }
        const btVector3 reach((btScalar)tolerance, (btScalar)tolerance, (btScalar)tolerance);
        lo -= reach, hi += reach;
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
            bmin.setMin(smin), bmax.setMax(smax);
            if (!TestAabbAgainstAabb2(lo, hi, bmin, bmax)) continue;
            SoftRecord& rec = st->records[key];
            rec.begin(psb, co, sdf, startPose(co, psb->m_sst.sdt));
            moved += guardRecord(st, rec, tolerance);
        }
    }
    for (auto& r : st->records) r.second.fresh = false;
    st->stats.guard_nodes += moved;
    return moved;
}

GuardingSolver::~GuardingSolver()
{
    if (state && state->wrapper == this) state->wrapper = nullptr; // the world is going away
}

void GuardingSolver::solveConstraints(btScalar dt)
{
    if (!state || !state->impl->dispatcher) return btDefaultSoftBodySolver::solveConstraints(dt);
    btSoftBodyArray& softs = state->world->getSoftBodyArray(); // Bullet's solver's loop, with the contact planes held
    for (int i = 0; i < softs.size(); ++i)
        if (softs[i]->isActive() && !softs[i]->isStaticObject()) solveHeld(state, softs[i]);
    for (auto& r : state->records) r.second.holds.clear(); // this step's planes
    const Config& cfg = state->impl->cfg;
    if (cfg.guard_tolerance > 0 && cfg.query.method != SDFCCD_METHOD_DCD) { // the guarantee's tolerance
        guardWorld(state, state->world, cfg.guard_tolerance);
        state->guarded_this_step = true;
    }
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

// Puts `solver` in the world's private slot (the world frees it when `owns`) and in its soft bodies.
void installSolver(btSoftRigidDynamicsWorld* world, btSoftBodySolver* solver, bool owns)
{
    world->*reach(SolverField()) = solver;
    world->*reach(OwnsField()) = owns;
    btSoftBodyArray& softs = world->getSoftBodyArray();
    for (int i = 0; i < softs.size(); ++i) softs[i]->setSoftBodySolver(solver);
}

} // namespace

void softRegister(BridgeImpl* impl)
{
    impl->soft.reset(new SoftState);
    impl->soft->impl = impl;
}

btCollisionAlgorithm* softAlgorithm(BridgeImpl* impl, const btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* w0)
{
    void* mem = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(SoftSdfAlgorithm));
    return new (mem) SoftSdfAlgorithm(ci, softOf(impl), w0->getCollisionShape()->getShapeType() != SOFTBODY_SHAPE_PROXYTYPE);
}

void softAttach(BridgeImpl* impl, btCollisionWorld* cw)
{
    btSoftRigidDynamicsWorld* world = dynamic_cast<btSoftRigidDynamicsWorld*>(cw);
    SoftState* st = softOf(impl);
    if (!world || !st || st->wrapper) return;
    btSoftBodySolver* inner = world->*reach(SolverField());
    if (!inner || typeid(*inner) != typeid(btDefaultSoftBodySolver)) return; // only Bullet's CPU solver
    st->world = world;
    st->wrapper = new (btAlignedAlloc(sizeof(GuardingSolver), 16)) GuardingSolver(*static_cast<btDefaultSoftBodySolver*>(inner), st);
    st->inner = world->*reach(OwnsField()) ? nullptr : inner;
    if (!st->inner) inner->~btSoftBodySolver(), btAlignedFree(inner); // the world's own: the wrapper is its copy
    installSolver(world, st->wrapper, true); // the world frees the wrapper
}

// Puts a plain solver back (the caller's, else a copy of the wrapper the world owns; the world must
// still exist: see Bridge's lifetime note).
void softDetach(SoftState* st)
{
    if (st->wrapper && st->world && st->world->*reach(SolverField()) == st->wrapper) {
        GuardingSolver* g = st->wrapper;
        installSolver(st->world, st->inner ? st->inner : new (btAlignedAlloc(sizeof(btDefaultSoftBodySolver), 16)) btDefaultSoftBodySolver(*g),
                      !st->inner);
        g->~GuardingSolver();
        btAlignedFree(g);
    }
    st->wrapper = nullptr, st->world = nullptr, st->inner = nullptr;
}

void softUnregister(BridgeImpl* impl)
{
    SoftState* st = softOf(impl);
    if (!st || !impl->dispatcher) return;
    softDetach(st);
    st->records.clear();
}

void softForget(BridgeImpl* impl)
{
    SoftState* st = softOf(impl);
    if (st && st->wrapper) st->wrapper->state = nullptr; // the world still holds it: make it a plain solver
}

} // namespace detail

SoftBodyStats softBodyStats(const Bridge& bridge)
{
    const detail::SoftState* st = detail::softOf(BridgeAccess::of(const_cast<Bridge&>(bridge)));
    if (!st) return SoftBodyStats();
    SoftBodyStats s = st->stats;
    s.face_queries = st->totals.face_queries, s.query_errors = st->totals.query_errors, s.sdf_evaluations = st->totals.sdf_evaluations;
    return s;
}

int guardSoftBodies(Bridge& bridge, btSoftRigidDynamicsWorld* world, double tolerance)
{
    if (!world || !(tolerance > 0) || !std::isfinite(tolerance)) return -1;
    detail::SoftState* st = detail::softOf(BridgeAccess::of(bridge));
    if (!st || !st->impl->dispatcher || st->impl->dispatcher != world->getDispatcher()) return -1;
    if (st->world == world && st->guarded_this_step) { // the automatic guard already checked this step
        st->guarded_this_step = false;
        return 0;
    }
    return detail::guardWorld(st, world, tolerance);
}

SDFCCD_BULLET_NAMESPACE_END
