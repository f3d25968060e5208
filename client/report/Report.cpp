// The report: sections per technique and context (scene, size, other non-pass parameters), each with
// the time-versus-error Pareto plot (one series and front per method, front points labelled by their
// parameters) and per-pass stacked timing bars; cost against every swept axis; the full table.
#include "client/report/Report.h"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "client/Commands.h"
#include "client/report/Thumbnails.h"
#include "client/sweep/Sweep.h"
#include "renderer/io/ImageIO.h"
#include "renderer/metrics/Metrics.h"

namespace radiant::client::report {

namespace fs = std::filesystem;
using nlohmann::json;

std::string formatNumber(double v) {
  char buf[64];
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  if (std::fabs(v) >= 1000) std::snprintf(buf, sizeof buf, "%.0f", v);
  else std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

namespace {

std::string html(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string md(const std::string& s) {
  std::string o;
  for (char c : s) o += c == '|' ? std::string("\\|") : std::string(1, c);
  return o;
}

// gnuplot string literal (single quotes: only '' needs escaping) and data cell (tab-separated).
std::string gq(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("''") : std::string(1, c);
  return o + "'";
}
std::string cell(const std::string& s) {
  std::string o;
  for (char c : s) o += (c == '\t' || c == '\n') ? ' ' : c;
  return o.empty() ? "-" : o;
}

std::string valueText(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

std::string sceneName(const json& r) {
  const json s = r["request"].value("scene", json::object());
  if (s.contains("builtin")) return s["builtin"].get<std::string>();
  if (s.contains("digest")) return s["digest"].get<std::string>().substr(0, 19);
  return "inline";
}
std::string sizeText(const json& r) {
  return std::to_string(r["request"].value("width", 256)) + "x" + std::to_string(r["request"].value("height", 256));
}

double num(const json& r, const std::string& key, const char* field = "median") {
  const json v = r.value(key, json());
  if (v.is_object() && v.contains(field) && v[field].is_number()) return v[field].get<double>();
  return std::nan("");
}
double metricOf(const json& r, const std::string& metric) {
  if (!r.contains("metrics") || !r["metrics"].is_object()) return std::nan("");
  const json v = r["metrics"].value(metric, json());
  return v.is_number() ? v.get<double>() : std::nan("");
}

bool contextPath(const std::string& path) { return path.rfind("passes.", 0) != 0; }

std::string contextOf(const json& r) {
  std::string c = sceneName(r) + " " + sizeText(r);
  for (const auto& [path, v] : r["params"].items())
    if (contextPath(path) && path.rfind("scene.", 0) != 0 && path != "width" && path != "height")
      c += " " + path + "=" + valueText(v);
  return c;
}

bool techniqueSkipped(const json& r) {
  const json sk = r.value("skipped", json::object());
  const std::string t = r.value("technique", "");
  return sk.is_object() && sk.contains(t);
}

std::string slug(const std::string& s) {
  std::string o;
  for (char c : s) o += std::isalnum(static_cast<unsigned char>(c)) ? c : '-';
  return o;
}

struct Plot {
  std::string id, title, svg, file;  // file: relative to the report dir
};

class Gnuplot {
public:
  Gnuplot(fs::path dir, std::string exe) : dir_(std::move(dir)), exe_(std::move(exe)) {
    fs::create_directories(dir_ / "plots");
  }
  // Runs `script` (terminal and output set here) with `data` in a file named by $data.
  Plot render(const std::string& id, const std::string& title, const std::string& data, const std::string& script,
              int width = 720, int height = 440) {
    const fs::path dataFile = dir_ / "plots" / (id + ".tsv");
    const fs::path svgFile = dir_ / "plots" / (id + ".svg");
    const fs::path scriptFile = dir_ / "plots" / (id + ".gp");
    writeFile(dataFile.string(), data);
    std::ostringstream gp;
    gp << "set terminal svg size " << width << "," << height
       << " fixed noenhanced font 'Helvetica,11' background rgb 'white'\n"
       << "set output " << gq(svgFile.string()) << "\n"
       << "set datafile separator '\\t'\n"
       << "data = " << gq(dataFile.string()) << "\n"
       << "set title " << gq(title) << "\n"
       << "set grid lc rgb '#dddddd'\n"
       << script;
    writeFile(scriptFile.string(), gp.str());
    const std::string cmd = exe_ + " '" + scriptFile.string() + "' 2>&1";
    FILE* pipe = ::popen(cmd.c_str(), "r");
    if (!pipe) throw std::runtime_error("cannot run " + exe_);
    std::string messages;
    char buf[512];
    while (std::fgets(buf, sizeof buf, pipe)) messages += buf;
    const int status = ::pclose(pipe);
    if (status != 0 || !fs::exists(svgFile))
      throw std::runtime_error("gnuplot failed on plot \"" + title + "\" (" + scriptFile.string() + "): " + messages);
    std::string svg = readFile(svgFile.string());
    // Inline SVGs share one id space: prefix every id and reference with the plot's id.
    svg = std::regex_replace(svg, std::regex(R"(<\?xml[^>]*>\s*)"), "");
    svg = std::regex_replace(svg, std::regex(R"(<!DOCTYPE[^>]*>\s*)"), "");
    svg = std::regex_replace(svg, std::regex(R"(\bid=(['"]))"), "id=$1" + id + "-");
    svg = std::regex_replace(svg, std::regex(R"(href=(['"])#)"), "href=$1#" + id + "-");
    svg = std::regex_replace(svg, std::regex(R"(url\(#)"), "url(#" + id + "-");
    svg = std::regex_replace(svg, std::regex(R"(<title>Gnuplot</title>)"), "<title>" + html(title) + "</title>");
    fs::remove(dataFile);
    fs::remove(scriptFile);
    return {id, title, svg, "plots/" + id + ".svg"};
  }

private:
  fs::path dir_;
  std::string exe_;
};

// Pareto front (time, error), both minimised: sorted by time, each point strictly better in error
// than every faster one.
std::vector<std::size_t> paretoFront(const std::vector<std::pair<double, double>>& pts) {
  std::vector<std::size_t> idx(pts.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    return pts[a].first != pts[b].first ? pts[a].first < pts[b].first : pts[a].second < pts[b].second;
  });
  std::vector<std::size_t> front;
  double best = INFINITY;
  for (auto i : idx)
    if (pts[i].second < best) {
      best = pts[i].second;
      front.push_back(i);
    }
  return front;
}

std::string logIfWide(const char* axis, double lo, double hi) {
  return lo > 0 && hi / lo > 20 ? std::string("set logscale ") + axis + "\n" : "";
}

struct Section {
  std::string technique, context;
  std::vector<const json*> records;
};

}  // namespace

std::string markdownToHtml(const std::string& markdown) {
  std::istringstream in(markdown);
  std::ostringstream out;
  std::vector<std::vector<std::string>> rows;
  std::string paragraph;
  auto cells = [](const std::string& line) {
    std::vector<std::string> c;
    std::string cur;
    for (std::size_t i = 1; i < line.size(); ++i) {  // after the leading '|'
      if (line[i] == '\\' && i + 1 < line.size() && line[i + 1] == '|') {
        cur += '|';
        ++i;
      } else if (line[i] == '|') {
        const auto b = cur.find_first_not_of(' '), e = cur.find_last_not_of(' ');
        c.push_back(b == std::string::npos ? "" : cur.substr(b, e - b + 1));
        cur.clear();
      } else {
        cur += line[i];
      }
    }
    return c;
  };
  auto flushTable = [&] {
    if (rows.empty()) return;
    out << "<div class=\"table-wrap\"><table>\n<thead><tr>";
    for (const auto& c : rows[0]) out << "<th>" << html(c) << "</th>";
    out << "</tr></thead>\n<tbody>\n";
    for (std::size_t r = 1; r < rows.size(); ++r) {
      out << "<tr>";
      for (const auto& c : rows[r]) out << "<td>" << html(c) << "</td>";
      out << "</tr>\n";
    }
    out << "</tbody></table></div>\n";
    rows.clear();
  };
  auto flushParagraph = [&] {
    if (!paragraph.empty()) out << "<p>" << html(paragraph) << "</p>\n";
    paragraph.clear();
  };
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '|') {
      flushParagraph();
      if (line.find_first_not_of("|-: ") == std::string::npos) continue;  // the header rule
      rows.push_back(cells(line));
    } else if (line.find_first_not_of(' ') == std::string::npos) {
      flushTable();
      flushParagraph();
    } else {
      flushTable();
      paragraph += (paragraph.empty() ? "" : " ") + line;
    }
  }
  flushTable();
  flushParagraph();
  return out.str();
}

Summary write(const std::vector<json>& all, const fs::path& dir, const Options& o) {
  fs::create_directories(dir);
  const std::vector<json> records = sweep::latestRecords(all);
  Gnuplot gnuplot(dir, o.gnuplot);
  Summary summary;
  summary.records = static_cast<int>(records.size());

  std::vector<const json*> ok;
  for (const auto& r : records)
    if (r.contains("error")) ++summary.errors;
    else ok.push_back(&r);

  // Sections, in first-appearance order.
  std::vector<Section> sections;
  for (const json* r : ok) {
    const std::string t = r->value("technique", "?"), c = contextOf(*r);
    auto it = std::find_if(sections.begin(), sections.end(), [&](const Section& s) { return s.technique == t && s.context == c; });
    if (it == sections.end()) {
      sections.push_back({t, c, {}});
      it = sections.end() - 1;
    }
    it->records.push_back(r);
  }
  // Metric columns present anywhere.
  std::vector<std::string> metricKeys;
  for (const char* k : {"rmse", "rel_mse", "psnr", "ssim", "mean_abs", "max_abs"})
    for (const json* r : ok)
      if (std::isfinite(metricOf(*r, k))) {
        metricKeys.push_back(k);
        break;
      }

  std::ostringstream body, mdBody;
  std::ostringstream toc;
  int plotCounter = 0;
  auto nextId = [&](const std::string& kind) { return kind + "-" + std::to_string(++plotCounter); };
  auto figure = [&](const Plot& p, const std::string& caption) {
    ++summary.plots;
    body << "<figure id=\"" << p.id << "\" data-plot=\"" << html(p.title) << "\">" << p.svg << "<figcaption>"
         << html(caption) << "</figcaption></figure>\n";
    mdBody << "![" << md(p.title) << "](" << p.file << ")\n\n";
  };

  // The Pareto points' pictures: the frame, its error in false colour (one scale for the section, the
  // largest error among them) and the reference once, from the thumbnails the sweep kept.
  int thumbCounter = 0;
  auto thumbnails = [&](const std::vector<std::pair<const json*, std::string>>& front, const auto& label) {
    struct Shown {
      const json* r;
      std::string method;
      Thumbnail t;
    };
    std::vector<Shown> shown;
    for (const auto& [r, method] : front) {
      const json t = r->value("thumbnail", json());
      if (!t.is_object() || !t.contains("file")) continue;
      try {
        shown.push_back({r, method, readThumbnail(t["file"].get<std::string>(), t.value("aov", "beauty"))});
      } catch (const std::exception&) {  // moved or deleted: the report goes on without it
      }
    }
    if (shown.empty()) return;
    double scale = 0;
    for (const auto& sh : shown)
      for (float v : sh.t.error.pixels) scale = std::max(scale, double(v));
    fs::create_directories(dir / "thumbs");
    auto png = [&](const Image& img, const std::string& name, bool falseColour) {
      std::string bytes;
      if (falseColour) {
        Image colour = metrics::falseColour(img, scale);
        for (float& v : colour.pixels) v = io::srgbToLinear(v);  // the PNG encoder applies the sRGB transfer
        bytes = io::encodePng(colour, 0.f, 9);
      } else {
        bytes = io::encodePng(img, 0.f, 9);
      }
      writeFile((dir / "thumbs" / name).string(), bytes);
      return bytes;
    };
    auto img = [&](const std::string& bytes, const std::string& point, const std::string& kind, const std::string& alt) {
      return "<img class=\"thumb\" data-point=\"" + html(point) + "\" data-kind=\"" + kind + "\" alt=\"" + html(alt) +
             "\" width=\"128\" src=\"" + pngDataUri(bytes) + "\">";
    };
    const std::string id = "thumbs-" + std::to_string(++thumbCounter);
    const Shown& first = shown.front();
    // One row each: frames, error maps, and the reference, once per method (an AO method's reference
    // is its own AO definition's).
    body << "<figure id=\"" << id << "\" class=\"thumbs\"><table class=\"thumbs\"><tr><th></th>";
    mdBody << "| |";
    for (const auto& sh : shown) {
      const std::string l = (sh.method.empty() ? "" : sh.method + " ") + label(*sh.r);
      body << "<th>" << html(l) << "<br><span class=\"n\" data-key=\"frame_gpu_ms.median\">"
           << formatNumber(num(*sh.r, "frame_gpu_ms")) << "</span> ms, " << html(o.metric)
           << " <span class=\"n\" data-key=\"metric\">" << formatNumber(metricOf(*sh.r, o.metric)) << "</span></th>";
      mdBody << " " << md(l) << " |";
    }
    mdBody << "\n|---|";
    for (std::size_t i = 0; i < shown.size(); ++i) mdBody << "---|";
    body << "</tr>\n<tr><td class=\"note\">frame</td>";
    mdBody << "\n| frame |";
    std::string errorRow = "<tr><td class=\"note\">error (false colour, 0.." + formatNumber(scale) + ")</td>";
    std::string referenceRow = "<tr><td class=\"note\">reference</td>";
    std::string mdErrors = "| error 0.." + formatNumber(scale) + " |", mdReferences = "| reference |";
    for (std::size_t i = 0; i < shown.size(); ++i) {
      const Shown& sh = shown[i];
      const std::string point = sh.r->value("point_id", "");
      const std::string frameName = id + "-" + point + "-frame.png", errorName = id + "-" + point + "-error.png";
      body << "<td>" << img(png(sh.t.frame, frameName, false), point, "frame", "frame " + point) << "</td>";
      errorRow += "<td>" + img(png(sh.t.error, errorName, true), point, "error", "error " + point) + "</td>";
      mdBody << " ![frame](thumbs/" << frameName << ") |";
      mdErrors += " ![error](thumbs/" + errorName + ") |";
      if (i == 0 || shown[i - 1].method != sh.method) {
        const std::string refName = id + "-" + point + "-reference.png";
        referenceRow += "<td>" + img(png(sh.t.reference, refName, false), point, "reference", "reference " + sh.method) + "</td>";
        mdReferences += " ![reference](thumbs/" + refName + ") |";
      } else {
        referenceRow += "<td></td>";
        mdReferences += " |";
      }
    }
    body << "</tr>\n" << errorRow << "</tr>\n" << referenceRow << "</tr></table><figcaption>" << html(
        "The Pareto points' frames (" + std::string(first.t.frame.aov) + ", exposure 0, box-filtered to at most " +
        std::to_string(kThumbnailPx) + " px) and their per-pixel error against the reference, in false colour (viridis, "
        "dark = 0, yellow = " + formatNumber(scale) + ", the largest error shown), and the reference each method is "
        "scored against.") << "</figcaption></figure>\n";
    mdBody << "\n" << mdErrors << "\n" << mdReferences << "\n\n";
  };

  // Per section: Pareto plot and stacked pass timings.
  body << "<h2 id=\"sections\">Time against error, and where the time goes</h2>\n";
  mdBody << "## Time against error\n\n";
  for (const auto& s : sections) {
    const std::string anchor = "section-" + slug(s.technique + "-" + s.context);
    toc << "<li><a href=\"#" << anchor << "\">" << html(s.technique + " — " + s.context) << "</a></li>\n";
    body << "<section id=\"" << anchor << "\" data-technique=\"" << html(s.technique) << "\"><h3>"
         << html(s.technique) << " <small>" << html(s.context) << "</small></h3>\n<div class=\"plots\">\n";
    mdBody << "### " << md(s.technique) << " — " << md(s.context) << "\n\n";
    // Parameters that vary within the section label its points; the method names the series.
    const std::string methodParam = s.records.front()->value("method_param", "");
    std::set<std::string> varying;
    std::map<std::string, std::set<std::string>> values;
    for (const json* r : s.records)
      for (const auto& [path, v] : (*r)["params"].items()) values[path].insert(v.dump());
    for (const auto& [path, vs] : values)
      if (vs.size() > 1 && path != methodParam && !contextPath(path)) varying.insert(path);
    auto label = [&](const json& r) {
      json shown = json::object();
      for (const auto& [path, v] : r["params"].items())
        if (varying.count(path)) shown[path] = v;
      std::string l = sweep::paramLabel(shown);
      return l.empty() ? (r.value("method", "").empty() ? std::string("default") : r.value("method", "")) : l;
    };
    std::vector<std::string> methods;
    for (const json* r : s.records)
      if (std::find(methods.begin(), methods.end(), r->value("method", "")) == methods.end())
        methods.push_back(r->value("method", ""));

    // Pareto.
    std::ostringstream data, plot;
    std::vector<std::string> frontRows;
    std::vector<std::pair<const json*, std::string>> frontRecords;  // with their method
    double xlo = INFINITY, xhi = 0, ylo = INFINITY, yhi = 0;
    int blocks = 0;
    std::vector<std::string> plotCmds;
    for (std::size_t m = 0; m < methods.size(); ++m) {
      std::vector<std::pair<double, double>> pts;
      std::vector<const json*> rs;
      for (const json* r : s.records) {
        if (r->value("method", "") != methods[m] || techniqueSkipped(*r)) continue;
        const double x = num(*r, "frame_gpu_ms"), y = metricOf(*r, o.metric);
        if (!std::isfinite(x) || !std::isfinite(y)) continue;
        pts.push_back({x, y});
        rs.push_back(r);
        xlo = std::min(xlo, x), xhi = std::max(xhi, x), ylo = std::min(ylo, y), yhi = std::max(yhi, y);
      }
      if (pts.empty()) continue;
      const auto front = paretoFront(pts);
      for (const auto& p : pts) data << p.first << "\t" << p.second << "\n";
      data << "\n\n";
      for (auto i : front) {
        frontRecords.push_back({rs[i], methods[m]});
        data << pts[i].first << "\t" << pts[i].second << "\t" << cell(label(*rs[i])) << "\n";
        frontRows.push_back("| " + md(methods[m].empty() ? "-" : methods[m]) + " | " + md(label(*rs[i])) + " | " +
                            formatNumber(pts[i].first) + " | " + formatNumber(pts[i].second) + " | `" +
                            rs[i]->value("point_id", "") + "` |");
      }
      data << "\n\n";
      const std::string name = methods[m].empty() ? s.technique : methods[m];
      const int lt = static_cast<int>(m) + 1;
      plotCmds.push_back("data index " + std::to_string(blocks) + " using 1:2 with points pt 7 ps 0.7 lt " +
                         std::to_string(lt) + " title " + gq(name));
      plotCmds.push_back("data index " + std::to_string(blocks + 1) + " using 1:2 with lines lw 1.5 lt " +
                         std::to_string(lt) + " notitle");
      plotCmds.push_back("data index " + std::to_string(blocks + 1) +
                         " using 1:2:3 with labels offset char 0.6,0.6 left font ',9' tc lt " + std::to_string(lt) +
                         " notitle");
      blocks += 2;
    }
    if (!plotCmds.empty()) {
      plot << "set xlabel 'frame GPU time, median over repeats (ms)'\nset ylabel " << gq(o.metric + " against the reference")
           << "\nset key outside right top\nset offsets graph 0.05, graph 0.25, graph 0.08, graph 0.08\n"
           << logIfWide("x", xlo, xhi) << logIfWide("y", ylo, yhi) << "plot ";
      for (std::size_t i = 0; i < plotCmds.size(); ++i) plot << (i ? ", \\\n  " : "") << plotCmds[i];
      plot << "\n";
      const Plot p = gnuplot.render(nextId("pareto"), "Pareto front: " + s.technique + ", " + s.context, data.str(), plot.str());
      figure(p, "Each point is one configuration (median frame time over the repeats, " + o.metric +
                    " of the compare run); lines join each method's Pareto front, whose points are labelled.");
      mdBody << "| method | parameters | frame GPU ms | " << md(o.metric) << " | point |\n|---|---|---|---|---|\n";
      for (const auto& row : frontRows) mdBody << row << "\n";
      mdBody << "\n";
      thumbnails(frontRecords, label);
    } else if (std::all_of(s.records.begin(), s.records.end(), [](const json* r) { return techniqueSkipped(*r); })) {
      const std::string why = valueText((*s.records.front())["skipped"][s.technique]);
      body << "<p class=\"note\">The planner skipped " << html(s.technique) << " here: " << html(why)
           << ". The timings below are of the other passes.</p>\n";
      mdBody << "Skipped by the planner: " << md(why) << ".\n\n";
    } else {
      body << "<p class=\"note\">No error metrics in these records (sweep without <code>compare</code>), so no Pareto plot.</p>\n";
      mdBody << "No error metrics (sweep without `compare`).\n\n";
    }

    // Stacked per-pass GPU time.
    std::vector<std::string> passNames;
    for (const json* r : s.records)
      for (const auto& p : r->value("passes", json::array()))
        if (std::find(passNames.begin(), passNames.end(), p.value("name", "")) == passNames.end())
          passNames.push_back(p.value("name", ""));
    if (!passNames.empty()) {
      std::vector<const json*> sorted = s.records;
      std::stable_sort(sorted.begin(), sorted.end(), [&](const json* a, const json* b) {
        return a->value("method", "") < b->value("method", "");
      });
      std::ostringstream bars, bp;
      for (const json* r : sorted) {
        const std::string m = r->value("method", "");
        const std::string l = label(*r);
        bars << cell(m.empty() || l == m ? l : m + " " + l);
        for (const auto& name : passNames) {
          double v = 0;
          for (const auto& p : r->value("passes", json::array()))
            if (p.value("name", "") == name) v = p["gpu_ms"].value("median", 0.0);
          bars << "\t" << v;
        }
        bars << "\n";
      }
      bp << "set style data histograms\nset style histogram rowstacked\nset style fill solid 0.85 border rgb '#333333'\n"
         << "set boxwidth 0.7\nset ylabel 'GPU ms, median over repeats'\nset key outside right top\n"
         << "set xtics rotate by -40 left font ',9'\nset yrange [0:*]\nset bmargin 8\nplot ";
      for (std::size_t i = 0; i < passNames.size(); ++i)
        bp << (i ? ", \\\n  " : "") << "data using " << i + 2 << (i == 0 ? ":xtic(1)" : "") << " title "
           << gq(passNames[i]);
      bp << "\n";
      const int w = std::max(720, 160 + 28 * static_cast<int>(sorted.size()));
      const Plot p = gnuplot.render(nextId("passes"), "GPU time per pass: " + s.technique + ", " + s.context, bars.str(),
                                    bp.str(), w, 460);
      figure(p, "Median GPU time of every pass, stacked, per configuration.");
    }
    body << "</div></section>\n";
  }

  // Cost against each swept axis, per technique.
  body << "<h2 id=\"axes\">Cost against each swept axis</h2>\n<div class=\"plots\">\n";
  mdBody << "## Cost against each swept axis\n\n";
  std::vector<std::string> techniques;
  for (const json* r : ok)
    if (std::find(techniques.begin(), techniques.end(), r->value("technique", "")) == techniques.end())
      techniques.push_back(r->value("technique", ""));
  int axisPlots = 0;
  for (const auto& t : techniques) {
    std::vector<const json*> rs;
    for (const json* r : ok)
      if (r->value("technique", "") == t) rs.push_back(r);
    std::vector<std::vector<std::string>> factors;  // first path names the axis
    for (const json* r : rs)
      for (const auto& f : r->value("factors", json::array())) {
        std::vector<std::string> paths = f.get<std::vector<std::string>>();
        if (!paths.empty() && std::find(factors.begin(), factors.end(), paths) == factors.end()) factors.push_back(paths);
      }
    for (const auto& f : factors) {
      const std::string axis = f.front();
      std::vector<const json*> has;
      std::vector<json> xs;
      bool numeric = true;
      for (const json* r : rs)
        if ((*r)["params"].contains(axis)) {
          has.push_back(r);
          const json& v = (*r)["params"][axis];
          if (std::find(xs.begin(), xs.end(), v) == xs.end()) xs.push_back(v);
          numeric = numeric && v.is_number();
        }
      if (xs.size() < 2) continue;
      if (numeric) std::sort(xs.begin(), xs.end(), [](const json& a, const json& b) { return a.get<double>() < b.get<double>(); });
      auto xOf = [&](const json& v) {
        return numeric ? v.get<double>() : static_cast<double>(std::find(xs.begin(), xs.end(), v) - xs.begin());
      };
      // Series: every combination of the other parameters (and context); by method when too many.
      auto seriesKey = [&](const json& r, bool byMethod) {
        if (byMethod) return r.value("method", "").empty() ? t : r.value("method", "");
        json other = json::object();
        for (const auto& [path, v] : r["params"].items())
          if (std::find(f.begin(), f.end(), path) == f.end()) other[path] = v;
        std::string k = sweep::paramLabel(other);
        return k.empty() ? t : k;
      };
      std::set<std::string> keys;
      for (const json* r : has) keys.insert(seriesKey(*r, false));
      const bool byMethod = keys.size() > 8;
      std::map<std::string, std::map<double, std::vector<double>>> series;
      std::vector<std::string> order;
      for (const json* r : has) {
        const std::string k = seriesKey(*r, byMethod);
        if (!series.count(k)) order.push_back(k);
        series[k][xOf((*r)["params"][axis])].push_back(num(*r, "frame_gpu_ms"));
      }
      std::ostringstream data, gp;
      double ylo = INFINITY, yhi = 0;
      for (const auto& k : order) {
        for (const auto& [x, ys] : series[k]) {
          const double y = sweep::summarize(ys)["median"].get<double>();
          ylo = std::min(ylo, y), yhi = std::max(yhi, y);
          data << x << "\t" << y << "\n";
        }
        data << "\n\n";
      }
      std::string axisName = axis;
      if (f.size() > 1) {
        axisName += " (with";
        for (std::size_t i = 1; i < f.size(); ++i) axisName += " " + f[i];
        axisName += ")";
      }
      gp << "set xlabel " << gq(axisName) << "\nset ylabel 'frame GPU ms, median'\n"
         << (order.size() > 1 ? "set key outside right top font ',9'\n" : "unset key\n") << logIfWide("y", ylo, yhi);
      if (!numeric) {
        gp << "set xtics (";
        for (std::size_t i = 0; i < xs.size(); ++i) gp << (i ? ", " : "") << gq(valueText(xs[i])) << " " << i;
        gp << ")\nset xrange [-0.5:" << xs.size() - 0.5 << "]\n";
      } else {
        gp << logIfWide("x", xs.front().get<double>(), xs.back().get<double>());
        gp << "set offsets graph 0.03, graph 0.03, 0, 0\n";
      }
      gp << "plot ";
      for (std::size_t i = 0; i < order.size(); ++i)
        gp << (i ? ", \\\n  " : "") << "data index " << i << " using 1:2 with linespoints pt 7 ps 0.6 lt " << i + 1
           << " title " << gq(order[i]);
      gp << "\n";
      const Plot p = gnuplot.render(nextId("axis"), "Cost against " + axis + ": " + t, data.str(), gp.str());
      figure(p, std::string("Median frame GPU time against ") + axisName + (byMethod ? ", median over the other parameters per method." : "; one line per setting of the other parameters."));
      ++axisPlots;
    }
  }
  body << "</div>\n";
  if (axisPlots == 0) {
    body << "<p class=\"note\">No axis with two or more values.</p>\n";
    mdBody << "No axis with two or more values.\n\n";
  }

  // The full table.
  std::vector<std::string> paramPaths;
  for (const auto& r : records)
    for (const auto& f : r.value("factors", json::array()))
      for (const auto& p : f)
        if (std::find(paramPaths.begin(), paramPaths.end(), p.get<std::string>()) == paramPaths.end())
          paramPaths.push_back(p.get<std::string>());
  struct Column {
    std::string key, head;
  };
  std::vector<Column> cols{{"point", "point"}, {"technique", "technique"}, {"method", "method"}, {"scene", "scene"},
                           {"size", "size"}};
  for (const auto& p : paramPaths)
    if (p.rfind("scene.", 0) != 0 && p != "width" && p != "height") cols.push_back({"param:" + p, p});
  for (const auto& c : std::vector<Column>{{"frame_gpu_ms.median", "GPU ms median"},
                                           {"frame_gpu_ms.min", "GPU ms min"},
                                           {"frame_gpu_ms.max", "GPU ms max"},
                                           {"frame_cpu_ms.median", "CPU ms median"},
                                           {"render_ms.median", "render ms"},
                                           {"latency_ms.median", "end-to-end ms"}})
    cols.push_back(c);
  for (const auto& m : metricKeys) cols.push_back({"metric:" + m, m});
  cols.push_back({"notes", "notes"});
  auto cellOf = [&](const json& r, const Column& c) -> std::pair<std::string, bool> {  // text, numeric
    if (c.key == "point") return {r.value("point_id", ""), false};
    if (c.key == "technique" || c.key == "method") return {r.value(c.key, ""), false};
    if (c.key == "scene") return {sceneName(r), false};
    if (c.key == "size") return {sizeText(r), false};
    if (c.key.rfind("param:", 0) == 0) {
      const json v = r["params"].value(c.key.substr(6), json());
      return {v.is_null() ? "" : valueText(v), false};
    }
    if (c.key.rfind("metric:", 0) == 0) {
      const double v = metricOf(r, c.key.substr(7));
      return {std::isfinite(v) ? formatNumber(v) : "", true};
    }
    if (c.key == "notes") {
      if (r.contains("error"))
        return {"error " + std::to_string(r["error"].value("status", 0)) + ": " + r["error"].value("detail", ""), false};
      std::string n;
      const json skipped = r.value("skipped", json::object());
      const json requested = r["request"].value("passes", json::object());
      for (const auto& [pass, why] : skipped.items())
        if (requested.contains(pass)) n += (n.empty() ? "" : "; ") + pass + " skipped: " + valueText(why);
      return {n, false};
    }
    const auto dot = c.key.find('.');
    const double v = num(r, c.key.substr(0, dot), c.key.substr(dot + 1).c_str());
    return {std::isfinite(v) ? formatNumber(v) : "", true};
  };
  body << "<h2 id=\"table\">All points</h2>\n<div class=\"table-wrap\"><table id=\"results\">\n<thead><tr>";
  for (const auto& c : cols) body << "<th data-key=\"" << html(c.key) << "\">" << html(c.head) << "</th>";
  body << "</tr></thead>\n<tbody>\n";
  mdBody << "## All points\n\n|";
  for (const auto& c : cols) mdBody << " " << md(c.head) << " |";
  mdBody << "\n|";
  for (std::size_t i = 0; i < cols.size(); ++i) mdBody << "---|";
  mdBody << "\n";
  for (const auto& r : records) {
    body << "<tr data-point=\"" << html(r.value("point_id", "")) << "\"" << (r.contains("error") ? " class=\"error\"" : "")
         << ">";
    mdBody << "|";
    for (const auto& c : cols) {
      const auto [text, numeric] = cellOf(r, c);
      body << "<td data-key=\"" << html(c.key) << "\"" << (numeric ? " class=\"n\"" : "") << ">" << html(text) << "</td>";
      mdBody << " " << md(text) << " |";
    }
    body << "</tr>\n";
    mdBody << "\n";
  }
  body << "</tbody></table></div>\n";
  std::ostringstream extraToc;
  for (const ExtraSection& e : o.extra) {
    body << "<h2 id=\"" << html(e.id) << "\">" << html(e.title) << "</h2>\n" << markdownToHtml(e.markdown);
    mdBody << "\n## " << e.title << "\n\n" << e.markdown << (e.markdown.empty() || e.markdown.back() == '\n' ? "" : "\n");
    extraToc << "<li><a href=\"#" << html(e.id) << "\">" << html(e.title) << "</a></li>";
  }

  // Header: where the numbers come from.
  std::set<std::string> devices, commands, servers;
  std::string first, last;
  for (const auto& r : records) {
    const json d = r.value("device", json());
    if (d.is_object())
      devices.insert(d.value("renderer", "?") + " — " + d.value("vendor", "?") + ", OpenGL " + d.value("version", "?"));
    if (!r.value("command", "").empty()) commands.insert(r.value("command", ""));
    servers.insert(r.value("server", ""));
    const std::string f = r.value("finished", "");
    if (!f.empty() && (first.empty() || f < first)) first = f;
    if (!f.empty() && (last.empty() || f > last)) last = f;
  }
  char made[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(made, sizeof made, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::ostringstream head, mdHead;
  head << "<dl class=\"meta\">\n<dt>Device</dt>";
  for (const auto& d : devices) head << "<dd class=\"device\">" << html(d) << "</dd>";
  head << "\n<dt>Measured</dt><dd class=\"date\">" << html(first) << (first != last ? " to " + html(last) : "")
       << "</dd>\n<dt>Servers</dt>";
  for (const auto& s : servers) head << "<dd>" << html(s) << "</dd>";
  head << "\n<dt>Produced by</dt>";
  for (const auto& c : commands) head << "<dd class=\"command\"><code>" << html(c) << "</code></dd>";
  head << "\n<dt>Report</dt><dd><code>" << html(o.command) << "</code> from <code>" << html(o.source) << "</code>, "
       << made << "</dd>\n<dt>Points</dt><dd>" << records.size() << " (" << summary.errors << " failed), error metric "
       << html(o.metric) << ", times are medians over each point's repeats</dd>\n</dl>\n";
  mdHead << "# " << o.title << "\n\n";
  for (const auto& d : devices) mdHead << "- Device: " << d << "\n";
  mdHead << "- Measured: " << first << (first != last ? " to " + last : "") << "\n";
  for (const auto& c : commands) mdHead << "- Produced by: `" << c << "`\n";
  mdHead << "- Report: `" << o.command << "` from `" << o.source << "`, " << made << "\n";
  mdHead << "- Points: " << records.size() << " (" << summary.errors << " failed); error metric " << o.metric
         << "; times are medians over each point's repeats; full interactive-free report in report.html\n\n";

  std::ostringstream page;
  page << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" << html(o.title) << "</title>\n"
       << "<style>\n"
          "body{font-family:system-ui,-apple-system,'Segoe UI',Helvetica,Arial,sans-serif;margin:24px;color:#222;max-width:1600px}\n"
          "h1{margin-bottom:4px} h3 small{font-weight:normal;color:#666}\n"
          "dl.meta{display:grid;grid-template-columns:max-content 1fr;gap:2px 12px} dl.meta dt{font-weight:600}"
          " dl.meta dd{margin:0} dl.meta dd+dd{grid-column:2}\n"
          ".plots{display:flex;flex-wrap:wrap;gap:12px} figure{margin:0;border:1px solid #ddd;padding:6px;background:#fff}"
          " figure svg{max-width:100%;height:auto;display:block} figcaption{font-size:12px;color:#555;max-width:720px}\n"
          "table{border-collapse:collapse;font-size:12px} th,td{border:1px solid #ccc;padding:2px 6px;text-align:left}"
          " td.n{text-align:right;font-variant-numeric:tabular-nums} tr.error td{background:#fde8e8}"
          " thead th{background:#f0f0f0;position:sticky;top:0}\n"
          ".note{color:#666;font-style:italic} .table-wrap{overflow-x:auto;max-width:100%}\n"
          "table.thumbs td,table.thumbs th{border:none;vertical-align:top;font-size:11px;font-weight:normal}"
          " img.thumb{image-rendering:pixelated;display:block}\n"
          "</style></head>\n<body>\n<h1>"
       << html(o.title) << "</h1>\n"
       << head.str() << "<nav><ul>\n" << toc.str() << "<li><a href=\"#axes\">Cost against each axis</a></li>"
       << "<li><a href=\"#table\">All points</a></li>" << extraToc.str() << "</ul></nav>\n"
       << body.str() << "</body></html>\n";
  summary.html = dir / "report.html";
  summary.markdown = dir / "report.md";
  writeFile(summary.html.string(), page.str());
  writeFile(summary.markdown.string(), mdHead.str() + mdBody.str());
  return summary;
}

}  // namespace radiant::client::report
