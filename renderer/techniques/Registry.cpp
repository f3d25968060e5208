#include "renderer/techniques/Registry.h"

#include "renderer/techniques/ambient_occlusion/AmbientOcclusion.h"
#include "renderer/techniques/caustics/Caustics.h"
#include "renderer/techniques/depth_impostors/DepthImpostors.h"
#include "renderer/techniques/direct/Direct.h"
#include "renderer/techniques/env_diffuse/EnvDiffuse.h"
#include "renderer/techniques/gbuffer/GBuffer.h"
#include "renderer/techniques/illumination_network/IlluminationNetwork.h"
#include "renderer/techniques/light_volumes/LightVolumes.h"
#include "renderer/techniques/photon_gi/PhotonGi.h"
#include "renderer/techniques/reference/ReferencePass.h"
#include "renderer/techniques/shadow_maps/ShadowMaps.h"
#include "renderer/techniques/specular/Specular.h"
#include "renderer/techniques/transparency/Transparency.h"
#include "renderer/techniques/spherical_billboards/SphericalBillboards.h"

namespace radiant {

std::vector<std::unique_ptr<Technique>> createTechniques() {
  std::vector<std::unique_ptr<Technique>> t;
  t.push_back(std::make_unique<GBufferPass>());
  t.push_back(std::make_unique<ShadowMapsPass>());
  t.push_back(std::make_unique<DirectPass>());
  // specular before caustics (which reads its distance maps), and caustics before photon_gi: the
  // first planned claimant of a light-path class owns it, and caustics owns LS+DE when it runs.
  t.push_back(std::make_unique<SpecularPass>());
  t.push_back(std::make_unique<CausticsPass>());
  t.push_back(std::make_unique<EnvDiffusePass>());
  t.push_back(std::make_unique<PhotonGiPass>());
  // Claims LS+DE and LG+DE: caustics, which also claims LS+DE, goes before it (so that it owns it by
  // default), and the planner gives both classes to light_volumes when the request names it.
  t.push_back(std::make_unique<LightVolumesPass>());
  t.push_back(std::make_unique<AmbientOcclusionPass>());
  t.push_back(std::make_unique<TransparencyPass>());  // composites alphaMode BLEND surfaces over the lit frame
  // Media compose over every opaque and blended contribution (beauty = beauty * T + C): after all of them.
  t.push_back(std::make_unique<SphericalBillboardsPass>());
  // The other media techniques after it: spherical_billboards, first, owns the media AOV by default;
  // the one a request names owns it instead (TechniqueInfo::exclusive, claimsWhenNamed).
  t.push_back(std::make_unique<DepthImpostorsPass>());
  t.push_back(std::make_unique<IlluminationNetworkPass>());  // multiple scattering: owns media when named
  t.push_back(std::make_unique<ReferencePass>());
  return t;
}

}  // namespace radiant
