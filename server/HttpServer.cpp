#include "server/HttpServer.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <iostream>
#include <limits>
#include <list>
#include <malloc.h>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <thread>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "api/Aovs.h"
#include "api/Base64.h"
#include "api/JsonLimits.h"
#include "api/Lru.h"
#include "api/Presets.h"
#include "api/Sha256.h"
#include "api/Validate.h"
#include "server/FrameStore.h"
#include "server/HttpTransport.h"
#include "server/Metrics.h"
#include "server/RenderService.h"
#include "server/Sessions.h"
#include "embedded/radiant_ui.h"
#include "server/ContentStore.h"
#include "renderer/ResidentMemory.h"
#include "renderer/scene/GltfPackage.h"

namespace radiant::server {

using nlohmann::json;

namespace {

constexpr const char* kVersion = "0.1.0";

// Per-request context for the log line; the logger runs on the handler's thread after the response.
struct RequestContext {
  std::string id;
  Clock::time_point start;
  double queueMs = -1, renderMs = -1, encodeMs = -1;
  std::string renderId;
  bool active = false;
};
thread_local RequestContext tRequest;

std::string randomHex(int n) {
  static std::mutex m;
  static std::mt19937_64 rng{std::random_device{}()};
  std::lock_guard lock(m);
  std::string s;
  static const char* kHex = "0123456789abcdef";
  for (int i = 0; i < n; ++i) s += kHex[rng() & 15];
  return s;
}

bool validRequestId(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) return false;
  return true;
}

void beginRequest(const httplib::Request& req, httplib::Response& res) {
  tRequest = RequestContext{};
  tRequest.active = true;
  tRequest.start = Clock::now();
  const std::string given = req.get_header_value("X-Request-Id");
  tRequest.id = validRequestId(given) ? given : "q-" + randomHex(16);
  res.set_header("X-Request-Id", tRequest.id);
}

void sendJson(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(api::dumpSafe(body, 2) + "\n", "application/json");
}

void sendProblem(httplib::Response& res, int status, const std::string& type, const std::string& title,
                 const std::string& detail, const std::string& pointer = "", const std::string& renderId = "") {
  json p{{"type", "https://radiant.dev/problems/" + type}, {"title", title}, {"status", status}, {"detail", detail}};
  if (!pointer.empty()) p["pointer"] = pointer;
  if (!tRequest.id.empty()) p["request_id"] = tRequest.id;
  if (!renderId.empty()) p["render_id"] = renderId;
  res.status = status;
  // dumpSafe: a detail may quote the client's bytes (a path, a value), which need not be UTF-8.
  res.set_content(api::dumpSafe(p, 2) + "\n", "application/problem+json");
}

void sendProblem(httplib::Response& res, const api::ApiError& e, const std::string& renderId = "") {
  sendProblem(res, e.status, e.type, e.title, e.detail(), e.pointer, renderId);
}

// The proxy routes uploads, HEADs and renders on X-Radiant-Scene (docs/DEPLOYMENT.md). A header that
// names another scene than the request's own would park the scene on a daemon the proxy never sends
// its renders to, so it is refused rather than ignored.
void checkSceneHeader(const httplib::Request& req, const std::string& digest, const std::string& pointer = "") {
  if (!req.has_header("X-Radiant-Scene")) return;
  const std::string given = req.get_header_value("X-Radiant-Scene");
  if (!api::isSceneDigest(given))
    throw api::ApiError(400, "invalid-scene-header", "Invalid X-Radiant-Scene header",
                        "the X-Radiant-Scene header must be the sha256:<64 lowercase hex> digest of the request's scene, got \"" +
                            api::truncateUtf8(given, 100) + "\"",
                        pointer);
  if (!digest.empty() && given != digest)
    throw api::ApiError(400, "scene-header-mismatch", "X-Radiant-Scene does not match the scene",
                        "the X-Radiant-Scene header names " + given + " but the request's scene is " + digest +
                            " (the proxy routes on this header: send the digest of the scene itself)",
                        pointer);
}

std::string mediaType(const httplib::Request& req) {
  std::string ct = req.get_header_value("Content-Type");
  if (auto semi = ct.find(';'); semi != std::string::npos) ct.resize(semi);
  while (!ct.empty() && ct.back() == ' ') ct.pop_back();
  for (char& c : ct) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ct;
}

std::string statusTitle(int status) {
  switch (status) {
    case 400: return "Bad request";
    case 401: return "Unauthorized";
    case 404: return "Not found";
    case 405: return "Method not allowed";
    case 413: return "Payload too large";
    case 414: return "URI too long";
    case 415: return "Unsupported media type";
    case 503: return "Service unavailable";
    default: return status >= 500 ? "Internal error" : "Error";
  }
}

std::string base64Decode(const std::string& in, const std::string& pointer) {
  std::size_t bad = 0;
  std::optional<std::string> bytes = api::base64Decode(in, &bad);
  if (!bytes)
    throw api::ApiError(422, "invalid-value", "Invalid value",
                        pointer + ": not base64 (character " + std::to_string(bad) + ")", pointer);
  return std::move(*bytes);
}

json deviceJson(const DeviceInfo& d) {
  return json{{"vendor", d.vendor},         {"renderer", d.renderer}, {"version", d.version},
              {"glsl_version", d.glslVersion}, {"platform", d.platform}, {"device_index", d.deviceIndex},
              {"reason", d.reason},         {"software", d.software}};
}

// Memory a decoded scene holds: its vertex arrays and texels (the strings and small structs aside).
std::size_t sceneBytes(const Scene& s) {
  std::size_t bytes = 0;
  for (const auto& m : s.meshes)
    bytes += m.positions.size() * sizeof(glm::vec3) + m.normals.size() * sizeof(glm::vec3) +
             m.tangents.size() * sizeof(glm::vec4) + (m.uv0.size() + m.uv1.size()) * sizeof(glm::vec2) +
             m.indices.size() * sizeof(std::uint32_t) + m.extrasJson.size();
  for (const auto& t : s.textures) bytes += t.rgba8.size();
  return bytes;
}

std::size_t imageBytes(const Image& i) { return i.pixels.size() * sizeof(float); }

// Decoded scenes (or images) by digest, least recently used dropped first, bounded in entries and in
// bytes (--scene-cache, --scene-cache-bytes). One larger than the whole budget is used, not kept.
template <class T, std::size_t (*SizeOf)(const T&)>
class DecodedCache {
public:
  DecodedCache(std::size_t capacity, std::size_t maxBytes) : capacity_(capacity), maxBytes_(maxBytes) {}
  std::size_t totalBytes() {
    std::lock_guard lock(mutex_);
    return lru_.bytes();
  }
  std::shared_ptr<const T> get(const std::string& digest) {
    std::lock_guard lock(mutex_);
    auto* value = lru_.use(digest);
    return value ? *value : nullptr;
  }
  // Drops least recently used entries that nothing else holds (no job, no request in flight) until
  // `bytes` are freed or none is left: their decode memory is released with them (DecodeMemory).
  void dropUnshared(std::size_t bytes) {
    std::vector<std::shared_ptr<const T>> dropped;  // destroyed after the lock is released
    {
      std::lock_guard lock(mutex_);
      const std::size_t target = lru_.bytes() > bytes ? lru_.bytes() - bytes : 0;
      lru_.evict([&](const Lru& l) { return l.bytes() > target; },
                 [](const typename Lru::Entry& e) { return e.value.use_count() != 1; },
                 [&](typename Lru::Entry&& e) { dropped.push_back(std::move(e.value)); });
    }
  }
  void put(const std::string& digest, std::shared_ptr<const T> value) {
    const std::size_t size = SizeOf(*value);
    std::lock_guard lock(mutex_);
    if (lru_.find(digest) != lru_.end() || size > maxBytes_) return;
    lru_.put(digest, std::move(value), size);
    lru_.evict([&](const Lru& l) { return l.size() > capacity_ || l.bytes() > maxBytes_; });
  }

private:
  using Lru = api::Lru<std::string, std::shared_ptr<const T>>;
  std::mutex mutex_;
  std::size_t capacity_, maxBytes_;
  Lru lru_;
};
using DecodedScenes = DecodedCache<Scene, sceneBytes>;
// Environment maps and comparison images, decoded once per digest (a 4k map took a decode per
// request): the last 4 at most, within half of --scene-cache-bytes.
using DecodedImages = DecodedCache<Image, imageBytes>;

// Memory admission for decoding (issue 30): every decode of an uploaded or named scene or image
// reserves the bytes it is about to allocate (its decoder calls the reservation before each image's
// pixels and each expanded accessor: BackendHooks::Reserve) from one budget,
// max(--decode-memory-bytes, --max-decode-bytes) bytes. What a decode produced stays charged to the same
// budget for as long as it lives (keep(): the decoded-scene and image caches and every queued or running
// job that holds it), so queued jobs are bounded by the bytes they hold, not only by their count. A
// reservation that does not fit first drops cached results nothing else holds, then waits up to a
// second for jobs to end, then the decode is refused with 503 decode-busy and Retry-After: concurrent
// uploads cannot add up to more than the budget (3 meshopt uploads decoding 256 MiB each took the daemon
// to 1.8 GB), nor can renders queued behind a long one, each holding a scene of its own.
// A second instance budgets the request bodies being read or handled (bodyMemory, --body-memory-bytes,
// readBody), whose callers turn its 503 decode-busy into body-busy.
//
// Both budgets are also held to the process's memory limit (--memory-limit-bytes) through one
// ResidentGate: a reservation fits only when the resident set, plus every claim still in flight (the
// process-wide MemoryClaims: decodes' and bodies' reservations, and the frame's next large allocation,
// which the renderer claims in FrameResources::admit; counted twice once resident, which errs on the
// safe side), plus its own bytes stays under the limit. So decoded scenes held by queued renders,
// bodies being read and the frame cannot add up past the limit, whatever the three budgets sum to.
// Refused after the same wait, with 503 memory-busy.
class ResidentGate {
public:
  ResidentGate(std::function<std::size_t()> resident, std::size_t limit)
      : resident_(resident ? std::move(resident) : std::function<std::size_t()>(radiant::residentBytes)), limit_(limit) {}
  std::size_t limit() const { return limit_; }
  // Claims `bytes` more (MemoryClaims, shared with the renderer's admission) when they fit; `resident`
  // (out) is what was read. No limit, or an unknown resident set (0), always fits.
  bool claim(std::size_t bytes, std::size_t& resident) {
    if (limit_ == 0) return true;
    return MemoryClaims::process().tryReplace(0, bytes, limit_, resident_, &resident);
  }
  void release(std::size_t bytes) {
    if (limit_ != 0) MemoryClaims::process().release(bytes);
  }
  std::uint64_t refused() const { return refused_.load(); }
  void countRefusal() { ++refused_; }

private:
  std::function<std::size_t()> resident_;
  std::size_t limit_;
  std::atomic<std::uint64_t> refused_{0};
};

class DecodeMemory {
public:
  explicit DecodeMemory(std::size_t bytes, ResidentGate* gate = nullptr)
      : total_(std::max<std::size_t>(1, bytes)), gate_(gate) {}
  std::size_t total() const { return total_; }
  std::size_t reserved() {
    std::lock_guard lock(mutex_);
    return used_;
  }
  // Called (without this object's lock) to free `bytes` by dropping cached results nobody holds.
  void setEvict(std::function<void(std::size_t)> evict) { evict_ = std::move(evict); }

  // One decode's bytes, released when it ends (success or not).
  class Reservation {
  public:
    explicit Reservation(DecodeMemory& m) : m_(&m) {}
    Reservation(const Reservation&) = delete;
    Reservation& operator=(const Reservation&) = delete;
    ~Reservation() {
      if (m_->gate_) m_->gate_->release(claimed_);
      m_->release(held_);
    }
    // Adds `bytes`, waiting up to `wait` for them; throws ApiError 503 decode-busy when they do not free
    // (memory-busy when the budget has them but the process's memory limit does not).
    void grow(std::size_t bytes, std::chrono::milliseconds wait = std::chrono::seconds(1)) {
      const std::size_t total = m_->total_;
      ResidentGate* gate = m_->gate_;
      // Never more than the whole budget: a decode the per-decode limit allows always fits on its own.
      bool overLimit = gate && gate->limit() != 0 && bytes > gate->limit();  // never fits: refused at once
      bool fits = bytes <= total - std::min(total, held_) && !overLimit;
      std::size_t resident = 0;
      const auto until = std::chrono::steady_clock::now() + wait;
      while (fits) {
        if (m_->evict_ && m_->reserved() + bytes > total) m_->evict_(m_->reserved() + bytes - total);
        std::unique_lock lock(m_->mutex_);
        overLimit = false;  // what the last try found decides the refusal's kind
        if (m_->used_ + bytes <= total) {
          // The budget has them; the process's limit next (claimed under the budget's lock, so a
          // claim is never left without its budget bytes).
          overLimit = gate && !gate->claim(bytes, resident);
          if (overLimit && m_->evict_) {
            // Over the limit: what only the caches hold goes first (the freed heap returns to the system).
            lock.unlock();
            m_->evict_(bytes);
            malloc_trim(0);
            lock.lock();
            overLimit = m_->used_ + bytes <= total && !gate->claim(bytes, resident);
          }
          if (!overLimit && m_->used_ + bytes <= total) {
            m_->used_ += bytes;
            held_ += bytes;
            if (gate) claimed_ += bytes;
            return;
          }
        }
        // A job ending releases its charges (notify); a cached result it held becomes droppable.
        const auto next = std::min(until, std::chrono::steady_clock::now() + std::chrono::milliseconds(100));
        if (std::chrono::steady_clock::now() >= until) break;
        m_->cv_.wait_until(lock, next);
      }
      if (overLimit) {
        gate->countRefusal();
        throw api::ApiError(503, "memory-busy", "Not enough memory",
                            "reading or decoding needs " + std::to_string(bytes >> 20) + " MiB more; the daemon "
                                "holds " + std::to_string(resident >> 20) + " MiB and decodes, bodies and the frame "
                                "in flight claim " + std::to_string(MemoryClaims::process().claimed() >> 20) +
                                " MiB more, over its limit of " + std::to_string(gate->limit() >> 20) +
                                " MiB (--memory-limit-bytes): retry after the Retry-After seconds");
      }
      std::lock_guard lock(m_->mutex_);
      ++m_->refused_;
      throw api::ApiError(503, "decode-busy", "Busy decoding",
                          "decoding needs " + std::to_string(bytes) + " more bytes and " + std::to_string(m_->used_) +
                              " of the " + std::to_string(total) +
                              " bytes that decodes in flight and the decoded scenes and images held by queued "
                              "and running renders may use together are taken (--decode-memory-bytes): retry "
                              "after the Retry-After seconds");
    }
    BackendHooks::Reserve hook() {
      return [this](std::size_t bytes) { grow(bytes); };
    }

  private:
    DecodeMemory* m_;
    std::size_t held_ = 0;
    std::size_t claimed_ = 0;  // of held_, claimed under the memory limit (MemoryClaims)
  };

  // A decoded value charged to the budget (`bytes`, what it holds) until its last holder lets it go.
  // Taken whole, without waiting: the decode that made it had reserved at least as much.
  template <class T>
  std::shared_ptr<const T> keep(T value, std::size_t bytes) {
    struct Held {
      Held(T v, DecodeMemory* memory, std::size_t n) : value(std::move(v)), m(memory), bytes(n) {}
      Held(const Held&) = delete;
      Held& operator=(const Held&) = delete;
      ~Held() { m->release(bytes); }
      T value;
      DecodeMemory* m;
      std::size_t bytes;
    };
    {
      std::lock_guard lock(mutex_);
      used_ += bytes;
    }
    auto held = std::make_shared<Held>(std::move(value), this, bytes);
    return std::shared_ptr<const T>(held, &held->value);
  }
  std::uint64_t refused() const { return refused_.load(); }

private:
  void release(std::size_t bytes) {
    if (bytes == 0) return;
    {
      std::lock_guard lock(mutex_);
      used_ -= bytes;
    }
    cv_.notify_all();
  }
  std::mutex mutex_;
  std::condition_variable cv_;
  std::size_t total_, used_ = 0;
  ResidentGate* gate_;
  std::atomic<std::uint64_t> refused_{0};
  std::function<void(std::size_t)> evict_;
};

}  // namespace

struct HttpServer::Impl {
  ServerConfig config;
  BackendHooks hooks;
  Metrics metrics;
  FrameStore frames;
  ContentStore scenes;
  ContentStore images;  // comparison targets (compare.against = their digest)
  ResidentGate residentGate;  // --memory-limit-bytes, for both budgets below
  DecodeMemory decodeMemory;  // before the caches: what they hold releases its charge here when dropped
  DecodeMemory bodyMemory;    // request bodies being read or handled (--body-memory-bytes; readBody)
  DecodedScenes decoded;
  DecodedImages decodedImages;
  RenderService service;
  SessionStore sessions;  // after the service: its jobs are canceled before the service goes
  BoundedServer http;
  std::atomic<bool> shuttingDown{false};

  std::mutex builtinMutex;
  std::map<std::string, std::string> builtinDigests;  // name -> digest, filled on first use

  static ServerConfig derived(ServerConfig c) {
    // One request's output files may not exceed the frame store that has to hold them.
    if (c.limits.maxOutputBytes == 0) c.limits.maxOutputBytes = c.maxFrameBytes;
    return c;
  }

  // The backend's memory accountant may drop the decoded scenes and images no job holds (on the render
  // thread, when it releases: FrameResources::makeRoom), so a frame is not refused memory that only
  // these caches keep.
  static BackendHooks withRelease(BackendHooks h, Impl* self) {
    if (!h.createBackend) return h;
    h.createBackend = [create = std::move(h.createBackend), self] {
      std::unique_ptr<RenderBackend> backend = create();
      backend->setReleaseHook([self] {
        self->decodedImages.dropUnshared(std::numeric_limits<std::size_t>::max());
        self->decoded.dropUnshared(std::numeric_limits<std::size_t>::max());
      });
      return backend;
    };
    return h;
  }

  Impl(ServerConfig c, BackendHooks h)
      : config(derived(std::move(c))),
        hooks(withRelease(std::move(h), this)),
        frames(config.maxFrameBytes, config.frameTtlS),
        scenes(config.cacheDir, config.maxSceneBytes, "scenes"),
        images(config.cacheDir, config.maxSceneBytes, "images"),
        residentGate(hooks.residentBytes, config.memoryLimitBytes),
        decodeMemory(std::max(config.decodeMemoryBytes, config.maxDecodeBytes), &residentGate),
        bodyMemory(std::max(config.bodyMemoryBytes, config.maxBodyBytes), &residentGate),
        decoded(config.sceneCacheEntries, config.sceneCacheBytes),
        decodedImages(std::min<std::size_t>(4, config.sceneCacheEntries), config.sceneCacheBytes / 2),
        service(config, hooks, frames, metrics),
        sessions(
            service,
            [this](const json& request, std::optional<std::uint64_t> firstSeed) {
              api::RenderRequest parsed = api::parseRenderRequest(request, config.limits);
              if (parsed.refine) parsed.refine->firstSeed = firstSeed;
              return submitRequest(std::move(parsed), nullptr);
            },
            SessionLimits{config.maxSessions, config.sessionIdleS}, config.daemonId.empty() ? "" : config.daemonId + "-") {
    decodeMemory.setEvict([this](std::size_t bytes) {
      decodedImages.dropUnshared(bytes);
      decoded.dropUnshared(bytes);
    });
    routes();
  }

  // ---- scenes ---------------------------------------------------------------------------------
  std::vector<std::string> builtinNames() { return hooks.builtinSceneNames ? hooks.builtinSceneNames() : std::vector<std::string>{}; }

  std::optional<std::string> builtinDigest(const std::string& name) {
    {
      std::lock_guard lock(builtinMutex);
      if (auto it = builtinDigests.find(name); it != builtinDigests.end()) return it->second;
    }
    const auto names = builtinNames();
    if (std::find(names.begin(), names.end(), name) == names.end()) return std::nullopt;
    const std::string digest = api::sceneDigest(hooks.builtinSceneSource(name));
    std::lock_guard lock(builtinMutex);
    builtinDigests[name] = digest;
    return digest;
  }

  std::optional<std::string> builtinByDigest(const std::string& digest) {
    for (const auto& name : builtinNames())
      if (builtinDigest(name) == digest) return name;
    return std::nullopt;
  }

  // Milliseconds this thread's last resolveScene() spent decoding (0 when the decoded scene was cached);
  // it becomes the frame's stats.scene_load_ms.
  static inline thread_local double tSceneLoadMs = 0;

  std::shared_ptr<const Scene> decode(const std::string& digest, std::string_view bytes, const std::string& pointer) {
    if (auto s = decoded.get(digest)) return s;
    const auto start = Clock::now();
    if (!hooks.decodeScene) throw std::logic_error("no scene decoder configured");
    std::shared_ptr<const Scene> scene;
    try {
      DecodeMemory::Reservation memory(decodeMemory);
      Scene s = hooks.decodeScene(bytes, memory.hook());
      if (s.digest.empty()) s.digest = digest;
      const std::size_t size = sceneBytes(s);
      scene = decodeMemory.keep(std::move(s), size);
    } catch (const api::ApiError& e) {
      // A render request points at its own field (/scene/inline_glb); an upload, whose body is the
      // glTF document, at the place in the document the decoder names.
      throw api::ApiError(e.status, e.type, e.title, e.detail(), pointer.empty() ? e.pointer : pointer);
    } catch (const std::exception& e) {
      throw api::ApiError(422, "invalid-scene", "Invalid scene", std::string("the scene cannot be loaded: ") + e.what(),
                          pointer);
    }
    tSceneLoadMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    decoded.put(digest, scene);
    return scene;
  }

  std::shared_ptr<const Scene> resolveScene(const api::SceneRef& ref) {
    tSceneLoadMs = 0;
    switch (ref.kind) {
      case api::SceneRef::Kind::Builtin: {
        auto digest = builtinDigest(ref.value);
        if (!digest)
          throw api::ApiError(404, "unknown-scene", "Unknown scene",
                              "/scene/builtin: no built-in scene \"" + ref.value + "\" (GET /v1/scenes lists them)",
                              "/scene/builtin");
        if (auto s = decoded.get(*digest)) return s;
        return decode(*digest, hooks.builtinSceneSource(ref.value), "/scene/builtin");
      }
      case api::SceneRef::Kind::Digest: {
        if (auto s = decoded.get(ref.value)) return s;
        if (auto bytes = scenes.get(ref.value)) return decode(ref.value, *bytes, "/scene/digest");
        if (auto name = builtinByDigest(ref.value))
          return decode(ref.value, hooks.builtinSceneSource(*name), "/scene/digest");
        throw api::ApiError(404, "unknown-scene", "Unknown scene",
                            "/scene/digest: no scene " + ref.value + " (upload it with PUT /v1/scenes)", "/scene/digest");
      }
      case api::SceneRef::Kind::Asset: {
        // A file under --asset-root, packed with the files it references into one GLB: the digest covers
        // every byte, so the decoded-scene cache never serves a scene whose files have changed.
        if (config.assetRoot.empty())
          throw api::ApiError(422, "no-asset-root", "No asset root",
                              "/scene/asset: this daemon serves no files (start radiantd with --asset-root DIR), "
                              "or upload the scene: `radiant render FILE.gltf` packs it and its files into one GLB",
                              "/scene/asset");
        PackResult packed;
        try {
          std::error_code ec;
          const std::filesystem::path root = std::filesystem::canonical(config.assetRoot, ec);
          if (ec) throw PackError("", "the asset root " + config.assetRoot + " does not exist");
          const std::filesystem::path file = resolveRelativeUri(ref.value, "/scene/asset", root, root);
          packed = packGltfFile(file, root, std::max<std::size_t>(config.maxBodyBytes, std::size_t(256) << 20));
        } catch (const PackError& e) {
          // 404 only for a file that is not there; a directory, FIFO or device is 422, a file over the
          // size limit 422 limit-exceeded (both were 404 unknown-scene: issue 30's 4xx wording).
          const bool missing = e.kind == PackError::Kind::Missing;
          const bool path = e.pointer == "/scene/asset";
          const std::string detail =
              "/scene/asset: " + (path ? std::string() : ref.value + (e.pointer.empty() ? "" : " at " + e.pointer) + ": ") + e.what();
          if (e.kind == PackError::Kind::TooLarge)
            throw api::ApiError(422, "limit-exceeded", "Limit exceeded", detail + " (radiantd --max-body-bytes, at least 256 MiB for assets)",
                                "/scene/asset");
          throw api::ApiError(missing ? 404 : 422, missing ? "unknown-scene" : "invalid-scene",
                              missing ? "Unknown scene" : "Invalid scene", detail, "/scene/asset");
        }
        const std::string digest = api::sceneDigest(packed.bytes);
        return decode(digest, packed.bytes, "/scene/asset");
      }
      case api::SceneRef::Kind::Inline: {
        std::string bytes = base64Decode(ref.value, "/scene/inline_glb");
        const std::string digest = api::sceneDigest(bytes);
        auto scene = decode(digest, bytes, "/scene/inline_glb");
        scenes.put(digest, std::move(bytes));  // now addressable by digest too
        return scene;
      }
    }
    throw std::logic_error("unreachable");
  }

  // An image a request names by digest (compare.against, environment), decoded. 404 at `pointer`
  // when the store does not hold it.
  std::shared_ptr<const Image> resolveImage(const std::string& digest, const std::string& pointer) {
    if (!api::isSceneDigest(digest))
      throw api::ApiError(422, "invalid-value", "Invalid value",
                          pointer + ": the sha256:... digest of an image uploaded to /v1/images", pointer);
    auto bytes = images.get(digest);
    if (!bytes)
      throw api::ApiError(404, "unknown-image", "Unknown image",
                          pointer + ": no image " + digest + " (upload it to /v1/images first)", pointer);
    if (auto image = decodedImages.get(digest)) return image;
    if (!hooks.decodeImage) throw std::logic_error("no image decoder configured");
    // Decoded once per digest: requests naming an image that is being decoded wait for that decode
    // (eight renders naming one new 4096 x 4096 map decoded it eight times at once), and share its
    // result or its error.
    std::promise<std::shared_ptr<const Image>> mine;
    const std::shared_future<std::shared_ptr<const Image>> result = mine.get_future().share();
    std::shared_future<std::shared_ptr<const Image>> pending;
    {
      std::lock_guard lock(imageDecodesMutex);
      if (auto it = imageDecodes.find(digest); it != imageDecodes.end()) pending = it->second;
      else imageDecodes.emplace(digest, result);
    }
    if (pending.valid()) return pending.get();
    try {
      if (auto cached = decodedImages.get(digest)) {  // finished between the first look and the claim
        mine.set_value(cached);
      } else {
        DecodeMemory::Reservation memory(decodeMemory);
        Image image = hooks.decodeImage(*bytes, memory.hook());
        const std::size_t size = imageBytes(image);
        auto decodedImage = decodeMemory.keep(std::move(image), size);
        metrics.countImageDecode();
        decodedImages.put(digest, decodedImage);
        mine.set_value(decodedImage);
      }
    } catch (...) {
      mine.set_exception(std::current_exception());
    }
    {
      std::lock_guard lock(imageDecodesMutex);
      imageDecodes.erase(digest);
    }
    return result.get();
  }
  std::mutex imageDecodesMutex;
  std::map<std::string, std::shared_future<std::shared_ptr<const Image>>> imageDecodes;  // in flight

  // ---- helpers --------------------------------------------------------------------------------
  // The body of a POST/PUT, counted while it is read: chunked and gzip/deflate bodies (which httplib
  // inflates on the way) stop at --max-body-bytes instead of being read whole first. Its bytes are
  // charged to `charge` (bodyMemory, --body-memory-bytes) before they are held: the Content-Length at
  // once when the request gives one (so a body that cannot fit is refused before it is read), else in
  // steps of 64 KiB as it arrives; wrapBody keeps the charge until the request is answered. Without it
  // every HTTP thread could hold a body of --max-body-bytes (24 threads x 64 MiB by default).
  std::string readBody(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader,
                       DecodeMemory::Reservation& charge) {
    std::string body;
    bool tooLarge = false, busy = false;
    std::optional<api::ApiError> overLimit;  // memory-busy: the process's limit, not the bodies' budget
    std::size_t charged = 0;
    auto chargeUpTo = [&](std::size_t bytes) {
      if (bytes <= charged) return true;
      const std::size_t more = std::min(std::max<std::size_t>(bytes - charged, std::size_t(64) << 10), config.maxBodyBytes - charged);
      try {
        charge.grow(more);
      } catch (const api::ApiError& e) {
        busy = true;
        if (e.type == "memory-busy") overLimit = e;
        return false;
      }
      charged += more;
      return true;
    };
    if (req.has_header("Content-Length")) {
      const std::uint64_t declared = req.get_header_value<std::uint64_t>("Content-Length");
      if (declared <= config.maxBodyBytes) chargeUpTo(static_cast<std::size_t>(declared));
    }
    const bool ok = !busy && reader([&](const char* data, std::size_t n) {
      if (n > config.maxBodyBytes - body.size()) {
        tooLarge = true;
        return false;
      }
      if (!chargeUpTo(body.size() + n)) return false;
      body.append(data, n);
      return true;
    });
    if (busy) {
      markCloseConnection();  // the body (or its rest) is still on the wire
      res.set_header("Connection", "close");
      if (overLimit) throw *overLimit;
      throw api::ApiError(503, "body-busy", "Busy reading bodies",
                          "the request bodies being read or handled hold " + std::to_string(bodyMemory.reserved()) +
                              " of the " + std::to_string(bodyMemory.total()) +
                              " bytes they may take together (--body-memory-bytes): retry after the Retry-After seconds");
    }
    // httplib refuses a Content-Length over the limit itself (status 413) without reading the body.
    if (!ok && res.status == 413) tooLarge = true;
    if (tooLarge || !ok) {
      markCloseConnection();  // the rest of the body is still on the wire
      res.set_header("Connection", "close");
    }
    if (tooLarge)
      throw api::ApiError(413, "payload-too-large", "Payload too large",
                          "the body (after any Content-Encoding is undone) exceeds this server's limit of " +
                              std::to_string(config.maxBodyBytes) + " bytes (radiantd --max-body-bytes)");
    if (!ok)
      throw api::ApiError(400, "incomplete-body", "Incomplete body",
                          "the body could not be read completely within " + std::to_string(config.readTimeoutS) +
                              " s (radiantd --read-timeout), or its encoding is invalid");
    return body;
  }

  // A handler that takes the request body, read with readBody().
  template <class F>
  httplib::Server::HandlerWithContentReader wrapBody(F f) {
    return [this, f](const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader) {
      try {
        DecodeMemory::Reservation charge(bodyMemory);  // held until the answer: the body lives that long
        const std::string body = readBody(req, res, reader, charge);
        f(req, body, res);
      } catch (const api::ApiError& e) {
        if (e.type == "decode-busy" || e.type == "body-busy" || e.type == "memory-busy") res.set_header("Retry-After", "1");
        if (e.type == "queue-full") res.set_header("Retry-After", std::to_string(service.retryAfterSeconds()));
        sendProblem(res, e, tRequest.renderId);
      } catch (const std::exception& e) {
        sendProblem(res, 500, "internal-error", "Internal error", e.what(), "", tRequest.renderId);
      }
    };
  }

  template <class F>
  httplib::Server::Handler wrap(F f) {
    return [this, f](const httplib::Request& req, httplib::Response& res) {
      try {
        f(req, res);
      } catch (const api::ApiError& e) {
        if (e.type == "decode-busy" || e.type == "memory-busy") res.set_header("Retry-After", "1");
        if (e.type == "queue-full" || e.type == "sessions-full")
          res.set_header("Retry-After", std::to_string(service.retryAfterSeconds()));
        sendProblem(res, e, tRequest.renderId);
      } catch (const std::exception& e) {
        sendProblem(res, 500, "internal-error", "Internal error", e.what(), "", tRequest.renderId);
      }
    };
  }

  json limitsJson() const {
    return json{{"max_body_bytes", config.maxBodyBytes},
                {"max_width", config.limits.maxWidth},
                {"max_height", config.limits.maxHeight},
                {"max_samples", config.limits.maxSamples},
                {"max_photons", config.limits.maxPhotons},
                {"max_particles", config.limits.maxParticles},
                {"max_map_resolution", config.limits.maxMapResolution},
                {"max_network_nodes", config.limits.maxNetworkNodes},
                {"max_iterations", config.limits.maxIterations},
                {"max_queue", config.maxQueue},
                {"request_timeout_s", config.requestTimeoutS},
                {"frame_ttl_s", config.frameTtlS},
                {"max_json_depth", config.limits.maxJsonDepth},
                {"max_decode_bytes", config.maxDecodeBytes},
                {"decode_memory_bytes", config.decodeMemoryBytes},
                {"decode_memory_effective_bytes", decodeMemory.total()},
                {"body_memory_bytes", config.bodyMemoryBytes},
                {"body_memory_effective_bytes", bodyMemory.total()},
                {"max_frame_bytes", config.maxFrameBytes},
                {"scene_cache_bytes", config.sceneCacheBytes},
                {"gpu_scenes", config.gpuScenes},
                {"derived_cache_bytes", config.derivedCacheBytes},
                {"memory_target_bytes", config.memoryTargetBytes},
                {"memory_limit_bytes", config.memoryLimitBytes},
                {"speed_factor", config.speedFactor > 0 ? json(config.speedFactor) : json("auto")},
                {"default_frame_budget_ms", config.limits.defaultFrameBudgetMs},
                {"read_timeout_s", config.readTimeoutS},
                {"keep_alive_timeout_s", config.keepAliveTimeoutS},
                {"shutdown_grace_s", config.shutdownGraceS},
                {"max_connections", config.maxConnections}};
  }

  json techniquesJson() const {
    json out = json::array();
    std::set<std::string> seen;
    for (const auto& t : api::techniqueSchemas()) {
      json j = api::to_json_value(t);
      bool available = hooks.techniques.empty();
      for (const auto& d : hooks.techniques)
        if (d.name == t.name) {
          available = true;
          j["ground_truths"] = d.groundTruths;
        }
      j["available"] = available;
      out.push_back(j);
      seen.insert(t.name);
    }
    for (const auto& d : hooks.techniques)
      if (!seen.count(d.name))  // implemented but without a schema file: usable with no parameters
        out.push_back(json{{"name", d.name}, {"description", d.description}, {"outputs", d.outputs},
                           {"params", json::object()}, {"available", true}, {"ground_truths", d.groundTruths}});
    return out;
  }

  // Timings from a describe() snapshot (taken under the service's lock).
  void timingHeader(httplib::Response& res, const json& described) {
    const json& t = described["timings"];
    tRequest.queueMs = t.value("queue_ms", 0.0);
    tRequest.renderMs = t.value("render_ms", 0.0);
    tRequest.encodeMs = t.value("encode_ms", 0.0);
    char buf[160];
    std::snprintf(buf, sizeof buf, "queue;dur=%.3f, render;dur=%.3f, encode;dur=%.3f", tRequest.queueMs,
                  tRequest.renderMs, tRequest.encodeMs);
    res.set_header("Server-Timing", buf);
  }

  // Checks a parsed render request's techniques, resolves its scene and images and queues it (POST
  // /v1/renders, sessions). `req`: the HTTP request whose X-Radiant-Scene header routed it (none for a
  // session's generations). A full queue's 503 gets its Retry-After from wrap() / wrapBody().
  std::shared_ptr<Job> submitRequest(api::RenderRequest request, const httplib::Request* req) {
    if (!hooks.techniques.empty())
      for (const auto& [name, params] : request.passes) {
        bool known = false;
        for (const auto& t : hooks.techniques) known = known || t.name == name;
        if (!known)
          throw api::ApiError(422, "technique-unavailable", "Technique unavailable",
                              "/passes/" + name + ": this daemon does not implement \"" + name + "\"",
                              api::pointerAppend("/passes", name));
      }
    // The header is checked before the scene is looked up where the request names its digest (a
    // forged header routes the render to a daemon that may lack the scene: the header is at fault).
    const bool named = request.scene.kind == api::SceneRef::Kind::Digest || request.scene.kind == api::SceneRef::Kind::Builtin;
    if (named && req)
      checkSceneHeader(*req, request.scene.kind == api::SceneRef::Kind::Digest ? request.scene.value
                                                                              : builtinDigest(request.scene.value).value_or(""),
                       "/scene");
    auto scene = resolveScene(request.scene);
    if (!named && req) checkSceneHeader(*req, scene->digest, "/scene");
    // A queued job holds the decoded scene (charged to the decode memory), not the upload's bytes
    // again: an inline scene's base64 (up to --max-body-bytes) is dropped once decoded.
    if (request.scene.kind == api::SceneRef::Kind::Inline) std::string().swap(request.scene.value);
    std::shared_ptr<const Image> compareTarget, environment;
    if (request.compare && request.compare->against != "reference")
      compareTarget = resolveImage(request.compare->against, "/compare/against");
    if (!request.environment.empty()) environment = resolveImage(request.environment, "/environment");
    // What no frame of this scene could render is the POST's 422, not a failed job (Renderer::check).
    if (hooks.checkFrame) {
      FrameInputs inputs;
      inputs.compareTarget = compareTarget.get();
      inputs.environment = environment.get();
      inputs.limits = &config.limits;
      hooks.checkFrame(*scene, request, inputs);
    }
    return service.submit(request, scene, compareTarget, environment, tSceneLoadMs);
  }

  // A refining job's current mean as EXR (the refined AOV and every AOV the outputs name) or PNG (the
  // refined AOV), with its batch count, error estimate and elapsed time as headers.
  void sendCurrent(httplib::Response& res, const Job& job, const RefineSnapshot& snap, const std::string& format) {
    api::OutputSpec spec;
    spec.format = format == "exr" ? api::ImageFormat::Exr : api::ImageFormat::Png;
    spec.halfFloat = false;
    spec.toneMap = job.request.toneMap;
    spec.aovs = {job.request.refine->aov};
    if (spec.format == api::ImageFormat::Exr)
      for (const auto& o : job.request.outputs)
        for (const auto& a : o.aovs)
          if (std::find(spec.aovs.begin(), spec.aovs.end(), a) == spec.aovs.end()) spec.aovs.push_back(a);
    std::string bytes = hooks.encodeFrame(snap.mean, spec, 0, job.request.exposure);
    res.set_header("X-Radiant-Batches", std::to_string(snap.batches));
    res.set_header("X-Radiant-Estimated-Rmse",
                   std::isfinite(snap.estimatedRmse) ? std::to_string(snap.estimatedRmse) : std::string("null"));
    res.set_header("X-Radiant-Elapsed-Ms", std::to_string(snap.elapsedMs));
    // With a compare block: the current mean's RMSE against the ground truth (server/Refinement.h).
    if (snap.metrics.is_object()) res.set_header("X-Radiant-Rmse", snap.metrics["rmse"].dump());
    res.status = 200;
    res.set_content(bytes, spec.format == api::ImageFormat::Exr ? "image/x-exr" : "image/png");
  }

  // One event stream's position: the events sent so far (their ids), and what of the session it has shown.
  struct EventStream {
    std::uint64_t sent = 0;
    bool hello = false, finished = false;
    int generation = -1, batches = 0;
    Clock::time_point lastWrite = Clock::now();
  };
  static constexpr std::size_t kMaxSessionBodyBytes = 1u << 20;

  // Writes what changed in the session since the stream last looked (httplib calls it again while it
  // returns true); waits up to 250 ms for a change, so that shutdown and a closed client are noticed.
  // The stream shows the session's state, not a queue of events: a client that reads slowly skips
  // frames (each event says its batch count) and holds no memory here.
  bool pumpEvents(Session& s, EventStream& st, httplib::DataSink& sink) {
    bool wrote = false, failed = false;
    auto emit = [&](const char* event, const json& data) {
      const std::string text = "id: " + std::to_string(++st.sent) + "\nevent: " + event + "\ndata: " + api::dumpSafe(data) + "\n\n";
      failed = failed || !sink.write(text.data(), text.size());
      wrote = true;
      st.lastWrite = Clock::now();
    };
    const auto until = Clock::now() + std::chrono::milliseconds(250);
    while (!wrote && Clock::now() < until) {
      const SessionStore::View v = sessions.view(s);
      if (!st.hello) {
        emit("session", {{"id", s.id}, {"generation", v.generation}});
        st.hello = true;
      }
      if (v.generation != st.generation && v.job) {
        emit("generation", {{"generation", v.generation}, {"render", v.job->id}});
        st = EventStream{st.sent, true, false, v.generation, 0, st.lastWrite};
      }
      auto frame = [&] {
        if (!v.job) return;
        auto snap = service.current(*v.job);
        if (!snap || snap->batches == st.batches) return;
        st.batches = snap->batches;
        json e{{"generation", v.generation},
               {"render", v.job->id},
               {"batches", snap->batches},
               {"elapsed_ms", snap->elapsedMs},
               {"estimated_rmse", std::isfinite(snap->estimatedRmse) ? json(snap->estimatedRmse) : json(nullptr)},
               {"noise_rmse", std::isfinite(snap->noiseRmse) ? json(snap->noiseRmse) : json(nullptr)},
               {"estimate_kind", snap->estimateKind},
               {"url", "/v1/sessions/" + s.id + "/frame?generation=" + std::to_string(v.generation) + "&batches=" +
                           std::to_string(snap->batches)},
               {"stats", snap->batchStats}};
        if (snap->metrics.is_object()) e["metrics"] = snap->metrics;
        emit("frame", e);
      };
      frame();
      if (v.job && !st.finished && service.terminal(*v.job)) {
        frame();  // a last batch may have landed since
        st.finished = true;
        const json d = service.describe(*v.job);
        if (d["state"] == "done")
          emit("done", {{"generation", v.generation}, {"render", v.job->id}, {"batches", st.batches},
                        {"stopped_by", d["stats"].value("refinement", json::object()).value("stopped_by", "")}});
        else if (d["state"] == "failed")
          emit("error", {{"generation", v.generation}, {"render", v.job->id}, {"error", d.value("error", json())}});
        // canceled: superseded by the next generation, or the session ended (its event follows)
      }
      if (!v.ended.empty()) {
        emit("ended", {{"reason", v.ended}});
        if (!failed) sink.done();
        return !failed;
      }
      if (!wrote) {
        if (Clock::now() - st.lastWrite > std::chrono::seconds(15)) {  // a comment keeps proxies from timing out
          static const std::string keepAlive = ": keep-alive\n\n";
          failed = !sink.write(keepAlive.data(), keepAlive.size());
          st.lastWrite = Clock::now();
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
    return !failed && sink.is_writable();
  }

  // ---- routes ---------------------------------------------------------------------------------
  // The routes, one function per resource (issue 33: the facade split by concern), registered in this
  // order; middleware() first (the worker pool, limits, authentication, problem+json errors, metrics
  // and the access log).
  void routes() {
    middleware();
    serviceRoutes();
    sceneRoutes();
    imageRoutes();
    renderRoutes();
    sessionRoutes();
    reportRoutes();
    viewerRoutes();
  }

  // Worker pool, body limits and timeouts, authentication, problem+json for httplib's own errors and
  // exceptions, per-status counts and the JSON access log.
  void middleware() {
    // Workers start as connections need them (slow clients must not queue health checks behind
    // them), from --http-threads up to --max-connections.
    const int threads = config.httpThreads > 0 ? config.httpThreads : std::min(256, config.maxQueue + 8);
    const int maxThreads = std::max(threads, config.maxConnections);
    http.new_task_queue = [threads, maxThreads] {
      return new ElasticPool(static_cast<std::size_t>(threads), static_cast<std::size_t>(maxThreads));
    };
    http.set_payload_max_length(config.maxBodyBytes);
    http.setTimeouts({config.readTimeoutS, config.keepAliveTimeoutS, 30.0});
    http.set_tcp_nodelay(true);

    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      beginRequest(req, res);
      if (!config.daemonId.empty()) res.set_header("X-Radiant-Daemon", config.daemonId);
      // httplib reads the body of any other POST/PUT/PATCH/DELETE whole into memory before routing;
      // with a Content-Length it is bounded by --max-body-bytes, a chunked or compressed one is not.
      const bool bodyRoute = (req.method == "POST" || req.method == "PUT") &&
                             (req.path == "/v1/renders" || req.path == "/v1/scenes" || req.path == "/v1/images");
      if (!bodyRoute && (req.has_header("Transfer-Encoding") || req.has_header("Content-Encoding"))) {
        markCloseConnection();
        res.set_header("Connection", "close");
        sendProblem(res, 400, "unexpected-body", "Unexpected body",
                    "only POST/PUT /v1/renders, /v1/scenes and /v1/images take a chunked or encoded body");
        return httplib::Server::HandlerResponse::Handled;
      }
      // The viewer's files hold no data (the page asks for the token and sends it with every call).
      const bool page = req.method == "GET" && (req.path == "/ui" || req.path.rfind("/ui/", 0) == 0);
      if (!config.token.empty() && req.path != "/v1/health" && !page) {
        const std::string auth = req.get_header_value("Authorization");
        const std::string expected = "Bearer " + config.token;
        // Constant-time comparison: the time taken must not reveal how much of the token matched.
        unsigned diff = auth.size() != expected.size();
        for (std::size_t i = 0; i < expected.size(); ++i) diff |= i < auth.size() ? (auth[i] ^ expected[i]) : 1u;
        if (diff != 0) {
          res.set_header("WWW-Authenticate", "Bearer");
          sendProblem(res, 401, "unauthorized", "Unauthorized", "a valid \"Authorization: Bearer <token>\" header is required");
          return httplib::Server::HandlerResponse::Handled;
        }
      }
      return httplib::Server::HandlerResponse::Unhandled;
    });

    // Errors httplib produces itself (no route, body over the limit, bad request line) become
    // problem+json too. Handlers' own errors already have a body and are left alone.
    http.set_error_handler(httplib::Server::HandlerWithResponse([this](const httplib::Request& req, httplib::Response& res) {
      if (!tRequest.active) beginRequest(req, res);
      if (!res.has_header("X-Request-Id")) res.set_header("X-Request-Id", tRequest.id);
      if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
      std::string detail = statusTitle(res.status);
      std::string type = "http-" + std::to_string(res.status);
      if (res.status == 404) { type = "not-found"; detail = "no resource at " + api::truncateUtf8(req.method, 16) + " " + api::truncateUtf8(req.path, 200); }
      if (res.status == 413) { type = "payload-too-large"; detail = "the body exceeds the limit of " + std::to_string(config.maxBodyBytes) + " bytes"; }
      sendProblem(res, res.status, type, statusTitle(res.status), detail);
      return httplib::Server::HandlerResponse::Handled;
    }));
    http.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
      std::string what = "unknown exception";
      try {
        if (ep) std::rethrow_exception(ep);
      } catch (const std::exception& e) {
        what = e.what();
      } catch (...) {
      }
      sendProblem(res, 500, "internal-error", "Internal error", what);
    });
    // Count in the post-routing handler, which httplib runs before it writes the response: counting
    // in the logger (after the write) let a client see its own request missing from /metrics.
    http.set_post_routing_handler([this](const httplib::Request&, httplib::Response& res) {
      metrics.countRequest(res.status);
    });
    http.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
      json line{{"ts_ms", std::chrono::duration_cast<std::chrono::milliseconds>(
                              std::chrono::system_clock::now().time_since_epoch()).count()},
                {"id", tRequest.id},
                {"method", req.method},
                {"path", req.path},
                {"status", res.status},
                {"duration_ms", tRequest.active ? std::chrono::duration<double, std::milli>(Clock::now() - tRequest.start).count() : 0.0}};
      line["queue_ms"] = tRequest.queueMs >= 0 ? json(tRequest.queueMs) : json(nullptr);
      line["render_ms"] = tRequest.renderMs >= 0 ? json(tRequest.renderMs) : json(nullptr);
      line["encode_ms"] = tRequest.encodeMs >= 0 ? json(tRequest.encodeMs) : json(nullptr);
      if (!tRequest.renderId.empty()) line["render_id"] = tRequest.renderId;
      std::fprintf(stderr, "%s\n", api::dumpSafe(line).c_str());
      tRequest = RequestContext{};
    });
  }

  // /v1/health, /v1/ready, /v1/info, /metrics.
  void serviceRoutes() {
    http.Get("/v1/health", wrap([](const httplib::Request&, httplib::Response& res) {
      sendJson(res, 200, {{"status", "ok"}});
    }));

    http.Get("/v1/ready", wrap([this](const httplib::Request&, httplib::Response& res) {
      if (shuttingDown) {
        res.set_header("Retry-After", "5");
        return sendProblem(res, 503, "shutting-down", "Shutting down", "the daemon is shutting down");
      }
      auto device = service.device();
      if (!service.ready() || !device) {
        res.set_header("Retry-After", "1");
        return sendProblem(res, 503, "not-ready", "Not ready", service.notReadyReason());
      }
      sendJson(res, 200, {{"ready", true}, {"device", deviceJson(*device)}});
    }));

    http.Get("/v1/info", wrap([this](const httplib::Request&, httplib::Response& res) {
      auto device = service.device();
      sendJson(res, 200,
               {{"name", "radiantd"},
                {"version", kVersion},
                {"api", "v1"},
                {"daemon_id", config.daemonId.empty() ? json(nullptr) : json(config.daemonId)},
                {"ready", service.ready()},
                {"device", device ? deviceJson(*device) : json(nullptr)},
                {"limits", limitsJson()},
                {"techniques", techniquesJson()},
                {"aovs", api::aovTableJson()},
                // quality / time_budget_ms resolve against this table (api/Presets.h, docs/API.md)
                {"presets", api::PresetTable::builtin().data()},
                {"request_schema", api::renderRequestSchema()}});
    }));

    http.Get("/metrics", wrap([this](const httplib::Request&, httplib::Response& res) {
      std::map<std::string, std::pair<std::string, double>> gauges{
          {"radiant_queue_depth", {"Jobs waiting for the render thread.", double(service.queueDepth())}},
          {"radiant_jobs_active", {"Jobs rendering or encoding.", double(service.active())}},
          {"radiant_sessions_open", {"Progressive sessions open.", double(sessions.open())}},
          {"radiant_ready", {"1 once the render thread has a GL context.", service.ready() ? 1.0 : 0.0}},
          {"radiant_scene_store_bytes", {"Bytes of uploaded scenes stored.", double(scenes.totalBytes())}},
          {"radiant_scene_cache_bytes", {"Bytes of decoded scenes kept in memory (--scene-cache-bytes).", double(decoded.totalBytes())}},
          {"radiant_image_store_bytes", {"Bytes of uploaded comparison images stored.", double(images.totalBytes())}},
          {"radiant_image_cache_bytes", {"Bytes of decoded images kept in memory (half of --scene-cache-bytes).", double(decodedImages.totalBytes())}},
          {"radiant_frame_store_bytes", {"Bytes of encoded frames stored.", double(frames.totalBytes())}},
          {"radiant_decode_bytes_reserved", {"Bytes of --decode-memory-bytes taken: decodes in flight, and the decoded scenes and images cached or held by renders.", double(decodeMemory.reserved())}},
          {"radiant_decodes_refused", {"Decodes refused with 503 decode-busy since start (--decode-memory-bytes).", double(decodeMemory.refused())}},
          {"radiant_memory_refused", {"Bodies and decodes refused with 503 memory-busy since start: the resident set was near --memory-limit-bytes.", double(residentGate.refused())}},
          {"radiant_body_bytes_reserved", {"Bytes of --body-memory-bytes taken by request bodies being read or handled.", double(bodyMemory.reserved())}},
          {"radiant_bodies_refused", {"Requests refused with 503 body-busy since start (--body-memory-bytes).", double(bodyMemory.refused())}}};
      res.status = 200;
      res.set_content(metrics.text(gauges), "text/plain; version=0.0.4; charset=utf-8");
    }));
  }

  // /v1/scenes: content-addressed glTF uploads (PUT/POST), the list, one scene's metadata (GET/HEAD).
  void sceneRoutes() {
    auto upload = wrapBody([this](const httplib::Request& req, const std::string& body, httplib::Response& res) {
      static const std::set<std::string> kTypes{"model/gltf-binary", "model/gltf+json", "application/octet-stream",
                                                "application/json"};
      const std::string type = mediaType(req);
      if (!kTypes.count(type))
        throw api::ApiError(415, "unsupported-media-type", "Unsupported media type",
                            "scenes are uploaded as model/gltf-binary or model/gltf+json (also accepted: "
                            "application/octet-stream, application/json), got \"" + type + "\"");
      if (body.empty()) throw api::ApiError(400, "empty-body", "Empty body", "the body holds no scene");
      const std::string digest = api::sceneDigest(body);
      checkSceneHeader(req, digest);
      bool created = false;
      // get(), not contains(): a file in the cache dir that no longer matches its digest is dropped there.
      if (!scenes.get(digest)) {
        decode(digest, body, "");  // reject what the loader cannot read before storing it
        created = scenes.put(digest, body);
      }
      res.set_header("Location", "/v1/scenes/" + digest);
      sendJson(res, created ? 201 : 200,
               {{"digest", digest}, {"bytes", body.size()}, {"format", ContentStore::formatOf(body)},
                {"created", created}});
    });
    http.Put("/v1/scenes", upload);
    http.Post("/v1/scenes", upload);

    http.Get("/v1/scenes", wrap([this](const httplib::Request&, httplib::Response& res) {
      json builtins = json::array();
      for (const auto& name : builtinNames()) builtins.push_back({{"name", name}, {"digest", *builtinDigest(name)}});
      json uploaded = json::array();
      for (const auto& s : scenes.list())
        uploaded.push_back({{"digest", s.digest}, {"bytes", s.bytes}, {"format", s.format}});
      sendJson(res, 200,
               {{"builtins", builtins},
                {"uploaded", uploaded},
                {"store", {{"bytes", scenes.totalBytes()}, {"max_bytes", config.maxSceneBytes}}}});
    }));

    // GET and HEAD (httplib routes HEAD to GET handlers and sends no body).
    http.Get(R"(/v1/scenes/([^/]+))", wrap([this](const httplib::Request& req, httplib::Response& res) {
      const std::string ref = req.matches[1];
      checkSceneHeader(req, api::isSceneDigest(ref) ? ref : builtinDigest(ref).value_or(""));
      std::optional<std::string> bytes;
      if (api::isSceneDigest(ref)) {
        if (req.method == "HEAD" && scenes.contains(ref)) bytes = std::string();
        else bytes = scenes.get(ref);
        if (!bytes)
          if (auto name = builtinByDigest(ref)) bytes = req.method == "HEAD" ? std::string() : hooks.builtinSceneSource(*name);
      } else if (builtinDigest(ref)) {
        bytes = req.method == "HEAD" ? std::string() : hooks.builtinSceneSource(ref);
      }
      if (!bytes) throw api::ApiError(404, "unknown-scene", "Unknown scene", "no scene " + ref);
      res.status = 200;
      if (req.method == "HEAD") return;
      res.set_content(*bytes, ContentStore::formatOf(*bytes) == "glb" ? "model/gltf-binary" : "model/gltf+json");
    }));
  }

  // /v1/images: comparison images and environment maps, content-addressed like scenes.
  void imageRoutes() {
    // Comparison images: content-addressed like scenes; a render's compare.against names one by digest.
    auto uploadImage = wrapBody([this](const httplib::Request& req, const std::string& body, httplib::Response& res) {
      static const std::set<std::string> kTypes{"image/x-exr", "image/vnd.radiance", "image/png",
                                                "application/octet-stream"};
      const std::string type = mediaType(req);
      if (!kTypes.count(type))
        throw api::ApiError(415, "unsupported-media-type", "Unsupported media type",
                            "comparison images are uploaded as image/x-exr, image/vnd.radiance or image/png (also "
                            "accepted: application/octet-stream), got \"" + type + "\"");
      if (body.empty()) throw api::ApiError(400, "empty-body", "Empty body", "the body holds no image");
      const std::string digest = api::sceneDigest(body);
      bool created = false;
      if (!images.get(digest)) {
        if (!hooks.decodeImage) throw std::logic_error("no image decoder configured");
        DecodeMemory::Reservation memory(decodeMemory);
        const Image decoded = hooks.decodeImage(body, memory.hook());  // refuse what cannot be read before storing it
        created = images.put(digest, body);
      }
      res.set_header("Location", "/v1/images/" + digest);
      sendJson(res, created ? 201 : 200,
               {{"digest", digest}, {"bytes", body.size()}, {"format", ContentStore::formatOf(body)},
                {"created", created}});
    });
    http.Put("/v1/images", uploadImage);
    http.Post("/v1/images", uploadImage);
    http.Get(R"(/v1/images/([^/]+))", wrap([this](const httplib::Request& req, httplib::Response& res) {
      const std::string digest = req.matches[1];
      std::optional<std::string> bytes;
      if (api::isSceneDigest(digest)) bytes = req.method == "HEAD" ? (images.contains(digest) ? std::optional<std::string>("") : std::nullopt)
                                                                   : images.get(digest);
      if (!bytes) throw api::ApiError(404, "unknown-image", "Unknown image", "no image " + digest);
      res.status = 200;
      if (req.method == "HEAD") return;
      static const std::map<std::string, std::string> kMime{{"exr", "image/x-exr"}, {"hdr", "image/vnd.radiance"}, {"png", "image/png"}};
      const auto mime = kMime.find(ContentStore::formatOf(*bytes));  // the store holds only these formats
      res.set_content(*bytes, mime != kMime.end() ? mime->second : "application/octet-stream");
    }));
  }

  // /v1/renders (submit, poll, cancel) and /v1/frames (a finished frame's bytes).
  void renderRoutes() {
    http.Post("/v1/renders", wrapBody([this](const httplib::Request& req, const std::string& requestBody, httplib::Response& res) {
      if (mediaType(req) != "application/json")
        throw api::ApiError(415, "unsupported-media-type", "Unsupported media type",
                            "render requests are application/json, got \"" + mediaType(req) + "\"");
      if (shuttingDown)
        throw api::ApiError(503, "shutting-down", "Shutting down", "the daemon is shutting down and accepts no new renders");
      api::RenderRequest request = api::parseRenderRequest(std::string_view(requestBody), config.limits);
      std::shared_ptr<Job> job = submitRequest(request, &req);
      tRequest.renderId = job->id;
      res.set_header("X-Render-Id", job->id);
      if (request.async) {
        res.set_header("Location", "/v1/renders/" + job->id);
        json body = service.describe(*job);
        body["url"] = "/v1/renders/" + job->id;
        return sendJson(res, 202, body);
      }
      // Housekeeping fails the job at its deadline; the margin covers its 50 ms tick.
      service.waitFor(job, job->deadline + std::chrono::seconds(2));
      json body = service.describe(*job);
      timingHeader(res, body);
      if (body["state"] == "done") return sendJson(res, 200, body);
      if (body.contains("error")) {
        const json& e = body["error"];
        std::string type = e["type"].get<std::string>().substr(std::string("https://radiant.dev/problems/").size());
        if (type == "memory-busy") res.set_header("Retry-After", "1");
        return sendProblem(res, e["status"], type, e["title"], e["detail"], e.value("pointer", ""), job->id);
      }
      sendProblem(res, 504, "timeout", "Render timed out", "render " + job->id + " did not finish in time", "", job->id);
    }));

    http.Get(R"(/v1/renders/([A-Za-z0-9_-]+))", wrap([this](const httplib::Request& req, httplib::Response& res) {
      auto job = service.find(req.matches[1]);
      if (!job)
        throw api::ApiError(404, "unknown-render", "Unknown render", "no render " + std::string(req.matches[1]) + " (finished renders expire after " + std::to_string(config.frameTtlS) + " s)");
      tRequest.renderId = job->id;
      // ?current=exr|png: a refine job's current mean (docs/API.md, "Progressive refinement").
      if (req.has_param("current")) {
        const std::string format = req.get_param_value("current");
        if (format != "exr" && format != "png")
          throw api::ApiError(400, "invalid-query", "Invalid query parameter",
                              "current: \"" + format + "\" is not exr or png");
        auto snap = service.current(*job);
        if (!snap)
          throw api::ApiError(409, "no-current-frame", "No current frame",
                              "render " + job->id +
                                  (job->request.refine ? " has not finished its first batch yet"
                                                       : " does not refine (the request has no \"refine\")"));
        sendCurrent(res, *job, *snap, format);
        return;
      }
      json body = service.describe(*job);
      if (body["progress"] == 1.0) timingHeader(res, body);
      sendJson(res, 200, body);
    }));

    http.Delete(R"(/v1/renders/([A-Za-z0-9_-]+))", wrap([this](const httplib::Request& req, httplib::Response& res) {
      const std::string id = req.matches[1];
      tRequest.renderId = id;
      switch (service.cancel(id)) {
        case RenderService::CancelResult::NotFound:
          throw api::ApiError(404, "unknown-render", "Unknown render", "no render " + id);
        case RenderService::CancelResult::Removed:
          return sendJson(res, 200, {{"id", id}, {"state", "canceled"}});
        case RenderService::CancelResult::Requested:
          return sendJson(res, 202, {{"id", id}, {"state", "running"}, {"cancel_requested", true}});
        case RenderService::CancelResult::Forgotten:
          return sendJson(res, 200, {{"id", id}, {"deleted", true}});
      }
    }));
    http.Get(R"(/v1/frames/([A-Za-z0-9_-]+)/([A-Za-z0-9_.-]+))", wrap([this](const httplib::Request& req, httplib::Response& res) {
      auto frame = frames.get(req.matches[1], req.matches[2]);
      if (!frame)
        throw api::ApiError(404, "unknown-frame", "Unknown frame",
                            "no frame " + std::string(req.matches[1]) + "/" + std::string(req.matches[2]) +
                                " (frames expire after " + std::to_string(config.frameTtlS) + " s)");
      res.status = 200;
      res.set_content(*frame->bytes, frame->contentType);
    }));
  }

  // Progressive sessions (server/Sessions.h, docs/API.md "Sessions").
  void sessionRoutes() {
    auto sessionBody = [this](const httplib::Request& req) {
      if (mediaType(req) != "application/json" && mediaType(req) != "application/merge-patch+json")
        throw api::ApiError(415, "unsupported-media-type", "Unsupported media type",
                            "session requests are application/json (a change may be application/merge-patch+json), got \"" +
                                mediaType(req) + "\"");
      if (req.body.size() > kMaxSessionBodyBytes)
        throw api::ApiError(413, "payload-too-large", "Payload too large",
                            "a session request or change is at most " + std::to_string(kMaxSessionBodyBytes) +
                                " bytes; upload scenes and images (PUT /v1/scenes, /v1/images) and name their digests");
      return api::parseJson(req.body, config.limits.maxJsonDepth);
    };
    auto findSession = [this](const std::string& id) {
      auto s = sessions.find(id);
      if (!s)
        throw api::ApiError(404, "unknown-session", "Unknown session",
                            "no session " + api::truncateUtf8(id, 80) + " (sessions end on DELETE, after " +
                                std::to_string(static_cast<int>(config.sessionIdleS)) +
                                " s without an event stream or a request, and on shutdown)");
      return s;
    };
    http.Post("/v1/sessions", wrap([this, sessionBody](const httplib::Request& req, httplib::Response& res) {
      if (shuttingDown)
        throw api::ApiError(503, "shutting-down", "Shutting down", "the daemon is shutting down and opens no sessions");
      auto s = sessions.create(sessionBody(req));
      res.set_header("Location", "/v1/sessions/" + s->id);
      sendJson(res, 201, sessions.describe(*s));
    }));
    http.Get("/v1/sessions", wrap([this](const httplib::Request&, httplib::Response& res) {
      sendJson(res, 200, {{"open", sessions.open()}, {"max_sessions", config.maxSessions}});
    }));
    http.Get(R"(/v1/sessions/([A-Za-z0-9_-]+))", wrap([this, findSession](const httplib::Request& req, httplib::Response& res) {
      sendJson(res, 200, sessions.describe(*findSession(req.matches[1])));
    }));
    http.Patch(R"(/v1/sessions/([A-Za-z0-9_-]+))", wrap([this, findSession, sessionBody](const httplib::Request& req, httplib::Response& res) {
      auto s = findSession(req.matches[1]);
      if (shuttingDown)
        throw api::ApiError(503, "shutting-down", "Shutting down", "the daemon is shutting down and renders nothing new");
      sessions.patch(s, sessionBody(req));
      sendJson(res, 200, sessions.describe(*s));
    }));
    http.Delete(R"(/v1/sessions/([A-Za-z0-9_-]+))", wrap([this, findSession](const httplib::Request& req, httplib::Response& res) {
      auto s = findSession(req.matches[1]);
      sessions.end(s->id, "deleted");
      sendJson(res, 200, {{"id", s->id}, {"ended", "deleted"}});
    }));
    // The current generation's refined mean: PNG (default) or EXR, as GET /v1/renders/{id}?current=.
    http.Get(R"(/v1/sessions/([A-Za-z0-9_-]+)/frame)", wrap([this, findSession](const httplib::Request& req, httplib::Response& res) {
      auto s = findSession(req.matches[1]);
      const std::string format = req.has_param("format") ? req.get_param_value("format") : "png";
      if (format != "exr" && format != "png")
        throw api::ApiError(400, "invalid-query", "Invalid query parameter", "format: \"" + api::truncateUtf8(format, 40) + "\" is not exr or png");
      const SessionStore::View v = sessions.view(*s);
      auto snap = v.job ? service.current(*v.job) : nullptr;
      if (!snap)
        throw api::ApiError(409, "no-current-frame", "No current frame",
                            "session " + s->id + " generation " + std::to_string(v.generation) + " has not finished its first batch yet");
      res.set_header("X-Radiant-Generation", std::to_string(v.generation));
      res.set_header("Cache-Control", "no-store");
      const std::string layer = req.has_param("layer") ? req.get_param_value("layer") : "mean";
      if (layer == "reference") {  // the compare block's ground truth, in the frame's view transform
        if (!snap->truth)
          throw api::ApiError(409, "no-reference", "No reference",
                              "session " + s->id + " is not scored against a reference (set \"compare\")");
        RefineSnapshot truth = *snap;
        truth.mean = {*snap->truth};
        truth.mean[0].aov = v.job->request.refine->aov;
        return sendCurrent(res, *v.job, truth, format);
      }
      if (layer != "mean")
        throw api::ApiError(400, "invalid-query", "Invalid query parameter", "layer: \"" + api::truncateUtf8(layer, 40) + "\" is not mean or reference");
      sendCurrent(res, *v.job, *snap, format);
    }));
    // Server-Sent Events: session, generation, frame, done, error, ended (docs/API.md "Sessions").
    http.Get(R"(/v1/sessions/([A-Za-z0-9_-]+)/events)", wrap([this, findSession](const httplib::Request& req, httplib::Response& res) {
      auto s = findSession(req.matches[1]);
      if (!sessions.streamOpened(*s))
        throw api::ApiError(429, "too-many-streams", "Too many event streams",
                            "session " + s->id + " already has " + std::to_string(SessionStore::kMaxStreams) +
                                " event streams open (each holds a connection); close one");
      auto state = std::make_shared<EventStream>();
      res.set_header("Cache-Control", "no-store");
      res.set_header("X-Accel-Buffering", "no");  // nginx passes events on as they come
      res.set_chunked_content_provider(
          "text/event-stream",
          [this, s, state](std::size_t, httplib::DataSink& sink) { return pumpEvents(*s, *state, sink); },
          [this, s](bool) { sessions.streamClosed(*s); });
    }));
  }

  // Sweep reports (--reports-dir), read-only.
  void reportRoutes() {
    // A report's files only: names of [A-Za-z0-9_.-] not starting with '.', at most one folder deep
    // inside the report, resolved (through symlinks) inside the reports folder, of a known type.
    static const std::map<std::string, std::string> kReportTypes{
        {".html", "text/html; charset=utf-8"}, {".svg", "image/svg+xml"}, {".png", "image/png"},
        {".md", "text/markdown; charset=utf-8"}, {".json", "application/json"}, {".jsonl", "application/x-ndjson"},
        {".txt", "text/plain; charset=utf-8"}, {".csv", "text/csv; charset=utf-8"}};
    auto reportHeaders = [](httplib::Response& res) {
      // Reports carry inline styles and SVG, never scripts.
      res.set_header("Content-Security-Policy",
                     "default-src 'none'; img-src 'self' data:; style-src 'unsafe-inline'; base-uri 'none'; "
                     "form-action 'none'; frame-ancestors 'none'");
      res.set_header("X-Content-Type-Options", "nosniff");
      res.set_header("Cache-Control", "no-cache");
    };
    auto reportsRoot = [this]() {
      std::error_code ec;
      const std::filesystem::path root = config.reportsDir.empty() ? std::filesystem::path() : std::filesystem::canonical(config.reportsDir, ec);
      if (config.reportsDir.empty() || ec)
        throw api::ApiError(404, "reports-off", "No reports",
                            config.reportsDir.empty() ? "this daemon serves no sweep reports (radiantd --reports-dir DIR)"
                                                      : "the reports folder " + config.reportsDir + " does not exist");
      return root;
    };
    http.Get("/reports/", wrap([reportHeaders, reportsRoot](const httplib::Request&, httplib::Response& res) {
      const std::filesystem::path root = reportsRoot();
      std::vector<std::pair<std::filesystem::file_time_type, std::string>> reports;
      std::error_code ec;
      for (const auto& e : std::filesystem::directory_iterator(root, ec)) {
        const std::string name = e.path().filename().string();
        if (name.empty() || name[0] == '.' || !e.is_directory(ec) || !std::filesystem::is_regular_file(e.path() / "report.html", ec)) continue;
        if (!std::all_of(name.begin(), name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'; }))
          continue;
        reports.emplace_back(std::filesystem::last_write_time(e.path() / "report.html", ec), name);
      }
      std::sort(reports.rbegin(), reports.rend());  // newest first
      std::string page = "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Sweep reports</title></head>\n"
                         "<body><h1>Sweep reports</h1>\n<ul>\n";
      for (const auto& [when, name] : reports) page += "<li><a href=\"" + name + "/report.html\">" + name + "</a></li>\n";
      page += std::string("</ul>\n") + (reports.empty() ? "<p>None yet: <code>radiant report RESULTS.jsonl -o DIR/NAME</code>.</p>\n" : "") +
              "</body></html>\n";
      reportHeaders(res);
      res.status = 200;
      res.set_content(page, "text/html; charset=utf-8");
    }));
    http.Get(R"(/reports/([A-Za-z0-9_-][A-Za-z0-9_.-]*)/((?:[A-Za-z0-9_-][A-Za-z0-9_.-]*/)?[A-Za-z0-9_-][A-Za-z0-9_.-]*))",
             wrap([reportHeaders, reportsRoot](const httplib::Request& req, httplib::Response& res) {
      const std::filesystem::path root = reportsRoot();
      const std::string rel = std::string(req.matches[1]) + "/" + std::string(req.matches[2]);
      auto notFound = [&] {
        return api::ApiError(404, "unknown-report-file", "Unknown report file", "no report file " + api::truncateUtf8(rel, 200));
      };
      if (rel.find("..") != std::string::npos) throw notFound();
      std::error_code ec;
      const std::filesystem::path file = std::filesystem::canonical(root / rel, ec);
      const auto type = kReportTypes.find(file.extension().string());
      if (ec || type == kReportTypes.end() || !std::filesystem::is_regular_file(file, ec)) throw notFound();
      auto [inside, rest] = std::mismatch(root.begin(), root.end(), file.begin(), file.end());
      if (inside != root.end()) throw notFound();  // a symlink out of the reports folder
      const auto size = std::filesystem::file_size(file, ec);
      if (ec || size > (std::uintmax_t(64) << 20)) throw notFound();
      std::ifstream in(file, std::ios::binary);
      std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      reportHeaders(res);
      res.status = 200;
      res.set_content(bytes, type->second);
    }));
  }

  // The viewer (server/ui, embedded).
  void viewerRoutes() {
    auto page = [this](const std::string& name, const char* type) {
      return wrap([this, name, type](const httplib::Request&, httplib::Response& res) {
        if (!uiServed(config))
          throw api::ApiError(404, "ui-off", "Viewer off",
                              config.ui ? "the viewer is served on a loopback address, or with --token-file, only"
                                        : "the viewer is off (--ui off)");
        const std::string_view bytes = ui::find(name);
        res.set_header("Content-Security-Policy",
                       "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' blob: data:; "
                       "connect-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'");
        res.set_header("X-Content-Type-Options", "nosniff");
        res.set_header("Referrer-Policy", "no-referrer");
        res.set_header("Cache-Control", "no-cache");
        res.status = 200;
        res.set_content(std::string(bytes), type);
      });
    };
    http.Get("/ui", wrap([](const httplib::Request&, httplib::Response& res) {
      res.status = 308;
      res.set_header("Location", "/ui/");
    }));
    http.Get("/ui/", page("index.html", "text/html; charset=utf-8"));
    http.Get("/ui/viewer.js", page("viewer.js", "text/javascript; charset=utf-8"));
    http.Get("/ui/viewer.css", page("viewer.css", "text/css; charset=utf-8"));
  }
};

HttpServer::HttpServer(ServerConfig config, BackendHooks hooks)
    : impl_(std::make_unique<Impl>(std::move(config), std::move(hooks))) {}

HttpServer::~HttpServer() {
  impl_->http.stop();
  impl_->service.stop();
}

int HttpServer::bind() {
  int port = impl_->config.port;
  if (port == 0) {
    port = impl_->http.bind_to_any_port(impl_->config.host);
    if (port < 0) throw std::runtime_error("HttpServer::bind(): cannot bind " + impl_->config.host + " to any port");
  } else if (!impl_->http.bind_to_port(impl_->config.host, port)) {
    throw std::runtime_error("HttpServer::bind(): cannot bind " + impl_->config.host + ":" + std::to_string(port) +
                             " (in use by another process? --port 0 takes a free one)");
  }
  return port;
}

bool HttpServer::run() { return impl_->http.listen_after_bind(); }

void HttpServer::shutdown() {
  impl_->shuttingDown = true;
  impl_->sessions.endAll("shutdown");
  impl_->service.drain();
  // Grace period: the renders just finished still have frames to download and jobs to poll
  // (new renders get 503 meanwhile). It ends early once every stored frame has been fetched.
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(impl_->config.shutdownGraceS));
  while (Clock::now() < end && impl_->frames.unfetched() > 0)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  impl_->http.stop();
}

RenderService& HttpServer::service() { return impl_->service; }
const ServerConfig& HttpServer::config() const { return impl_->config; }

}  // namespace radiant::server
