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

// Every technique, one line each. The frame graph orders the planned passes from their declarations
// (FramePlanner's executionOrder: what each reads, and its beauty_blend), and the ownership policy
// settles who supplies a light-path class; this order only breaks ties between passes the
// declarations leave unordered (it fixes the order of beauty's sums, so frames repeat bit for bit).
// A new technique goes anywhere in the list (tests FrameGraph.*: the registry reversed renders the same
// frames).
std::vector<std::unique_ptr<Technique>> createTechniques() {
  std::vector<std::unique_ptr<Technique>> t;
  t.push_back(std::make_unique<GBufferPass>());
  t.push_back(std::make_unique<ShadowMapsPass>());
  t.push_back(std::make_unique<DirectPass>());
  t.push_back(std::make_unique<SpecularPass>());
  t.push_back(std::make_unique<CausticsPass>());
  t.push_back(std::make_unique<EnvDiffusePass>());
  t.push_back(std::make_unique<PhotonGiPass>());
  t.push_back(std::make_unique<LightVolumesPass>());
  t.push_back(std::make_unique<AmbientOcclusionPass>());
  t.push_back(std::make_unique<TransparencyPass>());
  t.push_back(std::make_unique<SphericalBillboardsPass>());
  t.push_back(std::make_unique<DepthImpostorsPass>());
  t.push_back(std::make_unique<IlluminationNetworkPass>());
  t.push_back(std::make_unique<ReferencePass>());
  return t;
}

}  // namespace radiant
