// radiant: the command-line client of radiantd. See docs/API.md and `radiant help`.
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>

#include "client/Commands.h"

using namespace radiant::client;

namespace {

const char* kMainUsage = R"(usage: radiant [--server URL] [--token-file FILE] COMMAND [ARGS]
commands:
  render   render a scene file or a built-in scene to an EXR or PNG (radiant render --help)
  info     server version, device, limits, techniques and their parameters [--json]
  scenes   built-in and uploaded scenes [--json]
  sweep    run a parameter sweep spec into a JSON Lines results file (radiant sweep --help)
  report   HTML + Markdown report of sweep results (radiant report --help)
  bench    the standard benchmark suite, or --service for the service's own overhead (radiant bench --help)
  compare  metrics and a false-colour error image of two images from anywhere (radiant compare --help)
The server is --server, else $RADIANT_SERVER, else http://127.0.0.1:8080. A bearer token is read from
--token-file or $RADIANT_TOKEN_FILE.
exit codes: 0 ok, 2 usage, 3 error reported by the server, 4 server unreachable, 130 interrupted
)";

void printProblem(const ServerError& e) {
  const auto& p = e.problem;
  std::cerr << "radiant: server error " << e.status;
  if (p.contains("title")) std::cerr << " (" << p["title"].get<std::string>() << ")";
  std::cerr << ": " << p.value("detail", std::string(e.what())) << "\n";
  if (p.contains("pointer")) std::cerr << "  at " << p["pointer"].get<std::string>() << "\n";
  if (p.contains("request_id")) std::cerr << "  request id " << p["request_id"].get<std::string>() << "\n";
  if (p.contains("render_id") && !p["render_id"].get<std::string>().empty())
    std::cerr << "  render id " << p["render_id"].get<std::string>() << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  const std::map<std::string, std::function<int(const GlobalOptions&, const std::vector<std::string>&)>> commands{
      {"render", cmdRender}, {"info", cmdInfo}, {"scenes", cmdScenes},
      {"sweep", cmdSweep},   {"report", cmdReport}, {"bench", cmdBench}, {"compare", cmdCompare}};
  GlobalOptions g;
  const char* env = std::getenv("RADIANT_SERVER");
  g.server = env && *env ? env : "http://127.0.0.1:8080";
  std::string tokenFile = std::getenv("RADIANT_TOKEN_FILE") ? std::getenv("RADIANT_TOKEN_FILE") : "";
  try {
    int i = 1;
    for (; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--server" && i + 1 < argc) g.server = argv[++i];
      else if (a.rfind("--server=", 0) == 0) g.server = a.substr(9);
      else if (a == "--token-file" && i + 1 < argc) tokenFile = argv[++i];
      else if (a == "--help" || a == "-h" || a == "help") {
        std::cout << kMainUsage;
        return kExitOk;
      } else if (!a.empty() && a[0] == '-') throw UsageError("unknown option " + a);
      else break;
    }
    if (i >= argc) throw UsageError("no command given");
    auto cmd = commands.find(argv[i]);
    if (cmd == commands.end()) throw UsageError(std::string("unknown command \"") + argv[i] + "\"");
    if (!tokenFile.empty()) {
      g.token = readFile(tokenFile);
      while (!g.token.empty() && std::isspace(static_cast<unsigned char>(g.token.back()))) g.token.pop_back();
    }
    return cmd->second(g, std::vector<std::string>(argv + i + 1, argv + argc));
  } catch (const UsageError& e) {
    std::cerr << "radiant: " << e.what() << "\n";
    if (std::string(e.what()).find("usage:") == std::string::npos) std::cerr << kMainUsage;
    return kExitUsage;
  } catch (const ServerError& e) {
    printProblem(e);
    return kExitServerError;
  } catch (const UnreachableError& e) {
    std::cerr << "radiant: " << e.what() << "\n";
    return kExitUnreachable;
  } catch (const std::exception& e) {
    std::cerr << "radiant: " << e.what() << "\n";
    return 1;
  }
}
