#pragma once
// View transforms: scene-linear RGB radiance (times 2^exposure) to display-linear RGB in [0, 1], which
// the PNG writer then encodes with the sRGB transfer (render_request.json "tone_map"; docs/API.md,
// "View transforms"). The one place these operators live; each is the published formula, in double:
//
// - Standard: clamp(v, 0, 1), per channel (what PNG output always was).
// - Aces: three.js ACESFilmicToneMapping (src/renderers/shaders/ShaderChunk/tonemapping_pars_fragment),
//   the operator of model-viewer's render-fidelity goldens: v / 0.6 (three.js' brighter viewing
//   environment, its issue #19621), the sRGB -> AP1 (RRT_SAT) input matrix, Stephen Hill's RRT + ODT fit
//   f(x) = (x (x + 0.0245786) - 0.000090537) / (x (0.983729 x + 0.4329510) + 0.238081), the ODT_SAT ->
//   sRGB output matrix, clamp to [0, 1].
// - KhronosPbrNeutral: the Khronos PBR Neutral tone mapper (Khronos 3D Commerce, 2024), as the Khronos
//   specification and three.js NeutralToneMapping state it: startCompression = 0.8 - 0.04, desaturation
//   0.15; colours whose largest channel stays below startCompression pass through less a small offset.
// - Agx: three.js AgXToneMapping (after Filament's version of Troy Sobotka's AgX, Blender's default
//   view): linear sRGB -> Rec.2020, the AgX inset matrix, log2 encoding over [-12.47393, 4.026069] EV,
//   the 6th-order polynomial approximation of the default contrast sigmoid, the outset matrix, a 2.2
//   power, Rec.2020 -> linear sRGB, clamp to [0, 1].
//
// Every operator maps 0 to 0, never returns NaN or Inf (NaN inputs count as 0, +-Inf as the largest
// float), and clamps its result to [0, 1].
#include <glm/glm.hpp>

#include "api/Types.h"

namespace radiant::io {

// Display-linear RGB in [0, 1] of the scene-linear `linear` times 2^exposureEV under `op`.
glm::vec3 toneMap(api::ToneMap op, glm::vec3 linear, float exposureEV);

// The operators on an already exposed colour (toneMap above applies 2^exposureEV first).
glm::dvec3 toneMapAces(glm::dvec3 v);
glm::dvec3 toneMapKhronosPbrNeutral(glm::dvec3 v);
glm::dvec3 toneMapAgx(glm::dvec3 v);

}  // namespace radiant::io
