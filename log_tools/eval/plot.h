// Small line plots rendered with OpenCV into PNG files: panels with axes, "nice" ticks, labels,
// a title and a legend. Enough for the evaluator's figures (errors over time, the tracker modes
// side by side); the viewer's renderer draws scenes, not charts, so there is nothing to share.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace vtrack::eval {

struct Series {
  std::string name;                 // legend entry; "" = not in the legend
  std::vector<double> x, y;         // NaN in y breaks the line
  cv::Scalar color{0, 0, 0};        // BGR
  bool line = true;                 // draw segments between consecutive points
  bool markers = false;             // draw a marker at each point
};

struct Panel {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  bool y_from_zero = false;         // include y = 0 in the range
};

struct Figure {
  std::string title;
  std::vector<Panel> panels;
  int columns = 1;                  // panels per row
  int panel_width = 640;            // [px]
  int panel_height = 320;           // [px]
};

// The i-th colour of a palette of well-separated colours (BGR).
cv::Scalar PaletteColor(int i);

// Tick positions at 1, 2 or 5 times a power of ten covering [lo, hi], about `target` of them.
std::vector<double> NiceTicks(double lo, double hi, int target = 6);

cv::Mat RenderFigure(const Figure& figure);

// Renders and writes a PNG; throws std::runtime_error naming the path if it cannot be written.
void SaveFigure(const Figure& figure, const std::string& path);

}  // namespace vtrack::eval
