// The specular pass proper: rasterises each specular object (the first hit, thesis ch. 5: "the first
// point is identified by rasterization"), keeps the fragment the G-buffer sees, and traces the
// reflected and refracted rays through the layered distance maps (Algorithm 3, specular/trace.glsl).
// Writes the radiance arriving through the traced paths, already weighted by Fresnel and colour:
// the `specular` AOV, which compose.frag adds to beauty.
#define LDM_TRACING
#include "common/scene.glsl"
#include "specular/ldm.glsl"
#include "common/environment.glsl"

in vec3 v_position;

layout(binding = 0) uniform sampler2D t_position;
layout(binding = 1) uniform sampler2D t_normal;
layout(binding = 2) uniform sampler2D t_albedo;
layout(binding = 3) uniform sampler2D t_material;
layout(binding = 4) uniform sampler2D t_emission;

uniform int u_object;  // index of the specular object being drawn
uniform vec3 u_eye;
uniform vec3 u_viewForward;
uniform int u_orthographic;
uniform vec3 u_background;  // radiance where a ray leaves the scene (the sky), as `direct` uses
uniform int u_hasEnvironment;  // 1: a ray leaving the scene sees the environment map instead
layout(binding = kUnitEnvironment) uniform sampler2D t_environment;

layout(location = 0) out vec4 o_specular;

// A ray that leaves the scene sees the sky in its direction; a diffuse hit its stored radiance.
vec3 missRadiance(vec3 dir) {
  return u_hasEnvironment != 0 ? environmentRadiance(t_environment, dir) : u_background;
}
vec3 diffuseHitRadiance(vec3 hit, vec3 rayDir, vec3 dir, float cube, vec4 texel) { return texel.rgb; }

#include "specular/trace.glsl"

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 P = texelFetch(t_position, px, 0);
  float viewDepth = dot(v_position - u_eye, u_viewForward);
  // Only the fragment the G-buffer kept (same surface within rasterisation noise) is shaded.
  if (P.w <= 0.0 || abs(P.w - viewDepth) > 1e-3 * max(viewDepth, 1e-6) + 1e-6) discard;

  vec3 p = P.xyz;
  vec3 n = normalize(texelFetch(t_normal, px, 0).xyz);  // RGBA16F: unit only to ~5e-4 (direct.frag)
  vec4 mat = texelFetch(t_material, px, 0);  // metallic, roughness, occlusion, transmission
  vec3 albedo = texelFetch(t_albedo, px, 0).rgb;
  float ior = texelFetch(t_emission, px, 0).a;
  vec3 R = u_orthographic != 0 ? u_viewForward : normalize(p - u_eye);

  // The G-buffer normal faces the viewer; whether the ray enters or leaves the object is the face's
  // orientation (a camera inside a glass object sees its back faces).
  int traced;
  vec3 L = traceSpecularTree(p, R, n, specularTexel(albedo, mat.x, mat.w, ior), u_object, gl_FrontFacing, traced);
  o_specular = vec4(L, float(traced));
}
