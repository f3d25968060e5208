#include "client/report/Thumbnails.h"

#include <algorithm>

#include "api/Base64.h"
#include "renderer/io/ImageIO.h"

namespace radiant::client::report {

Image downscale(const Image& image, int maxSide) {
  const int side = std::max(image.width, image.height);
  const int f = std::max(1, (side + maxSide - 1) / maxSide);
  Image out = Image::make(image.aov, std::max(1, image.width / f), std::max(1, image.height / f), image.channels);
  const int fx = std::min(f, image.width), fy = std::min(f, image.height);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < image.channels; ++c) {
        double sum = 0;
        for (int j = 0; j < fy; ++j)
          for (int i = 0; i < fx; ++i) sum += image.at(x * fx + i, y * fy + j)[c];
        out.at(x, y)[c] = static_cast<float>(sum / (fx * fy));
      }
  return out;
}

Thumbnail thumbnailFromFrame(std::string_view exrBytes, const std::string& aov) {
  Thumbnail t{downscale(io::decodeImage(exrBytes, aov)), downscale(io::decodeImage(exrBytes, "error")),
              downscale(io::decodeImage(exrBytes, "reference"))};
  t.frame.aov = aov, t.error.aov = "error", t.reference.aov = "reference";
  return t;
}

std::string encodeThumbnail(const Thumbnail& t) { return io::encodeExr({t.frame, t.error, t.reference}, true); }

Thumbnail readThumbnail(const std::filesystem::path& file, const std::string& aov) {
  Thumbnail t{io::readImage(file.string(), aov), io::readImage(file.string(), "error"),
              io::readImage(file.string(), "reference")};
  t.frame.aov = aov, t.error.aov = "error", t.reference.aov = "reference";
  return t;
}

std::string pngDataUri(const std::string& png) { return "data:image/png;base64," + api::base64Encode(png); }

}  // namespace radiant::client::report
