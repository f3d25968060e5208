#pragma once
// Parameter sweeps: the spec (base request, axes over dotted paths, zipped groups, repeats, warm-up,
// compare), its expansion into points, the JSON Lines results file, and the runner that spreads the
// points over one or several servers. docs/SWEEPS.md describes the formats.
#include <atomic>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace radiant::client::sweep {

using nlohmann::json;

// One factor of the Cartesian product: one axis (one path), or a zipped group whose paths move together.
struct Factor {
  std::vector<std::string> paths;
  std::vector<std::vector<json>> settings;  // settings[i][k]: the i-th setting of paths[k]
};

struct Spec {
  std::string name;
  json base;                    // the render request every point starts from
  std::vector<Factor> factors;  // axes in spec order, then the zipped groups
  int repeats = 3;              // timed renders per point
  int warmup = 1;               // untimed renders before them (the first one carries `compare`)
  json compare;                 // null, or the request's compare block
  std::string technique;        // "" = inferred from the request's passes
  std::string method;           // dotted path of the parameter that names the method; "" = inferred
  std::filesystem::path dir;    // relative paths in the spec are relative to this
};

struct Point {
  std::string id;                    // resume key: sha256 of the canonical request
  std::string sweep;                 // the spec's name
  json params = json::object();      // dotted path -> value, for every factor
  json factors = json::array();      // [[path, ...], ...] in spec order
  json request;                      // the full request; scene.digest when the spec names a file
  std::string sceneFile;             // "" or the file to upload (once per server) before rendering
  int repeats = 3, warmup = 1;
  json compare;                      // sent with the first render only
  std::string technique, method;     // hints from the spec
};

// A spec file holds one sweep object or {"sweeps": [sweep, ...]}. Throws UsageError naming the key.
std::vector<Spec> parseSpecFile(const std::filesystem::path& file);
std::vector<Spec> parseSpecs(const json& j, const std::filesystem::path& dir);
std::vector<Point> expand(const Spec& spec);

// Dotted paths: "passes.ambient_occlusion.samples", "ambient.0". Setting "scene.<kind>" replaces
// the whole scene object (a scene has exactly one key).
void setPath(json& root, const std::string& path, const json& value);
const json* findPath(const json& root, const std::string& path);

// median, min, max (and n) of a list of samples.
json summarize(std::vector<double> v);

// The results file: JSON Lines, one record per point, appended whole (one write, then fsync), so an
// interrupted run leaves complete lines only. Opening repairs a torn last line from a killed writer.
class ResultsFile {
public:
  explicit ResultsFile(const std::filesystem::path& path);
  const std::filesystem::path& path() const { return path_; }
  // Done = a record with this id exists (an error record counts unless retryFailed).
  bool done(const std::string& id, bool retryFailed) const;
  void append(const json& record);
  std::vector<json> all() const;  // every record, in file order
private:
  std::filesystem::path path_;
  mutable std::mutex mutex_;
  std::set<std::string> ok_, failed_;
  int fd_ = -1;
};

// Skips lines that are not JSON; a record's relative thumbnail.file comes back relative to the working
// directory (it is stored relative to the results file).
std::vector<json> readRecords(const std::filesystem::path& path);
// Last record per point id, in first-appearance order.
std::vector<json> latestRecords(const std::vector<json>& records);
void writeCsv(const std::vector<json>& records, const std::filesystem::path& out);
// Display label of a record's params: "samples=4 method=gtao" (last path component).
std::string paramLabel(const json& params, const std::set<std::string>& skip = {});

struct RunOptions {
  std::vector<std::string> servers;
  std::string token;
  int inflight = 1;        // requests in flight per server
  bool retryFailed = false;
  bool quiet = false;
  std::string command;     // recorded in every record
  // "" = none; else the folder (beside the results file) where each point's compare render leaves a
  // thumbnail EXR (frame, error, reference: client/report/Thumbnails.h), named in its record.
  std::filesystem::path thumbnails;
  const std::atomic<bool>* stop = nullptr;  // set by SIGINT/SIGTERM
};

struct RunSummary {
  int total = 0, skipped = 0, done = 0, failed = 0, remaining = 0;
  bool interrupted = false;
  std::map<std::string, int> perServer;     // points finished per server
  std::map<std::string, std::string> lost;  // server -> why it was dropped
};

RunSummary run(const std::vector<Point>& points, ResultsFile& results, const RunOptions& options);

}  // namespace radiant::client::sweep
