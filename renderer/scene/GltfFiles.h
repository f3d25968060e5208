#pragma once
// The glTF loader's file access and the checks of the raw document before tinygltf parses it: external
// files only from inside the asset root and within the byte budget (tinygltf's file callbacks, hashed
// into the scene's digest), images charged against the decode budget before they are decoded, URIs and
// buffer views checked, and the GLB container's JSON chunk.
// Part of the glTF loader (GltfLoader.h: what is supported; its modules: docs/DEVELOPMENT.md).
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "api/Sha256.h"

namespace radiant::gltf {

// tinygltf's file callbacks (fsFileExists, fsExpandFilePath, fsReadWholeFile, fsWriteWholeFile) read
// only regular files inside the asset root, within the byte budget. The URIs were already checked
// (validateDocument); this is the second line of defence, applied to the exact path tinygltf is about
// to open (it also probes paths relative to the working directory). `user` is the FsContext.
struct FsContext {
  std::filesystem::path root;     // canonical; empty = no external files
  std::filesystem::path baseDir;  // canonical directory URIs are relative to (names files in the digest)
  std::size_t budget = 0;
  api::Sha256* digest = nullptr;
  std::string refused;  // why the last path was refused, for the error message
};

bool fsFileExists(const std::string& path, void* user);
std::string fsExpandFilePath(const std::string& path, void*);
bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user);
bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*);
// tinygltf's image loader; `user` is the scene's DecodeBudget (GltfLimits.h).
bool loadImageData(tinygltf::Image* image, int index, std::string* err, std::string* warn, int reqWidth,
                   int reqHeight, const unsigned char* bytes, int size, void* user);

// The raw document before tinygltf sees it: an object, its extensions (GltfExtensions.h), every external
// URI inside the root, every buffer view inside its buffer.
void validateDocument(const nlohmann::json& doc, const std::filesystem::path& baseDir,
                      const std::filesystem::path& root, std::vector<std::string>& warnings);
// The JSON chunk of a GLB, after checking the header and chunk lengths against the bytes there are.
std::string_view glbJson(std::string_view bytes);

}  // namespace radiant::gltf
