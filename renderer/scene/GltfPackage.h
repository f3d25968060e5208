#pragma once
// Packs a glTF asset and the files it references into one self-contained GLB, so that what is hashed,
// uploaded and cached is every byte the scene is made of. The client packs before it uploads
// (`radiant render`, `radiant sweep`); radiantd packs files under its --asset-root (scene.asset).
//
// Rules for the URIs of buffers and images (the same as the loader's, checked before any file is read):
// - data: URIs are decoded (buffers) or kept (images); every other scheme (http:, file:, ...) is refused;
// - a path must be relative, must not contain a ".." segment, and must resolve (through symlinks)
//   inside `root`, which defaults to the folder of the .gltf;
// - percent-encoding is decoded (RFC 3986), as the glTF spec asks.
// Every external buffer and data-URI buffer is concatenated into the GLB's BIN chunk (each start
// 16-byte aligned, so any accessor alignment survives); bufferViews (and the bufferView fields of
// EXT_meshopt_compression) are rebased onto it. External images become bufferView images with a
// mimeType from their magic bytes. Buffers without a uri and without GLB data (EXT_meshopt_compression
// fallback buffers) are kept as they are.
//
// No GL, no tinygltf: JSON and file I/O only, so the client can link it.
#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace radiant {

// A file that cannot be packed: `pointer` is the JSON pointer of the offending field ("" = the file).
struct PackError : std::runtime_error {
  // What went wrong with the file named (pointer empty): it is not there, it is there but not a regular
  // file (a directory, FIFO or device), or it is over the size limit; Invalid: its contents or a URI in it.
  enum class Kind { Invalid, Missing, NotRegular, TooLarge };
  PackError(std::string pointer_, const std::string& message, Kind kind_ = Kind::Invalid)
      : std::runtime_error(message), pointer(std::move(pointer_)), kind(kind_) {}
  std::string pointer;
  Kind kind;
};

struct PackResult {
  std::string bytes;            // a GLB, or the input unchanged when it referenced no external file
  std::size_t externalFiles = 0;  // how many files were pulled in
  bool packed = false;           // true when `bytes` is a newly written GLB
};

// True when the (canonical) path p lies inside the (canonical) directory root.
bool pathIsInside(const std::filesystem::path& root, const std::filesystem::path& p);

// True for a URI naming a file (not data:), after the checks above; throws PackError otherwise.
// Returns the canonical path of the file.
std::filesystem::path resolveRelativeUri(const std::string& uri, const std::string& pointer,
                                         const std::filesystem::path& baseDir, const std::filesystem::path& root);

// Packs `bytes` (.gltf JSON or GLB) whose URIs are relative to `baseDir`, reading only inside `root`.
// At most `maxBytes` are read from external files in total. `force`: write a GLB with every data
// buffer in its BIN chunk even when nothing external is referenced (the meshopt decoder needs that).
PackResult packGltf(std::string_view bytes, const std::filesystem::path& baseDir,
                    const std::filesystem::path& root, std::size_t maxBytes = std::size_t(1) << 31,
                    bool force = false);

// Reads `file` (.gltf or .glb) and packs it with root = `root` (empty: the file's folder). The file
// itself must lie inside the root.
PackResult packGltfFile(const std::filesystem::path& file, const std::filesystem::path& root = {},
                        std::size_t maxBytes = std::size_t(1) << 31);

}  // namespace radiant
