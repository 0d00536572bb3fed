// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: the contact policy of one mesh-SDF pair per step (see bridge.h).
//
//  1. A discrete query at the start pose with the margin widened by the step's travel: every
//     feature that can come within the margin during the step (phi is Lipschitz). When its broad
//     phase culls every triangle, the step provably has no contact and nothing else runs.
//  2. Unless that query shows the step STARTS in contact (a feature already within the margin;
//     the CCD would then only report "penetrating at t0"), one CCD query (sdfccd_query_mesh on
//     [0, dt]) with the contact margin. Its WHOLE contact set at the earliest time of impact is
//     kept (the buffer grows to contacts_found; every triangle within the library's TOI window,
//     with subdivision contacts), plus the vertices of those triangles within kVertexDistance of
//     the surface then. No hit: no contact this step.
//  3. Whenever the step has any contact, also when it starts in contact: the features of the
//     start-pose query and those of a discrete query at the predicted end pose; each is
//     constrained by its own closest surface point at the START of the step (the classic
//     speculative-contact rule), so the rest of the motion (a rotation about a touching corner,
//     a slide, a face landing after its first point) cannot push it in.
//  4. Every candidate is expressed at the start of the step (point on the mesh, point on the SDF
//     surface, normal, gap d along the normal; negative: penetrating) and the set is reduced to
//     the manifold's 4 points: deepest, then the points maximising the contact polygon's area;
//     cover points (sdfccd_cover_contacts) fill up to 3 more manifolds where the 4 leave the body
//     free to turn and sink deeper than the guarantee's tolerance.
//  5. The points are written into the pair's manifolds the way btManifoldResult and
//     btPersistentManifold::refreshContactPoints do it: persistent points keep their warm-start
//     impulses and lifetime, and the contact added / processed / started / ended callbacks fire.
// The speculative rule (the paper's Section 4: no advance past a time of impact): a point with gap
// d > 0 lets the solver close at most d in the step, so the mesh stops on the surface.
// All queries go through one reusable sdfccd_Workspace per bridge (no allocation per query).
#include "internal.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

SDFCCD_BULLET_NAMESPACE_BEGIN
namespace detail {

// The reduction's depth scale: a tenth of the mesh's radius, at most 0.3 m (a body's far features
// count less than those about to touch, in proportion to its size).
static const double kSpreadDepthFraction = 0.1, kSpreadDepthMax = 0.3;
// The vertices of a triangle in contact within this distance of the surface at its TOI are
// candidates too (a face landing flat gives its corners).
static const double kVertexDistance = 0.02;
// The discrete queries do not split subdivision regions smaller than (this x the mesh's radius)^2:
// their points lie that close to the triangle's vertices, which are candidates already.
static const double kDiscreteSubdivisionScale = 0.1;
// The face search splits faces down to regions with edges at most this share of the SDF's feature
// size (SdfShape::setFeatureSize).
static const double kFaceRegionShare = 0.4;

namespace {

double seconds(std::chrono::steady_clock::time_point a)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
}

// Everything the candidate builders of one pair and step share.
struct Gatherer {
    const MeshEntry* me;
    sdfccd_SdfId sdf;
    BodyMotion M, S;
    double margin;
    std::vector<Candidate>* out;
    PairScratch* w;
    int64_t evals = 0; // our own sdfccd_sdf_eval calls

    // A material point (mesh frame) constrained by a surface point qB and normal nL (SDF frame)
    // found at some time in the step; all expressed at the start of the step.
    void add(const btVector3& local, const btVector3& qB, const btVector3& nL, int tri)
    {
        Candidate c;
        c.local = local;
        c.pA0 = M.t0 * local;
        c.pB0 = S.t0 * qB;
        c.n0 = S.t0.getBasis() * nL;
        c.d = (double)c.n0.dot(c.pA0 - c.pB0);
        c.triangle = tri;
        c.speculative = c.d > margin;
        out->push_back(c);
    }
    // The material point constrained by its own closest surface point at the START of the step
    // (none when it is farther than `accept` there).
    void addFromStart(const btVector3& local, int tri, double accept = HUGE_VAL)
    {
        const btVector3 q = S.t0.invXform(M.t0 * local);
        double phi = 0;
        sdfccd_Vec3 g;
        ++evals;
        if (sdfccd_sdf_eval(sdf, v3(q), &phi, &g) != SDFCCD_OK || !std::isfinite(phi) || !(phi <= accept)) return;
        btVector3 nL = bt(g);
        const btScalar len = nL.length();
        if (!(len > btScalar(0))) return;
        nL /= len;
        add(local, q - nL * (btScalar)phi, nL, tri);
    }
    // Features in contact at the predicted end pose (Mx, Sx), and the vertices of their triangles
    // within `accept` there, each constrained from the start of the step.
    void addPose(const sdfccd_Contact* cs, int count, const btTransform& Mx, const btTransform& Sx, double accept)
    {
        std::vector<uint32_t>& ts = w->pose_tris;
        ts.clear();
        const bool at_start = Mx == M.t0 && Sx == S.t0;
        for (int i = 0; i < count; ++i) {
            addFromStart(Mx.invXform(bt(cs[i].point)), (int)cs[i].triangle);
            if (cs[i].triangle < me->indices.size() / 3) ts.push_back(cs[i].triangle);
        }
        std::vector<std::pair<uint32_t, uint32_t>>& vt = w->pose_vertices;
        vt.clear();
        for (uint32_t t : ts)
            for (int j = 0; j < 3; ++j) vt.push_back(std::make_pair(me->indices[3 * (size_t)t + j], t));
        std::sort(vt.begin(), vt.end());
        for (size_t i = 0; i < vt.size(); ++i) {
            if (i > 0 && vt[i].first == vt[i - 1].first) continue;
            const double* v = &me->vertices[3 * (size_t)vt[i].first];
            const btVector3 local((btScalar)v[0], (btScalar)v[1], (btScalar)v[2]);
            if (at_start) { // one evaluation: the test within `accept` and the start's closest point
                addFromStart(local, (int)vt[i].second, accept);
                continue;
            }
            double phi = 0;
            ++evals;
            if (sdfccd_sdf_eval(sdf, v3(Sx.invXform(Mx * local)), &phi, nullptr) != SDFCCD_OK || !(phi <= accept)) continue;
            addFromStart(local, (int)vt[i].second);
        }
    }
    // The face search (SdfShape::setFeatureSize; sdfccd_search_faces) at pose (Mx, Sx) within
    // `accept`, its points constrained from the start of the step. Returns the regions visited.
    int64_t searchFaces(sdfccd_Workspace* ws, double size, const btTransform& Mx, const btTransform& Sx, double accept,
                        const sdfccd_QueryParams& params)
    {
        std::vector<sdfccd_ContactPoint>& buf = w->face_points;
        const sdfccd_Pose mp = toPose(Mx), sp = toPose(Sx);
        sdfccd_FaceSearch fs{};
        for (int pass = 0; pass < 2; ++pass) {
            if (!ws || sdfccd_search_faces(ws, sdf, &sp, me->id, &mp, size, accept, &params, buf.data(), (int32_t)buf.size(), &fs) != SDFCCD_OK)
                return 0;
            if (fs.found <= fs.count) break;
            buf.resize((size_t)fs.found); // all or nothing: room for every point, and again
        }
        evals += fs.sdf_evaluations;
        const btMatrix3x3 sdf_basis_t = Sx.getBasis().transpose();
        for (int i = 0; i < fs.count; ++i)
            add(Mx.invXform(bt(buf[i].point)), Sx.invXform(bt(buf[i].surface_point)), sdf_basis_t * bt(buf[i].normal), (int)buf[i].triangle);
        return fs.regions;
    }
    // Each contact at its own triangle's time of impact, plus the vertices of that triangle within
    // `accept` of the surface at that time (a face landing flat gives its corners).
    void addContacts(const sdfccd_Contact* cs, int count, double accept)
    {
        // Contacts come sorted by time; one pose pair per distinct time.
        double t_pose = -1;
        btTransform Mx = M.t0, Sx = S.t0;
        std::vector<std::pair<uint32_t, double>>& tris = w->tris;
        tris.clear();
        for (int i = 0; i < count; ++i) {
            const sdfccd_Contact& k = cs[i];
            if (k.toi != t_pose) {
                t_pose = k.toi;
                Mx = M.at(k.toi);
                Sx = S.at(k.toi);
            }
            const btVector3 p = bt(k.point);
            const btVector3 nL = Sx.getBasis().transpose() * bt(k.normal);
            add(Mx.invXform(p), Sx.invXform(p) - nL * (btScalar)k.distance, nL, (int)k.triangle);
            if (k.triangle >= me->indices.size() / 3) continue;
            if (!tris.empty() && tris.back().first == k.triangle) continue;
            tris.push_back(std::make_pair(k.triangle, k.toi));
        }
        // Each (vertex, triangle's TOI) once, in a fixed order.
        std::vector<std::pair<uint32_t, std::pair<double, uint32_t>>>& vt = w->toi_vertices;
        vt.clear();
        for (const auto& t : tris)
            for (int j = 0; j < 3; ++j) vt.push_back(std::make_pair(me->indices[3 * (size_t)t.first + j], std::make_pair(t.second, t.first)));
        std::sort(vt.begin(), vt.end());
        for (size_t i = 0; i < vt.size(); ++i) {
            if (i > 0 && vt[i].first == vt[i - 1].first) continue; // the earliest TOI of the vertex
            const double t = vt[i].second.first;
            if (t != t_pose) {
                t_pose = t;
                Mx = M.at(t);
                Sx = S.at(t);
            }
            const double* v = &me->vertices[3 * (size_t)vt[i].first];
            const btVector3 local((btScalar)v[0], (btScalar)v[1], (btScalar)v[2]);
            const btVector3 q = Sx.invXform(Mx * local);
            double phi = 0;
            sdfccd_Vec3 g;
            ++evals;
            if (sdfccd_sdf_eval(sdf, v3(q), &phi, &g) != SDFCCD_OK || !(phi <= accept)) continue;
            btVector3 nL = bt(g);
            const btScalar len = nL.length();
            if (!(len > btScalar(0))) continue;
            nL /= len;
            add(local, q - nL * (btScalar)phi, nL, (int)vt[i].second.second);
        }
    }
};

} // namespace
} // namespace detail

using namespace detail;

QueryInput detail::queryInput(sdfccd_SdfId sdf, sdfccd_MeshId mesh, const sdfccd_RigidMotion* sm, const sdfccd_RigidMotion& m, double t1,
                              const sdfccd_QueryParams& p)
{
    QueryInput in;
    std::memset(&in, 0, sizeof in); // padding too: inputs are compared byte for byte
    in.sdf = sdf;
    in.mesh = mesh;
    in.has_sdf_motion = sm != nullptr;
    if (sm) std::memcpy(&in.sdf_motion, sm, sizeof *sm);
    std::memcpy(&in.motion, &m, sizeof m);
    in.t1 = t1;
    std::memcpy(&in.params, &p, sizeof p);
    return in;
}

bool BridgeImpl::plan(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, double dt, double margin, PairPlan& P)
{
    P.me = shapes.meshFor(mw->getCollisionShape());
    P.sdf = shapes.sdfFor(sw->getCollisionShape(), cfg.sdf_shape_type, cfg.handle_bt_sdf_shape);
    if (!P.me || !P.sdf.index1) return false;
    P.M = motionOf(mw->getCollisionObject(), mw->getWorldTransform(), dt);
    P.S = motionOf(sw->getCollisionObject(), sw->getWorldTransform(), dt);
    // A static SDF (the usual case): work in its frame, so the library evaluates the field without
    // moving it (no pose per evaluation); the candidates go back to the world at the end.
    P.static_sdf = P.S.v.isZero() && P.S.w.isZero() && P.S.t0 == P.S.t1;
    P.sdf_world = P.S.t0;
    if (P.static_sdf) {
        const btTransform inv = P.sdf_world.inverse();
        P.M.t0 = inv * P.M.t0;
        P.M.t1 = inv * P.M.t1;
        P.M.v = inv.getBasis() * P.M.v;
        P.M.w = inv.getBasis() * P.M.w;
        P.S.t0.setIdentity();
        P.S.t1.setIdentity();
    }
    P.margin = margin;
    P.mm = P.M.rigid();
    P.sm_value = P.S.rigid();
    std::memcpy(&P.params, &cfg.query, sizeof P.params);
    P.params.margin = margin;
    // With SDFCCD_METHOD_DCD (the discrete baseline the scenes compare against) the main query
    // runs first and alone decides whether the step has contact (the order before the start-pose
    // query was moved first).
    P.continuous = P.params.method != SDFCCD_METHOD_DCD;
    P.start_margin = margin;
    P.travel = 0;
    if (dt > 0) {
        const double reach = P.me->radius + (double)(P.M.t0.getOrigin() - P.S.t0.getOrigin()).length();
        P.travel = dt * ((double)(P.M.v - P.S.v).length() + (double)P.M.w.length() * P.me->radius + (double)P.S.w.length() * reach);
        P.start_margin = margin + P.travel;
    }
    // The face search's region size comes from the SDF shape's smallest feature.
    const SdfShape* shape = dynamic_cast<const SdfShape*>(sw->getCollisionShape());
    P.feature_size = shape ? shape->getFeatureSize() : 0.0;
    return true;
}

bool BridgeImpl::faceSearch(const PairPlan& P) const
{
    return P.params.subdivision && P.feature_size > 0;
}

sdfccd_QueryParams BridgeImpl::discreteParams(const PairPlan& P, double dcd_margin) const
{
    sdfccd_QueryParams dcd;
    std::memcpy(&dcd, &P.params, sizeof dcd);
    dcd.method = SDFCCD_METHOD_DCD;
    dcd.margin = dcd_margin;
    // Subdivision regions below (kDiscreteSubdivisionScale x the mesh radius)^2 are not split:
    // their points lie that close to the triangle's vertices, which are candidates already.
    // (Not for the DCD baseline, which keeps the library's subdivision.)
    const double sub = kDiscreteSubdivisionScale * P.me->radius;
    if (P.continuous && sub > 0) dcd.subdivision_min_area = std::max(dcd.subdivision_min_area, sub * sub);
    return dcd;
}

namespace {

// The rigid motions of a discrete query at pose (Mx, Sx).
void posePair(const btTransform& Mx, const btTransform& Sx, sdfccd_RigidMotion& m1, sdfccd_RigidMotion& s1)
{
    m1 = sdfccd_default_rigid_motion();
    s1 = sdfccd_default_rigid_motion();
    m1.pose = toPose(Mx);
    s1.pose = toPose(Sx);
}

// The start-pose query's verdicts, one rule for gather() and the batch: its broad phase culled
// every triangle (the step provably has no contact), or a feature is already within the margin
// (the step starts in contact: the CCD query is skipped).
bool culled(const sdfccd_QueryResult& r) { return r.triangles_tested == 0 && r.state == SDFCCD_STATE_NO_HIT; }
bool touching(const sdfccd_QueryResult& r, const sdfccd_Contact* c, int n, double margin)
{
    for (int i = 0; r.hit && i < n; ++i)
        if (c[i].distance <= margin) return true;
    return false;
}

// The end-pose query runs unless the step's travel is within the guarantee's tolerance: the end
// pose's features are then the start pose's (within the reach of its query), moved by at most that.
bool endQuery(const PairPlan& P, const Config& cfg) { return !(P.continuous && cfg.guard_tolerance > 0 && P.travel <= cfg.guard_tolerance); }

// Room given to a batched query's contacts (a query that finds more is run again in the narrow
// phase with room for all, as an unbatched one is).
const int32_t kBatchCapacity = 256;

} // namespace

const CachedQuery* BridgeImpl::batched(const btCollisionObject* mo, const btCollisionObject* so, int stage, const QueryInput& in,
                                       bool* ran) const
{
    *ran = false;
    auto it = batch_cache.find(PairStageKey{ mo, so, stage });
    if (it == batch_cache.end()) return nullptr;
    const CachedQuery& q = it->second;
    if (std::memcmp(&q.in, &in, sizeof in) != 0) return nullptr;
    *ran = true;
    if (q.status != SDFCCD_OK || q.result.contacts_found > q.result.contact_count) return nullptr;
    return &q;
}

void BridgeImpl::prefetch(double dt, double margin)
{
    const auto t_start = std::chrono::steady_clock::now();
    batch_cache.clear();
    if (!batch_world || !dispatcher || !(dt > 0)) return;
    struct Item {
        const btCollisionObject *mo, *so;
        PairPlan P;
        sdfccd_RigidMotion m1, s1; // the pose pair of the current discrete stage
    };
    std::vector<Item> items;
    btBroadphasePairArray& pairs = batch_world->getPairCache()->getOverlappingPairArray();
    for (int i = 0; i < pairs.size(); ++i) {
        const btBroadphasePair& bp = pairs[i];
        if (!bp.m_pProxy0 || !bp.m_pProxy1) continue;
        const btCollisionObject* a = static_cast<const btCollisionObject*>(bp.m_pProxy0->m_clientObject);
        const btCollisionObject* b = static_cast<const btCollisionObject*>(bp.m_pProxy1->m_clientObject);
        if (!a || !b || !dispatcher->needsCollision(a, b)) continue;
        // Top-level shapes only (a compound's children get their pairs from the compound's own
        // algorithm, with child transforms).
        const btCollisionObjectWrapper wa(nullptr, a->getCollisionShape(), a, a->getWorldTransform(), -1, -1);
        const btCollisionObjectWrapper wb(nullptr, b->getCollisionShape(), b, b->getWorldTransform(), -1, -1);
        bool mesh_is_b = false;
        if (!orient(&wa, &wb, mesh_is_b)) continue;
        const btCollisionObjectWrapper* mw = mesh_is_b ? &wb : &wa;
        const btCollisionObjectWrapper* sw = mesh_is_b ? &wa : &wb;
        if (sw->getCollisionShape()->getShapeType() != cfg.sdf_shape_type) continue; // btSdfCollisionShape: Bullet's sampling
        Item it;
        it.mo = mw->getCollisionObject();
        it.so = sw->getCollisionObject();
        if (!plan(mw, sw, dt, margin, it.P) || !it.P.continuous) continue;
        items.push_back(it);
    }
    // Stage by stage: the queries of `sel` (indices into items) as one batch into the cache.
    std::vector<sdfccd_BatchQuery> qs;
    auto runStage = [&](const std::vector<size_t>& sel, int stage) {
        if (sel.empty()) return;
        qs.assign(sel.size(), sdfccd_BatchQuery());
        std::vector<CachedQuery*> out(sel.size());
        for (size_t k = 0; k < sel.size(); ++k) {
            Item& it = items[sel[k]];
            const PairPlan& P = it.P;
            CachedQuery& c = batch_cache[PairStageKey{ it.mo, it.so, stage }];
            if (stage == kStageCcd) {
                c.in = queryInput(P.sdf, P.me->id, P.sm(), P.mm, dt, P.params);
            } else {
                sdfccd_RigidMotion s1;
                posePair(stage == kStageStart ? P.M.t0 : P.M.t1, stage == kStageStart ? P.S.t0 : P.S.t1, it.m1, s1);
                it.s1 = s1;
                c.in = queryInput(P.sdf, P.me->id, P.static_sdf ? nullptr : &it.s1, it.m1, 0.0,
                                  discreteParams(P, stage == kStageStart ? P.start_margin : P.margin));
            }
            c.contacts.resize((size_t)kBatchCapacity);
            out[k] = &c;
        }
        for (size_t k = 0; k < sel.size(); ++k) {
            CachedQuery& c = *out[k];
            sdfccd_BatchQuery& q = qs[k];
            q.kind = SDFCCD_BATCH_MESH;
            q.sdf = c.in.sdf;
            q.sdf_motion = c.in.has_sdf_motion ? &c.in.sdf_motion : nullptr;
            q.mesh = c.in.mesh;
            q.motion = &c.in.motion;
            q.t0 = 0.0;
            q.t1 = c.in.t1;
            q.params = &c.in.params;
            q.out_contacts = c.contacts.data();
            q.capacity = kBatchCapacity;
            q.out_result = &c.result;
        }
        sdfccd_query_batch(qs.data(), (int32_t)qs.size(), cfg.batch_threads);
        for (size_t k = 0; k < sel.size(); ++k) out[k]->status = qs[k].status;
        stats.batches++;
    };
    // (1) every pair's start-pose query; (2) the CCD query of the pairs it leaves open (some
    // triangle within reach, nothing within the margin yet, no face search to run first); (3) the
    // end-pose query of those that start in contact or whose CCD query hit: gather()'s order.
    std::vector<size_t> sel(items.size()), ccd, end;
    for (size_t k = 0; k < items.size(); ++k) sel[k] = k;
    runStage(sel, kStageStart);
    for (size_t k = 0; k < items.size(); ++k) {
        const CachedQuery& c = batch_cache[PairStageKey{ items[k].mo, items[k].so, kStageStart }];
        if (c.status != SDFCCD_OK) continue;
        if (culled(c.result) || faceSearch(items[k].P)) continue;
        const int n = std::min(c.result.contact_count, kBatchCapacity);
        if (!touching(c.result, c.contacts.data(), n, items[k].P.margin)) ccd.push_back(k);
        else if (endQuery(items[k].P, cfg)) end.push_back(k);
    }
    runStage(ccd, kStageCcd);
    for (size_t k : ccd) {
        const CachedQuery& c = batch_cache[PairStageKey{ items[k].mo, items[k].so, kStageCcd }];
        if (c.status == SDFCCD_OK && c.result.hit && endQuery(items[k].P, cfg)) end.push_back(k);
    }
    std::sort(end.begin(), end.end());
    runStage(end, kStageEnd);
    stats.query_seconds += seconds(t_start);
}

bool BridgeImpl::gather(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, double dt, double margin,
                        std::vector<Candidate>& cands, double* out_radius, btVector3* out_w)
{
    cands.clear();
    PairPlan P;
    if (!plan(mw, sw, dt, margin, P)) {
        stats.query_errors++;
        return false;
    }
    Gatherer G;
    G.me = P.me;
    G.sdf = P.sdf;
    G.M = P.M;
    G.S = P.S;
    if (!workspace && sdfccd_create_workspace(&workspace) != SDFCCD_OK) workspace = nullptr;
    if (out_radius) *out_radius = G.me->radius;
    if (out_w) *out_w = G.M.w - G.S.w;
    const bool static_sdf = P.static_sdf;
    const btTransform sdf_world = P.sdf_world;
    G.margin = margin;
    G.out = &cands;
    G.w = &work;
    G.evals = 0;
    const sdfccd_RigidMotion mm = P.mm;
    const sdfccd_RigidMotion* sm = P.sm();
    const sdfccd_QueryParams& params = P.params;
    const bool continuous = P.continuous;
    const btCollisionObject* mo = mw->getCollisionObject();
    const btCollisionObject* so = sw->getCollisionObject();
    // Config::batch_threads: a top-level pair of a step whose queries have not been batched yet
    // (its first pair) runs the batch of every pair.
    const bool top_level = mw->getWorldTransform() == mo->getWorldTransform() && mw->getCollisionShape() == mo->getCollisionShape() &&
                           sw->getWorldTransform() == so->getWorldTransform() && sw->getCollisionShape() == so->getCollisionShape();
    const bool batching = cfg.batch_threads > 1 && batch_world && dt > 0 && continuous && top_level &&
                          sw->getCollisionShape()->getShapeType() == cfg.sdf_shape_type;

    // The candidates back in the world frame, counted.
    auto finish = [&]() {
        stats.own_evaluations += G.evals;
        if (static_sdf)
            for (Candidate& c : cands) {
                c.pA0 = sdf_world * c.pA0;
                c.pB0 = sdf_world * c.pB0;
                c.n0 = sdf_world.getBasis() * c.n0;
            }
        stats.candidates += (int64_t)cands.size();
        return !cands.empty();
    };
    // One query into `buf` (grown to the whole contact set, asked again when it was too small),
    // taken from the step's batch when it ran there with exactly these inputs.
    auto run = [&](std::vector<sdfccd_Contact>& buf, const sdfccd_RigidMotion* s, const sdfccd_RigidMotion* m, double t1,
                   const sdfccd_QueryParams& p, sdfccd_QueryResult* r, int stage) {
        if (buf.size() < 256) buf.resize(256);
        if (batching) {
            const QueryInput in = queryInput(G.sdf, G.me->id, s, *m, t1, p);
            bool ran = false;
            const CachedQuery* c = batched(mo, so, stage, in, &ran);
            if (!ran && stage == kStageStart) { // a new step: batch its queries
                prefetch(dt, margin);
                c = batched(mo, so, stage, in, &ran);
            }
            if (c) {
                *r = c->result;
                if (buf.size() < (size_t)r->contact_count) buf.resize((size_t)r->contact_count);
                std::copy(c->contacts.begin(), c->contacts.begin() + r->contact_count, buf.begin());
                stats.batched_queries++;
                stats.sdf_evaluations += r->sdf_evaluations;
                return SDFCCD_OK;
            }
        }
        auto query = [&]() {
            return workspace ? sdfccd_query_mesh_ws(workspace, G.sdf, s, G.me->id, m, 0.0, t1, &p, buf.data(), (int32_t)buf.size(), r)
                             : sdfccd_query_mesh(G.sdf, s, G.me->id, m, 0.0, t1, &p, buf.data(), (int32_t)buf.size(), r);
        };
        const auto t_start = std::chrono::steady_clock::now();
        sdfccd_Status st = query();
        if (st == SDFCCD_OK && r->contacts_found > r->contact_count) {
            // Keep the whole set: grow the buffer and ask again (rare once the buffer has grown).
            buf.resize((size_t)r->contacts_found);
            stats.requeries++;
            st = query();
        }
        stats.query_seconds += seconds(t_start);
        if (st == SDFCCD_OK) stats.sdf_evaluations += r->sdf_evaluations;
        return st;
    };
    // A discrete query at pose (Mx, Sx) with margin `dcd_margin`, into `buf`.
    auto discrete = [&](std::vector<sdfccd_Contact>& buf, const btTransform& Mx, const btTransform& Sx, double dcd_margin,
                        sdfccd_QueryResult* r, int stage) {
        sdfccd_RigidMotion m1, s1;
        posePair(Mx, Sx, m1, s1);
        const sdfccd_QueryParams dcd = discreteParams(P, dcd_margin);
        stats.end_pose_queries++;
        return run(buf, static_sdf ? nullptr : &s1, &m1, 0.0, dcd, r, stage) == SDFCCD_OK;
    };

    // Moving steps. (1) A discrete query at the start pose with the margin widened by the step's
    // travel: phi is 1-Lipschitz (the library scales by the SDF's bound), so it sees every feature
    // that can come within the margin during the step. Its broad phase finding no triangle in
    // reach PROVES the step has no contact: no other query runs. A feature already within the
    // margin means the step starts in contact: the CCD query would only report "penetrating at
    // t0" with the same features, so it is skipped (it costs as much as both discrete queries
    // together on a resting body). Otherwise (2) the CCD query over the step; no hit, no contact.
    sdfccd_QueryResult r0{};
    bool start_ran = false, start_ok = false, starts_touching = false;
    const double start_margin = P.start_margin, travel = P.travel;
    if (dt > 0 && continuous) {
        start_ran = true;
        start_ok = discrete(start_contacts, G.M.t0, G.S.t0, start_margin, &r0, kStageStart);
        if (start_ok && culled(r0)) {
            stats.queries_skipped++;
            stats.last_state = (int)SDFCCD_STATE_NO_HIT;
            stats.last_toi_fraction = 1;
            return false;
        }
        starts_touching = start_ok && touching(r0, start_contacts.data(), r0.contact_count, margin);
    }
    // The face search (SdfShape::setFeatureSize; part of the subdivision, so off without it): at
    // the start pose over the step's reach (DCD, the discrete baseline: at the end pose within
    // the margin, as its own query). Its features count like the start-pose query's, even when
    // the CCD query misses them (a face landing flat on tips between its FW points).
    size_t face_found = 0;
    if (dt > 0 && faceSearch(P)) {
        const double fs = kFaceRegionShare * P.feature_size;
        stats.face_regions += continuous ? G.searchFaces(workspace, fs, G.M.t0, G.S.t0, start_margin, params)
                                         : G.searchFaces(workspace, fs, G.M.t1, G.S.t1, margin, params);
        face_found = cands.size();
        for (size_t i = 0; i < face_found && continuous && !starts_touching; ++i) starts_touching = cands[i].d <= margin;
    }
    if (starts_touching) {
        stats.queries_skipped++;
        stats.last_state = (int)SDFCCD_STATE_PENETRATING;
        stats.hits++;
        stats.last_toi_fraction = 0;
    } else {
        sdfccd_QueryResult res;
        sdfccd_Status status = run(contacts, sm, &mm, dt, params, &res, kStageCcd);
        stats.queries++;
        if (status != SDFCCD_OK) {
            stats.query_errors++;
            return false;
        }
        stats.last_state = (int)res.state;
        if (!res.hit) {
            stats.last_toi_fraction = 1;
            // The predicted motion is clear: only the face search can have found features the
            // CCD query missed; the start pose's features then count too.
            if (face_found > 0 && start_ok && r0.hit) G.addPose(start_contacts.data(), r0.contact_count, G.M.t0, G.S.t0, start_margin);
            return cands.empty() ? false : finish();
        }
        stats.hits++;
        stats.last_toi_fraction = res.fraction;
        G.addContacts(contacts.data(), res.contact_count, margin + std::max(kVertexDistance, params.contact_slop));
        if (dt > 0 && !start_ran && (res.toi > 0 || travel > margin)) {
            start_ran = true;
            start_ok = discrete(start_contacts, G.M.t0, G.S.t0, start_margin, &r0, kStageStart);
        }
    }

    // Each triangle gives its FIRST contact only, so the rest of a face that lands after its first
    // point, or passes through a thin part of the SDF within the step, needs more: every feature
    // within the step's travel of the surface at the START of the step (the speculative-contact
    // rule), and every feature in contact at the predicted end pose (the closest points of large
    // triangles differ there), each constrained by its own closest surface point at the start of
    // the step. When the CCD query was skipped, the vertices of the start pose's triangles within
    // the vertex distance count too, as they would have with the CCD's contacts (a face resting
    // flat gives its corners).
    if (dt > 0) {
        const double accept = starts_touching ? std::max(start_margin, margin + std::max(kVertexDistance, params.contact_slop))
                                              : start_margin;
        if (start_ok && r0.hit) G.addPose(start_contacts.data(), r0.contact_count, G.M.t0, G.S.t0, accept);
        sdfccd_QueryResult r1;
        if (endQuery(P, cfg) && discrete(contacts, G.M.t1, G.S.t1, margin, &r1, kStageEnd) && r1.hit) G.addPose(contacts.data(), r1.contact_count, G.M.t1, G.S.t1, margin);
    }
    return finish();
}

namespace {

// Writes the candidates `pick` into the pair's manifolds (A = mesh, B = SDF): the first `first`
// (at most 4) into the first manifold, the rest 4 per manifold in order, the way btManifoldResult and btPersistentManifold::refreshContactPoints do it: a point
// of the same material point as one of the last step (in any of the pair's manifolds) keeps its
// warm start and lifetime; added / processed callbacks fire for every point; started fires when
// the first manifold gains its first point and ended when it empties (the first manifold speaks
// for the pair: the others never fire started or ended).
void writeManifolds(btPersistentManifold* const* manifolds, int manifold_count, const std::vector<Candidate>& cands,
                    const std::vector<int32_t>& pick, int first, const btCollisionObjectWrapper* mw,
                    const btCollisionObjectWrapper* sw, PairScratch& w, Stats& stats)
{
    const int per = (int)MANIFOLD_CACHE_SIZE;
    first = std::max(0, std::min(first, per));
    const btCollisionObject* mo = mw->getCollisionObject();
    const btCollisionObject* so = sw->getCollisionObject();
    const int n = std::min((int)pick.size(), first + per * (manifold_count - 1));
    // The last step's points of every manifold of the pair.
    std::vector<btManifoldPoint>& old = w.old_points;
    std::vector<char>& matched = w.matched;
    old.clear();
    for (int m = 0; m < manifold_count; ++m)
        for (int i = 0; i < manifolds[m]->getNumContacts(); ++i) {
            old.push_back(manifolds[m]->getContactPoint(i));
        }
    matched.assign(old.size(), 0);
    const int primary_old = manifolds[0]->getNumContacts();
    const btScalar match = manifolds[0]->getContactBreakingThreshold();
    const btTransform& worldA = mo->getWorldTransform();
    const btTransform& worldB = so->getWorldTransform();
    const int flags = mo->getCollisionFlags() | so->getCollisionFlags();
    std::vector<btManifoldPoint>& pts = w.new_points;
    pts.resize((size_t)n);
    for (int k = 0; k < n; ++k) {
        const Candidate& c = cands[pick[k]];
        btManifoldPoint pt(worldA.invXform(c.pA0), worldB.invXform(c.pB0), c.n0, (btScalar)c.d);
        pt.m_positionWorldOnA = c.pA0;
        pt.m_positionWorldOnB = c.pB0;
        pt.m_combinedFriction = gCalculateCombinedFrictionCallback(mo, so);
        pt.m_combinedRestitution = c.speculative ? btScalar(0) : gCalculateCombinedRestitutionCallback(mo, so);
        pt.m_combinedRollingFriction = gCalculateCombinedRollingFrictionCallback(mo, so);
        pt.m_combinedSpinningFriction = gCalculateCombinedSpinningFrictionCallback(mo, so);
        if (flags & btCollisionObject::CF_HAS_CONTACT_STIFFNESS_DAMPING) {
            pt.m_combinedContactDamping1 = gCalculateCombinedContactDampingCallback(mo, so);
            pt.m_combinedContactStiffness1 = gCalculateCombinedContactStiffnessCallback(mo, so);
            pt.m_contactPointFlags |= BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING;
        }
        btPlaneSpace1(pt.m_normalWorldOnB, pt.m_lateralFrictionDir1, pt.m_lateralFrictionDir2);
        pt.m_partId0 = mw->m_partId;
        pt.m_index0 = c.triangle; // the mesh triangle (or compound child: see mw->m_index)
        pt.m_partId1 = sw->m_partId;
        pt.m_index1 = sw->m_index;
        // The same material point as a point of the last step keeps its warm start and lifetime
        // (btPersistentManifold::getCacheEntry / replaceContactPoint).
        int best = -1;
        btScalar best_d2 = match * match;
        for (size_t j = 0; j < old.size(); ++j) {
            const btScalar d2 = (old[j].m_localPointA - pt.m_localPointA).length2();
            if (!matched[j] && d2 < best_d2) {
                best_d2 = d2;
                best = (int)j;
            }
        }
        if (best >= 0) {
            matched[best] = 1;
            pt.m_appliedImpulse = old[best].m_appliedImpulse;
            pt.m_prevRHS = old[best].m_prevRHS;
            pt.m_appliedImpulseLateral1 = old[best].m_appliedImpulseLateral1;
            pt.m_appliedImpulseLateral2 = old[best].m_appliedImpulseLateral2;
            pt.m_userPersistentData = old[best].m_userPersistentData;
            pt.m_lifeTime = old[best].m_lifeTime + 1;
        }
        pts[k] = pt;
        if (c.speculative) stats.speculative_contacts++;
        else stats.ordinary_contacts++;
    }
    // Points that did not persist are dropped as refreshContactPoints drops them (their user data
    // released through the contact-destroyed callback).
    size_t o = 0;
    for (int m = 0; m < manifold_count; ++m)
        for (int i = 0; i < manifolds[m]->getNumContacts(); ++i, ++o)
            if (!matched[o] && n > 0) manifolds[m]->clearUserCache(manifolds[m]->getContactPoint(i));
    if (n == 0) manifolds[0]->clearManifold(); // fires the contact-ended callback if it had points
    for (int m = n == 0 ? 1 : 0; m < manifold_count; ++m) {
        btPersistentManifold* manifold = manifolds[m];
        const int lo = m == 0 ? 0 : std::min(n, first + (m - 1) * per), hi = m == 0 ? std::min(n, first) : std::min(n, lo + per);
        // The first manifold never passes through 0 points while contact goes on, so there is
        // no ended callback then.
        if (n == 0)
            for (int i = 0; i < manifold->getNumContacts(); ++i) manifold->clearUserCache(manifold->getContactPoint(i));
        manifold->setNumContacts(hi - lo);
        for (int k = lo; k < hi; ++k) manifold->getContactPoint(k - lo) = pts[k];
        if (gContactAddedCallback && (flags & btCollisionObject::CF_CUSTOM_MATERIAL_CALLBACK))
            for (int k = lo; k < hi; ++k) {
                const btManifoldPoint& p = pts[k];
                gContactAddedCallback(manifold->getContactPoint(k - lo), mw, p.m_partId0, p.m_index0, sw, p.m_partId1, p.m_index1);
            }
        if (m == 0 && gContactStartedCallback && primary_old == 0 && hi > lo) gContactStartedCallback(manifold);
        if (gContactProcessedCallback)
            for (int k = lo; k < hi; ++k)
                gContactProcessedCallback(manifold->getContactPoint(k - lo), (void*)manifold->getBody0(), (void*)manifold->getBody1());
    }
}

} // namespace

void BridgeImpl::process(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, const btDispatcherInfo& info,
                         btManifoldResult* out, btPersistentManifold* const* manifolds, int manifold_count, bool closest)
{
    const double dt = closest ? 0.0 : (double)info.m_timeStep;
    const double margin = closest ? std::max(0.0, (double)out->m_closestPointDistanceThreshold) : cfg.contact_margin;
    double radius = 0;
    btVector3 w(0, 0, 0);
    const bool any = gather(mw, sw, dt, margin, scratch, &radius, &w);
    // The guarantee's start poses: the world transforms of this step's first pair are the step's start.
    if (!closest && dt > 0) snapshotStartPoses(guard_world);
    const double tol = std::max(1e-6, 1e-3 * radius);
    const double depth_scale = std::min(kSpreadDepthMax, kSpreadDepthFraction * radius);
    // The candidates as the core's contact points (surface point, normal, gap), reduced to the
    // manifold's points: deepest first, then the area, far points weighted down.
    cover_set.resize(scratch.size());
    for (size_t i = 0; i < scratch.size(); ++i) {
        sdfccd_ContactPoint& p = cover_set[i];
        std::memset(&p, 0, sizeof p);
        p.surface_point = v3(scratch[i].pB0);
        p.normal = v3(scratch[i].n0);
        p.gap = scratch[i].d;
    }
    pick.resize((size_t)std::max(0, cfg.max_contacts));
    int32_t count = 0;
    if (!any || sdfccd_reduce_contacts_weighted(cover_set.data(), (int32_t)scratch.size(), tol, depth_scale, pick.data(),
                                                (int32_t)pick.size(), &count) != SDFCCD_OK)
        count = 0;
    pick.resize((size_t)count);
    if (closest) {
        for (int i : pick) out->addContactPoint(scratch[i].n0, scratch[i].pB0, (btScalar)scratch[i].d);
        return;
    }
    const int first = (int)pick.size();
    // More points where the first ones leave the body free to sink: every candidate that could end
    // deeper than the guarantee's tolerance while the points held so far stay out, for any rotation
    // of the body (relative to the SDF) about an axis in the contact plane up to its angular speed.
    const int extra_limit = (manifold_count - 1) * (int)MANIFOLD_CACHE_SIZE;
    if (!pick.empty() && extra_limit > 0) {
        const btVector3& n = scratch[pick[0]].n0;
        const double slope = dt * (double)(w - n * n.dot(w)).length();
        const double cover = cfg.guard_tolerance > 0 ? cfg.guard_tolerance : Config().guard_tolerance;
        pick.resize((size_t)(first + extra_limit));
        int32_t added = 0;
        if (sdfccd_cover_contacts(cover_set.data(), (int32_t)scratch.size(), pick.data(), first, slope, cover, tol, pick.data() + first,
                                  extra_limit, &added) != SDFCCD_OK)
            added = 0;
        pick.resize((size_t)(first + added));
    }
    writeManifolds(manifolds, manifold_count, scratch, pick, first, mw, sw, work, stats);
}

double BridgeImpl::timeOfImpact(const btCollisionObject* mo, const btCollisionObject* so, double dt)
{
    if (!(dt > 0)) return 1.0;
    const MeshEntry* me = shapes.meshFor(mo->getCollisionShape());
    sdfccd_SdfId sdf = shapes.sdfFor(so->getCollisionShape(), cfg.sdf_shape_type, cfg.handle_bt_sdf_shape);
    if (!me || !sdf.index1) return 1.0;
    BodyMotion M = motionOf(mo, mo->getWorldTransform(), dt), S = motionOf(so, so->getWorldTransform(), dt);
    sdfccd_RigidMotion mm = M.rigid(), sm = S.rigid();
    sdfccd_QueryParams params = cfg.query;
    params.margin = 0;
    sdfccd_QueryResult res;
    if (sdfccd_query_mesh(sdf, &sm, me->id, &mm, 0.0, dt, &params, nullptr, 0, &res) != SDFCCD_OK || !res.hit) return 1.0;
    return std::max(0.0, std::min(1.0, res.fraction));
}

SDFCCD_BULLET_NAMESPACE_END
