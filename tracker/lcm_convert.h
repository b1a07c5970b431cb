// Conversions between the LCM messages (lcmtypes/) and the tracker core's plain structs. The
// only place where the two meet: the core never sees an LCM type.
#pragma once

#include <string>

#include "lcmtypes/util/ladar_slices.h"
#include "tracker/core/scan.h"
#include "tracker/core/tracker.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/detection_list_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_debug_t.hpp"
#include "vtrack/track_list_t.hpp"

namespace vtrack {

// Moves the point arrays out of msg (no copy); msg's arrays are left empty.
LadarScan ScanFromLcm(ladar_scan_t&& msg);
// Gives msg the point arrays of a scan the tracker is done with (Tracker::TakeSpareScan), so that
// decoding into msg (lcm_util::Decode, which resizes each array to npoints and overwrites it)
// reuses their memory.
void LendArrays(LadarScan&& spare, ladar_scan_t* msg);
// A sweep assembled from slices: its scan moved out, its missing arcs as the lost wedges.
LadarScan ScanFromLcm(lcm_util::AssembledSweep&& sweep);
// A quaternion within 1e-3 of unit length is normalised; others are passed on as they are and
// refused by the core as "invalid_pose".
EgoPose PoseFromLcm(const pose_t& msg);

// A detector's boxes as the core takes them.
DetectionList DetectionsFromLcm(const detection_list_t& msg);

track_t TrackToLcm(const TrackReport& r);
track_list_t TrackListToLcm(const ScanOutput& out, const std::string& mode, std::int64_t latency_us);
track_debug_t DebugToLcm(const ScanOutput& out);

}  // namespace vtrack
