// Grouped bar charts (histograms) drawn into an Image.
#include "vitri/render/plot.hpp"

#include "vitri/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace vitri::viz {
namespace {

constexpr Color kPalette[] = {{52, 101, 164}, {204, 85, 0}, {78, 154, 6}, {117, 80, 123}, {193, 125, 17}, {85, 87, 83}};

/// A "nice" tick step (1, 2 or 5 times a power of ten) giving about `target` intervals over [0, top].
double nice_step(double top, int target) {
  const double raw = top / target;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

std::string format(double v, bool percent) {
  char buf[32];
  if (percent)
    std::snprintf(buf, sizeof buf, "%g%%", std::round(v * 1000.0) / 10.0);
  else
    std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

std::vector<double> histogram_shares(const std::vector<double>& values, double lo, double hi, int bins) {
  if (bins < 1) throw InvalidArgument("histogram_shares: bins must be >= 1");
  if (!(lo < hi)) throw InvalidArgument("histogram_shares: lo must be < hi");
  std::vector<double> out(static_cast<std::size_t>(bins), 0.0);
  if (values.empty()) return out;
  const double w = (hi - lo) / bins;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::isnan(values[i])) throw InvalidArgument("histogram_shares: value " + std::to_string(i) + " is NaN");
    const double k = std::floor((values[i] - lo) / w);
    out[static_cast<std::size_t>(std::clamp(k, 0.0, static_cast<double>(bins - 1)))] += 1.0;
  }
  for (auto& v : out) v /= static_cast<double>(values.size());
  return out;
}

Image plot_histograms(const std::vector<PlotSeries>& series, const HistogramPlotOptions& o) {
  if (series.empty()) throw InvalidArgument("plot_histograms: no series");
  const std::size_t bins = series[0].values.size();
  if (bins == 0) throw InvalidArgument("plot_histograms: series '" + series[0].name + "' has no bins");
  double top = 0.0;
  for (const auto& s : series) {
    if (s.values.size() != bins)
      throw InvalidArgument("plot_histograms: series '" + s.name + "' has " + std::to_string(s.values.size()) +
                            " bins, expected " + std::to_string(bins));
    for (const double v : s.values) {
      if (!std::isfinite(v) || v < 0.0) throw InvalidArgument("plot_histograms: series '" + s.name + "' has a negative or non-finite value");
      top = std::max(top, v);
    }
  }
  if (!(o.x_min < o.x_max)) throw InvalidArgument("plot_histograms: x_min must be < x_max");
  if (o.width < 200 || o.height < 150 || o.width > 16384 || o.height > 16384)
    throw InvalidArgument("plot_histograms: image too small or too large");

  const int fs = std::max(1, o.font_scale);
  const int th = text_height("0", fs);
  Image img(o.width, o.height, o.background);

  // Plot area: room for the title and y label on top, tick labels on the left and bottom, x label below.
  const double step = nice_step(top > 0.0 ? top : 1.0, 5);
  const double ymax = step * std::ceil((top > 0.0 ? top : 1.0) / step - 1e-9);
  int label_w = 0;
  for (double y = 0.0; y <= ymax + 0.5 * step; y += step) label_w = std::max(label_w, text_width(format(y, o.y_percent), fs));
  const int left = label_w + 6 * fs + 4;
  const int right = o.width - 8 * fs;
  const int top_px = (o.title.empty() ? 0 : th + 4 * fs) + th + 6 * fs;
  const int bottom = o.height - (o.x_label.empty() ? 0 : th + 4 * fs) - th - 8 * fs;
  if (right - left < 50 || bottom - top_px < 50) throw InvalidArgument("plot_histograms: image too small for the labels");
  const auto y_px = [&](double v) { return bottom - static_cast<int>(std::lround((bottom - top_px) * v / ymax)); };

  if (!o.title.empty()) draw_text(img, (o.width - text_width(o.title, fs)) / 2, 2 * fs, o.title, o.ink, fs);
  if (!o.y_label.empty()) draw_text(img, 2 * fs, top_px - th - 3 * fs, o.y_label, o.ink, fs);
  if (!o.x_label.empty())
    draw_text(img, left + (right - left - text_width(o.x_label, fs)) / 2, o.height - th - 2 * fs, o.x_label, o.ink, fs);

  // Horizontal grid lines and y tick labels.
  for (double y = 0.0; y <= ymax + 0.5 * step; y += step) {
    const int py = y_px(y);
    img.fill_rect(left, py, right - left, 1, {225, 225, 225});
    const std::string s = format(y, o.y_percent);
    draw_text(img, left - 4 * fs - text_width(s, fs), py - th / 2, s, o.ink, fs);
  }

  // Bars: each bin holds the series side by side with a small gap between bins.
  const double bin_w = static_cast<double>(right - left) / static_cast<double>(bins);
  const double bar_w = bin_w * 0.8 / static_cast<double>(series.size());
  std::size_t palette = 0;
  std::vector<Color> colors;
  for (const auto& s : series) colors.push_back(s.color == Color{0, 0, 0} ? kPalette[palette++ % 6] : s.color);
  for (std::size_t b = 0; b < bins; ++b)
    for (std::size_t s = 0; s < series.size(); ++s) {
      const double x0 = left + static_cast<double>(b) * bin_w + 0.1 * bin_w + static_cast<double>(s) * bar_w;
      const int px0 = static_cast<int>(std::lround(x0)), px1 = static_cast<int>(std::lround(x0 + bar_w));
      const int py = y_px(series[s].values[b]);
      img.fill_rect(px0, py, std::max(1, px1 - px0), bottom - py, colors[s]);
    }

  // Axes and x ticks at bin edges (every k-th edge so that labels do not overlap).
  img.fill_rect(left, top_px, 1, bottom - top_px + 1, o.ink);
  img.fill_rect(left, bottom, right - left + 1, 1, o.ink);
  const double bin_value = (o.x_max - o.x_min) / static_cast<double>(bins);
  int widest = 0;
  for (std::size_t b = 0; b <= bins; ++b) widest = std::max(widest, text_width(format(o.x_min + static_cast<double>(b) * bin_value, false), fs));
  const std::size_t every = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil((widest + 6.0 * fs) / bin_w)));
  for (std::size_t b = 0; b <= bins; b += every) {
    const int px = left + static_cast<int>(std::lround(static_cast<double>(b) * bin_w));
    img.fill_rect(px, bottom, 1, 3 * fs, o.ink);
    const std::string s = format(o.x_min + static_cast<double>(b) * bin_value, false);
    draw_text(img, px - text_width(s, fs) / 2, bottom + 4 * fs, s, o.ink, fs);
  }

  // Legend on the line above the plot area, right-aligned, so that it never hides a bar.
  const int box = th;
  int legend_w = 0;
  for (const auto& s : series) legend_w += box + 4 * fs + text_width(s.name, fs) + 10 * fs;
  int lx = right - legend_w + 10 * fs;
  const int ly = top_px - th - 3 * fs;
  for (std::size_t s = 0; s < series.size(); ++s) {
    img.fill_rect(lx, ly, box, box, colors[s]);
    draw_text(img, lx + box + 4 * fs, ly + 1, series[s].name, o.ink, fs);
    lx += box + 4 * fs + text_width(series[s].name, fs) + 10 * fs;
  }
  return img;
}

}  // namespace vitri::viz
