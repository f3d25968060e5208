#pragma once
// The one interface every illumination pass implements (see ARCHITECTURE.md, "A technique").
// Adding a technique never touches another: it registers itself in renderer/techniques/Registry.cpp,
// declares itself (parameters, what it reads and writes, its AOVs and light-path classes) in its
// descriptor renderer/techniques/<name>/<name>.json, and its method in docs/techniques/<name>.md.

#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/Aovs.h"
#include "api/Types.h"
#include "renderer/frame/BeautyBlend.h"
#include "renderer/scene/Scene.h"

namespace radiant {
namespace api {
struct SceneCounts;  // api/Presets.h
}

class FrameResources;
struct FrameView;
struct PassContext;

struct TechniqueInfo {
  std::string name;         // as used in the API ("direct", "ambient_occlusion")
  std::string description;  // one line
  std::vector<std::string> inputs;    // resources it reads and cannot run without ("depth", "normal")
  std::vector<std::string> optionalInputs;  // resources it reads when present ("shadow_maps")
  std::vector<std::string> outputs;   // resources / AOVs it writes ("direct")
  bool addsToBeauty = false;  // composes its result into "beauty", as beautyBlend says
  bool onByDefault = false;   // wanted in every frame; requirements() then decides (e.g. AO: only with ambient light)
  // Light-path classes it can supply (ARCHITECTURE.md, "Every light path is counted once"), e.g.
  // "LD+DE". The planner gives each class to one planned technique, as its ownership policy says
  // (FramePlanner.h); a technique adds a class to beauty only when it owns it (FrameResources::owns).
  std::vector<std::string> lightPaths = {};
  // When the request names this technique, it owns its classes ahead of the policy's order (a request
  // that asks for light_volumes gets them even when caustics, ahead of it in the policy, also runs).
  bool claimsWhenNamed = false;
  // Its light-path classes admit one supplier per frame: when another planned technique owns one of
  // them, the planner drops this one (skipped: "<class> is owned by <owner>") instead of running it
  // beside the owner, and a request that names two exclusive techniques sharing a class is a 422. The
  // media techniques: each writes the media AOV and composes it into beauty (class "media").
  bool exclusive = false;
  // Classes it must own to run at all (beyond an exclusive technique's, which are all of its classes),
  // because its estimate cannot leave them out: photon_gi's photons carry LD+DE, so where env_diffuse owns that
  // class photon_gi is dropped ("LD+DE is owned by env_diffuse"), and a request naming both is a 422.
  std::vector<std::string> requiredPaths = {};
  BeautyBlend beautyBlend = BeautyBlend::Add;  // how it composes into beauty (renderer/frame/BeautyBlend.h)
  // Outputs it publishes in prepare() (photon_gi's photon grid): every prepare runs before any execute,
  // so a pass reading one in its execute() need not run after this one (FrameResources refuses a write
  // of one in execute()).
  std::vector<std::string> prepareOutputs = {};
};

// A technique's TechniqueInfo as its descriptor declares it (renderer/techniques/<name>/<name>.json,
// merged into the schema at build time): every info() returns this, so nothing of it is written twice.
// Throws std::logic_error for an undeclared name.
TechniqueInfo describedTechnique(std::string_view name);

// Run or skip, and the reason if skipped. The planner records the reason in the frame stats.
struct Requirements {
  bool run = true;
  std::string reason;
  static Requirements ok() { return {}; }
  static Requirements skip(std::string why) { return {false, std::move(why)}; }
};

// A technique's parameters, validated against its schema with every default filled in
// (api::techniqueParams), whether or not the request named the technique; given() tells the keys the
// request set itself (RenderRequest::explicitParams) from defaults and preset or budget choices, for a
// pass whose default adapts to the frame but must run an explicit value as asked (specular's
// cube_resolution).
class Params {
public:
  Params() : json_(nlohmann::json::object()) {}
  explicit Params(nlohmann::json j, std::set<std::string> given = {})
      : json_(j.is_object() ? std::move(j) : nlohmann::json::object()), given_(std::move(given)) {}
  bool given(const char* key) const { return given_.count(key) != 0; }
  // The value of `key`: the schema gives every parameter a default (renderer/techniques/*/*.json; tests
  // Schema.EveryTechniqueFileIsMergedWithDocumentedParams, Params.*), the one place it is written; a key
  // that is not there is a programmer error.
  template <class T>
  T get(const char* key) const {
    auto it = json_.find(key);
    if (it == json_.end() || it->is_null())
      throw std::logic_error(std::string("Params::get(\"") + key +
                             "\"): no value (a key the technique's schema does not declare, or Params not from "
                             "api::techniqueParams)");
    return it->get<T>();
  }
  const nlohmann::json& json() const { return json_; }
private:
  nlohmann::json json_;
  std::set<std::string> given_;
};

// A cache key (FrameResources::cached's inputs digest) from typed values: the fields of a technique's
// generated parameter struct that the entry depends on, counts, other keys. A JSON array of them
// (numbers written to round-trip, enums as their integers): naming the struct's fields instead of
// the schema's strings keeps a renamed or misspelt parameter from silently dropping out of the key.
template <class... T>
std::string cacheKey(const T&... values) {
  return nlohmann::json::array({nlohmann::json(values)...}).dump();
}

// What scores one of a technique's AOVs (ARCHITECTURE.md, "A technique owns its knowledge"): the
// parameters of the reference pass (renderer/techniques/reference/reference.json) that render its ground truth,
// e.g. {"aov": "ao", "ao_radius": 0.5, "ao_definition": "volumetric"}; null when the reference renderer
// has none (the compare block then refuses instead of scoring the AOV against something else). A
// "max_bounces" in it is the technique's own bounce range and wins over compare.max_bounces.
struct GroundTruth {
  nlohmann::json reference;
  bool exists() const { return reference.is_object(); }
  // The AOV table's reference mode for `aov` (api/Aovs.cpp), with the reference's defaults otherwise.
  static GroundTruth fromAovTable(const std::string& aov) {
    const api::AovInfo* a = api::findAov(aov);
    if (!a || a->groundTruth.empty()) return {};
    return {nlohmann::json{{"aov", a->groundTruth}}};
  }
};

class Technique {
public:
  virtual ~Technique() = default;
  // The ground truth of `aov` (one of info().outputs) for a frame run with `params` (the technique's
  // own, validated, defaults filled in). Techniques whose ground truth depends on their parameters
  // override it; the default is the AOV table's reference mode.
  virtual GroundTruth groundTruth(const Params& params, const std::string& aov) const {
    (void)params;
    return GroundTruth::fromAovTable(aov);
  }
  virtual const TechniqueInfo& info() const = 0;
  // Run or skip for this scene and request (scene.features summarises what it contains; the whole
  // scene is there for rules that need more, such as which nodes receive indirect light). Called by
  // the FramePlanner only.
  virtual Requirements requirements(const Scene& scene, const api::RenderRequest& request) const = 0;
  // What this request's parameters ask of this scene and view that no frame could render, found without
  // GL (an unknown receiver node, a network above its size limit, an exact sky too costly for the
  // frame's particles): throws api::ApiError 422 naming the parameter. Called before the job is queued
  // (Renderer::check, on radiantd's HTTP thread: keep it const and free of state; `view` is the
  // request's, at its own size, without the environment's lights, with the planned passes'
  // shadowMapExclusions) and at the frame's start with the frame's parameters and view, so prepare()
  // need not check the same again (but what depends on the environment's lights: shadow_maps).
  virtual void validate(const Scene& scene, const FrameView& view, const Params& params) const {
    (void)scene;
    (void)view;
    (void)params;
  }
  // Allocate or reuse resources; build or fetch cached derived data. No drawing here.
  virtual void prepare(const Scene& scene, const Params& params, FrameResources& resources) = 0;
  // The only place GL is issued. Must not allocate GL objects.
  virtual void execute(PassContext& context) = 0;
  // The cost models' scene variables this technique's model scales with (api::SceneCounts, fitted by
  // bench/presets.py against stats.scene.counts): light_volumes' beams, specular's objects. Computed
  // here, beside the code whose cost they count, for every technique of the registry before planning
  // the budget (FramePlanner's costCounts).
  virtual void addCostCounts(const Scene& scene, api::SceneCounts& counts) const {
    (void)scene;
    (void)counts;
  }
  // Meshes (Scene::meshes indices) to leave out of this frame's shadow maps because this pass supplies
  // their shadows itself (light_volumes' negative beams), so that the two never both apply. Called
  // before any prepare().
  virtual std::vector<int> shadowMapExclusions(const Scene&, const Params&) const { return {}; }
};

}  // namespace radiant
