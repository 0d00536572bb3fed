// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: the no-tunnelling guarantee (paper, Section 4: the simulation never
// advances past a time of impact). An action (btActionInterface, run by Bullet after it
// integrates a step) checks the EXECUTED motion of every dynamic body that can reach an SDF
// (its start pose of the step to the pose the solver produced) with the CCD; a body that went
// deeper than Config::guard_tolerance goes back along that motion to its time of impact and
// loses its velocity into the surface there (an inelastic impulse at the contact point).
// Whatever moved it (its own contacts' spin, a kick from another body, a compound parent), it
// does not pass an SDF. Start poses: taken at the step's first narrow-phase call of the bridge
// (world transforms are the start poses then), otherwise the poses this action left the step before.
#include "internal.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

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

sdfccd_Status motionFromPoses(const sdfccd_Pose& a, const sdfccd_Pose& b, sdfccd_Vec3 c, double dt, sdfccd_RigidMotion* out)
{
    // Stand-in for the core's sdfccd_rigid_motion_from_poses (centre lerp, shortest-arc rotation).
    if (!(dt > 0)) return SDFCCD_INVALID_ARGUMENT;
    const btQuaternion qa((btScalar)a.orientation.x, (btScalar)a.orientation.y, (btScalar)a.orientation.z, (btScalar)a.orientation.w);
    const btQuaternion qb((btScalar)b.orientation.x, (btScalar)b.orientation.y, (btScalar)b.orientation.z, (btScalar)b.orientation.w);
    const btVector3 lc = bt(c);
    const btVector3 ga = bt(a.position) + quatRotate(qa, lc), gb = bt(b.position) + quatRotate(qb, lc);
    btQuaternion d = qb * qa.inverse();
    if (d.w() < 0) d = -d;
    const double s = std::sqrt((double)(d.x() * d.x() + d.y() * d.y() + d.z() * d.z()));
    const double ang = 2 * std::atan2(s, (double)d.w());
    btVector3 w(0, 0, 0);
    if (s > 0) w = btVector3(d.x(), d.y(), d.z()) * (btScalar)(ang / s / dt);
    *out = sdfccd_default_rigid_motion();
    out->pose = a;
    out->local_center = c;
    out->linear_velocity = v3((gb - ga) / (btScalar)dt);
    out->angular_velocity = v3(w);
    return SDFCCD_OK;
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
    // Stand-in for the core's sdfccd_guard_rigid. The contact level is the tolerance below the
    // surface, or the tolerance below the depth the step starts with. (1) The CCD over the step at
    // that level; (2) a discrete check of the end pose, which catches a contact the CCD's local
    // search missed (a large triangle touching in two places); (3) the body goes back to the
    // time it first came within half the tolerance of that level (the start if it began deeper),
    // so a body put back starts the next step guarded.
    out = GuardOut();
    out.toi = dt;
    const double tol = cfg.guard_tolerance;
    sdfccd_QueryParams ccd = sdfccd_default_query_params();
    sdfccd_QueryParams dcd = ccd;
    dcd.method = SDFCCD_METHOD_DCD;
    if (guard_contacts.size() < 64) guard_contacts.resize(64);
    // Deepest phi of the mesh at time t of the motion when some point is at or below `level`.
    auto deepest = [&](double t, double level, double* d, sdfccd_Contact* at) -> sdfccd_Status {
        sdfccd_RigidMotion m = mm, s;
        m.pose = toPose(poseAt(mm, t));
        m.linear_velocity = m.angular_velocity = sdfccd_Vec3{ 0, 0, 0 };
        if (sm) {
            s = *sm;
            s.pose = toPose(poseAt(*sm, t));
            s.linear_velocity = s.angular_velocity = sdfccd_Vec3{ 0, 0, 0 };
        }
        dcd.margin = level;
        sdfccd_QueryResult r;
        for (;;) {
            const sdfccd_Status st = sdfccd_query_mesh_ws(workspace, sdf, sm ? &s : nullptr, mesh, &m, 0, 0, &dcd, guard_contacts.data(),
                                                          (int32_t)guard_contacts.size(), &r);
            if (st != SDFCCD_OK) return st;
            stats.sdf_evaluations += r.sdf_evaluations;
            if (r.contacts_found <= r.contact_count) break;
            guard_contacts.resize((size_t)r.contacts_found);
        }
        *d = INFINITY;
        for (int k = 0; k < r.contact_count; ++k)
            if (guard_contacts[(size_t)k].distance < *d) {
                *d = guard_contacts[(size_t)k].distance;
                if (at) *at = guard_contacts[(size_t)k];
            }
        return SDFCCD_OK;
    };
    sdfccd_Contact c;
    auto sweep = [&](double level, double t1, sdfccd_QueryResult& r) {
        ccd.margin = level;
        const sdfccd_Status st = sdfccd_query_mesh_ws(workspace, sdf, sm, mesh, &mm, 0, t1, &ccd, &c, 1, &r);
        if (st == SDFCCD_OK) stats.sdf_evaluations += r.sdf_evaluations;
        return st;
    };
    double level = -tol, d = INFINITY;
    sdfccd_QueryResult r;
    sdfccd_Status st = sweep(level, dt, r);
    if (st != SDFCCD_OK) return st;
    if (r.hit && r.state == SDFCCD_STATE_PENETRATING) {
        // Starts deeper than the tolerance: held to the tolerance below its starting depth.
        if ((st = deepest(0, level, &d, nullptr)) != SDFCCD_OK) return st;
        if (!std::isfinite(d)) return SDFCCD_OK;
        level = d - tol;
        if ((st = sweep(level, dt, r)) != SDFCCD_OK) return st;
        if (r.hit && r.state == SDFCCD_STATE_PENETRATING) return SDFCCD_OK;
    }
    double bad = dt; // a time at which the mesh is at or below the level
    if (r.hit) {
        bad = r.toi;
        out.point = c.point;
        out.normal = c.normal;
    } else {
        if ((st = deepest(dt, level, &d, &c)) != SDFCCD_OK) return st;
        if (!std::isfinite(d)) return SDFCCD_OK; // clear
        out.point = c.point;
        out.normal = c.normal;
    }
    out.rolled_back = true;
    // The last time before `bad` at which the mesh is clear of the level plus half the tolerance:
    // the CCD's entry time when it finds one, else bisection on the discrete check.
    const double safe_level = level + 0.5 * tol;
    sdfccd_QueryResult r2;
    if ((st = sweep(safe_level, bad, r2)) != SDFCCD_OK) return st;
    double good = 0;
    if (r2.hit && r2.state != SDFCCD_STATE_PENETRATING) {
        good = r2.toi;
    } else if (!r2.hit) {
        good = bad;
    }
    // Confirm with the discrete check (the CCD may have missed as above; its entry point itself
    // lies at the safe level): no point deeper than a quarter of the tolerance below it, else
    // bisection between the start and there for the last time that is.
    const double accept = safe_level - 0.25 * tol;
    if (good > 0) {
        if ((st = deepest(good, accept, &d, nullptr)) != SDFCCD_OK) return st;
        if (std::isfinite(d)) {
            double lo = 0, hi = good;
            for (int it = 0; it < 12; ++it) {
                const double mid = 0.5 * (lo + hi);
                if ((st = deepest(mid, accept, &d, nullptr)) != SDFCCD_OK) return st;
                (std::isfinite(d) ? hi : lo) = mid;
            }
            good = lo;
        }
    }
    out.toi = good;
    out.fraction = good / dt;
    return SDFCCD_OK;
}

namespace detail {

void guardAttach(BridgeImpl* impl, btCollisionWorld* world)
{
    btDynamicsWorld* dw = dynamic_cast<btDynamicsWorld*>(world);
    if (!dw || !(impl->cfg.guard_tolerance > 0) || impl->guard_world) return;
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
    recordPoses(world);
    snapshot_step = guard_step;
}

void BridgeImpl::recordPoses(const btCollisionWorld* world)
{
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    start_poses.resize((size_t)objs.size());
    for (int i = 0; i < objs.size(); ++i) start_poses[(size_t)i] = std::make_pair(static_cast<const btCollisionObject*>(objs[i]), objs[i]->getWorldTransform());
}

void BridgeImpl::guardStep(btCollisionWorld* world, double dt)
{
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    auto startOf = [&](int i, btTransform& t) {
        if ((size_t)i >= start_poses.size() || start_poses[(size_t)i].first != objs[i]) return false;
        t = start_poses[(size_t)i].second;
        return true;
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
            if (objs[i]->isStaticObject() || !startOf(i, o.t0)) o.t0 = o.t1;
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
            if (!startOf(i, t0)) continue;
            const btTransform t1 = body->getWorldTransform();
            if (std::getenv("SDFCCD_GUARD_TRACE")) std::fprintf(stderr, "body %d start %g %g %g end %g %g %g\n", i, (double)t0.getOrigin().x(), (double)t0.getOrigin().y(), (double)t0.getOrigin().z(), (double)t1.getOrigin().x(), (double)t1.getOrigin().y(), (double)t1.getOrigin().z());
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
                const bool sdf_moves = !(o.t0 == o.t1);
                if (sdf_moves && motionFromPoses(toPose(o.t0), toPose(o.t1), sdfccd_Vec3{ 0, 0, 0 }, dt, &sm) != SDFCCD_OK) {
                    stats.query_errors++;
                    continue;
                }
                for (const auto& part : parts) {
                    if (part.first == o.co->getCollisionShape() || !isMeshLike(part.first)) continue;
                    const MeshEntry* me = shapes.meshFor(part.first);
                    if (!me) continue;
                    const btTransform inv = part.second.inverse();
                    sdfccd_RigidMotion mm;
                    if (motionFromPoses(toPose(t0 * part.second), toPose(t1 * part.second), v3(inv.getOrigin()), dt, &mm) !=
                        SDFCCD_OK) {
                        stats.query_errors++;
                        continue;
                    }
                    GuardOut r;
                    stats.guard_queries++;
                    if (guardRigid(o.sdf, sdf_moves ? &sm : nullptr, me->id, mm, dt, r) != SDFCCD_OK) {
                        stats.query_errors++;
                        continue;
                    }
                    if (std::getenv("SDFCCD_GUARD_TRACE"))
                        std::fprintf(stderr, "guard step %lld body %d: rolled %d toi %g\n", (long long)guard_step, i, (int)r.rolled_back, r.toi);
                    if (r.rolled_back && r.toi < best.toi) {
                        best = r;
                        best_sdf = &o;
                    }
                }
            }
            if (!best_sdf) continue;
            // Back to the time of impact along the executed motion (the body's own frame).
            sdfccd_RigidMotion bm;
            if (motionFromPoses(toPose(t0), toPose(t1), sdfccd_Vec3{ 0, 0, 0 }, dt, &bm) != SDFCCD_OK) continue;
            body->setCenterOfMassTransform(poseAt(bm, best.toi));
            // An inelastic impulse at the contact point along the SDF's normal: the point's velocity
            // into the surface (relative to the SDF body's velocity there) becomes zero; the SDF
            // body counts as infinitely heavy. Tangential velocity and the spin it does not take are kept.
            const btVector3 p = bt(best.point), n = bt(best.normal);
            const btVector3 r = p - body->getCenterOfMassPosition();
            btVector3 vs(0, 0, 0);
            if (const btRigidBody* sb = btRigidBody::upcast(best_sdf->co)) vs = sb->getVelocityInLocalPoint(p - sb->getCenterOfMassPosition());
            const btScalar vn = (body->getVelocityInLocalPoint(r) - vs).dot(n);
            if (vn < 0) {
                const btVector3 rxn = r.cross(n);
                const btScalar k = body->getInvMass() + n.dot((body->getInvInertiaTensorWorld() * rxn).cross(r));
                if (k > 0) body->applyImpulse(n * (-vn / k), r);
            }
            body->setInterpolationLinearVelocity(body->getLinearVelocity());
            body->setInterpolationAngularVelocity(body->getAngularVelocity());
            stats.rollbacks++;
            stats.last_toi_fraction = best.fraction;
        }
    }
    // The poses this step ends with start the next one, unless its narrow phase sees others.
    recordPoses(world);
    ++guard_step;
}

SDFCCD_BULLET_NAMESPACE_END
