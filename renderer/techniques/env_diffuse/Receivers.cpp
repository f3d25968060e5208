#include "renderer/techniques/env_diffuse/Receivers.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "api/Types.h"

namespace radiant::env_diffuse {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\n") - b + 1);
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep))
    if (!trim(item).empty()) out.push_back(trim(item));
  return out;
}

// -1: no flag, 0: false, 1: true.
int receiverFlag(const MeshInstance& m) {
  if (m.extrasJson.empty()) return -1;
  const nlohmann::json j = nlohmann::json::parse(m.extrasJson, nullptr, false);
  if (!j.is_object()) return -1;
  auto it = j.find("radiant_receiver");
  if (it == j.end() || !it->is_boolean()) return -1;
  return it->get<bool>() ? 1 : 0;
}

}  // namespace

std::vector<Receiver> selectReceivers(const Scene& scene, const std::string& receiversParam,
                                      const std::string& referencePointsParam) {
  // Nodes by name, in scene order.
  std::vector<Receiver> nodes;
  std::map<std::string, std::size_t> byName;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const MeshInstance& m = scene.meshes[i];
    auto [it, added] = byName.emplace(m.name, nodes.size());
    if (added) nodes.push_back(Receiver{m.name, {}, Bounds{}, {}});
    Receiver& r = nodes[it->second];
    r.meshes.push_back(static_cast<int>(i));
    r.bounds.extend(m.bounds);
  }

  std::vector<Receiver> out;
  const std::vector<std::string> named = split(receiversParam, ',');
  if (!named.empty()) {
    if (static_cast<int>(named.size()) > kMaxReceivers)
      throw api::ApiError(422, "invalid-value", "Too many receivers",
                          "at most " + std::to_string(kMaxReceivers) + " receivers, got " + std::to_string(named.size()),
                          "/passes/env_diffuse/receivers");
    for (const std::string& n : named) {
      auto it = byName.find(n);
      if (it == byName.end())
        throw api::ApiError(422, "invalid-value", "Unknown receiver", "the scene has no mesh node named '" + n + "'",
                            "/passes/env_diffuse/receivers");
      if (std::none_of(out.begin(), out.end(), [&](const Receiver& r) { return r.name == n; }))
        out.push_back(nodes[it->second]);
    }
  } else {
    bool anyFlag = false;
    std::map<std::string, bool> flagged;
    for (const MeshInstance& m : scene.meshes) {
      const int f = receiverFlag(m);
      if (f >= 0) {
        anyFlag = true;
        flagged[m.name] = flagged[m.name] || f == 1;
      }
    }
    if (anyFlag) {
      for (const Receiver& r : nodes)
        if (flagged.count(r.name) && flagged[r.name]) out.push_back(r);
    } else {
      const float sceneDiagonal = glm::length(scene.features.bounds.extent());
      std::vector<Receiver> candidates;
      for (const Receiver& r : nodes) {
        const glm::vec3 e = r.bounds.extent();
        const float lo = std::min({e.x, e.y, e.z}), hi = std::max({e.x, e.y, e.z});
        if (hi > 0.f && lo >= kCompactness * hi && glm::length(e) <= kMaxSceneFraction * sceneDiagonal)
          candidates.push_back(r);
      }
      std::stable_sort(candidates.begin(), candidates.end(), [](const Receiver& a, const Receiver& b) {
        return glm::length(a.bounds.extent()) < glm::length(b.bounds.extent());
      });
      if (static_cast<int>(candidates.size()) > kMaxReceivers) candidates.resize(kMaxReceivers);
      out = std::move(candidates);
    }
  }
  for (Receiver& r : out) r.referencePoint = r.bounds.center();

  for (const std::string& entry : split(referencePointsParam, ';')) {
    const auto eq = entry.find('=');
    const std::string name = trim(entry.substr(0, eq));
    std::vector<std::string> xyz = eq == std::string::npos ? std::vector<std::string>{} : split(entry.substr(eq + 1), ',');
    glm::vec3 p;
    bool ok = xyz.size() == 3;
    for (int k = 0; ok && k < 3; ++k) {
      try {
        std::size_t used = 0;
        p[k] = std::stof(xyz[k], &used);
        ok = used == xyz[k].size() && std::isfinite(p[k]);
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok)
      throw api::ApiError(422, "invalid-value", "Malformed reference point",
                          "expected 'node=x,y,z', got '" + entry + "'", "/passes/env_diffuse/reference_points");
    auto it = std::find_if(out.begin(), out.end(), [&](const Receiver& r) { return r.name == name; });
    if (it == out.end())
      throw api::ApiError(422, "invalid-value", "Unknown receiver",
                          "'" + name + "' is not a receiver of this request", "/passes/env_diffuse/reference_points");
    it->referencePoint = p;
  }
  return out;
}

}  // namespace radiant::env_diffuse
