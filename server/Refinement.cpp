#include "server/Refinement.h"

#include <stdexcept>

#include "renderer/metrics/Metrics.h"

namespace radiant::server {

void BatchMean::add(const std::vector<Image>& aovs) {
  if (n_ == 0) {
    layout_.clear();
    sum_.clear();
    sumSq_.clear();
    for (const Image& a : aovs) {
      layout_.push_back(Image{a.aov, a.width, a.height, a.channels, {}});
      sum_.emplace_back(a.pixels.size(), 0.0);
      sumSq_.emplace_back(a.pixels.size(), 0.0);
    }
  }
  if (aovs.size() != layout_.size()) throw std::logic_error("BatchMean::add: a batch with other AOVs than the first");
  for (std::size_t i = 0; i < aovs.size(); ++i) {
    const Image& a = aovs[i];
    if (a.aov != layout_[i].aov || a.pixels.size() != sum_[i].size())
      throw std::logic_error("BatchMean::add: AOV " + a.aov + " differs from the first batch's");
    for (std::size_t k = 0; k < a.pixels.size(); ++k) {
      const double v = a.pixels[k];
      sum_[i][k] += v;
      sumSq_[i][k] += v * v;
    }
  }
  ++n_;
}

std::vector<Image> BatchMean::mean() const {
  std::vector<Image> out;
  for (std::size_t i = 0; i < layout_.size(); ++i) {
    Image m = Image::make(layout_[i].aov, layout_[i].width, layout_[i].height, layout_[i].channels);
    for (std::size_t k = 0; k < m.pixels.size(); ++k) m.pixels[k] = static_cast<float>(sum_[i][k] / n_);
    out.push_back(std::move(m));
  }
  return out;
}

double BatchMean::estimatedRmse(const std::string& aov) const {
  if (n_ < 2) return std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < layout_.size(); ++i) {
    if (layout_[i].aov != aov) continue;
    const double n = n_;
    double acc = 0.0;
    for (std::size_t k = 0; k < sum_[i].size(); ++k) {
      const double m = sum_[i][k] / n;
      const double var = std::max(0.0, (sumSq_[i][k] - n * m * m) / (n - 1.0));  // unbiased sample variance
      acc += var / n;                                                          // variance of the mean
    }
    return sum_[i].empty() ? 0.0 : std::sqrt(acc / double(sum_[i].size()));
  }
  return std::numeric_limits<double>::quiet_NaN();
}

nlohmann::json scoreMean(const nlohmann::json& batchMetrics, const Image& mean, const Image& reference,
                         float exposureEV, int batches) {
  const metrics::ImageMetrics e = metrics::compareImages(mean, reference, exposureEV);
  nlohmann::json m = batchMetrics;
  metrics::writeMetricsJson(e, m);
  m["batches"] = batches;
  return m;
}

}  // namespace radiant::server
