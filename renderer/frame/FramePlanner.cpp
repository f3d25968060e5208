#include "renderer/frame/FramePlanner.h"

#include <algorithm>
#include <set>
#include <stdexcept>

#include "api/Aovs.h"
#include "api/Presets.h"
#include "renderer/scene/CostCounts.h"

namespace radiant {

// Accumulate AOVs (beauty) exist in every frame: passes add into them, none owns them (api/Aovs.cpp).
bool isFrameAov(const std::string& aov) {
  const api::AovInfo* a = api::findAov(aov);
  return a && a->blend == api::AovBlend::Accumulate;
}

std::vector<ResourceAccess> declaredAccess(const TechniqueInfo& info) {
  std::vector<ResourceAccess> out;
  for (const auto& in : info.inputs) out.push_back({in, Access::Read});
  for (const auto& in : info.optionalInputs) out.push_back({in, Access::Read});
  for (const auto& o : info.outputs)
    out.push_back({o, std::count(info.prepareOutputs.begin(), info.prepareOutputs.end(), o) ? Access::WriteInPrepare
                                                                                              : Access::Write});
  if (info.addsToBeauty)
    for (const api::AovInfo& a : api::aovTable())
      if (a.blend == api::AovBlend::Accumulate) out.push_back({a.resource, Access::Accumulate, info.beautyBlend});
  return out;
}

std::set<std::string> sharedResources(const std::vector<Technique*>& techniques) {
  std::set<std::string> names{kEnvironmentMap};
  for (const Technique* t : techniques) names.insert(t->info().outputs.begin(), t->info().outputs.end());
  for (const api::AovInfo& a : api::aovTable())
    if (!a.resource.empty()) names.insert(a.resource);
  return names;
}

std::string undeclaredWrite(const TechniqueInfo& info, const std::set<std::string>& written) {
  for (const std::string& name : written) {
    if (std::find(info.outputs.begin(), info.outputs.end(), name) != info.outputs.end()) continue;
    if (info.addsToBeauty && isFrameAov(name)) continue;
    return name;
  }
  return {};
}

api::SceneCounts costCounts(const std::vector<Technique*>& techniques, const Scene& scene,
                            const std::vector<api::ParticleSystem>& media) {
  api::SceneCounts counts = sceneCostCounts(scene, media);
  for (const Technique* t : techniques) t->addCostCounts(scene, counts);
  return counts;
}

std::set<int> shadowMapExclusions(const std::vector<Technique*>& passes, const std::vector<Params>& params,
                                  const Scene& scene) {
  std::set<int> out;
  for (std::size_t i = 0; i < passes.size(); ++i)
    for (int m : passes[i]->shadowMapExclusions(scene, params.at(i))) out.insert(m);
  return out;
}

std::vector<Technique*> executionOrder(const std::vector<Technique*>& planned) {
  const std::size_t n = planned.size();
  std::vector<std::set<std::size_t>> after(n);  // after[b]: the passes b must run after
  auto reads = [](const TechniqueInfo& i, const std::string& name) {
    return std::count(i.inputs.begin(), i.inputs.end(), name) + std::count(i.optionalInputs.begin(), i.optionalInputs.end(), name) > 0;
  };
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      if (a == b) continue;
      const TechniqueInfo& pa = planned[a]->info();
      const TechniqueInfo& pb = planned[b]->info();
      for (const std::string& out : pa.outputs)
        if (reads(pb, out) && !std::count(pa.prepareOutputs.begin(), pa.prepareOutputs.end(), out)) after[b].insert(a);
      if (pa.addsToBeauty && pb.addsToBeauty && pa.beautyBlend < pb.beautyBlend) after[b].insert(a);
    }
  // Kahn's algorithm, taking the first ready pass in registry order each time.
  std::vector<Technique*> order;
  std::vector<bool> done(n, false);
  while (order.size() < n) {
    std::size_t next = n;
    for (std::size_t b = 0; b < n && next == n; ++b)
      if (!done[b] && std::all_of(after[b].begin(), after[b].end(), [&](std::size_t a) { return done[a]; })) next = b;
    if (next == n) {
      std::string cycle;
      for (std::size_t b = 0; b < n; ++b)
        if (!done[b]) cycle += (cycle.empty() ? "" : ", ") + planned[b]->info().name;
      throw std::logic_error("frame graph: the declarations of " + cycle +
                             " order them in a cycle (each reads what another writes, or their beauty_blend)");
    }
    done[next] = true;
    order.push_back(planned[next]);
  }
  return order;
}

const std::vector<OwnershipRow>& ownershipPolicy() {
  static const std::vector<OwnershipRow> rows = {
      // The sky's glossy reflection: direct's prefiltered environment (image-based lighting) when it runs.
      {"L(sky)GE", {"direct", "photon_gi"}},
      // Indirect diffuse light: env_diffuse's cube maps where it is planned (photon_gi, which requires
      // the class, then goes: its photons would carry it whatever owned it).
      {"LD+DE", {"env_diffuse", "photon_gi"}},
      // The sky's diffuse light: photon_gi's photons (visibility at any distance) ahead of ambient
      // occlusion's (visibility within its radius).
      {"L(sky)DE", {"photon_gi", "ambient_occlusion"}},
      // Caustics: the caustic triangles (chapter 6), then photons, then light volumes (claims_when_named:
      // first when the request names it).
      {"LS+DE", {"caustics", "photon_gi", "light_volumes"}},
      // Participating media, one technique per frame (exclusive): spherical billboards by default.
      {"media", {"spherical_billboards", "depth_impostors", "illumination_network"}},
  };
  return rows;
}

namespace {

// Where `technique` stands in the policy for `cls`: its place in the row, else after the row.
std::size_t policyRank(std::string_view cls, std::string_view technique) {
  for (const OwnershipRow& row : ownershipPolicy())
    if (row.lightPath == cls) {
      const auto it = std::find(row.order.begin(), row.order.end(), technique);
      return it == row.order.end() ? row.order.size() : static_cast<std::size_t>(it - row.order.begin());
    }
  return 0;
}

// True when `a` owns `cls` ahead of `b`: a named claims_when_named technique first, then the policy's
// order, then the names.
bool ownsBefore(std::string_view cls, const TechniqueInfo& a, const TechniqueInfo& b, const api::RenderRequest& request) {
  auto claims = [&](const TechniqueInfo& i) { return i.claimsWhenNamed && request.passes.count(i.name) != 0; };
  if (claims(a) != claims(b)) return claims(a);
  const std::size_t ra = policyRank(cls, a.name), rb = policyRank(cls, b.name);
  if (ra != rb) return ra < rb;
  return a.name < b.name;
}

}  // namespace

FramePlan planFrame(const std::vector<Technique*>& techniques, const Scene& scene,
                    const api::RenderRequest& request) {
  std::map<std::string, Technique*> byName;
  std::map<std::string, Technique*> producerOf;
  for (Technique* t : techniques) {
    byName[t->info().name] = t;
    for (const auto& out : t->info().outputs) producerOf.emplace(out, t);
  }

  std::set<std::string> wantedOutputs;
  for (std::size_t i = 0; i < request.outputs.size(); ++i)
    for (std::size_t k = 0; k < request.outputs[i].aovs.size(); ++k) {
      const std::string& aov = request.outputs[i].aovs[k];
      if (!api::findAov(aov) || (!isFrameAov(aov) && !producerOf.count(aov)))
        throw api::ApiError(422, "unknown-aov", "Unknown AOV",
                            "no technique produces the AOV '" + aov + "'",
                            "/outputs/" + std::to_string(i) + "/aovs/" + std::to_string(k));
      wantedOutputs.insert(aov);
    }
  if (request.compare) wantedOutputs.insert(request.compare->aov);
  const bool beautyWanted = true;  // every frame has a beauty image

  std::set<Technique*> wanted;
  for (const auto& [name, params] : request.passes) {
    auto it = byName.find(name);
    if (it == byName.end())
      throw api::ApiError(422, "unknown-pass", "Unknown pass", "no technique is named '" + name + "'",
                          "/passes/" + name);
    wanted.insert(it->second);
  }
  // Two named techniques of which one must own a light-path class that the other supplies (two media
  // techniques; photon_gi and env_diffuse, LD+DE): the request is contradictory, whatever the scene.
  // The pointer names the one the ownership policy ranks later. Only the planner reports such conflicts.
  auto named = [&](const TechniqueInfo& info) {
    return request.passes.count(info.name) != 0 && !request.disabledPasses.count(info.name);
  };
  // The classes a technique must own to run: an exclusive one's are all of its classes.
  auto required = [](const TechniqueInfo& info) -> const std::vector<std::string>& {
    return info.exclusive ? info.lightPaths : info.requiredPaths;
  };
  for (std::size_t a = 0; a < techniques.size(); ++a)
    for (std::size_t b = 0; b < techniques.size(); ++b) {
      const TechniqueInfo& need = techniques[a]->info();
      const TechniqueInfo& other = techniques[b]->info();
      if (a == b || !named(need) || !named(other)) continue;
      for (const auto& cls : required(need))
        if (std::find(other.lightPaths.begin(), other.lightPaths.end(), cls) != other.lightPaths.end()) {
          const bool needFirst = policyRank(cls, need.name) != policyRank(cls, other.name)
                                     ? policyRank(cls, need.name) < policyRank(cls, other.name)
                                     : need.name < other.name;
          const TechniqueInfo& first = needFirst ? need : other;
          const TechniqueInfo& later = needFirst ? other : need;
          throw api::ApiError(422, "conflicting-passes", "Conflicting passes",
                              "passes names both " + first.name + " and " + later.name + ", which both supply '" +
                                  cls + "', and " + need.name +
                                  " must own it to run: one technique per frame owns it (name one of them)",
                              "/passes/" + later.name);
        }
    }
  for (Technique* t : techniques) {
    const auto& info = t->info();
    if (beautyWanted && info.onByDefault) wanted.insert(t);
    for (const auto& out : info.outputs)
      if (wantedOutputs.count(out)) wanted.insert(t);
  }

  FramePlan plan;
  // Evaluate requirements once, then close over inputs until nothing changes.
  std::map<Technique*, Requirements> req;
  auto requirement = [&](Technique* t) -> const Requirements& {
    auto it = req.find(t);
    if (it == req.end())
      it = req.emplace(t, request.disabledPasses.count(t->info().name)
                              ? Requirements::skip("turned off by the request (passes." + t->info().name + " = false)")
                              : t->requirements(scene, request))
               .first;
    return it->second;
  };
  std::set<Technique*> keep;
  bool changed = true;
  while (changed) {
    changed = false;
    for (Technique* t : techniques) {
      if (!wanted.count(t) || keep.count(t) || plan.skipped.count(t->info().name)) continue;
      const Requirements& r = requirement(t);
      if (!r.run) {
        plan.skipped[t->info().name] = r.reason;
        changed = true;
        continue;
      }
      std::string missing;
      for (const auto& in : t->info().inputs) {
        auto p = producerOf.find(in);
        if (p == producerOf.end()) { missing = "needs '" + in + "', which no technique produces"; break; }
        if (!requirement(p->second).run) {
          missing = "needs '" + in + "', which " + p->second->info().name +
                    " does not produce: " + requirement(p->second).reason;
          break;
        }
        if (!wanted.count(p->second)) { wanted.insert(p->second); changed = true; }
      }
      if (!missing.empty()) { plan.skipped[t->info().name] = missing; changed = true; continue; }
      for (const auto& in : t->info().optionalInputs) {
        auto p = producerOf.find(in);
        if (p != producerOf.end() && !wanted.count(p->second)) { wanted.insert(p->second); changed = true; }
      }
      keep.insert(t);
      changed = true;
    }
  }
  for (Technique* t : techniques)
    if (keep.count(t)) plan.passes.push_back(t);
  plan.passes = executionOrder(plan.passes);
  // Every light path is counted once: each class goes to the planned technique the ownership policy
  // puts first (ownsBefore: a named claimsWhenNamed technique, then the policy's row). A technique
  // that does not own a class it requires (TechniqueInfo::requiredPaths; an exclusive one: all of its
  // classes) is dropped, and the classes are handed out again without it, so that what it would have
  // supplied goes to the next claimant (photon_gi's sky light to ambient_occlusion when env_diffuse
  // owns LD+DE). A pass that needs what a dropped one produces goes too.
  for (bool dropped = true; dropped;) {
    dropped = false;
    plan.lightPaths.clear();
    std::map<std::string, const TechniqueInfo*> owner;
    for (Technique* t : plan.passes)
      for (const auto& cls : t->info().lightPaths) {
        const TechniqueInfo*& o = owner[cls];
        if (!o || ownsBefore(cls, t->info(), *o, request)) o = &t->info();
      }
    for (const auto& [cls, o] : owner) plan.lightPaths[cls] = o->name;
    for (auto it = plan.passes.begin(); it != plan.passes.end() && !dropped; ++it) {
      const TechniqueInfo& info = (*it)->info();
      for (const auto& cls : required(info))
        if (const std::string& owner = plan.lightPaths.at(cls); owner != info.name) {
          plan.skipped[info.name] = cls + " is owned by " + owner;
          plan.passes.erase(it);
          dropped = true;
          break;
        }
    }
    for (bool lost = dropped; lost;) {
      lost = false;
      for (auto it = plan.passes.begin(); it != plan.passes.end() && !lost; ++it)
        for (const auto& in : (*it)->info().inputs) {
          const auto p = producerOf.find(in);
          if (p == producerOf.end() || !plan.skipped.count(p->second->info().name)) continue;
          plan.skipped[(*it)->info().name] = "needs '" + in + "', which " + p->second->info().name +
                                             " does not produce: " + plan.skipped.at(p->second->info().name);
          plan.passes.erase(it);
          lost = true;
          break;
        }
    }
  }
  // The frame graph culls what nothing reads (Filament's FrameGraph): a planned pass that the request
  // does not name, none of whose outputs the request asks for or a kept pass reads, and that adds
  // nothing to beauty this frame (it supplies light-path classes and owns none of them) is dropped,
  // saying so; then its producers are weighed again. ambient_occlusion beside photon_gi, which owns
  // the sky's first bounce: it would compute an AO image nobody sees.
  for (bool culled = true; culled;) {
    culled = false;
    for (auto it = plan.passes.begin(); it != plan.passes.end(); ++it) {
      const TechniqueInfo& info = (*it)->info();
      if (named(info)) continue;
      std::string owners;
      bool composes = info.addsToBeauty && info.lightPaths.empty();  // transparency: no class to own
      for (const auto& cls : info.lightPaths) {
        const auto o = plan.lightPaths.find(cls);
        if (o == plan.lightPaths.end()) continue;
        if (o->second == info.name) composes = true;
        else owners += (owners.empty() ? "" : ", ") + cls + " by " + o->second;
      }
      if (composes) continue;
      bool read = false;
      std::string outputs;
      for (const auto& out : info.outputs) {
        outputs += (outputs.empty() ? "" : ", ") + out;
        read = read || wantedOutputs.count(out) != 0;
        for (Technique* other : plan.passes) {
          if (other == *it) continue;
          const TechniqueInfo& o = other->info();
          read = read || std::count(o.inputs.begin(), o.inputs.end(), out) ||
                 std::count(o.optionalInputs.begin(), o.optionalInputs.end(), out);
        }
      }
      if (read) continue;
      plan.skipped[info.name] = "culled: nothing in the frame reads what it writes (" +
                                (outputs.empty() ? std::string("nothing") : outputs) + ")" +
                                (owners.empty() ? std::string() : " and its light paths are owned (" + owners + ")");
      plan.passes.erase(it);
      culled = true;
      break;
    }
  }
  plan.owned.clear();
  for (Technique* t : plan.passes) plan.owned[t->info().name] = 0;
  for (const auto& [cls, name] : plan.lightPaths) plan.owned[name] |= api::lightPathBit(cls);
  return plan;
}

}  // namespace radiant
