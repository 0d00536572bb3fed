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

void BridgeImpl::clampPre(btDynamicsWorld* world)
{
    starts.clear();
    pairs.clear();
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    for (int i = 0; i < objs.size(); ++i) {
        const btCollisionObject* o = objs[i];
        if (!o->isStaticOrKinematicObject()) starts[o] = o->getWorldTransform();
    }
}

void BridgeImpl::clampPost(btDynamicsWorld*, double dt)
{
    for (const PairRecord& p : pairs) {
        auto it = starts.find(p.mesh);
        if (it == starts.end()) continue;
        btRigidBody* body = const_cast<btRigidBody*>(btRigidBody::upcast(p.mesh));
        if (!body) continue;
        const MeshEntry* me = shapes.meshFor(p.shape);
        sdfccd_SdfId sdf = shapes.sdfFor(p.sdf->getCollisionShape(), cfg.sdf_shape_type, cfg.handle_bt_sdf_shape);
        if (!me || !sdf.index1) continue;
        sdfccd_RigidMotion sm = sdfccd_default_rigid_motion();
        sm.pose = toPose(p.sdf->getWorldTransform());
        // 1. Does the end pose penetrate deeper than the tolerance?
        sdfccd_RigidMotion end = sdfccd_default_rigid_motion();
        end.pose = toPose(body->getWorldTransform() * p.child);
        sdfccd_QueryParams params = cfg.query;
        params.margin = -clamp_tolerance;
        sdfccd_QueryResult res;
        if (sdfccd_query_mesh(sdf, &sm, me->id, &end, 0, 0, &params, nullptr, 0, &res) != SDFCCD_OK || !res.hit) continue;
        // 2. Back to where the penetration was half the tolerance along the step's motion (or
        //    the tolerance itself if the step began deeper); a body that started the step that
        //    deep is left to the ordinary contacts.
        BodyMotion M;
        M.t0 = it->second * p.child;
        M.t1 = body->getWorldTransform() * p.child;
        btTransformUtil::calculateVelocity(M.t0, M.t1, (btScalar)dt, M.v, M.w);
        sdfccd_RigidMotion mm = M.rigid();
        sdfccd_Contact c[4];
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
        body->setCenterOfMassTransform(M.at(res.toi) * p.child.inverse());
        if (res.contact_count > 0) {
            btVector3 nrm = bt(c[0].normal);
            btVector3 v = body->getLinearVelocity();
            btScalar vn = v.dot(nrm);
            if (vn < 0) body->setLinearVelocity(v - nrm * vn);
        }
        stats.clamps++;
    }
}

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
        m_impl->starts.clear();
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
