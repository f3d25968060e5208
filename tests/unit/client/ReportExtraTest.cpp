// The report's sections from sibling benchmarks (client/report/Report.h, ExtraSection): the Markdown
// those benchmarks write (radiant bench --equal-error's table) becomes HTML tables and paragraphs with
// every text escaped, and report.md / report.html carry it after the sweep's own sections.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "client/report/Report.h"

namespace radiant::client::report {
namespace {

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::string kTable =
    "Equal-error speed-up (2026-12-04, <llvmpipe>): 128x128 px,\n"
    "truth at 4096 spp.\n"
    "\n"
    "| scene | RMSE | speed-up |\n"
    "|---|---|---|\n"
    "| cornell_box | 0.1059 | 16.8x |\n"
    "| a \\| b | 1 | > 4096 (truth) |\n";

TEST(ReportExtra, MarkdownTablesAndParagraphsBecomeEscapedHtml) {
  EXPECT_EQ(markdownToHtml(kTable),
            "<p>Equal-error speed-up (2026-12-04, &lt;llvmpipe&gt;): 128x128 px, truth at 4096 spp.</p>\n"
            "<div class=\"table-wrap\"><table>\n<thead><tr><th>scene</th><th>RMSE</th><th>speed-up</th></tr></thead>\n"
            "<tbody>\n<tr><td>cornell_box</td><td>0.1059</td><td>16.8x</td></tr>\n"
            "<tr><td>a | b</td><td>1</td><td>&gt; 4096 (truth)</td></tr>\n</tbody></table></div>\n");
  EXPECT_EQ(markdownToHtml(""), "");
}

TEST(ReportExtra, ReportCarriesTheSectionInBothFormats) {
  const auto dir = std::filesystem::temp_directory_path() / ("radiant-report-extra-" + std::to_string(::getpid()));
  Options o;
  o.extra.push_back({"equal-error", "Equal-error speed-up", kTable});
  const Summary s = write({}, dir, o);
  const std::string md = slurp(s.markdown), html = slurp(s.html);
  EXPECT_NE(md.find("\n## Equal-error speed-up\n\n" + kTable), std::string::npos) << md;
  EXPECT_NE(html.find("<h2 id=\"equal-error\">Equal-error speed-up</h2>\n" + markdownToHtml(kTable)), std::string::npos);
  EXPECT_NE(html.find("<li><a href=\"#equal-error\">Equal-error speed-up</a></li>"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace radiant::client::report
