// Real glTF content, as a new user has it, through the real `radiant` client and radiantd:
// - every public sample in RADIANT_GLTF_SAMPLES_DIR in every form it ships (glTF with separate files,
//   glTF-Binary, glTF-Embedded, ...) renders, and the forms give the same image;
// - the same files served by radiantd --asset-root (scene.asset) give that image too;
// - the client refuses URIs outside the .gltf's folder before anything is sent;
// - scenes without lights are lit by the default studio environment (stats.lighting = "default").
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <OpenImageIO/imageio.h>

#include "renderer/io/ImageIO.h"
#include "tests/support/DaemonProcess.h"

namespace radiant {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

using testing::ProcessRun;

ProcessRun client(const std::string& server, const std::string& args, const fs::path& dir) {
  return testing::runClient(RADIANT_CLIENT_PATH, server, args, dir);
}

// Each shipped form of each sample: model name -> (form folder -> the .gltf/.glb in it).
std::map<std::string, std::map<std::string, fs::path>> sampleForms(const fs::path& root) {
  std::map<std::string, std::map<std::string, fs::path>> out;
  if (!fs::is_directory(root)) return out;
  for (const auto& model : fs::directory_iterator(root)) {
    if (!model.is_directory()) continue;
    for (const auto& form : fs::directory_iterator(model.path())) {
      if (!form.is_directory()) continue;
      for (const auto& f : fs::directory_iterator(form.path())) {
        const std::string ext = f.path().extension().string();
        if (ext == ".gltf" || ext == ".glb") out[model.path().filename().string()][form.path().filename().string()] = f.path();
      }
    }
  }
  return out;
}

struct Frame {
  Image beauty, depth;
  json stats;
};

// One AOV of a multi-layer EXR: channels "<aov>.*", or the unprefixed R, G, B for beauty.
Image readAov(const fs::path& exr, const std::string& aov) {
  auto in = OIIO::ImageInput::open(exr.string());
  if (!in) throw std::runtime_error("cannot open " + exr.string());
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<float> all(std::size_t(spec.width) * spec.height * spec.nchannels);
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data());
  std::vector<int> chans;
  for (int c = 0; c < spec.nchannels; ++c) {
    const std::string& n = spec.channelnames[c];
    if (aov == "beauty" ? (n == "R" || n == "G" || n == "B") : n.rfind(aov + ".", 0) == 0) chans.push_back(c);
  }
  if (chans.empty()) throw std::runtime_error(exr.string() + " has no AOV " + aov);
  Image img = Image::make(aov, spec.width, spec.height, int(chans.size()));
  for (std::size_t p = 0; p < std::size_t(spec.width) * spec.height; ++p)
    for (std::size_t k = 0; k < chans.size(); ++k) img.pixels[p * chans.size() + k] = all[p * spec.nchannels + chans[k]];
  return img;
}

Frame readFrame(const fs::path& exr, const fs::path& statsFile) {
  Frame f;
  f.beauty = readAov(exr, "beauty");
  f.depth = readAov(exr, "depth");
  if (!statsFile.empty()) f.stats = json::parse(testing::slurp(statsFile))["stats"];
  return f;
}

// Largest |a - b| / max(1, |b|) over the beauty channels.
double maxRelDiff(const Image& a, const Image& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.pixels.size(), b.pixels.size()); ++i)
    worst = std::max(worst, double(std::abs(a.pixels[i] - b.pixels[i])) / std::max(1.0, double(std::abs(b.pixels[i]))));
  return worst;
}

// Mean beauty radiance over the pixels that show the model (depth > 0), and their count.
std::pair<double, int> objectMean(const Frame& f) {
  double sum = 0.0;
  int n = 0;
  for (int y = 0; y < f.beauty.height; ++y)
    for (int x = 0; x < f.beauty.width; ++x)
      if (f.depth.at(x, y)[0] > 0.f) {
        const float* p = f.beauty.at(x, y);
        sum += (p[0] + p[1] + p[2]) / 3.0;
        ++n;
      }
  return {n ? sum / n : 0.0, n};
}

class Content : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(testing::scratch("content"));
    daemon_ = new testing::Daemon(RADIANTD_PATH, {"--port", "0", "--asset-root", RADIANT_GLTF_SAMPLES_DIR}, {},
                                  *dir_ / "stderr.log");
    ready_ = daemon_->port() > 0 && daemon_->waitReady(std::chrono::seconds(120));
  }
  static void TearDownTestSuite() {
    delete daemon_;
    delete dir_;
  }
  void SetUp() override { ASSERT_TRUE(ready_) << testing::slurp(*dir_ / "stderr.log"); }
  static inline fs::path* dir_ = nullptr;
  static inline testing::Daemon* daemon_ = nullptr;
  static inline bool ready_ = false;
};

// The forms of one model hold the same data, so the daemon renders the same pixels from each: the
// bound 1e-4 (relative above 1) allows only float noise; the real risk it guards is a lost texture,
// buffer or node, which changes pixels by 1e-2 and more.
constexpr double kSameImage = 1e-4;

TEST_F(Content, EverySampleRendersAlikeInEveryShippedFormAndAsAnAsset) {
  const auto samples = sampleForms(RADIANT_GLTF_SAMPLES_DIR);
  if (samples.empty()) GTEST_SKIP() << "no glTF samples in " << RADIANT_GLTF_SAMPLES_DIR;
  // photon_gi off (--no-pass, "passes": {"photon_gi": false}): the bounds below are the raster's default
  // lighting and unlit colours; photon_gi's sky photons would also light the unlit G-buffer stand-in.
  for (const auto& [model, forms] : samples) {
    SCOPED_TRACE(model);
    std::optional<Frame> first;
    std::string firstForm;
    for (const auto& [form, file] : forms) {
      SCOPED_TRACE(form);
      const fs::path exr = *dir_ / (model + "-" + form + ".exr"), stats = *dir_ / (model + "-" + form + ".json");
      const ProcessRun r = client(daemon_->url(), "render '" + file.string() + "' -o '" + exr.string() +
                                                      "' --size 64x64 --float --aov beauty --aov depth --no-pass photon_gi --stats '" +
                                                      stats.string() + "'",
                                  *dir_);
      ASSERT_EQ(r.code, 0) << r.err;
      const Frame f = readFrame(exr, stats);
      const auto [mean, pixels] = objectMean(f);
      std::cout << model << "/" << form << ": object mean " << mean << " over " << pixels << " pixels, lighting "
                << f.stats.value("lighting", "") << "\n";
      EXPECT_GT(pixels, 64 * 64 / 30) << "the automatic camera frames the model: it covers at least 3% of the image";
      // None of the samples has lights: the default studio environment lights them, and the model is
      // not black. Bound: the raster lights non-metals by albedo * (map mean 0.466) * AO; these models'
      // mean diffuse albedo is above 0.16 over at least half their pixels and AO is above 0.5, so the
      // mean is above 0.16 * 0.466 * 0.5 / 2 = 0.0186 (measured: 0.13 to 0.41). Black would be 0.
      // DamagedHelmet's visor is emissive: the studio environment lights it all the same (issue 29, item 7).
      EXPECT_EQ(f.stats.value("lighting", ""), model == "DamagedHelmet" ? "scene+default" : "default");
      EXPECT_NE(r.err.find("note: lit by the default studio environment: the scene has no "), std::string::npos)
          << "the client's one-line note: " << r.err;
      EXPECT_GT(mean, 0.018);
      if (model == "UnlitTest") {
        // KHR_materials_unlit: the two materials show their base colours (1, 0.2176, 0) and
        // (0, 0.2176, 1), both of channel mean 0.40588, whatever lights the scene.
        EXPECT_NEAR(mean, (1.0 + 0.217637640824031) / 3.0, 0.004);
      }
      if (!first) {
        first = f;
        firstForm = form;
      } else {
        EXPECT_LE(maxRelDiff(f.beauty, first->beauty), kSameImage) << form << " vs " << firstForm;
      }
      // A file with separate files was packed by the client: its note says so.
      if (file.extension() == ".gltf" && fs::exists(file.parent_path() / (file.stem().string() + ".bin"))) {
        EXPECT_NE(r.err.find("into one GLB"), std::string::npos) << r.err;
      }

      // The same file named by path under --asset-root: packed by the daemon, same pixels.
      const json body{{"scene", {{"asset", fs::relative(file, RADIANT_GLTF_SAMPLES_DIR).generic_string()}}},
                      {"width", 64}, {"height", 64}, {"passes", {{"photon_gi", false}}},
                      {"outputs", {{{"format", "exr"}, {"aovs", {"beauty", "depth"}}, {"half", false}}}}};
      auto c = daemon_->client();
      auto res = c.Post("/v1/renders", body.dump(), "application/json");
      ASSERT_TRUE(res);
      ASSERT_EQ(res->status, 200) << res->body;
      const json out = json::parse(res->body);
      const fs::path served = *dir_ / (model + "-" + form + "-asset.exr");
      io::writeFile(served.string(), c.Get(out["frames"][0]["url"].get<std::string>().c_str())->body);
      EXPECT_LE(maxRelDiff(readFrame(served, {}).beauty, f.beauty), kSameImage) << "scene.asset vs upload";
    }
  }
}

// Issue 12's goal on the sample that misses it by the least, through the client and --asset-root:
// Fox at 128x128 against the reference at 256 spp. With "supersampling": 2 (the raster's pixel
// integral, as the reference takes it) it scores 30.75 and 30.80 dB in two measurements
// (docs/PERFORMANCE.md); the bound 30.3 leaves 0.5 dB for llvmpipe builds and the reference's own
// noise at 256 spp. At one sample per pixel it scored 28.95 dB: the gain (1.85 dB) is asserted to be
// above 1 dB. Energy: supersampling box-filters radiance, so the frame's mean light stays that of
// k = 1; measured within 0.4% (Fox) and 0.9% (BoxTextured, red) per channel, bound 1.5%. Rendered after
// the other samples in the same daemon: a photon set left over from another scene (the photon_gi
// splat buffers) would show here as an unlit Fox (21.7 dB before that fix).
TEST_F(Content, SupersamplingTwoTakesFoxAbove30DbAgainstTheReferenceAndKeepsItsLight) {
  const fs::path fox = fs::path(RADIANT_GLTF_SAMPLES_DIR) / "Fox" / "glTF" / "Fox.gltf";
  if (!fs::exists(fox)) GTEST_SKIP() << "no Fox sample";
  auto run = [&](int k) {
    const std::string tag = "fox-k" + std::to_string(k);
    const fs::path exr = *dir_ / (tag + ".exr"), stats = *dir_ / (tag + ".json"), req = *dir_ / (tag + "-request.json");
    io::writeFile(req.string(), json{{"supersampling", k}}.dump());
    const ProcessRun r = client(daemon_->url(), "render --asset Fox/glTF/Fox.gltf --size 128x128 --compare 256 --request '" +
                                                    req.string() + "' -o '" + exr.string() + "' --float --aov beauty --aov depth --stats '" +
                                                    stats.string() + "'",
                                *dir_);
    EXPECT_EQ(r.code, 0) << r.err;
    return readFrame(exr, stats);
  };
  const Frame one = run(1), two = run(2);
  EXPECT_EQ(one.stats["supersampling"], 1);
  EXPECT_EQ(two.stats["supersampling"], 2);
  const double psnr1 = one.stats["metrics"]["psnr"].get<double>(), psnr2 = two.stats["metrics"]["psnr"].get<double>();
  std::cout << "Fox 128x128 against the reference at 256 spp: " << psnr1 << " dB at k = 1, " << psnr2 << " dB at k = 2\n";
  EXPECT_GE(psnr2, 30.3);
  EXPECT_GT(psnr2 - psnr1, 1.0);
  for (int c = 0; c < 3; ++c) {
    double m1 = 0.0, m2 = 0.0;
    for (std::size_t p = 0; p < std::size_t(128) * 128; ++p) {
      m1 += one.beauty.pixels[p * 3 + c];
      m2 += two.beauty.pixels[p * 3 + c];
    }
    EXPECT_NEAR(m2 / m1, 1.0, 0.015) << "channel " << c;
  }
}

// Issue 12's goal as stated, "with the default settings and no flags", on its worst sample: Fox through
// the client with nothing but the size and the compare. The default supersampling at 128 x 128 is 4
// (api::defaultSupersampling, 2026-12-04; at 2 it measured 30.80 dB twice, docs/PERFORMANCE.md, against
// 28.93 at one sample per pixel); the bound 30.3 leaves 0.5 dB for llvmpipe builds and the reference's
// noise at 256 spp, as above.
TEST_F(Content, FoxAtTheDefaultSettingsScoresAbove30DbAgainstTheReference) {
  const fs::path fox = fs::path(RADIANT_GLTF_SAMPLES_DIR) / "Fox" / "glTF" / "Fox.gltf";
  if (!fs::exists(fox)) GTEST_SKIP() << "no Fox sample";
  const fs::path exr = *dir_ / "fox-default.exr", stats = *dir_ / "fox-default.json";
  const ProcessRun r = client(daemon_->url(), "render --asset Fox/glTF/Fox.gltf --size 128x128 --compare 256 -o '" +
                                                  exr.string() + "' --float --aov beauty --aov depth --stats '" + stats.string() + "'",
                              *dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const Frame f = readFrame(exr, stats);
  EXPECT_EQ(f.stats["supersampling"], 4);
  const double psnr = f.stats["metrics"]["psnr"].get<double>();
  std::cout << "Fox 128x128 at the default settings against the reference at 256 spp: " << psnr << " dB\n";
  EXPECT_GE(psnr, 30.3);
}

TEST_F(Content, ClientRefusesUrisOutsideTheGltfFolderBeforeUploading) {
  const fs::path d = *dir_ / "escape" / "model";
  fs::create_directories(d);
  const std::string bin(36, '\0');
  std::ofstream(*dir_ / "escape" / "secret.bin", std::ios::binary) << bin;
  for (const auto& [uri, reason] : std::vector<std::pair<std::string, std::string>>{
           {"../secret.bin", "\"..\" is not allowed"},
           {"/etc/hostname", "absolute paths are not allowed"},
           {"https://example.com/a.bin", "scheme \"https:\""}}) {
    const json doc{{"asset", {{"version", "2.0"}}}, {"buffers", {{{"byteLength", 36}, {"uri", uri}}}}};
    std::ofstream(d / "m.gltf") << doc.dump();
    const ProcessRun r = client(daemon_->url(), "render '" + (d / "m.gltf").string() + "' -o x.png", *dir_);
    EXPECT_EQ(r.code, 2) << uri << ": a usage error, nothing sent";
    EXPECT_NE(r.err.find("/buffers/0/uri"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(reason), std::string::npos) << r.err;
  }
  // scene.asset is held to the same rules on the daemon.
  auto c = daemon_->client();
  const json body{{"scene", {{"asset", "../escape/model/m.gltf"}}}};
  auto res = c.Post("/v1/renders", body.dump(), "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 422) << res->body;
  EXPECT_EQ(json::parse(res->body).value("pointer", ""), "/scene/asset");
}

// The client's lighting and camera options each reach the request and show in the stats.
TEST_F(Content, ClientLightingCameraAndRequestOptions) {
  const fs::path box = fs::path(RADIANT_GLTF_SAMPLES_DIR) / "BoxTextured" / "glTF" / "BoxTextured.gltf";
  if (!fs::exists(box)) GTEST_SKIP() << "no BoxTextured sample";
  auto run = [&](const std::string& tag, const std::string& options) {
    const fs::path exr = *dir_ / (tag + ".exr"), stats = *dir_ / (tag + ".json");
    const ProcessRun r = client(daemon_->url(), "render '" + box.string() + "' -o '" + exr.string() +
                                                    "' --float --aov beauty --aov depth --stats '" + stats.string() +
                                                    "' " + options,
                                *dir_);
    EXPECT_EQ(r.code, 0) << tag << ": " << r.err;
    return std::pair{readFrame(exr, stats), json::parse(testing::slurp(stats))};
  };
  // A uniform environment of radiance 2 (an EXR the client uploads by digest): the background is 2.
  Image env = Image::make("beauty", 8, 4, 3);
  for (float& v : env.pixels) v = 2.f;
  io::writeFile((*dir_ / "uniform2.exr").string(), io::encodeExr({env}, false));
  {
    auto [f, all] = run("env", "--size 32x32 --environment '" + (*dir_ / "uniform2.exr").string() + "' --camera 'yfov=20'");
    EXPECT_EQ(f.stats["lighting"], "environment");
    EXPECT_EQ(all["request"]["environment"].get<std::string>().rfind("sha256:", 0), 0u);
    EXPECT_NEAR(f.beauty.at(0, 0)[0], 2.f, 1e-3f) << "the corner sees the sky";
    EXPECT_EQ(f.stats["camera"]["source"], "request+auto");
    EXPECT_NEAR(f.stats["camera"]["yfov_deg"].get<double>(), 20.0, 1e-4);
  }
  {
    auto [f, all] = run("ambient", "--size 32x32 --ambient 0.5,0.25,0.125");
    EXPECT_EQ(f.stats["lighting"], "ambient");
    EXPECT_NEAR(f.beauty.at(0, 0)[1], 0.25f, 1e-6f);
  }
  {
    auto [f, all] = run("dark", "--size 32x32 --no-default-lighting");
    EXPECT_EQ(f.stats["lighting"], "none");
    EXPECT_EQ(objectMean(f).first, 0.0);
    // A frame no light reaches is not a silent success: the stats and the client say why.
    bool warned = false;
    for (const auto& w : f.stats["warnings"]) warned = warned || w.get<std::string>().rfind("black frame", 0) == 0;
    EXPECT_TRUE(warned) << f.stats.dump();
    const ProcessRun r = client(daemon_->url(), "render '" + box.string() + "' -o '" + (*dir_ / "dark.png").string() +
                                                    "' --size 16x16 --no-default-lighting", *dir_);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: black frame"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("no lights"), std::string::npos) << r.err;
  }
  {
    // --request: a whole request from a file, with -o's outputs and the camera option on top.
    std::ofstream(*dir_ / "req.json") << json{{"width", 40}, {"height", 24}, {"seed", 7},
                                              {"camera", {{"position", {0.0, 0.0, 4.0}}}}}.dump();
    auto [f, all] = run("request", "--request '" + (*dir_ / "req.json").string() + "' --camera 'target=0,0.5,0'");
    EXPECT_EQ(f.beauty.width, 40);
    EXPECT_EQ(f.beauty.height, 24);
    EXPECT_EQ(all["request"]["seed"], 7);
    EXPECT_EQ(f.stats["camera"]["position"], json::array({0.0, 0.0, 4.0}));
    EXPECT_NEAR(f.stats["camera"]["target"][1].get<double>(), 0.5, 1e-6);
  }
  // Bad option values are usage errors.
  EXPECT_EQ(client(daemon_->url(), "render '" + box.string() + "' -o x.png --camera 'fov=3'", *dir_).code, 2);
  EXPECT_EQ(client(daemon_->url(), "render '" + box.string() + "' -o x.png --ambient 1,2", *dir_).code, 2);
}

// radiant sweep packs a .gltf scene file with its files too: the points name the packed GLB's digest.
TEST_F(Content, SweepPacksGltfSceneFiles) {
  const fs::path box = fs::path(RADIANT_GLTF_SAMPLES_DIR) / "BoxTextured" / "glTF" / "BoxTextured.gltf";
  if (!fs::exists(box)) GTEST_SKIP() << "no BoxTextured sample";
  std::ofstream(*dir_ / "sweep.json") << json{{"base", {{"scene", {{"file", box.string()}}}, {"width", 16}, {"height", 16}}},
                                              {"axes", {{"exposure", {0, 1}}}},
                                              {"repeats", 1},
                                              {"warmup", 0}}.dump();
  const ProcessRun r = client(daemon_->url(), "sweep '" + (*dir_ / "sweep.json").string() + "' -o '" +
                                                  (*dir_ / "sweep.jsonl").string() + "'",
                              *dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(*dir_ / "sweep.jsonl");
  std::string line;
  int points = 0;
  while (std::getline(in, line)) {
    const json rec = json::parse(line);
    EXPECT_FALSE(rec.contains("error")) << line;
    // The digest of the packed GLB: the same one `radiant render` uploads (a GLB on the server).
    auto c = daemon_->client();
    const std::string digest = rec["request"]["scene"]["digest"];
    auto res = c.Get(("/v1/scenes/" + digest).c_str());
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200);
    EXPECT_EQ(res->body.substr(0, 4), "glTF");
    ++points;
  }
  EXPECT_EQ(points, 2);
}

}  // namespace
}  // namespace radiant
