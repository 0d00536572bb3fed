// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: the no-tunnelling guarantee (paper, Section 4: the simulation never
// advances past a time of impact). An action (btActionInterface, run by Bullet after it
// integrates a step) checks the EXECUTED motion of every dynamic body that can reach an SDF
// (its start pose of the step to the pose the solver produced) with the CCD; a body that went
// deeper than Config::guard_tolerance goes back along that motion to its time of impact (its
// velocity: see Config::guard_tolerance). Whatever moved it (its own contacts' spin, a kick from
// another body, a compound parent), it does not pass an SDF. Start poses: taken at the step's first
// narrow-phase call of the bridge (world transforms are the start poses then), otherwise Bullet's
// integration undone (the end pose moved back by the body's velocities).
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

// The box a shape can occupy while its object moves from t0 to t1 (origin lerp and any rotation
// about the origin): the two end boxes when the rotation does not change, else the bounding
// sphere about the origin around both end positions.
void sweptBox(const btCollisionShape* s, const btTransform& t0, const btTransform& t1, btVector3& lo, btVector3& hi)
{
    btVector3 lo1, hi1;
    s->getAabb(t0, lo, hi);
    s->getAabb(t1, lo1, hi1);
    lo.setMin(lo1);
    hi.setMax(hi1);
    if (t0.getBasis() == t1.getBasis()) return;
    btVector3 c;
    btScalar r;
    s->getBoundingSphere(c, r);
    const btScalar R = c.length() + r;
    const btVector3 e(R, R, R);
    btVector3 slo = t0.getOrigin(), shi = t0.getOrigin();
    slo.setMin(t1.getOrigin());
    shi.setMax(t1.getOrigin());
    lo.setMax(slo - e); // the tighter of the two bounds on each side
    hi.setMin(shi + e);
    lo.setMin(hi); // (never inverted)
}

bool overlaps(const btVector3& alo, const btVector3& ahi, const btVector3& blo, const btVector3& bhi)
{
    return alo.x() <= bhi.x() && blo.x() <= ahi.x() && alo.y() <= bhi.y() && blo.y() <= ahi.y() && alo.z() <= bhi.z() &&
           blo.z() <= ahi.z();
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

} // namespace

sdfccd_Status motionFromPoses(const btTransform& a, const btTransform& b, const btVector3& c, double dt, sdfccd_RigidMotion* out)
{
    const sdfccd_Pose pa = toPose(a), pb = toPose(b);
    return sdfccd_rigid_motion_from_poses(&pa, &pb, v3(c), 0, dt, out);
}

btTransform poseAt(const sdfccd_RigidMotion& m, double t)
{
    const btQuaternion q0((btScalar)m.pose.orientation.x, (btScalar)m.pose.orientation.y, (btScalar)m.pose.orientation.z,
                          (btScalar)m.pose.orientation.w);
    const btVector3 w = bt(m.angular_velocity);
    const double ang = (double)w.length() * t;
    btQuaternion dq(0, 0, 0, 1);
    if (ang > 0) dq = btQuaternion(w.normalized(), (btScalar)ang);
    const btQuaternion q = dq * q0;
    const btVector3 lc = bt(m.local_center);
    const btVector3 g0 = bt(m.pose.position) + quatRotate(q0, lc);
    const btVector3 g = g0 + bt(m.linear_velocity) * (btScalar)t;
    btTransform r(q.normalized(), g - quatRotate(q.normalized(), lc));
    return r;
}

} // namespace detail

sdfccd_Status BridgeImpl::guardRigid(sdfccd_SdfId sdf, const sdfccd_RigidMotion* sm, sdfccd_MeshId mesh, const sdfccd_RigidMotion& mm,
                                     double dt, GuardOut& out)
{
    // (1) sdfccd_guard_rigid at the tolerance; a body it rolls back goes back further, to where it
    // first came within HALF the tolerance (a second check over [0, toi]), so that it starts the
    // next step shallower than the tolerance and stays under the full check (put back at the
    // tolerance itself, it would start the next step "inside", where the core lets a triangle sink
    // a tolerance deeper than its start, step after step). (2) The pose the body is to take is
    // checked once more with the discrete query (another local search: it catches what the CCD's
    // missed, e.g. a large or thin triangle reaching the surface in two places); deeper than the
    // tolerance, the body goes back by bisection to the last time it is not deeper than half.
    out = GuardOut();
    out.toi = dt;
    const double tol = cfg.guard_tolerance;
    sdfccd_GuardParams gp = sdfccd_default_guard_params();
    gp.tolerance = tol;
    gp.query.fwgss_restarts = cfg.query.fwgss_restarts; // the bridge's (0): the discrete check below backs it
    sdfccd_GuardResult r;
    sdfccd_Status st = sdfccd_guard_rigid(workspace, sdf, sm, mesh, &mm, 0, dt, &gp, &r);
    if (st != SDFCCD_OK) return st;
    stats.sdf_evaluations += r.sdf_evaluations;
    if (r.state == SDFCCD_GUARD_INSIDE_AT_START) return SDFCCD_OK; // left to the contacts
    if (r.state == SDFCCD_GUARD_ROLLED_BACK) {
        out.rolled_back = true;
        out.toi = r.toi;
        out.point = r.point;
        out.normal = r.normal;
        if (r.toi > 0) {
            gp.tolerance = 0.5 * tol;
            sdfccd_GuardResult h;
            if ((st = sdfccd_guard_rigid(workspace, sdf, sm, mesh, &mm, 0, r.toi, &gp, &h)) != SDFCCD_OK) return st;
            stats.sdf_evaluations += h.sdf_evaluations;
            if (h.state == SDFCCD_GUARD_ROLLED_BACK) {
                out.toi = h.toi;
                out.point = h.point;
                out.normal = h.normal;
            }
        }
    }
    // (2) A point of the mesh deeper than `level` at time t, if the discrete query finds one.
    sdfccd_QueryParams dcd = sdfccd_default_query_params();
    dcd.method = SDFCCD_METHOD_DCD;
    dcd.contact_slop = 0;
    auto deep = [&](double t, double level, sdfccd_Contact* at, bool* found) -> sdfccd_Status {
        dcd.margin = level;
        sdfccd_RigidMotion m = mm, s = sm ? *sm : sdfccd_default_rigid_motion();
        m.pose = toPose(poseAt(mm, t));
        m.linear_velocity = m.angular_velocity = sdfccd_Vec3{ 0, 0, 0 };
        if (sm) {
            s.pose = toPose(poseAt(*sm, t));
            s.linear_velocity = s.angular_velocity = sdfccd_Vec3{ 0, 0, 0 };
        }
        sdfccd_QueryResult q;
        const sdfccd_Status e = sdfccd_query_mesh_ws(workspace, sdf, sm ? &s : nullptr, mesh, &m, 0, 0, &dcd, at, 1, &q);
        if (e == SDFCCD_OK) stats.sdf_evaluations += q.sdf_evaluations;
        *found = e == SDFCCD_OK && q.hit && q.contact_count > 0;
        return e;
    };
    sdfccd_Contact c;
    bool found = false;
    if ((st = deep(out.toi, -tol, &c, &found)) != SDFCCD_OK) return st;
    if (!found) {
        out.fraction = out.toi / dt;
        out.pinned = out.rolled_back && !(out.toi > 0);
        return SDFCCD_OK;
    }
    stats.guard_bisections++;
    out.rolled_back = true;
    out.point = c.point;
    out.normal = c.normal;
    double lo = 0, hi = out.toi;
    for (int it = 0; it < 12; ++it) {
        const double mid = 0.5 * (lo + hi);
        if ((st = deep(mid, -0.5 * tol, &c, &found)) != SDFCCD_OK) return st;
        if (found) {
            hi = mid;
            out.point = c.point;
            out.normal = c.normal;
        } else {
            lo = mid;
        }
    }
    out.toi = lo;
    out.fraction = out.toi / dt;
    // No time after the start passes the discrete check: the body cannot move in this step without
    // going deeper (a resting body the contacts hold a little deeper than half the tolerance): it
    // stays at its start, at rest relative to the SDF (see guardStep).
    out.pinned = !(out.toi > 0);
    return SDFCCD_OK;
}

namespace detail {

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
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    // The step's start pose of object i: the snapshot of this step's narrow phase, else Bullet's
    // integration of the step undone (its end pose moved back by its velocities over dt; kinematic
    // bodies by their interpolation velocities).
    const bool snapped = snapshot_step == guard_step;
    auto startOf = [&](int i, btTransform& t) {
        // (Kinematic bodies are already at their end pose in the narrow phase: saveKinematicState.)
        if (snapped && !objs[i]->isKinematicObject() && (size_t)i < start_poses.size() && start_poses[(size_t)i].first == objs[i]) {
            t = start_poses[(size_t)i].second;
            return;
        }
        const btCollisionObject* co = objs[i];
        const btRigidBody* rb = btRigidBody::upcast(co);
        const bool kin = co->isKinematicObject() || !rb;
        btTransformUtil::integrateTransform(co->getWorldTransform(), -(kin ? co->getInterpolationLinearVelocity() : rb->getLinearVelocity()),
                                            -(kin ? co->getInterpolationAngularVelocity() : rb->getAngularVelocity()), (btScalar)dt, t);
    };
    if (dt > 0) {
        if (!workspace && sdfccd_create_workspace(&workspace) != SDFCCD_OK) workspace = nullptr;
        const double tol = cfg.guard_tolerance;
        // The SDFs and the boxes they sweep in the step.
        struct SdfObject {
            const btCollisionObject* co;
            sdfccd_SdfId sdf;
            btTransform t0, t1;
            btVector3 lo, hi;
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
            else startOf(i, o.t0);
            sweptBox(s, o.t0, o.t1, o.lo, o.hi);
            sdfs.push_back(o);
        }
        std::vector<std::pair<const btCollisionShape*, btTransform>> parts;
        btTransform id;
        id.setIdentity();
        for (int i = 0; i < objs.size() && !sdfs.empty(); ++i) {
            btRigidBody* body = btRigidBody::upcast(objs[i]);
            if (!body || body->isStaticOrKinematicObject()) continue;
            btTransform t0;
            startOf(i, t0);
            const btTransform t1 = body->getWorldTransform();
            const btCollisionShape* shape = body->getCollisionShape();
            btVector3 lo, hi;
            sweptBox(shape, t0, t1, lo, hi);
            const btVector3 pad((btScalar)tol, (btScalar)tol, (btScalar)tol);
            lo -= pad;
            hi += pad;
            parts.clear();
            bool collected = false;
            GuardOut best;
            best.toi = dt;
            const SdfObject* best_sdf = nullptr;
            for (const SdfObject& o : sdfs) {
                if (o.co == body || !overlaps(lo, hi, o.lo, o.hi)) continue;
                if (!collected) {
                    leaves(shape, id, parts);
                    collected = true;
                }
                sdfccd_RigidMotion sm;
                // The SDF's motion (a static one still has its pose: NULL would mean the world origin).
                if (motionFromPoses(o.t0, o.t1, btVector3(0, 0, 0), dt, &sm) != SDFCCD_OK) {
                    stats.query_errors++;
                    continue;
                }
                for (const auto& part : parts) {
                    if (part.first == o.co->getCollisionShape() || !isMeshLike(part.first)) continue;
                    const MeshEntry* me = shapes.meshFor(part.first);
                    if (!me) continue;
                    // A check that costs nothing: this step's narrow phase (its start-pose query over the
                    // step's reach) saw the body (a top-level shape) no deeper than d0 at its start; no
                    // point moves farther than the centre's displacement plus the turn times the mesh's
                    // radius, so with a static SDF and d0 - that > -tolerance/2 no point reaches the
                    // tolerance (phi is 1-Lipschitz; as sure as that query's local search).
                    if (snapped && parts.size() == 1 && o.t0 == o.t1 && part.first == shape) {
                        auto g = start_gaps.find(std::make_pair(static_cast<const btCollisionObject*>(body), o.co));
                        if (g != start_gaps.end() && g->second.first == guard_step) {
                            const double moved = (double)(t1.getOrigin() - t0.getOrigin()).length() +
                                                 (double)t0.getRotation().angleShortestPath(t1.getRotation()) * me->radius;
                            if (g->second.second - moved > -0.5 * tol) {
                                stats.guard_skipped++;
                                continue;
                            }
                        }
                    }
                    const btTransform inv = part.second.inverse();
                    sdfccd_RigidMotion mm;
                    if (motionFromPoses(t0 * part.second, t1 * part.second, inv.getOrigin(), dt, &mm) !=
                        SDFCCD_OK) {
                        stats.query_errors++;
                        continue;
                    }
                    GuardOut r;
                    stats.guard_queries++;
                    if (guardRigid(o.sdf, &sm, me->id, mm, dt, r) != SDFCCD_OK) {
                        stats.query_errors++;
                        continue;
                    }
                    if (r.rolled_back && r.toi < best.toi) {
                        best = r;
                        best_sdf = &o;
                    }
                }
            }
            if (!best_sdf) continue;
            // Back to the time of impact along the executed motion (the body's own frame).
            sdfccd_RigidMotion bm;
            if (motionFromPoses(t0, t1, btVector3(0, 0, 0), dt, &bm) != SDFCCD_OK) continue;
            body->setCenterOfMassTransform(poseAt(bm, best.toi));
            // The velocity. A body rolled back for the first time keeps it: the next step starts at
            // the time of impact, in contact, and its contacts (every point, with friction) take the
            // impact as the solver's response. A body rolled back again in the next step (its
            // contacts did not stop it) loses its velocity into the surface: first its centre's
            // (relative to the SDF body at the contact point), then, if the contact point still
            // approaches (a spin), an inelastic impulse there along the normal makes the approach
            // zero, with Coulomb friction (the pair's combined coefficient) reducing the point's
            // tangential velocity by at most mu times that impulse. The SDF body counts as infinitely heavy.
            if (best.pinned) {
                // Held at its start pose for the whole step: at rest relative to the SDF body.
                const btRigidBody* sb = btRigidBody::upcast(best_sdf->co);
                body->setLinearVelocity(sb ? sb->getVelocityInLocalPoint(body->getCenterOfMassPosition() - sb->getCenterOfMassPosition())
                                           : btVector3(0, 0, 0));
                body->setAngularVelocity(sb ? sb->getAngularVelocity() : btVector3(0, 0, 0));
            }
            auto last = last_rollback.find(body);
            const bool again = last != last_rollback.end() && last->second == guard_step - 1;
            last_rollback[body] = guard_step;
            if (again && !best.pinned) {
                const btVector3 p = bt(best.point), n = bt(best.normal);
                btVector3 vs(0, 0, 0);
                if (const btRigidBody* sb = btRigidBody::upcast(best_sdf->co)) vs = sb->getVelocityInLocalPoint(p - sb->getCenterOfMassPosition());
                const btScalar vc = (body->getLinearVelocity() - vs).dot(n);
                if (vc < 0) body->setLinearVelocity(body->getLinearVelocity() - n * vc);
                const btVector3 r = p - body->getCenterOfMassPosition();
                const btScalar vn = (body->getVelocityInLocalPoint(r) - vs).dot(n);
                const btScalar k = body->getInvMass() + n.dot((body->getInvInertiaTensorWorld() * r.cross(n)).cross(r));
                if (vn < 0 && k > 0) {
                    const btScalar j = -vn / k;
                    body->applyImpulse(n * j, r);
                    const btScalar mu = body->getFriction() * best_sdf->co->getFriction();
                    btVector3 u = body->getVelocityInLocalPoint(r) - vs;
                    u -= n * u.dot(n);
                    const btScalar ul = u.length();
                    if (ul > SIMD_EPSILON && mu > 0) {
                        const btVector3 t = u / ul;
                        const btScalar kt = body->getInvMass() + t.dot((body->getInvInertiaTensorWorld() * r.cross(t)).cross(r));
                        if (kt > 0) body->applyImpulse(-t * btMin(mu * j, ul / kt), r);
                    }
                }
            }
            body->setInterpolationLinearVelocity(body->getLinearVelocity());
            body->setInterpolationAngularVelocity(body->getAngularVelocity());
            stats.rollbacks++;
            stats.last_toi_fraction = best.fraction;
        }
    }
    for (auto it = last_rollback.begin(); it != last_rollback.end();)
        if (it->second < guard_step) it = last_rollback.erase(it);
        else ++it;
    for (auto it = start_gaps.begin(); it != start_gaps.end();)
        if (it->second.first < guard_step) it = start_gaps.erase(it);
        else ++it;
    ++guard_step;
}

SDFCCD_BULLET_NAMESPACE_END
