// Offscreen top-down renderer in the style of the paper's Figure 4 (no display needed).
//
// What is drawn, back to front, and in which colour (viewer/README.md has the same table):
//   metric grid                                light grey, labelled in world metres
//   true trajectory and true boxes             red, thin (where ground truth exists; not for
//                                              walls, poles and bushes)
//   LADAR hits                                 grey dots; points associated with a track darker
//   ego vehicle and its recent path            blue (filled rectangle, light-blue path)
//   recent trajectory of each track            blue
//   predicted trajectory of each track         black
//   hypotheses of a mover (Fig. 6, optional)   thin purple (ISM) / teal (VASM), with their axles
//   measurement z and its position covariance  green rectangle and ellipse (Eq. 17, 18)
//   fitted, visible edges                      dashed black
//   updated state and its position covariance  orange rectangle and ellipse (Eq. 19)
//   estimated rear axle (VASM's L)             dashed red line across the vehicle
//   clutter tracks (class "other")             thin brown rectangle
//   label: id, model, speed, hypothesis count, beside each track
//          vehicle probability (p=)
//   scale bar, time stamp, legend              corners of the frame
// Tentative tracks are drawn thin, coasting tracks dashed. Ellipses are drawn at
// RenderParams::ellipse_sigma standard deviations of the 2x2 position block.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

#include "viewer/scene.h"
#include "viewer/validate.h"
#include "viewer/view.h"

namespace vtrack::viewer {

// Colours (OpenCV order: blue, green, red).
namespace color {
inline const cv::Scalar kBackground(255, 255, 255);
inline const cv::Scalar kGrid(232, 232, 232);
inline const cv::Scalar kGridText(150, 150, 150);
inline const cv::Scalar kPoint(165, 165, 165);
inline const cv::Scalar kAssociatedPoint(80, 80, 80);
inline const cv::Scalar kMeasurement(0, 160, 0);
inline const cv::Scalar kFittedEdge(0, 0, 0);
inline const cv::Scalar kState(0, 140, 255);
inline const cv::Scalar kRearAxle(0, 0, 220);
inline const cv::Scalar kPastPath(200, 90, 30);
inline const cv::Scalar kPredictedPath(0, 0, 0);
inline const cv::Scalar kTruth(40, 40, 200);
inline const cv::Scalar kTruthOutside(150, 150, 235);  // truth outside the labelled region
inline const cv::Scalar kEgo(200, 90, 30);
inline const cv::Scalar kEgoPath(240, 190, 140);
inline const cv::Scalar kHypothesisIsm(170, 40, 170);
inline const cv::Scalar kHypothesisVasm(150, 150, 0);
inline const cv::Scalar kClutter(70, 110, 150);
inline const cv::Scalar kText(20, 20, 20);
}  // namespace color

struct RenderParams {
  enum class Follow { kEgo, kWindow, kTrack };

  int width = 1280;                   // [px] frame width; even (video encoders need it)
  int height = 960;                   // [px] frame height; even
  Follow follow = Follow::kEgo;       // [-] centre on the ego vehicle, a fixed window, or a track
  double zoom = 10.0;                 // [px/m] scale when following the ego or a track
  std::int64_t follow_track_id = 0;   // [-] kTrack: the track to centre on (the ego while absent)
  Eigen::AlignedBox2d window{Eigen::Vector2d(-50, -50), Eigen::Vector2d(50, 50)};  // [m] kWindow
  double ellipse_sigma = 3.0;         // [-] covariance ellipses at this many standard deviations
  int point_size = 2;                 // [px] side of the square drawn for each LADAR hit
  bool show_hypotheses = false;       // [-] every hypothesis of each mover (Fig. 6 b-d)
  bool show_clutter = true;           // [-] tracks classed "other" (clutter)
  bool show_truth = true;             // [-] ground truth boxes and true trajectories
  bool show_grid = true;              // [-] metric grid
  bool show_legend = true;            // [-] colour legend
  bool show_labels = true;            // [-] id / model / speed / hypotheses beside each track
  bool antialias = true;              // [-] anti-aliased lines and text

  // True if every field is valid; otherwise false and *error names the key and its value.
  bool Validate(std::string* error) const { return ValidateByFirstProblem(*this, error); }
  std::string FirstProblem() const;  // "" if valid
};

// The view a frame uses: the fixed window, or centred at `zoom` on the followed track if it is in
// the scene, else on the ego (or, without one, on the mean of the tracks, of the points, or on
// the origin, in that order).
View MakeView(const RenderParams& params, const Scene& scene);

// Renders the scene into a new width x height BGR image. Throws std::invalid_argument if the
// parameters are invalid. Geometry that is not finite is skipped, never drawn at a wrong place.
cv::Mat Render(const Scene& scene, const RenderParams& params);
// Same, with a given view, into *image (reallocated if its size or type differ).
void Render(const Scene& scene, const RenderParams& params, const View& view, cv::Mat* image);

// The rear-axle segment of a rectangle whose rotation axis lies L metres ahead of the centre along
// the length axis (L < 0: behind): the line across the vehicle, from its right side to its left.
Segment RearAxleSegment(const OrientedBox& box, double rear_axle_offset);

}  // namespace vtrack::viewer
