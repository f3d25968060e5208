// radiant bench --fidelity: the default frame of real glTF models under HDR environments, scored
// against the reference path tracer with the glTF render-fidelity metric (issue 29; docs/PERFORMANCE.md,
// "Render fidelity against the reference path tracer").
//
// Per model x environment, at one orbit camera:
//  1. the default frame, once untimed: the request with no passes named, background transparent,
//     tone_map aces, PNG; its alpha is the coverage every score below is taken over;
//  2. the reference: renders of the same request with the `reference` pass at --spp and seeds 0, 1,
//     ..., each a PNG and a linear EXR of the reference AOV, cached under DIR/fidelity/reference/ by the
//     digest of the request (which names the seed and the scene's and the map's content digests), so a
//     second run renders none. The seeds are averaged in linear radiance until the mean of the even
//     seeds scores at most --converged-db against the mean of the odd ones (issue 29 asks for a
//     converged reference: at 1024 spp MetalRoughSpheres' two seeds were -20.6 dB apart, a noise as
//     large as the goal), or --max-spp samples are reached; the reference is then the mean of all
//     seeds, whose own noise is about that half-against-half score less 3 dB (the difference of two
//     halves has twice the RMS of the whole mean's error), tone mapped here as the daemon writes a PNG;
//  3. the default frame twice more, the second timed (scene loaded, shaders compiled, scene-keyed data
//     cached again after the reference's renders), with `compare.against` the reference's EXR (uploaded), which gives
//     relMSE and SSIM on the linear beauty (the daemon's stats.metrics, with the environment behind it,
//     as the reference renders it);
//  4. metrics::renderFidelity(default PNG, reference PNG): the reference pass writes no coverage, so the
//     golden takes the default frame's alpha (the same geometry; on silhouette pixels the reference's
//     colour still holds the environment it saw there);
//  5. a contact sheet DIR/fidelity/<model>.<environment>.png: default | reference | error, each over
//     white as the metric sees it; the error panel is viridis of sqrt(delta / 35215) up to 0.5 (white
//     where the default frame covers nothing).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "api/Sha256.h"
#include "client/Commands.h"
#include "client/report/Report.h"
#include "renderer/io/ImageIO.h"
#include "renderer/metrics/Metrics.h"

namespace radiant::client {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Model {
  std::string name;
  fs::path file;
};

// Each folder's glTF-Binary/*.glb if it has one, else glTF/*.gltf (the Khronos sample layout).
std::vector<Model> findModels(const fs::path& root, const std::vector<std::string>& only) {
  if (!fs::is_directory(root))
    throw UsageError("bench --fidelity: no model folder " + root.string() + " (--models DIR)");
  std::vector<Model> models;
  auto first = [](const fs::path& dir, const std::string& ext) -> fs::path {
    if (!fs::is_directory(dir)) return {};
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file() && e.path().extension() == ext) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files.empty() ? fs::path() : files.front();
  };
  for (const auto& e : fs::directory_iterator(root)) {
    if (!e.is_directory()) continue;
    const std::string name = e.path().filename().string();
    if (!only.empty() && std::find(only.begin(), only.end(), name) == only.end()) continue;
    fs::path file = first(e.path() / "glTF-Binary", ".glb");
    if (file.empty()) file = first(e.path() / "glTF", ".gltf");
    if (!file.empty()) models.push_back({name, file});
  }
  std::sort(models.begin(), models.end(), [](const Model& a, const Model& b) { return a.name < b.name; });
  if (models.empty()) throw UsageError("bench --fidelity: no glTF-Binary/*.glb or glTF/*.gltf under " + root.string());
  return models;
}

std::vector<fs::path> findEnvironments(const fs::path& root, const std::vector<std::string>& only) {
  if (!fs::is_directory(root))
    throw UsageError("bench --fidelity: no environment folder " + root.string() + " (--environments DIR)");
  std::vector<fs::path> maps;
  for (const auto& e : fs::directory_iterator(root)) {
    const std::string ext = e.path().extension().string();
    if (!e.is_regular_file() || (ext != ".hdr" && ext != ".exr")) continue;
    if (!only.empty() && std::find(only.begin(), only.end(), e.path().stem().string()) == only.end()) continue;
    maps.push_back(e.path());
  }
  std::sort(maps.begin(), maps.end());
  if (maps.empty()) throw UsageError("bench --fidelity: no .hdr or .exr map under " + root.string());
  return maps;
}

// A synchronous render: the answer's JSON and the bytes of each frame.
std::pair<json, std::vector<std::string>> render(const HttpClient& http, const json& request) {
  const std::string digest = request["scene"].value("digest", "");
  const json result = HttpClient::expectOk(http.post("/v1/renders", request.dump(), "application/json", sceneHeader(digest))).json();
  std::vector<std::string> frames;
  for (const auto& f : result.value("frames", json::array()))
    frames.push_back(HttpClient::expectOk(http.get(f["url"].get<std::string>())).body);
  if (frames.size() != request["outputs"].size())
    throw ServerError(500, {{"title", "No frames"}, {"detail", "expected " + std::to_string(request["outputs"].size()) +
                                                                  " frames, got " + std::to_string(frames.size())}});
  http.del("/v1/renders/" + result.value("id", ""));
  return {result, frames};
}

struct Reference {
  std::string png, exr;
  json record;  // {"request", "render_ms", "spp", "cached"}
};

// The reference of `request` (a whole render request), from the cache or rendered and cached.
Reference referenceFor(const HttpClient& http, const json& request, const fs::path& cacheDir) {
  const std::string key = api::sceneDigest(request.dump()).substr(7, 32);  // "sha256:" + 32 hex
  const fs::path base = cacheDir / key;
  Reference r;
  if (fs::exists(base.string() + ".json") && fs::exists(base.string() + ".png") && fs::exists(base.string() + ".exr")) {
    r.png = readFile(base.string() + ".png");
    r.exr = readFile(base.string() + ".exr");
    r.record = json::parse(readFile(base.string() + ".json"));
    r.record["cached"] = true;
    return r;
  }
  auto [result, frames] = render(http, request);
  r.png = frames[0], r.exr = frames[1];
  r.record = {{"request", request}, {"render_ms", result["stats"].value("render_ms", 0.0)},
              {"spp", request["passes"]["reference"]["spp"]}};
  fs::create_directories(cacheDir);
  writeFile(base.string() + ".png", r.png);
  writeFile(base.string() + ".exr", r.exr);
  writeFile(base.string() + ".json", r.record.dump(2) + "\n");
  r.record["cached"] = false;
  return r;
}

// The image with another image's alpha (the reference pass writes no coverage: it takes the default
// frame's, the same geometry seen by the same camera).
ImageRgba8 withAlphaOf(ImageRgba8 image, const ImageRgba8& alphaSource) {
  for (std::size_t p = 0; p < static_cast<std::size_t>(image.width) * image.height; ++p)
    image.pixels[p * 4 + 3] = alphaSource.pixels[p * 4 + 3];
  return image;
}

// The mean of the seeds' linear images whose index i has i % stride == offset: the reference at their
// samples' total. aov "beauty" (the unprefixed layer of an EXR, what compare.against reads).
Image meanOf(const std::vector<Image>& seeds, std::size_t offset, std::size_t stride) {
  Image mean = Image::make("beauty", seeds.front().width, seeds.front().height, 3);
  std::size_t n = 0;
  for (std::size_t i = offset; i < seeds.size(); i += stride, ++n)
    for (std::size_t p = 0; p < mean.pixels.size() / 3; ++p)
      for (int c = 0; c < 3; ++c)
        mean.pixels[p * 3 + c] += seeds[i].pixels[p * seeds[i].channels + std::min(c, seeds[i].channels - 1)];
  for (float& v : mean.pixels) v /= static_cast<float>(n);
  return mean;
}

// A linear image as the daemon writes the reference's PNG (exposure 0, tone_map aces, no alpha).
ImageRgba8 viewOf(const Image& linear) {
  io::PngOptions png;
  png.toneMap = api::ToneMap::Aces;
  return io::decodePngRgba8(io::encodePng(linear, png));
}

// default | reference | error, each over white as the metric sees it, 2 white pixels apart.
ImageRgba8 contactSheet(const ImageRgba8& candidate, const ImageRgba8& golden) {
  constexpr int kGap = 2;
  constexpr double kErrorScale = 0.5;  // sqrt(delta / 35215) at full scale
  const int w = candidate.width, h = candidate.height;
  ImageRgba8 sheet = ImageRgba8::make(3 * w + 2 * kGap, h);
  std::fill(sheet.pixels.begin(), sheet.pixels.end(), 255);
  auto overWhite = [](const std::uint8_t* p, std::uint8_t* out) {
    for (int c = 0; c < 3; ++c) out[c] = static_cast<std::uint8_t>(std::lround(255.0 + (p[c] - 255.0) * p[3] / 255.0));
  };
  Image delta = metrics::fidelityDeltaMap(candidate, golden);
  for (float& d : delta.pixels) d = std::sqrt(d);
  const Image heat = metrics::falseColour(delta, kErrorScale);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      overWhite(candidate.at(x, y), sheet.at(x, y));
      overWhite(golden.at(x, y), sheet.at(w + kGap + x, y));
      if (candidate.at(x, y)[3] != 0)
        for (int c = 0; c < 3; ++c)
          sheet.at(2 * (w + kGap) + x, y)[c] = static_cast<std::uint8_t>(std::lround(255.0 * heat.at(x, y)[c]));
    }
  return sheet;
}

std::string decibels(const std::optional<double>& db) {
  if (!db) return "n/a";
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << *db;
  return s.str();
}

}  // namespace

int fidelityBench(const GlobalOptions& g, const FidelityOptions& o) {
  const std::vector<Model> models = findModels(o.models, o.onlyModels);
  const std::vector<fs::path> maps = findEnvironments(o.environments, o.onlyEnvironments);
  const std::string server = o.servers.empty() ? g.server : o.servers.front();
  HttpClient http(server, g.token);
  const json info = HttpClient::expectOk(http.get("/v1/info")).json();
  const fs::path dir = o.dir, sheets = dir / "fidelity", cache = sheets / "reference";
  fs::create_directories(sheets);
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  json records = json::array();
  bool failed = false;
  for (const Model& model : models) {
    std::string sceneDigest;
    try {
      sceneDigest = ensureSceneUploaded(http, sceneFileBytes(model.file.string()), model.file.string(), !o.quiet);
    } catch (const ServerError& e) {
      std::cerr << "bench --fidelity: " << model.name << ": upload failed: " << e.what() << "\n";
      records.push_back({{"model", model.name}, {"error", e.what()}});
      failed = true;
      continue;
    }
    for (const fs::path& map : maps) {
      const std::string envName = map.stem().string();
      json record{{"model", model.name}, {"file", model.file.string()}, {"environment", envName}};
      try {
        const std::string envDigest = ensureImageUploaded(http, map.string(), !o.quiet);
        // The default request but for the background (transparent: the model's pixels are the alpha,
        // as model-viewer's goldens) and the view transform (aces, the default, named so that a change
        // of the default does not change this benchmark).
        const json base{{"scene", {{"digest", sceneDigest}}},
                        {"environment", envDigest},
                        {"camera", {{"orbit", {{"theta_deg", o.thetaDeg}, {"phi_deg", o.phiDeg}}}}},
                        {"width", o.size},
                        {"height", o.size},
                        {"background", "transparent"},
                        {"tone_map", "aces"},
                        {"seed", 0}};
        json defRequest = base;
        defRequest["outputs"] = {{{"format", "png"}, {"aovs", {"beauty"}}}};
        // Untimed (scene loaded, shaders compiled, derived data cached): its coverage is the pixels every
        // score is taken over, the reference's convergence included.
        const ImageRgba8 coverage = io::decodePngRgba8(render(http, defRequest).second.at(0));

        json refRequest = base;
        refRequest["passes"] = {{"reference", {{"spp", o.spp}}}};
        refRequest["outputs"] = {{{"format", "png"}, {"aovs", {"reference"}}},
                                 {{"format", "exr"}, {"aovs", {"reference"}}, {"half", false}}};
        std::vector<Reference> seeds;
        std::vector<Image> linear;
        auto addSeed = [&] {
          json r = refRequest;
          r["seed"] = static_cast<int>(seeds.size());
          seeds.push_back(referenceFor(http, r, cache));
          linear.push_back(io::decodeImage(seeds.back().exr, "reference"));
        };
        addSeed();
        // Seeds come in pairs (even against odd) once there is more than one.
        const int seedBudget = o.maxSpp / o.spp;  // >= 1: runBench refuses --max-spp below --spp
        const int maxSeeds = seedBudget < 2 ? 1 : seedBudget / 2 * 2;
        std::optional<double> halvesDb;
        bool converged = false;
        for (int want = 2; maxSeeds > 1;) {
          while (static_cast<int>(seeds.size()) < want) addSeed();
          const ImageRgba8 even = withAlphaOf(viewOf(meanOf(linear, 0, 2)), coverage);
          halvesDb = metrics::renderFidelity(withAlphaOf(viewOf(meanOf(linear, 1, 2)), coverage), even).decibels;
          if (!halvesDb || *halvesDb <= o.convergedDb) {  // no score: the halves are identical (floored)
            converged = true;
            break;
          }
          if (want >= maxSeeds) break;
          // Doubling the samples halves the noise's variance: -1.5 dB (10 log10 of an RMS). The seeds
          // predicted to reach --converged-db, a power of two times today's, at most maxSeeds.
          const int doublings = std::max(1, static_cast<int>(std::ceil((*halvesDb - o.convergedDb) / 1.5)));
          want = std::min(maxSeeds, want << std::min(doublings, 20));
        }
        // The reference: one seed as the daemon wrote it, or the mean of all, written beside the seeds.
        json seed0 = refRequest;
        seed0["seed"] = 0;
        const std::string key0 = api::sceneDigest(seed0.dump()).substr(7, 32);
        fs::path refExr = cache / (key0 + ".exr");
        std::string referencePng = seeds.front().png;
        if (seeds.size() > 1) {
          const Image mean = meanOf(linear, 0, 1);
          refExr = cache / (key0 + ".mean" + std::to_string(seeds.size()) + ".exr");
          writeFile(refExr.string(), io::encodeExr({mean}, false));
          referencePng = io::encodePngRgba8(viewOf(mean), false);
        }
        const std::string refDigest = ensureImageUploaded(http, refExr.string(), false);
        defRequest["compare"] = {{"against", refDigest}};
        // Warm again (the reference's renders may have displaced the frame's cached data), then timed.
        render(http, defRequest);
        auto [result, frames] = render(http, defRequest);
        const json& stats = result["stats"];
        const ImageRgba8 candidate = io::decodePngRgba8(frames[0]);
        const ImageRgba8 golden = withAlphaOf(io::decodePngRgba8(referencePng), candidate);
        const metrics::FidelityScore score = metrics::renderFidelity(candidate, golden);
        const std::string stem = model.name + "." + envName;
        writeFile((sheets / (stem + ".default.png")).string(), frames[0]);
        writeFile((sheets / (stem + ".reference.png")).string(), referencePng);
        writeFile((sheets / (stem + ".png")).string(), io::encodePngRgba8(contactSheet(candidate, golden), false));
        const json& m = stats.value("metrics", json::object());
        record["fidelity_db"] = score.decibels ? json(*score.decibels) : json(nullptr);
        record["fidelity_rms"] = score.rms;
        record["fidelity_floored"] = score.floored;
        record["covered_pixels"] = score.covered;
        record["rel_mse"] = m.value("rel_mse", json());
        record["ssim"] = m.value("ssim", json());
        record["default_ms"] = stats.value("render_ms", 0.0);
        record["lighting"] = stats.value("lighting", "");
        record["warnings"] = stats.value("warnings", json::array());
        double referenceMs = 0;
        bool allCached = true;
        for (const Reference& r : seeds) {
          referenceMs += r.record.value("render_ms", 0.0);
          allCached = allCached && r.record.value("cached", false);
        }
        record["reference_spp"] = o.spp * static_cast<int>(seeds.size());
        record["reference_seeds"] = seeds.size();
        record["reference_ms"] = referenceMs;
        record["reference_cached"] = allCached;
        // The even seeds' mean against the odd seeds' on the covered pixels, and the whole mean's own
        // noise estimated from it (RMS of a difference of two halves = 2 x the mean's: -3 dB).
        const std::optional<double> noiseDb =
            halvesDb ? std::optional<double>(*halvesDb - 10.0 * std::log10(2.0)) : std::nullopt;
        record["reference_halves_db"] = halvesDb ? json(*halvesDb) : json(nullptr);
        record["reference_noise_db"] = noiseDb ? json(*noiseDb) : json(nullptr);
        record["reference_converged"] = converged;
        record["camera"] = stats.value("camera", json::object());
        record["contact_sheet"] = (sheets / (stem + ".png")).string();
        if (!o.quiet)
          std::cerr << model.name << " / " << envName << ": " << decibels(score.decibels) << " dB ("
                    << score.covered << " px covered), default " << report::formatNumber(record["default_ms"].get<double>())
                    << " ms, reference " << record["reference_spp"] << " spp in "
                    << report::formatNumber(record["reference_ms"].get<double>()) << " ms"
                    << (allCached ? " (cached)" : "") << ", its noise " << decibels(noiseDb) << " dB"
                    << (converged ? "" : " (not converged)") << "\n";
      } catch (const ServerError& e) {
        std::cerr << "bench --fidelity: " << model.name << " / " << envName << ": " << e.what() << "\n";
        record["error"] = e.what();
        failed = true;
      }
      records.push_back(record);
    }
  }
  // The table, Markdown.
  std::ostringstream md;
  md << "Render fidelity of the default frame against the reference path tracer (" << date << ", "
     << info["device"].value("renderer", "?") << "): " << o.size << "x" << o.size << " px, orbit theta " << o.thetaDeg
     << " deg, phi " << o.phiDeg << " deg, automatic radius; fidelity = model-viewer's render-fidelity score in dB "
     << "(lower is better; its regression threshold " << metrics::kFidelityThresholdDb << " dB, floor "
     << metrics::kFidelityFloorDb << " dB); relMSE and SSIM on the linear beauty (stats.metrics); the reference: the mean "
     << "of renders of " << o.spp << " spp at seeds 0, 1, ... until its even seeds' mean scores " << o.convergedDb
     << " dB against its odd seeds', at most " << o.maxSpp << " spp; its noise = that score less 3 dB (n/a: one seed).\n\n"
     << "| model | environment | fidelity dB | relMSE | SSIM | default ms | reference spp | reference noise dB |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  auto num = [](const json& v, int digits) {
    if (!v.is_number()) return std::string("n/a");
    std::ostringstream s;
    s << std::fixed << std::setprecision(digits) << v.get<double>();
    return s.str();
  };
  for (const json& r : records) {
    if (r.contains("error")) {
      md << "| " << r.value("model", "") << " | " << r.value("environment", "") << " | failed: " << r["error"].get<std::string>()
         << " | | | | | |\n";
      continue;
    }
    md << "| " << r["model"].get<std::string>() << " | " << r["environment"].get<std::string>() << " | "
       << num(r["fidelity_db"], 1) << " | " << num(r["rel_mse"], 4) << " | " << num(r["ssim"], 3) << " | "
       << num(r["default_ms"], 0) << " | " << r["reference_spp"] << " | " << num(r["reference_noise_db"], 1)
       << (r.value("reference_converged", false) || r.value("reference_seeds", 0) == 1 ? "" : " (not converged)") << " |\n";
  }
  writeFile((dir / "fidelity.md").string(), md.str());
  writeFile((dir / "fidelity.json").string(),
            json{{"date", date}, {"server", server}, {"device", info.value("device", json())}, {"size", o.size},
                 {"spp", o.spp}, {"max_spp", o.maxSpp}, {"converged_db", o.convergedDb}, {"orbit", {{"theta_deg", o.thetaDeg}, {"phi_deg", o.phiDeg}}}, {"records", records}}
                    .dump(2) + "\n");
  std::cout << md.str() << "\nwrote " << (dir / "fidelity.md").string() << ", " << (dir / "fidelity.json").string()
            << " and contact sheets (default | reference | error) in " << sheets.string() << "\n";
  return failed ? kExitServerError : kExitOk;
}

}  // namespace radiant::client
