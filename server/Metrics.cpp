#include "server/Metrics.h"

#include <cstdio>

namespace radiant::server {

namespace {
std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}
std::string escapeLabel(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '\\' || c == '"') out += '\\';
    if (c == '\n') { out += "\\n"; continue; }
    out += c;
  }
  return out;
}
}  // namespace

void Histogram::observe(double seconds) {
  for (std::size_t i = 0; i < kBounds.size(); ++i)
    if (seconds <= kBounds[i]) ++counts_[i];
  ++count_;
  sum_ += seconds;
}

void Histogram::write(std::string& out, const std::string& name, const std::string& labels) const {
  const std::string sep = labels.empty() ? "" : ",";
  for (std::size_t i = 0; i < kBounds.size(); ++i)
    out += name + "_bucket{" + labels + sep + "le=\"" + num(kBounds[i]) + "\"} " + std::to_string(counts_[i]) + "\n";
  out += name + "_bucket{" + labels + sep + "le=\"+Inf\"} " + std::to_string(count_) + "\n";
  const std::string braces = labels.empty() ? "" : "{" + labels + "}";
  out += name + "_sum" + braces + " " + num(sum_) + "\n";
  out += name + "_count" + braces + " " + std::to_string(count_) + "\n";
}

void Metrics::countRequest(int status) {
  std::lock_guard lock(mutex_);
  ++requests_[status];
}
void Metrics::countRender(const std::string& result) {
  std::lock_guard lock(mutex_);
  ++renders_[result];
}
void Metrics::observeQueue(double s) {
  std::lock_guard lock(mutex_);
  queue_.observe(s);
}
void Metrics::observeRender(double s) {
  std::lock_guard lock(mutex_);
  render_.observe(s);
  renderSecondsTotal_ += s;
}
void Metrics::observeEncode(double s) {
  std::lock_guard lock(mutex_);
  encode_.observe(s);
}
void Metrics::observePass(const std::string& pass, const std::string& clock, double s) {
  std::lock_guard lock(mutex_);
  passes_[{pass, clock}].observe(s);
}

void Metrics::countImageDecode() {
  std::lock_guard lock(mutex_);
  ++imageDecodes_;
}

std::string Metrics::text(const std::map<std::string, std::pair<std::string, double>>& gauges) const {
  std::lock_guard lock(mutex_);
  std::string out;
  out += "# HELP radiant_http_requests_total HTTP requests answered, by status code.\n";
  out += "# TYPE radiant_http_requests_total counter\n";
  for (const auto& [status, n] : requests_)
    out += "radiant_http_requests_total{status=\"" + std::to_string(status) + "\"} " + std::to_string(n) + "\n";
  out += "# HELP radiant_renders_total Render jobs by outcome.\n# TYPE radiant_renders_total counter\n";
  for (const auto& [result, n] : renders_)
    out += "radiant_renders_total{result=\"" + escapeLabel(result) + "\"} " + std::to_string(n) + "\n";
  out += "# HELP radiant_image_decodes_total Uploaded images (environment maps, comparison images) decoded for a\n"
         "# request because no decoded copy was in memory.\n";
  out += "# TYPE radiant_image_decodes_total counter\nradiant_image_decodes_total " + std::to_string(imageDecodes_) + "\n";
  out += "# HELP radiant_render_seconds_total Wall-clock seconds the render thread spent rendering.\n";
  out += "# TYPE radiant_render_seconds_total counter\nradiant_render_seconds_total " + num(renderSecondsTotal_) + "\n";
  out += "# HELP radiant_queue_wait_seconds Time jobs waited in the queue.\n# TYPE radiant_queue_wait_seconds histogram\n";
  queue_.write(out, "radiant_queue_wait_seconds", "");
  out += "# HELP radiant_render_duration_seconds Wall-clock time of one render on the render thread.\n";
  out += "# TYPE radiant_render_duration_seconds histogram\n";
  render_.write(out, "radiant_render_duration_seconds", "");
  out += "# HELP radiant_encode_duration_seconds Time to encode all of one job's frames.\n";
  out += "# TYPE radiant_encode_duration_seconds histogram\n";
  encode_.write(out, "radiant_encode_duration_seconds", "");
  out += "# HELP radiant_pass_duration_seconds Duration of one pass, by pass and clock (gpu or cpu).\n";
  out += "# TYPE radiant_pass_duration_seconds histogram\n";
  for (const auto& [key, h] : passes_)
    h.write(out, "radiant_pass_duration_seconds",
            "pass=\"" + escapeLabel(key.first) + "\",clock=\"" + escapeLabel(key.second) + "\"");
  for (const auto& [name, g] : gauges) {
    out += "# HELP " + name + " " + g.first + "\n# TYPE " + name + " gauge\n";
    out += name + " " + num(g.second) + "\n";
  }
  return out;
}

}  // namespace radiant::server
