// LADAR sweeps as azimuth slices (ladar_slice_t on LADAR_SLICE), and their reassembly.
//
// Why. LCM's UDP multicast sends a message of at most kMaxDatagramMessageBytes as one datagram;
// a larger one is cut into fragments, and a receiver that misses one fragment loses the whole
// message. A 64-layer sweep (2-3 MB) is ~44 fragments: at 5 % datagram loss only ~10 % of sweeps
// arrive. Sent as slices that each fit one datagram, a lost datagram costs one wedge of one sweep.
//
// Slicing (SliceSweep). The sweep's returns are taken column by column (a run of consecutive
// returns with the same dt_us: one firing of every layer), so a column is never split. The full
// circle is cut into `count` equal arcs, starting half a column step before the first column
// (no column on the seam) and following the direction the sensor turned (the sign of the summed
// azimuth steps between columns), and
// every column goes to the arc that holds the azimuth of its first finite return. Slice k holds
// the columns of the k-th arc in their order in the sweep, so for a rotating sensor, whose
// returns come in firing order, the slices concatenated in index order are the sweep's returns
// in their original order. Every arc is sent, empty ones too: the slices of a sweep tile the
// circle, so what no received slice covers is exactly what was lost.
//
// Assembly (SweepAssembler). Slices are collected per sensor and sweep (sensor_id, seq). A sweep
// is handed on as a ladar_scan_t (the slices' returns concatenated in index order):
//   - whole, when all slice_count slices arrived;
//   - partial, with the arcs no received slice covers, when a slice of a later sweep of the same
//     sensor arrives whose sweep starts more than reorder_window_us after this one ended (with
//     the default 0: as soon as the next sweep's slices start), when a later sweep of the sensor
//     is complete, when Expire() is called with a time more than timeout_us past its end, or on
//     Flush().
// Sweeps of one sensor are handed on in time order. A slice that cannot belong to a consistent
// sweep is refused and counted by reason (refused()): slice_bad_index (index or count out of
// range), slice_bad_arc (arc not finite or not within one turn), slice_inconsistent (header or
// count unlike the sweep's other slices), slice_duplicate (an index already received), slice_late
// (its sweep, or a later one of its sensor, was already handed on; a slice more than 1 s older
// than that starts a new stream instead: a restarted driver or a looped log). At most 16 sweeps
// are pending at once; beyond that the oldest is handed on.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/ladar_slice_t.hpp"

namespace vtrack::lcm_util {

// [bytes] Largest LCM message that lcm_udpm sends as a single datagram.
inline constexpr std::int64_t kMaxDatagramMessageBytes = 65499;
// [-] Most slices per sweep (a sweep that would need more is refused by SliceSweep; 4096 x 64 KB
// is 268 MB, far beyond any LADAR).
inline constexpr int kMaxSlicesPerSweep = 4096;

// An arc of azimuth, counter-clockwise from begin to end: begin in [-pi, pi), begin < end <=
// begin + 2 pi. [rad], sensor frame.
struct AzimuthArc {
  double begin = 0.0;
  double end = 0.0;
  double width() const { return end - begin; }
};

// Encoded size [bytes] of a slice of scan's header with n returns.
std::int64_t SliceEncodedSize(const ladar_scan_t& scan, std::int64_t n);

// The fewest slices whose every one fits in max_bytes (SliceSweep's count 0). Throws
// std::invalid_argument if no count up to kMaxSlicesPerSweep does (a column too large).
int AutoSliceCount(const ladar_scan_t& scan, std::int64_t max_bytes = kMaxDatagramMessageBytes);

// The slices of scan (see the top of this file). count: number of slices, 1..kMaxSlicesPerSweep,
// or 0 for AutoSliceCount(scan). Throws std::invalid_argument for a count out of range or
// parallel arrays of different lengths.
std::vector<ladar_slice_t> SliceSweep(const ladar_scan_t& scan, int count);

// The drivers' --slices option: "auto" (kSlicesAuto), "0" (whole sweeps, one ladar_scan_t each)
// or a count N in [1, kMaxSlicesPerSweep]. nullopt for anything else.
inline constexpr int kSlicesAuto = -1;
std::optional<int> ParseSlicesOption(const std::string& text);
// How many slices to send scan as under that option: 0 = whole; auto: AutoSliceCount for a 3-D
// sweep (num_rings > 1, megabytes), 0 for a single-plane one (it fits one datagram already).
int SlicesFor(int option, const ladar_scan_t& scan);

// [messages] Queue capacity for a live LADAR_SLICE subscription (lcm::Subscription::
// setQueueCapacity): LCM drops messages beyond 30 queued per subscription by default, and a sweep
// arrives as a burst of dozens of slices (45 for velodyne64) while the subscriber is still busy
// with the one before. Sized, like the tracker's other queues, for a 3 s stall: 3 s of velodyne64
// sweeps at 10 Hz are 1350 slices (84 MB); 1500 with margin.
inline constexpr int kSliceQueueCapacity = 1500;

// [us] Default gap a live driver leaves between the slices of a sweep (45 slices: 13 ms). Debian's
// lcm-logger keeps LCM's queue of 30 messages per subscription and lost slices and poses behind
// bursts of 33 slices sent back to back (lcmtypes_logger_test); with 300 us between them it
// records every one. A sensor's own packets are spread over the whole sweep.
inline constexpr int kSliceGapUs = 300;

// A sweep put back together.
struct AssembledSweep {
  ladar_scan_t scan;                 // header of the sweep, returns of the received slices
  std::int32_t slice_count = 0;      // [-] slices the sweep was sent as
  std::int32_t slices_received = 0;  // [-]
  std::vector<AzimuthArc> missing;   // arcs that no received slice covers (empty if whole)
  bool partial() const { return slices_received < slice_count; }
  double MissingDeg() const;         // [deg] total width of the missing arcs
};

class SweepAssembler {
 public:
  struct Options {
    // [us] how long after a sweep's end a slice of a later sweep may start before the sweep is
    // handed on incomplete: 0 = at the first slice of the next sweep (slices are sent in order;
    // a larger window waits for slices reordered across sweeps, at the cost of latency).
    std::int64_t reorder_window_us = 0;
    // [us] Expire() hands on a sweep whose end lies this far before the time it is given.
    // Long: a partial sweep is normally handed on by the next sweep's first slice; this is for a
    // stream that stops, and a driver descheduled in the middle of its burst must not see the
    // rest of its sweep refused as late.
    std::int64_t timeout_us = 1'000'000;
  };

  SweepAssembler() : SweepAssembler(Options{}) {}
  // Throws std::invalid_argument for a negative window or timeout.
  explicit SweepAssembler(Options options);

  // One decoded slice; the sweeps it completes or closes are appended to *out (time order per
  // sensor). Never throws for bad slices: they are refused and counted.
  void Add(ladar_slice_t&& slice, std::vector<AssembledSweep>* out);
  // Hands on every sweep that ended more than timeout_us before now_utime [us] (e.g. the
  // newest ego pose's time: sweep time, not wall time).
  void Expire(std::int64_t now_utime, std::vector<AssembledSweep>* out);
  // Hands on every pending sweep (end of a log, shutdown).
  void Flush(std::vector<AssembledSweep>* out);

  // Counters since construction.
  std::int64_t slices_accepted() const { return slices_accepted_; }
  std::int64_t slices_lost() const { return slices_lost_; }      // missing from handed-on sweeps
  double missing_deg() const { return missing_deg_; }            // [deg] their total arc
  std::int64_t sweeps_whole() const { return sweeps_whole_; }
  std::int64_t sweeps_partial() const { return sweeps_partial_; }
  const std::map<std::string, std::int64_t>& refused() const { return refused_; }
  std::size_t pending() const { return pending_.size(); }

 private:
  struct Pending {
    std::vector<ladar_slice_t> slices;  // by index; npoints < 0 marks one not received
    std::int32_t received = 0;
  };
  using Key = std::pair<std::string, std::int64_t>;  // (sensor_id, seq)

  // The reason to refuse a slice, or "" to accept it into pending_.
  std::string Check(const ladar_slice_t& s) const;
  // Hands on every pending sweep of sensor that ends before end_before [us] (time order).
  void CloseSensorBefore(const std::string& sensor, std::int64_t end_before,
                         std::vector<AssembledSweep>* out);
  void HandOn(std::map<Key, Pending>::iterator it, std::vector<AssembledSweep>* out);
  void HandOnOldest(std::vector<AssembledSweep>* out);

  Options options_;
  std::map<Key, Pending> pending_;
  // Per sensor, the utime of the newest sweep handed on: slices of it or older ones are late.
  std::map<std::string, std::int64_t> handed_on_utime_;
  std::map<std::string, std::int64_t> refused_;
  std::int64_t slices_accepted_ = 0, slices_lost_ = 0;
  std::int64_t sweeps_whole_ = 0, sweeps_partial_ = 0;
  double missing_deg_ = 0.0;
};

// The arcs of the circle that none of covered covers (each arc as AzimuthArc), merged, in
// counter-clockwise order from the first gap. Gaps narrower than 1e-9 rad (rounding) are
// ignored. An empty covered list gives the whole circle.
std::vector<AzimuthArc> UncoveredArcs(std::vector<AzimuthArc> covered);

}  // namespace vtrack::lcm_util
