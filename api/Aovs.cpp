#include "api/Aovs.h"

#include <algorithm>

namespace radiant::api {

const std::vector<AovInfo>& aovTable() {
  using F = AovFormat;
  using B = AovBlend;
  constexpr AovResolve Nearest = AovResolve::Nearest, Average = AovResolve::Average;
  // name, format, resource, first channel, channels, EXR names, blend, producer, requestable, ground truth,
  // resolve (Average unless given), radiance (true unless given: false for data, which PNG shows as stored).
  // Beauty is EXR's default layer (R, G, B) so viewers show it first; the others are "<aov>.<channel>".
  static const std::vector<AovInfo> table = [] {
    std::vector<AovInfo> t = {
        {0, "beauty", F::Rgba32F, "beauty", 0, 3, {"R", "G", "B"}, B::Accumulate, "", true, "beauty"},
        {0, "direct", F::Rgba32F, "direct", 0, 3, {"direct.R", "direct.G", "direct.B"}, B::Overwrite, "direct", true,
         "direct"},
        {0, "indirect_diffuse", F::Rgba32F, "indirect_diffuse", 0, 3,
         {"indirect_diffuse.R", "indirect_diffuse.G", "indirect_diffuse.B"}, B::Overwrite, "env_diffuse", true,
         "indirect"},
        // photon_gi (the lead's branch): its own image of bounces >= 2; it also adds into beauty.
        {0, "indirect", F::Rgba32F, "indirect", 0, 3, {"indirect.R", "indirect.G", "indirect.B"}, B::Overwrite,
         "photon_gi", true, "indirect"},
        // No ground truth yet: the reference renders whole path classes, the specular AOV is the light
        // seen through specular surfaces only (needs a per-pixel mask: Technique::groundTruth, #20).
        {0, "specular", F::Rgba32F, "specular", 0, 3, {"specular.R", "specular.G", "specular.B"}, B::Overwrite,
         "specular", true, ""},
        // caustics: L S+ D E from punctual lights through mirrors and refractors (caustic triangles).
        {0, "caustics", F::Rgba32F, "caustics", 0, 3, {"caustics.R", "caustics.G", "caustics.B"}, B::Overwrite,
         "caustics", true, "caustics"},
        // light_volumes: first-order light through specular and glossy scatterers (LS+DE, LG+DE) from
        // punctual lights; added to beauty.
        {0, "light_volumes", F::Rgba32F, "light_volumes", 0, 3,
         {"light_volumes.R", "light_volumes.G", "light_volumes.B"}, B::Overwrite, "light_volumes", true, ""},
        {0, "ao", F::R32F, "ao", 0, 1, {"ao.Y"}, B::Overwrite, "ambient_occlusion", true, "ao", Average, false},
        {0, "depth", F::Rgba32F, "gbuffer_position", 3, 1, {"depth.Z"}, B::Overwrite, "gbuffer", true, "", Nearest, false},
        {0, "gbuffer_position", F::Rgba32F, "gbuffer_position", 0, 3,
         {"gbuffer_position.R", "gbuffer_position.G", "gbuffer_position.B"}, B::Overwrite, "gbuffer", true, "", Nearest,
         false},
        {0, "normal", F::Rgba16F, "normal", 0, 3, {"normal.R", "normal.G", "normal.B"}, B::Overwrite, "gbuffer", true,
         "", Nearest, false},
        {0, "geometric_normal", F::Rgba16F, "geometric_normal", 0, 3,
         {"geometric_normal.R", "geometric_normal.G", "geometric_normal.B"}, B::Overwrite, "gbuffer", true, "", Nearest,
         false},
        {0, "albedo", F::Rgba16F, "albedo", 0, 3, {"albedo.R", "albedo.G", "albedo.B"}, B::Overwrite, "gbuffer", true,
         "", Average, false},
        // metallic, roughness, occlusion, transmission (KHR_materials_transmission) in R, G, B, A.
        {0, "material", F::Rgba16F, "material", 0, 4, {"material.R", "material.G", "material.B", "material.A"},
         B::Overwrite, "gbuffer", true, "", Nearest, false},
        {0, "emission", F::Rgba16F, "emission", 0, 3, {"emission.R", "emission.G", "emission.B"}, B::Overwrite,
         "gbuffer", true, ""},
        // Scored against the reference in the pass's own mode (ReferencePass::groundTruth): beauty by default.
        {0, "reference", F::Rgba32F, "reference", 0, 3, {"reference.R", "reference.G", "reference.B"}, B::Overwrite,
         "reference", true, "beauty"},
        // Participating media: RGB = the media's radiance in front of the first surface
        // (premultiplied), A = the camera ray's transmittance to it; beauty = opaque * A + RGB. Scored
        // against the volumetric reference (VolumeTracer.h), in the mode of the technique that wrote it.
        // Several media techniques produce it, exactly one per frame (light-path class "media",
        // TechniqueInfo::exclusive): spherical_billboards by default (the producer named here), the one
        // the request names in passes otherwise.
        {0, "media", F::Rgba32F, "media", 0, 3, {"media.R", "media.G", "media.B"}, B::Overwrite,
         "spherical_billboards", true, "media"},
        {0, "media_transmittance", F::Rgba32F, "media", 3, 1, {"media_transmittance.Y"}, B::Overwrite,
         "spherical_billboards", true, "media_transmittance", Average, false},
        // With "background": "transparent", the Renderer's coverage of the beauty (the fraction of a
        // pixel's samples that hit a surface): the beauty's A channel in EXR and PNG; never requested.
        {0, "alpha", F::R32F, "", 0, 1, {"A"}, B::Overwrite, "background", false, "", Average, false},
        // compare() writes it (per-pixel luminance-weighted absolute error); never requested.
        {0, "error", F::R32F, "", 0, 1, {"error.Y"}, B::Overwrite, "compare", false, "", Average, false},
    };
    for (std::size_t i = 0; i < t.size(); ++i) t[i].id = static_cast<int>(i);
    return t;
  }();
  return table;
}

const AovInfo* findAov(std::string_view name) {
  const auto& t = aovTable();
  auto it = std::find_if(t.begin(), t.end(), [&](const AovInfo& a) { return a.name == name; });
  return it == t.end() ? nullptr : &*it;
}

const char* toString(AovFormat f) {
  switch (f) {
    case AovFormat::R32F: return "R32F";
    case AovFormat::Rgba16F: return "RGBA16F";
    default: return "RGBA32F";
  }
}
const char* toString(AovBlend b) { return b == AovBlend::Accumulate ? "accumulate" : "overwrite"; }
const char* toString(AovResolve r) { return r == AovResolve::Nearest ? "nearest" : "average"; }

nlohmann::json aovTableJson() {
  nlohmann::json out = nlohmann::json::array();
  for (const AovInfo& a : aovTable())
    out.push_back({{"name", a.name},
                   {"format", toString(a.format)},
                   {"channels", a.exr},
                   {"blend", toString(a.blend)},
                   {"resolve", toString(a.resolve)},
                   {"producer", a.producer.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.producer)},
                   {"requestable", a.requestable},
                   {"ground_truth", a.groundTruth.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.groundTruth)}});
  return out;
}

}  // namespace radiant::api
