// What C++ and GLSL share of illumination_network: the network's nodes, directions and lights as
// the compute shaders read them.
// Same rules as common/shared.h (every struct member a vec4/ivec4/mat4, nothing included, constants
// declared with RADIANT_CONST): GLSL includes it after "common/shared.h"; C++ after
// renderer/frame/GpuTypes.h, inside namespace radiant::gpu (renderer/techniques/illumination_network/NetworkGpu.h).
#ifndef RADIANT_ILLUMINATION_NETWORK_SHARED_H
#define RADIANT_ILLUMINATION_NETWORK_SHARED_H

// One network node: a point of the medium with its local extinction, albedo and emission.
struct NetworkNode {
  vec4 positionTau;  // xyz world position, w extinction at the node
  vec4 albedo;       // rgb single-scattering albedo, w unused
  vec4 emission;     // rgb source per unit opacity ((1 - a) L_e), w unused
};

// One shared direction: w the direction of propagation, u and v the window's axes.
struct NetworkDirection {
  vec4 w, u, v;  // xyz, w unused
};

// One directional light as the network sees it: propagation direction and irradiance.
struct NetworkLight {
  vec4 direction;   // xyz unit, w unused
  vec4 irradiance;  // rgb, w unused
};

#endif
