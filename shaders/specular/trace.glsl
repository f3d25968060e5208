// Algorithm 3 (thesis ch. 5) iterated with an explicit, bounded stack instead of recursion:
//   RayTrace(x, R) = radiance of the closest diffuse hit, or 0 when max_depth is reached, or
//                    F RayTrace(x, Rl) + (1 - F) T RayTrace(x, Rf) at a mirror or refractor.
// Shared by the specular pass (specular.frag: a diffuse hit sends the maps' stored radiance) and the
// caustics pass's secondary lookup (caustics/secondary.frag: the caustic at the hit). The includer
// defines, before including this file (with LDM_TRACING and specular/ldm.glsl):
//   vec3 missRadiance(vec3 dir, float cone)
//                                 radiance of a ray that leaves the scene, standing for a cone of
//                                 directions `cone` radians wide
//   vec3 diffuseHitRadiance(vec3 hit, vec3 rayDir, vec3 dir, float cube, vec4 texel)
//                                 radiance a non-specular hit sends back along the ray `rayDir`: `hit`
//                                 in world space, `dir` its direction from the reference point of the
//                                 map it was found in, `cube` that map's layer, `texel` its material texel
//   vec3 mirrorDiffuseRadiance(vec4 texel)
//                                 radiance the diffuse lobe of a mirror hit sends back (`texel` its
//                                 material texel, whose rgb the maps filled with it), added to what
//                                 the mirror reflects: a metal of metallic 0.67 is a third dielectric
#ifndef RADIANT_SPECULAR_TRACE
#define RADIANT_SPECULAR_TRACE

#include "common/brdf.glsl"  // fresnelDielectric

#ifndef MAX_STACK
#define MAX_STACK 10  // max_depth (<= 8) pending siblings + the current ray, see below
#endif

uniform int u_maxDepth;
uniform float u_minWeight;  // branches whose path weight falls below this are dropped

vec3 schlick(vec3 f0, float cosTheta) {
  float m = clamp(1.0 - cosTheta, 0.0, 1.0);
  float m2 = m * m;
  return f0 + (1.0 - f0) * (m2 * m2 * m);
}

// A ray cone (Amanatides 1984; Akenine-Moller et al., "Texture Level of Detail Strategies for
// Real-Time Ray Tracing", Ray Tracing Gems 2019, ch. 20): the directions a ray stands for, a cone of
// full width `cone` radians, `width` wide where the ray starts. It grows by cone x distance, and a
// reflection off a convex mirror of curvature k widens it by 2 k width: across a footprint w the
// normal turns by k w / cos(theta) in the plane of incidence and k w across it, the reflected
// direction by twice that times 1 / cos(theta) and cos(theta) respectively, and 2 k w is the
// circular cone of the same solid angle. A miss reads the environment's mean over its cone
// (missRadiance): a sun seen in a small mirror sphere through a glossy one is a glint
// spread over the cone, as the reference integrates it, instead of a single direction that misses
// it (MetalRoughSpheres' glossy mirror spheres and their small mirror neighbours). Concave mirrors
// and refraction keep the cone (they focus before they spread; the narrower cone is the sharper
// reading). The width at a hit is at least the map texel's size there (mapConvexCurvature).
struct Ray {
  vec3 origin;
  vec3 dir;
  vec3 weight;
  int depth;   // specular interactions on the path so far (the one that spawned this ray included)
  int object;  // whose layered distance map the ray is traced in: the object it leaves
  bool inside; // travels inside `object` (refracted in, or reflected inside): its medium absorbs
  vec3 surface; // the surface point it leaves (origin is pushed off it by the self-intersection offset)
  float cone;   // the ray cone's width (radians) and its width at `surface`
  float width;
};

Ray stack[MAX_STACK];
int sp = 0;

void push(vec3 origin, vec3 dir, vec3 weight, int depth, int object, bool inside, vec3 surface, float cone,
          float width) {
  if (max(weight.r, max(weight.g, weight.b)) < u_minWeight || sp >= MAX_STACK) return;
  stack[sp] = Ray(origin, dir, weight, depth, object, inside, surface, cone, width);
  ++sp;
}

// The two children of an ideal specular interaction at p. R: incoming unit direction; n: the
// surface normal as modelled (either side); texel: specularTexel(); the rays leave in `object`'s map.
// cone, width: the arriving ray cone at p; reflectedCone: the reflection's (widened by curvature).
void scatter(vec3 p, vec3 R, vec3 n, vec4 texel, vec3 weight, int depth, int object, bool entering, float cone,
             float reflectedCone, float width) {
  // Unit vectors throughout: the G-buffer normal is stored at half precision, and the search's shell
  // clipping (ldm.glsl) assumes |R| = 1.
  n = normalize(n);
  vec3 nn = dot(n, R) > 0.0 ? -n : n;  // faces the incoming ray
  float cosI = clamp(-dot(R, nn), 0.0, 1.0);
  // Self-intersection offset: the maps are sampled at nearest texels, so the surface at the origin is
  // known only to about half a texel; step off it by that (scaled by the object's size).
  float eps = objects[object].referenceRadius.w * (1e-3 + 0.5 / u_cubeResolution);
  vec3 rl = normalize(reflect(R, nn));
  if (texel.a < 0.0) {
    // Mirror: Schlick with F0 = the stored colour (glTF conductor Fresnel, as the reference).
    push(p + nn * eps, rl, weight * schlick(texel.rgb, cosI), depth, object, !entering, p, reflectedCone, width);
    return;
  }
  float ior = texel.a;
  float eta = entering ? ior : 1.0 / ior;  // n_t / n_i
  float F = fresnelDielectric(cosI, eta);
  // The reflection stays on the side it came from: inside when it was leaving (internal reflection).
  push(p + nn * eps, rl, weight * F, depth, object, !entering, p, reflectedCone, width);
  if (F < 1.0) {
    vec3 rf = refract(R, nn, 1.0 / eta);  // GLSL's eta is n_i / n_t
    if (dot(rf, rf) > 0.0)
      // Radiance crossing an interface scales by 1 / eta^2 (Veach 1997, 5.2), as in the reference.
      push(p - nn * eps, normalize(rf), weight * (1.0 - F) * texel.rgb / (eta * eta), depth, object, entering, p,
           cone, width);
  }
}

// The radiance arriving along R at p (a specular surface of `object` with normal n, material texel
// `texel`, entered when `entering`) through the traced tree; `traced` counts the rays. cone: the width
// of the ray cone that the rays leaving p stand for, width its width at p (both 0: single rays).
vec3 traceSpecularTree(vec3 p, vec3 R, vec3 n, vec4 texel, int object, bool entering, float cone, float width,
                       out int traced) {
  sp = 0;
  scatter(p, R, n, texel, vec3(1.0), 1, object, entering, cone, cone, width);
  vec3 L = vec3(0.0);
  traced = 0;
  // Each pop pushes at most two children and the walk is depth-first, so at most one pending sibling
  // per depth level waits on the stack: MAX_STACK >= max_depth + 1 bounds it, and the loop ends after
  // at most 2^(max_depth + 1) - 2 rays.
  while (sp > 0) {
    --sp;
    Ray r = stack[sp];
    ++traced;
    float d;
    int layer;
    if (!traceLayers(r.object, r.origin, r.dir, d, layer)) {
      // No surface in any layer: the ray leaves the scene (from inside an open mesh: through all of
      // its medium, which absorbs everything it can).
      L += r.weight * (r.inside ? volumeTransmittance(r.object, 3.0e38) : vec3(1.0)) * missRadiance(r.dir, r.cone);
      continue;
    }
    // KHR_materials_volume: Beer-Lambert over the segment's traced length, the real path inside the
    // object as the reference tracer takes it (not the spec's thickness stand-in), measured from the
    // surface point: the origin's offset (~0.3% of the object's radius) would otherwise go unabsorbed.
    vec3 hit = r.origin + r.dir * d;
    if (r.inside) r.weight *= volumeTransmittance(r.object, length(hit - r.surface));
    vec3 dir = hit - objects[r.object].referenceRadius.xyz;
    if (dot(dir, dir) < 1e-30) dir = r.dir;
    float cube = float(r.object * u_layers + layer);
    vec4 texel = texture(t_ldmMaterial, vec4(dir, cube));
    vec4 geo = texture(t_ldmGeometry, vec4(dir, cube));
    int code = int(geo.w + 0.5);
    if (texel.a == 0.0 || code == 0) {
      L += r.weight * diffuseHitRadiance(hit, r.dir, dir, cube, texel);
      continue;
    }
    if (texel.a < 0.0) L += r.weight * mirrorDiffuseRadiance(texel);
    if (r.depth >= u_maxDepth) continue;  // Algorithm 3: max ray depth reached -> zero
    vec3 hn = octDecode(geo.xy);
    // Entering a refractor when arriving against its outward normal.
    bool fromOutside = dot(hn, r.dir) < 0.0;
    float width = r.width + r.cone * d;
    float reflectedCone = r.cone;
    if ((r.cone > 0.0 || r.width > 0.0) && texel.a < 0.0 && fromOutside) {
      // The hit's normal is its map texel's: where a texel is wider than the beam, the reflected
      // directions come in steps of 2 k texel, and a cone narrower than a step reads them unevenly.
      float texelSize;
      float k = mapConvexCurvature(dir, cube, geo, texelSize);
      reflectedCone = min(r.cone + 2.0 * k * max(width, texelSize), PI);
    }
    scatter(hit, r.dir, hn, mapSpecularTexel(texel, dir, cube), r.weight, r.depth + 1, code - 1, fromOutside,
            r.cone, reflectedCone, width);
  }
  return L;
}
#endif
