#include "renderer/shading/EnvironmentLights.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "renderer/scene/Environment.h"

namespace radiant {
namespace {

constexpr double kPi = 3.14159265358979323846;

double luminanceOf(const float* p, int channels) {
  if (channels < 3) return std::max(0.f, p[0]);
  return std::max(0.0, 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
}

// The direction of texel (x, y)'s centre (the inverse of equirectUv, renderer/scene/Environment.h).
glm::dvec3 texelDirection(int x, int y, int w, int h) {
  const double u = (x + 0.5) / w, v = (y + 0.5) / h;
  const double phi = (u - 0.5) * 2.0 * kPi, theta = v * kPi;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

struct Region {
  std::vector<std::int32_t> texels;
  glm::dvec3 irradiance{0.0};  // sum of S dw per channel
  double power = 0.0;          // sum of Y(S) dw
  double solidAngle = 0.0;
  glm::dvec3 weighted{0.0};    // sum of Y(S) dw direction
};

}  // namespace

std::string EnvironmentLightOptions::key() const {
  std::ostringstream s;
  s << "envlights/" << maxLights << "/" << threshold << "/" << maxSolidAngle << "/" << minPowerFraction;
  return s.str();
}

EnvironmentLights extractEnvironmentLights(const Image& map, const EnvironmentLightOptions& o, const rt::Cancel& cancel) {
  constexpr const char* kWhere = "the environment's light split (environment_lights)";
  EnvironmentLights out;
  const int w = map.width, h = map.height, c = map.channels;
  if (o.maxLights <= 0 || w <= 0 || h <= 0 || c <= 0 || !(o.threshold > 0.f) ||
      map.pixels.size() < static_cast<std::size_t>(w) * h * c)
    return out;
  // Solid angle of a texel of row y, and the map's luminous power and mean.
  std::vector<double> dOmega(h);
  double power = 0.0, sphere = 0.0;
  for (int y = 0; y < h; ++y) {
    if ((y & 63) == 0) cancel.check(kWhere);
    dOmega[y] = 2.0 * kPi * kPi * std::sin(kPi * (y + 0.5) / h) / (double(w) * h);
    for (int x = 0; x < w; ++x) {
      const double Y = luminanceOf(map.at(x, y), c);
      if (std::isfinite(Y)) power += Y * dOmega[y];
    }
    sphere += dOmega[y] * w;
  }
  if (!(power > 0.0) || !std::isfinite(power)) return out;
  const double T = o.threshold * power / sphere;
  out.threshold = static_cast<float>(T);

  // Connected regions of texels above T (4-neighbours; u wraps around, v does not).
  const std::size_t n = static_cast<std::size_t>(w) * h;
  std::vector<std::uint8_t> above(n, 0), seen(n, 0);
  for (int y = 0; y < h; ++y) {
    if ((y & 63) == 0) cancel.check(kWhere);
    for (int x = 0; x < w; ++x) {
      const double Y = luminanceOf(map.at(x, y), c);
      above[static_cast<std::size_t>(y) * w + x] = std::isfinite(Y) && Y > T;
    }
  }
  std::vector<Region> regions;
  std::vector<std::int32_t> stack;
  for (std::size_t start = 0; start < n; ++start) {
    if ((start & 65535) == 0) cancel.check(kWhere);
    if (!above[start] || seen[start]) continue;
    Region r;
    stack.assign(1, static_cast<std::int32_t>(start));
    seen[start] = 1;
    while (!stack.empty()) {
      const std::int32_t i = stack.back();
      stack.pop_back();
      r.texels.push_back(i);
      if ((r.texels.size() & 65535) == 0) cancel.check(kWhere);
      const int x = i % w, y = i / w;
      const float* p = map.at(x, y);
      const double Y = luminanceOf(p, c);
      const double keep = 1.0 - T / Y;  // the share of this texel above T
      const glm::dvec3 L = c >= 3 ? glm::dvec3(p[0], p[1], p[2]) : glm::dvec3(p[0]);
      r.irradiance += L * (keep * dOmega[y]);
      r.power += Y * keep * dOmega[y];
      r.solidAngle += dOmega[y];
      r.weighted += texelDirection(x, y, w, h) * (Y * keep * dOmega[y]);
      const int nx[4] = {(x + 1) % w, (x + w - 1) % w, x, x}, ny[4] = {y, y, y + 1, y - 1};
      for (int k = 0; k < 4; ++k) {
        if (ny[k] < 0 || ny[k] >= h) continue;
        const std::size_t j = static_cast<std::size_t>(ny[k]) * w + nx[k];
        if (above[j] && !seen[j]) {
          seen[j] = 1;
          stack.push_back(static_cast<std::int32_t>(j));
        }
      }
    }
    regions.push_back(std::move(r));
  }
  std::sort(regions.begin(), regions.end(), [](const Region& a, const Region& b) { return a.power > b.power; });

  std::vector<const Region*> taken;
  for (const Region& r : regions) {
    if (static_cast<int>(taken.size()) >= o.maxLights) break;
    if (r.solidAngle > o.maxSolidAngle || r.power < o.minPowerFraction * power) continue;
    if (!(glm::length(r.weighted) > 0.0)) continue;
    taken.push_back(&r);
  }
  if (taken.empty()) return out;

  out.residual = map;
  double takenPower = 0.0;
  for (const Region* r : taken) {
    for (std::int32_t i : r->texels) {
      float* p = out.residual.at(i % w, i / w);
      const double Y = luminanceOf(p, c);
      const float scale = static_cast<float>(T / Y);
      for (int k = 0; k < std::min(c, 3); ++k) p[k] *= scale;
    }
    Light l;
    l.name = "environment light " + std::to_string(out.lights.size());
    l.type = LightType::Directional;
    l.direction = glm::vec3(-glm::normalize(r->weighted));  // the direction light travels
    l.color = glm::vec3(r->irradiance);
    l.intensity = 1.f;
    // The radius of the uniform cap with the same S-weighted mean cosine about the centre: (1 + cos rho) / 2
    // = |sum S d dw| / sum S dw. A uniform sun gives its own radius (the cap of its solid angle); a bright
    // core in a dimmer halo above T gives the core's, where the light is (the whole region's radius, from
    // its solid angle, spread a 0.5 degree sun's glints over qwantani's 4 degree halo: smooth metal lit
    // up around the glint and too dim at it). Never below the cap of one of its texels.
    const double meanCos = std::clamp(glm::length(r->weighted) / r->power, -1.0, 1.0);
    const double texelCap = std::acos(std::clamp(1.0 - r->solidAngle / double(r->texels.size()) / (2.0 * kPi), -1.0, 1.0));
    l.angularRadius = static_cast<float>(std::max(std::acos(std::clamp(2.0 * meanCos - 1.0, -1.0, 1.0)), texelCap));
    out.lights.push_back(l);
    takenPower += r->power;
  }
  out.fraction = static_cast<float>(takenPower / power);
  return out;
}

float EnvironmentLights::residualShare(const Image& map, const glm::vec3& dir) const {
  if (!split() || residual.width != map.width || residual.height != map.height) return 1.f;
  int x, y;
  equirectTexel(map, dir, x, y);
  const double full = luminanceOf(map.at(x, y), map.channels);
  if (!(full > 0.0)) return 1.f;
  return static_cast<float>(std::clamp(luminanceOf(residual.at(x, y), residual.channels) / full, 0.0, 1.0));
}

}  // namespace radiant
