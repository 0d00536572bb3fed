// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: a mesh-SDF pair's contacts in a step (see bridge.h). The contact model is the
// core's one generator (sdfccd_generate_contacts, contact.h: the start-pose query over the step's
// reach and its cull, the face search, the CCD unless the step starts in contact, the end-pose query,
// the reduction and the cover points). Here: its inputs from Bullet's bodies, the batch over the
// world's pairs (Config::batch_threads), and the points written into the pair's manifolds the way
// btManifoldResult and btPersistentManifold::refreshContactPoints do it.
#include "internal.h"

#include <algorithm>
#include <chrono>
#include <cstring>

SDFCCD_BULLET_NAMESPACE_BEGIN
using namespace detail;

namespace {

double seconds(std::chrono::steady_clock::time_point a)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
}

// Writes the points `pts` into the pair's manifolds (A = mesh, B = SDF): the first `first` (at most 4)
// into the first manifold, the rest 4 per manifold in order: a point
// of the same material point as one of the last step (in any of the pair's manifolds) keeps its
// warm start and lifetime; added / processed callbacks fire for every point; started fires when
// the first manifold gains its first point and ended when it empties (the first manifold speaks
// for the pair: the others never fire started or ended).
void writeManifolds(btPersistentManifold* const* manifolds, int manifold_count, const sdfccd_ContactPoint* cps, int count, int first,
                    double margin, const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, PairScratch& w, Stats& stats)
{
    const int per = (int)MANIFOLD_CACHE_SIZE;
    first = std::max(0, std::min(first, per));
    const btCollisionObject* mo = mw->getCollisionObject();
    const btCollisionObject* so = sw->getCollisionObject();
    const int n = std::min(count, first + per * (manifold_count - 1));
    // The last step's points of every manifold of the pair, and their places on the mesh body.
    std::vector<btManifoldPoint>& old = w.old_points;
    std::vector<char>& matched = w.matched;
    old.clear();
    w.old_places.clear();
    for (int m = 0; m < manifold_count; ++m)
        for (int i = 0; i < manifolds[m]->getNumContacts(); ++i) {
            old.push_back(manifolds[m]->getContactPoint(i));
            w.old_places.push_back(v3(old.back().m_localPointA));
        }
    matched.assign(old.size(), 0);
    const int primary_old = manifolds[0]->getNumContacts();
    const btScalar match = manifolds[0]->getContactBreakingThreshold();
    const btTransform& worldA = mo->getWorldTransform();
    const btTransform& worldB = so->getWorldTransform();
    const int flags = mo->getCollisionFlags() | so->getCollisionFlags();
    std::vector<btManifoldPoint>& pts = w.new_points;
    pts.resize((size_t)n);
    w.new_places.resize((size_t)n);
    for (int k = 0; k < n; ++k) {
        const sdfccd_ContactPoint& c = cps[k];
        const bool speculative = c.gap > margin; // an impact later in the step: restitution 0
        btManifoldPoint pt(worldA.invXform(bt(c.point)), worldB.invXform(bt(c.surface_point)), bt(c.normal), (btScalar)c.gap);
        pt.m_positionWorldOnA = bt(c.point);
        pt.m_positionWorldOnB = bt(c.surface_point);
        pt.m_combinedFriction = gCalculateCombinedFrictionCallback(mo, so);
        pt.m_combinedRestitution = speculative ? btScalar(0) : gCalculateCombinedRestitutionCallback(mo, so);
        pt.m_combinedRollingFriction = gCalculateCombinedRollingFrictionCallback(mo, so);
        pt.m_combinedSpinningFriction = gCalculateCombinedSpinningFrictionCallback(mo, so);
        if (flags & btCollisionObject::CF_HAS_CONTACT_STIFFNESS_DAMPING) {
            pt.m_combinedContactDamping1 = gCalculateCombinedContactDampingCallback(mo, so);
            pt.m_combinedContactStiffness1 = gCalculateCombinedContactStiffnessCallback(mo, so);
            pt.m_contactPointFlags |= BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING;
        }
        btPlaneSpace1(pt.m_normalWorldOnB, pt.m_lateralFrictionDir1, pt.m_lateralFrictionDir2);
        pt.m_partId0 = mw->m_partId;
        pt.m_index0 = (int)c.triangle; // the mesh triangle (or compound child: see mw->m_index)
        pt.m_partId1 = sw->m_partId;
        pt.m_index1 = sw->m_index;
        pts[k] = pt;
        w.new_places[(size_t)k] = v3(pt.m_localPointA);
        if (speculative) stats.speculative_contacts++;
        else stats.ordinary_contacts++;
    }
    // The same material point as a point of the last step keeps its warm start and lifetime
    // (btPersistentManifold::getCacheEntry / replaceContactPoint).
    w.match.assign((size_t)n, -1);
    sdfccd_match_contacts(w.old_places.data(), (int32_t)old.size(), w.new_places.data(), n, (double)match, w.match.data());
    for (int k = 0; k < n; ++k) {
        const int best = w.match[(size_t)k];
        if (best < 0) continue;
        matched[best] = 1;
        pts[k].m_appliedImpulse = old[best].m_appliedImpulse;
        pts[k].m_prevRHS = old[best].m_prevRHS;
        pts[k].m_appliedImpulseLateral1 = old[best].m_appliedImpulseLateral1;
        pts[k].m_appliedImpulseLateral2 = old[best].m_appliedImpulseLateral2;
        pts[k].m_userPersistentData = old[best].m_userPersistentData;
        pts[k].m_lifeTime = old[best].m_lifeTime + 1;
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

// The arguments' params with the previous step's ids (r.in.kept) to prefer.
const sdfccd_ContactParams& runParams(PairResult& r)
{
    r.run_params = r.in.params;
    r.run_params.previous.ids = r.in.kept.ids;
    r.run_params.previous.count = r.in.kept.count;
    return r.run_params;
}

} // namespace

bool BridgeImpl::pairInput(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, double dt, double margin, int capacity,
                           const KeptIds* kept, PairInput& in)
{
    std::memset(&in, 0, sizeof in); // padding too: inputs are compared byte for byte with a batch's
    const MeshEntry* me = shapes.meshFor(mw->getCollisionShape());
    in.sdf = shapes.sdfFor(sw->getCollisionShape(), cfg.sdf_shape_type, cfg.handle_bt_sdf_shape);
    if (!me || !in.sdf.index1) return false;
    in.mesh = me->id;
    in.motion = motionOf(mw->getCollisionObject(), mw->getWorldTransform(), dt);
    in.sdf_motion = motionOf(sw->getCollisionObject(), sw->getWorldTransform(), dt);
    in.dt = dt;
    const sdfccd_ContactParams p = sdfccd_default_contact_params();
    std::memcpy(&in.params, &p, sizeof p);
    std::memcpy(&in.params.query, &cfg.query, sizeof cfg.query);
    in.params.query.margin = margin;
    const SdfShape* shape = dynamic_cast<const SdfShape*>(sw->getCollisionShape());
    in.params.feature_size = shape ? shape->getFeatureSize() : 0.0;
    in.params.reduced_count = cfg.max_contacts;
    // Cover points into the further manifolds, against sinking deeper than the guarantee's tolerance.
    in.params.cover_depth = capacity > cfg.max_contacts ? (cfg.guard_tolerance > 0 ? cfg.guard_tolerance : Config().guard_tolerance) : 0.0;
    // A step whose travel is within the guarantee's tolerance reuses the start pose's features.
    in.params.end_skip_travel = cfg.guard_tolerance;
    in.capacity = capacity;
    if (kept) in.kept = *kept;
    return true;
}

int BridgeImpl::stepCapacity() const
{
    return cfg.max_contacts >= (int)MANIFOLD_CACHE_SIZE ? cfg.max_contacts + (int)MANIFOLD_CACHE_SIZE * kExtraManifolds : cfg.max_contacts;
}

bool BridgeImpl::generate(PairResult& r, sdfccd_Workspace* ws)
{
    const auto t_start = std::chrono::steady_clock::now();
    r.points.resize((size_t)std::max(1, r.in.capacity));
    r.status = sdfccd_generate_contacts(ws, r.in.sdf, &r.in.sdf_motion, r.in.mesh, &r.in.motion, 0.0, r.in.dt, &runParams(r),
                                        r.points.data(), r.in.capacity, &r.set);
    stats.query_seconds += seconds(t_start);
    return r.status == SDFCCD_OK;
}

void BridgeImpl::runBatch(double dt, double margin)
{
    const auto t_start = std::chrono::steady_clock::now();
    batch_cache.clear();
    if (!batch_world || !dispatcher || !(dt > 0)) return;
    std::vector<sdfccd_ContactPair> pairs;
    std::vector<PairResult*> results;
    btBroadphasePairArray& bps = batch_world->getPairCache()->getOverlappingPairArray();
    for (int i = 0; i < bps.size(); ++i) {
        const btBroadphasePair& bp = bps[i];
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
        const ObjectPair key(mw->getCollisionObject(), sw->getCollisionObject());
        PairResult& r = batch_cache[key];
        if (!pairInput(mw, sw, dt, margin, stepCapacity(), keptIdsOf(bp.m_algorithm), r.in)) {
            batch_cache.erase(key);
            continue;
        }
        r.points.resize((size_t)std::max(1, r.in.capacity));
        pairs.push_back(sdfccd_ContactPair{ r.in.sdf, &r.in.sdf_motion, r.in.mesh, &r.in.motion, 0.0, dt, &runParams(r), r.points.data(),
                                            r.in.capacity, &r.set, SDFCCD_OK });
        results.push_back(&r);
    }
    while (batch_ws.size() < (size_t)cfg.batch_threads) {
        sdfccd_Workspace* ws = nullptr;
        if (sdfccd_create_workspace(&ws) != SDFCCD_OK) break;
        batch_ws.push_back(ws);
    }
    if (batch_ws.empty()) return;
    sdfccd_generate_contacts_batch(batch_ws.data(), (int32_t)batch_ws.size(), pairs.data(), (int32_t)pairs.size());
    for (size_t k = 0; k < pairs.size(); ++k) results[k]->status = pairs[k].status;
    stats.batches++;
    stats.query_seconds += seconds(t_start);
}

const PairResult* BridgeImpl::batched(const btCollisionObject* mo, const btCollisionObject* so, const PairInput& in)
{
    // A pair of a new step (or one whose inputs changed) runs the batch of every pair first.
    for (int pass = 0; pass < 2; ++pass) {
        auto it = batch_cache.find(std::make_pair(mo, so));
        if (it != batch_cache.end() && std::memcmp(&it->second.in, &in, sizeof in) == 0)
            return it->second.status == SDFCCD_OK ? &it->second : nullptr;
        if (pass == 0) runBatch(in.dt, in.params.query.margin);
    }
    return nullptr;
}

void BridgeImpl::process(const btCollisionObjectWrapper* mw, const btCollisionObjectWrapper* sw, const btDispatcherInfo& info,
                         btManifoldResult* out, btPersistentManifold* const* manifolds, int manifold_count, bool closest, KeptIds* kept)
{
    const double dt = closest ? 0.0 : (double)info.m_timeStep;
    const double margin = closest ? std::max(0.0, (double)out->m_closestPointDistanceThreshold) : cfg.contact_margin;
    // The guarantee's start poses: the world transforms of this step's first pair are the step's start.
    if (!closest && dt > 0) snapshotStartPoses(guard_world);
    const btCollisionObject* mo = mw->getCollisionObject();
    const btCollisionObject* so = sw->getCollisionObject();
    const PairResult* r = nullptr;
    if (pairInput(mw, sw, dt, margin, closest ? cfg.max_contacts : stepCapacity(), kept, single.in)) {
        // Config::batch_threads: a top-level pair takes its set from the step's batch.
        const bool top_level = mw->getWorldTransform() == mo->getWorldTransform() && mw->getCollisionShape() == mo->getCollisionShape() &&
                               sw->getWorldTransform() == so->getWorldTransform() && sw->getCollisionShape() == so->getCollisionShape();
        if (cfg.batch_threads > 1 && batch_world && dt > 0 && top_level && sw->getCollisionShape()->getShapeType() == cfg.sdf_shape_type &&
            (r = batched(mo, so, single.in)))
            stats.batched_queries += r->set.ccd_ran + r->set.discrete_queries;
        if (!r) {
            if (!workspace && sdfccd_create_workspace(&workspace) != SDFCCD_OK) workspace = nullptr;
            if (workspace && generate(single, workspace)) r = &single;
        }
    }
    if (!r) stats.query_errors++;
    const sdfccd_ContactSet s = r ? r->set : sdfccd_ContactSet();
    if (r) {
        stats.queries += s.ccd_ran;
        stats.end_pose_queries += s.discrete_queries;
        stats.queries_skipped += !s.ccd_ran;
        stats.sdf_evaluations += s.sdf_evaluations - s.own_evaluations;
        stats.own_evaluations += s.own_evaluations;
        stats.candidates += s.candidates;
        stats.face_regions += s.face_regions;
        const bool hit = s.started_in_contact || (s.ccd_ran && (s.ccd_state == SDFCCD_STATE_HIT || s.ccd_state == SDFCCD_STATE_PENETRATING));
        stats.hits += hit;
        stats.last_state = s.started_in_contact ? (int)SDFCCD_STATE_PENETRATING : (int)s.ccd_state;
        stats.last_toi_fraction = !hit ? 1.0 : dt > 0 ? std::max(0.0, std::min(1.0, s.toi / dt)) : 0.0;
    }
    if (closest) {
        for (int i = 0; i < s.count; ++i) {
            const sdfccd_ContactPoint& c = r->points[(size_t)i];
            out->addContactPoint(bt(c.normal), bt(c.surface_point), (btScalar)c.gap);
        }
        return;
    }
    writeManifolds(manifolds, manifold_count, r ? r->points.data() : nullptr, s.count, s.reduced, margin, mw, sw, work, stats);
    if (guard_world && s.count > 0) {
        // For the friction hold after the step (holdFriction clears them; a world only queried, never stepped, drops them).
        if (dispatcher && held_manifolds.size() > 4 * (size_t)dispatcher->getNumManifolds() + 64) held_manifolds.clear();
        held_manifolds.insert(held_manifolds.end(), manifolds, manifolds + manifold_count);
    }
    if (kept) {
        kept->count = std::min(s.reduced, (int32_t)MANIFOLD_CACHE_SIZE);
        for (int i = 0; i < kept->count; ++i) kept->ids[i] = r->points[(size_t)i].id;
    }
}

void BridgeImpl::holdFriction(btCollisionWorld* world, double dt)
{
    if (!guard_world) return;
    // The step's manifolds still in the dispatcher (their points carry the solver's impulses), by body.
    std::vector<std::pair<const btCollisionObject*, const btPersistentManifold*>> live;
    btDispatcher* d = world->getDispatcher();
    std::sort(held_manifolds.begin(), held_manifolds.end());
    for (int m = 0; m < d->getNumManifolds(); ++m) {
        const btPersistentManifold* pm = d->getManifoldByIndexInternal(m);
        if (pm->getNumContacts() > 0 && std::binary_search(held_manifolds.begin(), held_manifolds.end(), pm))
            live.push_back(std::make_pair(pm->getBody0(), pm));
    }
    held_manifolds.clear();
    std::stable_sort(live.begin(), live.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    // Bullet's second friction direction when the world has one, and its resting-contact speed (no
    // restitution below it): a body whose contact points all move slower is at rest.
    const btContactSolverInfo& si = guard_world->getSolverInfo();
    const bool two = (si.m_solverMode & SOLVER_USE_2_FRICTION_DIRECTIONS) != 0;
    std::vector<sdfccd_HeldContact> cs;
    for (size_t lo = 0, hi; lo < live.size(); lo = hi) {
        for (hi = lo; hi < live.size() && live[hi].first == live[lo].first; ++hi) {}
        btRigidBody* body = btRigidBody::upcast(const_cast<btCollisionObject*>(live[lo].first));
        if (!body || body->isStaticOrKinematicObject() || !body->isActive()) continue;
        cs.clear();
        for (size_t k = lo; k < hi; ++k) {
            const btPersistentManifold* pm = live[k].second;
            const btRigidBody* sb = btRigidBody::upcast(pm->getBody1());
            if (sb && sb->getInvMass() > 0) continue; // a dynamic SDF body: the friction between two bodies is Bullet's
            for (int i = 0; i < pm->getNumContacts(); ++i) {
                const btManifoldPoint& p = pm->getContactPoint(i);
                if (!(p.m_appliedImpulse > 0)) continue;
                const btVector3 at = p.m_positionWorldOnA;
                sdfccd_HeldContact c;
                c.point = v3(at);
                c.normal = v3(p.m_normalWorldOnB);
                c.surface_velocity = v3(sb ? sb->getVelocityInLocalPoint(at - sb->getCenterOfMassPosition()) : btVector3(0, 0, 0));
                c.friction_impulse = v3(p.m_lateralFrictionDir1 * p.m_appliedImpulseLateral1 +
                                        (two ? p.m_lateralFrictionDir2 * p.m_appliedImpulseLateral2 : btVector3(0, 0, 0)));
                c.normal_impulse = (double)p.m_appliedImpulse;
                c.friction = (double)p.m_combinedFriction;
                cs.push_back(c);
            }
        }
        // The lever arms from the centre the solver used (the start pose's, before the integration).
        const btVector3 v = body->getLinearVelocity(), w = body->getAngularVelocity();
        btTransform t1 = body->getWorldTransform(), turn_old, turn_new;
        sdfccd_BodyState bs = bodyState(body);
        bs.center = v3(t1.getOrigin() - v * (btScalar)dt);
        const double rest = (double)si.m_restitutionVelocityThreshold;
        if (cs.empty() || sdfccd_friction_hold(cs.data(), (int32_t)cs.size(), rest, &bs, nullptr) != SDFCCD_OK) continue;
        if (bt(bs.linear_velocity) == v && bt(bs.angular_velocity) == w) continue;
        body->setLinearVelocity(bt(bs.linear_velocity));
        body->setAngularVelocity(bt(bs.angular_velocity));
        // Bullet's integration of the step redone with the new velocities: x1 + dv dt, and the turn of
        // w over dt replaced by that of the new w.
        btTransformUtil::integrateTransform(btTransform::getIdentity(), btVector3(0, 0, 0), w, (btScalar)dt, turn_old);
        btTransformUtil::integrateTransform(btTransform::getIdentity(), btVector3(0, 0, 0), body->getAngularVelocity(), (btScalar)dt, turn_new);
        t1.setOrigin(t1.getOrigin() + (body->getLinearVelocity() - v) * (btScalar)dt);
        t1.setRotation((turn_new.getRotation() * turn_old.getRotation().inverse() * t1.getRotation()).normalized());
        body->proceedToTransform(t1);
    }
}

double BridgeImpl::timeOfImpact(const btCollisionObject* mo, const btCollisionObject* so, double dt)
{
    if (!(dt > 0)) return 1.0;
    const MeshEntry* me = shapes.meshFor(mo->getCollisionShape());
    sdfccd_SdfId sdf = shapes.sdfFor(so->getCollisionShape(), cfg.sdf_shape_type, cfg.handle_bt_sdf_shape);
    if (!me || !sdf.index1) return 1.0;
    const sdfccd_RigidMotion mm = motionOf(mo, mo->getWorldTransform(), dt), sm = motionOf(so, so->getWorldTransform(), dt);
    sdfccd_QueryParams params = cfg.query;
    params.margin = 0;
    sdfccd_QueryResult res;
    if (sdfccd_query_mesh(sdf, &sm, me->id, &mm, 0.0, dt, &params, nullptr, 0, &res) != SDFCCD_OK || !res.hit) return 1.0;
    return std::max(0.0, std::min(1.0, res.fraction));
}

SDFCCD_BULLET_NAMESPACE_END
