// Illumination networks (thesis ch. 9): what the network's compute shaders share, the GLSL twin of
// renderer/techniques/illumination_network/Network.cpp (binOf, boundaryDistance, nodeSource). Nodes,
// directions and links are indexed [p * D + i] for node p and direction i; bins [i * M^2 + bin].
#ifndef RADIANT_NETWORK_GLSL
#define RADIANT_NETWORK_GLSL
#include "common/shared.h"
#include "illumination_network/shared.h"
#include "common/phase.glsl"

uniform int u_nodes;       // N
uniform int u_directions;  // D (the light pass bins one direction at a time)
uniform int u_window;      // M: the window's M x M bins
uniform int u_directionFirst;  // the visibility build's first direction of this stretch (0 when unset)
uniform vec3 u_center;     // bounding sphere of the medium
uniform float u_radius;

// The window bin of x for direction d (Network.cpp binOf, in float alike).
int networkBin(NetworkDirection d, vec3 x) {
  const vec3 r = x - u_center;
  const float scale = float(u_window) / (2.0 * u_radius);
  const int bu = clamp(int(floor((dot(r, d.u.xyz) + u_radius) * scale)), 0, u_window - 1);
  const int bv = clamp(int(floor((dot(r, d.v.xyz) + u_radius) * scale)), 0, u_window - 1);
  return bv * u_window + bu;
}

// Distance from x back along -w to the bounding sphere.
float networkBoundaryDistance(vec3 w, vec3 x) {
  const vec3 r = x - u_center;
  const float b = dot(r, w);
  return b + sqrt(max(0.0, b * b - dot(r, r) + u_radius * u_radius));
}
#endif
