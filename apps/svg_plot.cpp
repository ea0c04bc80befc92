#include "apps/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/files.h"

namespace surge {
namespace {

// Colours people tell apart (the first is the line the report test looks for).
const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};

// A tick step of 1, 2 or 5 times a power of ten giving about `count` ticks over `span`.
double niceStep(double span, int count) {
  const double raw = span / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (raw <= m * power) return m * power;
  return 10 * power;
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", std::abs(v) < 1e-12 ? 0.0 : v);
  return text;
}

// The range of the finite values, widened when they are all one value.
void range(const std::vector<PlotSeries>& series, bool ys, double& low, double& high) {
  low = std::numeric_limits<double>::infinity(), high = -low;
  for (const PlotSeries& s : series)
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      const double v = ys ? s.y[i] : s.x[i];
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) low = std::min(low, v), high = std::max(high, v);
    }
  if (!std::isfinite(low)) low = 0, high = 1;
  if (high - low < 1e-12 * std::max(1.0, std::abs(high))) {
    const double pad = std::max(1e-9, std::abs(high) * 0.1);
    low -= pad, high += pad;
  }
}

}  // namespace

std::string svgLinePlot(const PlotLabels& labels, const std::vector<PlotSeries>& series, int width, int height) {
  const double left = 72, right = 16, top = 30, bottom = 44;
  const double plotWidth = width - left - right, plotHeight = height - top - bottom;
  double x0, x1, y0, y1;
  range(series, false, x0, x1);
  range(series, true, y0, y1);
  const double yStep = niceStep(y1 - y0, 5), xStep = niceStep(x1 - x0, 6);
  y0 = std::floor(y0 / yStep) * yStep, y1 = std::ceil(y1 / yStep) * yStep;
  auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * plotWidth; };
  auto py = [&](double y) { return top + (y1 - y) / (y1 - y0) * plotHeight; };
  std::string svg;
  char buffer[256];
  auto add = [&](const char* format, auto... values) {
    std::snprintf(buffer, sizeof buffer, format, values...);
    svg += buffer;
  };
  add("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
      "font-family=\"sans-serif\" font-size=\"11\">\n",
      width, height, width, height);
  add("<rect width=\"%d\" height=\"%d\" fill=\"white\"/>\n", width, height);
  svg += "<text x=\"" + number(left) + "\" y=\"18\" font-size=\"13\" font-weight=\"bold\">" + escapeXml(labels.title) +
         "</text>\n";
  // Grid and ticks.
  for (double y = y0; y <= y1 + yStep * 1e-6; y += yStep) {
    add("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", left, py(y), left + plotWidth,
        py(y));
    add("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">", left - 4, py(y) + 4);
    svg += number(y) + "</text>\n";
  }
  for (double x = std::ceil(x0 / xStep) * xStep; x <= x1 + xStep * 1e-6; x += xStep) {
    add("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#eee\"/>\n", px(x), top, px(x),
        top + plotHeight);
    add("<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">", px(x), top + plotHeight + 14);
    svg += number(x) + "</text>\n";
  }
  add("<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"#444\"/>\n", left, top,
      plotWidth, plotHeight);
  add("<text x=\"%.1f\" y=\"%d\" text-anchor=\"middle\">", left + plotWidth / 2, height - 8);
  svg += escapeXml(labels.xLabel) + "</text>\n";
  add("<text transform=\"translate(14 %.1f) rotate(-90)\" text-anchor=\"middle\">", top + plotHeight / 2);
  svg += escapeXml(labels.yLabel) + "</text>\n";
  // The lines, and a legend entry each when there are several.
  for (size_t s = 0; s < series.size(); ++s) {
    const char* color = kColors[s % (sizeof kColors / sizeof kColors[0])];
    svg += std::string("<polyline fill=\"none\" stroke-width=\"1.8\" stroke=\"") + color + "\" points=\"";
    for (size_t i = 0; i < series[s].x.size() && i < series[s].y.size(); ++i)
      if (std::isfinite(series[s].x[i]) && std::isfinite(series[s].y[i]))
        add("%.1f,%.1f ", px(series[s].x[i]), py(series[s].y[i]));
    svg += "\"/>\n";
    if (series.size() < 2) continue;
    const double ly = top + 12 + 14 * double(s);
    add("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" stroke-width=\"2\"/>",
        left + plotWidth - 140, ly - 4, left + plotWidth - 122, ly - 4, color);
    add("<text x=\"%.1f\" y=\"%.1f\">", left + plotWidth - 118, ly);
    svg += escapeXml(series[s].name) + "</text>\n";
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace surge
