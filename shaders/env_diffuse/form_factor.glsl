// Mirror of renderer/techniques/env_diffuse/FormFactor.h (thesis ch. 3); the C++ side is unit tested
// against closed forms. Form factors are projected solid angles: pi for the whole hemisphere.
#ifndef RADIANT_ENV_DIFFUSE_FORM_FACTOR
#define RADIANT_ENV_DIFFUSE_FORM_FACTOR

// GL 4.5 table 8.19: face (+X, -X, +Y, -Y, +Z, -Z), face coordinates (sc, tc) in [-1, 1] -> direction.
vec3 cubeFaceDirection(int face, float sc, float tc) {
  if (face == 0) return vec3(1.0, -tc, -sc);
  if (face == 1) return vec3(-1.0, -tc, sc);
  if (face == 2) return vec3(sc, 1.0, tc);
  if (face == 3) return vec3(sc, -1.0, -tc);
  if (face == 4) return vec3(sc, -tc, 1.0);
  return vec3(-sc, -tc, -1.0);
}

// Solid angle of the face region [x0,x1] x [y0,y1]: antiderivative atan(x y, sqrt(1 + x^2 + y^2)).
float cubeAreaElement(float x, float y) { return atan(x * y, sqrt(1.0 + x * x + y * y)); }
float cubeTexelSolidAngle(float x0, float y0, float x1, float y1) {
  return cubeAreaElement(x1, y1) - cubeAreaElement(x0, y1) - cubeAreaElement(x1, y0) + cubeAreaElement(x0, y0);
}

// thesis eq. 3.3, one edge: 1/2 angle(a, b) (a x b / |a x b|) . n, as 1/2 (theta / sin theta) (a x b) . n.
float formFactorEdge(vec3 a, vec3 b, vec3 n) {
  vec3 c = cross(a, b);
  float s = length(c);
  if (s < 1e-7) return 0.0;
  float theta = atan(s, dot(a, b));
  return 0.5 * theta / s * dot(c, n);
}

// Polygon (4 vertices relative to the shaded point; only directions matter) to point form factor,
// optionally clipped to the horizon of n, positive part of the edge sum (Algorithm 1). See FormFactor.h.
float formFactorQuadToPoint(vec3 R0, vec3 R1, vec3 R2, vec3 R3, vec3 n, bool horizonClip) {
  vec3 v[4] = vec3[4](R0, R1, R2, R3);
  float scale = max(max(dot(R0, R0), dot(R1, R1)), max(dot(R2, R2), dot(R3, R3)));
  if (!(scale > 0.0) || isinf(scale)) return 0.0;
  float inv = inversesqrt(scale);
  for (int i = 0; i < 4; ++i) v[i] = dot(v[i], v[i]) <= 1e-10 * scale ? n : v[i] * inv;
  vec3 c[8];
  int m = 0;
  if (horizonClip) {
    for (int i = 0; i < 4; ++i) {
      vec3 a = v[i];
      vec3 b = v[(i + 1) & 3];
      float da = dot(a, n), db = dot(b, n);
      if (da >= 0.0) c[m++] = a;
      if ((da >= 0.0) != (db >= 0.0)) c[m++] = a + (b - a) * (da / (da - db));
    }
    if (m < 3) return 0.0;
  } else {
    for (int i = 0; i < 4; ++i) c[i] = v[i];
    m = 4;
  }
  float sum = 0.0;
  for (int i = 0; i < m; ++i) {
    vec3 a = c[i];
    vec3 b = c[i + 1 < m ? i + 1 : 0];
    float la = length(a), lb = length(b);
    if (la <= 0.0 || lb <= 0.0) continue;
    sum += formFactorEdge(a / la, b / lb, n);
  }
  return max(0.0, sum);
}

// Virtual point light: cos+ theta_x cos+ theta_y A / r^2 (the unstable baseline; 0 only for r = 0).
float formFactorPointToPoint(vec3 x, vec3 n, vec3 y, vec3 ny, float area) {
  vec3 d = y - x;
  float r2 = dot(d, d);
  if (!(r2 > 1e-20)) return 0.0;
  vec3 w = d * inversesqrt(r2);
  return max(0.0, dot(n, w)) * max(0.0, -dot(ny, w)) * area / r2;
}

float vplArea(float solidAngle, float distance, float cosToReference) {
  return solidAngle * distance * distance / max(cosToReference, 0.1);
}
#endif
