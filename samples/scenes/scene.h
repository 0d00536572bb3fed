// SPDX-License-Identifier: MIT
/** @file scene.h  The scene library: named scenes shared by the runner (sdfccd_scenes), the
 * stability tests (ctest runs the runner with --check) and the Table 4 benchmark.
 *
 * Model: Box2D's benchmark table. Each scene is written once as a class deriving from Scene and
 * listed in the table of registry.cpp as {name, summary, create, steps, dt}. A scene owns its
 * world (a Bullet btDiscreteDynamicsWorld with the sdfccd bridge, or a kinematic replay through
 * the C ABI) and exposes what the runner measures:
 *  - bodies: moving triangle meshes (vertices plus extra sample points in the body frame, the
 *    body pose after each step, or world positions for deformable meshes);
 *  - colliders: the SDF surfaces, each with an EXACT reference for measuring (the analytic SDF
 *    itself, the grid a .cdf holds, or the exact distance to the mesh a grid was baked from).
 * The runner (runner.cpp) evaluates phi of every collider at every sample point of every body
 * after every step, and reports the measured quantities (see Summary).
 *
 * Units: metres, seconds, kilograms. Every scene states its up axis and gravity.
 */
#ifndef SDFCCD_SCENES_SCENE_H
#define SDFCCD_SCENES_SCENE_H

#include <cstdint>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "sdfccd/sdfccd.h"

namespace scenes {

/** Options of a run (the runner's command line). */
struct Options {
    sdfccd_Method method = SDFCCD_METHOD_FWGSS; /**< CCD method of the bridge / kinematic queries. */
    bool subdivision = true;                    /**< Adaptive subdivision (Section 4.5). */
    bool stock = false;   /**< Bullet scenes: the SDF surfaces as btBvhTriangleMeshShape (no bridge). */
    bool quick = false;   /**< Fewer bodies where a scene is large (the ctest variants; documented per scene). */
    double margin = -1;   /**< Contact margin (m) of the bridge / queries; < 0: the scene's default. */
    int solver_iterations = -1; /**< Bullet scenes: btContactSolverInfo::m_numIterations; < 0: the scene's default. */
    double guard = NAN; /**< Bullet scenes: the bridge's Config::guard_tolerance (m); <= 0: off; NaN: its default. */
    int batch_threads = -1; /**< Bullet scenes: the bridge's Config::batch_threads (< 1: its default, 1). */
    std::string data_dir; /**< The project's data/ folder. */
};

/** A triangle mesh in its body frame, with the points the runner measures: every vertex, plus
 * (when `sample_density` > 1) a barycentric lattice on every triangle, so a coarse mesh whose
 * faces are pierced between vertices (the spikes scene) shows its penetration. */
struct MeshData {
    std::string name;
    std::vector<double> v;       /**< 3 * vertex count, body frame. */
    std::vector<uint32_t> f;     /**< 3 * triangle count, counter-clockwise. */
    std::vector<double> samples; /**< 3 * sample count: the vertices first, then lattice points. */
    double radius = 0;           /**< max |vertex| (body frame origin to farthest vertex). */
    double half_thickness = 0;   /**< Half the smallest extent of the local box. */
    sdfccd_Aabb bounds{};
    sdfccd_MeshId handle{};      /**< The mesh as an sdfccd handle (created by finish(); destroyed with the data). */
    MeshData() = default;
    MeshData(const MeshData&) = delete;
    MeshData& operator=(const MeshData&) = delete;
    ~MeshData();
    int vertexCount() const { return (int)(v.size() / 3); }
    int triangleCount() const { return (int)(f.size() / 3); }
    int sampleCount() const { return (int)(samples.size() / 3); }
    /** Recomputes samples, radius, bounds, half_thickness. `density` lattice points per edge (1: vertices only). */
    void finish(int density = 1);
    /** The samples for vertex positions `x` (3 per vertex; e.g. a deformed mesh's world positions). */
    void samplesFor(const double* x, std::vector<double>& out) const;
    int density = 1;
};

/** Loads an OBJ through sdfccd_load_mesh, scaled; returns null (message on stderr) on failure. */
std::shared_ptr<MeshData> loadMesh(const std::string& path, double scale);
/** loadMesh of `file` in the data folder (opt.data_dir + "/" + file), named `name` in reports
 * (null: the file's base name). */
std::shared_ptr<MeshData> loadDataMesh(const Options& opt, const std::string& file, double scale, const char* name = nullptr);
/** Copies a mesh handle's vertices (3 per vertex) and triangles (3 per triangle) out, with its info,
 * and destroys the handle. False (message on stderr; the handle still destroyed) on failure. */
bool takeMeshArrays(sdfccd_MeshId id, std::vector<double>& v, std::vector<uint32_t>& f, sdfccd_MeshInfo& info);
/** A mesh from arrays. */
std::shared_ptr<MeshData> makeMesh(const std::string& name, std::vector<double> v, std::vector<uint32_t> f);
/** The grid SDF of `mesh` (sdfccd_create_grid_from_mesh: `resolution` cells per axis, `padding`
 * m around the mesh, 2 threads); a null handle (message naming `what` on stderr) on failure. */
sdfccd_SdfId gridFromMesh(sdfccd_MeshId mesh, int resolution, double padding, const char* what);

/** A rigid transform in double: x_world = R x_local + p (R row-major). */
struct Frame {
    double R[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
    double p[3] = { 0, 0, 0 };
    void apply(const double* x, double* out) const;
    void applyInverse(const double* x, double* out) const;
    static Frame fromPose(const sdfccd_Pose& pose);
    sdfccd_Pose toPose() const;
};

/** A moving mesh the runner measures. The scene updates `frame`, `v`, `w` (or `world` for a
 * deformable mesh) after every step. */
struct Body {
    std::string name;
    std::shared_ptr<MeshData> mesh;
    Frame frame;
    double v[3] = { 0, 0, 0 }, w[3] = { 0, 0, 0 }; /**< Linear (m/s) and angular (rad/s) velocity, world. */
    bool deformable = false;
    std::vector<double> world; /**< Deformable: world positions of the samples (3 per sample). */
    bool active = true;        /**< False before a body enters the scene (a shot fired later). */
};

/** An SDF surface and its exact reference for measuring. Exactly one of `exact` (evaluated in
 * the collider's local frame: analytic, CSG, callback or a grid) or `exact_mesh` (the exact
 * signed distance to that mesh, in the local frame) is set. */
struct Collider {
    std::string name;
    Frame frame;             /**< World from local; updated by kinematic scenes. */
    sdfccd_SdfId exact{};    /**< Not owned (the scene owns its handles). */
    sdfccd_MeshId exact_mesh{};
    sdfccd_SdfId render{};   /**< Drawn in snapshots when `exact` is not set (e.g. the grid of a mesh). */
    sdfccd_Aabb bounds{};    /**< Local box containing the surface (for culling far bodies). */
    /** A body centre c with dot(kill_normal, c) > kill_offset has passed through (tunnelled): e.g.
     * below a floor, or beyond a plate it was thrown at. Default: never. */
    double kill_normal[3] = { 0, 0, 0 };
    double kill_offset = 1e300;
    /** Instead of the kill plane: a body whose centre's path over a step (sampled every 2 mm)
     * passes deeper inside `exact` than the body's half-thickness went through it (a thin plate
     * passed in one step, which a body may also fly around: the shuriken's breastplate). */
    bool kill_swept = false;
    /** Sharp convex features of the surface (local frame, 3 per point: the spike grid's tips).
     * A lattice on a coarse face can pass between them while they pierce it, so the runner also
     * measures each rigid body's triangles at their points closest to these (the deepest point of
     * a face pierced by a tip, exactly when the face is square to the tip's axis). */
    std::vector<double> feature_points;
    /** The SDF the CCD queries use (what the bridge's shape wraps); for Table 4's probe queries. */
    sdfccd_SdfId ccd{};
    /** Sets the kill plane to "centre below height h along up". */
    void killBelow(const double* up, double h)
    {
        for (int k = 0; k < 3; ++k) kill_normal[k] = -up[k];
        kill_offset = -h;
    }
};

/** Per-step figures a scene reports about its own collision pipeline. */
struct StepCost {
    double ccd_seconds = 0;  /**< Time inside CCD queries (bridge or direct), cumulative. */
    int64_t ccd_queries = 0; /**< Cumulative. */
    int64_t hits = 0;        /**< Cumulative queries that found contact. */
    int64_t query_errors = 0; /**< Cumulative CCD queries that failed (no contacts from them; the bridge's Stats::query_errors). */
    int64_t triangles_tested = 0; /**< Cumulative (direct queries only; -1 when unknown). */
    int64_t sdf_evaluations = -1; /**< Cumulative SDF evaluations of the collision pipeline (-1 when unknown). */
    int contacts = 0;        /**< Contact points alive after this step (manifolds or query contacts). */
    int64_t freezes = 0;     /**< Cumulative: steps whose collision response hit its iteration cap and froze what still hit (cloth). */
};

class Scene {
public:
    virtual ~Scene() {}
    /** Advances one step of `dt` seconds (step index i, from 0) and updates bodies/colliders. */
    virtual void step(int i, double dt) = 0;
    /** Cumulative collision costs and the current contact count. */
    virtual StepCost cost() const = 0;
    /** Total mechanical energy (kinetic + potential, J); NaN when the scene does not define it. */
    virtual double energy() const = 0;
    /** True when energy is injected at step i (a shot fired): energy gain is not counted there. */
    virtual bool injects(int i) const { return false; }
    /** Largest penetration (m, >= 0) seen INSIDE steps along the motion the scene executed, for
     * kinematic scenes that know it (sampled along the executed path); 0 otherwise. */
    virtual double sweptPenetration() const { return 0; }
    /** "float" or "double": the btScalar of the Bullet build ("n/a (no Bullet)" for the C ABI scenes). */
    virtual const char* precision() const;
    /** One-line description of the configuration actually built (bodies, variants). */
    virtual std::string describe() const = 0;

    std::vector<Body> bodies;
    std::vector<Collider> colliders;
    double up[3] = { 0, 0, 1 };  /**< Up axis (for kill planes and potential energy). */
    double gravity[3] = { 0, 0, 0 }; /**< m/s^2 (Table 4's probe predicts the motion with it). */
    double ccd_margin = 0.01;        /**< Contact margin of the scene's CCD (m). */
    sdfccd_Aabb view{};          /**< Snapshot view box (world); empty (lo = hi) frames the bodies. */
};

/** `s` once its build() succeeded, else null (`s` deleted; build() printed why): the body of
 * the `create` function of a scene that is built after construction. */
template <class S> Scene* built(S* s)
{
    std::unique_ptr<S> owned(s);
    return owned->build() ? owned.release() : nullptr;
}

/** Table entry: Box2D's benchmark model. */
struct SceneEntry {
    const char* name;
    const char* summary;
    Scene* (*create)(const Options&); /**< Null (message on stderr) when the scene cannot be built. */
    int steps;                        /**< Default number of steps. */
    double dt;                        /**< Default step (s). */
};

/** The table (registry.cpp). */
const std::vector<SceneEntry>& sceneTable();
const SceneEntry* findScene(const std::string& name);

/** The method's command-line name: fwgss, fw, dcd, certified. */
const char* methodName(sdfccd_Method m);
bool parseMethod(const std::string& s, sdfccd_Method* out);

} // namespace scenes

#endif
