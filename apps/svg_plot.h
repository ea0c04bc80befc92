// Line plots as inline SVG, for surge report's page: drawn here rather than by gnuplot so that the page needs no
// other program and its plots are text in the page itself.
#pragma once

#include <string>
#include <vector>

namespace surge {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;  // a NaN y leaves its point out
};

struct PlotLabels {
  std::string title, xLabel, yLabel;
};

// An <svg> element `width` x `height` pixels: the series as coloured lines over axes with rounded ticks, a legend
// when there are several. Names and labels are escaped (escapeXml).
std::string svgLinePlot(const PlotLabels& labels, const std::vector<PlotSeries>& series, int width = 560,
                        int height = 300);

}  // namespace surge
