#pragma once
// The render queue and the threads behind it:
//   - one render thread: creates the backend (and with it the GL context), then runs jobs one at a
//     time; catches everything, and recreates the backend after an environment failure;
//   - an encoder pool: turns rendered AOVs into EXR/PNG off the render thread, into the FrameStore;
//   - a housekeeping thread: enforces deadlines (a timed-out job leaves the queue at once; a running
//     one gets its cancel flag) and expires finished jobs and frames.
// The queue is bounded: submit() refuses with 503 when maxQueue jobs are already waiting.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/Types.h"
#include "server/Backend.h"
#include "server/Config.h"
#include "server/FrameStore.h"
#include "server/Metrics.h"
#include "server/Refinement.h"

namespace radiant::server {

using Clock = std::chrono::steady_clock;

enum class JobState { Queued, Running, Encoding, Done, Failed, Canceled };
const char* toString(JobState s);

struct Problem {  // a failed job's error, rendered as problem+json
  int status = 500;
  std::string type, title, detail, pointer;
};

struct FrameInfo {
  std::string name, url, format;
  std::vector<std::string> aovs;
  std::size_t bytes = 0;
};

struct Job {
  std::string id;
  api::RenderRequest request;
  // The decoded scene, and the images the request names by digest (null when it names none); charged
  // to the decode memory while held, so released when the job ends (guarded by the mutex from then).
  std::shared_ptr<const Scene> scene;
  std::shared_ptr<const Image> compareTarget;  // compare.against
  std::shared_ptr<const Image> environment;    // environment
  double sceneLoadMs = 0;                      // decoding the scene for this request (0: it was cached)
  std::atomic<bool> cancel{false};
  std::atomic<double> renderProgress{0.0};  // the renderer's own progress, 0..1 (FrameInputs::progress)
  // Everything below is guarded by RenderService's mutex.
  JobState state = JobState::Queued;
  bool timedOut = false;
  Clock::time_point submitted, deadline, started, rendered, finished;
  double queueMs = 0, renderMs = 0, encodeMs = 0;
  api::FrameStats stats;
  std::vector<FrameInfo> frames;
  std::optional<Problem> error;
  // refine jobs: the mean of the batches so far, replaced after every batch (null before the first).
  std::shared_ptr<const RefineSnapshot> current;
  bool terminal() const { return state == JobState::Done || state == JobState::Failed || state == JobState::Canceled; }
};

// Picks the images an output names, in the order named. Throws ApiError 422 with a pointer to the
// AOV ("/outputs/1/aovs/0") when the passes that ran did not produce it.
std::vector<Image> selectAovs(const std::vector<Image>& aovs, const api::OutputSpec& spec, std::size_t outputIndex);

// The seed of a refining job's batch k (RenderService::refine): seed + k modulo m, or with a first seed
// (api::RefineSpec::firstSeed) that one first and then seed, seed + 1, ... without it.
std::uint64_t batchSeed(std::uint64_t seed, std::optional<std::uint64_t> first, int k, std::uint64_t m);

class RenderService {
public:
  RenderService(const ServerConfig& config, const BackendHooks& hooks, FrameStore& frames, Metrics& metrics);
  ~RenderService();
  RenderService(const RenderService&) = delete;
  RenderService& operator=(const RenderService&) = delete;

  // Queues a job. Throws ApiError 503 ("queue-full", with retryAfterSeconds()) or 503 "shutting-down".
  std::shared_ptr<Job> submit(api::RenderRequest request, std::shared_ptr<const Scene> scene,
                              std::shared_ptr<const Image> compareTarget = nullptr,
                              std::shared_ptr<const Image> environment = nullptr, double sceneLoadMs = 0);
  std::shared_ptr<Job> find(const std::string& id);
  // Blocks until the job is terminal or `until`; returns whether it is terminal.
  bool waitFor(const std::shared_ptr<Job>& job, Clock::time_point until);
  nlohmann::json describe(const Job& job);  // state, progress, stats/frames or error
  // A refine job's current mean and its estimated error (null before its first batch, or not refining).
  std::shared_ptr<const RefineSnapshot> current(const Job& job);

  bool terminal(const Job& job);  // done, failed or canceled (under the lock that guards job.state)

  enum class CancelResult { NotFound, Removed, Requested, Forgotten };
  CancelResult cancel(const std::string& id);

  bool ready();
  std::optional<DeviceInfo> device();
  std::string notReadyReason();
  int retryAfterSeconds();
  std::size_t queueDepth();
  int active();  // running + encoding

  // Refuses new jobs from now on and waits until every accepted job is terminal.
  void drain();
  void stop();  // joins all threads (after drain() for a graceful stop)

private:
  void renderLoop();
  void encoderLoop();
  void housekeepingLoop();
  void finishLocked(Job& job, JobState state, std::optional<Problem> error);
  void encode(const std::shared_ptr<Job>& job, RenderOutput output);
  // Renders a refine job's batches (seeds seed, seed + 1, ...) until its stop rule and returns their mean.
  RenderOutput refine(RenderBackend& backend, const std::shared_ptr<Job>& job, const Scene& scene, const FrameInputs& inputs);

  const ServerConfig config_;
  const BackendHooks hooks_;
  FrameStore& frames_;
  Metrics& metrics_;

  std::mutex mutex_;
  std::condition_variable changed_;  // any job state change, queue push, stop
  std::deque<std::shared_ptr<Job>> queue_;
  std::map<std::string, std::shared_ptr<Job>> jobs_;
  std::deque<std::pair<std::shared_ptr<Job>, RenderOutput>> encodeQueue_;
  std::condition_variable encodeReady_;
  int running_ = 0, encoding_ = 0;
  bool draining_ = false, stopping_ = false;
  bool ready_ = false;
  std::optional<DeviceInfo> device_;
  std::string notReadyReason_ = "the render thread is creating the GL context";
  double meanRenderSeconds_ = 1.0;

  std::thread renderThread_, housekeeping_;
  std::vector<std::thread> encoders_;
};

}  // namespace radiant::server
