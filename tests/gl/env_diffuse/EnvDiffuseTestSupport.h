#pragma once
// Shared by env_diffuse_test and bench/env_diffuse_bench: which pixels show which receiver of the
// Cornell box, and the error measure both report.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "renderer/Renderer.h"

namespace radiant::testing {

// Which receiver each pixel shows: the same scene with the receivers made emissive (red sphere, green
// box), read back from the G-buffer's emission AOV, so the mask comes from the very rasteriser.
struct Masks {
  std::vector<int> id;  // 0 none, 1 sphere, 2 tall box; pixels at a silhouette (any 4-neighbour differs) -1
};
inline Masks receiverMasks(Renderer& renderer, const Scene& scene, int size) {
  Scene s = scene;
  s.digest += "|mask";
  for (MeshInstance& m : s.meshes) {
    if (m.name != "sphere" && m.name != "tall_box") continue;
    Material mat = s.material(m.material);
    mat.emissiveFactor = m.name == "sphere" ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    s.materials.push_back(mat);
    m.material = static_cast<int>(s.materials.size()) - 1;
  }
  api::RenderRequest r;
  r.width = r.height = size;
  r.outputs = {api::OutputSpec{api::ImageFormat::Exr, {"emission"}, false}};
  RenderOutput out = renderer.render(s, r);
  const Image& e = out.aovs.back();  // the one AOV asked for after beauty
  Masks m;
  m.id.assign(size * size, 0);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) m.id[y * size + x] = e.at(x, y)[0] > 0.5f ? 1 : e.at(x, y)[1] > 0.5f ? 2 : 0;
  std::vector<int> eroded = m.id;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int v = m.id[y * size + x];
      for (auto [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const int X = std::clamp(x + dx, 0, size - 1), Y = std::clamp(y + dy, 0, size - 1);
        if (m.id[Y * size + X] != v) eroded[y * size + x] = -1;
      }
    }
  m.id = eroded;
  return m;
}

// Relative RMS error after a 3 x 3 box filter, over the pixels whose whole 3 x 3 neighbourhood shows
// receiver `id`: the filter divides the reference's Monte Carlo noise by 3 while keeping the methods'
// errors, which are smooth (bias from the box-filtered environment) or a few pixels wide (spikes).
inline double relRmse3(const Image& test, const Image& ref, const Masks& m, int id) {
  double num = 0, den = 0;
  const int w = test.width;
  for (int y = 1; y + 1 < test.height; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      bool inside = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) inside = inside && m.id[(y + dy) * w + x + dx] == id;
      if (!inside) continue;
      for (int c = 0; c < 3; ++c) {
        double t = 0, r = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) t += test.at(x + dx, y + dy)[c], r += ref.at(x + dx, y + dy)[c];
        num += (t - r) * (t - r);
        den += r * r;
      }
    }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

}  // namespace radiant::testing
