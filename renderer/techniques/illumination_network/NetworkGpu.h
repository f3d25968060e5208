#pragma once
// The illumination network on the GPU (thesis §9.1): the visibility network V built by per-direction
// binning in compute shaders (count, scan, scatter, then each node's depth predecessor in its bin),
// and the iteration of eq. 9.1 in fp32 with the max-norm change of every step. Owns its buffers
// (created once per network: the technique caches an instance as derived data keyed by the medium
// and the parameters that shape it), so a warm start is the radiance it already holds.
// The CPU twin and oracle is Network.h.
#include <vector>

#include <glm/glm.hpp>

#include "renderer/gl/Gl.h"
#include "renderer/gl/ShaderLibrary.h"
#include "renderer/techniques/illumination_network/Network.h"

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
  void buildVisibility(gl::ShaderLibrary& shaders);
  bool visibilityBuilt() const { return built_; }
  Visibility downloadVisibility() const;

  // This frame's directional lights and their transmittance T[p * L + l] (lightTransmittance).
  void setLights(const std::vector<DirectionalLight>& lights, const std::vector<double>& transmittance);
  // I := 0 (a cold start).
  void clearRadiance();
  // `count` iterations with sky radiance `sky`; returns ||I^{n+1} - I^n||_inf of each.
  std::vector<double> iterate(gl::ShaderLibrary& shaders, int count, glm::vec3 sky);
  // I as iterated so far, [p * D + i].
  std::vector<glm::dvec3> downloadRadiance() const;
  void uploadRadiance(const std::vector<glm::dvec3>& I);

  // Fills the splats' source (MediaParticle::sourceTau.rgb; slot s is node order[s]) with each
  // node's radiance towards the camera (camera.comp).
  void cameraSources(gl::ShaderLibrary& shaders, const gl::Buffer& order, gl::Buffer& splats, bool orthographic,
                     glm::vec3 eye, glm::vec3 toCamera);

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
      lightBuf_, transmittance_, residual_;
  gl::Buffer radiance_[2];
};

}  // namespace radiant::network
