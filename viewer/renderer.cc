#include "viewer/renderer.h"

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <sstream>
#include <stdexcept>

#include "base/angle.h"

namespace vtrack::viewer {
namespace {

constexpr int kShift = 4;                     // fixed-point bits: lines are placed to 1/16 px
constexpr double kFixed = 1 << kShift;
constexpr double kClipMargin = 32.0;          // [px] geometry is clipped to the image grown by this
constexpr int kEllipseSegments = 72;

std::string Bad(const char* key, double value, const char* constraint) {
  std::ostringstream os;
  os << "render." << key << " = " << value << ": " << constraint;
  return os.str();
}

// Liang-Barsky clipping of the segment a-b to [x0, x1] x [y0, y1], in double precision.
// Hand-written because cv::clipLine takes integer points: geometry far outside the image (or not
// finite) must be rejected before the fixed-point conversion, not after it has overflowed. End
// points beyond kFarPx are refused: there, a + t (b - a) cannot place the visible part to a pixel.
constexpr double kFarPx = 1e9;
bool ClipSegment(double x0, double y0, double x1, double y1, Eigen::Vector2d* a,
                 Eigen::Vector2d* b) {
  if (!a->allFinite() || !b->allFinite()) return false;
  if (a->cwiseAbs().maxCoeff() > kFarPx || b->cwiseAbs().maxCoeff() > kFarPx) return false;
  const Eigen::Vector2d d = *b - *a;
  if (!d.allFinite()) return false;
  double t0 = 0.0, t1 = 1.0;
  auto clip = [&](double p, double q) {  // keep the part where p * t <= q
    if (p == 0.0) return q >= 0.0;
    const double r = q / p;
    if (p < 0.0) {
      if (r > t1) return false;
      t0 = std::max(t0, r);
    } else {
      if (r < t0) return false;
      t1 = std::min(t1, r);
    }
    return true;
  };
  if (!clip(-d.x(), a->x() - x0) || !clip(d.x(), x1 - a->x()) || !clip(-d.y(), a->y() - y0) ||
      !clip(d.y(), y1 - a->y())) {
    return false;
  }
  const Eigen::Vector2d a0 = *a;
  *a = a0 + t0 * d;
  *b = a0 + t1 * d;
  return true;
}

cv::Point Fixed(const Eigen::Vector2d& px) {
  return {static_cast<int>(std::lround(px.x() * kFixed)),
          static_cast<int>(std::lround(px.y() * kFixed))};
}

// Drawing primitives in world coordinates, all projected through one View.
class Canvas {
 public:
  Canvas(cv::Mat* image, const View& view, bool antialias)
      : img_(*image), view_(view), line_type_(antialias ? cv::LINE_AA : cv::LINE_8) {}

  cv::Mat& image() { return img_; }
  const View& view() const { return view_; }
  int line_type() const { return line_type_; }

  void LinePx(Eigen::Vector2d a, Eigen::Vector2d b, const cv::Scalar& c, int thickness) {
    if (!ClipSegment(-kClipMargin, -kClipMargin, img_.cols + kClipMargin, img_.rows + kClipMargin,
                     &a, &b)) {
      return;
    }
    cv::line(img_, Fixed(a), Fixed(b), c, thickness, line_type_, kShift);
  }

  // Dashes of dash px with gaps of gap px; *phase carries the pattern across joined segments.
  void DashedLinePx(Eigen::Vector2d a, Eigen::Vector2d b, const cv::Scalar& c, int thickness,
                    double dash, double gap, double* phase = nullptr) {
    const Eigen::Vector2d a_in = a;
    if (!ClipSegment(-kClipMargin, -kClipMargin, img_.cols + kClipMargin, img_.rows + kClipMargin,
                     &a, &b)) {
      return;
    }
    const double len = (b - a).norm();
    if (!(len > 0.0)) return;
    const Eigen::Vector2d u = (b - a) / len;
    const double period = dash + gap;
    // Continue the pattern from the unclipped start so dashes do not move when the view pans.
    double ph = std::fmod((phase ? *phase : 0.0) + (a - a_in).norm(), period);
    double s = 0.0;
    while (s < len) {
      const bool on = ph < dash;
      // At least a micro-pixel per step: rounding must not stall the walk at a dash boundary.
      const double step = std::max(on ? dash - ph : period - ph, 1e-6);
      const double e = std::min(len, s + step);
      if (on) LinePx(a + s * u, a + e * u, c, thickness);
      ph += e - s;
      s = e;
      if (ph >= period - 1e-9) ph = 0.0;
    }
    if (phase) *phase = ph;
  }

  void Line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const cv::Scalar& c,
            int thickness, bool dashed = false) {
    if (dashed) {
      DashedLinePx(W(a), W(b), c, thickness, DashLength(thickness), GapLength(thickness));
    } else {
      LinePx(W(a), W(b), c, thickness);
    }
  }

  void Polyline(const std::vector<Eigen::Vector2d>& pts, const cv::Scalar& c, int thickness,
                bool closed, bool dashed = false) {
    double phase = 0.0;
    const std::size_t n = pts.size();
    if (n < 2) return;
    const std::size_t segments = closed ? n : n - 1;
    for (std::size_t i = 0; i < segments; ++i) {
      const Eigen::Vector2d a = W(pts[i]), b = W(pts[(i + 1) % n]);
      if (dashed) {
        DashedLinePx(a, b, c, thickness, DashLength(thickness), GapLength(thickness), &phase);
      } else {
        LinePx(a, b, c, thickness);
      }
    }
  }

  void Box(const OrientedBox& box, const cv::Scalar& c, int thickness, bool dashed = false) {
    if (!box.center.allFinite() || !std::isfinite(box.theta) || !std::isfinite(box.length) ||
        !std::isfinite(box.width)) {
      return;
    }
    const auto corners = box.Corners();
    Polyline({corners.begin(), corners.end()}, c, thickness, /*closed=*/true, dashed);
  }

  void FilledBox(const OrientedBox& box, const cv::Scalar& c) {
    if (!box.center.allFinite() || !std::isfinite(box.theta)) return;
    const auto corners = box.Corners();
    FilledPolygon({corners.begin(), corners.end()}, c);
  }

  void FilledPolygon(const std::vector<Eigen::Vector2d>& world, const cv::Scalar& c) {
    std::vector<cv::Point> poly;
    for (const auto& p : world) {
      Eigen::Vector2d q = W(p), r = q;
      // Clip each corner's coordinates so a huge box cannot overflow the fixed-point conversion.
      if (!ClipSegment(-1e5, -1e5, 1e5, 1e5, &q, &r)) return;
      poly.push_back(Fixed(q));
    }
    cv::fillConvexPoly(img_, poly, c, line_type_, kShift);
  }

  // The sigma-level ellipse of a 2x2 position covariance, as a polygon through the view.
  void CovarianceEllipse(const Eigen::Vector2d& center, const Eigen::Matrix2d& cov, double sigma,
                         const cv::Scalar& c, int thickness) {
    const Eigen::Matrix2d p = 0.5 * (cov + cov.transpose());
    if (!p.allFinite() || !center.allFinite()) return;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(p);
    if (es.info() != Eigen::Success) return;
    // Not a covariance (clearly negative eigenvalue): nothing sensible to draw.
    if (es.eigenvalues()(0) < -1e-9 * std::max(1.0, std::abs(es.eigenvalues()(1)))) return;
    const Eigen::Vector2d axes =
        sigma * es.eigenvalues().cwiseMax(0.0).cwiseSqrt();  // [m] semi-axes
    const Eigen::Matrix2d v = es.eigenvectors();
    std::vector<Eigen::Vector2d> pts;
    pts.reserve(kEllipseSegments);
    for (int k = 0; k < kEllipseSegments; ++k) {
      const double t = 2.0 * kPi * k / kEllipseSegments;
      pts.push_back(center + axes(0) * std::cos(t) * v.col(0) + axes(1) * std::sin(t) * v.col(1));
    }
    Polyline(pts, c, thickness, /*closed=*/true);
  }

  void Points(const std::vector<Eigen::Vector2f>& pts, const cv::Scalar& c, int size) {
    const cv::Vec3b bgr(static_cast<uchar>(c[0]), static_cast<uchar>(c[1]),
                        static_cast<uchar>(c[2]));
    const int lo = -(size - 1) / 2;
    for (const auto& p : pts) {
      const Eigen::Vector2d q = W(p.cast<double>());
      if (!q.allFinite()) continue;
      if (q.x() < -size || q.y() < -size || q.x() > img_.cols + size || q.y() > img_.rows + size) {
        continue;
      }
      const int u0 = static_cast<int>(std::lround(q.x())) + lo;
      const int v0 = static_cast<int>(std::lround(q.y())) + lo;
      for (int v = std::max(0, v0); v < std::min(img_.rows, v0 + size); ++v) {
        auto* row = img_.ptr<cv::Vec3b>(v);
        for (int u = std::max(0, u0); u < std::min(img_.cols, u0 + size); ++u) row[u] = bgr;
      }
    }
  }

  Eigen::Vector2d W(const Eigen::Vector2d& world) const { return view_.WorldToImage(world); }

 private:
  static double DashLength(int thickness) { return 5.0 + 2.0 * thickness; }
  static double GapLength(int thickness) { return 4.0 + 2.0 * thickness; }

  cv::Mat& img_;
  const View& view_;
  int line_type_;
};

// Text helpers (Hershey fonts: the only ones in OpenCV's core modules).
struct Font {
  int face = cv::FONT_HERSHEY_SIMPLEX;
  double scale = 0.45;
  int thickness = 1;
  int line_type = cv::LINE_AA;

  cv::Size Size(const std::string& text, int* baseline = nullptr) const {
    int b = 0;
    const cv::Size s = cv::getTextSize(text, face, scale, thickness, &b);
    if (baseline) *baseline = b;
    return s;
  }
  int LineHeight() const { return Size("Ag").height + 7; }
};

// Lightens the rectangle so that text over data stays readable.
void Veil(cv::Mat& img, cv::Rect r, double opacity = 0.8) {
  r &= cv::Rect(0, 0, img.cols, img.rows);
  if (r.empty()) return;
  cv::Mat roi = img(r);
  roi = roi * (1.0 - opacity) + cv::Scalar::all(255.0 * opacity);
}

// Draws text with its baseline-left corner at org, on a veil.
void Text(cv::Mat& img, const Font& font, const std::string& text, cv::Point org,
          const cv::Scalar& c, bool veil = true) {
  int baseline = 0;
  const cv::Size s = font.Size(text, &baseline);
  if (veil) Veil(img, cv::Rect(org.x - 2, org.y - s.height - 3, s.width + 4, s.height + baseline + 5));
  cv::putText(img, text, org, font.face, font.scale, c, font.thickness, font.line_type);
}

// The smallest of 1, 2, 5 x 10^k that is at least x.
double NiceAtLeast(double x) {
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= x * (1.0 - 1e-9)) return m * p;
  }
  return 10.0 * p;
}

std::string FormatNumber(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

std::string FormatUtc(std::int64_t utime) {
  const std::time_t secs = static_cast<std::time_t>(utime / 1000000);
  const int ms = static_cast<int>((utime % 1000000) / 1000);
  std::tm tm{};
  if (!gmtime_r(&secs, &tm)) return "utime " + std::to_string(utime);
  char buf[64];
  std::strftime(buf, sizeof(buf), "%Y-%m-%d %H:%M:%S", &tm);
  char out[96];
  std::snprintf(out, sizeof(out), "%s.%03d UTC", buf, ms < 0 ? 0 : ms);
  return out;
}

const char* ModelName(MotionModel m) {
  return m == MotionModel::kVasm ? "VASM" : m == MotionModel::kCv ? "CV" : "ISM";
}

bool IsClutter(const SceneTrack& t) { return t.object_class == TrackClass::kOther; }

void DrawGrid(Canvas& cv, const Font& font) {
  const View& view = cv.view();
  const double step = NiceAtLeast(70.0 / view.px_per_m);  // [m] lines at least 70 px apart
  const Eigen::AlignedBox2d b = view.WorldBounds();
  cv::Mat& img = cv.image();
  const int decimals = step < 1.0 ? (step < 0.1 ? 2 : 1) : 0;
  // Lines by integer index, so that far from the origin the loop still ends.
  const double i0 = std::ceil(b.min().x() / step), i1 = std::floor(b.max().x() / step);
  const double j0 = std::ceil(b.min().y() / step), j1 = std::floor(b.max().y() / step);
  if (!(i1 - i0 < 1000.0) || !(j1 - j0 < 1000.0) || !(std::abs(i0) + std::abs(j0) < 1e12)) return;
  for (double i = i0; i <= i1; i += 1.0) {
    const double x = i * step;
    const double u = view.WorldToImage({x, 0.0}).x();
    cv.LinePx({u, 0.0}, {u, static_cast<double>(img.rows)}, color::kGrid, 1);
    Text(img, font, FormatNumber(x, decimals), cv::Point(static_cast<int>(u) + 3, img.rows - 6),
         color::kGridText, false);
  }
  for (double j = j0; j <= j1; j += 1.0) {
    const double y = j * step;
    const double v = view.WorldToImage({0.0, y}).y();
    cv.LinePx({0.0, v}, {static_cast<double>(img.cols), v}, color::kGrid, 1);
    Text(img, font, FormatNumber(y, decimals), cv::Point(3, static_cast<int>(v) - 3),
         color::kGridText, false);
  }
}

void DrawScaleBar(Canvas& cv, const Font& font) {
  const double px_per_m = cv.view().px_per_m;
  const double metres = NiceAtLeast(90.0 / px_per_m);
  const double len = metres * px_per_m;
  cv::Mat& img = cv.image();
  const double x0 = 20.0, y0 = img.rows - 34.0;
  Veil(img, cv::Rect(static_cast<int>(x0) - 8, static_cast<int>(y0) - 26, static_cast<int>(len) + 16, 36));
  cv.LinePx({x0, y0}, {x0 + len, y0}, color::kText, 3);
  cv.LinePx({x0, y0 - 6}, {x0, y0 + 5}, color::kText, 2);
  cv.LinePx({x0 + len, y0 - 6}, {x0 + len, y0 + 5}, color::kText, 2);
  const int decimals = metres < 1.0 ? (metres < 0.1 ? 2 : 1) : 0;
  const std::string label = FormatNumber(metres, decimals) + " m";
  const cv::Size s = font.Size(label);
  Text(img, font, label, cv::Point(static_cast<int>(x0 + 0.5 * len - 0.5 * s.width),
                                   static_cast<int>(y0) - 9),
       color::kText, false);
}

void DrawTimeStamp(const Scene& scene, cv::Mat& img, const Font& font) {
  std::vector<std::string> lines;
  std::string l1 = "t = " + FormatNumber(scene.time_s, 2) + " s";
  if (scene.scan_seq >= 0) l1 += "   scan " + std::to_string(scene.scan_seq);
  lines.push_back(l1);
  lines.push_back(FormatUtc(scene.utime));
  if (!scene.mode.empty() || !scene.tracks.empty()) {
    int confirmed = 0;
    for (const auto& t : scene.tracks) confirmed += t.status == TrackStatus::kConfirmed;
    std::string l3 = std::to_string(scene.tracks.size()) + " tracks (" +
                     std::to_string(confirmed) + " confirmed)";
    if (!scene.mode.empty()) l3 = "mode " + scene.mode + "   " + l3;
    if (std::isfinite(scene.latency_ms)) l3 += "   latency " + FormatNumber(scene.latency_ms, 1) + " ms";
    lines.push_back(l3);
  }
  for (const auto& n : scene.notes) lines.push_back(n);
  int width = 0;
  for (const auto& l : lines) width = std::max(width, font.Size(l).width);
  const int lh = font.LineHeight();
  const int x = img.cols - width - 14;
  Veil(img, cv::Rect(x - 6, 6, width + 14, lh * static_cast<int>(lines.size()) + 8), 0.85);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    Text(img, font, lines[i], cv::Point(x, 8 + lh * static_cast<int>(i + 1) - 4), color::kText,
         false);
  }
}

enum class Swatch { kDot, kRect, kLine, kDashed, kFilled };
struct LegendEntry {
  Swatch swatch;
  cv::Scalar color;
  std::string text;
  int thickness = 2;
};

void DrawLegend(const std::vector<LegendEntry>& entries, Canvas& cv, const Font& font) {
  cv::Mat& img = cv.image();
  const int lh = font.LineHeight() + 2;
  const int sw = 34;  // [px] swatch width
  int width = 0;
  for (const auto& e : entries) width = std::max(width, font.Size(e.text).width);
  const int x0 = 12, y0 = 10;
  const cv::Rect box(x0 - 4, y0 - 4, sw + width + 24, lh * static_cast<int>(entries.size()) + 10);
  Veil(img, box, 0.88);
  cv::rectangle(img, box, cv::Scalar(200, 200, 200), 1);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& e = entries[i];
    const double yc = y0 + lh * (i + 0.5) + 2;
    const double xa = x0 + 4, xb = x0 + sw;
    switch (e.swatch) {
      case Swatch::kDot:
        for (int k = 0; k < 4; ++k) {
          const cv::Point p(static_cast<int>(xa) + 4 + 8 * k, static_cast<int>(yc) + (k % 2 ? -2 : 2));
          cv::rectangle(img, p, p + cv::Point(1, 1), e.color, cv::FILLED);
        }
        break;
      case Swatch::kRect:
        cv.LinePx({xa, yc - 5}, {xb, yc - 5}, e.color, e.thickness);
        cv.LinePx({xb, yc - 5}, {xb, yc + 5}, e.color, e.thickness);
        cv.LinePx({xb, yc + 5}, {xa, yc + 5}, e.color, e.thickness);
        cv.LinePx({xa, yc + 5}, {xa, yc - 5}, e.color, e.thickness);
        break;
      case Swatch::kLine:
        cv.LinePx({xa, yc}, {xb, yc}, e.color, e.thickness);
        break;
      case Swatch::kDashed:
        cv.DashedLinePx({xa, yc}, {xb, yc}, e.color, e.thickness, 6.0, 4.0);
        break;
      case Swatch::kFilled:
        cv::rectangle(img, cv::Point(static_cast<int>(xa), static_cast<int>(yc) - 5),
                      cv::Point(static_cast<int>(xb), static_cast<int>(yc) + 5), e.color,
                      cv::FILLED);
        break;
    }
    Text(img, font, e.text, cv::Point(x0 + sw + 12, static_cast<int>(yc) + 5), color::kText,
         false);
  }
}

int StateThickness(const SceneTrack& t) {
  return t.status == TrackStatus::kTentative ? 1 : 2;
}

std::string TrackLabel(const SceneTrack& t) {
  std::ostringstream os;
  os << '#' << t.id;
  // The vehicle probability beside the class: why a track is (not) drawn as a vehicle.
  const std::string p =
      std::isfinite(t.vehicle_probability) ? " p=" + FormatNumber(t.vehicle_probability, 2) : "";
  if (IsClutter(t)) return os.str() + p;
  os << ' ' << ModelName(t.model) << ' ' << FormatNumber(t.speed, 1) << " m/s  "
     << t.num_hypotheses << " hyp" << p;
  if (t.status == TrackStatus::kTentative) os << " (new)";
  if (t.status == TrackStatus::kCoasting) os << " (coast)";
  return os.str();
}

// Places labels beside their rectangles without covering each other: the first free spot of
// right-top, right-bottom, left-top, left-bottom, above, below; a label with no free spot is
// tried in its short form and otherwise left out (a busy scene stays readable).
class LabelPlacer {
 public:
  LabelPlacer(cv::Mat* image, const Canvas& canvas) : img_(*image), cv_(canvas) {}

  // Returns false if no spot was free.
  bool Place(const OrientedBox& box, const std::vector<std::string>& texts, const Font& font,
             const cv::Scalar& c, bool veil) {
    double umin = 1e18, umax = -1e18, vmin = 1e18, vmax = -1e18;
    for (const auto& k : box.Corners()) {
      const Eigen::Vector2d p = cv_.W(k);
      if (!p.allFinite()) return false;
      umin = std::min(umin, p.x());
      umax = std::max(umax, p.x());
      vmin = std::min(vmin, p.y());
      vmax = std::max(vmax, p.y());
    }
    // Far outside the image: nothing to label. Nor beside a rectangle far larger than the image
    // (its label spots would not fit in an int: UB, found by clang's UBSan).
    if (umax < -200.0 || umin > img_.cols + 200.0 || vmax < -200.0 || vmin > img_.rows + 200.0 ||
        umax - umin > 1e6 || vmax - vmin > 1e6) {
      return false;
    }
    for (const std::string& text : texts) {
      int baseline = 0;
      const cv::Size s = font.Size(text, &baseline);
      const double w = s.width, h = s.height;
      const Eigen::Vector2d candidates[] = {
          {umax + 6.0, vmin + h},    {umax + 6.0, vmax},         {umin - 6.0 - w, vmin + h},
          {umin - 6.0 - w, vmax},    {umin, vmin - 6.0 - baseline}, {umin, vmax + h + 6.0}};
      for (const auto& o : candidates) {
        const cv::Point org(static_cast<int>(o.x()), static_cast<int>(o.y()));
        const cv::Rect r(org.x - 2, org.y - s.height - 3, s.width + 4, s.height + baseline + 5);
        if (std::any_of(taken_.begin(), taken_.end(),
                        [&](const cv::Rect& t) { return (t & r).area() > 0; })) {
          continue;
        }
        taken_.push_back(r);
        Text(img_, font, text, org, c, veil);
        return true;
      }
    }
    return false;
  }

 private:
  cv::Mat& img_;
  const Canvas& cv_;
  std::vector<cv::Rect> taken_;
};

}  // namespace

std::string RenderParams::FirstProblem() const {
  if (width < 64 || width > 8192 || width % 2 != 0)
    return Bad("width", width, "must be even and in [64, 8192] px");
  if (height < 64 || height > 8192 || height % 2 != 0)
    return Bad("height", height, "must be even and in [64, 8192] px");
  if (!(zoom > 0.0) || !std::isfinite(zoom) || zoom > 10000.0)
    return Bad("zoom", zoom, "must be in (0, 10000] px/m");
  if (follow == Follow::kWindow) {
    const Eigen::Vector2d s = window.sizes();
    if (!window.min().allFinite() || !window.max().allFinite() || !(s.x() > 0.0) || !(s.y() > 0.0))
      return Bad("window", s.minCoeff(), "must have finite corners and positive width and height [m]");
  }
  if (!(ellipse_sigma > 0.0) || !std::isfinite(ellipse_sigma) || ellipse_sigma > 100.0)
    return Bad("ellipse_sigma", ellipse_sigma, "must be in (0, 100]");
  if (point_size < 1 || point_size > 20) return Bad("point_size", point_size, "must be in [1, 20] px");
  return {};
}

View MakeView(const RenderParams& params, const Scene& scene) {
  if (params.follow == RenderParams::Follow::kWindow) {
    return FitView(params.window, params.width, params.height);
  }
  // Only positions within a plausible world (|x|, |y| < 1e7 m) can centre the view.
  auto plausible = [](const Eigen::Vector2d& p) {
    return p.allFinite() && p.cwiseAbs().maxCoeff() < 1e7;
  };
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  const auto followed = std::find_if(scene.tracks.begin(), scene.tracks.end(), [&](const auto& t) {
    return params.follow == RenderParams::Follow::kTrack && t.id == params.follow_track_id &&
           plausible(t.box.center);
  });
  if (followed != scene.tracks.end()) {
    center = followed->box.center;
  } else if (scene.ego && plausible(scene.ego->position)) {
    center = scene.ego->position;
  } else {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int n = 0;
    for (const auto& t : scene.tracks) {
      if (plausible(t.box.center)) {
        sum += t.box.center;
        ++n;
      }
    }
    if (n == 0) {
      for (const auto& p : scene.points) {
        if (plausible(p.cast<double>())) {
          sum += p.cast<double>();
          ++n;
        }
      }
    }
    if (n > 0) center = sum / n;
  }
  return CenteredView(center, params.zoom, params.width, params.height);
}

Segment RearAxleSegment(const OrientedBox& box, double rear_axle_offset) {
  const Eigen::Vector2d c = box.center + rear_axle_offset * box.Axis();
  const Eigen::Vector2d half = 0.5 * box.width * box.Normal();
  return {c - half, c + half};
}

cv::Mat Render(const Scene& scene, const RenderParams& params) {
  cv::Mat image;
  Render(scene, params, MakeView(params, scene), &image);
  return image;
}

void Render(const Scene& scene, const RenderParams& params, const View& view, cv::Mat* image) {
  if (const std::string err = params.FirstProblem(); !err.empty()) throw std::invalid_argument(err);
  if (view.width != params.width || view.height != params.height || !(view.px_per_m > 0.0) ||
      !view.center.allFinite()) {
    throw std::invalid_argument("render: view " + std::to_string(view.width) + "x" +
                                std::to_string(view.height) + " at " +
                                std::to_string(view.px_per_m) +
                                " px/m does not match the parameters or is not finite");
  }
  image->create(params.height, params.width, CV_8UC3);
  image->setTo(color::kBackground);
  Canvas cv(image, view, params.antialias);
  Font font;
  font.scale = std::clamp(0.45 * params.height / 960.0, 0.35, 1.2);
  font.line_type = params.antialias ? cv::LINE_AA : cv::LINE_8;
  const double sigma = params.ellipse_sigma;

  if (params.show_grid) DrawGrid(cv, font);

  // Which tracks are drawn, and their debug entries.
  std::vector<const SceneTrack*> tracks;
  std::map<std::int64_t, const SceneTrack*> track_by_id;
  bool any_clutter = false, any_hypotheses = false;
  for (const auto& t : scene.tracks) {
    track_by_id[t.id] = &t;
    if (IsClutter(t) && !params.show_clutter) continue;
    any_clutter |= IsClutter(t);
    tracks.push_back(&t);
  }
  // Debug entries of vehicles (and of tracks not in the list). Clutter keeps its associated
  // points (shown with the clutter) but not the fit detail, which would only crowd the view.
  std::vector<const SceneMeasurement*> measurements, clutter_measurements;
  std::map<std::int64_t, const SceneMeasurement*> measurement_by_track;
  for (const auto& m : scene.measurements) {
    const auto it = track_by_id.find(m.track_id);
    if (it != track_by_id.end() && IsClutter(*it->second)) {
      if (params.show_clutter) clutter_measurements.push_back(&m);
      continue;
    }
    measurements.push_back(&m);
    measurement_by_track[m.track_id] = &m;
  }

  // Ground truth: the true path and the true box, thin red.
  const bool draw_truth =
      params.show_truth && std::any_of(scene.truths.begin(), scene.truths.end(),
                                       [](const SceneTruth& g) { return !g.is_clutter; });
  if (draw_truth) {
    for (const auto& g : scene.truths) {
      if (g.is_clutter) continue;  // walls, poles, bushes: nothing to compare a track with
      const cv::Scalar& c = g.in_labelled_region ? color::kTruth : color::kTruthOutside;
      cv.Polyline(g.path, c, 1, /*closed=*/false);
      cv.Box(g.box, c, 1);
    }
  }

  cv.Points(scene.points, color::kPoint, params.point_size);
  for (const auto* list : {&clutter_measurements, &measurements}) {
    for (const auto* m : *list) cv.Points(m->points, color::kAssociatedPoint, params.point_size + 1);
  }

  if (scene.ego) {
    cv.Polyline(scene.ego->past, color::kEgoPath, 2, /*closed=*/false);
    cv.FilledBox(scene.ego->box, color::kEgo);
    // A white triangle marks the front of the ego vehicle, when it is big enough to see.
    const OrientedBox& b = scene.ego->box;
    if (b.center.allFinite() && std::isfinite(b.theta) && b.length * cv.view().px_per_m >= 24.0) {
      const Eigen::Vector2d tip = b.center + 0.42 * b.length * b.Axis();
      const Eigen::Vector2d base = b.center + 0.12 * b.length * b.Axis();
      cv.FilledPolygon({tip, base + 0.3 * b.width * b.Normal(), base - 0.3 * b.width * b.Normal()},
                       cv::Scalar(255, 255, 255));
    }
  }

  // Paths under the rectangles: recent (blue, ends at the centre), predicted (black, from it).
  for (const auto* t : tracks) {
    if (IsClutter(*t)) continue;
    std::vector<Eigen::Vector2d> past = t->past;
    if (!past.empty() && t->box.center.allFinite()) past.push_back(t->box.center);
    cv.Polyline(past, color::kPastPath, 2, /*closed=*/false);
    std::vector<Eigen::Vector2d> pred;
    if (!t->predicted.empty()) pred.push_back(t->box.center);
    pred.insert(pred.end(), t->predicted.begin(), t->predicted.end());
    cv.Polyline(pred, color::kPredictedPath, 2, /*closed=*/false);
  }

  // Hypotheses of each mover (Figure 6 b-d): every non-selected one, thin, with its axle.
  if (params.show_hypotheses) {
    for (const auto* m : measurements) {
      for (const auto& h : m->hypotheses) {
        if (h.selected) continue;
        any_hypotheses = true;
        const cv::Scalar& c =
            h.model == MotionModel::kVasm ? color::kHypothesisVasm : color::kHypothesisIsm;
        cv.Box(h.box, c, 1);
        if (std::isfinite(h.rear_axle_offset)) {
          const Segment s = RearAxleSegment(h.box, h.rear_axle_offset);
          cv.Line(s.first, s.second, c, 1, /*dashed=*/true);
        }
        if (params.show_labels && h.box.center.allFinite()) {
          const auto corners = h.box.Corners();
          Eigen::Vector2d lowest = cv.W(corners[0]);
          for (const auto& k : corners) {
            const Eigen::Vector2d p = cv.W(k);
            if (p.y() > lowest.y()) lowest = p;
          }
          if (lowest.allFinite() && lowest.cwiseAbs().maxCoeff() < 1e6) {
            Text(*image, font, "h" + std::to_string(h.index),
                 cv::Point(static_cast<int>(lowest.x()) - 8, static_cast<int>(lowest.y()) + 14),
                 c, false);
          }
        }
      }
    }
  }

  // Measurement z: green rectangle and its position covariance (Eq. 17, 18).
  for (const auto* m : measurements) {
    if (m->fit_kind == FitKind::kNone) continue;
    cv.Box(m->z_box, color::kMeasurement, 2);
    cv.CovarianceEllipse(m->z_box.center, m->R.topLeftCorner<2, 2>(), sigma, color::kMeasurement, 1);
  }
  // Fitted, visible edges: dashed black.
  for (const auto* m : measurements) {
    for (const auto& e : m->edges) cv.Line(e.first, e.second, color::kFittedEdge, 2, /*dashed=*/true);
  }

  // Updated state: orange rectangle and its position covariance; VASM rear axle dashed red.
  for (const auto* t : tracks) {
    if (IsClutter(*t)) {
      cv.Box(t->box, color::kClutter, 1);
      continue;
    }
    const bool coasting = t->status == TrackStatus::kCoasting;
    cv.Box(t->box, color::kState, StateThickness(*t), coasting);
    cv.CovarianceEllipse(t->box.center, t->cov.topLeftCorner<2, 2>(), sigma, color::kState, 1);
    std::optional<Segment> axle;
    if (std::isfinite(t->rear_axle_offset)) {
      axle = RearAxleSegment(t->box, t->rear_axle_offset);
    } else if (const auto it = measurement_by_track.find(t->id);
               it != measurement_by_track.end() && it->second->rear_axle) {
      axle = it->second->rear_axle;
    }
    if (axle) cv.Line(axle->first, axle->second, color::kRearAxle, 2, /*dashed=*/true);
  }

  if (params.show_labels) {
    // Movers first, then confirmed vehicles, then the rest; clutter last, small and grey.
    auto rank = [](const SceneTrack& t) {
      if (IsClutter(t)) return 3;
      if (t.moving) return 0;
      return t.status == TrackStatus::kConfirmed ? 1 : 2;
    };
    std::vector<const SceneTrack*> order = tracks;
    std::stable_sort(order.begin(), order.end(),
                     [&](const auto* a, const auto* b) { return rank(*a) < rank(*b); });
    Font small = font;
    small.scale *= 0.85;
    LabelPlacer labels(image, cv);
    for (const auto* t : order) {
      if (IsClutter(*t)) {
        labels.Place(t->box, {TrackLabel(*t)}, small, color::kGridText, false);
      } else {
        std::ostringstream id;  // (not "#" + std::to_string: GCC 12 warns falsely, -Wrestrict)
        id << '#' << t->id;
        labels.Place(t->box, {TrackLabel(*t), id.str()}, font, color::kText, true);
      }
    }
  }

  DrawScaleBar(cv, font);
  DrawTimeStamp(scene, *image, font);

  if (params.show_legend) {
    const std::string sig = FormatNumber(sigma, sigma == std::floor(sigma) ? 0 : 1);
    std::vector<LegendEntry> legend = {
        {Swatch::kDot, color::kPoint, "LADAR hits"},
        {Swatch::kRect, color::kMeasurement, "measurement z (ellipse " + sig + " sigma)"},
        {Swatch::kDashed, color::kFittedEdge, "fitted visible edges"},
        {Swatch::kRect, color::kState, "updated state (ellipse " + sig + " sigma)"},
        {Swatch::kDashed, color::kRearAxle, "rear axle L (VASM)"},
        {Swatch::kLine, color::kPastPath, "recent trajectory"},
        {Swatch::kLine, color::kPredictedPath, "predicted trajectory"},
    };
    if (draw_truth) legend.push_back({Swatch::kLine, color::kTruth, "true trajectory / box", 1});
    legend.push_back({Swatch::kFilled, color::kEgo, "ego vehicle"});
    if (any_hypotheses) {
      legend.push_back({Swatch::kRect, color::kHypothesisIsm, "ISM hypothesis", 1});
      legend.push_back({Swatch::kRect, color::kHypothesisVasm, "VASM hypothesis", 1});
    }
    if (any_clutter) legend.push_back({Swatch::kRect, color::kClutter, "clutter track", 1});
    DrawLegend(legend, cv, font);
  }
}

}  // namespace vtrack::viewer
