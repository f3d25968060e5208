// The technique descriptors (renderer/techniques/<name>/<name>.json) are merged into the request
// schema at build time by radiant_merge_schema: the AOV rows they declare are completed with their
// defaults, and a descriptor that breaks a rule fails the build naming its file and key (docs/API.md,
// "A technique declares itself in one file"). Run here on descriptors written by the test.
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Merge {
  int status = -1;
  std::string log;
  json merged;
};

class MergeSchema : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("radiant-merge-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    write("render_request.json", json{{"type", "object"},
                                      {"properties",
                                       {{"passes", {{"type", "object"}}},
                                        {"media", {{"type", "array"}}},
                                        {"outputs", {{"items", {{"properties", {{"aovs", {{"items", json::object()}}}}}}}}},
                                        {"compare", {{"properties", {{"aov", json::object()}}}}},
                                        {"refine", {{"properties", {{"aov", json::object()}}}}}}}});
    write("media.json", json{{"system", json::object()},
                             {"request_particles", json::object()},
                             {"gltf_particles", json::object()}});
  }
  void TearDown() override { fs::remove_all(dir_); }

  void write(const std::string& name, const json& j) { std::ofstream(dir_ / name) << j.dump(1); }

  // A minimal valid descriptor of technique `name`, writing AOV `aov`.
  static json descriptor(const std::string& name, const std::string& aov) {
    return json{{"name", name},
                {"summary", "s"},
                {"description", "d"},
                {"inputs", json::array()},
                {"outputs", {aov}},
                {"aovs", {{aov, {{"format", "RGBA32F"}, {"description", "an image"}}}}},
                {"adds_to_beauty", true},
                {"on_by_default", false},
                {"params", json::object()}};
  }

  Merge run(const std::vector<json>& techniques) {
    std::string cmd = std::string(MERGE_SCHEMA_PATH) + " " + (dir_ / "out.json").string() + " " +
                      (dir_ / "render_request.json").string() + " " + (dir_ / "media.json").string();
    for (const json& t : techniques) {
      const std::string file = t["name"].get<std::string>() + ".json";
      write(file, t);
      cmd += ' ';  // appended apart: GCC 12 warns falsely (-Wrestrict) on " " + std::string&&
      cmd += (dir_ / file).string();
    }
    cmd += " 2>";
    cmd += (dir_ / "log.txt").string();
    Merge m;
    m.status = std::system(cmd.c_str());
    std::ifstream log(dir_ / "log.txt");
    m.log.assign(std::istreambuf_iterator<char>(log), {});
    if (m.status == 0) m.merged = json::parse(std::ifstream(dir_ / "out.json"));
    return m;
  }

  fs::path dir_;
};

TEST_F(MergeSchema, AovRowsAreCompletedWithTheirDefaults) {
  json t = descriptor("alpha_pass", "glow");
  t["outputs"] = {"glow", "glow_mask"};
  t["resources"] = {"glow_cache"};
  t["aovs"]["glow_mask"] = {{"format", "RGBA16F"}, {"resource", "glow"}, {"first_channel", 3}, {"channels", 1},
                            {"resolve", "nearest"}, {"radiance", false}, {"ground_truth", "beauty"},
                            {"description", "its mask"}};
  const Merge m = run({t});
  ASSERT_EQ(m.status, 0) << m.log;
  const json& rows = m.merged["x-aovs"];
  ASSERT_EQ(rows.size(), 2u);
  const json& glow = rows[0]["name"] == "glow" ? rows[0] : rows[1];
  const json& mask = rows[0]["name"] == "glow" ? rows[1] : rows[0];
  EXPECT_EQ(glow["producer"], "alpha_pass");
  EXPECT_EQ(glow["resource"], "glow");
  EXPECT_EQ(glow["first_channel"], 0);
  EXPECT_EQ(glow["exr"], json({"glow.R", "glow.G", "glow.B"}));
  EXPECT_EQ(glow["resolve"], "average");
  EXPECT_EQ(glow["radiance"], true);
  EXPECT_EQ(glow["ground_truth"], "");
  EXPECT_EQ(mask["resource"], "glow");
  EXPECT_EQ(mask["first_channel"], 3);
  EXPECT_EQ(mask["exr"], json({"glow_mask.Y"}));
  EXPECT_EQ(mask["resolve"], "nearest");
  EXPECT_EQ(mask["radiance"], false);
  EXPECT_EQ(mask["ground_truth"], "beauty");
  // The declaration reaches the renderer (TechniqueInfo) through the pass's "x-technique", the
  // requestable AOVs through the schema's enum.
  const json& x = m.merged["properties"]["passes"]["properties"]["alpha_pass"]["x-technique"];
  EXPECT_EQ(x["resources"], json({"glow_cache"}));
  EXPECT_EQ(x["adds_to_beauty"], true);
  EXPECT_EQ(x["exclusive"], false);
  EXPECT_EQ(x["beauty_blend"], "add");  // the default
  EXPECT_EQ(x["prepare_outputs"], json::array());
  EXPECT_EQ(m.merged["properties"]["outputs"]["items"]["properties"]["aovs"]["items"]["enum"],
            json({"beauty", "glow", "glow_mask"}));
}

// `radiant bench`'s preset travels in the descriptor: one list serves both modes, or a list per mode,
// and the request fields and compare block come through as given (x-technique.bench, /v1/info).
TEST_F(MergeSchema, TheBenchPresetIsCarriedWithBothModes) {
  json t = descriptor("alpha_pass", "glow");
  t["params"] = {{"taps", {{"type", "integer"}, {"default", 4}, {"minimum", 1}, {"maximum", 16}, {"description", "t"}}},
                 {"mode", {{"type", "string"}, {"default", "x"}, {"enum", {"x", "y"}}, {"description", "m"}}}};
  t["bench"] = {{"axes", {{"mode", {"x", "y"}}, {"taps", {{"full", {2, 16}}, {"quick", {4}}}}}},
                {"request", {{"ambient", {1, 1, 1}}}},
                {"compare", {{"max_bounces", 5}}}};
  const Merge m = run({t});
  ASSERT_EQ(m.status, 0) << m.log;
  const json& b = m.merged["properties"]["passes"]["properties"]["alpha_pass"]["x-technique"]["bench"];
  EXPECT_EQ(b["axes"]["mode"], (json{{"full", {"x", "y"}}, {"quick", {"x", "y"}}}));
  EXPECT_EQ(b["axes"]["taps"], (json{{"full", {2, 16}}, {"quick", {4}}}));
  EXPECT_EQ(b["request"], (json{{"ambient", {1, 1, 1}}}));
  EXPECT_EQ(b["compare"], (json{{"max_bounces", 5}}));
  // A descriptor without one has an empty preset.
  const Merge none = run({descriptor("beta_pass", "glow")});
  ASSERT_EQ(none.status, 0) << none.log;
  EXPECT_EQ(none.merged["properties"]["passes"]["properties"]["beta_pass"]["x-technique"]["bench"],
            (json{{"axes", json::object()}, {"request", json::object()}, {"compare", json::object()}}));
}

// Each case breaks one rule; the build must fail and say where.
TEST_F(MergeSchema, ABrokenDescriptorFailsNamingItsFileAndKey) {
  struct Case {
    const char* what;
    std::vector<json> techniques;
    const char* says;
  };
  json noRow = descriptor("a", "glow");
  noRow.erase("aovs");
  json twoRows = descriptor("b", "glow");
  json notOutput = descriptor("a", "glow");
  notOutput["aovs"]["other"] = {{"format", "RGBA32F"}, {"description", "x"}};
  json badFormat = descriptor("a", "glow");
  badFormat["aovs"]["glow"]["format"] = "RGB8";
  json tooManyChannels = descriptor("a", "glow");
  tooManyChannels["aovs"]["glow"]["format"] = "R32F";
  json wrongNames = descriptor("a", "glow");
  wrongNames["aovs"]["glow"]["channel_names"] = {"X"};
  json noFlag = descriptor("a", "glow");
  noFlag.erase("on_by_default");
  json unknownKey = descriptor("a", "glow");
  unknownKey["runs_first"] = true;
  json badPaths = descriptor("a", "glow");
  badPaths["light_paths"] = "LD+DE";
  json foreignRequirement = descriptor("a", "glow");
  foreignRequirement["light_paths"] = {"LD+DE"};
  foreignRequirement["requires_paths"] = {"LS+DE"};
  json benchAxis = descriptor("a", "glow");
  benchAxis["params"] = {{"taps", {{"type", "integer"}, {"default", 4}, {"minimum", 1}, {"maximum", 16}, {"description", "t"}}},
                         {"mode", {{"type", "string"}, {"default", "x"}, {"enum", {"x", "y"}}, {"description", "m"}}}};
  json benchUnknownParam = benchAxis, benchOutOfRange = benchAxis, benchNotInEnum = benchAxis, benchWrongType = benchAxis,
       benchNoQuick = benchAxis, benchUnknownKey = benchAxis;
  benchUnknownParam["bench"] = {{"axes", {{"radius", {1, 2}}}}};
  benchOutOfRange["bench"] = {{"axes", {{"taps", {{"full", {4, 32}}, {"quick", {4}}}}}}};
  benchNotInEnum["bench"] = {{"axes", {{"mode", {"x", "z"}}}}};
  benchWrongType["bench"] = {{"axes", {{"taps", {2.5}}}}};
  benchNoQuick["bench"] = {{"axes", {{"taps", {{"full", {4}}}}}}};
  benchUnknownKey["bench"] = {{"scenes", {"cornell_box"}}};
  json unknownClass = descriptor("a", "glow");
  unknownClass["light_paths"] = {"LD+DE", "LD*E"};
  json after = descriptor("a", "glow");
  after["after"] = {"direct"};
  json badBlend = descriptor("a", "glow"), blendOffBeauty = descriptor("a", "glow");
  badBlend["beauty_blend"] = "multiply";
  blendOffBeauty["beauty_blend"] = "over";
  blendOffBeauty["adds_to_beauty"] = false;
  json foreignPrepareOutput = descriptor("a", "glow");
  foreignPrepareOutput["prepare_outputs"] = {"grid"};
  const std::vector<Case> cases = {
      {"the retired \"after\"", {after}, "unknown key \"after\" (gone: the frame graph orders passes"},
      {"an unknown beauty blend", {badBlend}, "\"beauty_blend\" must be \"add\", \"over\" or \"transmit\""},
      {"a blend of a pass that adds nothing", {blendOffBeauty}, "\"beauty_blend\" needs \"adds_to_beauty\": true"},
      {"a prepare output it does not write", {foreignPrepareOutput}, "prepare_outputs: \"grid\" is not one of its"},
      {"an unknown light-path class", {unknownClass}, "light_paths: \"LD*E\" is not a light-path class"},
      {"a bench axis of no parameter", {benchUnknownParam}, "bench.axes.radius is not one of its \"params\""},
      {"a bench value above the maximum", {benchOutOfRange}, "bench.axes.taps: 32 is above its maximum"},
      {"a bench value outside the enum", {benchNotInEnum}, "bench.axes.mode: \"z\" is not in its enum"},
      {"a bench value of another type", {benchWrongType}, "bench.axes.taps: 2.5 is not of type integer"},
      {"a bench axis without its quick values", {benchNoQuick}, "bench.axes.taps must be an array of values or"},
      {"an unknown bench key", {benchUnknownKey}, "bench: unknown key \"scenes\""},
      {"an output without a row", {noRow}, "no technique declares the row of AOV \"glow\""},
      {"a row declared twice", {descriptor("a", "glow"), twoRows}, "aovs.glow is declared by a too"},
      {"a row of no output", {notOutput}, "aovs.other is not one of its \"outputs\""},
      {"an unknown format", {badFormat}, "aovs.glow.format must be one of"},
      {"three channels of R32F", {tooManyChannels}, "aovs.glow: first_channel + channels exceed its format"},
      {"channel names of another count", {wrongNames}, "aovs.glow.channel_names must name each of its channels"},
      {"a required flag left out", {noFlag}, "missing \"on_by_default\""},
      {"an unknown key", {unknownKey}, "unknown key \"runs_first\""},
      {"light paths not an array", {badPaths}, "\"light_paths\" must be an array of names"},
      {"a required class it does not supply", {foreignRequirement}, "requires_paths: \"LS+DE\" is not one of its"},
  };
  for (const Case& c : cases) {
    const Merge m = run(c.techniques);
    EXPECT_NE(m.status, 0) << c.what;
    EXPECT_NE(m.log.find(c.says), std::string::npos) << c.what << ": " << m.log;
    EXPECT_NE(m.log.find(".json"), std::string::npos) << c.what << " names no file: " << m.log;
  }
}

// The typed parameter struct of a technique (api/tools/param_structs.cpp) is generated from the merged
// schema: integers, numbers, booleans and strings become fields, a string enum an enum class of its
// values in schema order; a parameter or value that cannot become a C++ name fails, naming it.
TEST_F(MergeSchema, ParamStructsAreGeneratedFromTheMergedSchema) {
  json t = descriptor("glow_pass", "glow");
  t["params"] = {
      {"taps", {{"type", "integer"}, {"default", 4}, {"minimum", 1}, {"maximum", 64}, {"description", "d"}}},
      {"seed", {{"type", "integer"}, {"default", 0}, {"minimum", 0}, {"maximum", 4294967295u}, {"description", "d"}}},
      {"gain", {{"type", "number"}, {"default", 0.5}, {"minimum", 0}, {"maximum", 1}, {"description", "d"}}},
      {"split", {{"type", "string"}, {"default", "2d"}, {"enum", {"2d", "screen_parallel"}}, {"description", "d"}}},
      {"label", {{"type", "string"}, {"default", ""}, {"description", "d"}}}};
  ASSERT_EQ(run({t}).status, 0);
  const auto structs = [&](const std::string& technique) {
    std::string cmd = std::string(PARAM_STRUCTS_PATH) + " " + (dir_ / "out.json").string() + " " +
                      (dir_ / "params").string() + " " + technique;
    cmd += " 2>";
    cmd += (dir_ / "log.txt").string();
    const int status = std::system(cmd.c_str());
    std::ifstream log(dir_ / "log.txt");
    return std::make_pair(status, std::string(std::istreambuf_iterator<char>(log), {}));
  };
  ASSERT_EQ(structs("glow_pass").first, 0);
  std::ifstream in(dir_ / "params" / "glow_pass_params.h");
  const std::string h(std::istreambuf_iterator<char>(in), {});
  for (const char* says : {"struct GlowPassParams {", "kTechnique = \"glow_pass\"", "  int taps;\n",
                           "  std::int64_t seed;\n", "  double gain;\n", "  std::string label;\n",
                           "enum class Split { k2d, kScreenParallel };", "  Split split;\n",
                           "case Split::kScreenParallel: return \"screen_parallel\";",
                           "out.given.gain = params.given(\"gain\");"})
    EXPECT_NE(h.find(says), std::string::npos) << says << " not in:\n" << h;
  const auto missing = structs("no_such_pass");
  EXPECT_NE(missing.first, 0);
  EXPECT_NE(missing.second.find("no_such_pass: not in the merged schema"), std::string::npos) << missing.second;

  t["params"] = {{"default", {{"type", "boolean"}, {"default", true}, {"description", "d"}}}};
  ASSERT_EQ(run({t}).status, 0);
  const auto keyword = structs("glow_pass");
  EXPECT_NE(keyword.first, 0);
  EXPECT_NE(keyword.second.find("parameter \"default\" cannot be a field name"), std::string::npos) << keyword.second;
  t["params"] = {{"mode", {{"type", "string"}, {"default", "a-b"}, {"enum", {"a-b"}}, {"description", "d"}}}};
  ASSERT_EQ(run({t}).status, 0);
  const auto value = structs("glow_pass");
  EXPECT_NE(value.first, 0);
  EXPECT_NE(value.second.find("enum value \"a-b\" cannot become a C++ name"), std::string::npos) << value.second;
}

}  // namespace
