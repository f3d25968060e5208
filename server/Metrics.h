#pragma once
// Prometheus text exposition (format 0.0.4) of the daemon's counters, gauges and histograms.
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace radiant::server {

class Histogram {
public:
  // Seconds; spans a 1 ms pass to a minute-long reference render.
  static constexpr std::array<double, 15> kBounds{0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25,
                                                  0.5,   1.0,    2.5,   5.0,  10.0,  30.0, 60.0};
  void observe(double seconds);
  void write(std::string& out, const std::string& name, const std::string& labels) const;

private:
  std::array<std::uint64_t, kBounds.size()> counts_{};
  std::uint64_t count_ = 0;
  double sum_ = 0;
};

class Metrics {
public:
  void countRequest(int status);
  void countRender(const std::string& result);  // done | failed | canceled | timeout | rejected
  void observeQueue(double seconds);
  void observeRender(double seconds);
  void observeEncode(double seconds);
  void observePass(const std::string& pass, const std::string& clock, double seconds);
  void countImageDecode();  // an uploaded image decoded for a request (not found decoded in memory)
  // Gauges are sampled when the text is written.
  std::string text(const std::map<std::string, std::pair<std::string, double>>& gauges) const;

private:
  mutable std::mutex mutex_;
  std::map<int, std::uint64_t> requests_;
  std::map<std::string, std::uint64_t> renders_;
  Histogram queue_, render_, encode_;
  double renderSecondsTotal_ = 0;
  std::uint64_t imageDecodes_ = 0;
  std::map<std::pair<std::string, std::string>, Histogram> passes_;
};

}  // namespace radiant::server
