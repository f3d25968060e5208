// The radiant command line, defined once with CLI11 (client/Cli.cpp): --help of every command and the
// bash completion come from that definition, and render's options reach the request it would send.
// The real binary runs here with a server that cannot answer (port 1): nothing in these tests needs one.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "api/Sha256.h"
#include "client/Cli.h"

namespace radiant {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct ProcessRun {
  int code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

fs::path scratch() {
  const fs::path d = fs::temp_directory_path() / ("radiant-cli-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

// `sh -c` of a command line with the client's path in $RADIANT; stdout and stderr kept apart.
ProcessRun shell(const std::string& script) {
  const fs::path d = scratch();
  const std::string cmd = "cd '" + d.string() + "' && RADIANT='" RADIANT_CLIENT_PATH "' RADIANT_SERVER=http://127.0.0.1:1 bash -c '" +
                          script + "' > out.txt 2> err.txt";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(d / "out.txt"), slurp(d / "err.txt")};
}
ProcessRun radiant(const std::string& args) { return shell("\"$RADIANT\" " + args); }

std::set<std::string> words(const std::string& text) {
  std::set<std::string> w;
  std::istringstream in(text);
  for (std::string s; in >> s;) w.insert(s);
  return w;
}

// The definition itself: every command and, per command, its option names.
struct Definition {
  std::vector<std::string> commands;
  std::map<std::string, std::vector<std::string>> options;  // command -> -x and --long names
};
Definition definition() {
  client::GlobalOptions g;
  client::Action action;
  const auto app = client::buildCli(g, action);
  Definition d;
  for (const CLI::App* sub : app->get_subcommands([](const CLI::App*) { return true; })) {
    d.commands.push_back(sub->get_name());
    for (const CLI::Option* o : sub->get_options()) {
      if (o->get_positional()) continue;
      for (const auto& s : o->get_snames()) d.options[sub->get_name()].push_back("-" + s);
      for (const auto& l : o->get_lnames()) d.options[sub->get_name()].push_back("--" + l);
    }
  }
  return d;
}

// What bash completes for `line` (the last word is the one being completed), with the script
// `radiant completion bash` prints sourced.
std::set<std::string> complete(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> w;
  for (std::string s; in >> s;) w.push_back(s);
  if (line.empty() || line.back() == ' ') w.push_back("");
  std::string array;
  for (const auto& s : w) array += " \"" + s + "\"";
  const ProcessRun r = shell("source <(\"$RADIANT\" completion bash) && COMP_WORDS=(" + array +
                      ") && COMP_CWORD=" + std::to_string(w.size() - 1) + " && _radiant && printf \"%s\\n\" \"${COMPREPLY[@]}\"");
  EXPECT_EQ(r.code, 0) << line << ": " << r.err;
  return words(r.out);
}

TEST(Cli, EveryCommandHasHelpFromTheDefinition) {
  const Definition d = definition();
  const std::set<std::string> expected{"render", "info", "scenes", "sweep", "report", "bench", "compare", "help", "completion"};
  EXPECT_EQ(std::set<std::string>(d.commands.begin(), d.commands.end()), expected);
  const ProcessRun top = radiant("--help");
  ASSERT_EQ(top.code, 0) << top.err;
  for (const auto& c : d.commands) EXPECT_NE(top.out.find(c), std::string::npos) << c;
  EXPECT_EQ(radiant("help").out, top.out);
  for (const auto& c : d.commands) {
    const ProcessRun r = radiant(c + " --help");
    ASSERT_EQ(r.code, 0) << c << ": " << r.err;
    if (c != "help") { EXPECT_EQ(radiant("help " + c).out, r.out) << c; }
    for (const auto& opt : d.options.at(c)) EXPECT_NE(r.out.find(opt), std::string::npos) << c << " " << opt;
  }
  // The flags the brief adds are in the definition.
  for (const char* flag : {"--quality", "--time-budget-ms", "--dry-run", "-o"})
    EXPECT_NE(radiant("render --help").out.find(flag), std::string::npos) << flag;
}

TEST(Cli, BadCommandLinesAreUsageErrors) {
  EXPECT_EQ(radiant("frobnicate").code, 2);
  EXPECT_EQ(radiant("").code, 2);
  EXPECT_EQ(radiant("render --builtin x -o a.png --frobnicate").code, 2);
  const ProcessRun r = radiant("render --builtin x -o a.png --time-budget-ms soon");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--time-budget-ms"), std::string::npos) << r.err;
  EXPECT_EQ(radiant("sweep s.json --inflight 0").code, 2);
  EXPECT_EQ(radiant("completion fish").code, 2);
  // bench --fidelity: not with --service; a missing model folder is named before any server is asked.
  EXPECT_EQ(radiant("bench --fidelity --service").code, 2);
  const ProcessRun f = radiant("bench --fidelity --models /nonexistent/models");
  EXPECT_EQ(f.code, 2);
  EXPECT_NE(f.err.find("/nonexistent/models"), std::string::npos) << f.err;
  EXPECT_EQ(radiant("bench --fidelity --spp 0").code, 2);
  const ProcessRun m = radiant("bench --fidelity --spp 1024 --max-spp 512");
  EXPECT_EQ(m.code, 2);
  EXPECT_NE(m.err.find("--max-spp"), std::string::npos) << m.err;
  EXPECT_EQ(radiant("bench --fidelity --converged-db 3").code, 2);
}

TEST(Cli, BashCompletionListsEveryCommandAndEachCommandsFlags) {
  const Definition d = definition();
  const std::set<std::string> top = complete("radiant ");
  for (const auto& c : d.commands) EXPECT_TRUE(top.count(c)) << c;
  EXPECT_TRUE(complete("radiant --").count("--server"));
  EXPECT_EQ(complete("radiant re"), (std::set<std::string>{"render", "report"}));
  for (const auto& c : d.commands) {
    const std::set<std::string> flags = complete("radiant " + c + " -");
    for (const auto& opt : d.options.at(c)) EXPECT_TRUE(flags.count(opt)) << c << " " << opt;
    EXPECT_EQ(flags.size(), std::set<std::string>(d.options.at(c).begin(), d.options.at(c).end()).size()) << c;
  }
  // A global option's value is skipped when finding the command.
  EXPECT_TRUE(complete("radiant --server http://x:1 sweep --").count("--retry-failed"));
  // Options with a fixed set of values complete to those values.
  EXPECT_EQ(complete("radiant render --quality "), (std::set<std::string>{"draft", "preview", "final", "reference"}));
  EXPECT_EQ(complete("radiant report r.jsonl --metric rel"), (std::set<std::string>{"rel_mse"}));
  EXPECT_EQ(complete("radiant help sw"), (std::set<std::string>{"sweep"}));
  EXPECT_EQ(complete("radiant completion "), (std::set<std::string>{"bash"}));
}

TEST(Cli, RenderPassesQualityAndTimeBudgetIntoTheRequest) {
  const ProcessRun r = radiant("render --builtin cornell_box -o a.png --quality draft --time-budget-ms 250 --size 64x32 --dry-run");
  ASSERT_EQ(r.code, 0) << r.err;
  const json req = json::parse(r.out);
  EXPECT_EQ(req["quality"], "draft");
  EXPECT_TRUE(req["time_budget_ms"].is_number_integer());
  EXPECT_EQ(req["time_budget_ms"], 250);
  EXPECT_EQ(req["scene"], (json{{"builtin", "cornell_box"}}));
  EXPECT_EQ(req["width"], 64);
  EXPECT_EQ(req["height"], 32);
  EXPECT_EQ(req["outputs"], (json::array({{{"format", "png"}, {"aovs", {"beauty"}}}})));
  // Neither is set when not given; the daemon, not the client, judges a preset's name.
  const json plain = json::parse(radiant("render --builtin cornell_box -o a.png --dry-run").out);
  EXPECT_FALSE(plain.contains("quality"));
  EXPECT_FALSE(plain.contains("time_budget_ms"));
  EXPECT_EQ(json::parse(radiant("render --builtin b -o a.png --quality ultra --dry-run").out)["quality"], "ultra");
  // A scene file is named by its digest, computed here; a dry run uploads nothing.
  const fs::path scene = scratch() / "s.gltf";
  std::ofstream(scene) << R"({"asset":{"version":"2.0"}})";
  const ProcessRun f = radiant("render " + scene.string() + " -o a.exr --aov beauty --aov depth --dry-run");
  ASSERT_EQ(f.code, 0) << f.err;
  const json fr = json::parse(f.out);
  EXPECT_EQ(fr["scene"]["digest"], api::sceneDigest(slurp(scene)));
  EXPECT_EQ(fr["outputs"][0]["aovs"], (json{"beauty", "depth"}));
  EXPECT_EQ(fr["outputs"][0]["half"], true);
}

// --camera orbit=THETA,PHI[,R]: model-viewer's camera-orbit into the request's camera.orbit; anything
// but two or three finite numbers is a usage error (exit 2).
TEST(Cli, RenderPassesAnOrbitCamera) {
  const ProcessRun r = radiant("render --builtin cornell_box -o a.png --camera \"orbit=30,75.5,3;target=0,1,0\" --dry-run");
  ASSERT_EQ(r.code, 0) << r.err;
  const json cam = json::parse(r.out)["camera"];
  EXPECT_EQ(cam["orbit"], (json{{"theta_deg", 30.0}, {"phi_deg", 75.5}, {"radius", 3.0}}));
  EXPECT_EQ(cam["target"], (json{0.0, 1.0, 0.0}));
  const json two = json::parse(radiant("render --builtin cornell_box -o a.png --camera orbit=-90,10 --dry-run").out);
  EXPECT_EQ(two["camera"]["orbit"], (json{{"theta_deg", -90.0}, {"phi_deg", 10.0}}));
  for (const char* bad : {"orbit=30", "orbit=30,75,3,4", "orbit=a,b", "orbit=30,nan", "orbit=inf,10"})
    EXPECT_EQ(radiant(std::string("render --builtin cornell_box -o a.png --camera \"") + bad + "\" --dry-run").code, 2) << bad;
}

// issue 29, item 8: --tone-map and --background become the request's tone_map and background; neither is
// sent unless given (the daemon's defaults apply), and a bad value is a usage error before any request.
TEST(Cli, RenderPassesToneMapAndBackgroundIntoTheRequest) {
  const json plain = json::parse(radiant("render --builtin cornell_box -o a.png --dry-run").out);
  EXPECT_FALSE(plain.contains("tone_map"));
  EXPECT_FALSE(plain.contains("background"));
  const ProcessRun r =
      radiant("render --builtin cornell_box -o a.png --tone-map khronos_pbr_neutral --background transparent --dry-run");
  ASSERT_EQ(r.code, 0) << r.err;
  const json req = json::parse(r.out);
  EXPECT_EQ(req["tone_map"], "khronos_pbr_neutral");
  EXPECT_EQ(req["background"], "transparent");
  const json colour =
      json::parse(radiant("render --builtin cornell_box -o a.png --background 0.25,0.5,1 --dry-run").out);
  EXPECT_EQ(colour["background"], json::array({0.25, 0.5, 1.0}));
  EXPECT_EQ(radiant("render --builtin cornell_box -o a.png --tone-map filmic --dry-run").code, 2);
  EXPECT_EQ(radiant("render --builtin cornell_box -o a.png --background 0,-1,0 --dry-run").code, 2);
  EXPECT_EQ(radiant("render --builtin cornell_box -o a.png --background black --dry-run").code, 2);
}

}  // namespace
}  // namespace radiant
