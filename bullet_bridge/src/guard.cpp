// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: the no-tunnelling guarantee (paper, Section 4). After Bullet integrates a
// step, an action hands each dynamic body's executed motion (per part and SDF) to sdfccd_guard_body
// and puts a body it rolls back at its safe pose, with sdfccd_guard_response's velocity.
#include "internal.h"

#include <LinearMath/btAabbUtil2.h>

SDFCCD_BULLET_NAMESPACE_BEGIN

using namespace detail;

namespace detail {

namespace {

// The action Bullet runs after integrating each step.
class GuardAction : public btActionInterface
{
public:
    explicit GuardAction(BridgeImpl* b) : m_bridge(b) {}
    void updateAction(btCollisionWorld* world, btScalar dt) override { m_bridge->guardStep(world, (double)dt); }
    void debugDraw(btIDebugDraw*) override {}

private:
    BridgeImpl* m_bridge;
};

// The box a shape can occupy while its object moves from t0 to t1 (sdfccd_swept_aabb: origin lerp,
// any turn about the origin; false for a NaN pose or box).
bool sweptBox(const btCollisionShape* s, const btTransform& t0, const btTransform& t1, btVector3& lo, btVector3& hi)
{
    btVector3 lo0, hi0, lo1, hi1, c;
    btScalar r;
    s->getAabb(t0, lo0, hi0);
    s->getAabb(t1, lo1, hi1);
    s->getBoundingSphere(c, r);
    const sdfccd_Aabb b0 = { v3(lo0), v3(hi0) }, b1 = { v3(lo1), v3(hi1) };
    const sdfccd_Pose p0 = toPose(t0), p1 = toPose(t1);
    sdfccd_Aabb out;
    if (sdfccd_swept_aabb(&b0, &b1, &p0, &p1, (double)(c.length() + r), &out) != SDFCCD_OK) return false;
    lo = bt(out.lo);
    hi = bt(out.hi);
    return true;
}

// The mesh parts of a shape with their offsets in the body frame: the shape itself, or the
// children of a btCompoundShape (nested compounds followed).
void leaves(const btCollisionShape* s, const btTransform& offset, std::vector<std::pair<const btCollisionShape*, btTransform>>& out)
{
    if (s->getShapeType() == COMPOUND_SHAPE_PROXYTYPE) {
        const btCompoundShape* c = static_cast<const btCompoundShape*>(s);
        for (int i = 0; i < c->getNumChildShapes(); ++i) leaves(c->getChildShape(i), offset * c->getChildTransform(i), out);
        return;
    }
    out.push_back(std::make_pair(s, offset));
}

// The executed motion from pose a (time 0) to pose b (time dt), rotating about c (local frame).
sdfccd_Status motionFromPoses(const btTransform& a, const btTransform& b, const btVector3& c, double dt, sdfccd_RigidMotion* out)
{
    const sdfccd_Pose pa = toPose(a), pb = toPose(b);
    return sdfccd_rigid_motion_from_poses(&pa, &pb, v3(c), 0, dt, out);
}

} // namespace

sdfccd_BodyState bodyState(const btRigidBody* b)
{
    sdfccd_BodyState s;
    s.center = v3(b->getCenterOfMassPosition());
    s.linear_velocity = v3(b->getLinearVelocity());
    s.angular_velocity = v3(b->getAngularVelocity());
    s.inverse_mass = (double)b->getInvMass();
    for (int k = 0; k < 9; ++k) s.inverse_inertia[k] = (double)b->getInvInertiaTensorWorld()[k / 3][k % 3];
    return s;
}

void guardAttach(BridgeImpl* impl, btCollisionWorld* world)
{
    btDynamicsWorld* dw = dynamic_cast<btDynamicsWorld*>(world);
    if (!dw || !(impl->cfg.guard_tolerance > 0) || impl->cfg.query.method == SDFCCD_METHOD_DCD || impl->guard_world) return;
    impl->guard.reset(new GuardAction(impl));
    dw->addAction(impl->guard.get());
    impl->guard_world = dw;
}

void guardDetach(BridgeImpl* impl)
{
    if (impl->guard_world && impl->guard) impl->guard_world->removeAction(impl->guard.get());
    impl->guard_world = nullptr;
    impl->start_poses.clear();
}

} // namespace detail

void BridgeImpl::snapshotStartPoses(const btCollisionWorld* world)
{
    if (!guard_world || world != guard_world || snapshot_step == guard_step) return;
    snapshot_step = guard_step;
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    start_poses.resize((size_t)objs.size());
    for (int i = 0; i < objs.size(); ++i) start_poses[(size_t)i] = std::make_pair(static_cast<const btCollisionObject*>(objs[i]), objs[i]->getWorldTransform());
}

void BridgeImpl::guardStep(btCollisionWorld* world, double dt)
{
    const bool snapped = snapshot_step == guard_step++; // this step's narrow phase took a snapshot
    if (!(dt > 0)) return;
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    // The step's start pose of object i: the snapshot, else Bullet's integration of the step undone
    // (its end pose moved back by its velocities over dt; kinematic bodies, already at their end pose
    // in the narrow phase (saveKinematicState), by their interpolation velocities).
    auto startOf = [&](int i) -> btTransform {
        const btCollisionObject* co = objs[i];
        if (snapped && !co->isKinematicObject() && (size_t)i < start_poses.size() && start_poses[(size_t)i].first == co)
            return start_poses[(size_t)i].second;
        return poseBefore(co, dt);
    };
    holdFriction(world, dt);
    if (!workspace && sdfccd_create_workspace(&workspace) != SDFCCD_OK) workspace = nullptr;
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    gp.tolerance = cfg.guard_tolerance;
    gp.query.fwgss_restarts = cfg.query.fwgss_restarts; // the bridge's (0): the core's discrete check backs it
    gp.query.fwgss_verify = cfg.query.fwgss_verify;
    // The SDFs and the boxes they sweep in the step.
    struct SdfObject { // the SDF's motion: a static one still has its pose (NULL would mean the world origin)
        const btCollisionObject* co;
        sdfccd_SdfId sdf;
        btTransform t0, t1;
        btVector3 lo, hi;
        sdfccd_RigidMotion motion;
    };
    std::vector<SdfObject> sdfs;
    for (int i = 0; i < objs.size(); ++i) {
        const btCollisionShape* s = objs[i]->getCollisionShape();
        if (!isOurSdf(s)) continue;
        SdfObject o;
        o.co = objs[i];
        o.sdf = shapes.sdfFor(s, cfg.sdf_shape_type, cfg.handle_bt_sdf_shape);
        if (!o.sdf.index1) continue;
        o.t1 = objs[i]->getWorldTransform();
        if (objs[i]->isStaticObject() && !objs[i]->isKinematicObject()) o.t0 = o.t1;
        else o.t0 = startOf(i);
        if (!sweptBox(s, o.t0, o.t1, o.lo, o.hi) || motionFromPoses(o.t0, o.t1, btVector3(0, 0, 0), dt, &o.motion) != SDFCCD_OK) {
            stats.query_errors++;
            continue;
        }
        sdfs.push_back(o);
    }
    std::vector<std::pair<const btCollisionShape*, btTransform>> parts;
    std::vector<sdfccd_GuardPair> pairs;
    std::vector<std::pair<const SdfObject*, btTransform>> which; // each pair's SDF and part offset
    for (int i = 0; i < objs.size() && !sdfs.empty(); ++i) {
        btRigidBody* body = btRigidBody::upcast(objs[i]);
        if (!body || body->isStaticOrKinematicObject()) continue;
        const btTransform t0 = startOf(i);
        const btTransform t1 = body->getWorldTransform();
        const btCollisionShape* shape = body->getCollisionShape();
        btVector3 lo, hi, pad = btVector3(1, 1, 1) * (btScalar)gp.tolerance;
        if (!sweptBox(shape, t0, t1, lo, hi)) continue;
        lo -= pad;
        hi += pad;
        parts.clear();
        pairs.clear();
        which.clear();
        for (const SdfObject& o : sdfs) {
            if (o.co == body || !TestAabbAgainstAabb2(lo, hi, o.lo, o.hi)) continue;
            if (t0 == t1 && o.t0 == o.t1) continue; // neither moved (a sleeping body): nothing went deeper
            if (parts.empty()) leaves(shape, btTransform::getIdentity(), parts);
            for (const auto& part : parts) {
                if (part.first == o.co->getCollisionShape() || !isMeshLike(part.first)) continue;
                const MeshEntry* me = shapes.meshFor(part.first);
                if (!me) continue;
                sdfccd_GuardPair pair = { o.sdf, &o.motion, me->id, sdfccd_RigidMotion() };
                stats.guard_queries++;
                if (motionFromPoses(t0 * part.second, t1 * part.second, part.second.inverse().getOrigin(), dt, &pair.executed) != SDFCCD_OK) {
                    stats.query_errors++;
                    continue;
                }
                pairs.push_back(pair);
                which.push_back(std::make_pair(&o, part.second));
            }
        }
        // The earliest rollback of the body's checks (sdfccd_guard_body).
        sdfccd_GuardBodyResult r;
        if (pairs.empty() || sdfccd_guard_body(workspace, pairs.data(), (int32_t)pairs.size(), 0, dt, &gp, &r) != SDFCCD_OK) continue;
        stats.query_errors += r.failed;
        stats.sdf_evaluations += r.sdf_evaluations;
        if (r.index < 0) continue;
        const sdfccd_GuardResult& best = r.first;
        const SdfObject* best_sdf = which[(size_t)r.index].first;
        const btTransform& best_part = which[(size_t)r.index].second;
        // The safe pose (of the part that hit first: the body's follows), then the velocity
        // (sdfccd_guard_response, always as "repeated": the body loses its velocity into the surface;
        // keeping it for a first rollback raised the body and left the velocity that sank it, and
        // bodies rocking on a ring in gimpact-demo did not come to rest).
        const sdfccd_Quat& q = best.safe_pose.orientation;
        btTransform safe = btTransform(btQuaternion((btScalar)q.x, (btScalar)q.y, (btScalar)q.z, (btScalar)q.w).normalized(),
                                       bt(best.safe_pose.position)) * best_part.inverse();
        // A moving SDF (kinematic or dynamic) goes on to its end pose: the body goes with it from the
        // time of impact, so it keeps the safe pose relative to the SDF instead of being left behind
        // inside it.
        if (!(best_sdf->t0 == best_sdf->t1)) {
            btTransform at_toi;
            btTransformUtil::integrateTransform(best_sdf->t0, bt(best_sdf->motion.linear_velocity), bt(best_sdf->motion.angular_velocity),
                                                (btScalar)best.toi, at_toi);
            safe = best_sdf->t1 * at_toi.inverse() * safe;
        }
        body->setCenterOfMassTransform(safe);
        const btRigidBody* sb = btRigidBody::upcast(best_sdf->co);
        const sdfccd_BodyState ss = sb ? bodyState(sb) : sdfccd_BodyState();
        sdfccd_BodyState bs = bodyState(body);
        const double mu = (double)(body->getFriction() * best_sdf->co->getFriction());
        if (sdfccd_guard_response(&best, 1, sb ? &ss : nullptr, mu, &bs) == SDFCCD_OK) {
            body->setLinearVelocity(bt(bs.linear_velocity));
            body->setAngularVelocity(bt(bs.angular_velocity));
        }
        body->setInterpolationLinearVelocity(body->getLinearVelocity());
        body->setInterpolationAngularVelocity(body->getAngularVelocity());
        stats.rollbacks++;
        stats.last_toi_fraction = best.fraction;
    }
}

SDFCCD_BULLET_NAMESPACE_END
