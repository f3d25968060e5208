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

// The dimensions (as Sampler::dimension counts them, from 1) that a low-discrepancy stream stratifies
// jointly, as the coordinates of the Kronecker sequence R_10: the first 10. For the photon tracer these
// are the emission's light choice and two pairs (a point light's direction; an area light's position
// and direction; the sky's direction and its disk position), the first bounce's lobe and Fresnel
// choices and direction, and its roulette, which together place a photon's first indirect hit. Each
// pair is stratified (a chi-square over 16 x 16 cells of 4096 streams 14-36, against 255 for
// independent samples), their 4-D joint less (106-204 over 4^4 cells). R_4 over just the point
// light's direction and the bounce's direction stratified that joint to 55 but left the sky's and the
// area lights' other pair random, and scored no better on the Cornell box.
inline constexpr int kLowDiscrepancyDims = 10;
// The generator of R_d (Roberts 2018): alpha_i = phi_d^-i, i = 1..d, phi_d the positive root of
// x^(d+1) = x + 1 (phi_1 is the golden ratio), as 64-bit fractions: point n of the sequence is the
// fractional part of n alpha, i.e. n * alpha_i mod 2^64, exact in unsigned arithmetic.
inline const std::uint64_t* kroneckerAlphas() {
  static const auto alphas = [] {
    long double phi = 2.0L;
    for (int it = 0; it < 64; ++it) {  // Newton on x^(d+1) - x - 1
      long double p = 1.0L;
      for (int k = 0; k < kLowDiscrepancyDims; ++k) p *= phi;  // phi^d
      phi -= (p * phi - phi - 1.0L) / ((kLowDiscrepancyDims + 1) * p - 1.0L);
    }
    struct { std::uint64_t a[kLowDiscrepancyDims]; } out{};
    long double inv = 1.0L;
    for (int i = 0; i < kLowDiscrepancyDims; ++i) {
      inv /= phi;
      const long double frac = inv - static_cast<long double>(static_cast<std::uint64_t>(inv));
      out.a[i] = static_cast<std::uint64_t>(frac * 18446744073709551616.0L);  // * 2^64
    }
    return out;
  }();
  return alphas.a;
}

struct Sampler {
  std::uint64_t key = 0;
  std::uint64_t dimension = 0;
  // lowDiscrepancy(): the first kLowDiscrepancyDims values are point `index` of R_10, shifted by a
  // random vector of the seed (Cranley-Patterson rotation), instead of hashes.
  std::uint64_t index = 0, shiftKey = 0;
  bool kronecker = false;
  // stream: a pixel or a photon index; sample: the sample within it.
  Sampler(std::uint64_t stream, std::uint64_t sample, std::uint64_t seed)
      : key(splitMix64(splitMix64(splitMix64(seed) ^ stream) ^ (sample * 0xD1B54A32D192ED03ull))) {}
  // Stream `index` of a set whose streams are stratified together: the first kLowDiscrepancyDims
  // dimensions of streams 0, 1, 2, ... are a randomly shifted Kronecker sequence R_10, so any prefix of
  // the set covers those dimensions' unit cube evenly (each value, hence each stream, is still uniform
  // on [0, 1): the shift is uniform); the other dimensions are hashes as in the constructor above.
  // Streams remain independent of the number of streams and of threads: stream i of m is stream i of
  // m + m'.
  static Sampler lowDiscrepancy(std::uint64_t index, std::uint64_t seed) {
    Sampler s(index, 0, seed);
    s.index = index;
    s.shiftKey = splitMix64(seed ^ 0x4B726F6E65636B65ull);  // "Kronecke"
    s.kronecker = true;
    return s;
  }
  float next() {
    ++dimension;
    if (kronecker && dimension <= static_cast<std::uint64_t>(kLowDiscrepancyDims)) {
      const std::uint64_t shift = splitMix64(shiftKey ^ (dimension * 0xA0761D6478BD642Full));
      const std::uint64_t x = shift + index * kroneckerAlphas()[dimension - 1];  // mod 2^64
      return static_cast<float>(x >> 40) * 0x1p-24f;  // [0, 1)
    }
    const std::uint64_t h = splitMix64(key ^ (dimension * 0xA0761D6478BD642Full));
    return static_cast<float>(h >> 40) * 0x1p-24f;  // [0, 1)
  }
  glm::vec2 next2() { const float a = next(); return {a, next()}; }
};

}  // namespace radiant::rt
