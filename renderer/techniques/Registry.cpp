#include "renderer/techniques/Registry.h"

#include "renderer/techniques/ambient_occlusion/AmbientOcclusion.h"
#include "renderer/techniques/direct/Direct.h"
#include "renderer/techniques/env_diffuse/EnvDiffuse.h"
#include "renderer/techniques/gbuffer/GBuffer.h"
#include "renderer/techniques/photon_gi/PhotonGi.h"
#include "renderer/techniques/reference/ReferencePass.h"
#include "renderer/techniques/shadow_maps/ShadowMaps.h"
#include "renderer/techniques/specular/Specular.h"
#include "renderer/techniques/spherical_billboards/SphericalBillboards.h"

namespace radiant {

std::vector<std::unique_ptr<Technique>> createTechniques() {
  std::vector<std::unique_ptr<Technique>> t;
  t.push_back(std::make_unique<GBufferPass>());
  t.push_back(std::make_unique<ShadowMapsPass>());
  t.push_back(std::make_unique<DirectPass>());
  t.push_back(std::make_unique<EnvDiffusePass>());
  t.push_back(std::make_unique<PhotonGiPass>());
  t.push_back(std::make_unique<SpecularPass>());
  t.push_back(std::make_unique<AmbientOcclusionPass>());
  // Media compose over every opaque contribution (beauty = beauty * T + C): after all of them.
  t.push_back(std::make_unique<SphericalBillboardsPass>());
  t.push_back(std::make_unique<ReferencePass>());
  return t;
}

}  // namespace radiant
