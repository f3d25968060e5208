// Issue 19, "Presets and budgets", against the real daemon on the built-in Cornell box:
//  - quality presets run the preset table's front points, and at the table's error size and seed the
//    measured error is the table's (error against the reference is deterministic for a fixed seed);
//  - a larger time_budget_ms never gives a larger predicted or measured error, the predicted cost fits
//    the budget, and the daemon runs what api::chooseConfiguration chooses at the speed factor it
//    reports; the measured frame times are printed, never asserted (issue 31: on a loaded or slower
//    machine they are not the model's to guarantee: the speed factor adapts the choice instead);
//  - the speed factor: measured by a calibration frame and then recent comparable frames, or pinned;
//  - a daemon's caps (--max-photons) bound what a preset or budget picks;
//  - progressive refinement of the reference: the estimated error of the batches' mean tracks its true
//    error against a high-spp ground truth within a factor; with a compare block the mean is scored.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "api/Presets.h"
#include "renderer/io/ImageIO.h"
#include "tests/support/DaemonProcess.h"

namespace radiant {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

struct RealDaemon {
  fs::path dir;
  testing::Daemon daemon;
  explicit RealDaemon(const std::string& name, std::vector<std::string> flags = {})
      : dir(testing::scratch(name)), daemon(RADIANTD_PATH, withPort(std::move(flags)), {}, dir / "stderr.log") {}
  static std::vector<std::string> withPort(std::vector<std::string> flags) {
    flags.insert(flags.begin(), {"--port", "0", "--request-timeout", "600"});
    return flags;
  }
  bool ready() { return daemon.port() > 0 && daemon.waitReady(std::chrono::seconds(120)); }
  json render(const json& body) {
    auto c = daemon.client();
    c.set_read_timeout(600, 0);
    auto r = c.Post("/v1/renders", body.dump(), "application/json");
    if (!r) return json{{"error", "no response"}};
    json j = json::parse(r->body, nullptr, false);
    if (r->status != 200) j["http_status"] = r->status;
    return j;
  }
  Image image(const std::string& url) {
    auto c = daemon.client();
    const std::string bytes = c.Get(url.c_str())->body;
    const fs::path f = dir / "frame.exr";
    io::writeFile(f.string(), bytes);
    return io::readImage(f.string());
  }
};

const json& tableEntry(const std::string& technique) {
  return api::PresetTable::builtin().data()["techniques"][technique];
}

// One daemon for the preset and budget tests, so that the compare block's reference (1024 spp) is
// rendered once. Its speed factor is pinned to 1 (radiantd --speed-factor): the budget ladders below
// assert the chooser's choices in the table's own units (a larger budget never a larger error), which a
// factor measured between two frames of a ladder would move; the measured factor has its own test
// (TheChooserMeasuresTheMachineAndScalesItsPredictions).
RealDaemon& sharedDaemon() {
  static RealDaemon d("budgets", {"--speed-factor", "1"});
  return d;
}

// What the daemon chose for `body` is what api::chooseConfiguration chooses for the same request at
// the speed factor, scene counts and planned passes its stats report: the choice follows the model,
// whatever the frame then measured.
void expectTheChoosersChoice(const json& body, const json& response) {
  const json& stats = response["stats"];
  const json& b = stats["budget"];
  ASSERT_TRUE(b.is_object()) << stats.dump();
  api::RenderRequest request = api::parseRenderRequest(body);
  const int k = stats["supersampling"];
  request.width *= k;
  request.height *= k;
  std::vector<std::string> planned;
  for (const auto& p : stats["passes"]) planned.push_back(p["name"]);
  const api::SceneCounts counts = api::SceneCounts::fromJson(b["scene_counts"]);
  const double speed = b["speed_factor"];
  EXPECT_EQ(speed, b["speed"]["factor"].get<double>()) << b.dump();
  const api::BudgetChoice local = api::chooseConfiguration(api::PresetTable::builtin(), planned, request, nullptr, counts, speed);
  // Every technique the chooser configured or charged, with the same knobs and the same prediction
  // (the daemon adds each pass's measured time to the same objects).
  for (const auto& [name, l] : local.stats["techniques"].items()) {
    ASSERT_TRUE(b["techniques"].contains(name)) << name << " " << b.dump();
    const json& t = b["techniques"][name];
    EXPECT_EQ(t.value("params", json()), l.value("params", json())) << name;
    if (l.contains("predicted_ms") && l["predicted_ms"].is_number()) {
      ASSERT_TRUE(t.contains("predicted_ms")) << name;
      EXPECT_NEAR(t["predicted_ms"].get<double>(), l["predicted_ms"].get<double>(), 1e-9 * l["predicted_ms"].get<double>())
          << name;
    }
  }
  EXPECT_NEAR(b["predicted_ms"].get<double>(), local.stats["predicted_ms"].get<double>(), 1e-9 * b["predicted_ms"].get<double>());
}

// The table's error sweep scored photon_gi's indirect against the reference at this many spp.
json photonGiCompare() {
  return json{{"aov", "indirect"}, {"spp", tableEntry("photon_gi")["error"].value("spp", 256)}};
}

json cornell(int size, std::uint64_t seed) {
  return json{{"scene", {{"builtin", "cornell_box"}}}, {"width", size}, {"height", size}, {"seed", seed},
              {"outputs", {{{"format", "exr"}, {"aovs", {"beauty", "indirect"}}}}}};
}

TEST(Budgets, QualityPresetsRunTheTablesPointsAndMeasureTheirError) {
  const json& entry = tableEntry("photon_gi");
  ASSERT_TRUE(entry.contains("front")) << "api/presets.json has no photon_gi front (regenerate it: bench/presets.py)";
  const int size = api::PresetTable::builtin().data()["generated"]["error_size"];
  RealDaemon& d = sharedDaemon();
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  double lastPredicted = 1e9, lastMeasured = 1e9;
  for (const char* q : {"draft", "preview", "final", "reference"}) {
    json body = cornell(size, 0);
    body["quality"] = q;
    body["compare"] = photonGiCompare();
    const json r = d.render(body);
    ASSERT_FALSE(r.contains("http_status")) << r.dump();
    const json& b = r["stats"]["budget"];
    ASSERT_TRUE(b.is_object()) << r["stats"].dump();
    EXPECT_EQ(b["quality"], q);
    const int i = entry["presets"][q];
    const json& chosen = b["techniques"]["photon_gi"];
    EXPECT_EQ(chosen["params"], entry["front"][i]["params"]) << q;
    EXPECT_TRUE(chosen["measured_ms"].is_number());
    EXPECT_TRUE(b["measured_ms"].is_number());
    const double predicted = chosen["predicted_error"]["value"], measured = r["stats"]["metrics"]["rmse"];
    // The same scene, size, seed and compare block as the table's error sweep: the same error, up to
    // llvmpipe's thread-order rounding (2%).
    EXPECT_NEAR(measured, predicted, 0.02 * predicted) << q;
    EXPECT_LE(predicted, lastPredicted) << q;
    EXPECT_LE(measured, lastMeasured * 1.02) << q;
    lastPredicted = predicted;
    lastMeasured = measured;
    // An explicit parameter wins over the preset.
    if (std::string(q) == "final") {
      body["passes"] = {{"photon_gi", {{"photons", 30000}}}};
      const json e = d.render(body);
      EXPECT_EQ(e["stats"]["budget"]["techniques"]["photon_gi"]["params"]["photons"], 30000);
      EXPECT_TRUE(e["stats"]["budget"]["techniques"]["photon_gi"]["predicted_error"].is_null());
    }
  }
}

TEST(Budgets, LargerBudgetsNeverGiveLargerErrorsAndRunTheChoosersChoice) {
  const json& front = tableEntry("photon_gi")["front"];
  ASSERT_TRUE(front.is_array() && front.size() >= 3);
  const int size = api::PresetTable::builtin().data()["generated"]["error_size"];
  RealDaemon& d = sharedDaemon();
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  d.render(cornell(size, 7));  // shaders compiled, scene uploaded

  // Budgets spanning the front: the cheapest frame's predicted ms times 1, 1.5, 2.5, 4, 8.
  json probe = cornell(size, 0);
  probe["time_budget_ms"] = 1;
  const json probed = d.render(probe);
  const double cheapest = probed["stats"]["budget"]["predicted_ms"];
  ASSERT_GT(cheapest, 0.0);
  // A request that keeps its own supersampling k under a budget is charged the raster's pixels,
  // k^2 width height (the table was measured at k = 1): direct's model at 4x the pixels for k = 2.
  json probe2 = probe;
  probe2["supersampling"] = 2;
  const json probed2 = d.render(probe2);
  ASSERT_EQ(probed2["stats"]["supersampling"], 2) << probed2.dump();
  const api::PresetTable& table = api::PresetTable::builtin();
  const json& direct1 = probed["stats"]["budget"]["techniques"]["direct"];
  const json& direct2 = probed2["stats"]["budget"]["techniques"]["direct"];
  const double px = double(size) * size;
  EXPECT_NEAR(direct1["predicted_ms"].get<double>(), table.predictMs("direct", json::object(), px), 1e-6) << direct1.dump();
  EXPECT_NEAR(direct2["predicted_ms"].get<double>(), table.predictMs("direct", json::object(), 4 * px), 1e-6) << direct2.dump();
  EXPECT_GT(probed2["stats"]["budget"]["predicted_ms"].get<double>(), cheapest);
  double lastPredicted = 1e9, lastMeasured = 1e9, lastMs = 0;
  int fits = 0, runs = 0;
  for (double factor : {1.0, 1.5, 2.5, 4.0, 8.0}) {
    const double budget = cheapest * factor * 1.0001;
    // Error: seed 0 as in the table's error sweep (deterministic).
    json body = cornell(size, 0);
    body["time_budget_ms"] = budget;
    body["compare"] = photonGiCompare();
    const json r = d.render(body);
    ASSERT_FALSE(r.contains("http_status")) << r.dump();
    expectTheChoosersChoice(body, r);
    const json& b = r["stats"]["budget"];
    const double predictedMs = b["predicted_ms"], predicted = b["techniques"]["photon_gi"]["predicted_error"]["value"];
    const double measured = r["stats"]["metrics"]["rmse"];
    EXPECT_LE(predictedMs, budget) << budget;
    EXPECT_GE(predictedMs, lastMs) << budget;
    EXPECT_LE(predicted, lastPredicted) << budget;
    EXPECT_LE(measured, lastMeasured * 1.02) << budget;
    lastPredicted = predicted, lastMeasured = measured, lastMs = predictedMs;
    // Time: a fresh seed, so the photons are traced as in the table's cost sweep (a cold first render).
    json timed = cornell(size, 500 + runs);
    timed["time_budget_ms"] = budget;
    const json t = d.render(timed);
    const double ms = t["stats"]["budget"]["measured_ms"];
    ++runs;
    fits += ms <= budget;
    std::printf("budget %.1f ms: predicted %.1f ms, measured %.1f ms, photons %d, C %g, predicted rmse %.4f, "
                "measured %.4f\n",
                budget, predictedMs, ms, t["stats"]["budget"]["techniques"]["photon_gi"]["params"]["photons"].get<int>(),
                t["stats"]["budget"]["techniques"]["photon_gi"]["params"]["C"].get<double>(), predicted, measured);
  }
  EXPECT_LT(lastPredicted, front[0]["error"].get<double>());  // the budgets did buy accuracy
  // The measured frame times are reported, not asserted (issue 31: a budget test asserts the choice and
  // the model, not wall-clock luck; at speed factor 1 they say how well the table fits this machine now).
  ::testing::Test::RecordProperty("within_budget", std::to_string(fits) + "/" + std::to_string(runs));
  std::printf("measured frame time within the budget in %d of %d runs (speed factor pinned to 1)\n", fits, runs);
}

// A daemon capped below the table's dearer photon_gi points (radiantd --max-photons): the preset and
// the budget run the best point within the cap, the pass traces that many photons, and the stats say
// what the cap excluded. An explicit request above the cap is still refused (422, the field named).
// Issue 31's default frame budget (radiantd --default-frame-budget-ms): the planner's default frame of
// cornell_box (photon_gi at its schema default: about 2 s predicted at 256 x 256, over a second at
// 32 x 32, mostly photon tracing) against a 50 ms budget first drops its default supersampling to 1
// (no k fits) and then renders what the chooser picks for time_budget_ms 50, saying both in
// stats.warnings and stats.budget.default_frame_budget; the same request naming its passes runs as
// asked (no budget block, the default supersampling, photon_gi's own parameters).
TEST(Budgets, TheDefaultFrameBudgetLowersOnlyTheDefaultFrame) {
  RealDaemon d("default-budget", {"--speed-factor", "1", "--default-frame-budget-ms", "50"});
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  {
    auto c = d.daemon.client();
    auto info = c.Get("/v1/info");
    ASSERT_TRUE(info);
    EXPECT_EQ(json::parse(info->body)["limits"]["default_frame_budget_ms"], 50.0) << info->body;
  }
  const json body = cornell(32, 0);
  const json r = d.render(body);
  ASSERT_TRUE(r.contains("stats")) << r.dump();
  const json& stats = r["stats"];
  const json& b = stats["budget"];
  ASSERT_TRUE(b.is_object()) << stats.dump();
  ASSERT_TRUE(b.contains("default_frame_budget")) << b.dump();
  EXPECT_EQ(b["default_frame_budget"]["budget_ms"], 50.0);
  EXPECT_EQ(b["default_frame_budget"]["flag"], "--default-frame-budget-ms");
  const double predictedDefault = b["default_frame_budget"]["predicted_default_ms"];
  EXPECT_GT(predictedDefault, 50.0);
  EXPECT_LT(b["predicted_ms"].get<double>(), predictedDefault);
  ASSERT_GE(stats["warnings"].size(), 2u);
  EXPECT_NE(stats["warnings"][0].get<std::string>().find("supersampling 1 instead of the default 4"), std::string::npos)
      << stats["warnings"].dump();
  EXPECT_NE(stats["warnings"][1].get<std::string>().find("--default-frame-budget-ms"), std::string::npos)
      << stats["warnings"].dump();
  // The chooser's choice for the same frame under the same limit, at the k the daemon used.
  api::RenderRequest request = api::parseRenderRequest(body);
  const int k = stats["supersampling"];
  EXPECT_EQ(k, 1);
  request.width *= k;
  request.height *= k;
  request.supersampling = k;
  std::vector<std::string> planned;
  for (const auto& p : stats["passes"]) planned.push_back(p["name"]);
  const api::SceneCounts counts = api::SceneCounts::fromJson(b["scene_counts"]);
  api::RequestLimits limits;
  limits.defaultFrameBudgetMs = 50;
  const api::BudgetChoice local = api::chooseConfiguration(api::PresetTable::builtin(), planned, request, &limits, counts, 1.0);
  ASSERT_TRUE(local.active);
  EXPECT_EQ(b["techniques"]["photon_gi"]["params"], local.stats["techniques"]["photon_gi"]["params"]) << b.dump();
  EXPECT_NEAR(predictedDefault, local.stats["default_frame_budget"]["predicted_default_ms"].get<double>(), 1e-9 * predictedDefault);

  // Named passes: as asked.
  json named = body;
  named["passes"] = {{"photon_gi", json::object()}};
  const json n = d.render(named);
  ASSERT_TRUE(n.contains("stats")) << n.dump();
  EXPECT_TRUE(!n["stats"].contains("budget") || n["stats"]["budget"].is_null()) << n["stats"].dump();
  EXPECT_EQ(n["stats"]["supersampling"], api::defaultSupersampling(32, 32));
  for (const auto& w : n["stats"]["warnings"])
    EXPECT_EQ(w.get<std::string>().find("--default-frame-budget-ms"), std::string::npos) << w;
}

TEST(Budgets, PresetsAndBudgetsStayWithinTheDaemonsCaps) {
  const json& front = tableEntry("photon_gi")["front"];
  ASSERT_TRUE(front.is_array() && front.size() >= 3);
  // The cap: between the front's second and third photon counts, so that exactly the points with at
  // most the second's photons fit.
  const long long cap = (front[1]["params"]["photons"].get<long long>() + front[2]["params"]["photons"].get<long long>()) / 2;
  int best = -1;  // the most accurate point within the cap (fronts are sorted by cost, error falling)
  for (std::size_t i = 0; i < front.size(); ++i)
    if (front[i]["params"]["photons"].get<long long>() <= cap) best = int(i);
  ASSERT_GE(best, 1);
  const int finalPoint = tableEntry("photon_gi")["presets"]["final"];
  ASSERT_GT(front[finalPoint]["params"]["photons"].get<long long>(), cap) << "the cap must bind on the final preset";
  RealDaemon d("caps", {"--max-photons", std::to_string(cap)});
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  auto photonGiPass = [](const json& r) {
    for (const auto& p : r["stats"]["passes"])
      if (p["name"] == "photon_gi") return p;
    return json();
  };
  // Most accurate preset first: the preset's point is above the cap, so the best point within it runs.
  for (const char* q : {"reference", "final"}) {
    json body = cornell(32, 0);
    body["quality"] = q;
    const json r = d.render(body);
    ASSERT_FALSE(r.contains("http_status")) << r.dump();
    const json& chosen = r["stats"]["budget"]["techniques"]["photon_gi"];
    EXPECT_EQ(chosen["point"], best) << q;
    EXPECT_EQ(chosen["params"], front[best]["params"]) << q;
    EXPECT_DOUBLE_EQ(chosen["predicted_error"]["value"].get<double>(), front[best]["error"].get<double>()) << q;
    EXPECT_EQ(chosen["capped"]["limits"]["photons"]["limit"], cap) << q;
    EXPECT_EQ(chosen["capped"]["limits"]["photons"]["flag"], "radiantd --max-photons");
    EXPECT_EQ(chosen["capped"]["preset_point"], tableEntry("photon_gi")["presets"][q]) << q;
    EXPECT_EQ(photonGiPass(r)["counters"]["photons"], front[best]["params"]["photons"]) << "the pass ran the capped point";
    EXPECT_NE(r["stats"]["warnings"].dump().find("--max-photons"), std::string::npos) << r["stats"]["warnings"].dump();
  }
  // A budget large enough for the whole front: the best point within the cap, the others excluded.
  json body = cornell(32, 0);
  body["time_budget_ms"] = 1e7;
  const json r = d.render(body);
  ASSERT_FALSE(r.contains("http_status")) << r.dump();
  const json& chosen = r["stats"]["budget"]["techniques"]["photon_gi"];
  EXPECT_EQ(chosen["point"], best);
  EXPECT_EQ(photonGiPass(r)["counters"]["photons"], front[best]["params"]["photons"]);
  EXPECT_EQ(chosen["capped"]["excluded_points"].size(), front.size() - best - 1);
  // The request's own photons above the cap: refused, naming the field, and the daemon keeps serving.
  body = cornell(32, 0);
  body["quality"] = "draft";
  body["passes"] = {{"photon_gi", {{"photons", cap + 1}}}};
  const json refused = d.render(body);
  EXPECT_EQ(refused["http_status"], 422) << refused.dump();
  EXPECT_EQ(refused["pointer"], "/passes/photon_gi/photons");
  body["passes"] = {{"photon_gi", {{"photons", cap}}}};
  EXPECT_EQ(photonGiPass(d.render(body))["counters"]["photons"], cap);
}

// Issue 19 item 6: budgets on the scenes whose other passes the table now models. `base` is a frame of
// a built-in scene; `technique` the pass whose front the budgets climb, scored by `compare` (its AOV
// against the reference in the table's mode and spp). Budgets of 1, 1.5, 2.5, 4 and 8 times the cheapest
// frame's predicted ms: every planned pass is charged (predicted_ms a number), a larger budget never gives
// a larger predicted or measured error, the prediction fits the budget, the daemon runs the chooser's
// choice, and the measured frame time (a fresh seed each) is reported.
struct Ladder {
  int fits = 0, runs = 0;
  double firstError = 0, lastError = 0;
};
// `errorTolerance`: how near the measured RMSE of a seed-0 frame must be to the table's error of the
// chosen point (relative): the error sweep rendered the same frame.
Ladder climbBudgets(RealDaemon& d, const json& base, const std::string& technique, double errorTolerance) {
  Ladder out;
  const json& entry = tableEntry(technique);
  const json compare{{"aov", entry["error"]["aov"]}, {"spp", entry["error"]["spp"]}};
  json warm = base;
  warm["seed"] = 7;
  d.render(warm);  // shaders compiled, scene uploaded
  json probe = base;
  probe["time_budget_ms"] = 1;
  const json p = d.render(probe);
  EXPECT_FALSE(p.contains("http_status")) << p.dump();
  const double cheapest = p["stats"]["budget"]["predicted_ms"];
  EXPECT_GT(cheapest, 0.0);
  for (const auto& [name, t] : p["stats"]["budget"]["techniques"].items())
    EXPECT_TRUE(t["predicted_ms"].is_number()) << name << " is not charged: " << t.dump();
  double lastPredicted = 1e9, lastMeasured = 1e9, lastMs = 0;
  for (double factor : {1.0, 1.5, 2.5, 4.0, 8.0}) {
    const double budget = cheapest * factor * 1.0001;
    json body = base;  // seed 0, the table's error sweep
    body["time_budget_ms"] = budget;
    body["compare"] = compare;
    const json r = d.render(body);
    EXPECT_FALSE(r.contains("http_status")) << r.dump();
    if (r.contains("http_status")) return out;
    expectTheChoosersChoice(body, r);
    const json& b = r["stats"]["budget"];
    const double predictedMs = b["predicted_ms"], predicted = b["techniques"][technique]["predicted_error"]["value"];
    const double measured = r["stats"]["metrics"]["rmse"];
    EXPECT_LE(predictedMs, budget) << technique << " " << budget;
    EXPECT_GE(predictedMs, lastMs) << technique << " " << budget;
    EXPECT_LE(predicted, lastPredicted) << technique << " " << budget;
    EXPECT_LE(measured, lastMeasured * 1.02) << technique << " " << budget;
    EXPECT_NEAR(measured, predicted, errorTolerance * predicted) << technique << " " << budget;
    if (out.runs == 0) out.firstError = measured;
    out.lastError = measured;
    lastPredicted = predicted, lastMeasured = measured, lastMs = predictedMs;
    json timed = base;
    timed["seed"] = 600 + out.runs;
    // A technique with its own seed-keyed cache (the illumination network): its seed follows the frame's,
    // so that the timed frame is cold like the table's cost sweep, not the error frame's network reused.
    if (base.contains("passes") && base["passes"].contains(technique) && base["passes"][technique].contains("seed"))
      timed["passes"][technique]["seed"] = 600 + out.runs;
    timed["time_budget_ms"] = budget;
    const json t = d.render(timed);
    const double ms = t["stats"]["budget"]["measured_ms"];
    ++out.runs;
    out.fits += ms <= budget;
    std::printf("%s budget %.1f ms: predicted %.1f ms, measured %.1f ms, %s %s, predicted rmse %.4f, measured %.4f\n",
                technique.c_str(), budget, predictedMs, ms, technique.c_str(),
                t["stats"]["budget"]["techniques"][technique]["params"].dump().c_str(), predicted, measured);
  }
  std::printf("%s: measured frame time within the budget in %d of %d runs\n", technique.c_str(), out.fits, out.runs);
  ::testing::Test::RecordProperty("within_budget_" + technique, std::to_string(out.fits) + "/" + std::to_string(out.runs));
  return out;
}

TEST(Budgets, BudgetsOnTheCausticsSceneChargeEveryPass) {
  ASSERT_TRUE(tableEntry("caustics").contains("front")) << "api/presets.json has no caustics front";
  RealDaemon& d = sharedDaemon();
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  const int size = tableEntry("caustics")["error"]["width"];  // the caustics sweep's error size (128)
  // cornell_glass with its default passes: specular, caustics and photon_gi all charged.
  const json base{{"scene", {{"builtin", "cornell_glass"}}}, {"width", size}, {"height", size}, {"seed", 0},
                  {"outputs", {{{"format", "exr"}, {"aovs", {"beauty", "caustics"}}}}}};
  // The caustic triangles are deterministic: the table's error up to llvmpipe's rounding (2%).
  const Ladder l = climbBudgets(d, base, "caustics", 0.02);
  EXPECT_LT(l.lastError, l.firstError);  // the budgets bought caustics accuracy
}

TEST(Budgets, BudgetsOnTheMediaSceneChargeEveryPass) {
  ASSERT_TRUE(tableEntry("illumination_network").contains("front")) << "api/presets.json has no illumination_network front";
  RealDaemon& d = sharedDaemon();
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  const int size = tableEntry("illumination_network")["error"]["width"];
  // explosion with the illumination network owning the media (its multiple scattering is the dearest
  // media pass); photon_gi off and no warm start, as in the table's sweep (a frame's first render).
  const json base{{"scene", {{"builtin", "explosion"}}}, {"width", size}, {"height", size}, {"seed", 0},
                  {"passes", {{"photon_gi", false}, {"illumination_network", {{"warm_start", false}, {"seed", 0}}}}},
                  {"outputs", {{{"format", "exr"}, {"aovs", {"beauty", "media"}}}}}};
  // Without a warm start the frame is the table's error frame: its error up to llvmpipe's rounding.
  const Ladder l = climbBudgets(d, base, "illumination_network", 0.02);
  EXPECT_LT(l.lastError, l.firstError);
}

// Issue 19, the scene variables: the media scene with ten times its particles (the request's `media`: a
// smoke of 1440 generated particles over explosion's own 159). The budget chooser sees the frame's
// particles (stats.budget.scene_counts, exactly the scene's plus the request's), charges the media pass
// more for them than on the bare scene, and over budgets of 1 to 8 times the cheapest frame's prediction
// a larger budget never gives a larger predicted error, the daemon runs the chooser's choice, and the
// measured frame time (a fresh seed and a cold network each) is reported, as for the other ladders.
// Without the particles in the model the prediction was that of 159 particles, and the frames of 1599
// ran over.
TEST(Budgets, BudgetsOnTheMediaSceneWithTenTimesTheParticlesChargeThem) {
  ASSERT_TRUE(tableEntry("illumination_network").contains("front")) << "api/presets.json has no illumination_network front";
  RealDaemon& d = sharedDaemon();
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  constexpr int kSceneParticles = 115 + 28 + 16, kAdded = 1440;  // scenes/explosion.gltf: fire, smoke, dust
  const json smoke{{"name", "many"}, {"kind", "smoke"}, {"tau", 1.0}, {"seed", 5}, {"profile", "linear_exact"},
                   {"generator", {{"shape", "sphere"}, {"center", {0, 1.1, 0}}, {"extent", {1.0, 0.7, 1.0}},
                                  {"count", kAdded}, {"radius", 0.25}, {"radius_jitter", 0.3}}}};
  json bare{{"scene", {{"builtin", "explosion"}}}, {"width", 64}, {"height", 64}, {"seed", 0},
            {"passes", {{"photon_gi", false}, {"illumination_network", {{"warm_start", false}, {"seed", 0}}}}},
            {"outputs", {{{"format", "exr"}, {"aovs", {"beauty", "media"}}}}}};
  json base = bare;
  base["media"] = json::array({smoke});
  json warm = base;
  warm["seed"] = 7;
  d.render(warm);
  json probe = base, probeBare = bare;
  probe["time_budget_ms"] = probeBare["time_budget_ms"] = 1;
  const json p = d.render(probe), pb = d.render(probeBare);
  ASSERT_FALSE(p.contains("http_status")) << p.dump();
  ASSERT_FALSE(pb.contains("http_status")) << pb.dump();
  EXPECT_EQ(p["stats"]["budget"]["scene_counts"]["particles"], kSceneParticles + kAdded);
  EXPECT_EQ(pb["stats"]["budget"]["scene_counts"]["particles"], kSceneParticles);
  EXPECT_EQ(p["stats"]["scene"]["counts"], p["stats"]["budget"]["scene_counts"]);
  const double many = p["stats"]["budget"]["techniques"]["illumination_network"]["predicted_ms"];
  const double few = pb["stats"]["budget"]["techniques"]["illumination_network"]["predicted_ms"];
  EXPECT_GT(many, few) << "the particles are not charged";
  const double cheapest = p["stats"]["budget"]["predicted_ms"];
  int fits = 0, runs = 0;
  double lastError = 1e9;
  for (double factor : {1.0, 1.5, 2.5, 4.0, 8.0}) {
    const double budget = cheapest * factor * 1.0001;
    json timed = base;
    timed["seed"] = 700 + runs;
    timed["passes"]["illumination_network"]["seed"] = 700 + runs;  // a cold network, as in the cost sweep
    timed["time_budget_ms"] = budget;
    const json r = d.render(timed);
    ASSERT_FALSE(r.contains("http_status")) << r.dump();
    expectTheChoosersChoice(timed, r);
    const json& b = r["stats"]["budget"];
    const double predictedMs = b["predicted_ms"], ms = b["measured_ms"];
    const double error = b["techniques"]["illumination_network"]["predicted_error"]["value"];
    EXPECT_LE(predictedMs, budget);
    EXPECT_LE(error, lastError) << budget;
    lastError = error;
    ++runs;
    fits += ms <= budget;
    std::printf("1599 particles, budget %.1f ms: predicted %.1f ms, measured %.1f ms, illumination_network %s "
                "(predicted %.1f ms, measured %.1f ms)\n",
                budget, predictedMs, ms, b["techniques"]["illumination_network"]["params"].dump().c_str(),
                b["techniques"]["illumination_network"]["predicted_ms"].get<double>(),
                b["techniques"]["illumination_network"].value("measured_ms", -1.0));
  }
  std::printf("1599 particles: measured frame time within the budget in %d of %d runs\n", fits, runs);
  ::testing::Test::RecordProperty("within_budget_1599_particles", std::to_string(fits) + "/" + std::to_string(runs));
}

// Issue 31, budgets that hold on a loaded machine. A daemon that measures its speed (the default):
//  - its first budgeted frame is preceded by the calibration frame, whose ratio of measured to
//    predicted time is the factor that frame's choice used (stats.budget.speed: source "measured");
//  - every budgeted frame's predictions are the table's times the factor, and the choice is the
//    chooser's at that factor (whatever this machine's load made it);
//  - frames comparable with the table's cost sweeps (a fresh seed: photons traced cold, as in the table)
//    join the recent window, the factor being the median of the window and the calibration; a frame
//    that reuses the photons of an earlier one (the same seed and parameters) does not join it.
// A daemon pinned with --speed-factor 4 scales by exactly 4 and never calibrates.
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

TEST(Budgets, TheChooserMeasuresTheMachineAndScalesItsPredictions) {
  RealDaemon d("speed");
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  const api::PresetTable& table = api::PresetTable::builtin();
  const int size = table.data()["generated"]["error_size"];
  auto budgeted = [&](std::uint64_t seed) {
    json body = cornell(size, seed);
    body["time_budget_ms"] = 400;
    return body;
  };
  json body = budgeted(11);
  json r = d.render(body);
  ASSERT_FALSE(r.contains("http_status")) << r.dump();
  json speed = r["stats"]["budget"]["speed"];
  EXPECT_EQ(speed["source"], "measured") << speed.dump();
  ASSERT_TRUE(speed["calibration"].is_number()) << speed.dump();
  EXPECT_EQ(speed["recent"].size(), 0u) << "the calibration frames are not observed as frames";
  EXPECT_DOUBLE_EQ(speed["factor"].get<double>(), speed["calibration"].get<double>());
  EXPECT_GT(speed["factor"].get<double>(), api::MachineSpeed::kMinRatio);
  EXPECT_LT(speed["factor"].get<double>(), api::MachineSpeed::kMaxRatio);
  expectTheChoosersChoice(body, r);
  // direct's model at the frame's pixels times the factor (supersampling 1 under a budget).
  const double px = double(size) * size;
  EXPECT_NEAR(r["stats"]["budget"]["techniques"]["direct"]["predicted_ms"].get<double>(),
              speed["factor"].get<double>() * table.predictMs("direct", json::object(), px), 1e-9);

  // Fresh seeds: comparable frames join the window (the first budgeted frame may have compiled its
  // point's shaders, so count from the second): the machine's factor is the median of window and
  // calibration; the frame's is its scene's own (api::MachineSpeed).
  int observed = r["stats"]["budget"]["speed"]["observed"].get<bool>();
  for (std::uint64_t seed = 12; seed < 16; ++seed) {
    body = budgeted(seed);
    r = d.render(body);
    ASSERT_FALSE(r.contains("http_status")) << r.dump();
    expectTheChoosersChoice(body, r);
    speed = r["stats"]["budget"]["speed"];
    std::vector<double> all = speed["recent"].get<std::vector<double>>();
    all.push_back(speed["calibration"].get<double>());
    EXPECT_DOUBLE_EQ(speed["machine"].get<double>(), median(all)) << speed.dump();
    // Every observed frame is this scene's and recent: its factor is the median of its own ratios.
    if (!speed["scene"]["recent"].empty()) {
      EXPECT_EQ(speed["scene"]["basis"], "own") << speed.dump();
      EXPECT_DOUBLE_EQ(speed["median"].get<double>(), median(speed["scene"]["recent"].get<std::vector<double>>()))
          << speed.dump();
    } else {
      EXPECT_DOUBLE_EQ(speed["median"].get<double>(), speed["machine"].get<double>()) << speed.dump();
    }
    // The budget plans with the median times its headroom (api::MachineSpeed::planningFactor).
    EXPECT_GE(speed["headroom"].get<double>(), 1.0);
    EXPECT_LE(speed["headroom"].get<double>(), api::MachineSpeed::kMaxHeadroom);
    EXPECT_NEAR(speed["factor"].get<double>(), speed["median"].get<double>() * speed["headroom"].get<double>(),
                1e-12 * speed["factor"].get<double>())
        << speed.dump();
    observed += speed["observed"].get<bool>();
    std::printf("seed %llu: speed %s, predicted %.1f ms, measured %.1f ms\n", static_cast<unsigned long long>(seed),
                speed.dump().c_str(), r["stats"]["budget"]["predicted_ms"].get<double>(),
                r["stats"]["budget"]["measured_ms"].get<double>());
  }
  EXPECT_GE(observed, 2) << "frames with fresh seeds are comparable with the table";
  EXPECT_EQ(r["stats"]["budget"]["speed"]["recent"].size(), std::size_t(observed) - r["stats"]["budget"]["speed"]["observed"].get<bool>())
      << "the window holds the observed frames before this one";
  // The same seed and point again: its photons are reused, so the frame is not observed.
  const json again = d.render(budgeted(15));
  if (again["stats"]["budget"]["techniques"]["photon_gi"]["params"] == r["stats"]["budget"]["techniques"]["photon_gi"]["params"]) {
    EXPECT_FALSE(again["stats"]["budget"]["speed"]["observed"].get<bool>()) << again["stats"]["cache"].dump();
  }

  // Pinned: exactly 4x the table, no calibration.
  RealDaemon pinned("speed-pinned", {"--speed-factor", "4"});
  ASSERT_TRUE(pinned.ready()) << testing::slurp(pinned.dir / "stderr.log");
  body = budgeted(11);
  body["width"] = body["height"] = 32;
  r = pinned.render(body);
  ASSERT_FALSE(r.contains("http_status")) << r.dump();
  speed = r["stats"]["budget"]["speed"];
  EXPECT_EQ(speed["source"], "pinned");
  EXPECT_EQ(speed["factor"], 4.0);
  EXPECT_TRUE(speed["calibration"].is_null());
  expectTheChoosersChoice(body, r);
  EXPECT_NEAR(r["stats"]["budget"]["techniques"]["direct"]["predicted_ms"].get<double>(),
              4.0 * table.predictMs("direct", json::object(), 32.0 * 32.0), 1e-9);
}

double rmse(const Image& a, const Image& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) s += (double(a.pixels[i]) - b.pixels[i]) * (double(a.pixels[i]) - b.pixels[i]);
  return std::sqrt(s / double(a.pixels.size()));
}

TEST(Refinement, TheEstimatedErrorOfTheReferenceTracksItsTrueError) {
  RealDaemon d("refine");
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  const int size = 32;
  json base{{"scene", {{"builtin", "cornell_box"}}}, {"width", size}, {"height", size},
            {"passes", {{"photon_gi", false}}}, {"outputs", {{{"format", "exr"}, {"half", false}, {"aovs", {"reference"}}}}}};
  // Ground truth: 2048 spp, seed 1000 (independent of the batches' seeds 0..15).
  json truthReq = base;
  truthReq["seed"] = 1000;
  truthReq["passes"]["reference"] = {{"spp", 2048}};
  const json truthOut = d.render(truthReq);
  ASSERT_FALSE(truthOut.contains("http_status")) << truthOut.dump();
  Image truth = d.image(truthOut["frames"][0]["url"]);

  json body = base;
  body["passes"]["reference"] = {{"spp", 4}};
  body["async"] = true;
  body["refine"] = {{"max_batches", 16}, {"aov", "reference"}};
  auto c = d.daemon.client();
  auto r = c.Post("/v1/renders", body.dump(), "application/json");
  ASSERT_EQ(r->status, 202) << r->body;
  const std::string location = r->get_header_value("Location");
  json state = json::object();
  double midEstimate = 0, midTrue = 0;
  int midBatches = 0;
  for (int i = 0; i < 6000 && state.value("state", "") != "done" && state.value("state", "") != "failed"; ++i) {
    state = json::parse(c.Get(location.c_str())->body);
    // Once, mid-way: the current mean and its estimate, served while the job refines.
    if (!midBatches && state.contains("refinement") && state["refinement"]["batches"].get<int>() >= 4 &&
        state["state"] == "running") {
      auto cur = c.Get((location + "?current=exr").c_str());
      ASSERT_EQ(cur->status, 200);
      midBatches = std::stoi(cur->get_header_value("X-Radiant-Batches"));
      midEstimate = std::stod(cur->get_header_value("X-Radiant-Estimated-Rmse"));
      io::writeFile((d.dir / "current.exr").string(), cur->body);
      midTrue = rmse(io::readImage((d.dir / "current.exr").string()), truth);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(state["state"], "done") << state.dump();
  const json& f = state["stats"]["refinement"];
  EXPECT_EQ(f["batches"], 16);
  const double estimate = f["estimated_rmse"];
  const Image mean = d.image(state["frames"][0]["url"]);
  // True error of the mean: its variance plus the ground truth's (2048 spp against 64: 1/32 of it), so
  // sqrt(1 + 1/32) = 1.016 of the estimate when the estimate is exact.
  const double trueError = rmse(mean, truth);
  std::printf("16 batches of 4 spp: estimated rmse %.5f, true %.5f (ratio %.3f); after %d batches: %.5f vs %.5f\n",
              estimate, trueError, estimate / trueError, midBatches, midEstimate, midTrue);
  // Within a factor 1.5: the batch variance of a path tracer is itself noisy (15 degrees of freedom per
  // pixel, heavy-tailed paths), averaged over 3072 pixel channels.
  EXPECT_GT(estimate / trueError, 1 / 1.5);
  EXPECT_LT(estimate / trueError, 1.5);
  if (midBatches >= 2) {
    EXPECT_GT(midEstimate / midTrue, 1 / 1.5);
    EXPECT_LT(midEstimate / midTrue, 1.5);
    EXPECT_LT(estimate, midEstimate);  // more batches, less error
  }
}

// A refining job with a compare block scores the batches' mean, not one batch: stats.metrics of the
// finished job, and the current mean's RMSE while it refines, equal the RMSE the test computes from the
// frames themselves against the ground truth the job returns. photon_gi's error then splits as
// bias^2 + noise^2 / batches: the mean's squared error minus its estimated noise is the bias (plus the
// ground truth's own noise), and one batch's squared error is that plus batches x the mean's noise.
TEST(Refinement, ACompareBlockScoresTheMeanAgainstTheGroundTruth) {
  RealDaemon d("refine-compare");
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  const int size = 32, batches = 8;
  json base = cornell(size, 0);
  base["outputs"] = {{{"format", "exr"}, {"half", false}, {"aovs", {"indirect"}}}};
  base["passes"] = {{"photon_gi", {{"photons", 20000}}}};
  base["compare"] = {{"aov", "indirect"}, {"spp", 256}};
  // One batch alone (the job's first seed), scored by an ordinary compare block.
  const json one = d.render(base);
  ASSERT_FALSE(one.contains("http_status")) << one.dump();
  const double oneBatchRmse = one["stats"]["metrics"]["rmse"];

  json body = base;
  body["async"] = true;
  body["refine"] = {{"max_batches", batches}, {"aov", "indirect"}};
  auto c = d.daemon.client();
  auto r = c.Post("/v1/renders", body.dump(), "application/json");
  ASSERT_EQ(r->status, 202) << r->body;
  const std::string location = r->get_header_value("Location");
  json state = json::object();
  double midRmse = -1;
  int midBatches = 0;
  for (int i = 0; i < 6000 && state.value("state", "") != "done" && state.value("state", "") != "failed"; ++i) {
    state = json::parse(c.Get(location.c_str())->body);
    if (!midBatches && state.contains("refinement") && state["refinement"]["batches"].get<int>() >= 2 &&
        state["state"] == "running") {
      auto cur = c.Get((location + "?current=exr").c_str());
      ASSERT_EQ(cur->status, 200);
      midBatches = std::stoi(cur->get_header_value("X-Radiant-Batches"));
      midRmse = std::stod(cur->get_header_value("X-Radiant-Rmse"));
      io::writeFile((d.dir / "current.exr").string(), cur->body);
      EXPECT_TRUE(state["refinement"]["metrics"]["rmse"].is_number()) << state.dump();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(state["state"], "done") << state.dump();
  const json& m = state["stats"]["metrics"];
  ASSERT_TRUE(m.is_object()) << state["stats"].dump();
  EXPECT_EQ(m["batches"], batches);
  EXPECT_EQ(m["aov"], "indirect");
  const fs::path frame = d.dir / "mean.exr";
  io::writeFile(frame.string(), c.Get(state["frames"][0]["url"].get<std::string>().c_str())->body);
  const Image mean = io::readImage(frame.string(), "indirect"), truth = io::readImage(frame.string(), "reference");
  // The reported score is the mean's (float EXR: the same numbers up to rounding).
  const double meanRmse = m["rmse"];
  EXPECT_NEAR(rmse(mean, truth), meanRmse, 1e-5 * meanRmse);
  if (midBatches >= 2) {
    const Image current = io::readImage((d.dir / "current.exr").string(), "indirect");
    EXPECT_NEAR(rmse(current, truth), midRmse, 1e-5 * midRmse) << "after " << midBatches << " batches";
  }
  // bias^2 + noise^2: the mean's noise is the batches' standard error; one batch has `batches` times its
  // variance.
  const double estimate = state["stats"]["refinement"]["noise_rmse"];
  const double bias2 = meanRmse * meanRmse - estimate * estimate;
  const double predictedOne = std::sqrt(bias2 + batches * estimate * estimate);
  std::printf("photon_gi indirect, %d batches of 20000 photons: one batch rmse %.5f, mean %.5f, estimated noise of "
              "the mean %.5f, so bias %.5f and one batch predicted %.5f\n",
              batches, oneBatchRmse, meanRmse, estimate, std::sqrt(std::max(0.0, bias2)), predictedOne);
  // The job's error estimate is the mean's score against the ground truth, bias included (issue 32).
  EXPECT_EQ(state["stats"]["refinement"]["estimate_kind"], "against_ground_truth");
  EXPECT_NEAR(state["stats"]["refinement"]["estimated_rmse"].get<double>(), meanRmse, 1e-12);
  EXPECT_NEAR(state["stats"]["refinement"]["bias_rmse"].get<double>(), std::sqrt(std::max(0.0, bias2)), 1e-9);
  EXPECT_LT(meanRmse, oneBatchRmse);
  EXPECT_GT(bias2, 0.0) << "the kernel's bias: the mean's error exceeds its noise";
  // The estimate is itself noisy (7 degrees of freedom per pixel channel): within 25 %.
  EXPECT_NEAR(predictedOne, oneBatchRmse, 0.25 * oneBatchRmse);
}

// Issue 32: refinement's error estimate includes the bias where a ground truth scores the refined AOV.
// photon_gi's indirect light at 32 px with 20000 photons is bias-dominated (the test above: the mean's
// error 0.24 against a noise estimate of 0.04 after 8 batches). A target between the two is reached by
// the noise estimate after a few batches, but not by the true error: the job must run all its batches
// instead of stopping on an error it does not have. Without compare the estimate is the noise, so said.
TEST(Refinement, TargetRmseStopsOnTheErrorAgainstTheGroundTruthBiasIncluded) {
  RealDaemon d("refine-target-bias");
  ASSERT_TRUE(d.ready()) << testing::slurp(d.dir / "stderr.log");
  json body = cornell(32, 0);
  body["outputs"] = {{{"format", "exr"}, {"half", false}, {"aovs", {"indirect"}}}};
  body["passes"] = {{"photon_gi", {{"photons", 20000}}}};
  body["async"] = true;
  body["refine"] = {{"max_batches", 4}, {"aov", "indirect"}, {"target_rmse", 0.12}};
  auto finished = [&](const json& request) {
    auto c = d.daemon.client();
    auto r = c.Post("/v1/renders", request.dump(), "application/json");
    EXPECT_EQ(r->status, 202) << r->body;
    const std::string location = r->get_header_value("Location");
    json state = json::object();
    for (int i = 0; i < 6000 && state.value("state", "") != "done" && state.value("state", "") != "failed"; ++i) {
      state = json::parse(c.Get(location.c_str())->body);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return state;
  };
  const json noiseOnly = finished(body);
  ASSERT_EQ(noiseOnly["state"], "done") << noiseOnly.dump();
  const json& n = noiseOnly["stats"]["refinement"];
  EXPECT_EQ(n["estimate_kind"], "noise_only");
  EXPECT_EQ(n["stopped_by"], "target_rmse") << n.dump();
  EXPECT_LE(n["estimated_rmse"].get<double>(), 0.12);
  EXPECT_EQ(n["estimated_rmse"], n["noise_rmse"]);

  body["compare"] = {{"aov", "indirect"}, {"spp", 256}};
  body["seed"] = 1;
  const json withTruth = finished(body);
  ASSERT_EQ(withTruth["state"], "done") << withTruth.dump();
  const json& t = withTruth["stats"]["refinement"];
  EXPECT_EQ(t["estimate_kind"], "against_ground_truth");
  EXPECT_EQ(t["stopped_by"], "max_batches") << t.dump();
  EXPECT_EQ(t["batches"], 4);
  EXPECT_GT(t["estimated_rmse"].get<double>(), 0.12);
  EXPECT_LT(t["noise_rmse"].get<double>(), 0.12);
  EXPECT_EQ(t["estimated_rmse"], withTruth["stats"]["metrics"]["rmse"]);
}

}  // namespace
}  // namespace radiant
