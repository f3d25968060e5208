#include <iostream>

#include "client/Cli.h"

namespace radiant::client {

namespace {

int runInfo(const GlobalOptions& g, bool asJson) {
  HttpClient http(g.server, g.token);
  const nlohmann::json info = HttpClient::expectOk(http.get("/v1/info")).json();
  if (asJson) {
    std::cout << info.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << info.value("name", "?") << " " << info.value("version", "?") << " at " << g.server << "\n";
  if (info["device"].is_object())
    std::cout << "device: " << info["device"].value("renderer", "?") << " (" << info["device"].value("vendor", "?")
              << ", OpenGL " << info["device"].value("version", "?") << ")\n";
  else
    std::cout << "device: not ready\n";
  const auto& l = info["limits"];
  std::cout << "limits: " << l.value("max_width", 0) << "x" << l.value("max_height", 0) << " px, "
            << l.value("max_samples", 0) << " samples, queue " << l.value("max_queue", 0) << ", body "
            << l.value("max_body_bytes", 0) << " bytes\n";
  std::cout << "techniques:\n";
  for (const auto& t : info["techniques"]) {
    std::cout << "  " << t.value("name", "?") << (t.value("available", true) ? "" : " (not available)") << ": "
              << t.value("description", "") << "\n";
    for (const auto& [name, p] : t["params"].items()) {
      std::cout << "    " << name << " (" << p.value("type", "?");
      if (p.contains("minimum") || p.contains("maximum"))
        std::cout << " " << (p.contains("minimum") ? p["minimum"].dump() : "") << ".."
                  << (p.contains("maximum") ? p["maximum"].dump() : "");
      std::cout << ", default " << p["default"].dump() << "): " << p.value("description", "") << "\n";
    }
  }
  return kExitOk;
}

int runScenes(const GlobalOptions& g, bool asJson) {
  HttpClient http(g.server, g.token);
  const nlohmann::json s = HttpClient::expectOk(http.get("/v1/scenes")).json();
  if (asJson) {
    std::cout << s.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << "built-in:\n";
  for (const auto& b : s["builtins"]) std::cout << "  " << b.value("name", "?") << "  " << b.value("digest", "") << "\n";
  std::cout << "uploaded:\n";
  for (const auto& u : s["uploaded"])
    std::cout << "  " << u.value("digest", "?") << "  " << u.value("format", "") << "  " << u.value("bytes", 0) << " bytes\n";
  return kExitOk;
}

}  // namespace

void addInfoCommands(CLI::App& root, const GlobalOptions& g, Action& action) {
  auto infoJson = std::make_shared<bool>(false), scenesJson = std::make_shared<bool>(false);
  CLI::App* info = root.add_subcommand("info", "server version, device, limits, techniques and their parameters");
  info->add_flag("--json", *infoJson, "print GET /v1/info as it came");
  info->callback([&g, &action, infoJson] { action = [&g, infoJson] { return runInfo(g, *infoJson); }; });
  CLI::App* scenes = root.add_subcommand("scenes", "built-in and uploaded scenes");
  scenes->add_flag("--json", *scenesJson, "print GET /v1/scenes as it came");
  scenes->callback([&g, &action, scenesJson] { action = [&g, scenesJson] { return runScenes(g, *scenesJson); }; });
}

}  // namespace radiant::client
