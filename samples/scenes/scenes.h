// SPDX-License-Identifier: MIT
/** @file scenes.h  The parts of the scene table, one function per file of scenes. */
#ifndef SDFCCD_SCENES_SCENES_H
#define SDFCCD_SCENES_SCENES_H

#include <vector>

#include "scene.h"

namespace scenes {

/** gimpact-demo, gimpact-shot-*, sdf-box*, landscape (bullet_recreations.cpp). */
void appendBulletRecreations(std::vector<SceneEntry>& table);
/** The paper's scenes: shuriken, torus-crossings, skateboard, pyramids, bunny, hoop, spikes,
 * triangle-flat, spin360 (paper_scenes.cpp); cloth (cloth.cpp). */
void appendPaperScenes(std::vector<SceneEntry>& table);
/** cloth, cloth-1ms (cloth.cpp). */
void appendClothScenes(std::vector<SceneEntry>& table);

} // namespace scenes

#endif
