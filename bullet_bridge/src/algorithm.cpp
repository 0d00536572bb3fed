// SPDX-License-Identifier: MIT
// sdfccd Bullet bridge: the collision algorithm, its create function, registration, verify()
// and check() (see bridge.h).
//
// Dispatch: ONE create function per dispatcher table serves every registered pair in both body
// orders. It decides once, when Bullet creates the pair's algorithm, which body is the mesh
// (GImpact mesh, convex shape, or the moving SdfShape of an SDF-SDF pair) and which the SDF; the
// algorithm then orders the wrappers in one place and everything downstream sees (mesh, SDF).
#include "internal.h"

#include <cassert>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <new>
#include <string>
#include <typeinfo>

#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <LinearMath/btPoolAllocator.h>

SDFCCD_BULLET_NAMESPACE_BEGIN

using namespace detail;

namespace {

// Dispatchers that have a bridge (for the "registered twice" check across bridges, and for the
// misuse report's diagnosis).
std::mutex g_registry_mutex;
std::map<const btCollisionDispatcher*, const BridgeImpl*> g_registered;

} // namespace

namespace detail {

class MeshSdfAlgorithm : public btCollisionAlgorithm
{
public:
    MeshSdfAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, BridgeImpl* bridge, bool mesh_is_body1, bool closest)
        : btCollisionAlgorithm(ci), m_bridge(bridge), m_manifold(ci.m_manifold), m_own(false),
          m_mesh_is_body1(mesh_is_body1), m_closest(closest)
    {
    }
    ~MeshSdfAlgorithm() override
    {
        if (m_manifold && m_own) m_dispatcher->releaseManifold(m_manifold);
        for (btPersistentManifold* m : m_extra) {
            if (!m) continue;
            // Their points never fire started/ended (the first manifold speaks for the pair).
            for (int i = 0; i < m->getNumContacts(); ++i) m->clearUserCache(m->getContactPoint(i));
            m->setNumContacts(0);
            m_dispatcher->releaseManifold(m);
        }
    }

    void processCollision(const btCollisionObjectWrapper* body0Wrap, const btCollisionObjectWrapper* body1Wrap,
                          const btDispatcherInfo& dispatchInfo, btManifoldResult* resultOut) override
    {
        const btCollisionObjectWrapper* mw = body0Wrap;
        const btCollisionObjectWrapper* sw = body1Wrap;
        if (m_mesh_is_body1) std::swap(mw, sw);
        // The manifold's order is fixed whatever the dispatcher's: A = mesh, B = SDF. A manifold
        // handed in by a compound is used when it has that order.
        if (m_manifold && !m_own && m_manifold->getBody0() != mw->getCollisionObject()) m_manifold = nullptr;
        if (!m_manifold) {
            m_manifold = m_dispatcher->getNewManifold(mw->getCollisionObject(), sw->getCollisionObject());
            m_own = true;
        }
        btPersistentManifold* all[1 + kExtraManifolds] = { m_manifold };
        int count = 1;
        if (!m_closest && m_bridge->cfg.max_contacts >= MANIFOLD_CACHE_SIZE)
            for (int i = 0; i < kExtraManifolds; ++i) {
                if (!m_extra[i]) m_extra[i] = m_dispatcher->getNewManifold(mw->getCollisionObject(), sw->getCollisionObject());
                all[count++] = m_extra[i];
            }
        resultOut->setPersistentManifold(m_manifold);
        m_bridge->process(mw, sw, dispatchInfo, resultOut, all, count, m_closest, m_closest ? nullptr : &m_kept);
    }

    btScalar calculateTimeOfImpact(btCollisionObject* body0, btCollisionObject* body1, const btDispatcherInfo& dispatchInfo,
                                   btManifoldResult*) override
    {
        if (m_mesh_is_body1) std::swap(body0, body1);
        return (btScalar)m_bridge->timeOfImpact(body0, body1, dispatchInfo.m_timeStep);
    }

    void getAllContactManifolds(btManifoldArray& manifoldArray) override
    {
        if (m_manifold && m_own) manifoldArray.push_back(m_manifold);
        for (btPersistentManifold* m : m_extra)
            if (m) manifoldArray.push_back(m);
    }

    KeptIds* kept() { return m_closest ? nullptr : &m_kept; }

private:
    BridgeImpl* m_bridge;
    btPersistentManifold* m_manifold;
    btPersistentManifold* m_extra[kExtraManifolds] = { nullptr, nullptr, nullptr }; // the cover points (contact_policy.cpp)
    bool m_own;
    bool m_mesh_is_body1;
    bool m_closest;
    KeptIds m_kept = KeptIds(); // the reduction's points of the last step (contact_policy.cpp)
};

KeptIds* keptIdsOf(btCollisionAlgorithm* algorithm)
{
    MeshSdfAlgorithm* a = dynamic_cast<MeshSdfAlgorithm*>(algorithm);
    return a ? a->kept() : nullptr;
}

// Bullet's collision-algorithm pool hands out 192-byte elements in both Debian builds; the
// algorithm stays far below (and falls back to btAlignedAlloc if a pool is smaller).
static_assert(sizeof(MeshSdfAlgorithm) <= 192, "MeshSdfAlgorithm must fit Bullet's collision-algorithm pool element");

} // namespace detail

struct BridgeImpl::CreateFunc : public btCollisionAlgorithmCreateFunc {
    BridgeImpl* bridge;
    bool closest;
    CreateFunc(BridgeImpl* b, bool closest_points) : bridge(b), closest(closest_points) {}

    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* w0,
                                                   const btCollisionObjectWrapper* w1) override
    {
        bool mesh_is_body1 = false;
        btCollisionDispatcher* d = dynamic_cast<btCollisionDispatcher*>(ci.m_dispatcher1);
        const int t0 = w0->getCollisionShape()->getShapeType(), t1 = w1->getCollisionShape()->getShapeType();
        if (!closest && (t0 == SOFTBODY_SHAPE_PROXYTYPE || t1 == SOFTBODY_SHAPE_PROXYTYPE)) return softAlgorithm(bridge, ci, w0);
        if (!bridge->orient(w0, w1, mesh_is_body1)) {
            // Not ours after all (a GImpact compound, an SdfShape without a valid handle): what
            // the slot held before us.
            if (!closest && (t0 == GIMPACT_SHAPE_PROXYTYPE || t1 == GIMPACT_SHAPE_PROXYTYPE))
                return bridge->gimpact_fn.CreateCollisionAlgorithm(ci, w0, w1);
            if (!d) return nullptr;
            btCollisionConfiguration* cc = d->getCollisionConfiguration();
            btCollisionAlgorithmCreateFunc* f =
                closest ? cc->getClosestPointsAlgorithmCreateFunc(t0, t1) : cc->getCollisionAlgorithmCreateFunc(t0, t1);
            return f ? f->CreateCollisionAlgorithm(ci, w0, w1) : nullptr;
        }
        void* mem = nullptr;
        btPoolAllocator* pool = d ? d->getCollisionConfiguration()->getCollisionAlgorithmPool() : nullptr;
        if (pool && pool->getElementSize() >= (int)sizeof(MeshSdfAlgorithm))
            mem = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(MeshSdfAlgorithm));
        else
            mem = btAlignedAlloc(sizeof(MeshSdfAlgorithm), 16); // freeCollisionAlgorithm falls back to btAlignedFree
        return new (mem) MeshSdfAlgorithm(ci, bridge, mesh_is_body1, closest);
    }
};

BridgeImpl::BridgeImpl(const Config& c) : cfg(c)
{
    cfg.max_contacts = std::max(1, std::min(cfg.max_contacts, 4));
    cfg.batch_threads = std::max(1, std::min(cfg.batch_threads, 256));
    if (!(cfg.contact_margin >= 0)) cfg.contact_margin = 0;
}

BridgeImpl::~BridgeImpl()
{
    sdfccd_destroy_workspace(workspace);
    for (sdfccd_Workspace* ws : batch_ws) sdfccd_destroy_workspace(ws);
}

bool BridgeImpl::isOurSdf(const btCollisionShape* s) const
{
    const int type = s->getShapeType();
    if (type == cfg.sdf_shape_type) {
        const SdfShape* shape = dynamic_cast<const SdfShape*>(s);
        return shape && shape->isValid();
    }
    return type == SDF_SHAPE_PROXYTYPE && cfg.handle_bt_sdf_shape && dynamic_cast<const btSdfCollisionShape*>(s);
}

bool BridgeImpl::isMeshLike(const btCollisionShape* s) const
{
    const int type = s->getShapeType();
    if (type == GIMPACT_SHAPE_PROXYTYPE)
        return static_cast<const btGImpactShapeInterface*>(s)->getGImpactShapeType() != CONST_GIMPACT_COMPOUND_SHAPE;
    if (s->isConvex()) return cfg.convex_shapes;
    if (type == cfg.sdf_shape_type) {
        const SdfShape* shape = dynamic_cast<const SdfShape*>(s);
        return shape && shape->isValid() && shape->hasFiniteBounds();
    }
    return false;
}

bool BridgeImpl::orient(const btCollisionObjectWrapper* w0, const btCollisionObjectWrapper* w1, bool& mesh_is_body1) const
{
    const btCollisionShape* s0 = w0->getCollisionShape();
    const btCollisionShape* s1 = w1->getCollisionShape();
    const bool m0 = isMeshLike(s0), m1 = isMeshLike(s1), sdf0 = isOurSdf(s0), sdf1 = isOurSdf(s1);
    if (m0 && m1 && sdf0 && sdf1) {
        // Two SdfShapes: the moving one is sampled by its triangulation against the other.
        mesh_is_body1 = w0->getCollisionObject()->isStaticOrKinematicObject() &&
                        !w1->getCollisionObject()->isStaticOrKinematicObject();
        return true;
    }
    if (m0 && sdf1 && !sdf0) {
        mesh_is_body1 = false;
        return true;
    }
    if (m1 && sdf0 && !sdf1) {
        mesh_is_body1 = true;
        return true;
    }
    return false;
}

// ---------------------------------------------------------------------------------------------
namespace {

// The slots the bridge writes: (a, b) pairs of shape types, each order.
std::vector<std::pair<int, int>> slots(const Config& cfg)
{
    std::vector<std::pair<int, int>> s;
    auto both = [&](int a, int b) {
        s.push_back(std::make_pair(a, b));
        if (a != b) s.push_back(std::make_pair(b, a));
    };
    both(GIMPACT_SHAPE_PROXYTYPE, cfg.sdf_shape_type);
    if (cfg.handle_bt_sdf_shape && cfg.sdf_shape_type != SDF_SHAPE_PROXYTYPE) both(GIMPACT_SHAPE_PROXYTYPE, SDF_SHAPE_PROXYTYPE);
    if (cfg.convex_shapes)
        for (int t = 0; t < CONCAVE_SHAPES_START_HERE; ++t) both(t, cfg.sdf_shape_type);
    both(cfg.sdf_shape_type, cfg.sdf_shape_type);
    both(SOFTBODY_SHAPE_PROXYTYPE, cfg.sdf_shape_type); // soft bodies: contacts only (closest points stay Bullet's)
    if (cfg.handle_bt_sdf_shape && cfg.sdf_shape_type != SDF_SHAPE_PROXYTYPE) both(SOFTBODY_SHAPE_PROXYTYPE, SDF_SHAPE_PROXYTYPE);
    return s;
}

// The dispatcher's tables, read without creating anything (findAlgorithm would allocate from a world
// that may be stepping on another thread). A pointer to a protected member, formed through a derived
// class, applies to any btCollisionDispatcher.
struct DispatchTable : btCollisionDispatcher {
    static btCollisionAlgorithmCreateFunc* func(const btCollisionDispatcher* d, bool closest, int a, int b)
    {
        return closest ? (d->*(&DispatchTable::m_doubleDispatchClosestPoints))[a][b] : (d->*(&DispatchTable::m_doubleDispatchContactPoints))[a][b];
    }
};

// Whether the registered bridge's create functions still fill the slots `which` of its dispatcher's contact
// table (and closest-points table when `closest`).
bool intact(const BridgeImpl* impl, const std::vector<std::pair<int, int>>& which, bool closest)
{
    const btCollisionDispatcher* d = impl->dispatcher;
    if (!d) return false;
    for (const auto& s : which)
        if (DispatchTable::func(d, false, s.first, s.second) != impl->fn[0].get() ||
            (closest && DispatchTable::func(d, true, s.first, s.second) != impl->fn[1].get()))
            return false;
    return true;
}

void say(std::string* message, const char* fmt, const char* a = "", long long n = 0)
{
    if (!message) return;
    char buf[512];
    std::snprintf(buf, sizeof buf, fmt, a, n);
    *message = buf;
}

} // namespace

// ---------------------------------------------------------------------------------------------
const char* statusString(Status s)
{
    static const char* const names[] = { "Ok", "AlreadyRegistered", "TooLate", "Overwritten", "NotRegistered", "InvalidArgument", "InvalidShape" };
    return (unsigned)s < sizeof names / sizeof names[0] ? names[(unsigned)s] : "?";
}

std::size_t collisionAlgorithmSize() { return sizeof(MeshSdfAlgorithm); }

Bridge::Bridge(const Config& config) : m_impl(new BridgeImpl(config))
{
    m_impl->fn[0].reset(new BridgeImpl::CreateFunc(m_impl, false));
    m_impl->fn[1].reset(new BridgeImpl::CreateFunc(m_impl, true));
}

Bridge::~Bridge()
{
    if (m_impl->dispatcher) {
        std::lock_guard<std::mutex> lock(g_registry_mutex);
        g_registered.erase(m_impl->dispatcher);
    }
    softForget(m_impl);
    delete m_impl;
}

Status Bridge::registerWith(btCollisionWorld* world)
{
    const Config& cfg = m_impl->cfg;
    btCollisionDispatcher* d = world ? dynamic_cast<btCollisionDispatcher*>(world->getDispatcher()) : nullptr;
    if (!d) return Status::InvalidArgument;
    if (m_impl->dispatcher) return Status::AlreadyRegistered;
    {
        std::lock_guard<std::mutex> lock(g_registry_mutex);
        if (g_registered.count(d)) return Status::AlreadyRegistered;
    }
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    for (int i = 0; i < objs.size(); ++i) {
        const btCollisionShape* s = objs[i]->getCollisionShape();
        if (s->getShapeType() == GIMPACT_SHAPE_PROXYTYPE || s->getShapeType() == cfg.sdf_shape_type || m_impl->isOurSdf(s))
            return Status::TooLate;
    }
    if (!(cfg.sdf_shape_type > CONCAVE_SHAPES_START_HERE && cfg.sdf_shape_type < CONCAVE_SHAPES_END_HERE) ||
        cfg.sdf_shape_type == GIMPACT_SHAPE_PROXYTYPE)
        return Status::InvalidArgument;
    {
        std::lock_guard<std::mutex> lock(g_registry_mutex);
        if (g_registered.count(d)) return Status::AlreadyRegistered;
        if (d->getNumManifolds() > 0) return Status::TooLate;
        g_registered[d] = m_impl;
    }
    // GImpact first: its registerAlgorithm overwrites every (GIMPACT, x) and (x, GIMPACT) slot.
    btGImpactCollisionAlgorithm::registerAlgorithm(d);
    for (const auto& s : slots(cfg)) {
        d->registerCollisionCreateFunc(s.first, s.second, m_impl->fn[0].get());
        d->registerClosestPointsCreateFunc(s.first, s.second, m_impl->fn[1].get());
    }
    softRegister(m_impl);
    m_impl->dispatcher = d;
    guardAttach(m_impl, world);
    softAttach(m_impl, world);
    m_impl->batch_world = world;
    return verify();
}

Status Bridge::verify() const
{
    if (!m_impl->dispatcher) return Status::NotRegistered;
    return intact(m_impl, slots(m_impl->cfg), true) ? Status::Ok : Status::Overwritten;
}

Status Bridge::check(btCollisionWorld* world, std::string* message) const
{
    say(message, "ok");
    if (!world) {
        say(message, "check: no world");
        return Status::InvalidArgument;
    }
    if (!m_impl->dispatcher || m_impl->dispatcher != world->getDispatcher()) {
        say(message, "the bridge is not registered with this world's dispatcher: call Bridge::registerWith(world) right "
                     "after creating the world, before adding bodies");
        return Status::NotRegistered;
    }
    if (verify() != Status::Ok) {
        say(message, "the dispatcher no longer creates the bridge's algorithm (registerCollisionCreateFunc or "
                     "btGImpactCollisionAlgorithm::registerAlgorithm was called after Bridge::registerWith)");
        return Status::Overwritten;
    }
    const btCollisionObjectArray& objs = world->getCollisionObjectArray();
    for (int i = 0; i < objs.size(); ++i) {
        const SdfShape* s = dynamic_cast<const SdfShape*>(objs[i]->getCollisionShape());
        if (!s) continue;
        sdfccd_SdfInfo info;
        if (!s->isValid() || sdfccd_sdf_get_info(s->sdf(), &info) != SDFCCD_OK) {
            say(message, "collision object %lld has an SdfShape whose sdfccd handle is invalid or destroyed", "", i);
            return Status::InvalidShape;
        }
    }
    if (m_impl->stats.query_errors > 0)
        say(message, "ok, but %s%lld queries failed (see sdfccd_last_error)", "", (long long)m_impl->stats.query_errors);
    return Status::Ok;
}

void Bridge::unregister()
{
    btCollisionDispatcher* d = m_impl->dispatcher;
    if (!d) return;
    btCollisionConfiguration* cc = d->getCollisionConfiguration();
    for (const auto& s : slots(m_impl->cfg)) {
        d->registerCollisionCreateFunc(s.first, s.second, cc->getCollisionAlgorithmCreateFunc(s.first, s.second));
        d->registerClosestPointsCreateFunc(s.first, s.second, cc->getClosestPointsAlgorithmCreateFunc(s.first, s.second));
    }
    guardDetach(m_impl);
    softUnregister(m_impl);
    m_impl->batch_world = nullptr;
    m_impl->batch_cache.clear();
    std::lock_guard<std::mutex> lock(g_registry_mutex);
    g_registered.erase(d);
    m_impl->dispatcher = nullptr;
}

double Bridge::timeOfImpact(const btCollisionObject* mesh_body, const btCollisionObject* sdf_body, double dt)
{
    if (!mesh_body || !sdf_body) return 1.0;
    return m_impl->timeOfImpact(mesh_body, sdf_body, dt);
}

Status Bridge::setBtSdfData(const btSdfCollisionShape* shape, const void* data, size_t size)
{
    if (!m_impl->shapes.setBtSdfData(shape, data, size)) return Status::InvalidArgument;
    m_impl->batch_cache.clear(); // its queries name the shape's old SDF handle
    return Status::Ok;
}

void Bridge::invalidateShape(const btCollisionShape* shape)
{
    m_impl->shapes.invalidate(shape);
    m_impl->batch_cache.clear(); // its queries name the shape's old mesh or SDF handle
}

// ---------------------------------------------------------------------------------------------
// Misuse reports (bridge.h: setMisuseHandler).
namespace {

std::mutex g_misuse_mutex;
MisuseHandler g_misuse_handler = nullptr;
void* g_misuse_user = nullptr;

void defaultMisuseHandler(Status, const char* message, const btCollisionShape*, void*)
{
    // Debug builds of the bridge stop here so the mistake is seen on the first step it matters;
    // release builds (NDEBUG) do nothing: the library never aborts there.
    (void)message;
    assert(!"sdfccd_bullet misuse (see the message passed to the misuse handler; Bridge::check(world) tells more)");
}

} // namespace

MisuseHandler setMisuseHandler(MisuseHandler handler, void* user)
{
    std::lock_guard<std::mutex> lock(g_misuse_mutex);
    MisuseHandler old = g_misuse_handler ? g_misuse_handler : defaultMisuseHandler;
    g_misuse_handler = handler;
    g_misuse_user = handler ? user : nullptr;
    return old;
}

void detail::callMisuseHandler(Status status, const char* message, const btCollisionShape* shape)
{
    MisuseHandler h;
    void* user;
    {
        std::lock_guard<std::mutex> lock(g_misuse_mutex);
        h = g_misuse_handler ? g_misuse_handler : defaultMisuseHandler;
        user = g_misuse_user;
    }
    h(status, message, shape, user);
}

namespace detail {

void reportGImpactMisuse(const btTriangleCallback* callback, const btCollisionShape* shape, int& last_reported)
{
    // btGImpactTriangleCallback is private to btGImpactCollisionAlgorithm.cpp: recognised by its
    // type name (RTTI is on in Debian's builds). Not recognising it only loses the report.
    const char* name = callback ? typeid(*callback).name() : nullptr;
    if (!name || !std::strstr(name, "btGImpactTriangleCallback")) return;
    // Which mistake it most likely is, from the bridges this process has registered (check(world)
    // knows the world and tells exactly).
    Status status = Status::NotRegistered;
    {
        std::lock_guard<std::mutex> lock(g_registry_mutex);
        if (!g_registered.empty()) {
            // (The dispatcher tables are read, not probed with findAlgorithm: another world may be
            // stepping on another thread.)
            status = Status::TooLate;
            for (const auto& r : g_registered) {
                const int t = r.second->cfg.sdf_shape_type; // both orders of (GImpact, SdfShape)
                if (!intact(r.second, { { GIMPACT_SHAPE_PROXYTYPE, t }, { t, GIMPACT_SHAPE_PROXYTYPE } }, false)) status = Status::Overwritten;
            }
        }
    }
    if (last_reported == (int)status + 1) return; // said already
    last_reported = (int)status + 1;
    const char* what = status == Status::NotRegistered
                           ? "no sdfccd_bullet::Bridge is registered: call Bridge::registerWith(world) right after creating the world"
                       : status == Status::Overwritten
                           ? "a registered bridge was overwritten (btGImpactCollisionAlgorithm::registerAlgorithm or "
                             "registerCollisionCreateFunc after Bridge::registerWith)"
                           : "the pair's algorithm was created before Bridge::registerWith (register before adding bodies), or this "
                             "world's dispatcher has no bridge";
    char message[512];
    std::snprintf(message, sizeof message,
                  "Bullet's GImpact algorithm is colliding a GImpact mesh with an SdfShape, without CCD (it can pass through): %s; "
                  "Bridge::check(world) names the problem",
                  what);
    callMisuseHandler(status, message, shape);
}

} // namespace detail

const Config& Bridge::config() const { return m_impl->cfg; }
Stats Bridge::stats() const { return m_impl->stats; }
void Bridge::resetStats() { m_impl->stats = Stats(); }

SDFCCD_BULLET_NAMESPACE_END
