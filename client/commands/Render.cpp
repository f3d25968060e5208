// radiant render: upload the scene if the server lacks it, render, download the frame.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <cmath>
#include <iostream>
#include <thread>

#include <unistd.h>

#include "api/Sha256.h"
#include "client/Commands.h"

namespace radiant::client {

namespace {

const char* kUsage =
    "usage: radiant render (SCENE.gltf|SCENE.glb|--builtin NAME|--asset PATH) -o OUT.exr|OUT.png\n"
    "         [--set pass.param=value ...] [--pass NAME ...] [--aov NAME ...] [--size WxH]\n"
    "         [--exposure EV] [--seed N] [--float] [--stats stats.json] [--async] [--quiet]\n"
    "         [--no-pass NAME ...] [--compare SPP]\n"
    "         [--ambient R,G,B] [--environment MAP.hdr|MAP.exr] [--no-default-lighting]\n"
    "         [--camera position=X,Y,Z;target=X,Y,Z;up=X,Y,Z;yfov=DEG] [--request REQUEST.json]\n"
    "  --no-pass NAME   turn an on-by-default pass off (photon_gi, specular, ...)\n"
    "  --compare SPP    score beauty against the reference path tracer at SPP samples (stats.metrics)\n"
    "  A .gltf that references .bin or image files is packed with them into one GLB before upload\n"
    "  (only relative paths inside its folder). --camera takes any subset of its keys; the others keep\n"
    "  the automatic framing. --request sends REQUEST.json with the other options applied on top.\n"
    "  --asset PATH names a file under the daemon's --asset-root instead of uploading one.\n";

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
    } else {
      throw UsageError("--camera: unknown key \"" + key + "\" (position, target, up, yfov)");
    }
  }
  if (cam.empty()) throw UsageError("--camera needs at least one of position=, target=, up=, yfov=");
  return cam;
}

// Uploads an environment map unless the server has it; returns its digest.
std::string ensureImageUploaded(const HttpClient& http, const std::string& path, bool verbose) {
  const std::string bytes = readFile(path);
  const std::string digest = api::sceneDigest(bytes);
  const HttpResponse head = http.head("/v1/images/" + digest);
  if (head.status == 200) return digest;
  if (head.status != 404) HttpClient::expectOk(head);
  const bool exr = bytes.size() >= 4 && bytes.compare(0, 4, "\x76\x2f\x31\x01") == 0;
  const HttpResponse r = http.put("/v1/images", bytes, exr ? "image/x-exr" : "image/vnd.radiance");
  HttpClient::expectOk(r);
  if (verbose) std::cerr << "uploaded " << path << " as " << digest << " (" << bytes.size() << " bytes)\n";
  return digest;
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

}  // namespace

int cmdRender(const GlobalOptions& g, const std::vector<std::string>& args) {
  std::string sceneFile, builtin, asset, out, statsFile, environmentFile, requestFile;
  std::optional<nlohmann::json> ambient, camera;
  bool noDefaultLighting = false;
  std::vector<std::pair<std::string, std::string>> sets;  // "pass.param", value
  std::vector<std::string> passes, aovs, disabled;
  int width = 0, height = 0, compareSpp = 0;
  std::optional<double> exposure;
  std::optional<unsigned long long> seed;
  bool async = false, quiet = false, fullFloat = false;

  auto need = [&](std::size_t& i) -> const std::string& {
    if (i + 1 >= args.size()) throw UsageError(args[i] + " needs a value\n" + kUsage);
    return args[++i];
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o" || a == "--output") out = need(i);
    else if (a == "--builtin") builtin = need(i);
    else if (a == "--asset") asset = need(i);
    else if (a == "--ambient") {
      ambient = triple("--ambient", need(i));
      for (const auto& v : *ambient)
        if (v.get<double>() < 0) throw UsageError("--ambient: radiance must not be negative");
    } else if (a == "--environment") environmentFile = need(i);
    else if (a == "--camera") camera = cameraOption(need(i));
    else if (a == "--request") requestFile = need(i);
    else if (a == "--no-default-lighting") noDefaultLighting = true;
    else if (a == "--set") {
      const std::string& kv = need(i);
      auto eq = kv.find('=');
      auto dot = kv.find('.');
      if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || dot + 1 == eq)
        throw UsageError("--set expects pass.param=value, got \"" + kv + "\"");
      sets.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
    } else if (a == "--pass") passes.push_back(need(i));
    else if (a == "--no-pass") disabled.push_back(need(i));
    else if (a == "--compare") {
      try {
        compareSpp = std::stoi(need(i));
      } catch (const std::exception&) {
        compareSpp = 0;
      }
      if (compareSpp <= 0) throw UsageError("--compare expects a positive sample count");
    }
    else if (a == "--aov") aovs.push_back(need(i));
    else if (a == "--size") {
      const std::string& s = need(i);
      if (std::sscanf(s.c_str(), "%dx%d", &width, &height) != 2 || width <= 0 || height <= 0)
        throw UsageError("--size expects WxH, got \"" + s + "\"");
    } else if (a == "--exposure") {
      try {
        exposure = std::stod(need(i));
      } catch (const std::exception&) {
        throw UsageError("--exposure expects a number (EV)");
      }
    } else if (a == "--seed") {
      try {
        seed = std::stoull(need(i));
      } catch (const std::exception&) {
        throw UsageError("--seed expects a non-negative integer");
      }
    } else if (a == "--stats") statsFile = need(i);
    else if (a == "--async") async = true;
    else if (a == "--float") fullFloat = true;
    else if (a == "--quiet" || a == "-q") quiet = true;
    else if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return kExitOk;
    } else if (!a.empty() && a[0] == '-') throw UsageError("render: unknown option " + a + "\n" + kUsage);
    else if (sceneFile.empty()) sceneFile = a;
    else throw UsageError("render: more than one scene given\n" + std::string(kUsage));
  }
  nlohmann::json request = nlohmann::json::object();
  if (!requestFile.empty()) {
    request = nlohmann::json::parse(readFile(requestFile), nullptr, false);
    if (request.is_discarded() || !request.is_object())
      throw UsageError("--request: " + requestFile + " does not hold a JSON object");
  }
  const int sources = !sceneFile.empty() + !builtin.empty() + !asset.empty();
  if (sources > 1 || (sources == 0 && !request.contains("scene")))
    throw UsageError(std::string("render: give one scene: a file, --builtin NAME, --asset PATH, or a scene in --request\n") + kUsage);
  if (out.empty()) throw UsageError(std::string("render: -o OUT.exr|OUT.png is required\n") + kUsage);
  const std::string format = extensionOf(out);
  if (format != "exr" && format != "png") throw UsageError("render: -o must end in .exr or .png, got \"" + out + "\"");
  if (format == "png" && aovs.size() > 1) throw UsageError("render: a png holds one AOV; use .exr for several");
  std::string packNote;
  const std::string sceneBytes = sceneFile.empty() ? "" : sceneFileBytes(sceneFile, &packNote);
  if (!packNote.empty() && !quiet) std::cerr << packNote << "\n";

  HttpClient http(g.server, g.token);
  if (!sets.empty() || !passes.empty() || !disabled.empty()) {
    const nlohmann::json info = HttpClient::expectOk(http.get("/v1/info")).json();
    nlohmann::json p = request.contains("passes") && request["passes"].is_object() ? request["passes"] : nlohmann::json::object();
    for (const auto& name : passes) p[name] = nlohmann::json::object();
    for (const auto& name : disabled) p[name] = false;
    for (const auto& [key, value] : sets) {
      const std::string pass = key.substr(0, key.find('.')), param = key.substr(key.find('.') + 1);
      p[pass][param] = typedValue(info, pass, param, value);
    }
    request["passes"] = p;
  }
  if (!builtin.empty()) request["scene"] = {{"builtin", builtin}};
  else if (!asset.empty()) request["scene"] = {{"asset", asset}};
  else if (!sceneFile.empty()) request["scene"] = {{"digest", ensureSceneUploaded(http, sceneBytes, sceneFile, !quiet)}};
  if (ambient) request["ambient"] = *ambient;
  if (!environmentFile.empty()) request["environment"] = ensureImageUploaded(http, environmentFile, !quiet);
  if (camera) {
    nlohmann::json c = request.contains("camera") && request["camera"].is_object() ? request["camera"] : nlohmann::json::object();
    c.update(*camera);
    request["camera"] = c;
  }
  if (noDefaultLighting) request["default_lighting"] = false;
  if (width > 0) {
    request["width"] = width;
    request["height"] = height;
  }
  if (exposure) request["exposure"] = *exposure;
  if (seed) request["seed"] = *seed;
  if (compareSpp > 0) request["compare"] = {{"against", "reference"}, {"aov", "beauty"}, {"spp", compareSpp}};
  nlohmann::json output{{"format", format}, {"aovs", aovs.empty() ? std::vector<std::string>{"beauty"} : aovs}};
  if (format == "exr") output["half"] = !fullFloat;
  // A --request's own outputs are kept when they agree with -o (the first frame is what -o receives).
  const bool keepOutputs = aovs.empty() && request.contains("outputs") && request["outputs"].is_array() &&
                           !request["outputs"].empty() && request["outputs"][0].is_object() &&
                           request["outputs"][0].value("format", "") == format;
  if (!keepOutputs) request["outputs"] = nlohmann::json::array({output});
  if (requestFile.empty() || async) request["async"] = async;

  const auto t0 = std::chrono::steady_clock::now();
  // A scene by digest routes to the daemon holding it when a proxy is in front (docs/DEPLOYMENT.md).
  std::string digest = request["scene"].is_object() && request["scene"].contains("digest") && request["scene"]["digest"].is_string()
                           ? request["scene"]["digest"].get<std::string>() : "";
  if (!api::isSceneDigest(digest)) digest.clear();  // the daemon names a bad digest at /scene/digest
  HttpResponse r = http.post("/v1/renders", request.dump(), "application/json", sceneHeader(digest));
  HttpClient::expectOk(r);
  nlohmann::json result = r.json();
  if (async) {
    const std::string location = r.header("location").empty() ? "/v1/renders/" + result.value("id", "") : r.header("location");
    const bool tty = isatty(STDERR_FILENO) && !quiet;
    for (;;) {
      const std::string state = result.value("state", "");
      if (state == "done") break;
      if (state == "failed" || state == "canceled") {
        if (tty) std::cerr << "\n";
        nlohmann::json problem = result.value("error", nlohmann::json::object());
        problem["render_id"] = result.value("id", "");
        throw ServerError(problem.value("status", 500), problem);
      }
      if (tty) {
        // A bar and, once rendering has visibly started, the time left at the rate so far.
        const double progress = std::clamp(result.value("progress", 0.0), 0.0, 1.0);
        const double elapsedS = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const int filled = static_cast<int>(20 * progress);
        std::string eta;
        if (progress > 0.06 && elapsedS > 1.0)
          eta = " ETA " + std::to_string(static_cast<int>(elapsedS * (1.0 - progress) / progress + 0.5)) + " s";
        std::cerr << "\r" << result.value("id", "") << ": " << state
                  << (result.contains("queue_position") ? " (position " + result["queue_position"].dump() + ")" : "")
                  << " [" << std::string(filled, '#') << std::string(20 - filled, '.') << "] "
                  << static_cast<int>(100 * progress) << "%" << eta << "      " << std::flush;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      result = HttpClient::expectOk(http.get(location)).json();
    }
    if (tty) std::cerr << "\r" << result.value("id", "") << ": done 100%          \n";
  }
  if (!result.contains("frames") || result["frames"].empty())
    throw ServerError(r.status, {{"title", "No frames"}, {"detail", "the server returned no frames: " + result.dump()}});
  const std::string url = result["frames"][0]["url"];
  const HttpResponse frame = http.get(url);
  HttpClient::expectOk(frame);
  writeFile(out, frame.body);
  if (!statsFile.empty()) {
    nlohmann::json stats{{"id", result["id"]}, {"request", request}, {"stats", result["stats"]},
                         {"timings", result.value("timings", nlohmann::json::object())}, {"frames", result["frames"]}};
    writeFile(statsFile, stats.dump(2) + "\n");
  }
  if (!quiet && result.contains("stats") && result["stats"].contains("warnings") && result["stats"]["warnings"].is_array())
    for (const auto& w : result["stats"]["warnings"])
      if (w.is_string()) std::cerr << "warning: " << w.get<std::string>() << "\n";
  if (!quiet && result.contains("stats") && result["stats"].value("lighting", "") == "default")
    std::cerr << "note: the scene has no lights, ambient or environment; it was lit by the default studio "
                 "environment (see docs/API.md; --ambient, --environment or --no-default-lighting change that)\n";
  if (!quiet) {
    const double wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::cout << "wrote " << out << " (" << frame.body.size() << " bytes, render " << result["id"].get<std::string>()
              << ", " << static_cast<int>(wallMs) << " ms)\n";
    const nlohmann::json& m = result["stats"].value("metrics", nlohmann::json());
    if (m.is_object() && m.contains("rmse"))
      std::cout << "error against the reference path tracer at " << m.value("spp", 0) << " spp: RMSE "
                << m["rmse"].get<double>() << ", relMSE " << m.value("rel_mse", 0.0) << ", SSIM " << m.value("ssim", 0.0)
                << "\n";
  }
  return kExitOk;
}

}  // namespace radiant::client
