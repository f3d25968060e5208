#pragma once
// Multiple specular reflections and refractions with layered distance maps (thesis ch. 5).
//
// prepare(): finds the specular objects (meshes whose material is Material::isSpecular()), declares
// their layered distance maps (cube-map arrays of material, geometry and filtered distance, `layers`
// cubes per object; layout in shaders/specular/ldm.glsl) and looks the maps up
// in the derived-data cache (scene digest, GPU scene, cube_resolution, layers, and in execute() the
// photon set of photon_gi's published grid, renderer/shading/PhotonGrid.h).
// execute(): on a cache miss renders every layer of every face of every object, adds photon_gi's
// indirect light to the environment layers' diffuse texels when photon_gi is planned
// (shaders/specular/map_indirect.comp) and reduces each layer to its min-max distances; then rasterises the specular objects, traces their reflected/refracted
// rays in the maps (shaders/specular/specular.frag) into the `specular` AOV, and adds it to beauty.
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/frame/Technique.h"
#include "renderer/shading/SpecularObjects.h"

namespace radiant {

struct FrameView;
struct Bounds;

// The diameter in raster pixels of the sphere bounding `bounds` as the frame's camera sees it (0 when
// it lies behind the camera, infinite when the camera is inside it).
double projectedDiameterPixels(const FrameView& view, const Bounds& bounds);
// The layered distance maps' face resolution for the largest specular object's projected diameter:
// texelsPerPixel times it, rounded up to a power of two, within [16, maxResolution].
int mapResolution(double objectPixels, double texelsPerPixel, int maxResolution);
// The maps' face resolution a frame runs at (before the memory bound's halving, SpecularPass::kMaxBytes):
// a cube_resolution the request gives (without map_texels_per_pixel) as given; cube_resolution when
// caustics owns L S+ D E (it traces its photons through these maps: keptForCaustics); else
// mapResolution of the largest specular object's projected diameter. One place for the pass and for
// the budget chooser, which charges specular's cost model this resolution (api::SceneCounts).
struct MapResolution {
  int texels = 0;
  double largestObjectPixels = 0.0;
  bool keptForCaustics = false;
  bool adaptive = true;  // false: a cube_resolution the request gave, run as given
};
MapResolution chooseMapResolution(const Scene& scene, const FrameView& view, const Params& params, bool causticsOwnsLSDE);

class SpecularPass final : public Technique {
public:
  const TechniqueInfo& info() const override;
  Requirements requirements(const Scene&, const api::RenderRequest&) const override;
  void addCostCounts(const Scene& scene, api::SceneCounts& counts) const override;
  // The maps' memory limit where the view cannot change the answer (fitMaps): a cube_resolution the
  // request gives above it, or specular objects that do not fit even at 16 texels, are 422s before the
  // job is queued (Renderer::check).
  void validate(const Scene& scene, const FrameView& view, const Params& params) const override;
  void prepare(const Scene&, const Params&, FrameResources&) override;
  void execute(PassContext&) override;

  // One specular object's map data (std430 in shaders/specular/ldm.glsl, binding 3).
  struct GpuObject {
    glm::vec4 referenceRadius;  // xyz reference point, w bounding radius
    glm::vec4 extent;           // x distance from the reference point to the farthest scene-bounds corner,
                                // yzw the extinction sigma_t of its KHR_materials_volume medium (0: none)
  };
  static_assert(sizeof(GpuObject) == 32, "std430 SpecularObject must be 32 bytes");

  // The specular objects and their reference points: renderer/shading/SpecularObjects.h (shared with
  // caustics). The caustics pass reads the maps (the frame resources specular_ldm_material / _geometry
  // / _distance / _albedo, specular_objects, specular_minmax) through the internal output "specular_maps".
  static glm::vec3 referencePoint(const MeshInstance& mesh) { return specularReferencePoint(mesh); }
  static std::vector<std::size_t> specularMeshes(const Scene& scene) { return radiant::specularMeshes(scene); }

  // The maps' memory (every object, layer and face of the four cube-map arrays: RGBA16F material,
  // RGBA32F geometry, R32F distance, RGBA8 albedo) is bounded whatever the scene: 36 glass and metal spheres
  // at 256 texels held 1.27 GiB. A resolution the pass chooses (from the objects' size on screen, or
  // cube_resolution kept for caustics) is halved until the maps fit, with a warning; one the request
  // gives (cube_resolution without map_texels_per_pixel) is a 422 above it, as is a scene whose
  // specular objects do not fit even at 16 texels.
  static constexpr double kMaxBytes = 512.0 * 1024.0 * 1024.0;
  static constexpr double kBytesPerTexel = 8.0 + 16.0 + 4.0 + 4.0;
  static double mapBytes(int objects, int layers, int resolution) {
    return double(std::max(1, objects * layers)) * 6.0 * double(resolution) * resolution * kBytesPerTexel;
  }
  // The resolution the maps are drawn at under kMaxBytes: `resolution` when they fit; else, when the pass
  // chose it (`adaptive`), halved (not below 16) until they fit, with the warning saying so. A 422 when
  // the request gave it, or when they do not fit even at 16 texels: neither depends on the view, so
  // validate() raises them before the queue and prepare() again for the frame's own parameters.
  struct FittedMaps {
    int resolution = 0;
    std::string warning;  // "" when the maps fit as chosen
  };
  static FittedMaps fitMaps(int objects, int layers, int resolution, bool adaptive, bool keptForCaustics);

private:
  struct Object {
    std::size_t mesh;
    GpuObject gpu;
    // Some of its texels may be stored as lit diffuse surfaces in its own maps (layers 0 and 1):
    // specular/ldm.glsl specularInMaps() can fail for its material (a transmission or
    // metallic-roughness texture, or factors below one half), so photon_gi's gather runs there too.
    bool partlyDiffuse = false;
  };
  std::vector<Object> objects_;
  std::vector<int> objectOfMesh_;  // specular object index per mesh, -1 for diffuse meshes
  int maxDepth_ = 4, linearSteps_ = 32, secantSteps_ = 4, resolution_ = 256, layers_ = 3;
  double largestObjectPixels_ = 0.0;  // the largest specular object's projected diameter (raster pixels)
  bool causticsKeepMaps_ = false;
  int indirectBlock_ = 8;             // map_indirect_block     // caustics traces its photons through the maps: cube_resolution
  bool minmax_ = true;
  bool mapsIbl_ = false;  // the maps carry the sky's glossy lobe (direct owns L(sky)GE and there is a sky)
  std::string warning_;   // for stats.warnings when kMaxBytes lowered the maps' resolution
  std::string digest_;  // the maps' key without the photon set (execute() appends it; FrameResources::refill)
};

}  // namespace radiant
