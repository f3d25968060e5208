#include "server/RenderService.h"

#include "api/JsonLimits.h"
#include "renderer/metrics/Metrics.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

namespace radiant::server {

using nlohmann::json;

namespace {

double msBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// "r-<hex>", or "<daemon id>-r-<hex>" behind a proxy, which routes the job's URLs on the prefix.
std::string newRenderId(const std::string& daemonId) {
  static std::mutex m;
  static std::mt19937_64 rng{std::random_device{}()};
  std::lock_guard lock(m);
  char buf[32];
  std::snprintf(buf, sizeof buf, "r-%016llx", static_cast<unsigned long long>(rng()));
  return daemonId.empty() ? std::string(buf) : daemonId + "-" + buf;
}

}  // namespace

const char* toString(JobState s) {
  switch (s) {
    case JobState::Queued: return "queued";
    case JobState::Running: return "running";
    case JobState::Encoding: return "encoding";
    case JobState::Done: return "done";
    case JobState::Failed: return "failed";
    case JobState::Canceled: return "canceled";
  }
  return "unknown";
}

std::vector<Image> selectAovs(const std::vector<Image>& aovs, const api::OutputSpec& spec, std::size_t outputIndex) {
  std::vector<Image> out;
  for (std::size_t i = 0; i < spec.aovs.size(); ++i) {
    const Image* found = nullptr;
    for (const auto& img : aovs)
      if (img.aov == spec.aovs[i]) found = &img;
    if (!found) {
      std::string have;
      for (const auto& img : aovs) have += (have.empty() ? "" : ", ") + img.aov;
      const std::string pointer = "/outputs/" + std::to_string(outputIndex) + "/aovs/" + std::to_string(i);
      throw api::ApiError(422, "aov-not-produced", "AOV not produced",
                          pointer + ": no pass that ran produced \"" + spec.aovs[i] + "\" (produced: " + have + ")",
                          pointer);
    }
    out.push_back(*found);
  }
  // With a compare block, an EXR also carries the error map and the ground truth it was scored
  // against, so the numbers in the stats can be inspected pixel by pixel.
  if (spec.format == api::ImageFormat::Exr)
    for (const char* extra : {"error", "reference"})
      for (const auto& img : aovs)
        if (img.aov == extra && std::none_of(out.begin(), out.end(), [&](const Image& o) { return o.aov == extra; }))
          out.push_back(img);
  return out;
}

RenderService::RenderService(const ServerConfig& config, const BackendHooks& hooks, FrameStore& frames,
                             Metrics& metrics)
    : config_(config), hooks_(hooks), frames_(frames), metrics_(metrics) {
  renderThread_ = std::thread([this] { renderLoop(); });
  for (int i = 0; i < std::max(1, config_.encoderThreads); ++i) encoders_.emplace_back([this] { encoderLoop(); });
  housekeeping_ = std::thread([this] { housekeepingLoop(); });
}

RenderService::~RenderService() { stop(); }

std::shared_ptr<Job> RenderService::submit(api::RenderRequest request, std::shared_ptr<const Scene> scene,
                                           std::shared_ptr<const Image> compareTarget,
                                           std::shared_ptr<const Image> environment, double sceneLoadMs) {
  auto job = std::make_shared<Job>();
  job->id = newRenderId(config_.daemonId);
  request.id = job->id;
  job->request = std::move(request);
  job->scene = std::move(scene);
  job->compareTarget = std::move(compareTarget);
  job->environment = std::move(environment);
  job->sceneLoadMs = sceneLoadMs;
  std::lock_guard lock(mutex_);
  if (draining_ || stopping_)
    throw api::ApiError(503, "shutting-down", "Shutting down", "the daemon is shutting down and accepts no new renders");
  if (queue_.size() >= static_cast<std::size_t>(config_.maxQueue)) {
    metrics_.countRender("rejected");
    throw api::ApiError(503, "queue-full", "Render queue full",
                        "the render queue holds " + std::to_string(queue_.size()) + " jobs, its limit; retry later");
  }
  job->submitted = Clock::now();
  job->deadline = job->submitted + std::chrono::duration_cast<Clock::duration>(
                                       std::chrono::duration<double>(config_.requestTimeoutS));
  queue_.push_back(job);
  jobs_[job->id] = job;
  changed_.notify_all();
  return job;
}

std::shared_ptr<Job> RenderService::find(const std::string& id) {
  std::lock_guard lock(mutex_);
  auto it = jobs_.find(id);
  return it == jobs_.end() ? nullptr : it->second;
}

bool RenderService::waitFor(const std::shared_ptr<Job>& job, Clock::time_point until) {
  std::unique_lock lock(mutex_);
  return changed_.wait_until(lock, until, [&] { return job->terminal(); });
}

json RenderService::describe(const Job& job) {
  std::lock_guard lock(mutex_);
  json j{{"id", job.id}, {"state", toString(job.state)}};
  double progress = 0;
  switch (job.state) {
    case JobState::Queued: {
      progress = 0;
      std::size_t pos = 0;
      for (; pos < queue_.size(); ++pos)
        if (queue_[pos].get() == &job) break;
      j["queue_position"] = pos;
      break;
    }
    // Rendering spans 0.05..0.9 of the job, following the renderer's progress (passes done, the running
    // pass's tiles or waves); encoding 0.9..1.
    case JobState::Running: progress = 0.05 + 0.85 * std::clamp(job.renderProgress.load(), 0.0, 1.0); break;
    case JobState::Encoding: progress = 0.9; j["state"] = "running"; j["phase"] = "encoding"; break;
    default: progress = 1; break;
  }
  if (job.state == JobState::Running) j["phase"] = "rendering";
  if (job.current && !job.terminal()) {
    const RefineSnapshot& c = *job.current;
    j["refinement"] = {{"batches", c.batches}, {"elapsed_ms", c.elapsedMs},
                       {"estimated_rmse", std::isfinite(c.estimatedRmse) ? json(c.estimatedRmse) : json(nullptr)},
                       {"noise_rmse", std::isfinite(c.noiseRmse) ? json(c.noiseRmse) : json(nullptr)},
                       {"estimate_kind", c.estimateKind}, {"current", "/v1/renders/" + job.id + "?current=exr"}};
    if (c.metrics.is_object()) j["refinement"]["metrics"] = c.metrics;  // the current mean against the ground truth
  }
  j["progress"] = progress;
  j["timings"] = {{"queue_ms", job.queueMs}, {"render_ms", job.renderMs}, {"encode_ms", job.encodeMs}};
  if (job.state == JobState::Done) {
    j["stats"] = job.stats;
    json frames = json::array();
    for (const auto& f : job.frames)
      frames.push_back({{"name", f.name}, {"url", f.url}, {"format", f.format}, {"aovs", f.aovs}, {"bytes", f.bytes}});
    j["frames"] = frames;
  }
  if (job.error) {
    const Problem& p = *job.error;
    j["error"] = {{"type", "https://radiant.dev/problems/" + p.type}, {"title", p.title}, {"status", p.status},
                  {"detail", p.detail}};
    if (!p.pointer.empty()) j["error"]["pointer"] = p.pointer;
  }
  return j;
}

std::shared_ptr<const RefineSnapshot> RenderService::current(const Job& job) {
  std::lock_guard lock(mutex_);
  return job.current;
}

// Batch k's seed: seed + k (mod m); with a first seed f (a session's next generation), f first, then
// seed, seed + 1, ... without f, so that the batches' seeds stay distinct.
std::uint64_t batchSeed(std::uint64_t seed, std::optional<std::uint64_t> first, int k, std::uint64_t m) {
  const std::uint64_t base = seed % m;
  if (!first) return (base + static_cast<std::uint64_t>(k)) % m;
  if (k == 0) return *first % m;
  const std::uint64_t j = static_cast<std::uint64_t>(k - 1);
  const std::uint64_t firstOffset = (*first % m + m - base) % m;  // where f sits in seed, seed + 1, ...
  return (base + j + (firstOffset <= j ? 1 : 0)) % m;
}

RenderOutput RenderService::refine(RenderBackend& backend, const std::shared_ptr<Job>& job, const Scene& scene,
                                   const FrameInputs& inputs) {
  const api::RefineSpec spec = *job->request.refine;
  api::RenderRequest batch = job->request;
  BatchMean acc;
  RenderOutput last;
  const auto start = Clock::now();
  double slowestBatchMs = 0;
  std::string stop = "max_batches";
  // compare: the mean is scored, after every batch, against the ground truth of the first batch's
  // compare block (server/Refinement.h, scoreMean). The frame's own "reference" AOV (an output, or the
  // compared AOV) is averaged like any other; the compare block's is the ground truth, added at the end.
  const std::optional<api::CompareSpec> compare = job->request.compare;
  bool frameHasReference = compare && compare->aov == "reference";
  for (const auto& o : job->request.outputs)
    frameHasReference = frameHasReference || std::count(o.aovs.begin(), o.aovs.end(), "reference");
  Image truth;
  std::shared_ptr<const Image> sharedTruth;  // the same for every snapshot
  json batchMetrics;
  constexpr std::uint64_t kMaxSeed = 9007199254740991ull;  // the schema's bound (2^53 - 1)
  for (int k = 0; k < spec.maxBatches; ++k) {
    // Progress: the larger of the batches' and the time limit's fraction.
    FrameInputs in = inputs;
    const double done = double(k) / spec.maxBatches;
    if (inputs.progress)
      in.progress = [&, done](double f) {
        const double byBatches = done + f / spec.maxBatches;
        const double byTime = spec.untilMs > 0 ? msBetween(start, Clock::now()) / spec.untilMs : 0.0;
        inputs.progress(std::clamp(std::max(byBatches, byTime), 0.0, 0.99));
      };
    batch.seed = batchSeed(job->request.seed, spec.firstSeed, k, kMaxSeed + 1);
    const auto t0 = Clock::now();
    last = backend.render(scene, batch, &job->cancel, in);
    slowestBatchMs = std::max(slowestBatchMs, msBetween(t0, Clock::now()));
    if (compare) {
      // Every batch runs the compare block (its ground truth is rendered once, then cached), so that
      // each reads back the compared AOV; the batch's own error map and ground truth are not averaged.
      if (k == 0) {
        truth = last.compareReference;
        batchMetrics = last.stats.metrics;
      }
      std::erase_if(last.aovs, [&](const Image& i) { return i.aov == "error" || (i.aov == "reference" && !frameHasReference); });
    }
    acc.add(last.aovs);
    auto snap = std::make_shared<RefineSnapshot>();
    snap->mean = acc.mean();
    snap->batches = acc.batches();
    snap->lastSeed = batch.seed;
    snap->noiseRmse = snap->estimatedRmse = acc.estimatedRmse(spec.aov);
    if (compare && !truth.pixels.empty())
      for (const Image& m : snap->mean)
        if (m.aov == compare->aov) snap->metrics = scoreMean(batchMetrics, m, truth, job->request.exposure, snap->batches);
    // The ground truth scores the refined AOV: its error holds the bias too (RefineSnapshot).
    if (snap->metrics.is_object() && compare->aov == spec.aov && snap->metrics.value("rmse", json()).is_number()) {
      snap->estimatedRmse = snap->metrics["rmse"].get<double>();
      snap->estimateKind = "against_ground_truth";
    }
    snap->elapsedMs = msBetween(start, Clock::now());
    snap->batchStats = last.stats;
    if (compare && !truth.pixels.empty()) {
      if (!sharedTruth) sharedTruth = std::make_shared<const Image>(truth);
      snap->truth = sharedTruth;
    }
    const double estimate = snap->estimatedRmse;
    const double elapsed = snap->elapsedMs;
    {
      std::lock_guard lock(mutex_);
      job->current = std::move(snap);
      if (k == 0 && std::none_of(last.aovs.begin(), last.aovs.end(), [&](const Image& i) { return i.aov == spec.aov; }))
        throw api::ApiError(422, "invalid-value", "Invalid value",
                            "/refine/aov: the frame has no AOV \"" + spec.aov + "\" (name it in outputs)", "/refine/aov");
    }
    if (spec.targetRmse > 0 && std::isfinite(estimate) && estimate <= spec.targetRmse) { stop = "target_rmse"; break; }
    if (spec.untilMs > 0 && elapsed >= spec.untilMs) { stop = "until_ms"; break; }
    // Another batch must end before the request timeout (with the slowest batch's time to spare).
    if (Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(
                           2 * slowestBatchMs + 1000)) > job->deadline) {
      stop = "request_timeout";
      break;
    }
    if (job->cancel) break;
  }
  RenderOutput out;
  out.aovs = acc.mean();
  out.stats = std::move(last.stats);  // the last batch's passes and counters
  // The last batch's snapshot holds the mean's scores and estimates (the accumulator has not changed since).
  std::shared_ptr<const RefineSnapshot> now;
  {
    std::lock_guard lock(mutex_);
    now = job->current;
  }
  if (compare && !truth.pixels.empty()) {
    // The mean's scores, error map and ground truth, as a compare block gives them for one frame.
    out.stats.metrics = now->metrics;
    for (const Image& m : out.aovs)
      if (m.aov == compare->aov) {
        Image err = metrics::errorMap(m, truth);
        err.aov = "error";
        out.aovs.push_back(std::move(err));
        break;
      }
    if (!frameHasReference) {
      out.aovs.push_back(truth);
      out.aovs.back().aov = "reference";
    }
    out.compareReference = std::move(truth);
  }
  const double estimate = now->noiseRmse;
  auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  out.stats.refinement = {{"batches", acc.batches()}, {"aov", spec.aov}, {"stopped_by", stop},
                          {"elapsed_ms", msBetween(start, Clock::now())},
                          {"estimated_rmse", number(now->estimatedRmse)},
                          {"noise_rmse", number(estimate)},
                          {"seeds", {job->request.seed, batch.seed}},
                          // noise_only: the batches' variance (server/Refinement.h), blind to a biased
                          // pass's bias (photon_gi's kernel); against_ground_truth: the compare block's
                          // score of the mean, bias included (RefineSnapshot).
                          {"estimate_kind", now->estimateKind}};
  // Scored against a ground truth on the refined AOV: the error splits as bias^2 + noise^2, so the part
  // the noise estimate does not explain (the bias, plus the ground truth's own noise) is measured.
  if (out.stats.metrics.is_object() && out.stats.metrics.value("aov", "") == spec.aov && std::isfinite(estimate)) {
    const double rmse = out.stats.metrics["rmse"].get<double>();
    out.stats.refinement["bias_rmse"] = std::sqrt(std::max(0.0, rmse * rmse - estimate * estimate));
  }
  out.stats.renderMs = msBetween(start, Clock::now());
  return out;
}

bool RenderService::terminal(const Job& job) {
  std::lock_guard lock(mutex_);
  return job.terminal();
}

RenderService::CancelResult RenderService::cancel(const std::string& id) {
  std::unique_lock lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return CancelResult::NotFound;
  std::shared_ptr<Job> job = it->second;
  switch (job->state) {
    case JobState::Queued:
      std::erase(queue_, job);
      finishLocked(*job, JobState::Canceled, Problem{409, "canceled", "Render canceled", "canceled while queued", ""});
      jobs_.erase(job->id);
      return CancelResult::Removed;
    case JobState::Running:
    case JobState::Encoding:
      job->cancel = true;
      return CancelResult::Requested;
    default:
      jobs_.erase(it);
      lock.unlock();
      frames_.eraseRender(id);
      return CancelResult::Forgotten;
  }
}

bool RenderService::ready() {
  std::lock_guard lock(mutex_);
  return ready_;
}
std::optional<DeviceInfo> RenderService::device() {
  std::lock_guard lock(mutex_);
  return device_;
}
std::string RenderService::notReadyReason() {
  std::lock_guard lock(mutex_);
  return notReadyReason_;
}
int RenderService::retryAfterSeconds() {
  std::lock_guard lock(mutex_);
  return std::max(1, static_cast<int>(std::ceil(meanRenderSeconds_ * static_cast<double>(queue_.size() + 1))));
}
std::size_t RenderService::queueDepth() {
  std::lock_guard lock(mutex_);
  return queue_.size();
}
int RenderService::active() {
  std::lock_guard lock(mutex_);
  return running_ + encoding_;
}

void RenderService::finishLocked(Job& job, JobState state, std::optional<Problem> error) {
  if (job.terminal()) return;
  job.state = state;
  job.finished = Clock::now();
  job.error = std::move(error);
  // A finished job (kept --frame-ttl for its frames) holds no decoded scene or image: they are charged
  // to the decode memory while held (docs/API.md, "Limits"). The render thread holds its own.
  job.scene.reset();
  job.compareTarget.reset();
  job.environment.reset();
  if (state == JobState::Done) metrics_.countRender("done");
  else if (job.timedOut) metrics_.countRender("timeout");
  else metrics_.countRender(state == JobState::Canceled ? "canceled" : "failed");
  changed_.notify_all();
}

void RenderService::renderLoop() {
  std::unique_ptr<RenderBackend> backend;
  double backoff = 0.25;
  for (;;) {
    if (!backend) {
      {
        std::lock_guard lock(mutex_);
        if (stopping_) break;
      }
      try {
        backend = hooks_.createBackend();
        DeviceInfo info = backend->device();
        std::lock_guard lock(mutex_);
        ready_ = true;
        device_ = info;
        notReadyReason_.clear();
        backoff = 0.25;
      } catch (const std::exception& e) {
        backend.reset();
        std::unique_lock lock(mutex_);
        ready_ = false;
        notReadyReason_ = std::string("creating the render backend failed: ") + e.what();
        std::cerr << "{\"event\":\"backend_create_failed\",\"detail\":" << api::dumpSafe(json(e.what())) << "}\n";
        changed_.wait_for(lock, std::chrono::duration<double>(backoff), [&] { return stopping_; });
        backoff = std::min(backoff * 2, 30.0);
        continue;
      }
    }

    std::shared_ptr<Job> job;
    // What the render reads, held here: a job that ends meanwhile (timed out) lets go of its own.
    std::shared_ptr<const Scene> scene;
    std::shared_ptr<const Image> compareTarget, environment;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) break;  // stopping and nothing left
      job = queue_.front();
      queue_.pop_front();
      scene = job->scene;
      compareTarget = job->compareTarget;
      environment = job->environment;
      job->state = JobState::Running;
      job->started = Clock::now();
      job->queueMs = msBetween(job->submitted, job->started);
      ++running_;
      changed_.notify_all();
    }
    metrics_.observeQueue(job->queueMs / 1000);

    std::optional<Problem> problem;
    RenderOutput output;
    bool recreate = false;
    try {
      Job* raw = job.get();
      // The caps: presets and budgets choose within this daemon's limits.
      FrameInputs inputs{compareTarget.get(), environment.get(),
                         [raw](double f) { raw->renderProgress.store(f); }, &config_.limits};
      output = job->request.refine ? refine(*backend, job, *scene, inputs)
                                   : backend->render(*scene, job->request, &job->cancel, inputs);
    } catch (const api::ApiError& e) {
      problem = Problem{e.status, e.type, e.title, e.detail(), e.pointer};
    } catch (const std::exception& e) {
      problem = Problem{500, "render-failed", "Render failed", std::string("render ") + job->id + ": " + e.what(), ""};
      recreate = true;
    } catch (...) {
      problem = Problem{500, "render-failed", "Render failed", "render " + job->id + ": unknown exception", ""};
      recreate = true;
    }
    const auto rendered = Clock::now();
    const double renderS = std::chrono::duration<double>(rendered - job->started).count();
    metrics_.observeRender(renderS);
    if (!problem)
      for (const auto& p : output.stats.passes) {
        metrics_.observePass(p.name, "gpu", p.gpuMs / 1000);
        metrics_.observePass(p.name, "cpu", p.cpuMs / 1000);
        metrics_.observePass(p.name, "prepare", p.prepareMs / 1000);
      }
    if (recreate) {
      std::cerr << "{\"event\":\"backend_recreate\",\"render_id\":" << api::dumpSafe(json(job->id))
                << ",\"detail\":" << api::dumpSafe(json(problem->detail)) << "}\n";
      backend.reset();  // destroyed here, on the thread that owns its context
      std::lock_guard lock(mutex_);
      ready_ = false;
      notReadyReason_ = "recreating the render backend after: " + problem->detail;
    }

    std::lock_guard lock(mutex_);
    --running_;
    changed_.notify_all();  // drain() waits for running_ to reach 0
    meanRenderSeconds_ = 0.8 * meanRenderSeconds_ + 0.2 * renderS;
    job->rendered = rendered;
    job->renderMs = renderS * 1000;
    if (job->terminal()) continue;  // timed out meanwhile
    if (problem && !(job->cancel && problem->status == 409)) {
      finishLocked(*job, JobState::Failed, problem);
    } else if (job->cancel) {
      // Canceled while running, whether the renderer noticed (its 409 between passes or inside a long
      // pass) or finished first: the job ends "canceled" as docs/API.md says, never "failed".
      finishLocked(*job, JobState::Canceled, Problem{409, "canceled", "Render canceled", "canceled while running", ""});
    } else {
      job->state = JobState::Encoding;
      ++encoding_;
      encodeQueue_.emplace_back(job, std::move(output));
      encodeReady_.notify_one();
      changed_.notify_all();
    }
  }
  backend.reset();
}

void RenderService::encoderLoop() {
  for (;;) {
    std::pair<std::shared_ptr<Job>, RenderOutput> work;
    {
      std::unique_lock lock(mutex_);
      encodeReady_.wait(lock, [&] { return stopping_ || !encodeQueue_.empty(); });
      if (encodeQueue_.empty()) return;
      work = std::move(encodeQueue_.front());
      encodeQueue_.pop_front();
    }
    encode(work.first, std::move(work.second));
  }
}

void RenderService::encode(const std::shared_ptr<Job>& job, RenderOutput output) {
  const auto start = Clock::now();
  std::optional<Problem> problem;
  std::vector<FrameInfo> infos;
  try {
    const auto& outputs = job->request.outputs;
    for (std::size_t i = 0; i < outputs.size(); ++i) {
      if (job->cancel) break;
      const api::OutputSpec& spec = outputs[i];
      std::string bytes = hooks_.encodeFrame(output.aovs, spec, i, job->request.exposure);
      FrameInfo f;
      f.format = api::toString(spec.format);
      f.name = std::to_string(i) + "." + f.format;
      f.url = "/v1/frames/" + job->id + "/" + f.name;
      f.aovs = spec.aovs;
      f.bytes = bytes.size();
      frames_.put(job->id, f.name, std::move(bytes), spec.format == api::ImageFormat::Exr ? "image/x-exr" : "image/png");
      infos.push_back(std::move(f));
    }
  } catch (const api::ApiError& e) {
    problem = Problem{e.status, e.type, e.title, e.detail(), e.pointer};
  } catch (const std::exception& e) {
    problem = Problem{500, "encode-failed", "Encoding failed", std::string("render ") + job->id + ": " + e.what(), ""};
  }
  const auto end = Clock::now();
  metrics_.observeEncode(std::chrono::duration<double>(end - start).count());
  std::lock_guard lock(mutex_);
  --encoding_;
  job->encodeMs = msBetween(start, end);
  changed_.notify_all();
  if (job->terminal()) {  // timed out while encoding
    frames_.eraseRender(job->id);
    return;
  }
  if (problem) {
    frames_.eraseRender(job->id);
    finishLocked(*job, JobState::Failed, problem);
  } else if (job->cancel) {
    frames_.eraseRender(job->id);
    finishLocked(*job, JobState::Canceled, Problem{409, "canceled", "Render canceled", "canceled while encoding", ""});
  } else {
    job->stats = std::move(output.stats);
    job->stats.sceneLoadMs = job->sceneLoadMs;
    job->stats.encodeMs = job->encodeMs;
    if (job->stats.renderMs == 0) job->stats.renderMs = job->renderMs;
    job->frames = std::move(infos);
    finishLocked(*job, JobState::Done, std::nullopt);
  }
}

void RenderService::housekeepingLoop() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    changed_.wait_for(lock, std::chrono::milliseconds(50), [&] { return stopping_; });
    const auto now = Clock::now();
    for (auto it = queue_.begin(); it != queue_.end();) {
      Job& job = **it;
      if (now >= job.deadline) {
        job.timedOut = true;
        finishLocked(job, JobState::Failed,
                     Problem{504, "timeout", "Render timed out",
                             "render " + job.id + " waited in the queue past the request timeout of " +
                                 std::to_string(config_.requestTimeoutS) + " s",
                             ""});
        it = queue_.erase(it);
      } else {
        ++it;
      }
    }
    const auto ttl = std::chrono::duration<double>(config_.frameTtlS);
    std::vector<std::string> expired;
    for (auto& [id, job] : jobs_) {
      if ((job->state == JobState::Running || job->state == JobState::Encoding) && now >= job->deadline &&
          !job->terminal()) {
        job->cancel = true;
        job->timedOut = true;
        finishLocked(*job, JobState::Failed,
                     Problem{504, "timeout", "Render timed out",
                             "render " + id + " ran past the request timeout of " +
                                 std::to_string(config_.requestTimeoutS) + " s",
                             ""});
      }
      if (job->terminal() && now - job->finished > ttl) expired.push_back(id);
    }
    for (const auto& id : expired) jobs_.erase(id);
    lock.unlock();
    for (const auto& id : expired) frames_.eraseRender(id);
    frames_.purgeExpired();
    lock.lock();
  }
}

void RenderService::drain() {
  std::unique_lock lock(mutex_);
  draining_ = true;
  changed_.wait(lock, [&] { return queue_.empty() && running_ == 0 && encoding_ == 0; });
}

void RenderService::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && !renderThread_.joinable()) return;
    stopping_ = true;
    draining_ = true;
    // Jobs still queued at a hard stop fail rather than hang their waiters.
    for (auto& job : queue_)
      finishLocked(*job, JobState::Failed, Problem{503, "shutting-down", "Shutting down", "the daemon stopped", ""});
    queue_.clear();
    changed_.notify_all();
    encodeReady_.notify_all();
  }
  if (renderThread_.joinable()) renderThread_.join();
  for (auto& t : encoders_)
    if (t.joinable()) t.join();
  encoders_.clear();
  if (housekeeping_.joinable()) housekeeping_.join();
}

}  // namespace radiant::server
