#pragma once
// radiantd settings: command-line flags, optionally on top of a JSON config file (--config) whose
// keys are the flag names with '_' for '-' ({"max_queue": 4, "cache_dir": "/var/cache/radiant"}).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "api/Validate.h"

namespace radiant::server {

struct ServerConfig {
  std::string host = "127.0.0.1";
  int port = 8080;                     // 0 = ephemeral
  std::string cacheDir;                // "" = scenes in memory only
  std::string assetRoot;               // scene.asset paths resolve here ("" = scene.asset refused)
  std::string token;                   // bearer token ("" = no auth), read from token_file
  std::size_t maxBodyBytes = 64u << 20;
  // Bytes the request bodies being read or handled may hold together, at least maxBodyBytes
  // (HttpServer.cpp readBody): bounds what many connections can make the daemon hold.
  std::size_t bodyMemoryBytes = 256u << 20;
  api::RequestLimits limits{.defaultFrameBudgetMs = 10000};  // --default-frame-budget-ms: on in the daemon
  int maxQueue = 16;                   // jobs waiting (the running one not counted)
  double requestTimeoutS = 300;        // submit -> frames encoded; a timed-out job frees its slot
  double frameTtlS = 600;              // frames and finished async jobs are kept this long
  std::size_t maxFrameBytes = 512u << 20;
  std::size_t maxSceneBytes = 1024u << 20;  // scene store (uploads), LRU evicted
  std::size_t sceneCacheEntries = 8;   // decoded scenes kept in memory
  int encoderThreads = 2;
  int httpThreads = 0;                 // 0 = maxQueue + 8
  std::optional<int> deviceIndex;      // EGL device index (radiantd only)
  std::optional<int> cudaDevice;       // the EGL device of this CUDA device id (EGL_NV_device_cuda)
  std::string deviceName;              // substring of GL_RENDERER/GL_VENDOR
  bool glDebug = false;
  // Hardening (docs/API.md, "Limits"): every budget a hostile input could exhaust is a flag.
  std::size_t maxDecodeBytes = std::size_t(512) << 20;     // decoded images + expanded accessors of one scene or image
  // Bytes all decodes in flight may reserve together, at least maxDecodeBytes (HttpServer.cpp DecodeMemory).
  std::size_t decodeMemoryBytes = std::size_t(1024) << 20;
  std::size_t sceneCacheBytes = std::size_t(1024) << 20;   // decoded scenes kept in memory, in bytes
  double speedFactor = 0.0;            // time budgets' speed factor: 0 measures it, > 0 pins it (--speed-factor)
  int gpuScenes = 4;                   // scenes kept uploaded to the GPU (with their derived data), LRU
  std::size_t derivedCacheBytes = std::size_t(1024) << 20;  // photon sets and splat grids kept, LRU (--derived-cache-bytes)
  // The resident set the renderer's memory accountant keeps the daemon under (--memory-target-bytes):
  // over it, what the frame does not use (other scenes' GPU copies, maps, derived data) is released.
  std::size_t memoryTargetBytes = std::size_t(1280) << 20;
  // Beyond it a frame's large allocation that the release cannot make room for is a 503 memory-busy
  // (--memory-limit-bytes; 0 = none).
  std::size_t memoryLimitBytes = 1500000000;
  double readTimeoutS = 30;            // receiving one request (headers and body), in total
  double keepAliveTimeoutS = 2;        // an idle keep-alive connection is closed after this
  // After SIGTERM, frame and job GETs are served this long (ending early once every frame was
  // fetched). 0 here, for servers embedded in tests; radiantd's command line defaults it to 10.
  double shutdownGraceS = 0;
  int maxConnections = 256;            // connections served at once (one HTTP worker thread each)
  // Behind a proxy (docs/DEPLOYMENT.md): this daemon's name in the fleet, [a-z0-9]{1,32}. Render ids
  // become "<id>-r-<hex>", so the job and frame URLs it hands out route back to it; every response
  // carries X-Radiant-Daemon. "" = a lone daemon, ids "r-<hex>".
  std::string daemonId;
  // Progressive sessions (server/Sessions.h): how many at once, and how long one without an open
  // event stream lives untouched.
  int maxSessions = 8;
  double sessionIdleS = 60;
  // The viewer page (/ui/): false = off. On, it is served when the daemon is bound to a loopback
  // address or requires a token (uiServed()).
  bool ui = true;
  // Sweep reports (`radiant report -o DIR/NAME`) served read-only under /reports/ ("" = none).
  std::string reportsDir;
};

// Whether /ui/ is served: on, and either bound to loopback or behind a token.
bool uiServed(const ServerConfig& c);

// Parses argv (argv[0] skipped). Throws std::invalid_argument with a usage message on bad flags.
// Reads --config and --token-file. Returns nullopt for --help (usage printed to stdout).
std::optional<ServerConfig> parseCommandLine(const std::vector<std::string>& args);
std::string usage();

}  // namespace radiant::server
