#pragma once
// The scene counts the preset table's cost models scale with (api::SceneCounts, api/Presets.h): the one
// place that computes them. The Renderer passes them to the budget chooser and reports them in
// stats.scene.counts (where bench/presets.py reads them for the fit).
#include <vector>

#include "api/Media.h"
#include "api/Presets.h"
#include "renderer/scene/Scene.h"

namespace radiant {

// `media`: the request's particle systems, added to the scene's own (as mediaFeatures does).
api::SceneCounts sceneCostCounts(const Scene& scene, const std::vector<api::ParticleSystem>& media);

}  // namespace radiant
