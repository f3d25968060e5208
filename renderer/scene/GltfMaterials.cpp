#include "renderer/scene/GltfConverter.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "renderer/scene/GltfAccessors.h"
#include "renderer/scene/GltfExtensions.h"
#include "renderer/scene/GltfLoader.h"

namespace radiant::gltf {

TextureRef Converter::textureRef(int index, int texCoord, float scale, const std::string& ptr, bool srgb) {
  if (index < 0) return {};
  if (std::size_t(index) >= scene_.textures.size())
    throw SceneError(ptr + "/index", "texture " + std::to_string(index) + " does not exist");
  if (!textureUsable_[std::size_t(index)]) return {};  // dropped with a warning (convertTextures)
  if (texCoord < 0 || texCoord > 1)
    throw SceneError(ptr + "/texCoord", "TEXCOORD_" + std::to_string(texCoord) +
                                            " is not supported (only TEXCOORD_0 and TEXCOORD_1)");
  if (srgb) scene_.textures[std::size_t(index)].colorSpace = TextureColorSpace::SRGB;
  TextureRef r;
  r.texture = index;
  r.texCoord = texCoord;
  r.scale = scale;
  return r;
}

// A textureInfo object of an extension (tinygltf leaves these as JSON values): index, texCoord, the
// normal `scale` of a normalTextureInfo, and its KHR_texture_transform.
TextureRef Converter::textureRef(const tinygltf::Value& info, const std::string& ptr, bool srgb) {
  if (!info.IsObject() || !info.Has("index")) return {};
  if (!info.Get("index").IsNumber()) throw SceneError(ptr + "/index", "a texture index must be a number");
  const int texCoord = info.Has("texCoord") ? info.Get("texCoord").GetNumberAsInt() : 0;
  const float scale = info.Has("scale") && info.Get("scale").IsNumber() ? float(info.Get("scale").GetNumberAsDouble()) : 1.f;
  TextureRef r = textureRef(info.Get("index").GetNumberAsInt(), texCoord, scale, ptr, srgb);
  if (r.valid() && info.Has("extensions") && info.Get("extensions").Has("KHR_texture_transform"))
    gltf::applyTextureTransform(&info.Get("extensions").Get("KHR_texture_transform"), r, ptr);
  return r;
}

void Converter::convertTextures() {
  for (std::size_t i = 0; i < m_.textures.size(); ++i) {
    tinygltf::Texture t = m_.textures[i];
    const std::string ptr = pointer("/textures", i);
    // EXT_texture_webp: its image wins over `source`, which is then an optional PNG/JPEG fallback
    // for viewers without WebP (the extension's README, "glTF Schema Updates").
    if (const auto e = t.extensions.find("EXT_texture_webp"); e != t.extensions.end()) {
      const tinygltf::Value& src = e->second.Get("source");
      if (!src.IsInt() && !src.IsNumber())
        throw SceneError(ptr + "/extensions/EXT_texture_webp/source", "texture " + std::to_string(i) +
                                                                        ": EXT_texture_webp needs an image index");
      t.source = src.GetNumberAsInt();
      if (t.source < 0)
        throw SceneError(ptr + "/extensions/EXT_texture_webp/source",
                         "texture " + std::to_string(i) + ": EXT_texture_webp names image " + std::to_string(t.source));
    }
    if (t.source < 0) {
      // Valid glTF (source is optional; an extension such as KHR_texture_basisu may name the only
      // image): the materials render without this texture, and the frame says so.
      scene_.warnings.push_back(ptr + ": texture " + std::to_string(i) +
                                " has no image this renderer can use: materials render without it");
      scene_.textures.emplace_back();
      textureUsable_.push_back(false);
      continue;
    }
    if (std::size_t(t.source) >= m_.images.size())
      throw SceneError(ptr + "/source", "texture " + std::to_string(i) + " names image " + std::to_string(t.source) +
                                            ", which does not exist");
    const auto& img = m_.images[std::size_t(t.source)];
    const std::string iptr = pointer("/images", std::size_t(t.source));
    if (img.image.empty() || img.width <= 0 || img.height <= 0 || img.component != 4)
      throw SceneError(iptr, "image " + std::to_string(t.source) +
                                 (img.uri.empty() ? std::string() : " (\"" + img.uri + "\")") +
                                 " could not be loaded or decoded");
    Texture out;
    out.name = !t.name.empty() ? t.name : img.name;
    out.width = img.width;
    out.height = img.height;
    const std::size_t texels = std::size_t(img.width) * std::size_t(img.height) * 4;
    out.rgba8.resize(texels);
    if (img.bits == 16 && img.image.size() >= texels * 2) {
      for (std::size_t k = 0; k < texels; ++k) {
        std::uint16_t v; std::memcpy(&v, img.image.data() + 2 * k, 2);
        out.rgba8[k] = std::uint8_t((std::uint32_t(v) * 255u + 32767u) / 65535u);
      }
    } else if (img.bits == 8 && img.image.size() >= texels) {
      std::memcpy(out.rgba8.data(), img.image.data(), texels);
    } else {
      throw SceneError(iptr, "image " + std::to_string(t.source) + " has an unsupported bit depth " +
                                 std::to_string(img.bits));
    }
    if (t.sampler >= 0) {
      if (std::size_t(t.sampler) >= m_.samplers.size())
        throw SceneError(ptr + "/sampler", "sampler " + std::to_string(t.sampler) + " does not exist");
      const auto& s = m_.samplers[std::size_t(t.sampler)];
      out.wrapS = s.wrapS;
      out.wrapT = s.wrapT;
      if (s.minFilter >= 0) out.minFilter = s.minFilter;
      if (s.magFilter >= 0) out.magFilter = s.magFilter;
    }
    scene_.textures.push_back(std::move(out));
    textureUsable_.push_back(true);
  }
}

void Converter::convertMaterials() {
  for (std::size_t i = 0; i < m_.materials.size(); ++i) {
    const auto& g = m_.materials[i];
    const std::string ptr = pointer("/materials", i);
    const auto& pbr = g.pbrMetallicRoughness;
    Material mat;
    mat.name = g.name;
    if (pbr.baseColorFactor.size() == 4)
      mat.baseColorFactor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                      pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
    mat.metallicFactor = float(pbr.metallicFactor);
    mat.roughnessFactor = float(pbr.roughnessFactor);
    if (g.emissiveFactor.size() == 3)
      mat.emissiveFactor = glm::vec3(g.emissiveFactor[0], g.emissiveFactor[1], g.emissiveFactor[2]);
    const std::string pp = ptr + "/pbrMetallicRoughness";
    mat.baseColorTexture = textureRef(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, 1.f,
                                      pp + "/baseColorTexture", true);
    mat.metallicRoughnessTexture =
        textureRef(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord, 1.f,
                   pp + "/metallicRoughnessTexture", false);
    mat.normalTexture = textureRef(g.normalTexture.index, g.normalTexture.texCoord,
                                   float(g.normalTexture.scale), ptr + "/normalTexture", false);
    mat.occlusionTexture = textureRef(g.occlusionTexture.index, g.occlusionTexture.texCoord,
                                      float(g.occlusionTexture.strength), ptr + "/occlusionTexture",
                                      false);
    mat.emissiveTexture = textureRef(g.emissiveTexture.index, g.emissiveTexture.texCoord, 1.f,
                                     ptr + "/emissiveTexture", true);
    // KHR_texture_transform per texture slot, KHR_materials_unlit (GltfExtensions.h).
    auto transform = [&](const tinygltf::ExtensionMap& ext, TextureRef& ref, const std::string& at) {
      if (ref.valid()) gltf::applyTextureTransform(extension(ext, "KHR_texture_transform"), ref, at);
    };
    transform(pbr.baseColorTexture.extensions, mat.baseColorTexture, pp + "/baseColorTexture");
    transform(pbr.metallicRoughnessTexture.extensions, mat.metallicRoughnessTexture, pp + "/metallicRoughnessTexture");
    transform(g.normalTexture.extensions, mat.normalTexture, ptr + "/normalTexture");
    transform(g.occlusionTexture.extensions, mat.occlusionTexture, ptr + "/occlusionTexture");
    transform(g.emissiveTexture.extensions, mat.emissiveTexture, ptr + "/emissiveTexture");
    mat.unlit = extension(g.extensions, "KHR_materials_unlit") != nullptr;
    mat.doubleSided = g.doubleSided;
    if (g.alphaMode == "MASK") mat.alphaMode = AlphaMode::Mask;
    else if (g.alphaMode == "BLEND") mat.alphaMode = AlphaMode::Blend;
    else if (g.alphaMode == "OPAQUE" || g.alphaMode.empty()) mat.alphaMode = AlphaMode::Opaque;
    else throw SceneError(ptr + "/alphaMode", "unknown alphaMode \"" + g.alphaMode + "\"");
    mat.alphaCutoff = float(g.alphaCutoff);
    const std::string ep = ptr + "/extensions/";
    if (const auto* e = extension(g.extensions, "KHR_materials_transmission")) {
      mat.transmissionFactor = number(*e, "transmissionFactor", 0.f);
      if (e->Has("transmissionTexture"))
        mat.transmissionTexture = textureRef(e->Get("transmissionTexture"),
                                             ep + "KHR_materials_transmission/transmissionTexture");
    }
    if (const auto* e = extension(g.extensions, "KHR_materials_ior")) mat.ior = number(*e, "ior", 1.5f);
    if (const auto* e = extension(g.extensions, "KHR_materials_emissive_strength"))
      mat.emissiveStrength = number(*e, "emissiveStrength", 1.f);
    // The layered extensions: factors and textures (the channels each texture contributes are in
    // shaders/common/material_decode.glsl). sheenColorTexture and specularColorTexture hold sRGB colour (the extensions'
    // specs); the others are data.
    auto layerTexture = [&](const tinygltf::Value& e, const char* ext, const char* key, bool srgb) {
      return e.Has(key) ? textureRef(e.Get(key), ep + ext + "/" + key, srgb) : TextureRef{};
    };
    auto color3 = [](const tinygltf::Value& e, const char* key, glm::vec3 fallback) {
      if (!e.Has(key)) return fallback;
      const tinygltf::Value& a = e.Get(key);
      if (!a.IsArray() || a.ArrayLen() != 3) return fallback;
      glm::vec3 c;
      for (int k = 0; k < 3; ++k) c[k] = a.Get(k).IsNumber() ? float(a.Get(k).GetNumberAsDouble()) : fallback[k];
      return c;
    };
    if (const auto* e = extension(g.extensions, "KHR_materials_clearcoat")) {
      const char* x = "KHR_materials_clearcoat";
      mat.clearcoatFactor = std::clamp(number(*e, "clearcoatFactor", 0.f), 0.f, 1.f);
      mat.clearcoatRoughnessFactor = std::clamp(number(*e, "clearcoatRoughnessFactor", 0.f), 0.f, 1.f);
      mat.clearcoatTexture = layerTexture(*e, x, "clearcoatTexture", false);
      mat.clearcoatRoughnessTexture = layerTexture(*e, x, "clearcoatRoughnessTexture", false);
      mat.clearcoatNormalTexture = layerTexture(*e, x, "clearcoatNormalTexture", false);
    }
    if (const auto* e = extension(g.extensions, "KHR_materials_sheen")) {
      const char* x = "KHR_materials_sheen";
      mat.sheenColorFactor = glm::clamp(color3(*e, "sheenColorFactor", glm::vec3(0.f)), 0.f, 1.f);
      mat.sheenRoughnessFactor = std::clamp(number(*e, "sheenRoughnessFactor", 0.f), 0.f, 1.f);
      mat.sheenColorTexture = layerTexture(*e, x, "sheenColorTexture", true);
      mat.sheenRoughnessTexture = layerTexture(*e, x, "sheenRoughnessTexture", false);
    }
    if (const auto* e = extension(g.extensions, "KHR_materials_specular")) {
      const char* x = "KHR_materials_specular";
      mat.specularFactor = std::clamp(number(*e, "specularFactor", 1.f), 0.f, 1.f);
      mat.specularColorFactor = glm::max(color3(*e, "specularColorFactor", glm::vec3(1.f)), 0.f);
      mat.specularTexture = layerTexture(*e, x, "specularTexture", false);
      mat.specularColorTexture = layerTexture(*e, x, "specularColorTexture", true);
    }
    if (const auto* e = extension(g.extensions, "KHR_materials_volume")) convertVolume(*e, ep + "KHR_materials_volume", mat);
    scene_.materials.push_back(std::move(mat));
  }
}

// KHR_materials_volume. Values outside the spec's ranges (thicknessFactor >= 0, attenuationDistance
// in (0, inf), attenuationColor in [0, 1]) are repaired with a warning naming the field, as a renderer
// draws a valid-looking file rather than refuse it: a negative thickness is a thin wall (0), a
// non-positive or non-numeric distance means no absorption, a colour is clamped to [0, 1].
void Converter::convertVolume(const tinygltf::Value& e, const std::string& at, Material& mat) {
  auto warn = [&](const char* key, const std::string& what) {
    scene_.warnings.push_back(at + "/" + key + ": " + what);
  };
  auto value = [&](const char* key, double fallback, bool& ok) {
    ok = true;
    if (!e.Has(key)) return fallback;
    const tinygltf::Value& v = e.Get(key);
    ok = v.IsNumber() && std::isfinite(v.GetNumberAsDouble());
    return ok ? v.GetNumberAsDouble() : fallback;
  };
  bool ok = true;
  const double thickness = value("thicknessFactor", 0.0, ok);
  if (!ok || thickness < 0.0) warn("thicknessFactor", "must be a number >= 0: the surface is a thin wall (0)");
  else mat.thicknessFactor = float(std::min(thickness, double(std::numeric_limits<float>::max())));
  const double distance = value("attenuationDistance", std::numeric_limits<double>::infinity(), ok);
  if (!ok || !(distance > 0.0)) warn("attenuationDistance", "must be a number > 0: the medium does not absorb");
  // Above FLT_MAX: infinite, no absorption. Below FLT_MIN a float is subnormal, which the ray tracer's
  // threads read as 0 (Embree's recommended flush-to-zero / denormals-are-zero mode): FLT_MIN instead,
  // as opaque as the value asked for.
  else if (distance > double(std::numeric_limits<float>::max()))
    mat.attenuationDistance = std::numeric_limits<float>::infinity();  // a cast would be undefined
  else mat.attenuationDistance = float(std::max(distance, double(std::numeric_limits<float>::min())));
  if (e.Has("attenuationColor")) {
    const tinygltf::Value& a = e.Get("attenuationColor");
    bool valid = a.IsArray() && a.ArrayLen() == 3;
    glm::vec3 c(1.f);
    for (int k = 0; valid && k < 3; ++k) {
      valid = a.Get(k).IsNumber() && std::isfinite(a.Get(k).GetNumberAsDouble());
      if (valid) c[k] = float(a.Get(k).GetNumberAsDouble());
    }
    if (!valid) {
      warn("attenuationColor", "must be three numbers in [0, 1]: white (no absorption) used");
    } else {
      if (glm::any(glm::lessThan(c, glm::vec3(0.f))) || glm::any(glm::greaterThan(c, glm::vec3(1.f))))
        warn("attenuationColor", "components outside [0, 1] clamped");
      mat.attenuationColor = glm::clamp(c, 0.f, 1.f);
    }
  }
  if (e.Has("thicknessTexture")) mat.thicknessTexture = textureRef(e.Get("thicknessTexture"), at + "/thicknessTexture");
}

}  // namespace radiant::gltf
