#pragma once
// Progressive sessions (docs/API.md, "Sessions"): a session holds a render request (scene, camera,
// configuration) and keeps one refining job of it (RenderService, "Progressive refinement") going:
// its first batch is the cheap frame, the next ones refine it. A change (PATCH, a JSON merge patch of
// the request) is validated as a whole request, then the running job is canceled and a new one, the
// next "generation", is queued: the renderer's derived-data cache keeps whatever the change left valid.
// The HTTP layer streams each generation's frames as Server-Sent Events (HttpServer.cpp).
//
// Bounded: at most `maxSessions` open (503 sessions-full), each with one job queued or running (a job
// being canceled may still be finishing); a session ends on DELETE, when no event stream is open and
// nothing touched it for `idleS`, and on shutdown; its jobs are canceled and forgotten then.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/RenderService.h"

namespace radiant::server {

struct SessionLimits {
  int maxSessions = 8;   // --max-sessions
  double idleS = 60;     // --session-idle-s: without an event stream, ended after this long untouched
};

struct Session {
  std::string id;
  std::mutex changing;  // one create/patch of this session at a time (submitting can decode a scene)
  // Guarded by SessionStore's mutex.
  nlohmann::json request;  // the render request PATCH merges into (without "async", which is always true)
  int generation = 0;
  std::shared_ptr<Job> job;  // the current generation's refining job
  Clock::time_point touched;
  int streams = 0;     // open event streams
  std::string ended;   // "" while open; why it ended: "deleted", "idle", "shutdown"
};

class SessionStore {
public:
  // Queues a refining job of a session's request (parse, resolve the scene and images, submit);
  // throws api::ApiError naming the field, as POST /v1/renders does.
  // firstSeed: the first batch's seed (api::RefineSpec::firstSeed), or none.
  using Submit = std::function<std::shared_ptr<Job>(const nlohmann::json& request, std::optional<std::uint64_t> firstSeed)>;
  SessionStore(RenderService& service, Submit submit, SessionLimits limits, std::string idPrefix);
  ~SessionStore();
  SessionStore(const SessionStore&) = delete;
  SessionStore& operator=(const SessionStore&) = delete;

  // The request completed for a session: async, and refine unless it has its own. Throws ApiError 422
  // for what a session cannot hold (an inline scene: upload it and name its digest).
  static nlohmann::json sessionRequest(nlohmann::json request);

  // Opens a session and queues its first generation. Throws ApiError (422 from the request, 503
  // sessions-full, the queue's 503).
  std::shared_ptr<Session> create(const nlohmann::json& request);
  // Applies a JSON merge patch (RFC 7386) to the session's request; on success the next generation
  // is queued and the previous job canceled. A refused patch changes nothing. Unless the patch names
  // `seed`, the new generation's first batch has the seed of the last batch rendered (batchSeed).
  void patch(const std::shared_ptr<Session>& s, const nlohmann::json& mergePatch);
  // nullptr when unknown or ended; touches it.
  std::shared_ptr<Session> find(const std::string& id);
  bool end(const std::string& id, const std::string& reason);
  void endAll(const std::string& reason);
  std::size_t open();

  // What GET /v1/sessions/{id} shows: id, generation, request, the job's state and refinement.
  nlohmann::json describe(const Session& s);

  struct View {
    int generation = 0;
    std::shared_ptr<Job> job;
    std::string ended;
  };
  View view(const Session& s);
  // Counts an event stream; false (and not counted) when the session has kMaxStreams open already:
  // each holds an HTTP worker, so that sessions x streams bounds the workers they can take.
  static constexpr int kMaxStreams = 4;
  bool streamOpened(Session& s);
  void streamClosed(Session& s);

private:
  void reapLoop();
  void endLocked(Session& s, const std::string& reason);

  RenderService& service_;
  const Submit submit_;
  const SessionLimits limits_;
  const std::string idPrefix_;
  std::mutex mutex_;
  std::condition_variable stop_;
  bool stopping_ = false;
  std::map<std::string, std::shared_ptr<Session>> sessions_;
  int reserved_ = 0;  // sessions being created (counted against maxSessions)
  // Jobs of earlier generations, canceled: forgotten (RenderService::cancel) once they are terminal,
  // so that their refinement means do not stay for the frame TTL.
  std::vector<std::shared_ptr<Job>> retiring_;
  std::thread reaper_;
};

}  // namespace radiant::server
