// surge report DIR: DIR/report.html, one page to look at a run: what it was, plots over time of stats.csv (density
// error, energy, iterations, particles, time a frame) and of the fluid's forces on each body and collider
// (bodies.csv, colliders.csv) as inline SVG, the contact sheet embedded as a PNG in base64, and the video beside
// it by its relative path (an mp4 of a run is megabytes; the page stays small and the browser streams it).
#include <cmath>
#include <cstdlib>
#include <map>
#include <ostream>
#include <tuple>

#include "apps/commands.h"
#include "apps/svg_plot.h"
#include "core/errors.h"
#include "render/contact_sheet.h"

namespace surge {
namespace {

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string text;
  text.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t word = 0;
    for (size_t k = 0; k < 3; ++k) word = (word << 8) | (k < n ? uint8_t(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) text += k <= n ? digits[(word >> (18 - 6 * k)) & 63] : '=';
  }
  return text;
}

double number(const std::string& field) {
  return field.empty() ? NAN : std::atof(field.c_str());
}

// One column of a table as numbers, scaled; NaN where a row leaves it empty, all NaN where there is no column.
std::vector<double> column(const CsvTable& table, const std::string& name, double scale = 1) {
  const int c = table.column(name);
  std::vector<double> values(table.rows.size(), NAN);
  if (c >= 0)
    for (size_t r = 0; r < table.rows.size(); ++r) values[r] = number(table.rows[r][size_t(c)]) * scale;
  return values;
}

// The plots of stats.csv: those whose columns the table has.
std::string statsPlots(const CsvTable& stats) {
  const std::vector<double> time = column(stats, "time");
  struct Plot {
    PlotLabels labels;
    std::vector<std::pair<std::string, double>> columns;  // name and scale
  };
  const std::vector<Plot> plots = {
      {{"Density error", "time (s)", "%"}, {{"density_error_avg", 100}, {"density_error_max", 100}}},
      {{"Energy", "time (s)", "J"}, {{"kinetic_energy", 1}, {"potential_energy", 1}}},
      {{"Solver iterations a substep", "time (s)", "iterations"}, {{"iterations", 1}}},
      {{"Particles", "time (s)", "particles"}, {{"particles", 1}}},
      {{"Wall time a frame", "time (s)", "s"}, {{"wall_seconds", 1}}}};
  std::string html;
  for (const Plot& plot : plots) {
    std::vector<PlotSeries> series;
    for (const auto& [name, scale] : plot.columns)
      if (stats.column(name) >= 0) series.push_back({name, time, column(stats, name, scale)});
    if (!series.empty()) html += svgLinePlot(plot.labels, series);
  }
  return html;
}

// A plot of fx, fy, fz a body or collider of bodies.csv or colliders.csv (`key` its name column).
std::string forcePlots(const CsvTable& table, const std::string& key, double fps) {
  std::map<std::string, std::vector<size_t>> rowsOf;
  std::vector<std::string> order;
  const int name = table.column(key), frame = table.column("frame");
  if (name < 0 || frame < 0) return "";
  for (size_t r = 0; r < table.rows.size(); ++r) {
    const std::string& object = table.rows[r][size_t(name)];
    if (!rowsOf.count(object)) order.push_back(object);
    rowsOf[object].push_back(r);
  }
  std::string html;
  for (const std::string& object : order) {
    std::vector<PlotSeries> series;
    for (const char* axis : {"fx", "fy", "fz"}) {
      const int c = table.column(axis);
      if (c < 0) continue;
      PlotSeries s{axis, {}, {}};
      for (size_t r : rowsOf[object]) {
        s.x.push_back(number(table.rows[r][size_t(frame)]) / fps);
        s.y.push_back(number(table.rows[r][size_t(c)]));
      }
      series.push_back(std::move(s));
    }
    html += svgLinePlot({"Fluid force on " + object, "time (s)", "N"}, series);
  }
  return html;
}

std::string summary(const Scene& scene, const CsvTable& stats) {
  double wall = 0;
  for (double s : column(stats, "wall_seconds"))
    if (std::isfinite(s)) wall += s;
  const std::vector<double> particles = column(stats, "particles");
  char text[512];
  std::snprintf(text, sizeof text,
                "<table><tr><td>scene</td><td>%s (%dD, %s)</td></tr><tr><td>frames</td><td>%zu at %g fps</td></tr>"
                "<tr><td>particles</td><td>%.0f at the last frame</td></tr><tr><td>simulation time</td>"
                "<td>%.1f s wall</td></tr></table>\n",
                escapeXml(scene.name).c_str(), scene.dimensions, escapeXml(scene.solver.method).c_str(),
                stats.rows.size(), scene.output.fps, particles.empty() ? 0.0 : particles.back(), wall);
  return text;
}

// Writes dir/report.html and returns its path. Throws InputError naming dir/stats.csv when the run has none.
fs::path writeReport(const fs::path& dir, const Scene& scene) {
  std::error_code error;
  const fs::path statsPath = dir / "stats.csv";
  if (!fs::exists(statsPath, error)) throw InputError(statsPath.string(), "missing: not an output folder of surge sim");
  const CsvTable stats = readCsvTable(statsPath);
  std::string html =
      "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>surge report: " + escapeXml(scene.name) +
      "</title>\n<style>body{font-family:sans-serif;margin:16px;background:#fff;color:#222}"
      ".plots{display:flex;flex-wrap:wrap;gap:8px}td{padding:1px 10px 1px 0}"
      "img,video{max-width:100%}</style></head>\n<body>\n<h1>" +
      escapeXml(scene.name) + "</h1>\n" + summary(scene, stats);
  html += "<h2>Over time</h2>\n<div class=\"plots\" id=\"stats\">\n" + statsPlots(stats) + "</div>\n";
  for (const auto& [file, key, title] :
       {std::tuple<const char*, const char*, const char*>{"bodies.csv", "body", "Bodies"},
        {"colliders.csv", "collider", "Colliders"}}) {
    if (!fs::exists(dir / file, error)) continue;
    html += std::string("<h2>") + title + ": the fluid's force</h2>\n<div class=\"plots\">\n" +
            forcePlots(readCsvTable(dir / file), key, scene.output.fps) + "</div>\n";
  }
  // The contact sheet: made from frames/ when it is missing and there are frames to make it of.
  fs::path sheet = dir / (scene.name + "_contact_sheet.png");
  if (!fs::exists(sheet, error) && !listFrames(dir, "frames", "png").empty()) sheet = makeContactSheet(dir, scene);
  html += "<h2>Frames</h2>\n";
  html += fs::exists(sheet, error)
              ? "<img alt=\"contact sheet\" src=\"data:image/png;base64," + base64(readTextFile(sheet)) + "\">\n"
              : "<p>No frames rendered (surge render DIR).</p>\n";
  const std::string video = scene.name + ".mp4";
  html += "<h2>Video</h2>\n";
  html += fs::exists(dir / video, error)
              ? "<video controls preload=\"metadata\" src=\"" + escapeXml(video) + "\"></video>\n"
              : "<p>No video yet (surge video DIR).</p>\n";
  html += "</body></html>\n";
  const fs::path path = dir / "report.html";
  writeFileAtomically(path, [&](std::ostream& out) { out << html; });
  return path;
}

}  // namespace

void addReportCommand(CLI::App& app) {
  struct Options {
    CommonOptions common;
    std::string dir;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "report", "DIR/report.html: plots of stats.csv, bodies.csv and colliders.csv, the contact sheet, the video");
  command->add_option("dir", options->dir, "output folder of surge sim (and render, video)")->required();
  addCommonOptions(*command, options->common, false);
  command->callback([options] {
    const Scene scene = sceneOfFolder(options->dir, options->common);
    checkOutputFolder(options->dir);
    say(options->common, "report -> " + writeReport(options->dir, scene).string());
  });
}

}  // namespace surge
