// The last step of segmentation: joining the pieces of faces seen at a grazing angle into one
// segment each.
//
// A 3-D scanner passing a parked row sees each car's side at a few degrees of incidence: one
// column of returns per azimuth step, metres apart along the face (spacing ~ range^2 * step /
// lateral offset: 1.4 m at 28 m for a 0.2 deg step and 2 m offset), each its own grid segment.
// Tracked one by one they slide with the ego (a column stays at its bearing) and re-spawn as new
// tracks. Two pieces (bounding-box diagonal < max_piece) are joined if their centroids are within
// max_gap and the line between them is within max_deg of the ray to their midpoint (a face seen
// nearly edge-on: a face seen at a larger slant is dense enough to be one grid segment already);
// joins are made nearest first and refused if the joined bounding box would exceed max_extent
// (cars of a row are 3 m apart and 4.5 m long: no chains). The joined segment replaces the
// first piece, the others are removed; returns keep their order.
#pragma once

#include <Eigen/Core>

#include "tracker/core/parameters.h"
#include "tracker/core/preprocess.h"
#include "tracker/core/segmentation.h"

namespace vtrack {

// Joins the grazing pieces of *segments (returns in pts, sensor at sensor_xy). Returns the
// number of joins.
int JoinGrazingPieces(const WorldPoints& pts, const Eigen::Vector2d& sensor_xy,
                      const GrazingJoinParams& params, Segments* segments);

}  // namespace vtrack
