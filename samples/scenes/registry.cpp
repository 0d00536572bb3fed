// SPDX-License-Identifier: MIT
// The scene table (Box2D's benchmark model): every scene is listed once and shared by the
// runner, the stability tests and the benchmark.
#include "scenes.h"

namespace scenes {

const std::vector<SceneEntry>& sceneTable()
{
    static const std::vector<SceneEntry> table = [] {
        std::vector<SceneEntry> t;
        appendPaperScenes(t);
        appendClothScenes(t);
        appendBulletRecreations(t);
        return t;
    }();
    return table;
}

} // namespace scenes
