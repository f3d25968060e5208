// libFuzzer: KHR_draco_mesh_compression streams as the glTF loader decodes them (issue 30, "Validate
// before decoding"; renderer/scene/GltfCompression.cpp decodeDraco). The input is the Draco bitstream
// of one primitive whose POSITION, NORMAL and TEXCOORD_0 name the stream's attributes 0, 1 and 2, as
// the seeds (tests/data/crashers/draco, a cube encoded sequentially and by edgebreaker) carry them.
// Any input decodes or throws SceneError; a crash, a sanitizer report or another exception is a bug.
#include <cstdint>
#include <string_view>

#include <tiny_gltf.h>  // shared library: no TINYGLTF_IMPLEMENTATION

#include "renderer/scene/GltfCompression.h"
#include "renderer/scene/GltfLoader.h"

namespace {

tinygltf::Accessor accessor(int type) {
  tinygltf::Accessor a;
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.type = type;
  a.count = 3;
  return a;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  tinygltf::Model model;
  tinygltf::Buffer buffer;
  buffer.data.assign(data, data + size);
  model.buffers.push_back(std::move(buffer));
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteLength = size;
  model.bufferViews.push_back(view);
  model.accessors = {accessor(TINYGLTF_TYPE_VEC3), accessor(TINYGLTF_TYPE_VEC3), accessor(TINYGLTF_TYPE_VEC2)};
  tinygltf::Primitive prim;
  prim.attributes = {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}};
  tinygltf::Value::Object attributes{{"POSITION", tinygltf::Value(0)}, {"NORMAL", tinygltf::Value(1)},
                                     {"TEXCOORD_0", tinygltf::Value(2)}};
  tinygltf::Value::Object extension{{"bufferView", tinygltf::Value(0)}, {"attributes", tinygltf::Value(attributes)}};
  prim.extensions["KHR_draco_mesh_compression"] = tinygltf::Value(extension);
  tinygltf::Mesh mesh;
  mesh.primitives.push_back(prim);
  model.meshes.push_back(mesh);
  try {
    radiant::gltf::decodeDraco(model, 64u << 20);
  } catch (const radiant::SceneError&) {
  }
  // Decoded faces may index beyond the decoded points (a mutated connectivity stream does): the loader
  // checks every primitive's indices against its vertices next (GltfMeshes.cpp, 422 at /indices).
  return 0;
}
