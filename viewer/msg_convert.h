// Converters from the bus messages (lcmtypes/) to the renderer's plain structs (viewer/scene.h)
// and to the tracker core's scan and pose structs. Pure functions: no LCM bus, no I/O.
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

// world_from_body of a pose message, or nullopt (and *why) if the position is not finite or the
// quaternion is not close to unit length (|q| outside [0.9, 1.1]); it is normalised otherwise.
std::optional<Eigen::Isometry3d> PoseFromMsg(const vtrack::pose_t& msg, std::string* why = nullptr);

// The scan as the tracker core's struct (arrays copied). nullopt (and *why) if the mounting pose
// is not finite or its quaternion not close to unit length.
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
