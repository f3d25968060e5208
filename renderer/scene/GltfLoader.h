#pragma once
// glTF 2.0 (.gltf and .glb) -> Scene. Everything the file says is validated before it is used, and
// every problem with the file is a SceneError that carries a JSON pointer into the glTF document.
//
// What is supported and how (details in the modules GltfLoader.cpp drives: docs/DEVELOPMENT.md):
// - Buffers and images from data URIs, the GLB BIN chunk, or files under LoadOptions::assetRoot.
//   External URIs may not be absolute, may not contain "..", and may not resolve (through
//   symlinks) outside the root. Other URI schemes (http:, file:) are refused.
// - The default scene's node hierarchy (TRS or matrix), flattened to world space. Primitives whose
//   world transform has a negative determinant get their winding flipped, so every MeshInstance
//   is counter-clockwise front facing.
// - Triangle lists, strips and fans (strips and fans are converted to lists). Points and lines are
//   refused. Any accessor component type (KHR_mesh_quantization), sparse accessors.
// - Missing normals are generated, area weighted over shared vertices (glTF asks for flat normals;
//   a file that wants faceted shading simply does not share vertices). Tangents are generated
//   (per-triangle UV derivatives, Gram-Schmidt, handedness in w) for primitives whose material has
//   a normal texture and whose file gave none.
// - Materials: metallic-roughness, KHR_materials_transmission, _ior, _emissive_strength.
//   KHR_texture_transform is ignored unless required (then refused).
// - KHR_lights_punctual; the first camera node in depth-first scene order.
// - Skins, morph targets and animations are ignored (the bind pose is rendered).
//
// Scene::digest is "sha256:" of the loaded bytes. When a .gltf pulls in external files, their
// bytes are hashed after the JSON, each preceded by its path relative to the .gltf and its
// length, so changing a .bin changes the digest.

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <functional>
#include <string>
#include <string_view>

#include "renderer/scene/Scene.h"
#include "api/Sha256.h"

namespace radiant {

// A problem with the scene file (user input): maps to a 4xx with `pointer` as the offending field.
struct SceneError : std::runtime_error {
  SceneError(std::string pointer_, const std::string& message)
      : std::runtime_error(message), pointer(std::move(pointer_)) {}
  std::string pointer;  // JSON pointer into the glTF document ("/accessors/3"); "" = whole file
};

struct LoadOptions {
  // External buffers and images are read only from inside this directory. For loadScene() an
  // empty root means the file's own directory; for loadSceneFromMemory() it means no external
  // files at all.
  std::filesystem::path assetRoot;
  // Upper bound on the bytes read (the file plus external files).
  std::size_t maxBytes = std::size_t(256) << 20;
  // Upper bound on decoded memory: every image's pixels and every mesh instance's expanded
  // accessors, charged before allocation (GltfLimits.h). radiantd --max-decode-bytes.
  std::size_t maxDecodedBytes = std::size_t(512) << 20;
  // Called with each decoded allocation's size before it is made, after it fits maxDecodedBytes (the
  // daemon's shared decode memory, radiantd --decode-memory-bytes: it may wait for memory and throw,
  // e.g. api::ApiError 503 decode-busy, which the load passes on unchanged). Empty: not called.
  std::function<void(std::size_t)> reserveDecoded;
  // Deepest nesting of the JSON (GltfLimits.h). radiantd --max-json-depth.
  std::size_t maxJsonDepth = 64;
};

// Loads a .gltf or .glb file, which must lie inside options.assetRoot (when given).
// Scene::name is the file's stem.
Scene loadScene(const std::filesystem::path& file, const LoadOptions& options = {});

// Loads GLB (detected by the magic "glTF") or glTF JSON from memory. External URIs resolve
// against options.assetRoot. Scene::name is the default scene's name in the file.
Scene loadSceneFromMemory(std::string_view bytes, const LoadOptions& options = {});

}  // namespace radiant
