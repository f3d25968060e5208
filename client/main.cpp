// radiant: the command-line client of radiantd. See docs/API.md and `radiant help`. The command line
// is defined once in client/Cli.cpp (CLI11); each command's work is in client/commands/.
#include <cctype>
#include <iostream>

#include "client/Cli.h"

using namespace radiant::client;

namespace {

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

// The command that was parsed (the root when none was).
const CLI::App& parsedCommand(const CLI::App& root) {
  const auto parsed = root.get_subcommands();
  return parsed.empty() ? root : *parsed.front();
}

}  // namespace

int main(int argc, char** argv) {
  GlobalOptions g;
  Action action;
  const std::unique_ptr<CLI::App> app = buildCli(g, action);
  try {
    app->parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << parsedCommand(*app).help();
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    const CLI::App& cmd = parsedCommand(*app);
    std::string what = e.what();
    if (&cmd == app.get())  // no command parsed: name the word that is not one
      for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--server" || a == "--token-file") ++i;
        else if (!a.empty() && a[0] != '-') {
          what = "unknown command \"" + a + "\"";
          break;
        }
      }
    std::cerr << "radiant: " << what << "\n"
              << "usage: see `radiant " << (&cmd == app.get() ? "" : cmd.get_name() + " ") << "--help`\n";
    return kExitUsage;
  }
  const CLI::App& cmd = parsedCommand(*app);
  try {
    // The words after the command's name, as typed (sweep records them with every result).
    for (int i = 1; i < argc; ++i)
      if (cmd.get_name() == argv[i]) {
        g.commandArgs.assign(argv + i + 1, argv + argc);
        break;
      }
    if (!g.tokenFile.empty()) {
      g.token = readFile(g.tokenFile);
      while (!g.token.empty() && std::isspace(static_cast<unsigned char>(g.token.back()))) g.token.pop_back();
    }
    if (!action) throw UsageError("no command given");
    return action();
  } catch (const UsageError& e) {
    std::cerr << "radiant: " << e.what() << "\n"
              << "usage: see `radiant " << (&cmd == app.get() ? "" : cmd.get_name() + " ") << "--help`\n";
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
