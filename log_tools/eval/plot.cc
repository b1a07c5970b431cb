#include "log_tools/eval/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace vtrack::eval {
namespace {

const cv::Scalar kBlack(0, 0, 0), kGrid(225, 225, 225), kAxis(90, 90, 90), kWhite(255, 255, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

std::string FormatTick(double v, double step) {
  char buf[32];
  const int decimals = step >= 1.0 ? 0 : std::min(6, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, std::abs(v) < 1e-12 * step ? 0.0 : v);
  return buf;
}

void PutText(cv::Mat& img, const std::string& s, cv::Point p, double scale, int thickness = 1,
             const cv::Scalar& color = kBlack) {
  cv::putText(img, s, p, kFont, scale, color, thickness, cv::LINE_AA);
}

cv::Size TextSize(const std::string& s, double scale, int thickness = 1) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, scale, thickness, &baseline);
}

void DrawPanel(cv::Mat& img, const Panel& panel, const cv::Rect& area) {
  const int left = 70, right = 16, top = 30, bottom = 46;
  const cv::Rect plot(area.x + left, area.y + top, area.width - left - right,
                      area.height - top - bottom);
  PutText(img, panel.title, {area.x + left, area.y + 20}, 0.5, 1);

  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const Series& s : panel.series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]);
      y1 = std::max(y1, s.y[i]);
    }
  }
  const bool empty = !std::isfinite(x0);
  if (empty) {
    x0 = 0.0, x1 = 1.0, y0 = 0.0, y1 = 1.0;
  }
  if (panel.y_from_zero) {
    y0 = std::min(y0, 0.0);
    y1 = std::max(y1, 0.0);
  }
  if (x1 - x0 < 1e-12) {
    x0 -= 0.5;
    x1 += 0.5;
  }
  // Room for markers at the ends of the x range.
  const bool markers = std::any_of(panel.series.begin(), panel.series.end(),
                                   [](const Series& s) { return s.markers; });
  if (markers) {
    const double xpad = 0.04 * (x1 - x0);
    x0 -= xpad;
    x1 += xpad;
  }
  if (y1 - y0 < 1e-12) {
    y0 -= 0.5;
    y1 += 0.5;
  }
  const double ypad = 0.05 * (y1 - y0);
  if (!(panel.y_from_zero && y0 == 0.0)) y0 -= ypad;
  y1 += ypad;

  auto px = [&](double x) { return plot.x + (x - x0) / (x1 - x0) * plot.width; };
  auto py = [&](double y) { return plot.y + plot.height - (y - y0) / (y1 - y0) * plot.height; };

  // Grid and ticks.
  const auto xt = NiceTicks(x0, x1);
  const auto yt = NiceTicks(y0, y1);
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1.0;
  const double ystep = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  for (const double x : xt) {
    const int X = static_cast<int>(std::lround(px(x)));
    cv::line(img, {X, plot.y}, {X, plot.y + plot.height}, kGrid, 1);
    cv::line(img, {X, plot.y + plot.height}, {X, plot.y + plot.height + 4}, kAxis, 1);
    const std::string label = FormatTick(x, xstep);
    const cv::Size sz = TextSize(label, 0.4);
    PutText(img, label, {X - sz.width / 2, plot.y + plot.height + 18}, 0.4);
  }
  for (const double y : yt) {
    const int Y = static_cast<int>(std::lround(py(y)));
    cv::line(img, {plot.x, Y}, {plot.x + plot.width, Y}, kGrid, 1);
    cv::line(img, {plot.x - 4, Y}, {plot.x, Y}, kAxis, 1);
    const std::string label = FormatTick(y, ystep);
    const cv::Size sz = TextSize(label, 0.4);
    PutText(img, label, {plot.x - 8 - sz.width, Y + sz.height / 2}, 0.4);
  }
  cv::rectangle(img, plot, kAxis, 1);

  // Axis labels: x below, y written vertically (rotated text block) left of the ticks.
  {
    const cv::Size sz = TextSize(panel.x_label, 0.45);
    PutText(img, panel.x_label, {plot.x + (plot.width - sz.width) / 2, plot.y + plot.height + 38},
            0.45);
  }
  if (!panel.y_label.empty()) {
    const cv::Size sz = TextSize(panel.y_label, 0.45);
    cv::Mat block(sz.height + 8, sz.width + 4, img.type(), kWhite);
    PutText(block, panel.y_label, {2, sz.height + 2}, 0.45);
    cv::Mat rotated;
    cv::rotate(block, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int x = area.x + 4;
    const int y = plot.y + std::max(0, (plot.height - rotated.rows) / 2);
    const cv::Rect dst(x, y, rotated.cols, std::min(rotated.rows, img.rows - y));
    if (dst.x + dst.width <= img.cols && dst.height > 0) {
      rotated(cv::Rect(0, 0, dst.width, dst.height)).copyTo(img(dst));
    }
  }
  if (empty) {
    PutText(img, "no data", {plot.x + plot.width / 2 - 30, plot.y + plot.height / 2}, 0.5);
    return;
  }

  // Data, clipped to the plot rectangle.
  cv::Mat roi = img(plot);
  const cv::Point offset(plot.x, plot.y);
  for (const Series& s : panel.series) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    bool have_prev = false;
    cv::Point prev;
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        have_prev = false;
        continue;
      }
      const cv::Point p(static_cast<int>(std::lround(px(s.x[i]))),
                        static_cast<int>(std::lround(py(s.y[i]))));
      if (s.line && have_prev) cv::line(roi, prev - offset, p - offset, s.color, 2, cv::LINE_AA);
      if (s.markers) cv::circle(roi, p - offset, 3, s.color, cv::FILLED, cv::LINE_AA);
      prev = p;
      have_prev = true;
    }
  }

  // Legend, top right inside the plot.
  std::vector<const Series*> named;
  for (const Series& s : panel.series) {
    if (!s.name.empty()) named.push_back(&s);
  }
  if (named.empty()) return;
  int w = 0;
  for (const Series* s : named) w = std::max(w, TextSize(s->name, 0.4).width);
  const int row = 16;
  const cv::Rect box(plot.x + plot.width - w - 44, plot.y + 6, w + 38,
                     row * static_cast<int>(named.size()) + 6);
  cv::rectangle(img, box, kWhite, cv::FILLED);
  cv::rectangle(img, box, kAxis, 1);
  for (std::size_t i = 0; i < named.size(); ++i) {
    const int y = box.y + 4 + row * static_cast<int>(i) + row / 2;
    if (named[i]->line) cv::line(img, {box.x + 6, y}, {box.x + 26, y}, named[i]->color, 2, cv::LINE_AA);
    if (named[i]->markers) cv::circle(img, {box.x + 16, y}, 3, named[i]->color, cv::FILLED);
    PutText(img, named[i]->name, {box.x + 32, y + 5}, 0.4);
  }
}

}  // namespace

cv::Scalar PaletteColor(int i) {
  // Tableau 10, as BGR.
  static const cv::Scalar kColors[] = {
      {180, 119, 31}, {14, 127, 255}, {44, 160, 44},  {40, 39, 214},  {189, 103, 148},
      {75, 86, 140},  {194, 119, 227}, {127, 127, 127}, {34, 189, 188}, {207, 190, 23}};
  return kColors[((i % 10) + 10) % 10];
}

std::vector<double> NiceTicks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || target < 1) return ticks;
  const double raw = (hi - lo) / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw) break;
  }
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (double v = first; v <= hi + 1e-9 * step; v += step) ticks.push_back(v);
  return ticks;
}

cv::Mat RenderFigure(const Figure& figure) {
  const int cols = std::max(1, figure.columns);
  const int n = static_cast<int>(figure.panels.size());
  const int rows = std::max(1, (n + cols - 1) / cols);
  const int title_h = figure.title.empty() ? 0 : 34;
  cv::Mat img(title_h + rows * figure.panel_height, cols * figure.panel_width, CV_8UC3, kWhite);
  if (!figure.title.empty()) {
    const cv::Size sz = TextSize(figure.title, 0.6, 1);
    PutText(img, figure.title, {(img.cols - sz.width) / 2, 24}, 0.6, 1);
  }
  for (int i = 0; i < n; ++i) {
    const cv::Rect area((i % cols) * figure.panel_width, title_h + (i / cols) * figure.panel_height,
                        figure.panel_width, figure.panel_height);
    DrawPanel(img, figure.panels[static_cast<std::size_t>(i)], area);
  }
  return img;
}

void SaveFigure(const Figure& figure, const std::string& path) {
  const cv::Mat img = RenderFigure(figure);
  bool ok = false;
  try {
    ok = cv::imwrite(path, img);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot write plot '" + path + "': " + e.what());
  }
  if (!ok) throw std::runtime_error("cannot write plot '" + path + "'");
}

}  // namespace vtrack::eval
