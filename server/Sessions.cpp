#include "server/Sessions.h"

#include <random>

#include "api/Validate.h"

namespace radiant::server {

using json = nlohmann::json;

namespace {

std::string randomHex16() {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(rng()));
  return buf;
}

// RFC 7386: objects merge member by member, null removes a member, anything else replaces.
json mergePatch(json target, const json& patch) {
  if (!patch.is_object()) return patch;
  if (!target.is_object()) target = json::object();
  for (const auto& [key, value] : patch.items()) {
    if (value.is_null()) target.erase(key);
    else target[key] = mergePatch(target.contains(key) ? target[key] : json(), value);
  }
  return target;
}

}  // namespace

SessionStore::SessionStore(RenderService& service, Submit submit, SessionLimits limits, std::string idPrefix)
    : service_(service), submit_(std::move(submit)), limits_(limits), idPrefix_(std::move(idPrefix)) {
  reaper_ = std::thread([this] { reapLoop(); });
}

SessionStore::~SessionStore() {
  endAll("shutdown");
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  reaper_.join();
}

json SessionStore::sessionRequest(json request) {
  if (!request.is_object())
    throw api::ApiError(422, "invalid-type", "Invalid type", "a session's request is a JSON object", "");
  if (request.contains("scene") && request["scene"].is_object() &&
      (request["scene"].contains("inline") || request["scene"].contains("inline_glb")))
    throw api::ApiError(422, "invalid-value", "Invalid value",
                        "/scene: a session names a built-in scene, an uploaded scene's digest or an asset; upload "
                        "the scene first (PUT /v1/scenes) and name its digest",
                        "/scene");
  if (request.contains("async") && request["async"] != true)
    throw api::ApiError(422, "invalid-value", "Invalid value", "/async: a session's renders are always async", "/async");
  request["async"] = true;
  if (!request.contains("refine")) request["refine"] = {{"max_batches", 64}, {"until_ms", 30000}};
  return request;
}

std::shared_ptr<Session> SessionStore::create(const json& body) {
  const json request = sessionRequest(body);
  {
    std::lock_guard lock(mutex_);
    if (static_cast<int>(sessions_.size()) + reserved_ >= limits_.maxSessions)
      throw api::ApiError(503, "sessions-full", "Too many sessions",
                          "this daemon holds " + std::to_string(limits_.maxSessions) +
                              " sessions (--max-sessions); end one (DELETE /v1/sessions/{id}) or wait for an idle one to expire");
    ++reserved_;
  }
  std::shared_ptr<Job> job;
  try {
    job = submit_(request, std::nullopt);
  } catch (...) {
    std::lock_guard lock(mutex_);
    --reserved_;
    throw;
  }
  auto s = std::make_shared<Session>();
  s->id = idPrefix_ + "s-" + randomHex16();
  s->request = request;
  s->request.erase("async");
  s->job = std::move(job);
  s->touched = Clock::now();
  std::lock_guard lock(mutex_);
  --reserved_;
  sessions_[s->id] = s;
  return s;
}

void SessionStore::patch(const std::shared_ptr<Session>& s, const json& change) {
  if (!change.is_object())
    throw api::ApiError(422, "invalid-type", "Invalid type", "a session change is a JSON merge patch (an object)", "");
  std::lock_guard changing(s->changing);
  json merged;
  {
    std::lock_guard lock(mutex_);
    if (!s->ended.empty()) throw api::ApiError(404, "unknown-session", "Unknown session", "session " + s->id + " has ended (" + s->ended + ")");
    merged = mergePatch(s->request, change);
  }
  const json request = sessionRequest(merged);
  // The next generation's first batch has the seed of the last batch rendered, unless the change names
  // a seed: that batch's photon set is the one on the GPU, so the cheap frame after a camera move does
  // not rebuild and upload a splat grid (60-70 ms on llvmpipe; docs/PERFORMANCE.md, "The viewer").
  std::optional<std::uint64_t> firstSeed;
  if (!change.contains("seed")) {
    std::shared_ptr<Job> current;
    {
      std::lock_guard lock(mutex_);
      current = s->job;
    }
    if (auto snap = current ? service_.current(*current) : nullptr; snap && snap->batches > 0) firstSeed = snap->lastSeed;
  }
  std::shared_ptr<Job> job = submit_(request, firstSeed);  // throws: the session keeps its request and job
  std::shared_ptr<Job> old;
  {
    std::lock_guard lock(mutex_);
    if (!s->ended.empty()) {
      old = job;  // ended while this change was submitted: the new job goes too
    } else {
      old = std::exchange(s->job, job);
      s->request = request;
      s->request.erase("async");
      ++s->generation;
      s->touched = Clock::now();
    }
    retiring_.push_back(old);
  }
  service_.cancel(old->id);
}

std::shared_ptr<Session> SessionStore::find(const std::string& id) {
  std::lock_guard lock(mutex_);
  auto it = sessions_.find(id);
  if (it == sessions_.end()) return nullptr;
  it->second->touched = Clock::now();
  return it->second;
}

void SessionStore::endLocked(Session& s, const std::string& reason) {
  if (!s.ended.empty()) return;
  s.ended = reason;
  if (s.job) retiring_.push_back(s.job);
  sessions_.erase(s.id);
}

bool SessionStore::end(const std::string& id, const std::string& reason) {
  std::shared_ptr<Job> job;
  {
    std::lock_guard lock(mutex_);
    auto it = sessions_.find(id);
    if (it == sessions_.end()) return false;
    std::shared_ptr<Session> s = it->second;
    job = s->job;
    endLocked(*s, reason);
  }
  if (job) service_.cancel(job->id);
  return true;
}

void SessionStore::endAll(const std::string& reason) {
  std::vector<std::string> ids;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [id, s] : sessions_) ids.push_back(id);
  }
  for (const auto& id : ids) end(id, reason);
}

std::size_t SessionStore::open() {
  std::lock_guard lock(mutex_);
  return sessions_.size();
}

SessionStore::View SessionStore::view(const Session& s) {
  std::lock_guard lock(mutex_);
  return {s.generation, s.job, s.ended};
}

bool SessionStore::streamOpened(Session& s) {
  std::lock_guard lock(mutex_);
  if (s.streams >= kMaxStreams) return false;
  ++s.streams;
  s.touched = Clock::now();
  return true;
}

void SessionStore::streamClosed(Session& s) {
  std::lock_guard lock(mutex_);
  --s.streams;
  s.touched = Clock::now();
}

json SessionStore::describe(const Session& s) {
  View v = view(s);
  json request;
  {
    std::lock_guard lock(mutex_);
    request = s.request;
  }
  json j{{"id", s.id},
         {"generation", v.generation},
         {"request", request},
         {"events", "/v1/sessions/" + s.id + "/events"},
         {"frame", "/v1/sessions/" + s.id + "/frame"}};
  if (!v.ended.empty()) j["ended"] = v.ended;
  if (v.job) j["render"] = service_.describe(*v.job);
  return j;
}

void SessionStore::reapLoop() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    stop_.wait_for(lock, std::chrono::milliseconds(250));
    const auto now = Clock::now();
    std::vector<std::shared_ptr<Job>> cancel, forget;
    for (auto it = sessions_.begin(); it != sessions_.end();) {
      std::shared_ptr<Session> s = (it++)->second;
      if (s->streams == 0 && std::chrono::duration<double>(now - s->touched).count() > limits_.idleS) {
        if (s->job) cancel.push_back(s->job);
        endLocked(*s, "idle");
      }
    }
    // A retired job is forgotten once terminal (its mean and frames go); until then it is asked to stop.
    std::vector<std::shared_ptr<Job>> retiring = std::move(retiring_);
    retiring_.clear();
    lock.unlock();
    std::vector<std::shared_ptr<Job>> still;
    for (auto& j : retiring) (service_.terminal(*j) ? forget : still).push_back(std::move(j));
    for (const auto& j : cancel) service_.cancel(j->id);
    for (const auto& j : forget) service_.cancel(j->id);
    lock.lock();
    for (auto& j : still) retiring_.push_back(std::move(j));
  }
}

}  // namespace radiant::server
