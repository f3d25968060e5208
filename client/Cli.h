#pragma once
// The radiant command line, defined once with CLI11: the global options, every command with its
// options, help text and checks. main.cpp parses with it; `--help` of every command, `radiant help
// COMMAND` and `radiant completion bash` are generated from the same tree.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "client/Commands.h"

namespace radiant::client {

// The whole tree. The global options land in `g`; the parsed command's work lands in `action`.
std::unique_ptr<CLI::App> buildCli(GlobalOptions& g, Action& action);

// Parses `args` (the words after the program's name) and returns the parsed command's work, which keeps
// the tree alive. A bad command line throws UsageError; --help throws CLI::CallForHelp. For tests.
Action parseCommandLine(GlobalOptions& g, const std::vector<std::string>& args);

// A bash completion script for `radiant`: the commands, each command's options, the values of
// options that take one of a fixed set (their type name is "a|b|c"), and file names elsewhere.
std::string bashCompletion(const CLI::App& root);

// An option that may be given several times, one value each time (`--aov a --aov b`), so that a
// positional after it is not taken as another value.
inline CLI::Option* repeated(CLI::Option* o) { return o->allow_extra_args(false); }

// The type name of an option with a fixed set of values, "{draft|preview|final}": --help shows it, and
// the completion offers the values.
std::string choices(std::initializer_list<const char*> values);

}  // namespace radiant::client
