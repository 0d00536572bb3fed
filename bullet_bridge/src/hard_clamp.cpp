// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: the optional hard clamp (notes/bullet-integration.md section 3.4 C).
// Internal pre/post-tick callbacks save each mesh body's start pose and, after integration, move
// a mesh that ends the step deeper than the tolerance back along its motion. The callbacks CHAIN
// the user's: callbacks installed before setHardClamp() are called after ours with the world's
// user info untouched; our callbacks find their bridge through a registry keyed by world, never
// through the world's user info, so a user callback installed later cannot make them crash
// (Bridge::check() reports that it displaced the clamp).
#include "internal.h"

#include <mutex>
#include <unordered_set>

SDFCCD_BULLET_NAMESPACE_BEGIN

namespace {

std::mutex g_clamp_mutex;
std::unordered_map<const btDynamicsWorld*, BridgeImpl*> g_clamps;

BridgeImpl* clampOf(const btDynamicsWorld* world)
{
    std::lock_guard<std::mutex> lock(g_clamp_mutex);
    auto it = g_clamps.find(world);
    return it == g_clamps.end() ? nullptr : it->second;
}

// Reads the world's installed callbacks (btDynamicsWorld has setters only): a pointer to a
// protected member formed in a derived class is a pointer to the base's member.
struct WorldAccess : public btDynamicsWorld {
    static btInternalTickCallback get(const btDynamicsWorld* w, bool pre)
    {
        return w->*(pre ? &WorldAccess::m_internalPreTickCallback : &WorldAccess::m_internalTickCallback);
    }
};

void clampPreTick(btDynamicsWorld* world, btScalar dt)
{
    BridgeImpl* b = clampOf(world);
    if (!b) return;
    b->clampPre(world);
    if (b->user_pre) b->user_pre(world, dt);
}

void clampPostTick(btDynamicsWorld* world, btScalar dt)
{
    BridgeImpl* b = clampOf(world);
    if (!b) return;
    b->clampPost(world, dt);
    if (b->user_post) b->user_post(world, dt);
}

} // namespace

using namespace detail;

void BridgeImpl::clampPre(btDynamicsWorld*) { pairs.clear(); }

void BridgeImpl::clampPost(btDynamicsWorld* world, double dt)
{
    stats.clamps += projectPairs(world, dt, clamp_tolerance, true);
    pairs.clear();
}

int BridgeImpl::projectPairs(btCollisionWorld* world, double dt, double tolerance, bool to_impact)
{
    // Records from a collision pass whose objects have left the world since are skipped.
    std::unordered_set<const btCollisionObject*> alive;
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    for (int i = 0; i < objs.size(); ++i) alive.insert(objs[i]);
    int moved = 0;
    std::vector<sdfccd_Contact> cs(64);
    for (const PairRecord& p : pairs) {
        if (!alive.count(p.mesh) || !alive.count(p.sdf) || p.mesh->getCollisionShape() != p.top) continue;
        btRigidBody* body = const_cast<btRigidBody*>(btRigidBody::upcast(p.mesh));
        if (!body || body->isStaticOrKinematicObject()) continue;
        const MeshEntry* me = shapes.meshFor(p.shape);
        sdfccd_SdfId sdf = shapes.sdfFor(p.sdf->getCollisionShape(), cfg.sdf_shape_type, cfg.handle_bt_sdf_shape);
        if (!me || !sdf.index1) continue;
        sdfccd_RigidMotion sm = sdfccd_default_rigid_motion();
        sm.pose = toPose(p.sdf->getWorldTransform());
        sdfccd_QueryParams params = cfg.query;
        params.method = SDFCCD_METHOD_DCD;
        params.margin = -tolerance;
        // The deepest feature of the mesh at pose `t` deeper than the tolerance (false if none).
        auto deepest = [&](const btTransform& t, sdfccd_Contact* out) {
            sdfccd_RigidMotion m = sdfccd_default_rigid_motion();
            m.pose = toPose(t * p.child);
            sdfccd_QueryResult res;
            if (sdfccd_query_mesh(sdf, &sm, me->id, &m, 0, 0, &params, cs.data(), (int32_t)cs.size(), &res) != SDFCCD_OK || !res.hit ||
                res.contact_count <= 0)
                return false;
            int k = 0;
            for (int i = 1; i < res.contact_count; ++i)
                if (cs[i].distance < cs[k].distance) k = i;
            if (out) *out = cs[k];
            return true;
        };
        if (to_impact) {
            // 1. Does the end pose penetrate deeper than the tolerance?
            sdfccd_RigidMotion end = sdfccd_default_rigid_motion();
            end.pose = toPose(body->getWorldTransform() * p.child);
            sdfccd_QueryParams q = cfg.query;
            q.margin = -tolerance;
            sdfccd_QueryResult r;
            if (sdfccd_query_mesh(sdf, &sm, me->id, &end, 0, 0, &q, nullptr, 0, &r) != SDFCCD_OK || !r.hit) continue;
            // The hard clamp: back along the step's motion to where the penetration was half the
            // tolerance (or the tolerance itself if the step began deeper), and no velocity into
            // the surface; a body that started the step that deep is left to the contacts.
            BodyMotion M;
            M.t0 = p.start * p.child;
            M.t1 = body->getWorldTransform() * p.child;
            btTransformUtil::calculateVelocity(M.t0, M.t1, (btScalar)dt, M.v, M.w);
            sdfccd_RigidMotion mm = M.rigid();
            sdfccd_QueryParams ccd = cfg.query;
            sdfccd_QueryResult res;
            bool found = false;
            const double margins[2] = { -0.5 * tolerance, -tolerance };
            for (double mg : margins) {
                ccd.margin = mg;
                sdfccd_Status cst = sdfccd_query_mesh(sdf, &sm, me->id, &mm, 0, dt, &ccd, cs.data(), 4, &res);
                if (cst == SDFCCD_OK && res.hit && res.state != SDFCCD_STATE_PENETRATING) {
                    found = true;
                    break;
                }
            }
            if (!found) continue;
            body->setCenterOfMassTransform(M.at(res.toi) * p.child.inverse());
            if (res.contact_count > 0) {
                btVector3 nrm = bt(cs[0].normal);
                btVector3 v = body->getLinearVelocity();
                btScalar vn = v.dot(nrm);
                if (vn < 0) body->setLinearVelocity(v - nrm * vn);
            }
            ++moved;
            continue;
        }
        // The projection. A body that started the step that deep is left to the contacts (no
        // jump out of a deep start, e.g. a body created inside the SDF).
        sdfccd_Contact c;
        if (p.clear) {
            // The queries proved every feature at least the margin away from the surface over the
            // predicted motion, the start included (phi is 1-Lipschitz). A feature moved by at
            // most `moved` from its predicted end position is then at least margin - moved away:
            // only a body that ended more than margin + tolerance from its predicted end pose (a
            // kick from another contact in the same step) can be deeper than the tolerance.
            if (p.sdf->getWorldTransform() == p.sdf_start) {
                const btTransform d = (p.predicted * p.child).inverseTimes(body->getWorldTransform() * p.child);
                const double moved = (double)d.getOrigin().length() + (double)d.getRotation().getAngleShortestPath() * me->radius;
                if (moved <= p.margin + tolerance) continue;
            }
            if (!deepest(body->getWorldTransform(), &c) || deepest(p.start, nullptr)) continue; // as for any body
            // Kicked: back along the step's actual motion, from its clear start, to where the mesh
            // first came within half the tolerance of the surface, and no velocity into the
            // surface there: the state a contact found at that time of impact would have left
            // (the normal projection below could push a body that a kick carried across most of a
            // thin part of the SDF out through its far side).
            BodyMotion M;
            M.t0 = p.start * p.child;
            M.t1 = body->getWorldTransform() * p.child;
            btTransformUtil::calculateVelocity(M.t0, M.t1, (btScalar)dt, M.v, M.w);
            const sdfccd_RigidMotion mm = M.rigid();
            sdfccd_QueryParams ccd = cfg.query;
            ccd.margin = -0.5 * tolerance;
            sdfccd_QueryResult res;
            sdfccd_Contact hit;
            if (dt > 0 && sdfccd_query_mesh(sdf, &sm, me->id, &mm, 0, dt, &ccd, &hit, 1, &res) == SDFCCD_OK && res.hit &&
                res.state != SDFCCD_STATE_PENETRATING) {
                body->setCenterOfMassTransform(M.at(res.toi) * p.child.inverse());
                if (res.contact_count > 0) {
                    const btVector3 nrm = bt(hit.normal);
                    const btRigidBody* sdf_body = btRigidBody::upcast(p.sdf);
                    const btVector3 v = body->getLinearVelocity();
                    const btScalar vn = (v - (sdf_body ? sdf_body->getLinearVelocity() : btVector3(0, 0, 0))).dot(nrm);
                    if (vn < 0) body->setLinearVelocity(v - nrm * vn);
                }
                ++moved;
                continue;
            }
        } else if (!deepest(body->getWorldTransform(), &c) || deepest(p.start, nullptr)) {
            continue;
        }
        // Out along the deepest feature's normal to half the tolerance, like a positional (split
        // impulse) correction: the velocity is left to the contacts.
        for (int it = 0; it < 3; ++it) {
            btTransform t = body->getWorldTransform();
            t.setOrigin(t.getOrigin() + bt(c.normal) * (btScalar)(-c.distance - 0.5 * tolerance));
            body->setCenterOfMassTransform(t);
            if (!deepest(t, &c)) break;
        }
        ++moved;
    }
    return moved;
}

namespace detail {

// The end-of-step projection: Bullet calls actions after it integrates the step (before it
// synchronises motion states), so this sees each body's final pose of the step.
class ProjectionAction : public btActionInterface
{
public:
    explicit ProjectionAction(BridgeImpl* b) : m_bridge(b) {}
    void updateAction(btCollisionWorld* world, btScalar dt) override
    {
        // The hard clamp, when on, does the same after the step with its own tolerance.
        if (!m_bridge->clamp_world) {
            m_bridge->stats.projections += m_bridge->projectPairs(world, (double)dt, m_bridge->cfg.projection_tolerance, false);
            m_bridge->pairs.clear();
        }
    }
    void debugDraw(btIDebugDraw*) override {}

private:
    BridgeImpl* m_bridge;
};

void projectionAttach(BridgeImpl* impl, btCollisionWorld* world)
{
    btDynamicsWorld* dw = dynamic_cast<btDynamicsWorld*>(world);
    if (!dw || !(impl->cfg.projection_tolerance > 0) || impl->projection_world) return;
    impl->projection.reset(new ProjectionAction(impl));
    dw->addAction(impl->projection.get());
    impl->projection_world = dw;
}

void projectionDetach(BridgeImpl* impl)
{
    if (impl->projection_world && impl->projection) impl->projection_world->removeAction(impl->projection.get());
    impl->projection_world = nullptr;
    impl->pairs.clear();
}

} // namespace detail

Status Bridge::setHardClamp(btDiscreteDynamicsWorld* world, bool on, double tolerance)
{
    if (!world) return Status::InvalidArgument;
    if (!m_impl->dispatcher) return Status::NotRegistered;
    if (on) {
        if (m_impl->clamp_world && m_impl->clamp_world != world) return Status::InvalidArgument;
        {
            std::lock_guard<std::mutex> lock(g_clamp_mutex);
            auto it = g_clamps.find(world);
            if (it != g_clamps.end() && it->second != m_impl) return Status::AlreadyRegistered;
            g_clamps[world] = m_impl;
        }
        m_impl->clamp_tolerance = tolerance > 0 ? tolerance : 1e-3;
        if (m_impl->clamp_world != world) {
            // Chain whatever the user installed; keep the world's user info as it is.
            m_impl->user_pre = WorldAccess::get(world, true);
            m_impl->user_post = WorldAccess::get(world, false);
            void* info = world->getWorldUserInfo();
            world->setInternalTickCallback(clampPreTick, info, true);
            world->setInternalTickCallback(clampPostTick, info, false);
            m_impl->clamp_world = world;
        }
    } else {
        if (m_impl->clamp_world == world) {
            // Give the user's callbacks their slots back (only where ours are still installed).
            void* info = world->getWorldUserInfo();
            if (WorldAccess::get(world, true) == clampPreTick) world->setInternalTickCallback(m_impl->user_pre, info, true);
            if (WorldAccess::get(world, false) == clampPostTick) world->setInternalTickCallback(m_impl->user_post, info, false);
            std::lock_guard<std::mutex> lock(g_clamp_mutex);
            g_clamps.erase(world);
        }
        m_impl->clamp_world = nullptr;
        m_impl->user_pre = m_impl->user_post = nullptr;
        m_impl->pairs.clear();
    }
    return Status::Ok;
}

bool Bridge::hardClampEnabled() const { return m_impl->clamp_world != nullptr; }

namespace detail {
// Ok, or ClampDisplaced when a callback installed after setHardClamp() replaced ours.
Status clampCheck(const BridgeImpl* impl, const btCollisionWorld* world)
{
    if (!impl->clamp_world || impl->clamp_world != world) return Status::Ok;
    if (WorldAccess::get(impl->clamp_world, true) != clampPreTick || WorldAccess::get(impl->clamp_world, false) != clampPostTick)
        return Status::ClampDisplaced;
    return Status::Ok;
}
void clampForget(BridgeImpl* impl)
{
    std::lock_guard<std::mutex> lock(g_clamp_mutex);
    for (auto it = g_clamps.begin(); it != g_clamps.end();)
        if (it->second == impl) it = g_clamps.erase(it);
        else ++it;
}
} // namespace detail

SDFCCD_BULLET_NAMESPACE_END
