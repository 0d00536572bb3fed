// SPDX-License-Identifier: MIT
/** @file snapshot.h  PNG snapshots of a scene (a small headless rasteriser, no library). */
#ifndef SDFCCD_SCENES_SNAPSHOT_H
#define SDFCCD_SCENES_SNAPSHOT_H

#include <string>
#include <vector>

#include "scene.h"

namespace scenes {

/** Writes DIR/<label>_step<N>.png: the bodies' meshes and the colliders' isosurfaces
 * (sdfccd_extract_isosurface), flat-shaded, seen from a fixed camera that frames the scene;
 * samples of a body deeper than 1 mm inside a collider are drawn red. */
class Snapshotter {
public:
    explicit Snapshotter(const std::string& dir);
    ~Snapshotter();
    bool enabled() const { return !m_dir.empty(); }
    /** `sample_phi[b][i]`: phi at sample i of body b (may be empty for a body). */
    void write(Scene& scene, const std::vector<std::vector<double>>& sample_phi, const char* label, int step);

private:
    struct Impl;
    std::string m_dir;
    Impl* m_impl;
};

} // namespace scenes

#endif
