#include "renderer/scene/GltfLoader.h"

#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>  // Debian ships tinygltf as a shared library: no TINYGLTF_IMPLEMENTATION here

#include "renderer/scene/GltfCompression.h"
#include "renderer/scene/GltfConverter.h"
#include "renderer/scene/GltfFiles.h"
#include "renderer/scene/GltfLimits.h"
#include "renderer/scene/GltfPackage.h"

// The loader's modules: GltfFiles (file access, the raw document's checks, GLB), GltfLimits (sizes and
// decode budget), GltfCompression (meshopt, Draco), GltfAccessors (typed reads of buffers),
// GltfConverter with GltfMaterials and GltfMeshes (model -> Scene), GltfExtensions (the extension table).

namespace radiant {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace gltf;

Scene load(std::string_view bytes, const fs::path& baseDir, const fs::path& root,
           const LoadOptions& options) {
  if (bytes.size() > options.maxBytes)
    throw SceneError("", "the scene is " + std::to_string(bytes.size()) + " bytes, over the limit of " +
                             std::to_string(options.maxBytes));
  if (bytes.size() >= std::numeric_limits<unsigned int>::max())
    throw SceneError("", "the scene is too large");
  api::Sha256 digest;
  digest.update(bytes);
  const bool glb = bytes.size() >= 4 && bytes.substr(0, 4) == "glTF";
  const std::string_view jsonText = glb ? glbJson(bytes) : bytes;
  checkGltfText(jsonText, options);  // before any parser: nesting, UTF-8, overflowing numbers
  json doc;
  try {
    doc = json::parse(jsonText);
  } catch (const json::exception& e) {
    throw SceneError("", std::string(glb ? "the GLB JSON chunk" : "the file") +
                             " is neither valid JSON nor GLB: " + e.what());
  }
  std::vector<std::string> warnings;
  validateDocument(doc, baseDir, root, warnings);
  DecodeBudget budget = checkGltfDocument(doc, options);  // finite transforms; accessor expansion charged
  // EXT_meshopt_compression is decoded into a plain GLB before tinygltf sees the file, KHR_draco_mesh_compression
  // into the model right after (GltfCompression.h).
  std::string decodedBytes;
  std::string_view source = bytes;
  bool sourceGlb = glb;
  const bool meshopt = gltf::usesMeshopt(doc), draco = gltf::usesDraco(doc);
  if (meshopt || draco) {
    try {
      decodedBytes = packGltf(bytes, baseDir, root, options.maxBytes, true).bytes;
    } catch (const PackError& e) {
      throw SceneError(e.pointer, e.what());
    }
    if (meshopt) decodedBytes = gltf::decodeMeshopt(decodedBytes, budget);  // charged against --max-decode-bytes
    if (draco) decodedBytes = gltf::prepareDraco(decodedBytes);
    source = decodedBytes;
    sourceGlb = true;
  }

  FsContext fsContext;
  fsContext.root = root;
  fsContext.baseDir = baseDir;
  fsContext.budget = options.maxBytes - bytes.size();
  fsContext.digest = &digest;
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&fsFileExists, &fsExpandFilePath, &fsReadWholeFile, &fsWriteWholeFile, &fsContext});
  loader.SetImageLoader(&loadImageData, &budget);
  loader.SetStoreOriginalJSONForExtrasAndExtensions(true);
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  try {
    const std::string base = baseDir.string();
    ok = sourceGlb ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                                 reinterpret_cast<const unsigned char*>(source.data()),
                                                 static_cast<unsigned int>(source.size()), base)
                   : loader.LoadASCIIFromString(&model, &err, &warn, source.data(),
                                                static_cast<unsigned int>(source.size()), base);
  } catch (const std::exception& e) {
    err += e.what();
    ok = false;
  }
  if (!ok) {
    budget.rethrowImageError();
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    for (auto& c : err)
      if (c == '\n') c = ';';
    throw SceneError("", "invalid glTF: " + (err.empty() ? std::string("unknown error") : err));
  }
  gltf::decodeDraco(model, options.maxBytes);
  Scene scene = Converter(model, options.maxBytes).run();
  scene.warnings.insert(scene.warnings.begin(), warnings.begin(), warnings.end());
  checkSceneMagnitudes(scene, doc);  // world-space positions, camera and lights: finite, bounded
  scene.digest = "sha256:" + digest.finishHex();
  scene.features = computeFeatures(scene);
  return scene;
}

fs::path canonicalRoot(const fs::path& root) {
  if (root.empty()) return {};
  std::error_code ec;
  fs::path r = fs::canonical(root, ec);
  if (ec || !fs::is_directory(r))
    throw SceneError("", "the asset root " + root.string() + " is not a directory");
  return r;
}

}  // namespace

Scene loadScene(const fs::path& file, const LoadOptions& options) {
  std::error_code ec;
  const fs::path canon = fs::weakly_canonical(fs::absolute(file, ec), ec);
  if (ec || !fs::is_regular_file(canon))
    throw SceneError("", "scene file " + file.string() + " does not exist or is not a regular file");
  const fs::path root = options.assetRoot.empty() ? canon.parent_path() : canonicalRoot(options.assetRoot);
  if (!pathIsInside(root, canon))
    throw SceneError("", "scene file " + file.string() + " is outside the asset root " + root.string());
  const auto size = fs::file_size(canon, ec);
  if (ec) throw SceneError("", "cannot read " + file.string() + ": " + ec.message());
  if (size > options.maxBytes)
    throw SceneError("", "the scene is " + std::to_string(size) + " bytes, over the limit of " +
                             std::to_string(options.maxBytes));
  std::string bytes(size, '\0');
  std::ifstream in(canon, std::ios::binary);
  if (!in.read(bytes.data(), std::streamsize(size)))
    throw SceneError("", "cannot read " + file.string());
  Scene scene = load(bytes, canon.parent_path(), root, options);
  scene.name = file.stem().string();
  return scene;
}

Scene loadSceneFromMemory(std::string_view bytes, const LoadOptions& options) {
  const fs::path root = canonicalRoot(options.assetRoot);
  return load(bytes, root, root, options);
}

}  // namespace radiant
