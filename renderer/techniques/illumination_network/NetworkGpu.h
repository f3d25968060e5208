#pragma once
// The illumination network on the GPU (thesis §9.1): the visibility network V built by per-direction
// binning in compute shaders (count, scan, scatter, then each node's depth predecessor in its bin),
// and the iteration of eq. 9.1 in fp32 with the max-norm change of every step. Owns its buffers
// (created once per network: the technique caches an instance as derived data keyed by the medium
// and the parameters that shape it), so a warm start is the radiance it already holds.
// The CPU twin and oracle is Network.h.
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "renderer/frame/GpuTypes.h"
#include "renderer/gl/Gl.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/raytracing/Cancel.h"
#include "renderer/techniques/illumination_network/Network.h"

namespace radiant::gpu {
#include "shaders/illumination_network/shared.h"  // the network's records as the shaders read them

static_assert(sizeof(NetworkNode) == 48 && sizeof(NetworkDirection) == 48 && sizeof(NetworkLight) == 32,
              "std430 network records are whole vec4s");
}  // namespace radiant::gpu

namespace radiant::network {

class NetworkGpu {
public:
  // Allocates every buffer and uploads the nodes, directions and phase weights. maxLights bounds the
  // directional lights per frame.
  NetworkGpu(const NodeSet& nodes, const std::vector<Direction>& dirs, const std::vector<float>& weights, int window,
             int maxLights);
  int nodes() const { return N_; }
  int directions() const { return D_; }
  int window() const { return M_; }

  // Builds V on the GPU (GL issued here).
  // In stretches of directions with `cancel` checked between them (throws rt::Cancelled, leaving the
  // visibility unbuilt).
  void buildVisibility(gl::ShaderLibrary& shaders, const rt::Cancel& cancel = {});
  bool visibilityBuilt() const { return built_; }
  Visibility downloadVisibility() const;
  // Replaces the link opacities (exactLinkOpacity).
  void uploadAlpha(const std::vector<float>& alpha);

  // This frame's directional lights and their transmittance T[p * L + l] (lightTransmittance).
  void setLights(const std::vector<DirectionalLight>& lights, const std::vector<double>& transmittance);
  // I := 0 (a cold start).
  void clearRadiance();
  // `count` iterations with sky radiance `sky` (each a source pass, source.comp, and a link pass,
  // iterate.comp; linearSource as Problem::linearSource); returns ||I^{n+1} - I^n||_inf of each.
  // `cancelled` is polled every kCancelPollIterations (4) iterations: when it turns true the iteration
  // stops early (fewer residuals are returned).
  std::vector<double> iterate(gl::ShaderLibrary& shaders, int count, glm::vec3 sky, bool linearSource = false,
                              const std::function<bool()>& cancelled = {});
  // I as iterated so far, [p * D + i].
  std::vector<glm::dvec3> downloadRadiance() const;
  void uploadRadiance(const std::vector<glm::dvec3>& I);

  // Fills the splats' source (MediaParticle::sourceTau.rgb; slot s is node order[s]) with each
  // node's radiance towards the camera (camera.comp); without includeLights the directional lights'
  // single scattering is left out (the march adds it exactly).
  void cameraSources(gl::ShaderLibrary& shaders, const gl::Buffer& order, gl::Buffer& splats, bool orthographic,
                     glm::vec3 eye, glm::vec3 toCamera, bool includeLights = true, bool excludeSky = false,
                     glm::vec3 sky = glm::vec3(0.f));
  // Binds the common uniforms (N, D, M, the bounding sphere) and the lights (binding 12) for a
  // program of the final render.
  void bindForRender(const gl::Program& p) const;
  // T0[p * D + i]: the unscattered sky's transmittance along each link chain (skyTransmittance); with
  // it, cameraSources can leave the sky scattered once out too (excludeSky), for the march to add exactly.
  void setSkyTransmittance(const std::vector<float>& T0);
  int lightCount() const { return lights_; }
  int phaseModel() const { return phaseModel_; }
  float phaseG() const { return g_; }

private:
  void bindCommon(const gl::Program& p) const;
  int N_, D_, M_, maxLights_, lights_ = 0;
  glm::vec3 center_;
  float radius_;
  int phaseModel_;
  float g_;
  bool built_ = false;
  int current_ = 0;  // which radiance buffer holds the latest I
  gl::Buffer nodes_, dirs_, binCount_, binStart_, binFill_, binItems_, nodeBin_, upstream_, alpha_, weights_,
      lightBuf_, transmittance_, residual_, skyTransmittance_, source_;
  gl::Buffer radiance_[2];
};

}  // namespace radiant::network
