#pragma once
// The scenes that ship with the daemon (scenes/*.gltf). Their text is embedded in the binary at
// build time, so the daemon is relocatable; builtinScenePath() is for tools that want the file.

#include <string>
#include <string_view>
#include <vector>

#include "renderer/scene/Scene.h"

namespace radiant {

// Sorted names without extension: "ao_creases", "cornell_box", "cornell_glass", "cornell_mirror".
std::vector<std::string> builtinSceneNames();

// The .gltf text of a built-in scene. Throws SceneError for an unknown name.
std::string_view builtinSceneSource(const std::string& name);

// The scene's file in the source tree (RADIANT_SCENES_DIR/<name>.gltf). Throws SceneError for an
// unknown name.
std::string builtinScenePath(const std::string& name);

// Loads a built-in scene from the embedded text; Scene::name is `name`.
Scene loadBuiltinScene(const std::string& name);

}  // namespace radiant
