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
  s << "envlights/" << maxLights << "/" << threshold << "/" << maxSolidAngle << "/" << minPowerFraction << "/sky"
    << skyLights;
  return s.str();
}

namespace {

EnvironmentLights extractCompactLights(const Image& map, const EnvironmentLightOptions& o, const rt::Cancel& cancel) {
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

// Median cut of `m` (the residual) into at most n rectangles of texels (Debevec 2005; see the header).
std::vector<Light> medianCutLights(const Image& m, int n, const rt::Cancel& cancel);

// `map` with blocks of sx x sy texels averaged by solid angle (non-finite texels carry nothing), so
// each coarse texel holds the block's mean radiance and the map's power is kept: the median cut of a
// large map works on at most kMaxCutTexels (its summed-area table is 8 bytes a texel: a 1 x 22-million
// map, within the decode limits, would have taken 350 MB).
constexpr std::size_t kMaxCutTexels = std::size_t(1) << 20;
Image coarsened(const Image& map, const rt::Cancel& cancel) {
  const int w = map.width, h = map.height, c = map.channels;
  int sx = 1, sy = 1;
  while (static_cast<std::size_t>((w + sx - 1) / sx) * ((h + sy - 1) / sy) > kMaxCutTexels) {
    if ((w + sx - 1) / sx >= (h + sy - 1) / sy) sx *= 2;
    else sy *= 2;
  }
  const int cw = (w + sx - 1) / sx, ch = (h + sy - 1) / sy;
  Image out = Image::make("environment", cw, ch, c);
  std::vector<double> sum(static_cast<std::size_t>(c));
  for (int cy = 0; cy < ch; ++cy) {
    cancel.check("the environment's sky lights (sky_lights)");
    for (int cx = 0; cx < cw; ++cx) {
      std::fill(sum.begin(), sum.end(), 0.0);
      double wsum = 0.0;
      for (int y = cy * sy; y < std::min(h, (cy + 1) * sy); ++y) {
        const double dw = std::sin(kPi * (y + 0.5) / h);
        for (int x = cx * sx; x < std::min(w, (cx + 1) * sx); ++x) {
          const float* p = map.at(x, y);
          bool finite = true;
          for (int k = 0; k < c; ++k) finite = finite && std::isfinite(p[k]);
          wsum += dw;
          if (finite)
            for (int k = 0; k < c; ++k) sum[k] += p[k] * dw;
        }
      }
      float* q = out.at(cx, cy);
      for (int k = 0; k < c; ++k) q[k] = wsum > 0.0 ? static_cast<float>(sum[k] / wsum) : 0.f;
    }
  }
  return out;
}

std::vector<Light> medianCutLights(const Image& m, int n, const rt::Cancel& cancel) {
  constexpr const char* kWhere = "the environment's sky lights (sky_lights)";
  std::vector<Light> out;
  const int w = m.width, h = m.height, c = m.channels;
  if (n <= 0 || w <= 0 || h <= 0 || c <= 0 || m.pixels.size() < static_cast<std::size_t>(w) * h * c) return out;
  if (static_cast<std::size_t>(w) * h > kMaxCutTexels) return medianCutLights(coarsened(m, cancel), n, cancel);
  // Summed-area table of the power Y dw (non-finite and negative texels carry none).
  std::vector<double> sat(static_cast<std::size_t>(w + 1) * (h + 1), 0.0);
  auto S = [&](int x, int y) -> double& { return sat[static_cast<std::size_t>(y) * (w + 1) + x]; };
  for (int y = 0; y < h; ++y) {
    if ((y & 63) == 0) cancel.check(kWhere);
    const double dw = 2.0 * kPi * kPi * std::sin(kPi * (y + 0.5) / h) / (double(w) * h);
    double row = 0.0;
    for (int x = 0; x < w; ++x) {
      const float* p = m.at(x, y);
      bool finite = true;
      for (int k = 0; k < std::min(c, 3); ++k) finite = finite && std::isfinite(p[k]);
      row += finite ? luminanceOf(p, c) * dw : 0.0;
      S(x + 1, y + 1) = S(x + 1, y) + row;
    }
  }
  struct Rect {
    int x0, y0, x1, y1;
    double power;
  };
  auto power = [&](int x0, int y0, int x1, int y1) { return S(x1, y1) - S(x0, y1) - S(x1, y0) + S(x0, y0); };
  std::vector<Rect> rects{{0, 0, w, h, power(0, 0, w, h)}};
  if (!(rects[0].power > 0.0) || !std::isfinite(rects[0].power)) return out;
  // The first cut is the horizon (v = 1/2; +Y is up): a light is the cosine-weighted sum of its
  // region only on surfaces that see all of it, and a region across the horizon lights an upward
  // surface from its centroid, near the horizon, with a fraction of the light its upper half gives.
  // Ground planes and what stands on them (the contact shadows) are the receivers that matter here.
  if (n >= 2 && h >= 2) rects = {{0, 0, w, h / 2, power(0, 0, w, h / 2)}, {0, h / 2, w, h, power(0, h / 2, w, h)}};
  while (static_cast<int>(rects.size()) < n) {
    cancel.check(kWhere);
    // The region of most power that can still be split.
    int best = -1;
    for (int i = 0; i < static_cast<int>(rects.size()); ++i) {
      const Rect& r = rects[i];
      if ((r.x1 - r.x0 > 1 || r.y1 - r.y0 > 1) && r.power > 0.0 && (best < 0 || r.power > rects[best].power)) best = i;
    }
    if (best < 0) break;
    const Rect r = rects[best];
    const double lat = kPi * (0.5 * (r.y0 + r.y1) / h - 0.5);
    const double across = (r.x1 - r.x0) * (2.0 * kPi / w) * std::cos(lat), down = (r.y1 - r.y0) * (kPi / h);
    const bool splitX = r.y1 - r.y0 <= 1 || (r.x1 - r.x0 > 1 && across > down);
    // The cut where the power halves: the first column (row) at which the prefix reaches half, kept
    // inside the rectangle so both halves hold at least one column (row).
    const int lo = splitX ? r.x0 : r.y0, hi = splitX ? r.x1 : r.y1;
    int a = lo + 1, b = hi - 1;
    while (a < b) {
      const int mid = (a + b) / 2;
      const double prefix = splitX ? power(r.x0, r.y0, mid, r.y1) : power(r.x0, r.y0, r.x1, mid);
      if (prefix < 0.5 * r.power) a = mid + 1;
      else b = mid;
    }
    Rect first = r, second = r;
    if (splitX) first.x1 = second.x0 = a;
    else first.y1 = second.y0 = a;
    first.power = power(first.x0, first.y0, first.x1, first.y1);
    second.power = power(second.x0, second.y0, second.x1, second.y1);
    rects[best] = first;
    rects.push_back(second);
  }
  for (const Rect& r : rects) {
    cancel.check(kWhere);
    glm::dvec3 weighted(0.0);  // sum Y(R) w dw
    glm::dmat3 vectors(0.0);   // column c: sum R_c w dw, the region's vector irradiance in channel c
    for (int y = r.y0; y < r.y1; ++y) {
      const double dw = 2.0 * kPi * kPi * std::sin(kPi * (y + 0.5) / h) / (double(w) * h);
      for (int x = r.x0; x < r.x1; ++x) {
        const float* p = m.at(x, y);
        const glm::dvec3 L = c >= 3 ? glm::dvec3(p[0], p[1], p[2]) : glm::dvec3(p[0]);
        if (!std::isfinite(L.x + L.y + L.z)) continue;
        const glm::dvec3 d = texelDirection(x, y, w, h);
        for (int k = 0; k < 3; ++k) vectors[k] += d * (L[k] * dw);
        weighted += d * (luminanceOf(p, c) * dw);
      }
    }
    if (!(glm::length(weighted) > 0.0)) continue;
    const glm::dvec3 centre = glm::normalize(weighted);
    // The light's irradiance is the region's vector irradiance along its direction, sum R (w . d) dw,
    // not sum R dw: a diffuse surface that sees the whole region receives n . sum R w dw from it, which
    // this reproduces exactly (for the luminance; per channel up to the channel's own mean direction).
    // sum R dw would overstate it by 1 / |mean direction|: 1.4x under the broad, dim regions of a map's
    // ground (test EnvironmentLights.SkyLightsCarryTheResidualAndLightAPlaneAsTheMapDoes).
    const glm::dvec3 irradiance(std::max(0.0, glm::dot(vectors[0], centre)), std::max(0.0, glm::dot(vectors[1], centre)),
                                std::max(0.0, glm::dot(vectors[2], centre)));
    if (!(irradiance.x + irradiance.y + irradiance.z > 0.0)) continue;
    Light l;
    l.name = "sky light " + std::to_string(out.size());
    l.type = LightType::Directional;
    l.direction = glm::vec3(-centre);
    l.color = glm::vec3(irradiance);
    l.intensity = 1.f;
    // The uniform cap with the region's mean cosine about its direction, (1 + cos sigma) / 2 =
    // |sum Y w dw| / sum Y dw, at most a hemisphere: the frame shades the light as that cap clipped by
    // the receiver's horizon (direct_lighting.glsl skyCapCosine).
    // Caps are not clipped at the map's horizon: the regions there are the ones a wall's horizon cuts
    // through, and a cap shrunk to stay above the map's horizon lit walls as a single direction (the
    // studio-lit frame of Transmission.* fell from 0.95 to 0.94 of the reference); the price is a
    // leak of 0.4% of a lower hemisphere onto an upward plane (Environment.ReferenceAndRasterLightByTheMapNotItsAverage).
    const double meanCos = r.power > 0.0 ? std::clamp(glm::length(weighted) / r.power, 0.5, 1.0) : 1.0;
    l.angularRadius = static_cast<float>(std::acos(2.0 * meanCos - 1.0));
    out.push_back(l);
  }
  return out;
}

}  // namespace

EnvironmentLights extractEnvironmentLights(const Image& map, const EnvironmentLightOptions& o, const rt::Cancel& cancel) {
  EnvironmentLights out = extractCompactLights(map, o, cancel);
  if (o.skyLights > 0) out.skyLights = medianCutLights(out.split() ? out.residual : map, o.skyLights, cancel);
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
