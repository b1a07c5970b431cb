// Publishing a run's messages against the wall clock: the clock that vtrack-ladar-driver and
// vtrack-ego-pose share without talking to each other.
//
// Data time is wall time: the message for scenario time t of a run that starts at U is stamped
// utime = U + t and published when the wall clock reads U + t (a scan: when its sweep is
// complete). A run ("lap") lasts the scenario's duration P; laps follow each other, lap k
// starting at U + k P. So scenario time is a pure function of the wall clock,
//   t = (now - U) mod P,
// and any two processes given the same scenario and the same U agree on it whenever each was
// started, restarted or delayed; a process that starts mid-lap joins at the current time.
//   --start-utime U   pins U (e.g. both started by one script with one value). If U is in the
//                     future the process waits for it.
//   (default)         U = 0, the Unix epoch: laps start at multiples of P since 1970, so two
//                     processes started by hand at any moments agree with no option at all.
// The same U given to vtrack-sim-log writes lap 0's messages: identical contents (seq of lap k is
// k * scans_per_lap + i live, i in the log).
//   --rate r          slow motion (r < 1) or fast forward (r > 1), like lcm-logplayer's --speed:
//                     the message for data time U + t is published at wall time U + t / r, so the
//                     data (stamps, contents) are those of r = 1 and only the pace changes. For a
//                     consumer too slow for real time (a sanitizer or debug build, a slow laptop).
//                     Needs --start-utime: both processes must share U (it is where data time and
//                     wall time coincide) and r.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace vtrack::sim {

// Items laid out on one lap, published one by one at their time.
class Timeline {
 public:
  virtual ~Timeline() = default;
  virtual int Count() const = 0;
  virtual std::int64_t LapUs() const = 0;  // [us] duration of one lap (RealtimeOptions::lap_us)
  virtual std::int64_t PublishOffsetUs(int i) const = 0;  // after the lap's start; non-decreasing
  // Builds item i of lap `lap` (which starts at lap_start_utime). Called before its time.
  virtual void Prepare(int i, std::int64_t lap_start_utime, std::int64_t lap) = 0;
  virtual void Publish() = 0;  // sends what Prepare() built
};

struct RealtimeOptions {
  std::int64_t lap_us = 0;                  // [us] P, > 0
  std::optional<std::int64_t> start_utime;  // [us] U; unset = 0 (the wall-clock grid)
  std::int64_t laps = 0;                    // laps to run from the first one; 0 = until stopped
  double stop_after_s = 0.0;                // [s] stop after this much wall time; 0 = never
  double rate = 1.0;                        // data seconds per wall second, > 0; != 1 needs
                                            // start_utime
  double late_limit_s = 0.5;                // [s] an item overdue by more than this is skipped;
                                            // one overdue by less is still published (a starved
                                            // process catches up in a burst, losing nothing)
  std::string name = "vtrack";              // prefix of progress lines on stderr
  std::string what = "messages";            // what is published, for progress lines
  double progress_interval_s = 5.0;         // [s] between progress lines; 0 = none
};

struct RealtimeStats {
  std::int64_t published = 0;
  std::int64_t skipped = 0;  // fell behind the clock and were not published
};

// Runs until the laps are done, the time limit passes or a stop signal arrives
// (lcm_util::InstallStopHandlers). Throws std::invalid_argument for bad options, and
// std::runtime_error if the requested laps are already over.
RealtimeStats RunRealtime(Timeline& timeline, const RealtimeOptions& options);

}  // namespace vtrack::sim
