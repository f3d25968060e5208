#pragma once
// Thumbnails for reports: a sweep keeps, per point, its compare render's frame, per-pixel error and
// reference, box-filtered to at most kThumbnailPx a side, in one small half-float EXR beside the
// results file; the report embeds the Pareto points' as PNG data URIs (docs/SWEEPS.md).
#include <filesystem>
#include <string>
#include <string_view>

#include "renderer/Image.h"

namespace radiant::client::report {

inline constexpr int kThumbnailPx = 64;

// Mean over factor x factor blocks, factor = the smallest integer that brings both sides to at most
// maxSide (1: a copy). A partial block at the right or bottom edge is dropped.
Image downscale(const Image& image, int maxSide = kThumbnailPx);

struct Thumbnail {
  Image frame;      // the compared AOV (beauty, ao, ...), linear
  Image error;      // the daemon's per-pixel error (EXR layer error.Y)
  Image reference;  // what it was compared against (reference.R/G/B)
};

// From the bytes of a compare render's EXR frame: the AOV `aov` and its error and reference layers,
// downscaled. Throws std::runtime_error when a layer is missing.
Thumbnail thumbnailFromFrame(std::string_view exrBytes, const std::string& aov);
std::string encodeThumbnail(const Thumbnail& t);  // half-float EXR
Thumbnail readThumbnail(const std::filesystem::path& file, const std::string& aov);

std::string base64(std::string_view bytes);
std::string pngDataUri(const std::string& png);

}  // namespace radiant::client::report
