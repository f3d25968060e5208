// The JSON Lines results file and its CSV view.
#include <fcntl.h>
#include <unistd.h>

#include <fstream>
#include <iostream>
#include <sstream>

#include "client/Commands.h"
#include "client/sweep/Sweep.h"

namespace radiant::client::sweep {

namespace fs = std::filesystem;

ResultsFile::ResultsFile(const fs::path& path) : path_(path) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  std::string text;
  if (fs::exists(path)) text = readFile(path.string());
  // A writer killed mid-line leaves a torn last line: cut it so the next record starts a line.
  const auto lastNewline = text.rfind('\n');
  const std::size_t keep = lastNewline == std::string::npos ? 0 : lastNewline + 1;
  if (keep < text.size()) {
    std::cerr << "radiant: " << path.string() << ": dropping an incomplete last line (" << text.size() - keep
              << " bytes) left by an interrupted run\n";
    fs::resize_file(path, keep);
    text.resize(keep);
  }
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const json r = json::parse(line, nullptr, false);
    if (!r.is_object() || !r.contains("point_id")) continue;
    (r.contains("error") ? failed_ : ok_).insert(r["point_id"].get<std::string>());
  }
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw UsageError("cannot open " + path.string() + " for appending");
}

bool ResultsFile::done(const std::string& id, bool retryFailed) const {
  std::lock_guard lock(mutex_);
  return ok_.count(id) || (!retryFailed && failed_.count(id));
}

void ResultsFile::append(const json& record) {
  const std::string line = record.dump() + "\n";
  std::lock_guard lock(mutex_);
  std::size_t off = 0;
  while (off < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + off, line.size() - off);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("cannot append to " + path_.string());
    }
    off += static_cast<std::size_t>(n);
  }
  ::fsync(fd_);
  (record.contains("error") ? failed_ : ok_).insert(record.value("point_id", ""));
}

std::vector<json> ResultsFile::all() const {
  std::lock_guard lock(mutex_);
  return readRecords(path_);
}

std::vector<json> readRecords(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw UsageError("cannot read " + path.string());
  std::vector<json> out;
  std::string line;
  while (std::getline(in, line)) {
    json r = json::parse(line, nullptr, false);
    if (!r.is_object() || !r.contains("point_id")) continue;
    // A thumbnail is named relative to its results file; readers get a path they can open.
    if (r.contains("thumbnail") && r["thumbnail"].is_object() && r["thumbnail"].contains("file") &&
        r["thumbnail"]["file"].is_string() && fs::path(r["thumbnail"]["file"].get<std::string>()).is_relative())
      r["thumbnail"]["file"] = (path.parent_path() / r["thumbnail"]["file"].get<std::string>()).string();
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<json> latestRecords(const std::vector<json>& records) {
  std::vector<json> out;
  std::map<std::string, std::size_t> index;
  for (const auto& r : records) {
    const std::string id = r.value("point_id", "");
    auto it = index.find(id);
    if (it == index.end()) {
      index[id] = out.size();
      out.push_back(r);
    } else {
      out[it->second] = r;
    }
  }
  return out;
}

namespace {

std::string csvCell(const json& v) {
  if (v.is_null()) return "";
  std::string s = v.is_string() ? v.get<std::string>() : v.dump();
  if (s.find_first_of(",\"\n") != std::string::npos) {
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  }
  return s;
}

}  // namespace

void writeCsv(const std::vector<json>& all, const fs::path& out) {
  const auto records = latestRecords(all);
  std::vector<std::string> params, passes, metrics;
  auto addUnique = [](std::vector<std::string>& v, const std::string& s) {
    if (std::find(v.begin(), v.end(), s) == v.end()) v.push_back(s);
  };
  for (const auto& r : records) {
    for (const auto& f : r.value("factors", json::array()))
      for (const auto& p : f) addUnique(params, p.get<std::string>());
    for (const auto& p : r.value("passes", json::array())) addUnique(passes, p.value("name", ""));
    if (r.contains("metrics") && r["metrics"].is_object())
      for (const auto& [k, v] : r["metrics"].items())
        if (v.is_number() && !v.is_boolean() && k != "spp" && k != "max_bounces" && k != "rel_mse_epsilon")
          addUnique(metrics, k);
  }
  std::ostringstream csv;
  csv << "point_id,sweep,technique,method,status";
  for (const auto& p : params) csv << "," << csvCell(p);
  for (const char* s : {"frame_gpu_ms", "frame_cpu_ms", "frame_prepare_ms", "latency_ms", "render_ms"})
    csv << "," << s << "_median," << s << "_min," << s << "_max";
  csv << ",queue_ms_median,encode_ms_median";
  for (const auto& p : passes) csv << ",gpu_ms." << p << ",cpu_ms." << p << ",prepare_ms." << p;
  for (const auto& m : metrics) csv << "," << m;
  csv << ",repeats,device,server,finished,error\n";
  for (const auto& r : records) {
    const bool ok = !r.contains("error");
    csv << csvCell(r["point_id"]) << "," << csvCell(r.value("sweep", json())) << ","
        << csvCell(r.value("technique", json())) << "," << csvCell(r.value("method", json())) << ","
        << (ok ? "ok" : "error");
    for (const auto& p : params) csv << "," << csvCell(r["params"].value(p, json()));
    for (const char* s : {"frame_gpu_ms", "frame_cpu_ms", "frame_prepare_ms", "latency_ms", "render_ms"}) {
      const json st = r.value(s, json());
      for (const char* k : {"median", "min", "max"}) csv << "," << (st.is_object() ? csvCell(st[k]) : "");
    }
    for (const char* s : {"queue_ms", "encode_ms"}) {
      const json st = r.value(s, json());
      csv << "," << (st.is_object() ? csvCell(st["median"]) : "");
    }
    for (const auto& name : passes) {
      json g, c, pr;
      for (const auto& p : r.value("passes", json::array()))
        if (p.value("name", "") == name) {
          g = p["gpu_ms"]["median"];
          c = p["cpu_ms"]["median"];
          if (p.contains("prepare_ms")) pr = p["prepare_ms"]["median"];  // records older than prepare_ms have none
        }
      csv << "," << csvCell(g) << "," << csvCell(c) << "," << csvCell(pr);
    }
    for (const auto& m : metrics)
      csv << "," << (r.contains("metrics") && r["metrics"].is_object() ? csvCell(r["metrics"].value(m, json())) : "");
    const json dev = r.value("device", json());
    csv << "," << csvCell(r.value("repeats", json())) << ","
        << csvCell(dev.is_object() ? json(dev.value("renderer", "")) : json()) << "," << csvCell(r.value("server", json()))
        << "," << csvCell(r.value("finished", json())) << ","
        << csvCell(ok ? json() : json(r["error"].value("detail", r["error"].dump()))) << "\n";
  }
  writeFile(out.string(), csv.str());
}

}  // namespace radiant::client::sweep
