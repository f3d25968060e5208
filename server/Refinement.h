#pragma once
// Progressive refinement (render request "refine"): the mean of independent batches of a frame, and
// the estimated error of that mean. Each batch is a whole frame rendered with its own seed, so the
// batches are independent and identically distributed per pixel; the standard error of the mean of
// pixel channel c is s_c / sqrt(n), s_c^2 the unbiased sample variance over the n batches. The estimate
// reported is their RMS over pixels and colour channels, comparable to metrics.rmse (renderer/metrics):
//   estimated RMSE = sqrt( mean_c s_c^2 / n ).
// It estimates the variance part of the error only: a biased estimator (photon_gi's kernel blur) has a
// true error the estimate does not see.
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/Image.h"

namespace radiant::server {

class BatchMean {
public:
  // The first batch fixes the AOVs and their sizes; a later batch must have the same.
  void add(const std::vector<Image>& aovs);
  int batches() const { return n_; }
  std::vector<Image> mean() const;
  // NaN with fewer than 2 batches or when `aov` is not among the batches' AOVs.
  double estimatedRmse(const std::string& aov) const;

private:
  std::vector<Image> layout_;  // names and sizes (pixels unused)
  std::vector<std::vector<double>> sum_, sumSq_;
  int n_ = 0;
};

// A refining job with a compare block scores the batches' mean, not one batch: `batchMetrics` (a
// batch's stats.metrics: against, aov, reference mode, spp, ...) with its numbers (rmse, rel_mse, psnr,
// ssim, mean_abs, max_abs) recomputed for `mean` (the compared AOV's mean) against `reference` (the
// ground truth the batch was scored against, RenderOutput::compareReference), plus "batches".
nlohmann::json scoreMean(const nlohmann::json& batchMetrics, const Image& mean, const Image& reference,
                         float exposureEV, int batches);

// What GET /v1/renders/{id} shows of a refining job: the mean so far and its estimated error; with a
// compare block also the mean's true error against the ground truth (scoreMean; null otherwise).
// The estimate (issue 32): with a compare block on refine.aov, the mean's RMSE against the ground truth,
// which holds the bias a biased pass has (photon_gi's kernel blur) as well as the noise
// (kind "against_ground_truth"); otherwise the batches' standard error, the noise alone ("noise_only").
// target_rmse stops on it.
struct RefineSnapshot {
  std::vector<Image> mean;
  int batches = 0;
  std::uint64_t lastSeed = 0;  // the seed of the last batch in the mean
  double estimatedRmse = std::numeric_limits<double>::quiet_NaN();
  double noiseRmse = std::numeric_limits<double>::quiet_NaN();  // BatchMean::estimatedRmse, always
  const char* estimateKind = "noise_only";
  double elapsedMs = 0;
  nlohmann::json metrics;
  nlohmann::json batchStats;  // the last batch's stats (passes and their times, camera): a session's events
  std::shared_ptr<const Image> truth;  // with a compare block: the ground truth of the compared AOV
};

}  // namespace radiant::server
