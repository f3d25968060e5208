// radiant bench --equal-error: issue 32's headline number, the equal-error speed-up of the default frame
// over the reference path tracer (docs/PERFORMANCE.md, "Unbiased transport and the denoiser").
//
// Per built-in scene, on one server, at SIZE x SIZE:
//  1. the truth: the reference at --truth-spp (compare.spp), rendered by the first request and cached by
//     the daemon under its own fixed seed, independent of every request's;
//  2. the default frame (no passes named) scored against it, rendered twice with fresh seeds so that the
//     timed one traces its own photons: time = stats.render_ms minus the truth's metrics.reference_ms;
//  3. the reference pass alone at each spp of --ladder (photon_gi off), scored against the same truth in
//     its own mode (compare.aov reference); time = the reference pass's CPU (or GPU) ms.
// How the truth's own noise is counted: both scores hold it. fitEqualError() fits the reference's MSE
// against the truth as MSE(s) = a / s + b (b: the truth's noise plus any common bias; a: the reference's
// variance per sample); the frame's own squared error is MSE_frame - b, which the reference reaches at
// s* = a / (MSE_frame - b) samples per pixel, costing t(s*) from a least-squares line t(s) = t0 + c s.
// Speed-up = t(s*) / frame time. When MSE_frame <= b the frame is closer to the truth than the truth's
// noise can tell: reported as "> truth".
#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "client/Commands.h"

namespace radiant::client {

namespace fs = std::filesystem;
using nlohmann::json;

EqualErrorFit fitEqualError(const std::vector<LadderPoint>& ladder, double frameMse) {
  if (ladder.size() < 2) throw UsageError("bench --equal-error: the ladder needs at least two spp values");
  const double n = static_cast<double>(ladder.size());
  double mx = 0, my = 0, ms = 0, mt = 0;
  for (const LadderPoint& p : ladder) {
    if (!(p.spp > 0)) throw UsageError("bench --equal-error: spp must be positive");
    mx += 1.0 / p.spp / n, my += p.mse / n, ms += p.spp / n, mt += p.ms / n;
  }
  double sxx = 0, sxy = 0, sss = 0, sst = 0;
  for (const LadderPoint& p : ladder) {
    sxx += (1.0 / p.spp - mx) * (1.0 / p.spp - mx), sxy += (1.0 / p.spp - mx) * (p.mse - my);
    sss += (p.spp - ms) * (p.spp - ms), sst += (p.spp - ms) * (p.ms - mt);
  }
  if (!(sxx > 0)) throw UsageError("bench --equal-error: the ladder's spp values must differ");
  EqualErrorFit f;
  f.a = sxy / sxx;
  f.b = my - f.a * mx;
  if (f.b < 0) {
    // Fireflies at the smallest spp bend the curve: the truth's noise is then taken as 0 and a from the
    // largest spp, the point nearest the asymptote.
    const LadderPoint* last = &ladder.front();
    for (const LadderPoint& p : ladder)
      if (p.spp > last->spp) last = &p;
    f.b = 0;
    f.a = last->spp * last->mse;
  }
  f.msPerSpp = sst / sss;
  f.t0 = mt - f.msPerSpp * ms;
  f.frameOwnMse = frameMse - f.b;
  f.truthLimited = !(f.frameOwnMse > 0);
  if (!f.truthLimited) {
    f.spp = f.a / f.frameOwnMse;
    f.ms = f.t0 + f.msPerSpp * f.spp;
  }
  return f;
}

namespace {

// A synchronous render whose frames are not needed: the answer's JSON (the frames are deleted).
json renderStats(const HttpClient& http, const json& request) {
  const json result = HttpClient::expectOk(http.post("/v1/renders", request.dump(), "application/json")).json();
  http.del("/v1/renders/" + result.value("id", ""));
  return result.at("stats");
}

double rmseOf(const json& stats) {
  const json& m = stats.value("metrics", json::object());
  if (!m.contains("rmse") || !m["rmse"].is_number())
    throw ServerError(500, {{"title", "No metrics"}, {"detail", "the render's stats carry no metrics.rmse"}});
  return m["rmse"].get<double>();
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

}  // namespace

int equalErrorBench(const GlobalOptions& g, const EqualErrorOptions& o) {
  const std::string server = o.servers.empty() ? g.server : o.servers.front();
  HttpClient http(server, g.token);
  const json info = HttpClient::expectOk(http.get("/v1/info")).json();
  const fs::path dir = o.dir;
  fs::create_directories(dir);
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  json records = json::array();
  bool failed = false;
  for (const std::string& scene : o.scenes) {
    json record{{"scene", scene}};
    try {
      const json base{{"scene", {{"builtin", scene}}},
                      {"width", o.size},
                      {"height", o.size},
                      {"outputs", {{{"format", "exr"}, {"aovs", {"beauty"}}}}}};
      json frame = base;
      frame["compare"] = {{"against", "reference"}, {"aov", "beauty"}, {"spp", o.truthSpp}};
      frame["seed"] = 1;
      renderStats(http, frame);  // renders (and caches) the truth; shaders compiled
      frame["seed"] = 2;
      const json st = renderStats(http, frame);
      const double frameRmse = rmseOf(st);
      const double frameMs = st.value("render_ms", 0.0) - st.value("metrics", json::object()).value("reference_ms", 0.0);
      std::vector<LadderPoint> ladder;
      for (int spp : o.ladder) {
        json req = base;
        req["outputs"] = {{{"format", "exr"}, {"aovs", {"reference"}}}};
        req["passes"] = {{"photon_gi", false}, {"reference", {{"spp", spp}}}};
        req["compare"] = {{"against", "reference"}, {"aov", "reference"}, {"spp", o.truthSpp}};
        req["seed"] = 3;
        const json s = renderStats(http, req);
        double ms = 0;
        for (const json& p : s.value("passes", json::array()))
          if (p.value("name", "") == "reference") ms = std::max(p.value("cpu_ms", 0.0), p.value("gpu_ms", 0.0));
        const double rmse = rmseOf(s);
        ladder.push_back({double(spp), rmse * rmse, ms});
      }
      const EqualErrorFit f = fitEqualError(ladder, frameRmse * frameRmse);
      json steps = json::array();
      for (const LadderPoint& p : ladder) steps.push_back({{"spp", p.spp}, {"rmse", std::sqrt(p.mse)}, {"ms", p.ms}});
      record.update({{"frame_rmse", frameRmse},
                     {"frame_own_rmse", f.truthLimited ? 0.0 : std::sqrt(f.frameOwnMse)},
                     {"frame_ms", frameMs},
                     {"truth_noise_rmse", std::sqrt(f.b)},
                     {"fit", {{"a", f.a}, {"b", f.b}, {"t0_ms", f.t0}, {"ms_per_spp", f.msPerSpp}}},
                     {"reference", steps},
                     {"truth_limited", f.truthLimited}});
      if (!f.truthLimited)
        record.update({{"reference_spp_at_equal_error", f.spp}, {"reference_ms_at_equal_error", f.ms},
                       {"speed_up", frameMs > 0 ? f.ms / frameMs : 0.0}});
      if (!o.quiet)
        std::cerr << scene << ": frame RMSE " << fixed(frameRmse, 4) << " in " << fixed(frameMs, 0) << " ms; "
                  << (f.truthLimited ? std::string("closer than the truth's noise")
                                     : "the reference needs " + fixed(f.spp, 0) + " spp (" + fixed(f.ms, 0) + " ms)")
                  << "\n";
    } catch (const ServerError& e) {
      std::cerr << "bench --equal-error: " << scene << ": " << e.what() << "\n";
      record["error"] = e.what();
      failed = true;
    }
    records.push_back(record);
  }
  std::ostringstream md;
  md << "Equal-error speed-up of the default frame over the reference path tracer (" << date << ", "
     << info["device"].value("renderer", "?") << "): " << o.size << "x" << o.size << " px, truth = the reference at "
     << o.truthSpp << " spp; the reference's MSE against it fitted as a / spp + b (b: the truth's noise, removed "
     << "from the frame's error), its time as a line in spp.\n\n"
     << "| scene | default frame RMSE (own) | frame ms | truth noise | reference RMSE at";
  for (std::size_t i = 0; i < o.ladder.size(); ++i) md << (i ? ", " : " ") << o.ladder[i];
  md << " spp | reference spp at equal error | its ms | speed-up |\n|---|---|---|---|---|---|---|---|\n";
  for (const json& r : records) {
    if (r.contains("error")) {
      md << "| " << r["scene"].get<std::string>() << " | failed: " << r["error"].get<std::string>() << " | | | | | | |\n";
      continue;
    }
    md << "| " << r["scene"].get<std::string>() << " | " << fixed(r["frame_rmse"], 4) << " ("
       << fixed(r["frame_own_rmse"], 4) << ") | " << fixed(r["frame_ms"], 0) << " | " << fixed(r["truth_noise_rmse"], 4)
       << " | ";
    bool first = true;
    for (const json& p : r["reference"]) md << (first ? "" : ", ") << fixed(p["rmse"], 4), first = false;
    if (r["truth_limited"].get<bool>())
      md << " | > " << o.truthSpp << " (truth) | | |\n";
    else
      md << " | " << fixed(r["reference_spp_at_equal_error"], 0) << " | " << fixed(r["reference_ms_at_equal_error"], 0)
         << " | " << fixed(r["speed_up"], 1) << "x |\n";
  }
  writeFile((dir / "equal_error.md").string(), md.str());
  writeFile((dir / "equal_error.json").string(),
            json{{"date", date}, {"server", server}, {"device", info.value("device", json())}, {"size", o.size},
                 {"truth_spp", o.truthSpp}, {"ladder", o.ladder}, {"records", records}}
                    .dump(2) + "\n");
  std::cout << md.str() << "\nwrote " << (dir / "equal_error.md").string() << " and "
            << (dir / "equal_error.json").string() << "\n";
  return failed ? kExitServerError : kExitOk;
}

}  // namespace radiant::client
