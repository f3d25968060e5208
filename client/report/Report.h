#pragma once
// `radiant report`: a self-contained HTML report (plots by gnuplot, inlined as SVG) and a Markdown
// summary of a sweep's results file. docs/SWEEPS.md describes what they contain.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace radiant::client::report {

// A table another benchmark wrote as Markdown (radiant bench --equal-error's DIR/equal_error.md,
// --fidelity's DIR/fidelity.md), shown after the sweep's sections: its paragraphs and pipe tables.
struct ExtraSection {
  std::string id, title, markdown;
};

struct Options {
  std::string metric = "rmse";      // error axis of the Pareto plots (any numeric stats.metrics key)
  std::string title = "Radiant performance report";
  std::string source;               // the results file, as named on the command line
  std::string command;              // the command that made the report
  std::string gnuplot = "gnuplot";  // executable
  std::vector<ExtraSection> extra;  // appended in order, listed in the contents
};

struct Summary {
  int records = 0, errors = 0, plots = 0;
  std::filesystem::path html, markdown;
};

// Writes DIR/report.html, DIR/report.md and DIR/plots/*.svg (the Markdown links them; the HTML
// inlines them). Throws std::runtime_error when gnuplot fails, naming the plot and its message.
Summary write(const std::vector<nlohmann::json>& records, const std::filesystem::path& dir, const Options& options);

// The HTML of the Markdown the benchmarks write: pipe tables (the first row the header, `|---|` rules
// dropped, `\|` an escaped bar) and paragraphs of the other lines, every text escaped.
std::string markdownToHtml(const std::string& markdown);

// The number format of every table: 4 significant digits at most, fixed point from 0.01 up.
std::string formatNumber(double v);

}  // namespace radiant::client::report
