#pragma once
// One function per subcommand; main.cpp dispatches. Each returns an exit code or throws
// UsageError / ServerError / UnreachableError (mapped to 2 / 3 / 4 by main).
// sweep, report and bench live in commands/Sweep.cpp on top of client/sweep/ and client/report/.
#include <string>
#include <vector>

#include "client/HttpClient.h"

namespace radiant::client {

struct GlobalOptions {
  std::string server;  // base URL
  std::string token;   // bearer token ("" = none)
};

int cmdRender(const GlobalOptions& g, const std::vector<std::string>& args);
int cmdInfo(const GlobalOptions& g, const std::vector<std::string>& args);
int cmdScenes(const GlobalOptions& g, const std::vector<std::string>& args);
int cmdSweep(const GlobalOptions& g, const std::vector<std::string>& args);
int cmdReport(const GlobalOptions& g, const std::vector<std::string>& args);
int cmdBench(const GlobalOptions& g, const std::vector<std::string>& args);
int cmdCompare(const GlobalOptions& g, const std::vector<std::string>& args);  // no server needed

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

}  // namespace radiant::client
