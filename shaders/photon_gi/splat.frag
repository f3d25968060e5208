// Adds one photon's phi f_r k / h^2 to the pixel's visible surface (G-buffer), additively blended
// into the accumulation target; resolve.frag turns it into `indirect`.
#include "photon_gi/photon.glsl"
#include "photon_gi/surface.glsl"

flat in int v_photon;
layout(location = 0) out vec4 o_accum;  // rgb radiance, a kernel mass of the coverage points

void main() {
  SplatSurface s;
  if (!loadSurface(ivec2(gl_FragCoord.xy), s)) discard;
  GpuPhoton p = photons[v_photon];
  if (p.power.a > 0.0) {
    // A coverage point of the edge renormalisation: w k / h^2 into alpha.
    float m = coverageContribution(p, s);
    if (!(m > 0.0)) discard;
    o_accum = vec4(0.0, 0.0, 0.0, m);
    return;
  }
  vec3 L = photonContribution(p, s);
  if (!(max(L.r, max(L.g, L.b)) > 0.0)) discard;
  o_accum = vec4(L, 0.0);
}
