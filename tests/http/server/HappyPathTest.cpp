// Issue 3's happy path: a frame the daemon returns over HTTP is the frame the renderer library makes
// for the same request. Both run the same code on the same device, so a float EXR must match to the
// last bit of what the GPU computes; the bound allows llvmpipe's thread-count-dependent rasterisation
// order (different processes) but nothing more: 1e-5 relative.
#include <cmath>
#include <set>

#include <OpenImageIO/imageio.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "api/Sha256.h"
#include "api/Validate.h"
#include "renderer/Renderer.h"
#include "renderer/io/ImageIO.h"
#include "renderer/scene/BuiltinScenes.h"
#include "tests/support/DaemonProcess.h"

namespace radiant {
namespace {

using nlohmann::json;

TEST(RealDaemon, FramesMatchTheRendererLibraryPixelForPixel) {
  const auto dir = testing::scratch("happy");
  testing::Daemon d(RADIANTD_PATH, {"--port", "0"}, {}, dir / "stderr.log");
  ASSERT_GT(d.port(), 0) << d.firstLine();
  ASSERT_TRUE(d.waitReady(std::chrono::seconds(120))) << testing::slurp(dir / "stderr.log");
  auto c = d.client();

  const json body{{"scene", {{"builtin", "cornell_box"}}},
                  {"width", 64},
                  {"height", 48},
                  {"ambient", {0.2, 0.2, 0.25}},
                  {"passes", {{"direct", {{"pcf_radius", 2}}}}},
                  {"outputs", {{{"format", "exr"}, {"aovs", {"beauty", "direct"}}, {"half", false}}}}};
  auto r = c.Post("/v1/renders", body.dump(), "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json out = json::parse(r->body);
  const std::string exr = c.Get(out["frames"][0]["url"].get<std::string>().c_str())->body;
  io::writeFile((dir / "served.exr").string(), exr);
  const Image served = io::readImage((dir / "served.exr").string());

  // The same request through the library, parsed by the same validator.
  const api::RenderRequest request = api::parseRenderRequest(body);
  Renderer renderer;
  const RenderOutput local = renderer.render(loadBuiltinScene("cornell_box"), request);
  const Image& beauty = local.aovs.front();
  ASSERT_EQ(beauty.aov, "beauty");
  ASSERT_EQ(served.width, beauty.width);
  ASSERT_EQ(served.height, beauty.height);
  double maxRel = 0.0, sum = 0.0;
  for (int y = 0; y < beauty.height; ++y)
    for (int x = 0; x < beauty.width; ++x)
      for (int ch = 0; ch < 3; ++ch) {
        const float a = served.at(x, y)[ch], b = beauty.at(x, y)[ch];
        maxRel = std::max(maxRel, static_cast<double>(std::abs(a - b) / std::max(std::abs(b), 1e-3f)));
        sum += b;
      }
  EXPECT_LT(maxRel, 1e-5);
  EXPECT_GT(sum, 0.0);  // not two black images
  // The stats name the same passes in the same order.
  ASSERT_EQ(out["stats"]["passes"].size(), local.stats.passes.size());
  for (std::size_t i = 0; i < local.stats.passes.size(); ++i)
    EXPECT_EQ(out["stats"]["passes"][i]["name"], local.stats.passes[i].name);
}

TEST(RealDaemon, ComparesAgainstAnUploadedImage) {
  const auto dir = testing::scratch("compare-upload");
  testing::Daemon d(RADIANTD_PATH, {"--port", "0"}, {}, dir / "stderr.log");
  ASSERT_GT(d.port(), 0) << d.firstLine();
  ASSERT_TRUE(d.waitReady(std::chrono::seconds(120))) << testing::slurp(dir / "stderr.log");
  auto c = d.client();

  json body{{"scene", {{"builtin", "cornell_box"}}}, {"width", 32}, {"height", 32},
            {"outputs", {{{"format", "exr"}, {"aovs", {"beauty"}}, {"half", false}}}}};
  auto r = c.Post("/v1/renders", body.dump(), "application/json");
  ASSERT_EQ(r->status, 200) << r->body;
  const std::string exr = c.Get(json::parse(r->body)["frames"][0]["url"].get<std::string>().c_str())->body;
  // The first request of this daemon decoded the scene; later ones reuse the decoded scene.
  EXPECT_GT(json::parse(r->body)["stats"]["scene_load_ms"].get<double>(), 0.0);

  // Upload it as a comparison image: 201, then idempotent 200; HEAD finds it.
  auto up = c.Put("/v1/images", exr, "image/x-exr");
  ASSERT_EQ(up->status, 201) << up->body;
  const std::string digest = json::parse(up->body)["digest"];
  EXPECT_EQ(c.Put("/v1/images", exr, "image/x-exr")->status, 200);
  EXPECT_EQ(c.Head(("/v1/images/" + digest).c_str())->status, 200);
  // Bytes that are no image are refused and not stored.
  auto bad = c.Put("/v1/images", "not an image", "application/octet-stream");
  EXPECT_EQ(bad->status, 422);
  // An image with a NaN pixel is refused too, naming the pixel, and nothing is stored.
  Image nan = Image::make("beauty", 4, 4, 3);
  nan.at(2, 1)[0] = std::nanf("");
  const std::string nanExr = io::encodeExr({nan}, false);
  bad = c.Put("/v1/images", nanExr, "image/x-exr");
  EXPECT_EQ(bad->status, 422);
  EXPECT_NE(json::parse(bad->body)["detail"].get<std::string>().find("pixel (2, 1)"), std::string::npos) << bad->body;
  EXPECT_EQ(c.Head(("/v1/images/" + api::sceneDigest(nanExr)).c_str())->status, 404);

  // The same render compared against its own upload: zero error, and the EXR gains the layers.
  body["compare"] = {{"against", digest}, {"aov", "beauty"}};
  r = c.Post("/v1/renders", body.dump(), "application/json");
  ASSERT_EQ(r->status, 200) << r->body;
  const json out = json::parse(r->body);
  const json& m = out["stats"]["metrics"];
  EXPECT_EQ(m["against"], digest);
  EXPECT_EQ(out["stats"]["scene_load_ms"].get<double>(), 0.0);
  EXPECT_LT(m["rmse"].get<double>(), 1e-5);
  EXPECT_GT(m["ssim"].get<double>(), 0.99999);
  const std::string compared = c.Get(out["frames"][0]["url"].get<std::string>().c_str())->body;
  io::writeFile((dir / "compared.exr").string(), compared);
  auto in = OIIO::ImageInput::open((dir / "compared.exr").string());
  ASSERT_TRUE(in);
  std::set<std::string> channels(in->spec().channelnames.begin(), in->spec().channelnames.end());
  EXPECT_TRUE(channels.count("error.Y")) << "EXR lacks the error-map layer";
  EXPECT_TRUE(channels.count("reference.R"));

  // An unknown image digest: 404 naming the field, and the daemon keeps serving.
  body["compare"]["against"] = "sha256:" + std::string(64, 'a');
  r = c.Post("/v1/renders", body.dump(), "application/json");
  EXPECT_EQ(r->status, 404);
  EXPECT_EQ(json::parse(r->body)["pointer"], "/compare/against");
  body.erase("compare");
  EXPECT_EQ(c.Post("/v1/renders", body.dump(), "application/json")->status, 200);

  // The same upload serves as an environment map; an unknown one is 404 at /environment, and the
  // sky given twice (ambient and environment) is 422 there. It is decoded once: the compare above
  // decoded it, the environment renders find it decoded in memory (radiant_image_decodes_total).
  auto metric = [&](const std::string& name) {
    const std::string text = c.Get("/metrics")->body;
    const auto at = text.find("\n" + name + " ");
    return at == std::string::npos ? -1.0 : std::stod(text.substr(at + name.size() + 2));
  };
  const double decodes = metric("radiant_image_decodes_total");
  EXPECT_GE(decodes, 1.0);
  EXPECT_GT(metric("radiant_image_cache_bytes"), 0.0);
  body["environment"] = digest;
  r = c.Post("/v1/renders", body.dump(), "application/json");
  EXPECT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(c.Post("/v1/renders", body.dump(), "application/json")->status, 200);
  EXPECT_EQ(metric("radiant_image_decodes_total"), decodes);
  body["environment"] = "sha256:" + std::string(64, 'b');
  r = c.Post("/v1/renders", body.dump(), "application/json");
  EXPECT_EQ(r->status, 404);
  EXPECT_EQ(json::parse(r->body)["pointer"], "/environment");
  body["environment"] = digest;
  body["ambient"] = {1, 1, 1};
  r = c.Post("/v1/renders", body.dump(), "application/json");
  EXPECT_EQ(r->status, 422);
  EXPECT_EQ(json::parse(r->body)["pointer"], "/environment");
}

}  // namespace
}  // namespace radiant
