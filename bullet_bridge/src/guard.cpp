// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: the no-tunnelling guarantee (paper, Section 4). After Bullet integrates a
// step, an action hands the SDFs and the dynamic bodies (poses at both ends of the step, parts,
// states) to sdfccd_guard_world and puts each body it rolls back at its safe pose, with its velocity.
#include "internal.h"

#include <cmath>

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

// A shape's world boxes at two poses and the reach of its points from its origin (Bullet's box
// and bounding sphere), as sdfccd_guard_world takes them.
void shapeBoxes(const btCollisionShape* s, const btTransform& t0, const btTransform& t1, sdfccd_Aabb& b0, sdfccd_Aabb& b1, double& reach)
{
    btVector3 lo, hi, c;
    btScalar r;
    s->getAabb(t0, lo, hi);
    b0 = { v3(lo), v3(hi) };
    s->getAabb(t1, lo, hi);
    b1 = { v3(lo), v3(hi) };
    s->getBoundingSphere(c, r);
    reach = (double)(c.length() + r);
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

// What sdfccd_guard_world's hook needs: the bodies and SDF objects behind its indices.
struct Placing {
    const std::vector<btRigidBody*>* bodies;
    const std::vector<const btCollisionObject*>* sdf_objects;
};

// The hook: Bullet puts the body at the safe pose and gives its state there (its own inertia
// update, in btScalar) and the pair's friction (Bullet's product, in btScalar).
void placeBody(void* user, int32_t i, int32_t j, const sdfccd_Pose* pose, sdfccd_BodyState* state, double* friction)
{
    const Placing* p = static_cast<const Placing*>(user);
    btRigidBody* body = (*p->bodies)[(size_t)i];
    const sdfccd_Quat& q = pose->orientation;
    body->setCenterOfMassTransform(btTransform(btQuaternion((btScalar)q.x, (btScalar)q.y, (btScalar)q.z, (btScalar)q.w).normalized(), bt(pose->position)));
    *state = bodyState(body);
    *friction = (double)(body->getFriction() * (*p->sdf_objects)[(size_t)j]->getFriction());
}

// False when a pose holds a NaN or infinity (a body that blew up): it is left out of the guard,
// so the other bodies stay guarded.
bool finitePose(const btTransform& t)
{
    double s = (double)t.getOrigin().x() + (double)t.getOrigin().y() + (double)t.getOrigin().z();
    for (int i = 0; i < 3; ++i) s += (double)t.getBasis()[i].x() + (double)t.getBasis()[i].y() + (double)t.getBasis()[i].z();
    return std::isfinite(s);
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
    // The dynamic bodies with their mesh parts, and the SDFs (a static one keeps its pose), as
    // sdfccd_guard_world takes them; it checks each body's executed motion and rolls it back.
    std::vector<btRigidBody*> dyn;
    std::vector<int> dyn_object;
    std::vector<int32_t> dyn_index((size_t)objs.size(), -1); // object -> body index (-1: not a dynamic body)
    for (int i = 0; i < objs.size(); ++i) {
        btRigidBody* body = btRigidBody::upcast(objs[i]);
        if (!body || body->isStaticOrKinematicObject()) continue;
        if (!finitePose(startOf(i)) || !finitePose(body->getWorldTransform())) {
            stats.query_errors++;
            continue;
        }
        dyn_index[(size_t)i] = (int32_t)dyn.size();
        dyn.push_back(body);
        dyn_object.push_back(i);
    }
    std::vector<sdfccd_GuardSdf> sdfs;
    std::vector<const btCollisionObject*> sdf_objects;
    for (int i = 0; i < objs.size(); ++i) {
        const btCollisionShape* s = objs[i]->getCollisionShape();
        if (!isOurSdf(s)) continue;
        sdfccd_GuardSdf o = sdfccd_GuardSdf();
        o.sdf = shapes.sdfFor(s, cfg.sdf_shape_type, cfg.handle_bt_sdf_shape);
        if (!o.sdf.index1) continue;
        const btTransform t1 = objs[i]->getWorldTransform();
        const btTransform t0 = objs[i]->isStaticObject() && !objs[i]->isKinematicObject() ? t1 : startOf(i);
        if (!finitePose(t0) || !finitePose(t1)) {
            stats.query_errors++;
            continue;
        }
        o.start = toPose(t0);
        o.end = toPose(t1);
        shapeBoxes(s, t0, t1, o.start_box, o.end_box, o.reach);
        o.friction = (double)objs[i]->getFriction();
        o.shape_key = (uint64_t)(uintptr_t)s;
        o.body = dyn_index[(size_t)i];
        if (const btRigidBody* sb = btRigidBody::upcast(objs[i])) {
            o.has_state = 1;
            o.state = bodyState(sb);
        }
        sdfs.push_back(o);
        sdf_objects.push_back(objs[i]);
    }
    if (sdfs.empty()) return;
    std::vector<sdfccd_GuardRigidBody> bodies(dyn.size());
    std::vector<sdfccd_GuardPart> parts;
    std::vector<size_t> first_part(dyn.size());
    std::vector<std::pair<const btCollisionShape*, btTransform>> leaf;
    for (size_t k = 0; k < dyn.size(); ++k) {
        btRigidBody* body = dyn[k];
        const btTransform t0 = startOf(dyn_object[k]), t1 = body->getWorldTransform();
        sdfccd_GuardRigidBody& b = bodies[k];
        b.start = toPose(t0);
        b.end = toPose(t1);
        shapeBoxes(body->getCollisionShape(), t0, t1, b.start_box, b.end_box, b.reach);
        b.friction = (double)body->getFriction();
        b.state = bodyState(body);
        leaf.clear();
        leaves(body->getCollisionShape(), btTransform::getIdentity(), leaf);
        first_part[k] = parts.size();
        for (const auto& l : leaf) {
            const MeshEntry* me = isMeshLike(l.first) ? shapes.meshFor(l.first) : nullptr;
            if (me) parts.push_back({ me->id, toPose(l.second), (uint64_t)(uintptr_t)l.first });
        }
        b.part_count = (int32_t)(parts.size() - first_part[k]);
    }
    for (size_t k = 0; k < bodies.size(); ++k) bodies[k].parts = parts.data() + first_part[k];
    std::vector<sdfccd_GuardWorldResult> results(bodies.size());
    Placing placing = { &dyn, &sdf_objects };
    if (sdfccd_guard_world(workspace, sdfs.data(), (int32_t)sdfs.size(), bodies.data(), (int32_t)bodies.size(), 0, dt, &gp, placeBody,
                           &placing, results.data()) != SDFCCD_OK) {
        stats.query_errors++;
        return;
    }
    // The rolled-back bodies are at their safe poses (placeBody); they leave with the response's velocity.
    for (size_t k = 0; k < results.size(); ++k) {
        const sdfccd_GuardWorldResult& r = results[k];
        stats.guard_queries += r.queries;
        stats.query_errors += r.failures;
        stats.sdf_evaluations += r.sdf_evaluations;
        if (!r.rolled_back) continue;
        btRigidBody* body = dyn[k];
        body->setLinearVelocity(bt(r.state.linear_velocity));
        body->setAngularVelocity(bt(r.state.angular_velocity));
        body->setInterpolationLinearVelocity(body->getLinearVelocity());
        body->setInterpolationAngularVelocity(body->getAngularVelocity());
        stats.rollbacks++;
        stats.last_toi_fraction = r.guard.fraction;
    }
}

SDFCCD_BULLET_NAMESPACE_END
