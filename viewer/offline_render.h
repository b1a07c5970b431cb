// Offline rendering: one or more LCM logs, merged by event time, rendered as fast as possible
// with a progress bar on stderr.
//
// The logs are read twice. The first pass counts the messages of every channel (to choose what
// makes a frame and to know the frame count), finds the start of the run, and collects the whole
// ground truth (so that each frame shows the true path ahead of it as well as behind). The
// second pass renders.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "viewer/frame_output.h"
#include "viewer/render_job.h"

namespace vtrack::viewer {

struct LogIndex {
  std::map<std::string, std::int64_t> events;   // events per channel (every channel in the logs)
  std::int64_t first_scan_utime = -1;           // [us] utime of the first scan; -1 if none
  std::int64_t sliced_sweeps = 0;               // sweeps on the slice channel (distinct seq)
  std::int64_t first_tracks_utime = -1;         // [us] of the first TRACKS message; -1 if none
  std::map<std::int64_t, TimedPath> truth_paths;  // [us, m] every true object's path

  std::int64_t Count(const std::string& channel) const;
};

// First pass. Throws std::runtime_error naming the path if a log cannot be opened.
LogIndex IndexLogs(const std::vector<std::string>& paths, const Channels& channels,
                   bool progress);

struct OfflineStats {
  std::int64_t events = 0;           // log events read
  std::int64_t frames_rendered = 0;
  std::int64_t frames_skipped = 0;   // outside [start, end]
  std::int64_t decode_errors = 0;
  std::int64_t late_dropped = 0;     // TRACKS messages that came too late to be placed in order
  AssemblerParams::Trigger trigger = AssemblerParams::Trigger::kAuto;  // what made frames
  std::int64_t expected_frames = 0;  // trigger messages in the logs
  double wall_s = 0.0;               // [s]
  std::vector<std::string> warnings;  // e.g. truncated logs
};

// Renders the logs into *out (not closed here). A trigger of kAuto becomes kTracks if the logs
// hold any TRACKS message, else kScans. Throws std::runtime_error if a log cannot be read, if
// there is nothing to render, or if the output fails. Stops early on StopRequested() (SIGINT).
OfflineStats RenderLogs(const std::vector<std::string>& paths, const RenderJob& job,
                        FrameOutput* out, bool progress);

}  // namespace vtrack::viewer
