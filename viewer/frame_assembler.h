// Puts together what one frame shows from messages that arrive separately and not quite in
// order: the scan, the tracker's answer to it (TRACKS) and its diagnostics (TRACK_DEBUG), the
// ground truth, and the ego poses around it. Also keeps what only time gives: the recent path
// of every track, of the ego vehicle and of every true object. Decoded messages in, FrameInputs
// out; no bus, no drawing.
//
// Frames. A frame is made per TRACKS message (trigger kTracks), per LADAR_SCAN (kScans), or
// (kAuto, for live use) per TRACKS message, and per scan while no TRACKS message has come for
// auto_idle_us of data time (no tracker running yet). Frames are keyed by the utime the message
// describes; a scan frame and a TRACKS frame at the same utime are one frame.
//
// Timing. Every message carries the time it describes (utime); the largest seen is the "data
// clock". A frame waits until the data clock is lag_us past the later of its utime and the time
// it was triggered, so that its TRACK_DEBUG, the poses that cover the sweep and the ground truth
// have arrived, whether the input is a live bus or logs merged by event time. Frames come out in
// increasing utime; one that would come out of order (a TRACKS message later than lag_us) is
// dropped and counted. A scan or pose stream that jumps back by more than 2 s (a log restarted)
// resets the assembler after handing out what was pending.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "base/pose.h"
#include "viewer/validate.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/track_debug_t.hpp"
#include "vtrack/track_list_t.hpp"

namespace vtrack::viewer {

struct AssemblerParams {
  enum class Trigger { kAuto, kTracks, kScans };

  Trigger trigger = Trigger::kAuto;         // [-] what makes a frame (see above)
  std::int64_t lag_us = 300'000;            // [us] data time a frame waits for its late parts
  std::int64_t scan_match_us = 500'000;     // [us] a frame takes each sensor's newest scan, and
                                            //      tracks/truth, at most this much older than it
  std::int64_t auto_idle_us = 1'000'000;    // [us] kAuto: scans make frames after this long
                                            //      without TRACKS
  double trail_s = 10.0;                    // [s] length of the recent paths (tracks, ego, truth)
  double truth_ahead_s = 5.0;               // [s] true path shown ahead of the frame time, when
                                            //     the whole path is known (SetTruthPaths)
  std::int64_t pose_span_us = 5'000'000;    // [us] ego poses kept for motion compensation

  // True if every field is valid; otherwise false and *error names the key and its value.
  bool Validate(std::string* error) const { return ValidateByFirstProblem(*this, error); }
  std::string FirstProblem() const;  // "" if valid
};

// A path with times: (utime [us], position [m]).
using TimedPath = std::vector<std::pair<std::int64_t, Eigen::Vector2d>>;

// Everything one frame needs, before any geometry is computed (that is SceneBuilder's job, on
// the render thread when live).
struct FrameInputs {
  std::int64_t utime = 0;                                    // [us] time the frame shows
  std::int64_t time_origin_utime = 0;                        // [us] start of the run
  std::vector<std::shared_ptr<const vtrack::ladar_scan_t>> scans;  // newest per sensor
  std::shared_ptr<const vtrack::track_list_t> tracks;        // for this utime, or the newest before
  std::shared_ptr<const vtrack::track_debug_t> debug;        // for exactly this utime, or null
  std::shared_ptr<const vtrack::object_list_t> truth;        // nearest in time, or null
  PoseHistory poses;                                         // ego poses around the frame
  std::map<std::int64_t, std::vector<Eigen::Vector2d>> track_trails;  // [m] by id, up to utime
  std::vector<Eigen::Vector2d> ego_trail;                    // [m] up to utime
  std::map<std::int64_t, std::vector<Eigen::Vector2d>> truth_paths;   // [m] by id
};

struct AssemblerStats {
  std::int64_t frames = 0;          // frames handed out
  std::int64_t late_dropped = 0;    // triggers that came after a later frame was handed out, and
                                    // TRACKS messages after their own utime's frame went out
                                    // without them (kAuto: a scan frame, the tracker slow)
  std::int64_t late_tracks = 0;     // of late_dropped, the TRACKS messages: no frame of their
                                    // own (a later scan frame, kAuto, may show them as the
                                    // newest tracks)
  std::int64_t resets = 0;          // time jumped back
  std::int64_t poses_refused = 0;   // out of order, repeated or invalid poses
};

class FrameAssembler {
 public:
  // Throws std::invalid_argument if the parameters are invalid.
  explicit FrameAssembler(const AssemblerParams& params);

  void AddScan(std::shared_ptr<const vtrack::ladar_scan_t> scan);
  void AddPose(const vtrack::pose_t& pose);
  void AddTracks(std::shared_ptr<const vtrack::track_list_t> tracks);
  void AddDebug(std::shared_ptr<const vtrack::track_debug_t> debug);
  void AddTruth(std::shared_ptr<const vtrack::object_list_t> truth);

  // The whole true path of every object, known in advance (offline: read from the logs first).
  // Frames then show each true path from trail_s before to truth_ahead_s after the frame.
  void SetTruthPaths(std::map<std::int64_t, TimedPath> paths);
  // Fixes the start of the run (default: the first frame's utime).
  void SetTimeOrigin(std::int64_t utime);

  // Frames that are ready, oldest first.
  std::vector<FrameInputs> TakeReady();
  // Every pending frame, ready or not (end of input, or the live bus went quiet).
  std::vector<FrameInputs> Flush();

  const AssemblerStats& stats() const { return stats_; }
  std::int64_t data_clock() const { return clock_; }
  std::size_t pending() const { return pending_.size(); }

 private:
  struct Pending {
    std::int64_t deadline = 0;  // [us] data clock at which the frame is complete
  };
  void Advance(std::int64_t utime);
  void Trigger(std::int64_t utime, bool by_tracks);
  void CheckJumpBack(std::int64_t utime, std::int64_t* last_of_stream);
  void Reset();
  void Prune();
  FrameInputs Make(std::int64_t utime) const;
  FrameInputs Emit(std::int64_t utime);  // Make, and remember it as the last handed out
  static std::vector<Eigen::Vector2d> Window(const TimedPath& path, std::int64_t from,
                                             std::int64_t to);

  AssemblerParams params_;
  AssemblerStats stats_;
  std::int64_t clock_ = 0;                 // [us] data clock
  std::int64_t last_scan_utime_ = 0;
  std::int64_t last_pose_utime_ = 0;
  std::int64_t last_tracks_clock_ = -1;    // data clock when TRACKS last came; -1 never
  std::int64_t last_emitted_ = -1;         // utime of the last frame handed out; -1 none
  bool last_emitted_had_tracks_ = false;   // that frame showed the TRACKS message of its utime
  bool has_origin_ = false;
  std::int64_t origin_ = 0;

  std::map<std::int64_t, Pending> pending_;
  std::vector<FrameInputs> ready_;  // handed out by the next TakeReady (after a reset)

  std::deque<std::shared_ptr<const vtrack::ladar_scan_t>> scans_;  // arrival order
  std::int64_t scan_points_ = 0;                                     // points in scans_
  std::map<std::int64_t, std::shared_ptr<const vtrack::track_list_t>> tracks_;
  std::map<std::int64_t, std::shared_ptr<const vtrack::track_debug_t>> debug_;
  std::map<std::int64_t, std::shared_ptr<const vtrack::object_list_t>> truth_;
  PoseHistory poses_;
  TimedPath ego_trail_;
  std::map<std::int64_t, TimedPath> track_trails_;
  std::map<std::int64_t, TimedPath> truth_trails_;  // accumulated from GROUND_TRUTH
  std::map<std::int64_t, TimedPath> known_truth_;   // SetTruthPaths
};

}  // namespace vtrack::viewer
