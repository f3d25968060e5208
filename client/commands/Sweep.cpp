// radiant sweep / report / bench.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <future>
#include <iostream>
#include <sstream>
#include <tuple>

#include "client/Cli.h"
#include "client/report/Report.h"
#include "client/sweep/Sweep.h"

namespace radiant::client {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::atomic<bool> gStop{false};

// First SIGINT/SIGTERM: finish the renders in flight, record nothing partial, exit. Second: exit at
// once (every record is already a whole line, so the file stays consistent).
void onSignal(int) {
  if (gStop.exchange(true)) ::_exit(130);
}

void installStopHandler() {
  struct sigaction sa{};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

std::string commandLine(const std::string& name, const std::vector<std::string>& args) {
  std::string c = "radiant " + name;
  for (const auto& a : args) c += " " + (a.find_first_of(" '\"") == std::string::npos ? a : "'" + a + "'");
  return c;
}

fs::path csvPathFor(const fs::path& results) {
  fs::path csv = results;
  csv.replace_extension(".csv");
  return csv;
}

// Runs points into `resultsPath`, writes the CSV view; returns the exit code.
int runPoints(const std::vector<sweep::Point>& points, const fs::path& resultsPath, sweep::RunOptions o) {
  sweep::ResultsFile results(resultsPath);
  // Thumbnails beside the results: RESULTS.thumbs/<point>.exr.
  o.thumbnails = resultsPath.parent_path() / (resultsPath.stem().string() + ".thumbs");
  installStopHandler();
  o.stop = &gStop;
  const sweep::RunSummary s = sweep::run(points, results, o);
  const auto all = results.all();
  sweep::writeCsv(all, csvPathFor(resultsPath));
  std::cerr << "sweep: " << s.done << " done, " << s.failed << " failed, " << s.skipped << " skipped (already done), "
            << s.remaining << " not run; results in " << resultsPath.string() << " and "
            << csvPathFor(resultsPath).string() << "\n";
  for (const auto& [url, n] : s.perServer) std::cerr << "  " << url << ": " << n << " points\n";
  for (const auto& [url, why] : s.lost) {
    if (url == "(client)") {
      std::cerr << "sweep: error: stopped: " << why << "\n";
      return 1;
    }
    std::cerr << "sweep: error: lost server " << url << ": " << why << "\n";
  }
  if (s.interrupted) {
    std::cerr << "sweep: interrupted; run the same command again to resume\n";
    return 130;
  }
  if (s.remaining > 0) {
    std::cerr << "sweep: error: " << s.remaining
              << " point(s) not run because no server is left; run the same command again to resume\n";
    return kExitUnreachable;
  }
  return s.failed > 0 ? kExitServerError : kExitOk;
}

struct SweepOptions {
  std::string specFile, out;
  sweep::RunOptions run;
  bool dryRun = false;
};

struct ReportOptions {
  std::vector<std::string> inputs;
  std::string out;
  report::Options report;
};

struct BenchOptions {
  std::string dir = "bench-out";
  bool quick = false, service = false, noReport = false, dryRun = false;
  int requests = 20, size = 256, throughputN = 40, pngCompression = 1;
  std::string scene = "cornell_box";
  CLI::Option* sceneGiven = nullptr;
  std::vector<std::string> techniques;  // the suite: only these (empty = every implemented one)
  sweep::RunOptions run;
  bool fidelity = false;
  CLI::Option* sizeGiven = nullptr;
  FidelityOptions fid;
  bool equalError = false;
  EqualErrorOptions eq;
};

int runSweep(const GlobalOptions& g, SweepOptions so) {
  const std::string& specFile = so.specFile;
  std::string out = so.out;
  sweep::RunOptions& o = so.run;
  const bool dryRun = so.dryRun;
  if (specFile.empty()) throw UsageError("sweep: no spec given");
  std::vector<sweep::Point> points;
  for (const auto& spec : sweep::parseSpecFile(specFile))
    for (auto& p : sweep::expand(spec)) points.push_back(std::move(p));
  if (dryRun) {
    for (const auto& p : points)
      std::cout << p.id << "  " << p.sweep << "  " << sweep::paramLabel(p.params) << "\n";
    std::cout << points.size() << " points\n";
    return kExitOk;
  }
  if (out.empty()) out = fs::path(specFile).stem().string() + ".jsonl";
  if (o.servers.empty()) o.servers.push_back(g.server);
  o.token = g.token;
  o.command = commandLine("sweep", g.commandArgs);
  return runPoints(points, out, o);
}

int runReport(const GlobalOptions& g, ReportOptions ro) {
  const std::vector<std::string>& inputs = ro.inputs;
  const std::string& out = ro.out;
  report::Options& o = ro.report;
  if (inputs.empty() || out.empty()) throw UsageError("report: give RESULTS.jsonl and -o DIR");
  static const std::set<std::string> metrics{"rmse", "rel_mse", "mean_abs", "max_abs", "psnr", "ssim"};
  if (!metrics.count(o.metric)) throw UsageError("report: --metric must be one of rmse, rel_mse, mean_abs, max_abs, psnr, ssim");
  std::vector<json> records;
  for (const auto& in : inputs)
    for (auto& r : sweep::readRecords(in)) records.push_back(std::move(r));
  if (records.empty()) throw UsageError("report: no records in " + inputs.front());
  o.command = commandLine("report", g.commandArgs);
  o.source = inputs.front();
  for (std::size_t i = 1; i < inputs.size(); ++i) o.source += ", " + inputs[i];
  const report::Summary s = report::write(records, out, o);
  std::cout << "wrote " << s.html.string() << " and " << s.markdown.string() << " (" << s.records << " points, "
            << s.errors << " failed, " << s.plots << " plots)\n";
  return kExitOk;
}

// A technique's preset: the descriptor's "bench" (renderer/techniques/<name>/<name>.json, served in
// /v1/info's techniques[].bench): axes over its parameters, extra request fields, and the compare block
// for a technique whose outputs have no ground truth. Parameters this server's schema lacks, and values
// outside its range or enum, are dropped (fitToSchema), so the suite also runs against an older or
// newer server. What scores a technique is not a preset: benchCompare() reads it from the server.
struct Preset {
  json axes;      // dotted path -> values
  json compare;   // compare block for a technique whose outputs have no ground truth (scored on beauty)
  json extra;     // extra request fields
};

// The compare block of a technique's sweep: its first output AOV with a ground truth in /v1/info
// (techniques[].ground_truths, Technique::groundTruth on the server), and the bounce range the
// technique declares with it; the preset's block when none has one.
json benchCompare(const json& technique, const json& fallback) {
  const json truths = technique.value("ground_truths", json::object());
  for (const auto& aov : technique.value("outputs", json::array())) {
    const auto t = truths.find(aov.get<std::string>());
    if (t == truths.end() || !t->is_object()) continue;
    json c{{"aov", aov}};
    if (t->contains("max_bounces")) c["max_bounces"] = (*t)["max_bounces"];
    return c;
  }
  return fallback;
}

Preset presetFor(const json& technique, bool quick) {
  // What the server sent: anything but objects (an older server has no "bench") counts as no preset.
  auto object = [](const json& j, const char* key) {
    const auto it = j.find(key);
    return it != j.end() && it->is_object() ? *it : json::object();
  };
  const json bench = object(technique, "bench");
  Preset out{json::object(), object(bench, "compare"), object(bench, "request")};
  const std::string prefix = "passes." + technique.value("name", "") + ".";
  const json axes = object(bench, "axes");
  for (const auto& [param, modes] : axes.items())
    if (modes.is_object() && modes.contains(quick ? "quick" : "full")) out.axes[prefix + param] = modes[quick ? "quick" : "full"];
  return out;
}

json fitToSchema(const json& axes, const json& params, const std::string& technique) {
  json out = json::object();
  const std::string prefix = "passes." + technique + ".";
  for (const auto& [path, values] : axes.items()) {
    const std::string name = path.substr(prefix.size());
    if (!params.contains(name)) continue;
    const json& s = params[name];
    json kept = json::array();
    for (const auto& v : values) {
      if (s.contains("enum") && std::find(s["enum"].begin(), s["enum"].end(), v) == s["enum"].end()) continue;
      const json lo = s.contains("minimum") ? s["minimum"] : s.value("min", json());
      const json hi = s.contains("maximum") ? s["maximum"] : s.value("max", json());
      if (v.is_number() && lo.is_number() && v.get<double>() < lo.get<double>()) continue;
      if (v.is_number() && hi.is_number() && v.get<double>() > hi.get<double>()) continue;
      kept.push_back(v);
    }
    if (!kept.empty()) out[path] = kept;
  }
  // Techniques without presets: every value of their method-like enum parameter.
  if (out.empty()) {
    for (const auto& [name, s] : params.items())
      if (s.value("type", "") == "string" && s.contains("enum") && (name == "method" || out.empty()))
        out = json{{prefix + name, s["enum"]}};
  }
  return out;
}

int serviceBench(const GlobalOptions& g, const fs::path& dir, int requests, int size, const std::string& scene,
                 int throughputN, int pngCompression) {
  HttpClient http(g.server, g.token);
  const json info = HttpClient::expectOk(http.get("/v1/info")).json();
  using Clock = std::chrono::steady_clock;
  struct Sample {
    double latency, render, queue, encode, server;
  };
  auto once = [&](const HttpClient& c, const json& req) {
    const auto t0 = Clock::now();
    const HttpResponse r = c.post("/v1/renders", req.dump(), "application/json");
    HttpClient::expectOk(r);
    const json res = r.json();
    for (const auto& f : res["frames"]) HttpClient::expectOk(c.get(f["url"].get<std::string>()));
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    const json& t = res["timings"];
    Sample s{ms, res["stats"].value("render_ms", 0.0), t.value("queue_ms", 0.0), t.value("encode_ms", 0.0),
             t.value("queue_ms", 0.0) + t.value("render_ms", 0.0) + t.value("encode_ms", 0.0)};
    c.del("/v1/renders/" + res.value("id", ""));
    return s;
  };
  const json req{{"scene", {{"builtin", scene}}}, {"width", size}, {"height", size},
                 {"outputs", {{{"format", "png"}, {"aovs", {"beauty"}}, {"png_compression", pngCompression}}}}};
  for (int i = 0; i < 3; ++i) once(http, req);  // scene cached, shaders compiled
  std::vector<Sample> samples;
  for (int i = 0; i < requests; ++i) samples.push_back(once(http, req));
  auto median = [](std::vector<double> v) { return sweep::summarize(std::move(v))["median"].get<double>(); };
  auto col = [&](double Sample::*m) {
    std::vector<double> v;
    for (const auto& s : samples) v.push_back(s.*m);
    return v;
  };
  std::vector<double> overhead, overheadNoEncode, transport;
  for (const auto& s : samples) {
    overhead.push_back(100.0 * (s.latency - s.render) / s.render);
    overheadNoEncode.push_back(100.0 * (s.latency - s.encode - s.render) / s.render);
    transport.push_back(s.latency - s.server);
  }
  const double mLat = median(col(&Sample::latency)), mRender = median(col(&Sample::render)),
               mQueue = median(col(&Sample::queue)), mEncode = median(col(&Sample::encode)),
               mServer = median(col(&Sample::server)), mOver = median(overhead),
               mOverNoEncode = median(overheadNoEncode), mTransport = median(transport);
  // Throughput: back-to-back small requests, 1 and 4 in flight.
  const json small{{"scene", {{"builtin", scene}}}, {"width", 32}, {"height", 32},
                   {"outputs", {{{"format", "png"}, {"aovs", {"beauty"}}}}}};
  json tput = json::array();
  for (int inflight : {1, 4}) {
    std::atomic<int> next{0};
    std::vector<double> renders;
    std::mutex m;
    const auto t0 = Clock::now();
    std::vector<std::future<void>> workers;
    for (int w = 0; w < inflight; ++w)
      workers.push_back(std::async(std::launch::async, [&] {
        HttpClient c(g.server, g.token);
        while (next++ < throughputN) {
          const Sample s = once(c, small);
          std::lock_guard lock(m);
          renders.push_back(s.render);
        }
      }));
    for (auto& w : workers) w.get();
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    tput.push_back({{"in_flight", inflight}, {"requests", throughputN}, {"seconds", wall},
                    {"requests_per_s", throughputN / wall}, {"render_ms_median", median(renders)},
                    {"render_bound_per_s", 1000.0 / median(renders)}});
  }
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  json result{{"date", date},
              {"server", g.server},
              {"device", info.value("device", json())},
              {"overhead", {{"scene", scene}, {"size", size}, {"format", "png"}, {"requests", requests},
                            {"latency_ms_median", mLat}, {"frame_ms_median", mRender}, {"queue_ms_median", mQueue},
                            {"encode_ms_median", mEncode}, {"server_ms_median", mServer},
                            {"overhead_pct_median", mOver}, {"overhead_without_encode_pct_median", mOverNoEncode},
                            {"http_json_download_ms_median", mTransport}, {"overhead_pct_of_medians", 100.0 * (mLat - mRender) / mRender},
                            {"target_pct", 15}, {"within_target", mOver <= 15.0}}},
              {"throughput", tput}};
  fs::create_directories(dir);
  writeFile((dir / "service.json").string(), result.dump(2) + "\n");
  std::cout << "Service overhead, " << scene << " " << size << "x" << size << " PNG, median over " << requests
            << " sequential requests (" << date << ", " << info["device"].value("renderer", "?") << "):\n\n"
            << "| end-to-end ms | renderer frame ms | queue ms | PNG encode ms | HTTP + JSON + download ms | overhead | "
               "overhead without encode | target |\n"
            << "|---|---|---|---|---|---|---|---|\n"
            << "| " << report::formatNumber(mLat) << " | " << report::formatNumber(mRender) << " | "
            << report::formatNumber(mQueue) << " | " << report::formatNumber(mEncode) << " | "
            << report::formatNumber(mTransport) << " | " << report::formatNumber(mOver) << " % | "
            << report::formatNumber(mOverNoEncode) << " % | <= 15 % " << (mOver <= 15.0 ? "(met)" : "(missed)")
            << " |\n\n(overheads: median over requests of (end-to-end - frame) / frame)\n\n"
            << "Throughput, " << throughputN << " back-to-back 32x32 PNG requests:\n\n"
            << "| in flight | requests/s | renderer frame ms (median) | bound by render time, requests/s |\n|---|---|---|---|\n";
  for (const auto& t : tput)
    std::cout << "| " << t["in_flight"] << " | " << report::formatNumber(t["requests_per_s"]) << " | "
              << report::formatNumber(t["render_ms_median"]) << " | " << report::formatNumber(t["render_bound_per_s"])
              << " |\n";
  std::cout << "\nwrote " << (dir / "service.json").string() << "\n";
  return kExitOk;
}

int runBench(const GlobalOptions& g, BenchOptions bo) {
  const fs::path dir = bo.dir;
  const bool quick = bo.quick, service = bo.service, makeReport = !bo.noReport, dryRun = bo.dryRun;
  const int requests = bo.requests, size = bo.size, throughputN = bo.throughputN, pngCompression = bo.pngCompression;
  const std::string& scene = bo.scene;
  sweep::RunOptions& o = bo.run;
  if (bo.fidelity) {
    if (service) throw UsageError("bench: --fidelity and --service are separate benchmarks");
    FidelityOptions& f = bo.fid;
    f.dir = bo.dir;
    if (bo.sizeGiven && bo.sizeGiven->count()) f.size = size;
    f.servers = o.servers;
    f.quiet = o.quiet;
    if (f.maxSpp < f.spp) throw UsageError("bench --fidelity: --max-spp must be at least --spp");
    return fidelityBench(g, f);
  }
  if (bo.equalError) {
    if (service || bo.fidelity) throw UsageError("bench: --equal-error, --fidelity and --service are separate benchmarks");
    EqualErrorOptions& e = bo.eq;
    e.dir = bo.dir;
    if (bo.sizeGiven && bo.sizeGiven->count()) e.size = size;
    if (bo.sceneGiven && bo.sceneGiven->count()) e.scenes = {scene};
    e.servers = o.servers;
    e.quiet = o.quiet;
    return equalErrorBench(g, e);
  }
  if (service) return serviceBench(g, dir, requests, size, scene, throughputN, pngCompression);
  if (o.servers.empty()) o.servers.push_back(g.server);
  // The suite follows what the (first) server implements and ships.
  HttpClient http(o.servers.front(), g.token);
  const json info = HttpClient::expectOk(http.get("/v1/info")).json();
  const json scenes = HttpClient::expectOk(http.get("/v1/scenes")).json();
  json sceneNames = json::array();
  for (const auto& b : scenes.value("builtins", json::array())) {
    const std::string name = b.value("name", "");
    if (bo.sceneGiven && bo.sceneGiven->count() ? name == scene
                                                 : !quick || name == "cornell_box" || name == "ao_creases" || name == "cornell_mirror")
      sceneNames.push_back(name);
  }
  if (sceneNames.empty() && bo.sceneGiven && bo.sceneGiven->count())
    throw UsageError("bench: the server has no built-in scene \"" + scene + "\" (radiant scenes lists them)");
  static const std::set<std::string> support{"gbuffer", "shadow_maps", "tonemap", "reference"};
  const std::vector<int> sizes = quick ? std::vector<int>{32, 64} : std::vector<int>{128, 256};
  json sweeps = json::array();
  for (const auto& t : info.value("techniques", json::array())) {
    const std::string name = t.value("name", "");
    if (support.count(name) || !t.value("available", true)) continue;
    if (!bo.techniques.empty() && std::find(bo.techniques.begin(), bo.techniques.end(), name) == bo.techniques.end())
      continue;
    const Preset preset = presetFor(t, quick);
    json axes{{"scene.builtin", sceneNames}};
    const json fitted = fitToSchema(preset.axes, t.value("params", json::object()), name);
    for (const auto& [path, values] : fitted.items())
      axes[path] = values;
    json base{{"scene", {{"builtin", sceneNames.empty() ? "cornell_box" : sceneNames[0]}}},
              {"passes", {{name, json::object()}}},
              {"outputs", {{{"format", "png"}, {"aovs", {"beauty"}}}}}};
    for (const auto& [k, v] : preset.extra.items()) base[k] = v;
    json compare = benchCompare(t, preset.compare);
    compare["spp"] = quick ? 16 : 64;
    sweeps.push_back({{"name", "bench-" + name},
                      {"technique", name},
                      {"base", base},
                      {"axes", axes},
                      {"zip", {{{"width", sizes}, {"height", sizes}}}},
                      {"repeats", quick ? 2 : 3},
                      {"warmup", 1},
                      {"compare", compare}});
  }
  if (sweeps.empty())
    throw UsageError(bo.techniques.empty() ? "bench: the server implements no technique to measure"
                                           : "bench: the server implements none of the --technique names (radiant info lists them)");
  fs::create_directories(dir);
  const fs::path specFile = dir / "bench.spec.json";
  writeFile(specFile.string(), json{{"sweeps", sweeps}}.dump(2) + "\n");
  std::vector<sweep::Point> points;
  for (const auto& spec : sweep::parseSpecFile(specFile))
    for (auto& p : sweep::expand(spec)) points.push_back(std::move(p));
  if (dryRun) {
    std::cout << "wrote " << specFile.string() << " (" << points.size() << " points)\n";
    return kExitOk;
  }
  o.token = g.token;
  o.command = commandLine("bench", g.commandArgs);
  const fs::path results = dir / "results.jsonl";
  const int code = runPoints(points, results, o);
  if (code == 130 || !makeReport) return code;
  report::Options ro;
  ro.title = std::string("Radiant benchmark") + (quick ? " (quick)" : "");
  ro.source = results.string();
  ro.command = o.command;
  // The tables of the suite's sibling benchmarks run into the same DIR (bench --equal-error, --fidelity).
  for (const auto& [file, id, title] :
       {std::tuple{"equal_error.md", "equal-error", "Equal-error speed-up (radiant bench --equal-error)"},
        std::tuple{"fidelity.md", "fidelity", "Render fidelity of real models (radiant bench --fidelity)"}})
    if (fs::is_regular_file(dir / file)) ro.extra.push_back({id, title, readFile((dir / file).string())});
  const report::Summary s = report::write(sweep::readRecords(results), dir, ro);
  std::cout << "wrote " << s.html.string() << " and " << s.markdown.string() << " (" << s.records << " points, "
            << s.errors << " failed, " << s.plots << " plots)\n";
  return code;
}

}  // namespace

void addSweepCommands(CLI::App& root, const GlobalOptions& g, Action& action) {
  auto so = std::make_shared<SweepOptions>();
  CLI::App* sw = root.add_subcommand("sweep", "run a parameter sweep spec into a JSON Lines results file");
  sw->footer(
      "Runs every point of the spec (docs/SWEEPS.md) and appends one JSON line per point to RESULTS.jsonl\n"
      "(default: SPEC's name with .jsonl), plus a CSV view next to it. Points already in the file are skipped.");
  sw->add_option("spec", so->specFile, "the sweep spec")->type_name("SPEC.json");
  sw->add_option("-o,--output", so->out, "the results file")->type_name("RESULTS.jsonl");
  repeated(sw->add_option("--server", so->run.servers,
                          "a server to share the points with (repeatable, or comma-separated; default the global one)"))
      ->delimiter(',')
      ->type_name("URL");
  sw->add_option("--inflight", so->run.inflight, "requests in flight per server (default 1, so latency is not queueing)")
      ->type_name("N")
      ->check(CLI::Range(1, 64));
  sw->add_flag("--retry-failed", so->run.retryFailed, "run the points recorded as failed again");
  sw->add_flag("--dry-run", so->dryRun, "list the points instead of running them");
  sw->add_flag("-q,--quiet", so->run.quiet, "no per-point lines and no progress bar");
  sw->callback([&g, &action, so] { action = [&g, so] { return runSweep(g, *so); }; });

  auto ro = std::make_shared<ReportOptions>();
  CLI::App* rep = root.add_subcommand("report", "HTML + Markdown report of sweep results");
  rep->footer("Writes DIR/report.html (self-contained, plots inline) and DIR/report.md (plots in DIR/plots/).");
  rep->add_option("results", ro->inputs, "one or more results files")->type_name("RESULTS.jsonl");
  rep->add_option("-o,--output", ro->out, "the report's directory")->type_name("DIR");
  rep->add_option("--metric", ro->report.metric, "the error axis of the Pareto plots (default rmse)")
      ->type_name(choices({"rmse", "rel_mse", "mean_abs", "max_abs", "psnr", "ssim"}));
  rep->add_option("--title", ro->report.title, "the report's title")->type_name("TEXT");
  rep->callback([&g, &action, ro] { action = [&g, ro] { return runReport(g, *ro); }; });

  auto bo = std::make_shared<BenchOptions>();
  CLI::App* b = root.add_subcommand("bench", "the standard benchmark suite, or --service for the service's own overhead");
  b->footer(
      "The standard suite: every built-in scene x every implemented technique at its presets x two\n"
      "resolutions, with error against the reference. Writes DIR/bench.spec.json, DIR/results.jsonl (+.csv),\n"
      "DIR/report.html and DIR/report.md (with DIR/equal_error.md and DIR/fidelity.md when those benchmarks\n"
      "wrote them into DIR first). Re-running resumes. Each technique is scored on its first output\n"
      "AOV that has a ground truth in the server's /v1/info (ground_truths).\n"
      "--service: the service's overhead (end-to-end latency against the renderer's frame time) and the\n"
      "throughput of back-to-back small requests; writes DIR/service.json and prints a Markdown table.\n"
      "--fidelity: every model under --models x every map under --environments at one orbit camera, the\n"
      "default frame (background transparent, tone_map aces) scored against the reference path tracer\n"
      "(renders of --spp at seeds 0, 1, ... averaged until the even seeds' mean scores --converged-db\n"
      "against the odd seeds', at most --max-spp) with model-viewer's render-fidelity metric (dB, lower\n"
      "is better), relMSE and SSIM; writes\n"
      "DIR/fidelity.md (also printed), DIR/fidelity.json and per scene a contact sheet default | reference |\n"
      "error in DIR/fidelity/; references are cached in DIR/fidelity/reference/ (docs/PERFORMANCE.md).\n"
      "--equal-error: per built-in scene (--scene, default cornell_box, cornell_glossy and cornell_mirror), the\n"
      "default frame's RMSE against the reference at --truth-spp, the reference's RMSE at each --ladder spp,\n"
      "and the reference's spp and time at the frame's error (the truth's own noise fitted and removed): the\n"
      "equal-error speed-up; writes DIR/equal_error.md (also printed) and DIR/equal_error.json.");
  b->add_option("-o,--output,--out", bo->dir, "the output directory (default bench-out)")->type_name("DIR");
  b->add_flag("--quick", bo->quick, "three scenes, smaller frames, fewer repeats");
  b->add_flag("--service", bo->service, "measure the service's overhead and throughput instead");
  b->add_flag("--no-report", bo->noReport, "write the results only");
  b->add_flag("--dry-run", bo->dryRun, "write DIR/bench.spec.json and list the points; render nothing");
  repeated(b->add_option("--server", bo->run.servers, "a server to share the points with (repeatable, or comma-separated)"))
      ->delimiter(',')
      ->type_name("URL");
  b->add_option("--inflight", bo->run.inflight, "requests in flight per server")->type_name("N")->check(CLI::Range(1, 64));
  b->add_option("--requests", bo->requests, "--service: sequential requests (default 20)")->type_name("N")->check(CLI::Range(1, 10000));
  bo->sizeGiven = b->add_option("--size", bo->size,
                                "--service: frame size in pixels (default 256); --fidelity: (default 128); --equal-error: (default 64)")
                      ->type_name("PX")
                      ->check(CLI::Range(1, 4096));
  b->add_flag("--fidelity", bo->fidelity, "the render-fidelity benchmark of the default frame against the reference");
  b->add_option("--spp", bo->fid.spp, "--fidelity: samples per pixel of each reference render, one seed (default 1024)")
      ->type_name("N")
      ->check(CLI::Range(1, 65536));
  b->add_option("--max-spp", bo->fid.maxSpp,
                "--fidelity: the most samples per pixel the reference averages over seeds (default 16384; --spp's "
                "value: one seed, no convergence check)")
      ->type_name("N")
      ->check(CLI::Range(1, 1 << 20));
  b->add_option("--converged-db", bo->fid.convergedDb,
                "--fidelity: the reference is converged when its even seeds' mean scores at most this against its odd "
                "seeds' (default -23: its own noise, 3 dB less, lies 6 dB under issue 29's -20 dB goal and moves a score there by 0.1 dB)")
      ->type_name("DB")
      ->check(CLI::Range(-100.0, 0.0));
  b->add_option("--models", bo->fid.models, "--fidelity: the model folders (default ../shared/testdata/gltf-samples)")
      ->type_name("DIR");
  b->add_option("--environments", bo->fid.environments,
                "--fidelity: the .hdr/.exr maps (default ../shared/testdata/environments)")
      ->type_name("DIR");
  repeated(b->add_option("--model", bo->fid.onlyModels, "--fidelity: only this model folder (repeatable)"))->type_name("NAME");
  repeated(b->add_option("--environment", bo->fid.onlyEnvironments, "--fidelity: only this map, by file stem (repeatable)"))
      ->type_name("NAME");
  b->add_flag("--equal-error", bo->equalError, "the equal-error speed-up of the default frame over the reference");
  b->add_option("--truth-spp", bo->eq.truthSpp, "--equal-error: the truth's samples per pixel (default 4096)")
      ->type_name("N")
      ->check(CLI::Range(1, 65536));
  b->add_option("--ladder", bo->eq.ladder, "--equal-error: the reference's spp to fit (default 64,256,1024)")
      ->delimiter(',')
      ->type_name("LIST")
      ->check(CLI::Range(1, 65536));
  bo->sceneGiven = b->add_option("--scene", bo->scene,
                                 "the suite: only this built-in scene; --service: the built-in scene (default cornell_box)")
                       ->type_name("NAME");
  repeated(b->add_option("--technique", bo->techniques, "the suite: only this technique (repeatable; default every one)"))
      ->type_name("NAME");
  b->add_option("--throughput", bo->throughputN, "--service: back-to-back requests per throughput run (default 40)")
      ->type_name("N")
      ->check(CLI::Range(1, 100000));
  b->add_option("--png-compression", bo->pngCompression, "--service: zlib level of the PNGs (default 1)")
      ->type_name("0-9")
      ->check(CLI::Range(0, 9));
  b->add_flag("-q,--quiet", bo->run.quiet, "no per-point lines and no progress bar");
  b->callback([&g, &action, bo] { action = [&g, bo] { return runBench(g, *bo); }; });
}

}  // namespace radiant::client
