#pragma once
// An edge-aware à-trous wavelet filter for the frame's noisy indirect light (issue 32; Dammertz et al.
// 2010, "Edge-avoiding à-trous wavelet transform for fast global illumination filtering", with the
// variance-guided luminance weight of SVGF, Schied et al. 2017, but spatial only: a frame has no
// history). shaders/common/denoise_atrous.comp.
//
// Input: radiance (RGBA32F, the frame's size) and the G-buffer of the same frame. The radiance is
// demodulated by the base colour (floored at kMinAlbedo) before filtering and re-modulated after, so
// texture detail is never blurred, only the illumination. `iterations` passes of a 5x5 B3-spline kernel
// with holes (step 1, 2, 4, ...: a pass of step s reaches 2 s pixels, so 3 passes reach 29 across) weight each tap by
//   plane:     exp(-|n_p . (x_q - x_p)| / (sigma_plane step pixel_p))   (pixel_p: the world size of a
//              pixel at p's depth; coplanar taps pass at any distance and viewing angle)
//   normal:    max(0, n_p . n_q)^sigma_normal
//   luminance: exp(-|l_p - l_q| / (sigma_luminance relative_noise (l_p + l_q) / 2 + eps))
// where relative_noise is the estimator's own per-pixel relative standard deviation (photon_gi: 0.757/C
// for the biweight kernel, docs/TECHNIQUES.md): illumination steps larger than a few noise widths
// survive. Pixels without geometry keep their value. Output: finite (a tap that would not be is left
// out, a pixel whose result is not finite keeps its input).
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/FrameView.h"

namespace radiant::denoise {

struct Settings {
  int iterations = 3;
  // The first pass's step in the frame's samples (then 2x, 4x, ...): the supersampling factor k, so
  // that the steps count output pixels. photon_gi's estimate of a supersampled frame is smooth over k
  // samples (its gather block is k gather_step samples wide), and a first pass at step 1 filtered
  // almost nothing: two passes of steps k, 2k give three passes' (1, 2, 4) error within 0.6%, or less,
  // for two thirds of the cost (the Cornell boxes at 64-256 px, k = 4, 4, 2: docs/PERFORMANCE.md,
  // "Denoiser").
  int baseStep = 1;
  float relativeNoise = 0.1f;    // per-pixel relative standard deviation of the input
  float sigmaLuminance = 1.5f;   // in noise widths (chosen, not swept: no figure for it is measured)
  float sigmaNormal = 64.f;     // cosine power
  float sigmaPlane = 1.f;       // in pixel footprints times the step
};

inline constexpr float kMinAlbedo = 0.02f;

// Declares the two scratch textures (prepare(): execute allocates nothing).
void declareResources(FrameResources& res);
// Filters `in` (w x h, RGBA) with the G-buffer ("gbuffer_position", "normal", "albedo"); the result is
// in the returned scratch texture (RGBA32F, alpha 1). GL only: call from execute().
gl::Texture& run(FrameResources& res, gl::ShaderLibrary& shaders, const FrameView& view, const gl::Texture& in,
                 const Settings& settings);

}  // namespace radiant::denoise
