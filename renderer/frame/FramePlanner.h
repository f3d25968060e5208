#pragma once
// Decides which passes run for a request (ARCHITECTURE.md, "A technique"). It starts from the outputs
// the request asks for and keeps the passes that produce them, plus the passes the request names and
// the on-by-default beauty contributors; then it pulls in the producers of their inputs. A pass whose
// requirements() says skip is dropped with its reason; a pass whose required input has no producer is
// dropped with "needs <input>, which <producer> did not produce: <reason>". Light-path classes
// (api/LightPaths.h) go to one technique each by the ownership policy below, not by registry order; a
// technique that does not own a class it requires (requiredPaths; an exclusive one: all of its
// classes, one media technique per frame) is dropped with "<class> is owned by <owner>" and the
// classes are handed out again. Last, the frame graph culls a pass that the request does not name,
// whose outputs nothing asks for or reads, and that owns none of the classes it could add to beauty
// ("culled: ...": ambient_occlusion beside photon_gi).
#include <map>
#include <set>
#include <string>
#include <vector>

#include "api/LightPaths.h"
#include "api/Types.h"
#include "renderer/frame/FrameResources.h"
#include "renderer/frame/Technique.h"

namespace radiant {

struct FramePlan {
  std::vector<Technique*> passes;              // in execution order (executionOrder)
  std::map<std::string, std::string> skipped;  // pass name -> reason
  std::map<std::string, std::string> lightPaths;  // light-path class -> the technique that owns it
  // The classes each planned technique owns (api::LightPathMask bits of lightPaths).
  std::map<std::string, api::LightPathMask> owned;
};

// The one ownership policy: for each light-path class that several techniques can supply, who owns it
// when several of them are planned, first to last. A technique with claims_when_named that the request
// names goes ahead of the list for its classes. A class not listed (one supplier), or a supplier a row
// does not list, is ranked after the listed ones by name; `LightPathOwnership.EveryContestedClass...`
// holds the real descriptors to a row for every class two of them supply.
struct OwnershipRow {
  std::string_view lightPath;
  std::vector<std::string_view> order;
};
const std::vector<OwnershipRow>& ownershipPolicy();

// The cost models' scene variables for this frame (api::SceneCounts): the scene's and `media`'s
// particles (sceneCostCounts), then each technique's own (Technique::addCostCounts), whether or not it
// is planned (the budget chooser weighs the planned ones).
api::SceneCounts costCounts(const std::vector<Technique*>& techniques, const Scene& scene,
                            const std::vector<api::ParticleSystem>& media);

// AOVs that are not a technique's output but exist in every frame (the AOV table's accumulate AOVs).
bool isFrameAov(const std::string& aov);

// The frame resource that holds the request's environment map (renderer/frame/FrameAllocation.h): the
// Renderer declares and uploads it, passes that show the environment read it (an optional input).
inline constexpr const char* kEnvironmentMap = "environment_map";

// What a pass declares it touches, from its TechniqueInfo: inputs and optional inputs Read, outputs
// Write, and the accumulate AOVs (beauty) Accumulate with its beautyBlend when it addsToBeauty.
// FrameResources enforces it.
std::vector<ResourceAccess> declaredAccess(const TechniqueInfo& info);

// The names passes exchange, whose access FrameResources checks: every technique's outputs, every AOV
// table resource and the frame resources.
std::set<std::string> sharedResources(const std::vector<Technique*>& techniques);

// The first of `written` (what a pass marked written) that its info does not declare: neither one of
// its outputs nor, when it addsToBeauty, an accumulate AOV. "" when every write is declared. The
// Renderer fails the frame with std::logic_error on one.
std::string undeclaredWrite(const TechniqueInfo& info, const std::set<std::string>& written);

// The meshes the shadow maps leave out when `passes` run with `params` (one per pass): the union of
// their Technique::shadowMapExclusions (FrameView::shadowMapExclusions).
std::set<int> shadowMapExclusions(const std::vector<Technique*>& passes, const std::vector<Params>& params,
                                  const Scene& scene);

// The frame graph's order (ARCHITECTURE.md, "The frame graph"): `planned` (in registry order) sorted so
// that every pass runs after
//   - the planned producers of what it reads (its inputs and optional inputs; not of what a producer
//     publishes in prepare(), TechniqueInfo::prepareOutputs: every prepare runs before any execute), and
//   - every beauty writer of an earlier BeautyBlend (Add, then Over, then Transmit).
// Among passes these declarations leave unordered, the registry's order decides (it fixes the order
// of beauty's floating-point sums, so a frame is reproducible bit for bit); no pass's result depends on
// it (tests FrameGraph.*). Throws std::logic_error naming the passes of a cycle.
std::vector<Technique*> executionOrder(const std::vector<Technique*>& planned);

// `techniques` is the registry (renderer/techniques/Registry.cpp): neither the passes planned, their
// order's constraints nor which technique owns a light-path class depend on its order.
// Throws api::ApiError (422) for a requested pass or AOV that no technique knows, and for a request
// that names two techniques of which one requires a light-path class the other supplies (pointer: the
// one the policy ranks later, /passes/<name>): the only place conflicts between passes are reported.
FramePlan planFrame(const std::vector<Technique*>& techniques, const Scene& scene,
                    const api::RenderRequest& request);

}  // namespace radiant
