// Hand-built scoring frames for the tests of the metrics (CLEAR MOT, HOTA).
#pragma once

#include <cstdint>
#include <vector>

#include "log_tools/eval/clear_mot.h"

namespace vtrack::testing {

// One frame: Gt adds a truth object, Tr a track, each with its id and position.
struct FrameBuilder {
  eval::ScoringFrame f;
  explicit FrameBuilder(std::int64_t utime) { f.utime = utime; }
  FrameBuilder& Gt(std::int64_t id, double x, double y = 0.0) {
    f.gt_ids.push_back(id);
    f.gt_xy.emplace_back(x, y);
    return *this;
  }
  FrameBuilder& Tr(std::int64_t id, double x, double y = 0.0) {
    f.track_ids.push_back(id);
    f.track_xy.emplace_back(x, y);
    return *this;
  }
};

// n frames, frame t (utime t) as frame_at(t).
template <typename FrameAt>
std::vector<eval::ScoringFrame> Scans(int n, FrameAt frame_at) {
  std::vector<eval::ScoringFrame> frames;
  for (int t = 0; t < n; ++t) frames.push_back(frame_at(t));
  return frames;
}

// Truth 1 at the origin for 10 scans, track 7 exactly on it but for scans 3 and 4.
inline std::vector<eval::ScoringFrame> TrackMissingScans3And4() {
  return Scans(10, [](int t) {
    FrameBuilder b(t);
    b.Gt(1, 0.0);
    if (t != 3 && t != 4) b.Tr(7, 0.0);
    return b.f;
  });
}

}  // namespace vtrack::testing
