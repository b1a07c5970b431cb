// Pixel tests of the renderer: a frame with a known track is rendered and every element is looked
// for where the track's geometry and the view's scale and origin put it. The expected pixel
// positions are computed here from first principles (corner = centre +- L/2 axis +- W/2 normal;
// u = W/2 + s (x - cx), v = H/2 - s (y - cy); the ellipse's bounding box is +- k sqrt(P_xx),
// +- k sqrt(P_yy)), not by the drawing code.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <cmath>
#include <limits>
#include <vector>

#include "tests/viewer/pixel_util.h"
#include "base/angle.h"
#include "viewer/renderer.h"

namespace vtrack::viewer {
namespace {

using testing::ColorNear;
using testing::DistanceToSegment;
using testing::IsColor;
using testing::PixelsOf;
using testing::SaveIfRequested;

constexpr int kWidth = 800, kHeight = 600;
constexpr double kScale = 40.0;                  // [px/m]: a 20 m x 15 m window fills 800 x 600
const Eigen::Vector2d kViewCenter(11.0, 4.0);    // [m]

// The projection written out independently of View: u right, v down, centre pixel (W/2, H/2).
Eigen::Vector2d Project(const Eigen::Vector2d& w) {
  return {kWidth / 2.0 + kScale * (w.x() - kViewCenter.x()),
          kHeight / 2.0 - kScale * (w.y() - kViewCenter.y())};
}

// Corners of a rectangle from its centre, heading, length and width.
std::vector<Eigen::Vector2d> Corners(const Eigen::Vector2d& c, double theta, double length,
                                     double width) {
  const Eigen::Vector2d a(std::cos(theta), std::sin(theta)), n(-std::sin(theta), std::cos(theta));
  return {c + 0.5 * length * a + 0.5 * width * n, c - 0.5 * length * a + 0.5 * width * n,
          c - 0.5 * length * a - 0.5 * width * n, c + 0.5 * length * a - 0.5 * width * n};
}

// Points on the k-sigma ellipse of a 2x2 covariance through its Cholesky factor (P = L L^T maps
// the unit circle onto the 1-sigma ellipse) - a different construction from the renderer's.
std::vector<Eigen::Vector2d> EllipseCurve(const Eigen::Vector2d& c, const Eigen::Matrix2d& p,
                                          double k) {
  const Eigen::Matrix2d l = p.llt().matrixL();
  std::vector<Eigen::Vector2d> out;
  for (int i = 0; i < 2000; ++i) {
    const double t = 2.0 * kPi * i / 2000.0;
    out.push_back(c + k * l * Eigen::Vector2d(std::cos(t), std::sin(t)));
  }
  return out;
}

double DistanceToPolygon(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& poly_px) {
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < poly_px.size(); ++i) {
    d = std::min(d, DistanceToSegment(p, poly_px[i], poly_px[(i + 1) % poly_px.size()]));
  }
  return d;
}

double DistanceToCurve(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& curve_px) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& q : curve_px) d = std::min(d, (q - p).norm());
  return d;
}

std::vector<Eigen::Vector2d> ProjectAll(const std::vector<Eigen::Vector2d>& w) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : w) out.push_back(Project(p));
  return out;
}

// Fraction of points every step px along a-b that have a pixel of the colour within radius.
double Coverage(const cv::Mat& img, const cv::Scalar& c, const Eigen::Vector2d& a,
                const Eigen::Vector2d& b, double radius, double step = 1.0) {
  const int n = std::max(2, static_cast<int>((b - a).norm() / step));
  int hits = 0;
  for (int i = 0; i <= n; ++i) hits += ColorNear(img, c, a + (b - a) * i / n, radius);
  return static_cast<double>(hits) / (n + 1);
}

struct KnownScene {
  Eigen::Vector2d center{10.0, 5.0};          // [m]
  double theta = DegToRad(30.0);              // [rad]
  double length = 4.6, width = 2.0;           // [m]
  double rear_axle = -1.3;                    // [m] L
  Eigen::Matrix2d cov;                        // [m^2] state position covariance
  Eigen::Vector2d z_center;                   // [m] measurement
  double z_theta = DegToRad(32.0);
  Eigen::Matrix2d r;                          // [m^2] measurement position covariance
  Segment edge1{{14.0, 0.5}, {17.0, 0.5}}, edge2{{14.0, 0.5}, {14.0, 2.5}};  // [m] fitted edges

  KnownScene() {
    cov << 0.06, 0.015, 0.015, 0.03;
    r << 0.05, -0.01, -0.01, 0.02;
    // The measurement 3.2 m to the left of the track, so the two rectangles do not touch.
    z_center = center + 3.2 * Eigen::Vector2d(-std::sin(theta), std::cos(theta));
  }

  // The covariance of (x, y, theta) with the given position block and theta variance.
  static Eigen::Matrix3d PoseCovariance(const Eigen::Matrix2d& position, double theta_variance) {
    Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
    c.topLeftCorner<2, 2>() = position;
    c(2, 2) = theta_variance;
    return c;
  }

  Scene Make() const {
    Scene s;
    s.utime = 1'700'000'000'000'000;
    SceneTrack t;
    t.id = 7;
    t.model = MotionModel::kVasm;
    t.moving = true;
    t.object_class = TrackClass::kVehicle;
    t.box = {center, theta, length, width};
    t.cov = PoseCovariance(cov, 0.01);
    t.rear_axle_offset = rear_axle;
    t.speed = 6.0;
    t.num_hypotheses = 2;
    s.tracks.push_back(t);
    SceneMeasurement m;
    m.track_id = 7;
    m.fit_kind = FitKind::kCorner;
    m.z_box = {z_center, z_theta, length, width};
    m.R = PoseCovariance(r, 0.004);
    m.edges = {edge1, edge2};
    s.measurements.push_back(m);
    return s;
  }
};

RenderParams TestParams() {
  RenderParams p;
  p.width = kWidth;
  p.height = kHeight;
  p.follow = RenderParams::Follow::kWindow;
  p.window = Eigen::AlignedBox2d(kViewCenter - Eigen::Vector2d(10.0, 7.5),
                                 kViewCenter + Eigen::Vector2d(10.0, 7.5));
  // The legend and labels carry the same colours as the drawing; they are tested separately.
  p.show_legend = false;
  p.show_labels = false;
  p.show_grid = false;
  return p;
}

TEST(ViewTest, ProjectionMatchesTheWrittenOutFormula) {
  const View v = FitView(TestParams().window, kWidth, kHeight);
  EXPECT_DOUBLE_EQ(v.px_per_m, kScale);
  for (const Eigen::Vector2d& w : {Eigen::Vector2d(11.0, 4.0), Eigen::Vector2d(1.0, -3.5),
                                  Eigen::Vector2d(20.9, 11.4), Eigen::Vector2d(-100.0, 250.0)}) {
    EXPECT_NEAR((v.WorldToImage(w) - Project(w)).norm(), 0.0, 1e-9) << w.transpose();
    EXPECT_NEAR((v.ImageToWorld(v.WorldToImage(w)) - w).norm(), 0.0, 1e-9);
  }
  const Eigen::AlignedBox2d b = v.WorldBounds();
  EXPECT_NEAR((b.min() - Eigen::Vector2d(1.0, -3.5)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((b.max() - Eigen::Vector2d(21.0, 11.5)).norm(), 0.0, 1e-9);
}

class KnownTrackTest : public ::testing::TestWithParam<std::tuple<double, double>> {};

// The orange state rectangle and its ellipse, the green measurement and its ellipse, the dashed
// red rear axle and the dashed black fitted edges, each where the geometry puts it.
TEST_P(KnownTrackTest, ElementsAtTheirProjectedPixels) {
  KnownScene k;
  k.rear_axle = std::get<0>(GetParam());
  const double sigma = std::get<1>(GetParam());
  RenderParams params = TestParams();
  params.ellipse_sigma = sigma;
  const Scene scene = k.Make();
  const View view = MakeView(params, scene);
  ASSERT_NEAR((view.WorldToImage(k.center) - Project(k.center)).norm(), 0.0, 1e-9);
  const cv::Mat img = Render(scene, params);
  SaveIfRequested("known_track_" + std::to_string(k.rear_axle) + "_" + std::to_string(sigma), img);
  ASSERT_EQ(img.cols, kWidth);
  ASSERT_EQ(img.rows, kHeight);

  const auto state_px = ProjectAll(Corners(k.center, k.theta, k.length, k.width));
  const auto z_px = ProjectAll(Corners(k.z_center, k.z_theta, k.length, k.width));
  const auto state_ellipse = ProjectAll(EllipseCurve(k.center, k.cov, sigma));
  const auto z_ellipse = ProjectAll(EllipseCurve(k.z_center, k.r, sigma));
  const Eigen::Vector2d axis(std::cos(k.theta), std::sin(k.theta));
  const Eigen::Vector2d normal(-std::sin(k.theta), std::cos(k.theta));
  const Eigen::Vector2d axle_a = Project(k.center + k.rear_axle * axis - 0.5 * k.width * normal);
  const Eigen::Vector2d axle_b = Project(k.center + k.rear_axle * axis + 0.5 * k.width * normal);

  // Corners and edges: every corner has its colour within 1.5 px, and the edges are covered
  // (apart from where the red axle is drawn over the orange sides).
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(ColorNear(img, color::kState, state_px[i], 1.5)) << "state corner " << i;
    EXPECT_TRUE(ColorNear(img, color::kMeasurement, z_px[i], 1.5)) << "z corner " << i;
    EXPECT_GT(Coverage(img, color::kMeasurement, z_px[i], z_px[(i + 1) % 4], 1.5), 0.97);
    int covered = 0, n = 0;
    const Eigen::Vector2d a = state_px[i], b = state_px[(i + 1) % 4];
    for (int s = 0; s <= 100; ++s) {
      const Eigen::Vector2d p = a + (b - a) * s / 100.0;
      if ((p - axle_a).norm() < 4.0 || (p - axle_b).norm() < 4.0) continue;
      ++n;
      covered += ColorNear(img, color::kState, p, 1.5);
    }
    EXPECT_GT(static_cast<double>(covered) / n, 0.97) << "state edge " << i;
  }

  // No orange or green pixel anywhere but on its rectangle or its ellipse.
  for (const auto& [c, rect, ellipse, name] :
       {std::make_tuple(color::kState, state_px, state_ellipse, "state"),
        std::make_tuple(color::kMeasurement, z_px, z_ellipse, "measurement")}) {
    int stray = 0;
    std::vector<Eigen::Vector2d> ellipse_pixels;
    for (const auto& p : PixelsOf(img, c)) {
      const double d_rect = DistanceToPolygon(p, rect);
      const double d_ell = DistanceToCurve(p, ellipse);
      if (std::min(d_rect, d_ell) > 2.5) ++stray;
      if (d_rect > 4.0) ellipse_pixels.push_back(p);
    }
    EXPECT_EQ(stray, 0) << name;

    // The ellipse's extent: its bounding box is +- sigma sqrt(P_xx) by +- sigma sqrt(P_yy) about
    // the centre (the support function of x^T P^-1 x = sigma^2 along the axes).
    const Eigen::Matrix2d& p = std::string(name) == "state" ? k.cov : k.r;
    const Eigen::Vector2d centre = Project(std::string(name) == "state" ? k.center : k.z_center);
    ASSERT_GT(ellipse_pixels.size(), 50u) << name;
    Eigen::Vector2d lo = ellipse_pixels[0], hi = ellipse_pixels[0];
    for (const auto& q : ellipse_pixels) {
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
    const double half_u = sigma * std::sqrt(p(0, 0)) * kScale;
    const double half_v = sigma * std::sqrt(p(1, 1)) * kScale;
    EXPECT_NEAR(0.5 * (hi.x() - lo.x()), half_u, 1.5) << name;
    EXPECT_NEAR(0.5 * (hi.y() - lo.y()), half_v, 1.5) << name;
    EXPECT_NEAR(0.5 * (hi.x() + lo.x()), centre.x(), 1.0) << name;
    EXPECT_NEAR(0.5 * (hi.y() + lo.y()), centre.y(), 1.0) << name;
  }

  // Rear axle: red only on the segment across the vehicle at L, dashed, spanning it.
  const auto red = PixelsOf(img, color::kRearAxle);
  ASSERT_FALSE(red.empty());
  const Eigen::Vector2d dir = (axle_b - axle_a).normalized();
  double tmin = 1e9, tmax = -1e9;
  for (const auto& p : red) {
    EXPECT_LT(DistanceToSegment(p, axle_a, axle_b), 2.5) << p.transpose();
    tmin = std::min(tmin, (p - axle_a).dot(dir));
    tmax = std::max(tmax, (p - axle_a).dot(dir));
  }
  const double axle_len = (axle_b - axle_a).norm();
  EXPECT_GT(tmax - tmin, 0.75 * axle_len);
  // Dashed: most of the line has its colour within 1.5 px, but the pixels on the line itself
  // show gaps.
  EXPECT_GT(Coverage(img, color::kRearAxle, axle_a, axle_b, 1.5), 0.6) << "rear axle missing";
  EXPECT_LT(Coverage(img, color::kRearAxle, axle_a, axle_b, 0.75), 0.85) << "not dashed";

  // Fitted edges: dashed black along each.
  for (const auto& e : {k.edge1, k.edge2}) {
    const Eigen::Vector2d a = Project(e.first), b = Project(e.second);
    EXPECT_GT(Coverage(img, color::kFittedEdge, a, b, 1.5), 0.6) << "fitted edge missing";
    EXPECT_LT(Coverage(img, color::kFittedEdge, a, b, 0.75), 0.85) << "fitted edge not dashed";
  }
}

INSTANTIATE_TEST_SUITE_P(AxleAndSigma, KnownTrackTest,
                         ::testing::Values(std::make_tuple(-1.3, 3.0), std::make_tuple(0.6, 3.0),
                                           std::make_tuple(-1.3, 2.0)));

TEST(RendererTest, CoastingTrackIsDashedAndTentativeThin) {
  KnownScene k;
  Scene s = k.Make();
  s.measurements.clear();
  s.tracks[0].rear_axle_offset = std::numeric_limits<double>::quiet_NaN();
  const auto corners = ProjectAll(Corners(k.center, k.theta, k.length, k.width));
  const RenderParams params = TestParams();

  s.tracks[0].status = TrackStatus::kConfirmed;
  const cv::Mat solid = Render(s, params);
  s.tracks[0].status = TrackStatus::kCoasting;
  const cv::Mat dashed = Render(s, params);
  EXPECT_GT(Coverage(solid, color::kState, corners[0], corners[1], 0.75), 0.97);
  EXPECT_GT(Coverage(dashed, color::kState, corners[0], corners[1], 1.5), 0.6);
  EXPECT_LT(Coverage(dashed, color::kState, corners[0], corners[1], 0.75), 0.85);

  s.tracks[0].status = TrackStatus::kTentative;
  const cv::Mat thin = Render(s, params);
  EXPECT_LT(PixelsOf(thin, color::kState).size(), PixelsOf(solid, color::kState).size());
}

TEST(RendererTest, HypothesesOnlyWhenAsked) {
  KnownScene k;
  Scene s = k.Make();
  SceneHypothesis ism;
  ism.index = 0;
  ism.selected = true;
  ism.box = s.tracks[0].box;
  SceneHypothesis vasm;
  vasm.index = 1;
  vasm.model = MotionModel::kVasm;
  vasm.box.center = k.center + Eigen::Vector2d(1.0, -2.5);
  vasm.box.theta = DegToRad(40.0);
  vasm.box.length = k.length;
  vasm.box.width = k.width;
  vasm.rear_axle_offset = -1.0;
  s.measurements[0].hypotheses = {ism, vasm};

  RenderParams params = TestParams();
  params.show_hypotheses = false;
  EXPECT_TRUE(PixelsOf(Render(s, params), color::kHypothesisVasm).empty());
  params.show_hypotheses = true;
  const cv::Mat img = Render(s, params);
  for (const auto& c : ProjectAll(Corners(vasm.box.center, vasm.box.theta, k.length, k.width))) {
    EXPECT_TRUE(ColorNear(img, color::kHypothesisVasm, c, 1.5)) << c.transpose();
  }
  // The selected hypothesis is the orange state itself, not drawn again in the ISM colour.
  EXPECT_TRUE(PixelsOf(img, color::kHypothesisIsm).empty());
}

TEST(RendererTest, ClutterShownOrHidden) {
  Scene s;
  SceneTrack t;
  t.id = 3;
  t.object_class = TrackClass::kOther;
  t.box.center = {8.0, 2.0};
  t.box.theta = 0.2;
  t.box.length = 1.5;
  t.box.width = 1.0;
  s.tracks.push_back(t);
  SceneMeasurement m;  // drawn with a vehicle, not with clutter
  m.track_id = 3;
  m.fit_kind = FitKind::kEdge;
  m.z_box = t.box;
  m.z_box.center += Eigen::Vector2d(0.3, 0.2);
  m.points = {Eigen::Vector2f(7.5f, 1.0f)};
  m.R = 0.01 * Eigen::Matrix3d::Identity();
  s.measurements.push_back(m);
  RenderParams params = TestParams();
  const cv::Mat shown = Render(s, params);
  SaveIfRequested("clutter_shown", shown);
  for (const auto& c : ProjectAll(Corners(t.box.center, t.box.theta, 1.5, 1.0))) {
    EXPECT_TRUE(ColorNear(shown, color::kClutter, c, 1.5));
  }
  EXPECT_TRUE(PixelsOf(shown, color::kState).empty()) << "clutter is not drawn as a vehicle";
  EXPECT_TRUE(PixelsOf(shown, color::kMeasurement).empty()) << "nor its fit";
  const Eigen::Vector2d point_px = Project({7.5, 1.0});
  EXPECT_TRUE(ColorNear(shown, color::kAssociatedPoint, point_px, 1.0)) << "its points are";
  params.show_clutter = false;
  const cv::Mat hidden = Render(s, params);
  SaveIfRequested("clutter_hidden", hidden);
  const cv::Rect around(static_cast<int>(point_px.x()) - 80, static_cast<int>(point_px.y()) - 80,
                        160, 160);
  EXPECT_TRUE(PixelsOf(hidden(around), color::kClutter).empty());
  EXPECT_FALSE(ColorNear(hidden, color::kAssociatedPoint, point_px, 1.0));
}

TEST(RendererTest, PathsEgoTruthAndPoints) {
  Scene s;
  SceneTrack t;
  t.id = 1;
  t.box.center = {12.0, 4.0};
  t.box.length = 4.0;
  t.box.width = 1.8;
  t.past = {{6.0, 4.0}, {9.0, 4.0}};
  t.predicted = {{14.0, 4.0}, {16.0, 5.0}};
  s.tracks.push_back(t);
  SceneTruth g;
  g.box.center = {12.0, 0.0};
  g.box.length = 4.0;
  g.box.width = 1.8;
  g.path = {{6.0, 0.0}, {18.0, 0.0}};
  s.truths.push_back(g);
  SceneEgo ego;
  ego.position = {4.0, 8.0};
  ego.box.center = ego.position;
  ego.box.length = 4.5;
  ego.box.width = 1.8;
  s.ego = ego;
  s.points = {Eigen::Vector2f(5.0f, 10.0f), Eigen::Vector2f(18.0f, 10.0f)};
  const cv::Mat img = Render(s, TestParams());
  EXPECT_GT(Coverage(img, color::kPastPath, Project({6.5, 4.0}), Project({9.5, 4.0}), 1.5), 0.97);
  EXPECT_GT(Coverage(img, color::kPredictedPath, Project({14.2, 4.1}), Project({15.8, 4.9}), 1.5),
            0.97);
  EXPECT_GT(Coverage(img, color::kTruth, Project({6.5, 0.0}), Project({9.0, 0.0}), 1.5), 0.97);
  EXPECT_TRUE(IsColor(img.at<cv::Vec3b>(cv::Point(Project({4.0, 8.0}).x() + 20, Project({4.0, 8.0}).y())),
                      color::kEgo, 0.9));
  for (const auto& p : s.points) {
    const Eigen::Vector2d q = Project(p.cast<double>());
    EXPECT_TRUE(IsColor(img.at<cv::Vec3b>(static_cast<int>(std::lround(q.y())),
                                          static_cast<int>(std::lround(q.x()))),
                        color::kPoint, 0.9, 5.0));
  }
}

TEST(RendererTest, LegendAndLabelsWhenOn) {
  KnownScene k;
  const Scene s = k.Make();
  RenderParams params = TestParams();
  params.show_legend = true;
  params.show_labels = true;
  const cv::Mat with = Render(s, params);
  params.show_legend = false;
  params.show_labels = false;
  const cv::Mat without = Render(s, params);
  // The legend sits in the top-left corner, away from the track.
  const cv::Rect corner(0, 0, 200, 120);
  EXPECT_FALSE(PixelsOf(with(corner), color::kState).empty());
  EXPECT_TRUE(PixelsOf(without(corner), color::kState).empty());
  // The label is dark text just right of the rectangle's right-most corner.
  const auto corners = ProjectAll(Corners(k.center, k.theta, k.length, k.width));
  double umax = 0, vmin = 1e9;
  for (const auto& c : corners) {
    umax = std::max(umax, c.x());
    vmin = std::min(vmin, c.y());
  }
  const cv::Rect label(static_cast<int>(umax) + 4, static_cast<int>(vmin) - 2, 60, 16);
  EXPECT_GT(PixelsOf(with(label), color::kText, 0.6).size(), 10u);
  EXPECT_TRUE(PixelsOf(without(label), color::kText, 0.6).empty());
}

TEST(RendererTest, FollowsTheEgo) {
  Scene s;
  SceneEgo ego;
  ego.position = {123.0, -45.0};
  ego.box.center = ego.position;
  ego.box.length = 4.5;
  ego.box.width = 1.8;
  s.ego = ego;
  RenderParams p;
  p.zoom = 7.5;
  const View v = MakeView(p, s);
  EXPECT_NEAR((v.center - ego.position).norm(), 0.0, 1e-12);
  EXPECT_EQ(v.px_per_m, 7.5);
  // Without an ego, the mean of the tracks.
  s.ego.reset();
  SceneTrack a, b;
  a.box.center = {0.0, 0.0};
  b.box.center = {10.0, 4.0};
  s.tracks = {a, b};
  EXPECT_NEAR((MakeView(p, s).center - Eigen::Vector2d(5.0, 2.0)).norm(), 0.0, 1e-12);
}

// Nothing in a scene can crash the renderer or draw outside the image: NaN, infinities and
// coordinates far beyond any image are skipped.
TEST(RendererTest, NonFiniteAndHugeGeometryIsSkipped) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Scene s;
  s.points = {Eigen::Vector2f(std::nanf(""), 1.0f), Eigen::Vector2f(1e30f, -1e30f)};
  SceneTrack t;
  t.box.center = {nan, 1.0};
  t.box.length = 4.0;
  t.box.width = 2.0;
  t.past = {{0.0, 0.0}, {nan, nan}, {1e300, -1e300}, {2.0, 2.0}};
  t.predicted = {{inf, 0.0}, {1e18, 1e18}};
  s.tracks.push_back(t);
  SceneTrack huge;
  huge.box.center = {1e200, 1e200};
  huge.box.length = 1e300;
  huge.box.width = 1e300;
  huge.cov = Eigen::Matrix3d::Constant(inf);
  huge.rear_axle_offset = 1e300;
  s.tracks.push_back(huge);
  SceneTrack bad_cov;
  bad_cov.box.center = {11.0, 4.0};
  bad_cov.box.length = 4.0;
  bad_cov.box.width = 2.0;
  bad_cov.cov << -1.0, 5.0, 0.0, 5.0, -2.0, 0.0, 0.0, 0.0, 1.0;  // not a covariance
  s.tracks.push_back(bad_cov);
  SceneMeasurement m;
  m.z_box.center = {1.0, 1.0};
  m.z_box.theta = nan;
  m.R = Eigen::Matrix3d::Constant(nan);
  m.fit_kind = FitKind::kCorner;
  m.edges = {{{nan, 0.0}, {1.0, 1.0}}, {{-1e300, 2.0}, {1e300, 2.0}}, {{-1e5, 0.0}, {1e5, 0.0}}};
  m.rear_axle = Segment({inf, 0.0}, {0.0, 0.0});
  s.measurements.push_back(m);
  SceneEgo ego;
  ego.position = {nan, nan};
  ego.box.center = {nan, nan};
  s.ego = ego;
  s.utime = -5;
  s.time_s = nan;
  for (const bool window : {true, false}) {
    RenderParams p = TestParams();
    p.show_legend = p.show_labels = p.show_grid = true;
    if (!window) p.follow = RenderParams::Follow::kEgo;
    const cv::Mat img = Render(s, p);
    EXPECT_EQ(img.cols, kWidth);
    EXPECT_EQ(img.rows, kHeight);
  }
  // The edge from x = -1e5 to 1e5 m at y = 0 is clipped to the view, not lost; the one from
  // -1e300 to 1e300 cannot be placed to a pixel and is left out.
  const cv::Mat img = Render(s, TestParams());
  SaveIfRequested("non_finite", img);
  EXPECT_GT(Coverage(img, color::kFittedEdge, Project({2.0, 0.0}), Project({20.0, 0.0}), 1.5), 0.6);
  EXPECT_EQ(Coverage(img, color::kFittedEdge, Project({2.0, 2.0}), Project({20.0, 2.0}), 1.5), 0.0);
  // The covariance that is not one (negative eigenvalue) draws no ellipse: only the rectangle.
  for (const auto& p : PixelsOf(img, color::kState)) {
    EXPECT_LT(DistanceToPolygon(p, ProjectAll(Corners({11.0, 4.0}, 0.0, 4.0, 2.0))), 2.5);
  }
}

TEST(RendererTest, InvalidParametersNameKeyAndValue) {
  RenderParams p;
  p.width = 1281;
  std::string error;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("width"), std::string::npos) << error;
  EXPECT_NE(error.find("1281"), std::string::npos) << error;
  EXPECT_THROW(Render(Scene{}, p), std::invalid_argument);
  p = RenderParams{};
  p.zoom = -2.0;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("zoom = -2"), std::string::npos) << error;
  p = RenderParams{};
  p.follow = RenderParams::Follow::kWindow;
  p.window = Eigen::AlignedBox2d(Eigen::Vector2d(0, 0), Eigen::Vector2d(0, 10));
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("window"), std::string::npos) << error;
  p = RenderParams{};
  p.ellipse_sigma = 0.0;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("ellipse_sigma = 0"), std::string::npos) << error;
  EXPECT_TRUE(RenderParams{}.Validate(&error)) << error;
}

}  // namespace
}  // namespace vtrack::viewer
