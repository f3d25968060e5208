#pragma once
// The radiant commands. Each command file defines its subcommand with CLI11 (its options, their
// help and checks: the one definition that --help, `radiant help` and `radiant completion` read) and
// sets `action` to the work it does once the command line is parsed. The work returns an exit code or
// throws UsageError / ServerError / UnreachableError (mapped to 2 / 3 / 4 by main).
// sweep, report and bench live in commands/Sweep.cpp on top of client/sweep/ and client/report/.
#include <functional>
#include <string>
#include <vector>

#include "client/HttpClient.h"

namespace CLI {
class App;
}

namespace radiant::client {

struct GlobalOptions {
  std::string server = "http://127.0.0.1:8080";  // base URL (--server, else $RADIANT_SERVER)
  std::string tokenFile;                         // --token-file, else $RADIANT_TOKEN_FILE
  std::string token;                             // bearer token read from tokenFile ("" = none)
  std::vector<std::string> commandArgs;          // the words after the command's name, as typed
};

// The work of the parsed command.
using Action = std::function<int()>;

void addRenderCommand(CLI::App& root, const GlobalOptions& g, Action& action);
void addInfoCommands(CLI::App& root, const GlobalOptions& g, Action& action);   // info, scenes
void addSweepCommands(CLI::App& root, const GlobalOptions& g, Action& action);  // sweep, report, bench
void addCompareCommand(CLI::App& root, const GlobalOptions& g, Action& action); // no server needed

// radiant bench --fidelity (commands/Fidelity.cpp): every model under `models` x every map under
// `environments`, the default frame scored against the reference path tracer (docs/PERFORMANCE.md).
struct FidelityOptions {
  std::string dir = "bench-out";                            // writes DIR/fidelity.md, .json, DIR/fidelity/
  std::string models = "../shared/testdata/gltf-samples";   // one folder per model (Khronos layout)
  std::string environments = "../shared/testdata/environments";
  std::vector<std::string> onlyModels, onlyEnvironments;    // empty = all (folder names, map file stems)
  int size = 128;
  // The reference: renders of `spp` samples per pixel at seeds 0, 1, ..., averaged, until the mean of
  // the even seeds scores at most `convergedDb` against the mean of the odd ones, or `maxSpp` samples
  // are reached (maxSpp == spp: one seed, no convergence check).
  int spp = 1024, maxSpp = 16384;
  double convergedDb = -23;
  double thetaDeg = 30, phiDeg = 75;                        // camera.orbit; radius: the automatic framing's
  bool quiet = false;
  std::vector<std::string> servers;                         // the first is used (default the global one)
};
int fidelityBench(const GlobalOptions& g, const FidelityOptions& o);

// radiant bench --equal-error (commands/EqualError.cpp): issue 32's equal-error speed-up of each
// scene's default frame over the reference path tracer.
struct EqualErrorOptions {
  std::string dir = "bench-out";  // writes DIR/equal_error.md (also printed) and DIR/equal_error.json
  std::vector<std::string> scenes{"cornell_box", "cornell_glossy", "cornell_mirror"};
  int size = 64, truthSpp = 4096;
  std::vector<int> ladder{64, 256, 1024};  // the reference's spp whose errors are fitted
  bool quiet = false;
  std::vector<std::string> servers;  // the first is used (default the global one)
};
int equalErrorBench(const GlobalOptions& g, const EqualErrorOptions& o);
// One rung of the reference's ladder: samples per pixel, MSE against the truth, pass time.
struct LadderPoint {
  double spp = 0, mse = 0, ms = 0;
};
// The reference's MSE(s) = a / s + b and time t(s) = t0 + msPerSpp s, least squares over the ladder (a
// fit with b < 0 takes b = 0 and a = s MSE of the largest s); the frame's own MSE = frameMse - b, which
// the reference reaches at spp = a / own in ms = t(spp); truthLimited (spp, ms unset) when own <= 0.
// Throws UsageError for fewer than two distinct spp or a non-positive one.
struct EqualErrorFit {
  double a = 0, b = 0, t0 = 0, msPerSpp = 0;
  double frameOwnMse = 0;
  bool truthLimited = false;
  double spp = 0, ms = 0;
};
EqualErrorFit fitEqualError(const std::vector<LadderPoint>& ladder, double frameMse);

// Helpers shared by commands.
std::string readFile(const std::string& path);            // throws UsageError
void writeFile(const std::string& path, const std::string& bytes);  // throws UsageError
// The bytes to upload for a scene file: a .gltf (or .glb) that references external files is packed
// with them into one GLB (renderer/scene/GltfPackage.h); throws UsageError naming the bad URI.
// `note` (may be null) receives a one-line description of what was packed.
std::string sceneFileBytes(const std::string& path, std::string* note = nullptr);
// Uploads `bytes` unless the server already has its digest; returns the digest.
std::string ensureSceneUploaded(const HttpClient& http, const std::string& bytes, const std::string& fileName,
                                bool verbose);
// Uploads an image (an environment map, Radiance HDR, or an EXR) to /v1/images unless the server has
// it; returns its digest.
std::string ensureImageUploaded(const HttpClient& http, const std::string& path, bool verbose);

}  // namespace radiant::client
