// Runs sweep points against one or several servers: `inflight` workers per server pull points from
// one queue, so a faster server takes more of them; each point runs all its renders on one server.
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <ctime>
#include <deque>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>

#include "client/Commands.h"
#include "client/report/Thumbnails.h"
#include "client/sweep/Sweep.h"

namespace radiant::client::sweep {

namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

struct Interrupted {};
// The server (not the point) failed: unreachable, shutting down, or refusing our token.
struct ServerGone : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Server {
  std::string url;
  std::unique_ptr<HttpClient> http;
  json info;
  std::mutex uploadMutex;
  std::set<std::string> uploaded;
  bool dead = false;  // guarded by Shared::m
  // A daemon with --daemon-id, or a proxy in front of several (docs/DEPLOYMENT.md): renders carry the
  // scene digest header, and a render the proxy could not complete (502/504, a draining daemon's 503)
  // is sent again, after re-uploading the scene when it landed on a daemon without it.
  bool fleet = false;
  std::map<std::string, std::string> builtinDigests;  // name -> digest, from GET /v1/scenes
};

// One render as the runner saw it.
struct Rendered {
  json result;
  std::vector<std::string> frames;  // the encoded frames, in the order of the request's outputs
  double latencyMs = 0;
  std::string daemon;  // X-Radiant-Daemon of the answer ("" for a daemon without --daemon-id)
};

// Renders through a proxy are retried this often (a second apart) before the server counts as gone.
constexpr int kFleetRetries = 60;

std::string isoNow() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

std::string clockText(double seconds) {
  const long s = static_cast<long>(seconds + 0.5);
  char buf[32];
  if (s >= 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  else std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  return buf;
}

const std::set<std::string> kSupportPasses{"gbuffer", "shadow_maps", "direct", "tonemap", "reference"};

// Which technique a point measures and which of its parameters names the method (for grouping in
// reports): the spec says so, or it is the one pass beyond the support passes, and its parameter
// called "method", else its first string parameter with an enum.
void classify(const Point& p, const json& info, json& record) {
  std::string technique = p.technique;
  const json passes = p.request.value("passes", json::object());
  if (technique.empty()) {
    for (const auto& [name, v] : passes.items())
      if (!kSupportPasses.count(name)) technique += (technique.empty() ? "" : "+") + name;
    if (technique.empty()) technique = passes.empty() || passes.contains("direct") ? "direct" : passes.begin().key();
  }
  std::string methodPath = p.method;
  if (methodPath.empty()) {
    for (const auto& t : info.value("techniques", json::array())) {
      if (t.value("name", "") != technique) continue;
      const json params = t.value("params", json::object());
      if (params.contains("method")) {
        methodPath = "passes." + technique + ".method";
        break;
      }
      for (const auto& [name, schema] : params.items())
        if (schema.value("type", "") == "string" && schema.contains("enum")) {
          methodPath = "passes." + technique + "." + name;
          break;
        }
    }
  }
  std::string method;
  if (!methodPath.empty()) {
    if (const json* v = findPath(p.request, methodPath)) {
      method = v->is_string() ? v->get<std::string>() : v->dump();
    } else {
      // Not in the request: the schema's default.
      const auto dot = methodPath.rfind('.');
      for (const auto& t : info.value("techniques", json::array()))
        if (t.value("name", "") == technique && t["params"].contains(methodPath.substr(dot + 1))) {
          const json& d = t["params"][methodPath.substr(dot + 1)]["default"];
          method = d.is_string() ? d.get<std::string>() : d.dump();
        }
    }
  }
  record["technique"] = technique;
  record["method"] = method;
  record["method_param"] = methodPath;
}

struct Shared {
  std::mutex m;
  std::condition_variable cv;
  std::deque<const Point*> pending;
  int active = 0;   // points being rendered
  int workers = 0;  // live worker threads
  RunSummary summary;
  std::vector<std::string> lines;  // finished-point lines for the main thread to print
  int finishedThisRun = 0;
};

class Runner {
public:
  Runner(ResultsFile& results, const RunOptions& o)
      : results_(results), o_(o), tty_(isatty(STDERR_FILENO) && !o.quiet) {}

  RunSummary run(const std::vector<Point>& points) {
    const auto start = Clock::now();
    for (const auto& url : o_.servers) {
      auto s = std::make_unique<Server>();
      s->url = url;
      s->http = std::make_unique<HttpClient>(url, o_.token);
      try {
        s->info = HttpClient::expectOk(s->http->get("/v1/info")).json();
        s->fleet = s->info.contains("daemon_id") && s->info["daemon_id"].is_string();
        if (s->fleet) {
          const json scenes = HttpClient::expectOk(s->http->get("/v1/scenes")).json();
          for (const auto& b : scenes.value("builtins", json::array()))
            s->builtinDigests[b.value("name", "")] = b.value("digest", "");
        }
      } catch (const UnreachableError& e) {
        dropServer(*s, e.what());
      } catch (const ServerError& e) {
        dropServer(*s, "GET /v1/info answered " + std::to_string(e.status) + ": " + e.what());
      }
      servers_.push_back(std::move(s));
    }
    if (!o_.thumbnails.empty()) fs::create_directories(o_.thumbnails);
    sh_.summary.total = static_cast<int>(points.size());
    for (const auto& p : points) {
      if (results_.done(p.id, o_.retryFailed)) ++sh_.summary.skipped;
      else sh_.pending.push_back(&p);
    }
    const int todo = static_cast<int>(sh_.pending.size());
    if (!o_.quiet)
      std::cerr << "sweep: " << points.size() << " points, " << sh_.summary.skipped << " already in "
                << results_.path().string() << ", " << todo << " to run on " << o_.servers.size() << " server(s)\n";
    std::vector<std::thread> threads;
    for (auto& s : servers_) {
      if (s->dead) continue;
      for (int i = 0; i < o_.inflight; ++i) {
        ++sh_.workers;
        threads.emplace_back([this, srv = s.get()] { worker(*srv); });
      }
    }
    const bool tty = tty_;
    bool announcedStop = false;
    for (;;) {
      std::unique_lock lock(sh_.m);
      sh_.cv.wait_for(lock, std::chrono::milliseconds(200));
      if (o_.stop && *o_.stop && !announcedStop) {
        announcedStop = true;
        sh_.cv.notify_all();
        std::cerr << (tty ? "\r\033[K" : "") << "sweep: stopping; waiting for " << sh_.active
                  << " render(s) in flight (their points are not recorded; Ctrl-C again to quit at once)\n";
      }
      for (const auto& l : sh_.lines) std::cerr << (tty ? "\r\033[K" : "") << l << "\n";
      sh_.lines.clear();
      const int finished = sh_.finishedThisRun;
      const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      if (tty && todo > 0) {
        const int width = 30, filled = width * finished / todo;
        std::ostringstream bar;
        bar << "\r\033[K[" << std::string(filled, '#') << std::string(width - filled, '.') << "] " << finished << "/"
            << todo << " " << (100 * finished / todo) << "%  " << clockText(elapsed);
        if (finished > 0 && finished < todo) bar << "  ETA " << clockText(elapsed / finished * (todo - finished));
        for (const auto& s : servers_)
          bar << "  " << s->url.substr(s->url.find("//") + 2) << "=" << sh_.summary.perServer[s->url]
              << (s->dead ? "(lost)" : "");
        std::cerr << bar.str() << std::flush;
      }
      if (sh_.workers == 0) break;
    }
    for (auto& t : threads) t.join();
    if (tty && todo > 0) std::cerr << "\n";
    sh_.summary.remaining = static_cast<int>(sh_.pending.size());
    sh_.summary.interrupted = o_.stop && *o_.stop;
    return sh_.summary;
  }

private:
  void dropServer(Server& s, const std::string& why) {
    s.dead = true;
    sh_.summary.lost[s.url] = why;
    std::cerr << (tty_ ? "\r\033[K" : "") << "sweep: server " << s.url << " dropped: " << why << "\n";
  }

  bool stopping() const { return (o_.stop && o_.stop->load()) || failed_.load(); }

  void worker(Server& s) {
    for (;;) {
      const Point* p = nullptr;
      {
        std::unique_lock lock(sh_.m);
        sh_.cv.wait(lock, [&] { return s.dead || stopping() || !sh_.pending.empty() || sh_.active == 0; });
        if (s.dead || stopping() || sh_.pending.empty()) break;
        p = sh_.pending.front();
        sh_.pending.pop_front();
        ++sh_.active;
      }
      json record;
      try {
        record = runPoint(s, *p);
      } catch (const Interrupted&) {
        std::lock_guard lock(sh_.m);
        --sh_.active;
        sh_.pending.push_front(p);  // counted as remaining
        break;
      } catch (const ServerGone& e) {
        std::lock_guard lock(sh_.m);
        --sh_.active;
        sh_.pending.push_front(p);  // another server takes it
        if (!s.dead) dropServer(s, e.what());
        break;
      } catch (const std::exception& e) {  // the client failed (cannot write results): stop everything
        std::lock_guard lock(sh_.m);
        --sh_.active;
        sh_.pending.push_front(p);
        if (!s.dead) dropServer(s, std::string("client error: ") + e.what());
        break;
      }
      try {
        results_.append(record);
      } catch (const std::exception& e) {  // the results file cannot be written: stop everything
        std::lock_guard lock(sh_.m);
        --sh_.active;
        sh_.pending.push_front(p);
        if (fatal_.empty()) fatal_ = e.what();
        sh_.summary.lost["(client)"] = fatal_;
        failed_ = true;
        sh_.cv.notify_all();
        break;
      }
      std::lock_guard lock(sh_.m);
      --sh_.active;
      ++sh_.finishedThisRun;
      ++sh_.summary.perServer[s.url];
      const bool ok = !record.contains("error");
      ok ? ++sh_.summary.done : ++sh_.summary.failed;
      if (!o_.quiet) {
        std::ostringstream line;
        line << "[" << sh_.summary.skipped + sh_.finishedThisRun << "/" << sh_.summary.total << "] " << p->sweep << " "
             << paramLabel(p->params) << "  ";
        if (ok) {
          char buf[128];
          std::snprintf(buf, sizeof buf, "gpu %.2f ms  e2e %.1f ms", record["frame_gpu_ms"]["median"].get<double>(),
                        record["latency_ms"]["median"].get<double>());
          line << buf;
          if (record["metrics"].is_object() && record["metrics"].contains("rmse"))
            line << "  rmse " << record["metrics"]["rmse"].get<double>();
        } else {
          line << "error " << record["error"].value("status", 0) << ": " << record["error"].value("detail", "");
        }
        line << "  @" << s.url;
        sh_.lines.push_back(line.str());
      }
      sh_.cv.notify_all();
    }
    std::lock_guard lock(sh_.m);
    --sh_.workers;
    sh_.cv.notify_all();
  }

  // The scene digest a proxy routes a render on: the uploaded file's, or the built-in's.
  static std::string routingDigest(const Server& s, const json& request) {
    const json scene = request.value("scene", json::object());
    if (!scene.is_object()) return "";
    if (scene.contains("digest") && scene["digest"].is_string()) return scene["digest"];
    if (scene.contains("builtin") && scene["builtin"].is_string())
      if (auto it = s.builtinDigests.find(scene["builtin"].get<std::string>()); it != s.builtinDigests.end()) return it->second;
    return "";
  }

  // Uploads the point's scene file unless this server has it; `again` after a render found it missing
  // (a proxy moved the scene to another daemon). HEAD first, so workers that race here upload once.
  void upload(Server& s, const Point& p, bool again) {
    std::lock_guard lock(s.uploadMutex);
    if (!again && s.uploaded.count(p.sceneFile)) return;
    try {
      ensureSceneUploaded(*s.http, sceneFileBytes(p.sceneFile), p.sceneFile, false);
    } catch (const UnreachableError& e) {
      throw ServerGone(e.what());
    }
    s.uploaded.insert(p.sceneFile);
    if (again && !o_.quiet) {
      std::lock_guard shared(sh_.m);
      sh_.lines.push_back("sweep: " + p.sceneFile + " was missing behind " + s.url + " (a daemon was lost); re-uploaded it");
    }
  }

  void pause(int seconds) {
    for (int i = 0; i < seconds * 10 && !stopping(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }

  // One render, with the frames downloaded.
  Rendered renderOnce(Server& s, const Point& p, const json& body) {
    const std::string text = body.dump();
    const Headers headers = sceneHeader(routingDigest(s, body));
    int retries = 0;
    for (;;) {
      if (stopping()) throw Interrupted{};
      const auto t0 = Clock::now();
      HttpResponse r;
      try {
        r = s.http->post("/v1/renders", text, "application/json", headers);
        const std::string type = r.status >= 400 ? problemType(r) : "";
        if (r.status == 503 && type == "queue-full") {
          // Another client fills the queue: wait as told, then retry the same render.
          pause(std::clamp(std::atoi(r.header("retry-after").c_str()), 1, 10));
          continue;
        }
        if (s.fleet && retries < kFleetRetries) {
          const FleetRetry retry = fleetRetry(r);
          if (retry == FleetRetry::Again) {
            ++retries;
            pause(1);
            continue;
          }
          if (retry == FleetRetry::Reupload && !p.sceneFile.empty()) {
            ++retries;
            upload(s, p, true);
            continue;
          }
        }
        if (r.status == 503 || r.status == 401) {
          const json problem = json::parse(r.body, nullptr, false);
          throw ServerGone("POST /v1/renders answered " + std::to_string(r.status) + " (" +
                           (problem.is_object() ? problem.value("detail", r.body) : r.body) + ")");
        }
        HttpClient::expectOk(r);
        json result = r.json();
        bool frameLost = false;
        std::vector<std::string> frames;
        for (const auto& f : result.value("frames", json::array())) {
          HttpResponse frame = s.http->get(f.value("url", ""));
          // The daemon holding the frames died after rendering: render again elsewhere.
          if (s.fleet && (frame.status == 502 || frame.status == 504) && retries < kFleetRetries) {
            frameLost = true;
            break;
          }
          HttpClient::expectOk(frame);
          frames.push_back(std::move(frame.body));
        }
        if (frameLost) {
          ++retries;
          pause(1);
          continue;
        }
        const double latency = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        try {
          s.http->del("/v1/renders/" + result.value("id", ""));  // free the frame store; not timed
        } catch (const std::exception&) {
        }
        return {std::move(result), std::move(frames), latency, r.header("x-radiant-daemon")};
      } catch (const UnreachableError& e) {
        throw ServerGone(e.what());
      }
    }
  }

  json runPoint(Server& s, const Point& p) {
    json record{{"point_id", p.id},   {"sweep", p.sweep},     {"params", p.params},   {"factors", p.factors},
                {"request", p.request}, {"repeats", p.repeats}, {"warmup", p.warmup}, {"server", s.url},
                {"command", o_.command}};
    if (!p.compare.is_null()) record["request"]["compare"] = p.compare;
    classify(p, s.info, record);
    try {
      if (!p.sceneFile.empty()) upload(s, p, false);
      json request = p.request;
      request["async"] = false;
      const int untimed = std::max(p.warmup, p.compare.is_null() ? 0 : 1);
      std::vector<double> gpu, cpu, prepare, latency, render, queue, encode;
      std::vector<std::string> order;
      struct PassTimes {
        std::vector<double> gpu, cpu, prepare;
      };
      std::map<std::string, PassTimes> perPass;
      json last;
      std::set<std::string> daemons;  // behind a proxy: which daemons rendered this point
      // The compare render also asks for an EXR of the compared AOV, which then carries the error and
      // reference layers (docs/API.md): the point's thumbnail. It is not timed.
      const std::string compareAov = p.compare.is_object() ? p.compare.value("aov", "beauty") : "beauty";
      for (int k = 0; k < untimed + p.repeats; ++k) {
        json body = request;
        std::size_t thumbnailFrame = SIZE_MAX;
        if (k == 0 && !p.compare.is_null()) {
          body["compare"] = p.compare;
          if (!o_.thumbnails.empty()) {
            if (!body.contains("outputs") || !body["outputs"].is_array()) body["outputs"] = json::array();
            const json exr{{"format", "exr"}, {"aovs", {compareAov}}, {"half", false}};
            if (body["outputs"].size() < 8 && std::find(body["outputs"].begin(), body["outputs"].end(), exr) == body["outputs"].end()) {
              thumbnailFrame = body["outputs"].size();
              body["outputs"].push_back(exr);
            }
          }
        }
        auto [result, frames, ms, daemon] = renderOnce(s, p, body);
        if (thumbnailFrame < frames.size()) {
          try {
            const fs::path file = o_.thumbnails / (p.id + ".exr");
            writeFile(file.string(), report::encodeThumbnail(report::thumbnailFromFrame(frames[thumbnailFrame], compareAov)));
            record["thumbnail"] = {{"file", (o_.thumbnails.filename() / file.filename()).string()}, {"aov", compareAov}};
          } catch (const std::runtime_error&) {  // no error/reference layers (a failed compare): no thumbnail
          }
        }
        if (!daemon.empty()) daemons.insert(daemon);
        const json stats = result.value("stats", json::object());
        if (k == 0 && !p.compare.is_null()) record["metrics"] = stats.value("metrics", json());
        if (k < untimed) continue;
        double g = 0, c = 0, pr = 0;
        for (const auto& pass : stats.value("passes", json::array())) {
          const std::string name = pass.value("name", "");
          if (!perPass.count(name)) order.push_back(name);
          PassTimes& t = perPass[name];
          t.gpu.push_back(pass.value("gpu_ms", 0.0));
          t.cpu.push_back(pass.value("cpu_ms", 0.0));
          // prepare() (allocations, cache lookups, the derived data built on a miss: docs/API.md);
          // a daemon older than prepare_ms reports none.
          t.prepare.push_back(pass.value("prepare_ms", 0.0));
          g += t.gpu.back();
          c += t.cpu.back();
          pr += t.prepare.back();
        }
        gpu.push_back(g);
        cpu.push_back(c);
        prepare.push_back(pr);
        latency.push_back(ms);
        render.push_back(stats.value("render_ms", 0.0));
        const json timings = result.value("timings", json::object());
        queue.push_back(timings.value("queue_ms", 0.0));
        encode.push_back(timings.value("encode_ms", 0.0));
        last = stats;
      }
      json passes = json::array();
      for (const auto& name : order) {
        const PassTimes& t = perPass[name];
        json entry{{"name", name},
                   {"gpu_ms", summarize(t.gpu)},
                   {"cpu_ms", summarize(t.cpu)},
                   {"prepare_ms", summarize(t.prepare)}};
        for (const auto& pass : last.value("passes", json::array()))
          if (pass.value("name", "") == name && pass.contains("counters")) entry["counters"] = pass["counters"];
        passes.push_back(entry);
      }
      record["passes"] = passes;
      record["frame_gpu_ms"] = summarize(gpu);
      record["frame_cpu_ms"] = summarize(cpu);
      record["frame_prepare_ms"] = summarize(prepare);
      record["latency_ms"] = summarize(latency);
      record["render_ms"] = summarize(render);
      record["queue_ms"] = summarize(queue);
      record["encode_ms"] = summarize(encode);
      if (!record.contains("metrics")) record["metrics"] = nullptr;
      record["skipped"] = last.value("skipped", json::object());
      // The cost models' scene variables (api::SceneCounts), which bench/presets.py fits against.
      if (last.contains("scene") && last["scene"].is_object() && last["scene"].contains("counts"))
        record["scene_counts"] = last["scene"]["counts"];
      record["cache"] = last.value("cache", json::array());
      record["device"] = last.value("device", s.info.value("device", json()));
      if (!daemons.empty()) record["daemons"] = daemons;
    } catch (const ServerError& e) {
      json error{{"status", e.status}, {"detail", e.what()}};
      for (const char* k : {"type", "title", "pointer", "request_id", "render_id"})
        if (e.problem.contains(k)) error[k] = e.problem[k];
      record["error"] = error;
      record["device"] = s.info.value("device", json());
    }
    record["finished"] = isoNow();
    return record;
  }

  ResultsFile& results_;
  const RunOptions& o_;
  bool tty_;
  std::atomic<bool> failed_{false};
  std::string fatal_;  // guarded by sh_.m
  std::vector<std::unique_ptr<Server>> servers_;
  Shared sh_;
};

}  // namespace

RunSummary run(const std::vector<Point>& points, ResultsFile& results, const RunOptions& options) {
  return Runner(results, options).run(points);
}

}  // namespace radiant::client::sweep
