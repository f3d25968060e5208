#pragma once
// The frame's own scene counts for the preset table's cost models (api::SceneCounts, api/Presets.h):
// the particles of the scene's and the request's systems, which every media technique scales with. The
// techniques add their own variables (Technique::addCostCounts: light_volumes' beams, specular's
// objects); FramePlanner's costCounts() assembles both, the Renderer passes them to the budget chooser
// and reports them in stats.scene.counts (where bench/presets.py reads them for the fit).
#include <vector>

#include "api/Media.h"
#include "api/Presets.h"
#include "renderer/scene/Scene.h"

namespace radiant {

// `media`: the request's particle systems, added to the scene's own (as mediaFeatures does).
api::SceneCounts sceneCostCounts(const Scene& scene, const std::vector<api::ParticleSystem>& media);

}  // namespace radiant
