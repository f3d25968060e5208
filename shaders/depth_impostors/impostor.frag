// One particle's contribution to its block's impostor texel (thesis 8.1.1, Fig. 8.1): with the
// alpha test (discard outside the sphere) and per-attachment blending in one pass,
//   0: front depth, blend MIN;   1: back depth, blend MAX;
//   2: transmittance, blend dst (1 - src): prod (1 - alpha_i), so alpha_block = 1 - prod (1 - alpha_i).
// Depths are along the axis from the block centre; alpha is the full chord's 1 - exp(-optical depth).
#include "common/particle_density.glsl"

layout(std430, binding = kBindingMediaParticles) readonly buffer Particles { MediaParticle particles[]; };

in vec2 v_offset;
flat in int v_particle;
flat in float v_depth;
layout(location = 0) out float o_front;
layout(location = 1) out float o_back;
layout(location = 2) out float o_alpha;

void main() {
  const MediaParticle p = particles[v_particle];
  const float r = p.centerRadius.w;
  const float d2 = dot(v_offset, v_offset);
  if (d2 >= r * r) discard;
  const float w = sqrt(r * r - d2);
  const float alpha = 1.0 - exp(-segmentDepth(p.models.x, p.sourceTau.w, r, sqrt(d2), -w, w));
  if (!(alpha > 0.0)) discard;
  o_front = v_depth - w;
  o_back = v_depth + w;
  o_alpha = alpha;
}
