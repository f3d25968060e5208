// radiant render: upload the scene if the server lacks it, render, download the frame.
#include <chrono>
#include <cstdio>
#include <optional>
#include <cmath>
#include <iostream>
#include <thread>

#include <unistd.h>

#include "client/Commands.h"

namespace radiant::client {

namespace {

const char* kUsage =
    "usage: radiant render (SCENE.gltf|SCENE.glb|--builtin NAME) -o OUT.exr|OUT.png\n"
    "         [--set pass.param=value ...] [--pass NAME ...] [--aov NAME ...] [--size WxH]\n"
    "         [--exposure EV] [--seed N] [--float] [--stats stats.json] [--async] [--quiet]\n"
    "         [--no-pass NAME ...] [--compare SPP]\n"
    "  --no-pass NAME   turn an on-by-default pass off (photon_gi, specular, ...)\n"
    "  --compare SPP    score beauty against the reference path tracer at SPP samples (stats.metrics)\n";

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
  std::string sceneFile, builtin, out, statsFile;
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
  if (sceneFile.empty() == builtin.empty()) throw UsageError(std::string("render: give a scene file or --builtin NAME\n") + kUsage);
  if (out.empty()) throw UsageError(std::string("render: -o OUT.exr|OUT.png is required\n") + kUsage);
  const std::string format = extensionOf(out);
  if (format != "exr" && format != "png") throw UsageError("render: -o must end in .exr or .png, got \"" + out + "\"");
  if (format == "png" && aovs.size() > 1) throw UsageError("render: a png holds one AOV; use .exr for several");
  const std::string sceneBytes = sceneFile.empty() ? "" : readFile(sceneFile);

  HttpClient http(g.server, g.token);
  nlohmann::json request;
  if (!sets.empty() || !passes.empty() || !disabled.empty()) {
    const nlohmann::json info = HttpClient::expectOk(http.get("/v1/info")).json();
    nlohmann::json p = nlohmann::json::object();
    for (const auto& name : passes) p[name] = nlohmann::json::object();
    for (const auto& name : disabled) p[name] = false;
    for (const auto& [key, value] : sets) {
      const std::string pass = key.substr(0, key.find('.')), param = key.substr(key.find('.') + 1);
      p[pass][param] = typedValue(info, pass, param, value);
    }
    request["passes"] = p;
  }
  if (!builtin.empty()) request["scene"] = {{"builtin", builtin}};
  else request["scene"] = {{"digest", ensureSceneUploaded(http, sceneBytes, sceneFile, !quiet)}};
  if (width > 0) {
    request["width"] = width;
    request["height"] = height;
  }
  if (exposure) request["exposure"] = *exposure;
  if (seed) request["seed"] = *seed;
  if (compareSpp > 0) request["compare"] = {{"against", "reference"}, {"aov", "beauty"}, {"spp", compareSpp}};
  nlohmann::json output{{"format", format}, {"aovs", aovs.empty() ? std::vector<std::string>{"beauty"} : aovs}};
  if (format == "exr") output["half"] = !fullFloat;
  request["outputs"] = nlohmann::json::array({output});
  request["async"] = async;

  const auto t0 = std::chrono::steady_clock::now();
  HttpResponse r = http.post("/v1/renders", request.dump(), "application/json");
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
      if (tty)
        std::cerr << "\r" << result.value("id", "") << ": " << state
                  << (result.contains("queue_position") ? " (position " + result["queue_position"].dump() + ")" : "")
                  << " " << static_cast<int>(100 * result.value("progress", 0.0)) << "%   " << std::flush;
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
