// Orientation rules: which axis of a fitted rectangle is the vehicle's length axis, and which
// way it points. A fit gives the heading modulo 90 deg (corner) or 180 deg (edge); these rules
// settle it (track_manager.h, "Orientation at the mover declaration" and "Axis of a stationary
// object"). Every turn goes through TurnAxis.
#pragma once

#include <Eigen/Core>

#include <cstdint>

#include "tracker/core/ekf.h"
#include "tracker/core/measurement.h"
#include "tracker/core/range_profile.h"
#include "tracker/core/track.h"
#include "tracker/core/parameters.h"

namespace vtrack {

// Turns h's heading by quarter_turns x 90 deg, converting its state into model `kind`
// (Ekf::Convert); an odd number of quarter turns swaps length and width, and what was seen of
// each.
void TurnAxis(const Ekf& ekf, ModelKind kind, int quarter_turns, TrackHypothesis* h);

// A moving vehicle drives along its length axis: each ISM hypothesis whose heading is more than
// 45 deg + ambiguity_deg / 2 off the velocity heading turns by the multiple of 90 deg that
// brings it nearest (a half turn for one pointing backwards).
void AlignIsmToMotion(const Ekf& ekf, double ambiguity_deg, Track* t);

// A VASM started from one fit may point backwards ((theta + pi, -v, -L) is the same motion):
// turned to point along its motion.
void AlignVasmToMotion(Track* t);

// A stationary object's length axis is its longer side: once the "width" estimate exceeds
// axis_swap_ratio x the "length" and any vehicle's length (vehicle_min_length), its hypotheses
// (ISM, CV or VASM) turn by 90 deg.
void AlignToShape(const Ekf& ekf, const TrackManagerParams& params, Track* t);

// A fitted face seen whole (free space or only farther returns just beyond both ends, in the
// scan's range profile), shorter than vehicle_min_length and not shorter than the shape estimate
// along it (by more than 0.5 m: then part of it was unseen) is a front or rear face: the heading
// is across it. If the heading ran along it, the ISM hypotheses turn by 90 deg and are measured
// afresh (the centre moves with the axis). Sets t->axis_from_full_face and the face's extent.
void AlignToFullFace(const Ekf& ekf, const TrackManagerParams& params, const PointSet& points,
                     const Eigen::Vector2d& sensor_xy, std::uint64_t seed,
                     const RangeProfile& profile, TrackMeasurer* measurer, Track* t);

}  // namespace vtrack
