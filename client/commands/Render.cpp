// radiant render: upload the scene if the server lacks it, render, download the frame.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <cmath>
#include <iostream>
#include <filesystem>
#include <set>
#include <thread>
#include <tuple>

#include <unistd.h>

#include "api/Sha256.h"
#include "client/Cli.h"

namespace radiant::client {

namespace {

constexpr const char* kFooter =
    "A .gltf that references .bin or image files is packed with them into one GLB before upload (only\n"
    "relative paths inside its folder). --camera takes any subset of its keys; the others keep the automatic\n"
    "framing. --request sends REQUEST.json with the other options applied on top. --asset PATH names a file\n"
    "under the daemon's --asset-root instead of uploading one.";

struct RenderOptions {
  std::string sceneFile, builtin, asset, statsFile, environmentFile, requestFile, ambient, camera, size, quality;
  std::string toneMap, background;
  std::string outDir, outFormat = "exr";
  std::vector<std::string> outs, sets, passes, disabled, aovs;
  int compareSpp = 0;
  double exposure = 0;
  unsigned long long seed = 0;
  long long timeBudgetMs = 0;
  bool async = false, quiet = false, fullFloat = false, noDefaultLighting = false, dryRun = false;
  CLI::Option *exposureGiven = nullptr, *seedGiven = nullptr, *budgetGiven = nullptr;
};

// "X,Y,Z" -> [X, Y, Z] (finite numbers).
nlohmann::json triple(const std::string& what, const std::string& text) {
  double v[3];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 || !std::isfinite(v[0]) ||
      !std::isfinite(v[1]) || !std::isfinite(v[2]))
    throw UsageError(what + " expects three numbers X,Y,Z, got \"" + text + "\"");
  return nlohmann::json::array({v[0], v[1], v[2]});
}

// --camera "position=0,1,3;target=0,0,0;yfov=35" -> the request's camera object (only the keys given).
nlohmann::json cameraOption(const std::string& text) {
  nlohmann::json cam = nlohmann::json::object();
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(';', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    start = end + 1;
    if (item.empty()) continue;
    const auto eq = item.find('=');
    const std::string key = item.substr(0, eq), value = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (key == "position" || key == "target" || key == "up") {
      cam[key] = triple("--camera " + key, value);
    } else if (key == "yfov") {
      try {
        std::size_t used = 0;
        const double d = std::stod(value, &used);
        if (used != value.size() || !std::isfinite(d)) throw std::invalid_argument(value);
        cam["yfov_deg"] = d;
      } catch (const std::exception&) {
        throw UsageError("--camera yfov expects degrees, got \"" + value + "\"");
      }
    } else if (key == "orbit") {
      // model-viewer's camera-orbit: theta and phi in degrees, then the radius (optional).
      double v[3];
      char tail = 0;
      const int n = std::sscanf(value.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail);
      if ((n != 2 && n != 3) || !std::isfinite(v[0]) || !std::isfinite(v[1]) || (n == 3 && !std::isfinite(v[2])))
        throw UsageError("--camera orbit expects THETA_DEG,PHI_DEG[,RADIUS], got \"" + value + "\"");
      cam["orbit"] = {{"theta_deg", v[0]}, {"phi_deg", v[1]}};
      if (n == 3) cam["orbit"]["radius"] = v[2];
    } else {
      throw UsageError("--camera: unknown key \"" + key + "\" (position, target, up, yfov, orbit)");
    }
  }
  if (cam.empty()) throw UsageError("--camera needs at least one of position=, target=, up=, yfov=, orbit=");
  return cam;
}

std::string extensionOf(const std::string& path) {
  auto dot = path.rfind('.');
  if (dot == std::string::npos) return "";
  std::string e = path.substr(dot + 1);
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// Types a --set value with the parameter's schema type from /v1/info. Unknown passes or parameters
// are sent as JSON (or a string) so that the server names them in its 422.
nlohmann::json typedValue(const nlohmann::json& info, const std::string& pass, const std::string& param,
                          const std::string& text) {
  const nlohmann::json* schema = nullptr;
  for (const auto& t : info["techniques"])
    if (t.value("name", "") == pass && t["params"].contains(param)) schema = &t["params"][param];
  const std::string where = "--set " + pass + "." + param + "=" + text;
  if (!schema) {
    auto j = nlohmann::json::parse(text, nullptr, false);
    return j.is_discarded() ? nlohmann::json(text) : j;
  }
  const std::string type = schema->value("type", "string");
  try {
    std::size_t used = 0;
    if (type == "integer") {
      long long v = std::stoll(text, &used);
      if (used != text.size()) throw std::invalid_argument(text);
      return v;
    }
    if (type == "number") {
      double v = std::stod(text, &used);
      if (used != text.size() || !std::isfinite(v)) throw std::invalid_argument(text);
      return v;
    }
  } catch (const std::exception&) {
    throw UsageError(where + ": " + pass + "." + param + " is " + (type == "integer" ? "an integer" : "a number"));
  }
  if (type == "boolean") {
    if (text == "true" || text == "1" || text == "on" || text == "yes") return true;
    if (text == "false" || text == "0" || text == "off" || text == "no") return false;
    throw UsageError(where + ": " + pass + "." + param + " is a boolean (true/false)");
  }
  return text;
}

// Where the frames go: request["outputs"][i] is written to the i-th path (docs/API.md: frame i of
// the response is outputs[i]). Sets the request's outputs from -o, --aov and --out-dir, or keeps a
// --request's own when they agree with the files asked for.
std::vector<std::string> planOutputs(const RenderOptions& o, nlohmann::json& request) {
  auto output = [&](const std::string& format, const std::vector<std::string>& aovs) {
    nlohmann::json out{{"format", format}, {"aovs", aovs}};
    if (format == "exr") out["half"] = !o.fullFloat;
    return out;
  };
  const std::vector<std::string> aovs = o.aovs.empty() ? std::vector<std::string>{"beauty"} : o.aovs;
  const bool requestOutputs = request.contains("outputs") && request["outputs"].is_array() && !request["outputs"].empty();
  auto formatOf = [&](std::size_t i) {
    const nlohmann::json& out = request["outputs"][i];
    return out.is_object() && out.contains("format") && out["format"].is_string() ? out["format"].get<std::string>() : "";
  };
  if (!o.outs.empty() && !o.outDir.empty()) throw UsageError("render: give -o files or --out-dir, not both");
  if (o.outs.empty() && o.outDir.empty()) throw UsageError("render: -o OUT.exr|OUT.png (repeatable) or --out-dir DIR is required");
  std::vector<std::string> formats;
  for (const auto& f : o.outs) {
    formats.push_back(extensionOf(f));
    if (formats.back() != "exr" && formats.back() != "png")
      throw UsageError("render: -o must end in .exr or .png, got \"" + f + "\"");
  }
  nlohmann::json outputs = nlohmann::json::array();
  if (o.outs.size() == 1) {
    if (formats[0] == "png" && o.aovs.size() > 1) throw UsageError("render: a png holds one AOV; use .exr for several");
    // A --request's own outputs are kept when the first agrees with -o (which receives frame 0).
    if (o.aovs.empty() && requestOutputs && formatOf(0) == formats[0]) return o.outs;
    outputs.push_back(output(formats[0], aovs));
  } else if (!o.outs.empty()) {
    const std::size_t n = o.outs.size();
    if (!o.aovs.empty()) {
      if (o.aovs.size() != n)
        throw UsageError("render: " + std::to_string(n) + " files (-o) take as many --aov (file i holds AOV i), or none; got " +
                         std::to_string(o.aovs.size()));
      for (std::size_t i = 0; i < n; ++i) outputs.push_back(output(formats[i], {o.aovs[i]}));
    } else if (requestOutputs) {
      if (request["outputs"].size() != n)
        throw UsageError("render: --request has " + std::to_string(request["outputs"].size()) + " outputs but " +
                         std::to_string(n) + " files (-o) were given");
      for (std::size_t i = 0; i < n; ++i)
        if (formatOf(i) != formats[i])
          throw UsageError("render: -o " + o.outs[i] + " is ." + formats[i] + " but --request's outputs/" + std::to_string(i) +
                           " is " + (formatOf(i).empty() ? "no format" : formatOf(i)));
      return o.outs;
    } else {
      for (std::size_t i = 0; i < n; ++i) outputs.push_back(output(formats[i], {"beauty"}));  // beauty in each format
    }
  } else if (o.aovs.empty() && requestOutputs) {
    outputs = request["outputs"];
  } else {
    for (const auto& aov : aovs) outputs.push_back(output(o.outFormat, {aov}));
  }
  request["outputs"] = outputs;
  if (!o.outs.empty()) return o.outs;
  // --out-dir: DIR/<aov>[+<aov>...].<format>, prefixed by the output's index when two would collide.
  std::vector<std::string> paths;
  std::set<std::string> used;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const nlohmann::json& out = outputs[i];
    std::string name;
    if (out.is_object() && out.contains("aovs") && out["aovs"].is_array())
      for (const auto& a : out["aovs"]) name += (name.empty() ? "" : "+") + (a.is_string() ? a.get<std::string>() : a.dump());
    if (name.empty()) name = "beauty";
    const std::string format = out.is_object() ? out.value("format", "png") : "png";
    name += "." + format;
    if (!used.insert(name).second) name = std::to_string(i) + "-" + name;
    used.insert(name);
    paths.push_back((std::filesystem::path(o.outDir) / name).string());
  }
  return paths;
}

// The request the options describe. `http` is null on a dry run: nothing is uploaded then (digests
// are computed locally) and --set values are typed from the schema only when the server answers.
nlohmann::json buildRequest(const RenderOptions& o, const HttpClient& http, bool upload, const std::string& sceneBytes) {
  nlohmann::json request = nlohmann::json::object();
  if (!o.requestFile.empty()) {
    request = nlohmann::json::parse(readFile(o.requestFile), nullptr, false);
    if (request.is_discarded() || !request.is_object())
      throw UsageError("--request: " + o.requestFile + " does not hold a JSON object");
  }
  const int sources = !o.sceneFile.empty() + !o.builtin.empty() + !o.asset.empty();
  if (sources > 1 || (sources == 0 && !request.contains("scene")))
    throw UsageError("render: give one scene: a file, --builtin NAME, --asset PATH, or a scene in --request");
  if (!o.sets.empty() || !o.passes.empty() || !o.disabled.empty()) {
    nlohmann::json info = nlohmann::json::object();
    if (!o.sets.empty()) {
      try {
        info = HttpClient::expectOk(http.get("/v1/info")).json();
      } catch (const std::exception&) {
        if (upload) throw;  // a dry run without a server sends --set values as written
      }
    }
    nlohmann::json p = request.contains("passes") && request["passes"].is_object() ? request["passes"] : nlohmann::json::object();
    for (const auto& name : o.passes) p[name] = nlohmann::json::object();
    for (const auto& name : o.disabled) p[name] = false;
    for (const auto& kv : o.sets) {
      const auto eq = kv.find('='), dot = kv.find('.');
      if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || dot + 1 == eq)
        throw UsageError("--set expects pass.param=value, got \"" + kv + "\"");
      const std::string pass = kv.substr(0, dot), param = kv.substr(dot + 1, eq - dot - 1);
      p[pass][param] = typedValue(info.contains("techniques") ? info : nlohmann::json{{"techniques", nlohmann::json::array()}},
                                  pass, param, kv.substr(eq + 1));
    }
    request["passes"] = p;
  }
  if (!o.builtin.empty()) request["scene"] = {{"builtin", o.builtin}};
  else if (!o.asset.empty()) request["scene"] = {{"asset", o.asset}};
  else if (!o.sceneFile.empty())
    request["scene"] = {{"digest", upload ? ensureSceneUploaded(http, sceneBytes, o.sceneFile, !o.quiet) : api::sceneDigest(sceneBytes)}};
  if (!o.ambient.empty()) {
    const nlohmann::json ambient = triple("--ambient", o.ambient);
    for (const auto& v : ambient)
      if (v.get<double>() < 0) throw UsageError("--ambient: radiance must not be negative");
    request["ambient"] = ambient;
  }
  if (!o.environmentFile.empty())
    request["environment"] = upload ? ensureImageUploaded(http, o.environmentFile, !o.quiet) : api::sceneDigest(readFile(o.environmentFile));
  if (!o.camera.empty()) {
    nlohmann::json c = request.contains("camera") && request["camera"].is_object() ? request["camera"] : nlohmann::json::object();
    c.update(cameraOption(o.camera));
    request["camera"] = c;
  }
  if (o.noDefaultLighting) request["default_lighting"] = false;
  if (!o.size.empty()) {
    int width = 0, height = 0;
    char tail = 0;
    if (std::sscanf(o.size.c_str(), "%dx%d%c", &width, &height, &tail) != 2 || width <= 0 || height <= 0)
      throw UsageError("--size expects WxH, got \"" + o.size + "\"");
    request["width"] = width;
    request["height"] = height;
  }
  if (o.exposureGiven->count()) request["exposure"] = o.exposure;
  if (!o.toneMap.empty()) request["tone_map"] = o.toneMap;
  if (o.background == "environment" || o.background == "transparent") {
    request["background"] = o.background;
  } else if (!o.background.empty()) {
    const nlohmann::json colour = triple("--background (environment, transparent or R,G,B)", o.background);
    for (const auto& v : colour)
      if (v.get<double>() < 0) throw UsageError("--background: a colour's radiance must not be negative");
    request["background"] = colour;
  }
  if (o.seedGiven->count()) request["seed"] = o.seed;
  // Presets and budgets are the daemon's to validate (docs/API.md); the client passes them on.
  if (!o.quality.empty()) request["quality"] = o.quality;
  if (o.budgetGiven->count()) request["time_budget_ms"] = o.timeBudgetMs;
  if (o.compareSpp > 0) request["compare"] = {{"against", "reference"}, {"aov", "beauty"}, {"spp", o.compareSpp}};
  if (o.requestFile.empty() || o.async) request["async"] = o.async;
  return request;
}

// A render through a proxy is sent this often before its failure is reported (a second apart).
constexpr int kRenderFleetTries = 10;

int runRender(const GlobalOptions& g, const RenderOptions& o) {
  std::string packNote;
  const std::string sceneBytes = o.sceneFile.empty() ? "" : sceneFileBytes(o.sceneFile, &packNote);
  if (!packNote.empty() && !o.quiet) std::cerr << packNote << "\n";

  HttpClient http(g.server, g.token);
  if (o.dryRun) {
    nlohmann::json request = buildRequest(o, http, false, sceneBytes);
    planOutputs(o, request);
    std::cout << request.dump(2) << "\n";
    return kExitOk;
  }
  nlohmann::json request = buildRequest(o, http, true, sceneBytes);
  const std::vector<std::string> paths = planOutputs(o, request);
  const bool async = request.value("async", false);
  // A synchronous render is sent as an async job and polled, so that it shows its progress as --async
  // does; it keeps a synchronous render's semantics (the client waits for the frames, and behind a proxy
  // a render whose daemon is lost is rendered again). The daemon describes a finished job with the same
  // JSON as a synchronous answer. --quiet shows no progress, so it sends the request as it is.
  const bool poll = async || !o.quiet;
  nlohmann::json sent = request;
  if (poll) sent["async"] = true;

  const auto t0 = std::chrono::steady_clock::now();
  // A scene by digest routes to the daemon holding it when a proxy is in front (docs/DEPLOYMENT.md).
  std::string digest = request["scene"].is_object() && request["scene"].contains("digest") && request["scene"]["digest"].is_string()
                           ? request["scene"]["digest"].get<std::string>() : "";
  if (!api::isSceneDigest(digest)) digest.clear();  // the daemon names a bad digest at /scene/digest
  // Behind a proxy (docs/DEPLOYMENT.md) a render whose daemon is lost on the way is sent again (the
  // proxy has marked that daemon down, so it lands on another), and the scene is uploaded again where
  // the next daemon lacks it. A lone daemon's answers are kept as they are (client::fleetRetry).
  const std::string body = sent.dump();
  auto submit = [&] {
    for (int attempt = 1;; ++attempt) {
      HttpResponse answer = http.post("/v1/renders", body, "application/json", sceneHeader(digest));
      const FleetRetry retry = attempt < kRenderFleetTries ? fleetRetry(answer) : FleetRetry::None;
      if (retry == FleetRetry::None || (retry == FleetRetry::Reupload && sceneBytes.empty())) return answer;
      if (!o.quiet)
        std::cerr << "render: " << (retry == FleetRetry::Reupload ? "the daemon behind the proxy lacks the scene; uploading it again"
                                                                    : "the proxy lost the daemon (" + std::to_string(answer.status) +
                                                                          "); sending the render again")
                  << "\n";
      if (retry == FleetRetry::Reupload) ensureSceneUploaded(http, sceneBytes, o.sceneFile, !o.quiet);
      else std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  };
  // Polls a submitted job until it is done: its JSON, or nullopt when a synchronous render's daemon was
  // lost behind a proxy (the caller sends the render again). Progress once the render has lasted a
  // second: on a terminal a bar redrawn in place, with the time left at the rate so far; otherwise (a
  // log, a pipe) a plain line per 10 % or change of state.
  auto waitForJob = [&](const HttpResponse& submitted, nlohmann::json result) -> std::optional<nlohmann::json> {
    const std::string location =
        submitted.header("location").empty() ? "/v1/renders/" + result.value("id", "") : submitted.header("location");
    const bool tty = isatty(STDERR_FILENO) && !o.quiet;
    bool shown = false;
    std::string lastLine;
    for (;;) {
      const std::string state = result.value("state", "");
      if (state == "done") break;
      if (state == "failed" || state == "canceled") {
        if (tty && shown) std::cerr << "\n";
        nlohmann::json problem = result.value("error", nlohmann::json::object());
        problem["render_id"] = result.value("id", "");
        throw ServerError(problem.value("status", 500), problem);
      }
      const double progress = std::clamp(result.value("progress", 0.0), 0.0, 1.0);
      const double elapsedS = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (!o.quiet && elapsedS > 1.0) {
        std::string eta;
        if (progress > 0.06)
          eta = " ETA " + std::to_string(static_cast<int>(elapsedS * (1.0 - progress) / progress + 0.5)) + " s";
        const std::string where = result.contains("queue_position") ? " (position " + result["queue_position"].dump() + ")" : "";
        if (tty) {
          const int filled = static_cast<int>(20 * progress);
          std::cerr << "\r" << result.value("id", "") << ": " << state << where << " [" << std::string(filled, '#')
                    << std::string(20 - filled, '.') << "] " << static_cast<int>(100 * progress) << "%" << eta << "      "
                    << std::flush;
        } else {
          const std::string line = result.value("id", "") + ": " + state + where + " " +
                                   std::to_string(10 * static_cast<int>(10 * progress)) + "%";
          if (line != lastLine) std::cerr << line << eta << "\n";
          lastLine = line;
        }
        shown = true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      const HttpResponse answer = http.get(location);
      if (!async && fleetRetry(answer) == FleetRetry::Again) {
        if (tty && shown) std::cerr << "\n";
        return std::nullopt;
      }
      result = HttpClient::expectOk(answer).json();
    }
    if (shown) std::cerr << (tty ? "\r" : "") << result.value("id", "") << ": done 100%" << (tty ? "          " : "") << "\n";
    return result;
  };
  // One render to its end: submitted, and polled unless --quiet sends it synchronously.
  auto run = [&]() -> std::pair<HttpResponse, nlohmann::json> {
    for (int attempt = 1;; ++attempt) {
      HttpResponse r = submit();
      HttpClient::expectOk(r);
      nlohmann::json result = r.json();
      if (!poll) return {r, result};
      if (std::optional<nlohmann::json> done = waitForJob(r, result)) return {r, *done};
      if (attempt >= kRenderFleetTries)
        throw ServerError(502, {{"title", "Daemon lost"},
                                {"detail", "the proxy lost the daemon of render " + result.value("id", "") + " " +
                                               std::to_string(attempt) + " times"}});
      if (!o.quiet) std::cerr << "render: the proxy lost the daemon (502) while it rendered; sending the render again\n";
    }
  };
  HttpResponse r;
  nlohmann::json result;
  std::tie(r, result) = run();
  if (!result.contains("frames") || !result["frames"].is_array() || result["frames"].size() < paths.size())
    throw ServerError(r.status, {{"title", "No frames"},
                                 {"detail", "the server returned " + std::to_string(result.value("frames", nlohmann::json::array()).size()) +
                                                " frames for " + std::to_string(paths.size()) + " files: " + result.dump()}});
  if (!o.outDir.empty()) std::filesystem::create_directories(o.outDir);
  std::vector<std::size_t> sizes;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    HttpResponse frame = http.get(result["frames"][i]["url"].get<std::string>());
    // The daemon holding a synchronous render's frames was lost after rendering: render it again.
    for (int again = 1; !async && fleetRetry(frame) == FleetRetry::Again && again < kRenderFleetTries; ++again) {
      if (!o.quiet) std::cerr << "render: the proxy lost the daemon holding the frames; rendering again\n";
      std::tie(r, result) = run();
      frame = http.get(result["frames"][i]["url"].get<std::string>());
    }
    HttpClient::expectOk(frame);
    writeFile(paths[i], frame.body);
    sizes.push_back(frame.body.size());
  }
  if (!o.statsFile.empty()) {
    nlohmann::json stats{{"id", result["id"]}, {"request", request}, {"stats", result["stats"]},
                         {"timings", result.value("timings", nlohmann::json::object())}, {"frames", result["frames"]}};
    writeFile(o.statsFile, stats.dump(2) + "\n");
  }
  if (!o.quiet && result.contains("stats") && result["stats"].contains("warnings") && result["stats"]["warnings"].is_array())
    for (const auto& w : result["stats"]["warnings"])
      if (w.is_string()) std::cerr << "warning: " << w.get<std::string>() << "\n";
  const std::string lighting = result.contains("stats") ? result["stats"].value("lighting", "") : "";
  if (!o.quiet && (lighting == "default" || lighting == "scene+default"))
    std::cerr << "note: lit by the default studio environment: " << result["stats"].value("lighting_reason", "")
              << " (docs/API.md, \"Default lighting\"; --ambient, --environment or --no-default-lighting change "
                 "that)\n";
  if (!o.quiet) {
    const double wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    for (std::size_t i = 0; i < paths.size(); ++i)
      std::cout << "wrote " << paths[i] << " (" << sizes[i] << " bytes, render " << result["id"].get<std::string>() << ", "
                << static_cast<int>(wallMs) << " ms)\n";
    const nlohmann::json& m = result["stats"].value("metrics", nlohmann::json());
    if (m.is_object() && m.contains("rmse"))
      std::cout << "error against the reference path tracer at " << m.value("spp", 0) << " spp: RMSE "
                << m["rmse"].get<double>() << ", relMSE " << m.value("rel_mse", 0.0) << ", SSIM " << m.value("ssim", 0.0)
                << "\n";
  }
  return kExitOk;
}

}  // namespace

void addRenderCommand(CLI::App& root, const GlobalOptions& g, Action& action) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* c = root.add_subcommand("render", "render a scene file or a built-in scene to an EXR or PNG");
  c->footer(kFooter);
  c->add_option("scene", o->sceneFile, "the scene: a .gltf or .glb file (uploaded unless the server has it)")
      ->type_name("SCENE")
      ->check(CLI::ExistingFile);
  c->add_option("--builtin", o->builtin, "a built-in scene (radiant scenes)")->type_name("NAME");
  c->add_option("--asset", o->asset, "a scene file under the daemon's --asset-root")->type_name("PATH");
  repeated(c->add_option("-o,--output", o->outs,
                         "a file to write: .exr (linear, AOV layers) or .png (tone mapped). Repeated: file i holds --aov i "
                         "(or output i of --request, or beauty when no --aov)"))
      ->type_name("OUT.exr|OUT.png");
  c->add_option("--out-dir", o->outDir,
                "write every output into DIR, named after its AOVs (beauty.exr, albedo.exr, ...): one per --aov, or "
                "--request's outputs")
      ->type_name("DIR");
  c->add_option("--format", o->outFormat, "the format of --out-dir's files made from --aov (default exr)")
      ->type_name(choices({"exr", "png"}))
      ->check(CLI::IsMember({"exr", "png"}).description(""));
  repeated(c->add_option("--set", o->sets, "a technique parameter, typed from the server's schema (repeatable)"))
      ->type_name("PASS.PARAM=VALUE");
  repeated(c->add_option("--pass", o->passes, "run this pass (repeatable)"))->type_name("NAME");
  repeated(c->add_option("--no-pass", o->disabled, "turn an on-by-default pass off: photon_gi, specular, ... (repeatable)"))
      ->type_name("NAME");
  repeated(c->add_option("--aov", o->aovs, "an AOV to write (repeatable; default beauty)"))->type_name("NAME");
  c->add_option("--size", o->size, "the frame size")->type_name("WxH");
  o->exposureGiven = c->add_option("--exposure", o->exposure, "exposure of the tone map")->type_name("EV");
  c->add_option("--tone-map", o->toneMap,
                "the view transform of PNG output (default aces: model-viewer's render-fidelity look; standard: "
                "clamp)")
      ->type_name(choices({"aces", "khronos_pbr_neutral", "agx", "standard"}))
      ->check(CLI::IsMember({"aces", "khronos_pbr_neutral", "agx", "standard"}).description(""));
  c->add_option("--background", o->background,
                "what the camera sees where no surface is: the environment (default), transparent (PNG alpha, EXR A) "
                "or a linear colour")
      ->type_name("environment|transparent|R,G,B");
  o->seedGiven = c->add_option("--seed", o->seed, "the random seed")->type_name("N");
  c->add_option("--quality", o->quality, "a quality preset (validated by the daemon)")
      ->type_name(choices({"draft", "preview", "final", "reference"}));
  o->budgetGiven = c->add_option("--time-budget-ms", o->timeBudgetMs,
                                 "let the renderer choose the most accurate configuration that fits N ms")
                       ->type_name("N");
  c->add_flag("--float", o->fullFloat, "32-bit float EXR channels (default: half)");
  c->add_option("--stats", o->statsFile, "write the request, stats, timings and frames as JSON")->type_name("FILE");
  c->add_flag("--async", o->async,
              "send the request as an async job (behind a proxy its URLs die with its daemon; without --async a lost "
              "render is sent again). Either way the client polls it and shows progress unless -q");
  c->add_flag("-q,--quiet", o->quiet, "print nothing but errors");
  c->add_option("--compare", o->compareSpp, "score beauty against the reference path tracer at SPP samples (stats.metrics)")
      ->type_name("SPP")
      ->check(CLI::PositiveNumber);
  c->add_option("--ambient", o->ambient, "uniform ambient radiance")->type_name("R,G,B");
  c->add_option("--environment", o->environmentFile, "an environment map (uploaded unless the server has it)")
      ->type_name("MAP.hdr|MAP.exr")
      ->check(CLI::ExistingFile);
  c->add_flag("--no-default-lighting", o->noDefaultLighting, "render an unlit scene black instead of studio-lit");
  c->add_option("--camera", o->camera, "any subset of the camera's keys")->type_name("position=X,Y,Z;target=X,Y,Z;up=X,Y,Z;yfov=DEG;orbit=THETA,PHI[,R]");
  c->add_option("--request", o->requestFile, "send REQUEST.json with the other options applied on top")
      ->type_name("REQUEST.json");
  c->add_flag("--dry-run", o->dryRun, "print the request instead of sending it (uploads nothing)");
  c->callback([&g, &action, o] { action = [&g, o] { return runRender(g, *o); }; });
}

}  // namespace radiant::client
