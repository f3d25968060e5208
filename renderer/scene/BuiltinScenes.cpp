#include "renderer/scene/BuiltinScenes.h"

#include <algorithm>

#include "embedded/radiant_builtin_scenes_data.h"
#include "renderer/scene/GltfLoader.h"

namespace radiant {
namespace {

constexpr std::string_view kExtension = ".gltf";

std::string_view findSource(const std::string& name) {
  const std::string_view text = builtin_scenes::find(name + std::string(kExtension));
  if (text.empty()) {
    std::string known;
    for (const auto& n : builtinSceneNames()) known += (known.empty() ? "" : ", ") + n;
    throw SceneError("", "unknown built-in scene \"" + name + "\" (known: " + known + ")");
  }
  return text;
}

}  // namespace

std::vector<std::string> builtinSceneNames() {
  std::vector<std::string> names;
  for (std::string_view n : builtin_scenes::names())
    if (n.size() > kExtension.size() && n.substr(n.size() - kExtension.size()) == kExtension)
      names.emplace_back(n.substr(0, n.size() - kExtension.size()));
  std::sort(names.begin(), names.end());
  return names;
}

std::string_view builtinSceneSource(const std::string& name) { return findSource(name); }

std::string builtinScenePath(const std::string& name) {
  findSource(name);
  return std::string(RADIANT_SCENES_DIR) + "/" + name + std::string(kExtension);
}

Scene loadBuiltinScene(const std::string& name) {
  // No asset root: the built-in scenes are self-contained (data URIs only).
  Scene scene = loadSceneFromMemory(findSource(name), LoadOptions{});
  scene.name = name;
  return scene;
}

}  // namespace radiant
