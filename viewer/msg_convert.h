// Converters from the bus messages (lcmtypes/) to the renderer's plain structs (viewer/scene.h),
// and checked wrappers of the tracker's own scan and pose conversions. Pure functions: no LCM
// bus, no I/O.
#pragma once

#include <Eigen/Geometry>

#include <optional>
#include <string>

#include "tracker/core/scan.h"
#include "viewer/scene.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_debug_entry_t.hpp"
#include "vtrack/track_t.hpp"

namespace vtrack::viewer {

// world_from_body of a pose message, converted as the tracker converts it (tracker/lcm_convert.h:
// a quaternion within 1e-3 of unit length is normalised), or nullopt (and *why, with the values)
// if the result is not a rigid transform.
std::optional<Eigen::Isometry3d> PoseFromMsg(const vtrack::pose_t& msg, std::string* why = nullptr);

// The scan as the tracker core's struct, converted as the tracker converts it (arrays copied),
// or nullopt (and *why) if the sensor's mounting is not a rigid transform.
std::optional<LadarScan> ScanFromMsg(const vtrack::ladar_scan_t& msg, std::string* why = nullptr);

// The reported state of a track; `past` is left empty (the trail is kept over time elsewhere),
// `predicted` is the track's predicted trajectory.
SceneTrack TrackFromMsg(const vtrack::track_t& msg);

// One track's debug entry. The measurement rectangle and the hypotheses take the vehicle's
// length and width from the entry's predicted rectangle (the estimate the fit used, Eq. 17),
// falling back to its updated rectangle and then to `track` (may be null).
SceneMeasurement MeasurementFromMsg(const vtrack::track_debug_entry_t& msg,
                                    const SceneTrack* track);

// One ground-truth object; `path` is left empty.
SceneTruth TruthFromMsg(const vtrack::object_t& msg);

}  // namespace vtrack::viewer
