#include "renderer/scene/GltfExtensions.h"

#include <algorithm>
#include <cmath>

#include <tiny_gltf.h>  // shared library: no TINYGLTF_IMPLEMENTATION

#include "renderer/scene/GltfLoader.h"

namespace radiant::gltf {

const std::vector<std::string>& supportedExtensions() {
  static const std::vector<std::string> k{
      "KHR_lights_punctual",
      "KHR_materials_transmission",
      "KHR_materials_ior",
      "KHR_materials_emissive_strength",
      "KHR_materials_clearcoat",  // factors and textures (coat normal map included)
      "KHR_materials_sheen",      // factors and textures
      "KHR_materials_specular",   // factors and textures
      "KHR_materials_volume",     // Beer-Lambert absorption over the traced path (thickness: see Scene.h)
      "KHR_mesh_quantization",  // any component type is read and normalised
      "KHR_texture_transform",
      "EXT_texture_webp",       // decoded with libwebp (GltfFiles.cpp); its image wins over `source`
      "KHR_materials_unlit",
      "KHR_draco_mesh_compression",  // decoded at load (GltfCompression.cpp)
      "EXT_meshopt_compression",     // decoded at load (GltfCompression.cpp)
      "RADIANT_particle_system",     // participating media, api/schema/media.json (GltfConverter.cpp)
  };
  return k;
}

bool isSupportedExtension(const std::string& name) {
  const auto& k = supportedExtensions();
  return std::find(k.begin(), k.end(), name) != k.end();
}

namespace {
// How to get a file with an unsupported required extension rendered.
std::string conversionHint(const std::string& name) {
  if (name == "KHR_texture_basisu" || name == "MSFT_texture_dds")
    return ": its textures are in a format this server cannot decode (no Debian package decodes "
           "KTX2/Basis Universal); re-encode them as PNG or JPEG (for example decode each .ktx2 with "
           "KTX-Software's `ktx extract`, point the images at the PNGs) and remove " + name +
           " from extensionsRequired";
  if (name == "KHR_materials_pbrSpecularGlossiness")
    return ": convert the materials to metallic-roughness (for example with glTF-Transform's "
           "`metalrough` command)";
  return ": it cannot be rendered correctly without it (supported: " + [] {
    std::string s;
    for (const auto& e : supportedExtensions()) s += (s.empty() ? "" : ", ") + e;
    return s;
  }() + ")";
}
}  // namespace

void checkExtensions(const nlohmann::json& doc, std::vector<std::string>& warnings) {
  std::vector<std::string> required;
  if (const auto it = doc.find("extensionsRequired"); it != doc.end() && it->is_array()) {
    for (std::size_t i = 0; i < it->size(); ++i) {
      const auto& e = (*it)[i];
      const std::string name = e.is_string() ? e.get<std::string>() : e.dump();
      if (!isSupportedExtension(name))
        throw SceneError("/extensionsRequired/" + std::to_string(i),
                         "unsupported required extension " + name + conversionHint(name));
      required.push_back(name);
    }
  }
  if (const auto it = doc.find("extensionsUsed"); it != doc.end() && it->is_array()) {
    for (const auto& e : *it) {
      if (!e.is_string()) continue;
      const std::string name = e.get<std::string>();
      if (!isSupportedExtension(name))
        warnings.push_back("extension " + name + " is used but not supported: ignored, the scene renders as if it "
                           "were absent");
    }
  }
}

void textureTransformRows(glm::vec2 offset, float rotation, glm::vec2 scale, glm::vec3& row0, glm::vec3& row1) {
  // KHR_texture_transform README, "Overview": matrix = T * R * S with
  // R = mat3(cos, sin, 0, -sin, cos, 0, 0, 0, 1) (GLSL, column major), so
  // u' = sx cos u - sy sin v + ox,  v' = sx sin u + sy cos v + oy.
  const float c = std::cos(rotation), s = std::sin(rotation);
  row0 = {scale.x * c, -scale.y * s, offset.x};
  row1 = {scale.x * s, scale.y * c, offset.y};
}

void applyTextureTransform(const tinygltf::Value* e, TextureRef& ref, const std::string& ptr) {
  if (!e || !e->IsObject()) return;
  const std::string p = ptr + "/extensions/KHR_texture_transform";
  auto pair = [&](const char* key, glm::vec2 fallback) {
    if (!e->Has(key)) return fallback;
    const tinygltf::Value& a = e->Get(key);
    if (!a.IsArray() || a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber())
      throw SceneError(p + "/" + key, std::string(key) + " must be an array of two numbers");
    const glm::vec2 v(float(a.Get(0).GetNumberAsDouble()), float(a.Get(1).GetNumberAsDouble()));
    if (!std::isfinite(v.x) || !std::isfinite(v.y)) throw SceneError(p + "/" + key, std::string(key) + " must be finite");
    return v;
  };
  const glm::vec2 offset = pair("offset", glm::vec2(0.f)), scale = pair("scale", glm::vec2(1.f));
  float rotation = 0.f;
  if (e->Has("rotation")) {
    if (!e->Get("rotation").IsNumber() || !std::isfinite(e->Get("rotation").GetNumberAsDouble()))
      throw SceneError(p + "/rotation", "rotation must be a finite number (radians)");
    rotation = float(e->Get("rotation").GetNumberAsDouble());
  }
  textureTransformRows(offset, rotation, scale, ref.uvRow0, ref.uvRow1);
  if (e->Has("texCoord")) {
    const int t = e->Get("texCoord").IsNumber() ? e->Get("texCoord").GetNumberAsInt() : -1;
    if (t < 0 || t > 1)
      throw SceneError(p + "/texCoord", "TEXCOORD_" + std::to_string(t) + " is not supported (only TEXCOORD_0 and TEXCOORD_1)");
    ref.texCoord = t;
  }
}

}  // namespace radiant::gltf
