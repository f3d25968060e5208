#pragma once
// Counter-based random numbers: every value is a hash of (stream, sample, seed, dimension), so an
// image or a photon set does not depend on the number of threads or on scheduling: results are
// bitwise reproducible, and photon i of a run of m photons is photon i of a run of m + m'.
#include <cstdint>

#include <glm/glm.hpp>

namespace radiant::rt {

inline std::uint64_t splitMix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

struct Sampler {
  std::uint64_t key = 0;
  std::uint64_t dimension = 0;
  // stream: a pixel or a photon index; sample: the sample within it.
  Sampler(std::uint64_t stream, std::uint64_t sample, std::uint64_t seed)
      : key(splitMix64(splitMix64(splitMix64(seed) ^ stream) ^ (sample * 0xD1B54A32D192ED03ull))) {}
  float next() {
    const std::uint64_t h = splitMix64(key ^ (++dimension * 0xA0761D6478BD642Full));
    return static_cast<float>(h >> 40) * 0x1p-24f;  // [0, 1)
  }
  glm::vec2 next2() { const float a = next(); return {a, next()}; }
};

}  // namespace radiant::rt
