#pragma once
// Compressed meshes, decoded at load so everything after the loader sees plain accessors:
// - EXT_meshopt_compression: bufferViews whose bytes are meshoptimizer streams (ATTRIBUTES, TRIANGLES,
//   INDICES; filters NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL). decodeMeshopt() rewrites the file
//   (packed into one GLB first) so each such view holds its decoded bytes; fallback buffers are dropped.
// - KHR_draco_mesh_compression: primitives whose attributes and indices are one Draco bitstream.
//   decodeDraco() decodes each into new float accessors (and a u32 index accessor) in the model.
// Both check sizes against the byte budget and report problems as SceneError with a JSON pointer.
// decodeMeshopt() checks every field meshoptimizer relies on (mode, filter, byteStride, count, the
// parent view's byteLength) before any decode: Debian's meshoptimizer aborts on a failed precondition.
#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace tinygltf {
class Model;
}

namespace radiant {
class DecodeBudget;
}

namespace radiant::gltf {

bool usesMeshopt(const nlohmann::json& doc);
// `glb` must be a GLB whose data buffers are all in its BIN chunk (GltfPackage's output); returns a GLB
// with every EXT_meshopt_compression bufferView decoded in place. The decoded sizes (count x byteStride
// of every view) are charged against `budget` (--max-decode-bytes) before the first view is decoded.
std::string decodeMeshopt(std::string_view glb, DecodeBudget& budget);

bool usesDraco(const nlohmann::json& doc);
// tinygltf 2.7 refuses index accessors without a bufferView, which Draco primitives have: drop the
// primitives' "indices" (decodeDraco() sets new ones). `glb` as for decodeMeshopt().
std::string prepareDraco(std::string_view glb);
// Decodes every KHR_draco_mesh_compression primitive of the model in place.
void decodeDraco(tinygltf::Model& model, std::size_t maxBytes);

}  // namespace radiant::gltf
