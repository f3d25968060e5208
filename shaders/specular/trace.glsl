// Algorithm 3 (thesis ch. 5) iterated with an explicit, bounded stack instead of recursion:
//   RayTrace(x, R) = radiance of the closest diffuse hit, or 0 when max_depth is reached, or
//                    F RayTrace(x, Rl) + (1 - F) T RayTrace(x, Rf) at a mirror or refractor.
// Shared by the specular pass (specular.frag: a diffuse hit sends the maps' stored radiance) and the
// caustics pass's secondary lookup (caustics/secondary.frag: the caustic at the hit). The includer
// defines, before including this file (with LDM_TRACING and specular/ldm.glsl):
//   vec3 missRadiance(vec3 dir)   radiance of a ray that leaves the scene
//   vec3 diffuseHitRadiance(vec3 hit, vec3 rayDir, vec3 dir, float cube, vec4 texel)
//                                 radiance a non-specular hit sends back along the ray `rayDir`: `hit`
//                                 in world space, `dir` its direction from the reference point of the
//                                 map it was found in, `cube` that map's layer, `texel` its material texel
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

struct Ray {
  vec3 origin;
  vec3 dir;
  vec3 weight;
  int depth;   // specular interactions on the path so far (the one that spawned this ray included)
  int object;  // whose layered distance map the ray is traced in: the object it leaves
  bool inside; // travels inside `object` (refracted in, or reflected inside): its medium absorbs
  vec3 surface; // the surface point it leaves (origin is pushed off it by the self-intersection offset)
};

Ray stack[MAX_STACK];
int sp = 0;

void push(vec3 origin, vec3 dir, vec3 weight, int depth, int object, bool inside, vec3 surface) {
  if (max(weight.r, max(weight.g, weight.b)) < u_minWeight || sp >= MAX_STACK) return;
  stack[sp] = Ray(origin, dir, weight, depth, object, inside, surface);
  ++sp;
}

// The two children of an ideal specular interaction at p. R: incoming unit direction; n: the
// surface normal as modelled (either side); texel: specularTexel(); the rays leave in `object`'s map.
void scatter(vec3 p, vec3 R, vec3 n, vec4 texel, vec3 weight, int depth, int object, bool entering) {
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
    push(p + nn * eps, rl, weight * schlick(texel.rgb, cosI), depth, object, !entering, p);
    return;
  }
  float ior = texel.a;
  float eta = entering ? ior : 1.0 / ior;  // n_t / n_i
  float F = fresnelDielectric(cosI, eta);
  // The reflection stays on the side it came from: inside when it was leaving (internal reflection).
  push(p + nn * eps, rl, weight * F, depth, object, !entering, p);
  if (F < 1.0) {
    vec3 rf = refract(R, nn, 1.0 / eta);  // GLSL's eta is n_i / n_t
    if (dot(rf, rf) > 0.0)
      // Radiance crossing an interface scales by 1 / eta^2 (Veach 1997, 5.2), as in the reference.
      push(p - nn * eps, normalize(rf), weight * (1.0 - F) * texel.rgb / (eta * eta), depth, object, entering, p);
  }
}

// The radiance arriving along R at p (a specular surface of `object` with normal n, material texel
// `texel`, entered when `entering`) through the traced tree; `traced` counts the rays.
vec3 traceSpecularTree(vec3 p, vec3 R, vec3 n, vec4 texel, int object, bool entering, out int traced) {
  sp = 0;
  scatter(p, R, n, texel, vec3(1.0), 1, object, entering);
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
      L += r.weight * (r.inside ? volumeTransmittance(r.object, 3.0e38) : vec3(1.0)) * missRadiance(r.dir);
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
    if (r.depth >= u_maxDepth) continue;  // Algorithm 3: max ray depth reached -> zero
    vec3 hn = octDecode(geo.xy);
    // Entering a refractor when arriving against its outward normal.
    scatter(hit, r.dir, hn, texel, r.weight, r.depth + 1, code - 1, dot(hn, r.dir) < 0.0);
  }
  return L;
}
#endif
