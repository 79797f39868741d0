#pragma once
/// @file plot.hpp
/// Grouped bar charts as images, for the minimum-angle histograms of the comparison (vitri vs CGAL vs
/// marching tetrahedra) and similar figures. Uses the Image and text drawing of render.hpp.

#include "vitri/render/render.hpp"

#include <string>
#include <vector>

namespace vitri::viz {

/// One series of a grouped bar chart: one value per bin.
struct PlotSeries {
  std::string name;            ///< Shown in the legend.
  std::vector<double> values;  ///< One value per bin (finite, >= 0).
  /// Bar colour; when left black the series gets the next colour of a built-in palette.
  Color color{0, 0, 0};
};

/// Layout and labels of plot_histograms().
struct HistogramPlotOptions {
  int width = 900;             ///< Image width in pixels (>= 200).
  int height = 500;            ///< Image height in pixels (>= 150).
  std::string title;           ///< Drawn above the plot (may be empty).
  std::string x_label;         ///< Below the x axis, e.g. "minimum angle (degrees)".
  std::string y_label;         ///< Above the y axis, e.g. "share of triangles".
  double x_min = 0.0;          ///< Left edge of the first bin (x axis value).
  double x_max = 60.0;         ///< Right edge of the last bin; bins split [x_min, x_max] evenly.
  bool y_percent = true;       ///< Label the y axis in percent (values are fractions 0..1).
  int font_scale = 2;          ///< Text size (font pixel multiplier).
  Color background{255, 255, 255};  ///< Background colour.
  Color ink{0, 0, 0};               ///< Axes and text colour.
};

/// Draws the series as grouped bars over common bins, with axes, ticks, grid lines and a legend.
/// Meant for 1 to 3 series (more work, but bars get thin).
/// @throws InvalidArgument when there is no series, the series have different or zero bin counts, a value
///         is negative or not finite, x_min >= x_max, or the image is too small.
Image plot_histograms(const std::vector<PlotSeries>& series, const HistogramPlotOptions& options = {});

/// Fraction of `values` falling in each of `bins` equal bins over [lo, hi] (values outside are clamped
/// into the first or last bin). The fractions sum to 1 unless values is empty (then all 0).
/// @throws InvalidArgument when bins < 1, lo >= hi or a value is NaN.
std::vector<double> histogram_shares(const std::vector<double>& values, double lo, double hi, int bins);

}  // namespace vitri::viz
