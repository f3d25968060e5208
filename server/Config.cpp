#include "server/Config.h"

#include <algorithm>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace radiant::server {

std::string usage() {
  return R"(usage: radiantd [options]
  --host ADDR               bind address (default 127.0.0.1)
  --port N                  TCP port, 0 = ephemeral (default 8080)
  --cache-dir DIR           persist uploaded scenes here across restarts
  --asset-root DIR          serve glTF files under DIR to requests naming scene.asset (a path
                            relative to DIR; the files it references must lie inside DIR too)
  --token-file FILE         require "Authorization: Bearer <contents of FILE>"
  --config FILE             JSON file with any of these options (keys use '_': "max_queue")
  --max-body-bytes N        largest request body (default 67108864)
  --body-memory-bytes N     bytes the request bodies being read or handled may hold together (at least
                            --max-body-bytes): a body is charged as it arrives (its Content-Length at
                            once) until its request is answered; one that does not fit waits up to 1 s,
                            then gets 503 body-busy (default 268435456)
  --max-width N, --max-height N   largest image (default 4096, never above the schema's 4096)
  --max-samples N           largest per-pixel sample count (x-cost "samples": spp, samples, light paths
                            per pixel, compare.spp) (default 65536)
  --max-photons N           largest photon count of any pass (x-cost "photons") (default 4000000)
  --max-particles N         particles of a request's media systems together (default 65536)
  --max-map-resolution N    texels per side of any map or grid a pass allocates (x-cost "resolution":
                            shadow_map_size, cube_resolution, ...) (default 4096)
  --max-network-nodes N     illumination_network nodes (x-cost "nodes") (default 65536)
  --max-iterations N        iterations of an iterative pass (x-cost "iterations") (default 1024)
  --max-queue N             jobs waiting behind the running one before 503 (default 16)
  --request-timeout S       seconds from submission to encoded frames (default 300)
  --frame-ttl S             seconds frames and finished jobs are kept (default 600)
  --max-frame-bytes N       frame store size (default 536870912)
  --max-scene-bytes N       scene store size, least recently used evicted (default 1073741824)
  --scene-cache N           decoded scenes kept in memory (default 8)
  --encoder-threads N       EXR/PNG encoder threads (default 2)
  --http-threads N          HTTP worker threads (default max-queue + 8)
  --device-index N          EGL device index
  --device NAME             EGL device whose GL_RENDERER or GL_VENDOR contains NAME
  --cuda-device N           EGL device of CUDA device N (NVIDIA, EGL_NV_device_cuda): one daemon per GPU
  --gl-debug                GL debug context, messages to stderr
  --max-json-depth N        deepest nesting of a request or a glTF document (default 64)
  --max-decode-bytes N      memory one scene or image may decode into: pixels of every image,
                            expanded accessors of every mesh instance (default 536870912)
  --decode-memory-bytes N   bytes all decodes in flight and the decoded scenes and images kept
                            (cached, or held by queued and running renders) may take together (at
                            least --max-decode-bytes): each decode reserves its images' and
                            accessors' bytes before allocating them; one that does not fit drops
                            unheld cached results, waits up to 1 s, then gets 503 decode-busy
                            (default 1073741824)
  --scene-cache-bytes N     decoded scenes kept in memory, in bytes (default 1073741824)
  --gpu-scenes N            scenes kept uploaded to the GPU with their derived data (BVH, shadow maps,
                            photon maps), least recently used evicted (default 4, at most 256)
  --derived-cache-bytes N   photon sets and splat grids kept across renders, in bytes, least recently
                            used dropped first (default 1073741824; the frame in use keeps its own)
  --memory-target-bytes N   the resident set the renderer keeps the daemon under: a pass about to
                            allocate much (photon records and splats, specular and caustic maps) and
                            every frame's end release what the frame does not use (other scenes' GPU
                            copies, maps and derived data) when over it (default 1342177280)
  --memory-limit-bytes N    a frame whose large allocation (photon records and splats, specular and
                            caustic maps) would take the daemon's resident set over N even after that
                            release gets 503 memory-busy with Retry-After, before allocating; so does a
                            decode or a request body that would (after dropping unheld decoded scenes
                            and waiting up to 1 s), whatever the budgets above sum to; 0 = no limit
                            (default 1500000000)
  --speed-factor F|auto      this machine's frame time over the preset table's prediction, which time
                            budgets scale every predicted cost by; auto (the default) measures it: a
                            calibration frame before the first budgeted frame, then recent frames
                            (docs/API.md, "Presets and budgets"); a number pins it
  --default-frame-budget-ms MS
                            a request that names no quality, time_budget_ms or passes, whose default
                            configuration the preset table (times the speed factor) predicts above MS,
                            renders the time budget's choice for MS instead, with a warning; 0 = off
                            (default 10000, sized for a 256x256 default frame on a 2-core llvmpipe machine;
                            docs/API.md, "Presets and budgets")
  --read-timeout S          seconds to receive one request, headers and body (default 30)
  --keep-alive-timeout S    seconds an idle keep-alive connection stays open (default 2)
  --shutdown-grace S        after SIGTERM, seconds frame and job GETs are still served (default 10)
  --max-connections N       connections served at once, one worker thread each (default 256)
  --daemon-id ID            this daemon's name behind a proxy, [a-z0-9]{1,32}: render ids (and so the
                            job and frame URLs) start with "ID-" for the proxy to route on (docs/DEPLOYMENT.md)
  --max-sessions N          progressive sessions open at once (default 8; docs/API.md, "Sessions")
  --session-idle-s S        a session without an open event stream ends after S s untouched (default 60)
  --reports-dir DIR         serve the sweep reports under DIR (radiant report -o DIR/NAME) read-only
                            at /reports/, linked from the viewer
  --ui auto|off             the viewer page at /ui/: auto serves it on a loopback address, or on any
                            address when a token is required (default auto)
)";
}

namespace {

std::string readToken(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("--token-file: cannot read " + path);
  std::string token((std::istreambuf_iterator<char>(in)), {});
  while (!token.empty() && (token.back() == '\n' || token.back() == '\r' || token.back() == ' ')) token.pop_back();
  if (token.empty()) throw std::invalid_argument("--token-file: " + path + " is empty");
  return token;
}

long long toInt(const std::string& flag, const std::string& v, long long lo, long long hi) {
  std::size_t used = 0;
  long long n = 0;
  try {
    n = std::stoll(v, &used);
  } catch (...) {
    used = 0;
  }
  if (used != v.size() || v.empty()) throw std::invalid_argument(flag + ": expected an integer, got \"" + v + "\"");
  if (n < lo || n > hi)
    throw std::invalid_argument(flag + ": " + v + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return n;
}

double toDouble(const std::string& flag, const std::string& v) {
  std::size_t used = 0;
  double d = 0;
  try {
    d = std::stod(v, &used);
  } catch (...) {
    used = 0;
  }
  if (used != v.size() || !(d > 0)) throw std::invalid_argument(flag + ": expected a positive number, got \"" + v + "\"");
  return d;
}

// Applies one option (flag name without dashes, '-' form) to the config.
void apply(ServerConfig& c, const std::string& name, const std::string& v, std::string& tokenFile) {
  const std::string flag = "--" + name;
  if (name == "host") c.host = v;
  else if (name == "port") c.port = static_cast<int>(toInt(flag, v, 0, 65535));
  else if (name == "cache-dir") c.cacheDir = v;
  else if (name == "asset-root") c.assetRoot = v;
  else if (name == "token-file") tokenFile = v;
  else if (name == "max-body-bytes") c.maxBodyBytes = static_cast<std::size_t>(toInt(flag, v, 1024, 1ll << 40));
  else if (name == "max-width") c.limits.maxWidth = static_cast<int>(toInt(flag, v, 1, 4096));
  else if (name == "max-height") c.limits.maxHeight = static_cast<int>(toInt(flag, v, 1, 4096));
  else if (name == "max-samples") c.limits.maxSamples = static_cast<int>(toInt(flag, v, 1, 65536));
  else if (name == "max-photons") c.limits.maxPhotons = toInt(flag, v, 1, 4000000);
  else if (name == "max-particles") c.limits.maxParticles = static_cast<std::size_t>(toInt(flag, v, 1, 1048576));
  else if (name == "max-map-resolution") c.limits.maxMapResolution = static_cast<int>(toInt(flag, v, 1, 4096));
  else if (name == "max-network-nodes") c.limits.maxNetworkNodes = static_cast<int>(toInt(flag, v, 1, 65536));
  else if (name == "max-iterations") c.limits.maxIterations = static_cast<int>(toInt(flag, v, 0, 1024));
  else if (name == "max-queue") c.maxQueue = static_cast<int>(toInt(flag, v, 1, 10000));
  else if (name == "request-timeout") c.requestTimeoutS = toDouble(flag, v);
  else if (name == "frame-ttl") c.frameTtlS = toDouble(flag, v);
  else if (name == "max-frame-bytes") c.maxFrameBytes = static_cast<std::size_t>(toInt(flag, v, 1024, 1ll << 40));
  else if (name == "max-scene-bytes") c.maxSceneBytes = static_cast<std::size_t>(toInt(flag, v, 1024, 1ll << 40));
  else if (name == "scene-cache") c.sceneCacheEntries = static_cast<std::size_t>(toInt(flag, v, 1, 1000));
  else if (name == "encoder-threads") c.encoderThreads = static_cast<int>(toInt(flag, v, 1, 64));
  else if (name == "http-threads") c.httpThreads = static_cast<int>(toInt(flag, v, 1, 1024));
  else if (name == "device-index") c.deviceIndex = static_cast<int>(toInt(flag, v, 0, 1024));
  else if (name == "device") c.deviceName = v;
  else if (name == "cuda-device") c.cudaDevice = static_cast<int>(toInt(flag, v, 0, 1024));
  else if (name == "gl-debug") c.glDebug = v != "false" && v != "0";
  else if (name == "max-json-depth") c.limits.maxJsonDepth = static_cast<std::size_t>(toInt(flag, v, 8, 1000));
  else if (name == "max-decode-bytes") c.maxDecodeBytes = static_cast<std::size_t>(toInt(flag, v, 1 << 20, 1ll << 40));
  else if (name == "body-memory-bytes") c.bodyMemoryBytes = static_cast<std::size_t>(toInt(flag, v, 1 << 20, 1ll << 40));
  else if (name == "decode-memory-bytes") c.decodeMemoryBytes = static_cast<std::size_t>(toInt(flag, v, 1 << 20, 1ll << 40));
  else if (name == "gpu-scenes") c.gpuScenes = static_cast<int>(toInt(flag, v, 1, 256));
  else if (name == "derived-cache-bytes") c.derivedCacheBytes = static_cast<std::size_t>(toInt(flag, v, 1 << 20, 1ll << 40));
  else if (name == "memory-target-bytes") c.memoryTargetBytes = static_cast<std::size_t>(toInt(flag, v, 1 << 20, 1ll << 40));
  else if (name == "memory-limit-bytes") c.memoryLimitBytes = static_cast<std::size_t>(toInt(flag, v, 0, 1ll << 40));
  else if (name == "speed-factor") {
    c.speedFactor = v == "auto" ? 0.0 : toDouble(flag, v);
    if (c.speedFactor > 64.0 || (c.speedFactor > 0 && c.speedFactor < 1.0 / 64.0))
      throw std::invalid_argument(flag + ": " + v + " is outside [1/64, 64]");
  }
  else if (name == "scene-cache-bytes") c.sceneCacheBytes = static_cast<std::size_t>(toInt(flag, v, 1 << 20, 1ll << 40));
  else if (name == "default-frame-budget-ms") c.limits.defaultFrameBudgetMs = v == "0" ? 0.0 : toDouble(flag, v);
  else if (name == "read-timeout") c.readTimeoutS = toDouble(flag, v);
  else if (name == "keep-alive-timeout") c.keepAliveTimeoutS = toDouble(flag, v);
  else if (name == "shutdown-grace") c.shutdownGraceS = v == "0" ? 0.0 : toDouble(flag, v);
  else if (name == "max-connections") c.maxConnections = static_cast<int>(toInt(flag, v, 4, 4096));
  else if (name == "daemon-id") {
    const bool ok = !v.empty() && v.size() <= 32 &&
                    std::all_of(v.begin(), v.end(), [](char ch) { return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9'); });
    if (!ok) throw std::invalid_argument(flag + ": expected 1 to 32 of [a-z0-9], got \"" + v + "\"");
    c.daemonId = v;
  }
  else if (name == "max-sessions") c.maxSessions = static_cast<int>(toInt(flag, v, 1, 1024));
  else if (name == "session-idle-s") c.sessionIdleS = toDouble(flag, v);
  else if (name == "reports-dir") c.reportsDir = v;
  else if (name == "ui") {
    if (v != "auto" && v != "off") throw std::invalid_argument(flag + ": expected auto or off, got \"" + v + "\"");
    c.ui = v == "auto";
  }
  else throw std::invalid_argument("unknown option " + flag);
}

}  // namespace

bool uiServed(const ServerConfig& c) {
  const bool loopback = c.host == "127.0.0.1" || c.host == "localhost" || c.host == "::1" || c.host.rfind("127.", 0) == 0;
  return c.ui && (loopback || !c.token.empty());
}

std::optional<ServerConfig> parseCommandLine(const std::vector<std::string>& args) {
  ServerConfig c;
  c.shutdownGraceS = 10;
  std::string tokenFile;
  // The config file first, so flags override it wherever they appear.
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--config") {
      if (i + 1 >= args.size()) throw std::invalid_argument("--config needs a file");
      std::ifstream in(args[i + 1]);
      if (!in) throw std::invalid_argument("--config: cannot read " + args[i + 1]);
      nlohmann::json j;
      try {
        j = nlohmann::json::parse(in);
      } catch (const std::exception& e) {
        throw std::invalid_argument("--config: " + args[i + 1] + ": " + e.what());
      }
      if (!j.is_object()) throw std::invalid_argument("--config: " + args[i + 1] + " must hold a JSON object");
      for (const auto& [k, v] : j.items()) {
        std::string name = k;
        for (char& ch : name)
          if (ch == '_') ch = '-';
        if (name == "token") throw std::invalid_argument("--config: put the token in a file and name it with token_file");
        apply(c, name, v.is_string() ? v.get<std::string>() : v.dump(), tokenFile);
      }
    }
  }
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::cout << usage();
      return std::nullopt;
    }
    if (a.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument \"" + a + "\"");
    std::string name = a.substr(2), value;
    if (auto eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    } else if (name == "gl-debug") {
      value = "true";
    } else {
      if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
      value = args[++i];
    }
    if (name == "token") throw std::invalid_argument("--token is not accepted: use --token-file");
    if (name == "config") continue;
    apply(c, name, value, tokenFile);
  }
  if (!tokenFile.empty()) c.token = readToken(tokenFile);
  return c;
}

}  // namespace radiant::server
