#pragma once
// Caustic triangles (thesis ch. 6, Algorithm 4): light from point, spot and directional lights that
// reaches a diffuse or glossy surface through mirrors and refractors (the light-path class LS+DE).
//
// prepare(): finds the generators (the specular pass's objects: transmissive, or metallic with
// roughness below Material::kSpecularRoughness; their layered distance maps are specular's, read
// through its internal output "specular_maps", never rebuilt) and the (light, generator) pairs, and
// declares the photon hit image (P x P, three RGBA32F targets), the vertex image and the caustic cube
// array (C x C x 6 per generator, RGBA32F, additive).
// execute(), per pair: (1) rasterise the generator from the light and trace each pixel's photon
// through the distance maps to its first non-specular hit (shaders/caustics/photon.frag); (2) vertex
// areas and irradiance I = dPhi / dA (area.comp); (3) 2 P^2 caustic triangles, or the splat
// baseline's disks, added into the generator's cube (triangles.geom / splat.geom); then (4) one camera
// pass over the G-buffer adds f_r E where the distance map says the receiver is visible from c_G
// (camera.frag), into the `caustics` AOV and beauty; and (5) the caustics seen in mirrors and through
// glass (LS+DS+E): the specular objects' rays traced as the specular pass does, the cubes looked up at
// their non-specular hits (secondary.frag), into beauty only.
//
// Generators stay opaque in the shadow maps: the direct pass leaves them black shadows and this pass
// brings the transmitted light back, so no light is counted twice.
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/frame/Technique.h"

namespace radiant {

class CausticsPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

  // The light camera of one (light, generator) pair (thesis 6.1.1: "place camera in light source and
  // orient to caster"): a square perspective frustum from the light holding the corners of the
  // generator's bounds, or, for a directional light, an orthographic one fitted to its bounding
  // sphere. false when the light is inside the bounds or so close that the frustum would be wider
  // than 170 degrees.
  struct LightCamera {
    glm::mat4 viewProj{1.f};
    bool orthographic = false;
    float halfExtent = 0.f;  // tan(half angle) or half the side of the square
  };
  static bool lightCamera(const Light& light, const Bounds& bounds, LightCamera& out);

  // Needed when a punctual light sees a generator and the camera can see a receiver: "" or the reason
  // to skip (also used by the tests).
  static std::string skipReason(const Scene& scene);

  // The caustic cubes' memory (RGBA32F with its mip chain, six faces per generator: 8 MiB a generator
  // at the default 256 texels, 128 MiB at 1024) is bounded whatever the scene. A cube_resolution the
  // request leaves to the default is halved until the cubes fit, with a warning; one it gives is a 422
  // above the limit, as is a scene whose generators do not fit even at 16 texels.
  static constexpr double kMaxBytes = 512.0 * 1024.0 * 1024.0;
  static double cubeBytes(int generators, int resolution) {
    double texels = 0.0;
    for (int r = resolution; r > 0; r >>= 1) texels += double(r) * r;  // the mip chain down to 1 x 1
    return double(std::max(1, generators)) * 6.0 * texels * 16.0;
  }
  // The cubes' resolution under kMaxBytes: `resolution` when they fit; else, when the request left it to
  // the default, halved (not below 16) until they fit, with the warning saying so. A 422 when the request
  // gave it, or when the generators do not fit even at 16 texels: validate() raises them before the
  // queue (they depend on the scene and the parameters only), prepare() again for the frame's own.
  struct FittedCubes {
    int resolution = 0;
    std::string warning;  // "" when the cubes fit as asked
  };
  static FittedCubes fitCubes(int generators, int resolution, bool given);
  void validate(const Scene& scene, const FrameView& view, const Params& params) const override;

private:
  struct Pair {
    int light;
    int generator;
    LightCamera camera;
    bool reflectFirst = false;  // the Fresnel-reflection image of a refracting generator
  };
  enum class Method { Triangles, Splat };
  Method method_ = Method::Triangles;
  int photonResolution_ = 128, cubeResolution_ = 256, maxDepth_ = 4, linearSteps_ = 32, secantSteps_ = 4;
  int secondaryMaxDepth_ = 2;  // specular_lookup's trees
  float areaWeight_ = 1.f / 3.f, visibilityTolerance_ = 2.f, splatRadius_ = 0.02f;
  bool energyCheck_ = false, fresnelReflection_ = true, footprintFilter_ = true, specularLookup_ = true;
  std::vector<std::size_t> generators_;  // mesh index per generator (= specular object index)
  std::vector<Pair> pairs_;
  int skippedPairs_ = 0;  // lights inside (or too close to) a generator's bounds
  std::string warning_;   // for stats.warnings when kMaxBytes lowered cube_resolution
};

}  // namespace radiant
